/* check_pixel_grid.c — polygons on a pixel grid (src/shape/rasterize.c) and the pixel_grid stage
 * (src/register/pixel_grid.c): a pixel is on when the polygon covers half its area or more; a
 * sub-pixel trace of a binary image gives that image back by its pixel centres; the stage runs on
 * targets traced from small binary images only (or, onto a large image's tracing, on such a
 * source), and the map it keeps differs from the small image in no more pixels than the first one,
 * and is as often right; a small image's pixel chain is registered as the image traced at
 * sub-pixel (src/register/pixel_chain.c). */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "match.h"
#include "suites.h"
#include "testutil.h"

enum { W = 48, NSRC = 600, ARMS = 5 };
/* A star's arms meet at this radius (its tips at 0.6-1). */
#define INNER 0.2
/* The targets of kept_map_fits_the_image: radius 9 px, 30 draws. */
#define RAD 9.0
#define NSEED 30
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static size_t count_on(const uint8_t *img, size_t n)
{
    size_t c = 0;
    for (size_t i = 0; i < n; i++)
        c += img[i] != 0;
    return c;
}

/* An axis-aligned square [a, b]^2 as a polygon. */
static void square(double a, double b, double *P)
{
    const double v[8] = {a, a, b, a, b, b, a, b};
    memcpy(P, v, sizeof v);
}

START_TEST(cover_by_half_area)
{
    double P[8];
    uint8_t img[36];
    /* [0.9, 4.1]: pixels 1..4 covered by 0.6 along a side, 0.36 at a corner */
    square(0.9, 4.1, P);
    ck_assert_int_eq(amscr__raster_cover(P, 4, 0, 0, 6, 6, img), AMSCR_OK);
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 6; i++) {
            int inside = i >= 1 && i <= 4 && j >= 1 && j <= 4, corner = (i == 1 || i == 4) && (j == 1 || j == 4);
            ck_assert_int_eq(img[6 * j + i], inside && !corner ? 255 : 0);
        }
    /* [1.1, 4.9]: pixels 1 and 5 covered by 0.4 only */
    square(1.1, 4.9, P);
    ck_assert_int_eq(amscr__raster_cover(P, 4, 0, 0, 6, 6, img), AMSCR_OK);
    for (int j = 0; j < 6; j++)
        for (int i = 0; i < 6; i++)
            ck_assert_int_eq(img[6 * j + i], (i >= 2 && i <= 4 && j >= 2 && j <= 4) ? 255 : 0);
    /* the grid's origin moves the pixels, not the polygon: (x0, y0) = (1, 1) */
    ck_assert_int_eq(amscr__raster_cover(P, 4, 1, 1, 6, 6, img), AMSCR_OK);
    ck_assert_int_eq(img[6 * 1 + 1], 255);
    ck_assert_int_eq(img[6 * 0 + 0], 0);
    ck_assert_uint_eq(count_on(img, 36), 9);
    /* a polygon far off the grid covers nothing */
    square(100.0, 104.0, P);
    ck_assert_int_eq(amscr__raster_cover(P, 4, 0, 0, 6, 6, img), AMSCR_OK);
    ck_assert_uint_eq(count_on(img, 36), 0);
}
END_TEST

/* A random smooth shape (star: a five-armed star) of radius r px centred in a g x g grid, under the map M (about the
 * centre), into out (2 NSRC). */
static void shape_px(uint64_t seed, int star, double r, const double M[6], size_t g, double *out)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    double *p = malloc(2 * NSRC * sizeof *p);
    ck_assert(p);
    if (star) { /* five arms of random length and slant */
        double v[2 * 2 * ARMS];
        for (int k = 0; k < 2 * ARMS; k++) {
            double a = 2.0 * M_PI * (k + 0.3 * (amscr_test_uniform(&rng) - 0.5)) / (2 * ARMS);
            double rad = k % 2 ? INNER : 0.6 + 0.4 * amscr_test_uniform(&rng);
            v[2 * k] = rad * cos(a);
            v[2 * k + 1] = rad * sin(a);
        }
        ck_assert_uint_eq(amscr_test_polygon(v, 2 * ARMS, NSRC / (2 * ARMS), p), NSRC);
    } else {
        amscr_test_random_shape(&rng, NSRC, 4, p);
    }
    for (size_t i = 0; i < NSRC; i++) {
        double x = r * p[2 * i], y = r * p[2 * i + 1];
        out[2 * i] = M[0] * x + M[1] * y + M[2] + (double)g / 2.0;
        out[2 * i + 1] = M[3] * x + M[4] * y + M[5] + (double)g / 2.0;
    }
    free(p);
}

/* The binary image of polygon P (NSRC points) on the g x g grid (img: g * g bytes), traced at
 * sub-pixel accuracy. */
static amscr_contour *traced(const double *P, size_t g, uint8_t *img)
{
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr__raster_cover(P, NSRC, 0, 0, g, g, img), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_from_image(img, g, g, g, 8, 127.5, 0, &c), AMSCR_OK);
    return c;
}

static const double ID[6] = {1, 0, 0, 0, 1, 0};

START_TEST(centres_give_the_traced_image_back)
{
    for (uint64_t seed = 1; seed <= 12; seed++) {
        double P[2 * NSRC];
        uint8_t img[W * W], back[W * W];
        shape_px(seed, 0, 8.0 + (double)seed, ID, W, P);
        amscr_contour *c = traced(P, W, img);
        ck_assert_int_eq(amscr__raster_centres(amscr_contour_xy(c), amscr_contour_size(c), 0, 0, W, W, back),
                         AMSCR_OK);
        ck_assert_msg(memcmp(img, back, sizeof img) == 0, "seed %d: the trace does not give the image back",
                      (int)seed);
        amscr_contour_free(c);
    }
}
END_TEST

/* Registration params with the pixel_grid stage off. */
static amscr_params *stage_off(void)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_stage(p, "pixel_grid", 0), AMSCR_OK);
    return p;
}

static amscr_result *reg(const amscr_params *p, const double *a, const amscr_contour *t)
{
    amscr_contour *s = NULL;
    amscr_result *r = NULL;
    ck_assert_int_eq(amscr_contour_new(a, NSRC, &s), AMSCR_OK);
    ck_assert_int_eq(amscr_register_contours(p, s, t, &r), AMSCR_OK);
    amscr_contour_free(s);
    return r;
}

/* Whether the last stage, pixel_grid, ran. */
static int ran(const amscr_result *r)
{
    size_t n = amscr_result_num_stages(r);
    const char *name = NULL;
    int on = -1;
    ck_assert_int_eq(amscr_result_stage(r, n - 1, &name, &on), AMSCR_OK);
    ck_assert_str_eq(name, "pixel_grid");
    return on;
}

/* Whether the pixel_grid stage ran registering S onto the point list q (n points). */
static int ran_onto(const double *S, const double *q, size_t n)
{
    amscr_contour *u = NULL;
    ck_assert_int_eq(amscr_contour_new(q, n, &u), AMSCR_OK);
    amscr_result *r = reg(NULL, S, u);
    int on = ran(r);
    amscr_result_free(r);
    amscr_contour_free(u);
    return on;
}

/* A pair: the source shape `seed` at 60 px (S) and its image under a random map (M, about the
 * grid's centre) rendered with radius about r px on a g x g grid and traced (returned). */
static amscr_contour *pair_image(uint64_t seed, double r, size_t g, double *S, double M[6], uint8_t *img);
static amscr_contour *pair(uint64_t seed, double r, size_t g, double *S, double M[6])
{
    uint8_t *img = malloc(g * g);
    ck_assert(img);
    amscr_contour *t = pair_image(seed, r, g, S, M, img);
    free(img);
    return t;
}

/* pair(), the target's binary image kept in img (g * g bytes). */
static amscr_contour *pair_image(uint64_t seed, double r, size_t g, double *S, double M[6], uint8_t *img)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 1000 + seed);
    amscr_test_random_affine(&rng, 1.6, 0.3, 0.0, 0, M);
    double k = 1.0 / sqrt(fabs(M[0] * M[4] - M[1] * M[3]));
    for (int i = 0; i < 6; i++)
        M[i] *= i % 3 == 2 ? 1.0 : k;
    double P[2 * NSRC];
    shape_px(seed, 1, 60.0, ID, 160, S);
    shape_px(seed, 1, r, M, g, P);
    return traced(P, g, img);
}

START_TEST(runs_on_small_binary_tracings_only)
{
    double S[2 * NSRC], M[6];
    amscr_contour *t = pair(3, 12.0, W, S, M);
    amscr_result *r = reg(NULL, S, t);
    ck_assert_int_eq(ran(r), 1);
    amscr_result_free(r);
    /* off the lattice by a thousandth of a pixel: a point list, not a tracing */
    size_t n = amscr_contour_size(t);
    double *q = malloc(2 * n * sizeof *q);
    ck_assert(q);
    memcpy(q, amscr_contour_xy(t), 2 * n * sizeof *q);
    q[0] += 1e-3;
    ck_assert_int_eq(ran_onto(S, q, n), 0);
    free(q);
    /* switched off */
    amscr_params *p = stage_off();
    r = reg(p, S, t);
    ck_assert_int_eq(ran(r), 0);
    amscr_result_free(r);
    amscr_params_free(p);
    amscr_contour_free(t);
    /* the same shape in a large image: its radius over 40 px */
    t = pair(3, 120.0, 300, S, M);
    r = reg(NULL, S, t);
    ck_assert_int_eq(ran(r), 0);
    amscr_result_free(r);
    amscr_contour_free(t);
}
END_TEST

static size_t pixels_apart(const double *P, size_t n, const amscr_contour *t, size_t g);

/* The pixels where the source under r's map, rendered on the grid, differs from the target
 * image (t's pixel centres). */
static size_t differing(const amscr_result *r, const double *S, const amscr_contour *t, size_t g)
{
    double A[6], P[2 * NSRC];
    ck_assert_int_eq(amscr_result_affine(r, A), AMSCR_OK);
    amscr_test_apply_affine(A, S, NSRC, P);
    return pixels_apart(P, NSRC, t, g);
}

/* The pixels of the g x g grid where the polygon P (n points), rendered, differs from the image
 * of the trace t (its pixel centres). */
static size_t pixels_apart(const double *P, size_t n, const amscr_contour *t, size_t g)
{
    uint8_t *a = malloc(2 * g * g), *b = a + g * g;
    ck_assert(a);
    ck_assert_int_eq(amscr__raster_cover(P, n, 0, 0, g, g, a), AMSCR_OK);
    ck_assert_int_eq(amscr__raster_centres(amscr_contour_xy(t), amscr_contour_size(t), 0, 0, g, g, b), AMSCR_OK);
    size_t d = 0;
    for (size_t i = 0; i < g * g; i++)
        d += a[i] != b[i];
    free(a);
    return d;
}

/* The RMS error of the map A against the truth M over the source S, % of the target's radius. */
static double map_error_pct(const double A[6], const double *S, const double M[6], size_t g)
{
    double T[6];
    /* the truth from S (a 60-px shape about (80, 80)) to the target: x -> M (x - 80) / 5 + g/2 */
    const double k = RAD / 60.0, c = 80.0, o = (double)g / 2.0;
    T[0] = k * M[0], T[1] = k * M[1], T[2] = M[2] + o - k * (M[0] * c + M[1] * c);
    T[3] = k * M[3], T[4] = k * M[4], T[5] = M[5] + o - k * (M[3] * c + M[4] * c);
    double s2 = 0.0, P[2 * NSRC];
    amscr_test_apply_affine(T, S, NSRC, P);
    for (size_t i = 0; i < NSRC; i++) {
        double x = S[2 * i], y = S[2 * i + 1];
        double ex = A[0] * x + A[1] * y + A[2] - P[2 * i], ey = A[3] * x + A[4] * y + A[5] - P[2 * i + 1];
        s2 += ex * ex + ey * ey;
    }
    return 100.0 * sqrt(s2 / NSRC) / amscr_test_shape_size(P, NSRC);
}

/* The RMS error of r's map against the truth M over the source S, % of the target's radius. */
static double error_pct(const amscr_result *r, const double *S, const double M[6], size_t g)
{
    double A[6];
    ck_assert_int_eq(amscr_result_affine(r, A), AMSCR_OK);
    return map_error_pct(A, S, M, g);
}

/* Stars of radius 9 px: with the stage on, the map kept never differs from the image in more
 * pixels than the first map, and it is right (within 4 % of the radius) at least as often. */
START_TEST(kept_map_fits_the_image)
{
    amscr_params *off = stage_off();
    int ok_on = 0, ok_off = 0, changed = 0;
    for (uint64_t seed = 1; seed <= NSEED; seed++) {
        double S[2 * NSRC], M[6];
        amscr_contour *t = pair(seed, RAD, W, S, M);
        amscr_result *a = reg(NULL, S, t), *b = reg(off, S, t);
        ck_assert_int_eq(ran(a), 1);
        size_t da = differing(a, S, t, W), db = differing(b, S, t, W);
        ck_assert_msg(da <= db, "seed %d: %zu pixels differ, %zu without the stage", (int)seed, da, db);
        changed += da < db;
        ok_on += error_pct(a, S, M, W) < 4.0;
        ok_off += error_pct(b, S, M, W) < 4.0;
        amscr_result_free(a);
        amscr_result_free(b);
        amscr_contour_free(t);
    }
    ck_assert_int_gt(changed, 0);
    ck_assert_int_ge(ok_on, ok_off);
    ck_assert_int_ge(ok_off, 10);
    amscr_params_free(off);
}
END_TEST

/* Whether two results report the same map, bit for bit. */
static int same_map(const amscr_result *a, const amscr_result *b)
{
    double A[6], B[6];
    ck_assert_int_eq(amscr_result_affine(a, A), AMSCR_OK);
    ck_assert_int_eq(amscr_result_affine(b, B), AMSCR_OK);
    return memcmp(A, B, sizeof A) == 0;
}

/* pair()'s target of radius r px as its image's pixel chain (returned) and its sub-pixel trace
 * (*trace). */
static amscr_contour *small_chain(uint64_t seed, double r, double *S, double M[6], amscr_contour **trace)
{
    uint8_t img[W * W];
    amscr_contour *chain = NULL;
    *trace = pair_image(seed, r, W, S, M, img);
    ck_assert_int_eq(amscr_contour_from_mask(img, W, W, W, 127, &chain), AMSCR_OK);
    return chain;
}

/* A target given as a pixel chain (the boundary pixel centres of a small binary image) is
 * registered as that image traced at sub-pixel: the same map bit for bit, the pixel_grid stage
 * run; the chain onto itself reads the identity. Not with the stage off, nor for a chain with a
 * gap, nor for a large image's chain. */
START_TEST(chain_registers_as_its_image_traced)
{
    amscr_params *off = stage_off();
    for (uint64_t seed = 1; seed <= 3; seed++) {
        double S[2 * NSRC], M[6];
        amscr_contour *t = NULL, *chain = small_chain(seed, RAD + (double)seed, S, M, &t);
        amscr_result *a = reg(NULL, S, chain), *b = reg(NULL, S, t), *c = reg(off, S, chain);
        ck_assert_msg(same_map(a, b), "seed %d: the chain's map is not its trace's", (int)seed);
        ck_assert_int_eq(ran(a), 1);
        ck_assert_int_eq(ran(c), 0);
        ck_assert_msg(!same_map(a, c), "seed %d: the chain registered as given", (int)seed);
        amscr_result_free(a);
        /* the chain onto itself: both traced again, the identity */
        ck_assert_int_eq(amscr_register_contours(NULL, chain, chain, &a), AMSCR_OK);
        ck_assert_int_eq(ran(a), 1);
        ck_assert_double_lt(amscr_result_distance(a), 1e-9);
        double A[6];
        ck_assert_int_eq(amscr_result_affine(a, A), AMSCR_OK);
        for (int k = 0; k < 6; k++)
            ck_assert_double_eq_tol(A[k], ID[k], 1e-9);
        amscr_result_free(a);
        amscr_result_free(b);
        amscr_result_free(c);
        /* every other point of the chain: integer points with gaps, a point list */
        size_t n = amscr_contour_size(chain) / 2;
        double *q = malloc(2 * n * sizeof *q);
        ck_assert(q);
        for (size_t i = 0; i < n; i++)
            memcpy(q + 2 * i, amscr_contour_xy(chain) + 4 * i, 2 * sizeof *q);
        ck_assert_int_eq(ran_onto(S, q, n), 0);
        free(q);
        amscr_contour_free(chain);
        amscr_contour_free(t);
    }
    /* a large image's chain (radius over 40 px) is registered as given */
    double S[2 * NSRC], M[6];
    uint8_t *img = malloc(300 * 300);
    ck_assert(img);
    amscr_contour *t = pair_image(3, 120.0, 300, S, M, img), *chain = NULL;
    ck_assert_int_eq(amscr_contour_from_mask(img, 300, 300, 300, 127, &chain), AMSCR_OK);
    amscr_result *a = reg(NULL, S, chain), *c = reg(off, S, chain);
    ck_assert(same_map(a, c));
    ck_assert_int_eq(ran(a), 0);
    amscr_result_free(a);
    amscr_result_free(c);
    amscr_contour_free(chain);
    amscr_contour_free(t);
    free(img);
    amscr_params_free(off);
}
END_TEST

/* A chain traced again keeps the start it was given: registered onto its own copy reversed and
 * started a third of the way round, a chain reads the identity, and where its first point lies
 * along the target (amscr_result_part) is where it lies along the chain as given (the stage off). */
START_TEST(chain_keeps_its_start)
{
    amscr_params *off = stage_off();
    for (uint64_t seed = 1; seed <= 2; seed++) {
        double S[2 * NSRC], M[6];
        amscr_contour *t = NULL, *chain = small_chain(seed, RAD + 4.0, S, M, &t), *moved = NULL;
        size_t n = amscr_contour_size(chain), k = n / 3;
        const double *c = amscr_contour_xy(chain);
        double *q = malloc(2 * n * sizeof *q);
        ck_assert(q);
        for (size_t i = 0; i < n; i++) { /* q[i] = reversed chain [(i + k) mod n] */
            size_t j = n - 1 - (i + k) % n;
            q[2 * i] = c[2 * j], q[2 * i + 1] = c[2 * j + 1];
        }
        ck_assert_int_eq(amscr_contour_new(q, n, &moved), AMSCR_OK);
        amscr_result *r = NULL;
        ck_assert_int_eq(amscr_register_contours(NULL, chain, moved, &r), AMSCR_OK);
        ck_assert_int_eq(ran(r), 1);
        double A[6], start, end;
        ck_assert_int_eq(amscr_result_affine(r, A), AMSCR_OK);
        for (int i = 0; i < 6; i++)
            ck_assert_double_eq_tol(A[i], ID[i], 1e-4);
        ck_assert_int_eq(amscr_result_part(r, &start, &end), AMSCR_OK);
        amscr_result_free(r);
        double given;
        ck_assert_int_eq(amscr_register_contours(off, chain, moved, &r), AMSCR_OK);
        ck_assert_int_eq(amscr_result_part(r, &given, &end), AMSCR_OK);
        double d = fabs(start - given);
        ck_assert_msg(fmin(d, 1.0 - d) < 0.02, "seed %d: the source starts at %g of the target, %g as given",
                      (int)seed, start, given);
        amscr_result_free(r);
        amscr_contour_free(moved);
        amscr_contour_free(chain);
        amscr_contour_free(t);
        free(q);
    }
    amscr_params_free(off);
}
END_TEST

/* The other way round: c (a small image's chain or trace) registered onto t, the map inverted,
 * then measured against the truth M over S (map_error_pct); *A (when not NULL) the map found. */
static double onto_error_pct(const amscr_params *p, const amscr_contour *c, const amscr_contour *t, const double *S,
                             const double M[6], double *A)
{
    amscr_result *r = NULL;
    ck_assert_int_eq(amscr_register_contours(p, c, t, &r), AMSCR_OK);
    double X[6], inv[6];
    ck_assert_int_eq(amscr_result_affine(r, X), AMSCR_OK);
    amscr_result_free(r);
    if (A)
        memcpy(A, X, sizeof X);
    double det = X[0] * X[4] - X[1] * X[3];
    ck_assert(fabs(det) > 1e-12);
    inv[0] = X[4] / det, inv[1] = -X[1] / det, inv[3] = -X[3] / det, inv[4] = X[0] / det;
    inv[2] = -(inv[0] * X[2] + inv[1] * X[5]), inv[5] = -(inv[3] * X[2] + inv[4] * X[5]);
    return map_error_pct(inv, S, M, W);
}

/* A source given as a small image's pixel chain, registered onto an image's tracing (the 60-px
 * star S rendered and traced; its RMS radius within the grid's limit, so the stage then runs on the
 * target's side), is traced again: right (within 4 % of the radius) as often as the image's sub-pixel trace, and far
 * more often than the chain as given (the stage off), a pixel thinner. Onto S's points themselves
 * (a target not traced from an image) the chain is registered as given. */
START_TEST(small_chain_source_traced_again)
{
    amscr_params *off = stage_off();
    int ok_chain = 0, ok_trace = 0, ok_given = 0;
    for (uint64_t seed = 1; seed <= NSEED; seed++) {
        double S[2 * NSRC], M[6], A[6], B[6];
        uint8_t *img = malloc(160 * 160);
        ck_assert(img);
        amscr_contour *t = NULL, *chain = small_chain(seed, RAD, S, M, &t), *big = traced(S, 160, img), *pts = NULL;
        ok_chain += onto_error_pct(NULL, chain, big, S, M, NULL) < 4.0;
        ok_trace += onto_error_pct(NULL, t, big, S, M, NULL) < 4.0;
        ok_given += onto_error_pct(off, chain, big, S, M, NULL) < 4.0;
        ck_assert_int_eq(amscr_contour_new(S, NSRC, &pts), AMSCR_OK);
        onto_error_pct(NULL, chain, pts, S, M, A);
        onto_error_pct(off, chain, pts, S, M, B);
        ck_assert_msg(memcmp(A, B, sizeof A) == 0, "seed %d: the chain traced again onto a point list", (int)seed);
        amscr_contour_free(pts);
        amscr_contour_free(big);
        amscr_contour_free(chain);
        amscr_contour_free(t);
        free(img);
    }
    ck_assert_msg(ok_chain >= ok_trace - 1 && ok_chain >= ok_given + 5,
                  "right of %d: chain %d, its image's trace %d, the chain as given %d", NSEED, ok_chain, ok_trace,
                  ok_given);
    amscr_params_free(off);
}
END_TEST

/* The source's pixel grid is W x W; the large target is S scaled by BIG about S's centre (80, 80)
 * onto a BIG * 160 px square grid: an RMS radius well over the stage's 40 px. */
#define BIG 3.0

/* S (60-px shapes about (80, 80)) scaled by BIG onto the large grid, into out (2 NSRC). */
static void enlarged(const double *S, double *out)
{
    for (size_t i = 0; i < 2 * NSRC; i++)
        out[i] = BIG * (S[i] - 80.0) + BIG * 80.0;
}

/* The map X of a small source onto the large target inverted and carried back to S's frame: the
 * map from S to the source, measured against the truth M (map_error_pct); *inv the inverse. */
static double enlarged_error_pct(const double X[6], const double *S, const double M[6], double inv[6])
{
    ck_assert_int_eq(amscr_affine_invert(X, inv), AMSCR_OK);
    const double K[6] = {BIG, 0, 0, 0, BIG, 0}; /* S -> the large grid (the offsets cancel) */
    double A[6];
    amscr__affine_compose(inv, K, A);
    return map_error_pct(A, S, M, W);
}

/* The pixels where the target t under the map inv (onto the source's g x g grid), rendered
 * there, differs from the source image (the pixel centres of the trace c). */
static size_t differing_on_source(const double inv[6], const amscr_contour *t, const amscr_contour *c, size_t g)
{
    size_t n = amscr_contour_size(t);
    double *P = malloc(2 * n * sizeof *P);
    ck_assert(P);
    amscr_test_apply_affine(inv, amscr_contour_xy(t), n, P);
    size_t d = pixels_apart(P, n, c, g);
    free(P);
    return d;
}

/* The map of c onto t with params p (NULL: the preset), and whether the pixel_grid stage ran. */
static int map_onto(const amscr_params *p, const amscr_contour *c, const amscr_contour *t, double X[6])
{
    amscr_result *r = NULL;
    ck_assert_int_eq(amscr_register_contours(p, c, t, &r), AMSCR_OK);
    ck_assert_int_eq(amscr_result_affine(r, X), AMSCR_OK);
    int on = ran(r);
    amscr_result_free(r);
    return on;
}

/* The stage on the source's side: a small image's sub-pixel trace (radius 9 px) registered onto
 * a large image's (its RMS radius over the stage's limit, so the target's condition never holds).
 * The stage runs; the map kept never differs from the source image in more pixels than the first
 * map (the target under its inverse, rendered on the source's grid); it is right at least as often
 * as with the stage off (these stars seldom change: the families' procedural shapes do,
 * test_pixel_chain.py). Onto a target not traced from an image (the large shape's points), the
 * stage does not run. */
START_TEST(small_source_corrected_on_its_grid)
{
    amscr_params *off = stage_off();
    int ok_on = 0, ok_off = 0, changed = 0;
    const size_t g = (size_t)(BIG * 160.0);
    uint8_t *img = malloc(g * g);
    ck_assert(img);
    for (uint64_t seed = 1; seed <= NSEED; seed++) {
        double S[2 * NSRC], L[2 * NSRC], M[6], A[6], B[6], ia[6], ib[6];
        amscr_contour *t = pair(seed, RAD, W, S, M), *pts = NULL;
        enlarged(S, L);
        amscr_contour *big = traced(L, g, img);
        ck_assert_msg(map_onto(NULL, t, big, A), "seed %d: the stage did not run on the small source", (int)seed);
        ck_assert(!map_onto(off, t, big, B));
        ok_on += enlarged_error_pct(A, S, M, ia) < 4.0;
        ok_off += enlarged_error_pct(B, S, M, ib) < 4.0;
        size_t da = differing_on_source(ia, big, t, W), db = differing_on_source(ib, big, t, W);
        ck_assert_msg(da <= db, "seed %d: %zu pixels differ, %zu without the stage", (int)seed, da, db);
        changed += da < db;
        ck_assert_int_eq(amscr_contour_new(L, NSRC, &pts), AMSCR_OK);
        ck_assert(!map_onto(NULL, t, pts, A));
        amscr_contour_free(pts);
        amscr_contour_free(big);
        amscr_contour_free(t);
    }
    printf("small source: right %d with the stage, %d without, %d maps changed, of %d\n", ok_on, ok_off, changed,
           NSEED);
    ck_assert_int_ge(ok_on, ok_off);
    free(img);
    amscr_params_free(off);
}
END_TEST

/* The pixels in which the map of r differs from the small side's image, as the stage counts them. */
static size_t stage_differing(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_result *r, int side)
{
    amscr_descriptor *d2 = NULL;
    size_t n = 0;
    ck_assert_int_eq(amscr__grid_correct(f, h, r, side, &d2, &n), AMSCR_OK);
    amscr_descriptor_free(d2);
    return n;
}

/* The stage's choice (amscr__grid_choose) on the source's side, the second registration's points
 * given as the source itself: a first map a quarter turn off is replaced by the second map, and
 * the image that decided is the ambiguity: the ratio of their differing pixels, the second's over
 * the first's (the second's own ambiguity set to 0); a first map only slightly off (not a distinct
 * map) is replaced with the second's ambiguity kept. */
START_TEST(distinct_map_chosen_by_pixels_is_ambiguous)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&p), AMSCR_OK);
    const size_t g = (size_t)(BIG * 160.0);
    uint8_t *img = malloc(g * g);
    ck_assert(img);
    for (uint64_t seed = 1; seed <= 4; seed++) {
        double S[2 * NSRC], L[2 * NSRC], M[6];
        amscr_contour *t = pair(seed, RAD, W, S, M);
        enlarged(S, L);
        amscr_contour *big = traced(L, g, img);
        amscr_descriptor *f = NULL, *h = NULL;
        ck_assert_int_eq(amscr_descriptor_new(p, t, &f), AMSCR_OK);
        ck_assert_int_eq(amscr_descriptor_new(p, big, &h), AMSCR_OK);
        for (int distinct = 0; distinct < 2; distinct++) {
            amscr_result *first = NULL, *second = NULL;
            ck_assert_int_eq(amscr_register(p, f, h, NULL, &first), AMSCR_OK);
            ck_assert_int_eq(amscr_register(p, f, h, NULL, &second), AMSCR_OK);
            double X2[6], *X = first->m.X;
            memcpy(X2, second->m.X, sizeof X2);
            if (distinct) { /* a quarter turn in the normalized frame */
                double t2[6] = {-X[3], -X[4], -X[5], X[0], X[1], X[2]};
                memcpy(X, t2, sizeof t2);
            } else {
                X[2] += 0.08; /* 6 % of the RMS radius: within the 10 % of a distinct map */
            }
            second->m.ambiguity = 0.0;
            size_t d1 = stage_differing(f, h, first, AMSCR__GRID_SOURCE);
            size_t d2 = stage_differing(f, h, second, AMSCR__GRID_SOURCE);
            ck_assert_msg(d2 < d1, "seed %d: %zu pixels for the second map, %zu for the first", (int)seed, d2, d1);
            ck_assert_int_eq(amscr__grid_choose(p, f, h, f, AMSCR__GRID_SOURCE, d1, first, second), AMSCR_OK);
            for (int k = 0; k < 6; k++) /* X2 o fwd(f) o inv(f): X2 to rounding */
                ck_assert_msg(fabs(first->m.X[k] - X2[k]) < 1e-9, "seed %d: the second map not kept", (int)seed);
            double want = distinct ? (double)d2 / (double)d1 : 0.0;
            ck_assert_msg(first->m.ambiguity == want, "seed %d: ambiguity %g, want %g", (int)seed,
                          first->m.ambiguity, want);
            amscr_result_free(first);
            amscr_result_free(second);
        }
        amscr_descriptor_free(f);
        amscr_descriptor_free(h);
        amscr_contour_free(big);
        amscr_contour_free(t);
    }
    free(img);
    amscr_params_free(p);
}
END_TEST

Suite *amscr_suite_pixel_grid(void)
{
    Suite *s = suite_create("pixel_grid");
    TCase *tc = tcase_create("pixel_grid");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, cover_by_half_area);
    tcase_add_test(tc, centres_give_the_traced_image_back);
    tcase_add_test(tc, runs_on_small_binary_tracings_only);
    tcase_add_test(tc, kept_map_fits_the_image);
    tcase_add_test(tc, chain_registers_as_its_image_traced);
    tcase_add_test(tc, chain_keeps_its_start);
    tcase_add_test(tc, small_chain_source_traced_again);
    tcase_add_test(tc, small_source_corrected_on_its_grid);
    tcase_add_test(tc, distinct_map_chosen_by_pixels_is_ambiguous);
    suite_add_tcase(s, tc);
    return s;
}
