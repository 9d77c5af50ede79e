/* index_refine.c — a shortlist build's neighbour lists refined from the lists of the
 * neighbours: a shape's neighbours are mostly among its neighbours' neighbours, so once every
 * row holds its K nearest among its M signature-nearest shapes, each row also matches the
 * neighbours of its neighbours that its shortlist missed and keeps the K nearest of both (one
 * pass, rows on threads). This lets a build seek the lists among fewer signature-nearest
 * shapes for the same share of the exact neighbours (docs/measurements.md, "The index:
 * build, query, recall"). */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>

typedef struct {
    amscr_index *x;
    const amscr__base *b;
    size_t first, m, rmax;
    const uint32_t *S; /* rows first..n-1: their shortlists, m each, ascending */
    uint32_t *R;       /* their new candidates, rmax each */
    double *D;         /* and the base distances to them */
    size_t *nr;        /* how many a row has */
    uint32_t *nb_idx;  /* the refined lists (x->cap x k; rows before first: as they were) */
    double *nb_dist;
} refine_ctx;

static int in_sorted(const uint32_t *r, size_t m, uint32_t v)
{
    size_t lo = 0, hi = m;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (r[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < m && r[lo] == v;
}

static int in_list(const uint32_t *r, size_t m, uint32_t v)
{
    for (size_t t = 0; t < m; t++)
        if (r[t] == v)
            return 1;
    return 0;
}

static amscr_status refine_init(void *ctx, void **scratch)
{
    return amscr__pair_ws_new(((refine_ctx *)ctx)->b, scratch);
}

/* Row i's new candidates (its neighbours' neighbours outside its shortlist) and their distances. */
static amscr_status refine_row(void *ctx, size_t i, void *scratch)
{
    refine_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t k = x->k, r = 0, row = i - c->first;
    const uint32_t *nb = x->nb_idx + i * k, *S = c->S + row * c->m;
    uint32_t *R = c->R + row * c->rmax;
    for (size_t t = 1; t < k; t++)
        for (size_t u = 1; u < k && nb[t] != i; u++) {
            uint32_t l = x->nb_idx[(size_t)nb[t] * k + u];
            if (l != i && !in_sorted(S, c->m, l) && !in_list(R, r, l))
                R[r++] = l;
        }
    c->nr[row] = r;
    size_t *cand = amscr__malloc_array(r ? r : 1, sizeof *cand);
    if (!cand)
        return AMSCR_E_NOMEM;
    for (size_t t = 0; t < r; t++)
        cand[t] = R[t];
    const amscr__hf *hq = x->nf ? x->hf + i * (size_t)x->nf : NULL;
    const amscr_descriptor *q;
    amscr_status st = amscr__db_shape(x->db, i, &q);
    if (st == AMSCR_OK)
        st = amscr__base_pairs(c->b, x->db, x->hf, q, hq, i, cand, r, scratch, c->D + row * c->rmax);
    free(cand);
    return st;
}

/* Row i's K nearest of its list and its new candidates, into the refined lists. */
static amscr_status merge_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    refine_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t k = x->k, row = i - c->first, r = c->nr[row], m = k - 1 + r;
    size_t *cj = amscr__malloc_array(m, sizeof *cj);
    double *cd = amscr__malloc_array(m, sizeof *cd);
    amscr_status st = cj && cd ? AMSCR_OK : AMSCR_E_NOMEM;
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) {
        cj[t] = t < k - 1 ? x->nb_idx[i * k + t + 1] : c->R[row * c->rmax + t - (k - 1)];
        cd[t] = t < k - 1 ? x->nb_dist[i * k + t + 1] : c->D[row * c->rmax + t - (k - 1)];
    }
    if (st == AMSCR_OK)
        st = amscr__knn_select(i, cj, cd, m, k, c->nb_idx + i * k, c->nb_dist + i * k);
    free(cj);
    free(cd);
    return st;
}

amscr_status amscr__index_refine(amscr_index *x, const amscr__base *b, size_t first, const uint32_t *S, size_t m)
{
    size_t n = amscr_db_size(x->db), k = x->k, rows = n - first;
    if (k < 3 || rows == 0)
        return AMSCR_OK;
    refine_ctx c = {x, b, first, m, (k - 1) * (k - 1), S, NULL, NULL, NULL, NULL, NULL};
    c.R = amscr__malloc_array(rows, c.rmax * sizeof *c.R);
    c.D = amscr__malloc_array(rows, c.rmax * sizeof *c.D);
    c.nr = amscr__calloc_array(rows, sizeof *c.nr);
    c.nb_idx = amscr__malloc_array(x->cap, k * sizeof *c.nb_idx); /* as amscr__index_reserve's */
    c.nb_dist = amscr__malloc_array(x->cap, k * sizeof *c.nb_dist);
    amscr_status st = c.R && c.D && c.nr && c.nb_idx && c.nb_dist ? AMSCR_OK
                                                                   : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    amscr__rows_fn f1 = {refine_init, amscr__pair_ws_delete, refine_row, &c, NULL};
    amscr__rows_fn f2 = {NULL, NULL, merge_row, &c, NULL};
    if (st == AMSCR_OK)
        st = amscr__run_rows(&f1, first, n, b->threads, NULL, NULL);
    if (st == AMSCR_OK)
        st = amscr__run_rows(&f2, first, n, b->threads, NULL, NULL);
    for (size_t row = 0; st == AMSCR_OK && row < rows; row++)
        for (size_t t = 0; t < c.nr[row]; t++)
            x->dmax = c.D[row * c.rmax + t] > x->dmax ? c.D[row * c.rmax + t] : x->dmax;
    if (st == AMSCR_OK) /* rows before first keep their lists */
        amscr__index_take_lists(&x->nb_idx, &x->nb_dist, &c.nb_idx, &c.nb_dist, first * k);
    free(c.R);
    free(c.D);
    free(c.nr);
    free(c.nb_idx);
    free(c.nb_dist);
    return st;
}
