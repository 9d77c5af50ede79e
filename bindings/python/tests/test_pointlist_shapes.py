"""Point-list registration on shapes beyond the datasets (docs/measurements.md, "Point lists on
fold A, fold B and procedural shapes"): the pairs of bench/registration_heldout.py (a random
affine map, a new start and point count, then the condition) built on a drawn T and on the seeded
procedural silhouettes of shapegen.py, scored as the independent check scores them: the RMS of
the map error over the source's points below 2 % of the target's RMS radius. Needs no dataset.
Measured: ~3 s."""
import os
import sys

import numpy as np
import pytest

cv2 = pytest.importorskip('cv2')

import amscr  # noqa: E402

import shapegen  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'bench'))
import registration_heldout as bench  # noqa: E402


def rms_error(key, f, seed):
    """The RMS map error (fraction of the size) of one pair of condition `key`, and the result."""
    amount = dict((c[0], c[2]) for c in bench.CONDITIONS)[key]
    src, tgt, T, size, partial = bench.make_case(f, key, amount, np.random.default_rng(seed))
    M, r = bench.amscr_register(src, tgt, partial)
    return (bench.map_error(M, T, src, size, rms=True) if M is not None else np.inf), r


def t_shape():
    """A T: straight edges that a fragment can collapse onto."""
    img = np.zeros((240, 240), np.uint8)
    cv2.fillPoly(img, [np.array([[30, 40], [210, 40], [210, 80], [150, 80], [135, 200], [105, 200], [90, 80],
                                 [30, 80]], np.int32)], 255)
    return amscr.contour_from_mask(img, subpixel=False)


@pytest.mark.parametrize('key', ['frag70', 'frag50'])
def test_fragments_of_a_t_keep_their_area(key):
    """20 draws each: all within 2 % (before a collapsed placement lost: 6 / 3 of 20 failed, the
    fragment mapped onto one straight edge, its area shrunk 10-1000x)."""
    f = t_shape()
    failed = []
    for d in range(20):
        err, r = rms_error(key, f, [42, d])
        if err >= 0.02:
            failed.append((d, round(100 * err, 1)))
        assert np.linalg.det(r.A) > 0
    assert not failed, failed


def test_procedural_fragments_of_70_percent():
    """The first 10 procedural shapes, 2 draws each: every 70 % fragment within 2 %."""
    failed = []
    for i in range(10):
        f = amscr.contour_from_mask(shapegen.silhouette(1, i), subpixel=False)
        for d in range(2):
            err, _ = rms_error('frag70', f, [14, 6, 1000 + i, d])
            if err >= 0.02:
                failed.append((i, d, round(100 * err, 1)))
    assert not failed, failed


def test_fragment_points_in_either_order():
    """An open fragment has no orientation of its own: given against the target's way round it
    registers as well, with a map that keeps the orientation (before: 0 of 10, mirrored maps)."""
    failed = []
    for i in range(5):
        f = amscr.contour_from_mask(shapegen.silhouette(1, i), subpixel=False)
        for d in range(2):
            src, tgt, T, size, _ = bench.make_case(f, 'frag70', 0.7, np.random.default_rng([14, 6, 1000 + i, d]))
            r = amscr.register(src[::-1].copy(), tgt, partial=True)
            err = bench.map_error(np.hstack([r.A, r.B[:, None]]), T, src, size, rms=True)
            if err >= 0.02 or r.reflected or np.linalg.det(r.A) <= 0:
                failed.append((i, d, round(100 * err, 1), r.reflected))
    assert not failed, failed


# Near-symmetric stars broken by a small harmonic (shapegen shapes 6 and 1): pairs whose right
# turn the criterion ranked below its three lowest minima (shape 6: clean, 5 % missing, 1 %
# noise), or which the ranking's trimmed cost could not tell from a wrong turn (shape 1, 1 %
# noise); each was a wrong turn before.
NEAR_SYMMETRIC = [(6, 'clean', [14, 0, 1006, 3]), (6, 'miss5', [14, 3, 1006, 0]), (6, 'noise1', [14, 1, 1006, 5]),
                  (6, 'noise1', [14, 1, 1006, 6]), (1, 'noise1', [14, 1, 1001, 3])]


@pytest.mark.parametrize('shape,key,seed', NEAR_SYMMETRIC)
def test_near_symmetric_star_takes_the_right_turn(shape, key, seed):
    f = amscr.contour_from_mask(shapegen.silhouette(1, shape), subpixel=False)
    err, _ = rms_error(key, f, seed)
    assert err < 0.02, '%s: %.1f %%' % (key, 100 * err)
