"""1-D Gaussian mixtures fitted by EM (C ``amscr_gmm1d``) and the Bayes threshold between two components."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, RWLock, as_count, as_float_array, as_scalar, as_uint, copy_doubles, dbuf, new_object
from .errors import StateError, _check


class GMM1D:
    """A 1-D Gaussian mixture fitted by EM (started from exact 1-D K-means).

    ``GMM1D(k, *, max_iterations=None, tolerance=None, variance_floor=None).fit(x)`` (the options
    are keyword-only); the fitted
    parameters are attributes (components sorted by mean). A fitted model may be used by many
    threads; fitting is serialized by a lock.

    Args:
        k: the number of components (>= 1).
        max_iterations: EM iterations cap (None: the library default).
        tolerance: convergence tolerance on the log-likelihood (None: the library default).
        variance_floor: the smallest variance allowed (None: the library default).
    Raises:
        InvalidArgumentError: a bad option.
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
        """The number of components."""
        return int(lib.amscr_gmm1d_num_components(self._g))

    def fit(self, x: ArrayLike) -> 'GMM1D':
        """Fits the mixture by EM.

        Args:
            x: (n,) values, n >= k.
        Returns:
            self.
        Raises:
            InvalidArgumentError: n < k or non-finite values (reaching the iteration cap is
            not an error: see :attr:`converged`).
        """
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
        """(k,) mixing weights (StateError before :meth:`fit`)."""
        return self._arr(lib.amscr_gmm1d_weights)

    @property
    def means(self) -> np.ndarray:
        """(k,) means, ascending (StateError before :meth:`fit`)."""
        return self._arr(lib.amscr_gmm1d_means)

    @property
    def variances(self) -> np.ndarray:
        """(k,) variances (StateError before :meth:`fit`)."""
        return self._arr(lib.amscr_gmm1d_variances)

    @property
    def loglik(self) -> float:
        """The log-likelihood of the fitted data."""
        return float(lib.amscr_gmm1d_loglik(self._g))

    @property
    def iterations(self) -> int:
        """EM iterations of the last fit."""
        return int(lib.amscr_gmm1d_iterations(self._g))

    @property
    def converged(self) -> bool:
        """True when the last fit converged."""
        return bool(lib.amscr_gmm1d_converged(self._g))

    def posterior(self, x: float) -> np.ndarray:
        """Responsibilities of the components at a value.

        Args:
            x: the value.
        Returns:
            (k,) float array summing to 1.
        Raises:
            StateError: not fitted.
        """
        out = np.zeros(self.k, dtype=np.float64)
        with self._lock.read():
            _check(lib.amscr_gmm1d_posterior(self._g, as_scalar(x, 'x'), dbuf(out)))
        return out

    def bayes_threshold(self, i: int = 0, j: int = 1) -> float:
        """Bayes threshold between two fitted components (see :func:`bayes_threshold`).

        Args:
            i, j: component indices (by ascending mean).
        Returns:
            the threshold (the midpoint of the means when no crossing lies between them).
        Raises:
            StateError: not fitted; InvalidArgumentError: an index out of range.
        """
        out = ffi.new('double *', float('nan'))
        with self._lock.read():
            st = lib.amscr_gmm1d_bayes_threshold(self._g, as_count(i, 'i'), as_count(j, 'j'), out)
            if st == lib.AMSCR_E_NOT_FOUND and np.isfinite(out[0]):
                return float(out[0])
            _check(st)
        return float(out[0])

    def __reduce__(self):
        raise TypeError('amscr.GMM1D cannot be pickled (the C model has no way to be set from its '
                        'parameters): send the data and fit it again, or pickle '
                        '(g.weights, g.means, g.variances)')

    def __repr__(self) -> str:
        if not self._fitted:
            return 'GMM1D(k=%d, not fitted)' % self.k
        return 'GMM1D(k=%d, weights=%s, means=%s, variances=%s)' % (self.k, self.weights, self.means,
                                                                    self.variances)


def gmm1d(x: ArrayLike, k: int, **options: Any) -> GMM1D:
    """Fits a 1-D Gaussian mixture.

    Args:
        x: (n,) values, n >= k.
        k: the number of components.
        **options: ``max_iterations``, ``tolerance``, ``variance_floor`` (see :class:`GMM1D`).
    Returns:
        the fitted :class:`GMM1D`.
    Raises:
        InvalidArgumentError: bad values or options.
    """
    return GMM1D(k, **options).fit(x)


def bayes_threshold(w1: float, mu1: float, var1: float, w2: float, mu2: float, var2: float,
                    strict: bool = False) -> float:
    """The point s between mu1 and mu2 where w1 N(s; mu1, var1) = w2 N(s; mu2, var2).

    Args:
        w1, mu1, var1: weight, mean and variance of the first Gaussian.
        w2, mu2, var2: those of the second.
        strict: raise instead of returning the midpoint when there is no crossing.
    Returns:
        the threshold s; when no crossing lies strictly between the means, their midpoint.
    Raises:
        NotFoundError: no crossing and `strict`; InvalidArgumentError: bad values.
    """
    args = [as_scalar(v, n) for v, n in ((w1, 'w1'), (mu1, 'mu1'), (var1, 'var1'), (w2, 'w2'), (mu2, 'mu2'),
                                          (var2, 'var2'))]
    out = ffi.new('double *', float('nan'))
    st = lib.amscr_bayes_threshold(*args, out)
    if st == lib.AMSCR_E_NOT_FOUND and not strict and np.isfinite(out[0]):
        return float(out[0])
    _check(st)
    return float(out[0])
