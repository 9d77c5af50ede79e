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
    """Indices of the k smallest distances, ascending (ties by lower index).

    Args:
        dist: (n,) distances, e.g. a row of :meth:`Collection.query`.
        k: how many (at most n, or n - 1 with `exclude`).
        exclude: an index to skip (the query itself), or None.
    Returns:
        (k,) int array of indices into `dist`.
    Raises:
        InvalidArgumentError: `dist` not 1-D, `k` too large, `exclude` out of range.
    """
    d = as_float_array(dist, 'dist', ndim=(1,), finite=False)
    k = as_count(k, 'k', 0)
    ex = ffi.cast('size_t', -1) if exclude is None else as_count(exclude, 'exclude', 0)
    out = np.zeros(k, dtype=np.uintp)
    _check(lib.amscr_topk(dbuf(d), d.shape[0], k, ex, ffi.from_buffer('size_t[]', out)))
    return out.astype(np.intp)


def bullseye(D: ArrayLike, labels: ArrayLike, window: int = 0) -> float:
    """Bull's eye score (MPEG-7): same-class shapes among each query's `window` nearest (itself
    included), over the sum of class sizes.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
        window: how many nearest to look at (0 = twice the query's class size, the MPEG-7 rule).
    Returns:
        the score, in [0, 1].
    Raises:
        InvalidArgumentError: D not square, or not one label per row.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_bullseye(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab),
                                    as_count(window, 'window', 0), out))
    return float(out[0])


def topk_table(D: ArrayLike, labels: ArrayLike, ranks: int = 10) -> np.ndarray:
    """Top-k table (Kimia): how many queries have a same-class shape at each rank.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
        ranks: the number of ranks (columns of the Kimia tables: 10 for Kimia-99).
    Returns:
        (ranks,) int array: ``out[r]`` = queries whose (r+1)-th nearest neighbour (the query
        excluded) has their label.
    Raises:
        InvalidArgumentError: D not square, not one label per row, ranks >= n.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    ranks = as_count(ranks, 'ranks', 1)
    out = np.zeros(ranks, dtype=np.uintp)
    _check(lib.amscr_score_topk_table(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), ranks,
                                      ffi.from_buffer('size_t[]', out)))
    return out.astype(np.int64)


def nn_accuracy(D: ArrayLike, labels: ArrayLike) -> float:
    """Leave-one-out nearest-neighbour accuracy.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
    Returns:
        the fraction of queries whose nearest other shape has their label, in [0, 1].
    Raises:
        InvalidArgumentError: D not square, or not one label per row.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_nn_accuracy(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), out))
    return float(out[0])


def nn_split(D: ArrayLike, test_labels: ArrayLike, train_labels: ArrayLike) -> float:
    """Train/test nearest-neighbour accuracy.

    Args:
        D: (ntest, ntrain) distances from the test shapes to the training shapes (e.g.
            :meth:`Collection.cross_matrix`).
        test_labels: ntest labels (ints or names).
        train_labels: ntrain labels, of the same kind.
    Returns:
        the fraction of test shapes whose nearest training shape has their label, in [0, 1].
    Raises:
        InvalidArgumentError: label counts that do not match D.
    """
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
