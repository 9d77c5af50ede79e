"""Dense least squares and affine maps (C ``amscr_lstsq_qr`` and ``amscr_affine_*``)."""
from __future__ import annotations

from typing import Literal, Tuple, Union, overload

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, PointArray, as_bool, as_float_array, as_points, bad, dbuf, m6_to_matrix, matrix_out, to_m6
from .errors import _check


@overload
def lstsq(a: ArrayLike, b: ArrayLike, return_residuals: Literal[False] = False) -> np.ndarray: ...
@overload
def lstsq(a: ArrayLike, b: ArrayLike, return_residuals: Literal[True]) -> Tuple[np.ndarray, np.ndarray]: ...
@overload
def lstsq(a: ArrayLike, b: ArrayLike, return_residuals: bool) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]: ...


def lstsq(a: ArrayLike, b: ArrayLike, return_residuals: bool = False
          ) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """Least squares min ||a x - b|| by Householder QR.

    Args:
        a: (m, n) matrix, m >= n.
        b: (m,) or (m, k) right-hand side(s).
        return_residuals: also return the residual 2-norms.
    Returns:
        x ((n,) or (n, k)), or (x, residual norms) when `return_residuals`.
    Raises:
        InvalidArgumentError: shapes that do not match, or `return_residuals` not a bool;
        NumericError: `a` rank-deficient or ill-conditioned.
    """
    want_res = as_bool(return_residuals, 'return_residuals')
    A = as_float_array(a, 'a', ndim=(2,))
    B = as_float_array(b, 'b', ndim=(1, 2))
    m, n = A.shape
    vec = B.ndim == 1
    B2 = B.reshape(-1, 1) if vec else B
    if B2.shape[0] != m:
        raise bad('b: expected %d rows (as a), got %d' % (m, B2.shape[0]))
    nrhs = B2.shape[1]
    x = np.empty((n, nrhs), dtype=np.float64)
    res = np.empty(nrhs, dtype=np.float64)
    _check(lib.amscr_lstsq_qr(dbuf(A), m, n, dbuf(np.ascontiguousarray(B2)), nrhs, dbuf(x), dbuf(res)))
    if vec:
        x, res = x[:, 0], res[:1]
    return (x, res) if want_res else x


def affine_fit(src: PointArray, dst: PointArray) -> Tuple[np.ndarray, float]:
    """Least-squares affine map taking src[i] to dst[i].

    Args:
        src: (n, 2) points, n >= 3.
        dst: (n, 2) points, the images of `src`.
    Returns:
        (3x3 matrix, RMS residual distance).
    Raises:
        InvalidArgumentError: different point counts; NumericError: collinear `src`.
    """
    s, d = as_points(src, 'src'), as_points(dst, 'dst')
    if s.shape != d.shape:
        raise bad('src and dst: expected the same number of points, got %d and %d' % (s.shape[0], d.shape[0]))
    m = ffi.new('double[6]')
    rms = ffi.new('double *')
    _check(lib.amscr_affine_fit(dbuf(s), dbuf(d), s.shape[0], m, rms))
    return m6_to_matrix(m), float(rms[0])


def affine_apply(matrix: ArrayLike, points: PointArray) -> np.ndarray:
    """Applies an affine map to points.

    Args:
        matrix: 3x3 (last row 0, 0, 1), 2x3 or flat 6 affine matrix.
        points: (n, 2) points (or an OpenCV contour); n may be 0.
    Returns:
        (n, 2) float array.
    Raises:
        InvalidArgumentError: a bad matrix or points.
    """
    m = to_m6(matrix)
    pts = as_points(points, allow_empty=True)
    out = np.empty_like(pts)
    if pts.shape[0]:
        _check(lib.amscr_affine_apply(dbuf(m), dbuf(pts), pts.shape[0], dbuf(out)))
    return out


def affine_invert(matrix: ArrayLike) -> np.ndarray:
    """Inverse of an affine map.

    Args:
        matrix: 3x3 (last row 0, 0, 1), 2x3 or flat 6 affine matrix.
    Returns:
        3x3 matrix.
    Raises:
        InvalidArgumentError: a bad matrix; DegenerateError: singular.
    """
    m = to_m6(matrix)
    return matrix_out(lib.amscr_affine_invert, dbuf(m))
