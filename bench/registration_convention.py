#!/usr/bin/env python3
"""Registration of noisy contours whose points were taken evenly along ANOTHER version of the curve.

The even-spacing stage reads a noisy curve's point index as arc length along the curve it is
registered to: true on the same polyline, not along a smoothed or 4-connected trace (the stage must
then stay out). For each of the first 35 classes and DRAWS seeded draws: the traced pixel contour
f, a random affine map T (registration_heldout.py's), the target resampled to 0.6-1.4 times the
point count along T(g), g = f ('plain'), f smoothed by a Gaussian of 2 points ('smooth') or f's
4-connected staircase ('four'), plus Gaussian noise.
Success: max_i |M(f_i) - T(f_i)| < 2 % of the RMS radius (registration_heldout.py's measure).

Usage: python3 bench/registration_convention.py [--curve plain|smooth|four] [--noise 0.02] [--draws 4]
(with AMSCR_LIBRARY=$PWD/build/libamscr.so.0 to measure the build tree's library).
"""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import registration_heldout as H  # noqa: E402


def smoothed(f, s=2.0):
    """The closed contour f smoothed by a Gaussian of s points."""
    k = np.arange(-int(3 * s), int(3 * s) + 1)
    w = np.exp(-0.5 * (k / s) ** 2)
    w /= w.sum()
    return sum(wj * np.roll(f, -kj, axis=0) for wj, kj in zip(w, k))


def four_connected(f):
    """f's 4-connected staircase: each diagonal step of the 8-connected chain split in two."""
    out = []
    for p, q in zip(f, np.roll(f, -1, axis=0)):
        out.append(p)
        if p[0] != q[0] and p[1] != q[1]:
            out.append([q[0], p[1]])
    return np.array(out)


def cases(data, curve, noise, draws):
    """(class, draw, source f, target, T, size) of each draw: the target taken evenly along T(g),
    g the `curve` version of f ('plain', 'smooth' or 'four'), plus Gaussian noise."""
    version = {'plain': lambda f: f, 'smooth': smoothed, 'four': four_connected}[curve]
    for si, (cls, f) in enumerate(H.load_shapes(data, 35)):
        for d in range(draws):
            rng = np.random.default_rng([77, si, d])
            T = H.random_affine(rng)
            g = version(f)
            nt = int(round(rng.uniform(0.6, 1.4) * len(f)))
            tgt = H.resample(H.apply(T, np.roll(g, -int(rng.integers(len(g))), axis=0)), nt)
            size = H.shape_size(H.apply(T, f))
            yield cls, d, f, tgt + rng.normal(0, noise * size, tgt.shape), T, size


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=H.default_data())
    ap.add_argument('--curve', choices=['plain', 'smooth', 'four'], default='smooth')
    ap.add_argument('--noise', type=float, default=0.02)
    ap.add_argument('--draws', type=int, default=4)
    args = ap.parse_args()
    if not os.path.exists(os.path.join(args.data, 'manifest.tsv')):
        print('no manifest in %s: skipped' % args.data)
        return 0
    errs = [H.preset_error(f, tgt, T, size) for _, _, f, tgt, T, size in cases(args.data, args.curve, args.noise, args.draws)]
    print('curve %s, noise %.1f %%: %s' % (args.curve, 100 * args.noise, H.error_summary(errs)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
