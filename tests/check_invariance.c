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

/* ------------------------------------------------- far from the origin */

/* A 5-lobed star of NP points, RMS radius ~50, moved by o (not a dyadic shape: its coordinates
 * use every bit, so far from the origin they are rounded) into far; back = far - o, exact. */
static void star_far(double k, double a, const double o[2], double *far, double *back)
{
    for (size_t i = 0; i < NP; i++) {
        double t = 2.0 * 3.141592653589793 * (double)i / NP, r = 50.0 * (1.0 + a * cos(k * t) + 0.1 * sin(3.0 * t));
        far[2 * i] = r * cos(t) + o[0];
        far[2 * i + 1] = r * sin(t) + o[1];
        back[2 * i] = far[2 * i] - o[0];
        back[2 * i + 1] = far[2 * i + 1] - o[1];
    }
}

/* Shapes far from the origin (0.7 * 2^48 = 2e14 here, 2e12 times their extent) register as the
 * same points moved back do, to their coordinates' own rounding (doubles 1/32 unit apart): the
 * preparation sums their raw coordinates no more (the distance was off by 0.4 %, now 0.05 %);
 * beyond 2^44 extents a clear error says to subtract an offset. */
START_TEST(test_far_from_the_origin_registers_as_near_it)
{
    const double o[2] = {0.7 * 281474976710656.0, -0.75 * 281474976710656.0};
    const double A0[6] = {1.2, 0.3, 5.0, -0.2, 0.9, -3.0};
    double sf[2 * NP], sb[2 * NP], tb[2 * NP], tf[2 * NP], m0[6], m1[6];
    star_far(5.0, 0.4, o, sf, sb); /* the target: another star's affine image, from point 37 on */
    amscr_test_apply_affine(A0, sb, NP, tb);
    for (size_t i = 0; i < NP; i++) { /* far, then moved back exactly */
        size_t j = (i + 37) % NP;
        tf[2 * j] = tb[2 * i] + o[0];
        tf[2 * j + 1] = tb[2 * i + 1] + o[1];
    }
    for (size_t i = 0; i < 2 * NP; i++)
        tb[i] = tf[i] - o[i % 2];
    star_far(5.0, 0.3, o, sf, sb);
    amscr_params *p = params_for(AMSCR_INVARIANCE_AFFINE);
    double d0 = reg(p, sb, NP, tb, NP, m0), d1 = reg(p, sf, NP, tf, NP, m1);
    ck_assert_msg(fabs(d1 - d0) <= 1.5e-3 * d0, "far %.9g, moved back %.9g", d1, d0);
    for (int k = 0; k < 6; k += 3) /* the linear part; B holds o's rounding */
        ck_assert_msg(fabs(m1[k] - m0[k]) < 1e-3 && fabs(m1[k + 1] - m0[k + 1]) < 1e-3,
                      "A row %d: %.9g %.9g, moved back %.9g %.9g", k / 3, m1[k], m1[k + 1], m0[k], m0[k + 1]);
    /* 2^50 = 1.1e15 from the origin: 1e13 extents (a distance of doubles of 1/8 unit) */
    const double o2[2] = {1125899906842624.0, 0.0};
    star_far(5.0, 0.3, o2, sf, sb);
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(sf, NP, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_validate(c, 1), AMSCR_OK);
    amscr_contour_free(c);
    const double o3[2] = {0.0, -4503599627370496.0}; /* 2^52: 4e13 extents */
    star_far(5.0, 0.3, o3, sf, sb);
    ck_assert_int_eq(amscr_contour_new(sf, NP, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_validate(c, 1), AMSCR_E_DEGENERATE);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "subtract an offset"));
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_E_DEGENERATE);
    amscr_contour_free(c);
    amscr_params_free(p);
}
END_TEST

/* A collection far from the origin (0.7 * 2^36 = 4.8e10 here, 5e8 times its shapes' extent)
 * scores as the same points moved back: the shape channel's features were off by up to 2e-4 in
 * the scores (0.7 at 2^40). */
START_TEST(test_far_from_the_origin_retrieves_as_near_it)
{
    enum { SHAPES = 12 };
    const double o[2] = {0.7 * 68719476736.0, 0.5 * 68719476736.0};
    double far[2 * NP], back[2 * NP], *D[2];
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 0), AMSCR_OK); /* the fused distance itself */
    amscr_db *db[2] = {NULL, NULL};
    for (int w = 0; w < 2; w++) {
        ck_assert_int_eq(amscr_db_new(p, &db[w]), AMSCR_OK);
        D[w] = malloc(SHAPES * SHAPES * sizeof *D[w]);
        ck_assert_ptr_nonnull(D[w]);
    }
    for (int s = 0; s < SHAPES; s++) {
        star_far(3.0 + s % 4, 0.1 + 0.1 * (s / 4), o, far, back);
        for (int w = 0; w < 2; w++) {
            amscr_contour *c = NULL;
            ck_assert_int_eq(amscr_contour_new(w ? far : back, NP, &c), AMSCR_OK);
            ck_assert_int_eq(amscr_db_add_contour(db[w], c, s, NULL), AMSCR_OK);
            amscr_contour_free(c);
        }
    }
    for (int w = 0; w < 2; w++)
        ck_assert_int_eq(amscr_db_retrieval_matrix(db[w], NULL, NULL, D[w]), AMSCR_OK);
    for (int i = 0; i < SHAPES * SHAPES; i++)
        ck_assert_msg(fabs(D[1][i] - D[0][i]) <= 1e-9, "cell %d: far %.12g, moved back %.12g", i, D[1][i], D[0][i]);
    for (int w = 0; w < 2; w++) {
        free(D[w]);
        amscr_db_free(db[w]);
    }
    amscr_params_free(p);
}
END_TEST

Suite *amscr_suite_invariance(void)
{
    Suite *s = suite_create("invariance");
    TCase *tc = tcase_create("modes");
    tcase_add_loop_test(tc, test_exact_recovery, 0, 6);
    tcase_add_loop_test(tc, test_group_invariance, 0, 4);
    tcase_add_test(tc, test_penalty_limits);
    tcase_add_test(tc, test_far_from_the_origin_registers_as_near_it);
    tcase_add_test(tc, test_far_from_the_origin_retrieves_as_near_it);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);
    return s;
}
