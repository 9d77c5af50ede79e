#!/usr/bin/env python3
"""Query-adaptive fusion of the re-ranking's graphs: a probe in NumPy on the matrices of
`amscr-retrieval-envelope` (AMSCR_ENVELOPE_DUMP=DIR: the retrieval preset's channel matrix C
before re-ranking, the inner distance I, the channel of the closed silhouettes E).

The library's re-ranking (rerank.c) builds one kNN graph a distance and gives each row of graph g
the same mass s_g (the channel 1 - the others' shares). Here each row's masses follow how
consistent that graph's neighbourhood of the row is, a measure that needs no labels:

  fixed        s_g for every row (the library; checked against its figures);
  mutual       s_g r_g(i), r_g(i) the share of row i's k neighbours that hold i among theirs;
  density      s_g d_g(i), d_g(i) the share of ordered pairs (a, b) of i's neighbours with b
               among a's neighbours (how tight the neighbourhood is);

the masses of a row then scaled to sum 1 (a row whose graphs all score 0 keeps s_g); "of the
collection": every row takes the collection's mean of r_g or d_g instead of its own. Scores:
bull's eye % on mpeg7-dev, its class folds A and B and the MCD-style set; top-10 / top-11 sums
on Kimia-99 / -216; 24 random class halves of mpeg7-dev (12 seeded shuffles cut in two, each
half its own collection): the mean gain over the library's fixed masses at the same shares and
how many halves rise / fall.

Usage: AMSCR_ENVELOPE_DUMP=DIR build/bench/amscr-retrieval-envelope ../shared/datasets 0.08 --one-frame
       .venv/bin/python bench/retrieval_fusion_probe.py DIR [--data ../shared/datasets]
"""
import argparse
import os
import sys

import numpy as np
import scipy.sparse as sp


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from retrieval_context_probe import sym, weights  # noqa: E402
from retrieval_rerank_probe import diffuse, neighbours, score  # noqa: E402

K, ITERS = 8, 10


def load(dump, name, closing='0.08'):
    lab = np.fromfile(os.path.join(dump, name + '_labels.i32'), dtype=np.int32)
    n = len(lab)
    mats = {w: np.fromfile(os.path.join(dump, f'{name}_{w}.f64')).reshape(n, n)
            for w in ('C', 'I', 'E' + closing)}
    mats['E'] = mats.pop('E' + closing)
    return mats, lab


def consistency(idx, kind):
    """Per row, in [0, 1]: the share of its neighbours (self left out) that hold it among theirs
    (mutual), or of ordered pairs of its neighbours where the second is among the first's
    (density)."""
    n, k = idx.shape
    A = np.zeros((n, n), dtype=bool)
    A[np.repeat(np.arange(n), k), idx.ravel()] = True
    nb = idx[:, 1:]
    if kind == 'mutual':
        return A[nb, np.arange(n)[:, None]].mean(1)
    pairs = A[nb[:, :, None], nb[:, None, :]]  # pairs[i, a, b]: nb[i,b] among nb[i,a]'s
    m = nb.shape[1]
    return (pairs.sum((1, 2)) - pairs[:, np.arange(m), np.arange(m)].sum(1)) / max(m * (m - 1), 1)


def rerank(dists, shares, kind='fixed', k=K, iters=ITERS):
    """The re-ranked matrix of the graphs of `dists` (the first takes 1 - the others' shares)."""
    Ds = [sym(F) for F in dists]
    n = len(Ds[0])
    k = min(k, n)
    s = np.array([1.0 - sum(shares)] + list(shares))
    idxs = [neighbours(D, k) for D in Ds]
    mass = np.tile(s, (n, 1))
    if kind != 'fixed':
        c = np.stack([consistency(idx, kind.split()[0]) for idx in idxs], 1) * s
        if kind.endswith('collection'):
            c = np.tile(c.mean(0), (n, 1))
        tot = c.sum(1, keepdims=True)
        mass = np.where(tot > 0, c / np.where(tot > 0, tot, 1.0), mass)
    rows, cols, vals = [], [], []
    for g, (D, idx) in enumerate(zip(Ds, idxs)):
        if s[g] == 0.0:
            continue
        rows.append(np.repeat(np.arange(n), k))
        cols.append(idx.ravel())
        w = weights(np.take_along_axis(D, idx, 1), idx, D.max())
        vals.append((w * mass[:, g:g + 1]).ravel())
    P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
    return diffuse(P, Ds[0], iters)


def sub(mats, idx):
    return {w: M[np.ix_(idx, idx)] for w, M in mats.items()}


VARIANTS = [  # (name, graphs, shares, kind)
    ('inner 0.1 (the default)', 'CI', (0.1,), 'fixed'),
    ('inner 0.1, mutual', 'CI', (0.1,), 'mutual'),
    ('inner 0.1, density', 'CI', (0.1,), 'density'),
    ('inner 0.2, mutual', 'CI', (0.2,), 'mutual'),
    ('inner 0.2, density', 'CI', (0.2,), 'density'),
    ('inner 0.1, E 0.1', 'CIE', (0.1, 0.1), 'fixed'),
    ('inner 0.1, E 0.1, mutual', 'CIE', (0.1, 0.1), 'mutual'),
    ('inner 0.1, E 0.1, density', 'CIE', (0.1, 0.1), 'density'),
    ('thirds, mutual', 'CIE', (1 / 3, 1 / 3), 'mutual'),
    ('thirds, density', 'CIE', (1 / 3, 1 / 3), 'density'),
    ('inner 0.1, mutual of the collection', 'CI', (0.1,), 'mutual collection'),
    ('inner 0.1, density of the collection', 'CI', (0.1,), 'density collection'),
    ('inner 0.2, density of the collection', 'CI', (0.2,), 'density collection'),
    ('inner 0.1, E 0.1, density of the collection', 'CIE', (0.1, 0.1), 'density collection'),
    ('inner 0.1, E 0.05', 'CIE', (0.1, 0.05), 'fixed'),
]


def run(mats, lab, v, kind):
    name, g, shares, how = v
    return score(kind, rerank([mats[c] for c in g], shares, how), lab)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('dump')
    ap.add_argument('--data', default=os.path.join(os.path.dirname(__file__), '..', '..', 'shared', 'datasets'))
    ap.add_argument('--halves', type=int, default=12)
    ap.add_argument('--only', help='comma-separated variant numbers (0 = the default)')
    a = ap.parse_args(argv)
    variants = VARIANTS if not a.only else [VARIANTS[int(t)] for t in a.only.split(',')]
    dev, lab = load(a.dump, 'mpeg7-dev')
    names = [l.split('\t')[1].strip() for l in open(os.path.join(a.data, 'mpeg7-dev', 'manifest.tsv'))][1:]
    first = {c: i for i, c in reversed(list(enumerate(dict.fromkeys(names))))}
    assert [first[c] for c in names] == list(lab), 'labels are not in manifest order'
    fold = dict(l.strip().split('\t') for l in open(os.path.join(a.data, 'mpeg7-dev', 'folds.tsv')) if '\t' in l)
    idxA = np.array([i for i, c in enumerate(names) if fold.get(c) == 'A'])
    idxB = np.array([i for i, c in enumerate(names) if fold.get(c) == 'B'])
    sets = [('mpeg7-dev', dev, lab, 'bull'), ('fold A', sub(dev, idxA), lab[idxA], 'bull'),
            ('fold B', sub(dev, idxB), lab[idxB], 'bull')]
    for nm, kind in (('kimia99', 'top10'), ('kimia216', 'top11'), ('mcd', 'bull')):
        m, l = load(a.dump, nm)
        sets.append((nm, m, l, kind))
    rng = np.random.default_rng(7)
    L = lab.max() + 1
    halves = []
    for _ in range(a.halves):
        perm = rng.permutation(L)
        for side in (0, 1):
            idx = np.nonzero((perm[lab] < L // 2) == (side == 0))[0]
            halves.append((sub(dev, idx), lab[idx]))
    ref = [run(m, l, VARIANTS[0], 'bull') for m, l in halves]
    print('| variant | ' + ' | '.join(s[0] for s in sets) + ' | halves: mean gain (up / down) |')
    print('|---' * (len(sets) + 2) + '|')
    for v in variants:
        cells = [run(m, l, v, kind) for _, m, l, kind in sets]
        hv = np.array([run(m, l, v, 'bull') for m, l in halves]) - ref
        print(f'| {v[0]} | ' + ' | '.join(f'{c:.2f}' if k == 'bull' else f'{c:.0f}'
                                          for c, (_, _, _, k) in zip(cells, sets)) +
              f' | {hv.mean():+.2f} ({(hv > 1e-9).sum()} / {(hv < -1e-9).sum()}) |', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
