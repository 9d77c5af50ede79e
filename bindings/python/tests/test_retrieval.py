"""The retrieval preset: the shape channel (amscr.channel_distance, Collection.channel_matrix)
and the fused, re-ranked Collection.retrieval_matrix."""
import numpy as np
import pytest

import amscr
from helpers import affine, blob


def _rotation(theta, s=1.0):
    c, n = np.cos(theta), np.sin(theta)
    return s * np.array([[c, -n], [n, c]])


def _bent(points, amount):
    """A non-affine deformation: the upper half pushed sideways by a bend."""
    p = np.array(points, dtype=float)
    p[:, 0] += amount * np.maximum(p[:, 1], 0.0) ** 2
    return p


def test_the_preset():
    p = amscr.Params.retrieval()
    assert p.channel_weight == 1.0 and p.rerank_k == 8 and p.rerank_iterations == 10
    assert p.reflections and p.channel_invariance == 'similarity' and p.channel_affine_share == 0.2
    assert p.invariance == 'affine' and p.refine == 0
    assert amscr.Params.retrieval(rerank_k=0).rerank_k == 0
    d = amscr.Params()
    assert d.channel_weight == 0.0 and d.rerank_k == 0  # the plain defaults keep 0.1's distance


def test_which_scores_params_rank_by():
    """Params.ranking (C amscr_params_ranking): the retrieval scores as soon as the params ask
    for the shape channel or re-ranking, the AMSCR distance otherwise; read-only."""
    assert amscr.Params().ranking == 'distance'
    assert amscr.Params.retrieval().ranking == 'retrieval'
    assert amscr.Params(rerank_k=8).ranking == 'retrieval'
    assert amscr.Params(channel_weight=0.25).ranking == 'retrieval'
    assert amscr.Params.retrieval(channel_weight=0, rerank_k=0).ranking == 'distance'
    with pytest.raises(TypeError):
        amscr.Params(ranking='retrieval')
    with pytest.raises(AttributeError):
        amscr.Params().ranking = 'retrieval'


def test_query_follows_the_ranking():
    """Collection.query scores a query as its params rank: the one-way AMSCR distance (the
    query's row of distance_matrix) or the retrieval scores (its row of retrieval_matrix), each
    on the collection plus the query."""
    shapes = [blob(200, seed=s) for s in range(7)]
    for params in (amscr.Params.retrieval(channel_weight=0, rerank_k=0), amscr.Params.retrieval()):
        coll, whole = amscr.Collection(params), amscr.Collection(params)
        for s in shapes[1:]:
            coll.add(s)
            whole.add(s)
        whole.add(shapes[0])
        full = whole.distance_matrix() if params.ranking == 'distance' else whole.retrieval_matrix()
        np.testing.assert_allclose(coll.query(shapes[0]), full[-1, :-1], rtol=0, atol=1e-12)


def test_query_keeps_the_collection_index_across_adds():
    """Collection.query's retrieval scores come from an index the collection keeps: the same
    scores on a second call, and after add() the scores of a collection made with every shape
    (the kept index enters the new shapes)."""
    params = amscr.Params.retrieval()
    shapes = [blob(200, seed=s) for s in range(30)]
    coll, whole = amscr.Collection(params), amscr.Collection(params)
    coll.extend(shapes[1:25])
    whole.extend(shapes[1:])
    first = coll.query(shapes[0])
    np.testing.assert_array_equal(coll.query(shapes[0]), first)
    coll.extend(shapes[25:])
    np.testing.assert_allclose(coll.query(shapes[0]), whole.query(shapes[0]), rtol=0, atol=1e-12)
    assert coll.query(shapes[0]).shape == (29,)


def test_channel_distance_is_zero_to_itself_and_invariant():
    a, b = blob(300, seed=1), blob(300, seed=2)
    assert amscr.channel_distance(a, a) == 0.0
    d_ab = amscr.channel_distance(a, b)
    assert d_ab > 1.0  # measured 2.09
    # the copies below start at the same point: their samples are the map's images of a's, and
    # the distances are exact (measured: 0, and d_ab to the last bit)
    # the similarity frame: a rotated, scaled, moved copy is the same shape
    moved = affine(a, _rotation(1.1, 2.5), [3.0, -7.0])
    assert amscr.channel_distance(moved, b) == d_ab
    assert amscr.channel_distance(moved, a) == 0.0
    # the affine frame: a sheared copy too (measured 0 against 1.96 for b)
    sheared = affine(a, [[1.4, 0.6], [-0.2, 0.7]], [1.0, 2.0])
    assert amscr.channel_distance(sheared, a, channel_invariance='affine') == 0.0
    assert amscr.channel_distance(b, a, channel_invariance='affine') > 1.0
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.channel_distance(a, b, closed=False)


def test_the_channel_tolerates_a_bend_more_than_the_amscr_distance():
    a, b = blob(300, seed=4), blob(300, seed=5)
    bent = _bent(a, 0.25)
    p = amscr.Params.retrieval()
    ratio_channel = amscr.channel_distance(a, bent, params=p) / amscr.channel_distance(a, b, params=p)
    ratio_amscr = amscr.distance(a, bent, params=p) / amscr.distance(a, b, params=p)
    assert ratio_channel < ratio_amscr


def _collection(params, classes=3, copies=4, seed=0):
    rng = np.random.default_rng(seed)
    db = amscr.Collection(params)
    for c in range(classes):
        base = blob(300, seed=20 + c)
        for _ in range(copies):
            A = _rotation(rng.uniform(0, 2 * np.pi), rng.uniform(0.5, 2.0)) @ (np.eye(2) + 0.2 * rng.normal(size=(2, 2)))
            db.add(affine(base, A, rng.normal(size=2)) + 0.002 * rng.normal(size=(300, 2)), label=c)
    return db


def test_channel_matrix_is_the_pairwise_channel_distance():
    db = _collection(amscr.Params.retrieval(points=64))
    H = db.channel_matrix()
    n = len(db)
    assert H.shape == (n, n) and np.all(np.diag(H) == 0.0)
    np.testing.assert_array_equal(H, H.T)
    for i, j in [(0, 1), (2, 9), (5, 11)]:
        assert H[i, j] == pytest.approx(amscr.channel_distance(db.shape(i), db.shape(j)), rel=1e-12)


def test_retrieval_matrix_fuses_and_reranks():
    p = amscr.Params.retrieval(points=64)
    db = _collection(p, copies=10)  # classes larger than the preset's 8 neighbours
    n, labels = len(db), db.label_codes
    calls = []
    R = db.retrieval_matrix(progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1][0] == calls[-1][1]
    assert np.all(np.diag(R) == 0.0) and np.all((R >= 0.0) & (R <= 1.0))
    assert amscr.bullseye(R, labels) == 1.0
    # the pieces: channel alone without re-ranking is the channel matrix
    alone = _collection(p.copy(rerank_k=0))
    np.testing.assert_array_equal(alone.retrieval_matrix(), alone.channel_matrix())
    # weight 0 without re-ranking: the symmetrized AMSCR matrix
    plain = _collection(p.copy(rerank_k=0, channel_weight=0.0))
    D = plain.distance_matrix()
    S = 0.5 * (D + D.T)
    np.fill_diagonal(S, 0.0)
    np.testing.assert_allclose(plain.retrieval_matrix(), S, rtol=1e-15, atol=0)
    # a fused matrix (weight 0.5, no re-ranking) is the mean of the two, each divided by its
    # median off-diagonal value (docs/method.md §10.3; the upper middle of an even count):
    # unlike either alone, and symmetric
    fused_db = _collection(p.copy(rerank_k=0, channel_weight=0.5))
    fused = fused_db.retrieval_matrix()
    C = fused_db.channel_matrix()
    off = ~np.eye(len(C), dtype=bool)

    def med(M):
        v = np.sort(M[off])
        return v[len(v) // 2]
    expect = 0.5 * S / med(S) + 0.5 * C / med(C)
    np.testing.assert_allclose(fused, expect, rtol=1e-12, atol=1e-15)
    for alone in (S, C):
        assert not np.allclose(fused / med(fused), alone / med(alone), rtol=1e-3)
    np.testing.assert_allclose(fused, fused.T, rtol=1e-12)
    assert n == 30


def test_retrieval_matrix_heldout():
    """Each group held out: its rows are the fusion with the other groups' medians (no
    re-ranking), its own group's entries +inf; with re-ranking, scores in [0, 1] that
    nn_groups reads."""
    p = amscr.Params.retrieval(points=64)
    fused_db = _collection(p.copy(rerank_k=0, channel_weight=0.5))
    n = len(fused_db)
    groups = np.arange(n) % 4  # one copy of each class in each group
    H = fused_db.retrieval_matrix_heldout(groups)
    D = fused_db.distance_matrix()
    S = 0.5 * (D + D.T)
    np.fill_diagonal(S, 0.0)
    C = fused_db.channel_matrix()
    for g in range(4):
        out = groups != g
        off = np.outer(out, out) & ~np.eye(n, dtype=bool)
        ms, mc = np.sort(S[off])[off.sum() // 2], np.sort(C[off])[off.sum() // 2]
        for i in np.flatnonzero(~out):
            np.testing.assert_allclose(H[i, out], 0.5 * S[i, out] / ms + 0.5 * C[i, out] / mc, rtol=1e-12)
            sib = ~out
            sib[i] = False
            assert H[i, i] == 0.0 and np.all(np.isposinf(H[i, sib]))
    db = _collection(p, copies=10)
    groups = np.arange(len(db)) % 5
    R = db.retrieval_matrix_heldout(['g%d' % g for g in groups])
    own = groups[:, None] == groups[None, :]
    assert np.all((R[~own] >= 0.0) & (R[~own] <= 1.0)) and np.all(np.diag(R) == 0.0)
    assert amscr.nn_groups(R, db.label_codes, groups).accuracy == 1.0
    with pytest.raises(amscr.InvalidArgumentError, match='at least 2 groups'):
        db.retrieval_matrix_heldout([1] * len(db))
    with pytest.raises(amscr.InvalidArgumentError):
        db.retrieval_matrix_heldout([1, 2])


def test_open_curves_need_weight_zero():
    db = amscr.Collection(amscr.Params.retrieval(closed=False, points=64))
    db.add(blob(200, seed=1)[:150])
    db.add(blob(200, seed=2)[:150])
    with pytest.raises(amscr.InvalidArgumentError):
        db.retrieval_matrix()
    db2 = amscr.Collection(amscr.Params.retrieval(closed=False, points=64, channel_weight=0.0, rerank_k=0))
    db2.add(blob(200, seed=1)[:150])
    db2.add(blob(200, seed=2)[:150])
    assert db2.retrieval_matrix().shape == (2, 2)
