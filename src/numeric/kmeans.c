/* kmeans.c — deterministic K-means: exact 1-D dynamic programming, seeded Lloyd with
 * k-means++ starts for dim > 1, and the elbow choice of K (docs/method.md §3.4a-b). */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ======================================================================
 * Exact 1-D K-means by dynamic programming
 * ====================================================================== */

/* Below this size the O(kmax n^2) loops are used; above, each layer is computed by
 * divide and conquer over the (monotone) optimal split, O(kmax n log n). Both give the
 * exact optimum and pick the smallest optimal split on ties. */
#define KM_DC_MIN_N 256

/* Scratch layout (doubles), with m = n + 1:
 *   s1[m], s2[m]   prefix sums of (x - shift) and (x - shift)^2
 *   rc[m]          rc[c] = 1/c (cluster sizes)
 *   prev[m], cur[m] DP rows D[k-1][.], D[k][.]
 *   arg[kmax * m]   arg[(k-1)*m + j] = start of the last cluster in the optimal
 *                   k-clustering of the first j values (stored as a double, exact). */
size_t amscr__kmeans1d_scratch(size_t n, size_t kmax)
{
    return (5 + kmax) * (n + 1);
}

/* SSE of sorted values i..j-1 from the prefix sums (clamped at 0). */
static inline double km_cost(const double *s1, const double *s2, const double *rc, size_t i, size_t j)
{
    double a = s1[j] - s1[i];
    double c = (s2[j] - s2[i]) - a * a * rc[j - i];
    return c > 0.0 ? c : 0.0;
}

/* One DP layer by divide and conquer: cur[j] for j in [jlo, jhi], the optimal split of
 * each lying in [ilo, ihi] (and in [k-1, j-1]). */
static void km_layer_dc(const double *s1, const double *s2, const double *rc, const double *prev, double *cur,
                        double *arg, size_t k, size_t jlo, size_t jhi, size_t ilo, size_t ihi)
{
    while (jlo <= jhi) {
        size_t j = jlo + (jhi - jlo) / 2;
        size_t lo = ilo > k - 1 ? ilo : k - 1;
        size_t hi = ihi < j - 1 ? ihi : j - 1;
        double best = INFINITY;
        size_t bi = lo;
        for (size_t i = lo; i <= hi; i++) {
            double v = prev[i] + km_cost(s1, s2, rc, i, j);
            if (v < best) {
                best = v;
                bi = i;
            }
        }
        cur[j] = best;
        arg[j] = (double)bi;
        /* Left half recursively (depth <= log2 n), right half by iteration. */
        if (j > jlo)
            km_layer_dc(s1, s2, rc, prev, cur, arg, k, jlo, j - 1, ilo, bi);
        jlo = j + 1;
        ilo = bi;
    }
}

/* sorted[0..n-1] ascending; 1 <= kmax <= n. sse_out[k-1] = optimal SSE with k clusters.
 * split_out (kmax*kmax, may be NULL): row k-1 holds, in its first k entries, the start
 * index (into sorted) of each cluster of the optimal k-clustering, ascending; cluster c
 * spans [split[c], split[c+1]) with split[k] taken as n. Entries past k are untouched.
 * No allocation; scratch: amscr__kmeans1d_scratch(n, kmax) doubles. */
void amscr__kmeans1d_dp(const double *sorted, size_t n, size_t kmax, double *scratch, double *sse_out,
                        size_t *split_out)
{
    const size_t m = n + 1;
    double *s1 = scratch, *s2 = s1 + m, *rc = s2 + m, *prev = rc + m, *cur = prev + m, *arg = cur + m;

    /* Shift by the middle value so the prefix sums do not cancel catastrophically. */
    const double shift = sorted[n / 2];
    s1[0] = s2[0] = rc[0] = 0.0;
    for (size_t i = 0; i < n; i++) {
        double v = sorted[i] - shift;
        s1[i + 1] = s1[i] + v;
        s2[i + 1] = s2[i] + v * v;
        rc[i + 1] = 1.0 / (double)(i + 1);
    }
    /* k = 1 */
    for (size_t j = 1; j <= n; j++) {
        prev[j] = km_cost(s1, s2, rc, 0, j);
        arg[j] = 0.0;
    }
    sse_out[0] = prev[n];
    for (size_t k = 2; k <= kmax; k++) {
        double *ak = arg + (k - 1) * m;
        /* D[k][j] is needed for j = k..n (kmax-k more clusters can follow). */
        if (n < KM_DC_MIN_N) {
            for (size_t j = k; j <= n; j++) {
                double best = INFINITY;
                size_t bi = k - 1;
                for (size_t i = k - 1; i < j; i++) {
                    double v = prev[i] + km_cost(s1, s2, rc, i, j);
                    if (v < best) {
                        best = v;
                        bi = i;
                    }
                }
                cur[j] = best;
                ak[j] = (double)bi;
            }
        } else {
            km_layer_dc(s1, s2, rc, prev, cur, ak, k, k, n, k - 1, n - 1);
        }
        sse_out[k - 1] = cur[n];
        double *t = prev;
        prev = cur;
        cur = t;
    }
    if (split_out) {
        for (size_t k = 1; k <= kmax; k++) {
            size_t *row = split_out + (k - 1) * kmax;
            size_t j = n;
            for (size_t c = k; c-- > 0;) {
                size_t i = c == 0 ? 0 : (size_t)arg[c * m + j];
                row[c] = i;
                j = i;
            }
        }
    }
}

/* Elbow (docs/method.md §3.4b) on sse[0..m-1] for K = k_min..k_min+m-1: with K and SSE scaled
 * to [0, 1], the K farthest below the chord from the first to the last point (ties: the
 * smaller K); k_min when m < 3, SSE(first) is negligible, the drop is negligible, or no
 * point is below the chord by more than 1e-9. */
size_t amscr__elbow_choose(const double *sse, size_t m, size_t k_min)
{
    if (m < 3)
        return k_min;
    const double first = sse[0], last = sse[m - 1];
    if (!(first > 1e-300) || first - last <= 1e-9 * first)
        return k_min;
    double lo = sse[0], hi = sse[0];
    for (size_t i = 1; i < m; i++) {
        if (sse[i] < lo)
            lo = sse[i];
        if (sse[i] > hi)
            hi = sse[i];
    }
    const double range = hi - lo;
    if (!(range > 0.0))
        return k_min;
    const double y0 = (first - lo) / range, y1 = (last - lo) / range;
    const double inv = 1.0 / (double)(m - 1);
    /* Perpendicular distance = vertical gap / sqrt(1 + slope^2): same argmax, but the
     * threshold is applied to the true distance. */
    const double norm = sqrt(1.0 + (y1 - y0) * (y1 - y0));
    double best = 1e-9;
    size_t bi = 0;
    for (size_t i = 1; i + 1 < m; i++) {
        double x = (double)i * inv;
        double y = (sse[i] - lo) / range;
        double gap = (y0 + (y1 - y0) * x - y) / norm;
        if (gap > best) {
            best = gap;
            bi = i;
        }
    }
    return k_min + bi;
}

/* ======================================================================
 * The amscr_kmeans object
 * ====================================================================== */

struct amscr_kmeans {
    size_t k;
    uint64_t seed;
    unsigned max_iterations;
    double tol;
    unsigned restarts;
    size_t dim;      /* 0 before a fit */
    double *centers; /* k*dim, NULL before a fit */
    double inertia;  /* NaN before a fit */
};

amscr_status amscr_kmeans_new(size_t k, amscr_kmeans **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    if (k == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_new: k must be >= 1");
    amscr_kmeans *km = malloc(sizeof *km);
    if (!km)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_new: out of memory");
    km->k = k;
    km->seed = 0;
    km->max_iterations = 100;
    km->tol = 1e-10;
    km->restarts = 4;
    km->dim = 0;
    km->centers = NULL;
    km->inertia = NAN;
    *out = km;
    return AMSCR_OK;
}

void amscr_kmeans_free(amscr_kmeans *km)
{
    if (!km)
        return;
    free(km->centers);
    free(km);
}

AMSCR__SETTER(amscr_kmeans_set_seed, amscr_kmeans, km, uint64_t, seed, AMSCR_OK)
AMSCR__SETTER(amscr_kmeans_set_max_iterations, amscr_kmeans, km, unsigned, max_iterations,
              AMSCR__REQUIRE(v >= 1, "amscr_kmeans_set_max_iterations: must be >= 1"))
AMSCR__SETTER(amscr_kmeans_set_tolerance, amscr_kmeans, km, double, tol,
              AMSCR__REQUIRE(v >= 0.0 && isfinite(v), "amscr_kmeans_set_tolerance: %g is not a finite value >= 0", v))
AMSCR__SETTER(amscr_kmeans_set_restarts, amscr_kmeans, km, unsigned, restarts,
              AMSCR__REQUIRE(v >= 1, "amscr_kmeans_set_restarts: must be >= 1"))

AMSCR__GETTER(amscr_kmeans_get_seed, amscr_kmeans, uint64_t, seed)
AMSCR__GETTER(amscr_kmeans_get_max_iterations, amscr_kmeans, unsigned, max_iterations)
AMSCR__GETTER(amscr_kmeans_get_tolerance, amscr_kmeans, double, tol)
AMSCR__GETTER(amscr_kmeans_get_restarts, amscr_kmeans, unsigned, restarts)
size_t amscr_kmeans_num_clusters(const amscr_kmeans *km) { return km ? km->k : 0; }
size_t amscr_kmeans_dim(const amscr_kmeans *km) { return km ? km->dim : 0; }
const double *amscr_kmeans_centers(const amscr_kmeans *km) { return km ? km->centers : NULL; }
double amscr_kmeans_inertia(const amscr_kmeans *km) { return km ? km->inertia : NAN; }

/* splitmix64: the object's own PRNG (no global state). */
static uint64_t km_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static double km_uniform(uint64_t *s) { return (double)(km_next(s) >> 11) * 0x1.0p-53; }

static int km_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Squared distance between two dim-vectors. */
static double km_d2(const double *a, const double *b, size_t dim)
{
    double s = 0.0;
    for (size_t d = 0; d < dim; d++) {
        double t = a[d] - b[d];
        s += t * t;
    }
    return s;
}

/* Nearest centre (ties: lower index) for every point; returns the SSE. */
static double km_assign_all(const double *data, size_t n, size_t dim, const double *c, size_t k, size_t *labels,
                            double *d2)
{
    double sse = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double *x = data + i * dim;
        size_t bj = 0;
        double bd = km_d2(x, c, dim);
        for (size_t j = 1; j < k; j++) {
            double dd = km_d2(x, c + j * dim, dim);
            if (dd < bd) {
                bd = dd;
                bj = j;
            }
        }
        labels[i] = bj;
        d2[i] = bd;
        sse += bd;
    }
    return sse;
}

/* k-means++ seeding: the first centre uniformly, the next ones with probability
 * proportional to the squared distance to the nearest chosen centre. */
static void km_plusplus(const double *data, size_t n, size_t dim, size_t k, uint64_t *rng, double *c, double *d2)
{
    size_t i0 = (size_t)(km_uniform(rng) * (double)n);
    if (i0 >= n)
        i0 = n - 1;
    memcpy(c, data + i0 * dim, dim * sizeof *c);
    for (size_t i = 0; i < n; i++)
        d2[i] = km_d2(data + i * dim, c, dim);
    for (size_t j = 1; j < k; j++) {
        double total = 0.0;
        for (size_t i = 0; i < n; i++)
            total += d2[i];
        size_t pick;
        if (total > 0.0) {
            double u = km_uniform(rng) * total, acc = 0.0;
            pick = n;
            size_t last_pos = 0;
            for (size_t i = 0; i < n; i++) {
                if (d2[i] > 0.0)
                    last_pos = i;
                acc += d2[i];
                if (acc > u && d2[i] > 0.0) {
                    pick = i;
                    break;
                }
            }
            if (pick == n) /* rounding: take the last point with positive weight */
                pick = last_pos;
        } else {
            pick = (size_t)(km_uniform(rng) * (double)n);
            if (pick >= n)
                pick = n - 1;
        }
        double *cj = c + j * dim;
        memcpy(cj, data + pick * dim, dim * sizeof *c);
        for (size_t i = 0; i < n; i++) {
            double dd = km_d2(data + i * dim, cj, dim);
            if (dd < d2[i])
                d2[i] = dd;
        }
    }
}

/* Lloyd iterations from the centres in c (updated in place); returns the final SSE.
 * Work arrays: labels[n], d2[n], sums[k*dim], counts[k]. */
static double km_lloyd(const double *data, size_t n, size_t dim, size_t k, unsigned max_it, double tol, double *c,
                       size_t *labels, double *d2, double *sums, size_t *counts)
{
    double prev = 0.0;
    for (unsigned it = 0; it < max_it; it++) {
        double sse = km_assign_all(data, n, dim, c, k, labels, d2);
        if (it > 0 && fabs(prev - sse) <= tol * prev)
            break;
        prev = sse;
        memset(sums, 0, k * dim * sizeof *sums);
        memset(counts, 0, k * sizeof *counts);
        for (size_t i = 0; i < n; i++) {
            size_t j = labels[i];
            counts[j]++;
            const double *x = data + i * dim;
            for (size_t d = 0; d < dim; d++)
                sums[j * dim + d] += x[d];
        }
        for (size_t j = 0; j < k; j++) {
            if (counts[j] == 0) {
                /* Empty cluster: re-seed with the point farthest from its centre. */
                size_t far = 0;
                for (size_t i = 1; i < n; i++)
                    if (d2[i] > d2[far])
                        far = i;
                memcpy(c + j * dim, data + far * dim, dim * sizeof *c);
                d2[far] = 0.0;
                continue;
            }
            double inv = 1.0 / (double)counts[j];
            for (size_t d = 0; d < dim; d++)
                c[j * dim + d] = sums[j * dim + d] * inv;
        }
    }
    return km_assign_all(data, n, dim, c, k, labels, d2);
}

/* Exact 1-D fit: centres (ascending) and SSE. Allocates its own work space. */
static amscr_status km_fit_1d(const double *data, size_t n, size_t k, double *centers, double *out_sse)
{
    size_t ns = amscr__kmeans1d_scratch(n, k);
    if (ns / (k + 5) != n + 1)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_fit: size overflow");
    double *sorted = amscr__malloc_array(n, sizeof *sorted);
    double *scratch = amscr__malloc_array(ns, sizeof *scratch);
    double *sse = amscr__malloc_array(k, sizeof *sse);
    size_t *split = k <= SIZE_MAX / k ? amscr__malloc_array(k * k, sizeof *split) : NULL;
    if (!sorted || !scratch || !sse || !split) {
        free(sorted);
        free(scratch);
        free(sse);
        free(split);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_fit: out of memory (n = %zu, k = %zu)", n, k);
    }
    memcpy(sorted, data, n * sizeof *sorted);
    qsort(sorted, n, sizeof *sorted, km_cmp_double);
    amscr__kmeans1d_dp(sorted, n, k, scratch, sse, split);
    const size_t *row = split + (k - 1) * k;
    double total = 0.0;
    for (size_t c = 0; c < k; c++) {
        size_t a = row[c], b = c + 1 < k ? row[c + 1] : n;
        double s = 0.0;
        for (size_t i = a; i < b; i++)
            s += sorted[i];
        double mean = s / (double)(b - a);
        double q = 0.0;
        for (size_t i = a; i < b; i++)
            q += (sorted[i] - mean) * (sorted[i] - mean);
        centers[c] = mean;
        total += q;
    }
    *out_sse = total;
    free(sorted);
    free(scratch);
    free(sse);
    free(split);
    return AMSCR_OK;
}

/* Seeded Lloyd with k-means++ starts and restarts; best SSE kept (ties: the earlier run). */
static amscr_status km_fit_nd(const amscr_kmeans *km, const double *data, size_t n, size_t dim, double *centers,
                              double *out_sse)
{
    const size_t k = km->k;
    size_t *labels = amscr__malloc_array(n, sizeof *labels);
    size_t *counts = amscr__malloc_array(k, sizeof *counts);
    double *d2 = amscr__malloc_array(n, sizeof *d2);
    double *sums = amscr__malloc_array(k, dim * sizeof *sums);
    double *c = amscr__malloc_array(k, dim * sizeof *c);
    amscr_status st = AMSCR_OK;
    if (!labels || !counts || !d2 || !sums || !c) {
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_fit: out of memory (n = %zu, k = %zu)", n, k);
    } else {
        uint64_t rng = km->seed;
        double best = INFINITY;
        for (unsigned r = 0; r < km->restarts; r++) {
            km_plusplus(data, n, dim, k, &rng, c, d2);
            double sse = km_lloyd(data, n, dim, k, km->max_iterations, km->tol, c, labels, d2, sums, counts);
            if (sse < best || r == 0) {
                best = sse;
                memcpy(centers, c, k * dim * sizeof *c);
            }
        }
        *out_sse = best;
    }
    free(labels);
    free(counts);
    free(d2);
    free(sums);
    free(c);
    return st;
}

amscr_status amscr_kmeans_fit(amscr_kmeans *km, const double *data, size_t n, size_t dim)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(km);
    AMSCR_CHECK_NULL(data);
    if (dim == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_fit: dim must be >= 1");
    if (n < km->k)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_fit: n = %zu < k = %zu", n, km->k);
    if (n > SIZE_MAX / dim || km->k > SIZE_MAX / dim)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_fit: n * dim overflows");
    if (!amscr__all_finite(data, n * dim))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_fit: non-finite data");
    double *centers = amscr__malloc_array(km->k, dim * sizeof *centers);
    if (!centers)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_fit: out of memory");
    double sse = NAN;
    amscr_status st = dim == 1 ? km_fit_1d(data, n, km->k, centers, &sse) : km_fit_nd(km, data, n, dim, centers, &sse);
    if (st != AMSCR_OK) {
        free(centers);
        return st;
    }
    free(km->centers);
    km->centers = centers;
    km->dim = dim;
    km->inertia = sse;
    return AMSCR_OK;
}

amscr_status amscr_kmeans_assign(const amscr_kmeans *km, const double *data, size_t n, size_t *out_labels,
                                 double *out_sq_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(km);
    if (!km->centers)
        return amscr__fail(AMSCR_E_STATE, "amscr_kmeans_assign: not fitted");
    AMSCR_CHECK_NULL(data);
    AMSCR_CHECK_NULL(out_labels);
    const size_t dim = km->dim;
    if (n > SIZE_MAX / dim)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_assign: n * dim overflows");
    if (!amscr__all_finite(data, n * dim))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_assign: non-finite data");
    for (size_t i = 0; i < n; i++) {
        const double *x = data + i * dim;
        size_t bj = 0;
        double bd = km_d2(x, km->centers, dim);
        for (size_t j = 1; j < km->k; j++) {
            double dd = km_d2(x, km->centers + j * dim, dim);
            if (dd < bd) {
                bd = dd;
                bj = j;
            }
        }
        out_labels[i] = bj;
        if (out_sq_dist)
            out_sq_dist[i] = bd;
    }
    return AMSCR_OK;
}

amscr_status amscr_kmeans_elbow(const double *data, size_t n, size_t dim, size_t k_min, size_t k_max, uint64_t seed,
                                double *out_inertia, size_t *out_k_best)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(data);
    AMSCR_CHECK_NULL(out_inertia);
    AMSCR_CHECK_NULL(out_k_best);
    if (dim == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_elbow: dim must be >= 1");
    if (k_min < 1 || k_min > k_max || k_max > n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_elbow: need 1 <= k_min (%zu) <= k_max (%zu) <= n (%zu)",
                           k_min, k_max, n);
    if (n > SIZE_MAX / dim)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_elbow: n * dim overflows");
    if (!amscr__all_finite(data, n * dim))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_kmeans_elbow: non-finite data");
    const size_t m = k_max - k_min + 1;
    double *sse = amscr__malloc_array(m, sizeof *sse);
    if (!sse)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_kmeans_elbow: out of memory");
    for (size_t i = 0; i < m; i++) {
        amscr_kmeans *km = NULL;
        amscr_status st = amscr_kmeans_new(k_min + i, &km);
        if (st == AMSCR_OK) {
            km->seed = seed;
            st = amscr_kmeans_fit(km, data, n, dim);
        }
        if (st != AMSCR_OK) {
            amscr_kmeans_free(km);
            free(sse);
            return st;
        }
        sse[i] = km->inertia;
        amscr_kmeans_free(km);
    }
    memcpy(out_inertia, sse, m * sizeof *sse);
    *out_k_best = amscr__elbow_choose(sse, m, k_min);
    free(sse);
    return AMSCR_OK;
}
