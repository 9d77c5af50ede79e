"""amscr — affine multi-scale registration and retrieval of 2-D shapes (Python bindings of libamscr).

Quick start::

    import numpy as np, amscr
    r = amscr.register(src, tgt)              # src, tgt: (n, 2) arrays of contour points
    r.A, r.B, r.distance, r.apply(src)        # tgt ~= src @ r.A.T + r.B

    db = amscr.Collection(reflections=True)
    for pts, cls in shapes:
        db.add(pts, label=cls)
    D = db.distance_matrix(progress=True)      # GIL released, POSIX threads in C
    amscr.bullseye(D, db.labels)

Points are NumPy arrays of shape (n, 2) (x, y rows); any array-like of real numbers is accepted
and validated (finite, at least one point) before it reaches C. Affine maps are returned as 3x3
matrices. C failures raise subclasses of :class:`AmscrError` (``amscr.Error``) that carry the
library's message. Library handles are freed automatically. The GIL is released during every C
call (cffi does that in both API and ABI mode), so Python threads run registrations in parallel.
"""
from __future__ import annotations

import contextlib
import os
import threading
from typing import Any, Dict, Iterable, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from ._lib import API_MODE, LIBRARY_PATH, SOVERSION, ffi, lib
from ._version import __version__
from . import errors
from .errors import (AmscrError, CancelledError, DegenerateError, Error, FileError, FormatError,
                     InternalError, InvalidArgumentError, IOError_, LimitError, NoMemoryError, NotConvergedError,
                     NotFoundError, NumericalError, NumericError, StateError, UnsupportedError, _check)
from ._util import (ProgressArg, RWLock, as_bool, as_count, as_float_array, as_points, as_scalar, bad,
                    copy_doubles, dbuf, factorize, m6_to_matrix, matrix_out, progress_call, to_m6)

try:
    from numpy.typing import ArrayLike
except ImportError:  # numpy < 1.20
    ArrayLike = Any  # type: ignore

__all__ = [
    'rerank_diffusion',
    '__version__', 'API_MODE', 'SOVERSION', 'LIBRARY_PATH', 'library_version', 'has_threads', 'errors',
    # errors
    'AmscrError', 'Error', 'InvalidArgumentError', 'NoMemoryError', 'FileError', 'IOError_', 'FormatError',
    'UnsupportedError', 'DegenerateError', 'NumericError', 'NumericalError', 'NotConvergedError',
    'NotFoundError', 'StateError', 'InternalError', 'CancelledError', 'LimitError',
    # registration and retrieval
    'Params', 'Shape', 'Registration', 'Mixture', 'register', 'distance', 'Collection', 'distance_matrix',
    'bullseye', 'topk_table', 'nn_accuracy', 'nn_split', 'topk',
    # contours
    'contour_from_mask', 'read_points', 'parse_points', 'write_points', 'signed_area', 'orient_ccw',
    'validate_contour',
    # building blocks
    'smooth', 'gaussian_kernel', 'resample_euclidean', 'resample_affine', 'affine_arclength',
    'normalize_whiten', 'lstsq', 'affine_fit', 'affine_apply', 'affine_invert',
    'kmeans', 'KMeansResult', 'elbow', 'GMM1D', 'gmm1d', 'bayes_threshold',
]

PointsLike = Union[ArrayLike, 'Shape']


def library_version() -> str:
    """Version string of the loaded C library ("M.m.p")."""
    return ffi.string(lib.amscr_version_string()).decode()


def has_threads() -> bool:
    """True when the loaded library runs batch calls on POSIX threads."""
    return bool(lib.amscr_has_feature(lib.AMSCR_FEATURE_THREADS))


# ======================================================================================== enums
_METHODS = {'acma': lib.AMSCR_METHOD_ACMA, 'amscr': lib.AMSCR_METHOD_AMSCR,
            'binary-em': lib.AMSCR_METHOD_BINARY_EM, 'multiclass-em': lib.AMSCR_METHOD_MULTICLASS_EM}
_PARAMETRIZATIONS = {'affine': lib.AMSCR_PARAM_AFFINE, 'euclidean': lib.AMSCR_PARAM_EUCLIDEAN,
                     'whitened': lib.AMSCR_PARAM_WHITENED}
_INVARIANCES = {'affine': lib.AMSCR_INVARIANCE_AFFINE, 'similarity': lib.AMSCR_INVARIANCE_SIMILARITY,
                'penalized': lib.AMSCR_INVARIANCE_PENALIZED}


def _enum_in(table: Dict[str, int], value: Any, what: str) -> int:
    if isinstance(value, str):
        key = value.strip().lower().replace('_', '-')
        if key in table:
            return table[key]
    raise bad('%s: expected one of %s, got %r' % (what, ', '.join(repr(k) for k in table), value))


def _enum_out(table: Dict[str, int], value: int) -> str:
    for k, v in table.items():
        if v == int(value):
            return k
    return str(int(value))


# ======================================================================================== Params
class Params:
    """Options of shape preparation and matching (a copy of the C ``amscr_params``).

    Every option is a keyword of the constructor and an attribute; ``None`` leaves the library's
    default. Options:

    ``points``          N, samples per scale (library default 128)
    ``scales``          the smoothing scales sigma_k, in samples of the N-point curve
    ``method``          'acma', 'amscr', 'binary-em' or 'multiclass-em' (default)
    ``closed``          closed (default) or open curves
    ``reflections``     also try the mirrored target
    ``parametrization`` 'whitened' (default), 'affine' (the paper's affine arc length) or 'euclidean'
    ``presmooth``       pre-smoothing of the parametrization, fraction of the curve length
    ``arclength_passes`` parametrization passes
    ``oversampling``    dense resampling factor
    ``kmax``            Kmax of the elbow
    ``symmetric``       symmetric distance (average of both directions)
    ``refine``          refinement iterations in the aligned frame (0 = the paper's method)
    ``threads``         threads of batch calls (0 = all cores)
    ``invariance``      'affine' (default), 'similarity' or 'penalized'
    ``penalty``         weight of the 'penalized' invariance
    ``partial``         the source is an open fragment of the target's closed boundary (register)
    """

    OPTIONS = ('points', 'scales', 'method', 'closed', 'reflections', 'parametrization', 'presmooth',
               'arclength_passes', 'oversampling', 'kmax', 'symmetric', 'refine', 'threads', 'invariance',
               'penalty', 'partial')

    def __init__(self, **options: Any):
        out = ffi.new('amscr_params **')
        _check(lib.amscr_params_new(out))
        self._p = ffi.gc(out[0], lib.amscr_params_free)
        self.update(**options)

    @classmethod
    def registration(cls, **options: Any) -> 'Params':
        """The registration preset (C ``amscr_params_new_registration``): the defaults with
        N = 256 and 20 refinement iterations, for registering single pairs robustly; the
        plain defaults (N = 128, no refinement) are tuned for collections."""
        self = cls.__new__(cls)
        out = ffi.new('amscr_params **')
        _check(lib.amscr_params_new_registration(out))
        self._p = ffi.gc(out[0], lib.amscr_params_free)
        self.update(**options)
        return self

    @classmethod
    def _copy_of(cls, ptr) -> 'Params':
        """A new Params holding a deep copy of the C params at `ptr` (borrowed)."""
        if ptr == ffi.NULL:
            raise InternalError('NULL params from the library', lib.AMSCR_E_INTERNAL)
        self = cls.__new__(cls)
        out = ffi.new('amscr_params **')
        _check(lib.amscr_params_copy(ptr, out))
        self._p = ffi.gc(out[0], lib.amscr_params_free)
        return self

    def copy(self, **options: Any) -> 'Params':
        """A copy, with `options` changed."""
        p = Params._copy_of(self._p)
        p.update(**options)
        return p

    def update(self, **options: Any) -> 'Params':
        """Sets the given options (None values are skipped); returns self."""
        for k, v in options.items():
            if k == 'num_samples':
                k = 'points'
            elif k == 'num_threads':
                k = 'threads'
            if k not in self.OPTIONS:
                raise TypeError('unknown amscr option %r (expected one of %s)' % (k, ', '.join(self.OPTIONS)))
            if v is not None:
                setattr(self, k, v)
        return self

    def to_dict(self) -> Dict[str, Any]:
        """Every option and its value."""
        return {k: getattr(self, k) for k in self.OPTIONS}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Params):
            return NotImplemented
        a, b = self.to_dict(), other.to_dict()
        return all(np.array_equal(a[k], b[k]) if k == 'scales' else a[k] == b[k] for k in a)

    __hash__ = None  # type: ignore  # mutable

    def __repr__(self) -> str:
        d = self.to_dict()
        d['scales'] = [float(x) for x in d['scales']]
        return 'Params(%s)' % ', '.join('%s=%r' % kv for kv in d.items())

    def __reduce__(self):
        d = self.to_dict()
        d['scales'] = [float(x) for x in d['scales']]
        return (_params_from_dict, (d,))

    # -- options -----------------------------------------------------------------------
    @property
    def points(self) -> int:
        """N, the samples per scale."""
        return int(lib.amscr_params_get_num_samples(self._p))

    @points.setter
    def points(self, v: int) -> None:
        _check(lib.amscr_params_set_num_samples(self._p, as_count(v, 'points', 0)))

    @property
    def scales(self) -> np.ndarray:
        """The scales sigma_k (samples of the N-point curve), a float array."""
        n = ffi.new('size_t *', 0)
        _check(lib.amscr_params_get_scales(self._p, ffi.NULL, n))
        out = np.zeros(int(n[0]), dtype=np.float64)
        if n[0]:
            _check(lib.amscr_params_get_scales(self._p, dbuf(out), n))
        return out[:int(n[0])]

    @scales.setter
    def scales(self, v: ArrayLike) -> None:
        a = as_float_array(v, 'scales', ndim=(1,), finite=False)
        _check(lib.amscr_params_set_scales(self._p, dbuf(a), a.shape[0]))

    @property
    def method(self) -> str:
        return _enum_out(_METHODS, lib.amscr_params_get_method(self._p))

    @method.setter
    def method(self, v: str) -> None:
        _check(lib.amscr_params_set_method(self._p, _enum_in(_METHODS, v, 'method')))

    @property
    def closed(self) -> bool:
        return bool(lib.amscr_params_get_closed(self._p))

    @closed.setter
    def closed(self, v: bool) -> None:
        _check(lib.amscr_params_set_closed(self._p, as_bool(v, 'closed')))

    @property
    def reflections(self) -> bool:
        return bool(lib.amscr_params_get_reflections(self._p))

    @reflections.setter
    def reflections(self, v: bool) -> None:
        _check(lib.amscr_params_set_reflections(self._p, as_bool(v, 'reflections')))

    @property
    def parametrization(self) -> str:
        return _enum_out(_PARAMETRIZATIONS, lib.amscr_params_get_parametrization(self._p))

    @parametrization.setter
    def parametrization(self, v: str) -> None:
        _check(lib.amscr_params_set_parametrization(self._p, _enum_in(_PARAMETRIZATIONS, v, 'parametrization')))

    @property
    def presmooth(self) -> float:
        return float(lib.amscr_params_get_presmooth(self._p))

    @presmooth.setter
    def presmooth(self, v: float) -> None:
        _check(lib.amscr_params_set_presmooth(self._p, as_scalar(v, 'presmooth')))

    @property
    def arclength_passes(self) -> int:
        return int(lib.amscr_params_get_arclength_passes(self._p))

    @arclength_passes.setter
    def arclength_passes(self, v: int) -> None:
        _check(lib.amscr_params_set_arclength_passes(self._p, _uint(v, 'arclength_passes')))

    @property
    def oversampling(self) -> int:
        return int(lib.amscr_params_get_oversampling(self._p))

    @oversampling.setter
    def oversampling(self, v: int) -> None:
        _check(lib.amscr_params_set_oversampling(self._p, _uint(v, 'oversampling')))

    @property
    def kmax(self) -> int:
        return int(lib.amscr_params_get_kmax(self._p))

    @kmax.setter
    def kmax(self, v: int) -> None:
        _check(lib.amscr_params_set_kmax(self._p, _uint(v, 'kmax')))

    @property
    def symmetric(self) -> bool:
        return bool(lib.amscr_params_get_symmetric(self._p))

    @symmetric.setter
    def symmetric(self, v: bool) -> None:
        _check(lib.amscr_params_set_symmetric(self._p, as_bool(v, 'symmetric')))

    @property
    def refine(self) -> int:
        return int(lib.amscr_params_get_refine(self._p))

    @refine.setter
    def refine(self, v: int) -> None:
        _check(lib.amscr_params_set_refine(self._p, _uint(v, 'refine')))

    @property
    def threads(self) -> int:
        """Threads of batch calls (0 = all cores)."""
        return int(lib.amscr_params_get_num_threads(self._p))

    @threads.setter
    def threads(self, v: int) -> None:
        _check(lib.amscr_params_set_num_threads(self._p, _uint(v, 'threads')))

    @property
    def invariance(self) -> str:
        return _enum_out(_INVARIANCES, lib.amscr_params_get_invariance(self._p))

    @invariance.setter
    def invariance(self, v: str) -> None:
        _check(lib.amscr_params_set_invariance(self._p, _enum_in(_INVARIANCES, v, 'invariance')))

    @property
    def penalty(self) -> float:
        return float(lib.amscr_params_get_penalty(self._p))

    @penalty.setter
    def penalty(self, v: float) -> None:
        _check(lib.amscr_params_set_penalty(self._p, as_scalar(v, 'penalty')))

    @property
    def partial(self) -> bool:
        return bool(lib.amscr_params_get_partial(self._p))

    @partial.setter
    def partial(self, v: bool) -> None:
        _check(lib.amscr_params_set_partial(self._p, 1 if v else 0))


def _uint(v: Any, name: str) -> int:
    v = as_count(v, name, 0)
    if v > 0xFFFFFFFF:
        raise bad('%s: too large (%d)' % (name, v))
    return v


def _params_from_dict(d: Dict[str, Any]) -> Params:
    return Params(**d)


def _make_params(params: Optional[Params], options: Dict[str, Any]) -> Params:
    """A fresh Params: a copy of `params` (or the defaults) with `options` applied."""
    if params is not None and not isinstance(params, Params):
        raise TypeError('params: expected amscr.Params, got %s' % type(params).__name__)
    p = params.copy() if params is not None else Params()
    p.update(**options)
    return p


# ====================================================================================== contours
def _contour_new(pts: np.ndarray):
    out = ffi.new('amscr_contour **')
    _check(lib.amscr_contour_new(dbuf(pts), pts.shape[0], out))
    return ffi.gc(out[0], lib.amscr_contour_free)


def _contour_take(out) -> np.ndarray:
    """Copies an owned contour (from an `amscr_contour **` just filled) into numpy and frees it."""
    c = ffi.gc(out[0], lib.amscr_contour_free)
    n = int(lib.amscr_contour_size(c))
    pts = copy_doubles(lib.amscr_contour_xy(c), 2 * n).reshape(n, 2)
    ffi.release(c)
    return pts


def contour_from_mask(mask: ArrayLike, threshold: Union[int, str, None] = None) -> np.ndarray:
    """Outer boundary of the largest 8-connected foreground component of a 2-D image.

    Args:
        mask: 2-D NumPy array, ``bool`` (True = foreground; stored as 0/255) or ``uint8`` (other
            integer arrays with values in 0..255 are accepted too); any strides or order.
        threshold: a pixel is "on" when its value is > threshold (0..254); ``'auto'`` for Otsu's
            threshold; None for 127 (the ``amscr`` tool's default). The polarity is automatic:
            if most of the image border is "on", on and off are swapped.
    Returns:
        (n, 2) float array of boundary pixel centres (x = column, y = row), with positive signed
        area (counter-clockwise in a y-up frame), no repeated end point.
    Raises:
        NotFoundError: no foreground (or foreground everywhere); DegenerateError: too small;
        LimitError: image too large.
    """
    a = np.asarray(mask)
    if a.ndim != 2:
        raise bad('mask: expected a 2-D array, got shape %s' % (a.shape,))
    if a.dtype == np.bool_:
        a = np.where(a, np.uint8(255), np.uint8(0))
    elif a.dtype != np.uint8:
        if a.dtype.kind not in 'iu':
            raise bad('mask: expected a bool or uint8 array, got dtype %s' % a.dtype)
        if a.size and (a.min() < 0 or a.max() > 255):
            raise bad('mask: values must be in 0..255 for dtype %s (got %d..%d)' % (a.dtype, a.min(), a.max()))
        a = a.astype(np.uint8)
    a = np.ascontiguousarray(a)
    if threshold is None:
        thr = 127
    elif isinstance(threshold, str):
        if threshold.strip().lower() not in ('auto', 'otsu'):
            raise bad("threshold: expected 0..254, 'auto' or None, got %r" % threshold)
        thr = lib.AMSCR_THRESHOLD_AUTO
    else:
        thr = as_count(threshold, 'threshold', 0)
        if thr > 0x7FFFFFFF:
            raise bad('threshold: expected 0..254, got %d' % thr)
    h, w = a.shape
    out = ffi.new('amscr_contour **')
    _check(lib.amscr_contour_from_mask(ffi.from_buffer('uint8_t[]', a), w, h, w, thr, out))
    return _contour_take(out)


def read_points(path: Union[str, os.PathLike]) -> np.ndarray:
    """Reads a text point list ("x y" or "x,y" per line, '#' comments) as an (n, 2) array.

    Raises FileError (cannot read) or FormatError (a bad line; the message names path:line).
    """
    out = ffi.new('amscr_contour **')
    _check(lib.amscr_contour_read_text(os.fsencode(path), out))
    return _contour_take(out)


def parse_points(text: Union[str, bytes]) -> np.ndarray:
    """Parses a text point list from a string (the format of :func:`read_points`)."""
    b = text.encode('utf-8') if isinstance(text, str) else bytes(text)
    out = ffi.new('amscr_contour **')
    _check(lib.amscr_contour_parse_text(ffi.from_buffer('char[]', b), len(b), out))
    return _contour_take(out)


def write_points(path: Union[str, os.PathLike], points: ArrayLike) -> None:
    """Writes points as a text point list, atomically (temporary file + rename)."""
    c = _contour_new(as_points(points))
    _check(lib.amscr_contour_write_text(c, os.fsencode(path)))


def signed_area(points: ArrayLike) -> float:
    """Signed area of the closed polygon (positive = counter-clockwise in a y-up frame)."""
    c = _contour_new(as_points(points))
    out = ffi.new('double *')
    _check(lib.amscr_contour_signed_area(c, out))
    return float(out[0])


def orient_ccw(points: ArrayLike) -> np.ndarray:
    """A copy of the points, reversed when their signed area is negative."""
    c = _contour_new(as_points(points))
    _check(lib.amscr_contour_orient_ccw(c))
    n = int(lib.amscr_contour_size(c))
    return copy_doubles(lib.amscr_contour_xy(c), 2 * n).reshape(n, 2)


def validate_contour(points: ArrayLike, closed: bool = True) -> None:
    """Raises DegenerateError when the contour cannot be registered (too few distinct points,
    zero area when closed, all collinear when open)."""
    c = _contour_new(as_points(points))
    _check(lib.amscr_contour_validate(c, as_bool(closed, 'closed')))


# ==================================================================================== workspaces
_tls = threading.local()


def _workspace():
    """The calling thread's workspace (scratch memory reused across registrations)."""
    ws = getattr(_tls, 'ws', None)
    if ws is None:
        out = ffi.new('amscr_workspace **')
        _check(lib.amscr_workspace_new(out))
        ws = _tls.ws = ffi.gc(out[0], lib.amscr_workspace_free)
    return ws


# ========================================================================================= Shape
class Shape:
    """A prepared shape (C ``amscr_descriptor``): resampled, parametrized, whitened and smoothed at
    every scale once, then matched any number of times. Immutable; shareable between threads.

    ``Shape(contour, params=None, **options)`` — `contour` is an (n, 2) point array; the options
    are those of :class:`Params` (e.g. ``Shape(pts, points=256)``).
    """

    def __init__(self, contour: ArrayLike, /, params: Optional[Params] = None, **options: Any):
        pts = as_points(contour, 'contour')
        p = _make_params(params, options)
        c = _contour_new(pts)
        out = ffi.new('amscr_descriptor **')
        _check(lib.amscr_descriptor_new(p._p, c, out))
        self._d = ffi.gc(out[0], lib.amscr_descriptor_free)
        self._owner = None
        self._source: Optional[np.ndarray] = pts.copy()

    @classmethod
    def _borrowed(cls, dptr, owner: Any) -> 'Shape':
        """A view of a descriptor owned by `owner`, which the view keeps alive and which must
        never be modified (see Collection.shape)."""
        if dptr == ffi.NULL:
            raise IndexError('no such shape')
        self = cls.__new__(cls)
        self._d = dptr
        self._owner = owner
        self._source = None
        return self

    @property
    def num_samples(self) -> int:
        """N, samples per scale."""
        return int(lib.amscr_descriptor_num_samples(self._d))

    @property
    def num_scales(self) -> int:
        """p, the number of scales."""
        return int(lib.amscr_descriptor_num_scales(self._d))

    def __len__(self) -> int:
        return self.num_samples

    @property
    def points(self) -> np.ndarray:
        """(N, 2) normalized (centred, whitened), unsmoothed points."""
        n = self.num_samples
        return copy_doubles(lib.amscr_descriptor_base_points(self._d), 2 * n).reshape(n, 2)

    def scale_points(self, k: int) -> np.ndarray:
        """(N, 2) normalized points smoothed at scale k (0 <= k < num_scales)."""
        k = as_count(k, 'k', 0)
        if k >= self.num_scales:
            raise IndexError('scale %d out of range (the shape has %d scales)' % (k, self.num_scales))
        n = self.num_samples
        return copy_doubles(lib.amscr_descriptor_scale_points(self._d, k), 2 * n).reshape(n, 2)

    @property
    def input_points(self) -> np.ndarray:
        """(N, 2) sampled points in input coordinates (before normalization)."""
        n = self.num_samples
        return copy_doubles(lib.amscr_descriptor_input_points(self._d), 2 * n).reshape(n, 2)

    @property
    def normalization(self) -> np.ndarray:
        """3x3 affine matrix taking input coordinates to the normalized frame."""
        return matrix_out(lib.amscr_descriptor_normalization, self._d)

    @property
    def params(self) -> Params:
        """A copy of the options the shape was prepared with."""
        return Params._copy_of(lib.amscr_descriptor_params(self._d))

    @property
    def closed(self) -> bool:
        return bool(lib.amscr_params_get_closed(lib.amscr_descriptor_params(self._d)))

    def __repr__(self) -> str:
        return 'Shape(N=%d, scales=%d)' % (self.num_samples, self.num_scales)

    def __reduce__(self):
        src = self._source if self._source is not None else self.input_points
        return (_shape_from_state, (src, self.params))


def _shape_from_state(points: np.ndarray, params: Params) -> Shape:
    return Shape(points, params)


def _as_shape(x: PointsLike, params: Params, name: str) -> Shape:
    if isinstance(x, Shape):
        return x
    return Shape(as_points(x, name), params)


# ================================================================================== registration
class Mixture(NamedTuple):
    """The 1-D Gaussian mixture of the per-scale residuals (components sorted by mean)."""
    weights: np.ndarray
    means: np.ndarray
    variances: np.ndarray


def _sized_doubles(fn, handle) -> np.ndarray:
    n = ffi.new('size_t *', 0)
    _check(fn(handle, ffi.NULL, n))
    out = np.zeros(int(n[0]), dtype=np.float64)
    if n[0]:
        _check(fn(handle, dbuf(out), n))
    return out[:int(n[0])]


class Registration:
    """The result of :func:`register`: the affine map taking the source onto the target and the
    diagnostics of scale selection. Every array is a NumPy copy (nothing refers to C memory).

    Attributes:
        A: (2, 2) linear part, in input coordinates: ``tgt ~= src @ A.T + B``.
        B: (2,) translation.
        matrix: (3, 3) homogeneous form of (A, B).
        matrix_normalized: (3, 3) the same map between the normalized frames.
        distance: affine-invariant distance (target's normalized frame).
        residuals: (p,) per-scale residuals L2_k (eq. 13).
        scales: (p,) the scales sigma_k.
        kept: (p,) bool, the scales kept by the selection.
        kept_scales: the sigma_k kept.
        k: K chosen by the elbow (2 for binary-em, 0 for acma/amscr).
        sse: SSE(K) for K = 1..Kmax of the elbow.
        mixture: :class:`Mixture` found by EM.
        threshold: the Bayes threshold s0 (inf when every scale is kept without one).
        shift: start shift (source sample a <-> target sample (a + shift) mod N).
        reflected: True when the match used the mirrored target.
        method: the method used.
        confidence: how sure the map is, in [0, 1] ((1 - ambiguity) x inlier_fraction; reject
            maps below about 0.25 — see the README's accuracy section).
        ambiguity: cost of the chosen map over that of the best clearly different candidate
            (1: a symmetric shape or a fragment that fits several places).
        inlier_fraction: share of source samples within 5 % of the target's size of its boundary.
        part: (start, end) fractions of the target's boundary the source's first and last samples
            fall on (where a fragment lies, with partial=True).
        correspondences: (N,) target boundary parameter (fraction) matched to each source sample.
        source_samples: (N, 2) the source samples (input coordinates).
        target_points: (N, 2) the matched target boundary points (input coordinates).
    """

    def __init__(self, handle, scales: np.ndarray):
        r = handle
        self.distance = float(lib.amscr_result_distance(r))
        self.matrix = matrix_out(lib.amscr_result_affine, r)
        self.matrix_normalized = matrix_out(lib.amscr_result_affine_normalized, r)
        self.A = self.matrix[:2, :2].copy()
        self.B = self.matrix[:2, 2].copy()
        self.shift = int(lib.amscr_result_shift(r))
        self.reflected = bool(lib.amscr_result_reflected(r))
        self.method = _enum_out(_METHODS, lib.amscr_result_method(r))
        self.residuals = _sized_doubles(lib.amscr_result_residuals, r)
        n = ffi.new('size_t *', 0)
        _check(lib.amscr_result_kept(r, ffi.NULL, n))
        kept = np.zeros(int(n[0]), dtype=np.intc)
        if n[0]:
            _check(lib.amscr_result_kept(r, ffi.from_buffer('int[]', kept), n))
        self.kept = kept[:int(n[0])].astype(bool)
        self.scales = np.asarray(scales, dtype=np.float64).copy()
        self.kept_scales = self.scales[self.kept] if self.scales.shape == self.kept.shape else self.scales[:0]
        self.k = int(lib.amscr_result_k(r))
        self.sse = _sized_doubles(lib.amscr_result_sse, r)
        n = ffi.new('size_t *', 0)
        _check(lib.amscr_result_mixture(r, ffi.NULL, ffi.NULL, ffi.NULL, n))
        k = int(n[0])
        w, m, v = (np.zeros(k) for _ in range(3))
        if k:
            _check(lib.amscr_result_mixture(r, dbuf(w), dbuf(m), dbuf(v), n))
        self.mixture = Mixture(w, m, v)
        self.threshold = float(lib.amscr_result_threshold(r))
        self.confidence = float(lib.amscr_result_confidence(r))
        self.ambiguity = float(lib.amscr_result_ambiguity(r))
        self.inlier_fraction = float(lib.amscr_result_inlier_fraction(r))
        part = ffi.new('double[2]')
        _check(lib.amscr_result_part(r, part, part + 1))
        self.part = (float(part[0]), float(part[1]))
        n = ffi.new('size_t *', 0)
        _check(lib.amscr_result_correspondences(r, ffi.NULL, ffi.NULL, ffi.NULL, n))
        m = int(n[0])
        src, par, tgt = np.zeros((m, 2)), np.zeros(m), np.zeros((m, 2))
        if m:
            _check(lib.amscr_result_correspondences(r, dbuf(src), dbuf(par), dbuf(tgt), n))
        self.source_samples, self.correspondences, self.target_points = src, par, tgt

    def apply(self, points: ArrayLike) -> np.ndarray:
        """The registered source: ``points @ A.T + B`` for (n, 2) points in source coordinates."""
        return as_points(points) @ self.A.T + self.B

    def __repr__(self) -> str:
        return ('Registration(distance=%.6g, method=%r, kept %d/%d scales, k=%d, shift=%d, reflected=%s)'
                % (self.distance, self.method, int(self.kept.sum()), self.kept.size, self.k, self.shift,
                   self.reflected))


def _pair(src: PointsLike, tgt: PointsLike, params: Optional[Params], options: Dict[str, Any]
          ) -> Tuple[Params, Shape, Shape]:
    base = params
    if base is None:
        first = src if isinstance(src, Shape) else tgt if isinstance(tgt, Shape) else None
        # prepared shapes bring their own settings; raw points get the registration preset
        base = first.params if first is not None else Params.registration()
    p = _make_params(base, options)
    if p.partial:  # the source prepared open, the target closed
        return p, _as_shape(src, p.copy(closed=False), 'src'), _as_shape(tgt, p.copy(closed=True), 'tgt')
    return p, _as_shape(src, p, 'src'), _as_shape(tgt, p, 'tgt')


def register(src: PointsLike, tgt: PointsLike, *, method: Optional[str] = None, points: Optional[int] = None,
             scales: Optional[ArrayLike] = None, reflections: Optional[bool] = None,
             closed: Optional[bool] = None, refine: Optional[int] = None, symmetric: Optional[bool] = None,
             parametrization: Optional[str] = None, invariance: Optional[str] = None,
             params: Optional[Params] = None, **options: Any) -> Registration:
    """Registers `src` onto `tgt`: finds (A, B) with ``tgt ~= A @ src + B`` and the distance.

    Args:
        src, tgt: (n, 2) point arrays (contours, closed by default) or prepared :class:`Shape` s.
        method: 'multiclass-em' (default), 'binary-em', 'amscr' or 'acma'.
        points: N, samples per scale (default 128).
        scales: the smoothing scales sigma_k (samples of the N-point curve).
        reflections: also try the mirrored target.
        closed: closed (default) or open curves.
        refine: refinement iterations in the aligned frame (trimmed closest-point pairs, started
            from AMSCR's global estimate); 0 gives the paper's method.
        symmetric: symmetric distance.
        parametrization: 'affine', 'euclidean' or 'whitened'.
        invariance: 'affine', 'similarity' or 'penalized'.
        params: a :class:`Params` to start from; other keywords of :class:`Params` are accepted.

    Options left as None take the registration preset (:meth:`Params.registration`: N = 256,
    20 refinement iterations, as the ``amscr register`` tool), or the settings of a given Shape
    (the options of preparation, N, scales, closed and parametrization, must then agree with the
    shapes').
    """
    options.update(method=method, points=points, scales=scales, reflections=reflections, closed=closed,
                   refine=refine, symmetric=symmetric, parametrization=parametrization, invariance=invariance)
    p, s, t = _pair(src, tgt, params, options)
    out = ffi.new('amscr_result **')
    _check(lib.amscr_register(p._p, s._d, t._d, _workspace(), out))
    r = ffi.gc(out[0], lib.amscr_result_free)
    res = Registration(r, p.scales)
    ffi.release(r)
    return res


def distance(src: PointsLike, tgt: PointsLike, *, params: Optional[Params] = None, **options: Any) -> float:
    """The distance only (the fast batch path; equal to ``register(...).distance`` to rounding)."""
    p, s, t = _pair(src, tgt, params, options)
    out = ffi.new('double *')
    _check(lib.amscr_distance(p._p, s._d, t._d, _workspace(), out))
    return float(out[0])


# ==================================================================================== Collection
class Collection:
    """Many prepared shapes with labels (C ``amscr_db``), for 1-vs-many queries and distance matrices.

    ``Collection(params=None, **options)`` — the options are those of :class:`Params`; every shape
    is prepared with them. Batch calls run on ``threads`` POSIX threads (0 = all cores) with the
    GIL released, and give bit-identical results for any thread count.

    Labels are int32 values, or any other hashable values (e.g. strings), which are mapped to
    codes 0, 1, ... in order of first use (:attr:`labels` gives them back; saved files hold codes).
    Thread-safety: any number of threads may query at once; :meth:`add` waits for them.
    """

    def __init__(self, params: Optional[Params] = None, **options: Any):
        p = _make_params(params, options)
        out = ffi.new('amscr_db **')
        _check(lib.amscr_db_new(p._p, out))
        self._init(out[0])

    def _init(self, ptr, label_names: Optional[Sequence[Any]] = None) -> None:
        self._db = ffi.gc(ptr, lib.amscr_db_free)
        self._lock = RWLock()
        self._label_names: Optional[List[Any]] = list(label_names) if label_names is not None else None
        self._label_codes: Dict[Any, int] = ({n: i for i, n in enumerate(self._label_names)}
                                             if self._label_names is not None else {})
        # a loaded collection without names holds int labels already
        self._int_labels = self._label_names is None and int(lib.amscr_db_size(ptr)) > 0

    @classmethod
    def _wrap(cls, ptr, label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        self = cls.__new__(cls)
        self._init(ptr, label_names)
        return self

    # -- building ---------------------------------------------------------------------
    def _label_code(self, label: Any) -> int:
        if isinstance(label, (bool, np.bool_)):
            raise bad('label: expected an int or a name, got a bool')
        if isinstance(label, (int, np.integer)):
            if self._label_names is not None:
                raise bad('label: this collection uses named labels; got the int %r' % (label,))
            v = int(label)
            if not -(2 ** 31) <= v < 2 ** 31:
                raise bad('label: %d does not fit in int32' % v)
            self._int_labels = True
            return v
        if self._int_labels:
            raise bad('label: this collection uses int labels; got %r' % (label,))
        try:
            hash(label)
        except TypeError:
            raise bad('label: expected an int or a hashable name, got %r' % (label,)) from None
        if self._label_names is None:
            self._label_names = []
        code = self._label_codes.get(label)
        if code is None:
            code = self._label_codes[label] = len(self._label_names)
            self._label_names.append(label)
        return code

    def add(self, shape: PointsLike, label: Any = 0) -> int:
        """Prepares (points) or copies (a :class:`Shape`) a shape into the collection; returns its index."""
        with self._lock.write():
            code = self._label_code(label)
            idx = ffi.new('size_t *')
            if isinstance(shape, Shape):
                _check(lib.amscr_db_add_descriptor(self._db, shape._d, code, idx))
            else:
                c = _contour_new(as_points(shape, 'shape'))
                _check(lib.amscr_db_add_contour(self._db, c, code, idx))
            return int(idx[0])

    def extend(self, shapes: Iterable[PointsLike], labels: Optional[Iterable[Any]] = None) -> List[int]:
        """Adds many shapes (labels default to 0); returns their indices."""
        shapes = list(shapes)
        labels = [0] * len(shapes) if labels is None else list(labels)
        if len(labels) != len(shapes):
            raise bad('extend: %d shapes but %d labels' % (len(shapes), len(labels)))
        return [self.add(s, lab) for s, lab in zip(shapes, labels)]

    # -- reading ----------------------------------------------------------------------
    def __len__(self) -> int:
        return int(lib.amscr_db_size(self._db))

    @property
    def label_codes(self) -> np.ndarray:
        """The int32 labels stored in C."""
        with self._lock.read():
            n = len(self)
            return np.fromiter((lib.amscr_db_label(self._db, i) for i in range(n)), dtype=np.int32, count=n)

    @property
    def labels(self) -> np.ndarray:
        """The labels as given to :meth:`add` (int32 array, or an object array of names)."""
        codes = self.label_codes
        if self._label_names is None:
            return codes
        out = np.empty(codes.shape[0], dtype=object)
        for i, c in enumerate(codes):
            out[i] = self._label_names[c] if 0 <= c < len(self._label_names) else c
        return out

    @property
    def params(self) -> Params:
        """A copy of the collection's options."""
        return Params._copy_of(lib.amscr_db_params(self._db))

    def shape(self, i: int) -> Shape:
        """A copy of the prepared shape i (negative indices count from the end).

        A copy, because the C collection's own descriptors are only valid until it is modified."""
        with self._lock.read():
            n = len(self)
            i = int(i)
            if i < 0:
                i += n
            if not 0 <= i < n:
                raise IndexError('shape index %d out of range (%d shapes)' % (i, n))
            holder = Collection(self.params)  # a private, never modified, one-shape collection
            _check(lib.amscr_db_add_descriptor(holder._db, lib.amscr_db_descriptor(self._db, i), 0, ffi.NULL))
        return Shape._borrowed(lib.amscr_db_descriptor(holder._db, 0), holder)

    def __repr__(self) -> str:
        return 'Collection(%d shapes)' % len(self)

    # -- matching ---------------------------------------------------------------------
    def _with_threads(self, threads: Optional[int]) -> Tuple['Collection', bool]:
        """(a collection computing with `threads`, whether it is a temporary copy)."""
        if threads is None or int(threads) == self.params.threads:
            return self, False
        tmp = Collection(self.params, threads=threads)
        for i in range(len(self)):
            _check(lib.amscr_db_add_descriptor(tmp._db, lib.amscr_db_descriptor(self._db, i), 0, ffi.NULL))
        return tmp, True

    def query(self, shape: PointsLike, threads: Optional[int] = None, progress: ProgressArg = False) -> np.ndarray:
        """Distances from `shape` (points or a :class:`Shape`) to every shape of the collection.

        Args:
            threads: threads for this call (None: the collection's).
            progress: True for a progress bar on stderr, or a callable(done, total) (returning
                True cancels with CancelledError; an exception it raises cancels and propagates).
        """
        with self._lock.read():
            p = self.params
            q = _as_shape(shape, p, 'shape')
            out = np.zeros(len(self), dtype=np.float64)
            if threads is None or int(threads) == p.threads:
                progress_call(lib.amscr_db_query, (self._db, q._d), (dbuf(out),), progress)
            else:
                qdb = Collection(p, threads=threads)
                _check(lib.amscr_db_add_descriptor(qdb._db, q._d, 0, ffi.NULL))
                progress_call(lib.amscr_db_cross_distances, (qdb._db, self._db), (dbuf(out),), progress)
            return out

    def distance_matrix(self, threads: Optional[int] = None, progress: ProgressArg = False) -> np.ndarray:
        """(n, n) matrix, ``D[i, j]`` = distance(shape i -> shape j); zero diagonal."""
        with self._lock.read():
            src, _ = self._with_threads(threads)
            n = len(self)
            out = np.zeros((n, n), dtype=np.float64)
            progress_call(lib.amscr_db_distance_matrix, (src._db,), (dbuf(out),), progress)
            return out

    def cross_matrix(self, other: 'Collection', threads: Optional[int] = None,
                     progress: ProgressArg = False) -> np.ndarray:
        """(len(self), len(other)) matrix of distances from this collection's shapes (queries)
        to `other`'s (targets), with this collection's options."""
        if not isinstance(other, Collection):
            raise TypeError('other: expected an amscr.Collection, got %s' % type(other).__name__)
        with self._lock.read(), (other._lock.read() if other is not self else contextlib.nullcontext()):
            src, _ = self._with_threads(threads)
            out = np.zeros((len(self), len(other)), dtype=np.float64)
            progress_call(lib.amscr_db_cross_distances, (src._db, other._db), (dbuf(out),), progress)
            return out

    # -- persistence ------------------------------------------------------------------
    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the prepared collection (binary, versioned, checksummed; atomic rename).
        Named labels are stored as their codes."""
        with self._lock.read():
            _check(lib.amscr_db_save(self._db, os.fsencode(path)))

    @classmethod
    def load(cls, path: Union[str, os.PathLike], label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        """Reads a collection written by :meth:`save` (or the tool). `label_names[code]` names
        the codes again if given."""
        out = ffi.new('amscr_db **')
        _check(lib.amscr_db_load(os.fsencode(path), out))
        return cls._wrap(out[0], label_names)

    def to_bytes(self) -> bytes:
        """The collection serialized as :meth:`save` writes it."""
        with self._lock.read():
            buf = ffi.new('void **')
            n = ffi.new('size_t *')
            _check(lib.amscr_db_save_memory(self._db, buf, n))
            try:
                return bytes(ffi.buffer(buf[0], n[0]))
            finally:
                lib.amscr_free(buf[0])

    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview],
                   label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        """The inverse of :meth:`to_bytes`."""
        b = bytes(data)
        out = ffi.new('amscr_db **')
        _check(lib.amscr_db_load_memory(ffi.from_buffer(b), len(b), out))
        return cls._wrap(out[0], label_names)

    def __reduce__(self):
        return (_collection_from_state, (self.to_bytes(), self._label_names))


def _collection_from_state(data: bytes, label_names: Optional[List[Any]]) -> Collection:
    return Collection.from_bytes(data, label_names)


def distance_matrix(shapes: Sequence[PointsLike], *, threads: Optional[int] = None, progress: ProgressArg = False,
                    params: Optional[Params] = None, **options: Any) -> np.ndarray:
    """(n, n) distance matrix of a list of shapes (points or Shapes); see :class:`Collection`."""
    db = Collection(params, threads=threads, **options)
    db.extend(shapes)
    return db.distance_matrix(progress=progress)


# ====================================================================================== retrieval
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


def rerank_diffusion(D: ArrayLike, k: int = 5, iterations: int = 20) -> np.ndarray:
    """Contextual re-ranking of a whole (n, n) distance matrix: affinity diffusion on the
    k-nearest-neighbour tensor-product graph (Yang, Prasad, Latecki, CVPR 2012), as
    ``amscr_rerank_diffusion``. Returns a new (n, n) dissimilarity for ranking: values in [0, 1)
    for pairs the diffusion reaches, 1 + D/max(D) for the others. The defaults (k = 5,
    20 iterations) are the ones the README's Kimia measurements chose."""
    d = np.array(as_float_array(D, 'D', ndim=(2,), finite=True), dtype=np.float64, order='C', copy=True)
    n = d.shape[0]
    if d.shape != (n, n):
        raise bad('D: expected a square matrix, got shape %s' % (d.shape,))
    out = np.empty_like(d)
    kk = min(int(k), n) if n else int(k)
    _check(lib.amscr_rerank_diffusion(dbuf(d), n, kk, int(iterations), dbuf(out)))
    return out


# ================================================================================ building blocks
def gaussian_kernel(sigma: float) -> np.ndarray:
    """FIR Gaussian taps: radius ceil(4 sigma), 2r+1 taps, sum 1."""
    s = as_scalar(sigma, 'sigma')
    n = ffi.new('size_t *', 0)
    _check(lib.amscr_gaussian_kernel(s, ffi.NULL, n))
    out = np.zeros(int(n[0]), dtype=np.float64)
    _check(lib.amscr_gaussian_kernel(s, dbuf(out), n))
    return out[:int(n[0])]


def smooth(points: ArrayLike, sigma: float, closed: bool = True) -> np.ndarray:
    """Gaussian smoothing of x and y (sigma in samples): circular when closed, mirrored at the ends
    ("reflect") when open; sigma 0 copies."""
    pts = as_points(points)
    out = np.empty_like(pts)
    _check(lib.amscr_smooth_gaussian(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'),
                                     as_scalar(sigma, 'sigma'), dbuf(out)))
    return out


def resample_euclidean(points: ArrayLike, m: int, closed: bool = True) -> np.ndarray:
    """m points equally spaced in Euclidean arc length along the polygon."""
    pts = as_points(points)
    m = as_count(m, 'm', 1)
    out = np.empty((m, 2), dtype=np.float64)
    _check(lib.amscr_resample_euclidean(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'), m, dbuf(out)))
    return out


def resample_affine(points: ArrayLike, m: int, closed: bool = True, sigma0: Optional[float] = None,
                    passes: Optional[int] = None) -> np.ndarray:
    """m points equally spaced in affine arc length (sigma0: pre-smoothing as a fraction of the curve
    length; passes: affine arc-length passes; None takes the defaults of :class:`Params`)."""
    pts = as_points(points)
    m = as_count(m, 'm', 1)
    defaults = Params()
    s0 = defaults.presmooth if sigma0 is None else as_scalar(sigma0, 'sigma0')
    ps = defaults.arclength_passes if passes is None else _uint(passes, 'passes')
    out = np.empty((m, 2), dtype=np.float64)
    _check(lib.amscr_resample_affine(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'), s0, ps, m, dbuf(out)))
    return out


def affine_arclength(points: ArrayLike, closed: bool = True, sigma0: float = 0.0) -> Tuple[np.ndarray, float]:
    """Cumulative affine arc length at each vertex (not normalized) and the total length."""
    pts = as_points(points)
    cum = np.empty(pts.shape[0], dtype=np.float64)
    total = ffi.new('double *')
    _check(lib.amscr_affine_arclength(dbuf(pts), pts.shape[0], as_bool(closed, 'closed'),
                                      as_scalar(sigma0, 'sigma0'), dbuf(cum), total))
    return cum, float(total[0])


def normalize_whiten(points: ArrayLike) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(whitened points, 3x3 forward map, 3x3 inverse map): centroid to 0, identity covariance."""
    pts = as_points(points)
    out = np.empty_like(pts)
    fwd, inv = ffi.new('double[6]'), ffi.new('double[6]')
    _check(lib.amscr_normalize_whiten(dbuf(pts), pts.shape[0], dbuf(out), fwd, inv))
    return out, m6_to_matrix(fwd), m6_to_matrix(inv)


def lstsq(a: ArrayLike, b: ArrayLike, return_residuals: bool = False):
    """Least squares min ||a x - b|| by Householder QR (a: (m, n), m >= n; b: (m,) or (m, k)).

    Returns x ((n,) or (n, k)), and the residual 2-norms when `return_residuals`.
    Raises NumericError when `a` is rank-deficient or ill-conditioned.
    """
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
    return (x, res) if return_residuals else x


def affine_fit(src: ArrayLike, dst: ArrayLike) -> Tuple[np.ndarray, float]:
    """Least-squares affine map taking src[i] to dst[i]: (3x3 matrix, RMS residual distance)."""
    s, d = as_points(src, 'src'), as_points(dst, 'dst')
    if s.shape != d.shape:
        raise bad('src and dst: expected the same number of points, got %d and %d' % (s.shape[0], d.shape[0]))
    m = ffi.new('double[6]')
    rms = ffi.new('double *')
    _check(lib.amscr_affine_fit(dbuf(s), dbuf(d), s.shape[0], m, rms))
    return m6_to_matrix(m), float(rms[0])


def affine_apply(matrix: ArrayLike, points: ArrayLike) -> np.ndarray:
    """Applies a 3x3 (or 2x3) affine matrix to (n, 2) points."""
    m = to_m6(matrix)
    pts = as_points(points)
    out = np.empty_like(pts)
    _check(lib.amscr_affine_apply(dbuf(m), dbuf(pts), pts.shape[0], dbuf(out)))
    return out


def affine_invert(matrix: ArrayLike) -> np.ndarray:
    """Inverse of a 3x3 (or 2x3) affine matrix; DegenerateError when singular."""
    m = to_m6(matrix)
    return matrix_out(lib.amscr_affine_invert, dbuf(m))


class KMeansResult(NamedTuple):
    """Result of :func:`kmeans`."""
    centers: np.ndarray  # (k,) for 1-D data (ascending), else (k, dim)
    inertia: float  # within-cluster sum of squares (SSE)
    labels: np.ndarray  # (n,) nearest-centre index of each point


def _data_2d(data: ArrayLike) -> Tuple[np.ndarray, bool]:
    x = as_float_array(data, 'data', ndim=(1, 2))
    one_d = x.ndim == 1
    return (x.reshape(-1, 1) if one_d else x), one_d


def kmeans(data: ArrayLike, k: int, seed: int = 0, *, max_iterations: Optional[int] = None,
           tolerance: Optional[float] = None, restarts: Optional[int] = None) -> KMeansResult:
    """Deterministic K-means: the exact optimum for 1-D data, seeded k-means++ + Lloyd otherwise.

    Args:
        data: (n,) or (n, dim) values, n >= k.
    """
    x, one_d = _data_2d(data)
    out = ffi.new('amscr_kmeans **')
    _check(lib.amscr_kmeans_new(as_count(k, 'k', 1), out))
    km = ffi.gc(out[0], lib.amscr_kmeans_free)
    _check(lib.amscr_kmeans_set_seed(km, as_count(seed, 'seed', 0)))
    if max_iterations is not None:
        _check(lib.amscr_kmeans_set_max_iterations(km, _uint(max_iterations, 'max_iterations')))
    if tolerance is not None:
        _check(lib.amscr_kmeans_set_tolerance(km, as_scalar(tolerance, 'tolerance')))
    if restarts is not None:
        _check(lib.amscr_kmeans_set_restarts(km, _uint(restarts, 'restarts')))
    n, dim = x.shape
    _check(lib.amscr_kmeans_fit(km, dbuf(x), n, dim))
    kk = int(lib.amscr_kmeans_num_clusters(km))
    centers = copy_doubles(lib.amscr_kmeans_centers(km), kk * dim).reshape(kk, dim)
    inertia = float(lib.amscr_kmeans_inertia(km))
    labels = np.zeros(n, dtype=np.uintp)
    _check(lib.amscr_kmeans_assign(km, dbuf(x), n, ffi.from_buffer('size_t[]', labels), ffi.NULL))
    return KMeansResult(centers[:, 0].copy() if one_d else centers, inertia, labels.astype(np.intp))


def elbow(data: ArrayLike, k_max: Optional[int] = None, k_min: int = 1, seed: int = 0) -> Tuple[int, np.ndarray]:
    """SSE(k) for k in [k_min, k_max] and the elbow k; returns (k_best, sse array).
    k_max defaults to the registration's Kmax (clamped to n)."""
    x, _ = _data_2d(data)
    n, dim = x.shape
    if k_max is None:
        k_max = min(Params().kmax, n)
    k_min, k_max = as_count(k_min, 'k_min', 1), as_count(k_max, 'k_max', 1)
    if k_max < k_min:
        raise bad('k_max (%d) must be >= k_min (%d)' % (k_max, k_min))
    sse = np.zeros(k_max - k_min + 1, dtype=np.float64)
    best = ffi.new('size_t *')
    _check(lib.amscr_kmeans_elbow(dbuf(x), n, dim, k_min, k_max, as_count(seed, 'seed', 0), dbuf(sse), best))
    return int(best[0]), sse


class GMM1D:
    """A 1-D Gaussian mixture fitted by EM (started from exact 1-D K-means).

    ``GMM1D(k, max_iterations=None, tolerance=None, variance_floor=None).fit(x)``; the fitted
    parameters are attributes (components sorted by mean). A fitted model may be used by many
    threads; fitting is serialized by a lock.
    """

    def __init__(self, k: int, *, max_iterations: Optional[int] = None, tolerance: Optional[float] = None,
                 variance_floor: Optional[float] = None):
        out = ffi.new('amscr_gmm1d **')
        _check(lib.amscr_gmm1d_new(as_count(k, 'k', 1), out))
        self._g = ffi.gc(out[0], lib.amscr_gmm1d_free)
        self._lock = RWLock()
        self._fitted = False
        if max_iterations is not None:
            _check(lib.amscr_gmm1d_set_max_iterations(self._g, _uint(max_iterations, 'max_iterations')))
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
