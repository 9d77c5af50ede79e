/* check_accuracy.c — the registration accuracy protocol (docs/measurements.md, "Accuracy suite").
 *
 * Every case: a source contour f, a random affine map T (any rotation, anisotropic scale up to
 * 2, shear up to 0.5, random translation; det < 0 in the mirror cases), and a target that is
 * T(f) with a new start point and a different number of input points (and, for the
 * robustness cases, 1 % Gaussian noise or a contiguous 5 % of the points removed). The
 * recovered map M = amscr_result_affine is scored by
 *
 *     err = max_i |M(f_i) - T(f_i)| / size(T(f))       (size: amscr_test_shape_size)
 *
 * over the source's own input points. Targets, asserted as stated:
 *   synthetic clean, det > 0 and det < 0:  err < 0.5 % in every case, median <= 0.1 %
 *                                         (asserted tighter, within 4x of the measured:
 *                                         worst < 0.1 %, median <= 0.01 %)
 *   synthetic 1 % noise:                  err < 2 % in >= 95 % of the cases
 *   synthetic 5 % occlusion:              err < 2 % in >= 90 % of the cases
 *   Kimia-99 + Kimia-216 pixel contours:  err < 2 % in >= 99 % (clean), >= 97 % (noise),
 *                                         >= 95 % (occlusion)
 *   and the heavier conditions of the robust registration on the same contours (one map each): 2 % noise,
 *   10 % and 20 % of the boundary missing, at the measured levels (KIMIA_T_*)
 * The measured rates, the worst cases (seed / file) and the mean time per registration are
 * printed so they show in the test log; time is never asserted.
 */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "suites.h"
#include "testutil.h"

/* Registration accuracy is measured with the library's registration preset
 * (amscr_params_new_registration: N 256, 20 refinement iterations), which the tool's
 * `register` and Python's `register()` use by default; the plain defaults serve collections. */


#define SYN_CASES 240 /* >= 200 seeded shapes per condition */
#define KIMIA_REPEATS 2 /* random affine maps per image and condition (the protocol's three conditions) */
#define KIMIA_CONDS 7
/* the heavier conditions (one map per image), asserted a little below the levels
 * measured on this suite (0.3.2 with the polish, the order and the even spacing of noisy points:
 * 2 % noise 98.73 % (0.3.1: 95.87 %, 0.3: 93.65 %, 84.1 % before the polish), 10 % missing
 * 100 %, 20 % missing 98.7 %; the goals of the robust registration are 99 / 95 / 85 %) */
#define KIMIA_T_NOISE2 0.97
#define KIMIA_T_MISSING10 0.97
#define KIMIA_T_MISSING20 0.92
/* The 2 % noise threshold above followed the measurements on its own draws (seeds 400000 +
 * 10 i). A seventh row draws the same condition afresh (seeds 700000 + 10 i, never used to
 * choose anything), so a change tuned to the first draws shows here. It is asserted at the
 * first row's level, fixed before this row was measured and never to be moved to follow it. */
#define KIMIA_T_NOISE2_FRESH KIMIA_T_NOISE2

/* ------------------------------------------------------------------ helpers */

static double clock_seconds(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double now_seconds(void) { return clock_seconds(CLOCK_MONOTONIC); }
/* CPU time of this thread: meaningful on a loaded machine, where wall time is not */
static double cpu_seconds(void) { return clock_seconds(CLOCK_THREAD_CPUTIME_ID); }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median_of(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

typedef enum {
    COND_CLEAN = 0,
    COND_MIRROR = 1,
    COND_NOISE = 2,
    COND_OCCLUSION = 3,
    COND_NOISE2 = 4,   /* 2 % noise */
    COND_MISSING10 = 5, /* 10 % of the boundary missing */
    COND_MISSING20 = 6  /* 20 % of the boundary missing */
} condition;
static const char *const cond_name[] = {"clean",    "mirror (det<0)", "1% noise",   "5% occlusion",
                                        "2% noise", "10% missing",    "20% missing"};

/* Timing accumulators of one run (prepare both shapes + register, and register only) and the
 * run's workspace (reused, as a batch caller would). */
typedef struct {
    double t_total, t_register, c_total, c_register;
    size_t count;
    amscr_workspace *ws;
} timing;

/* "a ms/pair (b ms/registration), CPU c / d ms" */
static void print_timing(const timing *tm)
{
    double n = (double)(tm->count ? tm->count : 1);
    printf("wall %.3f ms/pair (prepare both + register), %.3f ms/registration; CPU %.3f ms/pair, %.3f "
           "ms/registration\n",
           1e3 * tm->t_total / n, 1e3 * tm->t_register / n, 1e3 * tm->c_total / n, 1e3 * tm->c_register / n);
}

/* Registers src onto tgt with params prm; returns the error measure (or +inf when a call
 * fails, with the status in *out_status) and the distance. */
static double score_pair(const amscr_params *prm, const double *src, size_t ns, const double *tgt, size_t nt,
                         const double T[6], timing *tm, amscr_status *out_status, double *out_dist)
{
    amscr_contour *cs = NULL, *ct = NULL;
    amscr_descriptor *ds = NULL, *dt = NULL;
    amscr_result *r = NULL;
    double err = INFINITY;
    *out_dist = NAN;
    amscr_status st = amscr_contour_new(src, ns, &cs);
    if (st == AMSCR_OK)
        st = amscr_contour_new(tgt, nt, &ct);
    double t0 = now_seconds(), t1 = t0, t2 = t0, c0 = cpu_seconds(), c1 = c0, c2 = c0;
    if (st == AMSCR_OK) {
        t0 = now_seconds();
        c0 = cpu_seconds();
        st = amscr_descriptor_new(prm, cs, &ds);
        if (st == AMSCR_OK)
            st = amscr_descriptor_new(prm, ct, &dt);
        t1 = now_seconds();
        c1 = cpu_seconds();
        if (st == AMSCR_OK)
            st = amscr_register(prm, ds, dt, tm->ws, &r);
        t2 = now_seconds();
        c2 = cpu_seconds();
    }
    if (st == AMSCR_OK) {
        tm->t_total += t2 - t0;
        tm->t_register += t2 - t1;
        tm->c_total += c2 - c0;
        tm->c_register += c2 - c1;
        tm->count++;
        double M[6];
        st = amscr_result_affine(r, M);
        if (st == AMSCR_OK) {
            double *img = malloc(2 * ns * sizeof *img);
            ck_assert_ptr_nonnull(img);
            amscr_test_apply_affine(T, src, ns, img);
            double size = amscr_test_shape_size(img, ns);
            err = amscr_test_max_map_error(M, T, src, ns) / size;
            if (!(err == err))
                err = INFINITY;
            free(img);
            *out_dist = amscr_result_distance(r);
        }
    }
    *out_status = st;
    amscr_result_free(r);
    amscr_descriptor_free(ds);
    amscr_descriptor_free(dt);
    amscr_contour_free(cs);
    amscr_contour_free(ct);
    return err;
}

/* Builds the target from the mapped source points `mapped` (n points, already T(f) sampled as
 * wanted): reversal for mirror cases, noise, occlusion. Returns the new count; out has room for
 * 2n doubles. */
static size_t degrade_target(amscr_test_rng *rng, condition cond, const double *mapped, size_t n, double *out)
{
    memcpy(out, mapped, 2 * n * sizeof *out);
    if (cond == COND_MIRROR) { /* reversed order: a mirror image traversed counter-clockwise */
        for (size_t i = 0; i < n; i++) {
            out[2 * i] = mapped[2 * (n - 1 - i)];
            out[2 * i + 1] = mapped[2 * (n - 1 - i) + 1];
        }
    } else if (cond == COND_NOISE || cond == COND_NOISE2) {
        amscr_test_add_noise(rng, out, n, (cond == COND_NOISE ? 0.01 : 0.02) * amscr_test_shape_size(mapped, n));
    } else if (cond == COND_OCCLUSION || cond == COND_MISSING10 || cond == COND_MISSING20) {
        /* drop a contiguous run of 5 / 10 / 20 % of the points; the rest stays a closed curve */
        double share = cond == COND_OCCLUSION ? 0.05 : (cond == COND_MISSING10 ? 0.10 : 0.20);
        size_t drop = (size_t)ceil(share * (double)n);
        size_t start = (size_t)(amscr_test_uniform(rng) * (double)n) % n;
        size_t m = 0;
        for (size_t k = drop; k < n; k++) {
            size_t i = (start + k) % n;
            out[2 * m] = mapped[2 * i];
            out[2 * m + 1] = mapped[2 * i + 1];
            m++;
        }
        return m;
    }
    return n;
}

/* ------------------------------------------------------------------ synthetic */

typedef struct {
    size_t cases, within_half, within_2pct, failures_status;
    double worst;
    uint64_t worst_seed;
    double max_dist;
    double *errs;
    timing tm;
} syn_stats;

/* One synthetic case: a random star-shaped curve (complexity 3..10) sampled at ns points,
 * and the same curve function re-sampled at nt != ns points, cyclically shifted, mapped. */
static double synthetic_case(const amscr_params *prm, condition cond, uint64_t seed, timing *tm,
                             amscr_status *st, double *dist)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    int complexity = 3 + (int)(amscr_test_rng_next(&rng) % 8);
    size_t ns = 200 + (size_t)(amscr_test_uniform(&rng) * 400.0);
    size_t nt;
    do
        nt = 150 + (size_t)(amscr_test_uniform(&rng) * 500.0);
    while (nt == ns);
    size_t shift = (size_t)(amscr_test_uniform(&rng) * (double)nt) % nt;
    double T[6];
    amscr_test_random_affine(&rng, 2.0, 0.5, 10.0, cond == COND_MIRROR, T);
    amscr_test_rng shape_rng = rng; /* the same shape function for both samplings */
    amscr_test_rng shape_rng2 = rng;
    (void)amscr_test_rng_next(&rng);
    double *src = malloc(2 * ns * sizeof *src), *fun = malloc(2 * nt * sizeof *fun);
    double *sh = malloc(2 * nt * sizeof *sh), *tgt = malloc(2 * nt * sizeof *tgt);
    ck_assert(src && fun && sh && tgt);
    amscr_test_random_shape(&shape_rng, ns, complexity, src);
    amscr_test_random_shape(&shape_rng2, nt, complexity, fun);
    amscr_test_cyclic_shift(fun, nt, shift, sh);
    amscr_test_apply_affine(T, sh, nt, fun);
    size_t m = degrade_target(&rng, cond, fun, nt, tgt);
    double err = score_pair(prm, src, ns, tgt, m, T, tm, st, dist);
    free(src);
    free(fun);
    free(sh);
    free(tgt);
    return err;
}

static void run_synthetic(condition cond, syn_stats *s)
{
    amscr_params *prm = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&prm), AMSCR_OK);
    if (cond == COND_MIRROR)
        ck_assert_int_eq(amscr_params_set_reflections(prm, 1), AMSCR_OK);
    memset(s, 0, sizeof *s);
    ck_assert_int_eq(amscr_workspace_new(&s->tm.ws), AMSCR_OK);
    s->errs = malloc(SYN_CASES * sizeof *s->errs);
    ck_assert_ptr_nonnull(s->errs);
    for (size_t c = 0; c < SYN_CASES; c++) {
        uint64_t seed = 1000u * (uint64_t)(cond + 1) + c;
        amscr_status st;
        double dist;
        double err = synthetic_case(prm, cond, seed, &s->tm, &st, &dist);
        if (st != AMSCR_OK) {
            s->failures_status++;
            printf("accuracy: synthetic %s seed %llu: status %d (%s)\n", cond_name[cond], (unsigned long long)seed,
                   (int)st, amscr_last_error_detail());
        }
        s->errs[c] = err;
        s->cases++;
        if (err < 0.005)
            s->within_half++;
        if (err < 0.02)
            s->within_2pct++;
        if (err > s->worst || c == 0) {
            s->worst = err;
            s->worst_seed = seed;
        }
        if (dist == dist && dist > s->max_dist)
            s->max_dist = dist;
        if ((cond <= COND_MIRROR && !(err < 0.005)) || (cond > COND_MIRROR && !(err < 0.02)))
            printf("accuracy: synthetic %s seed %llu: error %.4f %% of the shape size\n", cond_name[cond],
                   (unsigned long long)seed, 100.0 * err);
    }
    amscr_workspace_free(s->tm.ws);
    s->tm.ws = NULL;
    amscr_params_free(prm);
}

static void print_syn(condition cond, syn_stats *s)
{
    double *copy = malloc(s->cases * sizeof *copy);
    ck_assert_ptr_nonnull(copy);
    memcpy(copy, s->errs, s->cases * sizeof *copy);
    double med = median_of(copy, s->cases);
    free(copy);
    printf("accuracy: synthetic %-14s %zu cases: < 0.5 %%: %.2f %%, < 2 %%: %.2f %%, median %.5f %%, worst %.4f %% "
           "(seed %llu), max distance %.3g; ",
           cond_name[cond], s->cases, 100.0 * (double)s->within_half / (double)s->cases,
           100.0 * (double)s->within_2pct / (double)s->cases, 100.0 * med, 100.0 * s->worst,
           (unsigned long long)s->worst_seed, s->max_dist);
    print_timing(&s->tm);
    fflush(stdout);
}

/* Median distance between DIFFERENT random shapes of the synthetic generator (16 shapes, all
 * ordered pairs): the scale against which "the distance is ~0" is judged. */
static double between_shape_median(const amscr_params *prm)
{
    enum { NSH = 16 };
    amscr_descriptor *d[NSH];
    for (int i = 0; i < NSH; i++) {
        amscr_test_rng rng;
        amscr_test_rng_seed(&rng, 900u + (uint64_t)i);
        size_t n = 200 + 23 * (size_t)i;
        double *xy = malloc(2 * n * sizeof *xy);
        ck_assert_ptr_nonnull(xy);
        amscr_test_random_shape(&rng, n, 3 + i % 8, xy);
        amscr_contour *c = NULL;
        ck_assert_int_eq(amscr_contour_new(xy, n, &c), AMSCR_OK);
        ck_assert_int_eq(amscr_descriptor_new(prm, c, &d[i]), AMSCR_OK);
        amscr_contour_free(c);
        free(xy);
    }
    double v[NSH * (NSH - 1)];
    size_t m = 0;
    for (int i = 0; i < NSH; i++)
        for (int j = 0; j < NSH; j++)
            if (i != j)
                ck_assert_int_eq(amscr_distance(prm, d[i], d[j], NULL, &v[m++]), AMSCR_OK);
    for (int i = 0; i < NSH; i++)
        amscr_descriptor_free(d[i]);
    return median_of(v, m);
}

static void assert_exact_protocol(condition cond)
{
    syn_stats s;
    run_synthetic(cond, &s);
    print_syn(cond, &s);
    amscr_params *prm = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&prm), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_reflections(prm, cond == COND_MIRROR), AMSCR_OK);
    double between = between_shape_median(prm);
    amscr_params_free(prm);
    printf("accuracy: synthetic %-14s largest distance %.3g = %.3g %% of the median distance between different "
           "shapes (%.3g)\n",
           cond_name[cond], s.max_dist, 100.0 * s.max_dist / between, between);
    ck_assert_int_ge(s.cases, 200);
    ck_assert_int_eq(s.failures_status, 0);
    double *copy = malloc(s.cases * sizeof *copy);
    ck_assert_ptr_nonnull(copy);
    memcpy(copy, s.errs, s.cases * sizeof *copy);
    double med = median_of(copy, s.cases);
    free(copy);
    /* every case within 0.5 % of the shape size, the median within 0.1 % */
    ck_assert_msg(s.within_half == s.cases, "%s: %zu of %zu cases within 0.5 %% (worst %.4f %%, seed %llu)",
                  cond_name[cond], s.within_half, s.cases, 100.0 * s.worst, (unsigned long long)s.worst_seed);
    /* tighter than the protocol's 0.1 %, within 4x of the measured: median 0.00304 % (clean)
     * and 0.00357 % (det < 0), worst 0.0259 % and 0.0268 % (CK_RUN_CASE=synthetic
     * build/tests/check_accuracy). Without the refinement and the polish the preset gives
     * median 0.0144 / 0.0177 %, worst 0.161 / 0.140 %: these bounds catch that. */
    ck_assert_msg(med <= 0.0001, "%s: median error %.5f %% > 0.01 %%", cond_name[cond], 100.0 * med);
    ck_assert_msg(s.worst < 0.001, "%s: worst error %.4f %% >= 0.1 %% (seed %llu)", cond_name[cond],
                  100.0 * s.worst, (unsigned long long)s.worst_seed);
    /* "the distance is ~0": an exact affine image up to re-sampling must sit far below the
     * distance between different shapes: under 1 % of their median */
    ck_assert_msg(s.max_dist < 0.01 * between, "%s: largest distance %.3g vs median between-shape distance %.3g",
                  cond_name[cond], s.max_dist, between);
    free(s.errs);
}

START_TEST(synthetic_exact)
{
    assert_exact_protocol(COND_CLEAN);
}
END_TEST

START_TEST(synthetic_mirror)
{
    assert_exact_protocol(COND_MIRROR);
}
END_TEST

START_TEST(synthetic_noise)
{
    syn_stats s;
    run_synthetic(COND_NOISE, &s);
    print_syn(COND_NOISE, &s);
    ck_assert_int_ge(s.cases, 200);
    double rate = (double)s.within_2pct / (double)s.cases;
    ck_assert_msg(rate >= 0.95, "1 %% noise: %.2f %% of cases within 2 %% (< 95 %%)", 100.0 * rate);
    free(s.errs);
}
END_TEST

START_TEST(synthetic_occlusion)
{
    syn_stats s;
    run_synthetic(COND_OCCLUSION, &s);
    print_syn(COND_OCCLUSION, &s);
    ck_assert_int_ge(s.cases, 200);
    double rate = (double)s.within_2pct / (double)s.cases;
    ck_assert_msg(rate >= 0.90, "5 %% occlusion: %.2f %% of cases within 2 %% (< 90 %%)", 100.0 * rate);
    free(s.errs);
}
END_TEST

/* ------------------------------------------------------------------ Kimia */

typedef struct {
    char **files; /* full paths */
    size_t n;
} file_list;

static void list_add(file_list *l, const char *path)
{
    l->files = realloc(l->files, (l->n + 1) * sizeof *l->files);
    ck_assert_ptr_nonnull(l->files);
    l->files[l->n] = malloc(strlen(path) + 1);
    ck_assert_ptr_nonnull(l->files[l->n]);
    strcpy(l->files[l->n], path);
    l->n++;
}

/* Files of <root>/<set>/manifest.tsv (first column, header skipped), in manifest order. */
static void read_manifest(const char *root, const char *set, file_list *l)
{
    char path[4096], line[1024];
    snprintf(path, sizeof path, "%s/%s/manifest.tsv", root, set);
    FILE *fp = fopen(path, "r");
    ck_assert_msg(fp != NULL, "cannot open %s", path);
    int first = 1;
    while (fgets(line, sizeof line, fp)) {
        if (first) {
            first = 0;
            continue;
        }
        char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        *tab = '\0';
        char full[4096];
        snprintf(full, sizeof full, "%s/%s/%s", root, set, line);
        list_add(l, full);
    }
    fclose(fp);
}

static void list_free(file_list *l)
{
    for (size_t i = 0; i < l->n; i++)
        free(l->files[i]);
    free(l->files);
}

typedef struct {
    size_t cases, within, status_failures;
    double worst;
    timing tm;
} kimia_stats;

/* One Kimia pair: source = the traced contour; target = T(source), new start point, resampled
 * by Euclidean arc length to a different count (0.6..1.4 times), then degraded per cond. */
static double kimia_case(const amscr_params *prm, condition cond, const double *src, size_t ns, uint64_t seed,
                         timing *tm, amscr_status *st)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    double T[6];
    amscr_test_random_affine(&rng, 2.0, 0.5, 50.0, 0, T);
    size_t shift = (size_t)(amscr_test_uniform(&rng) * (double)ns) % ns;
    size_t nt;
    do
        nt = (size_t)((0.6 + 0.8 * amscr_test_uniform(&rng)) * (double)ns);
    while (nt == ns || nt < 16);
    double *a = malloc(2 * ns * sizeof *a), *b = malloc(2 * ns * sizeof *b);
    double *res = malloc(2 * nt * sizeof *res), *tgt = malloc(2 * nt * sizeof *tgt);
    ck_assert(a && b && res && tgt);
    amscr_test_cyclic_shift(src, ns, shift, a);
    amscr_test_apply_affine(T, a, ns, b);
    ck_assert_int_eq(amscr_resample_euclidean(b, ns, 1, nt, res), AMSCR_OK);
    size_t m = degrade_target(&rng, cond, res, nt, tgt);
    double dist;
    double err = score_pair(prm, src, ns, tgt, m, T, tm, st, &dist);
    free(a);
    free(b);
    free(res);
    free(tgt);
    return err;
}

START_TEST(kimia_pixel_contours)
{
    const char *root = amscr_test_datasets_or_skip("accuracy");
    if (!root)
        return;
    file_list files = {NULL, 0};
    read_manifest(root, "kimia99", &files);
    size_t n99 = files.n;
    read_manifest(root, "kimia216", &files);
    ck_assert_int_ge(n99, 99);
    ck_assert_int_ge(files.n - n99, 216);

    /* trace every image once */
    double **pts = calloc(files.n, sizeof *pts);
    size_t *npts = calloc(files.n, sizeof *npts);
    ck_assert(pts && npts);
    for (size_t i = 0; i < files.n; i++) {
        unsigned char *px = NULL;
        size_t w = 0, h = 0;
        ck_assert_msg(amscr_test_read_png_gray(files.files[i], &px, &w, &h) == 0, "cannot read %s", files.files[i]);
        amscr_contour *c = NULL;
        amscr_status st = amscr_contour_from_mask(px, w, h, w, 127, &c);
        ck_assert_msg(st == AMSCR_OK, "%s: %s", files.files[i], amscr_last_error_detail());
        npts[i] = amscr_contour_size(c);
        pts[i] = malloc(2 * npts[i] * sizeof(double));
        ck_assert_ptr_nonnull(pts[i]);
        memcpy(pts[i], amscr_contour_xy(c), 2 * npts[i] * sizeof(double));
        amscr_contour_free(c);
        free(px);
    }

    amscr_params *prm = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&prm), AMSCR_OK);
    /* Point lists with synthetic noise: the point-list stages on (opt-in since 0.5, when they
     * were measured to change no traced-image pair). The preset alone, measured: 2 % noise
     * 93.97 %, fresh draws 92.70 %; the other rows as below. */
    ck_assert_int_eq(amscr_params_set_stage(prm, "despike", 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_stage(prm, "order", 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_stage(prm, "even_spacing", 1), AMSCR_OK);
    /* the protocol's three conditions on every image twice; the heavier ones once each */
    const condition conds[KIMIA_CONDS] = {COND_CLEAN, COND_NOISE, COND_OCCLUSION, COND_NOISE2, COND_MISSING10,
                                          COND_MISSING20, COND_NOISE2};
    /* 1 % noise: 99.84 % measured with the polish (99.05 % before) */
    const double targets[KIMIA_CONDS] = {0.99, 0.98, 0.95, KIMIA_T_NOISE2, KIMIA_T_MISSING10, KIMIA_T_MISSING20,
                                         KIMIA_T_NOISE2_FRESH};
    const unsigned repeats[KIMIA_CONDS] = {KIMIA_REPEATS, KIMIA_REPEATS, KIMIA_REPEATS, 1, 1, 1, 1};
    kimia_stats ks[KIMIA_CONDS];
    for (int ci = 0; ci < KIMIA_CONDS; ci++) {
        condition cond = conds[ci];
        kimia_stats *s = &ks[ci];
        memset(s, 0, sizeof *s);
        ck_assert_int_eq(amscr_workspace_new(&s->tm.ws), AMSCR_OK);
        for (size_t i = 0; i < files.n; i++) {
            for (unsigned rep = 0; rep < repeats[ci]; rep++) {
                uint64_t seed = 100000u * (uint64_t)(ci + 1) + 10u * i + rep;
                amscr_status st;
                double err = kimia_case(prm, cond, pts[i], npts[i], seed, &s->tm, &st);
                s->cases++;
                if (st != AMSCR_OK) {
                    s->status_failures++;
                    printf("accuracy: kimia %s %s seed %llu: status %d (%s)\n", cond_name[cond], files.files[i],
                           (unsigned long long)seed, (int)st, amscr_last_error_detail());
                }
                if (err < 0.02)
                    s->within++;
                else
                    printf("accuracy: kimia %s: %s seed %llu: error %.3f %% of the shape size\n", cond_name[cond],
                           files.files[i] + strlen(root) + 1, (unsigned long long)seed, 100.0 * err);
                if (err > s->worst)
                    s->worst = err;
            }
        }
        amscr_workspace_free(s->tm.ws);
        s->tm.ws = NULL;
        printf("accuracy: kimia99+216 %-12s%s %zu pairs: %.2f %% within 2 %% (target >= %.0f %%), worst %.3g %%; ",
               cond_name[cond], ci == KIMIA_CONDS - 1 ? " (fresh draws)" : "", s->cases, 100.0 * (double)s->within / (double)s->cases, 100.0 * targets[ci],
               100.0 * s->worst);
        print_timing(&s->tm);
        fflush(stdout);
    }
    amscr_params_free(prm);
    for (size_t i = 0; i < files.n; i++)
        free(pts[i]);
    free(pts);
    free(npts);
    list_free(&files);
    double rate[KIMIA_CONDS];
    int ok = 1;
    for (int ci = 0; ci < KIMIA_CONDS; ci++) {
        rate[ci] = (double)ks[ci].within / (double)ks[ci].cases;
        ok = ok && rate[ci] >= targets[ci];
    }
    ck_assert_msg(ok,
                  "kimia pairs within 2 %%: clean %.2f %% (target 99), 1 %% noise %.2f %% (target 98), "
                  "5 %% occlusion %.2f %% (target 95), 2 %% noise %.2f %% (target %.0f), 10 %% missing %.2f %% "
                  "(target %.0f), 20 %% missing %.2f %% (target %.0f), 2 %% noise fresh draws %.2f %% (target %.0f)",
                  100.0 * rate[0], 100.0 * rate[1], 100.0 * rate[2], 100.0 * rate[3], 100.0 * KIMIA_T_NOISE2,
                  100.0 * rate[4], 100.0 * KIMIA_T_MISSING10, 100.0 * rate[5], 100.0 * KIMIA_T_MISSING20,
                  100.0 * rate[6], 100.0 * KIMIA_T_NOISE2_FRESH);
}
END_TEST

Suite *amscr_suite_accuracy(void)
{
    Suite *s = suite_create("accuracy");
    TCase *syn = tcase_create("synthetic");
    tcase_set_timeout(syn, 300);
    tcase_add_test(syn, synthetic_exact);
    tcase_add_test(syn, synthetic_mirror);
    tcase_add_test(syn, synthetic_noise);
    tcase_add_test(syn, synthetic_occlusion);
    suite_add_tcase(s, syn);
    TCase *kim = tcase_create("kimia");
    tcase_set_timeout(kim, 600);
    tcase_add_test(kim, kimia_pixel_contours);
    suite_add_tcase(s, kim);
    return s;
}
