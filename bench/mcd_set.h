/* mcd_set.h — the MCD-style affine set of the retrieval, index and signature benchmarks
 * and the retrieval_mcd test: one contour of every class of a labelled collection (its first listed
 * shape) x MCD_COPIES random affine copies (any rotation, axis scales x0.5-2 log-uniform,
 * shear +-0.5, 0.5 % Gaussian noise of the RMS radius per coordinate), from a seeded
 * xorshift64* generator: the same set on every machine. */
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

#endif
