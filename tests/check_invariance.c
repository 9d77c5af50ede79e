/* check_invariance.c — the invariance modes (affine, similarity, penalized): each recovers its
 * own kind of map exactly, and its distance does not change under its group. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"
#include "testutil.h"

#define NP 300

static amscr_params *params_for(amscr_invariance inv)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_invariance(p, inv), AMSCR_OK);
    return p;
}

static double reg(const amscr_params *p, const double *a, size_t na, const double *b, size_t nb, double m6[6])
{
    amscr_contour *ca = NULL, *cb = NULL;
    amscr_result *r = NULL;
    ck_assert_int_eq(amscr_contour_new(a, na, &ca), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_new(b, nb, &cb), AMSCR_OK);
    ck_assert_int_eq(amscr_register_contours(p, ca, cb, &r), AMSCR_OK);
    if (m6)
        ck_assert_int_eq(amscr_result_affine(r, m6), AMSCR_OK);
    double d = amscr_result_distance(r);
    amscr_result_free(r);
    amscr_contour_free(ca);
    amscr_contour_free(cb);
    return d;
}

/* A random similarity: rotation, uniform scale, translation. */
static void random_similarity(amscr_test_rng *r, double m[6])
{
    double th = 6.283185307179586 * amscr_test_uniform(r), s = 0.5 + 2.0 * amscr_test_uniform(r);
    m[0] = s * cos(th);
    m[1] = -s * sin(th);
    m[3] = s * sin(th);
    m[4] = s * cos(th);
    m[2] = 10.0 * (2 * amscr_test_uniform(r) - 1);
    m[5] = 10.0 * (2 * amscr_test_uniform(r) - 1);
}

/* Each mode recovers its own kind of map exactly from an exact image of the source's points. */
START_TEST(test_exact_recovery)
{
    const amscr_invariance modes[3] = {AMSCR_INVARIANCE_AFFINE, AMSCR_INVARIANCE_SIMILARITY,
                                       AMSCR_INVARIANCE_PENALIZED};
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 9100 + (uint64_t)_i);
    double f[2 * NP], h[2 * NP], T[6], M[6];
    amscr_test_random_shape(&r, NP, 5, f);
    for (int k = 0; k < 3; k++) {
        if (modes[k] == AMSCR_INVARIANCE_AFFINE)
            amscr_test_random_affine(&r, 2.0, 0.5, 10.0, 0, T);
        else
            random_similarity(&r, T);
        amscr_test_apply_affine(T, f, NP, h);
        amscr_params *p = params_for(modes[k]);
        double d = reg(p, f, NP, h, NP, M);
        double err = amscr_test_max_map_error(M, T, f, NP) / amscr_test_shape_size(h, NP);
        ck_assert_msg(err < 1e-9, "mode %d: map error %.3g", (int)modes[k], err);
        ck_assert_double_lt(d, 1e-12);
        amscr_params_free(p);
    }
}
END_TEST

/* The distance does not change when either shape moves by a map of the mode's group; the
 * similarity distance DOES change under a shear (it tells aspect apart). */
START_TEST(test_group_invariance)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 9200 + (uint64_t)_i);
    double f[2 * NP], g[2 * NP], f2[2 * NP], g2[2 * NP], S[6];
    amscr_test_random_shape(&r, NP, 5, f);
    amscr_test_random_shape(&r, NP, 6, g);
    const amscr_invariance modes[2] = {AMSCR_INVARIANCE_SIMILARITY, AMSCR_INVARIANCE_PENALIZED};
    for (int k = 0; k < 2; k++) {
        amscr_params *p = params_for(modes[k]);
        double d0 = reg(p, f, NP, g, NP, NULL);
        random_similarity(&r, S);
        amscr_test_apply_affine(S, f, NP, f2);
        random_similarity(&r, S);
        amscr_test_apply_affine(S, g, NP, g2);
        double d1 = reg(p, f2, NP, g2, NP, NULL);
        ck_assert_msg(fabs(d1 - d0) <= 1e-9 * (1.0 + d0), "mode %d: %.12g vs %.12g", (int)modes[k], d0, d1);
        amscr_params_free(p);
    }
    /* a strong anisotropic stretch of the target changes the similarity distance */
    amscr_params *p = params_for(AMSCR_INVARIANCE_SIMILARITY);
    const double stretch[6] = {2.5, 0.0, 0.0, 0.0, 0.6, 0.0};
    amscr_test_apply_affine(stretch, f, NP, f2);
    double same = reg(p, f, NP, f, NP, NULL), stretched = reg(p, f, NP, f2, NP, NULL);
    ck_assert_double_lt(same, 1e-12);
    ck_assert_double_gt(stretched, 1e-3);
    amscr_params_free(p);
}
END_TEST

/* The penalty moves the penalized distance between the affine one (no penalty) and the
 * similarity one (a huge penalty). */
START_TEST(test_penalty_limits)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 9300);
    double f[2 * NP], g[2 * NP];
    amscr_test_random_shape(&r, NP, 5, f);
    amscr_test_random_shape(&r, NP, 6, g);
    amscr_params *ps = params_for(AMSCR_INVARIANCE_SIMILARITY), *pp = params_for(AMSCR_INVARIANCE_PENALIZED);
    double dsim = reg(ps, f, NP, g, NP, NULL);
    ck_assert_int_eq(amscr_params_set_penalty(pp, 1e6), AMSCR_OK);
    double dbig = reg(pp, f, NP, g, NP, NULL);
    ck_assert_msg(fabs(dbig - dsim) < 1e-3 * dsim, "huge penalty %.9g vs similarity %.9g", dbig, dsim);
    ck_assert_int_eq(amscr_params_set_penalty(pp, 0.0), AMSCR_OK);
    double dzero = reg(pp, f, NP, g, NP, NULL);
    ck_assert_double_le(dzero, dsim * (1 + 1e-9));
    amscr_params_free(ps);
    amscr_params_free(pp);
}
END_TEST

Suite *amscr_suite_invariance(void)
{
    Suite *s = suite_create("invariance");
    TCase *tc = tcase_create("modes");
    tcase_add_loop_test(tc, test_exact_recovery, 0, 6);
    tcase_add_loop_test(tc, test_group_invariance, 0, 4);
    tcase_add_test(tc, test_penalty_limits);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    return s;
}
