/* index_build.c — building an index: each shape's signature and its K nearest shapes under
 * the base distance of the retrieval matrix (fuse.c), from the full matrix (exact: a query
 * then equals the matrix of the collection plus the query) or, for large collections, among
 * each shape's M signature-nearest shapes and then its neighbours' neighbours (rows on
 * threads). */
#include "db_io.h"
#include "index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Shapes on which a shortlist build estimates the medians of a fused distance. */
enum { MEDIAN_SAMPLE = 256 };
/* A shortlist build seeks each shape's K neighbours among at most this many signature-nearest
 * shapes (the query's shortlist may be longer), then among its neighbours' neighbours
 * (index_refine.c): with the refinement, 192 keeps more of the exact neighbours (99.6 %) than
 * 256 without it (99.5 %), at 85 % of the build's CPU (160 kept 99.5 % but let an index query
 * keep only 98.8 % of the exact top 10; docs/measurements.md, "The index: build, query,
 * recall"). */
enum { BUILD_SHORTLIST = AMSCR__INDEX_BUILD_SHORTLIST };

/* Lists and dmax from the full base matrix (the retrieval matrix before its re-ranking), then
 * the inner distance's lists from its full matrix: progress in two stages when there are both. */
static amscr_status build_full(amscr_index *x, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db), k = x->k;
    amscr__stages sp = {progress, user, 0, x->k2 > 0 ? 2 : 1};
    amscr_progress_fn cb = progress ? amscr__stage_cb : NULL;
    double *D = amscr__malloc_array(n * n, sizeof *D), med[2] = {0.0, 0.0};
    size_t *cj = amscr__malloc_array(n, sizeof *cj);
    amscr_status st = D && cj ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "amscr_index_build: out of memory");
    if (st == AMSCR_OK)
        st = amscr__base_matrix(x->db, cb, &sp, D, med);
    x->med_a = med[0];
    x->med_h = med[1];
    x->dmax = 0.0;
    for (size_t j = 0; st == AMSCR_OK && j < n; j++)
        cj[j] = j;
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        for (size_t j = 0; j < n; j++)
            x->dmax = D[i * n + j] > x->dmax ? D[i * n + j] : x->dmax;
        if (k > 0)
            st = amscr__knn_select(i, cj, D + i * n, n, k, x->nb_idx + i * k, x->nb_dist + i * k);
    }
    free(D);
    free(cj);
    sp.stage = 1;
    return st == AMSCR_OK ? amscr__index_inner_full(x, cb, &sp) : st;
}

/* The fusion's medians estimated on at most MEDIAN_SAMPLE shapes spread evenly. */
static amscr_status sampled_medians(amscr_index *x)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db), m = n < MEDIAN_SAMPLE ? n : MEDIAN_SAMPLE;
    if (!(p->channel_weight > 0.0 && p->channel_weight < 1.0) || m < 2)
        return AMSCR_OK;
    amscr_db *sub = NULL;
    amscr_status st = amscr_db_new(p, &sub);
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) /* evenly spread: shape t * n / m */
        st = amscr__db_add_from(sub, x->db, (size_t)((double)t * (double)n / (double)m), -1);
    double *D = st == AMSCR_OK ? amscr__malloc_array(m * m, sizeof *D) : NULL, med[2] = {0.0, 0.0};
    if (st == AMSCR_OK && !D)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_build: out of memory");
    if (st == AMSCR_OK)
        st = amscr__base_matrix(sub, NULL, NULL, D, med);
    x->med_a = med[0];
    x->med_h = med[1];
    free(D);
    amscr_db_free(sub);
    return st;
}

/* ------------------------------------------------ shortlist build: rows on threads */

/* Rows first..n-1: each one's shortlist (m shapes, ascending) into S, the base distances of its
 * pairs into D (a pair in both rows' shortlists computed once, by the later row's partner:
 * the row of the lower index), then its k nearest. */
typedef struct {
    amscr_index *x;
    amscr__base b;
    size_t first, m;
    uint32_t *S;
    double *D;
} rows_ctx;

static amscr_status pw_init(void *ctx, void **scratch)
{
    return amscr__pair_ws_new(&((rows_ctx *)ctx)->b, scratch);
}

static amscr_status shortlist_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    rows_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t *cand = amscr__malloc_array(c->m, sizeof *cand);
    float sig[AMSCR__SIG_DIM];
    const float *lb = x->sig_lb + i * AMSCR__SIG_LB_DIM;
    amscr__index_sig(x, i, sig);
    size_t got = cand ? amscr__index_shortlist(x, sig, lb, c->m, i, cand) : 0; /* x's quantizer, if any */
    for (size_t t = 0; t < got; t++)
        c->S[(i - c->first) * c->m + t] = (uint32_t)cand[t];
    free(cand);
    return got == c->m ? AMSCR_OK : AMSCR_E_NOMEM;
}

/* Whether row j (>= first) holds i in its shortlist. */
static int row_holds(const rows_ctx *c, size_t j, size_t i)
{
    const uint32_t *r = c->S + (j - c->first) * c->m;
    size_t lo = 0, hi = c->m;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (r[mid] < i)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < c->m && r[lo] == i;
}

/* Pair (i, j) of row i is computed by row i unless j is a row too, j < i, and holds i. */
static int computed_by_other(const rows_ctx *c, size_t i, size_t j)
{
    return j >= c->first && j < i && row_holds(c, j, i);
}

static amscr_status distance_row(void *ctx, size_t i, void *scratch)
{
    rows_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t *cand = amscr__malloc_array(c->m, sizeof *cand), *pos = amscr__malloc_array(c->m, sizeof *pos), u = 0;
    double *d = amscr__malloc_array(c->m, sizeof *d);
    amscr_status st = cand && pos && d ? AMSCR_OK : AMSCR_E_NOMEM;
    const uint32_t *S = c->S + (i - c->first) * c->m;
    for (size_t t = 0; st == AMSCR_OK && t < c->m; t++)
        if (!computed_by_other(c, i, S[t])) {
            cand[u] = S[t];
            pos[u++] = t;
        }
    const amscr__hf *hq = x->nf ? x->hf + i * (size_t)x->nf : NULL;
    const amscr_descriptor *q = NULL;
    if (st == AMSCR_OK)
        st = amscr__db_shape(x->db, i, &q);
    if (st == AMSCR_OK)
        st = amscr__base_pairs(&c->b, x->db, x->hf, q, hq, i, cand, u, scratch, d);
    for (size_t t = 0; st == AMSCR_OK && t < u; t++)
        c->D[(i - c->first) * c->m + pos[t]] = d[t];
    free(cand);
    free(pos);
    free(d);
    return st;
}

/* Fills the pairs computed by other rows; row i's k nearest. */
static amscr_status list_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    rows_ctx *c = ctx;
    amscr_index *x = c->x;
    const uint32_t *S = c->S + (i - c->first) * c->m;
    double *D = c->D + (i - c->first) * c->m;
    size_t *cand = amscr__malloc_array(c->m, sizeof *cand);
    if (!cand)
        return AMSCR_E_NOMEM;
    for (size_t t = 0; t < c->m; t++) {
        cand[t] = S[t];
        if (computed_by_other(c, i, S[t])) {
            const uint32_t *r = c->S + (S[t] - c->first) * c->m;
            size_t lo = 0;
            while (r[lo] != i)
                lo++;
            D[t] = c->D[(S[t] - c->first) * c->m + lo];
        }
    }
    amscr_status st = x->k > 0 ? amscr__knn_select(i, cand, D, c->m, x->k, x->nb_idx + i * x->k,
                                                    x->nb_dist + i * x->k)
                               : AMSCR_OK;
    free(cand);
    return st;
}

/* Rows first..n-1 from their M signature-nearest shapes (of the quantizer's lists from
 * AMSCR__INDEX_IVF_MIN shapes: built here and kept for the queries); x->dmax grows to their
 * largest. */
amscr_status amscr__index_rows(amscr_index *x, size_t first, size_t m, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db), rows = n - first;
    rows_ctx c = {x, {0}, first, m, NULL, NULL};
    amscr__base_init(&c.b, amscr_db_params(x->db), x->med_a, x->med_h);
    c.S = amscr__malloc_array(rows, m * sizeof *c.S);
    c.D = amscr__malloc_array(rows, m * sizeof *c.D);
    amscr_status st = c.S && c.D ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    if (st == AMSCR_OK && n >= AMSCR__INDEX_IVF_MIN && x->ivf.nc == 0)
        st = amscr__sig_ivf_build(x->sig_lb, n, &x->ivf);
    amscr__rows_fn f1 = {NULL, NULL, shortlist_row, &c, NULL};
    amscr__rows_fn f2 = {pw_init, amscr__pair_ws_delete, distance_row, &c, NULL};
    amscr__rows_fn f3 = {NULL, NULL, list_row, &c, NULL};
    if (st == AMSCR_OK)
        st = amscr__run_rows(&f1, first, n, c.b.threads, NULL, NULL);
    if (st == AMSCR_OK)
        st = amscr__run_rows(&f2, first, n, c.b.threads, progress, user);
    if (st == AMSCR_OK)
        st = amscr__run_rows(&f3, first, n, c.b.threads, NULL, NULL);
    if (st == AMSCR_OK)
        st = amscr__index_refine(x, &c.b, first, c.S, m);
    if (st == AMSCR_OK)
        st = amscr__index_inner_rows(x, first, c.S, m);
    for (size_t t = 0; st == AMSCR_OK && t < rows * m; t++)
        x->dmax = c.D[t] > x->dmax ? c.D[t] : x->dmax;
    free(c.S);
    free(c.D);
    return st;
}

/* x's lists, from every pair (candidates 0) or each shape's shortlist; x freed on failure.
 * Progress in two stages: the shapes' features (a third of a full build's time), their lists. */
static amscr_status build_into(amscr_index *x, size_t candidates, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db);
    amscr__stages sp = {progress, user, 0, 2};
    amscr_progress_fn cb = progress ? amscr__stage_cb : NULL;
    amscr_status st = amscr__index_features(x, 0, 0, cb, &sp);
    sp.stage = 1;
    if (candidates > 0 && candidates + 1 < x->k)
        candidates = x->k - 1; /* a shortlist holds at least the K - 1 neighbours */
    x->candidates = candidates > 0 && n > 1 && candidates < n - 1 ? candidates : 0;
    if (st == AMSCR_OK && x->candidates == 0) {
        st = build_full(x, cb, &sp);
    } else if (st == AMSCR_OK) {
        size_t mb = x->candidates < BUILD_SHORTLIST ? x->candidates : BUILD_SHORTLIST;
        st = sampled_medians(x);
        if (st == AMSCR_OK)
            st = amscr__index_rows(x, 0, mb + 1 < x->k ? x->k - 1 : mb, cb, &sp);
    }
    if (st == AMSCR_OK)
        st = amscr__index_reverse(x);
    if (st == AMSCR_OK)
        amscr__index_drop_mirrors(x, 0);
    if (st != AMSCR_OK)
        amscr_index_free(x);
    return st;
}

amscr_status amscr_index_build(const amscr_db *db, size_t candidates, amscr_progress_fn progress, void *user,
                               amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out);
    amscr_status st = amscr__index_check_db(db, "amscr_index_build");
    amscr_index *x = NULL;
    if (st == AMSCR_OK) /* built on db's own shapes, then given its compact copy of them */
        st = amscr__index_alloc_on(db, &x);
    if (st == AMSCR_OK)
        st = build_into(x, candidates, progress, user);
    if (st == AMSCR_OK && (st = amscr__index_compact_db(x)) != AMSCR_OK)
        amscr_index_free(x);
    if (st == AMSCR_OK)
        *out = x;
    return st;
}

amscr_status amscr__index_build_on(const amscr_db *db, amscr_progress_fn progress, void *user, amscr_index **out)
{
    amscr_status st = amscr__index_check_db(db, "amscr_db_query_retrieval");
    amscr_index *x = NULL;
    if (st == AMSCR_OK)
        st = amscr__index_alloc_on(db, &x);
    if (st == AMSCR_OK)
        st = build_into(x, 0, progress, user);
    if (st == AMSCR_OK)
        *out = x;
    return st;
}
