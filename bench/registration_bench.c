/* amscr-registration-bench — speed (and, alongside, accuracy) of single registrations with the
 * registration preset, per stage: preparing both shapes, matching without the polish, matching
 * with it (the polish's cost is the difference).
 *
 * Shapes: random smooth silhouettes (radius harmonics 2..8, some with a thin limb) drawn into a
 * 400 x 400 mask and traced (pixel contours of 600-1500 points, like the datasets'). Each is
 * registered onto a random affine image of itself (any rotation, anisotropy up to 2, shear up to
 * 0.5), resampled to 0.6-1.4 times the point count from a new start point, clean and with
 * Gaussian noise of 1 % and 2 % of the RMS radius. Success: max error over the source points
 * below 2 % of the target's RMS radius (bench/registration_heldout.py's measure).
 *
 *   amscr-registration-bench [--pairs N] [--seed S]
 *
 * Not a test: it prints numbers (one thread, wall clock, median of the pairs). Run through
 * `meson compile -C build bench` or `meson compile -C build bench-registration`. */
#include <amscr.h>

#include "bench_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SIDE 400
#define TWO_PI 6.283185307179586

/* A random silhouette's pixel contour: a star-shaped blob, sometimes with a thin limb. */
static amscr_contour *random_silhouette(void)
{
    double a[9] = {0}, ph[9] = {0};
    for (int k = 2; k <= 8; k++) {
        a[k] = (0.25 / k) * uni();
        ph[k] = TWO_PI * uni();
    }
    int limb = uni() < 0.5;
    double limb_dir = TWO_PI * uni();
    uint8_t *mask = calloc((size_t)SIDE * SIDE, 1);
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            double dx = (x - SIDE / 2) / (0.3 * SIDE), dy = (y - SIDE / 2) / (0.3 * SIDE);
            double th = atan2(dy, dx), r = 1.0, rho = hypot(dx, dy);
            for (int k = 2; k <= 8; k++)
                r += a[k] * cos(k * th + ph[k]);
            int in = rho < r;
            if (limb) { /* a bar 0.12 wide from the centre out to 1.6 */
                double ux = cos(limb_dir), uy = sin(limb_dir), along = dx * ux + dy * uy;
                in |= along > 0.0 && along < 1.6 && fabs(-dx * uy + dy * ux) < 0.06;
            }
            mask[(size_t)y * SIDE + x] = in ? 255 : 0;
        }
    amscr_contour *c = NULL;
    if (amscr_contour_from_mask(mask, SIDE, SIDE, SIDE, 128, &c) != AMSCR_OK)
        c = NULL;
    free(mask);
    return c;
}

static void apply(const double T[6], double x, double y, double *u, double *v)
{
    *u = T[0] * x + T[1] * y + T[2];
    *v = T[3] * x + T[4] * y + T[5];
}

static void random_affine(double T[6])
{
    double th = TWO_PI * uni(), ph = TWO_PI * uni(), s1 = 1.0 + uni(), s2 = 1.0 / (1.0 + uni());
    double h = uni() - 0.5, sc = 0.5 + 2.0 * uni();
    double R1[4] = {cos(th), -sin(th), sin(th), cos(th)}, R2[4] = {cos(ph), -sin(ph), sin(ph), cos(ph)};
    double U[4] = {s1, s1 * h, 0.0, s2}, M[4], A[4];
    M[0] = R1[0] * U[0] + R1[1] * U[2], M[1] = R1[0] * U[1] + R1[1] * U[3];
    M[2] = R1[2] * U[0] + R1[3] * U[2], M[3] = R1[2] * U[1] + R1[3] * U[3];
    A[0] = M[0] * R2[0] + M[1] * R2[2], A[1] = M[0] * R2[1] + M[1] * R2[3];
    A[2] = M[2] * R2[0] + M[3] * R2[2], A[3] = M[2] * R2[1] + M[3] * R2[3];
    double B[2] = {100.0 * uni() - 50.0, 100.0 * uni() - 50.0};
    double T6[6] = {sc * A[0], sc * A[1], B[0], sc * A[2], sc * A[3], B[1]};
    memcpy(T, T6, sizeof T6);
}

/* RMS radius of n points about their centroid. */
static double rms_radius(const double *p, size_t n)
{
    double cx = 0, cy = 0, s = 0;
    for (size_t i = 0; i < n; i++)
        cx += p[2 * i], cy += p[2 * i + 1];
    cx /= (double)n, cy /= (double)n;
    for (size_t i = 0; i < n; i++)
        s += (p[2 * i] - cx) * (p[2 * i] - cx) + (p[2 * i + 1] - cy) * (p[2 * i + 1] - cy);
    return sqrt(s / (double)n);
}

/* T(src) from a new start, resampled to m points equally spaced in arc length, plus noise of
 * `noise` x its RMS radius per coordinate. */
static amscr_contour *make_target(const amscr_contour *src, const double T[6], double noise, double *size)
{
    size_t n = amscr_contour_size(src), m = (size_t)((0.6 + 0.8 * uni()) * (double)n), s0 = (size_t)(uni() * n);
    const double *xy = amscr_contour_xy(src);
    double *p = malloc(2 * (n + 1) * sizeof *p), *cum = malloc((n + 1) * sizeof *cum), *out = malloc(2 * m * sizeof *out);
    for (size_t i = 0; i <= n; i++) {
        size_t k = (s0 + i) % n;
        apply(T, xy[2 * k], xy[2 * k + 1], &p[2 * i], &p[2 * i + 1]);
        cum[i] = i ? cum[i - 1] + hypot(p[2 * i] - p[2 * i - 2], p[2 * i + 1] - p[2 * i - 1]) : 0.0;
    }
    for (size_t j = 0, i = 0; j < m; j++) {
        double t = cum[n] * (double)j / (double)m;
        while (i + 1 < n && cum[i + 1] < t)
            i++;
        double f = cum[i + 1] > cum[i] ? (t - cum[i]) / (cum[i + 1] - cum[i]) : 0.0;
        out[2 * j] = p[2 * i] + f * (p[2 * i + 2] - p[2 * i]);
        out[2 * j + 1] = p[2 * i + 1] + f * (p[2 * i + 3] - p[2 * i + 1]);
    }
    *size = rms_radius(p, n);
    for (size_t j = 0; j < 2 * m; j++)
        out[j] += noise * *size * gauss();
    amscr_contour *c = NULL;
    if (amscr_contour_new(out, m, &c) != AMSCR_OK)
        c = NULL;
    free(p);
    free(cum);
    free(out);
    return c;
}

static double map_error(const double M[6], const double T[6], const amscr_contour *src, double size)
{
    const double *xy = amscr_contour_xy(src);
    double worst = 0.0;
    for (size_t i = 0; i < amscr_contour_size(src); i++) {
        double a, b, c, d;
        apply(M, xy[2 * i], xy[2 * i + 1], &a, &b);
        apply(T, xy[2 * i], xy[2 * i + 1], &c, &d);
        double e = hypot(a - c, b - d);
        worst = e > worst ? e : worst;
    }
    return worst / size;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Registration of d_src onto d_tgt with polish on/off: seconds and success. */
static double timed_register(amscr_params *p, int polish, const amscr_descriptor *a, const amscr_descriptor *b,
                             const double T[6], const amscr_contour *src, double size, int *ok)
{
    amscr_result *r = NULL;
    double M[6];
    if (amscr_params_set_polish(p, polish) != AMSCR_OK)
        return NAN;
    double t0 = now();
    amscr_status st = amscr_register(p, a, b, NULL, &r);
    double t = now() - t0;
    *ok = st == AMSCR_OK && amscr_result_affine(r, M) == AMSCR_OK && map_error(M, T, src, size) < 0.02;
    amscr_result_free(r);
    return t;
}

int main(int argc, char **argv)
{
    size_t pairs = 40;
    rng_state = 14;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--pairs"))
            pairs = (size_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--seed"))
            rng_state = (uint64_t)atoll(argv[i + 1]);
        else {
            fprintf(stderr, "usage: amscr-registration-bench [--pairs N] [--seed S]\n");
            return 2;
        }
    }
    amscr_params *p = NULL;
    if (amscr_params_new_registration(&p) != AMSCR_OK)
        return 1;
    const double noises[3] = {0.0, 0.01, 0.02};
    printf("registration (preset: N 256, refine 20), %zu pairs per condition, one thread, median wall time:\n",
           pairs);
    printf("  %-10s %8s %10s %12s %12s %8s %12s %12s\n", "condition", "points", "prepare", "no polish", "polished",
           "polish", "ok no pol.", "ok polished");
    for (int c = 0; c < 3; c++) {
        double *tp = calloc(pairs, sizeof *tp), *t0 = calloc(pairs, sizeof *t0), *t1 = calloc(pairs, sizeof *t1);
        size_t ok0 = 0, ok1 = 0, npts = 0, done = 0;
        for (size_t k = 0; k < pairs; k++) {
            double T[6], size;
            amscr_contour *src = random_silhouette(), *tgt = NULL;
            random_affine(T);
            if (src)
                tgt = make_target(src, T, noises[c], &size);
            amscr_descriptor *a = NULL, *b = NULL;
            double s = now();
            int prepared = tgt && amscr_descriptor_new(p, src, &a) == AMSCR_OK && amscr_descriptor_new(p, tgt, &b) == AMSCR_OK;
            tp[done] = now() - s;
            int o0 = 0, o1 = 0;
            if (prepared) {
                t0[done] = timed_register(p, 0, a, b, T, src, size, &o0);
                t1[done] = timed_register(p, 1, a, b, T, src, size, &o1);
                ok0 += (size_t)o0, ok1 += (size_t)o1;
                npts += amscr_contour_size(src) + amscr_contour_size(tgt);
                done++;
            }
            amscr_descriptor_free(a);
            amscr_descriptor_free(b);
            amscr_contour_free(src);
            amscr_contour_free(tgt);
        }
        if (done)
            printf("  %3.0f %% noise %8zu %8.2f ms %9.2f ms %9.2f ms %5.2f ms %11.1f %% %11.1f %%\n", 100.0 * noises[c],
                   npts / (2 * done), 1e3 * median(tp, done), 1e3 * median(t0, done), 1e3 * median(t1, done),
                   1e3 * (median(t1, done) - median(t0, done)), 100.0 * (double)ok0 / (double)done,
                   100.0 * (double)ok1 / (double)done);
        free(tp);
        free(t0);
        free(t1);
    }
    amscr_params_free(p);
    return 0;
}
