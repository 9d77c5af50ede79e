#!/usr/bin/env python3
"""Whose context does the re-ranking see when a protocol holds shapes out? A probe in NumPy on
the retrieval preset's fused channel before re-ranking (one graph: the inner-distance share 0).

The 1-NN protocols of the held-out collections hold shapes out: ETH-80 classifies each object's
views against the other objects (leave one group out), the Swedish leaves classify the test
leaves against 25 training leaves a class (split). The re-ranking's diffusion is computed on a
kNN graph of a whole collection; two ways to give it one:

  whole matrix  the re-ranked matrix of every shape (held-out ones included), then 1-NN among
                the allowed shapes: the held-out shapes shape each other's context (an object's
                other views are its nearest neighbours, so its diffusion runs through itself);
  held out      each held-out shape is a query against a collection of the allowed shapes only:
                its row of the re-ranked matrix of (the allowed shapes + the query), computed
                exactly (the query enters the lists of the shapes it is nearer to than their
                k-th neighbour) by sparse powers, as amscr_index_query_scores computes it.

Checked (--check, Kimia-99): the whole-matrix re-ranking here equals the library's (inner share
0), and a held-out row equals the last row of the whole-matrix re-ranking of (allowed + query).
The base distances are the whole collection's (the library scales the two frames by the
collection's medians, so a collection of the allowed shapes alone has slightly other ones).

Usage: .venv/bin/python bench/retrieval_context_probe.py [--data ../shared/datasets]
       [--tool build/tools/amscr] [--sets split,views,views41] [--check]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
import scipy.sparse as sp

import amscr

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import retrieval_views  # noqa: E402
from retrieval_rerank_probe import diffuse, graph, neighbours  # noqa: E402

K, ITERS = 8, 10


def weights(d, idx, dmax):
    """exp(-d / sqrt(s_i s_j)) over each row's list (d: its distances), rows summing to 1
    (rerank.c)."""
    sc = d[:, -1]
    tiny = 1e-12 * dmax
    w = np.exp(-d / np.sqrt((sc[:, None] + tiny) * (sc[idx] + tiny)))
    return w / w.sum(1, keepdims=True)


def sym(F):
    D = 0.5 * (F + F.T)
    np.fill_diagonal(D, 0.0)
    return D


def whole(F):
    """The re-ranked matrix of every shape (rerank.c, halved into [0, 1])."""
    D = sym(F)
    return diffuse(graph(D, neighbours(D, min(K, len(D)))), D, ITERS)


class Context:
    """A collection of the allowed shapes S (base distances D restricted to S) that held-out
    queries are ranked against."""

    def __init__(self, D, S):
        self.S = np.asarray(S)
        self.D = D[np.ix_(self.S, self.S)]
        m = len(self.S)
        self.k = min(K, m + 1)
        self.idx = neighbours(self.D, min(self.k, m))  # each row's list within S
        self.dl = np.take_along_axis(self.D, self.idx, 1)
        self.kth = self.dl[:, -1]
        self.dmax = self.D.max()

    def row(self, dq):
        """The query's re-ranked scores against S (dq: its base distances to S)."""
        m, k = len(self.S), self.k
        n = m + 1
        dmax = max(self.dmax, dq.max())
        if self.idx.shape[1] < k:  # fewer shapes than k: every row holds every shape
            Dq = np.zeros((n, n))
            Dq[:m, :m] = self.D
            Dq[:m, m] = Dq[m, :m] = dq
            idx = neighbours(Dq, k)
            d = np.take_along_axis(Dq, idx, 1)
        else:
            idx = np.empty((n, k), dtype=np.int64)
            d = np.empty((n, k))
            idx[:m], d[:m] = self.idx, self.dl
            for i in np.nonzero(dq < self.kth)[0]:  # ties: the query's index is the highest
                lst = list(self.idx[i, :k - 1])
                pos = next(t for t in range(1, k) if t == k - 1 or self.D[i, lst[t]] > dq[i])
                idx[i] = lst[:pos] + [m] + lst[pos:]
                d[i] = [self.D[i, j] if j < m else dq[i] for j in idx[i]]
            order = np.lexsort((np.arange(m), dq))[:k - 1]
            idx[m] = np.concatenate([[m], order])
            d[m] = np.concatenate([[0.0], dq[order]])
        w = weights(d, idx, dmax)
        P = sp.csr_matrix((w.ravel(), idx.ravel(), np.arange(0, n * k + 1, k)), shape=(n, n))
        PT = P.T.tocsr()
        a = np.zeros(n)
        a[m] = 1.0
        rows = []
        for _ in range(ITERS):  # a_t = e_q P^t
            rows.append(a)
            a = PT @ a
        v = PT @ a  # a_(T+1)
        for t in range(ITERS - 1, -1, -1):  # sum_t P^t a_t + P^T a_(T+1), by Horner's rule
            v = P @ v + rows[t]
        r = v[:m]
        return 0.5 * np.where(r > 0, 1.0 - r / v.max(), 1.0 + dq / dmax)


def groups_scores(F, cls, grp):
    """1-NN with the query's group left out: (whole matrix, held out), in %."""
    R = whole(F)
    D = sym(F)
    n = len(F)
    hit_w = hit_h = 0
    for g in np.unique(grp):
        inside = grp == g
        S = np.nonzero(~inside)[0]
        ctx = Context(D, S)
        for q in np.nonzero(inside)[0]:
            hit_w += cls[S[np.argmin(R[q, S])]] == cls[q]
            hit_h += cls[S[np.argmin(ctx.row(D[q, S]))]] == cls[q]
    return 100.0 * hit_w / n, 100.0 * hit_h / n


def split_scores(F, cls, train, splits, seed=1):
    """1-NN of the test shapes against `train` shapes a class, mean over seeded splits."""
    R = whole(F)
    D = sym(F)
    rng = np.random.default_rng(seed)
    acc_w, acc_h = [], []
    for _ in range(splits):
        tr = np.concatenate([rng.permutation(np.nonzero(cls == c)[0])[:train] for c in np.unique(cls)])
        te = np.setdiff1d(np.arange(len(F)), tr)
        ctx = Context(D, tr)
        acc_w.append(np.mean([cls[tr[np.argmin(R[q, tr])]] == cls[q] for q in te]))
        acc_h.append(np.mean([cls[tr[np.argmin(ctx.row(D[q, tr]))]] == cls[q] for q in te]))
    return 100.0 * np.mean(acc_w), 100.0 * np.mean(acc_h)


def tool_matrix(tool, path, tmp):
    out = os.path.join(tmp, 'F.npy')
    subprocess.run([tool, 'matrix', path, '--no-rerank', '-o', out], check=True, capture_output=True)
    labels = [line.rstrip('\n').split('\t')[1] for line in list(open(path))[1:]]
    return np.load(out), np.unique(labels, return_inverse=True)[1]


def fold_manifests(data, tmp):
    dev = os.path.join(data, 'mpeg7-dev')
    rows = [line.rstrip('\n').split('\t') for line in list(open(os.path.join(dev, 'manifest.tsv')))[1:]]
    folds = dict(line.rstrip('\n').split('\t') for line in list(open(os.path.join(dev, 'folds.tsv')))[1:])
    out = [('mpeg7-dev', os.path.join(dev, 'manifest.tsv'), 10)]
    for fold in ('A', 'B'):
        path = os.path.join(tmp, 'fold%s.tsv' % fold)
        with open(path, 'w') as f:
            f.write('file\tclass\n')
            f.writelines('%s\t%s\n' % (os.path.join(dev, p), c) for p, c in rows if folds[c] == fold)
        out.append(('fold ' + fold, path, 10))
    out += [('Kimia-99', os.path.join(data, 'kimia99', 'manifest.tsv'), 5),
            ('Kimia-216', os.path.join(data, 'kimia216', 'manifest.tsv'), 6)]
    return out


def check(a, tmp):
    """whole() against the library's re-ranking (inner share 0) on Kimia-99, and the held-out
    row against whole() of (allowed + query) on the same base distances."""
    import cv2
    path = os.path.join(a.data, 'kimia99', 'manifest.tsv')
    F, cls = tool_matrix(a.tool, path, tmp)
    base = os.path.dirname(path)
    shapes = [amscr.contour_from_mask(cv2.imread(os.path.join(base, line.split('\t')[0]), 0), threshold=127,
                                      join=True) for line in list(open(path))[1:]]
    col = amscr.Collection(amscr.Params.retrieval(rerank_inner_share=0.0))
    col.extend(shapes)
    lib = float(np.abs(whole(F) - col.retrieval_matrix()).max())
    D, worst = sym(F), 0.0
    for q in (0, 37, 98):
        S = np.nonzero(cls != cls[q])[0]
        sub = np.append(S, q)
        ref = whole(F[np.ix_(sub, sub)])[-1, :-1]
        worst = max(worst, float(np.abs(Context(D, S).row(D[q, S]) - ref).max()))
    print('check on Kimia-99: whole matrix against the library %.3g, held-out rows against the whole '
          'matrix of (allowed + query) %.3g' % (lib, worst))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--tool', default=os.path.join(here, '..', 'build', 'tools', 'amscr'))
    ap.add_argument('--sets', default='split,views,views41')
    ap.add_argument('--splits', type=int, default=10)
    ap.add_argument('--check', action='store_true')
    a = ap.parse_args(argv)
    want = a.sets.split(',')
    print('| set | protocol | whole matrix | held out |\n|---|---|---|---|', flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        if a.check:
            check(a, tmp)
        if 'split' in want:
            for name, path, train in fold_manifests(a.data, tmp):
                F, cls = tool_matrix(a.tool, path, tmp)
                w, h = split_scores(F, cls, train, a.splits)
                print('| %s | split, %d a class train | %.2f | %.2f |' % (name, train, w, h), flush=True)
        plans = ([(0, 4, 10, s) for s in (1, 2, 3)] if 'views' in want else []) + \
                ([(8, 10, 41, s) for s in (1, 2)] if 'views41' in want else [])
        for ncls, objects, views, seed in plans:
            by = retrieval_views.draw(retrieval_views.classes(a.data, ''), ncls, seed)
            shapes, cls, grp = retrieval_views.build(by, objects, views, seed, True)
            col = amscr.Collection(amscr.Params.retrieval(rerank_k=0))
            col.extend(shapes)
            w, h = groups_scores(col.retrieval_matrix(), cls, grp)
            print('| views %d x %d x %d, seed %d | one object out | %.2f | %.2f |'
                  % (ncls or len(by), objects, views, seed, w, h), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
