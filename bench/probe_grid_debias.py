#!/usr/bin/env python3
"""Probe (not kept). Usage: probe_grid_debias.py LEVELS FOLDS DRAWS ITERS OUT.json (e.g. 30,40,60 A,B 2 1).
Prototype: de-biasing a binary low-resolution target by simulation (render the mapped source
on the target's pixel grid as the camera would, trace it, and subtract the tracing's bias)."""
import sys, os, math, json
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, cv2
import registration_traced as rt
import shapegen, amscr
from registration_heldout import apply, compose
rt.SPAN, rt.CANVAS = 200.0, 280
SS = 8

def render(M_pts, shape):
    h, w = shape
    big = np.zeros((h * SS, w * SS), np.uint8)
    pts = np.round(((M_pts + 0.5) * SS - 0.5) * 16).astype(np.int32)
    cv2.fillPoly(big, [pts], 255, lineType=cv2.LINE_8, shift=4)
    small = cv2.resize(big, (w, h), interpolation=cv2.INTER_AREA)
    return np.where(small > 127, 255, 0).astype(np.uint8)

def nearest_on_polyline(P, Q):
    """For each P point, the closest point on closed polyline Q."""
    A = Q; B = np.roll(Q, -1, axis=0); D = B - A
    L2 = np.maximum((D ** 2).sum(1), 1e-18)
    best = np.empty_like(P); bd = np.full(len(P), np.inf)
    for s in range(0, len(A), 256):
        a, d, l2 = A[s:s+256], D[s:s+256], L2[s:s+256]
        t = np.clip(((P[:, None, :] - a[None]) * d[None]).sum(2) / l2[None], 0, 1)
        c = a[None] + t[..., None] * d[None]
        dist = ((P[:, None, :] - c) ** 2).sum(2)
        j = dist.argmin(1); dj = dist[np.arange(len(P)), j]
        upd = dj < bd; bd[upd] = dj[upd]; best[upd] = c[np.arange(len(P)), j][upd]
    return best

def matrix(r):
    return np.hstack([np.asarray(r.A, float), np.asarray(r.B, float)[:, None]])

def chamfer(P, Q):
    a = np.sqrt(((P - nearest_on_polyline(P, Q)) ** 2).sum(1))
    b = np.sqrt(((Q - nearest_on_polyline(Q, P)) ** 2).sum(1))
    d = np.sort(np.concatenate([a, b]))
    return [float(np.sqrt((d ** 2).mean())), float(np.median(d)), float(np.sqrt((d[:int(0.9 * len(d))] ** 2).mean()))]

def synth_score(ps, pt, tgt_img, X):
    syn = render(apply(X, ps), tgt_img.shape)
    xor = int(((syn > 0) != (tgt_img > 0)).sum())
    try:
        C = np.asarray(amscr.contour_from_mask(syn, join=True), float)
    except Exception:
        return [math.inf] * 3 + [xor]
    return chamfer(C, pt) + [xor]

def debias(ps, pt, tgt_img, X, iters):
    out = []
    for _ in range(iters):
        M = apply(X, ps)
        syn = render(M, tgt_img.shape)
        try:
            C = np.asarray(amscr.contour_from_mask(syn, join=True), float)
        except Exception:
            break
        b = C - nearest_on_polyline(C, M)          # the tracing's bias at each synthetic point
        # each target point takes the bias of its nearest synthetic point
        d2 = ((pt[:, None, :] - C[None]) ** 2).sum(2)
        tb = b[d2.argmin(1)]
        r = amscr.register(ps, pt - tb)
        X = matrix(r)
        out.append((X, r.confidence, synth_score(ps, pt, tgt_img, X)))
    return out

def main():
    levels = [int(x) for x in sys.argv[1].split(',')]
    folds = sys.argv[2].split(',')
    draws = int(sys.argv[3]); iters = int(sys.argv[4])
    data = rt.H.default_data() if hasattr(rt, 'H') else __import__('registration_heldout').default_data()
    classes = rt.load_classes(data)
    idx = {c[0]: i for i, c in enumerate(classes)}
    for i in range(35):
        idx['proc%02d' % i] = 1000 + i
        classes.append(('proc%02d' % i, shapegen.silhouette(1, i), 'P'))
    conds = {c[3]: c for c in rt.family_conditions() if c[2] == 'lowres'}
    rows = []
    for cls, path, fold in classes:
        if fold not in folds:
            continue
        src = rt.load_source(path); f = rt.subpixel_contour(src)
        ps = np.asarray(amscr.contour_from_mask(src, join=True), float)
        for lv in levels:
            key, _, kind, level, thr, seed = conds[lv]
            for d in range(draws):
                rng = np.random.default_rng([idx[cls], seed, d, 2024])
                tgt, T = rt.family_target(src, f, kind, level, rng)
                pt = np.asarray(amscr.contour_from_mask(tgt, join=True), float)
                r0 = amscr.register(ps, pt)
                X0 = matrix(r0)
                e0 = rt.errors(X0, T, f)[0]
                res = debias(ps, pt, tgt, X0, iters)
                s0 = synth_score(ps, pt, tgt, X0)
                es = [rt.errors(X, T, f)[0] for X, _, _ in res]
                rows.append(dict(cls=cls, fold=fold, level=lv, draw=d, e0=e0, c0=r0.confidence, es=es, cs=[c for _, c, _ in res], s0=s0, ss=[q for _, _, q in res]))
        print('.', end='', file=sys.stderr, flush=True)
    json.dump(rows, open(sys.argv[5], 'w'))
    for lv in levels:
        for fo in folds:
            rs = [r for r in rows if r['level'] == lv and r['fold'] == fo]
            if not rs: continue
            line = '%3d px %s n=%d ok0 %.1f' % (lv, fo, len(rs), 100 * np.mean([r['e0'] < 4 for r in rs]))
            for k in range(iters):
                line += ' | it%d ok %.1f' % (k + 1, 100 * np.mean([(r['es'][k] if len(r['es']) > k else r['e0']) < 4 for r in rs]))
            line += ' | med e0 %.2f e1 %.2f' % (np.median([r['e0'] for r in rs]), np.median([r['es'][0] if r['es'] else r['e0'] for r in rs]))
            print(line)

def analyse(paths):
    """Success (< 4 % of R) as traced, and with the de-biased map kept where the selector (0 the
    chamfer's RMS, 2 its best 90 %, 3 the pixels where the rendering and the target differ) is lower."""
    rows = [r for p in paths.split(',') for r in json.load(open(p))]
    for k, name in ((0, 'chamfer rms'), (2, 'chamfer 90 %'), (3, 'pixels differing')):
        out = []
        for lv in sorted({r['level'] for r in rows}):
            for fo in 'ABP':
                rs = [r for r in rows if r['level'] == lv and r['fold'] == fo]
                if not rs:
                    continue
                e0 = np.array([r['e0'] for r in rs])
                ep = np.array([r['es'][0] if r['es'] and r['ss'][0][k] < r['s0'][k] else r['e0'] for r in rs])
                out.append('%d %s %.1f > %.1f' % (lv, fo, 100 * (e0 < 4).mean(), 100 * (ep < 4).mean()))
        print('%-17s %s' % (name, ' | '.join(out)))


if sys.argv[1] == '--analyse':
    analyse(sys.argv[2])
else:
    main()
