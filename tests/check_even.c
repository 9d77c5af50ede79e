/* check_even.c — the map refined on the evidence that a noisy curve's points were taken evenly
 * along it (src/register/even.c): long shapes whose position along their long axis a closest-point fit
 * cannot pin down, either running direction, and what it must leave alone (uneven sampling, a
 * drifting spacing, a missing run, clean points, degenerate input). */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "even.h"
#include "longshape.h"
#include "suites.h"
#include "testutil.h"

enum { POINTS = 600, CASES = 20 };

/* How the observed points are taken along the moved curve. */
typedef struct {
    double density, wave; /* amscr_test_resample_uneven's (1, 0: evenly) */
    double thin;          /* the long shape's width scaled by this (1: 5:1) */
    double stretch;       /* the start: the truth stretched by this along the long axis */
    double noise;         /* Gaussian noise sigma over the size */
    int reversed;         /* the points run backwards */
} sampling;

/* One case: the clean long shape a (POINTS points, evenly sampled), the truth Y, the observed
 * points b taken along the moved dense curve as `how` says from a random start, the start Z
 * `how` says, and the size of b; returns the noise variance per
 * coordinate. */
static double make_case(uint64_t seed, sampling how, double *a, double *b, double Y[6], double Z[6], double *size)
{
    amscr_test_rng rng;
    amscr_test_rng_seed(&rng, seed);
    double *d = malloc(2 * AMSCR_TEST_DENSE * sizeof *d), *md = malloc(2 * AMSCR_TEST_DENSE * sizeof *md);
    double *t = malloc(2 * POINTS * sizeof *t);
    ck_assert(d && md && t);
    amscr_test_long_dense(&rng, d);
    for (size_t i = 0; i < AMSCR_TEST_DENSE; i++)
        d[2 * i + 1] *= how.thin;
    amscr_test_resample_uneven(d, POINTS, 1.0, 0.0, a);
    amscr_test_random_affine(&rng, 2.0, 0.5, 10.0, 0, Y);
    amscr_test_apply_affine(Y, d, AMSCR_TEST_DENSE, md);
    amscr_test_resample_uneven(md, POINTS, how.density, how.wave, t);
    amscr_test_cyclic_shift(t, POINTS, (size_t)(amscr_test_uniform(&rng) * POINTS) % POINTS, b);
    *size = amscr_test_shape_size(b, POINTS);
    double sigma = how.noise * *size;
    amscr_test_add_noise(&rng, b, POINTS, sigma);
    if (how.reversed)
        amscr_test_reverse(b, POINTS);
    amscr_test_long_axis_stretch(b, POINTS, Y, how.stretch, Z);
    free(t);
    free(md);
    free(d);
    return sigma * sigma;
}

/* Over CASES long shapes (width times `thin`) with 2 % noise taken evenly along the moved curve,
 * started `stretch` off along the long axis: every start but one (the whiteness test refuses 1 %
 * of even samplings by design) is refined, to below a third of its error when it was off, and
 * the mean error ends below `limit` (of the start's error; of the size from the truth). */
static void check_even(int reversed, double thin, double stretch, double limit)
{
    double *a = malloc(2 * POINTS * sizeof *a), *b = malloc(2 * POINTS * sizeof *b), before = 0.0, after = 0.0;
    ck_assert(a && b);
    size_t better = 0;
    for (uint64_t c = 0; c < CASES; c++) {
        double Y[6], Z[6], size;
        double s2 = make_case(1500 + c, (sampling){1.0, 0.0, thin, stretch, 0.02, reversed}, a, b, Y, Z, &size);
        double e0 = amscr_test_max_map_error(Z, Y, a, POINTS) / size;
        int done = amscr__even_fit(a, POINTS, b, POINTS, s2, Z);
        double e1 = amscr_test_max_map_error(Z, Y, a, POINTS) / size;
        printf("even: %s, thin %g, case %2d: error %.2f %% -> %.2f %% (%s)\n", reversed ? "reversed" : "forward", thin,
               (int)c, 100 * e0, 100 * e1, done ? "refined" : "left");
        better += done && (stretch > 0.0 ? e1 < e0 / 3.0 : e1 < limit);
        before += e0 / CASES, after += e1 / CASES;
    }
    printf("even: %s, thin %g: %zu of %d below a third, mean %.2f %% -> %.2f %%\n", reversed ? "reversed" : "forward",
           thin, better, CASES, 100 * before, 100 * after);
    ck_assert_uint_ge(better, CASES - 1);
    ck_assert(after < (stretch > 0.0 ? limit * before : limit));
    free(a);
    free(b);
}

START_TEST(even_pins_the_long_axis)
{
    check_even(0, 1.0, 0.03, 0.2);
}
END_TEST

START_TEST(even_either_direction)
{
    check_even(1, 1.0, 0.03, 0.2);
}
END_TEST

/* Points not taken evenly along the moved curve leave the map exactly as given: twice as dense
 * on half of it (a pen that slowed down), or a spacing that drifts smoothly by +-10 % (points
 * taken evenly along another version of the curve). */
START_TEST(even_refuses_uneven_spacing)
{
    double *a = malloc(2 * POINTS * sizeof *a), *b = malloc(2 * POINTS * sizeof *b);
    ck_assert(a && b);
    const sampling kinds[] = {
        {2.0, 0.0, 1.0, 0.03, 0.02, 0}, {1.0, 0.1, 1.0, 0.03, 0.02, 0}, {1.0, 0.1, 1.0, 0.03, 0.01, 1}};
    for (size_t k = 0; k < sizeof kinds / sizeof *kinds; k++)
        for (uint64_t c = 0; c < CASES; c++) {
            double Y[6], Z[6], Z0[6], size, s2 = make_case(1600 + c, kinds[k], a, b, Y, Z, &size);
            memcpy(Z0, Z, sizeof Z);
            ck_assert_msg(amscr__even_fit(a, POINTS, b, POINTS, s2, Z) == 0, "kind %zu case %d refined", k, (int)c);
            ck_assert(memcmp(Z, Z0, sizeof Z) == 0);
        }
    free(a);
    free(b);
}
END_TEST

/* A run of 10 % of the points missing (the gap test of the polish did not see it): the points
 * after it are a run's length further on than their index says, so the map stays. */
START_TEST(even_refuses_a_missing_run)
{
    double *a = malloc(2 * POINTS * sizeof *a), *b = malloc(2 * POINTS * sizeof *b);
    ck_assert(a && b);
    for (uint64_t c = 0; c < CASES; c++) {
        double Y[6], Z[6], Z0[6], size;
        double s2 = make_case(1700 + c, (sampling){1.0, 0.0, 1.0, 0.03, 0.02, 0}, a, b, Y, Z, &size);
        size_t keep = POINTS - POINTS / 10;
        memcpy(Z0, Z, sizeof Z);
        ck_assert_msg(amscr__even_fit(a, POINTS, b, keep, s2, Z) == 0, "case %d refined", (int)c);
        ck_assert(memcmp(Z, Z0, sizeof Z) == 0);
    }
    free(a);
    free(b);
}
END_TEST

/* Outside its regime the stage returns 0 and leaves the map exactly as given (also a map that
 * does not explain the points, degenerate maps and curves); on points that are no curve at all
 * it stays finite. */
START_TEST(even_leaves_what_it_cannot_help)
{
    double *a = malloc(2 * POINTS * sizeof *a), *b = malloc(2 * POINTS * sizeof *b), Y[6], Z[6], Z0[6], size;
    ck_assert(a && b);
    make_case(90, (sampling){1.0, 0.0, 1.0, 0.03, 0.0, 0}, a, b, Y, Z, &size); /* clean: the spacing says it all */
    memcpy(Z0, Z, sizeof Z);
    ck_assert_int_eq(amscr__even_fit(a, POINTS, b, POINTS, 1e-10 * size * size, Z), 0);
    double s2 = make_case(91, (sampling){1.0, 0.0, 1.0, 0.03, 0.02, 0}, a, b, Y, Z, &size);
    memcpy(Z0, Z, sizeof Z);
    ck_assert_int_eq(amscr__even_fit(a, POINTS, b, 10, s2, Z), 0);     /* too few points */
    ck_assert_int_eq(amscr__even_fit(a, 2, b, POINTS, s2, Z), 0);      /* no curve */
    ck_assert_int_eq(amscr__even_fit(a, POINTS, b, POINTS, 0.0, Z), 0); /* no noise level */
    ck_assert_int_eq(amscr__even_fit(a, POINTS, b, POINTS, NAN, Z), 0);
    ck_assert(memcmp(Z, Z0, sizeof Z) == 0);
    double far[6]; /* a map that does not explain the points (moved by the size) */
    memcpy(far, Z, sizeof far);
    far[2] += 1.5 * size;
    ck_assert_int_eq(amscr__even_fit(a, POINTS, b, POINTS, s2, far), 0);
    amscr_test_stage_degenerate(amscr__even_fit, a, b, POINTS, s2, size, Z);
    free(a);
    free(b);
}
END_TEST

Suite *amscr_suite_even(void)
{
    Suite *s = suite_create("even");
    TCase *tc = tcase_create("even");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, even_pins_the_long_axis);
    tcase_add_test(tc, even_either_direction);
    tcase_add_test(tc, even_refuses_uneven_spacing);
    tcase_add_test(tc, even_refuses_a_missing_run);
    tcase_add_test(tc, even_leaves_what_it_cannot_help);
    suite_add_tcase(s, tc);
    return s;
}
