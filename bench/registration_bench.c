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
 * Then traced pairs from 200 x 200 images (the shape ~140 px across; `amscr register`'s path:
 * sub-pixel tracing with AMSCR_TRACE_JOIN, the registration preset): the target drawn under a
 * random affine map (anisotropy up to 2, shear up to 0.5), clean or damaged in the image —
 * segmentation noise (the boundary moved by a smooth field of 1.5 % of the radius, 12 specks),
 * a bite (a disk of 0.3 x radius removed at the boundary), a touching disk of 0.3 x radius.
 * Library time per stage (tracing both, preparing both, the method's search and solves, the rest
 * of amscr_register: recovery, polish, alternatives, correspondences) and per pair; success: RMS
 * error below 2 % of the RMS radius.
 *
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

/* ------------------------------------------------------------- traced 200-px pairs */

#define TSIDE 200

typedef struct {
    double a[9], ph[9], limb_dir;
    int limb;
} blob;

static double blob_radius(const blob *b, double th)
{
    double r = 1.0;
    for (int k = 2; k <= 8; k++)
        r += b->a[k] * cos(k * th + b->ph[k]);
    return r;
}

/* Whether unit-frame point (x, y) is inside the blob. */
static int blob_inside(const blob *b, double x, double y)
{
    if (hypot(x, y) < blob_radius(b, atan2(y, x)))
        return 1;
    double ux = cos(b->limb_dir), uy = sin(b->limb_dir), along = x * ux + y * uy;
    return b->limb && along > 0.0 && along < 1.6 && fabs(-x * uy + y * ux) < 0.06;
}

/* The blob under linear map L (2x2) drawn into a TSIDE^2 mask, ~140 px across: pixel = s L u + o.
 * Fills T6 (unit frame -> pixels). */
static void draw_blob(const blob *b, const double L[4], uint8_t *mask, double T6[6])
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int t = 0; t < 1440 + 4; t++) {
        double x, y;
        if (t < 1440) {
            double th = TWO_PI * t / 1440.0, r = blob_radius(b, th);
            x = r * cos(th), y = r * sin(th);
        } else if (b->limb) {
            double ux = cos(b->limb_dir), uy = sin(b->limb_dir), w = (t & 1) ? 0.06 : -0.06;
            x = 1.6 * ux - w * uy, y = 1.6 * uy + w * ux;
        } else
            continue;
        double u = L[0] * x + L[1] * y, v = L[2] * x + L[3] * y;
        lo[0] = fmin(lo[0], u), hi[0] = fmax(hi[0], u), lo[1] = fmin(lo[1], v), hi[1] = fmax(hi[1], v);
    }
    double sc = 140.0 / fmax(hi[0] - lo[0], hi[1] - lo[1]);
    double ox = 0.5 * TSIDE - sc * 0.5 * (lo[0] + hi[0]), oy = 0.5 * TSIDE - sc * 0.5 * (lo[1] + hi[1]);
    double T[6] = {sc * L[0], sc * L[1], ox, sc * L[2], sc * L[3], oy}, det = T[0] * T[4] - T[1] * T[3];
    for (int y = 0; y < TSIDE; y++)
        for (int x = 0; x < TSIDE; x++) {
            double dx = x - ox, dy = y - oy; /* inverse map to the unit frame */
            double ux = (T[4] * dx - T[1] * dy) / det, uy = (-T[3] * dx + T[0] * dy) / det;
            mask[(size_t)y * TSIDE + x] = blob_inside(b, ux, uy) ? 255 : 0;
        }
    memcpy(T6, T, sizeof T);
}

/* Radius sqrt(area / pi) and centroid of a mask's foreground. */
static double mask_radius(const uint8_t *m, double *cx, double *cy)
{
    double n = 0, sx = 0, sy = 0;
    for (int y = 0; y < TSIDE; y++)
        for (int x = 0; x < TSIDE; x++)
            if (m[(size_t)y * TSIDE + x])
                n++, sx += x, sy += y;
    *cx = sx / n, *cy = sy / n;
    return sqrt(n / 3.141592653589793);
}

static void disk(uint8_t *m, double cx, double cy, double r, uint8_t v)
{
    for (int y = 0; y < TSIDE; y++)
        for (int x = 0; x < TSIDE; x++)
            if (hypot(x - cx, y - cy) <= r)
                m[(size_t)y * TSIDE + x] = v;
}

/* Damage 1 noise (a smooth field moving the boundary by ~1.5 % of R, 12 specks), 2 bite,
 * 3 touching disk, in the target mask. */
static void damage(uint8_t *m, int kind)
{
    double cx, cy, R = mask_radius(m, &cx, &cy);
    if (kind == 1) {
        uint8_t *o = malloc((size_t)TSIDE * TSIDE);
        memcpy(o, m, (size_t)TSIDE * TSIDE);
        double a[4], ph[4], e = 0.015 * R;
        for (int k = 0; k < 4; k++)
            a[k] = gauss(), ph[k] = TWO_PI * uni();
        for (int y = 1; y < TSIDE - 1; y++)
            for (int x = 1; x < TSIDE - 1; x++) { /* shift the boundary by the field along the radius */
                double th = atan2(y - cy, x - cx), f = 0.0;
                for (int k = 0; k < 4; k++)
                    f += a[k] * cos((5 + 3 * k) * th + ph[k]) * 0.5;
                double d = e * f, ex = cos(th) * d, ey = sin(th) * d;
                int sx = (int)lround(x - ex), sy = (int)lround(y - ey);
                if (sx >= 0 && sx < TSIDE && sy >= 0 && sy < TSIDE)
                    m[(size_t)y * TSIDE + x] = o[(size_t)sy * TSIDE + sx];
            }
        free(o);
        for (int k = 0; k < 12; k++) {
            double x = TSIDE * uni(), y = TSIDE * uni();
            if (!m[(size_t)(int)y * TSIDE + (int)x] && hypot(x - cx, y - cy) > 1.5 * R)
                disk(m, x, y, 1.0 + uni(), 255);
        }
        return;
    }
    /* a boundary point in a random direction from the centroid */
    double th = TWO_PI * uni(), ux = cos(th), uy = sin(th), t = 0.0;
    for (double s = 0.0; s < TSIDE; s += 0.5) {
        int x = (int)lround(cx + s * ux), y = (int)lround(cy + s * uy);
        if (x < 0 || y < 0 || x >= TSIDE || y >= TSIDE)
            break;
        if (m[(size_t)y * TSIDE + x])
            t = s;
    }
    double bx = cx + t * ux, by = cy + t * uy, r = 0.3 * R;
    if (kind == 2)
        disk(m, bx, by, r, 0);
    else
        disk(m, bx + r * ux, by + r * uy, r, 255);
}

static int cmp_double(const void *a, const void *b);
static double median(double *v, size_t n);

/* RMS over the source contour of |M p - T p| over the RMS radius of T(src). */
static double rms_error(const double M[6], const double T[6], const amscr_contour *src)
{
    const double *xy = amscr_contour_xy(src);
    size_t n = amscr_contour_size(src);
    double s = 0.0, *tp = malloc(2 * n * sizeof *tp);
    for (size_t i = 0; i < n; i++) {
        double a, b;
        apply(M, xy[2 * i], xy[2 * i + 1], &a, &b);
        apply(T, xy[2 * i], xy[2 * i + 1], &tp[2 * i], &tp[2 * i + 1]);
        s += (a - tp[2 * i]) * (a - tp[2 * i]) + (b - tp[2 * i + 1]) * (b - tp[2 * i + 1]);
    }
    double e = sqrt(s / (double)n) / rms_radius(tp, n);
    free(tp);
    return e;
}

/* Thread CPU seconds: the machine may be shared, and every call here runs on this thread. */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Seconds of amscr_register with the recovery and the polish as given; *r the result (or NULL). */
static double cpu_register(amscr_params *p, int recovery, int polish, const amscr_descriptor *a,
                           const amscr_descriptor *d, amscr_workspace *ws, amscr_result **r)
{
    amscr_result *own = NULL;
    if (amscr_params_set_stage(p, "recovery", recovery) != AMSCR_OK || amscr_params_set_polish(p, polish) != AMSCR_OK)
        return NAN;
    double t0 = cpu_now();
    amscr_status st = amscr_register(p, a, d, ws, r ? r : &own);
    double t = cpu_now() - t0;
    amscr_result_free(own);
    return st == AMSCR_OK ? t : NAN;
}

/* The traced pairs' table: `pairs` per condition. */
static void traced_pairs(size_t pairs)
{
    static const char *names[4] = {"clean", "seg. noise", "bite 0.3R", "touch 0.3R"};
    enum { NT = 6 }; /* trace, prepare, register bare, the recovery, the polish, pair */
    amscr_params *p = NULL;
    amscr_workspace *ws = NULL;
    if (amscr_params_new_registration(&p) != AMSCR_OK || amscr_workspace_new(&ws) != AMSCR_OK)
        return;
    printf("\ntraced pairs, %d x %d px images (shape ~140 px across), sub-pixel tracing with join, registration\n"
           "preset, %zu pairs per condition, one thread, median (pair: [90th percentile, max]) CPU time of the\n"
           "library calls; register bare: without the recovery and the polish; recovery, polish: what each adds:\n",
           TSIDE, TSIDE, pairs);
    printf("  %-11s %6s %8s %8s %8s %8s %8s %25s %7s %8s\n", "condition", "points", "trace", "prepare", "reg.bare",
           "recovery", "polish", "pair [p90, max]", "recov.", "ok (RMS)");
    uint8_t *ms = malloc((size_t)TSIDE * TSIDE), *mt = malloc((size_t)TSIDE * TSIDE);
    for (int c = 0; c < 4; c++) {
        double *v[NT];
        for (int i = 0; i < NT; i++)
            v[i] = calloc(pairs, sizeof(double));
        size_t done = 0, ok = 0, npts = 0, recov = 0;
        for (size_t k = 0; k < pairs; k++) {
            blob b;
            for (int j = 2; j <= 8; j++)
                b.a[j] = (0.25 / j) * uni(), b.ph[j] = TWO_PI * uni();
            b.limb = uni() < 0.5;
            b.limb_dir = TWO_PI * uni();
            double I[4] = {1, 0, 0, 1}, L[4], A6[6], Ts[6], Tt[6];
            random_affine(A6);
            L[0] = A6[0], L[1] = A6[1], L[2] = A6[3], L[3] = A6[4];
            draw_blob(&b, I, ms, Ts);
            draw_blob(&b, L, mt, Tt);
            if (c > 0)
                damage(mt, c);
            amscr_contour *src = NULL, *tgt = NULL;
            amscr_descriptor *a = NULL, *d = NULL;
            amscr_result *r = NULL;
            double t0 = cpu_now();
            int good = amscr_contour_from_image(ms, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, &src) == AMSCR_OK &&
                       amscr_contour_from_image(mt, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, &tgt) == AMSCR_OK;
            double t1 = cpu_now();
            good = good && amscr_descriptor_new(p, src, &a) == AMSCR_OK && amscr_descriptor_new(p, tgt, &d) == AMSCR_OK;
            double t2 = cpu_now(), M[6], bare = NAN, norec = NAN, full = NAN;
            if (good) {
                bare = cpu_register(p, 0, 0, a, d, ws, NULL);
                norec = cpu_register(p, 1, 0, a, d, ws, NULL);
                full = cpu_register(p, 1, 1, a, d, ws, &r); /* the preset */
            }
            if (good && r && isfinite(bare + norec + full)) {
                /* the true map source pixels -> target pixels: Tt Ts^-1 */
                double det = Ts[0] * Ts[4] - Ts[1] * Ts[3], Si[6] = {Ts[4] / det, -Ts[1] / det, 0, -Ts[3] / det,
                                                                      Ts[0] / det, 0};
                Si[2] = -(Si[0] * Ts[2] + Si[1] * Ts[5]), Si[5] = -(Si[3] * Ts[2] + Si[4] * Ts[5]);
                double T[6] = {Tt[0] * Si[0] + Tt[1] * Si[3], Tt[0] * Si[1] + Tt[1] * Si[4],
                               Tt[0] * Si[2] + Tt[1] * Si[5] + Tt[2], Tt[3] * Si[0] + Tt[4] * Si[3],
                               Tt[3] * Si[1] + Tt[4] * Si[4], Tt[3] * Si[2] + Tt[4] * Si[5] + Tt[5]};
                ok += amscr_result_affine(r, M) == AMSCR_OK && rms_error(M, T, src) < 0.02;
                for (size_t i = 0; i < amscr_result_num_stages(r); i++) {
                    const char *nm = NULL;
                    int ran = 0;
                    if (amscr_result_stage(r, i, &nm, &ran) == AMSCR_OK && nm && !strcmp(nm, "recovery"))
                        recov += (size_t)ran;
                }
                v[0][done] = t1 - t0, v[1][done] = t2 - t1, v[2][done] = bare, v[3][done] = norec - bare;
                v[4][done] = full - norec, v[5][done] = t2 - t0 + full;
                npts += amscr_contour_size(src) + amscr_contour_size(tgt);
                done++;
            }
            amscr_result_free(r);
            amscr_descriptor_free(a);
            amscr_descriptor_free(d);
            amscr_contour_free(src);
            amscr_contour_free(tgt);
        }
        if (done) {
            double q[NT];
            for (int i = 0; i < NT; i++)
                q[i] = median(v[i], done); /* sorts v[i] */
            printf("  %-11s %6zu %5.2f ms %5.2f ms %5.2f ms %5.2f ms %5.2f ms %6.2f [%6.2f, %6.2f] ms %7zu %7.1f %%\n",
                   names[c], npts / (2 * done), 1e3 * q[0], 1e3 * q[1], 1e3 * q[2], 1e3 * q[3], 1e3 * q[4],
                   1e3 * q[5], 1e3 * v[5][(size_t)(0.9 * (double)(done - 1) + 0.5)], 1e3 * v[5][done - 1], recov,
                   100.0 * (double)ok / (double)done);
        }
        for (int i = 0; i < NT; i++)
            free(v[i]);
    }
    free(ms);
    free(mt);
    amscr_workspace_free(ws);
    amscr_params_free(p);
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
