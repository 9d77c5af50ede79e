/* check_affine.c — least-squares affine fit, apply, invert; expected values computed here. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"
#include "testutil.h"

static void random_points(amscr_test_rng *rng, size_t n, double scale, double *xy)
{
    for (size_t i = 0; i < 2 * n; i++)
        xy[i] = scale * (2.0 * amscr_test_uniform(rng) - 1.0);
}

/* Exact 3x3 solve by Cramer's rule. */
static void solve3(const double g[9], const double r[3], double x[3])
{
    double det = g[0] * (g[4] * g[8] - g[5] * g[7]) - g[1] * (g[3] * g[8] - g[5] * g[6]) +
                 g[2] * (g[3] * g[7] - g[4] * g[6]);
    for (int c = 0; c < 3; c++) {
        double h[9];
        memcpy(h, g, sizeof h);
        for (int i = 0; i < 3; i++)
            h[3 * i + c] = r[i];
        x[c] = (h[0] * (h[4] * h[8] - h[5] * h[7]) - h[1] * (h[3] * h[8] - h[5] * h[6]) +
                h[2] * (h[3] * h[7] - h[4] * h[6])) / det;
    }
}

/* Least-squares affine map by the normal equations of [x y 1] (per output coordinate). */
static void ref_fit(const double *src, const double *dst, size_t n, double m6[6])
{
    double g[9] = {0}, rx[3] = {0}, ry[3] = {0};
    for (size_t i = 0; i < n; i++) {
        double v[3] = {src[2 * i], src[2 * i + 1], 1.0};
        for (int a = 0; a < 3; a++) {
            for (int b = 0; b < 3; b++)
                g[3 * a + b] += v[a] * v[b];
            rx[a] += v[a] * dst[2 * i];
            ry[a] += v[a] * dst[2 * i + 1];
        }
    }
    solve3(g, rx, m6);
    solve3(g, ry, m6 + 3);
}

static double direct_rms(const double m6[6], const double *src, const double *dst, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        double x = src[2 * i], y = src[2 * i + 1];
        double ex = m6[0] * x + m6[1] * y + m6[2] - dst[2 * i];
        double ey = m6[3] * x + m6[4] * y + m6[5] - dst[2 * i + 1];
        s += ex * ex + ey * ey;
    }
    return sqrt(s / (double)n);
}

/* c = a o b (apply b first). */
static void compose(const double a[6], const double b[6], double c[6])
{
    c[0] = a[0] * b[0] + a[1] * b[3];
    c[1] = a[0] * b[1] + a[1] * b[4];
    c[2] = a[0] * b[2] + a[1] * b[5] + a[2];
    c[3] = a[3] * b[0] + a[4] * b[3];
    c[4] = a[3] * b[1] + a[4] * b[4];
    c[5] = a[3] * b[2] + a[4] * b[5] + a[5];
}

/* ------------------------------------------------------------------ fit */

START_TEST(test_fit_exact)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 100 + (uint64_t)_i);
    const size_t n = 10;
    double src[20], dst[20], truth[6], m6[6], rms = -1.0;
    random_points(&rng, n, 3.0, src);
    amscr_test_random_affine(&rng, 3.0, 1.0, 10.0, _i % 2, truth);
    amscr_test_apply_affine(truth, src, n, dst);
    double src0[20], dst0[20];
    memcpy(src0, src, sizeof src);
    memcpy(dst0, dst, sizeof dst);
    ck_assert_int_eq(amscr_affine_fit(src, dst, n, m6, &rms), AMSCR_OK);
    for (int k = 0; k < 6; k++)
        ck_assert_msg(fabs(m6[k] - truth[k]) < 1e-12 * (1.0 + fabs(truth[k])), "m6[%d] = %.17g, truth %.17g", k,
                      m6[k], truth[k]);
    ck_assert_double_eq_tol(rms, 0.0, 1e-12);
    ck_assert(memcmp(src, src0, sizeof src) == 0 && memcmp(dst, dst0, sizeof dst) == 0);
    /* The rms output is optional. */
    double m6b[6];
    ck_assert_int_eq(amscr_affine_fit(src, dst, n, m6b, NULL), AMSCR_OK);
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(m6b[k], m6[k], 1e-14 * (1.0 + fabs(m6[k])));
}
END_TEST

START_TEST(test_fit_three_points)
{
    /* A triangle determines the map exactly. */
    const double src[6] = {0, 0, 1, 0, 0, 1};
    const double truth[6] = {2, -1, 5, 0.5, 3, -4};
    double dst[6], m6[6], rms;
    amscr_test_apply_affine(truth, src, 3, dst);
    ck_assert_int_eq(amscr_affine_fit(src, dst, 3, m6, &rms), AMSCR_OK);
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(m6[k], truth[k], 1e-13);
    ck_assert_double_eq_tol(rms, 0.0, 1e-13);
}
END_TEST

START_TEST(test_fit_noisy)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 500 + (uint64_t)_i);
    const size_t n = 40;
    double src[80], dst[80], truth[6], m6[6], ref[6], rms;
    random_points(&rng, n, 2.0, src);
    amscr_test_random_affine(&rng, 2.0, 0.5, 5.0, 0, truth);
    amscr_test_apply_affine(truth, src, n, dst);
    amscr_test_add_noise(&rng, dst, n, 0.1);
    ck_assert_int_eq(amscr_affine_fit(src, dst, n, m6, &rms), AMSCR_OK);
    /* The least-squares optimum, from the normal equations solved here. */
    ref_fit(src, dst, n, ref);
    for (int k = 0; k < 6; k++)
        ck_assert_msg(fabs(m6[k] - ref[k]) < 1e-10, "m6[%d] = %.15g, normal equations %.15g", k, m6[k], ref[k]);
    /* The reported rms is the RMS residual distance of the returned map. */
    double direct = direct_rms(m6, src, dst, n);
    ck_assert_msg(fabs(rms - direct) < 1e-12, "rms %.15g, direct %.15g", rms, direct);
    ck_assert(rms > 0.05 && rms < 0.3); /* ~ sqrt(2) * 0.1 * sqrt((n-3)/n) */
    /* ... and no other map does better (perturb each coefficient). */
    for (int k = 0; k < 6; k++) {
        double p[6];
        memcpy(p, m6, sizeof p);
        p[k] += 1e-3;
        ck_assert(direct_rms(p, src, dst, n) > rms);
        p[k] -= 2e-3;
        ck_assert(direct_rms(p, src, dst, n) > rms);
    }
}
END_TEST

START_TEST(test_fit_errors)
{
    double line[16], dst[16], m6[6], rms;
    for (int i = 0; i < 8; i++) {
        line[2 * i] = 1.0 + i;
        line[2 * i + 1] = 2.0 - 3.0 * i;
        dst[2 * i] = (double)(i * i);
        dst[2 * i + 1] = (double)i;
    }
    for (int k = 0; k < 6; k++)
        m6[k] = 8.0;
    ck_assert_int_eq(amscr_affine_fit(line, dst, 8, m6, &rms), AMSCR_E_NUMERIC);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    for (int k = 0; k < 6; k++)
        ck_assert_msg(m6[k] == 8.0, "m6 written on failure");
    double same[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    ck_assert_int_eq(amscr_affine_fit(same, dst, 4, m6, &rms), AMSCR_E_NUMERIC);

    const double src[6] = {0, 0, 1, 0, 0, 1};
    ck_assert_int_eq(amscr_affine_fit(src, dst, 2, m6, &rms), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_affine_fit(src, dst, 0, m6, &rms), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_fit(NULL, dst, 3, m6, &rms), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_fit(src, NULL, 3, m6, &rms), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_fit(src, dst, 3, NULL, &rms), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_fit(src, dst, 3, m6, &rms), AMSCR_OK);
}
END_TEST

/* ---------------------------------------------------------------- apply */

START_TEST(test_apply)
{
    const double m6[6] = {1.5, -2.0, 3.0, 0.25, 4.0, -1.0};
    double xy[8] = {0, 0, 1, 0, 0, 1, -2, 3}, out[8];
    const double expect[8] = {3.0, -1.0, 4.5, -0.75, 1.0, 3.0, -6.0, 10.5};
    ck_assert_int_eq(amscr_affine_apply(m6, xy, 4, out), AMSCR_OK);
    for (int i = 0; i < 8; i++)
        ck_assert_double_eq_tol(out[i], expect[i], 1e-15);
    /* In place. */
    ck_assert_int_eq(amscr_affine_apply(m6, xy, 4, xy), AMSCR_OK);
    for (int i = 0; i < 8; i++)
        ck_assert_double_eq_tol(xy[i], expect[i], 1e-15);
}
END_TEST

START_TEST(test_apply_random_in_place)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 31 + (uint64_t)_i);
    const size_t n = 257;
    double *xy = malloc(2 * n * sizeof *xy), *ref = malloc(2 * n * sizeof *ref), m6[6];
    random_points(&rng, n, 10.0, xy);
    amscr_test_random_affine(&rng, 3.0, 1.0, 10.0, _i % 2, m6);
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        ref[2 * i] = m6[0] * x + m6[1] * y + m6[2];
        ref[2 * i + 1] = m6[3] * x + m6[4] * y + m6[5];
    }
    ck_assert_int_eq(amscr_affine_apply(m6, xy, n, xy), AMSCR_OK);
    for (size_t i = 0; i < 2 * n; i++)
        ck_assert_double_eq_tol(xy[i], ref[i], 1e-12);
    free(xy);
    free(ref);
}
END_TEST

START_TEST(test_apply_invalid)
{
    const double m6[6] = {1, 0, 0, 0, 1, 0};
    double xy[4] = {1, 2, 3, 4}, out[4];
    ck_assert_int_eq(amscr_affine_apply(NULL, xy, 2, out), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_affine_apply(m6, NULL, 2, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_apply(m6, xy, 2, NULL), AMSCR_E_INVALID_ARG);
}
END_TEST

/* --------------------------------------------------------------- invert */

START_TEST(test_invert_random)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 700 + (uint64_t)_i);
    double m6[6], inv[6], c[6];
    amscr_test_random_affine(&rng, 4.0, 1.5, 20.0, _i % 2, m6);
    ck_assert_int_eq(amscr_affine_invert(m6, inv), AMSCR_OK);
    /* Closed form: A^-1 = [d -b; -c a] / det, t' = -A^-1 t. */
    double det = m6[0] * m6[4] - m6[1] * m6[3];
    double e[6] = {m6[4] / det, -m6[1] / det, 0, -m6[3] / det, m6[0] / det, 0};
    e[2] = -(e[0] * m6[2] + e[1] * m6[5]);
    e[5] = -(e[3] * m6[2] + e[4] * m6[5]);
    for (int k = 0; k < 6; k++) /* bit for bit: the call's scaling by a power of 2 changes no rounding */
        ck_assert_msg(inv[k] == e[k], "inv[%d] = %.17g, expected %.17g", k, inv[k], e[k]);
    const double id[6] = {1, 0, 0, 0, 1, 0};
    compose(m6, inv, c);
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(c[k], id[k], 1e-12);
    compose(inv, m6, c);
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(c[k], id[k], 1e-12);
}
END_TEST

START_TEST(test_invert_scale_independent)
{
    /* Singularity is relative: tiny or huge but well-conditioned maps invert fine, also where the
     * determinant itself would overflow (1e300^2) or underflow (1e-200^2). */
    const double scales[] = {1e-200, 1e-4, 1e-2, 1e3, 1e6, 1e300};
    for (size_t s = 0; s < 6; s++) {
        double k = scales[s];
        const double m6[6] = {k, 0.5 * k, 1.0, -0.25 * k, k, 2.0};
        double inv[6], c[6];
        ck_assert_msg(amscr_affine_invert(m6, inv) == AMSCR_OK, "scale %g not invertible?", k);
        compose(inv, m6, c);
        ck_assert_double_eq_tol(c[0], 1.0, 1e-12);
        ck_assert_double_eq_tol(c[1], 0.0, 1e-12);
        ck_assert_double_eq_tol(c[3], 0.0, 1e-12);
        ck_assert_double_eq_tol(c[4], 1.0, 1e-12);
        ck_assert_double_eq_tol(c[2], 0.0, 1e-12);
        ck_assert_double_eq_tol(c[5], 0.0, 1e-12);
    }
    /* an inverse a double cannot hold (entries 1e-310: the inverse's would be 1e310) */
    const double tiny[6] = {1e-310, 0, 0, 0, 1e-310, 0};
    double inv[6] = {5, 5, 5, 5, 5, 5};
    ck_assert_int_eq(amscr_affine_invert(tiny, inv), AMSCR_E_DEGENERATE);
    ck_assert_msg(inv[0] == 5.0 && inv[4] == 5.0, "output written on failure");
    const double far[6] = {1e-300, 0, 1e300, 0, 1e-300, 0}; /* its inverse's translation: 1e600 */
    ck_assert_int_eq(amscr_affine_invert(far, inv), AMSCR_E_DEGENERATE);
}
END_TEST

START_TEST(test_invert_singular)
{
    const double rank1[6] = {1, 2, 3, 2, 4, 5};
    const double zero[6] = {0, 0, 1, 0, 0, 1};
    const double col0[6] = {0, 1, 0, 0, 3, 0};
    double inv[6];
    for (int k = 0; k < 6; k++)
        inv[k] = 5.0;
    ck_assert_int_eq(amscr_affine_invert(rank1, inv), AMSCR_E_DEGENERATE);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    for (int k = 0; k < 6; k++)
        ck_assert_msg(inv[k] == 5.0, "output written on failure");
    ck_assert_int_eq(amscr_affine_invert(zero, inv), AMSCR_E_DEGENERATE);
    ck_assert_int_eq(amscr_affine_invert(col0, inv), AMSCR_E_DEGENERATE);
    const double nanm[6] = {NAN, 0, 0, 0, 1, 0};
    ck_assert_int_ne(amscr_affine_invert(nanm, inv), AMSCR_OK);
    const double id[6] = {1, 0, 0, 0, 1, 0};
    ck_assert_int_eq(amscr_affine_invert(NULL, inv), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_affine_invert(id, NULL), AMSCR_E_INVALID_ARG);
}
END_TEST

Suite *amscr_suite_affine(void)
{
    Suite *s = suite_create("affine");
    TCase *tf = tcase_create("fit");
    tcase_add_loop_test(tf, test_fit_exact, 0, 8);
    tcase_add_test(tf, test_fit_three_points);
    tcase_add_loop_test(tf, test_fit_noisy, 0, 5);
    tcase_add_test(tf, test_fit_errors);
    suite_add_tcase(s, tf);

    TCase *ta = tcase_create("apply_invert");
    tcase_add_test(ta, test_apply);
    tcase_add_loop_test(ta, test_apply_random_in_place, 0, 3);
    tcase_add_test(ta, test_apply_invalid);
    tcase_add_loop_test(ta, test_invert_random, 0, 8);
    tcase_add_test(ta, test_invert_scale_independent);
    tcase_add_test(ta, test_invert_singular);
    suite_add_tcase(s, ta);
    return s;
}
