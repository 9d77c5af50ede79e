/* check_db.c — collections: building, getters, batch distances (vs amscr_distance, across
 * thread counts), edge cases, progress and cancellation, save/load round trips and corrupt
 * files. Only the public API (plus testutil) is used. */
#include <check.h>
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amscr.h"
#include "suites.h"
#include "testutil.h"

/* ---------------------------------------------------------------- helpers */

#define NPTS 96 /* points per synthetic contour */

static amscr_params *make_params(size_t N, const double *scales, size_t nscales, unsigned threads)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(p, N), AMSCR_OK);
    if (scales)
        ck_assert_int_eq(amscr_params_set_scales(p, scales, nscales), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(p, threads), AMSCR_OK);
    return p;
}

static const double SCALES3[3] = {0.0, 1.0, 2.5};

static amscr_params *small_params(unsigned threads) { return make_params(48, SCALES3, 3, threads); }

static amscr_contour *random_contour(amscr_test_rng *rng, int complexity)
{
    double xy[2 * NPTS];
    amscr_test_random_shape(rng, NPTS, complexity, xy);
    double m6[6], out[2 * NPTS];
    amscr_test_random_affine(rng, 2.0, 0.3, 5.0, 0, m6);
    amscr_test_apply_affine(m6, xy, NPTS, out);
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(out, NPTS, &c), AMSCR_OK);
    return c;
}

/* count descriptors built with p from random shapes (seeded). */
static amscr_descriptor **make_descs(const amscr_params *p, size_t count, uint64_t seed)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    amscr_descriptor **d = calloc(count, sizeof *d);
    ck_assert_ptr_nonnull(d);
    for (size_t i = 0; i < count; i++) {
        amscr_contour *c = random_contour(&rng, 3 + (int)(i % 5));
        amscr_status st = amscr_descriptor_new(p, c, &d[i]);
        ck_assert_msg(st == AMSCR_OK, "descriptor %zu: %s", i, amscr_last_error_detail());
        amscr_contour_free(c);
    }
    return d;
}

static void free_descs(amscr_descriptor **d, size_t count)
{
    for (size_t i = 0; i < count; i++)
        amscr_descriptor_free(d[i]);
    free(d);
}

static int32_t label_of(size_t i) { return (int32_t)(i % 7) * 1000 - 3000 + (int32_t)i; }

static amscr_db *db_from(const amscr_params *p, amscr_descriptor *const *d, size_t count)
{
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (size_t i = 0; i < count; i++) {
        size_t idx = 12345;
        amscr_status st = amscr_db_add_descriptor(db, d[i], label_of(i), &idx);
        ck_assert_msg(st == AMSCR_OK, "add %zu: %s", i, amscr_last_error_detail());
        ck_assert_uint_eq(idx, i);
    }
    return db;
}

static double *alloc_doubles(size_t n)
{
    double *x = malloc((n ? n : 1) * sizeof *x);
    ck_assert_ptr_nonnull(x);
    return x;
}

/* A NaN with a recognisable payload: a cell still holding it was never written. */
static double sentinel(void)
{
    uint64_t v = 0x7ff8dead0000beefull;
    double d;
    memcpy(&d, &v, 8);
    return d;
}

static void fill_sentinel(double *x, size_t n)
{
    double s = sentinel();
    for (size_t i = 0; i < n; i++)
        x[i] = s;
}

static int all_sentinel(const double *x, size_t n)
{
    double s = sentinel();
    for (size_t i = 0; i < n; i++)
        if (memcmp(&x[i], &s, sizeof s) != 0)
            return 0;
    return 1;
}

static int same_bits(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

static void expect_detail(void)
{
    const char *d = amscr_last_error_detail();
    ck_assert_ptr_nonnull(d);
    ck_assert_msg(d[0] != '\0', "no error detail");
}

/* -------------------------------------------------------------- progress */

typedef struct {
    pthread_t caller;
    size_t calls;
    size_t first_done, last_done, last_total;
    int monotonic, bounded, total_constant, same_thread;
    size_t cancel_at; /* return non-zero on this call number (1-based); 0 = never */
} prog_rec;

static void prog_init(prog_rec *r, size_t cancel_at)
{
    memset(r, 0, sizeof *r);
    r->caller = pthread_self();
    r->monotonic = r->bounded = r->total_constant = r->same_thread = 1;
    r->cancel_at = cancel_at;
}

static int prog_cb(void *user, size_t done, size_t total)
{
    prog_rec *r = user;
    if (!pthread_equal(pthread_self(), r->caller))
        r->same_thread = 0;
    if (done > total)
        r->bounded = 0;
    if (r->calls > 0) {
        if (done < r->last_done)
            r->monotonic = 0;
        if (total != r->last_total)
            r->total_constant = 0;
    } else {
        r->first_done = done;
    }
    r->calls++;
    r->last_done = done;
    r->last_total = total;
    return (r->cancel_at && r->calls >= r->cancel_at) ? 1 : 0;
}

static void prog_check_complete(const prog_rec *r, size_t total, const char *what)
{
    ck_assert_msg(r->calls >= 1, "%s: progress never called", what);
    ck_assert_msg(r->same_thread, "%s: progress called from another thread", what);
    ck_assert_msg(r->bounded, "%s: done > total", what);
    ck_assert_msg(r->monotonic, "%s: done decreased", what);
    ck_assert_msg(r->total_constant, "%s: total changed between calls", what);
    ck_assert_msg(r->last_total == total, "%s: total %zu, expected %zu", what, r->last_total, total);
    ck_assert_msg(r->last_done == total, "%s: final done %zu, expected %zu", what, r->last_done, total);
}

/* ------------------------------------------------------- building, getters */

START_TEST(db_add_and_getters)
{
    amscr_params *p = small_params(1);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    /* the db copies p: changing p afterwards does not change the db */
    ck_assert_int_eq(amscr_params_set_num_samples(p, 64), AMSCR_OK);
    const amscr_params *dp = amscr_db_params(db);
    ck_assert_ptr_nonnull(dp);
    ck_assert_uint_eq(amscr_params_get_num_samples(dp), 48);
    double sc[8];
    size_t ns = 8;
    ck_assert_int_eq(amscr_params_get_scales(dp, sc, &ns), AMSCR_OK);
    ck_assert_uint_eq(ns, 3);
    ck_assert(memcmp(sc, SCALES3, sizeof SCALES3) == 0);
    ck_assert_int_eq(amscr_params_get_num_threads(dp), 1);
    ck_assert_uint_eq(amscr_db_size(db), 0);
    ck_assert_ptr_null(amscr_db_descriptor(db, 0));
    ck_assert_int_eq(amscr_db_label(db, 0), 0);

    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 101);
    const size_t n = 6;
    for (size_t i = 0; i < n; i++) {
        amscr_contour *c = random_contour(&rng, 4);
        size_t idx = 999;
        ck_assert_int_eq(amscr_db_add_contour(db, c, label_of(i), &idx), AMSCR_OK);
        ck_assert_uint_eq(idx, i);
        ck_assert_uint_eq(amscr_db_size(db), i + 1);
        /* the stored descriptor is the one amscr_descriptor_new makes with the db's params */
        amscr_descriptor *ref = NULL;
        ck_assert_int_eq(amscr_descriptor_new(dp, c, &ref), AMSCR_OK);
        const amscr_descriptor *got = amscr_db_descriptor(db, i);
        ck_assert_ptr_nonnull(got);
        ck_assert_uint_eq(amscr_descriptor_num_samples(got), 48);
        ck_assert_uint_eq(amscr_descriptor_num_scales(got), 3);
        ck_assert(memcmp(amscr_descriptor_base_points(got), amscr_descriptor_base_points(ref),
                         2 * 48 * sizeof(double)) == 0);
        for (size_t k = 0; k < 3; k++)
            ck_assert(memcmp(amscr_descriptor_scale_points(got, k), amscr_descriptor_scale_points(ref, k),
                             2 * 48 * sizeof(double)) == 0);
        amscr_descriptor_free(ref);
        amscr_contour_free(c);
    }
    /* out_index may be NULL */
    amscr_contour *c = random_contour(&rng, 5);
    ck_assert_int_eq(amscr_db_add_contour(db, c, INT32_MIN, NULL), AMSCR_OK);
    amscr_contour_free(c);
    ck_assert_uint_eq(amscr_db_size(db), n + 1);
    for (size_t i = 0; i < n; i++)
        ck_assert_int_eq(amscr_db_label(db, i), label_of(i));
    ck_assert_int_eq(amscr_db_label(db, n), INT32_MIN);
    ck_assert_ptr_null(amscr_db_descriptor(db, n + 1));
    ck_assert_ptr_null(amscr_db_descriptor(db, SIZE_MAX));
    ck_assert_int_eq(amscr_db_label(db, n + 1), 0);
    ck_assert_int_eq(amscr_db_label(db, SIZE_MAX), 0);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(db_new_null_params_defaults)
{
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(NULL, &db), AMSCR_OK);
    amscr_params *def = NULL;
    ck_assert_int_eq(amscr_params_new(&def), AMSCR_OK);
    const amscr_params *dp = amscr_db_params(db);
    ck_assert_uint_eq(amscr_params_get_num_samples(dp), amscr_params_get_num_samples(def));
    ck_assert_int_eq(amscr_params_get_method(dp), amscr_params_get_method(def));
    ck_assert_uint_eq(amscr_params_get_num_threads(dp), amscr_params_get_num_threads(def));
    size_t n1 = 0, n2 = 0;
    ck_assert_int_eq(amscr_params_get_scales(dp, NULL, &n1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_scales(def, NULL, &n2), AMSCR_OK);
    ck_assert_uint_eq(n1, n2);
    ck_assert_uint_eq(amscr_db_size(db), 0);
    amscr_params_free(def);
    amscr_db_free(db);
    amscr_db_free(NULL); /* accepts NULL */
}
END_TEST

START_TEST(db_add_descriptor_copies)
{
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, 3, 202);
    amscr_db *db = db_from(p, d, 3);
    double base1[2 * 48];
    memcpy(base1, amscr_descriptor_base_points(d[1]), sizeof base1);
    const amscr_descriptor *stored = amscr_db_descriptor(db, 1);
    ck_assert_ptr_ne(stored, d[1]);
    /* the db keeps its own copy: the original may be freed */
    free_descs(d, 3);
    ck_assert(memcmp(amscr_descriptor_base_points(amscr_db_descriptor(db, 1)), base1, sizeof base1) == 0);
    double dist[9];
    ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, dist), AMSCR_OK);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(db_add_descriptor_incompatible)
{
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, 2, 303);
    amscr_db *db = db_from(p, d, 2);

    /* different N */
    amscr_params *q = make_params(64, SCALES3, 3, 1);
    amscr_descriptor **e = make_descs(q, 1, 304);
    size_t idx = 777;
    ck_assert_int_eq(amscr_db_add_descriptor(db, e[0], 5, &idx), AMSCR_E_INVALID_ARG);
    expect_detail();
    ck_assert_uint_eq(idx, 777);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    /* a query or a cross with the wrong N is refused too */
    double out[4];
    ck_assert_int_eq(amscr_db_query(db, e[0], NULL, NULL, out), AMSCR_E_INVALID_ARG);
    amscr_db *other = db_from(q, e, 1);
    ck_assert_int_eq(amscr_db_cross_distances(db, other, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_cross_distances(other, db, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    amscr_db_free(other);
    free_descs(e, 1);
    amscr_params_free(q);

    /* different scales */
    const double sc2[3] = {0.0, 1.0, 3.0};
    q = make_params(48, sc2, 3, 1);
    e = make_descs(q, 1, 305);
    ck_assert_int_eq(amscr_db_add_descriptor(db, e[0], 5, &idx), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    free_descs(e, 1);
    amscr_params_free(q);

    /* different closed flag */
    q = small_params(1);
    ck_assert_int_eq(amscr_params_set_closed(q, 0), AMSCR_OK);
    e = make_descs(q, 1, 306);
    ck_assert_int_eq(amscr_db_add_descriptor(db, e[0], 5, &idx), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    free_descs(e, 1);
    amscr_params_free(q);

    /* different threads / method only: compatible */
    q = small_params(3);
    ck_assert_int_eq(amscr_params_set_method(q, AMSCR_METHOD_ACMA), AMSCR_OK);
    e = make_descs(q, 1, 307);
    ck_assert_int_eq(amscr_db_add_descriptor(db, e[0], 5, &idx), AMSCR_OK);
    ck_assert_uint_eq(idx, 2);
    free_descs(e, 1);
    amscr_params_free(q);

    free_descs(d, 2);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(db_add_degenerate_contour)
{
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, 2, 404);
    amscr_db *db = db_from(p, d, 2);
    size_t idx = 4242;

    /* collinear points */
    double line[2 * 20];
    for (int i = 0; i < 20; i++) {
        line[2 * i] = i;
        line[2 * i + 1] = 2.0 * i + 1.0;
    }
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(line, 20, &c), AMSCR_OK);
    amscr_status st = amscr_db_add_contour(db, c, 1, &idx);
    ck_assert_msg(st != AMSCR_OK, "a collinear contour was accepted");
    ck_assert_int_eq(st, AMSCR_E_DEGENERATE);
    expect_detail();
    amscr_contour_free(c);

    /* too few points */
    const double tri[6] = {0, 0, 1, 0, 0, 1};
    ck_assert_int_eq(amscr_contour_new(tri, 3, &c), AMSCR_OK);
    st = amscr_db_add_contour(db, c, 1, &idx);
    ck_assert_int_ne(st, AMSCR_OK);
    amscr_contour_free(c);

    /* one repeated point */
    double same[2 * 12];
    for (int i = 0; i < 24; i++)
        same[i] = 3.0;
    ck_assert_int_eq(amscr_contour_new(same, 12, &c), AMSCR_OK);
    ck_assert_int_ne(amscr_db_add_contour(db, c, 1, &idx), AMSCR_OK);
    amscr_contour_free(c);

    /* non-finite coordinates */
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 405);
    double xy[2 * NPTS];
    amscr_test_random_shape(&rng, NPTS, 4, xy);
    xy[17] = NAN;
    ck_assert_int_eq(amscr_contour_new(xy, NPTS, &c), AMSCR_OK);
    ck_assert_int_ne(amscr_db_add_contour(db, c, 1, &idx), AMSCR_OK);
    amscr_contour_free(c);

    ck_assert_uint_eq(idx, 4242);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    ck_assert_ptr_null(amscr_db_descriptor(db, 2));
    /* the db still works, and the next add gets index 2 */
    c = random_contour(&rng, 4);
    ck_assert_int_eq(amscr_db_add_contour(db, c, 9, &idx), AMSCR_OK);
    ck_assert_uint_eq(idx, 2);
    amscr_contour_free(c);
    double m[9];
    ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
    free_descs(d, 2);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* ------------------------------------------------------------- batch calls */

#define NSH 40

START_TEST(matrix_equals_distance)
{
    amscr_params *p = small_params(2);
    amscr_descriptor **d = make_descs(p, NSH, 505);
    amscr_db *db = db_from(p, d, NSH);
    double *m = alloc_doubles(NSH * NSH);
    fill_sentinel(m, NSH * NSH);
    ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
    const amscr_params *dp = amscr_db_params(db);
    int asym = 0;
    for (size_t i = 0; i < NSH; i++)
        for (size_t j = 0; j < NSH; j++) {
            double v = m[i * NSH + j];
            if (i == j) {
                ck_assert_msg(same_bits(v, 0.0), "diagonal [%zu] = %.17g, not +0.0", i, v);
                continue;
            }
            double ref = -1;
            ck_assert_int_eq(amscr_distance(dp, d[i], d[j], NULL, &ref), AMSCR_OK);
            ck_assert_msg(same_bits(v, ref), "[%zu][%zu] = %.17g, amscr_distance = %.17g", i, j, v, ref);
            ck_assert(isfinite(v) && v >= 0.0);
            if (v != m[j * NSH + i])
                asym = 1;
        }
    ck_assert_msg(asym, "matrix unexpectedly symmetric (is it computing both directions?)");
    free(m);
    free_descs(d, NSH);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(results_identical_across_threads)
{
    static const unsigned threads[] = {1, 2, 3, 7, 0};
    const size_t nt = sizeof threads / sizeof threads[0];
    const size_t nq = 3, N = NSH + 30; /* > 32 targets: query uses several column blocks */
    amscr_params *base = small_params(1);
    amscr_descriptor **d = make_descs(base, N, 606);
    double *ref_m = NULL, *ref_q = NULL, *ref_x = NULL;
    for (size_t t = 0; t < nt; t++) {
        amscr_params *p = small_params(threads[t]);
        amscr_db *db = db_from(p, d, NSH);
        amscr_db *tg = db_from(p, d + NSH - nq, N - NSH + nq); /* overlaps db */
        amscr_db *qs = db_from(p, d, nq);
        ck_assert_uint_eq(amscr_params_get_num_threads(amscr_db_params(db)), threads[t]);
        double *m = alloc_doubles(NSH * NSH), *q = alloc_doubles(N), *x = alloc_doubles(nq * amscr_db_size(tg));
        ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
        amscr_db *all = db_from(p, d, N);
        ck_assert_int_eq(amscr_db_query(all, d[5], NULL, NULL, q), AMSCR_OK);
        ck_assert_int_eq(amscr_db_cross_distances(qs, tg, NULL, NULL, x), AMSCR_OK);
        if (t == 0) {
            ref_m = m;
            ref_q = q;
            ref_x = x;
        } else {
            ck_assert_msg(memcmp(m, ref_m, NSH * NSH * sizeof *m) == 0, "matrix differs for %u threads",
                          threads[t]);
            ck_assert_msg(memcmp(q, ref_q, N * sizeof *q) == 0, "query differs for %u threads", threads[t]);
            ck_assert_msg(memcmp(x, ref_x, nq * amscr_db_size(tg) * sizeof *x) == 0,
                          "cross differs for %u threads", threads[t]);
            free(m);
            free(q);
            free(x);
        }
        /* repeated call on the same db: identical again */
        if (threads[t] == 7) {
            double *m2 = alloc_doubles(NSH * NSH);
            ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m2), AMSCR_OK);
            ck_assert(memcmp(m2, ref_m, NSH * NSH * sizeof *m2) == 0);
            free(m2);
        }
        amscr_db_free(all);
        amscr_db_free(qs);
        amscr_db_free(tg);
        amscr_db_free(db);
        amscr_params_free(p);
    }
    free(ref_m);
    free(ref_q);
    free(ref_x);
    free_descs(d, N);
    amscr_params_free(base);
}
END_TEST

START_TEST(query_equals_distance)
{
    const size_t n = 45;
    amscr_params *p = small_params(2);
    amscr_descriptor **d = make_descs(p, n + 1, 707);
    amscr_db *db = db_from(p, d, n); /* d[n] is not in the db */
    const amscr_params *dp = amscr_db_params(db);
    double *q = alloc_doubles(n);
    for (size_t which = 0; which < 2; which++) {
        const amscr_descriptor *qd = which ? d[n] : d[7];
        fill_sentinel(q, n);
        ck_assert_int_eq(amscr_db_query(db, qd, NULL, NULL, q), AMSCR_OK);
        for (size_t i = 0; i < n; i++) {
            double ref = -1;
            ck_assert_int_eq(amscr_distance(dp, qd, d[i], NULL, &ref), AMSCR_OK);
            ck_assert_msg(same_bits(q[i], ref), "query %zu, shape %zu: %.17g vs %.17g", which, i, q[i], ref);
        }
    }
    /* the query row of a member equals its row in the matrix, except the diagonal (0 in the
     * matrix, the computed self-distance in a query) */
    double *m = alloc_doubles(n * n);
    ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
    ck_assert_int_eq(amscr_db_query(db, d[7], NULL, NULL, q), AMSCR_OK);
    for (size_t j = 0; j < n; j++)
        if (j != 7)
            ck_assert(same_bits(q[j], m[7 * n + j]));
    ck_assert(q[7] >= 0.0 && q[7] < 1e-6);
    free(m);
    free(q);
    free_descs(d, n + 1);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(cross_equals_union_block)
{
    const size_t nq = 7, ntg = 36, n = nq + ntg;
    amscr_params *p = small_params(2);
    amscr_descriptor **d = make_descs(p, n, 808);
    amscr_db *u = db_from(p, d, n);
    amscr_db *qs = db_from(p, d, nq);
    amscr_db *ts = db_from(p, d + nq, ntg);
    double *m = alloc_doubles(n * n), *x = alloc_doubles(nq * ntg), *y = alloc_doubles(ntg * nq);
    ck_assert_int_eq(amscr_db_distance_matrix(u, NULL, NULL, m), AMSCR_OK);
    fill_sentinel(x, nq * ntg);
    ck_assert_int_eq(amscr_db_cross_distances(qs, ts, NULL, NULL, x), AMSCR_OK);
    for (size_t i = 0; i < nq; i++)
        for (size_t j = 0; j < ntg; j++)
            ck_assert_msg(same_bits(x[i * ntg + j], m[i * n + nq + j]), "cross [%zu][%zu]", i, j);
    /* the other direction: the lower-left block */
    ck_assert_int_eq(amscr_db_cross_distances(ts, qs, NULL, NULL, y), AMSCR_OK);
    for (size_t i = 0; i < ntg; i++)
        for (size_t j = 0; j < nq; j++)
            ck_assert_msg(same_bits(y[i * nq + j], m[(nq + i) * n + j]), "cross T->Q [%zu][%zu]", i, j);
    /* a single query row (column-block path) */
    amscr_db *one = db_from(p, d + 2, 1);
    double *r = alloc_doubles(ntg);
    ck_assert_int_eq(amscr_db_cross_distances(one, ts, NULL, NULL, r), AMSCR_OK);
    for (size_t j = 0; j < ntg; j++)
        ck_assert(same_bits(r[j], m[2 * n + nq + j]));
    /* a db crossed with itself: the matrix, except the diagonal is computed */
    double *s = alloc_doubles(nq * nq), *mq = alloc_doubles(nq * nq);
    ck_assert_int_eq(amscr_db_cross_distances(qs, qs, NULL, NULL, s), AMSCR_OK);
    ck_assert_int_eq(amscr_db_distance_matrix(qs, NULL, NULL, mq), AMSCR_OK);
    for (size_t i = 0; i < nq; i++)
        for (size_t j = 0; j < nq; j++)
            if (i != j)
                ck_assert(same_bits(s[i * nq + j], mq[i * nq + j]));
    free(s);
    free(mq);
    free(r);
    amscr_db_free(one);
    free(m);
    free(x);
    free(y);
    amscr_db_free(u);
    amscr_db_free(qs);
    amscr_db_free(ts);
    free_descs(d, n);
    amscr_params_free(p);
}
END_TEST

/* Empty db: every batch call returns AMSCR_OK and writes nothing; the progress callback,
 * if called at all, reports done == total == 0. */
START_TEST(empty_db)
{
    for (unsigned th = 1; th <= 2; th++) {
        amscr_params *p = small_params(th);
        amscr_db *e = NULL;
        ck_assert_int_eq(amscr_db_new(p, &e), AMSCR_OK);
        amscr_descriptor **d = make_descs(p, 2, 909);
        amscr_db *two = db_from(p, d, 2);
        double buf[8];
        prog_rec r;

        fill_sentinel(buf, 8);
        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_distance_matrix(e, prog_cb, &r, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));
        ck_assert(r.same_thread && r.bounded && (r.calls == 0 || (r.last_done == 0 && r.last_total == 0)));
        ck_assert_int_eq(amscr_db_distance_matrix(e, NULL, NULL, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));

        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_query(e, d[0], prog_cb, &r, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));
        ck_assert(r.calls == 0 || (r.last_done == 0 && r.last_total == 0));

        ck_assert_int_eq(amscr_db_cross_distances(e, two, NULL, NULL, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));
        ck_assert_int_eq(amscr_db_cross_distances(two, e, NULL, NULL, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));
        ck_assert_int_eq(amscr_db_cross_distances(e, e, NULL, NULL, buf), AMSCR_OK);
        ck_assert(all_sentinel(buf, 8));

        /* a cancelling callback on an empty call: nothing to cancel (OK) or cancelled, no crash */
        prog_init(&r, 1);
        amscr_status st = amscr_db_distance_matrix(e, prog_cb, &r, buf);
        ck_assert(st == AMSCR_OK || st == AMSCR_E_CANCELLED);
        ck_assert(all_sentinel(buf, 8));

        free_descs(d, 2);
        amscr_db_free(two);
        amscr_db_free(e);
        amscr_params_free(p);
    }
}
END_TEST

/* One shape: the matrix is {0}; a query returns the self-distance (~0); 1x1 cross likewise. */
START_TEST(single_shape_db)
{
    amscr_params *p = small_params(2);
    amscr_descriptor **d = make_descs(p, 2, 1001);
    amscr_db *one = db_from(p, d, 1);
    double m[2];
    fill_sentinel(m, 2);
    ck_assert_int_eq(amscr_db_distance_matrix(one, NULL, NULL, m), AMSCR_OK);
    ck_assert(same_bits(m[0], 0.0));
    ck_assert(all_sentinel(m + 1, 1));

    fill_sentinel(m, 2);
    ck_assert_int_eq(amscr_db_query(one, d[1], NULL, NULL, m), AMSCR_OK);
    double ref;
    ck_assert_int_eq(amscr_distance(amscr_db_params(one), d[1], d[0], NULL, &ref), AMSCR_OK);
    ck_assert(same_bits(m[0], ref));
    ck_assert(all_sentinel(m + 1, 1));

    fill_sentinel(m, 2);
    ck_assert_int_eq(amscr_db_cross_distances(one, one, NULL, NULL, m), AMSCR_OK);
    ck_assert(m[0] >= 0.0 && m[0] < 1e-6);
    ck_assert(all_sentinel(m + 1, 1));

    /* progress on a 1x1 matrix: total must be 1 if called; the final call says done == total */
    prog_rec r;
    prog_init(&r, 0);
    ck_assert_int_eq(amscr_db_distance_matrix(one, prog_cb, &r, m), AMSCR_OK);
    ck_assert(r.same_thread && r.bounded && r.monotonic);
    if (r.calls > 0)
        prog_check_complete(&r, 1, "1x1 matrix");
    prog_init(&r, 0);
    ck_assert_int_eq(amscr_db_query(one, d[1], prog_cb, &r, m), AMSCR_OK);
    prog_check_complete(&r, 1, "query on one shape");

    free_descs(d, 2);
    amscr_db_free(one);
    amscr_params_free(p);
}
END_TEST

/* ------------------------------------------------------ progress, cancel */

START_TEST(progress_contract)
{
    const size_t n = NSH, nq = 3;
    static const unsigned threads[] = {1, 2, 3, 0};
    amscr_params *base = small_params(1);
    amscr_descriptor **d = make_descs(base, 80, 1101);
    for (size_t t = 0; t < sizeof threads / sizeof threads[0]; t++) {
        amscr_params *p = small_params(threads[t]);
        amscr_db *db = db_from(p, d, n);
        amscr_db *big = db_from(p, d, 80);
        amscr_db *qs = db_from(p, d, nq);
        double *m = alloc_doubles(n * n), *ref = alloc_doubles(n * n), *q = alloc_doubles(80);
        char what[64];
        prog_rec r;

        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_distance_matrix(db, prog_cb, &r, m), AMSCR_OK);
        snprintf(what, sizeof what, "matrix, %u threads", threads[t]);
        prog_check_complete(&r, n * n, what);
        if (threads[t] == 1) /* deterministic: 0, then after every row */
            ck_assert_msg(r.calls == n + 1 && r.first_done == 0, "%s: %zu calls, first done %zu", what, r.calls,
                          r.first_done);
        /* the callback does not change the results */
        ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, ref), AMSCR_OK);
        ck_assert(memcmp(m, ref, n * n * sizeof *m) == 0);

        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_query(db, d[50], prog_cb, &r, q), AMSCR_OK);
        snprintf(what, sizeof what, "query(40), %u threads", threads[t]);
        prog_check_complete(&r, n, what);

        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_query(big, d[50], prog_cb, &r, q), AMSCR_OK);
        snprintf(what, sizeof what, "query(80), %u threads", threads[t]);
        prog_check_complete(&r, 80, what);
        if (threads[t] == 1) /* work items are blocks of targets: several calls */
            ck_assert_msg(r.calls >= 3 && r.first_done == 0, "%s: %zu calls", what, r.calls);

        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_cross_distances(qs, db, prog_cb, &r, m), AMSCR_OK);
        snprintf(what, sizeof what, "cross, %u threads", threads[t]);
        prog_check_complete(&r, nq * n, what);

        free(m);
        free(ref);
        free(q);
        amscr_db_free(db);
        amscr_db_free(big);
        amscr_db_free(qs);
        amscr_params_free(p);
    }
    free_descs(d, 80);
    amscr_params_free(base);
}
END_TEST

static void check_cancelled(amscr_status st, const prog_rec *r, const char *what)
{
    ck_assert_msg(st == AMSCR_E_CANCELLED, "%s: status %d (%s), expected AMSCR_E_CANCELLED", what, (int)st,
                  amscr_strerror(st));
    const char *det = amscr_last_error_detail();
    ck_assert_msg(det && det[0], "%s: no detail", what);
    ck_assert_msg(r->same_thread, "%s: callback from another thread", what);
    ck_assert_msg(r->calls == r->cancel_at, "%s: callback called %zu times after asking to stop at call %zu", what,
                  r->calls, r->cancel_at);
}

START_TEST(cancellation)
{
    const size_t n = NSH;
    amscr_params *base = small_params(1);
    amscr_descriptor **d = make_descs(base, 130, 1201);
    for (unsigned th = 1; th <= 2; th++) {
        amscr_params *p = small_params(th);
        amscr_db *db = db_from(p, d, n);
        amscr_db *big = db_from(p, d, 130); /* 5 column blocks for a query */
        amscr_db *qs = db_from(p, d, 4);
        double *m = alloc_doubles(n * n), *ref = alloc_doubles(n * n), *q = alloc_doubles(130);
        ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, ref), AMSCR_OK);
        char what[80];
        prog_rec r;
        for (size_t at = 1; at <= 2; at++) {
            prog_init(&r, at);
            snprintf(what, sizeof what, "matrix, %u threads, stop at call %zu", th, at);
            check_cancelled(amscr_db_distance_matrix(db, prog_cb, &r, m), &r, what);

            prog_init(&r, at);
            snprintf(what, sizeof what, "query, %u threads, stop at call %zu", th, at);
            check_cancelled(amscr_db_query(big, d[3], prog_cb, &r, q), &r, what);

            prog_init(&r, at);
            snprintf(what, sizeof what, "cross, %u threads, stop at call %zu", th, at);
            check_cancelled(amscr_db_cross_distances(qs, db, prog_cb, &r, m), &r, what);

            prog_init(&r, at); /* the rows' loop (rows.c): it reported once more after a cancel */
            snprintf(what, sizeof what, "channel matrix, %u threads, stop at call %zu", th, at);
            check_cancelled(amscr_db_channel_matrix(db, prog_cb, &r, m), &r, what);

            prog_init(&r, at); /* the base distances alone (no re-ranking): it left a partial row */
            snprintf(what, sizeof what, "retrieval query, %u threads, stop at call %zu", th, at);
            check_cancelled(amscr_db_query_retrieval(big, d[3], prog_cb, &r, q, 130), &r, what);
            for (size_t j = 0; j < 130; j++)
                ck_assert_msg(isnan(q[j]), "%s: score %zu = %g, not NaN", what, j, q[j]);
        }
        /* a cancelled call leaves the db usable and the next results unchanged */
        ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
        ck_assert(memcmp(m, ref, n * n * sizeof *m) == 0);
        free(m);
        free(ref);
        free(q);
        amscr_db_free(db);
        amscr_db_free(big);
        amscr_db_free(qs);
        amscr_params_free(p);
    }
    free_descs(d, 130);
    amscr_params_free(base);
}
END_TEST

/* Regression (found by the hardening pass): with 2+ threads a worker could finish every item
 * before the calling thread's first progress check, so a callback saw only (total, total) and
 * could not cancel at its second call. The first report is now always (0, total), before any
 * worker starts. */
START_TEST(progress_first_report_is_zero)
{
    amscr_params *p = small_params(2);
    amscr_descriptor **d = make_descs(p, 40, 1401);
    amscr_db *db = db_from(p, d, 40);
    double *q = alloc_doubles(40), *m = alloc_doubles(40 * 40);
    for (int rep = 0; rep < 20; rep++) {
        prog_rec r;
        prog_init(&r, 0);
        ck_assert_int_eq(amscr_db_query(db, d[0], prog_cb, &r, q), AMSCR_OK);
        ck_assert_uint_eq(r.first_done, 0);
        ck_assert_uint_ge(r.calls, 2);
        prog_init(&r, 2); /* stop at the second call: always possible now */
        ck_assert_int_eq(amscr_db_distance_matrix(db, prog_cb, &r, m), AMSCR_E_CANCELLED);
    }
    free(q);
    free(m);
    free_descs(d, 40);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* amscr.h (amscr_db_query): batch outputs are computed in place, so on failure or
 * cancellation every element is NaN — never a silently partial result. */
START_TEST(cancel_writes_no_output)
{
    const size_t n = 12;
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, n, 1301);
    amscr_db *db = db_from(p, d, n);
    double *m = alloc_doubles(n * n);
    fill_sentinel(m, n * n);
    prog_rec r;
    prog_init(&r, 2); /* one row is done before the stop */
    ck_assert_int_eq(amscr_db_distance_matrix(db, prog_cb, &r, m), AMSCR_E_CANCELLED);
    /* the detail counts in the callback's unit: distances (cells), not rows */
    ck_assert_msg(strstr(amscr_last_error_detail(), "of 144 distances") != NULL, "%s", amscr_last_error_detail());
    size_t written = 0;
    for (size_t i = 0; i < n * n; i++)
        written += !isnan(m[i]);
    ck_assert_msg(written == 0, "a cancelled amscr_db_distance_matrix left %zu of %zu cells that are not NaN", written,
                  n * n);
    free(m);
    free_descs(d, n);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* Every one of the n values is -7 (untouched) or not NaN: counts the NaN ones. */
static size_t count_nan(const double *v, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        k += isnan(v[i]) != 0;
    return k;
}

/* The NaN rule holds for argument errors too (an incompatible or NULL query, a collection of
 * open curves for the channel, a single group), not only for cancellation. */
START_TEST(argument_errors_write_nan)
{
    const size_t n = 6;
    amscr_params *p = small_params(1), *p64 = make_params(64, SCALES3, 3, 1), *open = small_params(1);
    ck_assert_int_eq(amscr_params_set_closed(open, 0), AMSCR_OK);
    amscr_descriptor **d = make_descs(p, n, 1401), **d64 = make_descs(p64, 2, 1402);
    amscr_descriptor **dopen = make_descs(open, n, 1403);
    amscr_db *db = db_from(p, d, n), *db64 = db_from(p64, d64, 2), *dbopen = db_from(open, dopen, n);
    double m[36];
    const int32_t one_group[6] = {0, 0, 0, 0, 0, 0};
    for (int c = 0; c < 5; c++) {
        for (size_t i = 0; i < 36; i++)
            m[i] = -7.0;
        size_t cells = c == 0 || c == 1 ? n : c == 2 ? 2 * n : n * n;
        amscr_status st = c == 0   ? amscr_db_query(db, d64[0], NULL, NULL, m)
                          : c == 1 ? amscr_db_query(db, NULL, NULL, NULL, m)
                          : c == 2 ? amscr_db_cross_distances(db64, db, NULL, NULL, m)
                          : c == 3 ? amscr_db_channel_matrix(dbopen, NULL, NULL, m)
                                   : amscr_db_retrieval_matrix_heldout(db, one_group, n, NULL, NULL, m);
        ck_assert_msg(st == AMSCR_E_INVALID_ARG, "case %d: %s", c, amscr_strerror(st));
        ck_assert_msg(count_nan(m, cells) == cells, "case %d: %zu of %zu cells NaN", c, count_nan(m, cells), cells);
        for (size_t i = cells; i < 36; i++) /* nothing past the output */
            ck_assert_double_eq(m[i], -7.0);
    }
    amscr_db_free(db);
    amscr_db_free(db64);
    amscr_db_free(dbopen);
    free_descs(d, n);
    free_descs(d64, 2);
    free_descs(dopen, n);
    amscr_params_free(p);
    amscr_params_free(p64);
    amscr_params_free(open);
}
END_TEST

/* ------------------------------------------------------------ save / load */

static char *make_tmpdir(void)
{
    const char *base = getenv("TMPDIR");
    char tmpl[512];
    snprintf(tmpl, sizeof tmpl, "%s/amscr_db_XXXXXX", base && base[0] ? base : "/tmp");
    char *dir = mkdtemp(tmpl);
    ck_assert_msg(dir != NULL, "mkdtemp: %s", strerror(errno));
    return strdup(dir);
}

/* Number of entries of dir (without . and ..); the single name goes to name1 when wanted. */
static size_t dir_entries(const char *dir, char *name1, size_t cap)
{
    DIR *dd = opendir(dir);
    ck_assert_ptr_nonnull(dd);
    size_t k = 0;
    struct dirent *e;
    while ((e = readdir(dd)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        if (k == 0 && name1)
            snprintf(name1, cap, "%s", e->d_name);
        k++;
    }
    closedir(dd);
    return k;
}

static void remove_tree(const char *dir)
{
    DIR *dd = opendir(dir);
    if (!dd)
        return;
    struct dirent *e;
    char path[1024];
    while ((e = readdir(dd)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        if (remove(path) != 0)
            remove_tree(path);
        rmdir(path);
    }
    closedir(dd);
    rmdir(dir);
}

static void write_file(const char *path, const void *buf, size_t len)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(buf, 1, len, f), len);
    ck_assert_int_eq(fclose(f), 0);
}

static void *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    size_t cap = 1 << 16, n = 0;
    unsigned char *b = malloc(cap);
    for (;;) {
        if (n == cap)
            b = realloc(b, cap *= 2);
        size_t got = fread(b + n, 1, cap - n, f);
        n += got;
        if (!got)
            break;
    }
    fclose(f);
    *len = n;
    return b;
}

static void assert_params_equal(const amscr_params *a, const amscr_params *b)
{
    ck_assert_uint_eq(amscr_params_get_num_samples(a), amscr_params_get_num_samples(b));
    double sa[AMSCR_MAX_SCALES], sb[AMSCR_MAX_SCALES];
    size_t na = AMSCR_MAX_SCALES, nb = AMSCR_MAX_SCALES;
    ck_assert_int_eq(amscr_params_get_scales(a, sa, &na), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_scales(b, sb, &nb), AMSCR_OK);
    ck_assert_uint_eq(na, nb);
    ck_assert(memcmp(sa, sb, na * sizeof(double)) == 0);
    ck_assert_int_eq(amscr_params_get_method(a), amscr_params_get_method(b));
    ck_assert_int_eq(amscr_params_get_closed(a), amscr_params_get_closed(b));
    ck_assert_int_eq(amscr_params_get_reflections(a), amscr_params_get_reflections(b));
    ck_assert_int_eq(amscr_params_get_parametrization(a), amscr_params_get_parametrization(b));
    ck_assert(same_bits(amscr_params_get_presmooth(a), amscr_params_get_presmooth(b)));
    ck_assert_uint_eq(amscr_params_get_arclength_passes(a), amscr_params_get_arclength_passes(b));
    ck_assert_uint_eq(amscr_params_get_oversampling(a), amscr_params_get_oversampling(b));
    ck_assert_uint_eq(amscr_params_get_kmax(a), amscr_params_get_kmax(b));
    ck_assert_int_eq(amscr_params_get_symmetric(a), amscr_params_get_symmetric(b));
    ck_assert_uint_eq(amscr_params_get_refine(a), amscr_params_get_refine(b));
    ck_assert_uint_eq(amscr_params_get_num_threads(a), amscr_params_get_num_threads(b));
    ck_assert_int_eq(amscr_params_get_invariance(a), amscr_params_get_invariance(b));
    ck_assert(same_bits(amscr_params_get_penalty(a), amscr_params_get_penalty(b)));
}

static void assert_db_equal(const amscr_db *a, const amscr_db *b)
{
    size_t n = amscr_db_size(a);
    ck_assert_uint_eq(amscr_db_size(b), n);
    assert_params_equal(amscr_db_params(a), amscr_db_params(b));
    for (size_t i = 0; i < n; i++) {
        ck_assert_int_eq(amscr_db_label(a, i), amscr_db_label(b, i));
        const amscr_descriptor *da = amscr_db_descriptor(a, i), *db_ = amscr_db_descriptor(b, i);
        size_t N = amscr_descriptor_num_samples(da), p = amscr_descriptor_num_scales(da);
        ck_assert_uint_eq(amscr_descriptor_num_samples(db_), N);
        ck_assert_uint_eq(amscr_descriptor_num_scales(db_), p);
        ck_assert(memcmp(amscr_descriptor_base_points(da), amscr_descriptor_base_points(db_),
                         2 * N * sizeof(double)) == 0);
        ck_assert(memcmp(amscr_descriptor_input_points(da), amscr_descriptor_input_points(db_),
                         2 * N * sizeof(double)) == 0);
        for (size_t k = 0; k < p; k++)
            ck_assert(memcmp(amscr_descriptor_scale_points(da, k), amscr_descriptor_scale_points(db_, k),
                             2 * N * sizeof(double)) == 0);
        double fa[6], fb[6];
        ck_assert_int_eq(amscr_descriptor_normalization(da, fa), AMSCR_OK);
        ck_assert_int_eq(amscr_descriptor_normalization(db_, fb), AMSCR_OK);
        ck_assert(memcmp(fa, fb, sizeof fa) == 0);
    }
    if (n > 0) {
        double *ma = alloc_doubles(n * n), *mb = alloc_doubles(n * n);
        ck_assert_int_eq(amscr_db_distance_matrix(a, NULL, NULL, ma), AMSCR_OK);
        ck_assert_int_eq(amscr_db_distance_matrix(b, NULL, NULL, mb), AMSCR_OK);
        ck_assert_msg(memcmp(ma, mb, n * n * sizeof *ma) == 0, "distance matrix of the loaded db differs");
        /* a query with a loaded descriptor vs an original one */
        double *qa = alloc_doubles(n), *qb = alloc_doubles(n);
        ck_assert_int_eq(amscr_db_query(a, amscr_db_descriptor(a, 0), NULL, NULL, qa), AMSCR_OK);
        ck_assert_int_eq(amscr_db_query(b, amscr_db_descriptor(b, 0), NULL, NULL, qb), AMSCR_OK);
        ck_assert(memcmp(qa, qb, n * sizeof *qa) == 0);
        free(qa);
        free(qb);
        free(ma);
        free(mb);
    }
}

/* ------------------------------------------------- many contours at once */

static amscr_db *retrieval_db(unsigned threads)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(p, threads), AMSCR_OK);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    amscr_params_free(p);
    return db;
}

static void assert_same_retrieval(const amscr_db *a, const amscr_db *b)
{
    size_t n = amscr_db_size(a);
    double *ma = alloc_doubles(n * n), *mb = alloc_doubles(n * n);
    ck_assert_int_eq(amscr_db_retrieval_matrix(a, NULL, NULL, ma), AMSCR_OK);
    ck_assert_int_eq(amscr_db_retrieval_matrix(b, NULL, NULL, mb), AMSCR_OK);
    ck_assert_msg(memcmp(ma, mb, n * n * sizeof *ma) == 0, "retrieval matrices differ");
    free(ma);
    free(mb);
}

enum { MB = 12 };

/* amscr_db_add_contours = MB calls of amscr_db_add_contour after the shapes already there, on
 * any thread count (the prepared shapes, their closed outlines through the retrieval matrix, the
 * labels); progress from the calling thread up to MB. */
START_TEST(db_add_contours_as_one_by_one)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 505);
    amscr_contour *c[MB];
    int32_t lab[MB];
    for (size_t i = 0; i < MB; i++) {
        c[i] = random_contour(&rng, 3 + (int)(i % 5));
        lab[i] = label_of(i);
    }
    for (unsigned threads = 1; threads <= 3; threads += 2) {
        amscr_db *one = retrieval_db(threads), *batch = retrieval_db(threads);
        ck_assert_int_eq(amscr_db_add_contour(one, c[5], 77, NULL), AMSCR_OK);
        ck_assert_int_eq(amscr_db_add_contour(batch, c[5], 77, NULL), AMSCR_OK);
        for (size_t i = 0; i < MB; i++)
            ck_assert_int_eq(amscr_db_add_contour(one, c[i], lab[i], NULL), AMSCR_OK);
        prog_rec r;
        prog_init(&r, 0);
        size_t failed = 999;
        ck_assert_int_eq(amscr_db_add_contours(batch, (const amscr_contour *const *)c, lab, MB, prog_cb, &r, &failed),
                         AMSCR_OK);
        ck_assert_uint_eq(failed, MB);
        prog_check_complete(&r, MB, "amscr_db_add_contours");
        assert_db_equal(one, batch);
        assert_same_retrieval(one, batch);
        /* labels NULL: 0 each; n = 0: nothing */
        ck_assert_int_eq(amscr_db_add_contours(batch, (const amscr_contour *const *)c, NULL, 2, NULL, NULL, NULL),
                         AMSCR_OK);
        ck_assert_int_eq(amscr_db_add_contours(batch, NULL, NULL, 0, NULL, NULL, &failed), AMSCR_OK);
        ck_assert_uint_eq(amscr_db_size(batch), MB + 3);
        ck_assert_int_eq(amscr_db_label(batch, MB + 1), 0);
        ck_assert_int_eq(amscr_db_label(batch, MB + 2), 0);
        amscr_db_free(one);
        amscr_db_free(batch);
    }
    for (size_t i = 0; i < MB; i++)
        amscr_contour_free(c[i]);
}
END_TEST

/* A failing batch adds nothing and names its first failing contour in order, with the same
 * status and detail for any thread count: a collinear contour (3) before a non-finite one (7),
 * a NULL contour, a cancelled batch, NULL arguments. */
START_TEST(db_add_contours_all_or_nothing)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 506);
    amscr_contour *c[MB];
    for (size_t i = 0; i < MB; i++)
        c[i] = random_contour(&rng, 4);
    double line[2 * 20], xy[2 * NPTS];
    for (int i = 0; i < 20; i++) {
        line[2 * i] = i;
        line[2 * i + 1] = 2.0 * i + 1.0;
    }
    amscr_test_random_shape(&rng, NPTS, 4, xy);
    xy[17] = NAN;
    amscr_contour *collinear = NULL, *nonfinite = NULL;
    ck_assert_int_eq(amscr_contour_new(line, 20, &collinear), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_new(xy, NPTS, &nonfinite), AMSCR_OK);
    const amscr_contour *bad[MB];
    for (size_t i = 0; i < MB; i++)
        bad[i] = c[i];
    bad[3] = collinear;
    bad[7] = nonfinite;
    char first[256] = "";
    for (unsigned threads = 1; threads <= 4; threads++) {
        amscr_db *db = retrieval_db(threads);
        ck_assert_int_eq(amscr_db_add_contour(db, c[0], 1, NULL), AMSCR_OK);
        size_t failed = 999;
        ck_assert_int_eq(amscr_db_add_contours(db, bad, NULL, MB, NULL, NULL, &failed), AMSCR_E_DEGENERATE);
        ck_assert_uint_eq(failed, 3);
        ck_assert_uint_eq(amscr_db_size(db), 1);
        const char *d = amscr_last_error_detail();
        ck_assert_msg(strncmp(d, "contour 3: ", 11) == 0, "detail: %s", d);
        if (threads == 1)
            snprintf(first, sizeof first, "%s", d);
        ck_assert_str_eq(d, first);
        /* a NULL contour */
        bad[3] = c[3];
        bad[5] = NULL;
        ck_assert_int_eq(amscr_db_add_contours(db, bad, NULL, MB, NULL, NULL, &failed), AMSCR_E_INVALID_ARG);
        ck_assert_uint_eq(failed, 5);
        bad[3] = collinear;
        bad[5] = c[5];
        /* cancelled on the first report */
        prog_rec r;
        prog_init(&r, 1);
        ck_assert_int_eq(amscr_db_add_contours(db, (const amscr_contour *const *)c, NULL, MB, prog_cb, &r, &failed),
                         AMSCR_E_CANCELLED);
        ck_assert_uint_eq(failed, MB);
        ck_assert_uint_eq(amscr_db_size(db), 1);
        /* NULL arguments */
        ck_assert_int_eq(amscr_db_add_contours(NULL, bad, NULL, MB, NULL, NULL, &failed), AMSCR_E_INVALID_ARG);
        ck_assert_int_eq(amscr_db_add_contours(db, NULL, NULL, MB, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
        ck_assert_uint_eq(amscr_db_size(db), 1);
        amscr_db_free(db);
    }
    amscr_contour_free(collinear);
    amscr_contour_free(nonfinite);
    for (size_t i = 0; i < MB; i++)
        amscr_contour_free(c[i]);
}
END_TEST


/* non-default values for every parameter */
static amscr_params *odd_params(void)
{
    const double sc[4] = {2.0, 0.0, 0.75, 4.5}; /* unsorted on purpose */
    amscr_params *p = make_params(40, sc, 4, 3);
    ck_assert_int_eq(amscr_params_set_method(p, AMSCR_METHOD_BINARY_EM), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_reflections(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_parametrization(p, AMSCR_PARAM_AFFINE), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_presmooth(p, 0.0125), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_arclength_passes(p, 2), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_oversampling(p, 5), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_kmax(p, 3), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_symmetric(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_refine(p, 2), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_invariance(p, AMSCR_INVARIANCE_PENALIZED), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_penalty(p, 0.3), AMSCR_OK);
    return p;
}

START_TEST(save_load_roundtrip)
{
    char *dir = make_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/coll.amscrdb", dir);
    for (int variant = 0; variant < 2; variant++) {
        amscr_params *p = variant ? odd_params() : small_params(2);
        const size_t n = variant ? 8 : 30;
        amscr_db *db = NULL;
        ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
        amscr_test_rng rng;
        amscr_test_rng_seed(&rng, 1401 + (uint64_t)variant);
        for (size_t i = 0; i < n; i++) {
            amscr_contour *c = random_contour(&rng, 3 + (int)(i % 4));
            int32_t lab = i == 0 ? INT32_MIN : i == 1 ? INT32_MAX : i == 2 ? -1 : label_of(i);
            ck_assert_msg(amscr_db_add_contour(db, c, lab, NULL) == AMSCR_OK, "%s", amscr_last_error_detail());
            amscr_contour_free(c);
        }
        /* saving twice overwrites */
        for (int rep = 0; rep < 2; rep++) {
            amscr_status st = amscr_db_save(db, path);
            ck_assert_msg(st == AMSCR_OK, "save: %s", amscr_last_error_detail());
        }
        char name[256];
        ck_assert_uint_eq(dir_entries(dir, name, sizeof name), 1); /* no temporary left */
        ck_assert_str_eq(name, "coll.amscrdb");

        amscr_db *ld = NULL;
        amscr_status st = amscr_db_load(path, &ld);
        ck_assert_msg(st == AMSCR_OK, "load: %s", amscr_last_error_detail());
        assert_db_equal(db, ld);

        /* memory round trip: same bytes as the file; reserializing the loaded db is canonical */
        void *buf = NULL, *buf2 = NULL;
        size_t len = 0, len2 = 0, flen = 0;
        ck_assert_int_eq(amscr_db_save_memory(db, &buf, &len), AMSCR_OK);
        void *fbuf = read_file(path, &flen);
        ck_assert_uint_eq(flen, len);
        ck_assert(memcmp(fbuf, buf, len) == 0);
        free(fbuf);
        amscr_db *lm = NULL;
        ck_assert_int_eq(amscr_db_load_memory(buf, len, &lm), AMSCR_OK);
        assert_db_equal(db, lm);
        ck_assert_int_eq(amscr_db_save_memory(lm, &buf2, &len2), AMSCR_OK);
        ck_assert_uint_eq(len2, len);
        ck_assert(memcmp(buf, buf2, len) == 0);
        /* the loaded db accepts new shapes and descriptors of the original */
        amscr_contour *c = random_contour(&rng, 4);
        ck_assert_int_eq(amscr_db_add_contour(lm, c, 5, NULL), AMSCR_OK);
        ck_assert_int_eq(amscr_db_add_descriptor(lm, amscr_db_descriptor(db, 0), 6, NULL), AMSCR_OK);
        ck_assert_uint_eq(amscr_db_size(lm), n + 2);
        amscr_contour_free(c);
        /* cross between the original and the loaded db */
        double *x = alloc_doubles(n * n), *m = alloc_doubles(n * n);
        ck_assert_int_eq(amscr_db_cross_distances(db, ld, NULL, NULL, x), AMSCR_OK);
        ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, m), AMSCR_OK);
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                if (i != j)
                    ck_assert(same_bits(x[i * n + j], m[i * n + j]));
        free(x);
        free(m);
        amscr_free(buf);
        amscr_free(buf2);
        amscr_db_free(lm);
        amscr_db_free(ld);
        amscr_db_free(db);
        amscr_params_free(p);
    }
    /* an empty db round-trips too */
    amscr_params *p = small_params(1);
    amscr_db *e = NULL, *le = NULL;
    ck_assert_int_eq(amscr_db_new(p, &e), AMSCR_OK);
    ck_assert_int_eq(amscr_db_save(e, path), AMSCR_OK);
    ck_assert_int_eq(amscr_db_load(path, &le), AMSCR_OK);
    assert_db_equal(e, le);
    amscr_db_free(le);
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_db_save_memory(e, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_db_load_memory(buf, len, &le), AMSCR_OK);
    ck_assert_uint_eq(amscr_db_size(le), 0);
    amscr_free(buf);
    amscr_db_free(le);
    amscr_db_free(e);
    amscr_params_free(p);
    remove_tree(dir);
    free(dir);
}
END_TEST

START_TEST(save_io_errors)
{
    char *dir = make_tmpdir();
    char path[1024];
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, 2, 1501);
    amscr_db *db = db_from(p, d, 2);

    /* a non-existent folder: AMSCR_E_IO, nothing created */
    char missing[512];
    snprintf(missing, sizeof missing, "%s/no_such_dir", dir);
    snprintf(path, sizeof path, "%s/coll.amscrdb", missing);
    ck_assert_int_eq(amscr_db_save(db, path), AMSCR_E_IO);
    expect_detail();
    struct stat sb;
    ck_assert_int_ne(stat(missing, &sb), 0);
    ck_assert_uint_eq(dir_entries(dir, NULL, 0), 0);

    /* the path is an existing folder: AMSCR_E_IO, no temporary left beside it, folder intact */
    snprintf(path, sizeof path, "%s/sub", dir);
    ck_assert_int_eq(mkdir(path, 0700), 0);
    ck_assert_int_eq(amscr_db_save(db, path), AMSCR_E_IO);
    ck_assert_uint_eq(dir_entries(dir, NULL, 0), 1);
    ck_assert_int_eq(stat(path, &sb), 0);
    ck_assert(S_ISDIR(sb.st_mode));

    /* empty path */
    ck_assert_int_ne(amscr_db_save(db, ""), AMSCR_OK);
    ck_assert_uint_eq(dir_entries(dir, NULL, 0), 1);

    amscr_db_free(db);
    free_descs(d, 2);
    amscr_params_free(p);
    remove_tree(dir);
    free(dir);
}
END_TEST

/* ----------------------------------------------------------- corrupt input */

/* A small saved collection: 2 shapes, N = 16, one scale (2.0: a flip of its exponent's
 * lowest bit gives 2^17, a finite scale larger than N). */
#define BLOB_SCALE_OFFSET 32 /* magic 8, version 4, reserved 4, N 8, scale count 8 */
static void *small_blob(size_t *len)
{
    const double sc[1] = {2.0};
    amscr_params *p = make_params(16, sc, 1, 1);
    amscr_descriptor **d = make_descs(p, 2, 1601);
    amscr_db *db = db_from(p, d, 2);
    void *buf = NULL;
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, len), AMSCR_OK);
    void *copy = malloc(*len);
    memcpy(copy, buf, *len);
    amscr_free(buf);
    amscr_db_free(db);
    free_descs(d, 2);
    amscr_params_free(p);
    return copy;
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

static void fix_checksum(unsigned char *b, size_t len)
{
    uint64_t h = fnv1a(b, len - 8);
    for (int i = 0; i < 8; i++)
        b[len - 8 + i] = (unsigned char)(h >> (8 * i));
}

/* load_memory from an exactly-sized heap copy (so overreads are visible to sanitizers) */
static amscr_status load_exact(const unsigned char *src, size_t len, amscr_db **out)
{
    unsigned char *b = malloc(len ? len : 1);
    if (len)
        memcpy(b, src, len);
    amscr_status st = amscr_db_load_memory(b, len, out);
    free(b);
    return st;
}

START_TEST(blob_layout_sanity)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    ck_assert(len > 100);
    ck_assert(memcmp(b, "AMSCRDB", 8) == 0);
    ck_assert(b[8] == 12 && b[9] == 0 && b[10] == 0 && b[11] == 0); /* version 12, little-endian */
    uint64_t h = 0;
    for (int i = 0; i < 8; i++)
        h |= (uint64_t)b[len - 8 + i] << (8 * i);
    ck_assert_msg(h == fnv1a(b, len - 8), "trailer is not the FNV-1a of the rest");
    amscr_db *db = NULL;
    ck_assert_int_eq(load_exact(b, len, &db), AMSCR_OK);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    amscr_db_free(db);
    free(b);
}
END_TEST

/* Format version 12 puts the retrieval settings (84 bytes; 76 in version 10, 68 in version 7, 60
 * in version 5, 52 in version 2) right after the params, which end 60 bytes after the scales; version 1 files (the same
 * without that block) still load, with the retrieval settings at their defaults. */
#define BLOB_RETRIEVAL_OFFSET (BLOB_SCALE_OFFSET + 8 + 60)

/* The file b (*len bytes) as an older version writes it: the `drop` bytes at `at` removed, the
 * version byte set and the checksum fixed. */
static void as_older_version(unsigned char *b, size_t *len, size_t at, size_t drop, unsigned char version)
{
    memmove(b + at, b + at + drop, *len - at - drop);
    *len -= drop;
    b[8] = version;
    fix_checksum(b, *len);
}

/* An empty collection with params p saved to memory (*len bytes; free with amscr_free), and
 * the count of p's scales (the retrieval block starts 60 bytes after them). */
static unsigned char *saved_empty(const amscr_params *p, size_t *len, size_t *nscales)
{
    amscr_db *db = NULL;
    void *buf = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, len), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_scales(p, NULL, nscales), AMSCR_OK);
    amscr_db_free(db);
    return buf;
}

START_TEST(format_v1_still_loads)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    as_older_version(b, &len, BLOB_RETRIEVAL_OFFSET, 84, 1);
    amscr_db *db = NULL;
    ck_assert_int_eq(load_exact(b, len, &db), AMSCR_OK);
    ck_assert_uint_eq(amscr_db_size(db), 2);
    ck_assert(amscr_params_get_channel_weight(amscr_db_params(db)) == 0.0);
    ck_assert_uint_eq(amscr_params_get_rerank_k(amscr_db_params(db)), 0);
    amscr_db_free(db);
    free(b);
}
END_TEST

/* A version 2 file (before 0.6: a 52-byte block, one band for both frames) loads with the
 * whitened frame's band equal to the band, as it was computed; a bad band there is refused. */
START_TEST(format_v2_one_band)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_band(p, 0.125), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_band(p) != 0.125);
    size_t len = 0, nscales = 0;
    unsigned char *b = saved_empty(p, &len, &nscales);
    /* the affine band, the inner share, the closing and the affine-view factor, after the 52
     * bytes of version 2 */
    as_older_version(b, &len, BLOB_SCALE_OFFSET + 8 * nscales + 60 + 52, 32, 2);
    amscr_db *back = NULL;
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_OK);
    ck_assert(amscr_params_get_channel_band(amscr_db_params(back)) == 0.125);
    ck_assert(amscr_params_get_channel_affine_band(amscr_db_params(back)) == 0.125);
    ck_assert(amscr_params_get_rerank_inner_share(amscr_db_params(back)) == 0.0);
    amscr_db_free(back);
    back = NULL;
    b[8] = 12; /* read as version 12, the block runs 32 bytes into the counts: refused or inconsistent */
    fix_checksum(b, len);
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_E_FORMAT);
    ck_assert_ptr_null(back);
    amscr_free(b);
    amscr_params_free(p);
}
END_TEST

/* A version 5 file (0.6: a 60-byte block, one graph in the re-ranking) loads with the inner
 * share 0, as it was computed, and its bands kept. */
START_TEST(format_v5_one_graph)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.05), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, 0.0625), AMSCR_OK);
    size_t len = 0, nscales = 0;
    unsigned char *b = saved_empty(p, &len, &nscales);
    as_older_version(b, &len, BLOB_SCALE_OFFSET + 8 * nscales + 60 + 60, 24, 5);
    amscr_db *back = NULL;
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_OK);
    ck_assert(amscr_params_get_rerank_inner_share(amscr_db_params(back)) == 0.0);
    ck_assert(amscr_params_get_inner_closing(amscr_db_params(back)) == 0.0);
    ck_assert(amscr_params_get_channel_affine_band(amscr_db_params(back)) == 0.0625);
    ck_assert(amscr_params_get_channel_affine_view(amscr_db_params(back)) == 0.0);
    amscr_db_free(back);
    amscr_free(b);
    amscr_params_free(p);
}
END_TEST

/* A version 10 file (0.9-0.10: a 76-byte block, the frames' mix for every pair) loads with the
 * affine-view factor 0, as it was computed, its closing kept; the factor round-trips in 12. */
START_TEST(format_v10_mix_for_every_pair)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_view(p) == 2.0);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 3.5), AMSCR_OK);
    size_t len = 0, nscales = 0;
    unsigned char *b = saved_empty(p, &len, &nscales);
    amscr_db *back = NULL;
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_view(amscr_db_params(back)) == 3.5);
    amscr_db_free(back);
    back = NULL;
    as_older_version(b, &len, BLOB_SCALE_OFFSET + 8 * nscales + 60 + 76, 8, 10);
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_view(amscr_db_params(back)) == 0.0);
    ck_assert(amscr_params_get_inner_closing(amscr_db_params(back)) == 0.04);
    amscr_db_free(back);
    back = NULL;
    amscr_free(b);
    /* a factor the setter refuses, written into a version 12 block, is a format error */
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 0.0), AMSCR_OK);
    b = saved_empty(p, &len, &nscales);
    double bad = 0.5;
    uint64_t v;
    memcpy(&v, &bad, 8);
    for (size_t i = 0; i < 8; i++)
        b[BLOB_SCALE_OFFSET + 8 * nscales + 60 + 76 + i] = (unsigned char)(v >> (8 * i));
    fix_checksum(b, len);
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_E_FORMAT);
    ck_assert_ptr_null(back);
    amscr_free(b);
    amscr_params_free(p);
}
END_TEST

START_TEST(retrieval_settings_roundtrip)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_band(p, 0.125), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, 0.0625), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_share(p, 0.3), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.125), AMSCR_OK);
    size_t len = 0, nscales = 0;
    unsigned char *b = saved_empty(p, &len, &nscales);
    amscr_db *back = NULL;
    ck_assert_int_eq(amscr_db_load_memory(b, len, &back), AMSCR_OK);
    const amscr_params *q = amscr_db_params(back);
    ck_assert(amscr_params_get_channel_weight(q) == amscr_params_get_channel_weight(p));
    ck_assert(amscr_params_get_channel_band(q) == 0.125);
    ck_assert(amscr_params_get_channel_affine_band(q) == 0.0625);
    ck_assert(amscr_params_get_channel_affine_share(q) == 0.3);
    ck_assert(amscr_params_get_channel_skip(q) == amscr_params_get_channel_skip(p));
    ck_assert(amscr_params_get_channel_locality(q) == amscr_params_get_channel_locality(p));
    ck_assert_int_eq(amscr_params_get_channel_invariance(q), amscr_params_get_channel_invariance(p));
    ck_assert_uint_eq(amscr_params_get_rerank_k(q), amscr_params_get_rerank_k(p));
    ck_assert_uint_eq(amscr_params_get_rerank_iterations(q), amscr_params_get_rerank_iterations(p));
    ck_assert(amscr_params_get_rerank_inner_share(q) == 0.125);
    /* an out-of-range weight in the block is a format error, not a silent value */
    double bad = 2.0;
    uint64_t v;
    memcpy(&v, &bad, 8);
    for (size_t i = 0; i < 8; i++) /* the weight opens the block, after the params */
        b[BLOB_SCALE_OFFSET + 8 * nscales + 60 + i] = (unsigned char)(v >> (8 * i));
    fix_checksum(b, len);
    amscr_db *bad_db = NULL;
    ck_assert_int_eq(amscr_db_load_memory(b, len, &bad_db), AMSCR_E_FORMAT);
    amscr_free(b);
    amscr_db_free(back);
    amscr_params_free(p);
}
END_TEST

START_TEST(corrupt_magic_and_version)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    unsigned char *c = malloc(len);
    amscr_db *db = (amscr_db *)(void *)&db, *const sent = db;

    memcpy(c, b, len);
    c[0] = 'X';
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);
    expect_detail();
    ck_assert_ptr_eq(db, sent);
    fix_checksum(c, len); /* the magic is checked whatever the checksum */
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);

    memcpy(c, b, len);
    c[7] = 'X'; /* the terminating NUL of the magic */
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);

    /* a newer version, nothing else fixed */
    memcpy(c, b, len);
    c[8] = 99;
    c[9] = c[10] = c[11] = 0;
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);
    const char *det = amscr_last_error_detail();
    ck_assert_msg(strstr(det, "version") != NULL && strstr(det, "99") != NULL,
                  "detail does not name the version: \"%s\"", det);
    ck_assert_ptr_eq(db, sent);
    /* the same with a valid checksum */
    fix_checksum(c, len);
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "99") != NULL);
    /* a huge version number */
    c[8] = c[9] = c[10] = c[11] = 0xff;
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);
    /* version 0 */
    memcpy(c, b, len);
    c[8] = 0;
    fix_checksum(c, len);
    ck_assert_int_eq(load_exact(c, len, &db), AMSCR_E_FORMAT);
    ck_assert_ptr_eq(db, sent);

    /* an extra trailing byte */
    unsigned char *e = malloc(len + 1);
    memcpy(e, b, len);
    e[len] = 0;
    ck_assert_int_eq(load_exact(e, len + 1, &db), AMSCR_E_FORMAT);
    fix_checksum(e, len + 1);
    ck_assert_int_eq(load_exact(e, len + 1, &db), AMSCR_E_FORMAT);
    free(e);

    /* the file path also reports the version */
    char *dir = make_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/newer.amscrdb", dir);
    memcpy(c, b, len);
    c[8] = 99;
    write_file(path, c, len);
    ck_assert_int_eq(amscr_db_load(path, &db), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "99") != NULL);
    ck_assert_ptr_eq(db, sent);
    remove_tree(dir);
    free(dir);
    free(c);
    free(b);
}
END_TEST

START_TEST(corrupt_truncated)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    amscr_db *sent = (amscr_db *)(void *)&len;
    for (size_t k = 0; k < len; k++) {
        amscr_db *db = sent;
        amscr_status st = load_exact(b, k, &db);
        if (k == 0)
            ck_assert_msg(st == AMSCR_E_FORMAT || st == AMSCR_E_INVALID_ARG, "len 0: status %d", (int)st);
        else
            ck_assert_msg(st == AMSCR_E_FORMAT, "prefix of %zu/%zu bytes: status %d (%s)", k, len, (int)st,
                          amscr_last_error_detail());
        ck_assert_ptr_eq(db, sent);
    }
    /* through files as well (a few lengths) */
    char *dir = make_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/trunc.amscrdb", dir);
    const size_t lens[] = {0, 1, 7, 8, 12, 23, 24, len / 2, len - 9, len - 8, len - 1};
    for (size_t i = 0; i < sizeof lens / sizeof lens[0]; i++) {
        write_file(path, b, lens[i]);
        amscr_db *db = sent;
        amscr_status st = amscr_db_load(path, &db);
        ck_assert_msg(st == AMSCR_E_FORMAT, "file of %zu bytes: status %d", lens[i], (int)st);
        ck_assert_ptr_eq(db, sent);
    }
    write_file(path, b, len);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_load(path, &db), AMSCR_OK);
    amscr_db_free(db);
    remove_tree(dir);
    free(dir);
    free(b);
}
END_TEST

START_TEST(corrupt_flipped_bytes)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    unsigned char *c = malloc(len);
    static const unsigned char masks[] = {0x01, 0x80, 0xff};
    for (size_t pos = 0; pos < len; pos++)
        for (size_t mi = 0; mi < sizeof masks; mi++) {
            memcpy(c, b, len);
            c[pos] ^= masks[mi];
            amscr_db *db = NULL;
            amscr_status st = load_exact(c, len, &db);
            ck_assert_msg(st != AMSCR_OK, "byte %zu ^ 0x%02x: loaded", pos, masks[mi]);
            ck_assert_msg(st == AMSCR_E_FORMAT, "byte %zu ^ 0x%02x: status %d, expected AMSCR_E_FORMAT", pos,
                          masks[mi], (int)st);
        }
    free(c);
    free(b);
}
END_TEST

/* Corruption that also fixes the checksum (a crafted file): never a crash; when it loads,
 * the db is usable and its params obey the setters' rules. */
START_TEST(crafted_files_valid_checksum)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    unsigned char *c = malloc(len);
    static const unsigned char masks[] = {0x01, 0x40, 0x80, 0xff};
    size_t loaded = 0;
    char bad[4096] = "";
    size_t nbad = 0;
    for (size_t pos = 0; pos + 8 < len; pos++)
        for (size_t mi = 0; mi < sizeof masks; mi++) {
            memcpy(c, b, len);
            c[pos] ^= masks[mi];
            fix_checksum(c, len);
            amscr_db *db = NULL;
            amscr_status st = load_exact(c, len, &db);
            if (st != AMSCR_OK) {
                ck_assert_msg(st == AMSCR_E_FORMAT || st == AMSCR_E_NOMEM,
                              "byte %zu ^ 0x%02x: status %d (%s)", pos, masks[mi], (int)st,
                              amscr_last_error_detail());
                continue;
            }
            loaded++;
            /* the loaded params must be acceptable to the setters */
            const amscr_params *lp = amscr_db_params(db);
            amscr_params *chk = NULL;
            ck_assert_int_eq(amscr_params_new(&chk), AMSCR_OK);
            double sc[AMSCR_MAX_SCALES];
            size_t ns = AMSCR_MAX_SCALES;
            ck_assert_int_eq(amscr_params_get_scales(lp, sc, &ns), AMSCR_OK);
            int ok = amscr_params_set_num_samples(chk, amscr_params_get_num_samples(lp)) == AMSCR_OK &&
                     amscr_params_set_scales(chk, sc, ns) == AMSCR_OK;
            if (!ok && nbad < 8) {
                size_t used = strlen(bad);
                snprintf(bad + used, sizeof bad - used, " [byte %zu ^ 0x%02x: scale[0]=%g]", pos, masks[mi],
                         ns ? sc[0] : 0.0);
            }
            nbad += !ok;
            amscr_params_free(chk);
            double m[4];
            amscr_status ms = amscr_db_distance_matrix(db, NULL, NULL, m);
            (void)ms; /* any status, but no crash */
            amscr_db_free(db);
        }
    ck_assert_msg(nbad == 0, "%zu crafted files loaded with params the setters reject:%s", nbad, bad);
    ck_assert(loaded > 0); /* e.g. labels and coordinates may change freely */
    free(c);
    free(b);
}
END_TEST

/* A crafted file (valid checksum) whose scale breaks the setter's rule (finite, >= 0, <= N)
 * must be refused like every other invalid parameter. */
START_TEST(crafted_scale_out_of_range)
{
    size_t len = 0;
    unsigned char *b = small_blob(&len);
    double s0 = amscr_test_get_f64le(b + BLOB_SCALE_OFFSET);
    ck_assert_msg(s0 == 2.0, "layout changed: scale at offset %d is %g", BLOB_SCALE_OFFSET, s0);
    unsigned char *c = malloc(len);
    static const double bad[] = {-1.0, -1e-300, 17.0, 1000.0, 1e300};
    char msg[512] = "";
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        memcpy(c, b, len);
        amscr_test_put_le(c + BLOB_SCALE_OFFSET, &bad[k], 8);
        fix_checksum(c, len);
        amscr_db *db = NULL;
        amscr_status st = load_exact(c, len, &db);
        if (st != AMSCR_E_FORMAT) {
            size_t used = strlen(msg);
            snprintf(msg + used, sizeof msg - used, " [scale %g: status %d]", bad[k], (int)st);
        }
        amscr_db_free(db);
    }
    ck_assert_msg(msg[0] == '\0', "crafted scales outside [0, N = 16] not refused (expected AMSCR_E_FORMAT):%s", msg);
    /* in range: 0 and N are valid scales; the file loads */
    static const double good[] = {0.0, 16.0};
    for (size_t k = 0; k < 2; k++) {
        memcpy(c, b, len);
        amscr_test_put_le(c + BLOB_SCALE_OFFSET, &good[k], 8);
        fix_checksum(c, len);
        amscr_db *db = NULL;
        ck_assert_int_eq(load_exact(c, len, &db), AMSCR_OK);
        amscr_db_free(db);
    }
    free(c);
    free(b);
}
END_TEST

START_TEST(load_bad_paths)
{
    amscr_db *sent = (amscr_db *)(void *)&sent, *db = sent;
    ck_assert_int_eq(amscr_db_load("/nonexistent_amscr_dir/none.amscrdb", &db), AMSCR_E_IO);
    expect_detail();
    ck_assert_ptr_eq(db, sent);
    char *dir = make_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/absent.amscrdb", dir);
    ck_assert_int_eq(amscr_db_load(path, &db), AMSCR_E_IO);
    ck_assert(strstr(amscr_last_error_detail(), "absent.amscrdb") != NULL);
    amscr_status st = amscr_db_load(dir, &db);
    ck_assert_msg(st == AMSCR_E_IO || st == AMSCR_E_FORMAT, "directory: status %d", (int)st);
    ck_assert_ptr_eq(db, sent);
    /* a text file */
    snprintf(path, sizeof path, "%s/text.txt", dir);
    const char *txt = "0 0\n1 0\n1 1\n0 1\n0 0.5\n0.5 0\n1 0.5\n0.5 1\n0.2 0.3\n0.7 0.1\n0.9 0.4\n";
    write_file(path, txt, strlen(txt));
    ck_assert_int_eq(amscr_db_load(path, &db), AMSCR_E_FORMAT);
    ck_assert_ptr_eq(db, sent);
    remove_tree(dir);
    free(dir);
}
END_TEST

/* --------------------------------------------------------------- NULL args */

START_TEST(null_arguments)
{
    amscr_params *p = small_params(1);
    amscr_descriptor **d = make_descs(p, 2, 1701);
    amscr_db *db = db_from(p, d, 2);
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 1702);
    amscr_contour *c = random_contour(&rng, 4);
    size_t idx = 0;
    double out[4];
    void *buf = NULL;
    size_t len = 0;
    amscr_db *o = NULL;

    ck_assert_int_eq(amscr_db_new(p, NULL), AMSCR_E_INVALID_ARG);
    expect_detail();
    ck_assert_int_eq(amscr_db_new(NULL, NULL), AMSCR_E_INVALID_ARG);
    amscr_db_free(NULL);

    ck_assert_int_eq(amscr_db_add_contour(NULL, c, 0, &idx), AMSCR_E_INVALID_ARG);
    expect_detail();
    ck_assert_int_eq(amscr_db_add_contour(db, NULL, 0, &idx), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_add_descriptor(NULL, d[0], 0, &idx), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_add_descriptor(db, NULL, 0, &idx), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(amscr_db_size(db), 2);

    ck_assert_uint_eq(amscr_db_size(NULL), 0);
    ck_assert_int_eq(amscr_db_label(NULL, 0), 0);
    ck_assert_ptr_null(amscr_db_descriptor(NULL, 0));
    ck_assert_ptr_null(amscr_db_params(NULL));

    ck_assert_int_eq(amscr_db_query(NULL, d[0], NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_query(db, NULL, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_query(db, d[0], NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    expect_detail();
    ck_assert_int_eq(amscr_db_distance_matrix(NULL, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_distance_matrix(db, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_cross_distances(NULL, db, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_cross_distances(db, NULL, NULL, NULL, out), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_cross_distances(db, db, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);

    ck_assert_int_eq(amscr_db_save(NULL, "/tmp/x.amscrdb"), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_save(db, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_load(NULL, &o), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_load("/tmp/x.amscrdb", NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_save_memory(NULL, &buf, &len), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_save_memory(db, NULL, &len), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(buf);
    ck_assert_int_eq(amscr_db_load_memory(NULL, 100, &o), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_load_memory(NULL, 0, &o), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_db_load_memory(buf, len, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(o);
    amscr_free(buf);

    amscr_contour_free(c);
    free_descs(d, 2);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* ----------------------------------------------------------------- suite */


/* A saved file gets 0666 less the umask (not mkstemp's 0600); a replaced file keeps its mode. */
START_TEST(saved_file_mode)
{
    char path[] = "/tmp/amscr_mode_XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    close(fd);
    remove(path);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(NULL, &db), AMSCR_OK);
    mode_t old = umask(027);
    amscr_status st = amscr_db_save(db, path);
    umask(old);
    ck_assert_int_eq(st, AMSCR_OK);
    struct stat sb;
    ck_assert_int_eq(stat(path, &sb), 0);
    ck_assert_uint_eq(sb.st_mode & 0777, 0640);
    ck_assert_int_eq(chmod(path, 0664), 0);
    ck_assert_int_eq(amscr_db_save(db, path), AMSCR_OK);
    ck_assert_int_eq(stat(path, &sb), 0);
    ck_assert_uint_eq(sb.st_mode & 0777, 0664);
    remove(path);
    amscr_db_free(db);
}
END_TEST

Suite *amscr_suite_db(void)
{
    Suite *s = suite_create("db");
    TCase *tc = tcase_create("build");
    tcase_add_test(tc, db_add_and_getters);
    tcase_add_test(tc, db_new_null_params_defaults);
    tcase_add_test(tc, db_add_descriptor_copies);
    tcase_add_test(tc, db_add_descriptor_incompatible);
    tcase_add_test(tc, db_add_degenerate_contour);
    tcase_add_test(tc, db_add_contours_as_one_by_one);
    tcase_add_test(tc, db_add_contours_all_or_nothing);
    suite_add_tcase(s, tc);

    tc = tcase_create("batch");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, matrix_equals_distance);
    tcase_add_test(tc, results_identical_across_threads);
    tcase_add_test(tc, query_equals_distance);
    tcase_add_test(tc, cross_equals_union_block);
    tcase_add_test(tc, empty_db);
    tcase_add_test(tc, single_shape_db);
    suite_add_tcase(s, tc);

    tc = tcase_create("progress");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, progress_contract);
    tcase_add_test(tc, cancellation);
    tcase_add_test(tc, cancel_writes_no_output);
    tcase_add_test(tc, argument_errors_write_nan);
    tcase_add_test(tc, progress_first_report_is_zero);
    suite_add_tcase(s, tc);

    tc = tcase_create("io");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, save_load_roundtrip);
    tcase_add_test(tc, save_io_errors);
    tcase_add_test(tc, blob_layout_sanity);
    tcase_add_test(tc, corrupt_magic_and_version);
    tcase_add_test(tc, format_v1_still_loads);
    tcase_add_test(tc, retrieval_settings_roundtrip);
    tcase_add_test(tc, format_v2_one_band);
    tcase_add_test(tc, format_v5_one_graph);
    tcase_add_test(tc, format_v10_mix_for_every_pair);
    tcase_add_test(tc, corrupt_truncated);
    tcase_add_test(tc, corrupt_flipped_bytes);
    tcase_add_test(tc, crafted_files_valid_checksum);
    tcase_add_test(tc, crafted_scale_out_of_range);
    tcase_add_test(tc, load_bad_paths);
    tcase_add_test(tc, saved_file_mode);
    suite_add_tcase(s, tc);

    tc = tcase_create("null");
    tcase_add_test(tc, null_arguments);
    suite_add_tcase(s, tc);
    return s;
}
