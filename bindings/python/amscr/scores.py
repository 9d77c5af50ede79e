"""Retrieval scores of a distance matrix: top-k, bull's eye, top-k tables, nearest-neighbour accuracy,
and the evaluation protocols of ``amscr eval`` (per-class scores, the seeded random split, leave one
group out, precision-recall) (C ``amscr_topk`` and ``amscr_score_*``)."""
from __future__ import annotations

from typing import NamedTuple, Optional, Tuple

import numpy as np

from ._lib import ffi, lib
from ._util import ArrayLike, as_count, as_float_array, bad, dbuf, factorize
from .errors import _check, _reworded


def _square(D: ArrayLike, name: str = 'D') -> np.ndarray:
    a = as_float_array(D, name, ndim=(2,), finite=False)
    if a.shape[0] != a.shape[1]:
        raise bad('%s: expected a square distance matrix, got shape %s' % (name, a.shape))
    return a


def topk(dist: ArrayLike, k: int, exclude: Optional[int] = None) -> np.ndarray:
    """Indices of the k smallest distances, ascending (ties by lower index).

    Args:
        dist: (n,) distances, e.g. a row of :meth:`Collection.query`.
        k: how many (at most n, or n - 1 with `exclude`).
        exclude: an index to skip (the query itself), or None.
    Returns:
        (k,) int array of indices into `dist`.
    Raises:
        InvalidArgumentError: `dist` not 1-D or holding a NaN, `k` too large, `exclude` out of range.
    """
    d = as_float_array(dist, 'dist', ndim=(1,), finite=False)
    k = as_count(k, 'k', 0)
    ex = ffi.cast('size_t', -1) if exclude is None else as_count(exclude, 'exclude', 0)
    out = np.zeros(k, dtype=np.uintp)
    with _reworded(('amscr_topk: ', 'topk: ')):
        _check(lib.amscr_topk(dbuf(d), d.shape[0], k, ex, ffi.from_buffer('size_t[]', out)))
    return out.astype(np.intp)


def bullseye(D: ArrayLike, labels: ArrayLike, window: int = 0) -> float:
    """Bull's eye score (MPEG-7): same-class shapes among each query's `window` nearest (itself
    included), over the sum of class sizes.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
        window: how many nearest to look at (0 = twice the query's class size, the MPEG-7 rule).
    Returns:
        the score, in [0, 1].
    Raises:
        InvalidArgumentError: D not square, or not one label per row.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_bullseye(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab),
                                    as_count(window, 'window', 0), out))
    return float(out[0])


def topk_table(D: ArrayLike, labels: ArrayLike, ranks: int = 10) -> np.ndarray:
    """Top-k table (Kimia): how many queries have a same-class shape at each rank.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
        ranks: the number of ranks (columns of the Kimia tables: 10 for Kimia-99).
    Returns:
        (ranks,) int array: ``out[r]`` = queries whose (r+1)-th nearest neighbour (the query
        excluded) has their label.
    Raises:
        InvalidArgumentError: D not square, not one label per row, ranks >= n.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    ranks = as_count(ranks, 'ranks', 1)
    out = np.zeros(ranks, dtype=np.uintp)
    _check(lib.amscr_score_topk_table(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), ranks,
                                      ffi.from_buffer('size_t[]', out)))
    return out.astype(np.int64)


def nn_accuracy(D: ArrayLike, labels: ArrayLike) -> float:
    """Leave-one-out nearest-neighbour accuracy.

    Args:
        D: (n, n) distance matrix (rows = queries).
        labels: n class labels (ints or names).
    Returns:
        the fraction of queries whose nearest other shape has their label, in [0, 1].
    Raises:
        InvalidArgumentError: D not square, or not one label per row.
    """
    d = _square(D)
    lab = factorize(labels, d.shape[0])
    out = ffi.new('double *')
    _check(lib.amscr_score_nn_accuracy(dbuf(d), d.shape[0], ffi.from_buffer('int32_t[]', lab), out))
    return float(out[0])


def nn_split(D: ArrayLike, test_labels: ArrayLike, train_labels: ArrayLike) -> float:
    """Train/test nearest-neighbour accuracy.

    Args:
        D: (ntest, ntrain) distances from the test shapes to the training shapes (e.g.
            :meth:`Collection.cross_matrix`).
        test_labels: ntest labels (ints or names).
        train_labels: ntrain labels, of the same kind.
    Returns:
        the fraction of test shapes whose nearest training shape has their label, in [0, 1].
    Raises:
        InvalidArgumentError: label counts that do not match D.
    """
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


# ---- the evaluation protocols (C amscr_score_per_class, amscr_score_nn_random_split,
# amscr_score_nn_groups, amscr_score_precision_recall). Classes are the distinct labels in
# sorted order (the C order of the codes factorize gives); per-class arrays follow it.

class ClassScores(NamedTuple):
    """Result of :func:`per_class_scores`: one entry per class, classes sorted."""
    classes: np.ndarray  # the distinct labels, sorted
    sizes: np.ndarray  # shapes per class
    bullseye: np.ndarray  # each class's bull's eye (its queries, window 2 Nc, over Nc^2)
    nn_accuracy: np.ndarray  # each class's leave-one-out nearest-neighbour accuracy


class SplitScores(NamedTuple):
    """Result of :func:`nn_random_split`."""
    mean: float  # mean accuracy over the splits
    std: float  # sample standard deviation of the splits' accuracies (0 for one split)
    accuracies: np.ndarray  # (splits,) each split's accuracy
    classes: np.ndarray  # the distinct labels, sorted
    class_accuracy: np.ndarray  # each class's accuracy, averaged over the splits


class GroupScores(NamedTuple):
    """Result of :func:`nn_groups`."""
    accuracy: float  # fraction of all shapes classified right
    groups: np.ndarray  # the distinct groups, sorted
    group_accuracy: np.ndarray  # each group's accuracy
    classes: np.ndarray  # the distinct labels, sorted
    class_accuracy: np.ndarray  # each class's accuracy


class PrecisionRecall(NamedTuple):
    """Result of :func:`precision_recall`."""
    recall: np.ndarray  # (levels,) recall levels 0, 1/(levels-1), ..., 1
    precision: np.ndarray  # (levels,) mean interpolated precision at each level


def _codes(labels: ArrayLike, n: int, name: str = 'labels') -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(int32 codes for C, the distinct labels in the C class order, their sizes)."""
    codes = factorize(labels, n, name)
    nc = ffi.new('size_t *', 0)
    _check(lib.amscr_score_classes(ffi.from_buffer('int32_t[]', codes), n, ffi.NULL, ffi.NULL, nc))
    sizes = np.zeros(int(nc[0]), dtype=np.uintp)
    _check(lib.amscr_score_classes(ffi.from_buffer('int32_t[]', codes), n, ffi.NULL,
                                   ffi.from_buffer('size_t[]', sizes), nc))
    return codes, np.unique(np.asarray(labels)), sizes.astype(np.int64)


def _out(m: int):
    a = np.zeros(m, dtype=np.float64)
    return a, dbuf(a)


def per_class_scores(D: ArrayLike, labels: ArrayLike) -> ClassScores:
    """Per-class leave-one-out scores: each class's bull's eye and nearest-neighbour accuracy
    (``amscr eval``'s ``per_class``).

    Args:
        D: (n, n) distance matrix (rows = queries), n >= 2.
        labels: n class labels (ints or names).
    Returns:
        a :class:`ClassScores` (classes sorted, sizes, bullseye, nn_accuracy; one entry per
        class). Weighted back they give :func:`bullseye` (by size squared) and
        :func:`nn_accuracy` (by size).
    Raises:
        InvalidArgumentError: D not square, not one label per row, n < 2, NaN or -inf in D.
    """
    d = _square(D)
    n = d.shape[0]
    codes, classes, sizes = _codes(labels, n)
    be, pbe = _out(len(classes))
    nn, pnn = _out(len(classes))
    _check(lib.amscr_score_per_class(dbuf(d), n, ffi.from_buffer('int32_t[]', codes), len(classes), pbe, pnn))
    return ClassScores(classes, sizes, be, nn)


def nn_random_split(D: ArrayLike, labels: ArrayLike, train: int, splits: int = 10, seed: int = 1) -> SplitScores:
    """Seeded per-class random split (Swedish leaf): in each split, `train` shapes of every class
    are the training set and the others are classified by their nearest training shape.

    The draw is the library's (splitmix64 seeded with `seed`, a partial Fisher-Yates shuffle
    class by class), the same on every platform and the same as ``amscr eval --protocol split
    --train K --splits R --seed S`` when the labels sort like the tool's classes.

    Args:
        D: (n, n) distance matrix (rows = queries), n >= 2.
        labels: n class labels (ints or names).
        train: training shapes per class, 1 <= train < the smallest class size.
        splits: the number of random splits (>= 1).
        seed: the generator's seed (an integer in 0 .. 2**64 - 1).
    Returns:
        a :class:`SplitScores` (mean, std, accuracies, classes, class_accuracy).
    Raises:
        InvalidArgumentError: D not square, not one label per row, train 0 or not smaller
            than every class, splits 0, NaN or -inf in D.
    """
    d = _square(D)
    n = d.shape[0]
    train, splits, seed = as_count(train, 'train', 1), as_count(splits, 'splits', 1), as_count(seed, 'seed', 0)
    if seed > 0xFFFFFFFFFFFFFFFF:
        raise bad('seed: too large (%d)' % seed)
    codes, classes, _ = _codes(labels, n)
    mean, sd = ffi.new('double *'), ffi.new('double *')
    acc, pacc = _out(splits)
    cls, pcls = _out(len(classes))
    _check(lib.amscr_score_nn_random_split(dbuf(d), n, ffi.from_buffer('int32_t[]', codes), train, splits, seed,
                                           len(classes), mean, sd, pacc, pcls))
    return SplitScores(float(mean[0]), float(sd[0]), acc, classes, cls)


def nn_groups(D: ArrayLike, labels: ArrayLike, groups: ArrayLike) -> GroupScores:
    """Leave one group out (ETH-80: one object out): the shapes of each group are classified by
    their nearest shape among the other groups, never one of their own group.

    For the retrieval scores, give it :meth:`Collection.retrieval_matrix_heldout` (each group
    out of the fusion and the re-ranking graph, as ``amscr eval --protocol groups`` does): on
    :meth:`Collection.retrieval_matrix` the group's own shapes are in the graph that ranks it.

    Args:
        D: (n, n) distance matrix (rows = queries), n >= 2.
        labels: n class labels (ints or names).
        groups: n group names or ids (at least two distinct).
    Returns:
        a :class:`GroupScores` (accuracy, groups sorted, group_accuracy, classes,
        class_accuracy).
    Raises:
        InvalidArgumentError: D not square, not one label and one group per row, a single
            group, NaN or -inf in D.
    """
    d = _square(D)
    n = d.shape[0]
    codes, classes, _ = _codes(labels, n)
    gcodes, gnames, _ = _codes(groups, n, 'groups')
    acc = ffi.new('double *')
    ga, pga = _out(len(gnames))
    ca, pca = _out(len(classes))
    _check(lib.amscr_score_nn_groups(dbuf(d), n, ffi.from_buffer('int32_t[]', codes),
                                     ffi.from_buffer('int32_t[]', gcodes), len(gnames), len(classes), acc, pga,
                                     pca))
    return GroupScores(float(acc[0]), gnames, ga, classes, ca)


def precision_recall(D: ArrayLike, labels: ArrayLike, levels: int = 21) -> PrecisionRecall:
    """The precision-recall curve of a collection (``amscr eval --plot``): each shape queries the
    others, the other shapes of its class are relevant; interpolated precision (the best at any
    recall >= the level) averaged over the queries whose class has another shape.

    Args:
        D: (n, n) distance matrix (rows = queries), n >= 2.
        labels: n class labels (ints or names).
        levels: the number of recall levels, spaced evenly from 0 to 1 (>= 2; 21 = steps of 0.05).
    Returns:
        a :class:`PrecisionRecall` (recall, precision); precision is NaN when no class has two
        shapes.
    Raises:
        InvalidArgumentError: D not square, not one label per row, levels < 2, NaN or -inf in D.
    """
    d = _square(D)
    n = d.shape[0]
    levels = as_count(levels, 'levels', 2)
    codes, _, _ = _codes(labels, n)
    prec, pp = _out(levels)
    _check(lib.amscr_score_precision_recall(dbuf(d), n, ffi.from_buffer('int32_t[]', codes), levels, pp))
    return PrecisionRecall(np.arange(levels, dtype=np.float64) / (levels - 1), prec)
