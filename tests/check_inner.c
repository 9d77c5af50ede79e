/* check_inner.c — the inner-distance graph of the re-ranking (src/retrieval/inner.c): the pair
 * distance against a brute-force search over shifts and orientations (direct DFTs for the
 * low-pass along the curve), invariance under
 * similarity maps and mirror images, tolerance to a bent part, degenerate curves, the
 * collection matrix for any thread count, and the retrieval matrix with the graph's share; the
 * silhouette closed at a scale (src/shape/closing.c): slots close, wide notches stay, invariance,
 * the prepared shape's outline and its round trip through a file. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h"
#include "inner.h"
#include "suites.h"
#include "testutil.h"

#define NPTS 400

/* A body (4 x 2) with one arm of width 0.4 and length 4: straight, bent up at its middle, or
 * (kind 2) two short arms on opposite sides instead. */
static size_t body(int kind, const double m[6], double *xy)
{
    static const double straight[] = {0, 0, 4, 0, 4, 0.8, 8, 0.8, 8, 1.2, 4, 1.2, 4, 2, 0, 2};
    static const double bent[] = {0, 0, 4, 0, 4, 0.8, 6.2, 0.8, 6.2, 3.0, 5.8, 3.0, 5.8, 1.2, 4, 1.2, 4, 2, 0, 2};
    static const double two[] = {0, 0, 4, 0, 4, 0.8, 6, 0.8, 6, 1.2, 4, 1.2,
                                 4, 2, 0, 2, 0, 1.2, -2, 1.2, -2, 0.8, 0, 0.8};
    const double *v = kind == 0 ? straight : kind == 1 ? bent : two;
    size_t nv = kind == 0 ? 8 : kind == 1 ? 10 : 12;
    double tmp[2 * NPTS];
    size_t n = amscr_test_polygon(v, nv, 30, tmp); /* at most 12 x 30 < NPTS points */
    amscr_test_apply_affine(m, tmp, n, xy);
    return n;
}

static const double ident[6] = {1, 0, 0, 0, 1, 0};

typedef struct {
    amscr__inner f;
    double id[AMSCR__INNER_N * AMSCR__INNER_N];
} feat;

static void build(const double *xy, size_t n, feat *out, amscr__inner_ws *ws)
{
    ck_assert_int_eq(amscr__inner_build(xy, n, &out->f, ws), AMSCR_OK);
    memcpy(out->id, ws->id, sizeof out->id);
}

/* The offset form of M (N x N): J[k][i] = M[i][i + k], each column low-passed to the
 * frequencies |f| < AMSCR__INNER_F by a direct DFT. */
static void lowpassed_offsets(const double *M, double *J)
{
    const size_t n = AMSCR__INNER_N;
    double c[AMSCR__INNER_N];
    for (size_t m = 0; m < n; m++)
        c[m] = cos(2.0 * 3.14159265358979323846 * (double)m / (double)n);
    for (size_t k = 0; k < n; k++) {
        double col[AMSCR__INNER_N];
        for (size_t i = 0; i < n; i++)
            col[i] = M[i * n + (i + k) % n];
        for (size_t t = 0; t < n; t++) {
            double v = 0.0;
            for (size_t f = 0; f < n; f++) {
                if (f >= AMSCR__INNER_F && n - f >= AMSCR__INNER_F)
                    continue;
                for (size_t i = 0; i < n; i++)
                    v += col[i] * c[(f * ((t + n - i) % n)) % n];
            }
            J[k * n + t] = v / (double)n;
        }
    }
}

/* min over shifts s (and orientations: B's vertices reversed) of the RMS difference of the
 * low-passed offset forms of A and B. */
static double brute(const double *A, const double *B, int reflections)
{
    const size_t n = AMSCR__INNER_N;
    double *ja = malloc(n * n * sizeof *ja), *jb = malloc(n * n * sizeof *jb), *rb = malloc(n * n * sizeof *rb);
    double best = INFINITY;
    lowpassed_offsets(A, ja);
    for (int o = 0; o < (reflections ? 2 : 1); o++) {
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                rb[i * n + j] = o ? B[((n - i) % n) * n + (n - j) % n] : B[i * n + j];
        lowpassed_offsets(rb, jb);
        for (size_t s = 0; s < n; s++) {
            double sum = 0.0;
            for (size_t k = 1; k < n; k++)
                for (size_t i = 0; i < n; i++) {
                    double d = ja[k * n + i] - jb[k * n + (i + s) % n];
                    sum += d * d;
                }
            if (sum < best)
                best = sum;
        }
    }
    free(ja);
    free(jb);
    free(rb);
    return sqrt(best / (double)(n * n));
}

START_TEST(test_against_brute_force)
{
    amscr__inner_ws ws;
    ck_assert_int_eq(amscr__inner_ws_init(&ws), AMSCR_OK);
    double xy[2 * NPTS];
    feat *f = malloc(3 * sizeof *f);
    for (int k = 0; k < 3; k++)
        build(xy, body(k, ident, xy), &f[k], &ws);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            for (int refl = 0; refl < 2; refl++) {
                double fast = amscr__inner_distance(&f[a].f, &f[b].f, refl, &ws);
                double slow = brute(f[a].id, f[b].id, refl);
                /* the features are int16 with a per-shape scale (inner.h): agreement to ~1e-5 */
                ck_assert_msg(fabs(fast - slow) <= 5e-5 * (1.0 + slow), "%d-%d refl %d: %.12g vs %.12g", a, b, refl,
                              fast, slow);
                if (a == b)
                    ck_assert(fast == 0.0);
            }
    free(f);
    amscr__inner_ws_free(&ws);
}
END_TEST

/* A similarity copy (rotated, scaled, moved, started elsewhere) and a mirror image are near 0
 * (the resampling differs only by where it starts); the bent arm is much nearer than the
 * other shape; a curve with no extent is refused. */
START_TEST(test_invariance_and_articulation)
{
    amscr__inner_ws ws;
    ck_assert_int_eq(amscr__inner_ws_init(&ws), AMSCR_OK);
    double c = cos(2.2), s = sin(2.2);
    const double sim[6] = {3 * c, -3 * s, 10, 3 * s, 3 * c, -4}, mir[6] = {-1.5, 0, 2, 0, 1.5, 1};
    double xy[2 * NPTS], sh[2 * NPTS];
    feat *f = malloc(5 * sizeof *f);
    build(xy, body(0, ident, xy), &f[0], &ws);
    size_t n = body(0, sim, xy);
    amscr_test_cyclic_shift(xy, n, n / 3, sh);
    build(sh, n, &f[1], &ws);
    build(xy, body(0, mir, xy), &f[2], &ws);
    build(xy, body(1, ident, xy), &f[3], &ws);
    build(xy, body(2, ident, xy), &f[4], &ws);
    double copy = amscr__inner_distance(&f[0].f, &f[1].f, 0, &ws);
    double mirror = amscr__inner_distance(&f[0].f, &f[2].f, 1, &ws);
    double bent = amscr__inner_distance(&f[0].f, &f[3].f, 1, &ws);
    double other = amscr__inner_distance(&f[0].f, &f[4].f, 1, &ws);
    ck_assert(amscr__inner_distance(&f[4].f, &f[4].f, 1, &ws) == 0.0);
    ck_assert_msg(copy < 0.1 * other && mirror < 0.1 * other, "copy %g mirror %g other %g", copy, mirror, other);
    ck_assert_msg(bent < 0.5 * other, "bent arm %g vs other shape %g", bent, other);
    ck_assert(fabs(amscr__inner_distance(&f[3].f, &f[4].f, 1, &ws) - amscr__inner_distance(&f[4].f, &f[3].f, 1, &ws)) <
              1e-9);
    double dot[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    ck_assert_int_eq(amscr__inner_build(dot, 4, &f[0].f, &ws), AMSCR_E_DEGENERATE);
    free(f);
    amscr__inner_ws_free(&ws);
}
END_TEST

static amscr_db *collection(const amscr_params *p, unsigned threads)
{
    amscr_params *q = NULL;
    ck_assert_int_eq(amscr_params_copy(p, &q), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(q, threads), AMSCR_OK);
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(q, &db), AMSCR_OK);
    amscr_params_free(q);
    amscr_test_rng r;
    double xy[2 * NPTS], w[2 * NPTS], m[6];
    for (int i = 0; i < 12; i++) {
        size_t n = body(i % 3, ident, xy);
        amscr_test_rng_seed(&r, 100u + (unsigned)i);
        amscr_test_random_affine(&r, 1.5, 0.0, 3.0, 0, m);
        amscr_test_apply_affine(m, xy, n, w);
        amscr_test_add_noise(&r, w, n, 0.005);
        amscr_contour *c = NULL;
        ck_assert_int_eq(amscr_contour_new(w, n, &c), AMSCR_OK);
        ck_assert_int_eq(amscr_db_add_contour(db, c, i % 3, NULL), AMSCR_OK);
        amscr_contour_free(c);
    }
    return db;
}

/* The collection's inner matrix: symmetric, zero diagonal, bit for bit the same on 1 and 3
 * threads; the retrieval matrix with the graph's share: the same on 1 and 3 threads, a zero
 * diagonal, values in [0, 1], and different from the one-graph matrix. */
START_TEST(test_matrices)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 3), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.3), AMSCR_OK);
    enum { n = 12 };
    double I1[n * n], I3[n * n], R1[n * n], R3[n * n], R0[n * n];
    amscr_db *d1 = collection(p, 1), *d3 = collection(p, 3);
    ck_assert_int_eq(amscr__inner_matrix(d1, 1, NULL, NULL, I1), AMSCR_OK);
    ck_assert_int_eq(amscr__inner_matrix(d3, 3, NULL, NULL, I3), AMSCR_OK);
    ck_assert(memcmp(I1, I3, sizeof I1) == 0);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            ck_assert(i == j ? I1[i * n + j] == 0.0 : I1[i * n + j] == I1[j * n + i] && I1[i * n + j] >= 0.0);
    ck_assert_int_eq(amscr_db_retrieval_matrix(d1, NULL, NULL, R1), AMSCR_OK);
    ck_assert_int_eq(amscr_db_retrieval_matrix(d3, NULL, NULL, R3), AMSCR_OK);
    ck_assert(memcmp(R1, R3, sizeof R1) == 0);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.0), AMSCR_OK);
    amscr_db *d0 = collection(p, 2);
    ck_assert_int_eq(amscr_db_retrieval_matrix(d0, NULL, NULL, R0), AMSCR_OK);
    int differ = 0;
    for (int i = 0; i < n * n; i++) {
        ck_assert(R1[i] >= 0.0 && R1[i] <= 1.0);
        differ |= R1[i] != R0[i];
    }
    for (int i = 0; i < n; i++)
        ck_assert(R1[i * n + i] == 0.0);
    ck_assert(differ);
    amscr_db_free(d0);
    amscr_db_free(d1);
    amscr_db_free(d3);
    amscr_params_free(p);
}
END_TEST

/* The setter: [0, 1) only; the presets: 0, and 0.1 for retrieval. */
START_TEST(test_params)
{
    amscr_params *p = NULL, *r = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_retrieval(&r), AMSCR_OK);
    ck_assert(amscr_params_get_rerank_inner_share(p) == 0.0);
    ck_assert(amscr_params_get_rerank_inner_share(r) == 0.1);
    ck_assert(amscr_params_get_rerank_inner_share(NULL) == 0.0);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, -0.1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 1.0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(NULL, 0.1), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_params_get_rerank_inner_share(p) == 0.0);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.5), AMSCR_OK);
    ck_assert(amscr_params_get_rerank_inner_share(p) == 0.5);
    amscr_params_free(p);
    amscr_params_free(r);
}
END_TEST

/* A 10 x 10 square with a notch of width `w` and depth 6 cut from its top edge (w 0: none), at
 * about 30 points an edge. */
static size_t notched(double w, const double m[6], double *xy)
{
    double a = 5.0 - 0.5 * w, b = 5.0 + 0.5 * w;
    const double sq[] = {0, 0, 10, 0, 10, 10, 0, 10};
    const double v[] = {0, 0, 10, 0, 10, 10, b, 10, b, 4, a, 4, a, 10, 0, 10};
    double tmp[2 * NPTS];
    size_t n = amscr_test_polygon(w > 0.0 ? v : sq, w > 0.0 ? 8 : 4, 30, tmp);
    amscr_test_apply_affine(m, tmp, n, xy);
    return n;
}

/* The closing at c = 0.08 (a disk of radius ~0.78 here): a slot 0.4 wide closes (the square's
 * area, its inner distances), a notch 4 wide stays; a similarity map of the slotted square gives
 * the same closed inner distances; a collinear curve bounds no area. */
START_TEST(test_closing)
{
    double xy[2 * NPTS], V[2 * AMSCR__OUTLINE_N], *out = NULL;
    size_t nout = 0, n = notched(0.4, ident, xy);
    ck_assert_int_eq(amscr__close_curve(xy, n, 0.08, &out, &nout), AMSCR_OK);
    ck_assert_msg(fabs(amscr_test_shoelace(out, nout) - 100.0) < 2.0, "slot closed: area %g", amscr_test_shoelace(out, nout));
    free(out);
    n = notched(4.0, ident, xy);
    ck_assert_int_eq(amscr__close_curve(xy, n, 0.08, &out, &nout), AMSCR_OK);
    ck_assert_msg(fabs(amscr_test_shoelace(out, nout) - 76.0) < 2.0, "notch kept: area %g", amscr_test_shoelace(out, nout));
    free(out);
    amscr__inner_ws ws;
    ck_assert_int_eq(amscr__inner_ws_init(&ws), AMSCR_OK);
    feat *f = malloc(4 * sizeof *f);
    const double sim[6] = {0.8 * cos(1.1), -0.8 * sin(1.1), 40, 0.8 * sin(1.1), 0.8 * cos(1.1), -7};
    build(xy, notched(0.0, ident, xy), &f[0], &ws);                     /* the square */
    build(xy, notched(0.4, ident, xy), &f[1], &ws);                     /* the slotted square */
    ck_assert_int_eq(amscr__outline(xy, notched(0.4, ident, xy), 0.08, V), AMSCR_OK);
    build(V, AMSCR__OUTLINE_N, &f[2], &ws);                             /* ... closed */
    ck_assert_int_eq(amscr__outline(xy, notched(0.4, sim, xy), 0.08, V), AMSCR_OK);
    build(V, AMSCR__OUTLINE_N, &f[3], &ws);                             /* ... moved, closed */
    double open = amscr__inner_distance(&f[0].f, &f[1].f, 1, &ws);
    double shut = amscr__inner_distance(&f[0].f, &f[2].f, 1, &ws);
    double moved = amscr__inner_distance(&f[2].f, &f[3].f, 1, &ws);
    ck_assert_msg(shut < 0.2 * open && moved < 0.2 * open, "slot %g, closed %g, moved %g", open, shut, moved);
    const double line[] = {0, 0, 1, 1, 2, 2, 3, 3};
    ck_assert_int_eq(amscr__outline(line, 4, 0.08, V), AMSCR_E_DEGENERATE);
    ck_assert_int_eq(amscr__close_curve(xy, n, 0.0, &out, &nout), AMSCR_E_DEGENERATE);
    free(f);
    amscr__inner_ws_free(&ws);
}
END_TEST

/* A prepared shape keeps the outline of its input points (all of them, not its samples) when its
 * params close the inner distance's silhouette, and its features under that closing are the
 * outline's (they differ from the samples'); not otherwise; a collection with it saved and loaded gives the same retrieval matrix bit for bit,
 * and a file whose outline is not finite is refused. */
START_TEST(test_outline_kept)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, 3), AMSCR_OK);
    double xy[2 * NPTS];
    size_t n = notched(0.4, ident, xy);
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL, *d0 = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, n, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_OK);
    ck_assert_ptr_nonnull(d->outline);
    double cl = amscr_params_get_inner_closing(p), V[2 * AMSCR__OUTLINE_N];
    ck_assert(cl > 0.0);
    ck_assert_int_eq(amscr__outline(xy, n, cl, V), AMSCR_OK); /* the contour is counter-clockwise */
    ck_assert(memcmp(V, d->outline, sizeof V) == 0);
    amscr__inner_ws ws;
    ck_assert_int_eq(amscr__inner_ws_init(&ws), AMSCR_OK);
    feat *f = malloc(3 * sizeof *f);
    ck_assert_int_eq(amscr__inner_build_shape(d, cl, &f[0].f, &ws), AMSCR_OK);
    ck_assert_int_eq(amscr__inner_build_shape(d, 0.0, &f[1].f, &ws), AMSCR_OK);
    build(d->outline, AMSCR__OUTLINE_N, &f[2], &ws);
    ck_assert(amscr__inner_distance(&f[0].f, &f[2].f, 1, &ws) == 0.0);
    ck_assert(amscr__inner_distance(&f[0].f, &f[1].f, 1, &ws) > 0.0);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d0), AMSCR_OK);
    ck_assert_ptr_null(d0->outline);
    amscr_descriptor_free(d0);
    amscr_descriptor_free(d);
    amscr_contour_free(c);
    free(f);
    amscr__inner_ws_free(&ws);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, cl), AMSCR_OK);
    enum { m = 12 };
    double R[m * m], B[m * m];
    amscr_db *db = collection(p, 2), *back = NULL;
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, R), AMSCR_OK);
    ck_assert_int_eq(amscr_db_save_memory(db, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_db_load_memory(buf, len, &back), AMSCR_OK);
    ck_assert_int_eq(amscr_db_retrieval_matrix(back, NULL, NULL, B), AMSCR_OK);
    ck_assert(memcmp(R, B, sizeof R) == 0);
    amscr_db_free(back);
    back = NULL;
    unsigned char *b = buf;
    double nan = NAN;
    amscr_test_put_le(b + len - 8 - 8 * AMSCR__OUTLINE_N, &nan, 8); /* in the last shape's outline */
    uint64_t h = amscr__fnv1a(b, len - 8);                         /* the plain file's trailer */
    amscr_test_put_le(b + len - 8, &h, 8);
    ck_assert_int_eq(amscr_db_load_memory(buf, len, &back), AMSCR_E_FORMAT);
    ck_assert_msg(strstr(amscr_last_error_detail(), "non-finite") != NULL, "refused for another reason: %s",
                  amscr_last_error_detail()); /* not the checksum */
    ck_assert_ptr_null(back);
    amscr_free(buf);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* The closing's setter: [0, 1] only; the presets: 0, and 0.04 for retrieval. */
START_TEST(test_closing_params)
{
    amscr_params *p = NULL, *r = NULL;
    ck_assert_int_eq(amscr_params_new(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_new_retrieval(&r), AMSCR_OK);
    ck_assert(amscr_params_get_inner_closing(p) == 0.0);
    ck_assert(amscr_params_get_inner_closing(r) == 0.04);
    ck_assert(amscr_params_get_inner_closing(NULL) == 0.0);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, -0.01), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, 1.5), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, NAN), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_params_set_inner_closing(NULL, 0.1), AMSCR_E_INVALID_ARG);
    ck_assert(amscr_params_get_inner_closing(p) == 0.0);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, 1.0), AMSCR_OK);
    ck_assert(amscr_params_get_inner_closing(p) == 1.0);
    amscr_params_free(p);
    amscr_params_free(r);
}
END_TEST

Suite *amscr_suite_inner(void)
{
    Suite *s = suite_create("inner");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_against_brute_force);
    tcase_add_test(tc, test_invariance_and_articulation);
    tcase_add_test(tc, test_matrices);
    tcase_add_test(tc, test_params);
    tcase_add_test(tc, test_closing);
    tcase_add_test(tc, test_outline_kept);
    tcase_add_test(tc, test_closing_params);
    suite_add_tcase(s, tc);
    return s;
}
