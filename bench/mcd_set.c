/* mcd_set.c — labelled shape sets for the benchmarks: a collection as listed, its class folds, the MCD-style
 * affine set built from one, and the index benches' affine-warped copies (see mcd_set.h). */
#include "mcd_set.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "collection.h"
#include "image.h"

double warp_urand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

amscr_contour *warp_affine(const amscr_contour *c, unsigned long long *seed)
{
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    double th = 6.283185307179586 * warp_urand(seed);
    double sx = exp(log(0.5) + log(4.0) * warp_urand(seed)), sy = exp(log(0.5) + log(4.0) * warp_urand(seed));
    double sh = -0.5 + warp_urand(seed), cs = cos(th), sn = sin(th);
    double A[4] = {cs * sx, cs * sx * sh - sn * sy, sn * sx, sn * sx * sh + cs * sy};
    double *out = malloc(2 * n * sizeof *out), cx = 0, cy = 0, r = 0;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = A[0] * xy[2 * i] + A[1] * xy[2 * i + 1];
        out[2 * i + 1] = A[2] * xy[2 * i] + A[3] * xy[2 * i + 1];
        cx += out[2 * i] / (double)n;
        cy += out[2 * i + 1] / (double)n;
    }
    for (size_t i = 0; i < n; i++)
        r += ((out[2 * i] - cx) * (out[2 * i] - cx) + (out[2 * i + 1] - cy) * (out[2 * i + 1] - cy)) / (double)n;
    r = sqrt(r);
    for (size_t i = 0; i < 2 * n; i++) {
        double u = warp_urand(seed), w = warp_urand(seed);
        out[i] += 0.005 * r * sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * w);
    }
    amscr_contour *ct = NULL;
    if (amscr_contour_new(out, n, &ct) != AMSCR_OK)
        ct = NULL;
    free(out);
    return ct;
}

/* Standard normal from warp_urand's xorshift64* generator. */
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

/* Fold (0 A, 1 B) of every class of the manifest from folds.tsv beside it; -1 without it. */
int folds_tsv_read(const char *manifest, int32_t *fold_of_class, size_t cap)
{
    char path[4096], line[256];
    collection col;
    snprintf(path, sizeof path, "%.*s/folds.tsv", (int)(strrchr(manifest, '/') - manifest), manifest);
    FILE *f = fopen(path, "r");
    if (!f || collection_open(manifest, &col) != 0) {
        if (f)
            fclose(f);
        return -1;
    }
    for (size_t k = 0; k < cap; k++)
        fold_of_class[k] = 0;
    while (fgets(line, sizeof line, f)) {
        char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        *tab = '\0';
        for (size_t k = 0; k < col.nclasses && k < cap; k++)
            if (strcmp(col.classes[k], line) == 0)
                fold_of_class[k] = tab[1] == 'B';
    }
    fclose(f);
    collection_free(&col);
    return 0;
}
