"""amscr.Index: one-vs-many retrieval by the retrieval matrix's scores. Index.query with every
shape a candidate ranks as Collection.query (the query's row of the retrieval matrix of the
collection plus the query); save/load and bytes round trips; names and labels; add; the same
on Kimia-216 and mpeg7-dev with affine-warped queries (skipped visibly without the datasets)."""
import os
import pickle

import numpy as np
import pytest

import amscr
from helpers import blob

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', '..')
DATASETS = os.environ.get('AMSCR_DATASETS') or os.path.join(REPO, '..', 'shared', 'datasets')


def warp(points, rng):
    """A random affine map: any rotation, axis scales x0.5-2, shear +-0.5, then a rotation."""
    def rot(a):
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    s = np.diag(np.exp(rng.uniform(np.log(0.5), np.log(2.0), 2)))
    h = np.array([[1.0, rng.uniform(-0.5, 0.5)], [0.0, 1.0]])
    A = rot(rng.uniform(0, 2 * np.pi)) @ s @ h @ rot(rng.uniform(0, 2 * np.pi))
    return np.asarray(points, dtype=float) @ A.T + rng.uniform(-5, 5, 2)


def synthetic(params, n=24):
    rng = np.random.default_rng(5)
    coll = amscr.Collection(params)
    for i in range(n):
        coll.add(warp(blob(300, seed=i % 6), rng), label='class%d' % (i % 6))
    return coll


def same_ranking(idx, scores, full, top=10):
    """(idx, scores) is the top of the full score row (ties by index), scores to 1e-9."""
    order = np.lexsort((np.arange(len(full)), full))[:top]
    np.testing.assert_array_equal(idx, order)
    np.testing.assert_allclose(scores, full[order], rtol=0, atol=1e-9)


@pytest.mark.parametrize('weight,share', [(1.0, 0.05), (0.0, 0.05), (1.0, 0.0)])
def test_query_equals_collection_query(weight, share):
    params = amscr.Params.retrieval(points=64, channel_weight=weight, rerank_inner_share=share)
    coll = synthetic(params)
    index = amscr.Index(coll)
    q = warp(blob(300, seed=2), np.random.default_rng(9))
    # Collection.query with retrieval params (two graphs) is the row of the matrix of collection + query
    plus = amscr.Collection(params)
    for i in range(len(coll)):
        plus.add(coll.shape(i))
    plus.add(q)
    np.testing.assert_allclose(coll.query(q), plus.retrieval_matrix()[-1, :-1], rtol=0, atol=1e-12)
    # an Index holds the collection's graphs: its query
    assert index.collection_params().rerank_inner_share == share
    full = coll.query(q)
    idx, sc = index.query(q, top=10, candidates=0)
    same_ranking(idx, sc, full)
    np.testing.assert_allclose(index.scores(q), full, rtol=0, atol=1e-12)
    # its class's 4 shapes hold 3 of the top 4 (class3's blobs are near: at the channel alone the
    # first two scores are within 0.002)
    assert sum(coll.labels[i] == 'class2' for i in idx[:4]) >= 3


def test_round_trips_names_labels(tmp_path):
    params = amscr.Params.retrieval(points=64)
    coll = synthetic(params)
    index = amscr.Index(coll)
    assert len(index) == len(coll) and list(index.labels) == list(coll.labels)
    assert index.names == [None] * len(coll)
    q = blob(300, seed=4)
    path = str(tmp_path / 'shapes.idx')
    index.save(path)
    again = amscr.Index.load(path)
    for other in (again, amscr.Index.from_bytes(index.to_bytes()), pickle.loads(pickle.dumps(index))):
        a, b = index.query(q), other.query(q)
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])
    # an index file holds its collection
    assert len(amscr.Collection.load(path)) == len(coll)
    assert list(again.collection.labels) == list(coll.labels)
    # a collection file is not an index
    coll.save(path)
    with pytest.raises(amscr.FormatError, match='amscr_index_build'):
        amscr.Index.load(path)


def test_add():
    params = amscr.Params.retrieval(points=64)
    coll = synthetic(params, 24)
    first = amscr.Collection(params)
    for i in range(20):
        first.add(coll.shape(i), label=coll.labels[i])
    index = amscr.Index(first)
    for i in range(20, 24):
        assert index.add(coll.shape(i), label=coll.labels[i], name='shape%d' % i) == i
    assert index.names[22] == 'shape22' and index.labels[23] == coll.labels[23]
    q = blob(300, seed=1)
    rebuilt = amscr.Index(coll)
    np.testing.assert_allclose(index.scores(q), rebuilt.scores(q), rtol=0, atol=1e-12)
    with pytest.raises(amscr.InvalidArgumentError, match='another value of points than the index'):
        index.add(amscr.Shape(q, amscr.Params.retrieval(points=128)), label='class0')


def test_large_int_labels_are_read_at_once():
    """An index of int labels names no classes: its labels, collection and add do not walk every
    code up to the largest label (2**31 - 1 took hours: each of 2**31 codes read every label)."""
    coll = amscr.Collection(amscr.Params.retrieval(points=64))
    coll.extend([blob(300, seed=i) for i in range(4)], [7, 7, 2 ** 31 - 1, 2 ** 31 - 1])
    index = amscr.Index(coll, progress=False)
    assert index.labels.tolist() == [7, 7, 2 ** 31 - 1, 2 ** 31 - 1] and index.labels.dtype == np.int32
    assert index.collection.labels.tolist() == index.labels.tolist()
    assert index.add(blob(300, seed=5), label=2 ** 31 - 1) == 4 and index.labels[4] == 2 ** 31 - 1


@pytest.mark.parametrize('label', [2 ** 31, -(2 ** 31) - 1, 2 ** 40])
def test_add_refuses_an_int_label_past_int32(label):
    """Index.add's labels are int32, as Collection.add's: a larger int is the documented
    InvalidArgumentError (a bad label), not cffi's OverflowError, and adds nothing."""
    coll = amscr.Collection(amscr.Params.retrieval(points=64))
    coll.extend([blob(300, seed=i) for i in range(4)], [0, 0, 1, 1])
    index = amscr.Index(coll, progress=False)
    with pytest.raises(amscr.InvalidArgumentError, match='int32'):
        index.add(blob(300, seed=5), label=label)
    assert len(index) == 4


def test_add_interrupted_leaves_an_index_that_says_so(monkeypatch):
    """Ctrl-C during Index.add (a KeyboardInterrupt in its first report) leaves the index's new
    shape without its lists: using it again is a StateError saying so (the interpreter crashed)."""
    from amscr import _util
    params = amscr.Params.retrieval(points=64)
    coll = synthetic(params, 24)
    index = amscr.Index(coll)
    q = blob(300, seed=1)

    def interrupted(self, done, total):
        raise KeyboardInterrupt

    monkeypatch.setattr(_util._ProgressState, 'update', interrupted)
    with pytest.raises(KeyboardInterrupt):
        index.add(blob(300, seed=5), label='class0')
    monkeypatch.undo()
    with pytest.raises(amscr.StateError, match='left incomplete by a failed amscr_index_add'):
        index.scores(q)
    with pytest.raises(amscr.StateError):
        index.to_bytes()


def test_add_one_at_a_time_from_an_empty_index(tmp_path):
    """An index grown one shape at a time from empty (its lists' K grows with its size up to
    twice the re-ranking k: the small index is built again) scores as a build of them all, and
    an empty index saves, loads and pickles."""
    params = amscr.Params.retrieval(points=64)
    coll = synthetic(params, 20)
    index = amscr.Index(amscr.Collection(params))
    index.save(str(tmp_path / 'empty.idx'))
    assert len(amscr.Index.load(str(tmp_path / 'empty.idx'))) == 0
    assert len(pickle.loads(pickle.dumps(index))) == 0
    for i in range(20):
        assert index.add(coll.shape(i), label=coll.labels[i], name='shape%d' % i) == i
    assert index.names[3] == 'shape3' and list(index.labels) == list(coll.labels)
    q = blob(300, seed=1)
    np.testing.assert_allclose(index.scores(q), amscr.Index(coll).scores(q), rtol=0, atol=1e-12)


def test_arguments_are_checked():
    """top, candidates, threads and progress: the wrong kind of value is refused by name, not
    converted (top='2', threads=1.5) or ignored (threads=-1 on retrieval scores)."""
    params = amscr.Params.retrieval(points=64)
    coll = synthetic(params, 12)
    index = amscr.Index(coll)
    q = blob(300, seed=2)
    for kw in ({'top': '2'}, {'top': None}, {'top': -1}, {'top': 1.5}, {'candidates': '5'}, {'candidates': -3}):
        with pytest.raises(amscr.InvalidArgumentError, match=list(kw)[0]):
            index.query(q, **kw)
    for bad in (5, 'yes'):
        with pytest.raises(amscr.InvalidArgumentError, match='progress'):
            amscr.Index(coll, progress=bad)
    for bad in (-1, 1.5, '2', True):
        with pytest.raises(amscr.InvalidArgumentError, match='threads'):
            coll.query(q, threads=bad)
    assert len(coll.query(q, threads=1)) == 12 and len(index.query(q, top=np.int64(3))[0]) == 3


def dataset_shapes(name, count):
    """`count` shapes of a dataset spread over its classes: (points, class) pairs."""
    cv2 = pytest.importorskip('cv2')
    folder = os.path.join(DATASETS, name)
    manifest = os.path.join(folder, 'manifest.tsv')
    if not os.path.exists(manifest):
        pytest.skip('%s not found (%s)' % (name, folder))
    rows = [line.rstrip('\n').split('\t') for line in open(manifest) if line.strip()][1:]
    step = max(1, len(rows) // count)
    out = []
    for f, cls in rows[::step][:count]:
        img = cv2.imread(os.path.join(folder, f), cv2.IMREAD_GRAYSCALE)
        out.append((amscr.contour_from_mask(img > 127), cls))
    return out


@pytest.mark.parametrize('name', ['kimia216', 'mpeg7-dev'])
def test_datasets_affine_queries(name):
    shapes = dataset_shapes(name, 60)
    params = amscr.Params.retrieval()
    coll = amscr.Collection(params)
    for pts, cls in shapes:
        coll.add(pts, label=cls)
    index = amscr.Index(coll)
    rng = np.random.default_rng(216)
    for t in rng.choice(len(shapes), 3, replace=False):
        q = warp(shapes[t][0], rng)
        idx, sc = index.query(q, top=10, candidates=0)
        same_ranking(idx, sc, coll.query(q))
