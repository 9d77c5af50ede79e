#!/usr/bin/env python3
"""Probe: the silhouette closed at a scale as a cue of the re-ranking (docs/results-retrieval.md,
"The closed silhouette (0.9)").

Each silhouette is closed morphologically (OpenCV) by a disk of radius c sqrt(area), c in
--radii, before its contour is traced: cuts and slots narrower than the disk leave the outline.
Two uses are compared with the default's two graphs (the tool's channel matrix, `amscr matrix
--no-rerank --inner-share 0`, and the inner distance of retrieval_probes.py on the traced
contours, share 0.05):

  closed channel   a third kNN graph: the tool's channel matrix of the closed silhouettes;
  closed inner     the second graph's inner distance taken on the closed silhouettes' contours.

Re-ranking as retrieval_probes.py's NumPy copy of the library's (k 8, 10 iterations), the graphs
mixed by their shares. Sets: mpeg7-dev (bull's eye), its class folds A and B as own collections,
Kimia-99 / Kimia-216 (top-k sums); then, for the best rows, the classes whose bull's eye moved.

Usage: .venv/bin/python bench/retrieval_closing.py [--data ../shared/datasets] [--tool build/tools/amscr]
       [--radii 0.04,0.08]                                             # ~6 min on 2 cores
"""
import argparse
import os
import subprocess
import sys
import tempfile

import cv2
import numpy as np

import amscr
import retrieval_probes as rp

SETS = ('mpeg7-dev', 'kimia99', 'kimia216')
COLS = ('mpeg7-dev', 'fold A', 'fold B', 'kimia99', 'kimia216')


def closed(img, c):
    m = (img > 127).astype(np.uint8) * 255
    r = max(1, int(round(c * np.sqrt((m > 0).sum()))))
    m = cv2.copyMakeBorder(m, r + 2, r + 2, r + 2, r + 2, cv2.BORDER_CONSTANT, 0)
    return cv2.morphologyEx(m, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1,) * 2))


def channel(tool, manifest, tmp, tag):
    npy, tsv = os.path.join(tmp, tag + '.npy'), os.path.join(tmp, tag + '.tsv')
    subprocess.run([tool, 'matrix', manifest, '--no-rerank', '--inner-share', '0', '-o', npy, '--names', tsv],
                   check=True, capture_output=True)
    return np.load(npy), rp.names(tsv)


def load(a, radii, tmp):
    sets = {}
    for name in SETS:
        ch, (files, labels) = channel(a.tool, os.path.join(a.data, name, 'manifest.tsv'), tmp, name)
        imgs = [cv2.imread(os.path.join(a.data, name, f), cv2.IMREAD_GRAYSCALE) for f in files]
        s = dict(ch=ch, labels=labels, kind='bullseye' if name == 'mpeg7-dev' else 'topk',
                 inner=rp.inner_matrix([rp.inner_feature(amscr.contour_from_mask(im)) for im in imgs]))
        for c in radii:
            d = os.path.join(tmp, '%s-%g' % (name, c))
            os.makedirs(d)
            with open(os.path.join(d, 'manifest.tsv'), 'w') as mf:
                mf.write('file\tclass\n')
                for f, lab, im in zip(files, labels, imgs):
                    cv2.imwrite(os.path.join(d, f), closed(im, c))
                    mf.write('%s\t%s\n' % (f, lab))
            s['channel %g' % c] = channel(a.tool, os.path.join(d, 'manifest.tsv'), tmp, '%s-%g' % (name, c))[0]
            cs = [amscr.contour_from_mask(cv2.imread(os.path.join(d, f), cv2.IMREAD_GRAYSCALE)) for f in files]
            s['inner %g' % c] = rp.inner_matrix([rp.inner_feature(P) for P in cs])
        sets[name] = s
        print('loaded %s' % name, file=sys.stderr, flush=True)
    return sets


def rerank(Ds, shares, k=8, iters=10):
    P = sum(w * rp.knn_graph(X, k) for X, w in zip(Ds, shares))
    Q = P.copy()
    for _ in range(iters):
        Q = P @ Q @ P.T + np.eye(len(P))
    return np.where(Q > 0, 1 - Q / Q.max(1, keepdims=True), 1 + Ds[0] / Ds[0].max())


def subset(sets, folds, col):
    s = sets['mpeg7-dev' if col.startswith('fold') else col]
    idx = np.arange(len(s['labels']))
    if col.startswith('fold'):
        idx = np.array([i for i, lab in enumerate(s['labels']) if folds[lab] == col[-1]])
    return s, idx


def per_class(F, labels):
    labels = np.asarray(labels)
    hits = []
    for q in range(len(labels)):
        same = labels == labels[q]
        hits.append(same[np.argsort(F[q], kind='stable')[:2 * same.sum()]].sum() / same.sum())
    hits = np.array(hits)
    return {c: 100 * hits[labels == c].mean() for c in np.unique(labels)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--tool', default=os.path.join(here, '..', 'build', 'tools', 'amscr'))
    ap.add_argument('--radii', default='0.04,0.08')
    a = ap.parse_args()
    if not os.path.isdir(os.path.join(a.data, 'mpeg7-dev')):
        print('retrieval_closing: no data at %s (skipped)' % a.data)
        return 0
    radii = [float(x) for x in a.radii.split(',')]
    with tempfile.TemporaryDirectory() as tmp:
        sets = load(a, radii, tmp)
    folds = dict(line.rstrip('\n').split('\t') for line in list(open(os.path.join(a.data, 'mpeg7-dev', 'folds.tsv')))[1:])
    rows = [('default: channel + inner 0.05', [('ch', 0.95), ('inner', 0.05)])]
    for c in radii:
        rows += [('closed channel %g, third graph %g' % (c, w), [('ch', 0.95 - w), ('inner', 0.05), ('channel %g' % c, w)])
                 for w in (0.05, 0.1)]
        rows += [('inner on the closed silhouette %g, share %g' % (c, w), [('ch', 1 - w), ('inner %g' % c, w)])
                 for w in (0.05, 0.1)]
    print('| setting | ' + ' | '.join(COLS) + ' |\n|---|' + '---|' * len(COLS))
    for title, spec in rows:
        out = []
        for col in COLS:
            s, idx = subset(sets, folds, col)
            F = rerank([s[key][np.ix_(idx, idx)] for key, _ in spec], [w for _, w in spec])
            out.append(rp.score(s['kind'], F, [s['labels'][i] for i in idx]))
        print('| %s | ' % title + ' | '.join('%.2f' % v for v in out) + ' |', flush=True)
    s = sets['mpeg7-dev']
    base = per_class(rerank([s['ch'], s['inner']], [0.95, 0.05]), s['labels'])
    for title, spec in rows[1:]:
        if not title.endswith(' 0.05') or '%g' % radii[-1] not in title:
            continue
        pc = per_class(rerank([s[key] for key, _ in spec], [w for _, w in spec]), s['labels'])
        moved = sorted((c for c in pc if abs(pc[c] - base[c]) >= 0.5), key=lambda c: pc[c] - base[c])
        print('%s, mpeg7-dev classes that moved: ' % title
              + ', '.join('%s %.1f -> %.1f' % (c, base[c], pc[c]) for c in moved))
    return 0


if __name__ == '__main__':
    sys.exit(main())
