#!/usr/bin/env python3
"""Kimia-99 / Kimia-216 retrieval tables, measured with the `amscr eval` tool, beside the paper's
rows (docs/method.md §4). One command reproduces the tables of docs/measurements.md:

    python3 scripts/retrieval_table.py [--datasets ../shared/datasets] [--tool build/tools/amscr]

Table 1: the paper's four methods with the library's registration defaults (affine group, no
re-ranking). Table 2: invariance modes x contextual re-ranking of the AMSCR distance
alone (`--channel-weight 0`), which chose the 0.1 retrieval defaults; the 0.2 defaults (the
shape channel, fused and re-ranked) and their ablation come from `meson compile -C build
ablation` (bench/retrieval_ablation.c). Prints Markdown."""
import argparse
import json
import os
import subprocess
import sys

PAPER = {
    'kimia99': {
        'AMSCR': [99, 99, 99, 99, 99, 99, 98, 98, 97, 96],
        'AMSCR with Binary-EM': [99, 99, 99, 99, 99, 99, 96, 98, 98, 96],
        'AMSCR based on Multiclass-EM': [99, 99, 99, 99, 99, 99, 98, 97, 98, 97],
        'ACMA': [99, 99, 99, 99, 99, 99, 98, 98, 97, 95],
    },
    'kimia216': {
        'AMSCR': [216, 216, 216, 216, 215, 216, 213, 213, 212, 206, 204],
        'AMSCR with Binary-EM': [216, 216, 216, 216, 214, 216, 214, 213, 210, 207, 206],
        'AMSCR based on Multiclass-EM': [216, 216, 216, 216, 215, 216, 215, 214, 212, 207, 207],
        'ACMA': [216, 216, 216, 216, 215, 216, 214, 213, 212, 206, 206],
    },
}
RANKS = {'kimia99': 10, 'kimia216': 11}

METHODS = [('acma', 'ACMA'), ('amscr', 'AMSCR'), ('binary-em', 'AMSCR with Binary-EM'),
           ('multiclass-em', 'AMSCR based on Multiclass-EM')]
# label, flags (added to `amscr eval`)
MODES = [
    ('affine (paper), no re-ranking', ['--invariance', 'affine', '--no-rerank', '--refine', '0']),
    ('affine + re-ranking', ['--invariance', 'affine', '--rerank', '5,20', '--refine', '0']),
    ('similarity, no re-ranking', ['--invariance', 'similarity', '--no-rerank', '--refine', '0']),
    ('similarity + re-ranking', ['--invariance', 'similarity', '--rerank', '5,20', '--refine', '0']),
    ('penalized (lambda 0.5), no re-ranking', ['--invariance', 'penalized', '--no-rerank', '--refine', '0']),
    ('penalized (lambda 0.5) + re-ranking', ['--invariance', 'penalized', '--rerank', '5,20', '--refine', '0']),
    ('similarity + refine 1 + re-ranking', ['--invariance', 'similarity', '--refine', '1', '--rerank', '5,20']),
    ('similarity + refine 2 + re-ranking (0.1 retrieval default)',
     ['--invariance', 'similarity', '--refine', '2', '--rerank', '5,20']),
    ('similarity + refine 5 + re-ranking', ['--invariance', 'similarity', '--refine', '5', '--rerank', '5,20']),
    ('0.2 default: shape channel + re-ranking', ['--channel-weight', '1']),
]


# one factor at a time from the defaults (N 128, 8 scales 1..16, Kmax 5, whitened)
SWEEP = [
    ('defaults', []),
    ('N = 64', ['--points', '64']),
    ('N = 256', ['--points', '256']),
    ('scales 0,1,2,4,8', ['--scales', '0,1,2,4,8']),
    ('scales 1..32 (10)', ['--scales', '1,2,3,4,6,8,11,16,22,32']),
    ('Kmax 3', ['--kmax', '3']),
    ('Kmax 8', ['--kmax', '8']),
    ('affine arc length', ['--parametrization', 'affine']),
    ('Euclidean arc length', ['--parametrization', 'euclidean']),
]


def run(tool, folder, ranks, flags):
    # the AMSCR distance alone (these tables are about it), unless a row sets the weight
    weight = [] if '--channel-weight' in flags else ['--channel-weight', '0']
    cmd = [tool, 'eval', folder, '--protocol', 'all', '--ranks', str(ranks), '--json'] + weight + flags
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit('failed: %s\n%s' % (' '.join(cmd), out.stderr))
    return json.loads(out.stdout)


def row(label, counts, extra=''):
    return '| %s | %s | %d | %s |' % (label, ' '.join('%d' % c for c in counts), sum(counts), extra)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--datasets', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--tool', default=os.path.join(here, '..', 'build', 'tools', 'amscr'))
    ap.add_argument('--sweep', action='store_true', help='also the one-factor-at-a-time sweep (Table 3)')
    a = ap.parse_args()
    if not os.path.isdir(a.datasets):
        sys.exit('no datasets folder at %s' % a.datasets)
    for name in ('kimia99', 'kimia216'):
        folder = os.path.join(a.datasets, name)
        ranks = RANKS[name]
        best = ranks * (99 if name == 'kimia99' else 216)
        print('\n### %s: top-1..%d counts (query excluded; sum of %d possible)\n' % (name, ranks, best))
        print('Table 1: the paper\'s methods, registration defaults (affine group, whitened parametrization)\n')
        print('| method | top-1 .. top-%d | sum | bull\'s eye, 1-NN, seconds |' % ranks)
        print('|---|---|---|---|')
        for m, paper_name in METHODS:
            j = run(a.tool, folder, ranks, ['--method', m, '--invariance', 'affine', '--no-rerank', '--refine', '0'])
            print(row('amscr `%s`' % m, j['topk'], '%.2f %%, %.2f %%, %.1f s' % (100 * j['bullseye'],
                      100 * j['nn_accuracy'], j['seconds'])))
            print(row('paper: %s' % paper_name, PAPER[name][paper_name]))
        print('\nTable 2: invariance modes x contextual re-ranking (method multiclass-em)\n')
        print('| mode | top-1 .. top-%d | sum | bull\'s eye, 1-NN, seconds |' % ranks)
        print('|---|---|---|---|')
        for label, flags in MODES:
            j = run(a.tool, folder, ranks, flags)
            print(row(label, j['topk'], '%.2f %%, %.2f %%, %.1f s' % (100 * j['bullseye'], 100 * j['nn_accuracy'],
                                                                      j['seconds'])))
        print(row('paper: AMSCR based on Multiclass-EM', PAPER[name]['AMSCR based on Multiclass-EM']))
        if not a.sweep:
            continue
        print('\nTable 3: one factor at a time from the defaults: sum of the top-k counts, affine group '
              'without re-ranking | similarity + re-ranking (both without refinement)\n')
        print('| setting | affine, no re-ranking | similarity + re-ranking |')
        print('|---|---|---|')
        for label, flags in SWEEP:
            ja = run(a.tool, folder, ranks, flags + ['--invariance', 'affine', '--no-rerank', '--refine', '0'])
            js = run(a.tool, folder, ranks, flags + ['--invariance', 'similarity', '--rerank', '5,20', '--refine', '0'])
            print('| %s | %d | %d |' % (label, sum(ja['topk']), sum(js['topk'])))
    sys.stdout.flush()


if __name__ == '__main__':
    main()
