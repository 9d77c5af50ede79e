"""amscr.distributed scaling on this machine: C batch (1, 2 threads) vs Dask 1 and 2 worker processes
(threads_per_worker=1, 1 C thread per tile), interleaved, `reps` times; wall time (best) and CPU time
(pairs per CPU-second of the computing processes, median). `shards`: the index in shards
(build_index) with 1, 2, 4 workers: build time, query rate, memory per worker."""
import os, sys, time, statistics
# run from the repository root: python3 bench/distributed_scaling.py [N_SHAPES] [REPS] (needs psutil, dask);
# python3 bench/distributed_scaling.py shards [N_SHAPES] [REPS]: the index in shards (sharded() below)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bindings', 'python')); sys.path.insert(0, os.path.join(ROOT, 'bindings', 'python', 'tests'))
os.environ.setdefault('AMSCR_LIBRARY', os.path.join(ROOT, 'build', 'libamscr.so.0'))
import numpy as np, psutil, amscr, amscr.distributed as ad
from helpers import blob
from distributed import Client, LocalCluster

def wcpu():
    t = psutil.Process().cpu_times(); return t.user + t.system

def matrix(argv):
    n = int(argv[1]) if len(argv) > 1 else 1000
    reps = int(argv[2]) if len(argv) > 2 else 3
    db = amscr.Collection(threads=1)
    for i in range(n):
        db.add(blob(400, seed=i, phase=0.01 * i), label=i % 20)
    p = db.params
    print('n %d, N %d, %d scales, reflections %s, method %s' % (n, p.points, len(p.scales), p.reflections, p.method))
    pairs = n * (n - 1)
    clusters = {nw: LocalCluster(n_workers=nw, threads_per_worker=1, processes=True, dashboard_address=':0')
                for nw in (1, 2)}
    clients = {nw: Client(cl) for nw, cl in clusters.items()}
    D = db.distance_matrix(threads=1)
    res = {}
    def rec(name, dt, cpu, load):
        res.setdefault(name, []).append((dt, cpu, load))
    for rep in range(reps):
        for th in (1, 2):
            l0 = os.getloadavg()[0]; c0 = time.process_time(); t = time.perf_counter()
            M = db.distance_matrix(threads=th)
            dt = time.perf_counter() - t; cpu = time.process_time() - c0
            assert np.array_equal(M, D)
            rec('C batch, %d thread%s' % (th, 's' if th > 1 else ''), dt, cpu, l0)
        for nw in (1, 2):
            c = clients[nw]
            l0 = os.getloadavg()[0]; w0 = sum(c.run(wcpu).values()); t = time.perf_counter()
            M = ad.distance_matrix(db, client=c, threads=1, out=np.empty((n, n)))
            dt = time.perf_counter() - t; cpu = sum(c.run(wcpu).values()) - w0
            assert np.array_equal(M, D)
            rec('amscr.distributed matrix, %d worker%s' % (nw, 's' if nw > 1 else ''), dt, cpu, l0)
        c = clients[2]
        l0 = os.getloadavg()[0]; w0 = sum(c.run(wcpu).values()); t = time.perf_counter()
        idx, dist = ad.topk(db, db, k=10, client=c, threads=1, exclude=range(n))
        dt = time.perf_counter() - t; cpu = sum(c.run(wcpu).values()) - w0
        want = np.argsort(np.where(np.eye(n, dtype=bool), np.inf, D), axis=1, kind='stable')[:, :10]
        assert np.array_equal(idx, want)
        rec('amscr.distributed top-10, 2 workers', dt, cpu, l0)
        print('rep', rep, 'done', flush=True)
    print('%-40s %14s %12s %16s %s' % ('', 'pairs/s (best)', 'wall (best)', 'pairs/CPU-s (med)', 'load avg'))
    for name, v in res.items():
        best = min(x[0] for x in v); cpu = statistics.median(x[1] for x in v)
        print('%-40s %14.0f %11.2fs %16.0f   %s' % (name, pairs / best, best, pairs / cpu,
                                                  ' '.join('%.1f' % x[2] for x in v)))
    for c in clients.values(): c.close()
    for cl in clusters.values(): cl.close()


def sharded(n, reps, nq=20, workers=(1, 2, 4)):
    """amscr.distributed.build_index with 1, 2, 4 worker processes (one thread each): build (every pair,
    candidates 0, then the default: a global signature shortlist above 2,000 shapes), a batch of nq
    queries, the largest worker's memory (RSS after the builds and the queries); the scores checked
    against the single index built and queried alike. Run: python3 bench/distributed_scaling.py shards
    N [REPS] [WORKERS, e.g. 4]."""
    params = amscr.Params.retrieval(threads=1)  # the preset: N = 128, the inner distance's graph
    shapes = [blob(400, seed=i, phase=0.01 * i) for i in range(n)]
    db = amscr.Collection(params)
    db.extend(shapes, [i % 20 for i in range(n)])
    db2 = amscr.Collection(params.copy(threads=2))
    db2.extend(shapes, [i % 20 for i in range(n)])
    qs = [blob(400, seed=100000 + i, phase=0.37 * i) for i in range(nq)]
    M = amscr.lib.amscr_index_default_candidates(n)
    ref = {}
    for m in sorted({0, M}):
        t = time.perf_counter(); single = amscr.Index(db2, candidates=m)
        print('single index (2 C threads, candidates %d): build %.1fs' % (m, time.perf_counter() - t))
        ref[m] = np.array([single.scores(q, candidates=m) for q in qs])
    rss = lambda: psutil.Process().memory_info().rss
    print('%-10s %10s %12s %10s %16s %18s %14s %s' % ('workers', 'candidates', 'build (best)', 'pairs', 'query/s (best)',
                                                    'RSS/worker (max)', 'idle RSS', 'load avg'))
    for nw in workers:
        with LocalCluster(n_workers=nw, threads_per_worker=1, processes=True, dashboard_address=':0') as cl, Client(cl) as c:
            idle = max(c.run(rss).values())
            for m in sorted({0, M}):
                builds, queries, mem, loads = [], [], [], []
                for rep in range(reps):
                    loads.append(os.getloadavg()[0])
                    t = time.perf_counter(); sx = ad.build_index(c, db, candidates=m); builds.append(time.perf_counter() - t)
                    t = time.perf_counter(); S = sx.scores_many(qs); queries.append(time.perf_counter() - t)
                    assert np.array_equal(np.isinf(S), np.isinf(ref[m])) and np.abs(S - ref[m])[np.isfinite(S)].max() <= 1e-9
                    mem.append(max(c.run(rss).values()))
                    pairs = sx.pairs
                    del sx
                print('%-10d %10d %11.1fs %10d %16.1f %15.0f MB %11.0f MB %s' % (nw, m, min(builds), pairs, nq / min(queries),
                      max(mem) / 2**20, idle / 2**20, ' '.join('%.1f' % x for x in loads)), flush=True)


if __name__ == '__main__':
    if sys.argv[1:2] == ['shards']:
        sharded(int(sys.argv[2]) if len(sys.argv) > 2 else 1000, int(sys.argv[3]) if len(sys.argv) > 3 else 1,
                workers=tuple(int(w) for w in sys.argv[4:]) or (1, 2, 4))
    else:
        matrix(sys.argv)
