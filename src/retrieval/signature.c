/* signature.c — the shortlist signature of an index (signature.h): amscr__affine_signature
 * stored as floats, frequency-major so its first blocks hold the coarse part, and the exact
 * search of the M nearest signatures with a lower bound.
 *
 * The distance (affine_signature.h) is, per frame, sqrt(min(same, mirror)) with
 * same = 1/2 sum |x0 - y0|^2 + |x1 - y1|^2 and mirror = 1/2 sum |x0 - y1|^2 + |x1 - y0|^2
 * (o = 0, 1 the two orientations). With s = (x0 + x1) / 2 and t = (y0 + y1) / 2,
 * |s - t|^2 <= 1/2 (|x0 - y0|^2 + |x1 - y1|^2) and likewise for the mirror pairing, so the
 * Euclidean distance of the s vectors over any subset of the dimensions is at most the
 * frame's distance: the lower-bound vector keeps s for the first AMSCR__SIG_LB_FREQS
 * frequencies (a quarter of the dimensions or less). A search computes the bounds of every
 * shape, the full distances of the 2 M smallest bounds, then of every other shape whose
 * bound does not exceed the M-th distance found: exactly the M nearest, at a fraction of
 * the cost. */
#include "signature.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { BINS = AMSCR__SIG_BINS, FREQS = AMSCR__SIG_FREQS, BLOCK = 4 * AMSCR__SIG_BINS };

/* Float rounding of the two sides: the bound is shrunk by this factor. */
#define BOUND_SAFETY (1.0 - 1e-4)

void amscr__shape_signature(const amscr_descriptor *d, float *out)
{
    double s[AMSCR__AFFINE_SIG_DIM];
    amscr__affine_signature(d, s);
    for (size_t f = 0; f < 2; f++)
        for (size_t o = 0; o < 2; o++)
            for (size_t b = 0; b < BINS; b++)
                for (size_t k = 0; k < FREQS; k++)
                    out[k * BLOCK + (f * 2 + o) * BINS + b] = (float)s[((f * 2 + o) * BINS + b) * FREQS + k];
}

void amscr__sig_bound_vector(const float *sig, float *lb)
{
    for (size_t k = 0; k < AMSCR__SIG_LB_FREQS; k++)
        for (size_t f = 0; f < 2; f++)
            for (size_t b = 0; b < BINS; b++) {
                const float *x = sig + k * BLOCK + f * 2 * BINS + b;
                lb[(f * AMSCR__SIG_LB_FREQS + k) * BINS + b] = 0.5f * (x[0] + x[BINS]);
            }
}

double amscr__sig_bound(const float *la, const float *lb)
{
    const size_t F = AMSCR__SIG_LB_FREQS * BINS;
    double sum = 0.0;
    for (size_t f = 0; f < 2; f++) {
        float s = 0.0f;
        for (size_t t = 0; t < F; t++) {
            float e = la[f * F + t] - lb[f * F + t];
            s += e * e;
        }
        sum += sqrt((double)s);
    }
    return sum * BOUND_SAFETY;
}

double amscr__sig_distance(const float *a, const float *b)
{
    double same[2] = {0.0, 0.0}, mirror[2] = {0.0, 0.0};
    for (size_t k = 0; k < FREQS; k++)
        for (size_t f = 0; f < 2; f++) {
            const float *x = a + k * BLOCK + f * 2 * BINS, *y = b + k * BLOCK + f * 2 * BINS;
            float s = 0.0f, m = 0.0f;
            for (size_t t = 0; t < BINS; t++) {
                float e = x[t] - y[t], e2 = x[BINS + t] - y[BINS + t];
                float g = x[t] - y[BINS + t], g2 = x[BINS + t] - y[t];
                s += e * e + e2 * e2;
                m += g * g + g2 * g2;
            }
            same[f] += s;
            mirror[f] += m;
        }
    double sum = 0.0;
    for (size_t f = 0; f < 2; f++)
        sum += sqrt(0.5 * (same[f] < mirror[f] ? same[f] : mirror[f]));
    return sum;
}

/* Ascending indices (insertion sort: m is small). */
static void sort_indices(size_t *c, size_t m)
{
    for (size_t i = 1; i < m; i++) {
        size_t v = c[i], t = i;
        for (; t > 0 && c[t - 1] > v; t--)
            c[t] = c[t - 1];
        c[t] = v;
    }
}

size_t amscr__sig_nearest(const float *sigs, const float *lbs, size_t n, const float *sig, const float *lb, size_t m,
                          size_t exclude, size_t *cand)
{
    size_t avail = exclude < n ? n - 1 : n, first = 2 * m < avail ? 2 * m : avail;
    double *bound = amscr__malloc_array(n, sizeof *bound), *full = amscr__malloc_array(n, sizeof *full);
    size_t *order = amscr__malloc_array(first ? first : 1, sizeof *order);
    int ok = bound && full && order && m <= avail;
    for (size_t j = 0; ok && j < n; j++) {
        bound[j] = j == exclude ? INFINITY : amscr__sig_bound(lbs + j * AMSCR__SIG_LB_DIM, lb);
        full[j] = INFINITY;
    }
    ok = ok && amscr_topk(bound, n, first, exclude, order) == AMSCR_OK;
    for (size_t t = 0; ok && t < first; t++)
        full[order[t]] = amscr__sig_distance(sigs + order[t] * AMSCR__SIG_DIM, sig);
    ok = ok && amscr_topk(full, n, m, exclude, cand) == AMSCR_OK;
    if (ok && m > 0) {
        double tau = full[cand[m - 1]];
        int more = 0;
        for (size_t j = 0; j < n; j++)
            if (j != exclude && isinf(full[j]) && bound[j] <= tau) {
                full[j] = amscr__sig_distance(sigs + j * AMSCR__SIG_DIM, sig);
                more = 1;
            }
        if (more)
            ok = amscr_topk(full, n, m, exclude, cand) == AMSCR_OK;
    }
    free(bound);
    free(full);
    free(order);
    if (!ok)
        return 0;
    sort_indices(cand, m);
    return m;
}
