/* check_smooth.c — FIR Gaussian taps and Gaussian smoothing of polylines, checked against
 * direct sums computed here (circular for closed curves, half-sample mirrored — scipy.ndimage
 * "reflect" — for open ones, including kernels longer than the curve). */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"
#include "testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ----------------------------------------------------------- references */

/* Unnormalized Gaussian taps exp(-i^2 / (2 sigma^2)), i = -r..r, normalized here. */
static double *ref_taps(double sigma, long *out_r)
{
    long r = (long)ceil(4.0 * sigma);
    double *w = malloc((size_t)(2 * r + 1) * sizeof *w);
    double s = 0.0;
    for (long i = -r; i <= r; i++) {
        w[i + r] = exp(-(double)(i * i) / (2.0 * sigma * sigma));
        s += w[i + r];
    }
    for (long i = 0; i < 2 * r + 1; i++)
        w[i] /= s;
    *out_r = r;
    return w;
}

static size_t wrap_index(long j, size_t n)
{
    long m = j % (long)n;
    return (size_t)(m < 0 ? m + (long)n : m);
}

/* Half-sample symmetric extension with period 2n: ... d c b a | a b c d | d c b a | a b ... */
static size_t reflect_index(long j, size_t n)
{
    long p = 2 * (long)n;
    long m = j % p;
    if (m < 0)
        m += p;
    return (size_t)(m < (long)n ? m : p - 1 - m);
}

static void ref_smooth(const double *xy, size_t n, int closed, double sigma, double *out)
{
    long r;
    double *w = ref_taps(sigma, &r);
    for (size_t i = 0; i < n; i++) {
        double sx = 0.0, sy = 0.0;
        for (long k = -r; k <= r; k++) {
            long j = (long)i + k;
            size_t q = closed ? wrap_index(j, n) : reflect_index(j, n);
            sx += w[k + r] * xy[2 * q];
            sy += w[k + r] * xy[2 * q + 1];
        }
        out[2 * i] = sx;
        out[2 * i + 1] = sy;
    }
    free(w);
}

static double *random_points(uint64_t seed, size_t n)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    double *xy = malloc(2 * (n ? n : 1) * sizeof *xy);
    for (size_t i = 0; i < 2 * n; i++)
        xy[i] = 2.0 * amscr_test_uniform(&rng) - 1.0 + (i % 2 ? 3.0 : -5.0);
    return xy;
}

/* ------------------------------------------------------------ the kernel */

START_TEST(test_kernel_count_query)
{
    static const struct { double sigma; size_t ntaps; } cases[] = {
        {1.0, 9}, {2.5, 21}, {0.1, 3}, {0.25, 3}, {0.26, 5}, {0.5, 5}, {3.0, 25}, {1e6, 8000001},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        size_t nt = 0;
        ck_assert_int_eq(amscr_gaussian_kernel(cases[k].sigma, NULL, &nt), AMSCR_OK);
        ck_assert_msg(nt == cases[k].ntaps, "sigma %g: %zu taps, expected %zu", cases[k].sigma, nt,
                      cases[k].ntaps);
        /* The count query ignores the capacity given. */
        nt = 12345;
        ck_assert_int_eq(amscr_gaussian_kernel(cases[k].sigma, NULL, &nt), AMSCR_OK);
        ck_assert_uint_eq(nt, cases[k].ntaps);
    }
}
END_TEST

static const double kernel_sigmas[] = {0.3, 0.5, 1.0, 1.7, 2.5, 4.0, 10.0, 33.3};

START_TEST(test_kernel_values)
{
    double sigma = kernel_sigmas[_i];
    long r;
    double *ref = ref_taps(sigma, &r);
    size_t nt = (size_t)(2 * r + 1);
    double *taps = malloc(nt * sizeof *taps);
    ck_assert_int_eq(amscr_gaussian_kernel(sigma, taps, &nt), AMSCR_OK);
    ck_assert_uint_eq(nt, (size_t)(2 * r + 1));
    double sum = 0.0;
    for (long i = 0; i < 2 * r + 1; i++) {
        sum += taps[i];
        ck_assert_msg(fabs(taps[i] - ref[i]) <= 1e-14 * ref[r] + 1e-300, "sigma %g tap %ld: %.17g vs %.17g", sigma,
                      i - r, taps[i], ref[i]);
        ck_assert(taps[i] > 0.0);
        ck_assert(taps[i] <= taps[r]);
    }
    ck_assert_double_eq_tol(sum, 1.0, 1e-14);
    for (long i = 1; i <= r; i++)
        ck_assert_double_eq_tol(taps[r + i], taps[r - i], 1e-16);
    /* Ratio law: w_i / w_j = exp(-(i^2 - j^2) / (2 sigma^2)). */
    for (long i = 0; i <= r; i++) {
        for (long j = 0; j <= r; j += 3) {
            double expect = exp(-(double)(i * i - j * j) / (2.0 * sigma * sigma));
            double got = taps[r + i] / taps[r - j];
            ck_assert_msg(fabs(got / expect - 1.0) < 1e-12, "sigma %g: w%ld/w%ld = %.17g, expected %.17g", sigma,
                          i, j, got, expect);
        }
    }
    free(ref);
    free(taps);
}
END_TEST

START_TEST(test_kernel_capacity)
{
    double taps[64];
    size_t nt = 9;
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, taps, &nt), AMSCR_OK); /* exact capacity */
    ck_assert_uint_eq(nt, 9);
    nt = 64;
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, taps, &nt), AMSCR_OK); /* more than enough */
    ck_assert_uint_eq(nt, 9);

    for (int i = 0; i < 64; i++)
        taps[i] = -7.0;
    nt = 8;
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, taps, &nt), AMSCR_E_INVALID_ARG);
    ck_assert_msg(amscr_last_error_detail()[0] != '\0', "no detail for a too-small capacity");
    for (int i = 0; i < 64; i++)
        ck_assert_msg(taps[i] == -7.0, "taps[%d] written on failure", i);
    nt = 0;
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, taps, &nt), AMSCR_E_INVALID_ARG);
    nt = 20;
    ck_assert_int_eq(amscr_gaussian_kernel(2.5, taps, &nt), AMSCR_E_INVALID_ARG); /* needs 21 */
}
END_TEST

START_TEST(test_kernel_invalid)
{
    const double bad[] = {0.0, -0.0, -1.0, NAN, INFINITY, -INFINITY, 1.000001e6};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        size_t nt = 100;
        double taps[100];
        ck_assert_msg(amscr_gaussian_kernel(bad[k], NULL, &nt) == AMSCR_E_INVALID_ARG, "sigma %g accepted (query)",
                      bad[k]);
        nt = 100;
        ck_assert_msg(amscr_gaussian_kernel(bad[k], taps, &nt) == AMSCR_E_INVALID_ARG, "sigma %g accepted",
                      bad[k]);
        ck_assert(amscr_last_error_detail()[0] != '\0');
    }
    double taps[9];
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, taps, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gaussian_kernel(1.0, NULL, NULL), AMSCR_E_INVALID_ARG);
}
END_TEST

/* ------------------------------------------------------------ smoothing */

static const struct { size_t n; double sigma; } smooth_cases[] = {
    {50, 1.0},  {50, 3.7},  {200, 0.4}, {10, 5.0} /* r = 20: wraps twice */,
    {7, 12.3},  {3, 2.0},   {2, 1.5},   {1, 3.0}, {128, 0.25}, {13, 13.0},
};
#define NUM_SMOOTH_CASES (int)(sizeof smooth_cases / sizeof smooth_cases[0])

static void check_against_reference(int closed, int i)
{
    size_t n = smooth_cases[i].n;
    double sigma = smooth_cases[i].sigma;
    double *xy = random_points(1000 + (uint64_t)i, n);
    double *keep = malloc(2 * n * sizeof *keep);
    memcpy(keep, xy, 2 * n * sizeof *xy);
    double *out = malloc(2 * n * sizeof *out);
    double *ref = malloc(2 * n * sizeof *ref);
    ref_smooth(xy, n, closed, sigma, ref);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, n, closed, sigma, out), AMSCR_OK);
    for (size_t k = 0; k < 2 * n; k++)
        ck_assert_msg(fabs(out[k] - ref[k]) < 1e-12, "%s n=%zu sigma=%g: out[%zu] = %.17g, direct sum %.17g",
                      closed ? "closed" : "open", n, sigma, k, out[k], ref[k]);
    ck_assert_msg(memcmp(keep, xy, 2 * n * sizeof *xy) == 0, "input modified");
    free(xy);
    free(keep);
    free(out);
    free(ref);
}

START_TEST(test_smooth_closed_direct_sum) { check_against_reference(1, _i); }
END_TEST

START_TEST(test_smooth_open_direct_sum) { check_against_reference(0, _i); }
END_TEST

/* A sampled sinusoid is an eigenvector of circular convolution: out = G(k) * in with
 * G(k) = sum_j w_j cos(2 pi k j / n) — an analytic check of the closed case. */
START_TEST(test_smooth_closed_sinusoid_gain)
{
    const size_t n = 16;
    const double sigmas[] = {1.0, 2.5, 7.0};
    double xy[32], out[32];
    for (size_t s = 0; s < 3; s++) {
        long r;
        double *w = ref_taps(sigmas[s], &r);
        for (int k = 1; k <= 3; k++) {
            double gain = 0.0;
            for (long j = -r; j <= r; j++)
                gain += w[j + r] * cos(2.0 * M_PI * k * (double)j / (double)n);
            for (size_t i = 0; i < n; i++) {
                double t = 2.0 * M_PI * k * (double)i / (double)n;
                xy[2 * i] = 2.0 * cos(t + 0.3);
                xy[2 * i + 1] = 0.5 * sin(t);
            }
            ck_assert_int_eq(amscr_smooth_gaussian(xy, n, 1, sigmas[s], out), AMSCR_OK);
            for (size_t i = 0; i < 2 * n; i++)
                ck_assert_msg(fabs(out[i] - gain * xy[i]) < 1e-13, "sigma %g k %d: out[%zu] %.17g vs %.17g",
                              sigmas[s], k, i, out[i], gain * xy[i]);
        }
        free(w);
    }
}
END_TEST

START_TEST(test_smooth_sigma0_copies)
{
    for (int closed = 0; closed <= 1; closed++) {
        double *xy = random_points(77, 31);
        double out[62];
        ck_assert_int_eq(amscr_smooth_gaussian(xy, 31, closed, 0.0, out), AMSCR_OK);
        ck_assert(memcmp(out, xy, sizeof out) == 0);
        free(xy);
    }
}
END_TEST

START_TEST(test_smooth_constant_signal)
{
    const size_t ns[] = {1, 4, 10, 100};
    const double sigmas[] = {0.5, 5.0, 40.0};
    for (int closed = 0; closed <= 1; closed++)
        for (size_t a = 0; a < 4; a++)
            for (size_t b = 0; b < 3; b++) {
                size_t n = ns[a];
                double *xy = malloc(2 * n * sizeof *xy), *out = malloc(2 * n * sizeof *out);
                for (size_t i = 0; i < n; i++) {
                    xy[2 * i] = 3.25;
                    xy[2 * i + 1] = -1e3;
                }
                ck_assert_int_eq(amscr_smooth_gaussian(xy, n, closed, sigmas[b], out), AMSCR_OK);
                for (size_t i = 0; i < n; i++) {
                    ck_assert_double_eq_tol(out[2 * i], 3.25, 1e-13);
                    ck_assert_double_eq_tol(out[2 * i + 1], -1e3, 1e-10);
                }
                free(xy);
                free(out);
            }
}
END_TEST

START_TEST(test_smooth_closed_preserves_centroid)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 42 + (uint64_t)_i);
    const size_t n = 64;
    double xy[128], out[128];
    amscr_test_random_shape(&rng, n, 6, xy);
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] += 10.0;
        xy[2 * i + 1] -= 4.0;
    }
    const double sigma = 1.0 + 9.0 * amscr_test_uniform(&rng);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, n, 1, sigma, out), AMSCR_OK);
    double cx0 = 0, cy0 = 0, cx1 = 0, cy1 = 0;
    for (size_t i = 0; i < n; i++) {
        cx0 += xy[2 * i];
        cy0 += xy[2 * i + 1];
        cx1 += out[2 * i];
        cy1 += out[2 * i + 1];
    }
    ck_assert_double_eq_tol(cx1 / n, cx0 / n, 1e-12);
    ck_assert_double_eq_tol(cy1 / n, cy0 / n, 1e-12);
    /* Smoothing shrinks a convex-ish closed curve: the RMS radius must not grow. */
    ck_assert(amscr_test_shape_size(out, n) < amscr_test_shape_size(xy, n));
}
END_TEST

START_TEST(test_smooth_invalid)
{
    double xy[20] = {0}, out[20];
    for (int i = 0; i < 20; i++) {
        xy[i] = (double)(i * i % 7);
        out[i] = -99.0;
    }
    ck_assert_int_eq(amscr_smooth_gaussian(NULL, 10, 1, 1.0, out), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 10, 1, 1.0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 0, 1, 1.0, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 0, 0, 1.0, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 10, 1, -1.0, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 10, 0, -0.5, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 10, 1, NAN, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(xy, 10, 1, INFINITY, out), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    for (int i = 0; i < 20; i++)
        ck_assert_msg(out[i] == -99.0, "out[%d] written on failure", i);
    double big[24];
    for (int i = 0; i < 24; i++)
        big[i] = xy[i % 20];
    ck_assert_int_eq(amscr_smooth_gaussian(big, 10, 1, 1.0, big), AMSCR_E_INVALID_ARG); /* in place */
    ck_assert_int_eq(amscr_smooth_gaussian(big, 10, 1, 1.0, big + 2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_smooth_gaussian(big + 2, 10, 1, 1.0, big), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "overlaps"));
    ck_assert_int_eq(amscr_smooth_gaussian(big, 2, 1, 1.0, big + 4), AMSCR_OK); /* side by side */
}
END_TEST

Suite *amscr_suite_smooth(void)
{
    Suite *s = suite_create("smooth");
    TCase *tk = tcase_create("kernel");
    tcase_add_test(tk, test_kernel_count_query);
    tcase_add_loop_test(tk, test_kernel_values, 0, (int)(sizeof kernel_sigmas / sizeof kernel_sigmas[0]));
    tcase_add_test(tk, test_kernel_capacity);
    tcase_add_test(tk, test_kernel_invalid);
    suite_add_tcase(s, tk);

    TCase *ts = tcase_create("smooth");
    tcase_add_loop_test(ts, test_smooth_closed_direct_sum, 0, NUM_SMOOTH_CASES);
    tcase_add_loop_test(ts, test_smooth_open_direct_sum, 0, NUM_SMOOTH_CASES);
    tcase_add_test(ts, test_smooth_closed_sinusoid_gain);
    tcase_add_test(ts, test_smooth_sigma0_copies);
    tcase_add_test(ts, test_smooth_constant_signal);
    tcase_add_loop_test(ts, test_smooth_closed_preserves_centroid, 0, 4);
    tcase_add_test(ts, test_smooth_invalid);
    suite_add_tcase(s, ts);
    return s;
}
