/* affine_warp.h — the seeded affine-warped, noisy copy of a contour that the index benches
 * (index_scale.c, signature_recall.c) draw collections and queries from, and its xorshift64*
 * generator (mcd_set.c's too): any rotation, axis scales x0.5-2 log-uniform, shear +-0.5,
 * Gaussian noise 0.5 % of the RMS radius per coordinate: the same copies on every machine. */
#ifndef AMSCR_BENCH_AFFINE_WARP_H
#define AMSCR_BENCH_AFFINE_WARP_H

#include "amscr.h"

/* Uniform in [0, 1); advances *s. */
double warp_urand(unsigned long long *s);
/* A random affine copy of c drawn from *seed (advanced); NULL when out of memory or invalid. */
amscr_contour *warp_affine(const amscr_contour *c, unsigned long long *seed);

#endif
