"""Retrieval scores of a distance matrix: top-k, bull's eye, top-k tables, nearest-neighbour accuracy
(C ``amscr_topk`` and ``amscr_score_*``)."""
from __future__ import annotations

from typing import Optional

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, as_count, as_float_array, bad, dbuf, factorize
from .errors import _check


def _square(D: ArrayLike, name: str = 'D') -> np.ndarray:
    a = as_float_array(D, name, ndim=(2,), finite=False)
    if a.shape[0] != a.shape[1]:
        raise bad('%s: expected a square distance matrix, got shape %s' % (name, a.shape))
    return a


def topk(dist: ArrayLike, k: int, exclude: Optional[int] = None) -> np.ndarray:
    """Indices of the k smallest distances, ascending (ties by lower index), skipping `exclude`."""
    d = as_float_array(dist, 'dist', ndim=(1,), finite=False)
    k = as_count(k, 'k', 0)
    ex = ffi.cast('size_t', -1) if exclude is None else as_count(exclude, 'exclude', 0)
    out = np.zeros(k, dtype=np.uintp)
    _check(lib.amscr_topk(dbuf(d), d.shape[0], k, ex, ffi.from_buffer('size_t[]', out)))
    return out.astype(np.intp)


def bullseye(D: ArrayLike, labels: ArrayLike, window: int = 0) -> float:
    """Bull's eye score (MPEG-7): same-class shapes among each query's `window` nearest (itself
    included; 0 = twice its class size), over the sum of class sizes. In [0, 1]."""
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_bullseye(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab),
                                    as_count(window, 'window', 0), out))
    return float(out[0])


def topk_table(D: ArrayLike, labels: ArrayLike, ranks: int = 10) -> np.ndarray:
    """Top-k table (Kimia): ``out[r]`` = queries whose (r+1)-th nearest neighbour (query excluded)
    has their label, r = 0..ranks-1."""
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    ranks = as_count(ranks, 'ranks', 1)
    out = np.zeros(ranks, dtype=np.uintp)
    _check(lib.amscr_score_topk_table(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), ranks,
                                      ffi.from_buffer('size_t[]', out)))
    return out.astype(np.int64)


def nn_accuracy(D: ArrayLike, labels: ArrayLike) -> float:
    """Leave-one-out nearest-neighbour accuracy, in [0, 1]."""
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_nn_accuracy(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), out))
    return float(out[0])


def nn_split(D: ArrayLike, test_labels: ArrayLike, train_labels: ArrayLike) -> float:
    """Train/test nearest-neighbour accuracy; D is (ntest, ntrain)."""
    d = as_float_array(D, 'D', ndim=(2,), finite=False)
    nt, nr = d.shape
    te, tr = np.asarray(test_labels), np.asarray(train_labels)
    if te.ndim != 1 or te.shape[0] != nt:
        raise bad('test_labels: expected %d labels (rows of D), got shape %s' % (nt, te.shape))
    if tr.ndim != 1 or tr.shape[0] != nr:
        raise bad('train_labels: expected %d labels (columns of D), got shape %s' % (nr, tr.shape))
    codes = factorize(np.concatenate([te, tr]) if te.dtype == tr.dtype or te.dtype.kind == tr.dtype.kind
                      else np.concatenate([te.astype(object), tr.astype(object)]), nt + nr)
    a, b = np.ascontiguousarray(codes[:nt]), np.ascontiguousarray(codes[nt:])
    out = ffi.new('double *')
    _check(lib.amscr_score_nn_split(dbuf(d), nt, nr, ffi.from_buffer('int32_t[]', a),
                                    ffi.from_buffer('int32_t[]', b), out))
    return float(out[0])
