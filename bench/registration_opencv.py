#!/usr/bin/env python3
"""OpenCV contours of small binary images through amscr.register, as Python users pass them.

The pairs of bindings/python/tests/family_pairs.py: the 35 procedural shapes, the target at
binary 30 and 40 px across (--families' lowres30 / lowres40), draws 0-1 (140 pairs); the source
the 200-px image traced at sub-pixel. The target as cv2.findContours gives it with
CHAIN_APPROX_NONE, with CHAIN_APPROX_SIMPLE (both (n, 1, 2) int32, as returned) and with
CHAIN_APPROX_SIMPLE converted to floats first (a polygon through the kept points: what the
library sees when the OpenCV signature is lost). Prints right (RMS error < 4 % of R) and wrong +
confident (confidence >= 0.25) pairs a column, and how many SIMPLE maps equal the NONE ones bit
for bit. Needs OpenCV and scikit-image. Usage: OPENBLAS_NUM_THREADS=1 .venv/bin/python
bench/registration_opencv.py
"""
import os
import sys

import numpy as np

import cv2

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'bindings', 'python', 'tests'))
import family_pairs  # noqa: E402
import amscr  # noqa: E402


def main():
    B = family_pairs.bench()
    kinds = ('CHAIN_APPROX_NONE', 'CHAIN_APPROX_SIMPLE', 'CHAIN_APPROX_SIMPLE as floats')
    right, wc, same, n = dict.fromkeys(kinds, 0), dict.fromkeys(kinds, 0), 0, 0
    for i in range(35):
        for key, draw in family_pairs.LOW:
            src, f, tgt, T, thr = family_pairs.images(B, i, key, draw)
            none, simple = (family_pairs.opencv_contour(tgt, m) for m in (cv2.CHAIN_APPROX_NONE, cv2.CHAIN_APPROX_SIMPLE))
            s = amscr.contour_from_mask(src, join=True)
            maps = []
            for k, t in zip(kinds, (none, simple, simple[:, 0, :].astype(float))):
                r = amscr.register(s, t)
                maps.append(np.hstack([r.A, r.B[:, None]]))
                err = B.errors(maps[-1], T, f)[0]
                right[k] += err < thr
                wc[k] += err >= thr and r.confidence >= 0.25
            same += np.array_equal(maps[0], maps[1])
            n += 1
    print('%d pairs (procedural, binary 30 / 40 px, draws 0-1): right / wrong + confident' % n)
    for k in kinds:
        print('  %-32s %4d / %d' % (k, right[k], wc[k]))
    print('  SIMPLE maps equal to NONE ones, bit for bit: %d of %d' % (same, n))
    return 0


if __name__ == '__main__':
    sys.exit(main())
