#!/usr/bin/env python3
"""Holes as a retrieval cue: how many holes each class's silhouettes have, and how much of the
shape's area they take, so a channel of holes (an affine-invariant one: hole areas over the
outline's area) can be judged before it is built.

Each silhouette is traced with every contour (amscr.contours_from_mask, min_area 10 px^2, as
`amscr contour --all`); the largest outer contour is the shape, its holes are the contours whose
parent it is. Per class: the mean, least and most holes above 0.5 % of the shape's area, and the
mean, least and most share of the area that all its holes take. A cue for a class needs the
same holes in all of its shapes.

Usage: .venv/bin/python bench/retrieval_holes.py [--data ../shared/datasets] [--set mpeg7-dev]
"""
import argparse
import collections
import os

import numpy as np

import amscr
import cv2


def holes_of(path):
    """The hole areas of the largest outer contour of a silhouette, over its area, largest first."""
    img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise SystemExit('cannot read %s' % path)
    cs = amscr.contours_from_mask(img > 127, min_area=10)
    big = max((i for i, c in enumerate(cs) if not c.is_hole), key=lambda i: cs[i].area)
    return sorted((c.area / cs[big].area for c in cs if c.is_hole and c.parent == big), reverse=True)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--data', default=os.path.join(here, '..', '..', 'shared', 'datasets'))
    ap.add_argument('--set', default='mpeg7-dev')
    a = ap.parse_args()
    root = os.path.join(a.data, a.set)
    manifest = os.path.join(root, 'manifest.tsv')
    if not os.path.exists(manifest):
        raise SystemExit('no %s (the datasets are not here)' % manifest)
    rows = [line.rstrip('\n').split('\t') for line in open(manifest, encoding='utf-8')][1:]
    by_class = collections.defaultdict(list)
    for f, c in rows:
        by_class[c].append(holes_of(os.path.join(root, f)))
    print('| class | holes > 0.5 %: mean (least, most) | their area share: mean (least, most) |\n|---|---|---|')
    with_holes = 0
    for c, hs in sorted(by_class.items()):
        count = [sum(1 for h in x if h > 0.005) for x in hs]
        area = [sum(x) for x in hs]
        with_holes += max(count) > 0
        print('| %s | %.1f (%d, %d) | %.3f (%.3f, %.3f) |' % (c, np.mean(count), min(count), max(count),
                                                         np.mean(area), min(area), max(area)))
    print('\n%d of %d classes have a hole above 0.5 %% in some shape' % (with_holes, len(by_class)))


if __name__ == '__main__':
    main()
