"""Registration, prepared shapes and collections through the Pythonic layer."""
import pickle

import numpy as np
import pytest

import amscr
from helpers import A_TRUE, B_TRUE, affine, blob


@pytest.fixture(scope='module')
def pair():
    src = blob(600, seed=1)
    return src, affine(src, A_TRUE, B_TRUE)


def _rms(a, b):
    return float(np.sqrt(((np.asarray(a) - np.asarray(b)) ** 2).sum(axis=1).mean()))


# The four methods with the refinement and the polish off (refine=0, polish=False): with them on,
# the final fit on all the points gives every method the same map, hiding the method.
BARE = dict(refine=0, polish=False)


@pytest.mark.parametrize('method', ['multiclass-em', 'binary-em', 'amscr', 'acma'])
def test_exact_affine_round_trip(pair, method):
    """An exact affine image of the same points: measured |A - A_true|, |B - B_true| <= 3.4e-15
    and a distance of 2e-29..4e-29 for every method."""
    src, tgt = pair
    r = amscr.register(src, tgt, method=method, **BARE)
    assert r.method == method
    np.testing.assert_allclose(r.A, A_TRUE, rtol=0, atol=3e-14)
    np.testing.assert_allclose(r.B, B_TRUE, rtol=0, atol=3e-14)
    assert _rms(r.apply(src), tgt) < 1e-13 * _rms(tgt, tgt.mean(axis=0))
    assert 0 <= r.distance < 1e-20
    assert not r.reflected


@pytest.fixture(scope='module')
def noisy(pair):
    src, tgt = pair
    size = _rms(tgt, tgt.mean(axis=0))
    noisy = np.roll(tgt + np.random.default_rng(5).normal(0, 0.01 * size, tgt.shape), 123, axis=0)
    return src, tgt, noisy, size


def test_the_method_chooses_the_scales_and_the_map(noisy):
    """1 % noise, refinement and polish off: the method decides which scales enter the final
    solve, hence the map. Measured kept scales (of 8): multiclass-em and binary-em the 4 finest,
    amscr all 8 (no selection), acma the finest only; map errors 0.366 / 0.366 / 0.366 / 0.329 %
    of the size, and the amscr and acma maps differ from multiclass-em's."""
    src, tgt, noisy_tgt, size = noisy
    r = {m: amscr.register(src, noisy_tgt, method=m, **BARE) for m in ['multiclass-em', 'binary-em', 'amscr', 'acma']}
    kept = {m: int(x.kept.sum()) for m, x in r.items()}
    assert kept == {'multiclass-em': 4, 'binary-em': 4, 'amscr': 8, 'acma': 1}, kept
    for m in ('amscr', 'acma'):
        assert not np.array_equal(r[m].A, r['multiclass-em'].A), m
    for m, x in r.items():
        err = np.hypot(*(x.apply(src) - tgt).T).max() / size
        assert err < 0.01, (m, err)


def test_registration_result_fields(pair):
    src, tgt = pair
    r = amscr.register(src, tgt, points=128, reflections=True)
    p = len(r.scales)
    assert r.A.shape == (2, 2) and r.B.shape == (2,) and r.matrix.shape == (3, 3)
    np.testing.assert_array_equal(r.matrix[2], [0, 0, 1])
    np.testing.assert_array_equal(r.matrix[:2, :2], r.A)
    assert r.residuals.shape == (p,) and r.kept.shape == (p,) and r.kept.dtype == bool
    assert r.kept.any()
    np.testing.assert_array_equal(r.kept_scales, r.scales[r.kept])
    assert 0 <= r.shift < 128
    assert len(r.mixture.weights) == len(r.mixture.means) == len(r.mixture.variances)
    assert r.k >= 1 and len(r.sse) >= 1
    if r.k >= 1 and len(r.mixture.weights):
        assert r.mixture.weights.sum() == pytest.approx(1.0)
    # kept scales are those at or below the threshold (when there is one)
    if np.isfinite(r.threshold):
        assert np.all(r.residuals[r.kept] <= r.threshold)
    assert 'Registration(' in repr(r)
    assert r.matrix_normalized.shape == (3, 3)


def test_normalized_map_takes_source_samples_onto_the_target(pair):
    """matrix_normalized maps the source's normalized samples (Shape.points) onto the target's
    normalized curve, sample i near the target's sample i + shift. Measured on the exact pair
    with the target started 150 of 600 points later (shift 32 of 128): 0.0059 from the target's
    polygon at most, 0.042 from the sample the shift names (sample spacing 0.087, RMS radius
    1.41)."""
    src, tgt = pair
    p = amscr.Params.registration(points=128, reflections=True)
    S, T = amscr.Shape(src, p), amscr.Shape(np.roll(tgt, 150, axis=0), p)
    r = amscr.register(S, T)
    M = r.matrix_normalized
    mapped = S.points @ M[:2, :2].T + M[:2, 2]
    Q = T.points
    t = np.linspace(0.0, 1.0, 64, endpoint=False)[None, :, None]
    polygon = (Q[:, None] * (1 - t) + np.roll(Q, -1, axis=0)[:, None] * t).reshape(-1, 2)
    off_curve = np.sqrt(((mapped[:, None] - polygon[None]) ** 2).sum(axis=-1)).min(axis=1)
    assert off_curve.max() < 0.02, off_curve.max()
    assert np.abs(mapped - np.roll(Q, -r.shift, axis=0)).max() < 0.1


def test_distance_is_affine_invariant_and_matches_register(pair):
    src, tgt = pair
    other = blob(500, seed=7)
    d1 = amscr.distance(src, other)
    d2 = amscr.distance(affine(src, [[0.5, -1.2], [0.9, 0.3]], [3, 4]), other)
    assert d1 > 1e-3
    # the same points under an affine map, same start: measured relative difference 1.3e-14
    assert d2 == pytest.approx(d1, rel=1e-12)
    assert amscr.register(src, other).distance == pytest.approx(d1, rel=1e-9, abs=1e-12)


def test_reflections(pair):
    src, _ = pair
    mirror = src * [-1, 1]
    r = amscr.register(src, mirror, reflections=True)
    assert r.reflected
    assert np.linalg.det(r.A) < 0
    np.testing.assert_allclose(r.A, [[-1, 0], [0, 1]], rtol=0, atol=5e-12)  # measured 4.6e-13
    r0 = amscr.register(src, mirror, reflections=False)
    assert not r0.reflected and r0.distance > r.distance


def test_start_point_shift(pair):
    src, tgt = pair
    rolled = np.roll(tgt, 150, axis=0)
    r = amscr.register(src, rolled)
    np.testing.assert_allclose(r.A, A_TRUE, rtol=0, atol=5e-13)  # measured 6.9e-14


def test_shape_prepared_once(pair):
    src, tgt = pair
    s = amscr.Shape(src, points=64)
    assert s.num_samples == 64 and len(s) == 64 and s.num_scales == len(s.params.scales)
    pts = s.points
    assert pts.shape == (64, 2)
    np.testing.assert_allclose(pts.mean(axis=0), 0, atol=1e-10)
    np.testing.assert_allclose(np.cov(pts.T, bias=True), np.eye(2), atol=1e-10)
    np.testing.assert_allclose(amscr.affine_apply(s.normalization, s.input_points), pts, atol=1e-10)
    for k in range(s.num_scales):
        assert s.scale_points(k).shape == (64, 2)
    with pytest.raises(IndexError):
        s.scale_points(s.num_scales)
    t = amscr.Shape(tgt, points=64)
    r1 = amscr.register(s, t)
    r2 = amscr.register(src, tgt, params=s.params)  # the Shape's settings, prepared on the fly
    np.testing.assert_array_equal(r1.matrix, r2.matrix)
    assert r1.distance == r2.distance
    # mixed: the array is prepared with the Shape's options
    assert amscr.register(s, tgt).distance == r1.distance
    # mismatched preparation is a C-side InvalidArgumentError
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.register(s, amscr.Shape(tgt, points=128))
    s2 = pickle.loads(pickle.dumps(s))
    np.testing.assert_array_equal(s2.points, s.points)


def test_result_arrays_are_read_only_and_pickle():
    """A result is one map: its arrays cannot be changed in place (A *= 2 would leave matrix and
    apply() disagreeing), before and after pickling; a copy can."""
    src = blob(200, seed=3)
    r = amscr.register(src, affine(src, A_TRUE, B_TRUE))
    for r2 in (r, pickle.loads(pickle.dumps(r))):
        for a in (r2.A, r2.B, r2.matrix, r2.residuals, r2.kept, r2.mixture.means, r2.target_points,
                  r2.alternatives[0].A):
            with pytest.raises(ValueError, match='read-only'):
                a[...] = 0
        np.testing.assert_array_equal(r2.apply(src), src @ r.A.T + r.B)
    A = r.A.copy()
    A *= 2
    assert np.allclose(A, 2 * r.A)
    for name in ('A', 'distance', 'new_attribute'):  # nor can an attribute be set: one map
        with pytest.raises(AttributeError, match='read-only'):
            setattr(r, name, np.eye(2))
    with pytest.raises(AttributeError, match='read-only'):
        del r.B


def test_params_roundtrip():
    p = amscr.Params(points=96, scales=[0, 1, 2, 4], method='binary_em', reflections=True, closed=True,
                     refine=2, symmetric=True, threads=2, parametrization='whitened', invariance='similarity')
    assert p.points == 96 and list(p.scales) == [0, 1, 2, 4] and p.method == 'binary-em'
    assert p.reflections and p.symmetric and p.refine == 2 and p.threads == 2
    assert p.parametrization == 'whitened' and p.invariance == 'similarity'
    q = pickle.loads(pickle.dumps(p))
    assert q == p and q is not p
    assert p.copy(points=32).points == 32 and p.points == 96
    d = amscr.Params().to_dict()
    assert set(d) == set(amscr.Params.OPTIONS)


# ---------------------------------------------------------------- collections
@pytest.fixture(scope='module')
def shapes():
    rng = np.random.default_rng(11)
    out, labels = [], []
    for c in range(3):
        base = blob(300, seed=100 + c)
        for _ in range(4):
            M = np.eye(2) + 0.3 * rng.normal(size=(2, 2))
            out.append(affine(base, M, rng.normal(size=2)) + 0.002 * rng.normal(size=base.shape))
            labels.append(c)
    return out, np.array(labels)


@pytest.fixture(scope='module')
def collection(shapes):
    pts, labels = shapes
    db = amscr.Collection(points=64, reflections=True)
    for p, lab in zip(pts, labels):
        db.add(p, label=int(lab))
    return db


def test_collection_basics(collection, shapes):
    pts, labels = shapes
    assert len(collection) == len(pts)
    np.testing.assert_array_equal(collection.labels, labels)
    assert collection.labels.dtype == np.int32
    D = collection.distance_matrix()
    assert D.shape == (12, 12)
    np.testing.assert_array_equal(np.diag(D), 0)
    assert (D >= 0).all()
    # affine copies of one shape are near, other shapes far: perfect retrieval
    assert amscr.nn_accuracy(D, labels) == 1.0
    assert amscr.bullseye(D, labels) == 1.0
    q = collection.query(pts[5])
    off = np.arange(12) != 5
    np.testing.assert_allclose(q[off], D[5, off], rtol=1e-9, atol=1e-12)
    assert q[5] < 1e-6


def test_collection_threads_are_bit_identical(collection):
    D1 = collection.distance_matrix(threads=1)
    D2 = collection.distance_matrix(threads=2)
    D0 = collection.distance_matrix()
    np.testing.assert_array_equal(D1, D2)
    np.testing.assert_array_equal(D1, D0)
    q = collection.shape(3)
    np.testing.assert_array_equal(collection.query(q, threads=1), collection.query(q, threads=2))


def test_collection_cross_matrix(collection, shapes):
    pts, labels = shapes
    small = amscr.Collection(collection.params)
    for p in pts[:3]:
        small.add(p)
    C = small.cross_matrix(collection)
    assert C.shape == (3, 12)
    D = collection.distance_matrix()
    off = np.ones_like(C, dtype=bool)
    off[[0, 1, 2], [0, 1, 2]] = False
    np.testing.assert_allclose(C[off], D[:3][off], rtol=1e-9, atol=1e-12)


def test_collection_persistence(collection, tmp_path):
    D = collection.distance_matrix()
    path = tmp_path / 'db.amscr'
    collection.save(path)
    loaded = amscr.Collection.load(path)
    assert len(loaded) == len(collection)
    np.testing.assert_array_equal(loaded.labels, collection.labels)
    np.testing.assert_array_equal(loaded.distance_matrix(), D)
    b = collection.to_bytes()
    assert isinstance(b, bytes) and len(b) > 0
    np.testing.assert_array_equal(amscr.Collection.from_bytes(b).distance_matrix(), D)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(collection)).distance_matrix(), D)
    with pytest.raises(amscr.FormatError):
        amscr.Collection.from_bytes(b[:len(b) // 2])
    bad = bytearray(b)
    bad[len(bad) // 2] ^= 0xFF
    with pytest.raises(amscr.FormatError):
        amscr.Collection.from_bytes(bytes(bad))
    with pytest.raises(amscr.FileError):
        amscr.Collection.load(tmp_path / 'missing.amscr')


def test_collection_string_labels(shapes):
    pts, labels = shapes
    names = np.array(['bird', 'fish', 'leaf'])[labels]
    db = amscr.Collection(points=64)
    idx = db.extend(pts, names)
    assert idx == list(range(12))
    assert list(db.labels) == list(names)
    np.testing.assert_array_equal(db.label_codes, labels)
    with pytest.raises(ValueError):
        db.add(pts[0], label=3)
    db2 = pickle.loads(pickle.dumps(db))
    assert list(db2.labels) == list(names)
    D = db.distance_matrix()
    assert amscr.bullseye(D, db.labels) == 1.0


def test_extend_on_threads_is_add_one_by_one_and_all_or_nothing(shapes):
    """extend prepares point arrays together on the collection's threads: the collection equals
    one made by add, for any thread count; a degenerate shape adds nothing, names its position
    and registers none of the batch's new label names."""
    pts, labels = shapes
    names = list(np.array(['bird', 'fish', 'leaf'])[labels])
    one = amscr.Collection(amscr.Params.retrieval(threads=1))
    for p, n in zip(pts, names):
        one.add(p, n)
    for threads in (1, 3):
        many = amscr.Collection(amscr.Params.retrieval(threads=threads))
        seen = []
        assert many.extend(pts, names, progress=lambda done, total: seen.append((done, total))) == list(range(12))
        assert seen and seen[-1] == (12, 12)
        assert list(many.labels) == names
        np.testing.assert_array_equal(many.retrieval_matrix(), one.retrieval_matrix())
        line = np.column_stack([np.arange(20.0), 2.0 * np.arange(20.0)])
        batch = [pts[0], pts[1], pts[2], line, pts[3], line]
        with pytest.raises(amscr.DegenerateError, match='contour 3'):
            many.extend(batch, ['new', 'bird', 'bird', 'bird', 'bird', 'other'])
        assert len(many) == 12 and list(many.labels) == names
        assert many.extend([pts[0]], ['new']) == [12] and many.labels[12] == 'new'
        assert int(many.label_codes[12]) == 3  # 'new' got the next code: the failed batch left none
        # prepared Shapes mixed in: the same rule (nothing added, the position named), also for
        # a Shape prepared with other options
        for bad, where in ((line, 'shapes\\[2\\]'), (amscr.Shape(pts[4], points=64), 'shapes\\[2\\].*N differs')):
            with pytest.raises(amscr.AmscrError, match=where):
                many.extend([amscr.Shape(pts[0], many.params), pts[1], bad], ['x', 'y', 'z'])
            assert len(many) == 13 and 'x' not in list(many.labels)
        assert many.extend([amscr.Shape(pts[5], many.params), pts[6]], ['bird', 'x']) == [13, 14]


def test_collection_add_shape_and_mismatch(shapes):
    pts, _ = shapes
    db = amscr.Collection(points=64)
    db.add(amscr.Shape(pts[0], points=64), label=1)
    with pytest.raises(amscr.InvalidArgumentError):
        db.add(amscr.Shape(pts[0], points=32))
    assert len(db) == 1 and db.shape(0).num_samples == 64 and db.shape(-1).num_samples == 64
    with pytest.raises(IndexError):
        db.shape(1)


def test_module_distance_matrix(shapes):
    pts, labels = shapes
    D = amscr.distance_matrix(pts[:4], points=64, threads=1)
    db = amscr.Collection(points=64)
    db.extend(pts[:4])
    np.testing.assert_array_equal(D, db.distance_matrix())


def test_progress_bar_and_callbacks(collection, capfd):
    D = collection.distance_matrix(progress=True)
    err = capfd.readouterr().err
    assert 'amscr [' in err and '100%' in err and err.endswith('\n')
    seen = []
    np.testing.assert_array_equal(collection.distance_matrix(progress=lambda d, t: seen.append((d, t))), D)
    assert seen and seen[-1][0] == seen[-1][1] and all(d <= t for d, t in seen)

    class Boom(Exception):
        pass

    def raiser(done, total):
        raise Boom('stop here')

    with pytest.raises(Boom, match='stop here'):
        collection.distance_matrix(progress=raiser)
    calls = []

    def raise_once_then_count(done, total):
        calls.append((done, total))
        raise Boom('the first report')

    with pytest.raises(Boom, match='the first report'):  # not called again once it raised
        amscr.Collection(points=64, threads=2).extend([blob(200, seed=s) for s in range(12)],
                                                      progress=raise_once_then_count)
    assert len(calls) == 1, calls
    with pytest.raises(amscr.CancelledError):
        collection.query(blob(200), progress=lambda d, t: True)
    # still usable after a cancellation
    np.testing.assert_array_equal(collection.distance_matrix(), D)
    ranked = amscr.Collection(amscr.Params.retrieval(points=64))
    ranked.extend([blob(200, seed=s) for s in range(12)])
    scores = ranked.query(blob(200))  # builds its kept index; a query of that reports and cancels
    seen.clear()
    np.testing.assert_array_equal(ranked.query(blob(200), progress=lambda d, t: seen.append((d, t))), scores)
    assert seen and seen[-1][0] == seen[-1][1]
    with pytest.raises(amscr.CancelledError):
        ranked.query(blob(200), progress=lambda d, t: True)
    np.testing.assert_array_equal(ranked.query(blob(200)), scores)


def test_a_collection_used_from_its_own_progress_callback(shapes):
    """From a progress callback: querying a collection being extended, or adding to one being
    read, is a StateError (both hung for good); reading it again from a read's callback works."""
    pts, _ = shapes
    coll = amscr.Collection(points=64, threads=1)
    coll.extend(pts[:4])
    with pytest.raises(amscr.StateError, match='being changed by a call on this thread'):
        coll.extend(pts[4:8], progress=lambda d, t: coll.distance_matrix())
    assert len(coll) == 4  # all or nothing
    with pytest.raises(amscr.StateError, match='cannot be changed from inside a call that reads it'):
        coll.distance_matrix(progress=lambda d, t: coll.add(pts[5]))
    inner = []
    D = coll.distance_matrix(progress=lambda d, t: inner.append(coll.distance_matrix()) if not inner else None)
    np.testing.assert_array_equal(inner[0], D)


def _noisy_pairs():
    for s in range(6):
        rng = np.random.default_rng(100 + s)
        yield s, blob(400, seed=s), blob(400, seed=s + 10) + 0.01 * rng.normal(size=(400, 2))


@pytest.mark.parametrize('method', ['acma', 'multiclass-em'])
def test_batch_distance_agrees_with_register_on_noisy_shapes(method):
    """amscr.h: amscr_distance "agrees with amscr_result_distance to rounding"."""
    worst = 0.0
    for s, a, b in _noisy_pairs():
        d = amscr.distance(a, b, method=method)
        r = amscr.register(a, b, method=method).distance
        worst = max(worst, abs(d - r) / r)
    assert worst < 1e-9, 'largest relative difference %.3g' % worst


def test_shape_from_collection_survives_later_adds(shapes):
    pts, _ = shapes
    db = amscr.Collection(points=64)
    db.add(pts[0])
    s = db.shape(0)
    before = s.points
    for p in pts * 4:  # grows (and may reallocate) the C collection
        db.add(p)
    np.testing.assert_array_equal(s.points, before)
    assert amscr.register(s, db.shape(0)).distance < 1e-9


def test_loaded_collection_keeps_int_labels(collection, tmp_path):
    db = amscr.Collection.from_bytes(collection.to_bytes())
    with pytest.raises(ValueError):
        db.add(blob(200), label='name')
    db.add(blob(200), label=7)
    assert db.labels[-1] == 7


def _cross(cut=3.0):
    """A 4-armed cross (arms 1 wide reaching 3 from the centre, the first cut to `cut`)."""
    v = np.array([(1, -1), (cut, -1), (cut, 1), (1, 1), (1, 3), (-1, 3), (-1, 1), (-3, 1), (-3, -1), (-1, -1),
                  (-1, -3), (1, -3)], float)
    t = (np.arange(40) / 40)[:, None]
    return np.vstack([a + (b - a) * t for a, b in zip(v, np.roll(v, -1, axis=0))])


def test_confidence_evidence_on_an_exact_pair_and_a_bitten_cross(pair):
    """An exact affine copy: overlap ~1, nothing in doubt (no way back, no symmetry tried), a
    high confidence. A cross with an arm cut: every quarter turn fits the three whole arms, so
    the map, right or wrong, is reported ambiguous near the source's symmetry (confidence < 0.25).
    The exact copy cut by a fifth: the way back runs and composes with the map to the identity."""
    src, tgt = pair
    r = amscr.register(src, tgt)
    assert r.overlap > 0.99 and np.isnan(r.backward_error) and np.isnan(r.symmetry_ambiguity)
    assert r.confidence > 0.9
    A = np.array([[0.9, -0.5], [0.4, 1.2]])
    r = amscr.register(_cross(), _cross(1.6) @ A.T + 5)
    assert r.symmetry_ambiguity > 0.75 and r.confidence < 0.25
    share = min(r.inlier_fraction, r.overlap)
    assert r.confidence == pytest.approx((1 - max(r.ambiguity, r.symmetry_ambiguity)) * share, abs=1e-12)
    cut = len(tgt) // 5
    r = amscr.register(src, tgt[cut:])
    np.testing.assert_allclose(r.A, A_TRUE, atol=0.01)
    assert min(r.inlier_fraction, r.overlap) < 0.85 and r.backward_error < 1e-3
    assert r.confidence > 0.5


def test_a_collection_shape_unpickles_as_the_same_prepared_shape():
    """Collection.shape(i) holds the collection's prepared samples, not the input points: a
    pickled one (multiprocessing) is the same shape, found by the member rule, with the same
    scores, distances and registrations."""
    src, other = blob(300, seed=4), blob(300, seed=5)
    db = amscr.Collection()
    db.extend([src, other])
    index = amscr.Index(db)
    s = db.shape(0)
    for u in (pickle.loads(pickle.dumps(s)), pickle.loads(pickle.dumps(pickle.loads(pickle.dumps(s))))):
        assert index.find_member(u) == index.find_member(s) == 0
        np.testing.assert_array_equal(index.scores(u), index.scores(s))
        np.testing.assert_array_equal(db.query(u), db.query(s))
        np.testing.assert_array_equal(u.points, s.points)
        assert amscr.distance(u, other) == amscr.distance(s, other)
        np.testing.assert_array_equal(amscr.register(u, other).matrix, amscr.register(s, other).matrix)
        np.testing.assert_array_equal(amscr.register(other, u).matrix, amscr.register(other, s).matrix)


@pytest.mark.parametrize('i', [1.7, 1.0, True, '1', np.float64(1.0)],
                         ids=['float', 'whole_float', 'bool', 'str', 'numpy_float'])
def test_collection_shape_takes_integer_indices_only(i):
    db = amscr.Collection()
    db.extend([blob(200, seed=1), blob(200, seed=2)])
    with pytest.raises(TypeError, match=r'^i: expected an integer'):
        db.shape(i)
    np.testing.assert_array_equal(db.shape(np.int64(1)).points, db.shape(-1).points)
