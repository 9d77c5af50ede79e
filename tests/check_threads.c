/* check_threads.c — the thread-safety contract of amscr.h ("three laws"), exercised for real:
 * several threads at once build descriptors from shared const contours, register different
 * pairs of shared const descriptors (each with its own workspace, or none), query and
 * match a shared const db (single- and multi-threaded dbs: library threads inside user
 * threads), and provoke errors whose thread-local details must stay their own. Every result
 * is compared bit for bit with the one computed beforehand on a single thread.
 *
 * A normal Check suite (area "threads"); scripts/hardening.sh also runs it in a
 * ThreadSanitizer build (build-tsan), where any data race fails the run. Workers never call
 * ck_assert (Check is not thread-safe): they count mismatches, and the main thread asserts.
 * Only the public API (plus testutil) is used. */
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"
#include "testutil.h"

/* Until tests/suites.h declares it (check_all needs the prototype there; tests/meson.build
 * builds this file alone, with the main() at the end, while suites.h lacks it). */
Suite *amscr_suite_threads(void);

#define NSHAPES 6
#define NPTS 160
#define NTHREADS 4
#define ROUNDS 2

/* One registration's observable output, compared with memcmp (bit for bit). */
typedef struct {
    double dist, dist_batch;
    double m[6], mn[6];
    double residuals[8];
    int kept[8];
    size_t shift, nkept, k;
    int reflected;
} reg_out;

typedef struct {
    /* shared, read-only during the concurrent phase */
    amscr_params *params;
    amscr_contour *contours[NSHAPES];
    amscr_descriptor *desc[NSHAPES];
    amscr_db *db1; /* num_threads 1 */
    amscr_db *db2; /* num_threads 2: library threads inside the test threads */
    reg_out ref[NSHAPES][NSHAPES];
    double ref_query[NSHAPES][NSHAPES];
    double ref_matrix[NSHAPES * NSHAPES];
} shared_t;

typedef struct {
    shared_t *sh;
    int id;
    int use_ws;
    /* results, read by the main thread after join */
    int mismatches;
    int failures;
    char first[256];
} worker_t;

static void note(worker_t *w, int is_failure, const char *fmt, size_t a, size_t b)
{
    if (is_failure)
        w->failures++;
    else
        w->mismatches++;
    if (!w->first[0])
        snprintf(w->first, sizeof w->first, fmt, a, b);
}

/* Registers src -> tgt and records everything; returns the status. */
static amscr_status register_pair(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                  amscr_workspace *ws, reg_out *o)
{
    memset(o, 0, sizeof *o);
    amscr_result *r = NULL;
    amscr_status st = amscr_register(p, src, tgt, ws, &r);
    if (st != AMSCR_OK)
        return st;
    o->dist = amscr_result_distance(r);
    if (amscr_result_affine(r, o->m) != AMSCR_OK || amscr_result_affine_normalized(r, o->mn) != AMSCR_OK)
        st = AMSCR_E_INTERNAL;
    size_t n = 8;
    if (st == AMSCR_OK && amscr_result_residuals(r, o->residuals, &n) != AMSCR_OK)
        st = AMSCR_E_INTERNAL;
    n = 8;
    if (st == AMSCR_OK && amscr_result_kept(r, o->kept, &n) != AMSCR_OK)
        st = AMSCR_E_INTERNAL;
    o->shift = amscr_result_shift(r);
    o->nkept = amscr_result_num_kept(r);
    o->k = amscr_result_k(r);
    o->reflected = amscr_result_reflected(r);
    amscr_result_free(r);
    if (st == AMSCR_OK)
        st = amscr_distance(p, src, tgt, ws, &o->dist_batch);
    return st;
}

static int same_desc(const amscr_descriptor *a, const amscr_descriptor *b)
{
    size_t n = amscr_descriptor_num_samples(a), p = amscr_descriptor_num_scales(a);
    if (n != amscr_descriptor_num_samples(b) || p != amscr_descriptor_num_scales(b))
        return 0;
    if (memcmp(amscr_descriptor_base_points(a), amscr_descriptor_base_points(b), 2 * n * sizeof(double)) != 0 ||
        memcmp(amscr_descriptor_input_points(a), amscr_descriptor_input_points(b), 2 * n * sizeof(double)) != 0)
        return 0;
    for (size_t k = 0; k < p; k++)
        if (memcmp(amscr_descriptor_scale_points(a, k), amscr_descriptor_scale_points(b, k),
                   2 * n * sizeof(double)) != 0)
            return 0;
    return 1;
}

static void *worker_main(void *arg)
{
    worker_t *w = arg;
    shared_t *sh = w->sh;
    amscr_workspace *ws = NULL;
    if (w->use_ws && amscr_workspace_new(&ws) != AMSCR_OK) {
        note(w, 1, "thread: amscr_workspace_new failed (%zu %zu)", 0, 0);
        return NULL;
    }
    for (int round = 0; round < ROUNDS; round++) {
        /* 1. descriptors from the shared const contours, bit-identical to the reference */
        for (size_t i = (size_t)w->id % 2; i < NSHAPES; i += 2) {
            amscr_descriptor *d = NULL;
            if (amscr_descriptor_new(sh->params, sh->contours[i], &d) != AMSCR_OK)
                note(w, 1, "descriptor %zu failed (round %zu)", i, (size_t)round);
            else if (!same_desc(d, sh->desc[i]))
                note(w, 0, "descriptor %zu differs from the single-thread one (round %zu)", i, (size_t)round);
            amscr_descriptor_free(d);
        }
        /* 2. this thread's share of the pairs (different pairs per thread, rotating by round) */
        for (size_t i = 0; i < NSHAPES; i++)
            for (size_t j = 0; j < NSHAPES; j++) {
                if ((i * NSHAPES + j + (size_t)round) % NTHREADS != (size_t)w->id)
                    continue;
                reg_out o;
                if (register_pair(sh->params, sh->desc[i], sh->desc[j], ws, &o) != AMSCR_OK)
                    note(w, 1, "register %zu -> %zu failed", i, j);
                else if (memcmp(&o, &sh->ref[i][j], sizeof o) != 0)
                    note(w, 0, "register %zu -> %zu differs from the single-thread result", i, j);
            }
        /* 3. the convenience call on shared const contours (descriptors built inside) */
        {
            size_t i = (size_t)w->id % NSHAPES, j = ((size_t)w->id + 1 + (size_t)round) % NSHAPES;
            amscr_result *r = NULL;
            if (amscr_register_contours(sh->params, sh->contours[i], sh->contours[j], &r) != AMSCR_OK)
                note(w, 1, "register_contours %zu -> %zu failed", i, j);
            else {
                double d = amscr_result_distance(r), m[6];
                if (amscr_result_affine(r, m) != AMSCR_OK || memcmp(&d, &sh->ref[i][j].dist, sizeof d) != 0 ||
                    memcmp(m, sh->ref[i][j].m, sizeof m) != 0)
                    note(w, 0, "register_contours %zu -> %zu differs from the single-thread result", i, j);
            }
            amscr_result_free(r);
        }
        /* 4. queries of the shared dbs, and the whole matrix from one of them */
        for (size_t q = 0; q < NSHAPES; q++) {
            double row[NSHAPES];
            const amscr_db *db = (q + (size_t)w->id) % 2 ? sh->db2 : sh->db1;
            if (amscr_db_query(db, sh->desc[q], NULL, NULL, row) != AMSCR_OK)
                note(w, 1, "db query %zu failed (db with %zu threads)", q, amscr_params_get_num_threads(amscr_db_params(db)));
            else if (memcmp(row, sh->ref_query[q], sizeof row) != 0)
                note(w, 0, "db query %zu differs (db with %zu threads)", q, amscr_params_get_num_threads(amscr_db_params(db)));
        }
        {
            double mat[NSHAPES * NSHAPES];
            const amscr_db *db = w->id % 2 ? sh->db2 : sh->db1;
            if (amscr_db_distance_matrix(db, NULL, NULL, mat) != AMSCR_OK)
                note(w, 1, "distance matrix failed (thread %zu, round %zu)", (size_t)w->id, (size_t)round);
            else if (memcmp(mat, sh->ref_matrix, sizeof mat) != 0)
                note(w, 0, "distance matrix differs (thread %zu, round %zu)", (size_t)w->id, (size_t)round);
        }
        /* 5. the thread-local error detail: each thread's own failure, read back while the
         *    other threads fail and succeed in between */
        {
            amscr_params *p = NULL;
            size_t bad = 1000000 + (size_t)w->id * 1000 + (size_t)round;
            char want[64];
            snprintf(want, sizeof want, "%zu", bad);
            if (amscr_params_new(&p) != AMSCR_OK)
                note(w, 1, "params_new failed (%zu %zu)", 0, 0);
            else if (amscr_params_set_num_samples(p, bad) != AMSCR_E_INVALID_ARG)
                note(w, 0, "set_num_samples(%zu) did not fail (round %zu)", bad, (size_t)round);
            else {
                for (int spin = 0; spin < 20; spin++) /* let the others set theirs meanwhile */
                    sched_yield();
                if (strstr(amscr_last_error_detail(), want) == NULL)
                    note(w, 0, "error detail of thread %zu lost (round %zu)", (size_t)w->id, (size_t)round);
            }
            amscr_params_free(p);
        }
    }
    amscr_workspace_free(ws);
    return NULL;
}

static amscr_db *make_db(const shared_t *sh, unsigned threads)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_copy(sh->params, &p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(p, threads), AMSCR_OK);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(db, sh->desc[i], (int32_t)i, NULL), AMSCR_OK);
    amscr_params_free(p);
    return db;
}

static void shared_init(shared_t *sh, amscr_method method, int reflections, unsigned refine)
{
    memset(sh, 0, sizeof *sh);
    ck_assert_int_eq(amscr_params_new(&sh->params), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_method(sh->params, method), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_reflections(sh->params, reflections), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_refine(sh->params, refine), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(sh->params, 1), AMSCR_OK);
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 20240607u + (uint64_t)method * 7u + (uint64_t)refine);
    for (size_t i = 0; i < NSHAPES; i++) {
        double xy[2 * NPTS], out[2 * NPTS], m6[6];
        /* shapes 2k and 2k+1 are affine copies of one another: low and high distances */
        if (i % 2 == 0)
            amscr_test_random_shape(&rng, NPTS, 3 + (int)i, xy);
        else
            memcpy(xy, amscr_contour_xy(sh->contours[i - 1]), sizeof xy);
        amscr_test_random_affine(&rng, 2.0, 0.3, 5.0, 0, m6);
        amscr_test_apply_affine(m6, xy, NPTS, out);
        ck_assert_int_eq(amscr_contour_new(out, NPTS, &sh->contours[i]), AMSCR_OK);
        amscr_status st = amscr_descriptor_new(sh->params, sh->contours[i], &sh->desc[i]);
        ck_assert_msg(st == AMSCR_OK, "descriptor %zu: %s", i, amscr_last_error_detail());
    }
    /* single-thread reference */
    for (size_t i = 0; i < NSHAPES; i++)
        for (size_t j = 0; j < NSHAPES; j++) {
            amscr_status st = register_pair(sh->params, sh->desc[i], sh->desc[j], NULL, &sh->ref[i][j]);
            ck_assert_msg(st == AMSCR_OK, "reference %zu -> %zu: %s", i, j, amscr_last_error_detail());
            ck_assert(isfinite(sh->ref[i][j].dist));
        }
    sh->db1 = make_db(sh, 1);
    sh->db2 = make_db(sh, 2);
    for (size_t q = 0; q < NSHAPES; q++)
        ck_assert_int_eq(amscr_db_query(sh->db1, sh->desc[q], NULL, NULL, sh->ref_query[q]), AMSCR_OK);
    ck_assert_int_eq(amscr_db_distance_matrix(sh->db1, NULL, NULL, sh->ref_matrix), AMSCR_OK);
    /* the reference itself: thread count does not change results (header promise) */
    double row[NSHAPES];
    ck_assert_int_eq(amscr_db_query(sh->db2, sh->desc[0], NULL, NULL, row), AMSCR_OK);
    ck_assert(memcmp(row, sh->ref_query[0], sizeof row) == 0);
}

static void shared_free(shared_t *sh)
{
    for (size_t i = 0; i < NSHAPES; i++) {
        amscr_contour_free(sh->contours[i]);
        amscr_descriptor_free(sh->desc[i]);
    }
    amscr_db_free(sh->db1);
    amscr_db_free(sh->db2);
    amscr_params_free(sh->params);
}

static void run_concurrently(amscr_method method, int reflections, unsigned refine)
{
    shared_t *sh = malloc(sizeof *sh);
    ck_assert_ptr_nonnull(sh);
    shared_init(sh, method, reflections, refine);
    worker_t w[NTHREADS];
    pthread_t tid[NTHREADS];
    for (int t = 0; t < NTHREADS; t++) {
        memset(&w[t], 0, sizeof w[t]);
        w[t].sh = sh;
        w[t].id = t;
        w[t].use_ws = t % 2 == 0; /* half with a workspace, half with NULL (internal scratch) */
        ck_assert_int_eq(pthread_create(&tid[t], NULL, worker_main, &w[t]), 0);
    }
    for (int t = 0; t < NTHREADS; t++)
        ck_assert_int_eq(pthread_join(tid[t], NULL), 0);
    for (int t = 0; t < NTHREADS; t++) {
        ck_assert_msg(w[t].failures == 0, "thread %d: %d calls failed; first: %s", t, w[t].failures, w[t].first);
        ck_assert_msg(w[t].mismatches == 0, "thread %d: %d results differ from the single-thread ones; first: %s", t,
                      w[t].mismatches, w[t].first);
    }
    shared_free(sh);
    free(sh);
}

START_TEST(test_concurrent_default) { run_concurrently(AMSCR_METHOD_MULTICLASS_EM, 0, 0); }
END_TEST

START_TEST(test_concurrent_reflections_refine) { run_concurrently(AMSCR_METHOD_BINARY_EM, 1, 3); }
END_TEST

START_TEST(test_concurrent_acma) { run_concurrently(AMSCR_METHOD_ACMA, 0, 0); }
END_TEST

/* Fitted k-means and GMM objects are const-shareable for prediction calls. */
typedef struct {
    const amscr_kmeans *km;
    const amscr_gmm1d *g;
    const double *data;
    size_t n;
    const size_t *ref_labels;
    const double *ref_post;
    int mismatches;
} predict_arg;

static void *predict_main(void *arg)
{
    predict_arg *a = arg;
    size_t labels[64];
    double sq[64], post[3];
    for (int rep = 0; rep < 20; rep++) {
        if (amscr_kmeans_assign(a->km, a->data, a->n, labels, sq) != AMSCR_OK ||
            memcmp(labels, a->ref_labels, a->n * sizeof *labels) != 0)
            a->mismatches++;
        for (size_t i = 0; i < a->n; i++)
            if (amscr_gmm1d_posterior(a->g, a->data[i], post) != AMSCR_OK ||
                memcmp(post, a->ref_post + 3 * i, sizeof post) != 0)
                a->mismatches++;
    }
    return NULL;
}

START_TEST(test_concurrent_predict)
{
    double data[64];
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, 99);
    for (size_t i = 0; i < 64; i++)
        data[i] = (double)(i % 3) * 5.0 + amscr_test_normal(&rng);
    amscr_kmeans *km = NULL;
    amscr_gmm1d *g = NULL;
    ck_assert_int_eq(amscr_kmeans_new(3, &km), AMSCR_OK);
    ck_assert_int_eq(amscr_kmeans_fit(km, data, 64, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_new(3, &g), AMSCR_OK);
    ck_assert_int_eq(amscr_gmm1d_fit(g, data, 64), AMSCR_OK);
    size_t ref_labels[64];
    double ref_post[3 * 64];
    ck_assert_int_eq(amscr_kmeans_assign(km, data, 64, ref_labels, NULL), AMSCR_OK);
    for (size_t i = 0; i < 64; i++)
        ck_assert_int_eq(amscr_gmm1d_posterior(g, data[i], ref_post + 3 * i), AMSCR_OK);
    predict_arg a[NTHREADS];
    pthread_t tid[NTHREADS];
    for (int t = 0; t < NTHREADS; t++) {
        a[t] = (predict_arg){km, g, data, 64, ref_labels, ref_post, 0};
        ck_assert_int_eq(pthread_create(&tid[t], NULL, predict_main, &a[t]), 0);
    }
    for (int t = 0; t < NTHREADS; t++) {
        ck_assert_int_eq(pthread_join(tid[t], NULL), 0);
        ck_assert_msg(a[t].mismatches == 0, "thread %d: %d predictions differ", t, a[t].mismatches);
    }
    amscr_kmeans_free(km);
    amscr_gmm1d_free(g);
}
END_TEST

Suite *amscr_suite_threads(void)
{
    Suite *s = suite_create("threads");
    TCase *tc = tcase_create("concurrent");
    tcase_set_timeout(tc, 600); /* ThreadSanitizer and valgrind builds are slow */
    tcase_add_test(tc, test_concurrent_default);
    tcase_add_test(tc, test_concurrent_reflections_refine);
    tcase_add_test(tc, test_concurrent_acma);
    tcase_add_test(tc, test_concurrent_predict);
    suite_add_tcase(s, tc);
    return s;
}

#ifdef AMSCR_THREADS_MAIN
int main(void)
{
    SRunner *sr = srunner_create(amscr_suite_threads());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
#endif
