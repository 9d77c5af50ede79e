"""Where the work of ``amscr.distributed`` runs: the C threads of a task on its worker's host, and
a block of a collection as the collection a task computes with. Shared by the tiles of
:mod:`amscr.distributed` and the shards of its index."""
from __future__ import annotations

import os
from collections import defaultdict
from typing import Dict, Optional, Union

import distributed
from distributed.comm import get_address_host

from .collection import Collection


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
    """C threads per tile on each host: its cores over the Dask threads of its workers."""
    nthreads = client.nthreads()
    if not nthreads:
        return {}
    cores = client.run(_cores)
    dask_threads: Dict[str, int] = defaultdict(int)
    host_cores: Dict[str, int] = {}
    for addr, nt in nthreads.items():
        h = get_address_host(addr)
        dask_threads[h] += nt
        host_cores[h] = cores.get(addr, 1)
    return {h: max(1, host_cores[h] // dask_threads[h]) for h in dask_threads}
