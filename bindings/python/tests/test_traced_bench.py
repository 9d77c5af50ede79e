"""The traced-pair benchmark's own frame (bench/registration_traced.py): the source contour it
scores maps on is the silhouette's outline, and every warped target fits its canvas. (Before
0.5's fix the contour with the most points was taken: for the pocket watch a hole's boundary,
so its targets were fitted to the hole and overflowed the canvas.) Skipped without mpeg7-dev or
OpenCV."""
import numpy as np
import pytest

from test_polish import heldout_data


@pytest.fixture(scope='module')
def bench():
    pytest.importorskip('cv2')
    pytest.importorskip('skimage')
    data = heldout_data()
    import registration_traced
    return registration_traced, registration_traced.load_classes(data)


def test_source_contour_is_the_outline(bench):
    B, classes = bench
    for cls, path, _ in classes:
        src = B.load_source(path)
        area = B.enclosed_area(B.subpixel_contour(src))
        filled = (src > 0).sum()  # the outline encloses the silhouette and its holes
        assert area >= 0.95 * filled, '%s: contour encloses %.0f px, the silhouette has %d' % (cls, area, filled)


@pytest.mark.parametrize('key', ['clean', 'bite', 'lowres'])
def test_targets_fit_the_canvas(bench, key):
    B, classes = bench
    names = [c[0] for c in classes]
    for cls in ('pocket', 'fork', 'device7'):
        i = names.index(cls)
        src = B.load_source(classes[i][1])
        f = B.subpixel_contour(src)
        for d in range(2):
            rng = np.random.default_rng([i, [c[0] for c in B.CONDITIONS].index(key), d, 2024])
            tgt, _ = B.make_target(src, f, rng)
            border = np.concatenate([tgt[0], tgt[-1], tgt[:, 0], tgt[:, -1]])
            assert not border.any(), '%s draw %d: the target touches the canvas border' % (cls, d)
