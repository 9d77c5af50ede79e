#!/usr/bin/env python3
"""The affine-distorted views on many draws: MCD-style sets (one silhouette of each mpeg7-dev
class x 14 random affine copies: any rotation, axis scales log-uniform in 0.5-2, shear +-0.5)
built from the r-th silhouette of every class, r = 0 .. --draws - 1, so that one lucky choice of
shapes cannot decide (the ablation's MCD-style set is draw 0 of the points mode).

Modes: points (the traced contour's points mapped, 0.5 % noise of the RMS radius, as the
ablation's set) or image (the image, 200 px across, warped and traced again: the way users make
views). Bull's eye of each set with the retrieval preset and with each --options variant
(JSON objects of Params options); then the mean, the lowest draw and the draws below 99.5 %.

Usage: .venv/bin/python bench/retrieval_affine_draws.py [--data ../shared/datasets]
       [--mode points|image] [--draws 20] [--options '{"channel_affine_share": 0.3}' ...]
       # ~5 s a draw and variant
       .venv/bin/python bench/retrieval_affine_draws.py --collections [--options ...]
       # mpeg7-dev, its folds, Kimia-99 / -216 with each variant (~1 min a variant)
"""
import argparse
import json
import os
import sys

import numpy as np

import amscr
import cv2


def classes(data):
    d = os.path.join(data, 'mpeg7-dev')
    by = {}
    for line in list(open(os.path.join(d, 'manifest.tsv')))[1:]:
        f, c = line.rstrip('\n').split('\t')
        by.setdefault(c, []).append(os.path.join(d, f))
    return by


def affine_map(rng):
    th = rng.uniform(0, 2 * np.pi)
    sx, sy = np.exp(np.log(0.5) + np.log(4.0) * rng.uniform(size=2))
    sh = rng.uniform(-0.5, 0.5)
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    return R @ np.array([[sx, sx * sh], [0, sy]])


def warped(img, A):
    f0 = 200.0 / max(img.shape)
    small = cv2.resize(img, None, fx=f0, fy=f0, interpolation=cv2.INTER_AREA)
    h, w = small.shape
    corners = np.array([[0, 0], [w, 0], [0, h], [w, h]], float) @ A.T
    lo, hi = corners.min(0), corners.max(0)
    M = np.hstack([A, (4 - lo)[:, None]])
    size = (int(np.ceil(hi[0] - lo[0])) + 8, int(np.ceil(hi[1] - lo[1])) + 8)
    return cv2.warpAffine(small, M, size, flags=cv2.INTER_LINEAR)


def build(by, r, mode, seed=1, join=False):
    rng = np.random.default_rng(seed * 1000 + r)
    shapes, labels = [], []
    for k, c in enumerate(sorted(by)):
        img = cv2.imread(by[c][r % len(by[c])], cv2.IMREAD_GRAYSCALE)
        pts = amscr.contour_from_mask(img > 127)
        for _ in range(14):
            A = affine_map(rng)
            if mode == 'points':
                q = pts @ A.T
                rms = np.sqrt(((q - q.mean(0)) ** 2).sum(1).mean())
                shapes.append(q + 0.005 * rms * rng.standard_normal(q.shape))
            else:
                shapes.append(amscr.contour_from_mask(warped(img, A) > 127, join=join))
            labels.append(k)
    return shapes, np.array(labels)


def bullseye(shapes, labels, options):
    col = amscr.Collection(amscr.Params.retrieval(**options))
    col.extend(shapes, labels)
    return 100.0 * amscr.bullseye(col.retrieval_matrix(), labels)


def collections(data, variants, names):
    """mpeg7-dev, its class folds (folds.tsv) and Kimia-99 / -216 (top-10 / top-11 sums) with
    each variant: what a setting that helps the views costs elsewhere."""
    folds = dict(line.split() for line in list(open(os.path.join(data, 'mpeg7-dev', 'folds.tsv')))[1:])
    sets = {}
    for name in ('mpeg7-dev', 'kimia99', 'kimia216'):
        d = os.path.join(data, name)
        rows = [line.rstrip('\n').split('\t') for line in list(open(os.path.join(d, 'manifest.tsv')))[1:]]
        pts = [amscr.contour_from_mask(cv2.imread(os.path.join(d, f), cv2.IMREAD_GRAYSCALE)) for f, _ in rows]
        sets[name] = (pts, [c for _, c in rows])
    print('| variant | mpeg7-dev | fold A | fold B | Kimia-99 | Kimia-216 |\n|---|---|---|---|---|---|')
    for name, v in zip(names, variants):
        out = []
        pts, lab = sets['mpeg7-dev']
        for keep in (None, 'A', 'B'):
            idx = [i for i, c in enumerate(lab) if keep is None or folds[c] == keep]
            out.append('%.2f' % bullseye([pts[i] for i in idx], np.unique([lab[i] for i in idx], return_inverse=True)[1], v))
        for kimia, ranks in (('kimia99', 10), ('kimia216', 11)):
            pts, lab = sets[kimia]
            code = np.unique(lab, return_inverse=True)[1]
            col = amscr.Collection(amscr.Params.retrieval(**v))
            col.extend(pts, code)
            out.append('%d' % np.sum(amscr.topk_table(col.retrieval_matrix(), code, ranks)))
        print('| %s | ' % name + ' | '.join(out) + ' |', flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=os.path.join(os.path.dirname(__file__), '..', '..', 'shared', 'datasets'))
    ap.add_argument('--mode', default='points', choices=['points', 'image'])
    ap.add_argument('--draws', type=int, default=20)
    ap.add_argument('--options', nargs='*', default=[])
    ap.add_argument('--collections', action='store_true', help="score the collections instead of the views")
    ap.add_argument('--join', action='store_true', help="images traced with broken pieces joined (as the tool)")
    a = ap.parse_args(argv)
    by = classes(a.data)
    variants = [{}] + [json.loads(o) for o in a.options]
    names = ['preset'] + [o for o in a.options]
    if a.collections:
        collections(a.data, variants, names)
        return 0
    print('affine views on %d draws (%s), bull\'s eye %%, amscr %s' % (a.draws, a.mode, amscr.__version__))
    print('| draw | ' + ' | '.join(names) + ' |\n' + '|---' * (len(names) + 1) + '|')
    rows = []
    for r in range(a.draws):
        shapes, labels = build(by, r, a.mode, join=a.join)
        rows.append([bullseye(shapes, labels, v) for v in variants])
        print('| %d | ' % r + ' | '.join('%.2f' % v for v in rows[-1]) + ' |', flush=True)
    m = np.array(rows)
    print('| mean | ' + ' | '.join('%.2f' % v for v in m.mean(0)) + ' |')
    print('| lowest | ' + ' | '.join('%.2f' % v for v in m.min(0)) + ' |')
    print('| draws < 99.5 | ' + ' | '.join('%d' % v for v in (m < 99.5).sum(0)) + ' |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
