"""Curve building blocks: Gaussian smoothing, resampling in Euclidean or affine arc length, whitening."""
from __future__ import annotations

from typing import Optional, Tuple

import numpy as np

from ._lib import ffi, lib
from ._util import PointArray, as_bool, as_count, as_points, as_scalar, as_uint, dbuf, m6_to_matrix, sized_arrays
from .errors import _check
from .params import Params


def gaussian_kernel(sigma: float) -> np.ndarray:
    """FIR Gaussian taps, as :func:`smooth` uses them.

    Args:
        sigma: the standard deviation, in samples (> 0).
    Returns:
        (2r + 1,) float array summing to 1, radius r = ceil(4 sigma).
    Raises:
        InvalidArgumentError: sigma not in (0, 1e6].
    """
    taps, = sized_arrays(lib.amscr_gaussian_kernel, as_scalar(sigma, 'sigma'))
    return taps


def smooth(points: PointArray, sigma: float, closed: bool = True) -> np.ndarray:
    """Gaussian smoothing of x and y.

    Args:
        points: (n, 2) points (or an OpenCV contour).
        sigma: the standard deviation, in samples; 0 copies.
        closed: circular convolution when True, mirrored at the ends ("reflect") when False.
    Returns:
        (n, 2) float array.
    Raises:
        InvalidArgumentError: bad points or sigma.
    """
    pts = as_points(points)
    out = np.empty_like(pts)
    _check(lib.amscr_smooth_gaussian(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'),
                                     as_scalar(sigma, 'sigma'), dbuf(out)))
    return out


def resample_euclidean(points: PointArray, m: int, closed: bool = True) -> np.ndarray:
    """Resamples a polygon at equal Euclidean arc length.

    Args:
        points: (n, 2) points (or an OpenCV contour).
        m: the number of output points (>= 1).
        closed: a closed polygon (the last point joins the first) or an open one.
    Returns:
        (m, 2) float array.
    Raises:
        InvalidArgumentError: bad points or m; DegenerateError: zero length.
    """
    pts = as_points(points)
    m = as_count(m, 'm', 1)
    out = np.empty((m, 2), dtype=np.float64)
    _check(lib.amscr_resample_euclidean(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'), m, dbuf(out)))
    return out


def resample_affine(points: PointArray, m: int, closed: bool = True, sigma0: Optional[float] = None,
                    passes: Optional[int] = None) -> np.ndarray:
    """Resamples a polygon at equal affine arc length.

    Args:
        points: (n, 2) points (or an OpenCV contour).
        m: the number of output points (>= 1).
        closed: a closed or an open polygon.
        sigma0: pre-smoothing, as a fraction of the curve length (None: :class:`Params`'
            ``presmooth``).
        passes: affine arc-length passes (None: :class:`Params`' ``arclength_passes``).
    Returns:
        (m, 2) float array.
    Raises:
        InvalidArgumentError: bad arguments; DegenerateError: no affine length (e.g. a straight line).
    """
    pts = as_points(points)
    m = as_count(m, 'm', 1)
    defaults = Params()
    s0 = defaults.presmooth if sigma0 is None else as_scalar(sigma0, 'sigma0')
    ps = defaults.arclength_passes if passes is None else as_uint(passes, 'passes')
    out = np.empty((m, 2), dtype=np.float64)
    _check(lib.amscr_resample_affine(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'), s0, ps, m, dbuf(out)))
    return out


def affine_arclength(points: PointArray, closed: bool = True, sigma0: float = 0.0) -> Tuple[np.ndarray, float]:
    """Affine arc length along a polygon.

    Args:
        points: (n, 2) points (or an OpenCV contour).
        closed: a closed or an open polygon.
        sigma0: pre-smoothing, as a fraction of the curve length (0: none).
    Returns:
        (cumulative length at each vertex, (n,) not normalized; the total length).
    Raises:
        InvalidArgumentError: bad arguments.
    """
    pts = as_points(points)
    cum = np.empty(pts.shape[0], dtype=np.float64)
    total = ffi.new('double *')
    _check(lib.amscr_affine_arclength(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'),
                                      as_scalar(sigma0, 'sigma0'), dbuf(cum), total))
    return cum, float(total[0])


def normalize_whiten(points: PointArray) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Affine normalization: centroid to 0, identity covariance.

    Args:
        points: (n, 2) points (or an OpenCV contour).
    Returns:
        (whitened (n, 2) points, 3x3 forward map, 3x3 inverse map).
    Raises:
        InvalidArgumentError: bad points; DegenerateError: singular covariance (collinear points).
    """
    pts = as_points(points)
    out = np.empty_like(pts)
    fwd, inv = ffi.new('double[6]'), ffi.new('double[6]')
    _check(lib.amscr_normalize_whiten(dbuf(pts), pts.shape[0], dbuf(out), fwd, inv))
    return out, m6_to_matrix(fwd), m6_to_matrix(inv)
