/* check_shards.c — an index split in shards (amscr_index_pair_distances, amscr_index_graph_*):
 * lists merged from the pair distances of two blocks equal the single index's, and a query's
 * scores from its distances to the blocks equal amscr_index_query_scores with every shape a
 * candidate, and a member's (the member rule) amscr_index_member_scores; the signatures and
 * shortlists of a shortlist build in shards; bad lists and arguments are errors. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "index.h"
#include "suites.h"
#include "testutil.h"

#define NPTS 200
#define NSHAPES 24
#define CUT 10 /* block 0: shapes 0..CUT-1, block 1: the rest */

static amscr_params *params_of(double share)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(p, 64), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, share), AMSCR_OK);
    return p;
}

/* Shape `i`: one of 6 random base shapes, affinely warped (duplicates: i and i + 18). */
static amscr_descriptor *shape(const amscr_params *p, unsigned i)
{
    amscr_test_rng r;
    double xy[2 * NPTS], w[2 * NPTS], m[6];
    amscr_test_rng_seed(&r, 1000 + i % 6);
    amscr_test_random_shape(&r, NPTS, 5, xy);
    amscr_test_rng_seed(&r, 77 + (i >= 18 ? i - 18 : i));
    amscr_test_random_affine(&r, 2.0, 0.5, 3.0, 0, m);
    amscr_test_apply_affine(m, xy, NPTS, w);
    amscr_test_add_noise(&r, w, NPTS, 0.01);
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_contour_new(w, NPTS, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_OK);
    amscr_contour_free(c);
    return d;
}

static amscr_db *db_of(const amscr_params *p, unsigned lo, unsigned hi)
{
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (unsigned i = lo; i < hi; i++) {
        amscr_descriptor *d = shape(p, i);
        ck_assert_int_eq(amscr_db_add_descriptor(db, d, 0, NULL), AMSCR_OK);
        amscr_descriptor_free(d);
    }
    return db;
}

/* Row i's list: itself, then k - 1 others by (distance, index). */
static void list_of(const double *row, size_t n, size_t i, size_t k, uint32_t *idx, double *dist)
{
    unsigned char *used = calloc(n, 1);
    idx[0] = (uint32_t)i;
    dist[0] = 0.0;
    used[i] = 1;
    for (size_t t = 1; t < k; t++) {
        size_t best = n;
        for (size_t j = 0; j < n; j++)
            if (!used[j] && (best == n || row[j] < row[best]))
                best = j;
        used[best] = 1;
        idx[t] = (uint32_t)best;
        dist[t] = row[best];
    }
    free(used);
}

static void sharded_case(double share)
{
    amscr_params *p = params_of(share);
    amscr_db *whole = db_of(p, 0, NSHAPES), *b0 = db_of(p, 0, CUT), *b1 = db_of(p, CUT, NSHAPES);
    amscr_index *x = NULL, *s0 = NULL, *s1 = NULL;
    ck_assert_int_eq(amscr_index_build(whole, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_index_build(b0, 0, NULL, NULL, &s0), AMSCR_OK);
    ck_assert_int_eq(amscr_index_build(b1, 4, NULL, NULL, &s1), AMSCR_OK); /* its own lists never read */
    size_t n = NSHAPES, n1 = NSHAPES - CUT, k, k2;
    amscr_index_graph_widths(p, n, &k, &k2);
    ck_assert_uint_eq(k, x->k);
    ck_assert_uint_eq(k2, x->k2);
    double *D = calloc(n * n, sizeof *D), *D2 = calloc(n * n, sizeof *D2), dmax = 0.0, dmax2 = 0.0;
    for (size_t i = 0; i < n; i++) { /* blocks (0, 0), (0, 1), (1, 1); the matrix is symmetric */
        const amscr_descriptor *q = i < CUT ? amscr_db_descriptor(b0, i) : amscr_db_descriptor(b1, i - CUT);
        if (i < CUT) /* its block's pairs once: the shapes after it */
            ck_assert_int_eq(amscr_index_pair_distances(s0, q, i, i + 1, D + i * n + i + 1, D2 + i * n + i + 1,
                                                        CUT - i - 1), AMSCR_OK);
        size_t qpos = i < CUT ? 0 : i - CUT, first = i < CUT ? 0 : i - CUT + 1;
        ck_assert_int_eq(amscr_index_pair_distances(s1, q, qpos, first, D + i * n + CUT + first,
                                                    D2 + i * n + CUT + first, n1 - first), AMSCR_OK);
    }
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < i; j++) {
            D[i * n + j] = D[j * n + i];
            D2[i * n + j] = D2[j * n + i];
        }
    for (size_t e = 0; e < n * n; e++) {
        dmax = D[e] > dmax ? D[e] : dmax;
        dmax2 = D2[e] > dmax2 ? D2[e] : dmax2;
    }
    ck_assert_double_eq(dmax, x->dmax);
    uint32_t *ni = calloc(n * k, sizeof *ni), *ii = calloc(n * (k2 ? k2 : 1), sizeof *ii);
    double *nd = calloc(n * k, sizeof *nd), *id = calloc(n * (k2 ? k2 : 1), sizeof *id);
    for (size_t i = 0; i < n; i++) {
        list_of(D + i * n, n, i, k, ni + i * k, nd + i * k);
        if (k2)
            list_of(D2 + i * n, n, i, k2, ii + i * k2, id + i * k2);
    }
    ck_assert_mem_eq(ni, x->nb_idx, n * k * sizeof *ni);
    ck_assert_mem_eq(nd, x->nb_dist, n * k * sizeof *nd);
    amscr_index_graph *g = NULL;
    ck_assert_int_eq(amscr_index_graph_new(p, n, ni, nd, k2 ? ii : NULL, k2 ? id : NULL, dmax, dmax2, &g), AMSCR_OK);
    ck_assert_uint_eq(amscr_index_graph_size(g), n);
    size_t cand[NSHAPES];
    for (size_t j = 0; j < n; j++)
        cand[j] = j;
    for (unsigned t = 0; t < 3; t++) {
        amscr_descriptor *q = shape(p, 40 + t);
        double dq[NSHAPES], dq2[NSHAPES], got[NSHAPES], want[NSHAPES];
        ck_assert_int_eq(amscr_index_pair_distances(s0, q, SIZE_MAX, 0, dq, dq2, CUT), AMSCR_OK);
        ck_assert_int_eq(amscr_index_pair_distances(s1, q, SIZE_MAX, 0, dq + CUT, dq2 + CUT, n1), AMSCR_OK);
        ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, k2 ? dq2 : NULL, n, got, n), AMSCR_OK);
        ck_assert_int_eq(amscr_index_query_scores(x, q, 0, want, n), AMSCR_OK);
        for (size_t j = 0; j < n; j++)
            ck_assert_double_eq_tol(got[j], want[j], 1e-9);
        amscr_descriptor_free(q);
    }
    for (size_t i = 3; i < n; i += 15) { /* the member rule: shape i's row (3 in block 0, 18 in block 1) */
        double dq[NSHAPES], got[NSHAPES], want[NSHAPES];
        size_t mc[NSHAPES], m = 0;
        for (size_t j = 0; j < n; j++)
            if (j != i) {
                mc[m] = j;
                dq[m++] = D[i * n + j];
            }
        ck_assert_int_eq(amscr_index_graph_member_scores(g, i, mc, dq, m, got, n), AMSCR_OK);
        ck_assert_int_eq(amscr_index_member_scores(x, i, 0, want, n), AMSCR_OK);
        for (size_t j = 0; j < n; j++)
            ck_assert_double_eq_tol(got[j], want[j], 1e-9);
        ck_assert_int_eq(amscr_index_graph_member_scores(g, i, cand, dq, n, got, n), AMSCR_E_INVALID_ARG); /* i in */
        ck_assert_int_eq(amscr_index_graph_member_scores(g, n, mc, dq, m, got, n), AMSCR_E_INVALID_ARG);
        ck_assert_int_eq(amscr_index_graph_member_scores(g, i, mc, dq, m, got, n - 1), AMSCR_E_INVALID_ARG);
    }
    amscr_index_graph_free(g);
    free(ni);
    free(nd);
    free(ii);
    free(id);
    free(D);
    free(D2);
    amscr_index_free(x);
    amscr_index_free(s0);
    amscr_index_free(s1);
    amscr_db_free(whole);
    amscr_db_free(b0);
    amscr_db_free(b1);
    amscr_params_free(p);
}

START_TEST(two_blocks_inner) { sharded_case(0.1); }
END_TEST

START_TEST(two_blocks_one_graph) { sharded_case(0.0); }
END_TEST

/* The packed signatures of x (n shapes, d values each) are its float signatures sigs exactly,
 * and their shortlists are the floats' (every shape's 6 nearest, left out; 3 new queries); a
 * wrong count, an exponent out of range or NULL rows are refused. */
static void check_packed(const amscr_index *x, const float *sigs, size_t n, size_t d)
{
    uint16_t *q = malloc(n * d * sizeof *q);
    int32_t *e = malloc(n * sizeof *e);
    size_t *a = malloc(n * 6 * sizeof *a), *b = malloc(n * 6 * sizeof *b);
    ck_assert(q && e && a && b);
    ck_assert_int_eq(amscr_index_signatures_packed(x, q, e, n), AMSCR_OK);
    ck_assert_int_eq(amscr_index_signatures_packed(x, q, e, n - 1), AMSCR_E_INVALID_ARG);
    for (size_t i = 0; i < n; i++) {
        ck_assert(e[i] >= AMSCR_SIGNATURE_EXP_MIN && e[i] <= AMSCR_SIGNATURE_EXP_MAX);
        for (size_t t = 0; t < d; t++)
            ck_assert_float_eq(ldexpf((float)q[i * d + t], e[i]), sigs[i * d + t]);
    }
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs, n, 0, 6, 2, a, n * 6), AMSCR_OK);
    ck_assert_int_eq(amscr_signature_shortlists_packed(q, e, n, sigs, n, 0, 6, 2, b, n * 6), AMSCR_OK);
    ck_assert(memcmp(a, b, n * 6 * sizeof *a) == 0);
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs + 2 * d, 3, SIZE_MAX, 6, 1, a, 18), AMSCR_OK);
    ck_assert_int_eq(amscr_signature_shortlists_packed(q, e, n, sigs + 2 * d, 3, SIZE_MAX, 6, 1, b, 18), AMSCR_OK);
    ck_assert(memcmp(a, b, 18 * sizeof *a) == 0);
    ck_assert_int_eq(amscr_signature_shortlists_packed(q, NULL, n, sigs, 1, 0, 6, 1, b, 6), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_signature_shortlists_packed(q, e, n, sigs, 1, 0, 6, 1, b, 5), AMSCR_E_INVALID_ARG);
    e[1] = AMSCR_SIGNATURE_EXP_MAX + 1;
    ck_assert_int_eq(amscr_signature_shortlists_packed(q, e, n, sigs, 1, 0, 6, 1, b, 6), AMSCR_E_INVALID_ARG);
    free(q);
    free(e);
    free(a);
    free(b);
}

/* amscr_index_pair_distances_at equals amscr_index_pair_distances on its shapes; the signatures
 * of an index are its shapes' (amscr_shape_signature) and their shortlists those the index
 * ranks by; bad arguments are errors. */
START_TEST(shortlists_and_chosen_pairs)
{
    amscr_params *p = params_of(0.1);
    amscr_db *db = db_of(p, 0, NSHAPES);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    size_t d = amscr_signature_size(), n = NSHAPES;
    ck_assert_uint_gt(d, 0);
    float *sigs = malloc(n * d * sizeof *sigs), *one = malloc(d * sizeof *one);
    ck_assert_ptr_nonnull(sigs);
    ck_assert_ptr_nonnull(one);
    ck_assert_int_eq(amscr_index_signatures(x, sigs, n * d), AMSCR_OK);
    ck_assert_int_eq(amscr_index_signatures(x, sigs, n * d - 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_shape_signature(amscr_db_descriptor(db, 5), one, d), AMSCR_OK);
    float top = 0.0f; /* the stored one: the query's in 16 bits (half a step of the largest value's) */
    for (size_t t = 0; t < d; t++)
        top = one[t] > top ? one[t] : top;
    for (size_t t = 0; t < d; t++)
        ck_assert_float_le(fabsf(one[t] - sigs[5 * d + t]), top / 65536.0f);
    ck_assert(memcmp(one, sigs + 5 * d, d * sizeof *one) != 0);
    ck_assert_int_eq(amscr_shape_signature(amscr_db_descriptor(db, 5), one, d + 1), AMSCR_E_INVALID_ARG);
    /* shape 5's 4 nearest, itself left out; as a new query (first SIZE_MAX) it is its own nearest */
    size_t sl[4], sq[4];
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs + 5 * d, 1, 5, 4, 1, sl, 4), AMSCR_OK);
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs + 5 * d, 1, SIZE_MAX, 4, 2, sq, 4), AMSCR_OK);
    int self = 0;
    for (size_t t = 0; t < 4; t++) {
        ck_assert(sl[t] != 5 && sl[t] < n && (t == 0 || sl[t] > sl[t - 1]));
        self += sq[t] == 5;
    }
    ck_assert_int_eq(self, 1);
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs, 1, 0, n, 1, sl, n), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs, 1, 0, 4, 1, sl, 3), AMSCR_E_INVALID_ARG);
    check_packed(x, sigs, n, d);
    sigs[3] = NAN;
    ck_assert_int_eq(amscr_signature_shortlists(sigs, n, sigs + 5 * d, 1, 5, 4, 1, sl, 4), AMSCR_E_INVALID_ARG);
    /* the chosen pairs of shape 3 (as itself) equal its row's cells */
    double all[NSHAPES], all2[NSHAPES], at[3], at2[3];
    size_t cand[3] = {4, 9, 20};
    const amscr_descriptor *q = amscr_db_descriptor(db, 3);
    ck_assert_int_eq(amscr_index_pair_distances(x, q, 3, 4, all + 4, all2 + 4, n - 4), AMSCR_OK);
    ck_assert_int_eq(amscr_index_pair_distances_at(x, q, 3, cand, 3, at, at2), AMSCR_OK);
    for (size_t t = 0; t < 3; t++) {
        ck_assert_double_eq(at[t], all[cand[t]]);
        ck_assert_double_eq(at2[t], all2[cand[t]]);
    }
    ck_assert_int_eq(amscr_index_pair_distances_at(x, q, 3, cand, 3, NULL, at2), AMSCR_OK);
    ck_assert_double_eq(at2[2], all2[20]);
    size_t bad[2] = {9, 4}, out_of[1] = {NSHAPES};
    ck_assert_int_eq(amscr_index_pair_distances_at(x, q, 3, bad, 2, at, at2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_pair_distances_at(x, q, 3, out_of, 1, at, at2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_pair_distances_at(x, q, 3, cand, 3, NULL, NULL), AMSCR_E_INVALID_ARG);
    /* the build's shortlist width: 0 for every pair, the cap 192, at least K - 1 */
    size_t k = 0;
    amscr_index_graph_widths(p, 5000, &k, NULL);
    ck_assert_uint_eq(amscr_index_build_shortlist(p, 5000, 0), 0);
    ck_assert_uint_eq(amscr_index_build_shortlist(p, 5000, 256), 192);
    ck_assert_uint_eq(amscr_index_build_shortlist(p, 5000, 100), 100);
    ck_assert_uint_eq(amscr_index_build_shortlist(p, 5000, 1), k - 1);
    ck_assert_uint_eq(amscr_index_build_shortlist(p, 100, 256), 0);
    ck_assert_uint_eq(amscr_index_build_shortlist(NULL, 5000, 256), 0);
    free(sigs);
    free(one);
    amscr_index_free(x);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

START_TEST(bad_graphs)
{
    amscr_params *p = params_of(0.0);
    size_t n = 4, k, k2;
    amscr_index_graph_widths(p, n, &k, &k2);
    ck_assert_uint_eq(k, 2);
    ck_assert_uint_eq(k2, 0);
    uint32_t idx[8] = {0, 1, 1, 0, 2, 3, 3, 2};
    double dist[8] = {0, 1, 0, 1, 0, 2, 0, 2};
    amscr_index_graph *g = NULL;
    ck_assert_int_eq(amscr_index_graph_new(p, n, idx, dist, NULL, NULL, 2.0, 0.0, &g), AMSCR_OK);
    size_t cand[2] = {1, 0};
    double dq[2] = {0.5, 0.5}, out[4];
    ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, NULL, 2, out, 4), AMSCR_E_INVALID_ARG); /* not ascending */
    cand[0] = 0;
    cand[1] = 4;
    ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, NULL, 2, out, 4), AMSCR_E_INVALID_ARG); /* >= n */
    cand[1] = 2;
    ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, NULL, 2, out, 3), AMSCR_E_INVALID_ARG); /* n */
    dq[1] = NAN;
    ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, NULL, 2, out, 4), AMSCR_E_INVALID_ARG);
    dq[1] = 0.5;
    ck_assert_int_eq(amscr_index_graph_scores(g, cand, dq, NULL, 2, out, 4), AMSCR_OK);
    ck_assert(out[0] < out[3] && out[2] < out[3]);
    amscr_index_graph_free(g);
    idx[2] = 2; /* row 1 not itself first */
    g = (amscr_index_graph *)&k; /* a sentinel: outputs are written only on AMSCR_OK */
    ck_assert_int_eq(amscr_index_graph_new(p, n, idx, dist, NULL, NULL, 2.0, 0.0, &g), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_eq(g, (amscr_index_graph *)&k);
    g = NULL;
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "row 1"));
    idx[2] = 1;
    idx[3] = 9; /* past n */
    ck_assert_int_eq(amscr_index_graph_new(p, n, idx, dist, NULL, NULL, 2.0, 0.0, &g), AMSCR_E_INVALID_ARG);
    idx[3] = 0;
    dist[5] = -1.0;
    ck_assert_int_eq(amscr_index_graph_new(p, n, idx, dist, NULL, NULL, 2.0, 0.0, &g), AMSCR_E_INVALID_ARG);
    dist[5] = 2.0;
    ck_assert_int_eq(amscr_index_graph_new(p, n, idx, dist, NULL, NULL, INFINITY, 0.0, &g), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_graph_new(p, n, NULL, NULL, NULL, NULL, 2.0, 0.0, &g), AMSCR_E_INVALID_ARG);
    amscr_index_graph_free(NULL);
    ck_assert_uint_eq(amscr_index_graph_size(NULL), 0);
    amscr_db *db = db_of(p, 0, 6);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    double d[6];
    ck_assert_int_eq(amscr_index_pair_distances(x, amscr_db_descriptor(db, 0), 0, 0, d, NULL, 5), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_pair_distances(x, amscr_db_descriptor(db, 0), 0, 7, d, NULL, 0), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_pair_distances(x, amscr_db_descriptor(db, 0), 0, 0, d, NULL, 6), AMSCR_OK);
    ck_assert_double_eq(d[0], 0.0);
    ck_assert_int_eq(amscr_index_pair_distances(x, amscr_db_descriptor(db, 0), 0, 6, d, NULL, 0), AMSCR_OK);
    amscr_index_free(x);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

Suite *amscr_suite_shards(void)
{
    Suite *s = suite_create("shards");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, two_blocks_inner);
    tcase_add_test(tc, two_blocks_one_graph);
    tcase_add_test(tc, bad_graphs);
    tcase_add_test(tc, shortlists_and_chosen_pairs);
    suite_add_tcase(s, tc);
    return s;
}
