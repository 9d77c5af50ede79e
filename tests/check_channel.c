/* check_channel.c — the shape channel (amscr_channel_distance, amscr_db_channel_matrix) and
 * the fused retrieval matrix: invariance under the channel's group, self-distance 0, the
 * matrix against the pair function, articulation tolerance, the shift search, the
 * side-by-side DPs against the one-pair DP, and bad input. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>

#include "channel.h"
#include "suites.h"

#define NPTS 400
#define PI 3.14159265358979323846

/* r(t) = 1 + a cos(k1 t) + b sin(k2 t), optionally with one "limb" bent: the lobe around
 * t0 is moved sideways along the curve by `bend` radians (an articulation-like change). */
static amscr_contour *radial(double a, int k1, double b, int k2, double bend, const double m[6])
{
    double xy[2 * NPTS];
    for (int i = 0; i < NPTS; i++) {
        double t = 2.0 * PI * i / NPTS;
        double w = exp(-pow((t - PI) / 0.35, 2.0));
        double r = 1.0 + a * cos(k1 * (t - bend * w)) + b * sin(k2 * t);
        double x = r * cos(t), y = r * sin(t);
        xy[2 * i] = m[0] * x + m[1] * y + m[2];
        xy[2 * i + 1] = m[3] * x + m[4] * y + m[5];
    }
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, NPTS, &c), AMSCR_OK);
    return c;
}

static const double ident[6] = {1, 0, 0, 0, 1, 0};

static amscr_descriptor *prep(const amscr_params *p, amscr_contour *c)
{
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_OK);
    amscr_contour_free(c);
    return d;
}

static double chan(const amscr_params *p, const amscr_descriptor *a, const amscr_descriptor *b)
{
    double d = -1.0;
    ck_assert_int_eq(amscr_channel_distance(p, a, b, &d), AMSCR_OK);
    ck_assert(isfinite(d) && d >= 0.0);
    return d;
}

/* Under the affine frame, an affine copy (rotation, anisotropic scale, shear, translation,
 * and a mirror image with reflections on) is much closer than another shape; the similarity
 * frame keeps rotated and scaled copies close. */
START_TEST(test_invariance)
{
    for (int frame = 0; frame < 2; frame++) {
        amscr_params *p = NULL;
        ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
        amscr_invariance inv = frame ? AMSCR_INVARIANCE_SIMILARITY : AMSCR_INVARIANCE_AFFINE;
        ck_assert_int_eq(amscr_params_set_channel_invariance(p, inv), AMSCR_OK);
        double c = cos(1.1), s = sin(1.1);
        double aff[6] = {1.7 * c, -0.6 * s + 0.5, 3.0, 1.7 * s, 0.6 * c, -2.0};
        double sim[6] = {2.5 * c, -2.5 * s, 3.0, 2.5 * s, 2.5 * c, -2.0};
        double mir[6] = {-0.9, 0.2, 1.0, 0.3, 1.4, 0.0};
        const double *m = frame ? sim : aff;
        amscr_descriptor *f = prep(p, radial(0.3, 5, 0.1, 3, 0.0, ident));
        amscr_descriptor *g = prep(p, radial(0.3, 5, 0.1, 3, 0.0, m));
        amscr_descriptor *o = prep(p, radial(0.35, 3, 0.15, 2, 0.0, ident));
        double same = chan(p, f, g), other = chan(p, f, o);
        /* the copy starts at the same point, so its samples are the map's images of f's: the
         * distance is exactly 0 in both frames (measured; the other shape: 3.80 / 3.99) */
        ck_assert_msg(same == 0.0, "frame %d: copy %g (exactly 0 expected) vs other shape %g", frame, same, other);
        ck_assert_msg(other > 1.0, "frame %d: other shape %g", frame, other);
        if (!frame) {
            amscr_descriptor *r = prep(p, radial(0.3, 5, 0.1, 3, 0.0, mir));
            double mirrored = chan(p, f, r);
            /* re-oriented counter-clockwise, the mirror image starts elsewhere: measured 0.391
             * against 3.80 for the other shape (10 %) */
            ck_assert_msg(mirrored < 0.15 * other, "mirror %g vs other %g", mirrored, other);
            amscr_descriptor_free(r);
        }
        amscr_descriptor_free(f);
        amscr_descriptor_free(g);
        amscr_descriptor_free(o);
        amscr_params_free(p);
    }
}
END_TEST

/* The frames' rule: with the affine-view factor f a pair's channel distance is min(m, f d_a),
 * m the shares' mix, d_a the whitened frame's distance (read with the affine share 1, the
 * bands made equal so that the frame alone is computed as in the mix); with f = 0 it is m. A
 * sheared and stretched copy of a shape is ranked by the whitened frame, a bent copy and
 * another shape keep the mix. */
START_TEST(test_affine_view_rule)
{
    amscr_params *p = NULL, *ps = NULL, *pa = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_view(p) == 2.0);
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, amscr_params_get_channel_band(p)), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_retrieval(&ps), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_retrieval(&pa), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_share(ps, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_share(pa, 1.0), AMSCR_OK);
    double sh[6] = {1.6, 0.9, 0.0, -0.2, 0.55, 1.0}; /* stretched x1.6 / x0.55, sheared */
    amscr_descriptor *f = prep(p, radial(0.3, 5, 0.1, 3, 0.0, ident));
    amscr_descriptor *g[3] = {prep(p, radial(0.3, 5, 0.1, 3, 0.02, sh)), prep(p, radial(0.3, 5, 0.1, 3, 0.25, ident)),
                              prep(p, radial(0.35, 3, 0.15, 2, 0.0, ident))};
    double s = amscr_params_get_channel_affine_share(p);
    for (int i = 0; i < 3; i++) {
        double ds = chan(ps, f, g[i]), da = chan(pa, f, g[i]), m = (1.0 - s) * ds + s * da;
        double want = 2.0 * da < m ? 2.0 * da : m;
        ck_assert_msg(chan(p, f, g[i]) == want, "pair %d: %g, want min(%g, 2 x %g)", i, chan(p, f, g[i]), m, da);
        if (i == 0)
            ck_assert_msg(2.0 * da < m, "the affine copy: whitened %g, mix %g", da, m);
        else
            ck_assert_msg(2.0 * da >= m, "pair %d keeps the mix: whitened %g, mix %g", i, da, m);
        ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 0.0), AMSCR_OK);
        ck_assert(chan(p, f, g[i]) == m);
        ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 2.0), AMSCR_OK);
        /* one frame: the factor changes nothing */
        ck_assert(chan(ps, f, g[i]) == ds);
    }
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 0.5), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, -1.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 101.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(NULL, 2.0), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_params_get_channel_affine_view(p) == 2.0);
    ck_assert(amscr_params_get_channel_affine_view(NULL) == 0.0);
    amscr_params *base = NULL;
    ck_assert_int_eq(amscr_params_new(&base), AMSCR_OK);
    ck_assert(amscr_params_get_channel_affine_view(base) == 0.0);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(base, 1.0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(base, 100.0), AMSCR_OK);
    amscr_params_free(base);
    amscr_descriptor_free(f);
    for (int i = 0; i < 3; i++)
        amscr_descriptor_free(g[i]);
    amscr_params_free(p);
    amscr_params_free(ps);
    amscr_params_free(pa);
}
END_TEST

START_TEST(test_self_zero_and_articulation)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    amscr_descriptor *f = prep(p, radial(0.3, 5, 0.1, 3, 0.0, ident));
    amscr_descriptor *bent = prep(p, radial(0.3, 5, 0.1, 3, 0.25, ident));
    amscr_descriptor *o = prep(p, radial(0.35, 3, 0.15, 2, 0.0, ident));
    ck_assert(chan(p, f, f) == 0.0);
    ck_assert(chan(NULL, o, o) == 0.0);
    /* a bent lobe stays closer than a different shape */
    ck_assert(chan(p, f, bent) < 0.5 * chan(p, f, o));
    amscr_descriptor_free(f);
    amscr_descriptor_free(bent);
    amscr_descriptor_free(o);
    amscr_params_free(p);
}
END_TEST

/* The collection matrices: channel matrix = the pair function for i < j, mirrored, zero
 * diagonal; the same for any thread count; the retrieval matrix is in [0, 1] with a zero
 * diagonal and ranks each shape's bent and affine copies before the other family. */
START_TEST(test_matrices)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 3), AMSCR_OK);
    double sh[6] = {1.2, 0.3, 0.0, -0.1, 0.9, 1.0};
    amscr_contour *cs[6] = {radial(0.3, 5, 0.1, 3, 0.0, ident), radial(0.3, 5, 0.1, 3, 0.2, ident),
                            radial(0.3, 5, 0.1, 3, 0.1, sh),    radial(0.35, 3, 0.15, 2, 0.0, ident),
                            radial(0.35, 3, 0.15, 2, 0.2, ident), radial(0.35, 3, 0.15, 2, 0.1, sh)};
    double M[36], M1[36], R[36];
    for (int th = 0; th < 2; th++) {
        ck_assert_int_eq(amscr_params_set_num_threads(p, th ? 1 : 2), AMSCR_OK);
        amscr_db *db = NULL;
        ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
        for (int i = 0; i < 6; i++)
            ck_assert_int_eq(amscr_db_add_contour(db, cs[i], i / 3, NULL), AMSCR_OK);
        ck_assert_int_eq(amscr_db_channel_matrix(db, NULL, NULL, th ? M1 : M), AMSCR_OK);
        if (!th) {
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++) {
                    if (i == j)
                        ck_assert(M[i * 6 + j] == 0.0);
                    ck_assert(M[i * 6 + j] == M[j * 6 + i]);
                    if (i < j)
                        ck_assert(M[i * 6 + j] == chan(p, amscr_db_descriptor(db, i), amscr_db_descriptor(db, j)));
                }
            ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, R), AMSCR_OK);
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++) {
                    ck_assert(R[i * 6 + j] >= 0.0 && R[i * 6 + j] <= 1.0);
                    if (i == j)
                        ck_assert(R[i * 6 + j] == 0.0);
                    else if (i / 3 == j / 3)
                        for (int k = 0; k < 6; k++)
                            if (k / 3 != i / 3)
                                ck_assert_msg(R[i * 6 + j] < R[i * 6 + k], "%d: %d vs %d", i, j, k);
                }
            /* each group (one shape of each family) held out: its own entries +infinity, the
             * others in [0, 1], the family's other shapes first */
            int32_t grp[6] = {0, 1, 2, 0, 1, 2};
            double Hd[36];
            ck_assert_int_eq(amscr_db_retrieval_matrix_heldout(db, grp, 6, NULL, NULL, Hd), AMSCR_OK);
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++) {
                    if (i == j)
                        ck_assert(Hd[i * 6 + j] == 0.0);
                    else if (grp[i] == grp[j])
                        ck_assert(isinf(Hd[i * 6 + j]) && Hd[i * 6 + j] > 0);
                    else
                        ck_assert(Hd[i * 6 + j] >= 0.0 && Hd[i * 6 + j] <= 1.0);
                    for (int k = 0; k < 6; k++)
                        if (j != i && grp[j] != grp[i] && i / 3 == j / 3 && k / 3 != i / 3)
                            ck_assert_msg(Hd[i * 6 + j] < Hd[i * 6 + k], "held out %d: %d vs %d", i, j, k);
                }
            ck_assert_int_eq(amscr_db_retrieval_matrix_heldout(db, grp, 5, NULL, NULL, Hd), AMSCR_E_INVALID_ARG);
            ck_assert_int_eq(amscr_db_retrieval_matrix_heldout(db, NULL, 6, NULL, NULL, Hd), AMSCR_E_INVALID_ARG);
            int32_t one[6] = {7, 7, 7, 7, 7, 7};
            ck_assert_int_eq(amscr_db_retrieval_matrix_heldout(db, one, 6, NULL, NULL, Hd), AMSCR_E_INVALID_ARG);
            /* AMSCR and the channel fused half and half, without re-ranking: symmetric, finite,
             * zero diagonal */
            amscr_params *q = NULL;
            ck_assert_int_eq(amscr_params_copy(p, &q), AMSCR_OK);
            ck_assert_int_eq(amscr_params_set_rerank_k(q, 0), AMSCR_OK);
            ck_assert_int_eq(amscr_params_set_channel_weight(q, 0.5), AMSCR_OK);
            amscr_db *fdb = NULL;
            ck_assert_int_eq(amscr_db_new(q, &fdb), AMSCR_OK);
            for (int i = 0; i < 6; i++)
                ck_assert_int_eq(amscr_db_add_descriptor(fdb, amscr_db_descriptor(db, i), i / 3, NULL), AMSCR_OK);
            ck_assert_int_eq(amscr_db_retrieval_matrix(fdb, NULL, NULL, R), AMSCR_OK);
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++) {
                    ck_assert(isfinite(R[i * 6 + j]) && R[i * 6 + j] >= 0.0);
                    ck_assert(R[i * 6 + j] == R[j * 6 + i]);
                    if (i == j)
                        ck_assert(R[i * 6 + j] == 0.0);
                }
            amscr_db_free(fdb);
            amscr_params_free(q);
        }
        amscr_db_free(db);
    }
    for (int i = 0; i < 36; i++)
        ck_assert(M[i] == M1[i]);
    for (int i = 0; i < 6; i++)
        amscr_contour_free(cs[i]);
    amscr_params_free(p);
}
END_TEST

static int cancel_cb(void *user, size_t done, size_t total)
{
    (void)user;
    (void)total;
    return done > 0;
}

START_TEST(test_bad_input)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    amscr_descriptor *f = prep(p, radial(0.3, 5, 0.1, 3, 0.0, ident));
    double d = 0.0;
    ck_assert_int_eq(amscr_channel_distance(p, NULL, f, &d), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_channel_distance(p, f, NULL, &d), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_channel_distance(p, f, f, NULL), AMSCR_E_INVALID_ARG);
    /* different N */
    amscr_params *q = NULL;
    ck_assert_int_eq(amscr_params_copy(p, &q), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(q, 64), AMSCR_OK);
    amscr_descriptor *g = prep(q, radial(0.3, 5, 0.1, 3, 0.0, ident));
    ck_assert_int_eq(amscr_channel_distance(p, f, g, &d), AMSCR_E_INVALID_ARG);
    /* open curves */
    ck_assert_int_eq(amscr_params_set_closed(q, 0), AMSCR_OK);
    amscr_descriptor *h = prep(q, radial(0.3, 5, 0.1, 3, 0.0, ident));
    ck_assert_int_eq(amscr_channel_distance(q, h, h, &d), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(q, &db), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_descriptor(db, h, 0, NULL), AMSCR_OK);
    double m[1];
    ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, m), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_channel_matrix(db, NULL, NULL, m), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_channel_matrix(NULL, NULL, NULL, m), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, NULL), AMSCR_E_INVALID_ARG);
    amscr_db_free(db);
    /* cancellation leaves no partial matrix */
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (int i = 0; i < 3; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(db, f, i, NULL), AMSCR_OK);
    double m9[9];
    ck_assert_int_eq(amscr_db_channel_matrix(db, cancel_cb, NULL, m9), AMSCR_E_CANCELLED);
    for (int i = 0; i < 9; i++)
        ck_assert(isnan(m9[i]));
    int32_t g3[3] = {0, 1, 1};
    ck_assert_int_eq(amscr_db_retrieval_matrix_heldout(db, g3, 3, cancel_cb, NULL, m9), AMSCR_E_CANCELLED);
    for (int i = 0; i < 9; i++)
        ck_assert(isnan(m9[i]));
    amscr_db_free(db);
    /* setters reject what they cannot use */
    ck_assert_int_eq(amscr_params_set_channel_weight(p, 1.5), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_weight(p, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_band(p, 0.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_band(p, 0.6), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, 0.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_skip(p, -0.1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_locality(p, INFINITY), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_invariance(p, AMSCR_INVARIANCE_PENALIZED), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_rerank_iterations(p, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 1001), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_channel_weight(NULL, 1.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_new_retrieval(NULL), AMSCR_E_INVALID_ARG);
    /* defaults: off in the plain params, on in the retrieval preset */
    amscr_params *plain = NULL;
    ck_assert_int_eq(amscr_params_new(&plain), AMSCR_OK);
    ck_assert(amscr_params_get_channel_weight(plain) == 0.0);
    ck_assert_uint_eq(amscr_params_get_rerank_k(plain), 0);
    ck_assert(amscr_params_get_channel_weight(p) > 0.0);
    ck_assert_uint_eq(amscr_params_get_rerank_k(p), 8);
    amscr_params_free(plain);
    amscr_descriptor_free(f);
    amscr_descriptor_free(g);
    amscr_descriptor_free(h);
    amscr_params_free(q);
    amscr_params_free(p);
}
END_TEST

/* The shift search finds the cyclic shift and the orientation: a curve against its samples
 * rotated by more than the band, and against its mirror image rotated, is at distance 0
 * exactly in a band of 3 samples (the DP could not bridge the shift); without reflections
 * the mirror image is not. The side-by-side entry agrees. */
START_TEST(test_shift_search)
{
    enum { N = 128 };
    double xy[2 * N], rot[2 * N], mir[2 * N];
    for (int i = 0; i < N; i++) {
        double t = 2.0 * PI * i / N, r = 1.0 + 0.3 * cos(3 * t + 0.4) + 0.2 * sin(5 * t) + 0.1 * cos(7 * t);
        xy[2 * i] = 1.3 * r * cos(t);
        xy[2 * i + 1] = r * sin(t);
    }
    amscr__hf a, b, m;
    amscr__hf_ws ws;
    ck_assert_int_eq(amscr__hf_build(xy, N, 4.0, &a), AMSCR_OK);
    ck_assert_int_eq(amscr__hf_ws_init(&ws, N, 3), AMSCR_OK);
    const int shifts[3] = {37, 64, 101};
    for (int s = 0; s < 3; s++) {
        for (int i = 0; i < N; i++) {
            int j = (i + shifts[s]) % N, k = (N - 1 - i + shifts[s]) % N; /* mirror: x -> -x, reversed */
            rot[2 * i] = xy[2 * j];
            rot[2 * i + 1] = xy[2 * j + 1];
            mir[2 * i] = -xy[2 * k];
            mir[2 * i + 1] = xy[2 * k + 1];
        }
        ck_assert_int_eq(amscr__hf_build(rot, N, 4.0, &b), AMSCR_OK);
        ck_assert_int_eq(amscr__hf_build(mir, N, 4.0, &m), AMSCR_OK);
        amscr__hf_cfg on = {3, 1.0, 1, 0, 1}, off = {3, 1.0, 0, 0, 1};
        ck_assert_msg(amscr__hf_distance(&a, &b, &off, &ws) == 0.0, "shift %d", shifts[s]);
        ck_assert_msg(amscr__hf_distance(&a, &m, &on, &ws) == 0.0, "mirrored, shift %d", shifts[s]);
        ck_assert(amscr__hf_distance(&a, &m, &off, &ws) > 0.1);
        const amscr__hf *l[3] = {&a, &a, &b}, *r[3] = {&b, &m, &a};
        double d[3] = {-1, -1, -1};
        amscr__hf_distances(l, r, 3, &on, &ws, d);
        ck_assert(d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0);
        amscr__hf_free(&b);
        amscr__hf_free(&m);
    }
    amscr__hf_ws_free(&ws);
    amscr__hf_free(&a);
}
END_TEST

/* The side-by-side pair distances (the collection matrix's and the index's) equal the one-pair
 * distance bit for bit: pairs of different first shapes, every count of pairs 1-8 (eight DPs
 * in AVX2 lanes when the processor has them, groups of four otherwise and for the last four
 * or fewer), bands up to N/2, both strides, skip costs, one or both orientations, reflections
 * on and off; height sequences of random curves (N 128). */
START_TEST(test_side_by_side)
{
    enum { NS = 12, N = 128 };
    ck_assert(amscr__hf_lanes() == 4 || amscr__hf_lanes() == 8);
    amscr__hf hf[NS];
    double xy[2 * N];
    for (int k = 0; k < NS; k++) {
        for (int i = 0; i < N; i++) {
            double t = 2.0 * PI * i / N;
            double r = 1.0 + 0.3 * cos((k % 4 + 2) * t + k) + 0.15 * sin((k % 3 + 5) * t) + 0.05 * cos(11 * t * k);
            xy[2 * i] = (1.0 + 0.1 * k) * r * cos(t);
            xy[2 * i + 1] = r * sin(t);
        }
        ck_assert_int_eq(amscr__hf_build(xy, N, 4.0, &hf[k]), AMSCR_OK);
    }
    const size_t bands[3] = {3, 19, N / 2};
    amscr__hf_ws ws;
    ck_assert_int_eq(amscr__hf_ws_init(&ws, N, N / 2), AMSCR_OK);
    for (int c = 0; c < 3 * 2 * 2 * 2 * 2; c++) {
        amscr__hf_cfg cfg = {bands[c % 3], (c / 3) % 2 ? 0.5 : 1.25, (c / 6) % 2, (c / 12) % 2,
                             (size_t)1 + (c / 24) % 2};
        for (size_t count = 1; count <= AMSCR__HF_GROUP; count++)
            for (size_t j = 1; j + count <= NS; j += count) {
                double four[AMSCR__HF_GROUP] = {-1, -1, -1, -1, -1, -1, -1, -1};
                const amscr__hf *a[AMSCR__HF_GROUP], *b[AMSCR__HF_GROUP]; /* lane t: (j + t, 0) when t is odd, else (0, j + t) */
                for (size_t t = 0; t < count; t++) {
                    a[t] = t % 2 ? &hf[j + t] : &hf[0];
                    b[t] = t % 2 ? &hf[0] : &hf[j + t];
                }
                amscr__hf_distances(a, b, count, &cfg, &ws, four);
                for (size_t t = 0; t < count; t++) {
                    double one = amscr__hf_distance(a[t], b[t], &cfg, &ws);
                    ck_assert_msg(four[t] == one && one > 0.0, "config %d count %zu pair %zu: %.17g vs %.17g", c,
                                  count, j + t, four[t], one);
                }
                for (size_t t = count; t < AMSCR__HF_GROUP; t++)
                    ck_assert(four[t] == -1.0); /* nothing written past count */
            }
    }
    amscr__hf_ws_free(&ws);
    for (int k = 0; k < NS; k++)
        amscr__hf_free(&hf[k]);
}
END_TEST

Suite *amscr_suite_channel(void)
{
    Suite *s = suite_create("channel");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_invariance);
    tcase_add_test(tc, test_affine_view_rule);
    tcase_add_test(tc, test_self_zero_and_articulation);
    tcase_add_test(tc, test_matrices);
    tcase_add_test(tc, test_side_by_side);
    tcase_add_test(tc, test_shift_search);
    tcase_add_test(tc, test_bad_input);
    suite_add_tcase(s, tc);
    return s;
}
