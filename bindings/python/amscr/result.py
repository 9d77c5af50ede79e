"""Registration of one pair: :func:`register` and its result (C ``amscr_result``),
:func:`distance`, and the per-thread workspace they reuse."""
from __future__ import annotations

import threading
import types
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Tuple

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, Order, PointArray, as_points, matrix_out, new_object, points_in_order, sized_arrays
from .enums import METHODS, enum_out
from .errors import _check
from .params import Params, make_params
from .shape import PointsLike, Shape, as_shape

_tls = threading.local()


def _workspace():
    """The calling thread's workspace (scratch memory reused across registrations)."""
    ws = getattr(_tls, 'ws', None)
    if ws is None:
        ws = _tls.ws = new_object('amscr_workspace', lib.amscr_workspace_new, lib.amscr_workspace_free)
    return ws


class Mixture(NamedTuple):
    """The 1-D Gaussian mixture of the per-scale residuals (components sorted by mean)."""
    weights: np.ndarray
    means: np.ndarray
    variances: np.ndarray


class Alternative(NamedTuple):
    """A map that fits about as well as the chosen one (see :attr:`Registration.alternatives`)."""
    A: np.ndarray
    B: np.ndarray
    cost: float


class Registration:
    """The result of :func:`register`: the affine map taking the source onto the target and the
    diagnostics of scale selection. Read-only: every array is a read-only NumPy copy (nothing
    refers to C memory; ``r.A.copy()`` gives one to modify) and no attribute can be set, so the
    attributes stay one consistent map; shareable between threads.

    All maps are in the (x, y) frame of the input points (x = column, y = row for image
    contours, also when they were given with ``order='rc'``), the frame of OpenCV and of
    scikit-image's transforms: ``cv2.warpAffine(src_img, r.matrix[:2], (width, height))`` and
    ``skimage.transform.warp(src_img, AffineTransform(matrix=r.matrix).inverse)`` move the
    source image onto the target.

    Attributes:
        A: (2, 2) linear part, in input coordinates: ``tgt ~= src @ A.T + B``.
        B: (2,) translation.
        matrix: (3, 3) homogeneous form of (A, B): ``[[A, B], [0, 0, 1]]``.
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
        confidence: how sure the map is, in [0, 1]: (1 - max(ambiguity, symmetry_ambiguity))
            x min(inlier_fraction, overlap) / (1 + (backward_error / 0.01)^2)
            / (1 + (standard_error / 0.01)^2) (a value not measured, NaN, counts as no
            evidence against the map); reject maps below 0.25.
        ambiguity: cost of the chosen map over that of the best clearly different candidate
            (1: a symmetric shape or a fragment that fits several places); where the pixel_grid
            stage chose a clearly different map by a small image's pixels, at least the ratio of
            the pixels each map gets wrong.
        inlier_fraction: share of source samples within 5 % of the target's size of its boundary.
        overlap: intersection over union of the two contours as regions under the map (NaN for
            a partial match or open curves).
        backward_error: when the map is confident but less than 85 % of the shape agrees, the
            target registered onto the source on its own and composed with the map: the RMS
            displacement of the source samples, in units of its RMS radius (about 0 when the
            two maps agree); NaN when the check did not run.
        standard_error: how firmly the data fix the map: the block jackknife of the final fit
            (the source's samples in floor(sqrt(N)) runs along the curve, each left out in
            turn and the map solved again on the rest), the RMS displacement of the source
            samples, in units of the target's RMS radius (about 0.001 when every part of the
            boundary agrees; 0.01 halves the confidence); NaN when not measured (an invariance
            other than affine).
        symmetry_ambiguity: when the map is confident but less than 95 % of the shape agrees,
            the ambiguity against the source's own symmetries composed with the map (1: a
            symmetric turn fits the damaged target as well); NaN when not measured.
        part: (start, end) fractions of the target's boundary the source's first and last samples
            fall on (where a fragment lies, with partial=True).
        stages: read-only mapping {stage name: whether it ran}, in pipeline order (despike,
            search, method, recovery, final_solve, symmetric, polish, order, even_spacing,
            alternatives, correspondences, pixel_grid; C ``amscr_result_stage``).
        alternatives: tuple of :class:`Alternative` (A, B, cost): the distinct maps that fit
            about as well, the chosen map first (always there; its cost NaN when the
            registration ranked no starts), then each map that moves the source samples by more
            than 10 % of the shape's RMS radius from those before and whose ranking cost is
            within a factor 4/3 of the chosen one's (ambiguity >= 0.75). Each symmetry once: a
            square or a 4-armed cross gives 4 maps (its quarter turns), an equilateral triangle
            3, a regular 5-pointed star 5 — with ``reflections=True`` their mirror maps too (8,
            6, 10) — and an asymmetric shape the chosen map alone. At most 12 per orientation
            (the start-point search's cap): a circle or an ellipse lists 12 (24 with reflections).
        correspondences: (N,) target boundary parameter (fraction) matched to each source sample.
        source_samples: (N, 2) the source samples (input coordinates).
        target_points: (N, 2) the matched target boundary points (input coordinates): on the
            target's N samples joined by straight edges, which cut the input polygon's sharp
            corners by up to about a sample spacing.
    """

    # the attributes' types (py.typed): what type checkers and typing.get_type_hints see
    A: np.ndarray
    B: np.ndarray
    matrix: np.ndarray
    matrix_normalized: np.ndarray
    distance: float
    residuals: np.ndarray
    scales: np.ndarray
    kept: np.ndarray
    kept_scales: np.ndarray
    k: int
    sse: np.ndarray
    mixture: Mixture
    threshold: float
    shift: int
    reflected: bool
    method: str
    confidence: float
    ambiguity: float
    inlier_fraction: float
    overlap: float
    backward_error: float
    standard_error: float
    symmetry_ambiguity: float
    part: Tuple[float, float]
    stages: Mapping[str, bool]
    alternatives: Tuple[Alternative, ...]
    correspondences: np.ndarray
    source_samples: np.ndarray
    target_points: np.ndarray

    def __init__(self, handle, scales: np.ndarray):
        """Copies everything out of `handle`, a C ``amscr_result`` (made by :func:`register`,
        which users call instead), and `scales`, the sigma_k of the registration. Raises
        nothing of its own: the handle comes from a successful registration."""
        r = handle
        self.distance = float(lib.amscr_result_distance(r))
        self.matrix = matrix_out(lib.amscr_result_affine, r)
        self.matrix_normalized = matrix_out(lib.amscr_result_affine_normalized, r)
        self.A = self.matrix[:2, :2].copy()
        self.B = self.matrix[:2, 2].copy()
        self.shift = int(lib.amscr_result_shift(r))
        self.reflected = bool(lib.amscr_result_reflected(r))
        self.method = enum_out(METHODS, lib.amscr_result_method(r))
        self.residuals, = sized_arrays(lib.amscr_result_residuals, r)
        kept, = sized_arrays(lib.amscr_result_kept, r, dtype=np.intc, ctype='int[]')
        self.kept = kept.astype(bool)
        self.scales = np.asarray(scales, dtype=np.float64).copy()
        self.kept_scales = self.scales[self.kept] if self.scales.shape == self.kept.shape else self.scales[:0]
        self.k = int(lib.amscr_result_k(r))
        self.sse, = sized_arrays(lib.amscr_result_sse, r)
        self.mixture = Mixture(*sized_arrays(lib.amscr_result_mixture, r, arrays=3))
        self.threshold = float(lib.amscr_result_threshold(r))
        self.confidence = float(lib.amscr_result_confidence(r))
        self.ambiguity = float(lib.amscr_result_ambiguity(r))
        self.inlier_fraction = float(lib.amscr_result_inlier_fraction(r))
        self.overlap = float(lib.amscr_result_overlap(r))
        self.backward_error = float(lib.amscr_result_backward_error(r))
        self.standard_error = float(lib.amscr_result_standard_error(r))
        self.symmetry_ambiguity = float(lib.amscr_result_symmetry_ambiguity(r))
        part = ffi.new('double[2]')
        _check(lib.amscr_result_part(r, part, part + 1))
        self.part = (float(part[0]), float(part[1]))
        self.source_samples, self.correspondences, self.target_points = _correspondences(r)
        self.stages = _stages(r)
        self.alternatives = tuple(_alternatives(r))
        self._freeze()

    def _freeze(self) -> None:
        """Every array of the result read-only (the mixture's and the alternatives' too), stages a
        read-only mapping, alternatives a tuple, and every attribute fixed."""
        vars(self).update(stages=types.MappingProxyType(dict(self.stages)),
                          alternatives=tuple(self.alternatives))
        arrays = [v for v in vars(self).values() if isinstance(v, np.ndarray)] + list(self.mixture)
        for a in arrays + [x for alt in self.alternatives for x in (alt.A, alt.B)]:
            a.setflags(write=False)
        object.__setattr__(self, '_frozen', True)

    def __setattr__(self, name: str, value: Any) -> None:
        if self.__dict__.get('_frozen'):
            raise AttributeError('Registration is read-only: %s cannot be set (the attributes are one map; '
                                 'copy the arrays to change them)' % name)
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        raise AttributeError('Registration is read-only: %s cannot be deleted' % name)

    def __getstate__(self) -> Dict[str, Any]:
        return dict(vars(self), stages=dict(self.stages))  # a mappingproxy does not pickle

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)  # unpickled arrays are writable again
        self._freeze()

    def apply(self, points: PointArray, order: Order = 'xy') -> np.ndarray:
        """Maps points of the source onto the target: ``points @ A.T + B``.

        Args:
            points: (n, 2) points (or an OpenCV (n, 1, 2) contour) in source coordinates; n
                may be 0.
            order: 'xy' (default) or 'rc': the order of the given points' columns, kept in
                the returned array.
        Returns:
            (n, 2) float array, in the same order as `points`.
        Raises:
            InvalidArgumentError: bad points or order.
        """
        pts = as_points(points, 'points', order, allow_empty=True)
        return points_in_order(pts @ self.A.T + self.B, order)

    def __repr__(self) -> str:
        return ('Registration(distance=%.6g, method=%r, kept %d/%d scales, k=%d, shift=%d, reflected=%s)'
                % (self.distance, self.method, int(self.kept.sum()), self.kept.size, self.k, self.shift,
                   self.reflected))


def _correspondences(r) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(source samples (N, 2), target parameters (N,), target points (N, 2)) of a result."""
    n = ffi.new('size_t *', 0)
    _check(lib.amscr_result_correspondences(r, ffi.NULL, ffi.NULL, ffi.NULL, n))
    m = int(n[0])
    src, par, tgt = np.zeros((m, 2)), np.zeros(m), np.zeros((m, 2))
    if m:
        _check(lib.amscr_result_correspondences(r, ffi.from_buffer('double[]', src), ffi.from_buffer('double[]', par),
                                                ffi.from_buffer('double[]', tgt), n))
    return src, par, tgt


def _stages(r) -> Dict[str, bool]:
    """{stage name: ran} of a result, in pipeline order."""
    name, ran = ffi.new('const char **'), ffi.new('int *')
    out: Dict[str, bool] = {}
    for i in range(int(lib.amscr_result_num_stages(r))):
        _check(lib.amscr_result_stage(r, i, name, ran))
        out[ffi.string(name[0]).decode()] = bool(ran[0])
    return out


def _alternatives(r) -> List[Alternative]:
    """The alternatives of a result, the chosen map first."""
    m, cost = ffi.new('double[6]'), ffi.new('double *')
    out = []
    for i in range(int(lib.amscr_result_num_alternatives(r))):
        _check(lib.amscr_result_alternative(r, i, m, cost))
        out.append(Alternative(np.array([[m[0], m[1]], [m[3], m[4]]]), np.array([m[2], m[5]]), float(cost[0])))
    return out


def _pair(src: PointsLike, tgt: PointsLike, params: Optional[Params], options: Dict[str, Any], order: str
          ) -> Tuple[Params, Shape, Shape]:
    """The options of one registration and the two prepared shapes (see :func:`register`)."""
    base = params
    if base is None:
        first = src if isinstance(src, Shape) else tgt if isinstance(tgt, Shape) else None
        # prepared shapes bring their own settings; raw points get the registration preset
        base = first.params if first is not None else Params.registration()
    p = make_params(base, options)
    if p.partial:  # the source prepared open, the target closed
        return p, as_shape(src, p.copy(closed=False), 'src', order), as_shape(tgt, p.copy(closed=True), 'tgt', order)
    return p, as_shape(src, p, 'src', order), as_shape(tgt, p, 'tgt', order)


def register(src: PointsLike, tgt: PointsLike, *, method: Optional[str] = None, points: Optional[int] = None,
             scales: Optional[ArrayLike] = None, reflections: Optional[bool] = None,
             closed: Optional[bool] = None, refine: Optional[int] = None, symmetric: Optional[bool] = None,
             parametrization: Optional[str] = None, invariance: Optional[str] = None,
             params: Optional[Params] = None, order: Order = 'xy', **options: Any) -> Registration:
    """Registers `src` onto `tgt`: finds (A, B) with ``tgt ~= src @ A.T + B`` (each point
    ``x -> A x + B``) and the distance.

    Args:
        src, tgt: the two shapes: (n, 2) point arrays (contours, closed by default; OpenCV
            (n, 1, 2) contours are accepted as they are, ``CHAIN_APPROX_SIMPLE`` ones read as
            the pixel chain they stand for) or prepared :class:`Shape` s.
        method: 'multiclass-em' (default), 'binary-em', 'amscr' or 'acma'.
        points: N, samples per scale (None: 256, the registration preset; see below).
        scales: the smoothing scales sigma_k (samples of the N-point curve).
        reflections: also try the mirrored target.
        closed: closed (default) or open curves.
        refine: refinement iterations in the aligned frame (trimmed closest-point pairs, started
            from AMSCR's global estimate); 0 gives the paper's method (None: 20, the preset).
        symmetric: symmetric distance.
        parametrization: 'affine', 'euclidean' or 'whitened'.
        invariance: 'affine', 'similarity' or 'penalized'.
        params: a :class:`Params` to start from; other keywords of :class:`Params` are accepted.
        order: 'xy' (default: x = column, y = row for image contours) or 'rc' for (row, col)
            points such as scikit-image's ``measure.find_contours`` gives. Either way the
            result is in the (x, y) frame: 'rc' points are swapped on the way in.
        **options: other options of :class:`Params`, e.g. ``partial=True`` (the source an open
            fragment of the target), ``polish=False`` (skip the final fit on the input points,
            on in the preset: it fits the noisier curve onto the cleaner one) or
            ``stages={'even_spacing': True}`` (switch an optional stage; see
            :attr:`Params.stages`).

    Returns:
        a :class:`Registration`: the affine map (``A``, ``B``, ``matrix``), the distance and the
        diagnostics of scale selection.

    Many registrations in one process: set ``OPENBLAS_NUM_THREADS=1`` in the environment before
    the first import; the least squares wake OpenBLAS's own threads, which spin on another core
    for no speed (measured, 1,000 registrations of 64 points on 2 cores: 15.9 s wall either way,
    31.6 s of CPU without it, 15.9 s with it). Any number of threads may register at once (each
    reuses a workspace of its own; prepared shapes and params may be shared): the results are
    those of one thread, bit for bit.

    Raises:
        InvalidArgumentError: bad points or options; DegenerateError: a shape with too few
        distinct points or zero area; NumericError: the registration failed numerically.

    Options left as None take the registration preset (:meth:`Params.registration`: N = 256,
    20 refinement iterations, as the ``amscr register`` tool), or the settings of a given Shape
    (the options of preparation, N, scales, closed and parametrization, must then agree with the
    shapes').
    """
    options.update(method=method, points=points, scales=scales, reflections=reflections, closed=closed,
                   refine=refine, symmetric=symmetric, parametrization=parametrization, invariance=invariance)
    p, s, t = _pair(src, tgt, params, options, order)
    r = new_object('amscr_result', lib.amscr_register, lib.amscr_result_free, p._p, s._d, t._d, _workspace())
    res = Registration(r, p.scales)
    ffi.release(r)
    return res


def distance(src: PointsLike, tgt: PointsLike, *, params: Optional[Params] = None, order: Order = 'xy',
             **options: Any) -> float:
    """The distance only (the fast batch path; equal to ``register(...).distance`` to rounding).

    Args:
        src, tgt: (n, 2) point arrays, OpenCV (n, 1, 2) contours or prepared :class:`Shape` s.
        params: a :class:`Params` to start from (None: the registration preset, as in
            :func:`register`).
        order: 'xy' (default) or 'rc' for (row, col) points, as in :func:`register`.
        **options: options of :class:`Params`.
    Returns:
        the affine-invariant distance, a float >= 0.
    Raises:
        InvalidArgumentError: bad points or options; DegenerateError: a degenerate shape.
    """
    p, s, t = _pair(src, tgt, params, options, order)
    out = ffi.new('double *')
    _check(lib.amscr_distance(p._p, s._d, t._d, _workspace(), out))
    return float(out[0])


def channel_distance(src: PointsLike, tgt: PointsLike, *, params: Optional[Params] = None, order: Order = 'xy',
                     **options: Any) -> float:
    """The shape channel's distance of two closed shapes (C ``amscr_channel_distance``): height
    functions matched by banded dynamic programming in the channel's frame; 0 for a shape
    against itself, invariant to the channel's group, tolerant of articulation.

    Args:
        src, tgt: (n, 2) point arrays, OpenCV (n, 1, 2) contours or prepared :class:`Shape` s.
        params: a :class:`Params` to start from (None: a prepared shape's own, else the
            retrieval preset, :meth:`Params.retrieval`).
        order: 'xy' (default) or 'rc' for (row, col) points.
        **options: options of :class:`Params`.
    Returns:
        the channel distance, a float >= 0.
    Raises:
        InvalidArgumentError: bad points or options, open curves; DegenerateError: a degenerate
        shape.
    """
    if params is None and not isinstance(src, Shape) and not isinstance(tgt, Shape):
        params = Params.retrieval()
    p, s, t = _pair(src, tgt, params, options, order)
    out = ffi.new('double *')
    _check(lib.amscr_channel_distance(p._p, s._d, t._d, out))
    return float(out[0])
