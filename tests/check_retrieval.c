/* check_retrieval.c — top-k, bull's eye, top-k table, 1-NN accuracies; which scores params rank by. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"
#include "testutil.h"

/* A 6 x 6 matrix with ties. Orders (distance, index), row by row:
 *   row 0: 0(0) 2(1) 3(1) 5(2) 1(5) 4(9)
 *   row 1: 1(0) 2(3) 3(3) 4(3) 5(4) 0(5)
 *   row 2: 2(0) 0(1) 3(2) 4(2) 5(2) 1(3)
 *   row 3: 3(0) 0(1) 4(1) 2(2) 1(3) 5(7)
 *   row 4: 4(0) 5(0) 3(1) 2(2) 1(3) 0(9)
 *   row 5: 4(0) 5(0) 0(2) 2(2) 1(4) 3(7)   (row 5 ranks 4 before itself: a tie) */
static const double D6[36] = {
    0, 5, 1, 1, 9, 2, /* */
    5, 0, 3, 3, 3, 4, /* */
    1, 3, 0, 2, 2, 2, /* */
    1, 3, 2, 0, 1, 7, /* */
    9, 3, 2, 1, 0, 0, /* */
    2, 4, 2, 7, 0, 0,
};
static const int32_t LA[6] = {1, 1, 1, 2, 2, 3}; /* class sizes 3, 3, 3, 2, 2, 1 */
static const int32_t LB[6] = {1, 1, 2, 2, 3, 3}; /* class sizes 2 */

/* ---------------------------------------------------------------- reference */

static const double *ref_row;
static int ref_cmp(const void *a, const void *b)
{
    size_t i = *(const size_t *)a, j = *(const size_t *)b;
    if (ref_row[i] != ref_row[j])
        return ref_row[i] < ref_row[j] ? -1 : 1;
    return (i > j) - (i < j);
}

/* Full ranking of a row by qsort (ties by index), `exclude` removed. Returns the count. */
static size_t ref_rank(const double *row, size_t n, size_t exclude, size_t *out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (i != exclude)
            out[m++] = i;
    ref_row = row;
    qsort(out, m, sizeof *out, ref_cmp);
    return m;
}

/* ---------------------------------------------------------------- tests */

START_TEST(topk_hand)
{
    const double d[6] = {3, 1, 2, 1, 5, 0};
    size_t idx[6];
    ck_assert_int_eq(amscr_topk(d, 6, 3, SIZE_MAX, idx), AMSCR_OK);
    ck_assert(idx[0] == 5 && idx[1] == 1 && idx[2] == 3);
    ck_assert_int_eq(amscr_topk(d, 6, 3, 1, idx), AMSCR_OK);
    ck_assert(idx[0] == 5 && idx[1] == 3 && idx[2] == 2);
    ck_assert_int_eq(amscr_topk(d, 6, 6, SIZE_MAX, idx), AMSCR_OK);
    const size_t all[6] = {5, 1, 3, 2, 0, 4};
    ck_assert_int_eq(memcmp(idx, all, sizeof all), 0);
    ck_assert_int_eq(amscr_topk(d, 6, 5, 4, idx), AMSCR_OK);
    ck_assert_int_eq(memcmp(idx, all, 5 * sizeof(size_t)), 0);
    ck_assert_int_eq(amscr_topk(d, 6, 1, 5, idx), AMSCR_OK);
    ck_assert_uint_eq(idx[0], 1);
    ck_assert_int_eq(amscr_topk(d, 6, 0, SIZE_MAX, idx), AMSCR_OK);
    /* Infinities rank last, by index. */
    const double e[4] = {INFINITY, 1, INFINITY, -INFINITY};
    ck_assert_int_eq(amscr_topk(e, 4, 4, SIZE_MAX, idx), AMSCR_OK);
    ck_assert(idx[0] == 3 && idx[1] == 1 && idx[2] == 0 && idx[3] == 2);
    /* Invalid. */
    ck_assert_int_eq(amscr_topk(NULL, 6, 1, SIZE_MAX, idx), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_topk(d, 6, 1, SIZE_MAX, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_topk(d, 6, 7, SIZE_MAX, idx), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_topk(d, 6, 6, 0, idx), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_topk(d, 6, 1, 6, idx), AMSCR_E_INVALID_ARG);
    const double nan_row[3] = {1, NAN, 0};
    idx[0] = 99;
    ck_assert_int_eq(amscr_topk(nan_row, 3, 1, SIZE_MAX, idx), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_uint_eq(idx[0], 99);
}
END_TEST

START_TEST(topk_random)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 40 + (uint64_t)_i);
    size_t n = 1 + (size_t)(amscr_test_uniform(&r) * 60);
    double *d = malloc(n * sizeof *d);
    size_t *ref = malloc(n * sizeof *ref), *got = malloc(n * sizeof *got);
    ck_assert(d && ref && got);
    for (size_t i = 0; i < n; i++)
        d[i] = floor(amscr_test_uniform(&r) * 5); /* many ties */
    size_t ex = _i % 2 ? (size_t)(amscr_test_uniform(&r) * (double)n) : SIZE_MAX;
    size_t m = ref_rank(d, n, ex, ref);
    for (size_t k = 0; k <= m; k++) {
        ck_assert_int_eq(amscr_topk(d, n, k, ex, got), AMSCR_OK);
        ck_assert_int_eq(memcmp(got, ref, k * sizeof *got), 0);
    }
    free(d);
    free(ref);
    free(got);
}
END_TEST

START_TEST(bullseye_hand)
{
    double s = -1.0;
    /* LB, window 0 (= 2 Nc = 4): hits 1, 1, 2, 2, 2, 2 = 10 of 6 * 2. */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LB, 0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 10.0 / 12.0, 1e-15);
    /* LA, window 0: windows 6, 6, 6, 4, 4, 2 -> hits 3, 3, 3, 2, 2, 1 = 14 of 14. */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LA, 0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 1.0, 1e-15);
    /* LA, window 2: hits 2, 2, 2, 1, 1, 1 = 9 of 14 (row 5's window {4, 5} holds itself). */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LA, 2, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 9.0 / 14.0, 1e-15);
    /* LA, window 3: hits 2, 2, 2, 2, 2, 1 = 11 of 14. */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LA, 3, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 11.0 / 14.0, 1e-15);
    /* A window larger than n is clipped: everything counts. */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LA, 100, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 1.0, 1e-15);
    /* Labels are arbitrary int32 values: only equality matters. */
    const int32_t LC[6] = {INT32_MIN, INT32_MIN, -5, -5, INT32_MAX, INT32_MAX};
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LC, 0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 10.0 / 12.0, 1e-15);
    /* n = 1. */
    const double one = 0.0;
    ck_assert_int_eq(amscr_score_bullseye(&one, 1, LA, 0, &s), AMSCR_OK);
    ck_assert_double_eq(s, 1.0);
}
END_TEST

START_TEST(topk_table_hand)
{
    size_t c[5] = {9, 9, 9, 9, 9};
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, LA, 3, c), AMSCR_OK);
    ck_assert(c[0] == 3 && c[1] == 2 && c[2] == 0);
    ck_assert_uint_eq(c[3], 9); /* untouched past kmax */
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, LA, 5, c), AMSCR_OK);
    const size_t want[5] = {3, 2, 0, 1, 2};
    ck_assert_int_eq(memcmp(c, want, sizeof want), 0);
    /* kmax = 5 = n - 1 is the largest allowed. */
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, LA, 6, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, LA, 0, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(memcmp(c, want, sizeof want), 0);
}
END_TEST

START_TEST(nn_hand)
{
    double a = -1.0;
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 6, LA, &a), AMSCR_OK);
    ck_assert_double_eq_tol(a, 0.5, 1e-15);
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 6, LB, &a), AMSCR_OK);
    ck_assert_double_eq_tol(a, 2.0 / 6.0, 1e-15);
    /* Train/test: ties go to the lower training index. */
    const double d[6] = {3, 1, 1, 0.5, 2, 0.5};
    const int32_t tr[3] = {7, 8, 9}, te[2] = {8, 9};
    ck_assert_int_eq(amscr_score_nn_split(d, 2, 3, te, tr, &a), AMSCR_OK);
    ck_assert_double_eq_tol(a, 0.5, 1e-15);
    const int32_t te2[2] = {8, 7};
    ck_assert_int_eq(amscr_score_nn_split(d, 2, 3, te2, tr, &a), AMSCR_OK);
    ck_assert_double_eq(a, 1.0);
    ck_assert_int_eq(amscr_score_nn_split(d, 1, 3, te2, tr, &a), AMSCR_OK); /* first row only */
    ck_assert_double_eq(a, 1.0);
    /* The diagonal never counts, even when it is not the smallest. */
    const double m[4] = {5, 1, 1, 5};
    const int32_t l[2] = {1, 2};
    ck_assert_int_eq(amscr_score_nn_accuracy(m, 2, l, &a), AMSCR_OK);
    ck_assert_double_eq(a, 0.0);
}
END_TEST

/* Random matrices with ties against the qsort reference. */
START_TEST(scores_random)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 70 + (uint64_t)_i);
    size_t n = 2 + (size_t)(amscr_test_uniform(&r) * 80);
    int classes = 1 + (int)(amscr_test_uniform(&r) * 8);
    double *d = malloc(n * n * sizeof *d);
    int32_t *lab = malloc(n * sizeof *lab);
    size_t *rank = malloc(n * sizeof *rank);
    size_t kmax = n - 1 < 11 ? n - 1 : 11;
    size_t *cnt = calloc(kmax, sizeof *cnt), *got = malloc(kmax * sizeof *got);
    ck_assert(d && lab && rank && cnt && got);
    for (size_t i = 0; i < n * n; i++)
        d[i] = floor(amscr_test_uniform(&r) * 6);
    for (size_t i = 0; i < n; i++)
        lab[i] = (int32_t)(amscr_test_uniform(&r) * classes) * 1000 - 3000;
    size_t window = _i % 3 == 0 ? 0 : (size_t)(amscr_test_uniform(&r) * (double)n * 1.5);
    double hits = 0, denom = 0;
    size_t nn = 0;
    for (size_t i = 0; i < n; i++) {
        size_t nc = 0;
        for (size_t j = 0; j < n; j++)
            nc += lab[j] == lab[i];
        denom += (double)nc;
        size_t w = window ? window : 2 * nc;
        if (w > n)
            w = n;
        ref_rank(d + i * n, n, SIZE_MAX, rank);
        for (size_t q = 0; q < w; q++)
            hits += lab[rank[q]] == lab[i];
        ref_rank(d + i * n, n, i, rank);
        for (size_t q = 0; q < kmax; q++)
            cnt[q] += lab[rank[q]] == lab[i];
        nn += lab[rank[0]] == lab[i];
    }
    double s;
    ck_assert_int_eq(amscr_score_bullseye(d, n, lab, window, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, hits / denom, 1e-14);
    ck_assert_int_eq(amscr_score_topk_table(d, n, lab, kmax, got), AMSCR_OK);
    ck_assert_int_eq(memcmp(got, cnt, kmax * sizeof *got), 0);
    ck_assert_int_eq(amscr_score_nn_accuracy(d, n, lab, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, (double)nn / (double)n, 1e-14);
    /* The split score on the full square matrix without exclusion = ranking with self. */
    size_t self = 0;
    for (size_t i = 0; i < n; i++) {
        ref_rank(d + i * n, n, SIZE_MAX, rank);
        self += lab[rank[0]] == lab[i];
    }
    ck_assert_int_eq(amscr_score_nn_split(d, n, n, lab, lab, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, (double)self / (double)n, 1e-14);
    free(d);
    free(lab);
    free(rank);
    free(cnt);
    free(got);
}
END_TEST

START_TEST(scores_large)
{
    /* n = 1400 (MPEG-7 size), 70 classes of 20, a matrix that ranks classes perfectly
     * (a size and speed check: one allocation per call, not per query). */
    size_t n = 1400;
    double *d = malloc(n * n * sizeof *d);
    int32_t *lab = malloc(n * sizeof *lab);
    ck_assert(d && lab);
    for (size_t i = 0; i < n; i++)
        lab[i] = (int32_t)(i / 20);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            d[i * n + j] = (i / 20 == j / 20 ? 0.0 : 1.0) + (double)((i * 31 + j * 17) % 97) * 1e-3;
    double s;
    ck_assert_int_eq(amscr_score_bullseye(d, n, lab, 0, &s), AMSCR_OK);
    ck_assert_double_eq_tol(s, 1.0, 1e-15);
    size_t c[11];
    ck_assert_int_eq(amscr_score_topk_table(d, n, lab, 11, c), AMSCR_OK);
    for (int k = 0; k < 11; k++)
        ck_assert_uint_eq(c[k], n);
    ck_assert_int_eq(amscr_score_nn_accuracy(d, n, lab, &s), AMSCR_OK);
    ck_assert_double_eq(s, 1.0);
    free(d);
    free(lab);
}
END_TEST

START_TEST(scores_invalid)
{
    double s = 7.0;
    size_t c[3] = {5, 5, 5};
    ck_assert_int_eq(amscr_score_bullseye(NULL, 6, LA, 0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, NULL, 0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LA, 0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_bullseye(D6, 0, LA, 0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(NULL, 6, LA, 3, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, NULL, 3, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(D6, 6, LA, 3, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(D6, 1, LA, 1, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(NULL, 6, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 6, NULL, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 6, LA, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 1, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(NULL, 2, 3, LA, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, 2, 3, NULL, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, 2, 3, LA, NULL, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, 2, 3, LA, LA, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, 0, 3, LA, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, 2, 0, LA, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(D6, SIZE_MAX / 2, 4, LA, LA, &s), AMSCR_E_INVALID_ARG);
    /* A NaN anywhere (here on the diagonal) is rejected by every score. */
    double dn[36];
    memcpy(dn, D6, sizeof dn);
    dn[4 * 6 + 4] = NAN;
    ck_assert_int_eq(amscr_score_bullseye(dn, 6, LA, 0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(dn, 6, LA, 3, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(dn, 6, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_split(dn, 6, 6, LA, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    dn[4 * 6 + 4] = D6[4 * 6 + 4]; /* and in the very last cell */
    dn[35] = NAN;
    ck_assert_int_eq(amscr_score_bullseye(dn, 6, LA, 0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_topk_table(dn, 6, LA, 3, c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_accuracy(dn, 6, LA, &s), AMSCR_E_INVALID_ARG);
    ck_assert_double_eq(s, 7.0);
    ck_assert(c[0] == 5 && c[1] == 5 && c[2] == 5);
}
END_TEST

/* Which scores params rank by: the retrieval scores as soon as they ask for the shape channel or
 * for re-ranking, the AMSCR distance otherwise; NULL refused, the output untouched. */
START_TEST(ranking_of_params)
{
    amscr_params *p = NULL;
    amscr_ranking r = AMSCR_RANKING_RETRIEVAL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_ranking(p, &r), AMSCR_OK);
    ck_assert_int_eq(r, AMSCR_RANKING_DISTANCE);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 8), AMSCR_OK);
    ck_assert_int_eq(amscr_params_ranking(p, &r), AMSCR_OK);
    ck_assert_int_eq(r, AMSCR_RANKING_RETRIEVAL);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_weight(p, 0.25), AMSCR_OK);
    ck_assert_int_eq(amscr_params_ranking(p, &r), AMSCR_OK);
    ck_assert_int_eq(r, AMSCR_RANKING_RETRIEVAL);
    amscr_params_free(p);
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_ranking(p, &r), AMSCR_OK);
    ck_assert_int_eq(r, AMSCR_RANKING_RETRIEVAL);
    ck_assert_int_eq(amscr_params_set_channel_weight(p, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_ranking(p, &r), AMSCR_OK);
    ck_assert_int_eq(r, AMSCR_RANKING_DISTANCE);
    r = AMSCR_RANKING_RETRIEVAL;
    ck_assert_int_eq(amscr_params_ranking(NULL, &r), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_int_eq(r, AMSCR_RANKING_RETRIEVAL);
    ck_assert_int_eq(amscr_params_ranking(p, NULL), AMSCR_E_INVALID_ARG);
    amscr_params_free(p);
}
END_TEST

Suite *amscr_suite_retrieval(void)
{
    Suite *s = suite_create("retrieval");
    TCase *tc = tcase_create("scores");
    tcase_add_test(tc, topk_hand);
    tcase_add_loop_test(tc, topk_random, 0, 50);
    tcase_add_test(tc, bullseye_hand);
    tcase_add_test(tc, topk_table_hand);
    tcase_add_test(tc, nn_hand);
    tcase_add_loop_test(tc, scores_random, 0, 60);
    tcase_add_test(tc, scores_large);
    tcase_add_test(tc, scores_invalid);
    tcase_add_test(tc, ranking_of_params);
    suite_add_tcase(s, tc);
    return s;
}
