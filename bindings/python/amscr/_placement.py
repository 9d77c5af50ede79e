"""Where the work of ``amscr.distributed`` runs: the C threads of a task on its worker's host, a
block of a collection as the collection a task computes with, and the results of tasks pinned to
workers that may leave. Shared by the tiles of :mod:`amscr.distributed` and the shards of its index."""
from __future__ import annotations

import asyncio
import concurrent.futures
import os
from collections import defaultdict
from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import distributed
from distributed.comm import get_address_host

from .collection import Collection
from .errors import AmscrError

#: What distributed.wait raises at its timeout (Python and Dask versions differ).
_TIMEOUTS = (TimeoutError, asyncio.TimeoutError, concurrent.futures.TimeoutError)
#: How often a wait for tasks pinned to workers checks that the workers are still there (seconds).
LIVENESS_SECONDS = 1.0


def _worker_address() -> Optional[str]:
    try:
        return distributed.get_worker().address
    except ValueError:
        return None


def _cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


def _tile_threads(threads: Union[int, Dict[str, int], None]) -> int:
    """C threads of this tile: an explicit count, or this worker host's share of its cores."""
    if isinstance(threads, int):
        return threads
    addr = _worker_address()
    if threads and addr is not None and get_address_host(addr) in threads:
        return threads[get_address_host(addr)]
    try:
        nthreads = distributed.get_worker().nthreads
    except ValueError:  # not on a worker
        nthreads = 1
    return max(1, _cores() // max(1, nthreads))


def _block(coll: Collection, lo: int, hi: int, threads: int) -> Collection:
    """Shapes lo..hi-1 of `coll` as a collection computing with `threads` C threads (one copy of
    each prepared shape; `coll` itself when nothing changes)."""
    p = coll.params
    if lo == 0 and hi == len(coll) and p.threads == threads:
        return coll
    sub = Collection(p, threads=threads)
    with coll._lock.read():
        sub._add_copies(coll, range(lo, hi))
    return sub


def _threads_by_host(client) -> Dict[str, int]:
    """C threads per tile on each host: its cores over the Dask threads of its workers. A worker
    that does not answer (it left meanwhile, or hangs until the scheduler drops it) is left out of
    the cores, not an error: Dask runs its tasks elsewhere."""
    nthreads = client.nthreads()
    if not nthreads:
        return {}
    cores = client.run(_cores, on_error='ignore')
    dask_threads: Dict[str, int] = defaultdict(int)
    host_cores: Dict[str, int] = {}
    for addr, nt in nthreads.items():
        h = get_address_host(addr)
        dask_threads[h] += nt
        if addr in cores:
            host_cores[h] = cores[addr]
    return {h: max(1, host_cores.get(h, 1) // dask_threads[h]) for h in dask_threads}


def _worker_addresses(dask_scheduler: Any) -> List[str]:
    """The addresses of the cluster's workers (run on the scheduler)."""
    return list(dask_scheduler.workers)


def gone(client, placed: Sequence[str]) -> List[int]:
    """The positions s of `placed` (one worker address a shard) whose worker left the cluster."""
    live = set(client.run_on_scheduler(_worker_addresses))
    return [s for s, w in enumerate(placed) if w not in live]


def gather_live(client, futs: List[Any], placed: Sequence[str],
                lost: Callable[[List[int], str], Exception]) -> List[Any]:
    """client.gather(futs) of tasks pinned to the workers `placed` (one a shard), checking every
    LIVENESS_SECONDS that those workers are still in the cluster: a task pinned to a worker that
    left (killed, or retired by the cluster) would wait for it forever. Raises lost(shards, why)
    when some left, also when a task failed (Dask's errors for lost data vary by version)."""
    while True:
        try:
            distributed.wait(futs, timeout=LIVENESS_SECONDS)
            return client.gather(futs)
        except _TIMEOUTS:
            g = gone(client, placed)
            if g:
                raise lost(g, 'its worker left the cluster') from None
        except AmscrError:
            raise
        except Exception as e:  # noqa: BLE001 - a worker's loss surfaces as one of several errors
            g = gone(client, placed)
            if not g:
                raise
            raise lost(g, '%s: %s' % (type(e).__name__, e)) from e
