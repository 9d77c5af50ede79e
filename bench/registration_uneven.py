#!/usr/bin/env python3
"""Registration of noisy contours sampled UNEVENLY along the curve (the order stage).

For each of the first 35 classes (one shape each) and 4 seeded draws: the traced pixel contour f, a
random affine map T (registration_heldout.py's), T(f) resampled to 0.6-1.4 times the point count,
DENSITY times denser on alternating quarter arcs, new start point, Gaussian noise NOISE x RMS radius.
Success: max_i |M(f_i) - T(f_i)| < 2 % of the RMS radius (registration_heldout.py's measure).

Usage: python3 bench/registration_uneven.py [--density 6] [--noise 0.02] [--data DIR]
(with AMSCR_LIBRARY=$PWD/build/libamscr.so.0 to measure the build tree's library).
"""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import registration_heldout as H  # noqa: E402


def uneven(xy, m, density, rng):
    """m points along the closed curve xy, `density` times denser on alternating quarter arcs."""
    Q = np.vstack([xy, xy[:1]])
    s = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(Q, axis=0).T))])
    u = np.linspace(0, 1, 4000, endpoint=False)
    dens = np.where(((u + rng.uniform(0, 1)) * 4).astype(int) % 2 == 0, density, 1.0)
    cdf = np.concatenate([[0], np.cumsum(dens)])
    cdf /= cdf[-1]
    t = np.interp(np.arange(m) / m, cdf, np.concatenate([u, [1.0]])) * s[-1]
    return np.column_stack([np.interp(t, s, Q[:, 0]), np.interp(t, s, Q[:, 1])])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--data', default=H.default_data())
    ap.add_argument('--density', type=float, default=6.0)
    ap.add_argument('--noise', type=float, default=0.02)
    ap.add_argument('--draws', type=int, default=4)
    ap.add_argument('--outliers', type=float, default=0.0,
                    help='share of the target points moved to random places in its bounding box')
    args = ap.parse_args()
    if not os.path.exists(os.path.join(args.data, 'manifest.tsv')):
        print('no manifest in %s: skipped' % args.data)
        return 0
    errs = []
    for si, (_, f) in enumerate(H.load_shapes(args.data, 35)):
        for d in range(args.draws):
            rng = np.random.default_rng([99, si, d])
            T = H.random_affine(rng)
            tgt = H.apply(T, f)
            size = H.shape_size(tgt)
            m = int(len(f) * rng.uniform(0.6, 1.4))
            tgt = np.roll(uneven(tgt, m, args.density, rng), rng.integers(m), axis=0)
            tgt = tgt + rng.normal(0, args.noise * size, tgt.shape)
            k = int(round(args.outliers * m))
            if k:
                lo, hi = tgt.min(axis=0), tgt.max(axis=0)
                tgt[rng.choice(m, k, replace=False)] = lo + (hi - lo) * rng.uniform(0, 1, (k, 2))
            errs.append(H.preset_error(f, tgt, T, size))
    print('density %.1f, noise %.1f %%, outliers %.1f %%: %s' % (args.density, 100 * args.noise, 100 * args.outliers,
                                                                H.error_summary(errs)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
