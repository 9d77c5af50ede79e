"""Contours (C ``amscr_contour``): tracing a mask, text point lists, orientation and validation.

The C contour is a private carrier here: functions take and return (n, 2) NumPy arrays of
(x, y) rows. Every function taking points accepts an OpenCV contour ((n, 1, 2) from
``cv2.findContours``) as it is, and an :class:`ImageContour` of :func:`contours_from_mask` (its
points); (row, col) points (scikit-image) are converted by
:func:`as_points` with ``order='rc'`` (or the ``order=`` keyword of :func:`register`,
:class:`Shape` and :class:`Collection`).
"""
from __future__ import annotations

import os
from typing import Any, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from ._util import (GEOMETRY_POINTS, MaskLike, Order, PathArg, PointArray, as_bool, as_count, as_path, as_scalar,
                    bad, bad_type, copy_points, dbuf, described, is_geometry, new_object, unmasked)
from ._util import as_points as _as_points
from .errors import InvalidArgumentError, LimitError, NotFoundError, _check


def _new_contour(make: Any, *args: Any):
    return new_object('amscr_contour', make, lib.amscr_contour_free, *args)


def as_points(points: PointArray, order: Order = 'xy') -> np.ndarray:
    """Points as amscr takes them: a new C-contiguous float64 (n, 2) array of (x, y) rows.

    Args:
        points: (n, 2) array-like of real numbers, an OpenCV contour ((n, 1, 2) int32 from
            ``cv2.findContours``, already (x, y)), or an :class:`ImageContour` (its points).
        order: 'xy' (default) or 'rc' for (row, col) points, as scikit-image's
            ``measure.find_contours`` gives them: x = column (col), y = row. Image contours
            are then in the frame of :func:`contour_from_mask`, OpenCV and
            ``skimage.transform``.
    Returns:
        (n, 2) float64 array of (x, y) rows.
    Raises:
        InvalidArgumentError: not (n, 2) / (n, 1, 2), not real numbers, no points, a
        non-finite value, masked values (``numpy.ma``), or a bad `order`; TypeError: a prepared
        :class:`Shape`.
    """
    return _as_points(points, 'points', order)


def contour_new(pts: np.ndarray):
    """A C contour holding a copy of the (n, 2) float64 array `pts` (validated by the caller)."""
    return _new_contour(lib.amscr_contour_new, dbuf(pts), pts.shape[0])


def contour_points(c) -> np.ndarray:
    """The points of a C contour, copied into an (n, 2) array."""
    return copy_points(lib.amscr_contour_xy(c), int(lib.amscr_contour_size(c)))


def _take(c) -> np.ndarray:
    """The points of an owned C contour, which is freed right away."""
    pts = contour_points(c)
    ffi.release(c)
    return pts


class _Image(NamedTuple):
    """A mask made ready for the C tracer: its samples, their bits, the iso-level, the trace
    flags, and the offset to take off the traced points (1 when a bool mask was padded)."""
    a: np.ndarray
    bits: int
    level: float
    flags: int
    offset: int


def _float_level(lo: float, hi: float, threshold: Any) -> float:
    """The 16-bit level of a float image of values lo..hi mapped onto 0..65535: `threshold` in
    the array's units, by default 0.5 when hi <= 1 (scikit-image's float images), else
    halfway between 0 (or lo, when negative) and hi (127.5 for a 0..255 image)."""
    if threshold is None:
        t = 0.5 if hi <= 1.0 else (hi / 2.0 if lo >= 0.0 else (lo + hi) / 2.0)
    else:
        t = as_scalar(threshold, 'threshold')
    level = 32767.5 if hi <= lo else (t - lo) * 65535.0 / (hi - lo)
    if threshold is None and (hi <= lo or not 0.0 <= level < 65535.0):
        # the default level misses the image's values: nothing to trace, as for an integer image
        what = 'no foreground: no value is above' if t >= hi else 'foreground everywhere: every value is above'
        msg = ("mask: %s the default level %g of this float image (values %g..%g); pass a threshold between "
               "them or threshold='auto'" % (what, t, lo, hi))
        raise NotFoundError(msg, lib.AMSCR_E_NOT_FOUND, msg)
    if not 0.0 <= level < 65535.0:
        raise bad('threshold: %g is outside the values of the image (%g..%g)' % (t, lo, hi))
    return level


def _as_samples(mask: MaskLike, threshold: Any) -> Tuple[np.ndarray, Optional[Tuple[float, float]], int]:
    """(uint8 or uint16 samples, the (lo, hi) of a float image mapped onto 16 bits or None, the
    padding): a bool mask becomes 0/255, padded with one pixel of background when True covers
    most of its border, since True is the foreground even there (no automatic polarity); a mask
    the tracer would not swap is not padded, so every mask within the image limits is traced."""
    a = np.asarray(unmasked(mask, 'mask', 'mask.filled(0) (masked pixels as background)'))
    if a.dtype == object and a.ndim == 0:
        raise _not_an_image(mask)
    if a.ndim != 2:
        raise bad('mask: expected a 2-D array, got shape %s' % (a.shape,))
    if not a.dtype.isnative:  # e.g. big-endian '>u2': as the native dtype (its tests below, the bytes C reads)
        a = a.astype(a.dtype.newbyteorder('='))
    if a.dtype == np.bool_:
        b = a.astype(np.uint8) * np.uint8(255)
        if not _border_mostly_true(a):  # the tracer keeps this polarity: no frame needed
            return b, None, 0
        h, w = a.shape
        if max(h, w) + 2 > lib.AMSCR_MAX_IMAGE_SIDE or (h + 2) * (w + 2) > lib.AMSCR_MAX_IMAGE_PIXELS:
            raise LimitError('mask: a %d x %d bool mask True over most of its border is traced with a frame of '
                             'False around it, which exceeds the image limits (%d per side, %d pixels): crop it'
                             % (w, h, lib.AMSCR_MAX_IMAGE_SIDE, lib.AMSCR_MAX_IMAGE_PIXELS),
                             lib.AMSCR_E_LIMIT, '')
        return np.pad(b, 1), None, 1
    if a.dtype.kind == 'f':
        if a.size and not np.all(np.isfinite(a)):
            raise bad('mask: non-finite values')
        a = a.astype(np.float64)  # float16 cannot hold the scale to 65535
        lo, hi = (float(a.min()), float(a.max())) if a.size else (0.0, 1.0)
        scaled = np.zeros(a.shape, np.uint16) if hi <= lo else np.rint((a - lo) * (65535.0 / (hi - lo)))
        return scaled.astype(np.uint16), (lo, hi), 0
    if a.dtype.kind not in 'iu':
        raise bad('mask: expected a bool, integer or float array, got dtype %s' % a.dtype)
    if a.dtype != np.uint8 and a.size and (a.min() < 0 or a.max() > 65535):
        raise bad('mask: values must be in 0..65535 for dtype %s (got %d..%d)' % (a.dtype, a.min(), a.max()))
    if a.dtype == np.uint8 or (a.dtype == np.uint16 and threshold is not None):  # a 16-bit level given
        return a, None, 0
    want = np.uint8 if not a.size or int(a.max()) <= 255 else np.uint16  # values up to 255: 8 bits
    return (a if a.dtype == want else a.astype(want)), None, 0


def _border_mostly_true(a: np.ndarray) -> bool:
    """Whether more than half of the border pixels of the bool array `a` (each counted once) are
    True: those the C tracer's automatic polarity would swap, unless framed with False."""
    h, w = a.shape
    if h <= 2 or w <= 2:
        on, n = int(np.count_nonzero(a)), a.size
    else:
        on = int(np.count_nonzero(a[0]) + np.count_nonzero(a[-1]) + np.count_nonzero(a[1:-1, 0]) +
                 np.count_nonzero(a[1:-1, -1]))
        n = 2 * w + 2 * (h - 2)
    return 2 * on > n


def _not_an_image(mask: Any) -> InvalidArgumentError:
    """The error for a mask that is no array (None, a shapely geometry: its points are a contour already)."""
    how = ': it is a contour already, pass its points where amscr takes points, ' + GEOMETRY_POINTS
    return bad('mask: expected a 2-D bool, integer or float array, got %s%s'
               % (described(mask), how if is_geometry(mask) else ''))


def _image_and_level(mask: MaskLike, threshold: Union[int, float, str, None], subpixel: bool) -> _Image:
    """The mask ready for the C tracer (see :func:`contour_from_mask`)."""
    a, scale, pad = _as_samples(mask, threshold)
    a = np.ascontiguousarray(a)
    bits = 16 if a.dtype == np.uint16 else 8
    top = 65535 if bits == 16 else 255
    flags = 0 if as_bool(subpixel, 'subpixel') else lib.AMSCR_TRACE_PIXEL_CHAIN
    if isinstance(threshold, str):
        if threshold.strip().lower() not in ('auto', 'otsu'):
            raise bad("threshold: expected a level, 'auto' or None, got %r" % threshold)
        return _Image(a, bits, -1.0, flags, pad)
    if scale is not None:  # a level in the array's units
        return _Image(a, bits, _float_level(scale[0], scale[1], threshold), flags, pad)
    if threshold is None and a.size and int(a.max()) <= 1:  # a 0/1 mask (mask.astype(np.uint8))
        return _Image(a, bits, 0.5, flags, pad)
    thr = (top // 2) if threshold is None else as_count(threshold, 'threshold', 0)
    if thr > top - 1:
        raise bad('threshold: expected 0..%d, got %d' % (top - 1, thr))
    return _Image(a, bits, 127.5 if pad else thr + 0.5, flags, pad)  # a bool: every threshold the same


def _traced(a: np.ndarray, level: float, call: Any, *args: Any) -> Any:
    """call(*args), whose NotFoundError on the integer image `a` traced at `level` (a threshold
    T at T + 0.5), with no value above the threshold but some above 0, names the brightest value
    and what to pass instead."""
    try:
        return call(*args)
    except NotFoundError as e:
        m = int(a.max()) if a.size else 0
        if level < 0 or not 0 < m < level:
            raise
        raise NotFoundError("mask: no value is above the threshold %d (the brightest is %d): pass a threshold "
                            "below %d, or threshold='auto'" % (int(level), m, m), e.status, e.detail) from None


def contour_from_mask(mask: MaskLike, threshold: Union[int, float, str, None] = None,
                      subpixel: bool = True, join: bool = False) -> np.ndarray:
    """Outer boundary of the largest 8-connected foreground component of a 2-D image.

    Args:
        mask: 2-D NumPy array (or what NumPy reads as one, e.g. a PIL image), any strides,
            order or byte order: ``bool`` (True = foreground, also where it covers most of the
            image border), ``uint8``, ``uint16`` (other integer arrays with values in 0..65535
            are accepted too), or ``float`` (any range: mapped linearly onto 16 bits).
        threshold: integer images: a pixel is "on" when its value is > threshold (0..254 for
            8 bits, 0..65534 for 16 bits; None: 0 when every value is 0 or 1, a 0/1 mask as
            ``mask.astype(np.uint8)`` gives, else 127, the ``amscr`` tool's default, or 32767
            for values past 255); float images: the level in the array's units (None: 0.5 when
            no value is above 1, as in scikit-image's float images, else halfway between 0 and
            the largest value, or between the smallest and the largest when some are negative:
            127.5 for ``img.astype(np.float32)`` of an 8-bit image); ``'auto'`` for
            Otsu's split (the level halfway between the two classes' medians); no effect on a
            bool mask, traced halfway between its pixels. The polarity of integer and float
            images is automatic: if most of the image border is "on", on and off are swapped
            (a bool mask is never swapped).
        subpixel: True (default): the iso-line at the level (threshold + 0.5 for integer
            images) by marching squares, to sub-pixel accuracy on grey and antialiased edges
            (a binary edge lies halfway between pixel centres); False: the chain of boundary
            pixel centres.
        join: True: the other large components near the largest (at least 5 % of its pixels,
            within its RMS radius, not in its holes) are joined to its outline by zero-width
            bridges — a shape an occluder cut in pieces keeps all its boundary (as ``amscr
            register``, ``search``, ``matrix``, ``eval`` and ``index`` trace images; sub-pixel
            only, ignored with subpixel=False).
    Returns:
        (n, 2) float array (x = column, y = row; pixel centres at integers), with positive
        signed area (counter-clockwise in a y-up frame), no repeated end point.
    Raises:
        NotFoundError: no foreground (or, but for a bool mask, foreground everywhere);
        DegenerateError: too small;
        LimitError: image too large; InvalidArgumentError: a bad mask (one with masked values:
        pass ``mask.filled(0)``) or threshold.
    """
    im = _image_and_level(mask, threshold, subpixel)
    flags = im.flags | (lib.AMSCR_TRACE_JOIN if as_bool(join, 'join') else 0)
    h, w = im.a.shape
    pts = _take(_traced(im.a, im.level, _new_contour, lib.amscr_contour_from_image, ffi.from_buffer(im.a), w, h, w,
                        im.bits, im.level, flags))
    return pts - im.offset if im.offset else pts


class ImageContour(NamedTuple):
    """One contour of :func:`contours_from_mask`: its points, its parent's index in the list
    (None for a top-level component), whether it is a hole, and its polygon area (pixels^2).
    Every function taking points takes it too (its points)."""
    points: np.ndarray
    parent: Optional[int]
    is_hole: bool
    area: float


def contours_from_mask(mask: MaskLike, threshold: Union[int, float, str, None] = None,
                       min_area: float = 10.0, subpixel: bool = True) -> List[ImageContour]:
    """Every contour of a 2-D image with its hierarchy, as OpenCV's ``findContours`` with
    ``RETR_TREE``: each 8-connected foreground component's outer boundary and each hole's.

    Args:
        mask, threshold, subpixel: as :func:`contour_from_mask`.
        min_area: contours of a smaller polygon area (pixels^2) are dropped, with everything
            inside them (default 10, the ``amscr contour --all`` default; 0 keeps all).
    Returns:
        A list of :class:`ImageContour` in raster order of their first pixel, so a parent
        comes before its children. Outer contours run counter-clockwise (positive signed area),
        holes clockwise: iso-lines (subpixel=True), or with subpixel=False through the
        component's boundary pixel centres and the hole's own boundary (background) pixels. A
        hole's parent is the component around it; a component's parent is the hole it lies in,
        or None.
    Raises:
        NotFoundError: no foreground, foreground everywhere (but for a bool mask), or no
        contour of `min_area`;
        InvalidArgumentError: a bad mask, threshold or min_area; LimitError: image too large.
    """
    im = _image_and_level(mask, threshold, subpixel)
    area = as_scalar(min_area, 'min_area')
    h, w = im.a.shape
    out = ffi.new('amscr_contour_set **')
    _traced(im.a, im.level, lambda: _check(lib.amscr_contours_from_image(ffi.from_buffer(im.a), w, h, w, im.bits,
                                                                        im.level, im.flags, area, out)))
    cs = ffi.gc(out[0], lib.amscr_contour_set_free)
    result = []
    for i in range(int(lib.amscr_contour_set_size(cs))):
        parent = int(lib.amscr_contour_set_parent(cs, i))
        result.append(ImageContour(contour_points(lib.amscr_contour_set_contour(cs, i)) - im.offset,
                                   None if parent == int(ffi.cast('size_t', -1)) else parent,
                                   bool(lib.amscr_contour_set_is_hole(cs, i)),
                                   float(lib.amscr_contour_set_area(cs, i))))
    ffi.release(cs)
    return result


def read_points(path: PathArg) -> np.ndarray:
    """Reads a text point list ("x y" or "x,y" per line, '#' comments).

    The decimal point is '.', whatever locale the program set (``locale.setlocale``).

    Args:
        path: the file (``amscr contour IMG -o FILE`` writes one from a PNG or PGM).
    Returns:
        (n, 2) float array of (x, y) rows.
    Raises:
        FileError: cannot read; FormatError: a bad line (the message names path:line);
        InvalidArgumentError: a path holding a NUL character.
    """
    return _take(_new_contour(lib.amscr_contour_read_text, as_path(path)))


def parse_points(text: Union[str, bytes]) -> np.ndarray:
    """Parses a text point list from a string.

    Args:
        text: str or bytes in the format of :func:`read_points` (a file's content: a file is
            read by :func:`read_points`).
    Returns:
        (n, 2) float array of (x, y) rows.
    Raises:
        FormatError: a bad line (the message names the line); TypeError (also an
        InvalidArgumentError): a path (``os.PathLike``) or anything else that is no text.
    """
    if isinstance(text, os.PathLike):
        raise bad_type('text: expected the text of a point list (str or bytes), got %s: read a file with '
                       'amscr.read_points(path)' % described(text))
    if not isinstance(text, (str, bytes, bytearray, memoryview)):  # bytes(5) would be five NUL bytes
        raise bad_type('text: expected the text of a point list (str or bytes), got %s' % described(text))
    b = text.encode('utf-8') if isinstance(text, str) else bytes(text)
    return _take(_new_contour(lib.amscr_contour_parse_text, ffi.from_buffer('char[]', b), len(b)))


def write_points(path: PathArg, points: PointArray) -> None:
    """Writes points as a text point list, atomically (whole before it takes its name), with '.'
    as the decimal point whatever locale the program set.

    Args:
        path: the file to write.
        points: (n, 2) points (or an OpenCV contour).
    Raises:
        InvalidArgumentError: bad points, a path holding a NUL character; FileError: the file
        cannot be written.
    """
    c = contour_new(_as_points(points))
    _check(lib.amscr_contour_write_text(c, as_path(path)))


def signed_area(points: PointArray) -> float:
    """Signed area of the closed polygon.

    Args:
        points: (n, 2) points (or an OpenCV contour).
    Returns:
        the area, positive when counter-clockwise in a y-up frame (clockwise on screen, y down).
    Raises:
        InvalidArgumentError: bad points.
    """
    c = contour_new(_as_points(points))
    out = ffi.new('double *')
    _check(lib.amscr_contour_signed_area(c, out))
    return float(out[0])


def orient_ccw(points: PointArray) -> np.ndarray:
    """A copy of the points, reversed when their signed area is negative.

    Args:
        points: (n, 2) points (or an OpenCV contour).
    Returns:
        (n, 2) float array with a signed area >= 0.
    Raises:
        InvalidArgumentError: bad points.
    """
    c = contour_new(_as_points(points))
    _check(lib.amscr_contour_orient_ccw(c))
    return contour_points(c)


def validate_contour(points: PointArray, closed: bool = True) -> None:
    """Checks that a contour can be registered.

    Args:
        points: (n, 2) points (or an OpenCV contour).
        closed: True for a closed curve, False for an open one.
    Raises:
        DegenerateError: too few distinct points, an extent outside 1e-60 to 1e60, zero area when
        closed, all collinear when open; InvalidArgumentError: bad points.
    """
    c = contour_new(_as_points(points))
    _check(lib.amscr_contour_validate(c, as_bool(closed, 'closed')))
