/* check_protocols.c — the evaluation protocols (src/retrieval/protocols.c): the class list,
 * per-class scores, the seeded random split, leave one group out, precision-recall. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"
#include "testutil.h"

/* The 6 x 6 matrix of check_retrieval.c. Orders (distance, index), row by row:
 *   row 0: 0(0) 2(1) 3(1) 5(2) 1(5) 4(9)
 *   row 1: 1(0) 2(3) 3(3) 4(3) 5(4) 0(5)
 *   row 2: 2(0) 0(1) 3(2) 4(2) 5(2) 1(3)
 *   row 3: 3(0) 0(1) 4(1) 2(2) 1(3) 5(7)
 *   row 4: 4(0) 5(0) 3(1) 2(2) 1(3) 0(9)
 *   row 5: 4(0) 5(0) 0(2) 2(2) 1(4) 3(7) */
static const double D6[36] = {
    0, 5, 1, 1, 9, 2, /* */
    5, 0, 3, 3, 3, 4, /* */
    1, 3, 0, 2, 2, 2, /* */
    1, 3, 2, 0, 1, 7, /* */
    9, 3, 2, 1, 0, 0, /* */
    2, 4, 2, 7, 0, 0,
};
static const int32_t LB[6] = {1, 1, 2, 2, 3, 3};

START_TEST(classes_list_and_size_query)
{
    const int32_t l[5] = {5, -1, 5, 3, 5};
    size_t nc = 0, sizes[3];
    int32_t cls[3];
    ck_assert_int_eq(amscr_score_classes(l, 5, NULL, NULL, &nc), AMSCR_OK);
    ck_assert_uint_eq(nc, 3);
    ck_assert_int_eq(amscr_score_classes(l, 5, cls, sizes, &nc), AMSCR_OK);
    ck_assert(cls[0] == -1 && cls[1] == 3 && cls[2] == 5);
    ck_assert(sizes[0] == 1 && sizes[1] == 1 && sizes[2] == 3);
    nc = 2; /* too small */
    ck_assert_int_eq(amscr_score_classes(l, 5, cls, NULL, &nc), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "capacity") != NULL);
    ck_assert_uint_eq(nc, 2);
    ck_assert_int_eq(amscr_score_classes(l, 0, NULL, NULL, &nc), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_classes(NULL, 5, NULL, NULL, &nc), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_classes(l, 5, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
}
END_TEST

/* LB on D6 (classes 1 = {0, 1}, 2 = {2, 3}, 3 = {4, 5}, windows 4):
 *   bull's eye hits: row 0 {0,2,3,5} 1, row 1 {1,2,3,4} 1 -> 2/4; rows 2, 3 two each -> 4/4;
 *   rows 4, 5 two each -> 4/4. 1-NN: 0->2, 1->2, 2->0, 3->0 wrong, 4->5, 5->4 right. */
START_TEST(per_class_hand)
{
    double be[3], nn[3], whole;
    ck_assert_int_eq(amscr_score_per_class(D6, 6, LB, 3, be, nn), AMSCR_OK);
    ck_assert_double_eq(be[0], 0.5);
    ck_assert_double_eq(be[1], 1.0);
    ck_assert_double_eq(be[2], 1.0);
    ck_assert_double_eq(nn[0], 0.0);
    ck_assert_double_eq(nn[1], 0.0);
    ck_assert_double_eq(nn[2], 1.0);
    /* weighted back, they are the whole-matrix scores */
    ck_assert_int_eq(amscr_score_bullseye(D6, 6, LB, 0, &whole), AMSCR_OK);
    ck_assert_double_eq_tol(whole, (be[0] * 4 + be[1] * 4 + be[2] * 4) / 12.0, 1e-15);
    ck_assert_int_eq(amscr_score_nn_accuracy(D6, 6, LB, &whole), AMSCR_OK);
    ck_assert_double_eq_tol(whole, (nn[0] * 2 + nn[1] * 2 + nn[2] * 2) / 6.0, 1e-15);
    /* one output alone gives the same values */
    double nn2[3] = {7, 7, 7};
    ck_assert_int_eq(amscr_score_per_class(D6, 6, LB, 3, NULL, nn2), AMSCR_OK);
    ck_assert(memcmp(nn, nn2, sizeof nn) == 0);
}
END_TEST

/* Random matrices: the per-class scores weigh back to amscr_score_bullseye and
 * amscr_score_nn_accuracy. */
START_TEST(per_class_random)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 900 + (uint64_t)_i);
    size_t n = 5 + (size_t)(amscr_test_rng_next(&r) % 30), k = 1 + (size_t)(amscr_test_rng_next(&r) % 5);
    double *d = malloc(n * n * sizeof *d), be[5], nn[5], whole;
    int32_t *l = malloc(n * sizeof *l), cls[5];
    size_t sizes[5], nc = 5;
    for (size_t i = 0; i < n * n; i++)
        d[i] = floor(4 * amscr_test_uniform(&r)); /* many ties */
    for (size_t i = 0; i < n; i++)
        l[i] = (int32_t)(amscr_test_rng_next(&r) % k) * 10 - 7;
    ck_assert_int_eq(amscr_score_classes(l, n, cls, sizes, &nc), AMSCR_OK);
    ck_assert_int_eq(amscr_score_per_class(d, n, l, nc, be, nn), AMSCR_OK);
    double hb = 0, wb = 0, hn = 0;
    for (size_t c = 0; c < nc; c++) {
        double s = (double)sizes[c];
        hb += be[c] * s * s;
        wb += s * s; /* each of the Nc queries adds Nc to the denominator */
        hn += nn[c] * s;
    }
    ck_assert_int_eq(amscr_score_bullseye(d, n, l, 0, &whole), AMSCR_OK);
    ck_assert_double_eq_tol(whole, hb / wb, 1e-12);
    ck_assert_int_eq(amscr_score_nn_accuracy(d, n, l, &whole), AMSCR_OK);
    ck_assert_double_eq_tol(whole, hn / (double)n, 1e-12);
    free(d);
    free(l);
}
END_TEST

/* Two classes of 3; train 1. splitmix64 from seed 0 gives ...cdaf, ...65f4, ...454f, ...81ec,
 * mod 3: 1, 0, 1, 1. Split 1 trains {1, 3} (tests 0 x, 2 ok, 4 x, 5 ok: 0.5, classes 1/2, 1/2);
 * split 2 trains {1, 4} (tests 0 ok, 2 ok, 3 ok, 5 x: 0.75, classes 1, 1/2). */
static const double DS[36] = {
    0, 5, 8, 1, 9, 8, /* */
    8, 0, 8, 8, 8, 8, /* */
    8, 1, 0, 5, 5, 8, /* */
    8, 2, 8, 0, 1, 8, /* */
    8, 1, 8, 2, 0, 8, /* */
    8, 3, 8, 2, 4, 0,
};

START_TEST(split_hand)
{
    const int32_t l[6] = {0, 0, 0, 1, 1, 1}, l2[6] = {5, 5, 5, 9, 9, 9};
    double mean, sd, acc[2], cls[2];
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 1, 2, 0, 2, &mean, &sd, acc, cls), AMSCR_OK);
    ck_assert_double_eq(acc[0], 0.5);
    ck_assert_double_eq(acc[1], 0.75);
    ck_assert_double_eq(mean, 0.625);
    ck_assert_double_eq_tol(sd, sqrt(0.03125), 1e-15);
    ck_assert_double_eq(cls[0], 0.75);
    ck_assert_double_eq(cls[1], 0.5);
    /* only the order of the labels counts, not their values */
    double mean2, acc2[2], cls2[2];
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l2, 1, 2, 0, 2, &mean2, NULL, acc2, cls2), AMSCR_OK);
    ck_assert(mean2 == mean && memcmp(acc, acc2, sizeof acc) == 0 && memcmp(cls, cls2, sizeof cls) == 0);
    /* one split: std 0; the mean alone */
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 1, 1, 0, 0, &mean, &sd, NULL, NULL), AMSCR_OK);
    ck_assert_double_eq(mean, 0.5);
    ck_assert_double_eq(sd, 0.0);
}
END_TEST

/* A 40 x 40 random matrix, 4 classes of 10. */
static void random_problem(uint64_t seed, double *d, int32_t *l)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, seed);
    for (size_t i = 0; i < 40; i++) {
        l[i] = (int32_t)(i % 4);
        for (size_t j = 0; j < 40; j++)
            d[i * 40 + j] = i == j ? 0.0 : amscr_test_uniform(&r) + (i % 4 == j % 4 ? 0.0 : 0.4);
    }
}

START_TEST(split_deterministic)
{
    double d[1600], acc1[8], acc2[8], acc3[8], m1, m2, m3, one;
    int32_t l[40];
    random_problem(5, d, l);
    ck_assert_int_eq(amscr_score_nn_random_split(d, 40, l, 3, 8, 42, 0, &m1, NULL, acc1, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_score_nn_random_split(d, 40, l, 3, 8, 42, 0, &m2, NULL, acc2, NULL), AMSCR_OK);
    ck_assert(m1 == m2 && memcmp(acc1, acc2, sizeof acc1) == 0);
    ck_assert_int_eq(amscr_score_nn_random_split(d, 40, l, 3, 8, 43, 0, &m3, NULL, acc3, NULL), AMSCR_OK);
    ck_assert(memcmp(acc1, acc3, sizeof acc1) != 0);
    /* the generator runs on over the splits: the first split alone is split 1 of eight */
    ck_assert_int_eq(amscr_score_nn_random_split(d, 40, l, 3, 1, 42, 0, &one, NULL, NULL, NULL), AMSCR_OK);
    ck_assert_double_eq(one, acc1[0]);
    /* the largest training set: one test shape per class */
    ck_assert_int_eq(amscr_score_nn_random_split(d, 40, l, 9, 3, 1, 0, &m1, NULL, acc1, NULL), AMSCR_OK);
    for (int r = 0; r < 3; r++)
        ck_assert(acc1[r] == 0.0 || acc1[r] == 0.25 || acc1[r] == 0.5 || acc1[r] == 0.75 || acc1[r] == 1.0);
}
END_TEST

/* Groups: 10 = {0, 2}, 20 = {1, 3}; classes 0 = {0, 1}, 1 = {2, 3}. Every shape's nearest is
 * in its own group and never counts: 0 -> 1 ok, 1 -> 0 ok, 2 -> 3 ok, 3 -> 0 x (a tie with 2,
 * to the lower index). Leave-one-out 1-NN, groups ignored, gets all four wrong. */
static const double DG[16] = {
    0, 1, 0.1, 2, /* */
    1, 0, 2, 0.1, /* */
    0.1, 2, 0, 1, /* */
    0.5, 0.1, 0.5, 0,
};

START_TEST(groups_hand)
{
    const int32_t l[4] = {0, 0, 1, 1}, g[4] = {10, 20, 10, 20};
    double acc, ga[2], ca[2];
    ck_assert_int_eq(amscr_score_nn_groups(DG, 4, l, g, 2, 2, &acc, ga, ca), AMSCR_OK);
    ck_assert_double_eq(acc, 0.75);
    ck_assert_double_eq(ga[0], 1.0);
    ck_assert_double_eq(ga[1], 0.5);
    ck_assert_double_eq(ca[0], 1.0);
    ck_assert_double_eq(ca[1], 0.5);
    /* every shape its own group: leave-one-out 1-NN */
    const int32_t own[4] = {3, 2, 1, 0};
    double loo;
    ck_assert_int_eq(amscr_score_nn_groups(DG, 4, l, own, 0, 0, &acc, NULL, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_score_nn_accuracy(DG, 4, l, &loo), AMSCR_OK);
    ck_assert_double_eq(acc, loo);
    ck_assert_double_eq(acc, 0.0);
}
END_TEST

/* Precision-recall, 5 shapes, classes {0, 1, 2} and {3, 4}, 3 levels (recall 0, 0.5, 1).
 * Orders (query excluded): 0: 1 3 2 4 -> hits at 1, 3 -> 1, 1, 2/3; 1: 3 4 0 2 -> hits at 3, 4
 * -> 1/2 (best of 1/3 and 2/4) at every level; 2: 0 1 3 4 -> 1, 1, 1; 3: 4 ... -> 1, 1, 1;
 * 4: 0 1 2 3 -> 1/4. Means: 0.75, 0.75, (2/3 + 1/2 + 1 + 1 + 1/4) / 5. */
static const double DP[25] = {
    0, 1, 3, 2, 4, /* */
    3, 0, 4, 1, 2, /* */
    1, 2, 0, 3, 4, /* */
    2, 3, 4, 0, 1, /* */
    1, 2, 3, 4, 0,
};

START_TEST(precision_recall_hand)
{
    const int32_t l[5] = {0, 0, 0, 1, 1};
    double p[3];
    ck_assert_int_eq(amscr_score_precision_recall(DP, 5, l, 3, p), AMSCR_OK);
    ck_assert_double_eq_tol(p[0], 0.75, 1e-15);
    ck_assert_double_eq_tol(p[1], 0.75, 1e-15);
    ck_assert_double_eq_tol(p[2], (2.0 / 3 + 0.5 + 1 + 1 + 0.25) / 5, 1e-15);
    /* every class a singleton: no query has a relevant shape */
    const int32_t single[5] = {0, 1, 2, 3, 4};
    ck_assert_int_eq(amscr_score_precision_recall(DP, 5, single, 3, p), AMSCR_OK);
    ck_assert(isnan(p[0]) && isnan(p[2]));
    /* a perfect ranking has precision 1 at every level */
    const int32_t two[4] = {0, 0, 1, 1};
    const double dd[16] = {0, 1, 5, 5, 1, 0, 5, 5, 5, 5, 0, 1, 5, 5, 1, 0};
    double q[21];
    ck_assert_int_eq(amscr_score_precision_recall(dd, 4, two, 21, q), AMSCR_OK);
    for (int i = 0; i < 21; i++)
        ck_assert_double_eq(q[i], 1.0);
}
END_TEST

START_TEST(protocols_invalid)
{
    const int32_t l[6] = {0, 0, 0, 1, 1, 1}, g[6] = {0, 1, 2, 0, 1, 2}, g1[6] = {4, 4, 4, 4, 4, 4};
    double x = 7.0, v[6] = {7, 7, 7, 7, 7, 7}, d[36];
    /* NULL and sizes */
    ck_assert_int_eq(amscr_score_per_class(NULL, 6, l, 2, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_per_class(DS, 6, NULL, 2, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_per_class(DS, 6, l, 2, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_per_class(DS, 0, l, 2, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_per_class(DS, 1, l, 1, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_per_class(DS, 6, l, 3, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "nclasses = 3") != NULL);
    ck_assert_int_eq(amscr_score_per_class(DS, SIZE_MAX / 4, l, 2, v, NULL), AMSCR_E_INVALID_ARG);
    /* split: train too large for a class, zero train or splits, wrong nclasses */
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 3, 2, 0, 0, &x, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "class 0 (3 shapes)") != NULL);
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 0, 2, 0, 0, &x, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 1, 0, 0, 0, &x, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 1, 2, 0, 1, &x, NULL, NULL, v), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_random_split(DS, 6, l, 1, 2, 0, 2, NULL, NULL, NULL, v), AMSCR_E_INVALID_ARG);
    /* groups: NULL groups, one group, wrong counts */
    ck_assert_int_eq(amscr_score_nn_groups(DS, 6, l, NULL, 0, 0, &x, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_groups(DS, 6, l, g1, 0, 0, &x, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "at least 2 groups") != NULL);
    ck_assert_int_eq(amscr_score_nn_groups(DS, 6, l, g, 2, 2, &x, v, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_groups(DS, 6, l, g, 3, 3, &x, v, v), AMSCR_E_INVALID_ARG);
    /* precision-recall: levels */
    ck_assert_int_eq(amscr_score_precision_recall(DS, 6, l, 1, v), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_precision_recall(DS, 6, l, 2, NULL), AMSCR_E_INVALID_ARG);
    /* NaN and -inf anywhere are refused by every protocol; +inf is a distance */
    memcpy(d, DS, sizeof d);
    d[2 * 6 + 5] = NAN;
    ck_assert_int_eq(amscr_score_per_class(d, 6, l, 2, v, v), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "[2][5] is NaN") != NULL);
    ck_assert_int_eq(amscr_score_nn_random_split(d, 6, l, 1, 2, 0, 0, &x, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_nn_groups(d, 6, l, g, 0, 0, &x, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_score_precision_recall(d, 6, l, 3, v), AMSCR_E_INVALID_ARG);
    d[2 * 6 + 5] = -INFINITY;
    ck_assert_int_eq(amscr_score_precision_recall(d, 6, l, 3, v), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "-inf") != NULL);
    /* outputs untouched on failure */
    ck_assert_double_eq(x, 7.0);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq(v[i], 7.0);
    d[2 * 6 + 5] = INFINITY;
    ck_assert_int_eq(amscr_score_nn_groups(d, 6, l, g, 0, 0, &x, NULL, NULL), AMSCR_OK);
    ck_assert_str_eq(amscr_last_error_detail(), "");
}
END_TEST

Suite *amscr_suite_protocols(void)
{
    Suite *s = suite_create("protocols");
    TCase *tc = tcase_create("protocols");
    tcase_add_test(tc, classes_list_and_size_query);
    tcase_add_test(tc, per_class_hand);
    tcase_add_loop_test(tc, per_class_random, 0, 40);
    tcase_add_test(tc, split_hand);
    tcase_add_test(tc, split_deterministic);
    tcase_add_test(tc, groups_hand);
    tcase_add_test(tc, precision_recall_hand);
    tcase_add_test(tc, protocols_invalid);
    suite_add_tcase(s, tc);
    return s;
}
