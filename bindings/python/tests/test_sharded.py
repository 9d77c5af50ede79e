"""amscr.distributed.build_index on a real LocalCluster (4 worker processes on loopback): an index
split in shards answers as the single index (the top 10 of 2,000 procedural shapes with every pair,
of 2,100 with the global signature shortlists, the scores to 1e-9 with the inner distance's graph),
a saved set loads back, a missing, foreign or differently
built shard is an error naming its file, a write cut off never replaces a good set, files follow
the umask. Skipped without Dask."""
import contextlib
import json
import os
import threading
import time

import numpy as np
import pytest

distributed = pytest.importorskip(
    'distributed', reason='Dask is not installed: pip install "dask[distributed]>=2023" to run these tests')

import amscr  # noqa: E402
import amscr.distributed as ad  # noqa: E402
from amscr import _shard_tasks, _shards  # noqa: E402
from helpers import blob  # noqa: E402

POINTS = 32  # small N keeps the file fast; the sharding does not depend on N
N_LARGE = 2000
N_SMALL = 160
N_QUERIES = 100


def _shapes(n, seed0):
    out = [blob(120, seed=seed0 + i, phase=0.1 * i) for i in range(n - 8)]
    return out + [out[3 * i] for i in range(8)]  # exact duplicates: tied distances in the lists


def _collection(params, shapes):
    c = amscr.Collection(params)
    c.extend(shapes, [i % 20 for i in range(len(shapes))])
    return c


@pytest.fixture(scope='module')
def client():
    with distributed.LocalCluster(n_workers=4, threads_per_worker=1, processes=True, dashboard_address=':0') as cl, \
            distributed.Client(cl) as c:
        yield c


@pytest.fixture(scope='module')
def small(client):
    """A set with the retrieval preset's inner-distance graph, and its single index."""
    params = amscr.Params.retrieval(points=POINTS, threads=1)
    coll = _collection(params, _shapes(N_SMALL, 0))
    return ad.build_index(client, coll, shards=3), amscr.Index(coll, candidates=0), coll


def _queries(n, seed0=50000):
    return [blob(120, seed=seed0 + i, phase=0.37 * i) for i in range(n)]


def test_top10_equals_single_index_on_2000_shapes(client):
    params = amscr.Params.retrieval(points=POINTS, rerank_inner_share=0.0, threads=0)
    coll = _collection(params, _shapes(N_LARGE, 0))
    single = amscr.Index(coll, candidates=0)
    sx = ad.build_index(client, coll)
    assert len(sx) == N_LARGE and len(sx.bounds) == 4
    qs = _queries(N_QUERIES)
    idx, sc = sx.query_many(qs, 10)
    same = 0
    for i, q in enumerate(qs):
        ref_idx, ref_sc = single.query(q, 10, candidates=0)
        same += np.array_equal(idx[i], ref_idx)
        np.testing.assert_allclose(sc[i], ref_sc, rtol=0, atol=1e-9)
    assert same >= 0.99 * N_QUERIES


def test_global_shortlists_equal_single_index_above_2000_shapes(client):
    """Above 2,000 shapes both build with the default shortlist (256): each shape's candidates are
    its signature-nearest of the whole collection, so the lists and a query's scores (candidates
    256) are the single index's."""
    n = N_LARGE + 100
    params = amscr.Params.retrieval(points=POINTS, rerank_inner_share=0.0, threads=0)
    coll = _collection(params, _shapes(n, 0))
    single = amscr.Index(coll)
    sx = ad.build_index(client, coll)
    assert sx.candidates == 256 and len(sx.bounds) == 4
    assert sx.pairs < n * (n - 1) // 2 // 4  # not every pair: about n (192 + K^2) / 2
    qs = _queries(N_QUERIES)
    idx, sc = sx.query_many(qs, 10)
    same = 0
    for i, q in enumerate(qs):
        ref_idx, ref_sc = single.query(q, 10, candidates=256)
        same += np.array_equal(idx[i], ref_idx)
        np.testing.assert_allclose(sc[i], ref_sc, rtol=0, atol=1e-9)
    assert same >= 0.99 * N_QUERIES
    # every shape a candidate on the same lists
    np.testing.assert_allclose(sx.scores(qs[0], candidates=0), single.scores(qs[0], candidates=0), rtol=0, atol=1e-9)
    # the client holds the signatures packed (16-bit values, an exponent a shape): exactly the
    # single index's floats in half their bytes
    q, e = sx._signatures()
    d = int(amscr._lib.lib.amscr_signature_size())
    assert q.dtype == np.uint16 and e.dtype == np.int32 and q.shape == (n, d) and e.shape == (n,)
    assert (q.nbytes + e.nbytes) / n == 2 * d + 4
    ref = np.zeros((n, d), dtype=np.float32)
    amscr.errors._check(amscr._lib.lib.amscr_index_signatures(single._x, amscr._lib.ffi.from_buffer('float[]', ref),
                                                              ref.size))
    assert np.array_equal(_shard_tasks._floats((q, e), 0, n), ref)


def test_shortlist_build_with_the_inner_graph_member_rule_saved_and_loaded(client, tmp_path):
    params = amscr.Params.retrieval(points=POINTS, threads=1)
    coll = _collection(params, _shapes(N_SMALL, 100))
    single = amscr.Index(coll, candidates=40)
    sx = ad.build_index(client, coll, shards=3, candidates=40)
    assert sx.candidates == 40 and sx.pairs < N_SMALL * (N_SMALL - 1) // 2
    qs = _queries(8, 9000)
    S = sx.scores_many(qs)
    for i, q in enumerate(qs):
        ref = single.scores(q, candidates=40)
        assert np.array_equal(np.isinf(S[i]), np.isinf(ref))
        np.testing.assert_allclose(S[i][np.isfinite(ref)], ref[np.isfinite(ref)], rtol=0, atol=1e-9)
    np.testing.assert_allclose(sx.scores(qs[0], candidates=0), single.scores(qs[0], candidates=0), rtol=0, atol=1e-9)
    # the member rule: a member's copy is scored as that member (the lowest index of copies: 159 is 21's)
    shapes = _shapes(N_SMALL, 100)
    members = [shapes[i] for i in (0, 57, 100, 159)]
    assert [single.find_member(q) for q in members] == [0, 57, 100, 21]
    for m in (40, 0):
        Sm = sx.scores_many(members, candidates=m)
        for i, q in enumerate(members):
            ref = single.scores(q, candidates=m)
            assert np.array_equal(np.isinf(Sm[i]), np.isinf(ref))
            np.testing.assert_allclose(Sm[i][np.isfinite(ref)], ref[np.isfinite(ref)], rtol=0, atol=1e-9)
        assert Sm[3][21] == 0.0  # its own score
    sx.save(tmp_path / 'set')
    loaded = ad.load_index(client, tmp_path / 'set')
    assert loaded.candidates == 40
    np.testing.assert_array_equal(loaded.scores_many(qs[:3]), S[:3])
    with pytest.raises(amscr.InvalidArgumentError, match='candidates'):
        ad.build_index(client, coll, candidates=-1)


def test_members_shortlists_in_one_pass_are_each_members_own():
    """A batch of member queries finds its shortlists in one pass over the signatures (the m + 1
    nearest of each member's own, less the member): the lists of one search a member, with the
    member left out, to the index, also where more than m + 1 exact copies tie at distance 0."""
    shapes = _shapes(N_SMALL, 100)
    coll = _collection(amscr.Params.retrieval(points=POINTS, threads=1), shapes + [shapes[0]] * 6)
    sigs = _shard_tasks._signatures(amscr.Index(coll, candidates=40))
    n = len(coll)
    members = np.r_[np.arange(0, n, 7), n - 6:n]  # shape 0's copies: 152 (in _shapes) and n - 6 .. n - 1
    for m in (3, 16, 40, n - 1):
        got = _shard_tasks._member_shortlists(sigs, members, m, 2)
        ref = [_shard_tasks._shortlists(sigs, _shard_tasks._floats(sigs, j, j + 1), j, m, 1)[0] for j in members]
        assert got.shape == (len(members), m)
        assert np.array_equal(got, np.array(ref)), m
    assert list(_shard_tasks._member_shortlists(sigs, [n - 1], 3, 1)[0]) == [0, 152, n - 6]


def test_scores_equal_with_the_inner_graph(small):
    sx, single, _ = small
    qs = _queries(12)
    S = sx.scores_many(qs)
    for i, q in enumerate(qs):
        np.testing.assert_allclose(S[i], single.scores(q, candidates=0), rtol=0, atol=1e-9)
    m_idx, m_sc = sx.query(qs[0], 5)
    r_idx, r_sc = single.query(qs[0], 5, candidates=0)
    assert np.array_equal(m_idx, r_idx)


def test_queries_in_row_col_order_and_bad_points_named(small):
    """Queries take order='rc' as amscr.Index does, and bad points are named as the caller gave
    them (they were named 'shape', as a Collection's own)."""
    sx, single, _ = small
    q = np.asarray(_queries(1)[0])
    rc = q[:, ::-1]
    np.testing.assert_array_equal(sx.scores(rc, order='rc'), sx.scores(q))
    np.testing.assert_array_equal(sx.query(rc, 5, order='rc')[0], single.query(q, 5, candidates=0)[0])
    np.testing.assert_array_equal(sx.query_many([rc, rc], 3, order='rc')[0][1], sx.query(q, 3)[0])
    with pytest.raises(amscr.InvalidArgumentError, match='^points: '):
        sx.query(q[:, :1])
    with pytest.raises(amscr.InvalidArgumentError, match=r'^queries\[1\]: '):
        sx.query_many([q, q[:, :1]])
    with pytest.raises(amscr.InvalidArgumentError, match='order'):
        sx.scores(q, order='yx')


def test_save_load_round_trip(small, client, tmp_path):
    sx, single, _ = small
    sx.save(tmp_path / 'set')
    names = sorted(os.listdir(tmp_path / 'set'))
    assert 'manifest.json' in names and sum(n.startswith('shard-') for n in names) == 3
    loaded = ad.load_index(client, tmp_path / 'set')
    assert loaded.bounds == sx.bounds
    qs = _queries(3, 7000)
    np.testing.assert_array_equal(loaded.scores_many(qs), sx.scores_many(qs))
    # each shard is an ordinary index file
    shard = amscr.Index.load(tmp_path / 'set' / [n for n in names if n.startswith('shard-001')][0])
    assert len(shard) == sx.bounds[1][1] - sx.bounds[1][0]


def test_saves_at_once_follow_each_other_and_keep_the_users_files(small, client, tmp_path):
    """Two saves into one folder at once (threads of one client) leave one whole set, which loads
    and answers as its index; files of the user that only look like a set's are kept."""
    import threading
    sx, _, coll = small
    other = ad.build_index(client, coll, shards=2)
    d = tmp_path / 'set'
    d.mkdir()
    mine = ['graph-my-results.npz', 'shard-backup.amscr-index', 'notes.txt']
    for f in mine:
        (d / f).write_text('mine\n')
    errors = []

    def save(x):
        try:
            x.save(d)
        except Exception as e:  # noqa: BLE001 - collected and asserted below
            errors.append(e)
    for _ in range(3):
        ts = [threading.Thread(target=save, args=(x,)) for x in (sx, other)]
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        assert errors == []
        loaded = ad.load_index(client, d)
        q = _queries(2, 7100)
        assert any(np.array_equal(loaded.scores_many(q), x.scores_many(q)) for x in (sx, other))
    assert all((d / f).read_text() == 'mine\n' for f in mine)


def _shard_file(d, s):
    return [n for n in os.listdir(d) if n.startswith('shard-%03d-' % s)][0]


def test_missing_foreign_or_other_options_shard_is_named(small, client, tmp_path):
    sx, _, coll = small
    d = tmp_path / 'set'
    sx.save(d)
    name = _shard_file(d, 1)
    data = (d / name).read_bytes()

    os.unlink(d / name)
    with pytest.raises(ad.ShardSetError, match='shard 1 .*%s.* missing' % name):
        ad.load_index(client, d)

    lo, hi = sx.bounds[1]
    other = amscr.Collection(coll.params)
    other.extend(_shapes(hi - lo, 900), [0] * (hi - lo))
    (d / name).write_bytes(amscr.Index(other, candidates=0).to_bytes())
    with pytest.raises(ad.ShardSetError, match='shard 1, .*%s, is foreign' % name):
        ad.load_index(client, d)

    part = amscr.Collection(coll.params.copy(rerank_k=5))
    part.extend(_shapes(hi - lo, 0)[:hi - lo], [0] * (hi - lo))
    (d / name).write_bytes(amscr.Index(part, candidates=0).to_bytes())
    with pytest.raises(ad.ShardSetError, match='%s, was built with other options.*rerank_k 5' % name):
        ad.load_index(client, d)

    (d / name).write_bytes(data[:len(data) // 2])
    with pytest.raises(ad.ShardSetError, match='%s, is not an index file' % name):
        ad.load_index(client, d)

    (d / name).write_bytes(data)
    ad.load_index(client, d)  # whole again
    graph = [n for n in os.listdir(d) if n.startswith('graph-')][0]
    gdata = (d / graph).read_bytes()
    (d / graph).write_bytes(gdata[:-10])
    with pytest.raises(ad.ShardSetError, match='graph .*%s is foreign' % graph):
        ad.load_index(client, d)
    (d / graph).write_bytes(gdata)
    manifest = (d / 'manifest.json').read_bytes()
    for bad, what in ((manifest[:40], 'not a shard set manifest'),
                      (manifest.replace(b'"version": 1', b'"version": 7'), 'version 7'),
                      (manifest.replace(b'"shapes": %d' % len(coll), b'"shapes": 3'), 'do not cover')):
        (d / 'manifest.json').write_bytes(bad)
        with pytest.raises(amscr.FormatError, match=what):
            ad.load_index(client, d)
    # a manifest edited by hand: every file's checksum still holds, but not what it says of them
    m = json.loads(manifest)
    edits = [(lambda m: m['params'].__setitem__('rerank_iterations', 3), ad.ShardSetError,
              'shard 0, .*, was built with other options than the manifest says: rerank_iterations'),
             (lambda m: (m['shards'][0].__setitem__('count', m['shards'][0]['count'] - 1),
                         m['shards'][1].__setitem__('first', m['shards'][1]['first'] - 1),
                         m['shards'][1].__setitem__('count', m['shards'][1]['count'] + 1)), ad.ShardSetError,
              'shard 0, .*, holds %d shapes; the manifest says %d' % (sx.bounds[0][1], sx.bounds[0][1] - 1)),
             (lambda m: m['shards'][1].__setitem__('file', '../' + m['shards'][1]['file']), amscr.FormatError,
              'is not a name a save writes')]
    for edit, error, what in edits:
        bad = json.loads(manifest)
        edit(bad)
        (d / 'manifest.json').write_text(json.dumps(bad))
        with pytest.raises(error, match=what):
            ad.load_index(client, d)
    (d / 'manifest.json').write_text(json.dumps(m))
    ad.load_index(client, d)
    os.unlink(d / 'manifest.json')
    with pytest.raises(amscr.FileError, match='manifest.json is missing'):
        ad.load_index(client, d)


def test_cut_off_write_keeps_the_good_set(small, client, tmp_path, monkeypatch):
    sx, _, coll = small
    d = tmp_path / 'set'
    sx.save(d)
    before = sorted(os.listdir(d))
    qs = _queries(2, 8000)
    want = sx.scores_many(qs)
    other = ad.build_index(client, _collection(coll.params, _shapes(N_SMALL, 300)), shards=3)

    real_fsync, calls = os.fsync, []

    def full_disk(fd):  # the disk fills on the 4th file: the 3 shards are written, the graph is not
        calls.append(fd)
        if len(calls) > 3 * 2:  # each file: its own fsync and its directory's
            raise OSError(28, 'No space left on device')
        real_fsync(fd)

    monkeypatch.setattr(os, 'fsync', full_disk)
    with pytest.raises(amscr.FileError, match='No space left'):
        other.save(d)
    monkeypatch.setattr(os, 'fsync', real_fsync)
    assert not [n for n in os.listdir(d) if n.startswith('.amscr-tmp-')]
    np.testing.assert_array_equal(ad.load_index(client, d).scores_many(qs), want)

    # killed mid-write: a temporary file left behind; the set still loads, the next save clears it
    (d / '.amscr-tmp-killed').write_bytes(b'half a shard')
    np.testing.assert_array_equal(ad.load_index(client, d).scores_many(qs), want)
    other.save(d)
    after = sorted(os.listdir(d))
    assert '.amscr-tmp-killed' not in after and not set(before) - {'manifest.json', '.amscr-lock'} & set(after)
    assert not np.array_equal(ad.load_index(client, d).scores_many(qs), want)


def test_files_follow_the_umask(small, tmp_path):
    sx = small[0]
    old = os.umask(0o027)
    try:
        sx.save(tmp_path / 'set')
    finally:
        os.umask(old)
    for n in os.listdir(tmp_path / 'set'):
        assert os.stat(tmp_path / 'set' / n).st_mode & 0o777 == 0o640, n


def test_bad_input(client):
    params = amscr.Params.retrieval(points=POINTS, channel_weight=0.5)
    with pytest.raises(amscr.InvalidArgumentError, match='between 0 and 1'):
        ad.build_index(client, _collection(params, _shapes(40, 0)))
    with pytest.raises(TypeError):
        ad.build_index(client, [1, 2])
    with pytest.raises(amscr.InvalidArgumentError, match='empty'):
        ad.build_index(client, amscr.Collection(amscr.Params.retrieval()))
    with pytest.raises(amscr.InvalidArgumentError, match='shards'):
        ad.build_index(client, _collection(amscr.Params.retrieval(points=POINTS), _shapes(40, 0)), shards=0)


def _error_of(call, *args):
    """The exception call(*args) raises, or None."""
    try:
        call(*args)
    except Exception as e:  # noqa: BLE001 - returned for the test to check
        return e
    return None


def _restored(client, dead, workers=4, seconds=120):
    """Waits until the nanny has replaced the killed worker `dead`."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        w = client.nthreads()
        if len(w) == workers and dead not in w:
            return
        time.sleep(0.2)
    raise AssertionError('the cluster did not get its worker back')


def _build_loses_shard_1(client, coll, killed, **kw):
    """A 2-shard build (on a thread, at most 2 min) whose patched step killed shard 1's worker
    (its address in `killed`) raises the ShardSetError naming it; the cluster is made whole again."""
    got = []
    t = threading.Thread(target=lambda: got.append(_error_of(lambda: ad.build_index(client, coll, shards=2, **kw))),
                         daemon=True)
    t.start()
    t.join(120)
    assert killed and got and isinstance(got[0], ad.ShardSetError), got
    assert 'shard 1 lost with its worker during the build' in str(got[0]) and 'build again' in str(got[0])
    _restored(client, killed[0])


@pytest.mark.parametrize('candidates', [0, 16])
def test_worker_lost_during_the_build_is_a_clear_error(client, monkeypatch, candidates):
    """A worker killed while the build waits for its tasks: the build waited forever for it; now a
    ShardSetError naming the shard, within seconds (every pair, and the shortlist build)."""
    coll = _collection(amscr.Params.retrieval(points=POINTS, threads=1), _shapes(60, 0))
    real, killed = _shards.gather_live, []

    def kill_first(cl, futs, placed, lost):
        if not killed:
            killed.append(placed[1])
            with contextlib.suppress(Exception):  # the worker dies before it answers
                cl.run(os._exit, 1, workers=[placed[1]])
        return real(cl, futs, placed, lost)

    monkeypatch.setattr(_shards, 'gather_live', kill_first)
    _build_loses_shard_1(client, coll, killed, candidates=candidates)


def test_worker_gone_before_its_block_is_sent_is_a_clear_error(client, monkeypatch):
    """A worker that leaves between the build's look at the cluster and the scattering of its
    block: the build raised Dask's KeyError (the worker's address); now a ShardSetError naming the
    shard."""
    coll = _collection(amscr.Params.retrieval(points=POINTS, threads=1), _shapes(60, 0))
    real, killed = _shards._workers, []

    def workers_then_kill(cl):
        w = real(cl)
        killed.append(w[1])
        with contextlib.suppress(Exception):  # the worker dies before it answers
            cl.run(os._exit, 1, workers=[w[1]])
        deadline = time.monotonic() + 60  # until the scheduler has seen it go
        while w[1] in cl.nthreads() and time.monotonic() < deadline:
            time.sleep(0.05)
        return w

    monkeypatch.setattr(_shards, '_workers', workers_then_kill)
    _build_loses_shard_1(client, coll, killed)


def test_query_after_its_client_is_closed_says_so(client):
    """A set whose client was closed is the caller's to load again, not a lost shard (it said
    "shards 0, 1 lost with their worker (RuntimeError: IOLoop is closed)")."""
    coll = _collection(amscr.Params.retrieval(points=POINTS, threads=1), _shapes(40, 0))
    other = distributed.Client(client.cluster)
    sx = ad.build_index(other, coll, shards=2)
    sx.scores(_queries(1)[0])
    other.close()
    with pytest.raises(amscr.StateError, match='its client is closed'):
        sx.scores(_queries(1)[0])


def test_shard_lost_with_its_worker_is_a_clear_error(client, tmp_path):
    """Last in the file: it kills a worker of the module's cluster (its nanny starts another)."""
    coll = _collection(amscr.Params.retrieval(points=POINTS, threads=1), _shapes(60, 0))
    sx = ad.build_index(client, coll, shards=2)
    sx.scores(_queries(1)[0])
    sx.save(tmp_path / 'set')
    loaded = ad.load_index(client, tmp_path / 'set')  # its shard 1 on the same worker
    loaded.scores(_queries(1)[0])
    with contextlib.suppress(Exception):  # the worker dies before it answers
        client.run(os._exit, 1, workers=[sx._workers[1]])
    # a loaded set's shard waited forever for its worker; it is a clear error now
    got = []
    t = threading.Thread(target=lambda: got.append(_error_of(loaded.scores, _queries(1)[0])), daemon=True)
    t.start()
    t.join(120)
    assert got and isinstance(got[0], ad.ShardSetError) and 'shard 1 lost' in str(got[0]), got
    with pytest.raises(ad.ShardSetError, match='shard 1 lost with its worker'):
        deadline = time.monotonic() + 120  # until the scheduler has seen the worker go (slow on a loaded machine)
        while time.monotonic() < deadline:
            sx.scores(_queries(1)[0])
            time.sleep(0.2)
