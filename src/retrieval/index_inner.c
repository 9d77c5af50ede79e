/* index_inner.c — the inner distance's graph in an index (inner.c; the re-ranking's second
 * graph when the params give it a share): each shape's inner features and its K nearest shapes
 * under the inner distance, from the full inner matrix (a build with every shape: a query then
 * equals the matrix of the collection plus the query) or among each shape's signature-nearest
 * shapes and its base neighbours, then its inner neighbours' inner neighbours (a shortlist
 * build). */
#include "index.h"

#include <stdlib.h>

double amscr__index_inner_pair(const amscr_index *x, size_t i, size_t j, amscr__inner_ws *ws)
{
    int refl = amscr_db_params(x->db)->reflections;
    return i < j ? amscr__inner_distance(&x->inner[i], &x->inner[j], refl, ws)
                 : amscr__inner_distance(&x->inner[j], &x->inner[i], refl, ws);
}

amscr_status amscr__index_inner_full(amscr_index *x, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db), k2 = x->k2;
    if (k2 == 0)
        return AMSCR_OK;
    const amscr_params *p = amscr_db_params(x->db);
    double *D = amscr__malloc_array(n * n, sizeof *D);
    size_t *cj = amscr__malloc_array(n, sizeof *cj);
    amscr_status st = D && cj ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "amscr_index_build: out of memory");
    if (st == AMSCR_OK)
        st = amscr__inner_matrix_from(x->inner, n, p->reflections, amscr__resolve_threads(p->num_threads), progress,
                                      user, D);
    for (size_t j = 0; st == AMSCR_OK && j < n; j++)
        cj[j] = j;
    x->dmax2 = 0.0;
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        for (size_t j = 0; j < n; j++)
            x->dmax2 = D[i * n + j] > x->dmax2 ? D[i * n + j] : x->dmax2;
        st = amscr__knn_select(i, cj, D + i * n, n, k2, x->in_idx + i * k2, x->in_dist + i * k2);
    }
    free(D);
    free(cj);
    return st;
}

/* ------------------------------------------------ shortlist build: rows on threads */

typedef struct {
    amscr_index *x;
    size_t first, m;
    const uint32_t *S; /* rows first..n-1: their shortlists, m each */
    double *rmax;      /* per row: its largest inner distance */
} rows_ctx;

static amscr_status ws_init(void *ctx, void **scratch)
{
    (void)ctx;
    return amscr__inner_ws_new(scratch);
}

/* Row i: its shortlist and its base list (those the shortlist missed). */
static amscr_status inner_row(void *ctx, size_t i, void *scratch)
{
    rows_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t k = x->k, got = 0, *cand = amscr__malloc_array(c->m + k, sizeof *cand);
    double *d = amscr__malloc_array(c->m + k, sizeof *d);
    amscr_status st = cand && d ? AMSCR_OK : AMSCR_E_NOMEM;
    const uint32_t *S = c->S + (i - c->first) * c->m;
    for (size_t t = 0; st == AMSCR_OK && t < c->m; t++)
        cand[got++] = S[t];
    for (size_t t = 1; st == AMSCR_OK && t < k; t++) { /* the base list beyond the shortlist */
        size_t j = x->nb_idx[i * k + t], u = 0;
        while (u < c->m && S[u] != j)
            u++;
        if (u == c->m && j != i)
            cand[got++] = j;
    }
    double rmax = 0.0;
    for (size_t t = 0; st == AMSCR_OK && t < got; t++) {
        d[t] = amscr__index_inner_pair(x, i, cand[t], scratch);
        rmax = d[t] > rmax ? d[t] : rmax;
    }
    c->rmax[i - c->first] = rmax;
    if (st == AMSCR_OK)
        st = amscr__knn_select(i, cand, d, got, x->k2, x->in_idx + i * x->k2, x->in_dist + i * x->k2);
    free(cand);
    free(d);
    return st;
}

/* ------------------------------------------------ refined from the neighbours' lists */

typedef struct {
    amscr_index *x;
    uint32_t *idx; /* the refined lists (x->cap x k2; rows before first: as they were) */
    double *dist;
    double *rmax;  /* per row (from first): its largest new inner distance */
    size_t first;
} refine_ctx;

static int listed(const size_t *c, size_t m, size_t v)
{
    for (size_t t = 0; t < m; t++)
        if (c[t] == v)
            return 1;
    return 0;
}

/* Row i's K2 nearest of its list and its neighbours' lists (a shape's inner neighbours are
 * mostly among its neighbours' neighbours), into c->idx / c->dist. */
static amscr_status refine_row(void *ctx, size_t i, void *scratch)
{
    refine_ctx *c = ctx;
    const amscr_index *x = c->x;
    size_t k2 = x->k2, m = 0, cap = (k2 - 1) * k2;
    const uint32_t *nb = x->in_idx + i * k2;
    size_t *cj = amscr__malloc_array(cap, sizeof *cj);
    double *cd = amscr__malloc_array(cap, sizeof *cd), rmax = 0.0;
    if (!cj || !cd) {
        free(cj);
        free(cd);
        return AMSCR_E_NOMEM;
    }
    for (size_t t = 1; t < k2; t++, m++) {
        cj[m] = nb[t];
        cd[m] = x->in_dist[i * k2 + t];
    }
    for (size_t t = 1; t < k2; t++)
        for (size_t u = 1; u < k2; u++) {
            size_t l = x->in_idx[(size_t)nb[t] * k2 + u];
            if (l != i && !listed(cj, m, l)) {
                cj[m] = l;
                cd[m] = amscr__index_inner_pair(x, i, l, scratch);
                rmax = cd[m] > rmax ? cd[m] : rmax;
                m++;
            }
        }
    c->rmax[i - c->first] = rmax;
    amscr_status st = amscr__knn_select(i, cj, cd, m, k2, c->idx + i * k2, c->dist + i * k2);
    free(cj);
    free(cd);
    return st;
}

/* Rows first..n-1's inner lists refined from their neighbours' lists (one pass). */
static amscr_status refine(amscr_index *x, size_t first, unsigned threads)
{
    size_t n = amscr_db_size(x->db), k2 = x->k2;
    refine_ctx c = {x, amscr__malloc_array(x->cap, k2 * sizeof(uint32_t)), NULL, NULL, first};
    c.dist = amscr__malloc_array(x->cap, k2 * sizeof(double)); /* as amscr__index_reserve's */
    c.rmax = amscr__calloc_array(n - first, sizeof(double));
    amscr_status st = c.idx && c.dist && c.rmax ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    amscr__rows_fn f = {ws_init, amscr__inner_ws_delete, refine_row, &c, "inner distance"};
    if (st == AMSCR_OK && k2 > 2)
        st = amscr__run_rows(&f, first, n, threads, NULL, NULL);
    if (st == AMSCR_OK && k2 > 2) {
        amscr__index_take_lists(&x->in_idx, &x->in_dist, &c.idx, &c.dist, first * k2);
        for (size_t t = 0; t < n - first; t++)
            x->dmax2 = c.rmax[t] > x->dmax2 ? c.rmax[t] : x->dmax2;
    }
    free(c.idx);
    free(c.dist);
    free(c.rmax);
    return st;
}

amscr_status amscr__index_inner_rows(amscr_index *x, size_t first, const uint32_t *S, size_t m)
{
    size_t n = amscr_db_size(x->db);
    if (x->k2 == 0 || first >= n)
        return AMSCR_OK;
    rows_ctx c = {x, first, m, S, amscr__calloc_array(n - first, sizeof(double))};
    if (!c.rmax)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    unsigned threads = amscr__resolve_threads(amscr_db_params(x->db)->num_threads);
    amscr__rows_fn f = {ws_init, amscr__inner_ws_delete, inner_row, &c, "inner distance"};
    amscr_status st = amscr__run_rows(&f, first, n, threads, NULL, NULL);
    for (size_t t = 0; st == AMSCR_OK && t < n - first; t++)
        x->dmax2 = c.rmax[t] > x->dmax2 ? c.rmax[t] : x->dmax2;
    free(c.rmax);
    return st == AMSCR_OK ? refine(x, first, threads) : st;
}
