/* check_polish.c — the polish stage (docs/method.md §11.4) (src/register/polish.c): the flag's defaults and range,
 * noisy targets and noisy sources registered more accurately with it than without, exact pairs
 * kept exact, no polish without input points (collections, loaded collections), fragments
 * (partial matching) placed better with it, symmetric shapes still reported ambiguous; the closest-point
 * searches it and the refinement read (nearest.c, refine.c) against brute force. Generated shapes, seeded. */
#include <amscr.h>
#include <check.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "match.h"
#include "nearest.h"
#include "suites.h"
#include "testutil.h"

/* ------------------------------------------------------------------------------ the flag */

START_TEST(polish_flag)
{
    amscr_params *p = NULL, *reg = NULL, *c = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_registration(&reg), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_polish(p), 0);
    ck_assert_int_eq(amscr_params_get_polish(reg), 1);
    ck_assert_int_eq(amscr_params_set_polish(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_polish(p), 1);
    ck_assert_int_eq(amscr_params_set_polish(reg, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_polish(reg), 0);
    /* anything but 0/1 is refused with a message, and the flag stays as it was */
    const int bad[] = {2, -1, 100, INT_MAX, INT_MIN};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ck_assert_int_eq(amscr_params_set_polish(p, bad[i]), AMSCR_E_INVALID_ARG);
        ck_assert_msg(amscr_last_error_detail()[0] != '\0', "no detail for polish %d", bad[i]);
        ck_assert_int_eq(amscr_params_get_polish(p), 1);
    }
    /* a copy keeps it */
    ck_assert_int_eq(amscr_params_copy(p, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_polish(c), 1);
    ck_assert_int_eq(amscr_params_set_polish(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_polish(c), 1);
    /* NULL: refused by the setter, 0 from the getter */
    ck_assert_int_eq(amscr_params_set_polish(NULL, 1), AMSCR_E_INVALID_ARG);
    ck_assert_msg(amscr_last_error_detail()[0] != '\0', "no detail for a NULL params");
    ck_assert_int_eq(amscr_params_get_polish(NULL), 0);
    amscr_params_free(c);
    amscr_params_free(reg);
    amscr_params_free(p);
}
END_TEST

/* ----------------------------------------------------------------------------- helpers */

/* The registration preset with the polish flag (and partial flag) set. */
static amscr_params *preset(int polish, int partial)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_polish(p, polish), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_partial(p, partial), AMSCR_OK);
    return p;
}

/* Registers src (ns) onto tgt (nt) through amscr_register_contours; the map into M, the
 * result kept when out_r. */
static void reg_map(const double *src, size_t ns, const double *tgt, size_t nt, int polish, int partial, double M[6],
                    amscr_result **out_r)
{
    amscr_params *p = preset(polish, partial);
    amscr_contour *cs = NULL, *ct = NULL;
    amscr_result *r = NULL;
    ck_assert_int_eq(amscr_contour_new(src, ns, &cs), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_new(tgt, nt, &ct), AMSCR_OK);
    amscr_status st = amscr_register_contours(p, cs, ct, &r);
    ck_assert_msg(st == AMSCR_OK, "register: %s", amscr_last_error_detail());
    ck_assert_int_eq(amscr_result_affine(r, M), AMSCR_OK);
    if (out_r)
        *out_r = r;
    else
        amscr_result_free(r);
    amscr_contour_free(cs);
    amscr_contour_free(ct);
    amscr_params_free(p);
}

/* A closed shape with thin parts, as silhouettes have (legs, fingers, ears): a smooth random
 * body (amscr_test_random_shape) with 2-5 arms of random length and width (narrow bumps of
 * the radius), resampled to equal arc-length steps of 1/60 of its RMS radius (a pixel contour's
 * density for a shape of radius 60 px: 400-1200 points). Returns n; *xy malloc'ed (2n). */
static size_t thin_shape(amscr_test_rng *rng, int complexity, double **xy)
{
    enum { DENSE = 8192, ARMS_MAX = 5 };
    double *d = malloc(2 * (DENSE + 1) * sizeof *d), *cum = malloc((DENSE + 1) * sizeof *cum);
    ck_assert(d && cum);
    amscr_test_random_shape(rng, DENSE, complexity, d);
    int arms = 2 + (int)(amscr_test_uniform(rng) * (ARMS_MAX - 1));
    double at[ARMS_MAX], len[ARMS_MAX], kappa[ARMS_MAX];
    for (int j = 0; j < arms; j++) {
        at[j] = 6.283185307179586 * amscr_test_uniform(rng);
        len[j] = 1.0 + 2.0 * amscr_test_uniform(rng);
        kappa[j] = 60.0 + 120.0 * amscr_test_uniform(rng); /* half-width 0.07-0.13 rad */
    }
    for (size_t i = 0; i < DENSE; i++) {
        double t = 6.283185307179586 * (double)i / DENSE, x = d[2 * i], y = d[2 * i + 1];
        double r = hypot(x, y), grow = r;
        for (int j = 0; j < arms; j++)
            grow += len[j] * exp(kappa[j] * (cos(t - at[j]) - 1.0));
        d[2 * i] = x * grow / r;
        d[2 * i + 1] = y * grow / r;
    }
    d[2 * DENSE] = d[0];
    d[2 * DENSE + 1] = d[1];
    cum[0] = 0.0;
    for (size_t i = 0; i < DENSE; i++)
        cum[i + 1] = cum[i] + hypot(d[2 * i + 2] - d[2 * i], d[2 * i + 3] - d[2 * i + 1]);
    double size = amscr_test_shape_size(d, DENSE);
    size_t n = (size_t)(cum[DENSE] / (size / 60.0));
    double *out = malloc(2 * n * sizeof *out);
    ck_assert(out);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) { /* linear interpolation at equal arc-length steps */
        double s = cum[DENSE] * (double)i / (double)n;
        while (cum[k + 1] < s)
            k++;
        double w = (s - cum[k]) / (cum[k + 1] - cum[k]);
        out[2 * i] = (1 - w) * d[2 * k] + w * d[2 * k + 2];
        out[2 * i + 1] = (1 - w) * d[2 * k + 1] + w * d[2 * k + 3];
    }
    free(d);
    free(cum);
    *xy = out;
    return n;
}

/* One generated pair: a shape with thin parts (thin_shape), a random affine map (any rotation,
 * anisotropy up to 2, shear), the target starting at another point. clean, src, tgt: 2n each;
 * size: the RMS radius of the exact target T(clean). Gaussian noise of `noise` x the RMS radius
 * of the curve it goes on is added to the target (noisy_src 0) or the source (noisy_src 1). */
typedef struct {
    double *clean, *src, *tgt, T[6], size;
    size_t n;
} pair_t;

static void make_pair(uint64_t seed, double noise, int noisy_src, pair_t *pr)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    size_t n = thin_shape(&rng, 3 + (int)(seed % 6), &pr->clean);
    pr->n = n;
    pr->src = malloc(2 * n * sizeof *pr->src);
    pr->tgt = malloc(2 * n * sizeof *pr->tgt);
    double *a = malloc(2 * n * sizeof *a);
    ck_assert(pr->src && pr->tgt && a);
    amscr_test_random_affine(&rng, 2.0, 0.5, 50.0, 0, pr->T);
    amscr_test_cyclic_shift(pr->clean, n, (size_t)(amscr_test_uniform(&rng) * (double)n) % n, a);
    amscr_test_apply_affine(pr->T, a, n, pr->tgt);
    pr->size = amscr_test_shape_size(pr->tgt, n);
    memcpy(pr->src, pr->clean, 2 * n * sizeof *pr->src);
    if (noisy_src)
        amscr_test_add_noise(&rng, pr->src, n, noise * amscr_test_shape_size(pr->clean, n));
    else
        amscr_test_add_noise(&rng, pr->tgt, n, noise * pr->size);
    free(a);
}

static void free_pair(pair_t *pr)
{
    free(pr->clean);
    free(pr->src);
    free(pr->tgt);
}

/* The map error of the registration of the pair (max over the clean source points of
 * |M f - T f|, relative to the RMS radius of T f). */
static double pair_error(const pair_t *pr, int polish)
{
    double M[6];
    reg_map(pr->src, pr->n, pr->tgt, pr->n, polish, 0, M, NULL);
    return amscr_test_max_map_error(M, pr->T, pr->clean, pr->n) / pr->size;
}

/* ------------------------------------------------------------------------ noisy pairs */

enum { NOISY_PAIRS = 40 };

/* Counts, over NOISY_PAIRS pairs with 2 % noise on one side, the maps within 2 % of the size
 * without and with the polish; also the summed errors (the polish must lower them too). */
static void noisy_run(uint64_t seed0, int noisy_src, size_t *ok_off, size_t *ok_on, double *sum_off, double *sum_on)
{
    *ok_off = *ok_on = 0;
    *sum_off = *sum_on = 0.0;
    for (int c = 0; c < NOISY_PAIRS; c++) {
        pair_t pr;
        make_pair(seed0 + (uint64_t)c, 0.02, noisy_src, &pr);
        double e0 = pair_error(&pr, 0), e1 = pair_error(&pr, 1);
        printf("polish: %s pair %2d (n %zu): error %.2f %% -> %.2f %%\n", noisy_src ? "noisy source" : "noisy target",
               c, pr.n, 100.0 * e0, 100.0 * e1);
        *ok_off += e0 < 0.02;
        *ok_on += e1 < 0.02;
        *sum_off += e0;
        *sum_on += e1;
        free_pair(&pr);
    }
    printf("polish: %s, 2 %% noise: %zu -> %zu of %d within 2 %%, mean error %.2f %% -> %.2f %%\n",
           noisy_src ? "noisy source" : "noisy target", *ok_off, *ok_on, NOISY_PAIRS, 100.0 * *sum_off / NOISY_PAIRS,
           100.0 * *sum_on / NOISY_PAIRS);
    fflush(stdout);
}

/* 2 % noise on the target (pixel-like thin shapes, 40 pairs). Measured: 33 -> 40 of 40 within
 * 2 % of the size, mean error 1.44 % -> 0.88 %. */
START_TEST(noisy_target)
{
    size_t off, on;
    double soff, son;
    noisy_run(3100, 0, &off, &on, &soff, &son);
    ck_assert_msg(on >= 37, "noisy target, polished: %zu of %d within 2 %%", on, NOISY_PAIRS);
    ck_assert_msg(on >= off + 4, "noisy target: %zu -> %zu of %d within 2 %%", off, on, NOISY_PAIRS);
    ck_assert_msg(son < 0.75 * soff, "noisy target: mean error %.3f %% -> %.3f %%", 100.0 * soff / NOISY_PAIRS,
                  100.0 * son / NOISY_PAIRS);
}
END_TEST

/* 2 % noise on the SOURCE, the target clean: the roughness weighting must pick the other
 * direction (mapped source points onto the target), so the polish helps as much as for a noisy
 * target. FAILS on main@102625a: measured 35 -> 32 of 40 within 2 %, mean error 1.27 % -> 1.49 %
 * (worse), while registering the same pairs the other way round (the noisy curve as the target)
 * and inverting the map gives 40 of 40, mean 0.69 %. */
START_TEST(noisy_source)
{
    size_t off, on;
    double soff, son;
    noisy_run(3100, 1, &off, &on, &soff, &son);
    ck_assert_msg(on >= 37, "noisy source, polished: %zu of %d within 2 %%", on, NOISY_PAIRS);
    ck_assert_msg(son < 0.75 * soff, "noisy source: mean error %.3f %% -> %.3f %%", 100.0 * soff / NOISY_PAIRS,
                  100.0 * son / NOISY_PAIRS);
}
END_TEST

/* Exact affine images with the same points (a new start point) stay exact with the polish. */
START_TEST(exact_pairs_stay_exact)
{
    for (uint64_t c = 0; c < 6; c++) {
        pair_t pr;
        make_pair(5200 + c, 0.0, 0, &pr);
        double e = pair_error(&pr, 1);
        ck_assert_msg(e < 1e-6, "exact pair %d: error %.3g of the size", (int)c, e);
        free_pair(&pr);
    }
}
END_TEST

/* The maps of two results are bit-identical. */
static void same_map(const amscr_result *a, const amscr_result *b, const char *what)
{
    double Ma[6], Mb[6];
    ck_assert_int_eq(amscr_result_affine(a, Ma), AMSCR_OK);
    ck_assert_int_eq(amscr_result_affine(b, Mb), AMSCR_OK);
    ck_assert_msg(memcmp(Ma, Mb, sizeof Ma) == 0, "%s: the maps differ (%.17g vs %.17g ...)", what, Ma[0], Mb[0]);
}

/* Registers d_src onto d_tgt with the registration preset, polish on and off. */
static void register_both(const amscr_descriptor *ds, const amscr_descriptor *dt, amscr_result **on, amscr_result **off)
{
    amscr_params *p1 = preset(1, 0), *p0 = preset(0, 0);
    ck_assert_int_eq(amscr_register(p1, ds, dt, NULL, on), AMSCR_OK);
    ck_assert_int_eq(amscr_register(p0, ds, dt, NULL, off), AMSCR_OK);
    amscr_params_free(p1);
    amscr_params_free(p0);
}

/* Descriptors held by a collection (added as contours or as descriptors) and collections
 * loaded back have no input points: their registration is the same with the polish as without.
 * The same pair prepared by amscr_descriptor_new is polished (its map differs): the check is
 * not vacuous. */
START_TEST(no_polish_without_input_points)
{
    pair_t pr;
    make_pair(3101, 0.02, 0, &pr); /* a pair the polish changes (measured 0.74 % -> 0.51 %) */
    amscr_params *p = preset(1, 0);
    amscr_contour *cs = NULL, *ct = NULL;
    amscr_descriptor *ds = NULL, *dt = NULL;
    ck_assert_int_eq(amscr_contour_new(pr.src, pr.n, &cs), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_new(pr.tgt, pr.n, &ct), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, cs, &ds), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, ct, &dt), AMSCR_OK);
    amscr_result *on = NULL, *off = NULL;
    register_both(ds, dt, &on, &off);
    double M1[6], M0[6];
    ck_assert_int_eq(amscr_result_affine(on, M1), AMSCR_OK);
    ck_assert_int_eq(amscr_result_affine(off, M0), AMSCR_OK);
    ck_assert_msg(memcmp(M1, M0, sizeof M1) != 0, "fresh descriptors: the polish changed nothing");
    amscr_result_free(on);
    amscr_result_free(off);

    amscr_db *db = NULL, *back = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_contour(db, cs, 1, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_contour(db, ct, 2, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_descriptor(db, ds, 3, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_descriptor(db, dt, 4, NULL), AMSCR_OK);
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_db_load_memory(buf, len, &back), AMSCR_OK);
    free(buf);
    const amscr_db *dbs[2] = {db, back};
    for (int k = 0; k < 2; k++)
        for (size_t i = 0; i < 4; i += 2) {
            register_both(amscr_db_descriptor(dbs[k], i), amscr_db_descriptor(dbs[k], i + 1), &on, &off);
            char what[64];
            snprintf(what, sizeof what, "%s, shapes %zu/%zu", k ? "loaded collection" : "collection", i, i + 1);
            same_map(on, off, what);
            amscr_result_free(on);
            amscr_result_free(off);
        }
    amscr_db_free(back);
    amscr_db_free(db);
    amscr_descriptor_free(ds);
    amscr_descriptor_free(dt);
    amscr_contour_free(cs);
    amscr_contour_free(ct);
    amscr_params_free(p);
    free_pair(&pr);
}
END_TEST

/* Partial matching is polished too (the fragment's points alone onto the target): over 20
 * thin-limbed shapes, a clean fragment of half the source at a varying place onto the whole
 * target with 1 % noise, the polish must place at least as many within 2 % and lower the mean
 * error. Measured: 19 -> 20 of 20, mean error 1.16 % -> 0.79 %. */
enum { FRAGMENT_PAIRS = 20 };

START_TEST(partial_polished)
{
    size_t ok[2] = {0, 0};
    double sum[2] = {0.0, 0.0};
    for (int c = 0; c < FRAGMENT_PAIRS; c++) {
        pair_t pr;
        make_pair(3300 + (uint64_t)c, 0.01, 0, &pr);
        size_t k = pr.n / 2, start = (size_t)(c * 97) % pr.n;
        double *frag = malloc(2 * k * sizeof *frag), M[6];
        ck_assert(frag);
        for (size_t i = 0; i < k; i++) {
            frag[2 * i] = pr.clean[2 * ((start + i) % pr.n)];
            frag[2 * i + 1] = pr.clean[2 * ((start + i) % pr.n) + 1];
        }
        for (int polish = 0; polish < 2; polish++) {
            reg_map(frag, k, pr.tgt, pr.n, polish, 1, M, NULL);
            double e = amscr_test_max_map_error(M, pr.T, frag, k) / pr.size;
            ok[polish] += e < 0.02;
            sum[polish] += e < 1.0 ? e : 1.0; /* a misplaced fragment counts as 100 % */
        }
        free(frag);
        free_pair(&pr);
    }
    printf("polish: 50 %% fragments: %zu -> %zu of %d within 2 %%, mean error (capped at 100 %%) %.2f %% -> %.2f %%\n",
           ok[0], ok[1], FRAGMENT_PAIRS, 100.0 * sum[0] / FRAGMENT_PAIRS, 100.0 * sum[1] / FRAGMENT_PAIRS);
    ck_assert_msg(ok[1] >= ok[0] && sum[1] < sum[0], "fragments: %zu -> %zu within 2 %%, mean %.3f -> %.3f", ok[0],
                  ok[1], sum[0], sum[1]);
}
END_TEST

/* The shape s (n points) onto an affine copy with a new start and `noise` x its size of noise,
 * polish on: confidence (and ambiguity) of the result. */
static double noisy_confidence(const double *s, size_t n, double noise, uint64_t seed, double *out_amb)
{
    static const double T[6] = {1.2, 0.4, 3.0, -0.2, 0.8, -1.0}; /* check_robust.c's map */
    double *a = malloc(2 * n * sizeof *a), *t = malloc(2 * n * sizeof *t), M[6];
    ck_assert(a && t);
    amscr_test_cyclic_shift(s, n, n / 7, a);
    amscr_test_apply_affine(T, a, n, t);
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    amscr_test_add_noise(&rng, t, n, noise * amscr_test_shape_size(t, n));
    amscr_result *r = NULL;
    reg_map(s, n, t, n, 1, 0, M, &r);
    double c = amscr_result_confidence(r);
    *out_amb = amscr_result_ambiguity(r);
    ck_assert(c >= 0.0 && c <= 1.0);
    amscr_result_free(r);
    free(a);
    free(t);
    return c;
}

/* Symmetric shapes stay ambiguous with the polish (check_robust.c's thresholds): a square and a
 * regular 5-pointed star onto a noisy (1 % and 2 %) affine copy. Measured: ambiguity 1.000,
 * confidence 0.000 in all four. */
START_TEST(symmetric_stay_ambiguous)
{
    double xy[2 * 400], amb;
    const double sq[8] = {0, 0, 1, 0, 1, 1, 0, 1};
    double star[20];
    amscr_test_star5(star);
    const double noise[2] = {0.01, 0.02};
    for (int k = 0; k < 2; k++) {
        double c = noisy_confidence(xy, amscr_test_polygon(sq, 4, 90, xy), noise[k], 61 + (uint64_t)k, &amb);
        printf("polish: square, %.0f %% noise: confidence %.3f ambiguity %.3f\n", 100 * noise[k], c, amb);
        ck_assert_msg(amb > 0.8 && c < 0.2, "square: confidence %.3f ambiguity %.3f", c, amb);
        c = noisy_confidence(xy, amscr_test_polygon(star, 10, 36, xy), noise[k], 71 + (uint64_t)k, &amb);
        printf("polish: star, %.0f %% noise: confidence %.3f ambiguity %.3f\n", 100 * noise[k], c, amb);
        ck_assert_msg(amb > 0.8 && c < 0.2, "star: confidence %.3f ambiguity %.3f", c, amb);
    }
}
END_TEST

/* The polish's global partner search (nearest.c) equals brute force: random clouds, a thin
 * (nearly collinear) set, a single repeated point, and queries far outside the grid. */
START_TEST(grid_nearest_is_exact)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 77);
    double p[2 * 500], q[2];
    for (int set = 0; set < 4; set++) {
        size_t n = set == 3 ? 7 : 500;
        for (size_t i = 0; i < n; i++) {
            double u = amscr_test_uniform(&rng), v = amscr_test_uniform(&rng);
            p[2 * i] = set == 3 ? 1.5 : 100.0 * u;
            p[2 * i + 1] = set == 3 ? -2.0 : (set == 1 ? 1e-6 * v : 100.0 * v) + (set == 2 ? 5.0 * u : 0.0);
        }
        amscr__grid g = {0};
        ck_assert(amscr__grid_build(&g, p, n));
        for (int k = 0; k < 200; k++) {
            double spread = k % 4 == 0 ? 1e6 : 150.0;
            q[0] = spread * (amscr_test_uniform(&rng) - 0.3);
            q[1] = spread * (amscr_test_uniform(&rng) - 0.3);
            double d, best = INFINITY;
            size_t i = amscr__grid_nearest(&g, p, q[0], q[1], &d);
            for (size_t j = 0; j < n; j++) {
                double dx = p[2 * j] - q[0], dy = p[2 * j + 1] - q[1];
                best = dx * dx + dy * dy < best ? dx * dx + dy * dy : best;
            }
            ck_assert_msg(d == best && i < n, "set %d query %d: %g vs brute force %g", set, k, d, best);
        }
        amscr__grid_free(&g);
    }
    p[0] = NAN;
    amscr__grid g = {0};
    ck_assert(!amscr__grid_build(&g, p, 10)); /* non-finite points are refused */
    amscr__grid_free(&g);
}
END_TEST

/* The closest point on a polygon (refine.c: refinement, correspondences, recovery and partial
 * matching read it) equals brute force over every edge, the foot clamped to the edge's ends: open
 * and closed random polygons, queries near and far, beyond an open polygon's two ends (the foot
 * there is the end vertex itself), every edge searched; a closed polygon's faster search from its
 * edge arrays gives the same result bit for bit, in every window. */
static double brute_closest(const double *H, size_t n, int closed, double px, double py, double *qx, double *qy)
{
    double best = INFINITY;
    for (size_t b = 0; b + (closed ? 0 : 1) < n; b++) {
        size_t c = (b + 1) % n;
        double ex = H[2 * c] - H[2 * b], ey = H[2 * c + 1] - H[2 * b + 1], l2 = ex * ex + ey * ey;
        double t = l2 > 0.0 ? ((px - H[2 * b]) * ex + (py - H[2 * b + 1]) * ey) / l2 : 0.0;
        t = fmin(1.0, fmax(0.0, t));
        double cx = H[2 * b] + t * ex, cy = H[2 * b + 1] + t * ey;
        double d2 = (px - cx) * (px - cx) + (py - cy) * (py - cy);
        if (d2 < best) {
            best = d2;
            *qx = cx;
            *qy = cy;
        }
    }
    return best;
}

START_TEST(closest_on_polygon_is_exact)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 41);
    enum { N = 40 };
    double H[2 * N], E[5 * N];
    for (int set = 0; set < 6; set++) {
        int closed = set % 2;
        for (size_t i = 0; i < N; i++) {
            double t = 6.283185307179586 * (double)i / N, r = 1.0 + 0.5 * amscr_test_uniform(&rng);
            H[2 * i] = r * cos(t);
            H[2 * i + 1] = r * sin(t);
        }
        amscr__closed_edges(H, N, E);
        for (int k = 0; k < 300; k++) {
            double spread = k % 3 == 0 ? 10.0 : 3.0;
            double px = spread * (amscr_test_uniform(&rng) - 0.5), py = spread * (amscr_test_uniform(&rng) - 0.5);
            if (k < 2) { /* beyond an open polygon's first and last vertex, along its end edges */
                size_t e = k == 0 ? 0 : N - 1, f = k == 0 ? 1 : N - 2;
                px = H[2 * e] + 0.3 * (H[2 * e] - H[2 * f]);
                py = H[2 * e + 1] + 0.3 * (H[2 * e + 1] - H[2 * f + 1]);
            }
            double qx = NAN, qy = NAN, bx = NAN, by = NAN;
            size_t seg = N;
            double d = amscr__closest_on_polygon(H, N, closed, 0, N, px, py, &qx, &qy, &seg);
            double want = brute_closest(H, N, closed, px, py, &bx, &by);
            ck_assert_msg(fabs(d - want) <= 1e-12 * (1.0 + want) && fabs(qx - bx) <= 1e-12 && fabs(qy - by) <= 1e-12,
                          "set %d query %d: %.17g at (%g, %g), brute force %.17g at (%g, %g)", set, k, d, qx, qy,
                          want, bx, by);
            ck_assert(seg < (closed ? N : N - 1));
            if (k < 2 && !closed) /* the end vertex itself */
                ck_assert(qx == H[2 * (k == 0 ? 0 : N - 1)] && qy == H[2 * (k == 0 ? 0 : N - 1) + 1]);
            for (size_t w = 0; closed && w < N; w += 7) {
                size_t b0 = (size_t)k % N, s1 = N, s2 = N;
                double x1, y1, x2, y2;
                double d1 = amscr__closest_on_polygon(H, N, 1, b0, w, px, py, &x1, &y1, &s1);
                double d2 = amscr__closest_on_closed(E, N, b0, w, px, py, &x2, &y2, &s2);
                ck_assert(d1 == d2 && x1 == x2 && y1 == y2 && s1 == s2);
            }
        }
    }
}
END_TEST

/* Odd inputs through the whole registration with the polish (and partial matching every sixth):
 * random point clouds read as polygons (self-intersecting), spiky radii, repeated points, shapes
 * 1e-5 thin, coordinates from 1e-4 to 1e4, noise: every call gives a finite map or a clean error
 * (the sanitizer and valgrind runs of the hardening pass run this too). */
START_TEST(odd_inputs_finite_or_refused)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 99);
    double a[2 * 400], b[2 * 400];
    size_t ok = 0;
    for (int it = 0; it < 48; it++) {
        size_t n = 8 + (size_t)(amscr_test_uniform(&rng) * 390), m = 8 + (size_t)(amscr_test_uniform(&rng) * 390);
        double scale = pow(10.0, 8.0 * amscr_test_uniform(&rng) - 4.0), thin = it % 7 == 0 ? 1e-5 : 1.0;
        int kind = it % 4;
        for (size_t i = 0; i < n; i++) {
            double t = 6.283185307179586 * (double)i / (double)n;
            double r = 1.0 + (kind == 1 ? amscr_test_uniform(&rng) : 0.3 * cos(3.0 * t));
            a[2 * i] = scale * (kind == 2 ? amscr_test_uniform(&rng) : r * cos(t));
            a[2 * i + 1] = scale * thin * (kind == 2 ? amscr_test_uniform(&rng) : r * sin(t));
            if (kind == 3 && i % 5 == 1) { /* repeated points */
                a[2 * i] = a[2 * i - 2];
                a[2 * i + 1] = a[2 * i - 1];
            }
        }
        double T[6];
        amscr_test_random_affine(&rng, 2.0, 0.5, 100.0 * scale, it % 2, T);
        for (size_t j = 0; j < m; j++) {
            size_t i = ((size_t)((double)j / (double)m * (double)n) + 3) % n;
            amscr_test_apply_affine(T, &a[2 * i], 1, &b[2 * j]);
        }
        amscr_test_add_noise(&rng, b, m, (it % 3) * 0.01 * scale);
        amscr_params *p = preset(1, it % 6 == 5);
        amscr_contour *ca = NULL, *cb = NULL;
        amscr_result *r = NULL;
        ck_assert_int_eq(amscr_contour_new(a, n, &ca), AMSCR_OK);
        ck_assert_int_eq(amscr_contour_new(b, m, &cb), AMSCR_OK);
        amscr_status st = amscr_register_contours(p, ca, cb, &r);
        if (st == AMSCR_OK) {
            double M[6];
            ck_assert_int_eq(amscr_result_affine(r, M), AMSCR_OK);
            for (int k = 0; k < 6; k++)
                ck_assert_msg(isfinite(M[k]), "pair %d: non-finite map", it);
            ok++;
        } else {
            ck_assert_msg(st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG || st == AMSCR_E_NUMERIC,
                          "pair %d: status %d", it, (int)st);
            ck_assert(amscr_last_error_detail()[0] != '\0');
        }
        amscr_result_free(r);
        amscr_contour_free(ca);
        amscr_contour_free(cb);
        amscr_params_free(p);
    }
    printf("polish: odd inputs: %zu of 48 registered, the rest refused cleanly\n", ok);
    ck_assert(ok >= 24); /* most of them are valid shapes */
}
END_TEST

Suite *amscr_suite_polish(void)
{
    Suite *s = suite_create("polish");
    TCase *tc = tcase_create("polish");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, polish_flag);
    tcase_add_test(tc, noisy_target);
    tcase_add_test(tc, noisy_source);
    tcase_add_test(tc, exact_pairs_stay_exact);
    tcase_add_test(tc, no_polish_without_input_points);
    tcase_add_test(tc, partial_polished);
    tcase_add_test(tc, symmetric_stay_ambiguous);
    tcase_add_test(tc, grid_nearest_is_exact);
    tcase_add_test(tc, closest_on_polygon_is_exact);
    tcase_add_test(tc, odd_inputs_finite_or_refused);
    suite_add_tcase(s, tc);
    return s;
}
