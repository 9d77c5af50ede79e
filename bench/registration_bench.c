/* amscr-registration-bench — speed (and, alongside, accuracy) of single registrations with the
 * registration preset, per stage: random smooth silhouettes (radius harmonics, some with a thin
 * limb) traced from a 400 x 400 mask, registered onto random affine images of themselves, clean
 * and noisy; then pairs traced from 200 x 200 images as `amscr register` traces them, damaged in
 * the image (docs/measurements.md). Success: max error over the source points below 2 % of the
 * target's RMS radius. One thread, CPU time, median of the pairs; not a test.
 *
 *   amscr-registration-bench [--pairs N] [--seed S] */
#include <amscr.h>

#include "bench_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SIDE 400
#define TWO_PI 6.283185307179586

/* A random star-shaped blob, sometimes with a thin limb; harmonics 9..12 (0 unless set): the
 * traced pairs' segmentation noise. */
typedef struct { double a[13], ph[13], dir; int limb; } blob;

static blob random_blob(void)
{
    blob b = {{0}, {0}, 0.0, 0};
    for (int k = 2; k <= 8; k++) {
        b.a[k] = (0.25 / k) * uni();
        b.ph[k] = TWO_PI * uni();
    }
    b.limb = uni() < 0.5;
    b.dir = TWO_PI * uni();
    return b;
}

/* The blob into a side^2 mask: pixel (x, y) shows unit-frame point Li ((x, y) - o) / s. */
static void draw(const blob *b, int side, const double Li[4], double ox, double oy, double s, uint8_t *mask)
{
    for (int y = 0; y < side; y++)
        for (int x = 0; x < side; x++) {
            double u = (x - ox) / s, v = (y - oy) / s, dx = Li[0] * u + Li[1] * v, dy = Li[2] * u + Li[3] * v;
            double th = atan2(dy, dx), r = 1.0, rho = hypot(dx, dy);
            for (int k = 2; k <= 12; k++)
                r += b->a[k] * cos(k * th + b->ph[k]);
            int in = rho < r;
            if (b->limb) { /* a bar 0.12 wide from the centre out to 1.6 */
                double ux = cos(b->dir), uy = sin(b->dir), along = dx * ux + dy * uy;
                in |= along > 0.0 && along < 1.6 && fabs(-dx * uy + dy * ux) < 0.06;
            }
            mask[(size_t)y * side + x] = in ? 255 : 0;
        }
}

/* A random silhouette's pixel contour. */
static amscr_contour *random_silhouette(void)
{
    blob b = random_blob();
    double I[4] = {1, 0, 0, 1};
    uint8_t *mask = calloc((size_t)SIDE * SIDE, 1);
    amscr_contour *c = NULL;
    if (mask)
        draw(&b, SIDE, I, SIDE / 2, SIDE / 2, 0.3 * SIDE, mask);
    if (!mask || amscr_contour_from_mask(mask, SIDE, SIDE, SIDE, 128, &c) != AMSCR_OK)
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

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

#define TSIDE 200
/* The blob under the linear map L into a TSIDE^2 mask, fitted to 140 px (T: unit frame -> px). */
static void draw_fitted(const blob *b, const double L[4], uint8_t *m, double T[6])
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, det = L[0] * L[3] - L[1] * L[2];
    double Li[4] = {L[3] / det, -L[1] / det, -L[2] / det, L[0] / det};
    draw(b, TSIDE, Li, TSIDE / 2, TSIDE / 2, 20.0, m); /* at a scale that fits (L of det 1); its box: */
    for (int i = 0; i < TSIDE * TSIDE; i++)
        if (m[i])
            lo[0] = fmin(lo[0], i % TSIDE), hi[0] = fmax(hi[0], i % TSIDE), lo[1] = fmin(lo[1], i / TSIDE),
            hi[1] = fmax(hi[1], i / TSIDE);
    double sc = 20.0 * 140.0 / fmax(hi[0] - lo[0], hi[1] - lo[1]), ox = TSIDE / 2 - (lo[0] + hi[0] - TSIDE) * sc / 40.0;
    double oy = TSIDE / 2 - (lo[1] + hi[1] - TSIDE) * sc / 40.0, T6[6] = {sc * L[0], sc * L[1], ox, sc * L[2], sc * L[3], oy};
    draw(b, TSIDE, Li, ox, oy, sc, m);
    memcpy(T, T6, sizeof T6);
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

/* Traced pair `kind` (0 clean, 1 segmentation noise, 2 bite, 3 touching disk): the contours, the
 * true map T (source px -> target px), the target's size; returns the tracing's CPU seconds. */
static double traced_pair(int kind, amscr_contour **src, amscr_contour **tgt, double T[6], double *size)
{
    static uint8_t ms[TSIDE * TSIDE], mt[TSIDE * TSIDE];
    blob b = random_blob();
    double I[4] = {1, 0, 0, 1}, A[6], Ts[6], Tt[6];
    random_affine(A);
    double g = sqrt(fabs(A[0] * A[4] - A[1] * A[3])), L[4] = {A[0] / g, A[1] / g, A[3] / g, A[4] / g};
    draw_fitted(&b, I, ms, Ts);
    for (int j = 9; kind == 1 && j <= 12; j++) /* the boundary moved by ~1.5 % of the radius */
        b.a[j] = 0.0075 * gauss(), b.ph[j] = TWO_PI * uni();
    draw_fitted(&b, L, mt, Tt);
    if (kind > 0)
        damage(mt, kind);
    double s = Ts[0], t0 = cpu_now(); /* Tt Ts^-1; Ts is a scaling and a shift */
    double M[6] = {Tt[0] / s, Tt[1] / s, Tt[2] - (Tt[0] * Ts[2] + Tt[1] * Ts[5]) / s,
                   Tt[3] / s, Tt[4] / s, Tt[5] - (Tt[3] * Ts[2] + Tt[4] * Ts[5]) / s};
    memcpy(T, M, sizeof M);
    if (amscr_contour_from_image(ms, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, src) != AMSCR_OK ||
        amscr_contour_from_image(mt, TSIDE, TSIDE, TSIDE, 8, 127.5, AMSCR_TRACE_JOIN, tgt) != AMSCR_OK)
        return NAN;
    double t = cpu_now() - t0;
    *size = sqrt(fabs(T[0] * T[4] - T[1] * T[3])) * rms_radius(amscr_contour_xy(*src), amscr_contour_size(*src));
    return t;
}

/* amscr_register with the recovery and the polish on or off: CPU seconds (NaN on failure), and
 * whether the map is within 2 % of T's. */
static double timed_register(amscr_params *p, int rec, int pol, const amscr_descriptor *a, const amscr_descriptor *b,
                             const double T[6], const amscr_contour *src, double size, int *ok, int *recovered)
{
    amscr_result *r = NULL;
    double M[6], t0 = cpu_now();
    int st = amscr_params_set_stage(p, "recovery", rec) == AMSCR_OK && amscr_params_set_polish(p, pol) == AMSCR_OK &&
             amscr_register(p, a, b, NULL, &r) == AMSCR_OK;
    double t = cpu_now() - t0;
    *ok = st && amscr_result_affine(r, M) == AMSCR_OK && map_error(M, T, src, size) < 0.02;
    const char *nm = NULL;
    for (int i = 0, ran = 0; st && i < (int)amscr_result_num_stages(r); i++)
        if (amscr_result_stage(r, i, &nm, &ran) == AMSCR_OK && !strcmp(nm, "recovery"))
            *recovered = ran;
    amscr_result_free(r);
    return st ? t : NAN;
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
    uint64_t seed = rng_state;
    amscr_params *p = NULL;
    double *v = calloc(6 * (pairs ? pairs : 1), sizeof *v); /* trace, prepare, bare, no polish, preset, pair */
    if (amscr_params_new_registration(&p) != AMSCR_OK || !v)
        return 1;
    static const char *names[7] = {"0 % noise", "1 % noise", "2 % noise", "img clean", "img noise", "img bite",
                                   "img touch"};
    const double noises[3] = {0.0, 0.01, 0.02};
    printf("registration (preset: N 256, refine 20), %zu pairs per condition, one thread, median CPU time; pair:\n"
           "trace + prepare + register (preset) [90th percentile, max]; bare: register without the recovery and\n"
           "the polish, which add the next two; recov.: pairs the recovery ran for; ok: within 2 %% (no polish,\n"
           "preset). Point lists (n %% noise), then 200-px images (clean, segmentation noise, bite, touching disk):\n",
           pairs);
    printf("  %-10s %6s %8s %8s %8s %8s %8s %24s %6s %7s %7s\n", "condition", "points", "trace", "prepare", "bare",
           "recovery", "polish", "pair [p90, max]", "recov.", "ok", "ok pol.");
    for (int c = 0; c < 7; c++) {
        size_t ok0 = 0, ok1 = 0, npts = 0, done = 0, recov = 0;
        if (c == 3)
            rng_state = seed + 186; /* the images draw their own shapes */
        for (size_t k = 0; k < pairs; k++) {
            double T[6], size = 0.0, t[6] = {0.0};
            amscr_contour *src = NULL, *tgt = NULL;
            if (c < 3) {
                src = random_silhouette();
                random_affine(T);
                if (src)
                    tgt = make_target(src, T, noises[c], &size);
            } else
                t[0] = traced_pair(c - 3, &src, &tgt, T, &size);
            amscr_descriptor *a = NULL, *b = NULL;
            double s = cpu_now();
            int o[3] = {0}, rec = 0;
            int prepared = tgt && amscr_descriptor_new(p, src, &a) == AMSCR_OK && amscr_descriptor_new(p, tgt, &b) == AMSCR_OK;
            t[1] = cpu_now() - s;
            for (int i = 0; prepared && i < 3; i++) /* bare, with the recovery, the preset (with the polish) */
                t[2 + i] = timed_register(p, i > 0, i > 1, a, b, T, src, size, &o[i], &rec);
            t[5] = t[0] + t[1] + t[4];
            if (prepared && isfinite(t[0] + t[2] + t[3] + t[4])) {
                for (int i = 0; i < 6; i++)
                    v[i * pairs + done] = t[i];
                ok0 += (size_t)o[1], ok1 += (size_t)o[2], recov += (size_t)rec;
                npts += amscr_contour_size(src) + amscr_contour_size(tgt), done++;
            }
            amscr_descriptor_free(a), amscr_descriptor_free(b);
            amscr_contour_free(src), amscr_contour_free(tgt);
        }
        double q[6] = {0}; /* bare, recovery, polish: differences of the medians */
        for (int i = 0; done && i < 6; i++)
            q[i] = 1e3 * median(v + i * pairs, done); /* sorts that column */
        if (done)
            printf("  %-10s %6zu %5.2f ms %5.2f ms %5.2f ms %5.2f ms %5.2f ms %6.2f [%6.2f, %6.2f] ms %6zu %6.1f%% %6.1f%%\n",
                   names[c], npts / (2 * done), q[0], q[1], q[2], q[3] - q[2], q[4] - q[3], q[5],
                   1e3 * v[5 * pairs + (size_t)(0.9 * (double)(done - 1) + 0.5)], 1e3 * v[5 * pairs + done - 1], recov,
                   100.0 * (double)ok0 / (double)done, 100.0 * (double)ok1 / (double)done);
    }
    free(v);
    amscr_params_free(p);
    return 0;
}
