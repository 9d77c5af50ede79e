/* check_gmm1d.c — 1-D Gaussian mixture (EM) and the Bayes threshold. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "internal.h"
#include "suites.h"
#include "testutil.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---------------------------------------------------------------- helpers */

/* n samples of a mixture (component i with probability w[i]). */
static double *sample_mixture(uint64_t seed, size_t n, size_t k, const double *w, const double *mu,
                              const double *sd)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, seed);
    double *x = malloc(n * sizeof *x);
    ck_assert_ptr_nonnull(x);
    for (size_t i = 0; i < n; i++) {
        double u = amscr_test_uniform(&r), acc = 0.0;
        size_t c = 0;
        for (; c + 1 < k; c++) {
            acc += w[c];
            if (u < acc)
                break;
        }
        x[i] = mu[c] + sd[c] * amscr_test_normal(&r);
    }
    return x;
}

/* Log-likelihood of x under a mixture, computed directly. */
static double loglik(const double *x, size_t n, size_t k, const double *w, const double *mu, const double *var)
{
    double ll = 0.0;
    for (size_t i = 0; i < n; i++) {
        double p = 0.0;
        for (size_t c = 0; c < k; c++)
            p += w[c] * exp(-0.5 * (x[i] - mu[c]) * (x[i] - mu[c]) / var[c]) / sqrt(2.0 * M_PI * var[c]);
        ll += log(p);
    }
    return ll;
}

/* Fits a k-component model and returns it. */
static amscr_gmm1d *fit(const double *x, size_t n, size_t k)
{
    amscr_gmm1d *g = NULL;
    ck_assert_int_eq(amscr_gmm1d_new(k, &g), AMSCR_OK);
    amscr_status st = amscr_gmm1d_fit(g, x, n);
    ck_assert_msg(st == AMSCR_OK, "fit: %d %s", (int)st, amscr_last_error_detail());
    return g;
}

/* log(w1 N(s; mu1, v1)) - log(w2 N(s; mu2, v2)). */
static double log_ratio(double s, double w1, double mu1, double v1, double w2, double mu2, double v2)
{
    return log(w1) - 0.5 * log(v1) - 0.5 * (s - mu1) * (s - mu1) / v1 - log(w2) + 0.5 * log(v2) +
           0.5 * (s - mu2) * (s - mu2) / v2;
}

/* ---------------------------------------------------------------- EM */

START_TEST(em_two_components)
{
    const double w[2] = {0.3, 0.7}, mu[2] = {-2.0, 3.0}, sd[2] = {0.5, 1.5};
    size_t n = 20000;
    double *x = sample_mixture(11, n, 2, w, mu, sd);
    amscr_gmm1d *g = fit(x, n, 2);
    const double *fw = amscr_gmm1d_weights(g), *fm = amscr_gmm1d_means(g), *fv = amscr_gmm1d_variances(g);
    for (int c = 0; c < 2; c++) {
        ck_assert_double_eq_tol(fw[c], w[c], 0.015);
        ck_assert_double_eq_tol(fm[c], mu[c], 0.05);
        ck_assert_double_eq_tol(fv[c], sd[c] * sd[c], 0.08 * sd[c] * sd[c]);
    }
    ck_assert_double_eq_tol(fw[0] + fw[1], 1.0, 1e-12);
    ck_assert_int_eq(amscr_gmm1d_converged(g), 1);
    ck_assert_uint_ge(amscr_gmm1d_iterations(g), 1);
    ck_assert_uint_le(amscr_gmm1d_iterations(g), 200);
    double ll = loglik(x, n, 2, fw, fm, fv);
    ck_assert_double_eq_tol(amscr_gmm1d_loglik(g), ll, 1e-9 * fabs(ll));
    /* The truth does not beat the fit by more than rounding. */
    double vt[2] = {sd[0] * sd[0], sd[1] * sd[1]};
    ck_assert(amscr_gmm1d_loglik(g) >= loglik(x, n, 2, w, mu, vt) - 1e-6);
    amscr_gmm1d_free(g);
    free(x);
}
END_TEST

START_TEST(em_three_components)
{
    const double w[3] = {0.2, 0.5, 0.3}, mu[3] = {0.0, 5.0, 12.0}, sd[3] = {1.0, 0.8, 2.0};
    size_t n = 20000;
    double *x = sample_mixture(12, n, 3, w, mu, sd);
    amscr_gmm1d *g = fit(x, n, 3);
    const double *fw = amscr_gmm1d_weights(g), *fm = amscr_gmm1d_means(g), *fv = amscr_gmm1d_variances(g);
    for (int c = 0; c < 3; c++) {
        ck_assert_double_eq_tol(fw[c], w[c], 0.015);
        ck_assert_double_eq_tol(fm[c], mu[c], 0.06);
        ck_assert_double_eq_tol(fv[c], sd[c] * sd[c], 0.08 * sd[c] * sd[c]);
    }
    ck_assert(fm[0] < fm[1] && fm[1] < fm[2]);
    ck_assert_int_eq(amscr_gmm1d_converged(g), 1);
    double ll = loglik(x, n, 3, fw, fm, fv);
    ck_assert_double_eq_tol(amscr_gmm1d_loglik(g), ll, 1e-9 * fabs(ll));

    /* Posterior: sums to 1 and matches the direct formula. */
    const double at[] = {-3.0, 2.7, 5.0, 8.4, 30.0};
    for (size_t t = 0; t < sizeof at / sizeof at[0]; t++) {
        double post[3], dens[3], tot = 0.0;
        ck_assert_int_eq(amscr_gmm1d_posterior(g, at[t], post), AMSCR_OK);
        for (int c = 0; c < 3; c++) {
            dens[c] = fw[c] * exp(-0.5 * (at[t] - fm[c]) * (at[t] - fm[c]) / fv[c]) / sqrt(fv[c]);
            tot += dens[c];
        }
        for (int c = 0; c < 3; c++)
            ck_assert_double_eq_tol(post[c], dens[c] / tot, 1e-12);
    }
    double post[3];
    ck_assert_int_eq(amscr_gmm1d_posterior(g, -1e6, post), AMSCR_OK); /* far: no underflow to 0/0 */
    ck_assert(isfinite(post[0]) && isfinite(post[1]) && isfinite(post[2]));
    ck_assert_double_eq_tol(post[0] + post[1] + post[2], 1.0, 1e-12);

    /* The input order does not matter (the data are sorted internally). */
    double *y = malloc(n * sizeof *y);
    ck_assert_ptr_nonnull(y);
    for (size_t i = 0; i < n; i++)
        y[i] = x[(i * 7919) % n]; /* a permutation: 7919 is prime and does not divide 20000 */
    amscr_gmm1d *g2 = fit(y, n, 3);
    ck_assert_int_eq(memcmp(amscr_gmm1d_means(g2), fm, 3 * sizeof(double)), 0);
    ck_assert_int_eq(memcmp(amscr_gmm1d_variances(g2), fv, 3 * sizeof(double)), 0);
    ck_assert(amscr_gmm1d_loglik(g2) == amscr_gmm1d_loglik(g));
    amscr_gmm1d_free(g2);
    free(y);

    /* Iteration cap: one iteration, not converged, still AMSCR_OK. */
    amscr_gmm1d *g3 = NULL;
    ck_assert_int_eq(amscr_gmm1d_new(3, &g3), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_set_max_iterations(g3, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_set_tolerance(g3, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_fit(g3, x, n), AMSCR_OK);
    ck_assert_uint_eq(amscr_gmm1d_iterations(g3), 1);
    ck_assert_int_eq(amscr_gmm1d_converged(g3), 0);
    amscr_gmm1d_free(g3);
    amscr_gmm1d_free(g);
    free(x);
}
END_TEST

START_TEST(variance_floor)
{
    /* 50 identical values and 50 spread ones: the first component sits on the
     * identical values with variance = floor (1e-6 * data variance), finite. */
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 5);
    double x[100];
    for (int i = 0; i < 100; i++)
        x[i] = i < 50 ? 3.0 : 10.0 + amscr_test_normal(&r);
    double m = 0.0, v = 0.0;
    for (int i = 0; i < 100; i++)
        m += x[i];
    m /= 100;
    for (int i = 0; i < 100; i++)
        v += (x[i] - m) * (x[i] - m);
    v /= 100;
    amscr_gmm1d *g = fit(x, 100, 2);
    const double *fw = amscr_gmm1d_weights(g), *fm = amscr_gmm1d_means(g), *fv = amscr_gmm1d_variances(g);
    ck_assert_double_eq(fm[0], 3.0);
    ck_assert_double_eq_tol(fv[0], 1e-6 * v, 1e-12 * v);
    ck_assert_double_eq_tol(fw[0], 0.5, 1e-9);
    ck_assert(isfinite(amscr_gmm1d_loglik(g)));
    double t;
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 1, &t), AMSCR_OK);
    ck_assert(t > 3.0 && t < fm[1]);
    amscr_gmm1d_free(g);

    /* All values identical: every component collapses, nothing is NaN. */
    double same[20];
    for (int i = 0; i < 20; i++)
        same[i] = -7.5;
    for (size_t k = 1; k <= 3; k++) {
        g = fit(same, 20, k);
        fw = amscr_gmm1d_weights(g);
        fm = amscr_gmm1d_means(g);
        fv = amscr_gmm1d_variances(g);
        double wsum = 0.0;
        for (size_t c = 0; c < k; c++) {
            ck_assert_double_eq(fm[c], -7.5);
            ck_assert_double_eq_tol(fv[c], 1e-300 * 7.5 * 7.5, 1e-310);
            ck_assert(fv[c] > 0.0 && isfinite(fw[c]));
            wsum += fw[c];
        }
        ck_assert_double_eq_tol(wsum, 1.0, 1e-12);
        ck_assert(isfinite(amscr_gmm1d_loglik(g)));
        double post[3];
        ck_assert_int_eq(amscr_gmm1d_posterior(g, -7.5, post), AMSCR_OK);
        ck_assert(isfinite(post[0]));
        amscr_gmm1d_free(g);
    }
    /* Values near 0: the absolute floor is 1e-300. */
    double zeros[4] = {0, 0, 0, 0};
    g = fit(zeros, 4, 2);
    ck_assert_double_eq(amscr_gmm1d_variances(g)[0], 1e-300);
    ck_assert(isfinite(amscr_gmm1d_loglik(g)));
    amscr_gmm1d_free(g);
}
END_TEST

START_TEST(small_fit_equals_object)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 400 + (uint64_t)_i);
    size_t n = _i == 9 ? 3000 : 6 + (size_t)_i * 6; /* 6..54, and one large case */
    double *x = malloc(n * sizeof *x);
    ck_assert_ptr_nonnull(x);
    for (size_t i = 0; i < n; i++)
        x[i] = (i % 3 == 0 ? 0.001 : 0.02) * (1.0 + amscr_test_uniform(&r)) + (i % 5 == 0 ? 0.05 : 0.0);
    for (size_t k = 1; k <= 5 && k <= n; k++) {
        amscr_gmm1d *g = NULL;
        ck_assert_int_eq(amscr_gmm1d_new(k, &g), AMSCR_OK);
        ck_assert_int_eq(amscr_gmm1d_set_max_iterations(g, 50), AMSCR_OK);
        ck_assert_int_eq(amscr_gmm1d_set_tolerance(g, 1e-8), AMSCR_OK);
        ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, 1e-4), AMSCR_OK);
        ck_assert_int_eq(amscr_gmm1d_fit(g, x, n), AMSCR_OK);
        double *scratch = malloc(amscr__gmm1d_small_scratch(n, k) * sizeof *scratch);
        ck_assert_ptr_nonnull(scratch);
        double w[5], mu[5], var[5], ll = 0.0;
        unsigned it = 0;
        int conv = -1;
        ck_assert_int_eq(amscr__gmm1d_fit_small(x, n, k, 50, 1e-8, 1e-4, w, mu, var, scratch, &it, &conv, &ll),
                         AMSCR_OK);
        ck_assert_int_eq(memcmp(w, amscr_gmm1d_weights(g), k * sizeof(double)), 0);
        ck_assert_int_eq(memcmp(mu, amscr_gmm1d_means(g), k * sizeof(double)), 0);
        ck_assert_int_eq(memcmp(var, amscr_gmm1d_variances(g), k * sizeof(double)), 0);
        ck_assert(ll == amscr_gmm1d_loglik(g));
        ck_assert_uint_eq(it, amscr_gmm1d_iterations(g));
        ck_assert_int_eq(conv, amscr_gmm1d_converged(g));
        /* Optional outputs may be NULL. */
        ck_assert_int_eq(amscr__gmm1d_fit_small(x, n, k, 50, 1e-8, 1e-4, w, mu, var, scratch, NULL, NULL, NULL),
                         AMSCR_OK);
        free(scratch);
        amscr_gmm1d_free(g);
    }
    free(x);
}
END_TEST

START_TEST(small_fit_invalid)
{
    double x[4] = {1, 2, 3, 4}, w[17], mu[17], var[17], scratch[1000];
    ck_assert_int_eq(amscr__gmm1d_fit_small(x, 4, 5, 10, 0, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__gmm1d_fit_small(x, 4, 0, 10, 0, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__gmm1d_fit_small(NULL, 4, 2, 10, 0, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__gmm1d_fit_small(x, 4, 2, 0, 0, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__gmm1d_fit_small(x, 4, 2, 10, -1, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__gmm1d_fit_small(x, 4, 2, 10, 0, 2, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    double y[20];
    for (int i = 0; i < 20; i++)
        y[i] = i;
    ck_assert_int_eq(amscr__gmm1d_fit_small(y, 20, 17, 10, 0, 0, w, mu, var, scratch, NULL, NULL, NULL),
                     AMSCR_E_INVALID_ARG);
    ck_assert_uint_le(amscr__gmm1d_small_scratch(20, 16), 1000);
    ck_assert_int_eq(amscr__gmm1d_fit_small(y, 20, 16, 10, 0, 0, w, mu, var, scratch, NULL, NULL, NULL), AMSCR_OK);
}
END_TEST

/* ---------------------------------------------------------------- Bayes threshold */

START_TEST(bayes_equal_variances)
{
    /* s = (mu1+mu2)/2 + var ln(w1/w2) / (mu2 - mu1). */
    double s = 0.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.3, 1.0, 0.5, 0.7, 4.0, 0.5, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 2.5 + 0.5 * log(0.3 / 0.7) / 3.0, 1e-12);
    /* Roles swapped: the same point. */
    double s2 = 0.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.7, 4.0, 0.5, 0.3, 1.0, 0.5, &s2), AMSCR_OK);
    ck_assert_double_eq_tol(s2, s, 1e-12);
    /* Equal weights: the midpoint exactly. */
    ck_assert_int_eq(amscr_bayes_threshold(0.5, -1.0, 2.0, 0.5, 3.0, 2.0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 1.0, 1e-15);
    /* Variances equal to 1e-13 relative: treated as equal (linear). */
    ck_assert_int_eq(amscr_bayes_threshold(0.3, 1.0, 0.5, 0.7, 4.0, 0.5 * (1 + 1e-13), &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 2.5 + 0.5 * log(0.3 / 0.7) / 3.0, 1e-9);
}
END_TEST

START_TEST(bayes_unequal_variances)
{
    /* w1 = w2 = 1/2, mu1 = 0, var1 = 1, mu2 = 3, var2 = 4. Equal log-densities:
     *   -s^2/2 = -ln(2) - (s-3)^2/8          (the -ln(sqrt(2 pi)) terms cancel; ln sqrt 4 = ln 2)
     *   -4 s^2 = -8 ln 2 - (s^2 - 6 s + 9)
     *   3 s^2 + 6 s - (9 + 8 ln 2) = 0
     *   s = -1 +- sqrt(36 + 12 (9 + 8 ln 2)) / 6 = -1 +- sqrt(144 + 96 ln 2) / 6
     * = 1.41835... (between the means) or -3.418... (outside). */
    double want = -1.0 + sqrt(144.0 + 96.0 * log(2.0)) / 6.0;
    double s = 0.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0.0, 1.0, 0.5, 3.0, 4.0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, want, 1e-12);
    ck_assert_double_eq_tol(s, 1.41835, 1e-5);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 3.0, 4.0, 0.5, 0.0, 1.0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, want, 1e-12);
    /* Shifted far from 0 (cancellation): the same offset from mu1. */
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 1e6, 1.0, 0.5, 1e6 + 3.0, 4.0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s - 1e6, want, 1e-8);
    /* Tiny scales (the registration's residuals): scaled by 1e-4 in mu, 1e-8 in var. */
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0.0, 1e-8, 0.5, 3e-4, 4e-8, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, want * 1e-4, 1e-15);
}
END_TEST

START_TEST(bayes_no_root)
{
    /* Equal variances, the crossing at 0.5 + ln(0.01/0.99) = -4.1 lies outside [0, 1]. */
    double s = 123.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.01, 0.0, 1.0, 0.99, 1.0, 1.0, &s), AMSCR_E_NOT_FOUND);
    ck_assert_double_eq(s, 0.5);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    /* Unequal variances with a negative discriminant: a small narrow component under a
     * heavy wide one (w1 N1 < w2 N2 everywhere). */
    s = 123.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.001, 0.0, 1.0, 0.999, 0.5, 4.0, &s), AMSCR_E_NOT_FOUND);
    ck_assert_double_eq(s, 0.25);
    /* Equal means. */
    s = 0.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 2.0, 1.0, 0.5, 2.0, 3.0, &s), AMSCR_E_NOT_FOUND);
    ck_assert_double_eq(s, 2.0);
}
END_TEST

/* Random parameter sets against a sign scan of the log ratio. */
START_TEST(bayes_random)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 900 + (uint64_t)_i);
    double w1 = 0.02 + amscr_test_uniform(&r), w2 = 0.02 + amscr_test_uniform(&r);
    double mu1 = 10 * (amscr_test_uniform(&r) - 0.5), mu2 = mu1 + 0.1 + 5 * amscr_test_uniform(&r);
    double v1 = 0.01 + 3 * amscr_test_uniform(&r), v2 = 0.01 + 3 * amscr_test_uniform(&r);
    /* Sign changes of the log ratio strictly inside (mu1, mu2). */
    int changes = 0;
    const int steps = 20000;
    double prev = log_ratio(mu1, w1, mu1, v1, w2, mu2, v2);
    for (int i = 1; i <= steps; i++) {
        double t = mu1 + (mu2 - mu1) * i / steps;
        double f = log_ratio(t, w1, mu1, v1, w2, mu2, v2);
        if ((f > 0) != (prev > 0))
            changes++;
        prev = f;
    }
    double s = NAN;
    amscr_status st = amscr_bayes_threshold(w1, mu1, v1, w2, mu2, v2, &s);
    if (changes == 0) {
        ck_assert_int_eq(st, AMSCR_E_NOT_FOUND);
        ck_assert_double_eq(s, 0.5 * mu1 + 0.5 * mu2);
    } else {
        ck_assert_int_eq(st, AMSCR_OK);
        ck_assert(s > mu1 && s < mu2);
        ck_assert_double_eq_tol(log_ratio(s, w1, mu1, v1, w2, mu2, v2), 0.0, 1e-9);
    }
}
END_TEST

START_TEST(bayes_invalid)
{
    double s = 42.0;
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 1, 0.5, 1, 1, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.0, 0, 1, 0.5, 1, 1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 1, -0.5, 1, 1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 0, 0.5, 1, 1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 1, 0.5, 1, -1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, NAN, 1, 0.5, 1, 1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 1, INFINITY, 1, 1, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_bayes_threshold(0.5, 0, 1, 0.5, 1, NAN, &s), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_double_eq(s, 42.0);
}
END_TEST

/* ---------------------------------------------------------------- object API */

START_TEST(object_api)
{
    amscr_gmm1d *g = NULL;
    ck_assert_int_eq(amscr_gmm1d_new(0, &g), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_new(SIZE_MAX / 64 + 1, &g), AMSCR_E_INVALID_ARG); /* its arrays' size overflows */
    ck_assert_ptr_null(g);
    ck_assert_int_eq(amscr_gmm1d_new(2, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_new(2, &g), AMSCR_OK);
    ck_assert_uint_eq(amscr_gmm1d_get_max_iterations(g), 200);
    ck_assert_double_eq(amscr_gmm1d_get_tolerance(g), 1e-10);
    ck_assert_double_eq(amscr_gmm1d_get_variance_floor(g), 1e-6);
    ck_assert_uint_eq(amscr_gmm1d_num_components(g), 2);
    ck_assert_ptr_null(amscr_gmm1d_weights(g));
    ck_assert_ptr_null(amscr_gmm1d_means(g));
    ck_assert_ptr_null(amscr_gmm1d_variances(g));
    ck_assert(isnan(amscr_gmm1d_loglik(g)));
    ck_assert_uint_eq(amscr_gmm1d_iterations(g), 0);
    ck_assert_int_eq(amscr_gmm1d_converged(g), 0);
    double post[2], t;
    ck_assert_int_eq(amscr_gmm1d_posterior(g, 0.0, post), AMSCR_E_STATE);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 1, &t), AMSCR_E_STATE);

    ck_assert_int_eq(amscr_gmm1d_set_max_iterations(g, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_max_iterations(g, 300), AMSCR_OK);
    ck_assert_uint_eq(amscr_gmm1d_get_max_iterations(g), 300);
    ck_assert_int_eq(amscr_gmm1d_set_tolerance(g, -1e-3), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_tolerance(g, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_tolerance(g, 1e-9), AMSCR_OK);
    ck_assert_double_eq(amscr_gmm1d_get_tolerance(g), 1e-9);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, -0.1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, 1.5), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(g, 1e-3), AMSCR_OK);
    ck_assert_double_eq(amscr_gmm1d_get_variance_floor(g), 1e-3);
    ck_assert_int_eq(amscr_gmm1d_set_max_iterations(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_tolerance(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_set_variance_floor(NULL, 0.1), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(amscr_gmm1d_get_max_iterations(NULL), 0);
    ck_assert_double_eq(amscr_gmm1d_get_tolerance(NULL), 0.0);
    ck_assert_double_eq(amscr_gmm1d_get_variance_floor(NULL), 0.0);
    ck_assert_uint_eq(amscr_gmm1d_num_components(NULL), 0);
    ck_assert_ptr_null(amscr_gmm1d_weights(NULL));
    ck_assert(isnan(amscr_gmm1d_loglik(NULL)));
    amscr_gmm1d_free(NULL);

    double x[6] = {0.0, 0.1, 0.2, 5.0, 5.1, 5.3};
    ck_assert_int_eq(amscr_gmm1d_fit(NULL, x, 6), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_fit(g, NULL, 6), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_fit(g, x, 1), AMSCR_E_INVALID_ARG);
    x[2] = NAN;
    ck_assert_int_eq(amscr_gmm1d_fit(g, x, 6), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(amscr_gmm1d_means(g));
    x[2] = 0.2;
    ck_assert_int_eq(amscr_gmm1d_fit(g, x, 6), AMSCR_OK);
    ck_assert_str_eq(amscr_last_error_detail(), "");
    const double *fw = amscr_gmm1d_weights(g), *fm = amscr_gmm1d_means(g), *fv = amscr_gmm1d_variances(g);
    ck_assert_double_eq_tol(fw[0], 0.5, 1e-9);
    ck_assert_double_eq_tol(fm[0], 0.1, 1e-9);
    ck_assert_double_eq_tol(fm[1], 15.4 / 3.0, 1e-9);
    ck_assert_double_eq_tol(fv[0], 0.02 / 3.0, 1e-9);
    /* values too spread for the likelihood in a double: AMSCR_E_NUMERIC, the last fit kept */
    double wide[6] = {1e200, -1e200, 1e200, -1e200, 0.0, 1.0};
    ck_assert_int_eq(amscr_gmm1d_fit(g, wide, 6), AMSCR_E_NUMERIC);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_double_eq_tol(amscr_gmm1d_means(g)[0], 0.1, 1e-9);

    /* Thresholds of a fitted mixture = amscr_bayes_threshold of its components. */
    double t2;
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 1, &t), AMSCR_OK);
    ck_assert_int_eq(amscr_bayes_threshold(fw[0], fm[0], fv[0], fw[1], fm[1], fv[1], &t2), AMSCR_OK);
    ck_assert(t == t2);
    ck_assert(t > 0.2 && t < 5.0);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 1, 0, &t2), AMSCR_OK);
    ck_assert_double_eq_tol(t2, t, 1e-12);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 0, &t), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 2, &t), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(g, 0, 1, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_bayes_threshold(NULL, 0, 1, &t), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_posterior(g, NAN, post), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_posterior(g, 0.0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_posterior(NULL, 0.0, post), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_gmm1d_posterior(g, 0.1, post), AMSCR_OK);
    ck_assert(post[0] > 0.999999);
    /* A failed refit keeps the previous fit. */
    x[0] = INFINITY;
    ck_assert_int_eq(amscr_gmm1d_fit(g, x, 6), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_nonnull(amscr_gmm1d_means(g));
    amscr_gmm1d_free(g);
}
END_TEST

Suite *amscr_suite_gmm1d(void)
{
    Suite *s = suite_create("gmm1d");
    TCase *tc = tcase_create("em");
    tcase_add_test(tc, em_two_components);
    tcase_add_test(tc, em_three_components);
    tcase_add_test(tc, variance_floor);
    tcase_add_loop_test(tc, small_fit_equals_object, 0, 10);
    tcase_add_test(tc, small_fit_invalid);
    tcase_add_test(tc, object_api);
    suite_add_tcase(s, tc);
    TCase *tb = tcase_create("bayes");
    tcase_add_test(tb, bayes_equal_variances);
    tcase_add_test(tb, bayes_unequal_variances);
    tcase_add_test(tb, bayes_no_root);
    tcase_add_loop_test(tb, bayes_random, 0, 200);
    tcase_add_test(tb, bayes_invalid);
    suite_add_tcase(s, tb);
    return s;
}
