"""1-D Gaussian mixtures fitted by EM (C ``amscr_gmm1d``) and the Bayes threshold between two components."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, RWLock, as_count, as_float_array, as_scalar, as_uint, copy_doubles, dbuf, new_object
from .errors import StateError, _check


class GMM1D:
    """A 1-D Gaussian mixture fitted by EM (started from exact 1-D K-means).

    ``GMM1D(k, max_iterations=None, tolerance=None, variance_floor=None).fit(x)``; the fitted
    parameters are attributes (components sorted by mean). A fitted model may be used by many
    threads; fitting is serialized by a lock.
    """

    def __init__(self, k: int, *, max_iterations: Optional[int] = None, tolerance: Optional[float] = None,
                 variance_floor: Optional[float] = None):
        self._g = new_object('amscr_gmm1d', lib.amscr_gmm1d_new, lib.amscr_gmm1d_free, as_count(k, 'k', 1))
        self._lock = RWLock()
        self._fitted = False
        if max_iterations is not None:
            _check(lib.amscr_gmm1d_set_max_iterations(self._g, as_uint(max_iterations, 'max_iterations')))
        if tolerance is not None:
            _check(lib.amscr_gmm1d_set_tolerance(self._g, as_scalar(tolerance, 'tolerance')))
        if variance_floor is not None:
            _check(lib.amscr_gmm1d_set_variance_floor(self._g, as_scalar(variance_floor, 'variance_floor')))

    @property
    def k(self) -> int:
        return int(lib.amscr_gmm1d_num_components(self._g))

    def fit(self, x: ArrayLike) -> 'GMM1D':
        """Fits by EM to the values x (n >= k); returns self."""
        a = as_float_array(x, 'x', ndim=(1,))
        with self._lock.write():
            _check(lib.amscr_gmm1d_fit(self._g, dbuf(a), a.shape[0]))
            self._fitted = True
        return self

    def _arr(self, fn) -> np.ndarray:
        if not self._fitted:
            raise StateError('the mixture is not fitted', lib.AMSCR_E_STATE)
        with self._lock.read():
            return copy_doubles(fn(self._g), self.k)

    @property
    def weights(self) -> np.ndarray:
        return self._arr(lib.amscr_gmm1d_weights)

    @property
    def means(self) -> np.ndarray:
        return self._arr(lib.amscr_gmm1d_means)

    @property
    def variances(self) -> np.ndarray:
        return self._arr(lib.amscr_gmm1d_variances)

    @property
    def loglik(self) -> float:
        return float(lib.amscr_gmm1d_loglik(self._g))

    @property
    def iterations(self) -> int:
        return int(lib.amscr_gmm1d_iterations(self._g))

    @property
    def converged(self) -> bool:
        return bool(lib.amscr_gmm1d_converged(self._g))

    def posterior(self, x: float) -> np.ndarray:
        """Responsibilities of the components at x."""
        out = np.zeros(self.k, dtype=np.float64)
        with self._lock.read():
            _check(lib.amscr_gmm1d_posterior(self._g, as_scalar(x, 'x'), dbuf(out)))
        return out

    def bayes_threshold(self, i: int = 0, j: int = 1) -> float:
        """Bayes threshold between components i and j (see :func:`bayes_threshold`)."""
        out = ffi.new('double *', float('nan'))
        with self._lock.read():
            st = lib.amscr_gmm1d_bayes_threshold(self._g, as_count(i, 'i'), as_count(j, 'j'), out)
            if st == lib.AMSCR_E_NOT_FOUND and np.isfinite(out[0]):
                return float(out[0])
            _check(st)
        return float(out[0])

    def __repr__(self) -> str:
        if not self._fitted:
            return 'GMM1D(k=%d, not fitted)' % self.k
        return 'GMM1D(k=%d, weights=%s, means=%s, variances=%s)' % (self.k, self.weights, self.means,
                                                                    self.variances)


def gmm1d(x: ArrayLike, k: int, **options: Any) -> GMM1D:
    """Fits a k-component 1-D Gaussian mixture to x; see :class:`GMM1D`."""
    return GMM1D(k, **options).fit(x)


def bayes_threshold(w1: float, mu1: float, var1: float, w2: float, mu2: float, var2: float,
                    strict: bool = False) -> float:
    """The point s between mu1 and mu2 where w1 N(s; mu1, var1) = w2 N(s; mu2, var2).

    When no crossing lies strictly between the means, returns their midpoint (DESIGN.md §3.4d),
    or raises NotFoundError if `strict`.
    """
    args = [as_scalar(v, n) for v, n in ((w1, 'w1'), (mu1, 'mu1'), (var1, 'var1'), (w2, 'w2'), (mu2, 'mu2'),
                                          (var2, 'var2'))]
    out = ffi.new('double *', float('nan'))
    st = lib.amscr_bayes_threshold(*args, out)
    if st == lib.AMSCR_E_NOT_FOUND and not strict and np.isfinite(out[0]):
        return float(out[0])
    _check(st)
    return float(out[0])
