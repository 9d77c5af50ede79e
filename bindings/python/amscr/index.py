"""Index: a collection prepared for one-vs-many retrieval (C ``amscr_index``)."""
from __future__ import annotations

from typing import Any, List, Optional, Tuple, Union

import numpy as np

from ._lib import ffi, lib
from ._util import (Order, PathArg, ProgressArg, RWLock, as_count, as_path, bad, dbuf, new_object, progress_call,
                    saved_bytes)
from .collection import Collection, _new_db
from .errors import _check, _reworded
from .params import Params
from .shape import PointsLike, as_shape


def _new_index(make: Any, *args: Any):
    return new_object('amscr_index', make, lib.amscr_index_free, *args)


def _loaded_index(make: Any, *args: Any):
    """_new_index of a load: the index file format is a collection's with an index section, so
    the library's "not an amscr collection" says index."""
    with _reworded(('not an amscr collection', 'not an amscr index')):
        return _new_index(make, *args)


def _candidates(candidates: Optional[int]) -> int:
    """The shortlist size the C calls take: None is the library's default."""
    if candidates is None:
        return int(lib.AMSCR_INDEX_CANDIDATES)
    return as_count(candidates, 'candidates', 0)


#: Index.add's errors under the Python names (the option a shape differs in, as Params names it).
_ADD_NAMES = (*(('another %s ' % c, 'another %s ' % py) for c, py in Params.ALIASES.items()),
              ('amscr_index_add: the shapes were prepared with another ', 'Index.add: the shape was prepared with '
               'another value of '), ('amscr_index_add: ', 'Index.add: '))


#: The largest class code the library names (C ``amscr_index_set_class_name``: 0..1000000).
_CLASS_CODE_MAX = 1000000


def _text(p) -> Optional[str]:
    return None if p == ffi.NULL else ffi.string(p).decode('utf-8', 'surrogateescape')


class Index:
    """A collection prepared for one-vs-many retrieval (C ``amscr_index``): each shape's nearest
    shapes under the retrieval matrix's base distance, so one query is ranked by the scores of
    :meth:`Collection.retrieval_matrix` (shape channel, fusion, re-ranking, as the collection's
    :class:`Params` say, the inner-distance graph's share included) without the collection's
    matrix. The ``amscr`` tool's ``index``, ``search`` and this class read and write the same
    files.

    ``Index(collection, progress=None, candidates=None)`` builds the index of a
    :class:`Collection` on its threads from the collection's own shapes; the index keeps a compact
    copy of them (each shape's input samples and outline, ~3 KB at the defaults, the prepared
    shape recomputed when read), not a second collection. ``candidates=0`` computes the
    whole base matrix (exact lists: a query then ranks exactly as ``collection.query``);
    ``candidates=M`` seeks each shape's neighbours among its M signature-nearest shapes only
    (large collections); the default, None, is exact up to ``AMSCR_INDEX_EXACT_MAX`` (2,000)
    shapes and ``AMSCR_INDEX_CANDIDATES`` above (C ``amscr_index_default_candidates``). Thread-safety: any number of threads may query at once; :meth:`add`
    waits for them.

    Args:
        collection: the shapes and their params (``Params.retrieval()`` for the project's
            retrieval).
        progress: True for a progress bar on stderr, False for none, a callable(done, total),
            or None (default): a bar on a terminal's stderr once the build has run 2 s.
        candidates: None (the default for the collection's size), 0 (every pair), or the
            shortlist size M.
    Raises:
        InvalidArgumentError: open curves with a channel weight; CancelledError: cancelled.
    """

    def __init__(self, collection: Collection, progress: ProgressArg = None, candidates: Optional[int] = None):
        if not isinstance(collection, Collection):
            raise TypeError('collection: expected an amscr.Collection, got %s' % type(collection).__name__)
        out = ffi.new('amscr_index **')
        with collection._lock.read():
            m = lib.amscr_index_default_candidates(len(collection)) if candidates is None else _candidates(candidates)
            progress_call(lib.amscr_index_build, (collection._db, int(m)), (out,), progress)
            names = list(collection._label_names or ())  # a copy: a failed extend appends, then drops the list
        self._init(ffi.gc(out[0], lib.amscr_index_free))
        for code, name in enumerate(names):
            _check(lib.amscr_index_set_class_name(self._x, code, str(name).encode('utf-8', 'surrogateescape')))

    def _init(self, x) -> None:
        self._x = x
        self._lock = RWLock()

    @classmethod
    def _wrap(cls, x) -> 'Index':
        self = cls.__new__(cls)
        self._init(x)
        return self

    # -- persistence ------------------------------------------------------------------
    @classmethod
    def load(cls, path: PathArg) -> 'Index':
        """Reads an index file (written by :meth:`save` or ``amscr index``).

        Args:
            path: the file.
        Returns:
            a new :class:`Index`.
        Raises:
            FileError: cannot read; FormatError: not an index file (a collection file without
            an index, an index of the tool before 0.4: build it again), or a corrupt one;
            InvalidArgumentError: a path holding a NUL character.
        """
        return cls._wrap(_loaded_index(lib.amscr_index_load, as_path(path)))

    def save(self, path: PathArg) -> None:
        """Writes the index (its collection included; atomic rename). ``Collection.load`` of the
        file gives the collection.

        Args:
            path: the file to write.
        Raises:
            FileError: the file cannot be written; InvalidArgumentError: a path holding a NUL
            character.
        """
        with self._lock.read():
            _check(lib.amscr_index_save(self._x, as_path(path)))

    def to_bytes(self) -> bytes:
        """The index serialized as :meth:`save` writes it.

        Returns:
            bytes (give them to :meth:`from_bytes`).
        """
        with self._lock.read():
            return saved_bytes(lib.amscr_index_save_memory, self._x)

    @classmethod
    def from_bytes(cls, data: Union[bytes, bytearray, memoryview]) -> 'Index':
        """The inverse of :meth:`to_bytes`.

        Args:
            data: bytes from :meth:`to_bytes` or an index file's content.
        Returns:
            a new :class:`Index`.
        Raises:
            FormatError: not a serialized index, or a corrupt one.
        """
        b = bytes(data)
        return cls._wrap(_loaded_index(lib.amscr_index_load_memory, ffi.from_buffer(b), len(b)))

    def __reduce__(self):
        return (Index.from_bytes, (self.to_bytes(),))

    # -- contents ---------------------------------------------------------------------
    def __len__(self) -> int:
        """The number of shapes."""
        with self._lock.read():  # an add may build the index again, freeing its old collection
            return self._size()

    def _size(self) -> int:
        """len(self) for a caller holding the lock."""
        return int(lib.amscr_index_size(self._x))

    def __repr__(self) -> str:
        return 'Index(%d shapes)' % len(self)

    @property
    def collection(self) -> Collection:
        """A copy of the indexed collection (labels named by the class names, when set)."""
        with self._lock.read():
            buf = ffi.new('void **')
            n = ffi.new('size_t *')
            _check(lib.amscr_db_save_memory(lib.amscr_index_db(self._x), buf, n))
            try:
                data = bytes(ffi.buffer(buf[0], n[0]))
            finally:
                lib.amscr_free(buf[0])
            classes = self._class_names()
        db = _new_db(lib.amscr_db_load_memory, ffi.from_buffer(data), len(data))
        return Collection._wrap(db, classes if classes else None)

    def _class_names(self) -> List[Any]:
        """The class names by code, up to the last named one ([] without names). An index of int
        labels names none: its labels' values, however large, are not walked."""
        codes = {int(lib.amscr_index_label(self._x, i)) for i in range(self._size())}

        def name(code: int) -> Optional[str]:
            return _text(lib.amscr_index_class_name(self._x, code))

        if name(0) is None and not any(name(c) is not None for c in codes if 0 <= c <= _CLASS_CODE_MAX):
            return []
        top = min(max(codes, default=-1) + 1, _CLASS_CODE_MAX + 1)
        out: List[Any] = []
        for code in range(_CLASS_CODE_MAX + 1):
            this = name(code)
            if this is None and code >= top:
                break
            out.append(this if this is not None else code)
        return out if any(isinstance(v, str) for v in out) else []

    @property
    def names(self) -> List[Optional[str]]:
        """The shapes' names (file names of ``amscr index``, ``name=`` of :meth:`add`; None
        when unnamed)."""
        with self._lock.read():
            return [_text(lib.amscr_index_name(self._x, i)) for i in range(self._size())]

    @property
    def labels(self) -> np.ndarray:
        """The labels: class names (object array) when the index names its classes, else the
        int32 codes."""
        with self._lock.read():
            n = self._size()
            codes = np.fromiter((lib.amscr_index_label(self._x, i) for i in range(n)), dtype=np.int32, count=n)
            names = self._class_names()
        if not names:
            return codes
        out = np.empty(n, dtype=object)
        for i, c in enumerate(codes):
            out[i] = names[c] if 0 <= c < len(names) else int(c)
        return out

    # -- adding and querying ----------------------------------------------------------
    def _label_code(self, label: Any) -> int:
        names = self._class_names()
        if isinstance(label, (int, np.integer)) and not isinstance(label, (bool, np.bool_)):
            if names:
                raise bad('label: this index names its classes; got the int %r' % (label,))
            if not -(2 ** 31) <= int(label) < 2 ** 31:
                raise bad('label: %d does not fit in int32' % int(label))
            return int(label)
        if not isinstance(label, str):
            raise bad('label: expected an int or a class name, got %r' % (label,))
        if not names and self._size() > 0:
            raise bad('label: this index uses int labels; got %r' % (label,))
        if label in names:
            return names.index(label)
        code = len(names)
        _check(lib.amscr_index_set_class_name(self._x, code, label.encode('utf-8', 'surrogateescape')))
        return code

    def add(self, points: PointsLike, label: Any = 0, name: Optional[str] = None, *, order: Order = 'xy') -> int:
        """Prepares a shape with the index's params and adds it (its list and the lists it
        enters are updated; with every shape a candidate and a channel weight of 0 or 1 the
        result equals a rebuild; an index of fewer shapes than twice its re-ranking k, whose
        lists grow with its size, is built again, its names and classes kept).

        Args:
            points: (n, 2) points, an OpenCV contour, or a :class:`Shape` prepared with the
                index's params.
            label: an int label, or a class name (an index built from a collection with named
                labels).
            name: the shape's name (e.g. its file), or None.
            order: 'xy' (default) or 'rc'.
        Returns:
            the index of the new shape.
        Raises:
            InvalidArgumentError: bad points or label, or a Shape prepared with other params
            (the message names the option).
        """
        with self._lock.write():
            q = as_shape(points, self._params(), 'points', order)
            one = Collection(Params._copy_of(lib.amscr_descriptor_params(q._d)))  # the index names a differing option
            code = self._label_code(label)
            _check(lib.amscr_db_add_descriptor(one._db, q._d, code, ffi.NULL))
            with _reworded(*_ADD_NAMES):
                progress_call(lib.amscr_index_add, (self._x, one._db), (), False)
            i = self._size() - 1
            if name is not None:
                _check(lib.amscr_index_set_name(self._x, i, str(name).encode('utf-8', 'surrogateescape')))
            return i

    def collection_params(self) -> Params:
        """The index's options.

        Returns:
            a copy of the index's :class:`Params` (those of its collection).
        """
        with self._lock.read():  # an add may build the index again, freeing its old collection
            return self._params()

    def _params(self) -> Params:
        """collection_params() for a caller holding the lock."""
        return Params._copy_of(lib.amscr_db_params(lib.amscr_index_db(self._x)))

    def find_member(self, points: PointsLike, *, order: Order = 'xy') -> Optional[int]:
        """The member rule (C ``amscr_index_find_member``): the shape whose prepared samples are
        the query's, bit for bit (e.g. a file of the collection traced again), the lowest index
        when the collection holds copies; None when no shape is the query's copy.

        Args:
            points: the query: points or a :class:`Shape`.
            order: 'xy' (default) or 'rc'.
        Returns:
            the shape's index, or None.
        Raises:
            InvalidArgumentError: bad points, or a Shape prepared with incompatible params.
        """
        with self._lock.read():
            q = as_shape(points, self._params(), 'points', order)
            out = ffi.new('size_t *')
            _check(lib.amscr_index_find_member(self._x, q._d, out))
            return None if out[0] == ffi.cast('size_t', -1) else int(out[0])

    def scores(self, points: PointsLike, candidates: Optional[int] = None, *, order: Order = 'xy') -> np.ndarray:
        """The query's retrieval score against every shape (lower is better): its row of
        :meth:`Collection.retrieval_matrix` on the collection plus the query; a query that is a
        member's copy (:meth:`find_member`) gets that member's row of the collection's own
        retrieval matrix (0 against itself) when the scores re-rank, fuse or take the shape
        channel, as ``amscr search`` shows it (C ``amscr_index_search_scores``).

        Args:
            points: the query: points or a :class:`Shape`.
            candidates: None: the library's default shortlist (``AMSCR_INDEX_CANDIDATES``,
                256 shapes; the tool's ``amscr search`` default); 0: match the query with every
                shape (exact: its row of the retrieval matrix); M: its M signature-nearest only
                (the others score inf unless the re-ranking reaches them).
            order: 'xy' (default) or 'rc'.
        Returns:
            (len(self),) float array.
        Raises:
            InvalidArgumentError: bad points, or a Shape prepared with incompatible params.
        """
        with self._lock.read():
            q = as_shape(points, self._params(), 'points', order)
            out = np.zeros(self._size(), dtype=np.float64)
            _check(lib.amscr_index_search_scores(self._x, q._d, _candidates(candidates), dbuf(out), len(out)))
            return out

    def query(self, points: PointsLike, top: int = 10, candidates: Optional[int] = None, *,
              order: Order = 'xy') -> Tuple[np.ndarray, np.ndarray]:
        """The `top` best shapes for a query, best first (ties by index), as :meth:`scores` (a
        member's copy scored as the member: C ``amscr_index_search``).

        Args:
            points: the query: points or a :class:`Shape`.
            top: how many results.
            candidates: as in :meth:`scores`.
            order: 'xy' (default) or 'rc'.
        Returns:
            (indices, scores): an int64 and a float array of min(top, len(self)) entries.
        Raises:
            InvalidArgumentError: bad points or `top` < 0.
        """
        top = as_count(top, 'top', 0)
        with self._lock.read():
            q = as_shape(points, self._params(), 'points', order)
            idx = np.zeros(max(top, 1), dtype=np.uintp)
            sc = np.zeros(max(top, 1), dtype=np.float64)
            cnt = ffi.new('size_t *')
            _check(lib.amscr_index_search(self._x, q._d, _candidates(candidates), top,
                                         ffi.from_buffer('size_t[]', idx), dbuf(sc), cnt))
            k = int(cnt[0])
            return idx[:k].astype(np.int64), sc[:k].copy()
