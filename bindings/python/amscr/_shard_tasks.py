"""What the workers of a shard set compute (``amscr.distributed``; :mod:`amscr._shards` places the
tasks and gathers their results): a shard built from its block's bytes, the distances of a block's
pairs and of queries to a shard's shapes (C ``amscr_index_pair_distances``,
``amscr_index_pair_distances_at``), each row's best candidates, a shard's members and signatures
(packed: 16-bit values and an exponent a shape), and the signature shortlists
(``amscr_signature_shortlists_packed``).
"""
from __future__ import annotations

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ._lib import ffi, lib
from ._placement import _block, _tile_threads
from ._util import dbuf
from .collection import Collection
from .errors import _check
from .index import Index

SHARD_LIST = 16  # the shortlist of a shard's own (local) lists: they serve only the shard opened alone
QPOS_AFTER = 2 ** 64 - 1  # SIZE_MAX: the query after every shape


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


def _shard_facts(index: Index) -> Tuple[int, Dict[str, Any]]:
    """A loaded shard's size and options, for the load to check against the manifest."""
    return len(index), index.collection_params()._plain_dict()


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


Signatures = Tuple[np.ndarray, np.ndarray]  # packed: (n, d) uint16 values and n int32 exponents


def _signatures(index: Index) -> Signatures:
    """A shard's signatures as the index holds them (C ``amscr_index_signatures_packed``): 2 bytes a
    value and an exponent a shape, half the floats' bytes."""
    n, d = len(index), int(lib.amscr_signature_size())
    q = np.zeros((n, d), dtype=np.uint16)
    e = np.zeros(n, dtype=np.int32)
    with index._lock.read():
        _check(lib.amscr_index_signatures_packed(index._x, ffi.from_buffer('uint16_t[]', q) if n else ffi.NULL,
                                                 ffi.from_buffer('int32_t[]', e) if n else ffi.NULL, n))
    return q, e


def _joined(parts: List[Signatures]) -> Signatures:
    """The shards' signatures, in order."""
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def _floats(sigs: Signatures, lo: int, hi: int) -> np.ndarray:
    """Signatures lo..hi-1 as floats (exactly amscr_index_signatures')."""
    q, e = sigs
    return np.ldexp(q[lo:hi].astype(np.float32), e[lo:hi, None])


def _shortlists(sigs: Signatures, qsigs: np.ndarray, first: int, m: int, threads) -> np.ndarray:
    """Each query's m signature-nearest of sigs (C ``amscr_signature_shortlists_packed``); query r is
    shape first + r of sigs (left out), or a new shape (first QPOS_AFTER)."""
    nq = len(qsigs)
    out = np.zeros((nq, m), dtype=np.uintp)
    if nq == 0:
        return out.astype(np.int64)
    q, e = np.ascontiguousarray(sigs[0], dtype=np.uint16), np.ascontiguousarray(sigs[1], dtype=np.int32)
    qsigs = np.ascontiguousarray(qsigs, dtype=np.float32)
    _check(lib.amscr_signature_shortlists_packed(ffi.from_buffer('uint16_t[]', q), ffi.from_buffer('int32_t[]', e),
                                                 len(e), ffi.from_buffer('float[]', qsigs), nq, first, m,
                                                 _threads(threads), ffi.from_buffer('size_t[]', out), out.size))
    return out.astype(np.int64)


def _member_shortlists(sigs: Signatures, members: np.ndarray, m: int, threads) -> np.ndarray:
    """Each member j's m signature-nearest other shapes, as ``_shortlists`` with j left out gives
    them, in one pass over the rows for all members: the m + 1 nearest of j's own signature, less j
    (at distance 0; when m + 1 exact copies of lower index come first, j is not among them and the
    last of them goes)."""
    members = np.asarray(members, dtype=np.int64)
    q, e = sigs
    own = np.ldexp(q[members].astype(np.float32), e[members, None])
    near = _shortlists(sigs, own, QPOS_AFTER, m + 1, threads)
    return np.array([row[row != j][:m] for row, j in zip(near, members)], dtype=np.int64).reshape(len(members), m)


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
