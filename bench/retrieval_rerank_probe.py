#!/usr/bin/env python3
"""The re-ranking's neighbourhood against class size and many views of one object: the kNN
graph of the re-ranking (rerank.c, one graph: the inner-distance share 0) with other
neighbourhoods, computed in NumPy on the retrieval preset's fused channel before re-ranking.

The best k follows the class size (classes of 11 want 6-8, of 40 want 16-20) and, for objects
seen in many views, the number of views. Each variant here tries to serve every size with one
setting:

  k K                  the library's graph at k = K (k 8 = the preset's graph);
  mean of k 8/16/32    the three re-ranked matrices averaged;
  graph of k 8+16      one diffusion on the mean of the two kNN graphs;
  k 32, scale of 8th   32 neighbours weighted exp(-(d/s)^2), s from the 8th (a soft neighbourhood);
  diverse k 8          a neighbour is skipped when one already chosen is nearer to it than
                       0.5 x its distance to the query (k different shapes, not k copies of one);
  k 8 + w x distance   the re-ranked matrix plus w x the distance over its median.

Sets: Kimia-99 / -216 (top-10 / top-11 sums), mpeg7-dev and its class folds (bull's eye; the
channel matrices are the tool's: `amscr matrix M --no-rerank`), mpeg7-dev with a mild affine copy
of every image (classes of 40: any rotation, axis scales 0.75-1.33, shear +-0.25, re-traced), and
objects in views (bench/retrieval_views.py: 35 classes x 4 objects x 10 views, seeds 1-3; 8
classes x 10 objects x 41 views, ETH-80's shape, seeds 1-2; 1-NN with the query's object left out).

Usage: .venv/bin/python bench/retrieval_rerank_probe.py [--data ../shared/datasets]
       [--tool build/tools/amscr] [--quick]      # ~25 min on 2 cores; --quick: no 41-view sets
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
import scipy.sparse as sp

import amscr
import cv2

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import retrieval_views  # noqa: E402


def neighbours(D, k):
    """Each row's k nearest (itself first, ties by index), as rerank.c selects them."""
    order = np.argsort(D + np.diag(np.full(len(D), -1.0)), axis=1, kind='stable')
    return order[:, :k]


def graph(D, idx, scale_rank=None, power=1.0):
    """The kNN graph of rerank.c on the neighbours idx: self-tuning affinities, rows summing to 1."""
    n, k = idx.shape
    d = np.take_along_axis(D, idx, 1)
    sc = d[:, (scale_rank or k) - 1]
    tiny = 1e-12 * D.max()
    w = np.exp(-(d / np.sqrt((sc[:, None] + tiny) * (sc[idx] + tiny))) ** power)
    w /= w.sum(1, keepdims=True)
    return sp.csr_matrix((w.ravel(), idx.ravel(), np.arange(0, n * k + 1, k)), shape=(n, n))


def diffuse(P, D, iters=10):
    """Q = P, then Q <- P Q P^T + I; distances 1 - Q / rowmax halved into [0, 1] (rerank.c)."""
    n = P.shape[0]
    Q = P.toarray()
    for _ in range(iters):
        Q = (P @ (P @ Q).T).T
        Q[np.arange(n), np.arange(n)] += 1.0
    qmax = Q.max(1, keepdims=True)
    out = 0.5 * np.where(Q > 0, 1.0 - Q / qmax, 1.0 + D / D.max())
    np.fill_diagonal(out, 0.0)
    return out


def diverse(D, k, rho):
    n = len(D)
    order = neighbours(D, min(n, 400))
    idx = np.empty((n, k), dtype=np.int64)
    for i in range(n):
        ch = [i]
        for j in order[i, 1:]:
            if len(ch) == k:
                break
            if len(ch) == 1 or not (D[ch[1:], j] < rho * D[i, j]).any():
                ch.append(j)
        ch += [j for j in order[i] if j not in ch][:k - len(ch)]
        idx[i] = ch
    return idx


def variants(F):
    n = len(F)
    D = 0.5 * (F + F.T)
    np.fill_diagonal(D, 0.0)
    kk = {k: diffuse(graph(D, neighbours(D, min(k, n))), D) for k in (4, 8, 16, 32)}
    union = (graph(D, neighbours(D, 8)) + graph(D, neighbours(D, min(16, n)))) / 2
    med = np.median(D[~np.eye(n, dtype=bool)])
    return [F] + [kk[k] for k in (4, 8, 16, 32)] + [
        (kk[8] + kk[16] + kk[32]) / 3,
        diffuse(union.tocsr(), D),
        diffuse(graph(D, neighbours(D, min(32, n)), scale_rank=8, power=2.0), D),
        diffuse(graph(D, diverse(D, 8, 0.5)), D),
        kk[8] + 0.1 * D / med,
        kk[8] + 0.3 * D / med]


COLUMNS = ['before re-ranking', 'k 4', 'k 8', 'k 16', 'k 32', 'mean of k 8/16/32', 'graph of k 8+16',
           'k 32, scale of 8th', 'diverse k 8', 'k 8 + 0.1 x distance', 'k 8 + 0.3 x distance']


def score(kind, R, labels, groups=None):
    if kind == 'top10':
        return float(amscr.topk_table(R, labels, 10).sum())
    if kind == 'top11':
        return float(amscr.topk_table(R, labels, 11).sum())
    if kind == 'nn':
        return 100.0 * amscr.nn_groups(R, labels, groups).accuracy
    return 100.0 * amscr.bullseye(R, labels)


def tool_sets(a, tmp):
    dev = os.path.join(a.data, 'mpeg7-dev')
    rows = [line.rstrip('\n').split('\t') for line in list(open(os.path.join(dev, 'manifest.tsv')))[1:]]
    folds = dict(line.rstrip('\n').split('\t') for line in list(open(os.path.join(dev, 'folds.tsv')))[1:])
    manifests = [('Kimia-99', os.path.join(a.data, 'kimia99', 'manifest.tsv'), 'top10'),
                 ('Kimia-216', os.path.join(a.data, 'kimia216', 'manifest.tsv'), 'top11'),
                 ('mpeg7-dev', os.path.join(dev, 'manifest.tsv'), 'bullseye')]
    for fold in ('A', 'B'):
        path = os.path.join(tmp, 'fold%s.tsv' % fold)
        with open(path, 'w') as f:
            f.write('file\tclass\n')
            f.writelines('%s\t%s\n' % (os.path.join(dev, p), c) for p, c in rows if folds[c] == fold)
        manifests.append(('fold ' + fold, path, 'bullseye'))
    for name, path, kind in manifests:
        out = os.path.join(tmp, 'F.npy')
        subprocess.run([a.tool, 'matrix', path, '--no-rerank', '-o', out], check=True, capture_output=True)
        labels = [line.rstrip('\n').split('\t')[1] for line in list(open(path))[1:]]
        yield name, np.load(out), kind, np.unique(labels, return_inverse=True)[1], None


def preset_matrix(shapes):
    col = amscr.Collection(amscr.Params.retrieval(rerank_k=0))
    col.extend(shapes)
    return col.retrieval_matrix()


def affine_copies(a):
    dev = os.path.join(a.data, 'mpeg7-dev')
    rows = [line.rstrip('\n').split('\t') for line in list(open(os.path.join(dev, 'manifest.tsv')))[1:]]
    rng, shapes, labels = np.random.default_rng(7), [], []
    imgs = [cv2.imread(os.path.join(dev, f), cv2.IMREAD_GRAYSCALE) for f, _ in rows]
    for img, (_, c) in zip(imgs, rows):
        shapes.append(amscr.contour_from_mask(img, threshold=127, join=True))
        labels.append(c)
    for img, (_, c) in zip(imgs, rows):
        m = max(img.shape)
        img = cv2.copyMakeBorder(img, m, m, m, m, cv2.BORDER_CONSTANT, 0)
        th, sh = rng.uniform(0, 2 * np.pi), rng.uniform(-0.25, 0.25)
        s = np.exp(rng.uniform(np.log(0.75), np.log(1.33), 2))
        A = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]) @ np.array([[s[0], sh], [0, s[1]]])
        c0 = np.array([img.shape[1] / 2, img.shape[0] / 2])
        M = np.hstack([A, (c0 - A @ c0)[:, None]])
        shapes.append(amscr.contour_from_mask(cv2.warpAffine(img, M, img.shape[::-1]), threshold=127, join=True))
        labels.append(c)
    return preset_matrix(shapes), np.unique(labels, return_inverse=True)[1]


def view_sets(a):
    plans = [(0, 4, 10, s) for s in (1, 2, 3)] + ([] if a.quick else [(8, 10, 41, s) for s in (1, 2)])
    for ncls, objects, views, seed in plans:
        by = retrieval_views.draw(retrieval_views.classes(a.data, ''), ncls, seed)
        shapes, cls, grp = retrieval_views.build(by, objects, views, seed, True)
        name = 'views %d x %d x %d, seed %d' % (ncls or len(by), objects, views, seed)
        yield name, preset_matrix(shapes), 'nn', cls, grp


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--tool', default=os.path.join(here, '..', 'build', 'tools', 'amscr'))
    ap.add_argument('--quick', action='store_true', help='without the 41-view sets')
    a = ap.parse_args(argv)
    print('re-ranking neighbourhoods (one graph, 10 iterations; amscr %s)\n' % amscr.__version__)
    print('| set | ' + ' | '.join(COLUMNS) + ' |')
    print('|---' * (len(COLUMNS) + 1) + '|')
    with tempfile.TemporaryDirectory() as tmp:
        def sets():
            yield from tool_sets(a, tmp)
            F, labels = affine_copies(a)
            yield 'mpeg7-dev + affine copies', F, 'bullseye', labels, None
            yield from view_sets(a)
        for name, F, kind, labels, groups in sets():
            row = [score(kind, R, labels, groups) for R in variants(F)]
            fmt = '%.0f' if kind.startswith('top') else '%.2f'
            print('| %s (%d) | ' % (name, len(F)) + ' | '.join(fmt % v for v in row) + ' |', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
