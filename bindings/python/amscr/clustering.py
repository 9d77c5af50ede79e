"""K-means (C ``amscr_kmeans``): exact in 1-D, k-means++ and Lloyd otherwise; the elbow of SSE(k)."""
from __future__ import annotations

from typing import NamedTuple, Optional, Tuple

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, as_count, as_float_array, as_scalar, as_uint, bad, copy_doubles, dbuf, new_object
from .errors import _check
from .params import Params


class KMeansResult(NamedTuple):
    """Result of :func:`kmeans`."""
    centers: np.ndarray  # (k,) for 1-D data (ascending), else (k, dim)
    inertia: float  # within-cluster sum of squares (SSE)
    labels: np.ndarray  # (n,) nearest-centre index of each point


def _seed(seed: int) -> int:
    """A k-means++ seed: an integer in 0 .. 2**64 - 1 (the library's uint64_t)."""
    v = as_count(seed, 'seed', 0)
    if v > 0xFFFFFFFFFFFFFFFF:
        raise bad('seed: too large (%d; at most 2**64 - 1)' % v)
    return v


def _data_2d(data: ArrayLike) -> Tuple[np.ndarray, bool]:
    x = as_float_array(data, 'data', ndim=(1, 2))
    one_d = x.ndim == 1
    return (x.reshape(-1, 1) if one_d else x), one_d


def kmeans(data: ArrayLike, k: int, seed: int = 0, *, max_iterations: Optional[int] = None,
           tolerance: Optional[float] = None, restarts: Optional[int] = None) -> KMeansResult:
    """Deterministic K-means: the exact optimum for 1-D data, seeded k-means++ + Lloyd otherwise.

    Args:
        data: (n,) or (n, dim) values, n >= k.
        k: the number of clusters (>= 1).
        seed: the seed of k-means++, an integer in 0 .. 2**64 - 1 (the result depends only on it
            and the data).
        max_iterations: Lloyd iterations cap (None: the library default).
        tolerance: convergence tolerance (None: the library default).
        restarts: k-means++ restarts, the best kept (None: the library default).
    Returns:
        a :class:`KMeansResult` (centers, inertia, labels).
    Raises:
        InvalidArgumentError: n < k, non-finite values, a bad seed or bad options.
    """
    x, one_d = _data_2d(data)
    km = new_object('amscr_kmeans', lib.amscr_kmeans_new, lib.amscr_kmeans_free, as_count(k, 'k', 1))
    _check(lib.amscr_kmeans_set_seed(km, _seed(seed)))
    if max_iterations is not None:
        _check(lib.amscr_kmeans_set_max_iterations(km, as_uint(max_iterations, 'max_iterations')))
    if tolerance is not None:
        _check(lib.amscr_kmeans_set_tolerance(km, as_scalar(tolerance, 'tolerance')))
    if restarts is not None:
        _check(lib.amscr_kmeans_set_restarts(km, as_uint(restarts, 'restarts')))
    n, dim = x.shape
    _check(lib.amscr_kmeans_fit(km, dbuf(x), n, dim))
    kk = int(lib.amscr_kmeans_num_clusters(km))
    centers = copy_doubles(lib.amscr_kmeans_centers(km), kk * dim).reshape(kk, dim)
    inertia = float(lib.amscr_kmeans_inertia(km))
    labels = np.zeros(n, dtype=np.uintp)
    _check(lib.amscr_kmeans_assign(km, dbuf(x), n, ffi.from_buffer('size_t[]', labels), ffi.NULL))
    return KMeansResult(centers[:, 0].copy() if one_d else centers, inertia, labels.astype(np.intp))


def elbow(data: ArrayLike, k_max: Optional[int] = None, k_min: int = 1, seed: int = 0) -> Tuple[int, np.ndarray]:
    """The elbow of SSE(k), as the registration chooses K.

    Args:
        data: (n,) or (n, dim) values.
        k_max: the largest k (None: the registration's Kmax, clamped to n).
        k_min: the smallest k (>= 1).
        seed: the seed of k-means++, an integer in 0 .. 2**64 - 1.
    Returns:
        (k_best, sse): the elbow k and the (k_max - k_min + 1,) array of SSE(k).
    Raises:
        InvalidArgumentError: k_max < k_min, k_max > n or a bad seed.
    """
    x, _ = _data_2d(data)
    n, dim = x.shape
    if k_max is None:
        k_max = min(Params().kmax, n)
    k_min, k_max = as_count(k_min, 'k_min', 1), as_count(k_max, 'k_max', 1)
    if k_max < k_min:
        raise bad('k_max (%d) must be >= k_min (%d)' % (k_max, k_min))
    sse = np.zeros(k_max - k_min + 1, dtype=np.float64)
    best = ffi.new('size_t *')
    _check(lib.amscr_kmeans_elbow(dbuf(x), n, dim, k_min, k_max, _seed(seed), dbuf(sse), best))
    return int(best[0]), sse
