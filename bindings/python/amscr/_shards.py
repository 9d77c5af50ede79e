"""An index split in shards over a Dask cluster (``amscr.distributed.build_index``).

The collection is cut into contiguous blocks; block s is an ordinary index (:class:`amscr.Index`,
a *shard*) built and held by one worker. The whole collection's neighbour lists are global, those
of ``amscr.Index(collection, candidates=M)``. M 0 (every pair): every pair of blocks (s <= t) is
matched once on the worker holding shard t (C ``amscr_index_pair_distances``, each pair computed
as its cell of the whole collection's matrix), each block keeps its rows' and columns' best
candidates, and the client merges them. M > 0 (the default above 2,000 shapes): the client
gathers the signatures as the shards hold them, 16 bits a value (C ``amscr_index_signatures_packed``:
about 2 KB a shape), the workers find each shape's signature-nearest shapes of the whole collection
(``amscr_signature_shortlists_packed``), and the rounds
of the single shortlist build (the shortlists' pairs, the neighbours' neighbours, the inner lists)
are matched on the worker holding each pair's later shape (``amscr_index_pair_distances_at``). The
lists, without any shape, make the *graph* (C ``amscr_index_graph``). A query is matched with
every shard's shapes, or with its share of the query's M signature-nearest, on its worker
(fan-out); the client gathers its distances and diffuses them on the graph (merge,
``amscr_index_graph_scores``; a member's copy by the member rule,
``amscr_index_graph_member_scores``): the scores are those of ``amscr.Index(collection,
candidates=M).scores(query, candidates=M)``.

What the workers compute is :mod:`amscr._shard_tasks`; the global lists are made from it by
:mod:`amscr._shard_build`. A saved set is a directory of ordinary index files, the global lists
and a manifest (:mod:`amscr._shard_files`).
"""
from __future__ import annotations

import io
import os
from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from ._util import Order, as_count, dbuf
from .collection import Collection
from .errors import AmscrError, FormatError, InvalidArgumentError, StateError, _check
from .index import Index
from .params import Params
from .shape import as_shape
from ._placement import _block, _threads_by_host, gather_live, gone
from ._shard_build import _merge_lists, _shortlist_lists, widths
from ._shard_files import ShardSetError, check_shard, prepare_dir, read_set, write_set
from ._shard_tasks import (QPOS_AFTER, Signatures, _index_bytes, _joined, _member_shortlists, _members, _pair_block,
                           _query_block, _shard_facts, _shard_from_file_bytes, _shard_index, _shortlists,
                           _signatures)

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


# ========================================================================== the set (client)
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
    to rounding; a member's copy is scored as that member (the member rule), as there.

    Attributes:
        bounds: each shard's (first, end) shapes in the whole collection.
        params: the options (:class:`amscr.Params`).
        candidates: the build's shortlist M (0: every pair), the queries' default.
        pairs: the shape pairs the build matched (None for a loaded set).
    """

    def __init__(self, client, shards: List[Any], bounds: List[Tuple[int, int]], graph: _Graph, params: Params,
                 workers: List[str], candidates: int = 0, sigs: Optional[Signatures] = None):
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

    def _queries(self, queries: Sequence[Any], order: Order, name: str) -> Collection:
        """The queries prepared with the set's params: points in `order` (masked arrays refused) or
        Shapes; bad points are named `name` (with their position among several)."""
        q = Collection(self.params)
        queries = list(queries)
        for i, x in enumerate(queries):
            q.add(as_shape(x, self.params, name if len(queries) == 1 else '%s[%d]' % (name, i), order))
        return q

    def _gather(self, futs: List[Any]) -> List[Any]:
        """The results of one task a shard; a shard lost with its worker is a clear error."""
        return self._guard(lambda: self._gather_live(futs))

    def _gather_live(self, futs: List[Any]) -> List[Any]:
        return gather_live(self.client, futs, self._workers, _lost_error)

    def _guard(self, call: Any) -> Any:
        """call(); a failure while a shard's worker is gone is the clear error of a lost shard; a
        closed client is the caller's to renew, not a lost shard."""
        if getattr(self.client, 'status', None) in ('closing', 'closed'):
            raise StateError('ShardedIndex: its client is closed, and the shards lived on its cluster: load the set '
                             'again with an open client (amscr.distributed.load_index)')
        lost = [s for s, sh in enumerate(self._shards) if sh.status in ('lost', 'cancelled', 'error')]
        try:
            return call()
        except AmscrError:
            raise
        except Exception as e:  # noqa: BLE001 - Dask's errors for lost data vary by version
            lost = lost or [s for s, sh in enumerate(self._shards) if sh.status != 'finished']
            if not lost:
                raise
            raise _lost_error(lost, '%s: %s' % (type(e).__name__, e)) from e

    def _signatures(self) -> Signatures:
        if self._sigs is None:
            self._sigs = _joined(self._gather([self.client.submit(_signatures, sh, pure=False,
                                                                  workers=[self._workers[s]])
                                               for s, sh in enumerate(self._shards)]))
        return self._sigs

    def _want(self, candidates: Optional[int]) -> int:
        """The query's shortlist (0: every shape), as amscr_index_query_scores chooses it."""
        c = self.candidates if candidates is None else as_count(candidates, 'candidates', 0)
        n = len(self)
        if c == 0 or c >= n:
            return 0
        k = widths(self.params, n)[0]
        return k - 1 if c + 1 < k else c

    def scores_many(self, queries: Sequence[Any], candidates: Optional[int] = None, *,
                    order: Order = 'xy') -> np.ndarray:
        """The retrieval scores (len(queries), len(self)) of point arrays or :class:`amscr.Shape` s,
        as :meth:`amscr.Index.scores` gives them: each query matched on the workers with every
        shard's shapes (candidates 0) or with its share of the query's M signature-nearest shapes
        of the whole collection (candidates M; None: the build's M), the rows merged on the
        client. A member's copy is scored as that member (the member rule). order: 'xy'
        (default) or 'rc' for (row, col) points, as :meth:`amscr.Index.query` takes them.

        Raises:
            InvalidArgumentError: bad points, a negative candidates.
        """
        return self._scores(queries, candidates, order, 'queries')

    def _scores(self, queries: Sequence[Any], candidates: Optional[int], order: Order, name: str) -> np.ndarray:
        """scores_many, bad points named `name`."""
        want = self._want(candidates)
        q = self._queries(queries, order, name)
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
        near = _member_shortlists(self._signatures(), member[mem], want, self.params.threads) if want > 0 else None
        for r, i in enumerate(mem):
            j = int(member[i])
            C[i] = np.r_[np.arange(j), np.arange(j + 1, n)] if want == 0 else near[r]
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

    def scores(self, points: Any, candidates: Optional[int] = None, *, order: Order = 'xy') -> np.ndarray:
        """One query's scores against every shape (lower is better); candidates and order as
        :meth:`scores_many`."""
        return self._scores([points], candidates, order, 'points')[0]

    def query(self, points: Any, top: int = 10, candidates: Optional[int] = None, *,
              order: Order = 'xy') -> Tuple[np.ndarray, np.ndarray]:
        """The `top` best shapes, best first (ties by index), as :meth:`amscr.Index.query`."""
        top = as_count(top, 'top', 0)
        idx, sc = self._top(self._scores([points], candidates, order, 'points'), top)
        return idx[0], sc[0]

    def query_many(self, queries: Sequence[Any], top: int = 10, candidates: Optional[int] = None, *,
                   order: Order = 'xy') -> Tuple[np.ndarray, np.ndarray]:
        """(indices, scores), each (len(queries), min(top, len(self))), best first, ties by index."""
        top = as_count(top, 'top', 0)
        return self._top(self._scores(queries, candidates, order, 'queries'), top)

    @staticmethod
    def _top(S: np.ndarray, top: int) -> Tuple[np.ndarray, np.ndarray]:
        """The `top` best of each row of S, best first, ties by index."""
        k = min(top, S.shape[1])
        order = np.argsort(S, axis=1, kind='stable')[:, :k]
        return order.astype(np.int64), np.take_along_axis(S, order, 1)

    # -- persistence ------------------------------------------------------------------
    def save(self, path: PathLike) -> None:
        """Writes the set into directory `path` (created if needed): the shard files and the
        graph first, each under a temporary name renamed into place, then the manifest by an
        atomic rename, then the files of the set it replaces are removed. A write cut off (the
        process killed, the disk full) leaves the previous set whole. Files follow the umask.
        Saves into one folder at once follow each other, and a load waits for a save under way
        (a lock on the folder's ``.amscr-lock``); other files in the folder are kept.

        Raises:
            FileError: a file cannot be written (the previous set, if any, is kept).
        """
        d = prepare_dir(path)
        datas = self._gather([self.client.submit(_index_bytes, sh, pure=False, workers=[self._workers[s]])
                              for s, sh in enumerate(self._shards)])
        write_set(d, datas, self.bounds, self._graph.to_bytes(), len(self), self.params, self.candidates)


def _lost_error(lost: List[int], why: str) -> ShardSetError:
    return ShardSetError('amscr.distributed: shard%s %s lost with %s worker (%s); load the saved set again '
                         '(load_index) or build it again'
                         % ('s' if len(lost) > 1 else '', ', '.join(map(str, lost)),
                            'their' if len(lost) > 1 else 'its', why), lib.AMSCR_E_STATE)


def _build_lost(lost: List[int], why: str) -> ShardSetError:
    return ShardSetError('amscr.distributed.build_index: shard%s %s lost with %s worker during the build (%s); '
                         'build again' % ('s' if len(lost) > 1 else '', ', '.join(map(str, lost)),
                                          'their' if len(lost) > 1 else 'its', why), lib.AMSCR_E_STATE)


def _workers(client) -> List[str]:
    if not hasattr(client, 'nthreads') or not hasattr(client, 'submit'):
        raise TypeError('client: expected a distributed.Client, got %s' % type(client).__name__)
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
    if path is not None:
        prepare_dir(path)
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
    try:
        rows = [client.scatter(datas[s], workers=[placed[s]], hash=False) for s in range(ns)]
    except Exception as e:  # noqa: BLE001 - a worker gone since the look: a KeyError or a comm error
        g = gone(client, placed)
        if not g:
            raise
        raise _build_lost(g, '%s: %s' % (type(e).__name__, e)) from e
    th = _threads_by_host(client)
    idx = [client.submit(_shard_index, rows[s], th, pure=False, workers=[placed[s]])
           for s in range(ns)]

    def gather(futs: List[Any]) -> List[Any]:
        return gather_live(client, futs, placed, _build_lost)
    k, k2 = widths(params, n)
    mb = int(lib.amscr_index_build_shortlist(params._p, n, m))
    sigs = None
    if mb > 0:
        (nb_idx, nb_dist, in_idx, in_dist, dmax, dmax2), sigs, pairs = _shortlist_lists(
            client, gather, params, n, bounds, rows, idx, placed, mb, th)
    else:
        blocks = {}
        for s in range(ns):
            for t in range(s, ns):
                blocks[s, t] = client.submit(_pair_block, rows[s], idx[t], bounds[s][0], bounds[t][0], k, k2,
                                             pure=False, workers=[placed[t]])
        got = dict(zip(blocks, gather(list(blocks.values()))))
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
        ShardSetError: a shard missing, foreign, or built with other options or of another size
        than the manifest says (the message names the file); the shards are loaded on their
        workers and checked before it returns.
    """
    d = os.fspath(path)
    params, n, bounds, candidates, gp, gdata, datas, names = read_set(d)
    try:
        graph = _Graph.from_bytes(params, n, gdata)
    except (KeyError, ValueError, OSError) as e:
        raise FormatError('amscr.distributed.load_index: the graph %s does not fit the manifest (%s): a corrupt '
                          'file, or a manifest edited by hand' % (gp, e),
                          lib.AMSCR_E_FORMAT) from None
    workers = _workers(client)
    placed = [workers[s % len(workers)] for s in range(len(datas))]
    idx = [client.submit(_shard_from_file_bytes, datas[s], pure=False, workers=[placed[s]])
           for s in range(len(datas))]
    facts = gather_live(client, [client.submit(_shard_facts, sh, pure=False, workers=[placed[s]])
                                 for s, sh in enumerate(idx)], placed, _lost_error)
    for s, got in enumerate(facts):  # as the manifest says: a checksum vouches for a file, not for the manifest
        check_shard(d, s, names[s], bounds[s][1] - bounds[s][0], params, got)
    return ShardedIndex(client, idx, bounds, graph, params, placed, candidates)
