/* check_lstsq.c — Householder QR least squares against normal equations solved here. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"
#include "testutil.h"

/* Solves the n x n system g x = r (r has nrhs columns, row-major) by Gaussian elimination
 * with partial pivoting; g and r are overwritten, the solution is left in r. */
static void gauss_solve(double *g, size_t n, double *r, size_t nrhs)
{
    for (size_t c = 0; c < n; c++) {
        size_t piv = c;
        for (size_t i = c + 1; i < n; i++)
            if (fabs(g[i * n + c]) > fabs(g[piv * n + c]))
                piv = i;
        if (piv != c) {
            for (size_t j = 0; j < n; j++) {
                double t = g[c * n + j];
                g[c * n + j] = g[piv * n + j];
                g[piv * n + j] = t;
            }
            for (size_t j = 0; j < nrhs; j++) {
                double t = r[c * nrhs + j];
                r[c * nrhs + j] = r[piv * nrhs + j];
                r[piv * nrhs + j] = t;
            }
        }
        for (size_t i = c + 1; i < n; i++) {
            double f = g[i * n + c] / g[c * n + c];
            for (size_t j = c; j < n; j++)
                g[i * n + j] -= f * g[c * n + j];
            for (size_t j = 0; j < nrhs; j++)
                r[i * nrhs + j] -= f * r[c * nrhs + j];
        }
    }
    for (size_t c = n; c-- > 0;) {
        for (size_t j = 0; j < nrhs; j++) {
            double s = r[c * nrhs + j];
            for (size_t k = c + 1; k < n; k++)
                s -= g[c * n + k] * r[k * nrhs + j];
            r[c * nrhs + j] = s / g[c * n + c];
        }
    }
}

/* x = (A^T A)^-1 A^T b. */
static void normal_equations(const double *a, size_t m, size_t n, const double *b, size_t nrhs, double *x)
{
    double *g = calloc(n * n, sizeof *g);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            for (size_t k = 0; k < m; k++)
                g[i * n + j] += a[k * n + i] * a[k * n + j];
    memset(x, 0, n * nrhs * sizeof *x);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < nrhs; j++)
            for (size_t k = 0; k < m; k++)
                x[i * nrhs + j] += a[k * n + i] * b[k * nrhs + j];
    gauss_solve(g, n, x, nrhs);
    free(g);
}

static double residual_norm(const double *a, size_t m, size_t n, const double *b, size_t nrhs, const double *x,
                            size_t col)
{
    double s = 0.0;
    for (size_t k = 0; k < m; k++) {
        double r = -b[k * nrhs + col];
        for (size_t i = 0; i < n; i++)
            r += a[k * n + i] * x[i * nrhs + col];
        s += r * r;
    }
    return sqrt(s);
}

static void fill_normal(amscr_test_rng *rng, double *v, size_t count)
{
    for (size_t i = 0; i < count; i++)
        v[i] = amscr_test_normal(rng);
}

START_TEST(test_lstsq_random_vs_normal_equations)
{
    enum { M = 50, N = 4, R = 3 };
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 10 + (uint64_t)_i);
    double a[M * N], b[M * R], a0[M * N], b0[M * R], x[N * R], xr[N * R], res[R];
    fill_normal(&rng, a, M * N);
    fill_normal(&rng, b, M * R);
    for (size_t k = 0; k < M * R; k++)
        b[k] = 3.0 * b[k] + 1.0;
    memcpy(a0, a, sizeof a);
    memcpy(b0, b, sizeof b);
    ck_assert_int_eq(amscr_lstsq_qr(a, M, N, b, R, x, res), AMSCR_OK);
    ck_assert_msg(memcmp(a, a0, sizeof a) == 0, "a was modified");
    ck_assert_msg(memcmp(b, b0, sizeof b) == 0, "b was modified");
    normal_equations(a, M, N, b, R, xr);
    for (size_t k = 0; k < N * R; k++)
        ck_assert_msg(fabs(x[k] - xr[k]) < 1e-10, "x[%zu] = %.15g, normal equations %.15g", k, x[k], xr[k]);
    for (size_t j = 0; j < R; j++) {
        double direct = residual_norm(a, M, N, b, R, xr, j);
        ck_assert_msg(fabs(res[j] - direct) < 1e-10 * direct, "residual %zu: %.15g, direct %.15g", j, res[j],
                      direct);
        ck_assert(direct > 1.0); /* an inconsistent system: the residual check means something */
    }
    /* The residual argument may be NULL; x is the same. */
    double x2[N * R];
    ck_assert_int_eq(amscr_lstsq_qr(a, M, N, b, R, x2, NULL), AMSCR_OK);
    for (size_t k = 0; k < N * R; k++)
        ck_assert_double_eq_tol(x2[k], x[k], 1e-14);
}
END_TEST

START_TEST(test_lstsq_exact_system)
{
    /* b = A x_true exactly (columns scaled over six orders of magnitude). */
    enum { M = 30, N = 5, R = 2 };
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 99 + (uint64_t)_i);
    double a[M * N], xt[N * R], b[M * R], x[N * R], res[R];
    fill_normal(&rng, a, M * N);
    const double colscale[N] = {1e-3, 1.0, 1e3, 0.5, 20.0};
    for (size_t k = 0; k < M; k++)
        for (size_t i = 0; i < N; i++)
            a[k * N + i] *= colscale[i];
    for (size_t i = 0; i < N; i++)
        for (size_t j = 0; j < R; j++)
            xt[i * R + j] = amscr_test_normal(&rng) / colscale[i];
    double bnorm = 0.0;
    for (size_t k = 0; k < M; k++)
        for (size_t j = 0; j < R; j++) {
            double s = 0.0;
            for (size_t i = 0; i < N; i++)
                s += a[k * N + i] * xt[i * R + j];
            b[k * R + j] = s;
            bnorm += s * s;
        }
    bnorm = sqrt(bnorm);
    ck_assert_int_eq(amscr_lstsq_qr(a, M, N, b, R, x, res), AMSCR_OK);
    for (size_t i = 0; i < N; i++)
        for (size_t j = 0; j < R; j++)
            ck_assert_msg(fabs(x[i * R + j] * colscale[i] - xt[i * R + j] * colscale[i]) < 1e-9,
                          "x[%zu][%zu] = %.15g, expected %.15g", i, j, x[i * R + j], xt[i * R + j]);
    for (size_t j = 0; j < R; j++)
        ck_assert_msg(res[j] < 1e-11 * bnorm, "residual %zu = %g of ||b|| %g", j, res[j], bnorm);
}
END_TEST

START_TEST(test_lstsq_square_and_small)
{
    /* Square: the exact solution of a 3 x 3 system. */
    const double a[9] = {2, 1, 0, 1, 3, 1, 0, 1, 4};
    const double b[3] = {3, 5, 5}; /* x = (1, 1, 1) */
    double x[3], res[1];
    ck_assert_int_eq(amscr_lstsq_qr(a, 3, 3, b, 1, x, res), AMSCR_OK);
    for (int i = 0; i < 3; i++)
        ck_assert_double_eq_tol(x[i], 1.0, 1e-14);
    ck_assert_double_eq_tol(res[0], 0.0, 1e-13);

    /* n = 1: x = a.b / a.a, residual = |b - a x|. */
    const double c[4] = {1, 2, 3, 4}, d[8] = {1, -1, 2, 0, 2, 1, 5, 2}; /* two right-hand sides */
    double y[2], r2[2];
    ck_assert_int_eq(amscr_lstsq_qr(c, 4, 1, d, 2, y, r2), AMSCR_OK);
    ck_assert_double_eq_tol(y[0], (1 + 4 + 6 + 20) / 30.0, 1e-14);
    ck_assert_double_eq_tol(y[1], (-1 + 0 + 3 + 8) / 30.0, 1e-14);
    for (int j = 0; j < 2; j++) {
        double s = 0.0;
        for (int k = 0; k < 4; k++) {
            double e = d[2 * k + j] - c[k] * y[j];
            s += e * e;
        }
        ck_assert_double_eq_tol(r2[j], sqrt(s), 1e-13);
    }

    /* Line fit y = p + q t through 4 points (row-major [1 t]). */
    const double t[4] = {0, 1, 2, 3}, yy[4] = {1, 3, 2, 5};
    double l[8];
    for (int k = 0; k < 4; k++) {
        l[2 * k] = 1.0;
        l[2 * k + 1] = t[k];
    }
    double pq[2], rl;
    ck_assert_int_eq(amscr_lstsq_qr(l, 4, 2, yy, 1, pq, &rl), AMSCR_OK);
    /* Closed form: q = cov(t, y)/var(t) = 1.1, p = mean(y) - q mean(t) = 2.75 - 1.65 = 1.1. */
    ck_assert_double_eq_tol(pq[1], 1.1, 1e-13);
    ck_assert_double_eq_tol(pq[0], 1.1, 1e-13);
    double s = 0.0;
    for (int k = 0; k < 4; k++)
        s += (yy[k] - 1.1 - 1.1 * t[k]) * (yy[k] - 1.1 - 1.1 * t[k]);
    ck_assert_double_eq_tol(rl, sqrt(s), 1e-13);
}
END_TEST

START_TEST(test_lstsq_tall)
{
    enum { M = 2000, N = 3, R = 2 };
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 7);
    double *a = malloc(M * N * sizeof *a), *b = malloc(M * R * sizeof *b);
    double x[N * R], xr[N * R], res[R];
    fill_normal(&rng, a, M * N);
    fill_normal(&rng, b, M * R);
    ck_assert_int_eq(amscr_lstsq_qr(a, M, N, b, R, x, res), AMSCR_OK);
    normal_equations(a, M, N, b, R, xr);
    for (size_t k = 0; k < N * R; k++)
        ck_assert_double_eq_tol(x[k], xr[k], 1e-11);
    for (size_t j = 0; j < R; j++)
        ck_assert_double_eq_tol(res[j], residual_norm(a, M, N, b, R, xr, j), 1e-9);
    free(a);
    free(b);
}
END_TEST

START_TEST(test_lstsq_rank_deficient)
{
    enum { M = 20, N = 3 };
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 3);
    double a[M * N], b[M], x[N], res[1];
    fill_normal(&rng, a, M * N);
    fill_normal(&rng, b, M);

    /* Duplicate column. */
    double d[M * N];
    memcpy(d, a, sizeof a);
    for (size_t k = 0; k < M; k++)
        d[k * N + 2] = d[k * N + 0];
    for (int i = 0; i < N; i++)
        x[i] = 17.0;
    res[0] = 17.0;
    ck_assert_int_eq(amscr_lstsq_qr(d, M, N, b, 1, x, res), AMSCR_E_NUMERIC);
    ck_assert_msg(amscr_last_error_detail()[0] != '\0', "no detail for a rank-deficient system");
    for (int i = 0; i < N; i++)
        ck_assert_msg(x[i] == 17.0, "x written on failure");
    ck_assert(res[0] == 17.0);

    /* Zero column. */
    memcpy(d, a, sizeof a);
    for (size_t k = 0; k < M; k++)
        d[k * N + 1] = 0.0;
    ck_assert_int_eq(amscr_lstsq_qr(d, M, N, b, 1, x, res), AMSCR_E_NUMERIC);
    ck_assert(amscr_last_error_detail()[0] != '\0');

    /* A linear combination of the other columns, up to 1e-15: condition ~1e15 > 1e12. */
    memcpy(d, a, sizeof a);
    for (size_t k = 0; k < M; k++)
        d[k * N + 2] = 2.0 * d[k * N + 0] - 0.5 * d[k * N + 1] + 1e-15 * amscr_test_normal(&rng);
    ck_assert_int_eq(amscr_lstsq_qr(d, M, N, b, 1, x, res), AMSCR_E_NUMERIC);

    /* All zero. */
    memset(d, 0, sizeof d);
    ck_assert_int_eq(amscr_lstsq_qr(d, M, N, b, 1, x, res), AMSCR_E_NUMERIC);

    /* Moderately conditioned (~1e4) is fine. */
    memcpy(d, a, sizeof a);
    for (size_t k = 0; k < M; k++)
        d[k * N + 2] = d[k * N + 0] + 1e-4 * d[k * N + 2];
    ck_assert_int_eq(amscr_lstsq_qr(d, M, N, b, 1, x, res), AMSCR_OK);
}
END_TEST

START_TEST(test_lstsq_invalid)
{
    double a[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 13}, b[6] = {1, 2, 3, 4, 5, 6}, x[6], res[2];
    /* m < n */
    ck_assert_int_eq(amscr_lstsq_qr(a, 3, 4, b, 1, x, res), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_lstsq_qr(a, 1, 2, b, 1, x, res), AMSCR_E_INVALID_ARG);
    /* NULL */
    ck_assert_int_eq(amscr_lstsq_qr(NULL, 4, 3, b, 1, x, res), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, NULL, 1, x, res), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, b, 1, NULL, res), AMSCR_E_INVALID_ARG);
    /* zero sizes */
    ck_assert_int_eq(amscr_lstsq_qr(a, 0, 0, b, 1, x, res), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 0, b, 1, x, res), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, b, 0, x, res), AMSCR_E_INVALID_ARG);
    /* the limits: at most 4096 right-hand sides (4096 pass) */
    double *bb = calloc(4 * 4097, sizeof *bb), *xb = calloc(3 * 4097, sizeof *xb), *rb = calloc(4097, sizeof *rb);
    ck_assert(bb && xb && rb);
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, bb, 4097, xb, rb), AMSCR_E_LIMIT);
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, bb, 4096, xb, rb), AMSCR_OK);
    free(bb);
    free(xb);
    free(rb);
    /* valid call on the same data, as a control */
    ck_assert_int_eq(amscr_lstsq_qr(a, 4, 3, b, 1, x, res), AMSCR_OK);
    /* non-finite data must not succeed */
    a[5] = NAN;
    ck_assert_int_ne(amscr_lstsq_qr(a, 4, 3, b, 1, x, res), AMSCR_OK);
    a[5] = 6;
    b[2] = INFINITY;
    ck_assert_int_ne(amscr_lstsq_qr(a, 4, 3, b, 1, x, res), AMSCR_OK);
}
END_TEST

Suite *amscr_suite_lstsq(void)
{
    Suite *s = suite_create("lstsq");
    TCase *tc = tcase_create("qr");
    tcase_add_loop_test(tc, test_lstsq_random_vs_normal_equations, 0, 8);
    tcase_add_loop_test(tc, test_lstsq_exact_system, 0, 4);
    tcase_add_test(tc, test_lstsq_square_and_small);
    tcase_add_test(tc, test_lstsq_tall);
    tcase_add_test(tc, test_lstsq_rank_deficient);
    tcase_add_test(tc, test_lstsq_invalid);
    suite_add_tcase(s, tc);
    return s;
}
