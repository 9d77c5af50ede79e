/* check_fenv.c — the library under a caller's floating-point environment: with the invalid and
 * divide-by-zero traps enabled (feenableexcept, as robotics code does to catch its own NaNs),
 * registration, retrieval and tracing finish without SIGFPE (a NaN that marks "not computed"
 * is compared quietly), and the traps are still on afterwards. */
#define _GNU_SOURCE /* feenableexcept (glibc) */
#include <amscr.h>
#include <check.h>
#include <fenv.h>
#include <math.h>
#include <stdlib.h>

#include "suites.h"
#include "testutil.h"

enum { N = 240, SHAPES = 10 };

/* Shape k of the set: random shapes of rising complexity, an ellipse (2-fold symmetric), a star. */
static amscr_contour *shape(int k, double *xy)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 900u + (uint64_t)k);
    if (k == 0)
        amscr_test_ellipse(N, 60, 30, 0.0, xy);
    else if (k == 1) {
        double v[20];
        amscr_test_star5(v);
        amscr_test_polygon(v, 10, N / 10, xy);
    } else
        amscr_test_random_shape(&r, N, 4 + k % 5, xy);
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, N, &c), AMSCR_OK);
    return c;
}

/* Registers shape k onto a random affine image of itself, noisy for odd k, closed or open. */
static void register_pair(const amscr_params *p, int k)
{
    double xy[2 * N], warped[2 * N], m6[6];
    amscr_contour *a = shape(k, xy), *b = NULL;
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 77u + (uint64_t)k);
    amscr_test_random_affine(&r, 1.6, 0.4, 20.0, 0, m6);
    amscr_test_apply_affine(m6, xy, N, warped);
    if (k % 2)
        amscr_test_add_noise(&r, warped, N, 0.5);
    ck_assert_int_eq(amscr_contour_new(warped, N, &b), AMSCR_OK);
    amscr_result *res = NULL;
    ck_assert_int_eq(amscr_register_contours(p, a, b, &res), AMSCR_OK);
    ck_assert(isfinite(amscr_result_distance(res)));
    (void)amscr_result_confidence(res);
    amscr_result_free(res);
    amscr_contour_free(a);
    amscr_contour_free(b);
}

START_TEST(traps_on_invalid_and_divide_by_zero)
{
#if defined(__GLIBC__)
    ck_assert_int_ne(feenableexcept(FE_INVALID | FE_DIVBYZERO), -1);
    ck_assert_int_eq(fegetexcept() & (FE_INVALID | FE_DIVBYZERO), FE_INVALID | FE_DIVBYZERO); /* (not valgrind) */
    amscr_params *reg = NULL, *open = NULL, *ret = NULL;
    ck_assert_int_eq(amscr_params_new_registration(&reg), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new(&open), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_closed(open, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_retrieval(&ret), AMSCR_OK);
    for (int k = 0; k < SHAPES; k++) {
        register_pair(reg, k);
        register_pair(NULL, k);
        register_pair(open, k);
    }
    amscr_contour *cs[SHAPES];
    double xy[2 * N];
    for (int k = 0; k < SHAPES; k++)
        cs[k] = shape(k, xy);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(ret, &db), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_contours(db, (const amscr_contour *const *)cs, NULL, SHAPES, NULL, NULL, NULL),
                     AMSCR_OK);
    double d[SHAPES * SHAPES], scores[SHAPES];
    ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, d), AMSCR_OK);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    amscr_descriptor *q = NULL;
    ck_assert_int_eq(amscr_descriptor_new(ret, cs[3], &q), AMSCR_OK);
    ck_assert_int_eq(amscr_index_search_scores(x, q, 0, scores, SHAPES), AMSCR_OK);
    unsigned char img[64 * 64];
    for (int y = 0; y < 64; y++)
        for (int i = 0; i < 64; i++)
            img[y * 64 + i] = (unsigned char)((i - 30.3) * (i - 30.3) / 400 + (y - 33.1) * (y - 33.1) / 225 < 1 ? 220 : 15);
    amscr_contour *traced = NULL;
    ck_assert_int_eq(amscr_contour_from_image(img, 64, 64, 64, 8, -1, 0, &traced), AMSCR_OK);
    ck_assert_int_eq(fegetexcept() & (FE_INVALID | FE_DIVBYZERO), FE_INVALID | FE_DIVBYZERO);
    fedisableexcept(FE_ALL_EXCEPT);
    amscr_contour_free(traced);
    amscr_descriptor_free(q);
    amscr_index_free(x);
    amscr_db_free(db);
    for (int k = 0; k < SHAPES; k++)
        amscr_contour_free(cs[k]);
    amscr_params_free(reg);
    amscr_params_free(open);
    amscr_params_free(ret);
#else
    printf("SKIP: fenv: feenableexcept is glibc's\n");
#endif
}
END_TEST

Suite *amscr_suite_fenv(void)
{
    Suite *s = suite_create("fenv");
    TCase *tc = tcase_create("traps");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, traps_on_invalid_and_divide_by_zero);
    suite_add_tcase(s, tc);
    return s;
}
