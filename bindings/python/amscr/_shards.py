"""An index split in shards over a Dask cluster (``amscr.distributed.build_index``).

The collection is cut into contiguous blocks; block s is an ordinary index (:class:`amscr.Index`,
a *shard*) built and held by one worker. The whole collection's neighbour lists are global, those
of ``amscr.Index(collection, candidates=M)``. M 0 (every pair): every pair of blocks (s <= t) is
matched once on the worker holding shard t (C ``amscr_index_pair_distances``, each pair computed
as its cell of the whole collection's matrix), each block keeps its rows' and columns' best
candidates, and the client merges them. M > 0 (the default above 2,000 shapes): the client
gathers the signatures (C ``amscr_index_signatures``), the workers find each shape's
signature-nearest shapes of the whole collection (``amscr_signature_shortlists``), and the rounds
of the single shortlist build (the shortlists' pairs, the neighbours' neighbours, the inner lists)
are matched on the worker holding each pair's later shape (``amscr_index_pair_distances_at``). The
lists, without any shape, make the *graph* (C ``amscr_index_graph``). A query is matched with
every shard's shapes, or with its share of the query's M signature-nearest, on its worker
(fan-out); the client gathers its distances and diffuses them on the graph (merge,
``amscr_index_graph_scores``; a member's copy by the member rule,
``amscr_index_graph_member_scores``): the scores are those of ``amscr.Index(collection,
candidates=M).scores(query, candidates=M)``.

A saved set is a directory of ordinary index files, the global lists and a manifest
(:mod:`amscr._shard_files`).
"""
from __future__ import annotations

import io
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from ._util import dbuf
from .collection import Collection
from .errors import AmscrError, FormatError, InvalidArgumentError, _check
from .index import Index
from .params import Params
from .shape import Shape
from ._placement import _block, _threads_by_host, _tile_threads
from ._shard_files import ShardSetError, read_set, write_set

SHARD_LIST = 16  # the shortlist of a shard's own (local) lists: they serve only the shard opened alone
QPOS_AFTER = 2 ** 64 - 1  # SIZE_MAX: the query after every shape

PathLike = Union[str, 'os.PathLike[str]']


def _register_sizeof() -> None:
    """Tells Dask what a shard weighs (its shapes and features), so that its scheduler never
    steals a shard's task to another worker, which would copy and rebuild the shard there."""
    try:
        from dask.sizeof import sizeof
    except ImportError:  # pragma: no cover - amscr.distributed needs Dask anyway
        return

    @sizeof.register(Index)
    def _index_size(x: Index) -> int:
        return 64 * 1024 + len(x) * 40 * 1024


_register_sizeof()


# ========================================================================== the graph (client)
class _Graph:
    """The whole collection's lists without its shapes (C ``amscr_index_graph``)."""

    def __init__(self, params: Params, n: int, nb_idx, nb_dist, in_idx, in_dist, dmax: float, dmax2: float):
        k, k2 = widths(params, n)
        self.arrays = {'nb_idx': np.ascontiguousarray(nb_idx, dtype=np.uint32).reshape(n, k),
                       'nb_dist': np.ascontiguousarray(nb_dist, dtype=np.float64).reshape(n, k),
                       'in_idx': np.ascontiguousarray(in_idx, dtype=np.uint32).reshape(n, k2),
                       'in_dist': np.ascontiguousarray(in_dist, dtype=np.float64).reshape(n, k2),
                       'dmax': np.float64(dmax), 'dmax2': np.float64(dmax2)}
        a = self.arrays
        out = ffi.new('amscr_index_graph **')
        nul = ffi.NULL
        _check(lib.amscr_index_graph_new(params._p, n, ffi.from_buffer('uint32_t[]', a['nb_idx']) if k else nul,
                                         dbuf(a['nb_dist'].ravel()) if k else nul,
                                         ffi.from_buffer('uint32_t[]', a['in_idx']) if k2 else nul,
                                         dbuf(a['in_dist'].ravel()) if k2 else nul, float(dmax), float(dmax2), out))
        self._g = ffi.gc(out[0], lib.amscr_index_graph_free)
        self.n, self.k2 = n, k2

    def scores(self, dq: np.ndarray, dq2: np.ndarray, cand: Optional[np.ndarray] = None) -> np.ndarray:
        """Scores from the distances dq, dq2 to shapes cand (ascending; None: every shape)."""
        n = self.n
        cand = np.arange(n, dtype=np.uintp) if cand is None else np.ascontiguousarray(cand, dtype=np.uintp)
        out = np.zeros(n, dtype=np.float64)
        dq = np.ascontiguousarray(dq, dtype=np.float64)
        dq2 = np.ascontiguousarray(dq2, dtype=np.float64)
        m = len(cand)
        _check(lib.amscr_index_graph_scores(self._g, ffi.from_buffer('size_t[]', cand) if m else ffi.NULL,
                                            dbuf(dq) if m else ffi.NULL,
                                            dbuf(dq2) if self.k2 and m else ffi.NULL, m, dbuf(out), n))
        return out

    def member_scores(self, i: int, dq: np.ndarray, cand: np.ndarray) -> np.ndarray:
        """Shape i's scores (the member rule) from its base distances dq to shapes cand."""
        out = np.zeros(self.n, dtype=np.float64)
        cand = np.ascontiguousarray(cand, dtype=np.uintp)
        dq = np.ascontiguousarray(dq, dtype=np.float64)
        m = len(cand)
        _check(lib.amscr_index_graph_member_scores(self._g, i, ffi.from_buffer('size_t[]', cand) if m else ffi.NULL,
                                                   dbuf(dq) if m else ffi.NULL, m, dbuf(out), self.n))
        return out

    def to_bytes(self) -> bytes:
        buf = io.BytesIO()
        np.savez(buf, **self.arrays)
        return buf.getvalue()

    @classmethod
    def from_bytes(cls, params: Params, n: int, data: bytes) -> '_Graph':
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            return cls(params, n, z['nb_idx'], z['nb_dist'], z['in_idx'], z['in_dist'], float(z['dmax']),
                       float(z['dmax2']))


def widths(params: Params, n: int) -> Tuple[int, int]:
    """(k, k2): the base and inner lists' entries a shape for n shapes (C ``amscr_index_graph_widths``)."""
    k, k2 = ffi.new('size_t *'), ffi.new('size_t *')
    lib.amscr_index_graph_widths(params._p, n, k, k2)
    return int(k[0]), int(k2[0])


# ========================================================================== worker side
def _threads(threads) -> int:
    return _tile_threads(threads)


def _shard_index(data: bytes, threads) -> Index:
    """Shard from its collection's bytes: an ordinary index (local lists from a short shortlist)."""
    coll = Collection.from_bytes(data)
    t = _threads(threads)
    if coll.params.threads != t:
        coll = _block(coll, 0, len(coll), t)
    return Index(coll, progress=False, candidates=SHARD_LIST if len(coll) > SHARD_LIST + 1 else 0)


def _shard_from_file_bytes(data: bytes) -> Index:
    return Index.from_bytes(data)  # computes on the threads the shard was built with


def _index_bytes(index: Index) -> bytes:
    return index.to_bytes()


def _distances(index: Index, qdb, count: int, where: str) -> Tuple[np.ndarray, np.ndarray]:
    """Base and inner distances (count x len(index)) of shapes 0..count-1 of C db qdb, which come
    (`where`) 'after' every shape of the index (queries), 'before' them (an earlier block), or are
    the index's own shapes ('diagonal': each pair computed once and mirrored)."""
    diagonal = where == 'diagonal'
    qpos = {'after': QPOS_AFTER, 'before': 0, 'diagonal': None}[where]
    m = len(index)
    D = np.zeros((count, m), dtype=np.float64)
    D2 = np.zeros((count, m), dtype=np.float64)
    with index._lock.read():
        for i in range(count):
            first = i + 1 if diagonal else 0
            _check(lib.amscr_index_pair_distances(index._x, lib.amscr_db_descriptor(qdb, i),
                                                  i if diagonal else qpos, first,
                                                  dbuf(D[i, first:]), dbuf(D2[i, first:]), m - first))
    if diagonal:
        D += D.T
        D2 += D2.T
    return D, D2


def _best(D: np.ndarray, cols0: int, k: int, self0: Optional[int]) -> Tuple[np.ndarray, np.ndarray]:
    """Each row's k best (distance, column) among D's columns (numbered from cols0), a row's own
    column (self0 + row) left out."""
    m, c = D.shape
    cols = np.broadcast_to(np.arange(cols0, cols0 + c, dtype=np.int64), (m, c))
    key = D.copy()
    if self0 is not None:
        r = np.arange(m)
        key[r, self0 + r - cols0] = np.inf
    order = np.lexsort((cols, key), axis=-1)[:, :k]
    idx = np.take_along_axis(cols, order, 1)
    dist = np.take_along_axis(key, order, 1)
    return idx, dist


def _pair_block(rows_data: bytes, index: Index, r0: int, c0: int, k: int, k2: int) -> Dict[str, Any]:
    """Block (rows of shard s, columns of shard t), s <= t, on shard t's worker: each row's and
    (s < t) each column's best candidates under both distances, and the block's largest ones."""
    same = r0 == c0
    rows = index if same else Collection.from_bytes(rows_data)
    qdb = lib.amscr_index_db(index._x) if same else rows._db
    count = len(index) if same else len(rows)
    D, D2 = _distances(index, qdb, count, 'diagonal' if same else 'before')
    out: Dict[str, Any] = {'dmax': float(D.max(initial=0.0)), 'dmax2': float(D2.max(initial=0.0))}
    out['rows'] = (_best(D, c0, k, r0 if same else None), _best(D2, c0, k2, r0 if same else None))
    if not same:
        out['cols'] = (_best(D.T, r0, k, None), _best(D2.T, r0, k2, None))
    return out


def _members(index: Index, qdata: bytes) -> List[int]:
    """Each query's member in a shard (C ``amscr_index_find_member``), -1 for none."""
    q = Collection.from_bytes(qdata)
    out = ffi.new('size_t *')
    res = []
    with index._lock.read():
        for i in range(len(q)):
            _check(lib.amscr_index_find_member(index._x, lib.amscr_db_descriptor(q._db, i), out))
            res.append(-1 if out[0] == ffi.cast('size_t', -1) else int(out[0]))
    return res


def _signatures(index: Index) -> np.ndarray:
    """A shard's signatures (len x amscr_signature_size floats, C ``amscr_index_signatures``)."""
    d = int(lib.amscr_signature_size())
    out = np.zeros((len(index), d), dtype=np.float32)
    with index._lock.read():
        _check(lib.amscr_index_signatures(index._x, ffi.from_buffer('float[]', out) if out.size else ffi.NULL,
                                          out.size))
    return out


def _shortlists(sigs: np.ndarray, qsigs: np.ndarray, first: int, m: int, threads) -> np.ndarray:
    """Each query's m signature-nearest of sigs (C ``amscr_signature_shortlists``); query r is shape
    first + r of sigs (left out), or a new shape (first QPOS_AFTER)."""
    nq = len(qsigs)
    out = np.zeros((nq, m), dtype=np.uintp)
    if nq == 0:
        return out.astype(np.int64)
    sigs = np.ascontiguousarray(sigs, dtype=np.float32)
    qsigs = np.ascontiguousarray(qsigs, dtype=np.float32)
    _check(lib.amscr_signature_shortlists(ffi.from_buffer('float[]', sigs), len(sigs), ffi.from_buffer('float[]', qsigs),
                                          nq, first, m, _threads(threads), ffi.from_buffer('size_t[]', out), out.size))
    return out.astype(np.int64)


def _pairs_at(rows_data: Optional[bytes], index: Index, a: np.ndarray, b: np.ndarray, qpos: Optional[int],
              base: bool, inner: bool) -> Tuple[np.ndarray, np.ndarray]:
    """Distances of pairs (a[t], b[t]) on shard b's worker: a local to the rows' block (rows_data's
    collection, or the shard itself when rows_data is None: then a < b and qpos is a), b local to
    the shard, a ascending. qpos: QPOS_AFTER (queries), 0 (an earlier block), None (the shard's own)
    or an array (each pair's)."""
    m = len(a)
    D = np.zeros(m, dtype=np.float64)
    D2 = np.zeros(m, dtype=np.float64)
    if m == 0:
        return D, D2
    rows = None if rows_data is None else Collection.from_bytes(rows_data)
    with index._lock.read():
        qdb = lib.amscr_index_db(index._x) if rows is None else rows._db
        starts = np.flatnonzero(np.r_[True, a[1:] != a[:-1]])
        ends = np.r_[starts[1:], m]
        for lo, hi in zip(starts, ends):
            i = int(a[lo])
            qp = i if qpos is None else int(qpos[lo]) if isinstance(qpos, np.ndarray) else qpos
            order = np.argsort(b[lo:hi], kind='stable')
            cand = np.ascontiguousarray(b[lo:hi][order], dtype=np.uintp)
            db_ = np.zeros(hi - lo)
            di_ = np.zeros(hi - lo)
            _check(lib.amscr_index_pair_distances_at(index._x, lib.amscr_db_descriptor(qdb, i),
                                                     qp, ffi.from_buffer('size_t[]', cand),
                                                     hi - lo, dbuf(db_) if base else ffi.NULL,
                                                     dbuf(di_) if inner else ffi.NULL))
            D[lo:hi][order] = db_
            D2[lo:hi][order] = di_
    return D, D2


def _query_block(index: Index, qdata: bytes, a=None, b=None, qpos=None):
    """The queries' base and inner distances to every shape of a shard (queries after every shape),
    or (a, b given) to shapes b[t] of the shard for query a[t] only (qpos: each pair's position of
    the query, for members; then base distances only)."""
    if a is not None:
        return _pairs_at(qdata, index, a, b, QPOS_AFTER if qpos is None else qpos, True, qpos is None)
    q = Collection.from_bytes(qdata)
    return _distances(index, q._db, len(q), 'after')


# ========================================================================== client side
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


def _shortlist_lists(client, params: Params, n: int, bounds, rows, idx, placed, mb: int, th):
    """The global lists of a shortlist build, as amscr_index_build(candidates) computes them: each
    shape matched with its mb signature-nearest shapes of the whole collection, then with its
    neighbours' neighbours (the base lists, then the inner lists from the shortlist and the base
    list, refined the same way). Each round's pairs are computed once, on the worker holding the
    later shape's shard. Returns the graph's arrays, the signatures and the pairs matched."""
    k, k2 = widths(params, n)
    starts = np.array([lo for lo, _ in bounds], dtype=np.int64)
    sigs = np.concatenate(client.gather([client.submit(_signatures, idx[s], pure=False, workers=[placed[s]])
                                         for s in range(len(bounds))]))
    sf = client.scatter(sigs, broadcast=True, hash=False)
    S = np.concatenate(client.gather([client.submit(_shortlists, sf, sigs[lo:hi], lo, mb, th, pure=False,
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
        for sel, (d, d2) in zip(groups, client.gather(futs)):
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


def _bounds(n: int, shards: int) -> List[Tuple[int, int]]:
    b = [n * s // shards for s in range(shards + 1)]
    return [(b[s], b[s + 1]) for s in range(shards)]


def _check_params(params: Params) -> None:
    w = params.channel_weight
    if 0.0 < w < 1.0:
        raise InvalidArgumentError('amscr.distributed.build_index: a channel weight strictly between 0 and 1 '
                                   '(%g) fuses by medians of the whole collection, which shards do not share; '
                                   'use 0 or 1' % w)


class ShardedIndex:
    """An index split in shards held by the workers of a Dask cluster (see
    :func:`amscr.distributed.build_index`). Its scores equal the single index's
    (``amscr.Index(collection, candidates=M)`` queried with ``candidates=M``, M the build's),
    to rounding, but for a member's copy (scored as a new shape: no member rule).

    Attributes:
        bounds: each shard's (first, end) shapes in the whole collection.
        params: the options (:class:`amscr.Params`).
        candidates: the build's shortlist M (0: every pair), the queries' default.
        pairs: the shape pairs the build matched (None for a loaded set).
    """

    def __init__(self, client, shards: List[Any], bounds: List[Tuple[int, int]], graph: _Graph, params: Params,
                 workers: List[str], candidates: int = 0, sigs: Optional[np.ndarray] = None):
        self.client = client
        self.candidates = candidates  # the build's shortlist M (0: every pair), the queries' default
        self.pairs: Optional[int] = None  # the pairs a build matched (None for a loaded set)
        self._sigs = sigs
        self._shards = shards  # futures of Index, one a shard
        self.bounds = bounds
        self._graph = graph
        self.params = params
        self._workers = workers

    def __len__(self) -> int:
        return self.bounds[-1][1] if self.bounds else 0

    def __repr__(self) -> str:
        return 'ShardedIndex(%d shapes, %d shards)' % (len(self), len(self.bounds))

    def _queries(self, queries: Sequence[Any]) -> Collection:
        q = Collection(self.params)
        for x in queries:
            if isinstance(x, Shape):
                q.add(x)
            else:
                q.add(np.asarray(x, dtype=np.float64))
        return q

    def _gather(self, futs: List[Any]) -> List[Any]:
        """The results of one task a shard; a shard lost with its worker is a clear error."""
        return self._guard(lambda: self.client.gather(futs))

    def _guard(self, call: Any) -> Any:
        """call(); a failure while a shard's worker is gone is the clear error of a lost shard."""
        lost = [s for s, sh in enumerate(self._shards) if sh.status in ('lost', 'cancelled', 'error')]
        try:
            return call()
        except AmscrError:
            raise
        except Exception as e:  # noqa: BLE001 - Dask's errors for lost data vary by version
            lost = lost or [s for s, sh in enumerate(self._shards) if sh.status != 'finished']
            if not lost:
                raise
            raise ShardSetError('amscr.distributed: shard%s %s lost with %s worker (%s: %s); load the saved set '
                                'again (load_index) or build it again'
                                % ('s' if len(lost) > 1 else '', ', '.join(map(str, lost)),
                                   'their' if len(lost) > 1 else 'its', type(e).__name__, e), lib.AMSCR_E_STATE) from e

    def _signatures(self) -> np.ndarray:
        if self._sigs is None:
            self._sigs = np.concatenate(self._gather([self.client.submit(_signatures, sh, pure=False,
                                                                         workers=[self._workers[s]])
                                                      for s, sh in enumerate(self._shards)]))
        return self._sigs

    def _want(self, candidates: Optional[int]) -> int:
        """The query's shortlist (0: every shape), as amscr_index_query_scores chooses it."""
        c = self.candidates if candidates is None else int(candidates)
        if c < 0:
            raise InvalidArgumentError('candidates: %d is negative' % c)
        n = len(self)
        if c == 0 or c >= n:
            return 0
        k = widths(self.params, n)[0]
        return k - 1 if c + 1 < k else c

    def scores_many(self, queries: Sequence[Any], candidates: Optional[int] = None) -> np.ndarray:
        """The retrieval scores (len(queries), len(self)) of point arrays or :class:`amscr.Shape` s,
        as :meth:`amscr.Index.scores` gives them: each query matched on the workers with every
        shard's shapes (candidates 0) or with its share of the query's M signature-nearest shapes
        of the whole collection (candidates M; None: the build's M), the rows merged on the
        client. A member's copy is scored as that member (the member rule).

        Raises:
            InvalidArgumentError: bad points, a negative candidates.
        """
        want = self._want(candidates)
        q = self._queries(queries)
        nq, n = len(q), len(self)
        out = np.zeros((nq, n), dtype=np.float64)
        if nq == 0 or n == 0:
            return out
        qf = self._guard(lambda: self.client.scatter(q.to_bytes(), broadcast=True, hash=False))
        member = np.full(nq, -1, dtype=np.int64)
        if self.params.rerank_k > 0:  # the rule matters only with re-ranking (weights are 0 or 1 here)
            for s, found in enumerate(self._gather([self.client.submit(_members, sh, qf, pure=False,
                                                                       workers=[self._workers[s]])
                                                    for s, sh in enumerate(self._shards)])):
                f = np.asarray(found, dtype=np.int64)
                member = np.where((member < 0) & (f >= 0), f + self.bounds[s][0], member)
        new = np.flatnonzero(member < 0)
        mem = np.flatnonzero(member >= 0)
        if want == 0 and len(new):
            futs = [self.client.submit(_query_block, sh, qf, pure=False, workers=[self._workers[s]])
                    for s, sh in enumerate(self._shards)]
            parts = self._gather(futs)
            dq = np.concatenate([p[0] for p in parts], axis=1)
            dq2 = np.concatenate([p[1] for p in parts], axis=1)
            for i in new:
                out[i] = self._graph.scores(dq[i], dq2[i])
            new = new[:0]
        # the rest: each query's candidates (ascending) and, for a member, its position
        C: List[np.ndarray] = [np.zeros(0, dtype=np.int64)] * nq
        if want > 0 and len(new):
            d = int(lib.amscr_signature_size())
            qs = np.zeros((len(new), d), dtype=np.float32)
            for r, i in enumerate(new):
                _check(lib.amscr_shape_signature(lib.amscr_db_descriptor(q._db, int(i)),
                                                 ffi.from_buffer('float[]', qs[r]), d))
            for r, c in zip(new, _shortlists(self._signatures(), qs, QPOS_AFTER, want, self.params.threads)):
                C[r] = c
        for i in mem:
            j = int(member[i])
            C[i] = np.r_[np.arange(j), np.arange(j + 1, n)] if want == 0 else \
                _shortlists(self._signatures(), self._signatures()[j:j + 1], j, want, self.params.threads)[0]
        todo = np.r_[new, mem].astype(np.int64)
        if len(todo) == 0:
            return out
        a = np.concatenate([np.full(len(C[i]), i, dtype=np.int64) for i in todo])
        b = np.concatenate([C[i] for i in todo])
        starts = np.array([lo for lo, _ in self.bounds], dtype=np.int64)
        sb = np.searchsorted(starts, b, 'right') - 1
        D, D2 = np.zeros(len(b)), np.zeros(len(b))
        for is_member in (False, True):
            rows = (member[a] >= 0) == is_member
            sels = [np.flatnonzero(rows & (sb == s)) for s in range(len(self._shards))]
            futs = []
            for s, sh in enumerate(self._shards):
                qp = None
                if is_member:  # the member's position relative to this shard's block
                    j = member[a[sels[s]]]
                    lo, hi = self.bounds[s]
                    qp = np.where(j < lo, 0, j - lo).astype(np.uint64)
                    qp[j >= hi] = QPOS_AFTER
                futs.append(self.client.submit(_query_block, sh, qf, a[sels[s]], b[sels[s]] - starts[s], qp,
                                               pure=False, workers=[self._workers[s]]))
            for sel, (x, x2) in zip(sels, self._gather(futs)):
                D[sel], D2[sel] = x, x2
        pos = 0
        for i in todo:
            c = C[i]
            d, d2 = D[pos:pos + len(c)], D2[pos:pos + len(c)]
            pos += len(c)
            out[i] = self._graph.member_scores(int(member[i]), d, c) if member[i] >= 0 else \
                self._graph.scores(d, d2, c)
        return out

    def scores(self, points: Any, candidates: Optional[int] = None) -> np.ndarray:
        """One query's scores against every shape (lower is better); candidates as :meth:`scores_many`."""
        return self.scores_many([points], candidates)[0]

    def query(self, points: Any, top: int = 10, candidates: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
        """The `top` best shapes, best first (ties by index), as :meth:`amscr.Index.query`."""
        idx, sc = self.query_many([points], top, candidates)
        return idx[0], sc[0]

    def query_many(self, queries: Sequence[Any], top: int = 10,
                   candidates: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]:
        """(indices, scores), each (len(queries), min(top, len(self))), best first, ties by index."""
        top = int(top)
        if top < 0:
            raise InvalidArgumentError('top: %d is negative' % top)
        S = self.scores_many(queries, candidates)
        k = min(top, S.shape[1])
        order = np.argsort(S, axis=1, kind='stable')[:, :k]
        return order.astype(np.int64), np.take_along_axis(S, order, 1)

    # -- persistence ------------------------------------------------------------------
    def save(self, path: PathLike) -> None:
        """Writes the set into directory `path` (created if needed): the shard files and the
        graph first, each under a temporary name renamed into place, then the manifest by an
        atomic rename, then the files of the set it replaces are removed. A write cut off (the
        process killed, the disk full) leaves the previous set whole. Files follow the umask.

        Raises:
            FileError: a file cannot be written (the previous set, if any, is kept).
        """
        d = os.fspath(path)
        os.makedirs(d, exist_ok=True)
        datas = self._gather([self.client.submit(_index_bytes, sh, pure=False, workers=[self._workers[s]])
                              for s, sh in enumerate(self._shards)])
        write_set(d, datas, self.bounds, self._graph.to_bytes(), len(self), self.params, self.candidates)


def _workers(client) -> List[str]:
    w = sorted(client.nthreads())
    if not w:
        raise InvalidArgumentError('amscr.distributed: the cluster has no workers')
    return w


def build_index(client, collection: Collection, path: Optional[PathLike] = None, *,
                shards: Optional[int] = None, candidates: Optional[int] = None) -> ShardedIndex:
    """Builds an index of `collection` split in shards over the workers of `client`.

    Args:
        client: a ``distributed.Client``.
        collection: the shapes and their params (``Params.retrieval()``: a channel weight of 0
            or 1).
        path: a directory to save the set into (:meth:`ShardedIndex.save`), or None.
        shards: how many shards (default: one a worker; at most one a shape).
        candidates: as :class:`amscr.Index`: None (the default for the collection's size, C
            ``amscr_index_default_candidates``: every pair up to 2,000 shapes, a shortlist of
            256 above), 0 (every pair: exact lists) or M (each shape matched with its
            signature-nearest shapes of the whole collection, then its neighbours' neighbours:
            the lists of ``amscr.Index(collection, candidates=M)``). Queries default to it.
    Returns:
        a :class:`ShardedIndex` whose shards live on the workers.
    Raises:
        InvalidArgumentError: an empty collection, a channel weight strictly between 0 and 1, open
        curves with a channel weight, no workers, a bad shard count.
    Cost: candidates 0: every pair of shapes once (n (n - 1) / 2 pair distances, as the single
    index with candidates 0); M: O(n (M + K^2)) pair distances, as the single index with
    candidates M (the signatures gathered on the client); spread over the blocks, plus a short
    shortlist build of each shard. The pairs matched are in the result's ``pairs``.
    """
    if not isinstance(collection, Collection):
        raise TypeError('collection: expected an amscr.Collection, got %s' % type(collection).__name__)
    params = collection.params
    _check_params(params)
    workers = _workers(client)
    n = len(collection)
    if n == 0:
        raise InvalidArgumentError('amscr.distributed.build_index: the collection is empty')
    if shards is not None and (isinstance(shards, bool) or int(shards) != shards or shards < 1):
        raise InvalidArgumentError('amscr.distributed.build_index: shards must be a count >= 1, got %r' % (shards,))
    if candidates is not None and (isinstance(candidates, bool) or int(candidates) != candidates or candidates < 0):
        raise InvalidArgumentError('amscr.distributed.build_index: candidates must be a count >= 0, got %r'
                                   % (candidates,))
    m = int(lib.amscr_index_default_candidates(n)) if candidates is None else int(candidates)
    ns = min(int(shards) if shards is not None else len(workers), n)
    bounds = _bounds(n, ns)
    datas = [_block(collection, lo, hi, params.threads).to_bytes() for lo, hi in bounds]
    placed = [workers[s % len(workers)] for s in range(ns)]
    rows = [client.scatter(datas[s], workers=[placed[s]], hash=False) for s in range(ns)]
    th = _threads_by_host(client)
    idx = [client.submit(_shard_index, rows[s], th, pure=False, workers=[placed[s]])
           for s in range(ns)]
    k, k2 = widths(params, n)
    mb = int(lib.amscr_index_build_shortlist(params._p, n, m))
    sigs = None
    if mb > 0:
        (nb_idx, nb_dist, in_idx, in_dist, dmax, dmax2), sigs, pairs = _shortlist_lists(
            client, params, n, bounds, rows, idx, placed, mb, th)
    else:
        blocks = {}
        for s in range(ns):
            for t in range(s, ns):
                blocks[s, t] = client.submit(_pair_block, rows[s], idx[t], bounds[s][0], bounds[t][0], k, k2,
                                             pure=False, workers=[placed[t]])
        got = dict(zip(blocks, client.gather(list(blocks.values()))))
        base = [[] for _ in range(ns)]
        inner = [[] for _ in range(ns)]
        dmax = dmax2 = 0.0
        for (s, t), r in got.items():
            dmax, dmax2 = max(dmax, r['dmax']), max(dmax2, r['dmax2'])
            base[s].append(r['rows'][0])
            inner[s].append(r['rows'][1])
            if s != t:
                base[t].append(r['cols'][0])
                inner[t].append(r['cols'][1])
        nb = [_merge_lists(base[s], lo, hi - lo, k) for s, (lo, hi) in enumerate(bounds)]
        nb_idx = np.concatenate([x[0] for x in nb]) if n else np.zeros((0, k), np.uint32)
        nb_dist = np.concatenate([x[1] for x in nb]) if n else np.zeros((0, k))
        ni = [_merge_lists(inner[s], lo, hi - lo, k2) for s, (lo, hi) in enumerate(bounds)]
        in_idx = np.concatenate([x[0] for x in ni]) if n else np.zeros((0, k2), np.uint32)
        in_dist = np.concatenate([x[1] for x in ni]) if n else np.zeros((0, k2))
        pairs = n * (n - 1) // 2
    graph = _Graph(params, n, nb_idx, nb_dist, in_idx, in_dist, dmax, dmax2 if k2 else 0.0)
    for f in rows:
        f.release()
    sx = ShardedIndex(client, idx, bounds, graph, params, placed, m if mb > 0 else 0, sigs)
    sx.pairs = pairs
    if path is not None:
        sx.save(path)
    return sx


def load_index(client, path: PathLike) -> ShardedIndex:
    """Reads a set saved by :meth:`ShardedIndex.save` and places its shards on the workers.

    Raises:
        FileError: no manifest (or unreadable files); FormatError: not a manifest, a corrupt graph;
        ShardSetError: a shard missing, foreign or built with other options (the message names
        the file).
    """
    d = os.fspath(path)
    params, n, bounds, candidates, gp, gdata, datas = read_set(d)
    try:
        graph = _Graph.from_bytes(params, n, gdata)
    except (KeyError, ValueError, OSError) as e:
        raise FormatError('amscr.distributed.load_index: the graph %s is corrupt: %s' % (gp, e),
                          lib.AMSCR_E_FORMAT) from None
    workers = _workers(client)
    placed = [workers[s % len(workers)] for s in range(len(datas))]
    idx = [client.submit(_shard_from_file_bytes, datas[s], pure=False, workers=[placed[s]])
           for s in range(len(datas))]
    return ShardedIndex(client, idx, bounds, graph, params, placed, candidates)
