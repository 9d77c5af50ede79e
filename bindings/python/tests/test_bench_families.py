"""The registration bench's procedural silhouettes (shapegen.py, beside this file) and damage
families (bench/registration_traced.py --families): seeded, one piece each, and the damage as
stated -- a bite leaves one piece, a touching disk adds area, a low-resolution target spans its
pixels. Skipped without OpenCV or scikit-image."""
import os
import sys

import numpy as np
import pytest

cv2 = pytest.importorskip('cv2')
pytest.importorskip('skimage')
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'bench'))
import shapegen  # noqa: E402  (beside this file)

N = 35  # the bench's procedural set: silhouette(1, i), i < 35


def pieces(mask):
    return cv2.connectedComponents((mask > 0).astype(np.uint8), connectivity=8)[0] - 1


def test_silhouettes_are_seeded():
    for i in (0, 7, 12):
        a, b = shapegen.silhouette(1, i), shapegen.silhouette(1, i)
        assert a.dtype == np.uint8 and np.array_equal(a, b)
        assert not np.array_equal(a, shapegen.silhouette(2, i))
    assert not np.array_equal(shapegen.silhouette(1, 0), shapegen.silhouette(1, 5))


@pytest.mark.parametrize('i', range(N))
def test_silhouettes_are_single_shapes(i):
    m = shapegen.silhouette(1, i)
    assert set(np.unique(m)) <= {0, 255}
    assert pieces(m) == 1, 'shape %d: %d pieces' % (i, pieces(m))
    assert not np.concatenate([m[0], m[-1], m[:, 0], m[:, -1]]).any()
    x, y, w, h = cv2.boundingRect(m)
    assert 185 <= max(w, h) <= 201, 'shape %d spans %d px' % (i, max(w, h))  # thin tips fade
    assert 0.05 < (m > 0).sum() / float(w * h) < 0.95
    holes = pieces(255 - m) - 1  # background pieces other than the outside
    if shapegen.KINDS[i % len(shapegen.KINDS)] == 'holes':
        assert holes >= 1, 'shape %d of kind holes has none' % i


@pytest.fixture(scope='module')
def bench():
    import registration_traced as B
    B.SPAN, B.CANVAS = 200.0, 280  # as --families sets them
    src = B.load_source(shapegen.silhouette(1, 3))
    return B, src, B.subpixel_contour(src)


def test_family_levels():
    import registration_traced as B
    full, quick = B.family_conditions(), B.family_conditions(quick=True)
    assert len(full) == 21 and [c[0] for c in quick] == ['clean', 'noise1.5', 'bite0.3', 'touching0.3',
                                                         'lowres40', 'grey40']
    assert all(c in full for c in quick)  # --quick: the same seeds as the full sweep


@pytest.mark.parametrize('d', range(3))
def test_family_damage(bench, d):
    B, src, f = bench
    for key, _, kind, level, _, seed in B.family_conditions():
        rng = np.random.default_rng([1003, seed, d, 2024])
        tgt, T = B.family_target(src, f, kind, level, rng)
        clean, T0 = B.make_target(src, f, np.random.default_rng([1003, seed, d, 2024]))
        if kind in ('lowres', 'grey'):
            span = max(cv2.boundingRect((tgt > 0).astype(np.uint8))[2:])
            want = max(cv2.boundingRect(clean)[2:]) * level / B.SPAN  # thin tips fade in binary
            assert span <= want + 3 and (kind == 'lowres' or span >= want - 3), '%s spans %d px' % (key, span)
            assert np.allclose(T[:, :2], T0[:, :2] * (tgt.shape[0] / float(B.CANVAS)))
            continue
        assert np.array_equal(T, T0)
        a, a0 = (tgt > 0).sum(), (clean > 0).sum()
        if kind == 'bite':
            assert pieces(tgt) == 1 and a < a0
        elif kind == 'touching':
            assert pieces(tgt) <= pieces(clean) and a > a0 + 0.5 * np.pi * (level * B.shape_size(B.apply(T, f))) ** 2
        elif kind == 'noise':
            assert pieces(tgt) > 1  # the specks
            assert np.mean((tgt > 0) != (clean > 0)) < 0.1
        else:
            assert np.array_equal(tgt, clean)
