"""The pairs of bench/registration_traced.py --families on the procedural shapes, one at a time,
for the tests that pin a pair of that sweep: the source silhouette, its damaged target (as the
bench seeds it) and the library's registration of the two traced contours. Needs OpenCV and
scikit-image (the callers skip without them)."""
import os
import sys

import numpy as np

import amscr

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..', 'bench'))
import shapegen  # noqa: E402  (beside this file)


def bench():
    """registration_traced, set up as --families sets it."""
    import registration_traced as B
    B.SPAN, B.CANVAS = 200.0, 280
    return B


def opencv_contour(img, method=None):
    """The largest outer contour of img as cv2.findContours returns it ((n, 1, 2) int32), with
    `method` (None: cv2.CHAIN_APPROX_NONE, the boundary pixel centres)."""
    import cv2
    binary = (img > 127).astype(np.uint8)
    cs, _ = cv2.findContours(binary, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE if method is None else method)
    return max(cs, key=len)


def opencv_chain(img):
    """opencv_contour(img) as (n, 2) floats."""
    return opencv_contour(img)[:, 0, :].astype(float)


def images(B, i, key, draw):
    """(source image, its sub-pixel contour f, damaged target image, true map T, success
    threshold %) of procedural shape i under the families condition `key`, draw `draw`, seeded
    as the bench seeds it."""
    _, _, kind, level, thr, seed = [c for c in B.family_conditions() if c[0] == key][0]
    src = B.load_source(shapegen.silhouette(1, i))
    f = B.subpixel_contour(src)
    tgt, T = B.family_target(src, f, kind, level, np.random.default_rng([1000 + i, seed, draw, 2024]))
    return src, f, tgt, T, thr


def pair(B, i, key, draw, chain=False, swap=False, **options):
    """(registration, RMS error % of R, success threshold %) of procedural shape i under the
    families condition `key`, draw `draw` (chain: the target as OpenCV's pixel chain; swap: the
    target registered onto the source, its map inverted before it is measured; options:
    amscr.register's)."""
    src, f, tgt, T, thr = images(B, i, key, draw)
    t = opencv_chain(tgt) if chain else amscr.contour_from_mask(tgt, join=True)
    s = amscr.contour_from_mask(src, join=True)
    r = amscr.register(t, s, **options) if swap else amscr.register(s, t, **options)
    M = np.hstack([np.asarray(r.A), np.asarray(r.B)[:, None]])
    return r, B.errors(B.inv_affine(M) if swap else M, T, f)[0], thr


LOW = [(key, draw) for key in ('lowres30', 'lowres40') for draw in (0, 1)]


def low_pairs(B, chain=False, swap=False, off=True):
    """The procedural shapes (35) at binary 30 and 40 px, draws 0-1, with and without (off) the
    pixel_grid stage (swap: the small image the source): {(shape, key, draw): (error with it, its
    confidence, whether it ran, error without or nan, success threshold)}."""
    out = {}
    for i in range(35):
        for key, draw in LOW:
            on, err_on, thr = pair(B, i, key, draw, chain=chain, swap=swap)
            err_off = pair(B, i, key, draw, chain=chain, swap=swap, stages={'pixel_grid': False})[1] if off else np.nan
            out[(i, key, draw)] = (err_on, on.confidence, on.stages['pixel_grid'], err_off, thr)
    return out
