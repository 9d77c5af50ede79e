/* check_errors.c — status codes, their descriptions, and the per-thread error detail. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"

#define NUM_STATUS 14

START_TEST(test_status_values_pinned)
{
    /* The numeric values are ABI: never renumbered. */
    ck_assert_int_eq(AMSCR_OK, 0);
    ck_assert_int_eq(AMSCR_E_INVALID_ARG, 1);
    ck_assert_int_eq(AMSCR_E_NOMEM, 2);
    ck_assert_int_eq(AMSCR_E_IO, 3);
    ck_assert_int_eq(AMSCR_E_FORMAT, 4);
    ck_assert_int_eq(AMSCR_E_UNSUPPORTED, 5);
    ck_assert_int_eq(AMSCR_E_DEGENERATE, 6);
    ck_assert_int_eq(AMSCR_E_NUMERIC, 7);
    ck_assert_int_eq(AMSCR_E_NOT_CONVERGED, 8);
    ck_assert_int_eq(AMSCR_E_NOT_FOUND, 9);
    ck_assert_int_eq(AMSCR_E_STATE, 10);
    ck_assert_int_eq(AMSCR_E_INTERNAL, 11);
    ck_assert_int_eq(AMSCR_E_CANCELLED, 12);
    ck_assert_int_eq(AMSCR_E_LIMIT, 13);
    ck_assert_int_eq(AMSCR_FEATURE_THREADS, 1);
}
END_TEST

START_TEST(test_strerror_known_codes)
{
    const char *msg[NUM_STATUS];
    for (int i = 0; i < NUM_STATUS; i++) {
        msg[i] = amscr_strerror((amscr_status)i);
        ck_assert_msg(msg[i] != NULL, "amscr_strerror(%d) is NULL", i);
        ck_assert_msg(msg[i][0] != '\0', "amscr_strerror(%d) is empty", i);
    }
    for (int i = 0; i < NUM_STATUS; i++)
        for (int j = i + 1; j < NUM_STATUS; j++)
            ck_assert_msg(strcmp(msg[i], msg[j]) != 0, "amscr_strerror(%d) == amscr_strerror(%d) = \"%s\"", i,
                          j, msg[i]);
}
END_TEST

START_TEST(test_strerror_unknown_codes)
{
    const int unknown[] = {14, 15, 99, 1000, -1, -13, 0x7fffffff};
    const char *ok = amscr_strerror(AMSCR_OK);
    for (size_t k = 0; k < sizeof unknown / sizeof unknown[0]; k++) {
        const char *m = amscr_strerror((amscr_status)unknown[k]);
        ck_assert_msg(m != NULL, "amscr_strerror(%d) is NULL", unknown[k]);
        ck_assert_msg(m[0] != '\0', "amscr_strerror(%d) is empty", unknown[k]);
        /* An unknown code must not be described as success. */
        ck_assert_msg(strcmp(m, ok) != 0, "amscr_strerror(%d) says \"%s\" like AMSCR_OK", unknown[k], m);
    }
}
END_TEST

START_TEST(test_strerror_static)
{
    for (int i = 0; i < NUM_STATUS; i++)
        ck_assert_ptr_eq(amscr_strerror((amscr_status)i), amscr_strerror((amscr_status)i));
}
END_TEST

START_TEST(test_detail_never_null)
{
    const char *d = amscr_last_error_detail();
    ck_assert_ptr_nonnull(d);
}
END_TEST

START_TEST(test_detail_set_after_failure)
{
    amscr_contour *sentinel = (amscr_contour *)(void *)&sentinel;
    amscr_contour *c = sentinel;
    ck_assert_int_eq(amscr_contour_new(NULL, 5, &c), AMSCR_E_INVALID_ARG);
    /* Outputs are written only on AMSCR_OK. */
    ck_assert_ptr_eq(c, sentinel);
    const char *d = amscr_last_error_detail();
    ck_assert_ptr_nonnull(d);
    ck_assert_msg(d[0] != '\0', "no detail after amscr_contour_new(NULL, 5, &c)");
    ck_assert_msg(strlen(d) < 4096, "detail not terminated sensibly");
    /* no points, and one past the limit (its pages never touched: the count is refused first) */
    double xy[2] = {0.0, 0.0};
    ck_assert_int_eq(amscr_contour_new(xy, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "no points"));
    double *big = calloc(2 * ((size_t)AMSCR_MAX_POINTS + 1), sizeof *big);
    ck_assert_ptr_nonnull(big);
    ck_assert_int_eq(amscr_contour_new(big, (size_t)AMSCR_MAX_POINTS + 1, &c), AMSCR_E_LIMIT);
    ck_assert_ptr_eq(c, sentinel);
    free(big);
}
END_TEST

START_TEST(test_free_null)
{
    amscr_free(NULL);
    amscr_free(NULL);
}
END_TEST

/* ---------------------------------------------------------------- threads */

typedef struct {
    char start_detail[512];  /* detail seen when the thread starts (no failure yet) */
    int start_null;
    int status;              /* status of the thread's failing call */
    char detail[512];        /* detail after the thread's failure */
} thread_probe;

static void copy_detail(char *dst, size_t cap, const char *src)
{
    if (src == NULL) {
        dst[0] = '\0';
        return;
    }
    strncpy(dst, src, cap - 1);
    dst[cap - 1] = '\0';
}

static void *probe_thread(void *arg)
{
    thread_probe *t = arg;
    const char *d0 = amscr_last_error_detail();
    t->start_null = d0 == NULL;
    copy_detail(t->start_detail, sizeof t->start_detail, d0);
    /* A failure of a different kind than the main thread's. */
    const double singular[6] = {1.0, 2.0, 3.0, 2.0, 4.0, 5.0};
    double inv[6];
    t->status = (int)amscr_affine_invert(singular, inv);
    copy_detail(t->detail, sizeof t->detail, amscr_last_error_detail());
    return NULL;
}

START_TEST(test_detail_is_per_thread)
{
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(NULL, 5, &c), AMSCR_E_INVALID_ARG);
    char main_detail[512];
    copy_detail(main_detail, sizeof main_detail, amscr_last_error_detail());
    ck_assert_msg(main_detail[0] != '\0', "no detail in the main thread");

    thread_probe t;
    memset(&t, 0, sizeof t);
    pthread_t th;
    ck_assert_int_eq(pthread_create(&th, NULL, probe_thread, &t), 0);
    ck_assert_int_eq(pthread_join(th, NULL), 0);

    /* A new thread has had no failure: its detail is empty, not the main thread's. */
    ck_assert_int_eq(t.start_null, 0);
    ck_assert_msg(t.start_detail[0] == '\0', "fresh thread sees detail \"%s\"", t.start_detail);
    ck_assert_int_eq(t.status, AMSCR_E_DEGENERATE);
    ck_assert_msg(t.detail[0] != '\0', "no detail in the failing thread");
    ck_assert_msg(strcmp(t.detail, main_detail) != 0,
                  "thread detail equals main detail (\"%s\"): the two failures are different", t.detail);
    /* The main thread's detail did not change. */
    ck_assert_str_eq(amscr_last_error_detail(), main_detail);
}
END_TEST

#define STRESS_THREADS 8
#define STRESS_ITERS 2000

typedef struct {
    int kind;
    pthread_barrier_t *barrier;
    int mismatches;
    int empty;
    char first[512];
} stress_arg;

static void fail_once(int kind)
{
    if (kind == 0) {
        amscr_contour *c = NULL;
        (void)!amscr_contour_new(NULL, 5, &c);
    } else {
        const double singular[6] = {1.0, 2.0, 3.0, 2.0, 4.0, 5.0};
        double inv[6];
        (void)!amscr_affine_invert(singular, inv);
    }
}

static void *stress_thread(void *arg)
{
    stress_arg *s = arg;
    pthread_barrier_wait(s->barrier);
    fail_once(s->kind);
    copy_detail(s->first, sizeof s->first, amscr_last_error_detail());
    for (int i = 0; i < STRESS_ITERS; i++) {
        fail_once(s->kind);
        const char *d = amscr_last_error_detail();
        if (d == NULL || d[0] == '\0')
            s->empty++;
        else if (strcmp(d, s->first) != 0)
            s->mismatches++;
    }
    return NULL;
}

START_TEST(test_detail_concurrent_threads)
{
    pthread_barrier_t barrier;
    ck_assert_int_eq(pthread_barrier_init(&barrier, NULL, STRESS_THREADS), 0);
    stress_arg args[STRESS_THREADS];
    pthread_t th[STRESS_THREADS];
    for (int i = 0; i < STRESS_THREADS; i++) {
        memset(&args[i], 0, sizeof args[i]);
        args[i].kind = i % 2;
        args[i].barrier = &barrier;
        ck_assert_int_eq(pthread_create(&th[i], NULL, stress_thread, &args[i]), 0);
    }
    for (int i = 0; i < STRESS_THREADS; i++)
        ck_assert_int_eq(pthread_join(th[i], NULL), 0);
    pthread_barrier_destroy(&barrier);
    for (int i = 0; i < STRESS_THREADS; i++) {
        ck_assert_msg(args[i].first[0] != '\0', "thread %d: no detail", i);
        ck_assert_int_eq(args[i].empty, 0);
        ck_assert_msg(args[i].mismatches == 0, "thread %d: detail changed %d times (another thread's detail?)",
                      i, args[i].mismatches);
    }
    ck_assert_str_ne(args[0].first, args[1].first);
}
END_TEST

/* Asserts that call fails with status st and exactly the detail want. */
#define FAILS_WITH(call, st, want)                                                                                   \
    do {                                                                                                           \
        ck_assert_int_eq((call), (st));                                                                            \
        ck_assert_str_eq(amscr_last_error_detail(), (want));                                                      \
    } while (0)

/* A detail names the public call the caller made (not a helper of it) and the value as given. */
START_TEST(test_detail_names_the_call_and_the_value)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    FAILS_WITH(amscr_params_set_invariance(p, (amscr_invariance)-1), AMSCR_E_INVALID_ARG,
               "amscr_params_set_invariance: invariance -1 is not in 0..2");
    FAILS_WITH(amscr_params_set_channel_weight(p, 1.0000001), AMSCR_E_INVALID_ARG,
               "amscr_params_set_channel_weight: channel_weight 1.0000001 is not in [0, 1]");
    amscr_params_free(p);
    amscr_index *x = NULL;
    amscr_contour_set *cs = NULL;
    FAILS_WITH(amscr_index_load_memory(NULL, 0, &x), AMSCR_E_INVALID_ARG, "amscr_index_load_memory: buf is NULL");
    FAILS_WITH(amscr_index_load(NULL, &x), AMSCR_E_INVALID_ARG, "amscr_index_load: path is NULL");
    FAILS_WITH(amscr_db_query_retrieval(NULL, NULL, NULL, NULL, NULL, 0), AMSCR_E_INVALID_ARG,
               "amscr_db_query_retrieval: db is NULL");
    FAILS_WITH(amscr_contours_from_mask(NULL, 4, 4, 4, -1, 0.0, &cs), AMSCR_E_INVALID_ARG,
               "amscr_contours_from_mask: pixels is NULL");
    ck_assert_int_eq(amscr_index_load(".", &x), AMSCR_E_IO); /* a folder: the reason, not "read error" alone */
    ck_assert_msg(strstr(amscr_last_error_detail(), "read error: ") != NULL &&
                      strlen(strstr(amscr_last_error_detail(), "read error: ")) > strlen("read error: "),
                  "%s", amscr_last_error_detail());
    ck_assert_ptr_null(x);
}
END_TEST

/* Flags are int 0 or 1 (the header's Conventions): every call taking `closed` refuses 2 and -1
 * by name, as amscr_params_set_closed does. */
START_TEST(test_flags_are_zero_or_one)
{
    double xy[32], out[64], total;
    for (int i = 0; i < 16; i++) { /* an ellipse of 16 points */
        xy[2 * i] = 20.0 * cos(0.39269908169872414 * i);
        xy[2 * i + 1] = 9.0 * sin(0.39269908169872414 * i);
    }
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, 16, &c), AMSCR_OK);
    const int bad[2] = {2, -1};
    for (int i = 0; i < 2; i++) {
        int f = bad[i];
        FAILS_WITH(amscr_contour_validate(c, f), AMSCR_E_INVALID_ARG,
                   f == 2 ? "amscr_contour_validate: closed = 2 is not 0 or 1"
                          : "amscr_contour_validate: closed = -1 is not 0 or 1");
        ck_assert_int_eq(amscr_smooth_gaussian(xy, 16, f, 1.0, out), AMSCR_E_INVALID_ARG);
        ck_assert_int_eq(amscr_resample_euclidean(xy, 16, f, 16, out), AMSCR_E_INVALID_ARG);
        ck_assert_int_eq(amscr_affine_arclength(xy, 16, f, 0.0, out, &total), AMSCR_E_INVALID_ARG);
        ck_assert_int_eq(amscr_resample_affine(xy, 16, f, 0.0, 1, 16, out), AMSCR_E_INVALID_ARG);
    }
    for (int f = 0; f <= 1; f++) {
        ck_assert_int_eq(amscr_contour_validate(c, f), AMSCR_OK);
        ck_assert_int_eq(amscr_smooth_gaussian(xy, 16, f, 1.0, out), AMSCR_OK);
        ck_assert_int_eq(amscr_resample_euclidean(xy, 16, f, 16, out), AMSCR_OK);
    }
    amscr_contour_free(c);
}
END_TEST

Suite *amscr_suite_errors(void)
{
    Suite *s = suite_create("errors");
    TCase *tc = tcase_create("codes");
    tcase_add_test(tc, test_status_values_pinned);
    tcase_add_test(tc, test_strerror_known_codes);
    tcase_add_test(tc, test_strerror_unknown_codes);
    tcase_add_test(tc, test_strerror_static);
    tcase_add_test(tc, test_free_null);
    suite_add_tcase(s, tc);

    TCase *td = tcase_create("detail");
    tcase_add_test(td, test_detail_never_null);
    tcase_add_test(td, test_detail_set_after_failure);
    tcase_add_test(td, test_detail_is_per_thread);
    tcase_add_test(td, test_detail_concurrent_threads);
    tcase_add_test(td, test_detail_names_the_call_and_the_value);
    tcase_add_test(td, test_flags_are_zero_or_one);
    suite_add_tcase(s, td);
    return s;
}
