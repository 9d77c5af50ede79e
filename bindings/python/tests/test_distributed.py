"""amscr.distributed on a real LocalCluster (2 worker processes on loopback): distance matrix,
cross matrix and top-k equal the single-machine results exactly, a worker killed mid-run (or one
that dies holding the only copy of a query block) does not change the result, a corrupt serialized
collection is a clear error. Skipped without Dask."""
import concurrent.futures
import contextlib
import os
import time

import numpy as np
import pytest

distributed = pytest.importorskip(
    'distributed', reason='Dask is not installed: pip install "dask[distributed]>=2023" to run these tests')

import amscr  # noqa: E402
import amscr.distributed as ad  # noqa: E402
from helpers import blob  # noqa: E402

N_SHAPES = 240
POINTS = 32  # small N keeps the file fast; the tiling does not depend on N
TIMEOUT = 60  # seconds: a failure must be an error, never a hang


def _shapes(n, seed0):
    return [blob(120, seed=seed0 + i, phase=0.1 * i) for i in range(n)]


@pytest.fixture(scope='module')
def db():
    c = amscr.Collection(points=POINTS, reflections=True, threads=0)
    shapes = _shapes(N_SHAPES - 12, 0)
    shapes += [shapes[5 * i] for i in range(12)]  # exact duplicates: tied distances in every ranking
    c.extend(shapes, [i % 12 for i in range(N_SHAPES)])
    return c


@pytest.fixture(scope='module')
def queries():
    c = amscr.Collection(points=POINTS, reflections=True, threads=0)
    c.extend(_shapes(45, 10_000))
    return c


@pytest.fixture(scope='module')
def D(db):
    return db.distance_matrix()


@pytest.fixture(scope='module')
def client():
    # workers are spawned processes: they inherit os.environ (AMSCR_LIBRARY set by conftest) and
    # sys.path, so they load the same amscr and library as this process
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=':0',
                                  host='127.0.0.1') as cluster, distributed.Client(cluster) as c:
        c.wait_for_workers(2, timeout=TIMEOUT)
        yield c


@pytest.fixture
def two_workers(client):
    """The module's client once both workers are up (a test before may have killed one: its nanny
    restarts it)."""
    client.wait_for_workers(2, timeout=TIMEOUT)
    assert len(client.nthreads()) == 2
    return client


def _within(fn, timeout=TIMEOUT):
    """fn() on a thread; fails (instead of hanging the suite) when it takes longer than timeout."""
    ex = concurrent.futures.ThreadPoolExecutor(1)
    try:
        return ex.submit(fn).result(timeout=timeout)
    finally:
        ex.shutdown(wait=False)


def _ranking(row, k, exclude=-1):
    order = np.argsort(row, kind='stable')
    return order[order != exclude][:k]


# ------------------------------------------------------------------------------ no cluster
def test_merge_is_the_stable_argsort():
    """Per-tile top-k merged in any grouping = np.argsort(kind='stable') of the full row, with
    heavy ties, NaN, -0.0/+0.0 and exclusions."""
    rng = np.random.default_rng(1)
    for trial in range(200):
        m, n = int(rng.integers(1, 6)), int(rng.integers(2, 60))
        row = rng.integers(0, 4, size=(m, n)).astype(float)
        row[rng.random((m, n)) < 0.1] = np.nan
        row[rng.random((m, n)) < 0.1] = -0.0
        ex = np.where(rng.random(m) < 0.5, rng.integers(0, n, size=m), -1)
        k = int(rng.integers(1, n))  # <= n - 1
        cuts = np.unique(np.concatenate([[0, n], rng.integers(0, n, size=3)]))
        parts = [ad._tile_candidates(row[:, c0:c1], c0, k, ex if trial % 2 else np.where(ex < 0, -1, ex))
                 for c0, c1 in zip(cuts[:-1], cuts[1:])]
        while len(parts) > 1:
            parts = [ad._merge(k, *parts[i:i + 2]) for i in range(0, len(parts), 2)]
        idx, dist = parts[0]
        for r in range(m):
            want = _ranking(row[r], k, ex[r])
            assert np.array_equal(idx[r], want), (trial, r)
            assert np.array_equal(dist[r], row[r, want], equal_nan=True)


def test_tile_size():
    assert ad.tile_size(300, 300, 2) == (75, 75)  # 16 tiles: 8 per thread
    assert ad.tile_size(10 ** 6, 10 ** 6, 3200) == (2048, 2048)
    assert ad.tile_size(100, 100, 64) == (64, 64)
    assert ad.tile_size(30, 1000, 2, tile=(16, 100)) == (16, 100)
    assert ad.tile_size(30, 40, 2, tile=500) == (30, 40)
    with pytest.raises(ValueError):
        ad.tile_size(10, 10, 1, tile=0)


# ------------------------------------------------------------------------------ on the cluster
def test_workers_use_the_same_library(two_workers):
    paths = two_workers.run(lambda: (amscr.LIBRARY_PATH, amscr.API_MODE, amscr.library_version()))
    assert len(paths) == 2
    assert set(paths.values()) == {(amscr.LIBRARY_PATH, amscr.API_MODE, amscr.library_version())}


def test_distance_matrix_equals_single_machine(client, db, D):
    before = client.run(ad._parsed_count)
    A = ad.distance_matrix(db, client=client, tile=50)  # lazy: 5 x 5 tiles, ragged last
    assert A.shape == D.shape and A.chunks[0] == (50, 50, 50, 50, 40)
    assert np.array_equal(_within(A.compute), D)
    # the collection was parsed once per worker, not once per tile
    after = client.run(ad._parsed_count)
    assert all(after[w] - before[w] <= 1 for w in after)
    # default tiles, progress bar, eager into a NumPy array
    out = np.full(D.shape, np.nan)
    got = _within(lambda: ad.distance_matrix(db, client=client, progress=True, out=out))
    assert got is out and np.array_equal(out, D)


def test_distance_matrix_into_memmap(client, db, D, tmp_path):
    path = tmp_path / 'D.npy'
    M = _within(lambda: ad.distance_matrix(db, client=client, tile=(64, 96), out=path))
    assert isinstance(M, np.memmap) and np.array_equal(M, D)
    assert np.array_equal(np.load(path), D)


def test_failed_call_leaves_the_out_path_as_it_was(client, db, D, tmp_path, monkeypatch):
    """out=path: the tiles go to a temporary file beside the path, renamed to it once complete; a
    call that fails keeps the file there before (no zero-filled matrix of the right shape in its
    place) and leaves no other file."""
    path = tmp_path / 'D.npy'
    np.save(path, np.arange(4.0))  # an earlier result
    data = bytearray(db.to_bytes())
    data[len(data) // 2] ^= 0xFF
    with monkeypatch.context() as m:  # corrupted on its way to the workers: every tile fails
        m.setattr(amscr.Collection, 'to_bytes', lambda self: bytes(data))
        with pytest.raises(amscr.FormatError, match='corrupt'):
            _within(lambda: ad.distance_matrix(db, client=client, tile=60, out=path))
    assert os.listdir(tmp_path) == ['D.npy']
    assert np.array_equal(np.load(path), np.arange(4.0))
    M = _within(lambda: ad.distance_matrix(db, client=client, tile=60, out=path))
    assert os.listdir(tmp_path) == ['D.npy'] and np.array_equal(np.load(path), D)
    assert M.filename == str(path)
    umask = os.umask(0o022)
    os.umask(umask)
    assert os.stat(path).st_mode & 0o777 == 0o666 & ~umask
    M[0, 0] = 5.0  # still the file's map
    M.flush()
    assert np.load(path)[0, 0] == 5.0


def test_cross_matrix_equals_single_machine(client, db, queries):
    want = queries.cross_matrix(db)
    got = _within(ad.cross_matrix(queries, db, client=client, tile=(20, 64)).compute)
    assert np.array_equal(got, want)


def test_topk_equals_single_machine_query(client, db, queries):
    k = 10
    idx, dist = _within(lambda: ad.topk(queries, db, k=k, client=client, tile=(16, 32), progress=True))
    assert idx.shape == dist.shape == (len(queries), k)
    assert (np.diff(dist, axis=1) == 0).any(), 'the duplicates should tie somewhere in the top-k'
    for i in range(len(queries)):
        row = db.query(queries.shape(i))  # the single-machine search
        assert np.array_equal(idx[i], _ranking(row, k))
        assert np.array_equal(dist[i], row[idx[i]])
    # raw points are prepared with the collection's options, as Collection.query does
    pts = _shapes(3, 10_000)
    idx2, dist2 = _within(lambda: ad.topk(pts, db, k=k, client=client, tile=(2, 64)))
    assert np.array_equal(idx2, idx[:3]) and np.array_equal(dist2, dist[:3])


@pytest.mark.parametrize('options', [{}, {'channel_weight': 0.5}, {'rerank_k': 0}])
def test_topk_by_retrieval_scores_equals_collection_query(client, options):
    """Params that ask for retrieval: top-k by the scores of Collection.query (the retrieval
    matrix's row of the collection plus the query), element for element, exclusions too."""
    coll = amscr.Collection(amscr.Params.retrieval(points=POINTS, threads=1, **options))
    coll.extend(_shapes(30, 500), [i % 5 for i in range(30)])
    pts = _shapes(5, 20_000) + [coll.shape(3).input_points]
    k = 7
    idx, dist = _within(lambda: ad.topk(pts, coll, k=k, client=client, tile=(2, 8)))
    ex = [-1, 2, -1, -1, 0, 3]
    idx2, dist2 = _within(lambda: ad.topk(pts, coll, k=k, client=client, exclude=ex))
    for i, q in enumerate(pts):
        row = coll.query(q)
        assert np.array_equal(idx[i], _ranking(row, k)), i
        assert np.array_equal(dist[i], row[idx[i]]), i
        assert np.array_equal(idx2[i], _ranking(row, k, exclude=ex[i])), i
        assert np.array_equal(dist2[i], row[idx2[i]]), i


def test_topk_leave_one_out_equals_matrix_rows(client, db, D):
    """A collection against itself, each shape excluded: the ranking of the query rows."""
    n, k = len(db), 12
    idx, dist = _within(lambda: ad.topk(db, db, k=k, client=client, tile=(40, 64), exclude=range(n)))
    for i in range(n):
        row = db.query(db.shape(i))
        assert np.array_equal(idx[i], _ranking(row, k, exclude=i))
        assert np.array_equal(dist[i], row[idx[i]])
    # off the diagonal the rows are those of the distance matrix
    assert np.array_equal(dist, np.take_along_axis(D, idx, 1))
    # k larger than the candidates is clipped
    idx, _ = _within(lambda: ad.topk(db.shape(0).input_points, db, k=10 ** 6, client=client))
    assert idx.shape == (1, n)


def test_corrupt_serialized_collection_is_a_clear_error(client, db, monkeypatch):
    data = bytearray(db.to_bytes())
    data[len(data) // 2] ^= 0xFF
    # handed over corrupt: refused on the client at once
    with pytest.raises(amscr.FormatError):
        ad.distance_matrix(bytes(data), client=client)
    # corrupted on its way to the workers: each worker refuses it, the client gets the error
    monkeypatch.setattr(amscr.Collection, 'to_bytes', lambda self: bytes(data))
    with pytest.raises(amscr.FormatError, match='corrupt'):
        _within(lambda: ad.distance_matrix(db, client=client, tile=60, out=np.empty((len(db),) * 2)))
    with pytest.raises(ValueError, match='corrupt'):  # FormatError is a ValueError
        _within(ad.distance_matrix(db, client=client, tile=60).compute)


class _KillOnce(distributed.WorkerPlugin):
    """Kills its worker process (os._exit) when the nth task whose key starts with `prefix`
    starts on it; only once in the whole cluster (an O_EXCL marker file claims the kill)."""

    def __init__(self, marker, prefix='amscr-matrix-', nth=3):
        self.marker, self.prefix, self.nth = marker, prefix, nth
        self.started = 0

    def transition(self, key, start, finish, **kwargs):
        if finish != 'executing' or not str(key).startswith(self.prefix):
            return
        self.started += 1
        if self.started < self.nth:
            return
        try:
            fd = os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return
        os.close(fd)
        os._exit(1)


@contextlib.contextmanager
def _kill_once(client, tmp_path, prefix, nth):
    """A worker dies (once) at the nth task of `prefix` it starts; yields the marker path."""
    marker = str(tmp_path / 'killed')
    name = 'amscr-kill-once'
    register = getattr(client, 'register_plugin', None) or client.register_worker_plugin
    register(_KillOnce(marker, prefix, nth), name=name)
    try:
        yield marker
    finally:
        client.unregister_worker_plugin(name)
        client.wait_for_workers(2, timeout=TIMEOUT)  # the nanny restarts the killed worker


def test_worker_killed_mid_run_gives_the_same_matrix(two_workers, db, D, tmp_path):
    with _kill_once(two_workers, tmp_path, 'amscr-matrix-', 3) as marker:
        out = np.full(D.shape, np.nan)
        _within(lambda: ad.distance_matrix(db, client=two_workers, tile=30, out=out))  # 64 tiles
        assert os.path.exists(marker), 'no worker was killed'
        assert np.array_equal(out, D)


def test_worker_killed_holding_its_query_block_gives_the_same_topk(two_workers, db, queries, tmp_path):
    """Each query block lives on one worker: the worker starting the first top-k tile holds that
    tile's block (usually the only copy) and dies; the tiles are resubmitted, the result equal."""
    k = 7
    with _kill_once(two_workers, tmp_path, 'amscr-topk-', 1) as marker:
        idx, dist = _within(lambda: ad.topk(queries, db, k=k, client=two_workers, tile=(8, 120)))
        assert os.path.exists(marker), 'no worker was killed'
    want = queries.cross_matrix(db)
    assert np.array_equal(idx, np.argsort(want, axis=1, kind='stable')[:, :k])
    assert np.array_equal(dist, np.take_along_axis(want, idx, 1))


@pytest.fixture
def lose_first_query_block(two_workers, monkeypatch):
    """Right after the query blocks are scattered, the worker holding block 0 (its only copy)
    is restarted, so the tiles of block 0 depend on lost data. Yields the payload counts that
    _Scattered.refresh scattered again."""
    scatter, refresh, recovered = ad._Scattered._scatter, ad._Scattered.refresh, []

    def scatter_then_lose(self, which):
        futures = scatter(self, which)
        if not self.broadcast and not recovered:  # the first scatter of query blocks
            [holder] = two_workers.who_has(futures[:1])[futures[0].key]
            two_workers.restart_workers([holder], timeout=TIMEOUT, raise_for_error=False)  # its nanny: a new one
            deadline = time.monotonic() + TIMEOUT
            while futures[0].status == 'finished' and time.monotonic() < deadline:
                time.sleep(0.05)
            assert futures[0].status != 'finished', 'the restarted worker kept query block 0'
            recovered.append(0)
        return futures

    def counted_refresh(self):
        n = refresh(self)
        recovered.append(n)
        return n

    monkeypatch.setattr(ad._Scattered, '_scatter', scatter_then_lose)
    monkeypatch.setattr(ad._Scattered, 'refresh', counted_refresh)
    yield recovered
    two_workers.wait_for_workers(2, timeout=TIMEOUT)


def test_lost_query_block_is_scattered_again_for_topk(two_workers, db, queries, lose_first_query_block):
    k = 5
    idx, dist = _within(lambda: ad.topk(queries, db, k=k, client=two_workers, tile=(10, 64)))
    assert sum(lose_first_query_block) >= 1, 'no lost payload was scattered again'
    want = queries.cross_matrix(db)
    assert np.array_equal(idx, np.argsort(want, axis=1, kind='stable')[:, :k])
    assert np.array_equal(dist, np.take_along_axis(want, idx, 1))


def test_lost_query_block_is_scattered_again_for_cross_matrix(two_workers, db, queries, lose_first_query_block):
    out = np.full((len(queries), len(db)), np.nan)
    _within(lambda: ad.cross_matrix(queries, db, client=two_workers, tile=(10, 64), out=out))
    assert sum(lose_first_query_block) >= 1, 'no lost payload was scattered again'
    assert np.array_equal(out, queries.cross_matrix(db))


def test_tiles_cancelled_every_time_are_a_clear_error(two_workers, db, queries, monkeypatch):
    """A payload that cannot be brought back (here: refresh does nothing) ends in LostTilesError
    after LOST_ROUNDS resubmissions, never in a partial result or an exception in the matrix."""
    monkeypatch.setattr(ad._Scattered, 'refresh', lambda self: 0)
    monkeypatch.setattr(ad, 'LOST_ROUNDS', 1)
    scatter = ad._Scattered._scatter

    def scatter_then_lose(self, which):
        futures = scatter(self, which)
        if not self.broadcast:
            two_workers.cancel(futures)  # every query block gone: its tiles are cancelled
        return futures

    monkeypatch.setattr(ad._Scattered, '_scatter', scatter_then_lose)
    out = np.full((len(queries), len(db)), np.nan)
    with pytest.raises(ad.LostTilesError, match='cancelled by Dask 2 times'):
        _within(lambda: ad.cross_matrix(queries, db, client=two_workers, tile=(10, 64), out=out))
    with pytest.raises(amscr.AmscrError):
        _within(lambda: ad.topk(queries, db, k=3, client=two_workers, tile=(10, 64)))


def test_worker_not_answering_at_the_start_is_left_out_of_the_core_count(two_workers, db, D, monkeypatch):
    """The call asks every worker for its host's cores first (client.run): a worker that fails to
    answer (it died meanwhile, or hangs until the scheduler drops it: CommClosedError) is left out
    of the count, as Dask reschedules its tiles; the call was that error."""
    from amscr import _placement
    victim = sorted(two_workers.nthreads())[0]
    cores = _placement._cores

    def cores_but_victim(dask_worker):  # pickled by value: runs as such on the workers
        if dask_worker.address == victim:
            raise distributed.comm.CommClosedError('simulated: the worker left during the call')
        return cores()

    monkeypatch.setattr(_placement, '_cores', cores_but_victim)
    out = np.full(D.shape, np.nan)
    _within(lambda: ad.distance_matrix(db, client=two_workers, tile=60, out=out))
    assert np.array_equal(out, D)
    assert _placement._threads_by_host(two_workers) == {'127.0.0.1': max(1, cores() // 2)}


@pytest.mark.parametrize('call', ['matrix', 'topk'])
def test_client_closed_mid_call_is_a_clear_error(client, db, queries, monkeypatch, call):
    """The caller's client closed (from another thread) while the tiles run: Dask cancels them
    all; the call raises LostTilesError naming the closed client, not an AttributeError from a
    scatter on the closed client, and never a partial result."""
    own = distributed.Client(client.scheduler.address, timeout=TIMEOUT)
    collect = ad._collect

    def close_then_collect(c, placed, progress, put):
        if c.status == 'running':
            c.close()
        return collect(c, placed, progress, put)

    monkeypatch.setattr(ad, '_collect', close_then_collect)
    try:
        with pytest.raises(ad.LostTilesError, match='client was closed'):
            if call == 'matrix':
                _within(lambda: ad.cross_matrix(queries, db, client=own, tile=(10, 64), out=np.empty((45, N_SHAPES))))
            else:
                _within(lambda: ad.topk(queries, db, k=3, client=own, tile=(10, 64)))
    finally:
        own.close()


def test_no_client_starts_and_closes_a_local_cluster(db, D):
    small = amscr.Collection(db.params)
    for i in range(40):
        small.add(db.shape(i))
    got = _within(lambda: ad.distance_matrix(small, tile=16))
    assert isinstance(got, np.ndarray) and np.array_equal(got, D[:40, :40])
