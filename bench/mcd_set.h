/* mcd_set.h — the shape sets of the retrieval, index and signature benchmarks and the retrieval_mcd test:
 * a collection as listed, mpeg7-dev's class folds, and the MCD-style affine set: one contour of every class of a
 * labelled collection (its first listed shape) x MCD_COPIES random affine copies (any rotation, axis scales
 * x0.5-2 log-uniform, shear +-0.5, 0.5 % Gaussian noise of the RMS radius per coordinate), from a seeded
 * xorshift64* generator: the same set on every machine. The index benches (index_scale.c, signature_recall.c)
 * draw their collections and queries as such copies too (warp_affine, with the same generator). */
#ifndef AMSCR_BENCH_MCD_SET_H
#define AMSCR_BENCH_MCD_SET_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"

enum { MCD_COPIES = 14 };
#define MCD_SEED 0x9E3779B97F4A7C15ull

/* A labelled set of contours (owned). */
typedef struct {
    amscr_contour **c;
    int32_t *labels;
    size_t n;
} shape_set;

/* The shapes of a manifest or folder (decoded and traced at threshold 127), labels = classes.
 * 0, or -1 after printing the error. */
int shape_set_load(const char *path, shape_set *s);
/* The MCD-style set built from the collection at path with `seed`. 0, or -1. */
int shape_set_mcd(const char *path, unsigned long long seed, shape_set *s);
void shape_set_free(shape_set *s);

/* fold_of_class[k] (0 fold A, 1 fold B) for every class k of the manifest (in the manifest's
 * class order, k < cap), from folds.tsv beside it: 0, or -1 without it. */
int folds_tsv_read(const char *manifest, int32_t *fold_of_class, size_t cap);

/* Uniform in [0, 1) from the xorshift64* generator; advances *s. */
double warp_urand(unsigned long long *s);
/* A random affine copy of c drawn from *seed (advanced); NULL when out of memory or invalid. */
amscr_contour *warp_affine(const amscr_contour *c, unsigned long long *seed);

#endif
