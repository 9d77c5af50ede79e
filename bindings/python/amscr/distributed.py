"""amscr.distributed — distance matrices and collection search on a Dask cluster.

Beyond one machine: a collection's distance matrix, a cross matrix and the top-k search of many
queries against a large collection, computed as a graph of tiles on ``dask.distributed``
(``pip install "amscr[distributed]"``)::

    from dask.distributed import Client
    import amscr.distributed as ad
    D = ad.distance_matrix(db, client=Client("tcp://scheduler:8786"))   # lazy Dask array
    idx, dist = ad.topk(queries, db, k=10, client=client)               # (nq, k) each, NumPy

How it runs:

* The prepared shapes travel once per worker: the collection is serialized once on the client
  (:meth:`amscr.Collection.to_bytes`), scattered to every worker (``broadcast=True``) and
  rebuilt there once (:meth:`amscr.Collection.from_bytes`, on first use, kept for as long as the
  computation holds it). Queries of :func:`cross_matrix` and :func:`topk` travel as row blocks,
  each only to the workers that need it.
* Each tile (rows x columns) is one multi-threaded C call (``amscr_db_cross_distances``) on
  sub-collections of the tile's rows and columns. The C results are per cell independent and
  bit-identical for any thread count, so every result equals the single-machine
  :meth:`amscr.Collection.distance_matrix`, :meth:`amscr.Collection.cross_matrix` and
  :meth:`amscr.Collection.query` element for element.
* :func:`topk` keeps the k best of each tile row and merges these partial lists in a tree,
  without ever materializing the full matrix. When the collection's params ask for retrieval
  (:attr:`amscr.Params.ranking`: channel weight > 0 or re-ranking on), a query's scores depend
  on the whole collection (the retrieval matrix's fusion and re-ranking), so a tile is a block
  of queries against every shape, each scored by ``amscr_db_search_retrieval`` as
  :meth:`amscr.Collection.query` does (a query that is a copy of a member is scored as that
  member: the member rule of the collections guide). Ranking is by (distance, index): the order of
  ``np.argsort(row, kind='stable')`` (NaN last), so ties go to the lower index.
* ``client=None`` starts a local cluster (one single-threaded worker process per core), computes
  and closes it. With a client, :func:`distance_matrix` and :func:`cross_matrix` return a lazy
  Dask array (``out=`` a path instead writes the tiles, as they arrive, into a ``.npy`` file
  memory-mapped on the client: a temporary file beside the path, renamed to it once complete).
* A worker that dies mid-run has its tiles rescheduled by Dask (``distributed.scheduler.
  allowed-failures``, 3 by default); tasks raising an exception are retried ``retries`` times.
  The shapes a tile needs may have lived only on the dead worker: query blocks go to one worker,
  and Dask's active memory manager drops the extra replicas of the broadcast collection that no
  waiting task needs. Dask then cancels the tiles depending on them. The eager paths (``out=``,
  ``client=None``, :func:`topk`) scatter the lost shapes again from the client's copy and
  resubmit those tiles (up to ``LOST_ROUNDS`` times, then :class:`LostTilesError`); a lazy
  array carries its shapes in its graph instead (one task per block, held by the scheduler), so
  Dask rebuilds a lost block by itself.
"""
from __future__ import annotations

import concurrent.futures
import contextlib
import math
import os
import threading
import uuid
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

try:
    import dask
    import distributed
    from distributed import as_completed
except ImportError as e:  # pragma: no cover - exercised only without Dask
    raise ImportError('amscr.distributed needs Dask: pip install "dask[distributed]>=2023.4" '
                      '(or pip install "amscr[distributed]")') from e

from ._lib import ffi, lib
from ._util import dbuf
from .collection import Collection
from .errors import AmscrError, FormatError, _check
from .shape import Shape
from ._placement import _block, _cores, _threads_by_host, _tile_threads, _worker_address

__all__ = ['distance_matrix', 'cross_matrix', 'topk', 'tile_size', 'LostTilesError', 'build_index', 'load_index',
           'ShardedIndex', 'ShardSetError']

TILE_MIN, TILE_MAX = 64, 2048
TILES_PER_THREAD = 8  # enough tiles that the last round leaves few threads idle
MERGE_FAN_IN = 8
LOST_ROUNDS = 3  # resubmissions of tiles cancelled because the shapes they needed were lost

PathLike = Union[str, 'os.PathLike[str]']
TileArg = Union[None, int, Tuple[int, int]]


class LostTilesError(AmscrError, RuntimeError):
    """Tiles were cancelled by Dask (their shapes were lost with the workers holding them, or
    the computation was cancelled) more than ``LOST_ROUNDS`` times in a row, or the client was
    closed during the computation; no partial result is returned."""


# ========================================================================== worker side
class _Payload:
    """A serialized collection sent to the workers. The first task using it on a worker parses
    it (once per worker process, under a lock) and drops the bytes; the parsed collection lives
    as long as Dask keeps the scattered payload."""

    def __init__(self, data: bytes, what: str = 'collection'):
        self._data: Optional[bytes] = data
        self._coll: Optional[Collection] = None
        self._lock = threading.Lock()
        self.what = what

    def collection(self, threads: Optional[int] = None) -> Collection:
        """The collection, computing with `threads` C threads (converted once: a worker always
        asks with the same count)."""
        with self._lock:
            if self._coll is None:
                try:
                    self._coll = Collection.from_bytes(self._data)
                except FormatError as e:
                    where = _worker_address() or 'this process'
                    raise FormatError('amscr.distributed: the serialized %s received by %s is corrupt (%d bytes): %s'
                                      % (self.what, where, len(self._data or b''), e.message),
                                      e.status, e.detail) from None
                _PARSED[0] += 1
                self._data = None
            if threads is not None and self._coll.params.threads != threads:
                self._coll = _block(self._coll, 0, len(self._coll), threads)
            return self._coll

    def __reduce__(self):
        # moved between workers (a replacement worker) or spilled: serialize what we hold
        with self._lock:
            data = self._data if self._coll is None else self._coll.to_bytes()
        return (_Payload, (data, self.what))


_PARSED = [0]  # collections parsed in this process (tests read it through client.run)


def _parsed_count() -> int:
    return _PARSED[0]


def _matrix_tile(payload: _Payload, r0: int, r1: int, c0: int, c1: int, threads) -> np.ndarray:
    """D[r0:r1, c0:c1] of the payload collection's distance matrix (zero diagonal)."""
    t = _tile_threads(threads)
    coll = payload.collection(t)
    rows = _block(coll, r0, r1, t)
    cols = rows if (r0, r1) == (c0, c1) else _block(coll, c0, c1, t)
    D = rows.cross_matrix(cols)
    lo, hi = max(r0, c0), min(r1, c1)
    if lo < hi:  # the distance matrix's diagonal is 0 by definition (never computed in C)
        i = np.arange(lo, hi)
        D[i - r0, i - c0] = 0.0
    return D


def _cross_tile(qpayload: _Payload, tpayload: _Payload, c0: int, c1: int, threads) -> np.ndarray:
    """Distances from a block of queries to targets c0..c1-1 (the queries' options)."""
    t = _tile_threads(threads)
    q = qpayload.collection(t)  # a query block: all of it
    return q.cross_matrix(_block(tpayload.collection(t), c0, c1, t))


def _select(idx: np.ndarray, dist: np.ndarray, k: int) -> Tuple[np.ndarray, np.ndarray]:
    """The k best candidates of each row, ordered by (valid, distance with NaN last, index);
    index -1 marks no candidate."""
    order = np.lexsort((idx, dist, idx < 0), axis=-1)[:, :k]
    return np.take_along_axis(idx, order, 1), np.take_along_axis(dist, order, 1)


def _tile_candidates(D: np.ndarray, c0: int, k: int, exclude: Optional[np.ndarray]) -> Tuple[np.ndarray, np.ndarray]:
    """The k best of each row of a tile whose columns are targets c0.. (`exclude[row]`: a target
    to leave out, or -1). A partition finds each row's k-th value first, so only the entries up to
    it (all its ties included) are sorted."""
    m, c = D.shape
    cols = np.arange(c0, c0 + c, dtype=np.intp)
    hit = None if exclude is None else cols[None, :] == exclude[:, None]
    key = D if hit is None or not hit.any() else np.where(hit, np.nan, D)  # excluded: ranked last
    if k < c:
        kth = np.partition(key, k - 1, axis=1)[:, k - 1:k]
        cand = (key <= kth) | np.isnan(kth)  # a NaN k-th value: every entry may rank
    else:
        cand = np.ones(D.shape, dtype=bool)
    if hit is not None:
        cand &= ~hit
    counts = cand.sum(axis=1)
    width = max(int(counts.max(initial=0)), 1)
    r, j = np.nonzero(cand)  # row-major: ascending columns within a row
    pos = np.arange(r.size) - np.repeat(np.cumsum(counts) - counts, counts)
    idx = np.full((m, width), -1, dtype=np.intp)
    dist = np.full((m, width), np.nan)
    idx[r, pos] = cols[j]
    dist[r, pos] = D[r, j]
    return _select(idx, dist, k)


def _topk_tile(qpayload: _Payload, tpayload: _Payload, c0: int, c1: int, k: int,
               exclude: Optional[np.ndarray], threads) -> Tuple[np.ndarray, np.ndarray]:
    return _tile_candidates(_cross_tile(qpayload, tpayload, c0, c1, threads), c0, k, exclude)


def _retrieval_tile(qpayload: _Payload, tpayload: _Payload, k: int, exclude: Optional[np.ndarray],
                    threads) -> Tuple[np.ndarray, np.ndarray]:
    """The k best of each query of a block by its retrieval scores against every target: the
    scores of :meth:`Collection.query` (C ``amscr_db_search_retrieval``, one query at a time)."""
    t = _tile_threads(threads)
    q, coll = qpayload.collection(t), tpayload.collection(t)
    D = np.empty((len(q), len(coll)), dtype=np.float64)
    with q._lock.read(), coll._lock.read():
        for i in range(len(q)):
            _check(lib.amscr_db_search_retrieval(coll._db, lib.amscr_db_descriptor(q._db, i), ffi.NULL, ffi.NULL,
                                                 dbuf(D[i]), D.shape[1]))
    return _tile_candidates(D, 0, k, exclude)


def _merge(k: int, *parts: Tuple[np.ndarray, np.ndarray]) -> Tuple[np.ndarray, np.ndarray]:
    idx = np.concatenate([p[0] for p in parts], axis=1)
    dist = np.concatenate([p[1] for p in parts], axis=1)
    return _select(idx, dist, k)


# ========================================================================== client side
def tile_size(nrows: int, ncols: int, nthreads: int, tile: TileArg = None) -> Tuple[int, int]:
    """(rows, cols) of a tile: `tile` if given (an int or a pair), else about
    ``TILES_PER_THREAD * nthreads`` tiles in all, clipped to [64, 2048] (and to the matrix)."""
    if tile is None:
        t = math.ceil(math.sqrt(nrows * ncols / (TILES_PER_THREAD * max(1, nthreads))))
        tr = tc = min(max(t, TILE_MIN), TILE_MAX)
    else:
        tr, tc = (tile, tile) if np.ndim(tile) == 0 else tuple(tile)
        tr, tc = int(tr), int(tc)
        if tr < 1 or tc < 1:
            raise ValueError('tile: expected positive sizes, got %r' % (tile,))
    return max(1, min(tr, nrows)), max(1, min(tc, ncols))


def _bounds(n: int, t: int) -> List[Tuple[int, int]]:
    return [(lo, min(lo + t, n)) for lo in range(0, n, t)]


def _check_threads(threads: Any) -> Optional[int]:
    if threads is None:
        return None
    if isinstance(threads, (bool, np.bool_)) or int(threads) != threads or not 0 <= threads <= 0xFFFFFFFF:
        raise ValueError('threads: expected None or a count >= 0 (0 = all cores), got %r' % (threads,))
    return int(threads)


def _threads_arg(threads: Optional[int], client) -> Union[int, Dict[str, int]]:
    return _threads_by_host(client) if threads is None else threads


@contextlib.contextmanager
def _client_or_local(client):
    if client is not None:
        yield client
        return
    n = _cores()
    with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                  dashboard_address=':0') as cluster, distributed.Client(cluster) as c:
        yield c


def _as_collection(x: Any, name: str) -> Collection:
    if isinstance(x, Collection):
        return x
    if isinstance(x, (bytes, bytearray, memoryview)):
        return Collection.from_bytes(x)  # FormatError here when corrupt
    raise TypeError('%s: expected an amscr.Collection (or its to_bytes()), got %s' % (name, type(x).__name__))


def _queries_like(queries: Any, targets: Collection) -> Collection:
    """The queries prepared as :meth:`Collection.query` would: with the targets' options."""
    if isinstance(queries, (bytes, bytearray, memoryview)):
        queries = Collection.from_bytes(queries)
    q = Collection(targets.params)
    if isinstance(queries, Collection):
        with queries._lock.read():
            q._add_copies(queries, range(len(queries)))
        return q
    if isinstance(queries, Shape) or (isinstance(queries, np.ndarray) and queries.ndim == 2):
        queries = [queries]
    for s in queries:
        q.add(s)
    return q


PayloadMaker = Callable[[], _Payload]


def _whole(coll: Collection, what: str) -> PayloadMaker:
    return lambda: _Payload(coll.to_bytes(), what)


def _blocks(coll: Collection, bounds: Sequence[Tuple[int, int]], what: str) -> List[PayloadMaker]:
    return [lambda lo=lo, hi=hi: _Payload(_block(coll, lo, hi, coll.params.threads).to_bytes(), what)
            for lo, hi in bounds]


class _Scattered:
    """Payloads scattered from the client's collections (`makers` serialize them on demand);
    :meth:`refresh` scatters again those the cluster lost. `broadcast`: to every worker, else
    each payload to one worker (it travels to the others when a tile there needs it)."""

    def __init__(self, client, makers: Sequence[PayloadMaker], broadcast: bool):
        self.client, self.makers, self.broadcast = client, list(makers), broadcast
        self.futures = self._scatter(range(len(self.makers)))

    def _scatter(self, which: Iterable[int]) -> list:
        payloads = [self.makers[i]() for i in which]
        return self.client.scatter(payloads, broadcast=self.broadcast, hash=False) if payloads else []

    def __getitem__(self, i: int):
        return self.futures[i]

    def refresh(self) -> int:
        """Scatters again the payloads no worker holds any more; returns how many."""
        who: Dict[Any, Any] = {}
        for _ in range(3):  # who_has raises when a future is cancelled meanwhile: ask again
            held = [f for f in self.futures if f.status == 'finished']
            try:
                who = self.client.who_has(held) if held else {}
                break
            except concurrent.futures.CancelledError:
                continue
        lost = [i for i, f in enumerate(self.futures) if f.status != 'finished' or not who.get(f.key)]
        for i, f in zip(lost, self._scatter(lost)):
            self.futures[i] = f
        return len(lost)


def _graph_payloads(makers: Sequence[PayloadMaker], token: str) -> list:
    """Payloads as tasks of a lazy graph (one key each): Dask recomputes a lost one."""
    return [dask.delayed(m(), name='%s-payload-%d' % (token, i), traverse=False) for i, m in enumerate(makers)]


def _cross_layout(client, q: Collection, t: Collection, tile: TileArg, threads: Optional[int]):
    """Tiles of a queries x targets computation: (row bounds, column bounds, threads argument,
    the targets' payload maker, the query row blocks' payload makers)."""
    nq, nt = len(q), len(t)
    tr, tc = tile_size(nq, nt, sum(client.nthreads().values()), tile)
    row_b, col_b = _bounds(nq, tr), _bounds(nt, tc)
    th = _threads_arg(threads, client)
    return row_b, col_b, th, _whole(t, 'target collection'), _blocks(q, row_b, 'query block')


def _out_array(out: Any, shape: Tuple[int, int]) -> np.ndarray:
    if out is None:
        return np.empty(shape, dtype=np.float64)
    if isinstance(out, np.ndarray):
        if out.shape != shape or out.dtype != np.float64 or not out.flags.writeable:
            raise ValueError('out: expected a writeable float64 array of shape %s, got %s %s'
                             % (shape, out.dtype, out.shape))
        return out
    return np.lib.format.open_memmap(os.fspath(out), mode='w+', dtype=np.float64, shape=shape)


def _show_progress(client, futures: list) -> Optional[threading.Thread]:
    """Dask's progress bar over `futures` (and everything they depend on), without blocking."""
    from distributed.utils import is_kernel
    if is_kernel():  # pragma: no cover - notebooks
        from IPython.display import display
        display(distributed.progress(futures, notebook=True, scheduler=client.scheduler.address))
        return None
    t = threading.Thread(target=distributed.progress, args=(futures,),
                         kwargs={'notebook': False, 'scheduler': client.scheduler.address},
                         name='amscr-progress', daemon=True)
    t.start()
    return t


def _collect(client, placed: Dict[Any, Any], progress: bool, put) -> Tuple[list, Optional[BaseException]]:
    """Waits for the futures of `placed` (future -> job), calling put(job, result) as each
    arrives and dropping it at once. Returns the jobs whose futures Dask cancelled (with the last
    reason); on an error, cancels the rest and raises it."""
    bar = _show_progress(client, list(placed)) if progress else None
    cancelled, reason = [], None
    try:
        for fut, result in as_completed(list(placed), with_results=True):
            job = placed.pop(fut)
            if fut.status == 'cancelled' or isinstance(result, BaseException):
                cancelled.append(job)  # as_completed yields the CancelledError as the result
                reason = result if isinstance(result, BaseException) else reason
            else:
                put(job, result)
            del fut, result
    except BaseException:
        client.cancel(list(placed))
        raise
    finally:
        placed.clear()
        if bar is not None:
            bar.join(timeout=5)
    return cancelled, reason


def _drain(client, jobs: Dict[Any, Callable[[int], Any]], progress: bool, put,
           payloads: Sequence[_Scattered]) -> None:
    """Runs the jobs (job -> submit(attempt), returning the job's future), calling put(job,
    result) for each. Jobs cancelled by Dask (a payload lost with its worker) are resubmitted
    after the lost payloads are scattered again, up to LOST_ROUNDS times; then LostTilesError."""
    placed = {submit(0): job for job, submit in jobs.items()}
    for attempt in range(1, LOST_ROUNDS + 2):
        cancelled, reason = _collect(client, placed, progress, put)
        if not cancelled:
            return
        if client.status in ('closing', 'closed'):  # closing a client cancels its futures: nothing to resubmit
            raise LostTilesError('amscr.distributed: the client was closed during the computation: %d tiles were '
                                 'cancelled and no partial result is returned' % len(cancelled))
        if attempt > LOST_ROUNDS:
            raise LostTilesError('amscr.distributed: %d tiles were cancelled by Dask %d times in a row (their '
                                 'shapes were lost with the workers holding them, or the computation was '
                                 'cancelled); last reason: %s' % (len(cancelled), attempt, reason))
        for p in payloads:
            p.refresh()
        placed = {jobs[job](attempt): job for job in cancelled}


def _temp_beside(path: str) -> str:
    """A new empty file in path's folder, named after it (mode 0666 less the umask)."""
    d, base = os.path.split(path)
    tmp = os.path.join(d, '.%s.amscr-tmp-%s' % (base, uuid.uuid4().hex[:12]))
    os.close(os.open(tmp, os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, 'O_CLOEXEC', 0), 0o666))
    return tmp


def _eager_matrix(client, task, row_b, col_b, args_of, out, progress, retries, token, shape, payloads):
    if out is None or isinstance(out, np.ndarray):
        return _eager_into(client, task, row_b, col_b, args_of, _out_array(out, shape), progress, retries, token,
                           payloads)
    # a path: the tiles go to a temporary file beside it, renamed into place once complete, so a
    # call that fails (or is interrupted) leaves neither a partial matrix nor a leftover file there
    path = os.fspath(out)
    tmp = _temp_beside(path)
    try:
        arr = _eager_into(client, task, row_b, col_b, args_of, _out_array(tmp, shape), progress, retries, token,
                          payloads)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    arr.filename = os.path.abspath(path)
    return arr


def _eager_into(client, task, row_b, col_b, args_of, arr, progress, retries, token, payloads):

    def submit_of(i, j):
        return lambda attempt: client.submit(task, *args_of(i, j), key='%s-%d-%d-%d' % (token, i, j, attempt),
                                             retries=retries, pure=False)

    jobs = {(i, j): submit_of(i, j) for i in range(len(row_b)) for j in range(len(col_b))}

    def put(ij, tile):
        i, j = ij
        arr[slice(*row_b[i]), slice(*col_b[j])] = tile

    _drain(client, jobs, progress, put, payloads)
    if isinstance(arr, np.memmap):
        arr.flush()
    return arr


def _lazy_matrix(client, task, row_b, col_b, args_of, progress, retries, token):
    import dask.array as da
    if not row_b or not col_b:
        return da.zeros((row_b[-1][1] if row_b else 0, col_b[-1][1] if col_b else 0), dtype=np.float64)
    with dask.annotate(retries=retries):
        blocks = [[da.from_delayed(dask.delayed(task, pure=True)(*args_of(i, j),
                                                                  dask_key_name='%s-%d-%d' % (token, i, j)),
                                   shape=(r1 - r0, c1 - c0), dtype=np.float64)
                   for j, (c0, c1) in enumerate(col_b)] for i, (r0, r1) in enumerate(row_b)]
    arr = da.block(blocks)
    if progress:
        arr = client.persist(arr)
        bar = _show_progress(client, distributed.futures_of(arr))
        distributed.wait(arr)
        if bar is not None:
            bar.join(timeout=5)
    return arr


def distance_matrix(collection: Union[Collection, bytes], client=None, tile: TileArg = None, progress: bool = False,
                    out: Union[None, PathLike, np.ndarray] = None, *, threads: Optional[int] = None,
                    retries: int = 2):
    """The (n, n) distance matrix of a collection, tiled over a Dask cluster; equal element for
    element to ``collection.distance_matrix()``.

    Args:
        collection: an :class:`amscr.Collection` (or its ``to_bytes()``).
        client: a ``distributed.Client``; None starts a local cluster (one single-threaded worker
            process per core) for this call and closes it.
        tile: tile size (an int, or (rows, cols)); None picks it from n and the cluster's threads
            (see :func:`tile_size`).
        progress: show Dask's progress bar.
        out: None, or a path: the tiles are written as they arrive into a new ``.npy`` file,
            memory-mapped on the client (``np.lib.format.open_memmap``), which is returned;
            the file is a temporary one beside the path, renamed to it once every tile is in
            (a call that fails leaves the path as it was, and no other file). A writeable
            float64 NumPy array of the right shape is accepted too.
        threads: C threads per tile; None: each host's cores over the Dask threads of its workers.
        retries: retries of a tile whose task raised (a dead worker's tiles are rescheduled anyway).

    Returns:
        with a client and no `out`: a lazy Dask array (computed on `client`; with
        ``progress=True`` it is persisted first and the bar shown); with ``client=None``: a NumPy
        array; with `out`: the memmap (or array).

    Raises:
        LostTilesError: (eager paths) tiles were still cancelled by Dask after ``LOST_ROUNDS``
            resubmissions with their lost shapes scattered again, or the client was closed.
    """
    coll = _as_collection(collection, 'collection')
    threads = _check_threads(threads)
    n = len(coll)
    lazy = client is not None and out is None
    with _client_or_local(client) as c:
        tr, tc = tile_size(n, n, sum(c.nthreads().values()), tile)
        row_b, col_b = _bounds(n, tr), _bounds(n, tc)
        th = _threads_arg(threads, c)
        token = 'amscr-matrix-' + uuid.uuid4().hex
        maker = _whole(coll, 'collection')
        payload = _graph_payloads([maker], token) if lazy else _Scattered(c, [maker], broadcast=True)

        def args_of(i, j):
            return (payload[0],) + row_b[i] + col_b[j] + (th,)

        if lazy:
            return _lazy_matrix(c, _matrix_tile, row_b, col_b, args_of, progress, retries, token)
        return _eager_matrix(c, _matrix_tile, row_b, col_b, args_of, out, progress, retries, token, (n, n),
                             [payload])


def cross_matrix(queries: Union[Collection, bytes], targets: Union[Collection, bytes], client=None,
                 tile: TileArg = None, progress: bool = False, out: Union[None, PathLike, np.ndarray] = None, *,
                 threads: Optional[int] = None, retries: int = 2):
    """The (len(queries), len(targets)) cross matrix, equal element for element to
    ``queries.cross_matrix(targets)`` (the queries' options). Arguments and result as
    :func:`distance_matrix`; the queries travel as row blocks, the targets once per worker."""
    q = _as_collection(queries, 'queries')
    t = _as_collection(targets, 'targets')
    threads = _check_threads(threads)
    nq, nt = len(q), len(t)
    lazy = client is not None and out is None
    with _client_or_local(client) as c:
        row_b, col_b, th, tmaker, qmakers = _cross_layout(c, q, t, tile, threads)
        token = 'amscr-cross-' + uuid.uuid4().hex
        if lazy:
            tpay, qpays = _graph_payloads([tmaker], token + '-t'), _graph_payloads(qmakers, token + '-q')
        else:
            tpay, qpays = _Scattered(c, [tmaker], broadcast=True), _Scattered(c, qmakers, broadcast=False)

        def args_of(i, j):
            return (qpays[i], tpay[0]) + col_b[j] + (th,)

        if lazy:
            return _lazy_matrix(c, _cross_tile, row_b, col_b, args_of, progress, retries, token)
        return _eager_matrix(c, _cross_tile, row_b, col_b, args_of, out, progress, retries, token, (nq, nt),
                             [tpay, qpays])


def topk(queries: Union[Collection, Iterable[Any], bytes], collection: Union[Collection, bytes], k: int = 10,
         client=None, tile: TileArg = None, progress: bool = False, *, exclude: Optional[Sequence[int]] = None,
         threads: Optional[int] = None, retries: int = 2) -> Tuple[np.ndarray, np.ndarray]:
    """The k nearest shapes of `collection` for each query, without materializing the matrix.

    Args:
        queries: a :class:`amscr.Collection`, or point arrays / :class:`amscr.Shape` s; they are
            matched with the collection's options, as :meth:`Collection.query` does.
        collection: the targets.
        k: neighbours per query (at most len(collection), minus one with `exclude`).
        exclude: per query, a target index to leave out (negative: none), e.g.
            ``range(len(db))`` for a leave-one-out search of a collection against itself.
        client, tile, progress, threads, retries: as :func:`distance_matrix`.

    Returns:
        (indices, distances), each (len(queries), k): for query i the targets ordered as
        ``np.argsort(collection.query(q_i), kind='stable')`` (ascending distance, NaN last, ties
        by lower index), excluded target removed. With params that ask for retrieval
        (:attr:`Params.ranking` 'retrieval') the distances are the retrieval scores of
        :meth:`Collection.query`, each query scored against the whole collection (one tile a
        query block).
    """
    t = _as_collection(collection, 'collection')
    threads = _check_threads(threads)
    nt = len(t)
    q = _queries_like(queries, t)
    nq = len(q)
    ex = None
    if exclude is not None:
        ex = np.asarray(exclude)
        if ex.shape != (nq,) or ex.dtype.kind not in 'iu':
            raise ValueError('exclude: expected %d integer indices (one per query), got %s %s'
                             % (nq, ex.dtype, ex.shape))
        ex = np.where(ex < 0, -1, ex).astype(np.intp)
    if isinstance(k, (bool, np.bool_)) or int(k) != k or k < 0:
        raise ValueError('k: expected a non-negative integer, got %r' % (k,))
    k = min(int(k), nt - (1 if ex is not None and (ex >= 0).any() else 0))
    k = max(k, 0)
    indices = np.zeros((nq, k), dtype=np.intp)
    distances = np.zeros((nq, k), dtype=np.float64)
    if nq == 0 or k == 0:
        return indices, distances
    retrieval = t.params.ranking == 'retrieval'  # as Collection.query decides
    with _client_or_local(client) as c:
        row_b, col_b, th, tmaker, qmakers = _cross_layout(c, q, t, tile, threads)
        tpay, qpays = _Scattered(c, [tmaker], broadcast=True), _Scattered(c, qmakers, broadcast=False)
        token = uuid.uuid4().hex
        if retrieval:  # a query's scores need the whole collection: one column block
            col_b = [(0, nt)]

        def submit_row(i, attempt):
            """The tiles of query block i and their merge tree; returns the root's future."""
            r0, r1 = row_b[i]
            exi = None if ex is None else ex[r0:r1]
            name = '%s-%d-%d' % (token, i, attempt)
            if retrieval:
                return c.submit(_retrieval_tile, qpays[i], tpay[0], k, exi, th, retries=retries, pure=False,
                                key='amscr-topk-%s-r' % name)
            level = [c.submit(_topk_tile, qpays[i], tpay[0], c0, c1, k, exi, th, retries=retries, pure=False,
                              key='amscr-topk-%s-%d' % (name, j)) for j, (c0, c1) in enumerate(col_b)]
            depth = 0
            while len(level) > 1:
                level = [c.submit(_merge, k, *level[m:m + MERGE_FAN_IN], retries=retries, pure=False,
                                  key='amscr-merge-%s-%d-%d' % (name, depth, m))
                         for m in range(0, len(level), MERGE_FAN_IN)]
                depth += 1
            return level[0]

        def put(i, result):
            idx, dist = result
            if (idx < 0).any():  # pragma: no cover - k is clipped to the valid candidates
                raise RuntimeError('amscr.distributed.topk: fewer than k candidates in a row')
            rows = slice(*row_b[i])
            indices[rows], distances[rows] = idx, dist

        jobs = {i: (lambda attempt, i=i: submit_row(i, attempt)) for i in range(len(row_b))}
        _drain(c, jobs, progress, put, [tpay, qpays])
    return indices, distances


from ._shards import ShardedIndex, ShardSetError, build_index, load_index  # noqa: E402  (an index in shards)
