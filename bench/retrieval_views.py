#!/usr/bin/env python3
"""Objects seen in several views, 1-NN leave one object out: the protocol of ETH-80 (each
object photographed from many viewpoints; a view is classified by its nearest shape among the
other objects), made from mpeg7-dev's silhouettes the way users make contours.

Each object (the first --objects silhouettes of a class) is seen in --views views: its image
downscaled to 200 px, warped by a random perspective map (any rotation, axis scales x0.78-1.28,
shear +-0.15, a tilt that shrinks one side by up to ~35 %) and a smooth non-rigid displacement
(a random field of ~2.5 % of the size, the outline bending as a 3-D object's does when the
viewpoint moves), rendered at 120 px across and traced by the library (amscr.contour_from_mask).
The draw is seeded: the same set on every machine for one seed.

Rows: the retrieval preset's fused channel before re-ranking, re-ranked on one graph (the
inner-distance share 0) and at each --shares value (the library's retrieval_matrix). Scores:
1-NN accuracy with the query's own object left out of the collection and its re-ranking graph
(Collection.retrieval_matrix_heldout, amscr.nn_groups).

Usage: .venv/bin/python bench/retrieval_views.py [--data ../shared/datasets] [--seeds 1,2,3]
       [--fold A|B] [--objects 4] [--views 10] [--shares 0.1]           # ~1.5 min a seed
       [--classes 8] [--k 16,41]    # ETH-80's shape: 8 classes drawn per seed, x 10 objects x 41 views
       [--join]                     # views traced as the tool's retrieval commands trace them
       [--options '{"channel_affine_view": 0}' ...]   # a column for each set of Params options
"""
import argparse
import json
import os
import sys
import time

import numpy as np

import amscr
import cv2


def classes(data, fold):
    d = os.path.join(data, 'mpeg7-dev')
    rows = [line.rstrip('\n').split('\t') for line in open(os.path.join(d, 'manifest.tsv'))][1:]
    folds = dict(line.rstrip('\n').split('\t') for line in list(open(os.path.join(d, 'folds.tsv')))[1:])
    by = {}
    for f, c in rows:
        if not fold or folds[c] == fold:
            by.setdefault(c, []).append(os.path.join(d, f))
    return by


def smooth_field(rng, shape, amp):
    f = cv2.GaussianBlur(rng.standard_normal((24, 24)).astype(np.float32), (0, 0), 2.0)
    f = cv2.resize(f, (shape[1], shape[0]), interpolation=cv2.INTER_CUBIC)
    return f * (amp / (f.std() + 1e-9))


def view(img, rng):
    f0 = 200.0 / max(img.shape)
    img = cv2.resize(img, None, fx=f0, fy=f0, interpolation=cv2.INTER_AREA)
    m = max(img.shape)
    img = cv2.copyMakeBorder(img, m // 2, m // 2, m // 2, m // 2, cv2.BORDER_CONSTANT, 0)
    h, w = img.shape
    c = np.array([w / 2, h / 2])
    th = rng.uniform(0, 2 * np.pi)
    s = np.exp(rng.uniform(-0.25, 0.25, 2))
    sh = rng.uniform(-0.15, 0.15)
    A = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]) @ np.array([[s[0], sh], [0, s[1]]])
    p = rng.uniform(-0.35, 0.35, 2) / m
    T = np.eye(3)
    T[:2, :2] = A
    T[:2, 2] = c - A @ c
    T[2, :2] = p
    T[2, 2] = 1 - p @ c
    img = cv2.warpPerspective(img, T, (w, h), flags=cv2.INTER_LINEAR)
    dx, dy = smooth_field(rng, img.shape, 0.025 * m), smooth_field(rng, img.shape, 0.025 * m)
    X, Y = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    img = cv2.remap(img, X + dx, Y + dy, cv2.INTER_LINEAR)
    ys, xs = np.nonzero(img > 127)
    img = img[ys.min():ys.max() + 1, xs.min():xs.max() + 1]
    f = 120.0 / max(img.shape)
    img = cv2.resize(img, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
    return cv2.copyMakeBorder(img, 4, 4, 4, 4, cv2.BORDER_CONSTANT, 0)


def draw(by, n, seed):
    """n of the classes drawn with the seed (all when n is 0)."""
    if not n:
        return by
    names = sorted(by)
    pick = np.random.default_rng(seed).choice(len(names), n, replace=False)
    return {names[i]: by[names[i]] for i in sorted(pick)}


def build(by, objects, views, seed, join=False):
    rng = np.random.default_rng(seed)
    shapes, cls, grp = [], [], []
    for ci, c in enumerate(sorted(by)):
        for oi, path in enumerate(by[c][:objects]):
            img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
            for _ in range(views):
                shapes.append(amscr.contour_from_mask(view(img, rng), threshold=127, join=join))
                cls.append(ci)
                grp.append(ci * 1000 + oi)
    return shapes, np.array(cls), np.array(grp)


def accuracy(shapes, cls, grp, **options):
    col = amscr.Collection(amscr.Params.retrieval(**options))
    col.extend(shapes, cls)
    return 100.0 * amscr.nn_groups(col.retrieval_matrix_heldout(grp), cls, grp).accuracy


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=os.path.join(os.path.dirname(__file__), '..', '..', 'shared', 'datasets'))
    ap.add_argument('--seeds', default='1,2,3')
    ap.add_argument('--fold', default='', choices=['', 'A', 'B'])
    ap.add_argument('--objects', type=int, default=4)
    ap.add_argument('--views', type=int, default=10)
    ap.add_argument('--shares', default='0.1')
    ap.add_argument('--classes', type=int, default=0, help="that many classes drawn with each seed (0: all)")
    ap.add_argument('--k', default='', help="re-ranking k values for more columns (the preset otherwise)")
    ap.add_argument('--join', action='store_true', help="trace as the tool's retrieval commands: broken pieces joined")
    ap.add_argument('--options', nargs='*', default=[], help='JSON objects of Params options, a column each')
    a = ap.parse_args(argv)
    shares = [float(x) for x in a.shares.split(',')]
    ks = [int(x) for x in a.k.split(',') if x]
    opts = [json.loads(o) for o in a.options]
    cols = ['before re-ranking', 'share 0'] + ['share %g' % s for s in shares] + ['k %d' % k for k in ks]
    cols += [json.dumps(o) for o in opts]
    print('objects in views, 1-NN leave one object out (%s classes, %d objects x %d views, amscr %s)'
          % (a.classes or len(classes(a.data, a.fold)), a.objects, a.views, amscr.__version__))
    print('| seed | ' + ' | '.join(cols) + ' | s |')
    print('|---' * (len(cols) + 2) + '|')
    sums = np.zeros(len(cols))
    seeds = [int(x) for x in a.seeds.split(',')]
    for seed in seeds:
        t = time.time()
        by = draw(classes(a.data, a.fold), a.classes, seed)
        shapes, cls, grp = build(by, a.objects, a.views, seed, a.join)
        row = [accuracy(shapes, cls, grp, rerank_k=0), accuracy(shapes, cls, grp, rerank_inner_share=0.0)]
        row += [accuracy(shapes, cls, grp, rerank_inner_share=s) for s in shares]
        row += [accuracy(shapes, cls, grp, rerank_k=k) for k in ks]
        row += [accuracy(shapes, cls, grp, **o) for o in opts]
        sums += row
        print('| %d | ' % seed + ' | '.join('%.2f' % v for v in row) + ' | %.0f |' % (time.time() - t), flush=True)
    print('| mean | ' + ' | '.join('%.2f' % v for v in sums / len(seeds)) + ' | |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
