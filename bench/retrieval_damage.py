#!/usr/bin/env python3
"""Collections of damaged silhouettes, made the way damage reaches users' images: a copy of a
collection (manifest + images) where a share of each class's images is cut or bitten before it
is traced. For `amscr eval` (OUT mirrors the datasets folder: mpeg7-dev with its folds.tsv,
kimia99, kimia216).

Damage (one kind per damaged image, drawn with the seed):

  slots   1-3 cuts 0.03 sqrt(area) wide (at least 2 px) from a boundary point straight towards
          the centroid, 0.2-0.5 of the way (a crack, a scratch, a slotted part);
  bite    a disk of radius 0.15 sqrt(area) removed at a boundary point (a chip, an occluder
          in the background colour);
  specks  the boundary moved by a smooth field of 1.5 % of sqrt(area) (segmentation noise).

Usage: .venv/bin/python bench/retrieval_damage.py OUT [--data ../shared/datasets]
       [--share 0.5] [--seed 1] [--sets mpeg7-dev,kimia99,kimia216] [--kinds slots,bite,specks]
then   build/tools/amscr eval OUT/mpeg7-dev/manifest.tsv            # the library's default
"""
import argparse
import os
import shutil
import sys

import numpy as np

import cv2

KINDS = ('slots', 'bite', 'specks')


def outline(img):
    cs, _ = cv2.findContours((img > 127).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    return max(cs, key=cv2.contourArea)[:, 0, :].astype(float)


def slots(img, rng, R, g, c):
    out = img.copy()
    w = max(2, int(round(0.03 * R)))
    for _ in range(rng.integers(1, 4)):
        p = g[rng.integers(len(g))]
        q = p + rng.uniform(0.2, 0.5) * (c - p)
        u = (p - q) / max(np.linalg.norm(p - q), 1e-9)
        p = p + 2 * w * u  # start outside the outline so the cut opens it
        cv2.line(out, tuple(int(v) for v in np.round(p)), tuple(int(v) for v in np.round(q)), 0, w)
    return out


def bite(img, rng, R, g, c):
    p = g[rng.integers(len(g))]
    return cv2.circle(img.copy(), tuple(int(v) for v in np.round(p)), int(round(0.15 * R)), 0, -1)


def specks(img, rng, R, g, c):
    on = (img > 127).astype(np.uint8)
    sd = cv2.distanceTransform(on, cv2.DIST_L2, 5) - cv2.distanceTransform(1 - on, cv2.DIST_L2, 5)
    field = cv2.GaussianBlur(rng.normal(0, 1, img.shape), (0, 0), 0.1 * R)
    field *= 0.015 * R / max(field.std(), 1e-12)
    return np.where(sd + field > 0, 255, 0).astype(np.uint8)


def damaged(img, kind, rng):
    """img (0/255, shape on) with one kind of damage."""
    img = cv2.copyMakeBorder(img, 4, 4, 4, 4, cv2.BORDER_CONSTANT, 0)
    g = outline(img)
    R = np.sqrt(max(np.count_nonzero(img > 127), 1))
    return {'slots': slots, 'bite': bite, 'specks': specks}[kind](img, rng, R, g, g.mean(0))


def binary(path):
    img = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise SystemExit('cannot read %s' % path)
    on = img > 127
    if np.count_nonzero(on[0]) + np.count_nonzero(on[-1]) > img.shape[1]:  # the border is background
        on = ~on
    return np.where(on, 255, 0).astype(np.uint8)


def copy_set(src, dst, share, rng, kinds=KINDS):
    rows = [line.rstrip('\n').split('\t') for line in open(os.path.join(src, 'manifest.tsv'))][1:]
    os.makedirs(dst, exist_ok=True)
    by = {}
    for f, c in rows:
        by.setdefault(c, []).append(f)
    hit = set()
    for c, fs in by.items():
        hit.update(rng.choice(fs, int(round(share * len(fs))), replace=False))
    counts = dict.fromkeys(kinds, 0)
    with open(os.path.join(dst, 'manifest.tsv'), 'w') as m:
        m.write('file\tclass\n')
        for f, c in rows:
            name = os.path.splitext(os.path.basename(f))[0] + '.png'
            img = binary(os.path.join(src, f))
            if f in hit:
                kind = kinds[rng.integers(len(kinds))]
                counts[kind] += 1
                img = damaged(img, kind, rng)
            cv2.imwrite(os.path.join(dst, name), img)
            m.write('%s\t%s\n' % (name, c))
    if os.path.exists(os.path.join(src, 'folds.tsv')):
        shutil.copy(os.path.join(src, 'folds.tsv'), dst)
    return len(rows), counts


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('out')
    ap.add_argument('--data', default=os.path.join(os.path.dirname(__file__), '..', '..', 'shared', 'datasets'))
    ap.add_argument('--share', type=float, default=0.5)
    ap.add_argument('--seed', type=int, default=1)
    ap.add_argument('--sets', default='mpeg7-dev,kimia99,kimia216')
    ap.add_argument('--kinds', default=','.join(KINDS), help='the kinds of damage drawn from')
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)
    for s in a.sets.split(','):
        n, counts = copy_set(os.path.join(a.data, s), os.path.join(a.out, s), a.share, rng,
                             tuple(a.kinds.split(',')))
        print('%s: %d images, damaged %s' % (s, n, ', '.join('%s %d' % kv for kv in counts.items())))
    return 0


if __name__ == '__main__':
    sys.exit(main())
