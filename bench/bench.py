#!/usr/bin/env python3
"""Runs the speed benchmark, then single registrations per stage (amscr-registration-bench), then
(when the tool is built) the query time against synthetic
1400- and 10,000-shape indexes (bench/index_bench.py; each index is built once and cached in
--index-work), then (when ../shared/datasets exists) `amscr eval` on Kimia-99's and Kimia-216's
manifest.tsv (the order and classes the docs' figures use), printing the top-k tables beside the
paper's rows."""
import argparse
import json
import os
import subprocess
import sys

PAPER = {
    'kimia99': [99, 99, 99, 99, 99, 99, 98, 97, 98, 97],
    'kimia216': [216, 216, 216, 216, 215, 216, 215, 214, 212, 207, 207],
}

ap = argparse.ArgumentParser()
ap.add_argument('--bench', required=True)
ap.add_argument('--registration-bench')
ap.add_argument('--tool')
ap.add_argument('--datasets')
ap.add_argument('--shapes', default='1400')
ap.add_argument('--index-shapes', default='1400,10000', help='shapes of the synthetic indexes, comma-separated (0: skip)')
ap.add_argument('--index-work', default=os.path.join('build', 'bench-index'))
args, rest = ap.parse_known_args()

cmds = [[args.bench, '--shapes', args.shapes] + rest]
if args.registration_bench:
    cmds.append([args.registration_bench])
if args.tool and args.index_shapes != '0':
    cmds.append([sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'index_bench.py'),
                 '--tool', args.tool, '--shapes', args.index_shapes, '--work', args.index_work])
for cmd in cmds:
    sys.stdout.flush()
    rc = subprocess.call(cmd)
    if rc != 0:
        sys.exit(rc)
if not args.tool or not args.datasets or not os.path.isdir(args.datasets):
    print('(Kimia tables skipped: no tool or no ../shared/datasets)')
    sys.exit(0)
for name, paper in PAPER.items():
    manifest = os.path.join(args.datasets, name, 'manifest.tsv')
    if not os.path.isfile(manifest):
        continue
    ranks = len(paper)
    out = subprocess.run([args.tool, 'eval', manifest, '--protocol', 'topk', '--ranks', str(ranks), '--json'],
                         capture_output=True, text=True)
    if out.returncode != 0:
        print('%s: amscr eval failed: %s' % (name, out.stderr.strip()))
        continue
    res = json.loads(out.stdout)
    ours = res['topk']
    print('%s (n = %d, %.2f s)' % (name, res['n'], res['seconds']))
    print('  %-28s %s  sum' % ('', ' '.join('%4s' % ('T%d' % (r + 1)) for r in range(ranks))))
    print('  %-28s %s  %d' % ('amscr (defaults)', ' '.join('%4d' % v for v in ours), sum(ours)))
    print('  %-28s %s  %d' % ('paper, AMSCR multiclass-EM', ' '.join('%4d' % v for v in paper), sum(paper)))
