#!/usr/bin/env python3
"""Held-out registration check: amscr against OpenCV's ECC on MPEG-7-like contours.

For each of the first 35 classes of a manifest (one shape per class, the class's first file) and
2 seeded draws per condition: the traced pixel contour f, a random affine map T (any rotation,
anisotropic scale x0.5-2, shear +-0.5, translation), the target T(f) with a new start point and a
new point count (Euclidean resampling to 0.6-1.4 times the count), then the condition:

  clean; 1 % / 2 % Gaussian noise (sigma relative to the shape size); 5 / 10 / 20 % of the
  boundary missing (one contiguous run of the target's points dropped, the rest still closed);
  an open fragment of 70 % / 50 % of the source's boundary against the whole target (--partial).

Success: max_i |M(f_i) - T(f_i)| / size(T(f)) < 2 % over the source's (the fragment's) points,
size = RMS radius about the centroid.

ECC (--ecc; opencv-python-headless): cv2.findTransformECC, MOTION_AFFINE, on rendered, blurred
masks, from 8 starting rotations (centroid and area matched), the best correlation kept.

--sets A,B,P (the check's view): fold A / fold B of the manifest's classes (folds.tsv) and 35
procedural silhouettes (bindings/python/tests/shapegen.py, set 1, 200 px, traced the same way) side
by side: ok % under the max rule above and under the check's rule (RMS of the error over the
source's points < 2 % of the size), and wrong + confident (an RMS failure with confidence >= 0.25).
--stages NAME,... switches optional stages on (order, even_spacing, ...); --reversed gives the
fragments' points in the other order (against the target's way round).
Without --sets: the table, the confidences' medians, then each condition's largest errors (within
2 %, the median, the 90th and the 95th percentile).

Usage: nice .venv/bin/python3 bench/registration_heldout.py [--data DIR] [--ecc] [--draws 2] [--stray F] [--only KEYS]
       [--sets A,B,P] [--stages NAMES] [--reversed]
Deterministic: every draw is seeded by (condition, class index, draw); procedural shape i has index 1000 + i.
"""
import argparse
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def default_data(name='mpeg7-dev'):
    """$AMSCR_HELDOUT_DATA, else NAME in $AMSCR_DATASETS, else in ../shared/datasets beside the checkout."""
    return os.environ.get('AMSCR_HELDOUT_DATA') or os.path.join(
        os.environ.get('AMSCR_DATASETS') or os.path.join(HERE, '..', '..', 'shared', 'datasets'), name)


try:  # the installed package (scripts/setup.sh puts it into .venv)
    import amscr  # noqa: E402
except ImportError:  # else this checkout's, with AMSCR_LIBRARY naming build/libamscr.so.0
    sys.path.insert(0, os.path.join(HERE, '..', 'bindings', 'python'))
    try:
        import amscr  # noqa: E402
    except ImportError:  # registration_traced.py needs the tool alone
        amscr = None

CONDITIONS = [
    ('clean', 'clean', 0.0, 99.5),
    ('noise1', '1 % noise', 0.01, 99.0),
    ('noise2', '2 % noise', 0.02, 99.0),
    ('miss5', '5 % missing', 0.05, 98.0),
    ('miss10', '10 % missing', 0.10, 95.0),
    ('miss20', '20 % missing', 0.20, 85.0),
    ('frag70', 'fragment 70 %', 0.70, 95.0),
    ('frag50', 'fragment 50 %', 0.50, 90.0),
]


def shape_size(xy):
    c = xy - xy.mean(axis=0)
    return math.sqrt((c * c).sum(axis=1).mean())


def apply(T, xy):
    return xy @ T[:, :2].T + T[:, 2]


def random_affine(rng):
    th, ph = rng.uniform(0, 2 * math.pi, 2)
    s1 = rng.uniform(1.0, 2.0)
    s2 = 1.0 / rng.uniform(1.0, 2.0)
    h = rng.uniform(-0.5, 0.5)
    scale = rng.uniform(0.5, 2.5)
    rot = lambda a: np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    A = scale * rot(th) @ np.array([[s1, s1 * h], [0.0, s2]]) @ rot(ph)
    return np.hstack([A, rng.uniform(-50, 50, (2, 1))])


def resample(xy, m):
    """Closed polygon resampled to m points equally spaced in Euclidean arc length."""
    p = np.vstack([xy, xy[:1]])
    seg = np.hypot(*np.diff(p, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.arange(m) * cum[-1] / m
    return np.column_stack([np.interp(t, cum, p[:, 0]), np.interp(t, cum, p[:, 1])])


def make_case(f, key, amount, rng):
    """(source points, target points, T, partial) of one draw."""
    T = random_affine(rng)
    n = len(f)
    shift = int(rng.integers(n))
    nt = int(round(rng.uniform(0.6, 1.4) * n))
    tgt = resample(apply(T, np.roll(f, -shift, axis=0)), max(nt, 16))
    src = f
    size = shape_size(apply(T, f))
    if key.startswith('noise'):
        tgt = tgt + rng.normal(0.0, amount * size, tgt.shape)
    elif key.startswith('miss'):
        m = len(tgt)
        drop = int(math.ceil(amount * m))
        start = int(rng.integers(m))
        tgt = np.roll(tgt, -start, axis=0)[drop:]
    elif key.startswith('frag'):
        k = int(round(amount * n))
        start = int(rng.integers(n))
        src = np.roll(f, -start, axis=0)[:k]
    return src, tgt, T, size, key.startswith('frag')


def with_strays(src, share, rng):
    """src with round(share * n) of its inner points (not the first or last two) moved to random
    places in its bounding box."""
    k = int(round(share * len(src)))
    if k == 0:
        return src
    out = src.copy()
    lo, hi = src.min(axis=0), src.max(axis=0)
    out[rng.choice(np.arange(2, len(src) - 2), k, replace=False)] = lo + (hi - lo) * rng.uniform(0, 1, (k, 2))
    return out


def map_error(M, T, src, size, rms=False):
    """The largest (rms: the RMS) |M(f_i) - T(f_i)| over src, a share of size; inf without a map."""
    if M is None:
        return math.inf
    d = apply(M, src) - apply(T, src)
    d = np.sqrt((d * d).sum(axis=1))
    return float((np.sqrt((d * d).mean()) if rms else d.max()) / size)


def preset_error(src, tgt, T, size):
    """The map error (% of the size) of amscr.register(src, tgt) against T; inf when it fails."""
    return 100 * map_error(amscr_register(src, tgt, False)[0], T, src, size)


def error_summary(errs):
    """'N pairs, within 2 %: ..., median ..., 90th pct ..., 95th pct ...' of errors in %."""
    e = np.sort(errs)
    n = len(e)
    return '%d pairs, within 2 %%: %.1f %%, median %.3f %%, 90th pct %.3f %%, 95th pct %.3f %%' % (
        n, 100 * np.mean(e < 2), e[n // 2], e[9 * n // 10], e[95 * n // 100])


def amscr_register(src, tgt, partial, stages=None):
    """The recovered 2x3 map, or None when the call fails."""
    opts = {'stages': stages} if stages else {}
    try:
        r = amscr.register(src, tgt, partial=True, **opts) if partial else amscr.register(src, tgt, **opts)
    except amscr.AmscrError:
        return None, None
    return np.hstack([r.A, r.B[:, None]]), r


# ------------------------------------------------------------------------ ECC
CANVAS = 400


def render(xy, cv2):
    """Mask of the polygon in a CANVAS^2 image and the 2x3 map input -> pixels."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    s = 0.7 * CANVAS / max(hi - lo)
    off = 0.5 * CANVAS - s * 0.5 * (lo + hi)
    P = np.array([[s, 0, off[0]], [0, s, off[1]]])
    img = np.zeros((CANVAS, CANVAS), np.uint8)
    cv2.fillPoly(img, [np.round(apply(P, xy) * 16).astype(np.int32)], 255, lineType=cv2.LINE_AA, shift=4)
    return cv2.GaussianBlur(img, (0, 0), 4.0).astype(np.float32) / 255.0, P


def inv_affine(P):
    A = np.linalg.inv(P[:, :2])
    return np.hstack([A, -(A @ P[:, 2:])])


def compose(P, Q):  # P after Q
    return np.hstack([P[:, :2] @ Q[:, :2], P[:, :2] @ Q[:, 2:] + P[:, 2:]])


def ecc_multistart(a, b, cv2):
    """OpenCV's ECC (MOTION_AFFINE) between float images a and b from 8 starting rotations, the
    centroids and areas matched: the W (2 x 3, b(W x) ~ a(x)) of the best correlation, or None."""
    ma, mb = cv2.moments(a), cv2.moments(b)
    if ma['m00'] <= 0 or mb['m00'] <= 0:
        return None
    ca = np.array([ma['m10'], ma['m01']]) / ma['m00']
    cb = np.array([mb['m10'], mb['m01']]) / mb['m00']
    k = math.sqrt(mb['m00'] / ma['m00'])
    crit = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 100, 1e-5)
    best, best_rho = None, -np.inf
    for i in range(8):
        t = 2 * math.pi * i / 8
        A = k * np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        W = np.hstack([A, (cb - A @ ca)[:, None]]).astype(np.float32)
        try:
            rho, W = cv2.findTransformECC(a, b, W, cv2.MOTION_AFFINE, crit, None, 5)
        except cv2.error:
            continue
        if rho > best_rho:
            best, best_rho = W.astype(np.float64), rho
    return best


def ecc_register(src, tgt, cv2):
    a, Ps = render(src, cv2)
    b, Pt = render(tgt, cv2)
    best = ecc_multistart(a, b, cv2)
    if best is None:
        return None
    # a(x) ~ b(W x): W maps source pixels to target pixels
    return compose(inv_affine(Pt), compose(best, Ps))


# ------------------------------------------------------------------------ main
def load_shapes(data, nclass, subpixel=False):
    """The outer contour of the first silhouette of each of the first nclass classes. The table's
    sources are the pixel-centre chains (subpixel=False), as published; subpixel=True traces the
    iso-line instead (amscr's default for images)."""
    from PIL import Image
    rows = [l.rstrip('\n').split('\t') for l in open(os.path.join(data, 'manifest.tsv'))][1:]
    first = {}
    for fname, cls in rows:
        first.setdefault(cls, fname)
    shapes = []
    for cls, fname in list(first.items())[:nclass]:
        img = np.asarray(Image.open(os.path.join(data, fname)).convert('L'))
        shapes.append((cls, amscr.contour_from_mask(img, subpixel=subpixel)))
    return shapes


CONFIDENT = 0.25


def load_sets(data, sets, subpixel=False):
    """[(set, class, contour, seed index)]: the manifest's classes of folds.tsv's folds in `sets`
    (A, B) and, for P, 35 procedural silhouettes (shapegen set 1)."""
    out = []
    if set(sets) & {'A', 'B'}:
        folds = dict(l.rstrip('\n').split('\t') for l in list(open(os.path.join(data, 'folds.tsv')))[1:])
        for si, (cls, f) in enumerate(load_shapes(data, 10 ** 6, subpixel)):
            if folds.get(cls) in sets:
                out.append((folds[cls], cls, f, si))
    if 'P' in sets:
        sys.path.insert(1, os.path.join(HERE, '..', 'bindings', 'python', 'tests'))
        import shapegen
        for i in range(35):
            out.append(('P', 'proc%02d' % i, amscr.contour_from_mask(shapegen.silhouette(1, i), subpixel=subpixel),
                        1000 + i))
    return out


def run(args, shapes, conds, cv2=None):
    """{(set, condition key): [(ok, ok under the RMS rule, confidence or None, ms, ECC ok, the largest
    error in % of the size)]} of every seeded draw; shapes: [(set, class, contour, seed index)]."""
    stages = {k: True for k in args.stages.split(',')} if args.stages else None
    res = {}
    for key, _, amount, _ in conds:
        ci = [c[0] for c in CONDITIONS].index(key)
        for fold, cls, f, si in shapes:
            for d in range(args.draws):
                src, tgt, T, size, partial = make_case(f, key, amount, np.random.default_rng([14, ci, si, d]))
                if partial and args.reversed:
                    src = src[::-1].copy()
                seen = with_strays(src, args.stray, np.random.default_rng([15, ci, si, d]))
                t0 = time.perf_counter()
                M, r = amscr_register(seen, tgt, partial, stages)
                ms = 1e3 * (time.perf_counter() - t0)
                ok_ecc = cv2 is not None and map_error(ecc_register(src, tgt, cv2), T, src, size) < 0.02
                err = map_error(M, T, src, size)
                res.setdefault((fold, key), []).append((err < 0.02,
                                                        map_error(M, T, src, size, rms=True) < 0.02,
                                                        r.confidence if r is not None else None, ms, ok_ecc,
                                                        100 * err))
        print('.', end='', file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return res


def sets_table(args, conds):
    """The check's view: the sets side by side, both success rules and wrong + confident."""
    sets = args.sets.split(',')
    res = run(args, load_sets(args.data, sets, args.tracer == 'subpixel'), conds)
    names = {'A': 'fold A', 'B': 'fold B', 'P': 'procedural'}
    print('ok %% max rule / ok %% RMS rule / wrong + confident %% / successes confident %% (%d draws%s)' %
          (args.draws, ', stages ' + args.stages if args.stages else ''))
    print('| condition | ' + ' | '.join('%s (%d)' % (names[k], len(res[(k, conds[0][0])])) for k in sets) + ' | ms |')
    print('|---|' + '---|' * len(sets) + '---|')
    for key, label, _, _ in conds:
        cells = []
        for k in sets:  # a failed call: confidence 0
            ok, ok_rms, conf = np.array([(r[0], r[1], (r[2] or 0.0) >= CONFIDENT) for r in res[(k, key)]]).T
            cells.append('%.1f / %.1f / %.1f / %.1f' % (100 * ok.mean(), 100 * ok_rms.mean(),
                                                        100 * (conf & ~ok_rms).mean(),
                                                        100 * (conf & ok_rms).sum() / max(1, ok_rms.sum())))
        ms = np.mean([r[3] for k in sets for r in res[(k, key)]])
        print('| %s | %s | %.1f |' % (label, ' | '.join(cells), ms))
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=default_data())
    ap.add_argument('--classes', type=int, default=35)
    ap.add_argument('--draws', type=int, default=2)
    ap.add_argument('--ecc', action='store_true', help='also run OpenCV ECC (slow)')
    ap.add_argument('--only', help='comma-separated condition keys')
    ap.add_argument('--stray', type=float, default=0.0,
                    help='share of the SOURCE points moved to random places in its bounding box (stray points); '
                         'the error is still measured on the clean source')
    ap.add_argument('--tracer', choices=['pixel-chain', 'subpixel'], default='pixel-chain',
                    help='how the source silhouettes are traced (the published table: pixel-chain)')
    ap.add_argument('--sets', help="comma-separated sets side by side: A, B (folds.tsv), P (procedural)")
    ap.add_argument('--stages', default='', help='comma-separated optional stages switched on')
    ap.add_argument('--reversed', action='store_true', help="fragments given against the target's way")
    args = ap.parse_args()
    if not os.path.exists(os.path.join(args.data, 'manifest.tsv')):
        print('no manifest in %s: skipped' % args.data)
        return 0
    conds = [c for c in CONDITIONS if not args.only or c[0] in args.only.split(',')]
    if args.sets:
        return sets_table(args, conds)
    cv2 = None
    if args.ecc:
        try:
            import cv2
        except ImportError:
            print('opencv not installed: ECC column skipped')
    shapes = [('', cls, f, si) for si, (cls, f) in enumerate(load_shapes(args.data, args.classes,
                                                                        args.tracer == 'subpixel'))]
    res = run(args, shapes, conds, cv2)
    print('| condition | amscr | ECC multi-start | goal | ms/registration (Python call) |')
    print('|---|---|---|---|---|')
    for key, label, _, goal in conds:
        rs = res[('', key)]
        ecc = '%.1f %%' % (100.0 * np.mean([r[4] for r in rs])) if cv2 is not None else '-'
        print('| %s | %.1f %% | %s | >= %.1f %% | %.2f |' % (label, 100.0 * np.mean([r[0] for r in rs]), ecc, goal,
                                                          np.mean([r[3] for r in rs])))
    if any(r[2] is not None for rs in res.values() for r in rs):
        print('\nconfidence (median) of successes / failures per condition:')
        for key, label, _, _ in conds:
            good, bad = ([r[2] for r in res[('', key)] if r[2] is not None and r[0] == ok] for ok in (True, False))
            print('  %-14s %s / %s' % (label, '%.3f' % np.median(good) if good else '-',
                                      '%.3f' % np.median(bad) if bad else '-'))
    print('\nlargest error over the source\'s points, % of the size, per condition:')
    for key, label, _, _ in conds:
        print('  %-14s %s' % (label, error_summary([r[5] for r in res[('', key)]])))
    return 0


if __name__ == '__main__':
    sys.exit(main())
