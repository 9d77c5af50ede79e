/* check_params.c — registration parameters: defaults, range checks, getters, deep copy, NULL. */
#include <amscr.h>
#include <check.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"

static amscr_params *p;

static void setup(void)
{
    p = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_ptr_nonnull(p);
}

static void teardown(void)
{
    amscr_params_free(p);
    p = NULL;
}

#define EXPECT_INVALID(call)                                                                                 \
    do {                                                                                                     \
        ck_assert_int_eq((call), AMSCR_E_INVALID_ARG);                                                       \
        ck_assert_msg(amscr_last_error_detail()[0] != '\0', "no detail after %s", #call);                   \
    } while (0)

START_TEST(test_defaults)
{
    ck_assert_uint_eq(amscr_params_get_num_samples(p), 128);
    ck_assert_int_eq(amscr_params_get_method(p), AMSCR_METHOD_MULTICLASS_EM);
    ck_assert_int_eq(amscr_params_get_closed(p), 1);
    ck_assert_int_eq(amscr_params_get_reflections(p), 0);
    ck_assert_int_eq(amscr_params_get_parametrization(p), AMSCR_PARAM_WHITENED);
    ck_assert_uint_eq(amscr_params_get_oversampling(p), 8);
    ck_assert_uint_eq(amscr_params_get_kmax(p), 5);
    ck_assert_int_eq(amscr_params_get_symmetric(p), 0);
    ck_assert_uint_le(amscr_params_get_refine(p), 50);
    ck_assert_uint_eq(amscr_params_get_num_threads(p), 0);
    ck_assert_int_eq(amscr_params_get_invariance(p), AMSCR_INVARIANCE_AFFINE);
    ck_assert_double_eq(amscr_params_get_penalty(p), 0.5);
    double ps = amscr_params_get_presmooth(p);
    ck_assert(ps >= 0.0 && ps <= 0.25);
    unsigned passes = amscr_params_get_arclength_passes(p);
    ck_assert_uint_ge(passes, 1);
    ck_assert_uint_le(passes, 10);
    /* Default scales satisfy their own documented constraints. */
    size_t ns = 0;
    ck_assert_int_eq(amscr_params_get_scales(p, NULL, &ns), AMSCR_OK);
    ck_assert_uint_ge(ns, 1);
    ck_assert_uint_le(ns, AMSCR_MAX_SCALES);
    double sig[AMSCR_MAX_SCALES];
    size_t cap = AMSCR_MAX_SCALES;
    ck_assert_int_eq(amscr_params_get_scales(p, sig, &cap), AMSCR_OK);
    ck_assert_uint_eq(cap, ns);
    for (size_t k = 0; k < ns; k++)
        ck_assert(isfinite(sig[k]) && sig[k] >= 0.0 && sig[k] <= 128.0);
}
END_TEST

START_TEST(test_num_samples)
{
    ck_assert_int_eq(amscr_params_set_num_samples(p, 16), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_samples(p), 16);
    ck_assert_int_eq(amscr_params_set_num_samples(p, AMSCR_MAX_SAMPLES), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_samples(p), AMSCR_MAX_SAMPLES);
    ck_assert_int_eq(amscr_params_set_num_samples(p, 200), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_num_samples(p, 15));
    EXPECT_INVALID(amscr_params_set_num_samples(p, 0));
    EXPECT_INVALID(amscr_params_set_num_samples(p, (size_t)AMSCR_MAX_SAMPLES + 1));
    EXPECT_INVALID(amscr_params_set_num_samples(p, SIZE_MAX));
    ck_assert_uint_eq(amscr_params_get_num_samples(p), 200);
}
END_TEST

static void get_all_scales(const amscr_params *q, double *out, size_t *n)
{
    size_t cap = AMSCR_MAX_SCALES;
    ck_assert_int_eq(amscr_params_get_scales(q, out, &cap), AMSCR_OK);
    *n = cap;
}

START_TEST(test_scales)
{
    const double s4[4] = {4.0, 0.0, 2.5, 1.0}; /* stored as given: order kept */
    ck_assert_int_eq(amscr_params_set_scales(p, s4, 4), AMSCR_OK);
    size_t n = 99;
    ck_assert_int_eq(amscr_params_get_scales(p, NULL, &n), AMSCR_OK); /* size query */
    ck_assert_uint_eq(n, 4);
    double got[AMSCR_MAX_SCALES];
    get_all_scales(p, got, &n);
    ck_assert_uint_eq(n, 4);
    for (size_t k = 0; k < 4; k++)
        ck_assert_double_eq(got[k], s4[k]);
    /* Exact capacity works; a too-small one does not. */
    n = 4;
    ck_assert_int_eq(amscr_params_get_scales(p, got, &n), AMSCR_OK);
    n = 3;
    EXPECT_INVALID(amscr_params_get_scales(p, got, &n));
    EXPECT_INVALID(amscr_params_get_scales(p, got, NULL));
    EXPECT_INVALID(amscr_params_get_scales(p, NULL, NULL));

    /* Limits: 1..AMSCR_MAX_SCALES values, finite, >= 0, <= N (N = 128 by default). */
    double many[AMSCR_MAX_SCALES + 1];
    for (size_t k = 0; k <= AMSCR_MAX_SCALES; k++)
        many[k] = (double)k * 0.5;
    ck_assert_int_eq(amscr_params_set_scales(p, many, AMSCR_MAX_SCALES), AMSCR_OK);
    get_all_scales(p, got, &n);
    ck_assert_uint_eq(n, AMSCR_MAX_SCALES);
    ck_assert_double_eq(got[AMSCR_MAX_SCALES - 1], (AMSCR_MAX_SCALES - 1) * 0.5);
    const double one[1] = {128.0};
    ck_assert_int_eq(amscr_params_set_scales(p, one, 1), AMSCR_OK); /* sigma == N is allowed */

    ck_assert_int_eq(amscr_params_set_scales(p, s4, 4), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_scales(p, many, AMSCR_MAX_SCALES + 1));
    EXPECT_INVALID(amscr_params_set_scales(p, many, 0));
    EXPECT_INVALID(amscr_params_set_scales(p, NULL, 3));
    const double with_nan[3] = {1.0, NAN, 2.0};
    EXPECT_INVALID(amscr_params_set_scales(p, with_nan, 3));
    const double with_inf[2] = {1.0, INFINITY};
    EXPECT_INVALID(amscr_params_set_scales(p, with_inf, 2));
    const double with_neg[3] = {1.0, 2.0, -0.5};
    EXPECT_INVALID(amscr_params_set_scales(p, with_neg, 3));
    const double too_big[2] = {1.0, 128.5};
    EXPECT_INVALID(amscr_params_set_scales(p, too_big, 2));
    /* The old list is intact after every rejected call. */
    get_all_scales(p, got, &n);
    ck_assert_uint_eq(n, 4);
    for (size_t k = 0; k < 4; k++)
        ck_assert_double_eq(got[k], s4[k]);
}
END_TEST

START_TEST(test_scales_bound_follows_num_samples)
{
    /* "<= N": with N = 300 a scale of 200 is fine. */
    ck_assert_int_eq(amscr_params_set_num_samples(p, 300), AMSCR_OK);
    const double s[2] = {1.0, 200.0};
    ck_assert_int_eq(amscr_params_set_scales(p, s, 2), AMSCR_OK);
    const double s2[2] = {1.0, 300.5};
    EXPECT_INVALID(amscr_params_set_scales(p, s2, 2));
    /* N lowered below a scale set before: preparing a shape refuses the params, saying why */
    const double s3[2] = {1.0, 64.0};
    ck_assert_int_eq(amscr_params_set_num_samples(p, 64), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_scales(p, s3, 2), AMSCR_OK);
    double xy[2 * 40];
    for (int i = 0; i < 40; i++) {
        xy[2 * i] = 2.0 * cos(0.157 * i);
        xy[2 * i + 1] = sin(0.157 * i) + 0.3 * cos(0.471 * i);
    }
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, 40, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(p, 63), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "scale 64 exceeds N = 63"));
    ck_assert_ptr_null(d);
    amscr_contour_free(c);
}
END_TEST

START_TEST(test_enums)
{
    const amscr_method methods[] = {AMSCR_METHOD_ACMA, AMSCR_METHOD_AMSCR, AMSCR_METHOD_BINARY_EM,
                                    AMSCR_METHOD_MULTICLASS_EM};
    for (int k = 0; k < 4; k++) {
        ck_assert_int_eq(amscr_params_set_method(p, methods[k]), AMSCR_OK);
        ck_assert_int_eq(amscr_params_get_method(p), methods[k]);
    }
    ck_assert_int_eq(amscr_params_set_method(p, AMSCR_METHOD_BINARY_EM), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_method(p, (amscr_method)99));
    EXPECT_INVALID(amscr_params_set_method(p, (amscr_method)4));
    EXPECT_INVALID(amscr_params_set_method(p, (amscr_method)-1));
    ck_assert_int_eq(amscr_params_get_method(p), AMSCR_METHOD_BINARY_EM);

    const amscr_parametrization pars[] = {AMSCR_PARAM_AFFINE, AMSCR_PARAM_EUCLIDEAN, AMSCR_PARAM_WHITENED};
    for (int k = 0; k < 3; k++) {
        ck_assert_int_eq(amscr_params_set_parametrization(p, pars[k]), AMSCR_OK);
        ck_assert_int_eq(amscr_params_get_parametrization(p), pars[k]);
    }
    EXPECT_INVALID(amscr_params_set_parametrization(p, (amscr_parametrization)3));
    EXPECT_INVALID(amscr_params_set_parametrization(p, (amscr_parametrization)-1));
    ck_assert_int_eq(amscr_params_get_parametrization(p), AMSCR_PARAM_WHITENED);

    const amscr_invariance invs[] = {AMSCR_INVARIANCE_AFFINE, AMSCR_INVARIANCE_SIMILARITY,
                                     AMSCR_INVARIANCE_PENALIZED};
    for (int k = 0; k < 3; k++) {
        ck_assert_int_eq(amscr_params_set_invariance(p, invs[k]), AMSCR_OK);
        ck_assert_int_eq(amscr_params_get_invariance(p), invs[k]);
    }
    EXPECT_INVALID(amscr_params_set_invariance(p, (amscr_invariance)3));
    EXPECT_INVALID(amscr_params_set_invariance(p, (amscr_invariance)-1));
    ck_assert_int_eq(amscr_params_get_invariance(p), AMSCR_INVARIANCE_PENALIZED);
}
END_TEST

START_TEST(test_flags)
{
    ck_assert_int_eq(amscr_params_set_closed(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_closed(p), 0);
    ck_assert_int_eq(amscr_params_set_closed(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_closed(p), 1);
    ck_assert_int_eq(amscr_params_set_reflections(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_reflections(p), 1);
    ck_assert_int_eq(amscr_params_set_reflections(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_reflections(p), 0);
    ck_assert_int_eq(amscr_params_set_symmetric(p, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_symmetric(p), 1);
    ck_assert_int_eq(amscr_params_set_symmetric(p, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_symmetric(p), 0);
}
END_TEST

START_TEST(test_presmooth)
{
    ck_assert_int_eq(amscr_params_set_presmooth(p, 0.0), AMSCR_OK);
    ck_assert_double_eq(amscr_params_get_presmooth(p), 0.0);
    ck_assert_int_eq(amscr_params_set_presmooth(p, 0.25), AMSCR_OK);
    ck_assert_double_eq(amscr_params_get_presmooth(p), 0.25);
    ck_assert_int_eq(amscr_params_set_presmooth(p, 0.0375), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_presmooth(p, 0.3));
    EXPECT_INVALID(amscr_params_set_presmooth(p, 0.2500001));
    EXPECT_INVALID(amscr_params_set_presmooth(p, -0.01));
    EXPECT_INVALID(amscr_params_set_presmooth(p, NAN));
    EXPECT_INVALID(amscr_params_set_presmooth(p, INFINITY));
    ck_assert_double_eq(amscr_params_get_presmooth(p), 0.0375);
}
END_TEST

START_TEST(test_unsigned_ranges)
{
    /* passes 1..10 */
    ck_assert_int_eq(amscr_params_set_arclength_passes(p, 1), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_arclength_passes(p), 1);
    ck_assert_int_eq(amscr_params_set_arclength_passes(p, 10), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_arclength_passes(p), 10);
    ck_assert_int_eq(amscr_params_set_arclength_passes(p, 3), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_arclength_passes(p, 0));
    EXPECT_INVALID(amscr_params_set_arclength_passes(p, 11));
    ck_assert_uint_eq(amscr_params_get_arclength_passes(p), 3);

    /* oversampling 1..64 */
    ck_assert_int_eq(amscr_params_set_oversampling(p, 1), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_oversampling(p), 1);
    ck_assert_int_eq(amscr_params_set_oversampling(p, 64), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_oversampling(p), 64);
    ck_assert_int_eq(amscr_params_set_oversampling(p, 12), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_oversampling(p, 0));
    EXPECT_INVALID(amscr_params_set_oversampling(p, 65));
    ck_assert_uint_eq(amscr_params_get_oversampling(p), 12);

    /* kmax 1..16 */
    ck_assert_int_eq(amscr_params_set_kmax(p, 1), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_kmax(p), 1);
    ck_assert_int_eq(amscr_params_set_kmax(p, 16), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_kmax(p), 16);
    ck_assert_int_eq(amscr_params_set_kmax(p, 7), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_kmax(p, 0));
    EXPECT_INVALID(amscr_params_set_kmax(p, 17));
    ck_assert_uint_eq(amscr_params_get_kmax(p), 7);

    /* refine 0..50 */
    ck_assert_int_eq(amscr_params_set_refine(p, 0), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_refine(p), 0);
    ck_assert_int_eq(amscr_params_set_refine(p, 50), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_refine(p), 50);
    ck_assert_int_eq(amscr_params_set_refine(p, 4), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_refine(p, 51));
    EXPECT_INVALID(amscr_params_set_refine(p, 4000000000u));
    ck_assert_uint_eq(amscr_params_get_refine(p), 4);

    /* threads 0 (all cores) or 1..1024 */
    ck_assert_int_eq(amscr_params_set_num_threads(p, 1), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_threads(p), 1);
    ck_assert_int_eq(amscr_params_set_num_threads(p, 1024), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_threads(p), 1024);
    ck_assert_int_eq(amscr_params_set_num_threads(p, 0), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_threads(p), 0);
    ck_assert_int_eq(amscr_params_set_num_threads(p, 6), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_num_threads(p, 1025));
    EXPECT_INVALID(amscr_params_set_num_threads(p, 0xffffffffu));
    ck_assert_uint_eq(amscr_params_get_num_threads(p), 6);
}
END_TEST

START_TEST(test_penalty)
{
    ck_assert_int_eq(amscr_params_set_penalty(p, 0.0), AMSCR_OK);
    ck_assert_double_eq(amscr_params_get_penalty(p), 0.0);
    ck_assert_int_eq(amscr_params_set_penalty(p, 1e6), AMSCR_OK);
    ck_assert_double_eq(amscr_params_get_penalty(p), 1e6);
    ck_assert_int_eq(amscr_params_set_penalty(p, 2.25), AMSCR_OK);
    EXPECT_INVALID(amscr_params_set_penalty(p, -1.0));
    EXPECT_INVALID(amscr_params_set_penalty(p, -1e-300));
    EXPECT_INVALID(amscr_params_set_penalty(p, NAN));
    ck_assert_double_eq(amscr_params_get_penalty(p), 2.25);
}
END_TEST

/* Sets every field to a non-default value. */
static void set_all(amscr_params *q)
{
    const double s[3] = {0.0, 3.0, 1.5};
    ck_assert_int_eq(amscr_params_set_num_samples(q, 256), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_scales(q, s, 3), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_method(q, AMSCR_METHOD_AMSCR), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_closed(q, 0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_reflections(q, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_parametrization(q, AMSCR_PARAM_EUCLIDEAN), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_presmooth(q, 0.125), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_arclength_passes(q, 7), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_oversampling(q, 3), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_kmax(q, 9), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_symmetric(q, 1), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_refine(q, 11), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(q, 5), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_invariance(q, AMSCR_INVARIANCE_SIMILARITY), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_penalty(q, 3.5), AMSCR_OK);
}

static void assert_all_set(const amscr_params *q)
{
    ck_assert_uint_eq(amscr_params_get_num_samples(q), 256);
    double s[AMSCR_MAX_SCALES];
    size_t n;
    get_all_scales(q, s, &n);
    ck_assert_uint_eq(n, 3);
    ck_assert_double_eq(s[0], 0.0);
    ck_assert_double_eq(s[1], 3.0);
    ck_assert_double_eq(s[2], 1.5);
    ck_assert_int_eq(amscr_params_get_method(q), AMSCR_METHOD_AMSCR);
    ck_assert_int_eq(amscr_params_get_closed(q), 0);
    ck_assert_int_eq(amscr_params_get_reflections(q), 1);
    ck_assert_int_eq(amscr_params_get_parametrization(q), AMSCR_PARAM_EUCLIDEAN);
    ck_assert_double_eq(amscr_params_get_presmooth(q), 0.125);
    ck_assert_uint_eq(amscr_params_get_arclength_passes(q), 7);
    ck_assert_uint_eq(amscr_params_get_oversampling(q), 3);
    ck_assert_uint_eq(amscr_params_get_kmax(q), 9);
    ck_assert_int_eq(amscr_params_get_symmetric(q), 1);
    ck_assert_uint_eq(amscr_params_get_refine(q), 11);
    ck_assert_uint_eq(amscr_params_get_num_threads(q), 5);
    ck_assert_int_eq(amscr_params_get_invariance(q), AMSCR_INVARIANCE_SIMILARITY);
    ck_assert_double_eq(amscr_params_get_penalty(q), 3.5);
}

START_TEST(test_copy_is_deep)
{
    set_all(p);
    assert_all_set(p);
    amscr_params *c = NULL;
    ck_assert_int_eq(amscr_params_copy(p, &c), AMSCR_OK);
    ck_assert_ptr_nonnull(c);
    ck_assert_ptr_ne(c, p);
    assert_all_set(c);
    /* Changing the copy leaves the original alone (and vice versa). */
    const double s[2] = {9.0, 10.0};
    ck_assert_int_eq(amscr_params_set_scales(c, s, 2), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(c, 64), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_method(c, AMSCR_METHOD_ACMA), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_penalty(c, 0.0), AMSCR_OK);
    assert_all_set(p);
    amscr_params_free(p);
    p = NULL; /* the copy outlives the original */
    double got[AMSCR_MAX_SCALES];
    size_t n;
    get_all_scales(c, got, &n);
    ck_assert_uint_eq(n, 2);
    ck_assert_double_eq(got[0], 9.0);
    ck_assert_double_eq(got[1], 10.0);
    ck_assert_uint_eq(amscr_params_get_num_samples(c), 64);
    amscr_params_free(c);
}
END_TEST

START_TEST(test_copy_of_defaults)
{
    amscr_params *c = NULL;
    ck_assert_int_eq(amscr_params_copy(p, &c), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_samples(c), 128);
    ck_assert_int_eq(amscr_params_get_method(c), AMSCR_METHOD_MULTICLASS_EM);
    size_t n0 = 0, n1 = 0;
    ck_assert_int_eq(amscr_params_get_scales(p, NULL, &n0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_get_scales(c, NULL, &n1), AMSCR_OK);
    ck_assert_uint_eq(n0, n1);
    amscr_params_free(c);
}
END_TEST

START_TEST(test_null_handling)
{
    amscr_params *sentinel = (amscr_params *)(void *)&sentinel, *out = sentinel;
    EXPECT_INVALID(amscr_params_new(NULL));
    EXPECT_INVALID(amscr_params_copy(NULL, &out));
    ck_assert_ptr_eq(out, sentinel);
    EXPECT_INVALID(amscr_params_copy(p, NULL));
    amscr_params_free(NULL);

    const double s[1] = {1.0};
    double buf[4];
    size_t n = 4;
    EXPECT_INVALID(amscr_params_set_num_samples(NULL, 128));
    EXPECT_INVALID(amscr_params_set_scales(NULL, s, 1));
    EXPECT_INVALID(amscr_params_get_scales(NULL, buf, &n));
    EXPECT_INVALID(amscr_params_get_scales(NULL, NULL, &n));
    EXPECT_INVALID(amscr_params_set_method(NULL, AMSCR_METHOD_ACMA));
    EXPECT_INVALID(amscr_params_set_closed(NULL, 1));
    EXPECT_INVALID(amscr_params_set_reflections(NULL, 1));
    EXPECT_INVALID(amscr_params_set_parametrization(NULL, AMSCR_PARAM_AFFINE));
    EXPECT_INVALID(amscr_params_set_presmooth(NULL, 0.01));
    EXPECT_INVALID(amscr_params_set_arclength_passes(NULL, 2));
    EXPECT_INVALID(amscr_params_set_oversampling(NULL, 8));
    EXPECT_INVALID(amscr_params_set_kmax(NULL, 5));
    EXPECT_INVALID(amscr_params_set_symmetric(NULL, 1));
    EXPECT_INVALID(amscr_params_set_refine(NULL, 1));
    EXPECT_INVALID(amscr_params_set_num_threads(NULL, 1));
    EXPECT_INVALID(amscr_params_set_invariance(NULL, AMSCR_INVARIANCE_AFFINE));
    EXPECT_INVALID(amscr_params_set_penalty(NULL, 1.0));

    ck_assert_uint_eq(amscr_params_get_num_samples(NULL), 0);
    ck_assert_int_eq((int)amscr_params_get_method(NULL), 0);
    ck_assert_int_eq(amscr_params_get_closed(NULL), 0);
    ck_assert_int_eq(amscr_params_get_reflections(NULL), 0);
    ck_assert_int_eq((int)amscr_params_get_parametrization(NULL), 0);
    ck_assert_double_eq(amscr_params_get_presmooth(NULL), 0.0);
    ck_assert_uint_eq(amscr_params_get_arclength_passes(NULL), 0);
    ck_assert_uint_eq(amscr_params_get_oversampling(NULL), 0);
    ck_assert_uint_eq(amscr_params_get_kmax(NULL), 0);
    ck_assert_int_eq(amscr_params_get_symmetric(NULL), 0);
    ck_assert_uint_eq(amscr_params_get_refine(NULL), 0);
    ck_assert_uint_eq(amscr_params_get_num_threads(NULL), 0);
    ck_assert_int_eq((int)amscr_params_get_invariance(NULL), 0);
    ck_assert_double_eq(amscr_params_get_penalty(NULL), 0.0);
}
END_TEST

START_TEST(test_independent_objects)
{
    amscr_params *q = NULL;
    ck_assert_int_eq(amscr_params_new(&q), AMSCR_OK);
    ck_assert_ptr_ne(q, p);
    ck_assert_int_eq(amscr_params_set_num_samples(q, 512), AMSCR_OK);
    ck_assert_uint_eq(amscr_params_get_num_samples(p), 128);
    amscr_params_free(q);
}
END_TEST

/* ---- the keyed calls (amscr_params_set_int / _set_real / _get_int / _get_real / _get_bounds) ---- */

/* Every key, with its kind (1 = real). */
static const struct {
    amscr_option key;
    int real;
} KEYS[] = {
    {AMSCR_OPT_NUM_SAMPLES, 0},          {AMSCR_OPT_CLOSED, 0},
    {AMSCR_OPT_PARAMETRIZATION, 0},      {AMSCR_OPT_PRESMOOTH, 1},
    {AMSCR_OPT_ARCLENGTH_PASSES, 0},     {AMSCR_OPT_OVERSAMPLING, 0},
    {AMSCR_OPT_METHOD, 0},               {AMSCR_OPT_KMAX, 0},
    {AMSCR_OPT_REFLECTIONS, 0},          {AMSCR_OPT_SYMMETRIC, 0},
    {AMSCR_OPT_INVARIANCE, 0},           {AMSCR_OPT_PENALTY, 1},
    {AMSCR_OPT_REFINE, 0},               {AMSCR_OPT_PARTIAL, 0},
    {AMSCR_OPT_POLISH, 0},               {AMSCR_OPT_NUM_THREADS, 0},
    {AMSCR_OPT_CHANNEL_WEIGHT, 1},       {AMSCR_OPT_CHANNEL_INVARIANCE, 0},
    {AMSCR_OPT_CHANNEL_AFFINE_SHARE, 1}, {AMSCR_OPT_CHANNEL_BAND, 1},
    {AMSCR_OPT_CHANNEL_AFFINE_BAND, 1},  {AMSCR_OPT_CHANNEL_SKIP, 1},
    {AMSCR_OPT_CHANNEL_LOCALITY, 1},     {AMSCR_OPT_RERANK_K, 0},
    {AMSCR_OPT_RERANK_ITERATIONS, 0},    {AMSCR_OPT_RERANK_INNER_SHARE, 1},
    {AMSCR_OPT_INNER_CLOSING, 1},        {AMSCR_OPT_CHANNEL_AFFINE_VIEW, 1},
};
#define NUM_KEYS (sizeof KEYS / sizeof KEYS[0])

/* The named setter of an integer key (the value cast to its type as a caller would). */
static amscr_status named_set_int(amscr_params *q, amscr_option key, int v)
{
    switch (key) {
    case AMSCR_OPT_NUM_SAMPLES: return amscr_params_set_num_samples(q, (size_t)v);
    case AMSCR_OPT_CLOSED: return amscr_params_set_closed(q, v);
    case AMSCR_OPT_PARAMETRIZATION: return amscr_params_set_parametrization(q, (amscr_parametrization)v);
    case AMSCR_OPT_ARCLENGTH_PASSES: return amscr_params_set_arclength_passes(q, (unsigned)v);
    case AMSCR_OPT_OVERSAMPLING: return amscr_params_set_oversampling(q, (unsigned)v);
    case AMSCR_OPT_METHOD: return amscr_params_set_method(q, (amscr_method)v);
    case AMSCR_OPT_KMAX: return amscr_params_set_kmax(q, (unsigned)v);
    case AMSCR_OPT_REFLECTIONS: return amscr_params_set_reflections(q, v);
    case AMSCR_OPT_SYMMETRIC: return amscr_params_set_symmetric(q, v);
    case AMSCR_OPT_INVARIANCE: return amscr_params_set_invariance(q, (amscr_invariance)v);
    case AMSCR_OPT_REFINE: return amscr_params_set_refine(q, (unsigned)v);
    case AMSCR_OPT_PARTIAL: return amscr_params_set_partial(q, v);
    case AMSCR_OPT_POLISH: return amscr_params_set_polish(q, v);
    case AMSCR_OPT_NUM_THREADS: return amscr_params_set_num_threads(q, (unsigned)v);
    case AMSCR_OPT_CHANNEL_INVARIANCE: return amscr_params_set_channel_invariance(q, (amscr_invariance)v);
    case AMSCR_OPT_RERANK_K: return amscr_params_set_rerank_k(q, (unsigned)v);
    case AMSCR_OPT_RERANK_ITERATIONS: return amscr_params_set_rerank_iterations(q, (unsigned)v);
    default: ck_abort_msg("key %d is not an integer key", (int)key);
    }
    return AMSCR_E_INVALID_ARG;
}

static amscr_status named_set_real(amscr_params *q, amscr_option key, double v)
{
    switch (key) {
    case AMSCR_OPT_PRESMOOTH: return amscr_params_set_presmooth(q, v);
    case AMSCR_OPT_PENALTY: return amscr_params_set_penalty(q, v);
    case AMSCR_OPT_CHANNEL_WEIGHT: return amscr_params_set_channel_weight(q, v);
    case AMSCR_OPT_CHANNEL_AFFINE_SHARE: return amscr_params_set_channel_affine_share(q, v);
    case AMSCR_OPT_CHANNEL_BAND: return amscr_params_set_channel_band(q, v);
    case AMSCR_OPT_CHANNEL_AFFINE_BAND: return amscr_params_set_channel_affine_band(q, v);
    case AMSCR_OPT_CHANNEL_SKIP: return amscr_params_set_channel_skip(q, v);
    case AMSCR_OPT_CHANNEL_LOCALITY: return amscr_params_set_channel_locality(q, v);
    case AMSCR_OPT_RERANK_INNER_SHARE: return amscr_params_set_rerank_inner_share(q, v);
    case AMSCR_OPT_INNER_CLOSING: return amscr_params_set_inner_closing(q, v);
    case AMSCR_OPT_CHANNEL_AFFINE_VIEW: return amscr_params_set_channel_affine_view(q, v);
    default: ck_abort_msg("key %d is not a real key", (int)key);
    }
    return AMSCR_E_INVALID_ARG;
}

/* The named getter of any key, as a double. */
static double named_get(const amscr_params *q, amscr_option key)
{
    switch (key) {
    case AMSCR_OPT_NUM_SAMPLES: return (double)amscr_params_get_num_samples(q);
    case AMSCR_OPT_CLOSED: return amscr_params_get_closed(q);
    case AMSCR_OPT_PARAMETRIZATION: return amscr_params_get_parametrization(q);
    case AMSCR_OPT_PRESMOOTH: return amscr_params_get_presmooth(q);
    case AMSCR_OPT_ARCLENGTH_PASSES: return amscr_params_get_arclength_passes(q);
    case AMSCR_OPT_OVERSAMPLING: return amscr_params_get_oversampling(q);
    case AMSCR_OPT_METHOD: return amscr_params_get_method(q);
    case AMSCR_OPT_KMAX: return amscr_params_get_kmax(q);
    case AMSCR_OPT_REFLECTIONS: return amscr_params_get_reflections(q);
    case AMSCR_OPT_SYMMETRIC: return amscr_params_get_symmetric(q);
    case AMSCR_OPT_INVARIANCE: return amscr_params_get_invariance(q);
    case AMSCR_OPT_PENALTY: return amscr_params_get_penalty(q);
    case AMSCR_OPT_REFINE: return amscr_params_get_refine(q);
    case AMSCR_OPT_PARTIAL: return amscr_params_get_partial(q);
    case AMSCR_OPT_POLISH: return amscr_params_get_polish(q);
    case AMSCR_OPT_NUM_THREADS: return amscr_params_get_num_threads(q);
    case AMSCR_OPT_CHANNEL_WEIGHT: return amscr_params_get_channel_weight(q);
    case AMSCR_OPT_CHANNEL_INVARIANCE: return amscr_params_get_channel_invariance(q);
    case AMSCR_OPT_CHANNEL_AFFINE_SHARE: return amscr_params_get_channel_affine_share(q);
    case AMSCR_OPT_CHANNEL_BAND: return amscr_params_get_channel_band(q);
    case AMSCR_OPT_CHANNEL_AFFINE_BAND: return amscr_params_get_channel_affine_band(q);
    case AMSCR_OPT_CHANNEL_SKIP: return amscr_params_get_channel_skip(q);
    case AMSCR_OPT_CHANNEL_LOCALITY: return amscr_params_get_channel_locality(q);
    case AMSCR_OPT_RERANK_K: return amscr_params_get_rerank_k(q);
    case AMSCR_OPT_RERANK_ITERATIONS: return amscr_params_get_rerank_iterations(q);
    case AMSCR_OPT_RERANK_INNER_SHARE: return amscr_params_get_rerank_inner_share(q);
    case AMSCR_OPT_INNER_CLOSING: return amscr_params_get_inner_closing(q);
    case AMSCR_OPT_CHANNEL_AFFINE_VIEW: return amscr_params_get_channel_affine_view(q);
    }
    ck_abort_msg("unknown key %d", (int)key);
    return 0.0;
}

/* The keyed getter of any key, as a double. */
static double keyed_get(const amscr_params *q, amscr_option key, int real)
{
    double v = NAN;
    int i = -1;
    if (real) {
        ck_assert_int_eq(amscr_params_get_real(q, key, &v), AMSCR_OK);
        return v;
    }
    ck_assert_int_eq(amscr_params_get_int(q, key, &i), AMSCR_OK);
    return i;
}

static amscr_status keyed_set(amscr_params *q, amscr_option key, int real, double v)
{
    return real ? amscr_params_set_real(q, key, v) : amscr_params_set_int(q, key, (int)v);
}

/* Every key: the keyed getter reads what the named getter reads (defaults of all three presets),
 * and both bounds (or, at an open end, the nearest value inside), set by key, read back by key and
 * by name. */
START_TEST(test_keyed_round_trip)
{
    amscr_status (*presets[3])(amscr_params **) = {amscr_params_new, amscr_params_new_registration,
                                                  amscr_params_new_retrieval};
    for (int k = 0; k < 3; k++) {
        amscr_params *q = NULL;
        ck_assert_int_eq(presets[k](&q), AMSCR_OK);
        for (size_t i = 0; i < NUM_KEYS; i++)
            ck_assert_double_eq(keyed_get(q, KEYS[i].key, KEYS[i].real), named_get(q, KEYS[i].key));
        amscr_params_free(q);
    }
    for (size_t i = 0; i < NUM_KEYS; i++) {
        amscr_option key = KEYS[i].key;
        double lo = NAN, hi = NAN;
        ck_assert_int_eq(amscr_params_get_bounds(key, &lo, &hi), AMSCR_OK);
        ck_assert(lo < hi);
        double vals[2] = {lo, hi};
        for (int j = 0; j < 2; j++) {
            double v = vals[j];
            if (keyed_set(p, key, KEYS[i].real, v) != AMSCR_OK) { /* an open end (test_keyed_bounds) */
                ck_assert(KEYS[i].real);
                v = nextafter(v, vals[1 - j]);
                ck_assert_msg(keyed_set(p, key, 1, v) == AMSCR_OK, "key %d = %g", (int)key, v);
            }
            ck_assert_double_eq(keyed_get(p, key, KEYS[i].real), v);
            ck_assert_double_eq(named_get(p, key), v);
        }
    }
}
END_TEST

/* The documented bounds of a few keys, and the values inside them that three keys refuse. */
START_TEST(test_keyed_bounds)
{
    double lo = NAN, hi = NAN;
    ck_assert_int_eq(amscr_params_get_bounds(AMSCR_OPT_NUM_SAMPLES, &lo, &hi), AMSCR_OK);
    ck_assert_double_eq(lo, 16.0);
    ck_assert_double_eq(hi, (double)AMSCR_MAX_SAMPLES);
    ck_assert_int_eq(amscr_params_get_bounds(AMSCR_OPT_METHOD, &lo, &hi), AMSCR_OK);
    ck_assert_double_eq(lo, AMSCR_METHOD_ACMA);
    ck_assert_double_eq(hi, AMSCR_METHOD_MULTICLASS_EM);
    ck_assert_int_eq(amscr_params_get_bounds(AMSCR_OPT_PENALTY, &lo, &hi), AMSCR_OK);
    ck_assert_double_eq(lo, 0.0);
    ck_assert_double_eq(hi, 1e6);
    ck_assert_int_eq(amscr_params_get_bounds(AMSCR_OPT_CHANNEL_AFFINE_VIEW, &lo, &hi), AMSCR_OK);
    ck_assert_double_eq(lo, 0.0);
    ck_assert_double_eq(hi, 100.0);
    EXPECT_INVALID(amscr_params_set_real(p, AMSCR_OPT_CHANNEL_BAND, 0.0));
    EXPECT_INVALID(amscr_params_set_real(p, AMSCR_OPT_CHANNEL_AFFINE_BAND, 0.0));
    EXPECT_INVALID(amscr_params_set_real(p, AMSCR_OPT_RERANK_INNER_SHARE, 1.0));
    EXPECT_INVALID(amscr_params_set_real(p, AMSCR_OPT_CHANNEL_AFFINE_VIEW, 0.5));
    ck_assert_int_eq(amscr_params_set_real(p, AMSCR_OPT_CHANNEL_AFFINE_VIEW, 0.0), AMSCR_OK);
}
END_TEST

/* Outside the bounds, NaN and infinities: refused with a detail, p unchanged. */
START_TEST(test_keyed_rejects)
{
    for (size_t i = 0; i < NUM_KEYS; i++) {
        amscr_option key = KEYS[i].key;
        double lo = NAN, hi = NAN, before = named_get(p, key);
        ck_assert_int_eq(amscr_params_get_bounds(key, &lo, &hi), AMSCR_OK);
        if (KEYS[i].real) {
            const double bad[] = {lo - 0.5, nextafter(lo, -INFINITY), nextafter(hi, INFINITY), hi + 0.5,
                                  NAN, INFINITY, -INFINITY};
            for (size_t j = 0; j < sizeof bad / sizeof bad[0]; j++)
                EXPECT_INVALID(amscr_params_set_real(p, key, bad[j]));
            EXPECT_INVALID(amscr_params_set_int(p, key, 0)); /* a real key by the integer call */
            int iv = 0;
            EXPECT_INVALID(amscr_params_get_int(p, key, &iv));
        } else {
            EXPECT_INVALID(amscr_params_set_int(p, key, (int)lo - 1));
            EXPECT_INVALID(amscr_params_set_int(p, key, (int)hi + 1));
            EXPECT_INVALID(amscr_params_set_int(p, key, INT_MIN));
            EXPECT_INVALID(amscr_params_set_int(p, key, INT_MAX));
            EXPECT_INVALID(amscr_params_set_real(p, key, lo)); /* an integer key by the real call */
            double rv = 0.0;
            EXPECT_INVALID(amscr_params_get_real(p, key, &rv));
        }
        ck_assert_double_eq(named_get(p, key), before);
    }
}
END_TEST

START_TEST(test_keyed_unknown_and_null)
{
    const int unknown[] = {0, -1, (int)AMSCR_OPT_CHANNEL_AFFINE_VIEW + 1, 1000, INT_MAX, INT_MIN};
    int iv = 0;
    double rv = 0.0, lo = 0.0, hi = 0.0;
    for (size_t j = 0; j < sizeof unknown / sizeof unknown[0]; j++) {
        amscr_option key = (amscr_option)unknown[j];
        EXPECT_INVALID(amscr_params_set_int(p, key, 1));
        EXPECT_INVALID(amscr_params_set_real(p, key, 0.5));
        EXPECT_INVALID(amscr_params_get_int(p, key, &iv));
        EXPECT_INVALID(amscr_params_get_real(p, key, &rv));
        EXPECT_INVALID(amscr_params_get_bounds(key, &lo, &hi));
    }
    EXPECT_INVALID(amscr_params_set_int(NULL, AMSCR_OPT_NUM_SAMPLES, 128));
    EXPECT_INVALID(amscr_params_set_real(NULL, AMSCR_OPT_PENALTY, 1.0));
    EXPECT_INVALID(amscr_params_get_int(NULL, AMSCR_OPT_NUM_SAMPLES, &iv));
    EXPECT_INVALID(amscr_params_get_int(p, AMSCR_OPT_NUM_SAMPLES, NULL));
    EXPECT_INVALID(amscr_params_get_real(NULL, AMSCR_OPT_PENALTY, &rv));
    EXPECT_INVALID(amscr_params_get_real(p, AMSCR_OPT_PENALTY, NULL));
    EXPECT_INVALID(amscr_params_get_bounds(AMSCR_OPT_PENALTY, NULL, &hi));
    EXPECT_INVALID(amscr_params_get_bounds(AMSCR_OPT_PENALTY, &lo, NULL));
}
END_TEST

/* The keyed and the named setter of every key accept and refuse the same values and store the
 * same result. */
START_TEST(test_keyed_agrees_with_named)
{
    amscr_params *a = NULL, *b = NULL;
    ck_assert_int_eq(amscr_params_new(&a), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new(&b), AMSCR_OK);
    for (size_t i = 0; i < NUM_KEYS; i++) {
        amscr_option key = KEYS[i].key;
        double lo = NAN, hi = NAN;
        ck_assert_int_eq(amscr_params_get_bounds(key, &lo, &hi), AMSCR_OK);
        const double vals[] = {lo - 1.0, lo, nextafter(lo, INFINITY), 0.5, 1.0, 1.5, 2.0, 3.0, 16.0, 0.5 * (lo + hi),
                               nextafter(hi, -INFINITY), hi, hi + 1.0, -1.0, NAN, INFINITY};
        for (size_t j = 0; j < sizeof vals / sizeof vals[0]; j++) {
            double v = vals[j];
            amscr_status sa, sb;
            if (KEYS[i].real) {
                sa = named_set_real(a, key, v);
                sb = amscr_params_set_real(b, key, v);
            } else {
                if (!isfinite(v) || v != floor(v))
                    continue;
                sa = named_set_int(a, key, (int)v);
                sb = amscr_params_set_int(b, key, (int)v);
            }
            ck_assert_msg(sa == sb, "key %d = %g: named %d, keyed %d", (int)key, v, (int)sa, (int)sb);
            ck_assert_double_eq(named_get(a, key), named_get(b, key));
            ck_assert_double_eq(keyed_get(a, key, KEYS[i].real), named_get(a, key));
        }
    }
    amscr_params_free(a);
    amscr_params_free(b);
}
END_TEST

Suite *amscr_suite_params(void)
{
    Suite *s = suite_create("params");
    TCase *tc = tcase_create("params");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, test_defaults);
    tcase_add_test(tc, test_num_samples);
    tcase_add_test(tc, test_scales);
    tcase_add_test(tc, test_scales_bound_follows_num_samples);
    tcase_add_test(tc, test_enums);
    tcase_add_test(tc, test_flags);
    tcase_add_test(tc, test_presmooth);
    tcase_add_test(tc, test_unsigned_ranges);
    tcase_add_test(tc, test_penalty);
    tcase_add_test(tc, test_copy_is_deep);
    tcase_add_test(tc, test_copy_of_defaults);
    tcase_add_test(tc, test_null_handling);
    tcase_add_test(tc, test_independent_objects);
    tcase_add_test(tc, test_keyed_round_trip);
    tcase_add_test(tc, test_keyed_bounds);
    tcase_add_test(tc, test_keyed_rejects);
    tcase_add_test(tc, test_keyed_unknown_and_null);
    tcase_add_test(tc, test_keyed_agrees_with_named);
    suite_add_tcase(s, tc);
    return s;
}
