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
 * frequencies (half the frequencies: a quarter of the signature's floats). A search computes
 * the bounds of every shape, the full distances of the 5/4 M smallest bounds, then of every
 * other shape whose bound does not exceed the M-th distance found, each given up once a
 * partial sum (a lower bound too: the sums only grow) exceeds it: exactly the M nearest, at a
 * fraction of the cost. The sums run in one float a bin (the loops vectorize). */
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
    enum { F = AMSCR__SIG_LB_FREQS * BINS };
    double sum = 0.0;
    for (size_t f = 0; f < 2; f++) {
        float acc[BINS] = {0.0f}; /* one sum a lane: the loop vectorizes */
        for (size_t u = 0; u < F; u += BINS)
            for (size_t t = 0; t < BINS; t++) {
                float e = la[f * F + u + t] - lb[f * F + u + t];
                acc[t] += e * e;
            }
        float s = 0.0f;
        for (size_t t = 0; t < BINS; t++)
            s += acc[t];
        sum += sqrt((double)s);
    }
    return sum * BOUND_SAFETY;
}

void amscr__sig_quantize(const float *sig, uint16_t *q, int32_t *e)
{
    float top = 0.0f;
    for (size_t t = 0; t < AMSCR__SIG_DIM; t++)
        top = sig[t] > top ? sig[t] : top;
    int k = 0;
    frexpf(top, &k); /* top = m 2^k, 0.5 <= m < 1: top / 2^(k - 16) below 65536 */
    *e = top > 0.0f ? (k - 16 < -126 ? -126 : k - 16) : 0;
    float inv = ldexpf(1.0f, -*e);
    for (size_t t = 0; t < AMSCR__SIG_DIM; t++) {
        float v = sig[t] > 0.0f ? sig[t] * inv + 0.5f : 0.0f; /* exact product: a power of two */
        q[t] = (uint16_t)(v >= 65535.0f ? 65535.0f : v);
    }
}

/* n values of q at the scale 2^e into out. */
static void dequantize_n(const uint16_t *q, int32_t e, size_t n, float *out)
{
    float s = ldexpf(1.0f, e);
    for (size_t t = 0; t < n; t++)
        out[t] = (float)q[t] * s;
}

void amscr__sig_dequantize(const uint16_t *q, int32_t e, float *out) { dequantize_n(q, e, AMSCR__SIG_DIM, out); }

/* Frequencies k0..k1-1 of the distance's sums into same / mirror, a's from frequency k0 on (one
 * sum a bin: the loop vectorizes). */
static void sig_sums(const float *a, const float *b, size_t k0, size_t k1, float same[2][BINS], float mirror[2][BINS])
{
    for (size_t k = k0; k < k1; k++)
        for (size_t f = 0; f < 2; f++) {
            const float *x = a + (k - k0) * BLOCK + f * 2 * BINS, *y = b + k * BLOCK + f * 2 * BINS;
            for (size_t t = 0; t < BINS; t++) {
                float e = x[t] - y[t], e2 = x[BINS + t] - y[BINS + t];
                float g = x[t] - y[BINS + t], g2 = x[BINS + t] - y[t];
                same[f][t] += e * e + e2 * e2;
                mirror[f][t] += g * g + g2 * g2;
            }
        }
}

/* The distance from the sums so far (a lower bound of the full one until every frequency is in). */
static double sig_value(float same[2][BINS], float mirror[2][BINS])
{
    double sum = 0.0;
    for (size_t f = 0; f < 2; f++) {
        double s = 0.0, m = 0.0;
        for (size_t t = 0; t < BINS; t++) {
            s += same[f][t];
            m += mirror[f][t];
        }
        sum += sqrt(0.5 * (s < m ? s : m));
    }
    return sum;
}

/* Frequencies a partial sum covers before the search checks it against its threshold. */
enum { EARLY_STEP = 4 };

/* Frequencies k0..k1-1 of row i of R (k1 - k0 <= EARLY_STEP): in R's floats, or dequantized into
 * buf. */
static const float *row_block(const amscr__sig_rows *R, size_t i, size_t k0, size_t k1, float *buf)
{
    if (R->f)
        return R->f + i * AMSCR__SIG_DIM + k0 * BLOCK;
    dequantize_n(R->q + i * AMSCR__SIG_DIM + k0 * BLOCK, R->e[i], (k1 - k0) * BLOCK, buf);
    return buf;
}

/* The distance of row i of R and b, or (once a partial sum exceeds tau) that partial sum: a
 * value > tau whenever the distance is (tau infinite: the distance). */
static double sig_distance_within(const amscr__sig_rows *R, size_t i, const float *b, double tau)
{
    float same[2][BINS] = {{0.0f}}, mirror[2][BINS] = {{0.0f}}, buf[EARLY_STEP * BLOCK];
    for (size_t k = 0; k < FREQS; k += EARLY_STEP) {
        size_t k1 = k + EARLY_STEP < FREQS ? k + EARLY_STEP : FREQS;
        sig_sums(row_block(R, i, k, k1, buf), b, k, k1, same, mirror);
        double v = sig_value(same, mirror);
        if (v > tau || k + EARLY_STEP >= FREQS)
            return v;
    }
    return sig_value(same, mirror);
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

/* The exact search among ids[0..nids-1] (ascending; NULL: the n shapes 0..n-1). */

static size_t nearest_among(const amscr__sig_rows *sigs, const float *lbs, const size_t *ids, size_t nids,
                            const float *sig, const float *lb, size_t m, size_t exclude, size_t *cand)
{
    size_t ex = SIZE_MAX;
    for (size_t t = 0; t < nids && exclude != SIZE_MAX; t++)
        if ((ids ? ids[t] : t) == exclude)
            ex = t;
    size_t avail = ex < nids ? nids - 1 : nids, first = m + m / 4 < avail ? m + m / 4 : avail;
    double *bound = amscr__malloc_array(nids, sizeof *bound), *full = amscr__malloc_array(nids, sizeof *full);
    size_t *order = amscr__malloc_array(first ? first : 1, sizeof *order);
    int ok = bound && full && order && m <= avail;
    for (size_t t = 0; ok && t < nids; t++) {
        bound[t] = t == ex ? INFINITY : amscr__sig_bound(lbs + (ids ? ids[t] : t) * AMSCR__SIG_LB_DIM, lb);
        full[t] = INFINITY;
    }
    ok = ok && amscr_topk(bound, nids, first, ex, order) == AMSCR_OK;
    for (size_t t = 0; ok && t < first; t++)
        full[order[t]] = sig_distance_within(sigs, ids ? ids[order[t]] : order[t], sig, INFINITY);
    ok = ok && amscr_topk(full, nids, m, ex, cand) == AMSCR_OK;
    if (ok && m > 0) {
        double tau = full[cand[m - 1]];
        int more = 0;
        for (size_t t = 0; t < nids; t++)
            if (t != ex && isinf(full[t]) && bound[t] <= tau) {
                full[t] = sig_distance_within(sigs, ids ? ids[t] : t, sig, tau);
                more = 1;
            }
        if (more)
            ok = amscr_topk(full, nids, m, ex, cand) == AMSCR_OK;
    }
    for (size_t t = 0; ok && ids && t < m; t++)
        cand[t] = ids[cand[t]];
    free(bound);
    free(full);
    free(order);
    if (!ok)
        return 0;
    sort_indices(cand, m);
    return m;
}

size_t amscr__sig_nearest(const amscr__sig_rows *sigs, const float *lbs, size_t n, const float *sig, const float *lb,
                          size_t m, size_t exclude, size_t *cand)
{
    return nearest_among(sigs, lbs, NULL, n, sig, lb, m, exclude, cand);
}

/* ------------------------------------------------ the coarse quantizer of a large build */

enum { IVF_ITERS = 6, IVF_TRAIN_PER_LIST = 48 };
/* A search probes the lists nearest its bound vector: at least this many, and until they hold
 * at least IVF_PROBE_PER_M m + 1 shapes (a build's rows and, from AMSCR__INDEX_IVF_MIN shapes,
 * an index query: docs/decisions.md). */
#define IVF_PROBE_LISTS 8
#define IVF_PROBE_PER_M 16

static float sq_dist(const float *a, const float *b)
{
    float acc[BINS] = {0.0f}, s = 0.0f; /* one sum a lane: the loop vectorizes */
    for (size_t u = 0; u < AMSCR__SIG_LB_DIM; u += BINS)
        for (size_t t = 0; t < BINS; t++) {
            float e = a[u + t] - b[u + t];
            acc[t] += e * e;
        }
    for (size_t t = 0; t < BINS; t++)
        s += acc[t];
    return s;
}

static size_t nearest_centroid(const amscr__sig_ivf *v, const float *x)
{
    size_t best = 0;
    float bd = INFINITY;
    for (size_t c = 0; c < v->nc; c++) {
        float d = sq_dist(v->cent + c * AMSCR__SIG_LB_DIM, x);
        if (d < bd) {
            bd = d;
            best = c;
        }
    }
    return best;
}

/* Lloyd iterations on the shapes t * n / ntrain (evenly spread), from nc of them. */
static int ivf_train(amscr__sig_ivf *v, const float *lbs, size_t n)
{
    size_t ntrain = v->nc * IVF_TRAIN_PER_LIST < n ? v->nc * IVF_TRAIN_PER_LIST : n, D = AMSCR__SIG_LB_DIM;
    double *sum = amscr__malloc_array(v->nc, D * sizeof *sum);
    size_t *cnt = amscr__malloc_array(v->nc, sizeof *cnt);
    if (!sum || !cnt) {
        free(sum);
        free(cnt);
        return 0;
    }
    for (size_t c = 0; c < v->nc; c++)
        memcpy(v->cent + c * D, lbs + (size_t)((double)c * (double)n / (double)v->nc) * D, D * sizeof *v->cent);
    for (int it = 0; it < IVF_ITERS; it++) {
        memset(sum, 0, v->nc * D * sizeof *sum);
        memset(cnt, 0, v->nc * sizeof *cnt);
        for (size_t t = 0; t < ntrain; t++) {
            const float *x = lbs + (size_t)((double)t * (double)n / (double)ntrain) * D;
            size_t c = nearest_centroid(v, x);
            cnt[c]++;
            for (size_t u = 0; u < D; u++)
                sum[c * D + u] += x[u];
        }
        for (size_t c = 0; c < v->nc; c++)
            for (size_t u = 0; cnt[c] > 0 && u < D; u++) /* an empty list keeps its centroid */
                v->cent[c * D + u] = (float)(sum[c * D + u] / (double)cnt[c]);
    }
    free(sum);
    free(cnt);
    return 1;
}

int amscr__sig_ivf_lists(amscr__sig_ivf *v)
{
    size_t *start = amscr__calloc_array(v->nc + 1, sizeof *start), *ids = amscr__malloc_array(v->n ? v->n : 1, sizeof *ids);
    size_t *fill = amscr__calloc_array(v->nc ? v->nc : 1, sizeof *fill);
    int ok = start && ids && fill;
    for (size_t i = 0; ok && i < v->n; i++)
        start[v->cell[i] + 1]++;
    for (size_t c = 0; ok && c < v->nc; c++)
        start[c + 1] += start[c];
    for (size_t i = 0; ok && i < v->n; i++) /* ascending within a list */
        ids[start[v->cell[i]] + fill[v->cell[i]]++] = i;
    free(fill);
    if (!ok) { /* the old lists kept */
        free(start);
        free(ids);
        return 0;
    }
    free(v->start);
    free(v->ids);
    v->start = start;
    v->ids = ids;
    return 1;
}

amscr_status amscr__sig_ivf_build(const float *lbs, size_t n, amscr__sig_ivf *v)
{
    memset(v, 0, sizeof *v);
    v->nc = (size_t)ceil(sqrt((double)n));
    v->n = n;
    v->cent = amscr__malloc_array(v->nc, AMSCR__SIG_LB_DIM * sizeof *v->cent);
    v->cell = amscr__malloc_array(n ? n : 1, sizeof *v->cell);
    int ok = v->cent && v->cell && ivf_train(v, lbs, n);
    for (size_t i = 0; ok && i < n; i++)
        v->cell[i] = (uint32_t)nearest_centroid(v, lbs + i * AMSCR__SIG_LB_DIM);
    if (!ok || !amscr__sig_ivf_lists(v)) {
        amscr__sig_ivf_free(v);
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    }
    return AMSCR_OK;
}

amscr_status amscr__sig_ivf_add(amscr__sig_ivf *v, const float *lbs, size_t n)
{
    uint32_t *cell = n > v->n ? realloc(v->cell, n * sizeof *cell) : v->cell;
    if (!cell)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    v->cell = cell;
    for (size_t i = v->n; i < n; i++)
        cell[i] = (uint32_t)nearest_centroid(v, lbs + i * AMSCR__SIG_LB_DIM);
    size_t n0 = v->n;
    v->n = n;
    if (!amscr__sig_ivf_lists(v)) {
        v->n = n0;
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    }
    return AMSCR_OK;
}

void amscr__sig_ivf_free(amscr__sig_ivf *v)
{
    free(v->cent);
    free(v->cell);
    free(v->start);
    free(v->ids);
    memset(v, 0, sizeof *v);
}

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

size_t amscr__sig_ivf_nearest(const amscr__sig_ivf *v, const amscr__sig_rows *sigs, const float *lbs, size_t n,
                              const float *sig, const float *lb, size_t m, size_t exclude, size_t *cand)
{
    double *cd = amscr__malloc_array(v->nc, sizeof *cd);
    size_t *order = amscr__malloc_array(v->nc, sizeof *order), *ids = NULL, got = 0, lists = 0;
    int ok = cd && order;
    for (size_t c = 0; ok && c < v->nc; c++)
        cd[c] = sq_dist(v->cent + c * AMSCR__SIG_LB_DIM, lb);
    ok = ok && amscr_topk(cd, v->nc, v->nc, SIZE_MAX, order) == AMSCR_OK;
    for (; ok && lists < v->nc && (lists < IVF_PROBE_LISTS || got < IVF_PROBE_PER_M * m + 1); lists++)
        got += v->start[order[lists] + 1] - v->start[order[lists]];
    ids = ok ? amscr__malloc_array(got ? got : 1, sizeof *ids) : NULL;
    ok = ok && ids;
    got = 0;
    for (size_t r = 0; ok && r < lists; r++)
        for (size_t t = v->start[order[r]]; t < v->start[order[r] + 1]; t++)
            ids[got++] = v->ids[t];
    if (ok)
        qsort(ids, got, sizeof *ids, cmp_size);
    size_t res = 0;
    if (ok && got > m + 1)
        res = nearest_among(sigs, lbs, ids, got, sig, lb, m, exclude, cand);
    else if (ok)
        res = nearest_among(sigs, lbs, NULL, n, sig, lb, m, exclude, cand);
    free(cd);
    free(order);
    free(ids);
    return res;
}
