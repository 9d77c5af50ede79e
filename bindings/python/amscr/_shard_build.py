"""The global lists of a shard set (``amscr.distributed.build_index``), made on the client from what
the workers compute (:mod:`amscr._shard_tasks`): the lists' widths, the exhaustive build's merge of
each block's best candidates, and the rounds of the shortlist build, as ``amscr_index_build``
makes them on one machine.
"""
from __future__ import annotations

from typing import List, Tuple

import numpy as np

from ._lib import ffi, lib
from ._shard_tasks import _floats, _joined, _pairs_at, _shortlists, _signatures
from .params import Params


def widths(params: Params, n: int) -> Tuple[int, int]:
    """(k, k2): the base and inner lists' entries a shape for n shapes (C ``amscr_index_graph_widths``)."""
    k, k2 = ffi.new('size_t *'), ffi.new('size_t *')
    lib.amscr_index_graph_widths(params._p, n, k, k2)
    return int(k[0]), int(k2[0])


def _merge_lists(parts: List[Tuple[np.ndarray, np.ndarray]], r0: int, n: int, k: int) -> Tuple[np.ndarray, np.ndarray]:
    """Lists of rows r0..r0+n-1 from their candidates: itself first, then k - 1 by (distance, index)."""
    idx = np.zeros((n, k), dtype=np.uint32)
    dist = np.zeros((n, k), dtype=np.float64)
    if k == 0:
        return idx, dist
    ci = np.concatenate([p[0] for p in parts], axis=1)
    cd = np.concatenate([p[1] for p in parts], axis=1)
    order = np.lexsort((ci, cd), axis=-1)[:, :k - 1]
    idx[:, 0] = np.arange(r0, r0 + n)
    idx[:, 1:] = np.take_along_axis(ci, order, 1)
    dist[:, 1:] = np.take_along_axis(cd, order, 1)
    return idx, dist


class _Store:
    """Pair distances by key a * n + b (a < b), kept sorted."""

    def __init__(self):
        self.keys = np.zeros(0, dtype=np.int64)
        self.vals = np.zeros(0, dtype=np.float64)

    def missing(self, keys: np.ndarray) -> np.ndarray:
        keys = np.unique(keys)
        pos = np.searchsorted(self.keys, keys)
        found = (pos < len(self.keys)) & (self.keys[np.minimum(pos, len(self.keys) - 1)] == keys) if len(self.keys) \
            else np.zeros(len(keys), dtype=bool)
        return keys[~found]

    def add(self, keys: np.ndarray, vals: np.ndarray) -> None:
        k = np.concatenate([self.keys, keys])
        order = np.argsort(k, kind='stable')
        self.keys, self.vals = k[order], np.concatenate([self.vals, vals])[order]

    def get(self, keys: np.ndarray) -> np.ndarray:
        return self.vals[np.searchsorted(self.keys, keys)]


def _keys(i: np.ndarray, j: np.ndarray, n: int) -> np.ndarray:
    i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
    return np.minimum(i, j) * n + np.maximum(i, j)


def _knn(i: int, cj: np.ndarray, cd: np.ndarray, k: int) -> Tuple[np.ndarray, np.ndarray]:
    """Row i's list: itself first, then its k - 1 nearest of cj by (distance, index)."""
    order = np.lexsort((cj, cd))[:k - 1]
    return np.r_[i, cj[order]], np.r_[0.0, cd[order]]


def _shortlist_lists(client, gather, params: Params, n: int, bounds, rows, idx, placed, mb: int, th):
    """The global lists of a shortlist build, as amscr_index_build(candidates) computes them: each
    shape matched with its mb signature-nearest shapes of the whole collection, then with its
    neighbours' neighbours (the base lists, then the inner lists from the shortlist and the base
    list, refined the same way). Each round's pairs are computed once, on the worker holding the
    later shape's shard; gather(futures) waits for their results. Returns the graph's arrays, the
    signatures and the pairs matched."""
    k, k2 = widths(params, n)
    starts = np.array([lo for lo, _ in bounds], dtype=np.int64)
    sigs = _joined(gather([client.submit(_signatures, idx[s], pure=False, workers=[placed[s]])
                                  for s in range(len(bounds))]))
    sf = client.scatter([sigs], broadcast=True, hash=False)[0]  # one future of the pair
    S = np.concatenate(gather([client.submit(_shortlists, sf, _floats(sigs, lo, hi), lo, mb, th, pure=False,
                                                    workers=[placed[s]]) for s, (lo, hi) in enumerate(bounds)]))
    base, inner = _Store(), _Store()

    def run(keys: np.ndarray, want_base: bool, want_inner: bool) -> None:
        keys = np.unique(keys)
        if len(keys) == 0:
            return
        a, b = keys // n, keys % n
        sa, sb = np.searchsorted(starts, a, 'right') - 1, np.searchsorted(starts, b, 'right') - 1
        groups, futs = [], []
        for s, t in sorted(set(zip(sa.tolist(), sb.tolist()))):
            sel = np.flatnonzero((sa == s) & (sb == t))
            groups.append(sel)
            futs.append(client.submit(_pairs_at, None if s == t else rows[s], idx[t], a[sel] - starts[s],
                                      b[sel] - starts[t], None if s == t else 0, want_base, want_inner,
                                      pure=False, workers=[placed[t]]))
        D, D2 = np.zeros(len(keys)), np.zeros(len(keys))
        for sel, (d, d2) in zip(groups, gather(futs)):
            D[sel], D2[sel] = d, d2
        if want_base:
            base.add(keys, D)
        if want_inner:
            inner.add(keys, D2)

    ii = np.repeat(np.arange(n, dtype=np.int64), mb).reshape(n, mb)
    run(_keys(ii, S, n).ravel(), True, k2 > 0)
    nb_idx = np.zeros((n, k), dtype=np.int64)
    nb_dist = np.zeros((n, k))
    if k > 0:
        D = base.get(_keys(ii, S, n))
        for i in range(n):
            nb_idx[i], nb_dist[i] = _knn(i, S[i], D[i], k)
    if k >= 3:  # the refinement by the neighbours' neighbours (index_refine.c)
        R = []
        for i in range(n):
            c = np.unique(nb_idx[nb_idx[i, 1:], 1:])
            R.append(np.setdiff1d(c[c != i], S[i], assume_unique=True))
        run(base.missing(np.concatenate([_keys(np.full(len(r), i), r, n) for i, r in enumerate(R)])), True, False)
        new_idx, new_dist = nb_idx.copy(), nb_dist.copy()
        for i in range(n):
            cj = np.r_[nb_idx[i, 1:], R[i]]
            new_idx[i], new_dist[i] = _knn(i, cj, np.r_[nb_dist[i, 1:], base.get(_keys(np.full(len(R[i]), i), R[i], n))],
                                           k)
        nb_idx, nb_dist = new_idx, new_dist
    dmax = float(base.vals.max(initial=0.0))
    in_idx = np.zeros((n, k2), dtype=np.int64)
    in_dist = np.zeros((n, k2))
    dmax2 = 0.0
    if k2 > 0:  # the inner lists: the shortlist and the base list (index_inner.c), then refined
        C = [np.r_[S[i], np.setdiff1d(nb_idx[i, 1:], S[i])] for i in range(n)]
        run(inner.missing(np.concatenate([_keys(np.full(len(c), i), c, n) for i, c in enumerate(C)])), False, True)
        for i in range(n):
            d = inner.get(_keys(np.full(len(C[i]), i), C[i], n))
            dmax2 = max(dmax2, float(d.max(initial=0.0)))
            in_idx[i], in_dist[i] = _knn(i, C[i], d, k2)
        if k2 > 2:
            R = []
            for i in range(n):
                seen = set(in_idx[i, 1:].tolist())
                r = []
                for l in in_idx[in_idx[i, 1:], 1:].ravel().tolist():
                    if l != i and l not in seen:
                        seen.add(l)
                        r.append(l)
                R.append(np.array(r, dtype=np.int64))
            run(inner.missing(np.concatenate([_keys(np.full(len(r), i), r, n) for i, r in enumerate(R)])), False,
                True)
            new_idx, new_dist = in_idx.copy(), in_dist.copy()
            for i in range(n):
                d = inner.get(_keys(np.full(len(R[i]), i), R[i], n))
                dmax2 = max(dmax2, float(d.max(initial=0.0)))
                new_idx[i], new_dist[i] = _knn(i, np.r_[in_idx[i, 1:], R[i]], np.r_[in_dist[i, 1:], d], k2)
            in_idx, in_dist = new_idx, new_dist
    sf.release()
    pairs = len(np.union1d(base.keys, inner.keys))
    return (nb_idx, nb_dist, in_idx, in_dist, dmax, dmax2), sigs, pairs
