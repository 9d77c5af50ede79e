/* check_signature.c — the shortlist signature of an index query (src/retrieval/
 * affine_signature.c): its whitened block is invariant to affine maps of the input, its
 * similarity block to similarities, the whole signature to the start point and direction;
 * finite for degenerate-but-valid shapes; deterministic; the distance is a symmetric,
 * zero-on-itself dissimilarity that tells shapes apart.
 *
 * Tolerances are 10x the worst relative change measured over the seeded maps below (the
 * prepared samples of a mapped input are not exactly the mapped samples: resampling and the
 * pre-smoothing act on another polygon; the mirror image's bins split the samples at other
 * places). Measured (N = 128, five 400-point random shapes x 4 maps each, half of them mirror
 * images), relative to the distance between two different random shapes: whitened block
 * under affine maps 0.034 (1e-13 without mirror images), similarity-weighted signature under
 * similarities 0.0087, under another start point / direction 0.0146. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "affine_signature.h"
#include "suites.h"
#include "testutil.h"

#define NPTS 400
#define DIM AMSCR__AFFINE_SIG_DIM
/* 10x the worst measured: 0.034 (affine, mirror images included), 0.0087 (similarity), 0.0146
 * (start point and direction) */
#define TOL_AFFINE 0.34
#define TOL_SIM 0.087
#define TOL_START 0.146

static void sig_of(const double *xy, size_t n, double share, double *out)
{
    amscr_params *p = NULL;
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_new(xy, n, &c), AMSCR_OK);
    ck_assert_msg(amscr_descriptor_new(p, c, &d) == AMSCR_OK, "%s", amscr_last_error_detail());
    if (share < 0.0)
        amscr__affine_signature(d, out);
    else
        amscr__affine_signature_share(d, share, out);
    for (size_t t = 0; t < DIM; t++)
        ck_assert_msg(isfinite(out[t]), "signature[%zu] = %g", t, out[t]);
    amscr_descriptor_free(d);
    amscr_contour_free(c);
    amscr_params_free(p);
}

/* The distance of shape xy's signature to that of its image under m (share as sig_of),
 * relative to the distance between xy and `other`. */
static double rel_change(const double *xy, const double *other, const double m[6], int reverse, size_t shift,
                         double share)
{
    double *a = malloc(2 * NPTS * sizeof *a), *b = malloc(2 * NPTS * sizeof *b);
    double sa[DIM], sb[DIM], so[DIM];
    ck_assert(a && b);
    amscr_test_apply_affine(m, xy, NPTS, a);
    amscr_test_cyclic_shift(a, NPTS, shift, b);
    for (size_t i = 0; reverse && i < NPTS; i++) {
        a[2 * i] = b[2 * (NPTS - 1 - i)];
        a[2 * i + 1] = b[2 * (NPTS - 1 - i) + 1];
    }
    sig_of(xy, NPTS, share, sa);
    sig_of(reverse ? a : b, NPTS, share, sb);
    sig_of(other, NPTS, share, so);
    double between = amscr__affine_signature_distance(sa, so);
    ck_assert(between > 0.0);
    free(a);
    free(b);
    return amscr__affine_signature_distance(sa, sb) / between;
}

/* Random affine maps (reflections included) leave the whitened block unchanged. */
START_TEST(test_affine_invariance)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 17);
    double xy[2 * NPTS], other[2 * NPTS], worst = 0.0;
    for (int s = 0; s < 5; s++) {
        amscr_test_random_shape(&r, NPTS, 6, xy);
        amscr_test_random_shape(&r, NPTS, 6, other);
        for (int k = 0; k < 4; k++) {
            double m[6];
            amscr_test_random_affine(&r, 2.0, 0.5, 10.0, k % 2, m);
            double c = rel_change(xy, other, m, 0, 0, 1.0);
            worst = c > worst ? c : worst;
        }
    }
    ck_assert_msg(worst < TOL_AFFINE, "whitened block changed by %g of a between-shape distance", worst);
}
END_TEST

/* Rotations, uniform scales, translations and mirror images leave the similarity block (and
 * so the default signature) unchanged. */
START_TEST(test_similarity_invariance)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 23);
    double xy[2 * NPTS], other[2 * NPTS], worst = 0.0;
    for (int s = 0; s < 5; s++) {
        amscr_test_random_shape(&r, NPTS, 6, xy);
        amscr_test_random_shape(&r, NPTS, 6, other);
        for (int k = 0; k < 4; k++) {
            double th = 6.283185307179586 * amscr_test_uniform(&r), sc = 0.2 + 5.0 * amscr_test_uniform(&r);
            double f = k % 2 ? -1.0 : 1.0;
            double m[6] = {sc * cos(th), -f * sc * sin(th), 3.0, sc * sin(th), f * sc * cos(th), -7.0};
            double c = rel_change(xy, other, m, 0, 0, -1.0);
            worst = c > worst ? c : worst;
        }
    }
    ck_assert_msg(worst < TOL_SIM, "signature changed by %g of a between-shape distance", worst);
}
END_TEST

/* Another start point and the opposite direction leave the signature unchanged. */
START_TEST(test_start_and_direction)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 29);
    double xy[2 * NPTS], other[2 * NPTS], worst = 0.0;
    const double id[6] = {1, 0, 0, 0, 1, 0};
    for (int s = 0; s < 5; s++) {
        amscr_test_random_shape(&r, NPTS, 6, xy);
        amscr_test_random_shape(&r, NPTS, 6, other);
        for (int k = 0; k < 4; k++) {
            size_t shift = 1 + (size_t)(amscr_test_uniform(&r) * (NPTS - 1));
            double c = rel_change(xy, other, id, k % 2, shift, -1.0);
            worst = c > worst ? c : worst;
        }
    }
    ck_assert_msg(worst < TOL_START, "signature changed by %g of a between-shape distance", worst);
}
END_TEST

/* Degenerate-but-valid shapes: a triangle, a thin sliver, a polygon with repeated points. */
START_TEST(test_degenerate_finite)
{
    double tri[6] = {0, 0, 1, 0, 0, 1}, tri_pts[2 * 12], sig[DIM];
    sig_of(tri_pts, amscr_test_polygon(tri, 3, 4, tri_pts), -1.0, sig);
    double sliver[2 * NPTS];
    amscr_test_ellipse(NPTS, 1.0, 1e-2, 0.0, sliver);
    sig_of(sliver, NPTS, -1.0, sig);
    double star[20], poly[2 * 200], twice[4 * 200];
    amscr_test_star5(star);
    size_t n = amscr_test_polygon(star, 10, 20, poly);
    for (size_t i = 0; i < n; i++) /* every point repeated */
        for (int t = 0; t < 2; t++) {
            twice[4 * i + 2 * t] = poly[2 * i];
            twice[4 * i + 2 * t + 1] = poly[2 * i + 1];
        }
    sig_of(twice, 2 * n, -1.0, sig);
    sig_of(twice, 2 * n, 1.0, sig);
}
END_TEST

/* The same input gives the same bits; the distance is 0 on itself and symmetric. */
START_TEST(test_deterministic)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 31);
    double xy[2 * NPTS], other[2 * NPTS], a[DIM], b[DIM], o[DIM];
    amscr_test_random_shape(&r, NPTS, 6, xy);
    amscr_test_random_shape(&r, NPTS, 6, other);
    sig_of(xy, NPTS, -1.0, a);
    sig_of(xy, NPTS, -1.0, b);
    sig_of(other, NPTS, -1.0, o);
    ck_assert(memcmp(a, b, sizeof a) == 0);
    ck_assert(amscr__affine_signature_distance(a, b) == 0.0);
    ck_assert(amscr__affine_signature_distance(a, o) > 0.0);
    ck_assert(amscr__affine_signature_distance(a, o) == amscr__affine_signature_distance(o, a));
}
END_TEST

Suite *amscr_suite_signature(void)
{
    Suite *s = suite_create("signature");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_affine_invariance);
    tcase_add_test(tc, test_similarity_invariance);
    tcase_add_test(tc, test_start_and_direction);
    tcase_add_test(tc, test_degenerate_finite);
    tcase_add_test(tc, test_deterministic);
    suite_add_tcase(s, tc);
    return s;
}
