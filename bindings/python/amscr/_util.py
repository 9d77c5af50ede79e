"""Private helpers: input validation, buffers, progress callbacks, locks."""
from __future__ import annotations

import contextlib
import operator
import os
import sys
import threading
import time
import warnings
import weakref
from typing import TYPE_CHECKING, Any, Callable, ForwardRef, Iterator, List, Literal, Optional, Protocol, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from .errors import InvalidArgumentError, StateError, _check

try:
    from numpy.typing import ArrayLike
except ImportError:  # numpy < 1.20
    ArrayLike = Any  # type: ignore

if TYPE_CHECKING:
    from .contour import ImageContour


def forward_ref(name: str, module: str) -> Any:
    """A forward reference in a type alias that ``typing.get_type_hints`` resolves in `module`
    (``amscr.contour`` for 'ImageContour'), whichever module's function the alias annotates; the
    bare name on Pythons before 3.9.7, whose ForwardRef takes no module."""
    try:
        return ForwardRef(name, module=module)
    except TypeError:
        return name


if TYPE_CHECKING:
    #: What a function taking points accepts: an (n, 2) array-like, an OpenCV (n, 1, 2) contour, or an
    #: :class:`ImageContour` of :func:`contours_from_mask` (its points).
    PointArray = Union[ArrayLike, 'ImageContour']
    #: A file path, as ``open()`` takes it.
    PathArg = Union[str, bytes, 'os.PathLike[str]', 'os.PathLike[bytes]']
else:  # the same, with references that resolve outside this module (typing.get_type_hints(amscr.register))
    PointArray = Union[ArrayLike, forward_ref('ImageContour', 'amscr.contour')]
    PathArg = Union[str, bytes, forward_ref('os.PathLike[str]', __name__), forward_ref('os.PathLike[bytes]', __name__)]

#: The type of an ``order=`` argument (see ORDERS).
Order = Literal['xy', 'rc']


class ArrayInterface(Protocol):
    """An object NumPy reads through its ``__array_interface__``, as a PIL image."""

    @property
    def __array_interface__(self) -> Any: ...


#: What the tracers take for an image: an array-like or an object with ``__array_interface__``.
MaskLike = Union[ArrayLike, ArrayInterface]

INT32_MIN, INT32_MAX = -(2 ** 31), 2 ** 31 - 1


def bad(msg: str) -> InvalidArgumentError:
    """A Python-side validation error (also a ValueError)."""
    return InvalidArgumentError(msg, lib.AMSCR_E_INVALID_ARG, msg)


class ArgumentTypeError(InvalidArgumentError, TypeError):
    """An argument of the wrong type (a float or str index, a str option): a TypeError, and an
    InvalidArgumentError (a ValueError) as the other bad arguments."""


def bad_type(msg: str) -> ArgumentTypeError:
    """A Python-side type error (also an InvalidArgumentError and a ValueError)."""
    return ArgumentTypeError(msg, lib.AMSCR_E_INVALID_ARG, msg)


def unmasked(x: Any, name: str, instead: str) -> Any:
    """`x` itself, or the data of a ``numpy.ma`` array with nothing masked; a masked array with
    masked values is refused (its masked values would be used as they are)."""
    if not isinstance(x, np.ma.MaskedArray):
        return x
    masked = int(np.ma.getmaskarray(x).sum())
    if masked:
        raise bad('%s: masked values are not accepted (%d values of the numpy.ma array are masked); pass %s'
                  % (name, masked, instead))
    return x.data


def as_path(path: Any, name: str = 'path') -> bytes:
    """A str, bytes or os.PathLike path as the bytes given to the library's ``char *``; one
    holding a NUL character is refused, as ``open()`` refuses it (C would cut it short there)."""
    try:
        b = os.fsencode(path)
    except TypeError:
        raise bad_type('%s: expected a str, bytes or os.PathLike path, got %s' % (name, described(path))) from None
    if b'\0' in b:
        raise bad('%s: embedded null byte' % name)
    return b


def described(x: Any) -> str:
    """What `x` is, for a message: 'None', 'an int', 'a shapely.Polygon', 'a pandas.DataFrame'."""
    if x is None:
        return 'None'
    t = type(x)
    what = t.__name__ if t.__module__ == 'builtins' else t.__module__.partition('.')[0] + '.' + t.__name__
    return ('an ' if what[0] in 'aeiouAEIOU' else 'a ') + what


def is_geometry(x: Any) -> bool:
    """Whether `x` holds its points behind ``.exterior`` or ``.coords``, as a shapely geometry."""
    return hasattr(type(x), 'exterior') or hasattr(type(x), 'coords')


#: How to take the points of a shapely geometry.
GEOMETRY_POINTS = ('np.asarray(poly.exterior.coords) of a Polygon, np.asarray(line.coords) of a LineString or '
                   'LinearRing, or shapely.get_coordinates(geom)')


def not_real(name: str, x: Any, a: np.ndarray) -> InvalidArgumentError:
    """The error for `x` (as the array `a`) that does not hold real numbers: an object that is no
    array is named (a shapely geometry with how to take its points); an object array gets a hint,
    as a pandas nullable Float64 frame gives one."""
    if a.dtype == object and a.ndim == 0:
        how = ': pass its points, ' + GEOMETRY_POINTS if is_geometry(x) else ''
        return bad('%s: expected an array of real numbers, got %s%s' % (name, described(x), how))
    hint = ': convert it first, e.g. df.to_numpy(float)' if a.dtype == object else ''
    return bad('%s: expected real numbers, got an array of dtype %s%s' % (name, a.dtype, hint))


#: The hint for a list of OpenCV contours given where one is taken.
CONTOURS_HINT = ' (a list of OpenCV contours? pass one of them, e.g. max(contours, key=cv2.contourArea))'


#: What NumPy before 1.24 warned of a ragged list, where later ones raise ValueError.
RAGGED_WARNING = getattr(getattr(np, 'exceptions', np), 'VisibleDeprecationWarning', DeprecationWarning)


def not_regular(name: str, x: Any, e: Exception) -> InvalidArgumentError:
    """The error for points NumPy cannot make one array of (ragged lists): for a list of
    OpenCV contours of different lengths, the hint to pass one of them."""
    if isinstance(x, (list, tuple)) and x and all(isinstance(c, np.ndarray) and c.ndim == 3 and c.shape[1:] == (1, 2)
                                                  for c in x):
        return bad('%s: expected an array of shape (n, 2) (one x, y row per point) or (n, 1, 2) (OpenCV), '
                   'got %d arrays of different lengths%s' % (name, len(x), CONTOURS_HINT))
    return bad('%s: expected an array of shape (n, 2) (or one OpenCV contour, (n, 1, 2)): %s' % (name, e))


def image_contour_points(x: Any) -> Any:
    """The points of an :class:`ImageContour` (:func:`contours_from_mask`), else `x` itself."""
    from .contour import ImageContour  # contour imports this module
    return x.points if isinstance(x, ImageContour) else x


#: The point orders accepted by ``order=``: (x, y) columns, or (row, col) as scikit-image gives them.
ORDERS = ('xy', 'rc')


def as_order(order: Any) -> str:
    """Validates an ``order=`` argument: 'xy' or 'rc'."""
    if order not in ORDERS:
        raise bad("order: expected 'xy' (x = column, y = row) or 'rc' (row, column), got %r" % (order,))
    return order


def as_points(x: Any, name: str = 'points', order: str = 'xy', closed_shape: bool = False,
              allow_empty: bool = False) -> np.ndarray:
    """The one conversion of user points: array-like -> C-contiguous float64 (n, 2) array of
    (x, y) rows, n >= 1 (n >= 0 with allow_empty: then ``[]`` too), all finite.

    Accepts (n, 2) arrays of any real dtype, OpenCV contours ((n, 1, 2) int32 from
    ``cv2.findContours``, already (x, y)) and the :class:`ImageContour` s of
    :func:`contours_from_mask` (their points). ``order='rc'`` takes (row, col) points (scikit-image's
    ``measure.find_contours``) and swaps them: x = column, y = row. closed_shape (the points
    become a closed prepared shape): an OpenCV contour compressed by ``CHAIN_APPROX_SIMPLE`` is
    expanded to the pixel chain it stands for (:func:`expand_chain`).
    """
    order = as_order(order)
    if hasattr(x, 'input_points') and hasattr(x, 'scale_points'):
        raise TypeError('%s: expected an array of points, got a prepared Shape' % name)
    x = unmasked(image_contour_points(x), name,
                 'the points to keep, e.g. points[~points.mask.any(axis=1)], or points.filled(value)')
    try:
        with warnings.catch_warnings():  # NumPy < 1.24 made ragged lists object arrays, with this warning
            warnings.simplefilter('error', RAGGED_WARNING)
            a = np.asarray(x)
    except (ValueError, RAGGED_WARNING) as e:  # ragged nested lists, e.g. the whole tuple cv2.findContours returns
        raise not_regular(name, x, e) from None
    if a.dtype.kind not in 'iuf':
        raise not_real(name, x, a)
    if a.ndim == 3 and a.shape[1:] == (1, 2):  # an OpenCV contour
        a = a[:, 0, :]
        if closed_shape and a.dtype.kind in 'iu':
            a = expand_chain(a, name)
    if allow_empty and a.ndim == 1 and a.size == 0:  # [] or an empty array: no points
        a = a.reshape(0, 2)
    if a.ndim != 2 or a.shape[1] != 2:
        hint = CONTOURS_HINT if a.ndim == 4 and a.shape[2:] == (1, 2) else ''
        raise bad('%s: expected an array of shape (n, 2) (one x, y row per point) or (n, 1, 2) (OpenCV), '
                  'got shape %s%s' % (name, a.shape, hint))
    if a.shape[0] == 0 and not allow_empty:
        raise bad('%s: no points' % name)
    if order == 'rc':
        a = a[:, ::-1]
    a = np.ascontiguousarray(a, dtype=np.float64)
    finite = np.isfinite(a).all(axis=1)
    if not finite.all():
        i = int(np.argmin(finite))
        raise bad('%s: point %d is not finite: (%r, %r)' % (name, i, float(a[i, 0]), float(a[i, 1])))
    return a


def expand_chain(a: np.ndarray, name: str = 'points') -> np.ndarray:
    """The closed pixel chain an integer (n, 2) contour compressed by OpenCV's
    ``CHAIN_APPROX_SIMPLE`` stands for: each step to the next point (the last to the first
    included) along one of the 8 grid directions, split into unit steps (the points the
    compression dropped: the same outline, as ``CHAIN_APPROX_NONE`` gives it). `a` itself when
    some step is not along a grid direction or every step is already a unit step. A chain of
    more points than a contour may hold (``AMSCR_MAX_POINTS``) is an InvalidArgumentError, raised
    before it is made."""
    d = np.roll(a, -1, axis=0).astype(np.int64) - a
    k = np.abs(d).max(axis=1)
    along = (k > 0) & ((d[:, 0] == 0) | (d[:, 1] == 0) | (np.abs(d[:, 0]) == np.abs(d[:, 1])))
    if a.shape[0] < 2 or not along.all() or k.max() <= 1:
        return a
    total = int(k.sum())
    if total > lib.AMSCR_MAX_POINTS:
        raise bad('%s: this integer OpenCV contour stands for a pixel chain of %d points, more than the %d a '
                  'contour may hold (give its points as floats to use them as they are)'
                  % (name, total, lib.AMSCR_MAX_POINTS))
    i = np.repeat(np.arange(a.shape[0]), k)
    j = np.arange(total) - np.repeat(np.cumsum(k) - k, k)
    return a[i] + (d // k[:, None])[i] * j[:, None]


def points_in_order(xy: np.ndarray, order: str) -> np.ndarray:
    """(x, y) points returned in the caller's `order` (the inverse of :func:`as_points`'s swap)."""
    return np.ascontiguousarray(xy[:, ::-1]) if as_order(order) == 'rc' else xy


def as_float_array(x: Any, name: str, ndim: Optional[Tuple[int, ...]] = None, finite: bool = True) -> np.ndarray:
    try:
        a = np.asarray(x)
    except ValueError as e:
        raise bad('%s: not a regular array: %s' % (name, e)) from None
    if a.dtype.kind not in 'iuf':
        raise not_real(name, x, a)
    if ndim is not None and a.ndim not in ndim:
        raise bad('%s: expected %s dimension(s), got shape %s' % (name, ' or '.join(map(str, ndim)), a.shape))
    a = np.ascontiguousarray(a, dtype=np.float64)
    if finite and not np.isfinite(a).all():
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
        raise bad('%s: value at index %s is not finite' % (name, idx if len(idx) > 1 else idx[0]))
    return a


def as_scalar(x: Any, name: str) -> float:
    if isinstance(x, (str, bytes, bool, np.bool_)):
        raise bad_type('%s: expected a number, got %r' % (name, x))
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise bad('%s: expected a number, got %r' % (name, x)) from None
    return v


def as_index(x: Any, name: str) -> int:
    """An integer (int, a NumPy integer: operator.index), not a bool, float or str."""
    if not isinstance(x, (bool, np.bool_)):
        with contextlib.suppress(TypeError):
            return operator.index(x)
    raise bad_type('%s: expected an integer, got %r' % (name, x))


def as_count(x: Any, name: str, minimum: int = 0) -> int:
    v = as_index(x, name)
    if v < minimum:
        raise bad('%s: must be >= %d, got %d' % (name, minimum, v))
    return v


def as_uint(x: Any, name: str) -> int:
    """A count that fits the library's `unsigned` (32-bit) arguments."""
    v = as_count(x, name, 0)
    if v > 0xFFFFFFFF:
        raise bad('%s: too large (%d)' % (name, v))
    return v


def as_bool(x: Any, name: str) -> int:
    if isinstance(x, (bool, np.bool_)) or (isinstance(x, (int, np.integer)) and x in (0, 1)):
        return int(bool(x))
    raise bad('%s: expected True or False, got %r' % (name, x))


def new_object(ctype: str, make: Callable[..., int], free: Callable[[Any], None], *args: Any):
    """Calls ``make(*args, ctype **out)`` (a C constructor) and returns ``*out``, which the
    garbage collector frees with `free`."""
    out = ffi.new(ctype + ' **')
    _check(make(*args, out))
    return ffi.gc(out[0], free)


def dbuf(a: np.ndarray):
    """`double *` view of a C-contiguous float64 array (no copy)."""
    return ffi.from_buffer('double[]', a)


def saved_bytes(save_memory, obj) -> bytes:
    """The bytes of save_memory(obj, void **, size_t *) (a buffer the library allocated)."""
    buf = ffi.new('void **')
    n = ffi.new('size_t *')
    _check(save_memory(obj, buf, n))
    try:
        return bytes(ffi.buffer(buf[0], n[0]))
    finally:
        lib.amscr_free(buf[0])


def copy_doubles(p, count: int) -> np.ndarray:
    """Copies `count` doubles from a borrowed C pointer into a new numpy array."""
    if p == ffi.NULL:
        raise bad('no data (NULL pointer from the library)')
    return np.frombuffer(ffi.buffer(p, count * 8), dtype=np.float64).copy()


def copy_points(p, n: int) -> np.ndarray:
    """Copies n (x, y) points from a borrowed C pointer into a new (n, 2) array."""
    return copy_doubles(p, 2 * n).reshape(n, 2)


def sized_arrays(fn, *args: Any, arrays: int = 1, dtype: Any = np.float64, ctype: str = 'double[]'
                 ) -> Tuple[np.ndarray, ...]:
    """The library's two-call size pattern: ``fn(*args, NULL..., &n)`` asks for the length n,
    ``fn(*args, buf..., &n)`` fills `arrays` buffers of n values; returns them as numpy arrays."""
    n = ffi.new('size_t *', 0)
    _check(fn(*args, *([ffi.NULL] * arrays), n))
    bufs = [np.zeros(int(n[0]), dtype=dtype) for _ in range(arrays)]
    if n[0]:
        _check(fn(*args, *(ffi.from_buffer(ctype, b) for b in bufs), n))
    return tuple(b[:int(n[0])] for b in bufs)


def factorize(labels: Any, n: Optional[int] = None, name: str = 'labels') -> np.ndarray:
    """Any labels (ints, strings...) -> int32 codes; equal labels get equal codes."""
    a = np.asarray(labels)
    if a.ndim != 1:
        raise bad('%s: expected a 1-D sequence, got shape %s' % (name, a.shape))
    if n is not None and a.shape[0] != n:
        raise bad('%s: expected %d labels, got %d' % (name, n, a.shape[0]))
    if a.dtype.kind in 'iu' and (a.size == 0 or (a.min() >= INT32_MIN and a.max() <= INT32_MAX)):
        return np.ascontiguousarray(a, dtype=np.int32)
    try:
        _, codes = np.unique(a, return_inverse=True)
    except TypeError as e:
        raise bad('%s: labels cannot be compared: %s' % (name, e)) from None
    return np.ascontiguousarray(codes.reshape(-1), dtype=np.int32)


def to_m6(m: Any, name: str = 'matrix') -> np.ndarray:
    """3x3 (last row 0 0 1), 2x3 or flat 6 -> the library's {a11, a12, tx, a21, a22, ty}."""
    a = as_float_array(m, name)
    if a.shape == (3, 3):
        if not np.allclose(a[2], [0.0, 0.0, 1.0]):
            raise bad('%s: the last row of a 3x3 affine matrix must be (0, 0, 1), got %s' % (name, a[2]))
        a = a[:2]
    if a.shape not in ((2, 3), (6,)):
        raise bad('%s: expected a 3x3 or 2x3 affine matrix, got shape %s' % (name, a.shape))
    return np.ascontiguousarray(a.reshape(6))


def m6_to_matrix(m6) -> np.ndarray:
    out = np.eye(3)
    out[:2, :] = np.asarray([m6[i] for i in range(6)], dtype=np.float64).reshape(2, 3)
    return out


def matrix_out(fn, *args) -> np.ndarray:
    """Calls fn(*args, double[6]) and returns the 3x3 matrix."""
    m = ffi.new('double[6]')
    _check(fn(*args, m))
    return m6_to_matrix(m)


# ------------------------------------------------------------------ progress / cancellation
ProgressArg = Union[bool, Callable[[int, int], Any], None]


# progress=None (the default of long builds: Index) shows the bar only once the call has run this long
AUTO_AFTER = 2.0


def _stderr_is_terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


class _ProgressState:
    """Per-call state of the C progress callback (see `progress_call`)."""

    __slots__ = ('progress', 'error', 'last', 'started', 'shown', 'stream')

    def __init__(self, progress: ProgressArg):
        self.progress = progress
        self.error: Optional[BaseException] = None
        self.last = 0.0
        self.started = time.monotonic()
        self.shown = False
        self.stream = sys.stderr

    def update(self, done: int, total: int) -> int:
        p = self.progress
        if p is None:  # 'auto': a bar once the call has run AUTO_AFTER seconds, on a terminal
            p = self.progress = (True if time.monotonic() - self.started >= AUTO_AFTER and _stderr_is_terminal()
                                 else None)
            if p is None:
                return 0
        if p is True:
            now = time.monotonic()
            if done >= total or now - self.last >= 0.1:
                self.last = now
                self.bar(done, total, now)
            return 0
        if p:
            return 1 if p(done, total) is True else 0
        return 0

    def bar(self, done: int, total: int, now: float) -> None:
        width = 30
        frac = done / total if total else 1.0
        fill = int(round(width * frac))
        elapsed = now - self.started
        eta = (elapsed / frac - elapsed) if frac > 0 else float('nan')
        self.stream.write('\ramscr [%s%s] %d/%d %3d%% %.1fs%s' % (
            '#' * fill, '-' * (width - fill), done, total, int(100 * frac), elapsed,
            (' eta %.1fs' % eta) if 0 < frac < 1 else '   '))
        self.stream.flush()
        self.shown = True

    def finish(self) -> None:
        if self.shown:
            self.stream.write('\n')
            self.stream.flush()


_callback_errors = threading.local()


def _progress_onerror(exc_type, exc_value, tb):
    """An exception that escaped the trampoline itself: a signal (Ctrl-C) is raised as soon as the
    callback starts running Python code, before its try block. Keep it for progress_call (the
    callback runs on the thread that made the batch call) and cancel the call."""
    if getattr(_callback_errors, 'error', None) is None:
        _callback_errors.error = exc_value if exc_value is not None else exc_type()
    return 1


@ffi.callback('amscr_progress_fn', onerror=_progress_onerror)
def _progress_trampoline(user, done, total):
    state = ffi.from_handle(user)
    if state.error is not None:  # cancelled already: a report before the call returns is not passed on
        return 1
    try:
        return state.update(done, total)
    except BaseException as e:  # includes KeyboardInterrupt: cancel the call, re-raise after it
        state.error = e
        return 1


def progress_call(fn, args_before: tuple, args_after: tuple, progress: ProgressArg) -> None:
    """Calls fn(*args_before, callback, user, *args_after) with a progress callback.

    The callback is always installed, so Ctrl-C (KeyboardInterrupt) cancels a long call made
    from the main thread (a registration under way returns first; at the default points it takes
    milliseconds). An exception raised by a user's progress callable cancels the call
    and is re-raised here; a callable returning True cancels it (CancelledError).
    """
    if not (progress is None or isinstance(progress, (bool, np.bool_)) or callable(progress)):
        raise bad('progress: expected True, False, None or a callable(done, total), got %r' % (progress,))
    state = _ProgressState(progress)
    handle = ffi.new_handle(state)
    _callback_errors.error = None
    try:
        status = fn(*args_before, _progress_trampoline, handle, *args_after)
        error = state.error or _callback_errors.error
        if error is not None:  # the callback raised (or Ctrl-C): that is the error to report
            _callback_errors.error = None
            raise error
        _check(status)
    finally:
        state.finish()


# ------------------------------------------------------------------ locks
_LIVE_LOCKS: 'weakref.WeakSet[RWLock]' = weakref.WeakSet()
_FORK_HELD: List['RWLock'] = []


def _before_fork() -> None:
    """os.fork() waits for the calls under way on other threads (the C library's own locks, e.g.
    a collection's kept index, are held only inside them): a child then never inherits a lock
    held by a thread it does not have. Objects this thread is using (fork from a progress
    callback) are skipped. Each object is waited for holding nothing else (a call may read two
    objects), then every mutex is taken at once (no thread waits while holding one) and kept
    across fork(), so no call starts; a few retries if a call started in between."""
    me = threading.get_ident()
    locks = [lk for lk in list(_LIVE_LOCKS) if lk._owner != me and not lk._held()]
    for _ in range(100):
        for lk in locks:
            with lk._mutex:
                while lk._writer or lk._readers:
                    lk._cond.wait()
        for lk in locks:
            lk._mutex.acquire()
        _FORK_HELD.extend(locks)
        if not any(lk._writer or lk._readers for lk in locks):
            return
        _after_fork()


def _after_fork() -> None:
    while _FORK_HELD:
        lk = _FORK_HELD.pop()
        lk._mutex.release()


if hasattr(os, 'register_at_fork'):
    os.register_at_fork(before=_before_fork, after_in_parent=_after_fork, after_in_child=_after_fork)


class RWLock:
    """Many readers or one writer, writers first (a collection may be queried by many threads and
    added to by one; a waiting add() is not starved by a stream of queries). A thread may read
    again while it reads (a query from a query's progress callback); reading while it writes, or
    writing while it reads or writes (from a progress callback), is a StateError, not a
    deadlock."""

    def __init__(self) -> None:
        # A plain (C) lock: its __enter__/__exit__ run no Python code, so a KeyboardInterrupt
        # (Ctrl-C) cannot land between taking it and the with block that releases it.
        self._mutex = threading.Lock()
        self._cond = threading.Condition(self._mutex)
        self._readers = 0
        self._writer = False
        self._writers_waiting = 0
        self._owner: Optional[int] = None  # the writing thread
        self._mine = threading.local()  # this thread's reads held
        _LIVE_LOCKS.add(self)

    def _held(self) -> int:
        return getattr(self._mine, 'n', 0)

    def _refuse_reentry(self, writing: bool) -> None:
        if self._owner == threading.get_ident():
            raise StateError('amscr: this object is being changed by a call on this thread (from its progress '
                             'callback?); use it once that call returns', lib.AMSCR_E_STATE)
        if writing and self._held():
            raise StateError('amscr: this object cannot be changed from inside a call that reads it on this '
                             'thread (from its progress callback?); change it once that call returns',
                             lib.AMSCR_E_STATE)

    # Each count is changed together with a local flag in one run of bytecodes without a call (the
    # interpreter runs signal handlers only at calls and backward jumps), and undone in `finally`
    # exactly when it was made: a KeyboardInterrupt anywhere leaves the counts right.
    @contextlib.contextmanager
    def read(self) -> Iterator[None]:
        self._refuse_reentry(False)
        held = self._held()
        counted = False
        try:
            with self._mutex:
                while (self._writer or self._writers_waiting) and not held:
                    self._cond.wait()
                self._readers += 1
                counted = True
            self._mine.n = held + 1
            yield
        finally:
            if counted:
                self._mine.n = held
                with self._mutex:
                    self._readers -= 1
                    counted = False
                    self._cond.notify_all()

    @contextlib.contextmanager
    def write(self) -> Iterator[None]:
        self._refuse_reentry(True)
        waiting = owned = False
        try:
            with self._mutex:
                self._writers_waiting += 1
                waiting = True
                while self._writer or self._readers:
                    self._cond.wait()
                self._writers_waiting -= 1
                waiting = False
                self._writer = True
                owned = True
                self._owner = threading.get_ident()
            yield
        finally:
            if waiting or owned:
                with self._mutex:
                    if waiting:
                        self._writers_waiting -= 1
                        waiting = False
                    if owned:
                        self._writer = False
                        self._owner = None
                        owned = False
                    self._cond.notify_all()
