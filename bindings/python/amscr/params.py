"""Params: the options of shape preparation and matching (C ``amscr_params``).

Every option is declared once, as a line of the table in the class body: the attribute name,
the C getter/setter suffix, how its value crosses the C boundary and its documentation. The
properties, :attr:`Params.OPTIONS` and the option list of the class docstring come from it.
"""
from __future__ import annotations

from typing import Any, Callable, Dict, Generic, Optional, Tuple, TypeVar, overload

import numpy as np

from ._lib import ffi, lib
from ._util import as_bool, as_count, as_float_array, as_scalar, as_uint, dbuf, new_object, sized_arrays
from .enums import INVARIANCES, METHODS, PARAMETRIZATIONS, RANKINGS, enum_in, enum_out
from .errors import InternalError, InvalidArgumentError, _check, error_from_status

T = TypeVar('T')


class _Conv(Generic[T]):
    """How an option's value crosses the C boundary: `read(getter, params)` gives the Python
    value, `write(value, name)` validates a Python value into the C setter's arguments."""

    def __init__(self, read: Callable[[Callable[..., Any], Any], T],
                 write: Callable[[Any, str], Tuple[Any, ...]]):
        self.read, self.write = read, write


def _scalar(to_py: Callable[[Any], T], to_c: Callable[[Any, str], Any]) -> _Conv[T]:
    return _Conv(lambda get, p: to_py(get(p)), lambda v, name: (to_c(v, name),))


def _enum(table: Dict[str, int]) -> _Conv[str]:
    return _Conv(lambda get, p: enum_out(table, get(p)), lambda v, name: (enum_in(table, v, name),))


def _scales_in(v: Any, name: str) -> Tuple[Any, ...]:
    a = as_float_array(v, name, ndim=(1,), finite=False)
    return dbuf(a), a.shape[0]


_COUNT = _scalar(int, lambda v, name: as_count(v, name, 0))
_UINT = _scalar(int, as_uint)
_BOOL = _scalar(bool, as_bool)
_FLOAT = _scalar(float, as_scalar)
_SCALES: _Conv[np.ndarray] = _Conv(lambda get, p: sized_arrays(get, p)[0], _scales_in)


class _Option(Generic[T]):
    """A Params attribute backed by ``amscr_params_get_<c_name>`` / ``amscr_params_set_<c_name>``."""

    def __init__(self, c_name: str, conv: _Conv[T], doc: str):
        self.conv, self.__doc__ = conv, doc
        self.name = self.c_name = c_name
        self.c_get = getattr(lib, 'amscr_params_get_' + c_name)
        self.c_set = getattr(lib, 'amscr_params_set_' + c_name)

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, obj: None, owner: Optional[type] = None) -> '_Option[T]': ...
    @overload
    def __get__(self, obj: 'Params', owner: Optional[type] = None) -> T: ...

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        return self.conv.read(self.c_get, obj._p)

    def __set__(self, obj: 'Params', value: Any) -> None:
        self._set(obj._p, *self.conv.write(value, self.name))

    def _set(self, *args: Any) -> None:
        """The C setter's call; its errors under the option's Python name ('amscr_params_set_num_samples:
        num_samples 3 is not in 16..65536' -> 'points: 3 is not in 16..65536')."""
        try:
            _check(self.c_set(*args))
        except InvalidArgumentError as e:
            c = 'amscr_params_set_%s: ' % self.c_name
            if not e.detail.startswith(c):
                raise
            rest = e.detail[len(c):]
            rest = rest[len(self.c_name) + 1:] if rest.startswith(self.c_name + ' ') else rest
            raise error_from_status(e.status, '%s: %s' % (self.name, rest)) from None


#: The stages of ``amscr_register`` a Params can switch (C ``amscr_params_set_stage``).
SWITCHABLE_STAGES: Tuple[str, ...] = ('despike', 'recovery', 'polish', 'order', 'even_spacing', 'pixel_grid')


class _StagesOption(_Option[Dict[str, bool]]):
    """The switchable stages as a dict {name: on}; setting one changes the names it holds only."""

    def __init__(self, doc: str):
        super().__init__('stage', _BOOL, doc)  # type: ignore[arg-type]

    def __get__(self, obj, owner=None):
        if obj is None:
            return self
        return {k: bool(self.c_get(obj._p, k.encode())) for k in SWITCHABLE_STAGES}

    def __set__(self, obj: 'Params', value: Any) -> None:
        if not isinstance(value, dict):
            raise TypeError('stages: expected a dict {stage name: bool}, got %s' % type(value).__name__)
        for k, on in value.items():
            if not isinstance(k, str):
                raise TypeError('stages: stage names are str, got %s' % type(k).__name__)
            self._set(obj._p, k.encode(), as_bool(on, 'stages[%r]' % k))


def _new_params(make: Callable[..., int], *args: Any):
    return new_object('amscr_params', make, lib.amscr_params_free, *args)


class Params:
    """Options of shape preparation and matching (a copy of the C ``amscr_params``).

    ``Params(**options)``: every option is a keyword of the constructor and an attribute;
    ``None`` leaves the library's default. An unknown option raises TypeError, a bad value
    InvalidArgumentError (also a ValueError). Thread-safety: any number of threads may read one
    Params at once (its options, :meth:`copy`, the calls taking it, which copy it); changing it
    while another thread reads it is not synchronized: give each thread its own :meth:`copy`.
    Options:

    """

    # -- the options: attribute = (C name, conversion, documentation) -------------------
    points = _Option('num_samples', _COUNT, 'N, samples per scale (library default 128)')
    scales = _Option('scales', _SCALES, 'the smoothing scales sigma_k, in samples of the N-point curve')
    method = _Option('method', _enum(METHODS), "'acma', 'amscr', 'binary-em' or 'multiclass-em' (default)")
    closed = _Option('closed', _BOOL, 'closed (default) or open curves')
    reflections = _Option('reflections', _BOOL, 'also try the mirrored target')
    parametrization = _Option('parametrization', _enum(PARAMETRIZATIONS),
                              "'whitened' (default), 'affine' (the paper's affine arc length) or 'euclidean'")
    presmooth = _Option('presmooth', _FLOAT, 'pre-smoothing of the parametrization, fraction of the curve length')
    arclength_passes = _Option('arclength_passes', _UINT, 'parametrization passes')
    oversampling = _Option('oversampling', _UINT, 'dense resampling factor')
    kmax = _Option('kmax', _UINT, 'Kmax of the elbow')
    symmetric = _Option('symmetric', _BOOL, 'symmetric distance (average of both directions)')
    refine = _Option('refine', _UINT, "refinement iterations in the aligned frame (0 = the paper's method)")
    threads = _Option('num_threads', _UINT, 'threads of batch calls (0 = all cores)')
    invariance = _Option('invariance', _enum(INVARIANCES), "'affine' (default), 'similarity' or 'penalized'")
    penalty = _Option('penalty', _FLOAT, "weight of the 'penalized' invariance")
    partial = _Option('partial', _BOOL, "the source is an open fragment of the target's closed boundary (register)")
    polish = _Option('polish', _BOOL, 'polish the map on the input points, fitting the noisier curve onto the '
                     'cleaner (register; on in the registration preset; its order and even-spacing steps for '
                     'markedly noisy point lists are opt-in: stages)')
    stages = _StagesOption("the optional stages of register on or off, a dict {name: bool} over "
                           "'despike', 'recovery', 'polish', 'order', 'even_spacing', 'pixel_grid' (setting one leaves "
                           "the others; default: despike, order and even_spacing off, for point lists with stray "
                           "points or synthetic noise; pixel_grid: a target traced from a small binary image "
                           "registered again with its tracing's bias removed (or such a source, onto a larger "
                           "image's trace), a small image's pixel chain (as "
                           "cv2.findContours gives) traced again at sub-pixel first; Registration.stages says "
                           "which ran)")
    channel_weight = _Option('channel_weight', _FLOAT,
                             'share of the shape channel in Collection.retrieval_matrix, 0..1 (0 = the AMSCR '
                             'distance alone, the default; 1 = the channel alone, the retrieval preset)')
    channel_invariance = _Option('channel_invariance', _enum(INVARIANCES),
                                 "frame of the shape channel: 'similarity' (default) or 'affine' (whitened)")
    channel_affine_share = _Option('channel_affine_share', _FLOAT,
                                   'with the similarity frame: the share, 0..1, of the channel computed in the '
                                   'affine frame (default 0.2; 0 = the similarity frame alone, proportions kept, '
                                   'less time; 1 = the affine frame alone)')
    channel_band = _Option('channel_band', _FLOAT,
                           "half width of the channel's dynamic-programming band, fraction of N in (0, 0.5] "
                           '(default 0.15; 0.08 before 0.6)')
    channel_affine_band = _Option('channel_affine_band', _FLOAT,
                                  "the band of the whitened frame mixed in by channel_affine_share, fraction of N "
                                  'in (0, 0.5] (default 0.08; equal to channel_band for the settings before 0.6)')
    channel_skip = _Option('channel_skip', _FLOAT, "the channel's cost of a skipped sample (>= 0)")
    channel_locality = _Option('channel_locality', _FLOAT, "the channel's locality of the height functions (>= 0)")
    rerank_k = _Option('rerank_k', _UINT, 'neighbours of the re-ranking of retrieval_matrix (0 = none; preset 8)')
    rerank_iterations = _Option('rerank_iterations', _UINT, 'diffusion iterations of that re-ranking (1..1000)')
    rerank_inner_share = _Option('rerank_inner_share', _FLOAT,
                                 'share, in [0, 1), of the inner-distance graph in that re-ranking (0 = one graph, '
                                 'the default; 0.1 in the retrieval preset; an Index holds both graphs)')
    inner_closing = _Option('inner_closing', _FLOAT,
                            'closing radius, in units of sqrt(area) in [0, 1], of the silhouette the inner '
                            'distance is taken in (0 = as it is, the default; 0.04 in the retrieval preset)')
    channel_affine_view = _Option('channel_affine_view', _FLOAT,
                                  'with two frames: a pair the affine frame alone finds f times nearer than the '
                                  "frames' mix is ranked by it, min(mix, f * d_affine) (0 = the mix for every pair, "
                                  'the default; 2 in the retrieval preset; f in [1, 100])')

    #: The option names, in the order of the table above.
    OPTIONS: Tuple[str, ...] = ()
    #: Other names accepted by the constructor and :meth:`update` (the C names).
    ALIASES: Dict[str, str] = {'num_samples': 'points', 'num_threads': 'threads'}

    def __init__(self, **options: Any):
        self._p = _new_params(lib.amscr_params_new)
        self.update(**options)

    @classmethod
    def registration(cls, **options: Any) -> 'Params':
        """The registration preset (C ``amscr_params_new_registration``): the defaults with
        N = 256 and 20 refinement iterations, for registering single pairs robustly; the
        plain defaults (N = 128, no refinement) are tuned for collections.

        Args:
            **options: options to change from the preset.
        Returns:
            a new :class:`Params`.
        Raises:
            TypeError: an unknown option; InvalidArgumentError: a bad value.
        """
        return cls._preset(lib.amscr_params_new_registration, options)

    @classmethod
    def retrieval(cls, **options: Any) -> 'Params':
        """The retrieval preset (C ``amscr_params_new_retrieval``): the defaults with mirror
        images, the shape channel alone (channel weight 1: height functions matched by banded
        dynamic programming, in the similarity frame with 0.2 of the affine frame, a pair the
        affine frame finds twice as near ranked by it) and re-ranking (k 8, 10 iterations, with
        0.1 of the inner distance's graph); use it with :meth:`Collection.retrieval_matrix`.

        Args:
            **options: options to change from the preset.
        Returns:
            a new :class:`Params`.
        Raises:
            TypeError: an unknown option; InvalidArgumentError: a bad value.
        """
        return cls._preset(lib.amscr_params_new_retrieval, options)

    @classmethod
    def _preset(cls, make: Any, options: Dict[str, Any]) -> 'Params':
        """A new Params from the C preset constructor `make`, with `options` changed."""
        self = cls.__new__(cls)
        self._p = _new_params(make)
        self.update(**options)
        return self

    @classmethod
    def _copy_of(cls, ptr) -> 'Params':
        """A new Params holding a deep copy of the C params at `ptr` (borrowed)."""
        if ptr == ffi.NULL:
            raise InternalError('NULL params from the library', lib.AMSCR_E_INTERNAL)
        self = cls.__new__(cls)
        self._p = _new_params(lib.amscr_params_copy, ptr)
        return self

    def copy(self, **options: Any) -> 'Params':
        """A copy, with `options` changed.

        Args:
            **options: options to change in the copy.
        Returns:
            a new :class:`Params`.
        Raises:
            TypeError: an unknown option; InvalidArgumentError: a bad value.
        """
        p = Params._copy_of(self._p)
        p.update(**options)
        return p

    def update(self, **options: Any) -> 'Params':
        """Sets the given options in place.

        Args:
            **options: options to set (None values are skipped; the C names ``num_samples``
                and ``num_threads`` are accepted too).
        Returns:
            self.
        Raises:
            TypeError: an unknown option; InvalidArgumentError: a bad value.
        """
        for k, v in options.items():
            k = self.ALIASES.get(k, k)
            if k not in self.OPTIONS:
                raise TypeError('unknown amscr option %r (expected one of %s)' % (k, ', '.join(self.OPTIONS)))
            if v is not None:
                setattr(self, k, v)
        return self

    @property
    def ranking(self) -> str:
        """Which scores these params rank a collection by (C ``amscr_params_ranking``): 'retrieval'
        (the scores of :meth:`Collection.retrieval_matrix`, of :meth:`Collection.query` and of an
        :class:`Index`) when they ask for the shape channel (``channel_weight`` > 0) or for
        re-ranking (``rerank_k`` > 0), else 'distance' (the AMSCR distance of
        :meth:`Collection.distance_matrix`).

        Returns:
            'distance' or 'retrieval'.
        """
        out = ffi.new('amscr_ranking *')
        _check(lib.amscr_params_ranking(self._p, out))
        return enum_out(RANKINGS, out[0])

    def to_dict(self) -> Dict[str, Any]:
        """Every option and its value.

        Returns:
            a dict {option: value} (``Params(**d)`` makes an equal Params).
        """
        return {k: getattr(self, k) for k in self.OPTIONS}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Params):
            return NotImplemented
        a, b = self.to_dict(), other.to_dict()
        return all(np.array_equal(a[k], b[k]) if k == 'scales' else a[k] == b[k] for k in a)

    __hash__ = None  # type: ignore  # mutable

    def _plain_dict(self) -> Dict[str, Any]:
        d = self.to_dict()
        d['scales'] = [float(x) for x in d['scales']]
        return d

    def __repr__(self) -> str:
        return 'Params(%s)' % ', '.join('%s=%r' % kv for kv in self._plain_dict().items())

    def __reduce__(self):
        return (_params_from_dict, (self._plain_dict(),))


def _document_options(cls: type) -> None:
    """Fills OPTIONS and the option list of the class docstring from the table."""
    table = [(k, v) for k, v in vars(cls).items() if isinstance(v, _Option)]
    cls.OPTIONS = tuple(k for k, _ in table)
    if cls.__doc__:
        lines = ['    %s %s' % (('``%s``' % k).ljust(19), opt.__doc__) for k, opt in table]
        cls.__doc__ = cls.__doc__.rstrip() + '\n\n' + '\n'.join(lines) + '\n    '


_document_options(Params)


def _params_from_dict(d: Dict[str, Any]) -> Params:
    return Params(**d)


def make_params(params: Optional[Params], options: Dict[str, Any]) -> Params:
    """A fresh Params: a copy of `params` (or the defaults) with `options` applied."""
    if params is not None and not isinstance(params, Params):
        raise TypeError('params: expected amscr.Params, got %s' % type(params).__name__)
    p = params.copy() if params is not None else Params()
    p.update(**options)
    return p
