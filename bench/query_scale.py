#!/usr/bin/env python3
"""One query's cost against a collection in memory, by size: `Collection.query` with the
retrieval preset (C amscr_db_query_retrieval: the collection keeps an exact index, built by its
first query) against `Index.scores(candidates=0)` on an index built once. Synthetic collections
(index_bench.py's: 100 classes of smooth closed curves, each shape under a random similarity).
Prints, per size: the first query (it builds the kept index), the median and p90 of the next
queries, the index's build and its queries, their ratio (target: at most 2), and the largest
difference of the two scores (the same scores: ~1e-12).

    .venv/bin/python bench/query_scale.py [--shapes 700,10000] [--queries 20]
"""
import argparse
import os
import random
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from index_bench import curve  # noqa: E402

import amscr  # noqa: E402


def shapes_of(n, classes=100, seed=15):
    rng = random.Random(seed)
    protos = [[(rng.uniform(0.02, 0.18) / (k + 1) ** 0.5, rng.uniform(0, 2 * 3.141592653589793)) for k in range(6)]
              for _ in range(classes)]
    return [np.array(curve(protos[i % classes], rng, 0.15)) for i in range(n)], [i % classes for i in range(n)]


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


def one_size(n, queries):
    shapes, labels = shapes_of(n + queries)
    coll = amscr.Collection(amscr.Params.retrieval())
    _, t_prep = timed(lambda: coll.extend(shapes[:n], labels[:n]))
    qs = shapes[n:]
    first, t_first = timed(lambda: coll.query(qs[0]))
    times, rows = [], []
    for q in qs[1:]:
        r, t = timed(lambda: coll.query(q))
        rows.append(r)
        times.append(t)
    index, t_build = timed(lambda: amscr.Index(coll, progress=False, candidates=0))
    itimes, diff = [], 0.0
    for q, r in zip(qs[1:], rows):
        s, t = timed(lambda: index.scores(q, candidates=0))
        itimes.append(t)
        diff = max(diff, float(np.max(np.abs(s - r))))
    med, imed = statistics.median(times), statistics.median(itimes)
    p90 = sorted(times)[int(0.9 * (len(times) - 1))]
    print('%6d shapes: prepare %.1f s; Collection.query: first %.2f s (builds the kept index), then median %.1f ms,'
          ' p90 %.1f ms | Index(candidates=0): build %.2f s, scores median %.1f ms | ratio %.2f (target <= 2) |'
          ' largest score difference %.1e' % (n, t_prep, t_first, 1e3 * med, 1e3 * p90, t_build, 1e3 * imed,
                                               med / imed, diff))
    return med / imed <= 2.0 and diff <= 1e-9


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--shapes', default='700,10000', help='collection sizes, comma-separated')
    ap.add_argument('--queries', type=int, default=20)
    args = ap.parse_args()
    ok = [one_size(int(v), args.queries) for v in args.shapes.split(',') if v.strip()]
    sys.exit(0 if all(ok) else 1)


if __name__ == '__main__':
    main()
