#!/usr/bin/env python3
"""Probe (not kept): a block-jackknife standard error of the final map, computed in NumPy from
a registration's dense correspondences, and the confidence it would give, on the families of
bench/registration_traced.py. Rows: `probe_standard_error.py CONDS PART NPARTS OUT.jsonl`
(conditions comma-separated, one of NPARTS shape shares); table: `probe_standard_error.py
--analyse A.jsonl,B.jsonl` (w+c pairs and good maps confident per variant)."""

import json, math, os, sys
import numpy as np
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(1, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'bindings', 'python', 'tests'))
import registration_traced as rt
import shapegen, amscr
from registration_heldout import apply, compose, inv_affine, shape_size

rt.SPAN, rt.CANVAS = 200.0, 280

def tangent_at(pt_contour, par):
    n = len(pt_contour)
    u = (par % 1.0) * n
    i = np.floor(u).astype(int) % n
    a, b = pt_contour[(i - 1) % n], pt_contour[(i + 2) % n]
    t = b - a
    return t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-12)

def jackknife(src, tgtp, tan, M, R, blocks, inl):
    m = apply(M, src)
    res = m - tgtp
    nrm = np.column_stack([-tan[:, 1], tan[:, 0]])
    r = (res * nrm).sum(1)
    J = np.column_stack([nrm[:, 0] * src[:, 0], nrm[:, 0] * src[:, 1], nrm[:, 0],
                         nrm[:, 1] * src[:, 0], nrm[:, 1] * src[:, 1], nrm[:, 1]])
    n = len(src)
    idx = np.arange(n)
    keep = inl
    disp = []
    for b in range(blocks):
        sel = keep & ~((idx * blocks // n) == b)
        if sel.sum() < 12:
            continue
        d, *_ = np.linalg.lstsq(J[sel], -r[sel], rcond=None)
        D = np.array([[d[0], d[1], d[2]], [d[3], d[4], d[5]]])
        disp.append(src @ D[:, :2].T + D[:, 2])
    if len(disp) < 3:
        return math.nan, math.nan
    disp = np.array(disp)  # (B, n, 2)
    mean = disp.mean(0)
    B = len(disp)
    var = (B - 1) / B * ((disp - mean) ** 2).sum(-1).sum(0)  # per sample
    se = math.sqrt(var.mean()) / R
    worst = math.sqrt(((disp - mean) ** 2).sum(-1).mean(1).max()) / R
    return se, worst

def main():
    conds = sys.argv[1].split(',')
    part, nparts = int(sys.argv[2]), int(sys.argv[3])
    out = open(sys.argv[4], 'w')
    draws = 8
    classes = rt.load_classes(os.path.join(os.environ.get('AMSCR_DATASETS', os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'shared', 'datasets')), 'mpeg7-dev'))
    class_index = {c[0]: i for i, c in enumerate(classes)}
    for i in range(35):
        class_index['proc%02d' % i] = 1000 + i
        classes.append(('proc%02d' % i, shapegen.silhouette(1, i), 'P'))
    allc = {c[0]: c for c in rt.family_conditions()}
    for ci, (cls, path, fold) in enumerate(classes):
        if ci % nparts != part:
            continue
        src = rt.load_source(path)
        f = rt.subpixel_contour(src)
        for key in conds:
            _, _, kind, level, thr, seed = allc[key]
            for d in range(draws):
                rng = np.random.default_rng([class_index[cls], seed, d, 2024])
                tgt, T = rt.family_target(src, f, kind, level, rng)
                ps = amscr.contour_from_mask(src, join=True)
                pt = amscr.contour_from_mask(tgt, join=True)
                try:
                    reg = amscr.register(ps, pt)
                except Exception as e:
                    out.write(json.dumps({'cls': cls, 'fold': fold, 'cond': key, 'draw': d, 'fail': str(e)}) + '\n')
                    continue
                M = reg.matrix[:2]
                rms, mx = rt.errors(M, T, f)
                R = shape_size(pt)
                s, tp = reg.source_samples, reg.target_points
                tan = tangent_at(pt, reg.correspondences)
                dist = np.linalg.norm(apply(M, s) - tp, axis=1)
                row = {'cls': cls, 'fold': fold, 'cond': key, 'draw': d, 'rms': rms, 'thr': thr,
                       'conf': reg.confidence, 'inl': reg.inlier_fraction, 'ov': reg.overlap,
                       'fb': reg.backward_error, 'amb': reg.ambiguity, 'sym': reg.symmetry_ambiguity,
                       'npt': len(pt), 'nsamp': len(s), 'resid_rms': float(np.sqrt((dist ** 2).mean()) / R)}
                med = np.median(dist)
                for blocks in (8, 16):
                    for tag, inl in (('all', np.ones(len(s), bool)), ('in', dist < 0.05 * R),
                                     ('tr', (dist < 0.05 * R) & (dist <= 5 * med)),
                                     ('tr3', (dist < 0.05 * R) & (dist <= 3 * med))):
                        se, worst = jackknife(s, tp, tan, M, R, blocks, inl)
                        row['jk%d_%s' % (blocks, tag)] = se
                        row['jkw%d_%s' % (blocks, tag)] = worst
                out.write(json.dumps(row) + '\n')
        out.flush()
        print('.', end='', file=sys.stderr, flush=True)



def analyse(files):
    import collections
    rows = [json.loads(l) for f in files.split(',') for l in open(f)]
    rows = [r for r in rows if 'rms' in r]
    def run(stat, k, p=2):
        c = collections.defaultdict(lambda: [0, 0, 0, 0])
        for r in rows:
            v = r.get(stat, math.nan)
            conf2 = r['conf'] / (1 + (v / k) ** p) if (stat and not math.isnan(v)) else r['conf']
            ok = r['rms'] < r['thr']
            x = c[(r['cond'], r['fold'])]
            x[0] += 1; x[1] += ok; x[2] += (not ok) and conf2 >= 0.25; x[3] += ok and conf2 >= 0.25
        tot = [sum(x[i] for x in c.values()) for i in range(4)]
        over = sorted(((round(100 * x[2] / x[0], 1), key) for key, x in c.items() if x[2] / x[0] > 0.01), reverse=True)
        return tot[2], 100 * tot[3] / tot[1], over
    print('none: w+c %d ok+c %.2f over %s' % run(None, 1))
    stats = sorted(k for k in rows[0] if k.startswith('jk'))
    for stat in stats:
        for k in (0.01, 0.0125, 0.015, 0.02):
            for p in (2, 4):
                print('%-9s k %.4f p %d: w+c %2d ok+c %.2f over %s' % ((stat, k, p) + run(stat, k, p)))


if __name__ == '__main__':
    if sys.argv[1] == '--analyse':
        analyse(sys.argv[2])
    else:
        main()
