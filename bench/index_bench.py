#!/usr/bin/env python3
"""Query time against large indexes: builds a synthetic collection of each of --shapes sizes
(100 classes of smooth closed curves, each shape a class prototype with its own small shape
noise under a random similarity map, as text point lists), indexes it once with `amscr index`
(cached in --work: rebuilt only when missing or of an older format), then times `amscr search` of
a few queries (wall clock of the whole command: reading the index, preparing the query,
matching the candidates, re-ranking). Prints the times and whether each size's target is met:
0.1 s at 1400 shapes, 0.5 s at 10,000 (the median of the queries).

    python3 bench/index_bench.py --tool build/tools/amscr [--shapes 1400,10000] [--work build/bench-index]
    .venv/bin/python3 bench/index_bench.py --rss-index m7.idx [--rss-copies 4]   # amscr.Index's memory (psutil)
"""
import argparse
import math
import os
import random
import statistics
import subprocess
import sys
import time


def index_version(path):
    """The format version of an index file (bytes 8..11, little-endian), 0 when unreadable."""
    try:
        with open(path, 'rb') as f:
            head = f.read(12)
        return int.from_bytes(head[8:12], 'little') if len(head) == 12 else 0
    except OSError:
        return 0


def curve(coef, rng, noise, m=120):
    """A closed curve r(t) = 1 + sum a_k cos(k t + p_k), perturbed, under a random similarity."""
    c = [(a * (1 + noise * rng.gauss(0, 1)), p + noise * rng.gauss(0, 1)) for a, p in coef]
    ang, s = rng.uniform(0, 2 * math.pi), rng.uniform(40, 120)
    tx, ty = rng.uniform(-50, 50), rng.uniform(-50, 50)
    pts = []
    for i in range(m):
        t = 2 * math.pi * i / m
        r = 1 + sum(a * math.cos((k + 2) * t + p) for k, (a, p) in enumerate(c))
        x, y = r * math.cos(t), r * math.sin(t)
        pts.append((s * (x * math.cos(ang) - y * math.sin(ang)) + tx, s * (x * math.sin(ang) + y * math.cos(ang)) + ty))
    return pts


def make_collection(folder, n, classes=100):
    rng = random.Random(15)
    os.makedirs(os.path.join(folder, "shapes"), exist_ok=True)
    protos = [[(rng.uniform(0.02, 0.18) / (k + 1) ** 0.5, rng.uniform(0, 2 * math.pi)) for k in range(6)]
              for _ in range(classes)]
    rows = ["file\tclass"]
    for i in range(n):
        c = i % classes
        rel = "shapes/c%03d_%05d.txt" % (c, i)
        with open(os.path.join(folder, rel), "w") as f:
            f.write("".join("%.3f %.3f\n" % p for p in curve(protos[c], rng, 0.15)))
        rows.append("%s\tc%03d" % (rel, c))
    with open(os.path.join(folder, "manifest.tsv"), "w") as f:
        f.write("\n".join(rows) + "\n")


def one_size(args, shapes):
    folder = os.path.join(args.work, "n%d" % shapes)
    idx = os.path.join(folder, "shapes.idx")
    if not os.path.exists(os.path.join(folder, "manifest.tsv")):
        make_collection(folder, shapes)
    if index_version(idx) < 4:  # missing, or of a format before the stored channel features
        t = time.time()
        r = subprocess.run([args.tool, "index", os.path.join(folder, "manifest.tsv"), "-o", idx, "--candidates",
                            args.build_candidates], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit("amscr index failed: " + r.stderr.strip())
        print("index: %d shapes built in %.1f s (once; cached in %s), %.0f MB" %
              (shapes, time.time() - t, idx, os.path.getsize(idx) / 1e6))
    rng = random.Random(7)
    qdir = os.path.join(folder, "queries")
    os.makedirs(qdir, exist_ok=True)
    files = sorted(os.listdir(os.path.join(folder, "shapes")))
    goal = 0.1 if shapes <= 1400 else 0.5  # s, the median query (the docstring's targets)
    times = []
    for qi in range(args.queries):
        q = os.path.join(qdir, "q%d.txt" % qi)
        src = os.path.join(folder, "shapes", files[qi * 997 % shapes])
        with open(src) as f, open(q, "w") as g:  # a new shape near a collection shape
            g.write("".join("%.3f %.3f\n" % (float(a) + rng.uniform(-0.3, 0.3), float(b) + rng.uniform(-0.3, 0.3))
                            for a, b in (line.split() for line in f)))
        t = time.time()
        r = subprocess.run([args.tool, "search", q, idx, "--top", "10"], capture_output=True, text=True)
        times.append(time.time() - t)
        if r.returncode != 0:
            sys.exit("amscr search failed: " + r.stderr.strip())
    med = statistics.median(times)
    print("query against %d shapes: median %.3f s, min %.3f s, max %.3f s (%d queries, wall clock) -> %s"
          " the %.1f s target" % (shapes, med, min(times), max(times), len(times),
                                  "meets" if med <= goal else "MISSES", goal))


def python_rss(args):
    """amscr.Index(collection) in Python: the process's RSS before and after the build, a shape,
    the saved file's bytes a shape and a load's RSS in a new process (the mpeg7-dev index of
    --rss-index, its shapes --rss-copies times)."""
    import gc
    import psutil
    import amscr
    proc = psutil.Process()
    src = amscr.Index.load(args.rss_index).collection
    coll = amscr.Collection(src.params)
    for _ in range(args.rss_copies):
        coll._add_copies(src, range(len(src)))
    del src
    gc.collect()
    n, r0 = len(coll), proc.memory_info().rss
    x = amscr.Index(coll, candidates=256, progress=False)
    r1 = proc.memory_info().rss
    path = os.path.join(args.work, "rss.idx")
    os.makedirs(args.work, exist_ok=True)
    x.save(path)
    code = ("import amscr, psutil, sys; p = psutil.Process(); r0 = p.memory_info().rss; "
            "x = amscr.Index.load(sys.argv[1]); print((p.memory_info().rss - r0) / len(x) / 1e3)")
    load = float(subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True, check=True).stdout)
    print("amscr.Index(collection) of %d shapes: RSS %.0f -> %.0f MB, %.1f KB a shape; file %.1f KB a shape; "
          "amscr.Index.load in a new process %.1f KB a shape"
          % (n, r0 / 1e6, r1 / 1e6, (r1 - r0) / n / 1e3, os.path.getsize(path) / n / 1e3, load))
    rng, ms = random.Random(3), {"a member": [], "an affine-warped member": []}
    for i in rng.sample(range(n), 60):  # Index.query, M = 256: the median CPU
        a, c, s = rng.uniform(0, 6.3), rng.uniform(0.7, 1.3), rng.uniform(-0.3, 0.3)
        shape = coll.shape(i)  # the member itself (scored as the member), and warped
        warped = shape.input_points @ [[c * math.cos(a), math.sin(a)], [s - math.sin(a), math.cos(a)]]
        for kind, q in (("a member", shape), ("an affine-warped member", warped)):
            t = time.process_time()
            x.query(q)
            ms[kind].append(1e3 * (time.process_time() - t))
    print("; ".join("a query of %s %.1f ms of CPU" % (k, statistics.median(v)) for k, v in ms.items()))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rss-index", help="an index file: measure amscr.Index(collection)'s memory instead")
    ap.add_argument("--rss-copies", type=int, default=4)
    ap.add_argument("--tool")
    ap.add_argument("--shapes", default="1400,10000", help="collection sizes, comma-separated")
    ap.add_argument("--work", default=os.path.join("build", "bench-index"))
    ap.add_argument("--build-candidates", default="8",
                    help="index --candidates (neighbours sought among each shape's M nearest signatures)")
    ap.add_argument("--queries", type=int, default=5)
    args = ap.parse_args()
    if args.rss_index:
        return python_rss(args)
    if not args.tool:
        ap.error("--tool is required")
    for shapes in (int(v) for v in str(args.shapes).split(",") if v.strip()):
        one_size(args, shapes)


if __name__ == "__main__":
    main()
