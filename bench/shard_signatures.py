#!/usr/bin/env python3
"""The signatures an index in shards keeps on its client (amscr.distributed): packed as the shards
hold them (C amscr_index_signatures_packed: 16-bit values and an exponent a shape) against floats
(amscr_index_signatures). Prints the bytes a shape of each, the time of every shape's M
signature-nearest (amscr_signature_shortlists_packed against amscr_signature_shortlists, one
thread, best of the runs) and whether the lists are the same (they must be); then a batch of member
queries' shortlists (a sharded query that is a member's copy): one search a member against one pass
for the batch (_member_shortlists), and whether they are the same.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python bench/shard_signatures.py [--shapes 3000] [--m 192] [--runs 3] [--members 200]
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from query_scale import shapes_of  # noqa: E402

import amscr  # noqa: E402
from amscr import _shard_tasks as tasks  # noqa: E402
from amscr._lib import ffi, lib  # noqa: E402


def float_lists(sigs, m):
    out = np.zeros((len(sigs), m), dtype=np.uintp)
    amscr.errors._check(lib.amscr_signature_shortlists(ffi.from_buffer('float[]', sigs), len(sigs),
                                                       ffi.from_buffer('float[]', sigs), len(sigs), 0, m, 1,
                                                       ffi.from_buffer('size_t[]', out), out.size))
    return out.astype(np.int64)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--shapes', type=int, default=3000)
    ap.add_argument('--m', type=int, default=192, help='the nearest a shape (a shortlist build: 192)')
    ap.add_argument('--runs', type=int, default=3)
    ap.add_argument('--members', type=int, default=200, help='member queries (every shapes/members-th shape)')
    a = ap.parse_args()
    coll = amscr.Collection(amscr.Params.retrieval(points=32, threads=0))
    coll.extend(*shapes_of(a.shapes))
    packed = tasks._signatures(amscr.Index(coll, candidates=256))
    floats = tasks._floats(packed, 0, a.shapes)
    tf = tp = float('inf')
    for _ in range(a.runs):
        t0 = time.perf_counter()
        lf = float_lists(floats, a.m)
        t1 = time.perf_counter()
        lp = tasks._shortlists(packed, floats, 0, a.m, 1)
        t2 = time.perf_counter()
        tf, tp = min(tf, t1 - t0), min(tp, t2 - t1)
    n = a.shapes
    print('shapes %d, %d nearest each: floats %d bytes a shape, %.2f s; packed %d bytes a shape, %.2f s '
          '(%.2fx); the same lists: %s' % (n, a.m, floats.nbytes // n, tf, (packed[0].nbytes + packed[1].nbytes) // n,
                                          tp, tp / tf, np.array_equal(lf, lp)))
    js = np.arange(0, n, max(1, n // a.members))[:a.members]
    t0 = time.perf_counter()
    each = np.array([tasks._shortlists(packed, floats[j:j + 1], j, a.m, 1)[0] for j in js])
    t1 = time.perf_counter()
    batch = tasks._member_shortlists(packed, js, a.m, 1)
    t2 = time.perf_counter()
    print('%d member queries, %d nearest each: one search a member %.2f s, one pass %.2f s (%.1fx); the same '
          'lists: %s' % (len(js), a.m, t1 - t0, t2 - t1, (t1 - t0) / (t2 - t1), np.array_equal(each, batch)))
    return 0 if np.array_equal(lf, lp) and np.array_equal(each, batch) else 1


if __name__ == '__main__':
    sys.exit(main())
