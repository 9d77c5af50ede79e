/* check_kmeans.c — exact 1-D K-means DP, Lloyd/k-means++ for dim > 1, elbow. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "internal.h"
#include "suites.h"
#include "testutil.h"

/* ---------------------------------------------------------------- helpers */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Two-pass SSE of v[a..b-1]. */
static double sse_range(const double *v, size_t a, size_t b)
{
    double m = 0.0;
    for (size_t i = a; i < b; i++)
        m += v[i];
    m /= (double)(b - a);
    double s = 0.0;
    for (size_t i = a; i < b; i++)
        s += (v[i] - m) * (v[i] - m);
    return s;
}

/* Brute force: minimum SSE over every split of sorted v[0..n-1] into k contiguous
 * non-empty groups (recursive enumeration of the k-1 cut positions). */
static double brute(const double *v, size_t start, size_t n, size_t k)
{
    if (k == 1)
        return sse_range(v, start, n);
    double best = INFINITY;
    for (size_t cut = start + 1; cut + (k - 1) <= n; cut++) {
        double s = sse_range(v, start, cut) + brute(v, cut, n, k - 1);
        if (s < best)
            best = s;
    }
    return best;
}

/* Reference O(k n^2) DP with incrementally updated (Welford) cluster costs. */
static void reference_dp(const double *v, size_t n, size_t kmax, double *sse)
{
    double *prev = malloc((n + 1) * sizeof *prev), *cur = malloc((n + 1) * sizeof *cur);
    ck_assert_ptr_nonnull(prev);
    ck_assert_ptr_nonnull(cur);
    for (size_t j = 1; j <= n; j++)
        prev[j] = sse_range(v, 0, j);
    sse[0] = prev[n];
    for (size_t k = 2; k <= kmax; k++) {
        for (size_t j = k; j <= n; j++) {
            double best = INFINITY, mean = 0.0, s = 0.0;
            size_t cnt = 0;
            for (size_t i = j; i-- > k - 1;) { /* cluster v[i..j-1] grows leftwards */
                double x = v[i];
                cnt++;
                double d = x - mean;
                mean += d / (double)cnt;
                s += d * (x - mean);
                double t = prev[i] + s;
                if (t < best)
                    best = t;
            }
            cur[j] = best;
        }
        sse[k - 1] = cur[n];
        double *t = prev;
        prev = cur;
        cur = t;
    }
    free(prev);
    free(cur);
}

/* ---------------------------------------------------------------- DP */

START_TEST(dp_equals_brute_force)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 100 + (uint64_t)_i);
    enum { N = 9, KMAX = 4 };
    double v[N];
    for (int i = 0; i < N; i++) {
        /* a mix of scales, clumps and exact duplicates */
        double u = amscr_test_uniform(&r);
        v[i] = (_i % 3 == 0) ? floor(u * 4.0) : (u < 0.5 ? u : 5.0 + 3.0 * u) * (1.0 + (double)_i);
    }
    qsort(v, N, sizeof v[0], cmp_double);
    double scratch[(5 + KMAX) * (N + 1)];
    ck_assert_uint_le(amscr__kmeans1d_scratch(N, KMAX), sizeof scratch / sizeof scratch[0]);
    double sse[KMAX];
    size_t split[KMAX * KMAX];
    amscr__kmeans1d_dp(v, N, KMAX, scratch, sse, split);
    for (size_t k = 1; k <= KMAX; k++) {
        double b = brute(v, 0, N, k);
        ck_assert_msg(fabs(sse[k - 1] - b) <= 1e-9 * (1.0 + b), "k=%zu: dp %.17g brute %.17g", k, sse[k - 1], b);
        /* The stored clustering for this k achieves the optimum. */
        const size_t *row = split + (k - 1) * KMAX;
        ck_assert_uint_eq(row[0], 0);
        double s = 0.0;
        for (size_t c = 0; c < k; c++) {
            size_t a = row[c], e = c + 1 < k ? row[c + 1] : N;
            ck_assert_uint_lt(a, e);
            s += sse_range(v, a, e);
        }
        ck_assert_msg(fabs(s - b) <= 1e-9 * (1.0 + b), "k=%zu: clustering %.17g brute %.17g", k, s, b);
    }
    /* Without split_out, the same SSE values. */
    double sse2[KMAX];
    amscr__kmeans1d_dp(v, N, KMAX, scratch, sse2, NULL);
    ck_assert_int_eq(memcmp(sse, sse2, sizeof sse), 0);
}
END_TEST

START_TEST(dp_large_divide_and_conquer)
{
    /* n above the divide-and-conquer switch: agrees with a plain O(k n^2) DP. */
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 77 + (uint64_t)_i);
    size_t n = 300 + 150 * (size_t)_i, kmax = 6;
    double *v = malloc(n * sizeof *v);
    ck_assert_ptr_nonnull(v);
    for (size_t i = 0; i < n; i++)
        v[i] = 1000.0 + (double)(i % 5) * 3.0 + amscr_test_normal(&r) * (0.2 + (double)_i);
    qsort(v, n, sizeof *v, cmp_double);
    double *scratch = malloc(amscr__kmeans1d_scratch(n, kmax) * sizeof *scratch);
    size_t *split = malloc(kmax * kmax * sizeof *split);
    double sse[6], ref[6];
    ck_assert_ptr_nonnull(scratch);
    ck_assert_ptr_nonnull(split);
    amscr__kmeans1d_dp(v, n, kmax, scratch, sse, split);
    reference_dp(v, n, kmax, ref);
    for (size_t k = 1; k <= kmax; k++) {
        ck_assert_msg(fabs(sse[k - 1] - ref[k - 1]) <= 1e-9 * ref[k - 1] + 1e-12, "k=%zu: %.17g vs %.17g", k,
                      sse[k - 1], ref[k - 1]);
        const size_t *row = split + (k - 1) * kmax;
        double s = 0.0;
        for (size_t c = 0; c < k; c++)
            s += sse_range(v, row[c], c + 1 < k ? row[c + 1] : n);
        ck_assert(fabs(s - ref[k - 1]) <= 1e-9 * ref[k - 1] + 1e-12);
        if (k > 1)
            ck_assert(sse[k - 1] <= sse[k - 2]);
    }
    free(v);
    free(scratch);
    free(split);
}
END_TEST

START_TEST(dp_kmax_equals_n)
{
    const double v[] = {1.0, 2.0, 2.0, 7.0};
    double scratch[(5 + 4) * 5], sse[4];
    size_t split[16];
    ck_assert_uint_le(amscr__kmeans1d_scratch(4, 4), sizeof scratch / sizeof scratch[0]);
    amscr__kmeans1d_dp(v, 4, 4, scratch, sse, split);
    /* k = 1: mean 3, SSE 4+1+1+16 = 22; k = 2: {1,2,2},{7}: 2/3; k = 3: {1},{2,2},{7}: 0. */
    ck_assert_double_eq_tol(sse[0], 22.0, 1e-12);
    ck_assert_double_eq_tol(sse[1], 2.0 / 3.0, 1e-12);
    ck_assert_double_eq_tol(sse[2], 0.0, 1e-12);
    ck_assert_double_eq_tol(sse[3], 0.0, 1e-12);
    ck_assert_uint_eq(split[1 * 4 + 1], 3);
    ck_assert_uint_eq(split[2 * 4 + 1], 1);
    ck_assert_uint_eq(split[2 * 4 + 2], 3);
    ck_assert(split[3 * 4 + 0] == 0 && split[3 * 4 + 1] == 1 && split[3 * 4 + 2] == 2 && split[3 * 4 + 3] == 3);
}
END_TEST

/* ---------------------------------------------------------------- elbow */

START_TEST(elbow_choose_hand)
{
    /* Scaled: y = 1, .355, .032, .011, 0 at x = 0, .25, .5, .75, 1; chord y = 1 - x;
     * gaps .395, .468, .239: the third point, K = k_min + 2. */
    const double sse[] = {100, 40, 10, 8, 7};
    ck_assert_uint_eq(amscr__elbow_choose(sse, 5, 1), 3);
    ck_assert_uint_eq(amscr__elbow_choose(sse, 5, 4), 6);
    /* Fewer than 3 points. */
    ck_assert_uint_eq(amscr__elbow_choose(sse, 2, 1), 1);
    ck_assert_uint_eq(amscr__elbow_choose(sse, 1, 2), 2);
    /* Negligible SSE or drop. */
    const double zero[] = {0, 0, 0, 0};
    ck_assert_uint_eq(amscr__elbow_choose(zero, 4, 1), 1);
    const double tiny[] = {1e-301, 1e-302, 0, 0};
    ck_assert_uint_eq(amscr__elbow_choose(tiny, 4, 1), 1);
    const double flat[] = {5.0, 5.0 - 1e-10, 5.0 - 2e-10, 5.0 - 3e-10};
    ck_assert_uint_eq(amscr__elbow_choose(flat, 4, 1), 1);
    const double bent_but_flat[] = {1.0, 1.0 - 5e-10, 1.0 - 6e-10}; /* a bend, within a negligible drop */
    ck_assert_uint_eq(amscr__elbow_choose(bent_but_flat, 3, 1), 1);
    /* A straight line (no bend) and a concave curve (above the chord). */
    const double line[] = {4, 3, 2, 1, 0};
    ck_assert_uint_eq(amscr__elbow_choose(line, 5, 1), 1);
    const double concave[] = {10, 9.9, 9.5, 8, 0};
    ck_assert_uint_eq(amscr__elbow_choose(concave, 5, 1), 1);
    /* The elbow at the second point. */
    const double sharp[] = {10, 1, 0.9, 0.8, 0.7};
    ck_assert_uint_eq(amscr__elbow_choose(sharp, 5, 1), 2);
    /* Ties (exact in binary): y = 1, .5, .25, 0, 0, every gap is .25: the smallest K. */
    const double tie[] = {4, 2, 1, 0, 0};
    ck_assert_uint_eq(amscr__elbow_choose(tie, 5, 1), 2);
}
END_TEST

/* Three tight 1-D clusters: elbow 3. */
START_TEST(elbow_three_clusters)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 9);
    enum { N = 300 };
    double v[N];
    for (int i = 0; i < N; i++)
        v[i] = (double)(i % 3) * 10.0 + 0.3 * amscr_test_normal(&r);
    double inertia[7];
    size_t kb = 0;
    ck_assert_int_eq(amscr_kmeans_elbow(v, N, 1, 1, 6, 0, inertia, &kb), AMSCR_OK);
    ck_assert_uint_eq(kb, 3);
    for (int k = 1; k < 6; k++)
        ck_assert(inertia[k] <= inertia[k - 1]);
    /* Each value is the fit's inertia for that k. */
    amscr_kmeans *km = NULL;
    ck_assert_int_eq(amscr_kmeans_new(3, &km), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_fit(km, v, N, 1), AMSCR_OK);
    ck_assert_double_eq(amscr_kmeans_inertia(km), inertia[2]);
    amscr_kmeans_free(km);

    /* The same in 2-D (three blobs). */
    double p[2 * N];
    for (int i = 0; i < N; i++) {
        int c = i % 3;
        p[2 * i] = (c == 1 ? 8.0 : 0.0) + 0.4 * amscr_test_normal(&r);
        p[2 * i + 1] = (c == 2 ? 8.0 : 0.0) + 0.4 * amscr_test_normal(&r);
    }
    ck_assert_int_eq(amscr_kmeans_elbow(p, N, 2, 1, 7, 5, inertia, &kb), AMSCR_OK);
    ck_assert_uint_eq(kb, 3);
    /* k_min = k_max. */
    ck_assert_int_eq(amscr_kmeans_elbow(p, N, 2, 2, 2, 5, inertia, &kb), AMSCR_OK);
    ck_assert_uint_eq(kb, 2);
    /* Identical values: SSE(k_min) = 0 -> k_min. */
    double same[10];
    for (int i = 0; i < 10; i++)
        same[i] = 4.25;
    ck_assert_int_eq(amscr_kmeans_elbow(same, 10, 1, 1, 5, 0, inertia, &kb), AMSCR_OK);
    ck_assert_uint_eq(kb, 1);
    ck_assert_double_eq(inertia[0], 0.0);
}
END_TEST

/* ---------------------------------------------------------------- fits */

START_TEST(fit_1d_exact)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 21);
    enum { N = 600 };
    double v[N];
    const double truth[3] = {-10.0, 0.0, 10.0};
    for (int i = 0; i < N; i++)
        v[N - 1 - i] = truth[i % 3] + 0.5 * amscr_test_normal(&r);
    amscr_kmeans *km = NULL;
    ck_assert_int_eq(amscr_kmeans_new(3, &km), AMSCR_OK);
    ck_assert_ptr_null(amscr_kmeans_centers(km));
    ck_assert(isnan(amscr_kmeans_inertia(km)));
    ck_assert_uint_eq(amscr_kmeans_dim(km), 0);
    ck_assert_int_eq(amscr_kmeans_fit(km, v, N, 1), AMSCR_OK);
    ck_assert_uint_eq(amscr_kmeans_dim(km), 1);
    const double *c = amscr_kmeans_centers(km);
    for (int j = 0; j < 3; j++)
        ck_assert_double_eq_tol(c[j], truth[j], 0.1);
    /* Inertia = SSE of the nearest-centre assignment. */
    size_t lab[N];
    double d2[N], s = 0.0;
    ck_assert_int_eq(amscr_kmeans_assign(km, v, N, lab, d2), AMSCR_OK);
    for (int i = 0; i < N; i++) {
        ck_assert_uint_eq(lab[i], (size_t)((N - 1 - i) % 3));
        ck_assert_double_eq_tol(d2[i], (v[i] - c[lab[i]]) * (v[i] - c[lab[i]]), 1e-12);
        s += d2[i];
    }
    ck_assert_double_eq_tol(amscr_kmeans_inertia(km), s, 1e-9 * s);
    amscr_kmeans_free(km);
}
END_TEST

START_TEST(fit_1d_optimal_small)
{
    /* Exact optimum on small random data (Lloyd could get stuck; the DP cannot). */
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 300 + (uint64_t)_i);
    enum { N = 9 };
    double v[N], sorted[N];
    for (int i = 0; i < N; i++)
        sorted[i] = v[i] = amscr_test_uniform(&r) * 10.0;
    qsort(sorted, N, sizeof sorted[0], cmp_double);
    for (size_t k = 1; k <= 4; k++) {
        amscr_kmeans *km = NULL;
        ck_assert_int_eq(amscr_kmeans_new(k, &km), AMSCR_OK);
        ck_assert_int_eq(amscr_kmeans_fit(km, v, N, 1), AMSCR_OK);
        double b = brute(sorted, 0, N, k);
        ck_assert_double_eq_tol(amscr_kmeans_inertia(km), b, 1e-9 * (1 + b));
        const double *c = amscr_kmeans_centers(km);
        for (size_t j = 1; j < k; j++)
            ck_assert(c[j - 1] <= c[j]);
        amscr_kmeans_free(km);
    }
}
END_TEST

START_TEST(fit_2d_blobs)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 55);
    enum { N = 800, K = 4 };
    const double truth[K][2] = {{0, 0}, {10, 0}, {0, 10}, {10, 10}};
    double *p = malloc(2 * N * sizeof *p);
    ck_assert_ptr_nonnull(p);
    for (int i = 0; i < N; i++) {
        p[2 * i] = truth[i % K][0] + 0.7 * amscr_test_normal(&r);
        p[2 * i + 1] = truth[i % K][1] + 0.7 * amscr_test_normal(&r);
    }
    amscr_kmeans *km = NULL, *km2 = NULL;
    ck_assert_int_eq(amscr_kmeans_new(K, &km), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_set_seed(km, 12345), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_fit(km, p, N, 2), AMSCR_OK);
    ck_assert_uint_eq(amscr_kmeans_dim(km), 2);
    const double *c = amscr_kmeans_centers(km);
    /* Each true centre has a fitted centre within 0.2. */
    size_t match[K];
    for (int t = 0; t < K; t++) {
        size_t bj = 0;
        double bd = INFINITY;
        for (size_t j = 0; j < K; j++) {
            double d = hypot(c[2 * j] - truth[t][0], c[2 * j + 1] - truth[t][1]);
            if (d < bd) {
                bd = d;
                bj = j;
            }
        }
        ck_assert_msg(bd < 0.2, "centre %d off by %g", t, bd);
        match[t] = bj;
    }
    size_t *lab = malloc(N * sizeof *lab);
    ck_assert_ptr_nonnull(lab);
    ck_assert_int_eq(amscr_kmeans_assign(km, p, N, lab, NULL), AMSCR_OK);
    int agree = 0;
    for (int i = 0; i < N; i++)
        agree += lab[i] == match[i % K];
    ck_assert_int_ge(agree, N - 2);

    /* Determinism: the same seed gives bit-identical centres. */
    ck_assert_int_eq(amscr_kmeans_new(K, &km2), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_set_seed(km2, 12345), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_fit(km2, p, N, 2), AMSCR_OK);
    ck_assert_int_eq(memcmp(amscr_kmeans_centers(km2), c, K * 2 * sizeof(double)), 0);
    ck_assert(amscr_kmeans_inertia(km2) == amscr_kmeans_inertia(km));
    /* Refit the same object: same answer. */
    ck_assert_int_eq(amscr_kmeans_fit(km2, p, N, 2), AMSCR_OK);
    ck_assert_int_eq(memcmp(amscr_kmeans_centers(km2), c, K * 2 * sizeof(double)), 0);
    amscr_kmeans_free(km);
    amscr_kmeans_free(km2);
    free(lab);
    free(p);
}
END_TEST

START_TEST(fit_duplicates_and_empty_clusters)
{
    /* Many identical points: k-means++ and re-seeding must stay finite. */
    double p[2 * 12];
    for (int i = 0; i < 12; i++) {
        p[2 * i] = i < 9 ? 1.0 : 5.0 + i;
        p[2 * i + 1] = i < 9 ? 2.0 : -3.0;
    }
    for (size_t k = 1; k <= 5; k++) {
        amscr_kmeans *km = NULL;
        ck_assert_int_eq(amscr_kmeans_new(k, &km), AMSCR_OK);
        ck_assert_int_eq(amscr_kmeans_set_restarts(km, 3), AMSCR_OK);
        ck_assert_int_eq(amscr_kmeans_fit(km, p, 12, 2), AMSCR_OK);
        const double *c = amscr_kmeans_centers(km);
        for (size_t j = 0; j < 2 * k; j++)
            ck_assert(isfinite(c[j]));
        ck_assert(amscr_kmeans_inertia(km) >= 0.0);
        if (k >= 4) /* {9 identical}, {14}, {15}, {16}: zero SSE is reachable */
            ck_assert_double_eq_tol(amscr_kmeans_inertia(km), 0.0, 1e-12);
        amscr_kmeans_free(km);
    }
    /* All points identical in 2-D, k = n. */
    double same[8] = {3, 3, 3, 3, 3, 3, 3, 3};
    amscr_kmeans *km = NULL;
    ck_assert_int_eq(amscr_kmeans_new(4, &km), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_fit(km, same, 4, 2), AMSCR_OK);
    ck_assert_double_eq(amscr_kmeans_inertia(km), 0.0);
    amscr_kmeans_free(km);
}
END_TEST

START_TEST(settings_and_invalid)
{
    amscr_kmeans *km = NULL;
    ck_assert_int_eq(amscr_kmeans_new(0, &km), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_int_eq(amscr_kmeans_new(2, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_new(2, &km), AMSCR_OK);
    /* Defaults. */
    ck_assert_uint_eq(amscr_kmeans_get_seed(km), 0);
    ck_assert_uint_eq(amscr_kmeans_get_max_iterations(km), 100);
    ck_assert_double_eq(amscr_kmeans_get_tolerance(km), 1e-10);
    ck_assert_uint_eq(amscr_kmeans_get_restarts(km), 4);
    ck_assert_uint_eq(amscr_kmeans_num_clusters(km), 2);
    /* Setters. */
    ck_assert_int_eq(amscr_kmeans_set_seed(km, 99), AMSCR_OK);
    ck_assert_uint_eq(amscr_kmeans_get_seed(km), 99);
    ck_assert_int_eq(amscr_kmeans_set_max_iterations(km, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_max_iterations(km, 7), AMSCR_OK);
    ck_assert_uint_eq(amscr_kmeans_get_max_iterations(km), 7);
    ck_assert_int_eq(amscr_kmeans_set_tolerance(km, -1.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_tolerance(km, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_tolerance(km, INFINITY), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_tolerance(km, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_set_restarts(km, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_restarts(km, 2), AMSCR_OK);
    ck_assert_uint_eq(amscr_kmeans_get_restarts(km), 2);
    ck_assert_int_eq(amscr_kmeans_set_seed(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_max_iterations(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_tolerance(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_set_restarts(NULL, 1), AMSCR_E_INVALID_ARG);
    /* NULL-safe getters. */
    ck_assert_uint_eq(amscr_kmeans_get_seed(NULL), 0);
    ck_assert_uint_eq(amscr_kmeans_get_max_iterations(NULL), 0);
    ck_assert_double_eq(amscr_kmeans_get_tolerance(NULL), 0.0);
    ck_assert_uint_eq(amscr_kmeans_get_restarts(NULL), 0);
    ck_assert_uint_eq(amscr_kmeans_num_clusters(NULL), 0);
    ck_assert_uint_eq(amscr_kmeans_dim(NULL), 0);
    ck_assert_ptr_null(amscr_kmeans_centers(NULL));
    ck_assert(isnan(amscr_kmeans_inertia(NULL)));
    amscr_kmeans_free(NULL);

    /* Assign before a fit. */
    double v[4] = {0, 1, 5, 6};
    size_t lab[4];
    ck_assert_int_eq(amscr_kmeans_assign(km, v, 4, lab, NULL), AMSCR_E_STATE);
    /* Fit arguments. */
    ck_assert_int_eq(amscr_kmeans_fit(NULL, v, 4, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_fit(km, NULL, 4, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_fit(km, v, 4, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_fit(km, v, 1, 1), AMSCR_E_INVALID_ARG);
    double bad[4] = {0, NAN, 5, 6};
    ck_assert_int_eq(amscr_kmeans_fit(km, bad, 4, 1), AMSCR_E_INVALID_ARG);
    bad[1] = INFINITY;
    ck_assert_int_eq(amscr_kmeans_fit(km, bad, 4, 1), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_ptr_null(amscr_kmeans_centers(km)); /* failures leave the object unfitted */
    /* A good fit, then assign: centres 0.5 and 5.5. */
    ck_assert_int_eq(amscr_kmeans_fit(km, v, 4, 1), AMSCR_OK);
    ck_assert_str_eq(amscr_last_error_detail(), "");
    ck_assert_double_eq(amscr_kmeans_centers(km)[0], 0.5);
    ck_assert_double_eq(amscr_kmeans_centers(km)[1], 5.5);
    ck_assert_double_eq(amscr_kmeans_inertia(km), 1.0);
    double q[3] = {2.9, 3.0, 3.1}, d2[3];
    ck_assert_int_eq(amscr_kmeans_assign(km, q, 3, lab, d2), AMSCR_OK);
    ck_assert(lab[0] == 0 && lab[1] == 0 && lab[2] == 1); /* 3.0 is a tie: the lower index */
    ck_assert_double_eq_tol(d2[0], 2.4 * 2.4, 1e-12);
    ck_assert_double_eq_tol(d2[2], 2.4 * 2.4, 1e-12);
    ck_assert_int_eq(amscr_kmeans_assign(NULL, q, 3, lab, d2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_assign(km, NULL, 3, lab, d2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_assign(km, q, 3, NULL, d2), AMSCR_E_INVALID_ARG);
    q[1] = NAN;
    ck_assert_int_eq(amscr_kmeans_assign(km, q, 3, lab, d2), AMSCR_E_INVALID_ARG);
    /* A failed fit keeps the previous result. */
    ck_assert_int_eq(amscr_kmeans_fit(km, bad, 4, 1), AMSCR_E_INVALID_ARG);
    ck_assert_double_eq(amscr_kmeans_centers(km)[0], 0.5);
    amscr_kmeans_free(km);

    /* Elbow arguments. */
    double inertia[4];
    size_t kb = 77;
    ck_assert_int_eq(amscr_kmeans_elbow(NULL, 4, 1, 1, 2, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 1, 1, 2, 0, NULL, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 1, 1, 2, 0, inertia, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 0, 1, 2, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 1, 0, 2, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 1, 3, 2, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(v, 4, 1, 1, 5, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_kmeans_elbow(bad, 4, 1, 1, 2, 0, inertia, &kb), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(kb, 77);
}
END_TEST

Suite *amscr_suite_kmeans(void)
{
    Suite *s = suite_create("kmeans");
    TCase *tc = tcase_create("dp");
    tcase_add_loop_test(tc, dp_equals_brute_force, 0, 30);
    tcase_add_loop_test(tc, dp_large_divide_and_conquer, 0, 4);
    tcase_add_test(tc, dp_kmax_equals_n);
    tcase_add_test(tc, elbow_choose_hand);
    suite_add_tcase(s, tc);
    TCase *tf = tcase_create("fit");
    tcase_add_test(tf, elbow_three_clusters);
    tcase_add_test(tf, fit_1d_exact);
    tcase_add_loop_test(tf, fit_1d_optimal_small, 0, 20);
    tcase_add_test(tf, fit_2d_blobs);
    tcase_add_test(tf, fit_duplicates_and_empty_clusters);
    tcase_add_test(tf, settings_and_invalid);
    suite_add_tcase(s, tf);
    return s;
}
