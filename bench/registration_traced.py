#!/usr/bin/env python3
"""Registration from images: the amscr tool on traced PNG pairs against OpenCV's ECC.

For each class of mpeg7-dev (one shape a class, its first file; folds.tsv's fold A / B) and
`--procedural N` seeded silhouettes (bindings/python/tests/shapegen.py; "fold" P), `--draws`
seeded draws a condition: the silhouette 140 px across in a 200-px image (the source), a random
affine map T (any rotation, axis scales x0.5-2, shear +-0.5; then scaled and shifted so the shape
again spans 140 px) applied with cv2.warpAffine (the target), the target damaged in the image:
clean (thresholded at half level); noise (the boundary moved by a smooth field of 1.5 % of the RMS
radius, 12 specks of 1-2 px); bite (a disk of 0.3 x the radius removed at a boundary point);
touching (such a disk added outside); lowres / grey (both images reduced 4x by area, --low-px N,
thresholded / grey). --families (--quick: the check's points only) builds the check's conditions,
each swept (family_target): one table a method, ok % / w+c %, fold A, fold B and the procedural
set side by side (RMS measure); --json OUT writes {draws, table, pairs}. The pairs are registered
by the tool, `amscr register SRC TGT --json` (--tool or $AMSCR_TOOL; also --pixel-chain), and by
cv2.findTransformECC (MOTION_AFFINE, 8 starting rotations, centroid and area matched, the best
correlation kept); --reference: find_contours point lists of both images through the tool.
--swap: the other direction, the damaged image registered onto the clean one (the tool and the
library; its map inverted before it is measured), so a small image is the source.

Error over the clean source's sub-pixel contour f, % of R = size(T(f)) (the RMS radius): the RMS
of |M(f_i) - T(f_i)| (the primary table: the reference evaluation's figures, by its calibration,
are RMS ones; docs/measurements.md) and the max (stricter, the figures before 0.5). Success: < 2 %
(4 % at low resolution). Wrong + confident (w+c): a failure reported with confidence >= 0.25;
ok+c: the successes' share with confidence >= 0.25. ms: wall time a pair (the tool's with process
start and PNG decoding). --json OUT: a row a pair, each method [RMS %, max %, confidence, ms, the evidence:
the --json fields of the confidence (docs/method.md §11.5) and whether pixel_grid ran].
"lib ms": the library alone in this process (amscr.contour_from_mask(join=True), amscr.register),
the median; skipped with --families or without the amscr package. Every draw is seeded by (shape
index, condition, draw). Usage: nice .venv/bin/python bench/registration_traced.py --help
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import cv2

import registration_heldout  # noqa: E402  (bench/: the ECC multi-start both benches use)
sys.path.insert(1, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'bindings', 'python', 'tests'))
import shapegen  # noqa: E402  (the procedural silhouettes, shared with the tests)
from registration_heldout import apply, compose, inv_affine, shape_size  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, '..')

CONDITIONS = [  # key, label, success threshold (% of the size)
    ('clean', 'clean', 2.0),
    ('noise', 'segmentation noise', 2.0),
    ('bite', 'bite', 2.0),
    ('touching', 'touching object', 2.0),
    ('lowres', 'low resolution, binary', 4.0),
    ('grey', 'low resolution, antialiased grey', 4.0),
]
CANVAS = 200
SPAN = 140.0
REDUCE = 4
CONFIDENT = 0.25


def enclosed_area(xy):
    return abs(float(cv2.contourArea(xy.astype(np.float32))))


def subpixel_contour(img):
    """The iso-line at half level of an 8-bit image enclosing the largest area (the outer boundary,
    not a hole's) as (x, y) rows (skimage)."""
    from skimage import measure
    cs = measure.find_contours(np.pad(img.astype(float), 1), 127.5)
    c = max(cs, key=enclosed_area)[:, ::-1] - 1.0
    return c[:-1] if np.all(c[0] == c[-1]) else c


def fit_map(xy):
    """The map (scale, shift) putting xy's bounding box at SPAN px in the middle of CANVAS."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    s = SPAN / max(hi - lo)
    off = 0.5 * (CANVAS - 1) - s * 0.5 * (lo + hi)
    return np.array([[s, 0, off[0]], [0, s, off[1]]])


def load_source(path):
    """The silhouette (foreground 255; a file or an array) scaled to SPAN px in a CANVAS image."""
    img = cv2.imread(path, cv2.IMREAD_GRAYSCALE) if isinstance(path, str) else path
    m = (img > 127).astype(np.uint8) * 255
    if np.mean(np.concatenate([m[0], m[-1], m[:, 0], m[:, -1]])) > 127:
        m = 255 - m
    m = largest_piece(m)
    ys, xs = np.nonzero(m)
    P = fit_map(np.column_stack([xs, ys]).astype(float))
    src = cv2.warpAffine(m, P, (CANVAS, CANVAS), flags=cv2.INTER_AREA if P[0, 0] < 1 else cv2.INTER_LINEAR)
    return np.where(src > 127, 255, 0).astype(np.uint8)


def random_affine(rng):
    th = rng.uniform(0, 2 * math.pi)
    s1, s2 = rng.uniform(0.5, 2.0, 2)
    h = rng.uniform(-0.5, 0.5)
    R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    return R @ np.diag([s1, s2]) @ np.array([[1.0, h], [0.0, 1.0]])


def make_target(src, f, rng):
    """The warped source and the true map T (source pixels -> target pixels)."""
    A = random_affine(rng)
    T0 = np.hstack([A, np.zeros((2, 1))])
    T = compose(fit_map(apply(T0, f)), T0)
    tgt = cv2.warpAffine(src, T, (CANVAS, CANVAS), flags=cv2.INTER_LINEAR)
    return np.where(tgt > 127, 255, 0).astype(np.uint8), T


def disk(img, c, r, v):
    out = img.copy()
    cv2.circle(out, (int(round(c[0] * 16)), int(round(c[1] * 16))), int(round(r * 16)), int(v), -1,
               lineType=cv2.LINE_8, shift=4)
    return out


def damage(key, tgt, g, rng):
    """The damaged target; g: its sub-pixel contour (target pixels)."""
    radius = shape_size(g)
    if key == 'noise':
        inside = cv2.distanceTransform((tgt > 0).astype(np.uint8), cv2.DIST_L2, 5)
        outside = cv2.distanceTransform((tgt == 0).astype(np.uint8), cv2.DIST_L2, 5)
        sd = inside - outside
        field = cv2.GaussianBlur(rng.normal(0, 1, tgt.shape), (0, 0), 0.1 * radius)
        field *= 0.015 * radius / max(field.std(), 1e-12)
        out = np.where(sd + field > 0, 255, 0).astype(np.uint8)
        for _ in range(12):
            out = disk(out, rng.uniform(0, CANVAS, 2), rng.uniform(1, 2), 255)
        return out
    if key in ('bite', 'touching'):
        p = g[rng.integers(len(g))]
        r = 0.3 * radius
        if key == 'bite':
            return disk(tgt, p, r, 0)
        u = p - g.mean(axis=0)
        u /= max(np.linalg.norm(u), 1e-12)
        return disk(tgt, p + 0.95 * r * u, r, 255)
    return tgt


# ---- families: the conditions as the independent check states them, each swept over its levels
def family_conditions(quick=False):
    """(key, label, kind, level, success threshold %, seed index); --quick: the check's points."""
    lv = [('clean', 0)] + [('noise', a) for a in (0.5, 1, 1.5, 2)] + \
         [(k, r) for k in ('bite', 'touching') for r in (0.1, 0.2, 0.3, 0.4)] + \
         [(k, px) for k in ('lowres', 'grey') for px in (30, 40, 60, 80)]
    fmt = {'clean': 'clean', 'noise': 'noise %g %% R', 'bite': 'bite %g R', 'touching': 'touching %g R',
           'lowres': 'binary %g px', 'grey': 'grey %g px'}
    quick_points = (('clean', 0), ('noise', 1.5), ('bite', 0.3), ('touching', 0.3), ('lowres', 40), ('grey', 40))
    return [('%s%g' % (k, v) if v else k, fmt[k] % v if v else k, k, v, 4.0 if k in ('lowres', 'grey') else 2.0,
             100 + i) for i, (k, v) in enumerate(lv) if not quick or (k, v) in quick_points]


def largest_piece(img):
    n, lab, stats, _ = cv2.connectedComponentsWithStats((img > 0).astype(np.uint8), connectivity=8)
    if n <= 2:
        return img
    return np.where(lab == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA])), img, 0).astype(np.uint8)


def family_target(src, f, kind, level, rng):
    """(target, T) as the check builds them: the warped source thresholded at half level, then
    noise: a smooth Gaussian field (correlation 2 % of R, amplitude `level` % of R) added to the
    signed distance, and specks on 0.05 % of the pixels; bite: a disk of `level` R removed at a
    random boundary point, the largest piece kept; touching: a disk of `level` R centred 0.8 x
    its radius outside a random boundary point (along the ray from the centroid) added;
    lowres / grey: the target alone reduced (area) so the shape spans `level` px, binary or grey.
    R: the RMS radius of the true target contour."""
    tgt, T = make_target(src, f, rng)
    g = apply(T, f)
    R = shape_size(g)
    if kind == 'noise':
        sd = (cv2.distanceTransform((tgt > 0).astype(np.uint8), cv2.DIST_L2, 5) -
              cv2.distanceTransform((tgt == 0).astype(np.uint8), cv2.DIST_L2, 5))
        field = cv2.GaussianBlur(rng.normal(0, 1, tgt.shape), (0, 0), 0.02 * R)
        out = np.where(sd + field * (level / 100 * R / max(field.std(), 1e-12)) > 0, 255, 0).astype(np.uint8)
        out.flat[rng.choice(out.size, int(round(0.0005 * out.size)), replace=False)] = 255
        return out, T
    if kind in ('bite', 'touching'):
        p = g[rng.integers(len(g))]
        if kind == 'bite':
            return largest_piece(disk(tgt, p, level * R, 0)), T
        u = (p - g.mean(axis=0)) / max(np.linalg.norm(p - g.mean(axis=0)), 1e-12)
        return disk(tgt, p + 0.8 * level * R * u, level * R, 255), T
    if kind in ('lowres', 'grey'):
        side = int(round(CANVAS * level / SPAN))
        return reduce(tgt, kind == 'lowres', side), compose(low_map(side), T)
    return tgt, T


def low_map(side):
    """Pixel centres of the CANVAS image -> those of its area reduction to side x side."""
    r = CANVAS / side
    return np.array([[1.0 / r, 0, (1.0 / r - 1) / 2], [0, 1.0 / r, (1.0 / r - 1) / 2]])


def set_low_px(px):
    """The lowres / grey shapes `px` across (35: the 4x reduction): the reduced canvas and S_LOW (low-res
    pixel x = (x - 1.5) / 4 for a 4x area reduction)."""
    global LOW_SIDE, S_LOW
    LOW_SIDE = int(round(CANVAS * px / SPAN))
    S_LOW = low_map(LOW_SIDE)


def reduce(img, binary, side=None):
    small = cv2.resize(img, (side or LOW_SIDE,) * 2, interpolation=cv2.INTER_AREA)
    return np.where(small > 127, 255, 0).astype(np.uint8) if binary else small


def errors(M, T, f):
    """The RMS (the primary measure) and the largest of |M f_i - T f_i| over the contour, % of the
    size; inf when the registration failed."""
    if M is None:
        return math.inf, math.inf
    d = np.sqrt(((apply(M, f) - apply(T, f)) ** 2).sum(axis=1)) / shape_size(apply(T, f))
    return 100 * float(np.sqrt((d * d).mean())), 100 * float(d.max())


CLOCK = time.perf_counter  # --cpu-time: time.process_time


def lib_register_ms(src, tgt, breakdown=None):
    """Wall time (ms) of the library alone on the pair: both traces and the registration.
    breakdown: a list that receives the ms of (the two traces, the registration, the
    registration without the pixel_grid stage, without the polish, without the polish and the
    refinement)."""
    try:
        import amscr
    except ImportError:
        return math.nan
    t0 = CLOCK()
    ps, pt = amscr.contour_from_mask(src, join=True), amscr.contour_from_mask(tgt, join=True)  # as the tool
    if SWAP:
        ps, pt = pt, ps
    t1 = CLOCK()
    amscr.register(ps, pt)
    t2 = CLOCK()
    if breakdown is not None:
        times = [t1 - t0, t2 - t1]
        for opts in ({'stages': {'pixel_grid': False}}, {'polish': False}, {'polish': False, 'refine': 0}):
            t3 = CLOCK()
            amscr.register(ps, pt, **opts)
            times.append(CLOCK() - t3)
        breakdown.extend(1000 * t for t in times)
    return 1000 * (t2 - t0)


EVIDENCE = ('ambiguity', 'symmetry_ambiguity', 'inlier_fraction', 'overlap', 'backward_error', 'standard_error')


SWAP = False  # --swap: the target registered onto the source, the map inverted


def tool_register(tool, sp, tp, extra):
    """(map source -> target or None, confidence, wall ms, evidence); --swap: tp onto sp, inverted."""
    t0 = time.perf_counter()
    r = subprocess.run([tool, 'register'] + ([tp, sp] if SWAP else [sp, tp]) + ['--json'] + extra,
                       capture_output=True, text=True)
    ms = 1000 * (time.perf_counter() - t0)
    if r.returncode != 0:
        return None, 0.0, ms, None
    j = json.loads(r.stdout)
    M = np.hstack([np.array(j['A'], float), np.array(j['B'], float)[:, None]])
    if SWAP:
        M = inv_affine(M) if abs(np.linalg.det(M[:, :2])) > 1e-12 else None
    evidence = {k: j.get(k) for k in EVIDENCE}
    evidence['pixel_grid'] = j.get('stages', {}).get('pixel_grid')
    return M, float(j.get('confidence', 0.0)), ms, evidence


def ecc_register(a8, b8):
    """W with b(W x) ~ a(x): source pixels -> target pixels; None when every start fails."""
    a, b = (cv2.GaussianBlur(x.astype(np.float32) / 255, (0, 0), 0.01 * max(a8.shape)) for x in (a8, b8))
    return registration_heldout.ecc_multistart(a, b, cv2)


def load_classes(data):
    rows = [l.rstrip('\n').split('\t') for l in open(os.path.join(data, 'manifest.tsv'))][1:]
    first = {}
    for fname, cls in rows:
        first.setdefault(cls, fname)
    folds = {}
    fp = os.path.join(data, 'folds.tsv')
    if os.path.exists(fp):
        for line in list(open(fp))[1:]:
            c, fo = line.rstrip('\n').split('\t')
            folds[c] = fo
    return [(c, os.path.join(data, f), folds.get(c, '?')) for c, f in first.items()]


METHODS = [('sub', 'amscr sub-pixel'), ('chain', 'amscr --pixel-chain'), ('ref', 'skimage lists (reference)'),
           ('ecc', 'OpenCV ECC')]
EXTRA = [('lib', 'library alone')]  # timing only


def run_pair(tool, tmp, key, src, tgt, f, T, use_ecc, use_chain=True, breakdown=None, use_ref=False, lib=True):
    """{method: (rms error %, max error %, confidence, ms)}."""
    if key in ('lowres', 'grey'):
        src, tgt = reduce(src, key == 'lowres'), reduce(tgt, key == 'lowres')
        T = compose(S_LOW, compose(T, inv_affine(S_LOW)))
        f = apply(S_LOW, f)
    sp, tp = os.path.join(tmp, 'src.png'), os.path.join(tmp, 'tgt.png')
    cv2.imwrite(sp, src), cv2.imwrite(tp, tgt)
    out = {}
    for m, extra in [('sub', [])] + ([('chain', ['--pixel-chain'])] if use_chain else []):
        M, conf, ms, ev = tool_register(tool, sp, tp, extra)
        out[m] = (*errors(M, T, f), conf, ms, ev)
    if use_ref:  # the calibration: both images traced by find_contours, to the tool as point lists
        np.savetxt(sp + '.txt', subpixel_contour(src)), np.savetxt(tp + '.txt', subpixel_contour(tgt))
        M, conf, ms, ev = tool_register(tool, sp + '.txt', tp + '.txt', [])
        out['ref'] = (*errors(M, T, f), conf, ms, ev)
    out['lib'] = (0.0, 0.0, 0.0, lib_register_ms(src, tgt, breakdown) if lib else math.nan)
    if use_ecc:
        t0 = time.perf_counter()
        W = ecc_register(src, tgt)
        out['ecc'] = (*errors(W, T, f), math.nan, 1000 * (time.perf_counter() - t0))
    return out


def summary(recs, thr, measure=0):
    """(ok %, wrong + confident %, median error %, mean ms, pairs, successes with confidence
    >= CONFIDENT %) under the measure (0: RMS, 1: max)."""
    if not recs:
        return None
    err, conf = np.array([r[measure] for r in recs]), np.array([r[2] for r in recs])
    ok = err < thr
    wrong_conf = (~ok) & (conf >= CONFIDENT)
    good_conf = 100 * float(np.mean(conf[ok] >= CONFIDENT)) if ok.any() else math.nan
    return (100 * ok.mean(), 100 * wrong_conf.mean(), float(np.median(err)), float(np.mean([r[3] for r in recs])),
            len(recs), good_conf)


def print_table(title, res, conds, methods, measure=0):
    print('\n%s' % title)
    print('%-44s' % 'condition' + ''.join(' | %-38s' % lab for _, lab in methods))
    print('%-44s' % '' + ''.join(' | %-38s' % 'ok %   w+c %  ok+c %  med err %  ms' for _ in methods))
    for key, lab, thr in conds:
        line = '%-44s' % ('%s (%d pairs)' % (lab, len(res[key]['sub'])))
        for m, _ in methods:
            s = summary(res[key][m], thr, measure)
            if m == 'ecc':
                line += ' | %5.1f      -       -  %9.3f %5.0f' % (s[0], s[2], s[3])
            else:
                line += ' | %5.1f  %5.1f   %5.1f  %9.3f %5.0f' % (s[0], s[1], s[5], s[2], s[3])
        lib = [r[3] for r in res[key]['lib']]
        if lib and np.all(np.isfinite(lib)):
            line += ' | lib ms median %.1f' % float(np.median(lib))
        print(line)


def family_table(res, conds, methods):
    """One table a method: success and wrong + confident (RMS measure) per condition level, the
    sets side by side; returns {method: {set: {key: [ok %, w+c %, pairs]}}}."""
    sets = [(k, l) for k, l in (('A', 'fold A'), ('B', 'fold B'), ('P', 'procedural')) if res[k][conds[0][0]]['sub']]
    out = {}
    for m, lab in methods:
        print('\n%s: ok %% / wrong + confident %% (RMS error < 2 %% of R, 4 %% at low resolution)' % lab)
        print('%-20s' % 'condition' + ''.join(' | %-19s' % ('%s (%d)' % (sl, len(res[k][conds[0][0]][m])))
                                             for k, sl in sets))
        for c in conds:
            line = '%-20s' % c[1]
            for k, _ in sets:
                sm = summary(res[k][c[0]][m], c[4])
                out.setdefault(m, {}).setdefault(k, {})[c[0]] = [sm[0], sm[1], sm[4]]
                line += ' | %6.1f / %5.1f     ' % (sm[0], sm[1]) if m != 'ecc' else ' | %6.1f / -         ' % sm[0]
            print(line)
    return out


def main():
    global CLOCK, SPAN, CANVAS, SWAP
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=os.path.join(os.environ.get('AMSCR_DATASETS') or
                                                   os.path.join(ROOT, '..', 'shared', 'datasets'), 'mpeg7-dev'))
    ap.add_argument('--tool', default=os.environ.get('AMSCR_TOOL') or os.path.join(ROOT, 'build', 'tools', 'amscr'))
    ap.add_argument('--draws', type=int, default=2)
    ap.add_argument('--no-ecc', action='store_true')
    ap.add_argument('--no-chain', action='store_true', help='skip the --pixel-chain column')
    ap.add_argument('--conditions', '--only', dest='only', default='',
                    help='comma-separated condition keys: ' + ','.join(c[0] for c in CONDITIONS))
    ap.add_argument('--fold', default='', choices=['', 'A', 'B', 'P'], help='one fold (P: procedural) only')
    ap.add_argument('--families', action='store_true', help="the check's conditions swept (see above)")
    ap.add_argument('--quick', action='store_true', help='--families at the check\'s points only')
    ap.add_argument('--procedural', type=int, default=None, help='N procedural shapes (35 with --families, else 0)')
    ap.add_argument('--breakdown', action='store_true',
                    help="lib ms split: traces, register, no pixel_grid, no polish, no refine")
    ap.add_argument('--cpu-time', action='store_true', help="lib ms as CPU time (with OPENBLAS_NUM_THREADS=1)")
    ap.add_argument('--reference', action='store_true', help="add the calibration: find_contours lists to the tool")
    ap.add_argument('--classes', type=int, default=0, help='the first N classes only (0: all)')
    ap.add_argument('--low-px', type=float, default=SPAN / REDUCE, help='lowres / grey: the shape N px across')
    ap.add_argument('--swap', action='store_true', help='the damaged image registered onto the clean one')
    ap.add_argument('--json', default=None)
    a = ap.parse_args()
    SWAP = a.swap
    if a.cpu_time:
        CLOCK = time.process_time
    set_low_px(a.low_px)  # before --families' frame: 35 px (the default) is the 4x reduction of the 200-px canvas
    a.families = a.families or a.quick
    if a.families:
        SPAN, CANVAS = 200.0, 280
    nproc = a.procedural if a.procedural is not None else (35 if a.families else 0)
    classes = load_classes(a.data) if os.path.isdir(a.data) else []
    if not classes and nproc:  # said, not silent: the folds' columns would read as empty
        print('registration_traced: no data at %s (set --data or AMSCR_DATASETS): the procedural set only'
              % a.data, file=sys.stderr)
    if not classes and not nproc:
        print('registration_traced: no data at %s (skipped)' % a.data)
        return 0
    class_index = {c[0]: i for i, c in enumerate(classes)}  # the seeds do not depend on --fold
    if a.classes:
        classes = classes[:a.classes]
    for i in range(nproc):
        class_index['proc%02d' % i] = 1000 + i
        classes.append(('proc%02d' % i, shapegen.silhouette(1, i), 'P'))
    if a.fold:
        classes = [c for c in classes if c[2] == a.fold]
    use_ecc = not a.no_ecc and not a.swap  # ECC aligns images: one direction
    use_chain = not a.no_chain
    allconds = (family_conditions(a.quick) if a.families else
                [(k, lab, k, None, t, i) for i, (k, lab, t) in enumerate(CONDITIONS)])
    conds = [c for c in allconds if not a.only or c[0] in a.only.split(',')]
    res = {fold: {c[0]: {m: [] for m, _ in METHODS + EXTRA} for c in conds} for fold in ('A', 'B', 'P', 'all')}
    rows = []
    split = {}  # condition -> [ms of the traces, register, no polish, no polish + no refine]
    with tempfile.TemporaryDirectory() as tmp:
        for ci, (cls, path, fold) in enumerate(classes):
            src = load_source(path)
            f = subpixel_contour(src)
            for key, _, kind, level, _, seed in conds:
                for d in range(a.draws):
                    rng = np.random.default_rng([class_index[cls], seed, d, 2024])
                    if a.families:
                        tgt, T = family_target(src, f, kind, level, rng)
                    else:
                        tgt, T = make_target(src, f, rng)
                        tgt = damage(key, tgt, apply(T, f), rng)
                    bd = [] if a.breakdown else None
                    out = run_pair(a.tool, tmp, key, src, tgt, f, T, use_ecc, use_chain, bd, a.reference,
                                   lib=not a.families)
                    if bd:
                        split.setdefault(key, []).append(bd)
                    rows.append({'class': cls, 'fold': fold, 'condition': key, 'draw': d,
                                 **{m: list(v) for m, v in out.items()}})
                    for m, v in out.items():
                        res['all'][key][m].append(v)
                        if fold in res:
                            res[fold][key][m].append(v)
            print('.', end='', file=sys.stderr, flush=True)
    print(file=sys.stderr)
    methods = [m for m in METHODS if (use_ecc or m[0] != 'ecc') and (use_chain or m[0] != 'chain')
               and (a.reference or m[0] != 'ref')]
    if a.families:
        table = family_table(res, conds, methods)
        if a.json:
            with open(a.json, 'w') as fp:
                json.dump({'draws': a.draws, 'table': table, 'pairs': rows}, fp)
        return 0
    conds = [(c[0], c[1], c[4]) for c in conds]
    keys = [c[0] for c in conds]
    for measure, what in ((0, 'RMS error (as the reference evaluation measures)'), (1, 'max error (stricter; the figures before 0.5)')):
        print('\n=== %s: success < 2 %% of the size (4 %% at low resolution) ===' % what)
        for fold, title in (('A', 'fold 1 (folds.tsv A)'), ('B', 'fold 2 (folds.tsv B)'), ('P', 'procedural'),
                            ('all', 'all shapes')):
            if any(res[fold][k]['sub'] for k in keys):
                print_table('%s, %s' % (title, what.split(' (')[0]), res[fold], conds, methods, measure)
    if split:
        print('\nlibrary ms, medians over the run: traces | register | no pixel_grid | no polish | no polish, '
              'no refine')
        for key in keys:
            if key in split:
                print('%-10s' % key + ' | '.join('%7.2f' % v for v in np.median(np.array(split[key]), axis=0)))
    if a.json:
        with open(a.json, 'w') as fp:
            json.dump(rows, fp)
    return 0


if __name__ == '__main__':
    sys.exit(main())
