/* longshape.c — long noisy test shapes (longshape.h). */
#include "longshape.h"

#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void amscr_test_long_dense(amscr_test_rng *rng, double *d)
{
    amscr_test_random_shape(rng, AMSCR_TEST_DENSE, 4, d);
    for (size_t i = 0; i < AMSCR_TEST_DENSE; i++)
        d[2 * i] *= 5.0;
}

void amscr_test_resample_uneven(const double *d, size_t n, double density, double wave, double *out)
{
    double *cum = malloc((AMSCR_TEST_DENSE + 1) * sizeof *cum);
    ck_assert(cum);
    cum[0] = 0.0;
    for (size_t i = 0; i < AMSCR_TEST_DENSE; i++) {
        size_t e = (i + 1) % AMSCR_TEST_DENSE;
        double w = (i * 4 / AMSCR_TEST_DENSE) % 2 == 0 ? density : 1.0;
        w *= 1.0 + wave * sin(6.0 * 3.14159265358979323846 * (double)i / AMSCR_TEST_DENSE);
        cum[i + 1] = cum[i] + w * hypot(d[2 * e] - d[2 * i], d[2 * e + 1] - d[2 * i + 1]);
    }
    for (size_t j = 0, i = 0; j < n; j++) {
        double s = cum[AMSCR_TEST_DENSE] * (double)j / (double)n;
        while (cum[i + 1] < s)
            i++;
        size_t e = (i + 1) % AMSCR_TEST_DENSE;
        double w = (s - cum[i]) / (cum[i + 1] - cum[i]);
        out[2 * j] = (1 - w) * d[2 * i] + w * d[2 * e];
        out[2 * j + 1] = (1 - w) * d[2 * i + 1] + w * d[2 * e + 1];
    }
    free(cum);
}

void amscr_test_long_axis_stretch(const double *b, size_t n, const double Y[6], double k, double Z[6])
{
    double cx = 0, cy = 0, sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < n; i++)
        cx += b[2 * i] / (double)n, cy += b[2 * i + 1] / (double)n;
    for (size_t i = 0; i < n; i++) {
        double x = b[2 * i] - cx, y = b[2 * i + 1] - cy;
        sxx += x * x, sxy += x * y, syy += y * y;
    }
    double th = 0.5 * atan2(2 * sxy, sxx - syy), ux = cos(th), uy = sin(th);
    double S[6] = {1 + k * ux * ux, k * ux * uy, 0, k * ux * uy, 1 + k * uy * uy, 0};
    S[2] = cx - (S[0] * cx + S[1] * cy), S[5] = cy - (S[3] * cx + S[4] * cy);
    Z[0] = S[0] * Y[0] + S[1] * Y[3], Z[1] = S[0] * Y[1] + S[1] * Y[4], Z[2] = S[0] * Y[2] + S[1] * Y[5] + S[2];
    Z[3] = S[3] * Y[0] + S[4] * Y[3], Z[4] = S[3] * Y[1] + S[4] * Y[4], Z[5] = S[3] * Y[2] + S[4] * Y[5] + S[5];
}

void amscr_test_reverse(double *p, size_t n)
{
    for (size_t i = 0, j = n ? n - 1 : 0; i < j; i++, j--)
        for (int q = 0; q < 2; q++) {
            double v = p[2 * i + q];
            p[2 * i + q] = p[2 * j + q], p[2 * j + q] = v;
        }
}

void amscr_test_stage_degenerate(amscr_test_stage stage, const double *a, double *b, size_t n, double s2, double size,
                                 double Z[6])
{
    double zero[6] = {0}, nan6[6] = {NAN, 0, 0, 0, 1, 0}, Z0[6];
    double *dot = calloc(2 * n, sizeof *dot);
    ck_assert(dot);
    ck_assert_int_eq(stage(a, n, b, n, s2, zero), 0);
    ck_assert_int_eq(stage(a, n, b, n, s2, nan6), 0);
    memcpy(Z0, Z, sizeof Z0);
    ck_assert_int_eq(stage(dot, n, b, n, s2, Z), 0);
    ck_assert(memcmp(Z, Z0, sizeof Z0) == 0);
    amscr_test_rng rng; /* points that are no curve at all */
    amscr_test_rng_seed(&rng, 81);
    for (size_t i = 0; i < 2 * n; i++)
        b[i] = size * (2.0 * amscr_test_uniform(&rng) - 1.0);
    int done = stage(a, n, b, n, 0.1 * size * size, Z);
    for (int k = 0; k < 6; k++)
        ck_assert(isfinite(Z[k]));
    if (!done)
        ck_assert(memcmp(Z, Z0, sizeof Z0) == 0);
    free(dot);
}
