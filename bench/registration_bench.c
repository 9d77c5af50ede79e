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
 * Then pairs traced from 200 x 200 images as `amscr register` traces them, the target drawn under
 * such a map and damaged in the image (segmentation noise, a bite, a touching disk): CPU time of
 * the library per stage and per pair (traced_pairs).
 *   amscr-registration-bench [--pairs N] [--traced-pairs N] [--seed S]
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

/* ------------------------------------------------------------- traced 200-px pairs */
#define TSIDE 200
typedef struct { double a[13], ph[13], dir; int limb; } blob; /* random_silhouette's; 9..12: noise */

static int blob_inside(const blob *b, double x, double y)
{
    double r = 1.0, th = atan2(y, x), ux = cos(b->dir), uy = sin(b->dir), along = x * ux + y * uy;
    for (int k = 2; k <= 12; k++)
        r += b->a[k] * cos(k * th + b->ph[k]);
    return hypot(x, y) < r || (b->limb && along > 0.0 && along < 1.6 && fabs(-x * uy + y * ux) < 0.06);
}

/* The blob under the linear map L drawn into a TSIDE^2 mask, fitted to 140 px; T: unit -> px. */
static void draw_blob(const blob *b, const double L[4], uint8_t *m, double T[6])
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int y = -85; y <= 85; y++) /* the bounding box of its image, on a grid of the unit frame */
        for (int x = -85; x <= 85; x++)
            if (blob_inside(b, x / 50.0, y / 50.0))
                for (int d = 0; d < 2; d++) {
                    double u = L[2 * d] * x / 50.0 + L[2 * d + 1] * y / 50.0;
                    lo[d] = fmin(lo[d], u), hi[d] = fmax(hi[d], u);
                }
    double sc = 140.0 / fmax(hi[0] - lo[0], hi[1] - lo[1]), det = L[0] * L[3] - L[1] * L[2];
    T[0] = sc * L[0], T[1] = sc * L[1], T[2] = 0.5 * (TSIDE - sc * (lo[0] + hi[0]));
    T[3] = sc * L[2], T[4] = sc * L[3], T[5] = 0.5 * (TSIDE - sc * (lo[1] + hi[1]));
    for (int i = 0; i < TSIDE * TSIDE; i++) {
        double dx = (i % TSIDE - T[2]) / sc, dy = (i / TSIDE - T[5]) / sc;
        m[i] = blob_inside(b, (L[3] * dx - L[1] * dy) / det, (-L[2] * dx + L[0] * dy) / det) ? 255 : 0;
    }
}

static void disk(uint8_t *m, double cx, double cy, double r, uint8_t v)
{
    for (int i = 0; i < TSIDE * TSIDE; i++)
        m[i] = hypot(i % TSIDE - cx, i / TSIDE - cy) <= r ? v : m[i];
}

/* Damage 1: 12 specks (with the noise harmonics); 2: a bite, 3: a touching disk of 0.3 R
 * (R = sqrt(area / pi)) at the boundary. */
static void damage(uint8_t *m, int kind)
{
    double n = 0, cx = 0, cy = 0, th = TWO_PI * uni(), t = 0.0;
    for (int i = 0; i < TSIDE * TSIDE; i++)
        if (m[i])
            n++, cx += i % TSIDE, cy += i / TSIDE;
    cx /= n, cy /= n;
    double R = sqrt(n / 3.141592653589793), ux = cos(th), uy = sin(th);
    for (int k = 0; kind == 1 && k < 12; k++) {
        double x = TSIDE * uni(), y = TSIDE * uni(), rs = 1.0 + uni();
        disk(m, x, y, hypot(x - cx, y - cy) > 1.5 * R ? rs : -1.0, 255);
    }
    if (kind == 1)
        return;
    for (double r = 0.0; r < TSIDE; r += 0.5) { /* the outermost boundary point in direction th */
        int x = (int)lround(cx + r * ux), y = (int)lround(cy + r * uy);
        if (x >= 0 && y >= 0 && x < TSIDE && y < TSIDE && m[y * TSIDE + x])
            t = r;
    }
    double r = 0.3 * R, off = kind == 2 ? 0.0 : r; /* a bite centred on the boundary, a disk touching it */
    disk(m, cx + (t + off) * ux, cy + (t + off) * uy, r, kind == 2 ? 0 : 255);
}

static double cpu_now(void) /* thread CPU seconds: every call timed runs on this thread */
{
    struct timespec t;
    return clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) == 0 ? (double)t.tv_sec + 1e-9 * (double)t.tv_nsec : NAN;
}

/* Seconds of amscr_register with the recovery and the polish on or off; the result into *r. */
static double cpu_register(amscr_params *p, int rec, int pol, const amscr_descriptor *a, const amscr_descriptor *d,
                           amscr_workspace *ws, amscr_result **r)
{
    amscr_result_free(*r), *r = NULL;
    double t0 = cpu_now();
    int ok = amscr_params_set_stage(p, "recovery", rec) == AMSCR_OK && amscr_params_set_polish(p, pol) == AMSCR_OK &&
             amscr_register(p, a, d, ws, r) == AMSCR_OK;
    return ok ? cpu_now() - t0 : NAN;
}

/* The traced pairs' table, `pairs` a condition (the table of docs/measurements.md). */
static void traced_pairs(size_t pairs)
{
    static const char *names[4] = {"clean", "seg. noise", "bite 0.3R", "touch 0.3R"};
    amscr_params *p = NULL;
    amscr_workspace *ws = NULL;
    uint8_t *ms = malloc(TSIDE * TSIDE), *mt = malloc(TSIDE * TSIDE);
    double *v = malloc(6 * pairs * sizeof *v); /* trace, prepare, bare, recovery, polish, pair */
    if (amscr_params_new_registration(&p) != AMSCR_OK || amscr_workspace_new(&ws) != AMSCR_OK || !ms || !mt || !v)
        return; /* (a benchmark: leaks on failure) */
    printf("\npairs traced from %d px images (shape 140 px across), registration preset, %zu pairs a condition, one\n"
           "thread, median (pair: [90th percentile, max]) CPU time of the library calls; bare: no recovery, no polish:\n",
           TSIDE, pairs);
    printf("  %-10s %6s %8s %8s %8s %8s %8s %24s %6s %7s\n", "condition", "points", "trace", "prepare", "bare",
           "recovery", "polish", "pair [p90, max]", "recov", "ok");
    for (int c = 0; c < 4; c++) {
        size_t done = 0, ok = 0, npts = 0, recov = 0;
        for (size_t k = 0; k < pairs; k++) {
            blob b = {{0}, {0}, 0.0, 0};
            for (int j = 2; j <= 8; j++)
                b.a[j] = (0.25 / j) * uni(), b.ph[j] = TWO_PI * uni();
            b.limb = uni() < 0.5, b.dir = TWO_PI * uni();
            double I[4] = {1, 0, 0, 1}, A[6], Ts[6], Tt[6], M[6], t[6];
            random_affine(A);
            double L[4] = {A[0], A[1], A[3], A[4]};
            draw_blob(&b, I, ms, Ts);
            for (int j = 9; c == 1 && j <= 12; j++) /* the boundary moved by ~1.5 % of the radius */
                b.a[j] = 0.0075 * gauss(), b.ph[j] = TWO_PI * uni();
            draw_blob(&b, L, mt, Tt);
            if (c > 0)
                damage(mt, c);
            amscr_contour *src = NULL, *tgt = NULL;
            amscr_descriptor *a = NULL, *d = NULL;
            amscr_result *r = NULL;
            t[0] = cpu_now(); /* the library's calls: trace both, prepare both, register 3 ways */
            int good = amscr_contour_from_image(ms, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, &src) == AMSCR_OK &&
                       amscr_contour_from_image(mt, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, &tgt) == AMSCR_OK;
            t[1] = cpu_now();
            good = good && amscr_descriptor_new(p, src, &a) == AMSCR_OK && amscr_descriptor_new(p, tgt, &d) == AMSCR_OK;
            t[2] = cpu_now();
            for (int i = 0; i < 3; i++) /* bare, with the recovery, the preset (with the polish too) */
                t[3 + i] = good ? cpu_register(p, i > 0, i > 1, a, d, ws, &r) : NAN;
            if (isfinite(t[3] + t[4] + t[5]) && amscr_result_affine(r, M) == AMSCR_OK) {
                /* the true map, source px -> target px: Tt Ts^-1 (Ts is a scaling and a shift) */
                double s = Ts[0], T[6] = {Tt[0] / s, Tt[1] / s, Tt[2] - (Tt[0] * Ts[2] + Tt[1] * Ts[5]) / s,
                                          Tt[3] / s, Tt[4] / s, Tt[5] - (Tt[3] * Ts[2] + Tt[4] * Ts[5]) / s};
                double size = sqrt(fabs(T[0] * T[4] - T[1] * T[3])) * rms_radius(amscr_contour_xy(src), amscr_contour_size(src));
                ok += map_error(M, T, src, size) < 0.02; /* size: the source's RMS radius times the map's scale */
                const char *nm = NULL;
                for (int i = 0, ran = 0; i < (int)amscr_result_num_stages(r); i++)
                    if (amscr_result_stage(r, i, &nm, &ran) == AMSCR_OK && !strcmp(nm, "recovery"))
                        recov += (size_t)ran;
                double row[6] = {t[1] - t[0], t[2] - t[1], t[3], t[4] - t[3], t[5] - t[4], t[2] - t[0] + t[5]};
                for (int i = 0; i < 6; i++)
                    v[i * pairs + done] = row[i];
                npts += amscr_contour_size(src) + amscr_contour_size(tgt), done++;
            }
            amscr_result_free(r), amscr_descriptor_free(a), amscr_descriptor_free(d);
            amscr_contour_free(src), amscr_contour_free(tgt);
        }
        double q[6] = {0};
        for (int i = 0; done && i < 6; i++)
            q[i] = 1e3 * median(v + i * pairs, done); /* sorts that column */
        if (done)
            printf("  %-10s %6zu %5.2f ms %5.2f ms %5.2f ms %5.2f ms %5.2f ms %6.2f [%6.2f, %6.2f] ms %6zu %6.1f%%\n",
                   names[c], npts / (2 * done), q[0], q[1], q[2], q[3], q[4], q[5],
                   1e3 * v[5 * pairs + (size_t)(0.9 * (double)(done - 1) + 0.5)], 1e3 * v[5 * pairs + done - 1], recov,
                   100.0 * (double)ok / (double)done);
    }
    free(ms), free(mt), free(v);
    amscr_workspace_free(ws), amscr_params_free(p);
}

int main(int argc, char **argv)
{
    size_t pairs = 40, traced = 40;
    rng_state = 14;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--pairs"))
            pairs = (size_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--traced-pairs"))
            traced = (size_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--seed"))
            rng_state = (uint64_t)atoll(argv[i + 1]);
        else {
            fprintf(stderr, "usage: amscr-registration-bench [--pairs N] [--traced-pairs N] [--seed S]\n");
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
    rng_state = 200; /* the traced pairs draw their own shapes: the table above keeps its draws */
    if (traced)
        traced_pairs(traced);
    return 0;
}
