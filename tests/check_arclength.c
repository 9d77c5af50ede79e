/* check_arclength.c — affine arc length, affine and Euclidean resampling, whitening.
 * Expected values are computed here: the affine speed of a uniformly sampled ellipse is
 * constant, central differences commute with linear maps, and so on. */
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

static double *alloc_pts(size_t n) { return malloc(2 * (n ? n : 1) * sizeof(double)); }

/* Ellipse (a cos t, b sin t) at t = t0 + (t1 - t0) * i / div. */
static void ellipse_arc(size_t n, double a, double b, double t0, double t1, double div, double *xy)
{
    for (size_t i = 0; i < n; i++) {
        double t = t0 + (t1 - t0) * (double)i / div;
        xy[2 * i] = a * cos(t);
        xy[2 * i + 1] = b * sin(t);
    }
}

/* ====================================================== affine arc length */

START_TEST(test_arclength_ellipse_uniform)
{
    const size_t n = 2000;
    const double a = 2.0, b = 0.7;
    const double sigma0s[] = {0.0, 3.0};
    double *xy = alloc_pts(n), *cum = malloc(n * sizeof *cum);
    amscr_test_ellipse(n, a, b, 0.3, xy);
    for (int s = 0; s < 2; s++) {
        double total = -1.0;
        for (size_t i = 0; i < n; i++)
            cum[i] = -1.0;
        ck_assert_int_eq(amscr_affine_arclength(xy, n, 1, sigma0s[s], cum, &total), AMSCR_OK);
        ck_assert_double_eq(cum[0], 0.0);
        /* Affine length is parametrization-free: 2 pi (ab)^(1/3) whatever the sampling units. */
        double expect = 2.0 * M_PI * cbrt(a * b);
        if (sigma0s[s] == 0.0)
            ck_assert_msg(fabs(total / expect - 1.0) < 1e-4, "total %.10g, expected %.10g", total, expect);
        else /* smoothing shrinks the ellipse by a constant factor (an eigenvector of the filter) */
            ck_assert_msg(total > 0.9 * expect && total < expect, "smoothed total %.10g vs %.10g", total, expect);
        /* Constant speed: cumulative[i] / total = i / n (the closing segment is the n-th). */
        for (size_t i = 0; i < n; i++)
            ck_assert_msg(fabs(cum[i] / total - (double)i / (double)n) < 1e-9,
                          "sigma0 %g: cum[%zu]/total = %.12g, expected %.12g", sigma0s[s], i, cum[i] / total,
                          (double)i / (double)n);
    }
    free(xy);
    free(cum);
}
END_TEST

START_TEST(test_arclength_circle_scaling)
{
    /* Affine length scales as r^(2/3): doubling r multiplies it by 2^(2/3). */
    const size_t n = 500;
    double *c1 = alloc_pts(n), *c2 = alloc_pts(n), *cum = malloc(n * sizeof *cum);
    amscr_test_ellipse(n, 1.0, 1.0, 0.0, c1);
    amscr_test_ellipse(n, 2.0, 2.0, 0.0, c2);
    double t1, t2;
    ck_assert_int_eq(amscr_affine_arclength(c1, n, 1, 0.0, cum, &t1), AMSCR_OK);
    ck_assert_int_eq(amscr_affine_arclength(c2, n, 1, 0.0, cum, &t2), AMSCR_OK);
    ck_assert_double_eq_tol(t2 / t1, cbrt(4.0), 1e-12);
    ck_assert_double_eq_tol(t1, 2.0 * M_PI, 2.0 * M_PI * 1e-4);
    free(c1);
    free(c2);
    free(cum);
}
END_TEST

/* Direct computation of the header's recipe for a closed curve without smoothing:
 * f' = (f[i+1] - f[i-1]) / 2, f'' = f[i+1] - 2 f[i] + f[i-1] (periodic),
 * v = |x'y'' - x''y'|^(1/3), trapezoid sums. */
static double ref_speed(const double *xy, size_t n, size_t i)
{
    size_t ip = (i + 1) % n, im = (i + n - 1) % n;
    double d1x = 0.5 * (xy[2 * ip] - xy[2 * im]), d1y = 0.5 * (xy[2 * ip + 1] - xy[2 * im + 1]);
    double d2x = xy[2 * ip] - 2.0 * xy[2 * i] + xy[2 * im];
    double d2y = xy[2 * ip + 1] - 2.0 * xy[2 * i + 1] + xy[2 * im + 1];
    return cbrt(fabs(d1x * d2y - d2x * d1y));
}

START_TEST(test_arclength_direct_recipe)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 300 + (uint64_t)_i);
    const size_t n = 256;
    double *xy = alloc_pts(n), *cum = malloc(n * sizeof *cum), *v = malloc(n * sizeof *v);
    amscr_test_random_shape(&rng, n, 5, xy);
    for (size_t i = 0; i < n; i++)
        v[i] = ref_speed(xy, n, i);
    double total;
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 1, 0.0, cum, &total), AMSCR_OK);
    double acc = 0.0;
    for (size_t i = 0; i < n; i++) {
        ck_assert_msg(fabs(cum[i] - acc) < 1e-12 * (1.0 + acc), "cum[%zu] = %.17g, direct %.17g", i, cum[i], acc);
        acc += 0.5 * (v[i] + v[(i + 1) % n]);
    }
    ck_assert_double_eq_tol(total, acc, 1e-12 * acc);

    /* Open: the interior increments follow the same recipe; the last value is the total. */
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 0, 0.0, cum, &total), AMSCR_OK);
    ck_assert_double_eq(cum[0], 0.0);
    ck_assert_double_eq_tol(cum[n - 1], total, 1e-12 * total);
    for (size_t i = 1; i + 2 < n; i++) {
        double inc = cum[i + 1] - cum[i];
        ck_assert_msg(fabs(inc - 0.5 * (v[i] + v[i + 1])) < 1e-12, "open increment %zu: %.17g vs %.17g", i, inc,
                      0.5 * (v[i] + v[i + 1]));
    }
    free(xy);
    free(cum);
    free(v);
}
END_TEST

START_TEST(test_arclength_affine_covariance)
{
    /* Differences and the Gaussian filter are linear, so for any affine map A
     * cumulative(A f) = |det A|^(1/3) cumulative(f), exactly up to rounding. */
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 900 + (uint64_t)_i);
    const size_t n = 400;
    double *xy = alloc_pts(n), *axy = alloc_pts(n);
    double *c0 = malloc(n * sizeof *c0), *c1 = malloc(n * sizeof *c1);
    amscr_test_random_shape(&rng, n, 6, xy);
    double m6[6];
    amscr_test_random_affine(&rng, 3.0, 0.8, 5.0, _i % 2, m6);
    amscr_test_apply_affine(m6, xy, n, axy);
    double det = m6[0] * m6[4] - m6[1] * m6[3];
    const double sigma0s[] = {0.0, 2.5};
    for (int closed = 0; closed <= 1; closed++)
        for (int s = 0; s < 2; s++) {
            double t0, t1;
            ck_assert_int_eq(amscr_affine_arclength(xy, n, closed, sigma0s[s], c0, &t0), AMSCR_OK);
            ck_assert_int_eq(amscr_affine_arclength(axy, n, closed, sigma0s[s], c1, &t1), AMSCR_OK);
            double k = cbrt(fabs(det));
            ck_assert_msg(fabs(t1 - k * t0) < 1e-9 * t1, "closed %d sigma0 %g: total %.15g, expected %.15g", closed,
                          sigma0s[s], t1, k * t0);
            for (size_t i = 0; i < n; i++)
                ck_assert_msg(fabs(c1[i] - k * c0[i]) < 1e-9 * t1, "closed %d sigma0 %g: cum[%zu] %.15g vs %.15g",
                              closed, sigma0s[s], i, c1[i], k * c0[i]);
        }
    free(xy);
    free(axy);
    free(c0);
    free(c1);
}
END_TEST

START_TEST(test_arclength_open_arc)
{
    /* Half an ellipse, uniform in t: the speed is constant, so cum[i]/total ~ i/(n-1). */
    const size_t n = 2001;
    const double a = 1.5, b = 0.8;
    double *xy = alloc_pts(n), *cum = malloc(n * sizeof *cum);
    ellipse_arc(n, a, b, 0.2, 0.2 + M_PI, (double)(n - 1), xy);
    double total;
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 0, 0.0, cum, &total), AMSCR_OK);
    ck_assert_double_eq(cum[0], 0.0);
    ck_assert_double_eq_tol(cum[n - 1], total, 1e-12 * total);
    ck_assert_msg(fabs(total / (M_PI * cbrt(a * b)) - 1.0) < 1e-3, "open total %.10g, expected %.10g", total,
                  M_PI * cbrt(a * b));
    for (size_t i = 1; i < n; i++) {
        ck_assert(cum[i] >= cum[i - 1]);
        ck_assert_msg(fabs(cum[i] / total - (double)i / (double)(n - 1)) < 1e-3, "cum[%zu]/total = %.10g", i,
                      cum[i] / total);
    }
    free(xy);
    free(cum);
}
END_TEST

START_TEST(test_arclength_degenerate)
{
    const size_t n = 12;
    double xy[24], cum[12], total = -5.0;
    for (size_t i = 0; i < n; i++) { /* a straight open polyline, unevenly spaced */
        double s = (double)(i * i) * 0.1;
        xy[2 * i] = 1.0 + 2.0 * s;
        xy[2 * i + 1] = -3.0 + 0.5 * s;
    }
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 0, 0.0, cum, &total), AMSCR_E_DEGENERATE);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_double_eq(total, -5.0); /* not written on failure */
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 0, 2.0, cum, &total), AMSCR_E_DEGENERATE);
    /* Closed "curve" going out and back along a line: zero affine length everywhere. */
    for (size_t i = 0; i < n; i++) {
        double s = (double)(i < n / 2 ? i : n - i);
        xy[2 * i] = 2.0 * s;
        xy[2 * i + 1] = -s;
    }
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 1, 0.0, cum, &total), AMSCR_E_DEGENERATE);
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 1, 1.5, cum, &total), AMSCR_E_DEGENERATE);
    /* All points equal. */
    for (size_t i = 0; i < 2 * n; i++)
        xy[i] = 4.0;
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 1, 0.0, cum, &total), AMSCR_E_DEGENERATE);
    ck_assert_int_eq(amscr_affine_arclength(xy, n, 0, 0.0, cum, &total), AMSCR_E_DEGENERATE);
}
END_TEST

START_TEST(test_arclength_invalid)
{
    double xy[40], cum[20], total;
    amscr_test_ellipse(20, 1.0, 0.5, 0.0, xy);
    ck_assert_int_eq(amscr_affine_arclength(NULL, 20, 1, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_affine_arclength(xy, 4, 1, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_arclength(xy, 4, 0, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_arclength(xy, 0, 1, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_arclength(xy, 5, 1, 0.0, cum, &total), AMSCR_OK); /* n = 5 is enough */
    ck_assert_int_eq(amscr_affine_arclength(xy, 20, 1, -1.0, cum, &total), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_affine_arclength(xy, 20, 1, NAN, cum, &total), AMSCR_E_INVALID_ARG);
    xy[7] = NAN;
    ck_assert_int_eq(amscr_affine_arclength(xy, 20, 1, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
    xy[7] = INFINITY;
    ck_assert_int_eq(amscr_affine_arclength(xy, 20, 0, 0.0, cum, &total), AMSCR_E_INVALID_ARG);
}
END_TEST

/* ======================================================= affine resampling */

/* An ellipse sampled non-uniformly: t = 2 pi u + 0.6 sin(2 pi u), u = i/n. */
static void nonuniform_ellipse(size_t n, double a, double b, double *xy)
{
    for (size_t i = 0; i < n; i++) {
        double u = (double)i / (double)n;
        double t = 2.0 * M_PI * u + 0.6 * sin(2.0 * M_PI * u);
        xy[2 * i] = a * cos(t);
        xy[2 * i + 1] = b * sin(t);
    }
}

START_TEST(test_resample_affine_ellipse_uniform_in_angle)
{
    const size_t n = 1000, m = 128;
    const double a = 1.0, b = 0.5;
    double *xy = alloc_pts(n), *out = alloc_pts(m);
    nonuniform_ellipse(n, a, b, xy);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.005, 3, m, out), AMSCR_OK);
    /* On the ellipse, and equally spaced in its angle parameter up to a constant offset. */
    double t0 = atan2(out[1] / b, out[0] / a), prev = t0, worst = 0.0;
    for (size_t k = 0; k < m; k++) {
        double x = out[2 * k] / a, y = out[2 * k + 1] / b;
        ck_assert_msg(fabs(x * x + y * y - 1.0) < 1e-3, "output %zu is off the ellipse (%g)", k, x * x + y * y);
        double t = atan2(y, x);
        while (t < prev - M_PI)
            t += 2.0 * M_PI;
        while (t > prev + M_PI)
            t -= 2.0 * M_PI;
        prev = t;
        double dev = fabs((t - t0) - 2.0 * M_PI * (double)k / (double)m);
        if (dev > worst)
            worst = dev;
    }
    ck_assert_msg(worst < 1e-3, "angle spacing deviates by %g rad", worst);
    free(xy);
    free(out);
}
END_TEST

START_TEST(test_resample_affine_covariance)
{
    /* resample(A f + t) = A resample(f) + t up to a cyclic shift. */
    const size_t n = 1000, m = 128;
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 4242 + (uint64_t)_i);
    double *xy = alloc_pts(n), *axy = alloc_pts(n), *r0 = alloc_pts(m), *r1 = alloc_pts(m), *ar0 = alloc_pts(m);
    nonuniform_ellipse(n, 1.0, 0.5, xy);
    double m6[6];
    amscr_test_random_affine(&rng, 2.0, 0.5, 3.0, 0, m6);
    amscr_test_apply_affine(m6, xy, n, axy);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.005, 3, m, r0), AMSCR_OK);
    ck_assert_int_eq(amscr_resample_affine(axy, n, 1, 0.005, 3, m, r1), AMSCR_OK);
    amscr_test_apply_affine(m6, r0, m, ar0);
    double size = amscr_test_shape_size(axy, n), best = INFINITY;
    size_t best_shift = 0;
    for (size_t s = 0; s < m; s++) {
        double worst = 0.0;
        for (size_t k = 0; k < m; k++) {
            size_t j = (k + s) % m;
            double e = hypot(r1[2 * j] - ar0[2 * k], r1[2 * j + 1] - ar0[2 * k + 1]);
            if (e > worst)
                worst = e;
        }
        if (worst < best) {
            best = worst;
            best_shift = s;
        }
    }
    ck_assert_msg(best < 1e-3 * size, "max error %g of size %g (shift %zu)", best / size, size, best_shift);
    free(xy);
    free(axy);
    free(r0);
    free(r1);
    free(ar0);
}
END_TEST

START_TEST(test_resample_affine_errors)
{
    const size_t n = 100;
    double *xy = alloc_pts(n), out[2 * 16];
    nonuniform_ellipse(n, 1.0, 0.5, xy);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.01, 2, 4, out), AMSCR_OK); /* m = 4 is enough */
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.01, 2, 3, out), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.01, 0, 16, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(NULL, n, 1, 0.01, 2, 16, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.01, 2, 16, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(xy, 4, 1, 0.01, 2, 16, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(xy, 0, 1, 0.01, 2, 16, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, -0.01, 2, 16, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, NAN, 2, 16, out), AMSCR_E_INVALID_ARG);
    xy[11] = NAN;
    ck_assert_int_eq(amscr_resample_affine(xy, n, 1, 0.01, 2, 16, out), AMSCR_E_INVALID_ARG);
    /* Straight open polyline. */
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] = (double)i;
        xy[2 * i + 1] = 0.5 * (double)i + 1.0;
    }
    for (size_t i = 0; i < 32; i++)
        out[i] = 123.0;
    ck_assert_int_eq(amscr_resample_affine(xy, n, 0, 0.01, 2, 16, out), AMSCR_E_DEGENERATE);
    ck_assert_int_eq(amscr_resample_affine(xy, n, 0, 0.0, 1, 16, out), AMSCR_E_DEGENERATE);
    for (size_t i = 0; i < 32; i++)
        ck_assert_msg(out[i] == 123.0, "out[%zu] written on failure", i);
    free(xy);
}
END_TEST

/* ==================================================== Euclidean resampling */

/* Independent reference: walk the polygon. */
static void ref_resample_euclid(const double *xy, size_t n, int closed, size_t m, double *out)
{
    size_t nseg = closed ? n : n - 1;
    double L = 0.0;
    for (size_t j = 0; j < nseg; j++) {
        size_t q = (j + 1) % n;
        L += hypot(xy[2 * q] - xy[2 * j], xy[2 * q + 1] - xy[2 * j + 1]);
    }
    for (size_t k = 0; k < m; k++) {
        double s = closed ? L * (double)k / (double)m : L * (double)k / (double)(m - 1);
        double acc = 0.0;
        size_t j = 0;
        for (;; j++) {
            size_t q = (j + 1) % n;
            double len = hypot(xy[2 * q] - xy[2 * j], xy[2 * q + 1] - xy[2 * j + 1]);
            if (j + 1 == nseg || (len > 0.0 && s < acc + len)) {
                double u = len > 0.0 ? (s - acc) / len : 0.0;
                if (u > 1.0)
                    u = 1.0;
                out[2 * k] = xy[2 * j] + u * (xy[2 * q] - xy[2 * j]);
                out[2 * k + 1] = xy[2 * j + 1] + u * (xy[2 * q + 1] - xy[2 * j + 1]);
                break;
            }
            acc += len;
        }
    }
    if (!closed) {
        out[2 * (m - 1)] = xy[2 * (n - 1)];
        out[2 * (m - 1) + 1] = xy[2 * (n - 1) + 1];
    }
}

static void assert_points(const double *got, const double *expect, size_t m, double tol, const char *what)
{
    for (size_t k = 0; k < m; k++)
        ck_assert_msg(fabs(got[2 * k] - expect[2 * k]) < tol && fabs(got[2 * k + 1] - expect[2 * k + 1]) < tol,
                      "%s: point %zu is (%.15g, %.15g), expected (%.15g, %.15g)", what, k, got[2 * k], got[2 * k + 1],
                      expect[2 * k], expect[2 * k + 1]);
}

START_TEST(test_resample_euclid_square)
{
    const double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    const double expect[16] = {0, 0, 0.5, 0, 1, 0, 1, 0.5, 1, 1, 0.5, 1, 0, 1, 0, 0.5};
    double out[16];
    ck_assert_int_eq(amscr_resample_euclidean(sq, 4, 1, 8, out), AMSCR_OK);
    assert_points(out, expect, 8, 1e-12, "square");
    /* Starting at another vertex: the first output is the first input point. */
    const double sq2[8] = {1, 1, 0, 1, 0, 0, 1, 0};
    const double expect2[16] = {1, 1, 0.5, 1, 0, 1, 0, 0.5, 0, 0, 0.5, 0, 1, 0, 1, 0.5};
    ck_assert_int_eq(amscr_resample_euclidean(sq2, 4, 1, 8, out), AMSCR_OK);
    assert_points(out, expect2, 8, 1e-12, "square from (1,1)");
    /* Repeated vertices (zero-length edges) change nothing. */
    const double sq3[14] = {0, 0, 0, 0, 1, 0, 1, 1, 1, 1, 0, 1, 0, 1};
    ck_assert_int_eq(amscr_resample_euclidean(sq3, 7, 1, 8, out), AMSCR_OK);
    assert_points(out, expect, 8, 1e-12, "square with repeats");
    /* at least 2 points in and out (the header's n, m >= 2); the output untouched when refused */
    out[0] = -7.0;
    ck_assert_int_eq(amscr_resample_euclidean(sq, 4, 1, 1, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_euclidean(sq, 1, 1, 8, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_euclidean(sq, 4, 0, 1, out), AMSCR_E_INVALID_ARG);
    ck_assert_double_eq(out[0], -7.0);
}
END_TEST

START_TEST(test_resample_euclid_open)
{
    const double L[6] = {0, 0, 2, 0, 2, 1}; /* length 3 */
    const double e4[8] = {0, 0, 1, 0, 2, 0, 2, 1};
    const double e7[14] = {0, 0, 0.5, 0, 1, 0, 1.5, 0, 2, 0, 2, 0.5, 2, 1};
    double out[14];
    ck_assert_int_eq(amscr_resample_euclidean(L, 3, 0, 4, out), AMSCR_OK);
    assert_points(out, e4, 4, 1e-12, "open L, m = 4");
    ck_assert_int_eq(amscr_resample_euclidean(L, 3, 0, 7, out), AMSCR_OK);
    assert_points(out, e7, 7, 1e-12, "open L, m = 7");
    /* The same polygon closed: perimeter 3 + sqrt(5). */
    double outc[12], refc[12];
    ck_assert_int_eq(amscr_resample_euclidean(L, 3, 1, 6, outc), AMSCR_OK);
    ref_resample_euclid(L, 3, 1, 6, refc);
    assert_points(outc, refc, 6, 1e-12, "closed triangle");
    ck_assert_double_eq_tol(outc[2], (3.0 + sqrt(5.0)) / 6.0, 1e-12);
}
END_TEST

START_TEST(test_resample_euclid_random)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 77 + (uint64_t)_i);
    const size_t n = 37;
    const size_t ms[] = {2, 5, 64, 301};
    double xy[2 * 37];
    amscr_test_random_shape(&rng, n, 5, xy);
    amscr_test_add_noise(&rng, xy, n, 0.05);
    double *out = alloc_pts(301), *ref = alloc_pts(301), keep[2 * 37];
    memcpy(keep, xy, sizeof xy);
    for (int closed = 0; closed <= 1; closed++)
        for (size_t k = 0; k < 4; k++) {
            ck_assert_int_eq(amscr_resample_euclidean(xy, n, closed, ms[k], out), AMSCR_OK);
            ref_resample_euclid(xy, n, closed, ms[k], ref);
            assert_points(out, ref, ms[k], 1e-12, closed ? "random closed" : "random open");
            ck_assert_double_eq(out[0], xy[0]);
            ck_assert_double_eq(out[1], xy[1]);
            if (!closed) {
                ck_assert_double_eq_tol(out[2 * (ms[k] - 1)], xy[2 * (n - 1)], 1e-14);
                ck_assert_double_eq_tol(out[2 * (ms[k] - 1) + 1], xy[2 * (n - 1) + 1], 1e-14);
            }
        }
    ck_assert(memcmp(keep, xy, sizeof xy) == 0);
    free(out);
    free(ref);
}
END_TEST

START_TEST(test_resample_euclid_errors)
{
    double same[10] = {3, 4, 3, 4, 3, 4, 3, 4, 3, 4};
    double out[16];
    for (int i = 0; i < 16; i++)
        out[i] = 42.0;
    ck_assert_int_eq(amscr_resample_euclidean(same, 5, 1, 8, out), AMSCR_E_DEGENERATE);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_resample_euclidean(same, 5, 0, 8, out), AMSCR_E_DEGENERATE);
    for (int i = 0; i < 16; i++)
        ck_assert(out[i] == 42.0);
    const double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    ck_assert_int_eq(amscr_resample_euclidean(NULL, 4, 1, 8, out), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_resample_euclidean(sq, 4, 1, 8, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_euclidean(sq, 0, 1, 8, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_resample_euclidean(sq, 4, 1, 0, out), AMSCR_E_INVALID_ARG);
    double bad[8] = {0, 0, 1, NAN, 1, 1, 0, 1};
    ck_assert_int_eq(amscr_resample_euclidean(bad, 4, 1, 8, out), AMSCR_E_INVALID_ARG);
}
END_TEST

/* ================================================================ whitening */

/* Symmetric inverse square root of the SPD matrix [[p, q], [q, r]]. */
static void inv_sqrt_2x2(double p, double q, double r, double w[4])
{
    double s = sqrt(p * r - q * q), t = sqrt(p + r + 2.0 * s);
    double h[4] = {(p + s) / t, q / t, q / t, (r + s) / t}; /* sqrt */
    double d = h[0] * h[3] - h[1] * h[2];
    w[0] = h[3] / d;
    w[1] = -h[1] / d;
    w[2] = -h[2] / d;
    w[3] = h[0] / d;
}

START_TEST(test_whiten_random)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 555 + (uint64_t)_i);
    const size_t n = 150;
    double *xy = alloc_pts(n), *axy = alloc_pts(n), *out = alloc_pts(n), *chk = alloc_pts(n);
    amscr_test_random_shape(&rng, n, 6, xy);
    double m6[6];
    amscr_test_random_affine(&rng, 4.0, 1.0, 50.0, _i % 2, m6);
    amscr_test_apply_affine(m6, xy, n, axy);
    double fwd[6], inv[6];
    ck_assert_int_eq(amscr_normalize_whiten(axy, n, out, fwd, inv), AMSCR_OK);

    /* Zero mean and identity covariance (1/n). */
    double mx = 0, my = 0, sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < n; i++) {
        mx += out[2 * i];
        my += out[2 * i + 1];
    }
    mx /= (double)n;
    my /= (double)n;
    for (size_t i = 0; i < n; i++) {
        double dx = out[2 * i] - mx, dy = out[2 * i + 1] - my;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    ck_assert_double_eq_tol(mx, 0.0, 1e-12);
    ck_assert_double_eq_tol(my, 0.0, 1e-12);
    ck_assert_double_eq_tol(sxx / (double)n, 1.0, 1e-12);
    ck_assert_double_eq_tol(sxy / (double)n, 0.0, 1e-12);
    ck_assert_double_eq_tol(syy / (double)n, 1.0, 1e-12);

    /* The forward map is x -> Sigma^(-1/2) (x - c): computed here from the input's moments. */
    double cx = 0, cy = 0, p = 0, q = 0, r = 0;
    for (size_t i = 0; i < n; i++) {
        cx += axy[2 * i];
        cy += axy[2 * i + 1];
    }
    cx /= (double)n;
    cy /= (double)n;
    for (size_t i = 0; i < n; i++) {
        double dx = axy[2 * i] - cx, dy = axy[2 * i + 1] - cy;
        p += dx * dx;
        q += dx * dy;
        r += dy * dy;
    }
    double w[4];
    inv_sqrt_2x2(p / (double)n, q / (double)n, r / (double)n, w);
    double wscale = fabs(w[0]) + fabs(w[1]) + fabs(w[3]);
    ck_assert_double_eq_tol(fwd[0], w[0], 1e-10 * wscale);
    ck_assert_double_eq_tol(fwd[1], w[1], 1e-10 * wscale);
    ck_assert_double_eq_tol(fwd[3], w[2], 1e-10 * wscale);
    ck_assert_double_eq_tol(fwd[4], w[3], 1e-10 * wscale);
    ck_assert_double_eq_tol(fwd[2], -(w[0] * cx + w[1] * cy), 1e-9 * (1.0 + wscale * (fabs(cx) + fabs(cy))));
    ck_assert_double_eq_tol(fwd[5], -(w[2] * cx + w[3] * cy), 1e-9 * (1.0 + wscale * (fabs(cx) + fabs(cy))));

    /* forward(input) == output; inverse(output) == input. */
    amscr_test_apply_affine(fwd, axy, n, chk);
    for (size_t i = 0; i < 2 * n; i++)
        ck_assert_double_eq_tol(chk[i], out[i], 1e-10);
    amscr_test_apply_affine(inv, out, n, chk);
    double size = amscr_test_shape_size(axy, n) + fabs(cx) + fabs(cy);
    for (size_t i = 0; i < 2 * n; i++)
        ck_assert_double_eq_tol(chk[i], axy[i], 1e-12 * size);
    /* inverse o forward = identity as matrices. */
    double c[6] = {inv[0] * fwd[0] + inv[1] * fwd[3], inv[0] * fwd[1] + inv[1] * fwd[4],
                   inv[0] * fwd[2] + inv[1] * fwd[5] + inv[2], inv[3] * fwd[0] + inv[4] * fwd[3],
                   inv[3] * fwd[1] + inv[4] * fwd[4], inv[3] * fwd[2] + inv[4] * fwd[5] + inv[5]};
    const double id[6] = {1, 0, 0, 0, 1, 0};
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(c[k], id[k], (k == 2 || k == 5) ? 1e-12 * size : 1e-12);

    /* Every output may be NULL. */
    double fwd2[6];
    ck_assert_int_eq(amscr_normalize_whiten(axy, n, NULL, NULL, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_normalize_whiten(axy, n, NULL, fwd2, NULL), AMSCR_OK);
    for (int k = 0; k < 6; k++)
        ck_assert_double_eq_tol(fwd2[k], fwd[k], 1e-15 * (1.0 + fabs(fwd[k])));
    free(xy);
    free(axy);
    free(out);
    free(chk);
}
END_TEST

START_TEST(test_whiten_errors)
{
    double line[16], out[16], fwd[6], inv[6];
    for (int i = 0; i < 8; i++) {
        line[2 * i] = 1.0 + 3.0 * i;
        line[2 * i + 1] = -2.0 + 1.5 * i;
    }
    for (int i = 0; i < 16; i++)
        out[i] = 9.0;
    ck_assert_int_eq(amscr_normalize_whiten(line, 8, out, fwd, inv), AMSCR_E_DEGENERATE);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    for (int i = 0; i < 16; i++)
        ck_assert(out[i] == 9.0);
    double same[8] = {1, 2, 1, 2, 1, 2, 1, 2};
    ck_assert_int_eq(amscr_normalize_whiten(same, 4, out, fwd, inv), AMSCR_E_DEGENERATE);
    double two[4] = {0, 0, 1, 1};
    ck_assert_int_eq(amscr_normalize_whiten(two, 2, out, fwd, inv), AMSCR_E_DEGENERATE);
    double tri[6] = {0, 0, 1, 0, 0, 1};
    ck_assert_int_eq(amscr_normalize_whiten(tri, 3, out, fwd, inv), AMSCR_OK);
    ck_assert_int_eq(amscr_normalize_whiten(NULL, 3, out, fwd, inv), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_last_error_detail()[0] != '\0');
    ck_assert_int_eq(amscr_normalize_whiten(tri, 0, out, fwd, inv), AMSCR_E_INVALID_ARG);
    tri[3] = NAN;
    ck_assert_int_ne(amscr_normalize_whiten(tri, 3, out, fwd, inv), AMSCR_OK);
}
END_TEST

Suite *amscr_suite_arclength(void)
{
    Suite *s = suite_create("arclength");
    TCase *ta = tcase_create("affine_arclength");
    tcase_add_test(ta, test_arclength_ellipse_uniform);
    tcase_add_test(ta, test_arclength_circle_scaling);
    tcase_add_loop_test(ta, test_arclength_direct_recipe, 0, 3);
    tcase_add_loop_test(ta, test_arclength_affine_covariance, 0, 4);
    tcase_add_test(ta, test_arclength_open_arc);
    tcase_add_test(ta, test_arclength_degenerate);
    tcase_add_test(ta, test_arclength_invalid);
    suite_add_tcase(s, ta);

    TCase *tr = tcase_create("resample_affine");
    tcase_add_test(tr, test_resample_affine_ellipse_uniform_in_angle);
    tcase_add_loop_test(tr, test_resample_affine_covariance, 0, 5);
    tcase_add_test(tr, test_resample_affine_errors);
    suite_add_tcase(s, tr);

    TCase *te = tcase_create("resample_euclidean");
    tcase_add_test(te, test_resample_euclid_square);
    tcase_add_test(te, test_resample_euclid_open);
    tcase_add_loop_test(te, test_resample_euclid_random, 0, 3);
    tcase_add_test(te, test_resample_euclid_errors);
    suite_add_tcase(s, te);

    TCase *tw = tcase_create("whiten");
    tcase_add_loop_test(tw, test_whiten_random, 0, 4);
    tcase_add_test(tw, test_whiten_errors);
    suite_add_tcase(s, tw);
    return s;
}
