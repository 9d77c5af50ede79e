"""Collection: many prepared shapes with labels (C ``amscr_db``), and :func:`distance_matrix`."""
from __future__ import annotations

import contextlib
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from ._util import (Order, PathArg, ProgressArg, RWLock, as_index, as_path, as_points, as_uint, bad, dbuf, factorize,
                    new_object, progress_call, saved_bytes)
from .contour import contour_new
from .errors import AmscrError, _check
from .params import Params, make_params
from .shape import PointsLike, Shape, as_shape


def _new_db(make: Any, *args: Any):
    return new_object('amscr_db', make, lib.amscr_db_free, *args)


class Collection:
    """Many prepared shapes with labels (C ``amscr_db``), for 1-vs-many queries and distance matrices.

    ``Collection(params=None, **options)`` — the options are those of :class:`Params`; every shape
    is prepared with them. Batch calls run on ``threads`` POSIX threads (0 = all cores) with the
    GIL released, and give bit-identical results for any thread count.

    Labels are int32 values, or any other hashable values (e.g. strings), which are mapped to
    codes 0, 1, ... in order of first use (:attr:`labels` gives them back; saved files hold codes).
    Thread-safety: any number of threads may query at once; :meth:`add` waits for them.

    A pickled collection (multiprocessing) holds its shapes but not the index that retrieval
    queries keep (see :meth:`query`): the copy builds it again on its first retrieval query
    (every pair, O(n²)); send an :class:`Index` to processes that run retrieval queries.

    Args:
        params: a :class:`Params` to start from (None: the library defaults, tuned for
            collections: N = 128, no refinement).
        **options: options of :class:`Params`, e.g. ``reflections=True, threads=0``.
    Raises:
        InvalidArgumentError: a bad option.
    """

    def __init__(self, params: Optional[Params] = None, **options: Any):
        p = make_params(params, options)
        self._init(_new_db(lib.amscr_db_new, p._p))

    def _init(self, db, label_names: Optional[Sequence[Any]] = None) -> None:
        """Adopts `db`, an owned C collection (from _new_db)."""
        self._db = db
        self._lock = RWLock()
        self._label_names: Optional[List[Any]] = list(label_names) if label_names is not None else None
        self._label_codes: Dict[Any, int] = ({n: i for i, n in enumerate(self._label_names)}
                                             if self._label_names is not None else {})
        # a loaded collection without names holds int labels already
        self._int_labels = self._label_names is None and int(lib.amscr_db_size(db)) > 0

    @classmethod
    def _wrap(cls, db, label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        self = cls.__new__(cls)
        self._init(db, label_names)
        return self

    def _add_copies(self, src: 'Collection', indices: Iterable[int]) -> None:
        """Adds copies of the prepared shapes `indices` of `src` (label 0). The caller holds
        src's read lock; self is a private collection nobody else sees yet."""
        for i in indices:
            _check(lib.amscr_db_add_descriptor(self._db, lib.amscr_db_descriptor(src._db, i), 0, ffi.NULL))

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

    def add(self, shape: PointsLike, label: Any = 0, *, order: Order = 'xy') -> int:
        """Prepares (points) or copies (a :class:`Shape`) a shape into the collection.

        Args:
            shape: (n, 2) points, an OpenCV (n, 1, 2) contour, or a prepared :class:`Shape`.
            label: an int32 class label, or any hashable name (not both kinds in one collection).
            order: 'xy' (default) or 'rc' for (row, col) points (scikit-image).
        Returns:
            the index of the new shape.
        Raises:
            InvalidArgumentError: bad points or label; DegenerateError: a degenerate shape.
        """
        with self._lock.write():
            code = self._label_code(label)
            idx = ffi.new('size_t *')
            if isinstance(shape, Shape):
                _check(lib.amscr_db_add_descriptor(self._db, shape._d, code, idx))
            else:
                c = contour_new(as_points(shape, 'shape', order, closed_shape=self._closed()))
                _check(lib.amscr_db_add_contour(self._db, c, code, idx))
            return int(idx[0])

    def extend(self, shapes: Iterable[PointsLike], labels: Optional[Iterable[Any]] = None, *,
               order: Order = 'xy', progress: ProgressArg = False) -> List[int]:
        """Adds many shapes, as :meth:`add`; point arrays are prepared together on the
        collection's threads with the GIL released (C ``amscr_db_add_contours``).

        Args:
            shapes: point arrays or :class:`Shape` s.
            labels: one label per shape (None: all 0).
            order: 'xy' (default) or 'rc', the order of every shape's points.
            progress: True for a progress bar on stderr, or a callable (done, total) -> bool
                (True cancels); point arrays only.
        Returns:
            the indices of the new shapes.
        Raises:
            InvalidArgumentError: as many labels as shapes are needed; as :meth:`add`.
            DegenerateError: a shape cannot be prepared (the message names the first such
                shape by its position in ``shapes``). Point arrays are added all or nothing.
        """
        shapes = list(shapes)
        labels = [0] * len(shapes) if labels is None else list(labels)
        if len(labels) != len(shapes):
            raise bad('extend: %d shapes but %d labels' % (len(shapes), len(labels)))
        if not shapes:
            return []
        if any(isinstance(s, Shape) for s in shapes):
            return self._extend_shapes(shapes, labels, order)
        closed = self._closed()
        contours = [contour_new(as_points(s, 'shapes[%d]' % i, order, closed_shape=closed))
                    for i, s in enumerate(shapes)]
        with self._lock.write():
            kept = (None if self._label_names is None else list(self._label_names), dict(self._label_codes),
                    self._int_labels)
            try:
                codes = ffi.new('int32_t[]', [self._label_code(lab) for lab in labels])
                first = len(self)
                progress_call(lib.amscr_db_add_contours, (self._db, ffi.new('amscr_contour *[]', contours), codes,
                                                          len(contours)), (ffi.NULL,), progress)
            except BaseException:
                self._label_names, self._label_codes, self._int_labels = kept
                raise
            return list(range(first, first + len(contours)))

    def _extend_shapes(self, shapes: List[Any], labels: List[Any], order: str) -> List[int]:
        """extend of a list holding prepared Shapes: every point array is prepared and every
        shape is tried in a scratch collection (the params must be the collection's) before
        one is added, so a bad shape adds none and is named by its position."""
        params, scratch = self.params, _new_db(lib.amscr_db_new, self.params._p)
        prepared = []
        for i, s in enumerate(shapes):
            try:
                prepared.append(as_shape(s, params, 'shapes[%d]' % i, order))
                _check(lib.amscr_db_add_descriptor(scratch, prepared[-1]._d, 0, ffi.NULL))
            except AmscrError as e:
                where = 'shapes[%d]' % i
                msg = e.message if where in e.message else '%s: %s' % (where, e.message)
                raise type(e)(msg, e.status, e.detail) from None
        with self._lock.write():
            kept = (None if self._label_names is None else list(self._label_names), dict(self._label_codes),
                    self._int_labels)
            try:
                codes = [self._label_code(lab) for lab in labels]
                first = len(self)
                for s, code in zip(prepared, codes):
                    _check(lib.amscr_db_add_descriptor(self._db, s._d, code, ffi.NULL))
            except BaseException:
                self._label_names, self._label_codes, self._int_labels = kept
                raise
            return list(range(first, first + len(prepared)))

    # -- reading ----------------------------------------------------------------------
    def __len__(self) -> int:
        """The number of shapes."""
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

    def _closed(self) -> bool:
        """Whether the collection's shapes are closed curves (its params, without a copy)."""
        return bool(lib.amscr_params_get_closed(lib.amscr_db_params(self._db)))

    def shape(self, i: int) -> Shape:
        """A copy of the prepared shape i (a copy, because the C collection's own descriptors
        are only valid until it is modified).

        Args:
            i: the index, an integer; negative indices count from the end.
        Returns:
            a :class:`Shape`.
        Raises:
            IndexError: `i` out of range; TypeError: `i` not an integer (a float, str or bool).
        """
        i = as_index(i, 'i')
        with self._lock.read():
            n = len(self)
            if i < 0:
                i += n
            if not 0 <= i < n:
                raise IndexError('shape index %d out of range (%d shapes)' % (i, n))
            holder = Collection(self.params)  # a private, never modified, one-shape collection
            holder._add_copies(self, (i,))
        return Shape._borrowed(lib.amscr_db_descriptor(holder._db, 0), holder)

    def __repr__(self) -> str:
        return 'Collection(%d shapes)' % len(self)

    # -- matching ---------------------------------------------------------------------
    def _with_threads(self, threads: Optional[int]) -> Tuple['Collection', bool]:
        """(a collection computing with `threads`, whether it is a temporary copy)."""
        if threads is None or as_uint(threads, 'threads') == self.params.threads:
            return self, False
        tmp = Collection(self.params, threads=threads)
        tmp._add_copies(self, range(len(self)))
        return tmp, True

    def query(self, shape: PointsLike, threads: Optional[int] = None, progress: ProgressArg = False, *,
              order: Order = 'xy') -> np.ndarray:
        """Distances from `shape` to every shape of the collection, by the collection's own
        params: the plain AMSCR distance (query -> shape) with the defaults, and the retrieval
        scores (C ``amscr_db_search_retrieval``: the query's row of :meth:`retrieval_matrix` on
        the collection plus the query, shape channel, fusion and re-ranking) when the params
        ask for retrieval (:attr:`Params.ranking` 'retrieval': ``channel_weight`` > 0 or
        ``rerank_k`` > 0, e.g. :meth:`Params.retrieval`). Retrieval scores come from an exact
        index of the collection that the first such query builds (every pair: O(n²) once) and
        the collection keeps; a query after :meth:`add` first enters the new shapes (O(n) a
        shape), and every query then costs O(n), as :meth:`Index.query` with ``candidates=0``.
        With a ``channel_weight`` strictly between 0 and 1 the fusion uses the collection's
        medians (those of the first query's build), not medians moved by the query. A query
        whose prepared samples are a shape's of the collection, bit for bit (the member rule,
        :meth:`Index.find_member`), gets that shape's row of the collection's own retrieval
        matrix when the scores re-rank, fuse or take the shape channel (C
        ``amscr_db_search_retrieval``), as :meth:`Index.query` and ``amscr search`` give it.

        Args:
            shape: the query: (n, 2) points, an OpenCV (n, 1, 2) contour or a :class:`Shape`.
            threads: threads for this call (None: the collection's; retrieval scores always
                use the collection's, with the index it keeps).
            progress: True for a progress bar on stderr, or a callable(done, total) (returning
                True cancels with CancelledError; an exception it raises cancels and propagates).
            order: 'xy' (default) or 'rc' for (row, col) points (scikit-image).
        Returns:
            (len(self),) float array; rank it with :func:`topk` or ``numpy.argsort``.
        Raises:
            InvalidArgumentError: bad points; DegenerateError: a degenerate query;
            CancelledError: cancelled by `progress`; KeyboardInterrupt: Ctrl-C (a registration under
            way returns first; at the default points it takes milliseconds).
        """
        with self._lock.read():
            p = self.params
            if threads is not None:
                as_uint(threads, 'threads')
            q = as_shape(shape, p, 'shape', order)
            out = np.zeros(len(self), dtype=np.float64)
            if p.ranking == 'retrieval':  # the collection's kept index (a copy would build its own)
                progress_call(lib.amscr_db_search_retrieval, (self._db, q._d), (dbuf(out), len(out)), progress)
            elif threads is None or int(threads) == p.threads:
                progress_call(lib.amscr_db_query, (self._db, q._d), (dbuf(out),), progress)
            else:
                qdb = Collection(p, threads=threads)
                _check(lib.amscr_db_add_descriptor(qdb._db, q._d, 0, ffi.NULL))
                progress_call(lib.amscr_db_cross_distances, (qdb._db, self._db), (dbuf(out),), progress)
            return out

    def distance_matrix(self, threads: Optional[int] = None, progress: ProgressArg = False) -> np.ndarray:
        """All pairwise distances of the collection.

        Args:
            threads: threads for this call (None: the collection's).
            progress: True for a progress bar on stderr, or a callable(done, total), as in
                :meth:`query`.
        Returns:
            (n, n) float array, ``D[i, j]`` = distance(shape i -> shape j); zero diagonal.
        Raises:
            CancelledError: cancelled by `progress`; KeyboardInterrupt: Ctrl-C (a registration under
            way returns first; at the default points it takes milliseconds).
        """
        with self._lock.read():
            src, _ = self._with_threads(threads)
            n = len(self)
            out = np.zeros((n, n), dtype=np.float64)
            progress_call(lib.amscr_db_distance_matrix, (src._db,), (dbuf(out),), progress)
            return out

    def channel_matrix(self, threads: Optional[int] = None, progress: ProgressArg = False) -> np.ndarray:
        """All pairwise distances of the shape channel (C ``amscr_db_channel_matrix``): height
        functions matched by banded dynamic programming, in the frame(s) of the collection's
        ``channel_invariance`` / ``channel_affine_share``; closed curves only.

        Args:
            threads: threads for this call (None: the collection's).
            progress: as in :meth:`query`.
        Returns:
            (n, n) float array, symmetric, zero diagonal.
        Raises:
            InvalidArgumentError: open curves; CancelledError: cancelled by `progress`.
        """
        return self._matrix(lib.amscr_db_channel_matrix, threads, progress)

    def retrieval_matrix(self, threads: Optional[int] = None, progress: ProgressArg = False) -> np.ndarray:
        """The retrieval distance (C ``amscr_db_retrieval_matrix``): the AMSCR matrix
        (symmetrized) and the shape channel, each divided by its median off-diagonal value and
        mixed by ``channel_weight``, then diffusion re-ranking when ``rerank_k`` > 0 (scores
        in [0, 1], 0 for a shape itself). With :meth:`Params.retrieval` this is the project's
        default retrieval; with channel weight 0 and no re-ranking it is the symmetrized
        :meth:`distance_matrix`.

        Args:
            threads: threads for this call (None: the collection's).
            progress: as in :meth:`query`.
        Returns:
            (n, n) float array for ranking, zero diagonal.
        Raises:
            InvalidArgumentError: open curves with a channel weight; CancelledError: cancelled
            by `progress`.
        """
        return self._matrix(lib.amscr_db_retrieval_matrix, threads, progress)

    def retrieval_matrix_heldout(self, groups: Sequence[Any], threads: Optional[int] = None,
                                 progress: ProgressArg = False) -> np.ndarray:
        """The retrieval matrix with each group held out in turn (C
        ``amscr_db_retrieval_matrix_heldout``; ``amscr eval --protocol groups``): row i holds
        shape i's scores as a new query against the collection without i's group, whose fusion
        medians and re-ranking graph are computed without the group. Its own group's entries
        are +inf (diagonal 0). :func:`amscr.nn_groups` on it is the leave-one-group-out
        accuracy of a collection that never saw the group (on :meth:`retrieval_matrix` the
        group's own shapes shape its neighbours' graph, which flatters or hurts the figure).

        Args:
            groups: n group names or ids (at least two distinct), e.g. the object of each view.
            threads: threads for this call (None: the collection's).
            progress: as in :meth:`query`.
        Returns:
            (n, n) float array for ranking.
        Raises:
            InvalidArgumentError: not one group per shape, a single group, open curves with a
            channel weight; CancelledError: cancelled by `progress`.
        """
        with self._lock.read():
            src, _ = self._with_threads(threads)
            n = len(self)
            codes = factorize(groups, n, 'groups')
            out = np.zeros((n, n), dtype=np.float64)
            progress_call(lib.amscr_db_retrieval_matrix_heldout, (src._db, ffi.from_buffer('int32_t[]', codes), n),
                          (dbuf(out),), progress)
            return out

    def _matrix(self, fn: Any, threads: Optional[int], progress: ProgressArg) -> np.ndarray:
        with self._lock.read():
            src, _ = self._with_threads(threads)
            n = len(self)
            out = np.zeros((n, n), dtype=np.float64)
            progress_call(fn, (src._db,), (dbuf(out),), progress)
            return out

    def cross_matrix(self, other: 'Collection', threads: Optional[int] = None,
                     progress: ProgressArg = False) -> np.ndarray:
        """Distances from this collection's shapes (queries) to `other`'s (targets), with this
        collection's options.

        Args:
            other: the target :class:`Collection`.
            threads: threads for this call (None: the collection's).
            progress: as in :meth:`query`.
        Returns:
            (len(self), len(other)) float array.
        Raises:
            TypeError: `other` is not a Collection; CancelledError: cancelled by `progress`.
        """
        if not isinstance(other, Collection):
            raise TypeError('other: expected an amscr.Collection, got %s' % type(other).__name__)
        with self._lock.read(), (other._lock.read() if other is not self else contextlib.nullcontext()):
            src, _ = self._with_threads(threads)
            out = np.zeros((len(self), len(other)), dtype=np.float64)
            progress_call(lib.amscr_db_cross_distances, (src._db, other._db), (dbuf(out),), progress)
            return out

    # -- persistence ------------------------------------------------------------------
    def save(self, path: PathArg) -> None:
        """Writes the prepared collection (binary, versioned, checksummed; atomic rename).

        Args:
            path: the file to write. Named labels are stored as their codes (give the names
                back to :meth:`load`).
        Raises:
            FileError: the file cannot be written; InvalidArgumentError: a path holding a NUL
            character.
        """
        with self._lock.read():
            _check(lib.amscr_db_save(self._db, as_path(path)))

    @classmethod
    def load(cls, path: PathArg, label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        """Reads a collection written by :meth:`save` (or the ``amscr`` tool).

        Args:
            path: the file.
            label_names: if given, ``label_names[code]`` names the stored label codes again.
        Returns:
            a new :class:`Collection`.
        Raises:
            FileError: cannot read; FormatError: not a collection file, or a corrupt one;
            InvalidArgumentError: a path holding a NUL character.
        """
        return cls._wrap(_new_db(lib.amscr_db_load, as_path(path)), label_names)

    def to_bytes(self) -> bytes:
        """The collection serialized as :meth:`save` writes it.

        Returns:
            bytes (give them to :meth:`from_bytes`).
        """
        with self._lock.read():
            return saved_bytes(lib.amscr_db_save_memory, self._db)

    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview],
                   label_names: Optional[Sequence[Any]] = None) -> 'Collection':
        """The inverse of :meth:`to_bytes`.

        Args:
            data: bytes written by :meth:`to_bytes` (or a saved file's content).
            label_names: as in :meth:`load`.
        Returns:
            a new :class:`Collection`.
        Raises:
            FormatError: not a serialized collection, or a corrupt one.
        """
        b = bytes(data)
        return cls._wrap(_new_db(lib.amscr_db_load_memory, ffi.from_buffer(b), len(b)), label_names)

    def __reduce__(self):
        with self._lock.read():  # the names of these shapes (extend appends to the list, then drops it on failure)
            names = None if self._label_names is None else list(self._label_names)
            return (_collection_from_state, (self.to_bytes(), names))


def _collection_from_state(data: bytes, label_names: Optional[List[Any]]) -> Collection:
    return Collection.from_bytes(data, label_names)


def distance_matrix(shapes: Iterable[PointsLike], *, threads: Optional[int] = None, progress: ProgressArg = False,
                    params: Optional[Params] = None, order: Order = 'xy', **options: Any) -> np.ndarray:
    """All pairwise distances of a list of shapes (through a temporary :class:`Collection`).

    Args:
        shapes: point arrays (or OpenCV contours) or :class:`Shape` s, any iterable.
        threads: threads (None: the library default, 0 = all cores).
        progress: True for a progress bar on stderr, or a callable(done, total), as in
            :meth:`Collection.query`.
        params: a :class:`Params` to start from (None: the library defaults).
        order: 'xy' (default) or 'rc' for (row, col) points.
        **options: options of :class:`Params`.
    Returns:
        (n, n) float array, ``D[i, j]`` = distance(shape i -> shape j).
    Raises:
        InvalidArgumentError: bad points or options; DegenerateError: a degenerate shape;
        CancelledError: cancelled by `progress`.
    """
    db = Collection(params, threads=threads, **options)
    db.extend(shapes, order=order)
    return db.distance_matrix(progress=progress)
