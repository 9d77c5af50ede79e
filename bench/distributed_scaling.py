"""amscr.distributed scaling on this machine: C batch (1, 2 threads) vs Dask 1 and 2 worker processes
(threads_per_worker=1, 1 C thread per tile), interleaved, `reps` times; wall time (best) and CPU time
(pairs per CPU-second of the computing processes, median)."""
import os, sys, time, statistics
# run from the repository root: python3 bench/distributed_scaling.py [N_SHAPES] [REPS] (needs psutil, dask)
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, 'bindings', 'python')); sys.path.insert(0, os.path.join(ROOT, 'bindings', 'python', 'tests'))
os.environ.setdefault('AMSCR_LIBRARY', os.path.join(ROOT, 'build', 'libamscr.so.0'))
import numpy as np, psutil, amscr, amscr.distributed as ad
from helpers import blob
from distributed import Client, LocalCluster

def wcpu():
    t = psutil.Process().cpu_times(); return t.user + t.system

if __name__ == '__main__':
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    reps = int(sys.argv[2]) if len(sys.argv) > 2 else 3
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
