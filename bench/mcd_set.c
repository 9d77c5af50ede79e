/* mcd_set.c — labelled shape sets for the benchmark: a collection as listed, and the
 * MCD-style affine set built from one (see mcd_set.h). */
#include "mcd_set.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "affine_warp.h"
#include "collection.h"
#include "image.h"

/* Standard normal from affine_warp.h's xorshift64* generator. */
static double nrand(unsigned long long *s)
{
    double u = warp_urand(s), v = warp_urand(s);
    if (u < 1e-300)
        u = 1e-300;
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

/* A random affine copy of c (mcd_set.h), A = R(theta) diag(sx, sy) [[1 sh] [0 1]]; NULL on failure. */
static amscr_contour *affine_copy(const amscr_contour *c, unsigned long long *seed)
{
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    double th = 6.283185307179586 * warp_urand(seed);
    double sx = exp(log(0.5) + log(4.0) * warp_urand(seed)), sy = exp(log(0.5) + log(4.0) * warp_urand(seed));
    double sh = -0.5 + warp_urand(seed);
    double cs = cos(th), sn = sin(th);
    double a = cs * sx, b = cs * sx * sh - sn * sy, c2 = sn * sx, d = sn * sx * sh + cs * sy;
    double *out = malloc(2 * n * sizeof *out);
    if (!out)
        return NULL;
    double cx = 0, cy = 0, r = 0;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = a * xy[2 * i] + b * xy[2 * i + 1];
        out[2 * i + 1] = c2 * xy[2 * i] + d * xy[2 * i + 1];
        cx += out[2 * i];
        cy += out[2 * i + 1];
    }
    cx /= (double)n;
    cy /= (double)n;
    for (size_t i = 0; i < n; i++)
        r += (out[2 * i] - cx) * (out[2 * i] - cx) + (out[2 * i + 1] - cy) * (out[2 * i + 1] - cy);
    r = sqrt(r / (double)n);
    for (size_t i = 0; i < 2 * n; i++)
        out[i] += 0.005 * r * nrand(seed);
    amscr_contour *ct = NULL;
    if (amscr_contour_new(out, n, &ct) != AMSCR_OK)
        ct = NULL;
    free(out);
    return ct;
}

static int set_alloc(shape_set *s, size_t cap)
{
    s->n = 0;
    s->c = calloc(cap ? cap : 1, sizeof *s->c);
    s->labels = calloc(cap ? cap : 1, sizeof *s->labels);
    return s->c && s->labels ? 0 : -1;
}

int shape_set_load(const char *path, shape_set *s)
{
    collection col;
    if (collection_open(path, &col) != 0)
        return -1;
    int r = set_alloc(s, col.n);
    for (size_t i = 0; r == 0 && i < col.n; i++) {
        r = shape_load(col.items[i].path, 127, &s->c[i]);
        s->labels[i] = col.items[i].label;
        s->n += r == 0;
    }
    collection_free(&col);
    if (r != 0)
        shape_set_free(s);
    return r;
}

int shape_set_mcd(const char *path, unsigned long long seed, shape_set *s)
{
    collection col;
    if (collection_open(path, &col) != 0)
        return -1;
    int r = set_alloc(s, col.nclasses * MCD_COPIES);
    for (size_t k = 0; r == 0 && k < col.nclasses; k++) {
        size_t first = 0;
        while (col.items[first].label != (int32_t)k)
            first++;
        amscr_contour *ct = NULL;
        r = shape_load(col.items[first].path, 127, &ct);
        for (int j = 0; r == 0 && j < MCD_COPIES; j++) {
            s->c[s->n] = affine_copy(ct, &seed);
            s->labels[s->n] = (int32_t)k;
            r = s->c[s->n] ? 0 : -1;
            s->n += r == 0;
        }
        amscr_contour_free(ct);
    }
    collection_free(&col);
    if (r != 0) {
        fprintf(stderr, "%s: cannot build the MCD-style set\n", path);
        shape_set_free(s);
    }
    return r;
}

void shape_set_free(shape_set *s)
{
    for (size_t i = 0; s->c && i < s->n; i++)
        amscr_contour_free(s->c[i]);
    free(s->c);
    free(s->labels);
    s->c = NULL;
    s->labels = NULL;
    s->n = 0;
}
