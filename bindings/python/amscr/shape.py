"""Shape: a prepared shape (C ``amscr_descriptor``)."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from ._lib import ffi, lib
from ._util import Order, PointArray, as_count, as_points, copy_points, forward_ref, matrix_out, new_object
from .contour import contour_new
from .params import Params, make_params


class Shape:
    """A prepared shape (C ``amscr_descriptor``): resampled, parametrized, whitened and smoothed at
    every scale once, then matched any number of times. Immutable (its point arrays are new
    copies at every call); shareable between threads. Pickles (multiprocessing) as the same
    prepared shape: one made from points is prepared again from them, one of
    :meth:`Collection.shape` travels as its prepared samples.

    Args:
        contour: the shape's points: an (n, 2) array of (x, y) rows (any real dtype), or an
            OpenCV contour ((n, 1, 2), as ``cv2.findContours`` gives it; closed, one compressed by
            ``CHAIN_APPROX_SIMPLE`` is read as the pixel chain it stands for, as
            ``CHAIN_APPROX_NONE`` gives it), or an :class:`ImageContour` (its points).
        params: a :class:`Params` to start from (None: the library defaults).
        order: 'xy' (default) or 'rc' for (row, col) points such as scikit-image's
            ``measure.find_contours`` gives; they are taken as x = column, y = row, so every
            output (points, matrices) is in the (x, y) image frame.
        **options: options of :class:`Params` (e.g. ``Shape(pts, points=256)``).
    Raises:
        InvalidArgumentError: bad points or options; DegenerateError: too few distinct points
        or zero area.
    """

    def __init__(self, contour: PointArray, /, params: Optional[Params] = None, *, order: Order = 'xy',
                 **options: Any):
        p = make_params(params, options)
        pts = as_points(contour, 'contour', order, closed_shape=p.closed)
        self._d = new_object('amscr_descriptor', lib.amscr_descriptor_new, lib.amscr_descriptor_free,
                             p._p, contour_new(pts))
        self._owner = None
        self._source: Optional[np.ndarray] = pts.copy()

    @classmethod
    def _borrowed(cls, dptr, owner: Any) -> 'Shape':
        """A view of `dptr`, the shape 0 of `owner`, a one-shape Collection that the view keeps
        alive (and pickles as) and which must never be modified (see Collection.shape)."""
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
        """N, samples per scale."""
        return self.num_samples

    @property
    def points(self) -> np.ndarray:
        """(N, 2) normalized (centred, whitened), unsmoothed points."""
        return copy_points(lib.amscr_descriptor_base_points(self._d), self.num_samples)

    def scale_points(self, k: int) -> np.ndarray:
        """The normalized points smoothed at one scale.

        Args:
            k: the scale index, 0 <= k < num_scales.
        Returns:
            (N, 2) float array.
        Raises:
            IndexError: `k` out of range; InvalidArgumentError: `k` not an integer >= 0.
        """
        k = as_count(k, 'k', 0)
        if k >= self.num_scales:
            raise IndexError('scale %d out of range (the shape has %d scales)' % (k, self.num_scales))
        return copy_points(lib.amscr_descriptor_scale_points(self._d, k), self.num_samples)

    @property
    def input_points(self) -> np.ndarray:
        """(N, 2) sampled points in input coordinates (before normalization)."""
        return copy_points(lib.amscr_descriptor_input_points(self._d), self.num_samples)

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
        """True when the shape is a closed curve."""
        return bool(lib.amscr_params_get_closed(lib.amscr_descriptor_params(self._d)))

    def __repr__(self) -> str:
        return 'Shape(N=%d, scales=%d)' % (self.num_samples, self.num_scales)

    def __reduce__(self):
        if self._source is None:  # a collection's shape: its one-shape collection, bit for bit
            return (_shape_of, (self._owner,))
        return (_shape_from_state, (self._source, self.params))


if TYPE_CHECKING:
    #: What the matching functions accept for a shape: an (n, 2) point array or a prepared Shape.
    PointsLike = Union[PointArray, 'Shape']
else:  # resolvable by typing.get_type_hints in every module (see forward_ref)
    PointsLike = Union[PointArray, forward_ref('Shape', __name__)]


def _shape_from_state(points: np.ndarray, params: Params) -> Shape:
    return Shape(points, params)


def _shape_of(owner: Any) -> Shape:
    """The shape of `owner`, an unpickled one-shape Collection (see Collection.shape)."""
    return Shape._borrowed(lib.amscr_db_descriptor(owner._db, 0), owner)


def as_shape(x: PointsLike, params: Params, name: str, order: str = 'xy') -> Shape:
    """`x` itself when it is a Shape, else the points `x` (in `order`) prepared with `params`."""
    if isinstance(x, Shape):
        return x
    return Shape(as_points(x, name, order, closed_shape=params.closed), params)
