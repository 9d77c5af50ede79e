#!/usr/bin/env python3
"""Probes of two retrieval directions beside the shape channel (docs/results-retrieval.md, "The
inner-distance graph (0.7)"): a convex-hull channel and the inner distance, each fused into the
retrieval distance and as a second kNN graph of the re-ranking.

The channel matrix of every set is the tool's (`amscr matrix MANIFEST --no-rerank --inner-share
0`: the retrieval preset's fused channel before re-ranking); the probes are computed here in
NumPy from the contours the library traces (amscr.contour_from_mask):

  hull    the convex hull's support function at 64 directions, in the whitened (affine) or the
          similarity frame of the hull's own moments, compared over rotations and mirror images
          (FFT correlation);
  inner   the inner distance (shortest paths inside the 64-gon resampled along the contour,
          divided by their mean) in offset form, compared over cyclic shifts and both
          orientations (the full spectrum: the library's version compares a low-passed one).

Fusion: "dist w" = channel / median + w * probe / median, re-ranked by amscr.rerank_diffusion
(k 8, 10 iterations); "graph w" = the re-ranking's diffusion on (P + w P2) / (1 + w), P and P2
the two distances' kNN graphs built as the library builds them (a NumPy copy of rerank.c).
Sets: mpeg7-dev (bull's eye), its class folds A and B as own collections, Kimia-99 / Kimia-216
(top-k sums), an MCD-style set (the first contour of each mpeg7-dev class x 14 random affine
copies, 0.5 % noise; seeded).

Usage: .venv/bin/python bench/retrieval_probes.py [--data ../shared/datasets] [--tool build/tools/amscr]
       [--probes hull,inner]                                           # ~5 min on 2 cores
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

import amscr
import cv2

M = 64  # directions of the hull's support function; vertices of the inner-distance polygon


def names(path):
    rows = [line.rstrip('\n').split('\t') for line in open(path)][1:]
    return [r[0] for r in rows], [r[1] for r in rows]


def contour(path):
    return amscr.contour_from_mask(cv2.imread(path, cv2.IMREAD_GRAYSCALE))


def hull(P):
    P = np.unique(np.round(np.asarray(P, float), 9), axis=0)
    P = P[np.lexsort((P[:, 1], P[:, 0]))]

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def half(Q):
        h = []
        for p in Q:
            while len(h) >= 2 and turn(h[-2], h[-1], p) <= 0:
                h.pop()
            h.append(p)
        return h
    lo, up = half(P), half(P[::-1])
    return np.array(lo[:-1] + up[:-1])


def polygon_moments(H):
    x, y = H[:, 0], H[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    c = x * y1 - x1 * y
    a = c.sum() / 2
    cx, cy = ((x + x1) * c).sum() / (6 * a), ((y + y1) * c).sum() / (6 * a)
    xx = ((x * x + x * x1 + x1 * x1) * c).sum() / (12 * a) - cx * cx
    yy = ((y * y + y * y1 + y1 * y1) * c).sum() / (12 * a) - cy * cy
    xy = ((x * y1 + 2 * x * y + 2 * x1 * y1 + x1 * y) * c).sum() / (24 * a) - cx * cy
    return np.array([cx, cy]), np.array([[xx, xy], [xy, yy]])


def hull_feature(P, frame):
    H = hull(P)
    c, C = polygon_moments(H)
    X = H - c
    if frame == 'affine':
        w, V = np.linalg.eigh(C)
        X = X @ (V @ np.diag(w ** -0.5) @ V.T).T
    else:
        X = X / np.sqrt(np.trace(C) / 2)
    th = 2 * np.pi * np.arange(M) / M
    return (X @ np.stack([np.cos(th), np.sin(th)], 0)).max(0)


def hull_matrix(F):
    F = np.asarray(F)
    A, R = np.fft.rfft(F, axis=1), np.fft.rfft(F[:, (-np.arange(M)) % M], axis=1)
    nrm, n = (F ** 2).sum(1), len(F)
    D = np.empty((n, n))
    for i in range(n):
        c = np.maximum(np.fft.irfft(A[i][None] * np.conj(A), n=M, axis=1).max(1),
                       np.fft.irfft(A[i][None] * np.conj(R), n=M, axis=1).max(1))
        D[i] = np.sqrt(np.maximum(nrm[i] + nrm - 2 * c, 0) / M)
    return D


def resample(P, n):
    Q = np.vstack([P, P[:1]])
    s = np.concatenate([[0], np.cumsum(np.sqrt(((Q[1:] - Q[:-1]) ** 2).sum(1)))])
    t = np.linspace(0, s[-1], n, endpoint=False)
    return np.column_stack([np.interp(t, s, Q[:, 0]), np.interp(t, s, Q[:, 1])])


def inside(pts, V):
    x, y = pts[:, :1], pts[:, 1:]
    x1, y1, x2, y2 = V[:, 0][None], V[:, 1][None], np.roll(V[:, 0], -1)[None], np.roll(V[:, 1], -1)[None]
    return (((y1 > y) != (y2 > y)) & (x < (x2 - x1) * (y - y1) / (y2 - y1 + 1e-300) + x1)).sum(1) % 2 == 1


def inner_feature(P):
    V = resample(np.asarray(P, float), M)
    A, B = V[:, None, None, :], V[None, :, None, :]
    E1, E2 = V[None, None, :, :], np.roll(V, -1, 0)[None, None, :, :]

    def cr(o, a, b):
        return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (a[..., 1] - o[..., 1]) * (b[..., 0] - o[..., 0])
    proper = (cr(A, B, E1) * cr(A, B, E2) < 0) & (cr(E1, E2, A) * cr(E1, E2, B) < 0)
    i = np.arange(M)
    inc = ((i[None, None] == i[:, None, None]) | (i[None, None] == i[None, :, None])
           | ((i[None, None] + 1) % M == i[:, None, None]) | ((i[None, None] + 1) % M == i[None, :, None]))
    vis = ~(proper & ~inc).any(2)
    vis &= inside(((V[:, None] + V[None]) / 2).reshape(-1, 2), V).reshape(M, M) | (
        np.abs(i[:, None] - i[None]) % (M - 1) <= 1)
    np.fill_diagonal(vis, True)
    L = np.sqrt(((V[:, None] - V[None]) ** 2).sum(2))
    D = np.where(vis, L, np.inf)
    for k in range(M):
        D = np.minimum(D, D[:, k:k + 1] + D[k:k + 1, :])
    D = np.where(np.isfinite(D), D, L)
    return D / D.mean()


def inner_matrix(IDs):
    def offsets(I):
        return I[i[:, None], (i[:, None] + i[None, :]) % M]
    i = np.arange(M)
    J = np.array([offsets(I) for I in IDs])
    Jr = np.array([offsets(I[::-1, ::-1]) for I in IDs])
    FA, FR = np.fft.rfft(J, axis=1), np.fft.rfft(Jr, axis=1)
    nrm, n = (J ** 2).sum((1, 2)), len(J)
    D = np.empty((n, n))
    for a in range(n):
        c = np.maximum(np.fft.irfft((FA[a][None] * np.conj(FA)).sum(2), n=M, axis=1).max(1),
                       np.fft.irfft((FA[a][None] * np.conj(FR)).sum(2), n=M, axis=1).max(1))
        D[a] = np.sqrt(np.maximum(nrm[a] + nrm - 2 * c, 0) / M ** 2)
    return D


def median(D):
    return np.median(D[~np.eye(len(D), dtype=bool)])


def knn_graph(D, k):
    """The library's kNN graph (rerank.c): itself first, self-tuning affinities, rows summing to 1."""
    n = len(D)
    D = 0.5 * (D + D.T)
    np.fill_diagonal(D, 0)
    order = np.lexsort((np.tile(np.arange(n), (n, 1)), D + np.diag(np.full(n, -1.0))), axis=1)[:, :k]
    s = D[np.arange(n), order[:, -1]]
    tiny = 1e-12 * D.max()
    P = np.zeros((n, n))
    for r in range(n):
        j = order[r]
        w = np.exp(-D[r, j] / np.sqrt((s[r] + tiny) * (s[j] + tiny)))
        P[r, j] = w / w.sum()
    return P


def graph_rerank(D, D2, w, k, iters=10):
    """(P + w P2) / (1 + w) diffused as rerank.c diffuses; 1 - Q / rowmax, unreached after."""
    P = (knn_graph(D, k) + w * knn_graph(D2, k)) / (1 + w)
    Q = P.copy()
    for _ in range(iters):
        Q = P @ Q @ P.T + np.eye(len(P))
    return np.where(Q > 0, 1 - Q / Q.max(1, keepdims=True), 1 + D / D.max())


def score(kind, F, labels):
    if kind == 'topk':
        return float(amscr.topk_table(F, labels, 10 if len(labels) < 150 else 11).sum())
    return 100 * amscr.bullseye(F, labels)


def ranked(D, X, mode, w):
    n = len(D)
    k = min(8, max(1, n // 2))
    if mode == 'graph':
        return graph_rerank(D, X, w, k)
    return amscr.rerank_diffusion(D / median(D) + w * X / median(X), k, 10)


def load_sets(a, tmp):
    sets = {}
    for name in ('mpeg7-dev', 'kimia99', 'kimia216'):
        mf = os.path.join(a.data, name, 'manifest.tsv')
        npy, tsv = os.path.join(tmp, name + '.npy'), os.path.join(tmp, name + '.tsv')
        subprocess.run([a.tool, 'matrix', mf, '--no-rerank', '--inner-share', '0', '-o', npy, '--names', tsv],
                       check=True, capture_output=True)
        files, labels = names(tsv)
        sets[name] = dict(ch=np.load(npy), labels=labels, kind='bullseye' if name == 'mpeg7-dev' else 'topk',
                          cs=[contour(os.path.join(a.data, name, f)) for f in files])
    rng, cs, labels, seen = np.random.default_rng(7), [], [], set()
    for P, lab in zip(sets['mpeg7-dev']['cs'], sets['mpeg7-dev']['labels']):
        if lab in seen:
            continue
        seen.add(lab)
        P = P - P.mean(0)
        for _ in range(14):
            th, h = rng.uniform(0, 2 * np.pi), rng.uniform(-0.5, 0.5)
            s1, s2 = np.exp(rng.uniform(np.log(0.5), np.log(2), 2))
            R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
            Q = P @ (R @ np.diag([s1, s2]) @ np.array([[1, h], [0, 1]])).T
            cs.append(Q + rng.normal(0, 0.005 * np.sqrt((Q ** 2).sum(1).mean()), Q.shape))
            labels.append(lab)
    coll = amscr.Collection(amscr.Params.retrieval())
    for Q in cs:
        coll.add(Q)
    sets['MCD-style'] = dict(ch=coll.channel_matrix(), labels=labels, kind='bullseye', cs=cs)
    return sets


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--tool', default=os.path.join(here, '..', 'build', 'tools', 'amscr'))
    ap.add_argument('--probes', default='hull,inner')
    a = ap.parse_args()
    if not os.path.isdir(os.path.join(a.data, 'mpeg7-dev')):
        print('retrieval_probes: no data at %s (skipped)' % a.data)
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        sets = load_sets(a, tmp)
    folds = dict(line.rstrip('\n').split('\t') for line in list(open(os.path.join(a.data, 'mpeg7-dev', 'folds.tsv')))[1:])
    probes = []
    for p in a.probes.split(','):
        frames = ('affine', 'similarity') if p == 'hull' else ('similarity',)
        for fr in frames:
            key = '%s %s' % (p, fr)
            for s in sets.values():
                F = [hull_feature(P, fr) for P in s['cs']] if p == 'hull' else [inner_feature(P) for P in s['cs']]
                s[key] = hull_matrix(F) if p == 'hull' else inner_matrix(F)
            probes.append(key)
    cols = ['mpeg7-dev', 'fold A', 'fold B', 'kimia99', 'kimia216', 'MCD-style']

    def row(D_of, mode, w):
        out = []
        for c in cols:
            s = sets['mpeg7-dev' if c.startswith('fold') else c]
            idx = np.arange(len(s['labels']))
            if c.startswith('fold'):
                idx = np.array([i for i, lab in enumerate(s['labels']) if folds[lab] == c[-1]])
            D, X = (M_[np.ix_(idx, idx)] for M_ in D_of(s))
            labels = [s['labels'][i] for i in idx]
            out.append(score(s['kind'], D if mode == 'none' else ranked(D, X, mode, w), labels))
        return out
    print('| probe | fusion | weight | ' + ' | '.join(cols) + ' |\n|---|---|---|' + '---|' * len(cols))
    base = row(lambda s: (s['ch'], s['ch']), 'dist', 0.0)
    print('| channel alone, re-ranked | | | ' + ' | '.join('%.2f' % v for v in base) + ' |')
    for key in probes:
        print('| %s alone | none | | ' % key + ' | '.join('%.2f' % v for v in row(lambda s: (s[key], s[key]), 'none', 0)) + ' |')
        for mode, ws in (('dist', (0.05, 0.1, 0.2, 0.5)), ('graph', (0.05, 0.1, 0.25))):
            for w in ws:
                r = row(lambda s: (s['ch'], s[key]), mode, w)
                print('| %s | %s | %.2f | ' % (key, mode, w) + ' | '.join('%.2f' % v for v in r) + ' |', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
