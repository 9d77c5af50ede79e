/* index_query.c — one query against an index: base distances (fuse.c, pair by pair) to the
 * candidate shapes and, with re-ranking, the query's row of the retrieval matrix's diffusion
 * (amscr_db_retrieval_matrix: amscr_rerank_diffusion halved into [0, 1]) on the collection
 * plus the query, from the stored neighbour lists alone.
 *
 * With P the row-normalized kNN affinities of the n + 1 shapes, Q_0 = P and
 * Q <- P Q P^T + I for T iterations give
 *     Q_T = sum_{t=0}^{T-1} P^t (P^T)^t + P^T P (P^T)^T   (powers),
 * so row q is sum_t P^t (e_q P^t)^T + P^T (e_q P^T P)^T (as columns): sparse vector products
 * only, O(T^2 (n+1) K) instead of the O(T n^2 K) of the whole matrix. Adding the query
 * changes the neighbour list of every shape it is nearer to than that shape's K-th
 * neighbour, and nothing else, so the stored lists (plus the query) give P exactly. */
#include "index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    size_t n, k;   /* rows (the query last, when there is one), k entries each */
    uint32_t *j;   /* neighbours */
    double *d, *w; /* base distances, then the row-normalized affinities */
    double *s;     /* scales: each row's k-th distance */
} graph;

static amscr_status graph_alloc(graph *g, size_t n, size_t k)
{
    g->n = n;
    g->k = k;
    g->j = amscr__malloc_array(n, k * sizeof *g->j);
    g->d = amscr__malloc_array(n, k * sizeof *g->d);
    g->w = amscr__malloc_array(n, k * sizeof *g->w);
    g->s = amscr__malloc_array(n, sizeof *g->s);
    return g->j && g->d && g->w && g->s ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
}

static void graph_free(graph *g)
{
    free(g->j);
    free(g->d);
    free(g->w);
    free(g->s);
}

/* Row i of the graph: its stored list (x->k entries) with the query (index g->n - 1, distance
 * dq) merged in by (distance, index) when `have`, the first g->k kept. */
static void collection_row(const amscr_index *x, size_t i, double dq, int have, graph *g)
{
    size_t k = g->k, ks = x->k, q = g->n - 1, o = 0;
    const uint32_t *sj = x->nb_idx + i * ks;
    const double *sd = x->nb_dist + i * ks;
    int placed = !have;
    for (size_t t = 0; t < k; t++) {
        if (!placed && (o >= ks || (o > 0 && sd[o] > dq))) { /* ties: the query's index is the highest */
            g->j[i * k + t] = (uint32_t)q;
            g->d[i * k + t] = dq;
            placed = 1;
        } else { /* (past the stored list only for a shape the query was not matched with) */
            g->j[i * k + t] = sj[o < ks ? o : ks - 1];
            g->d[i * k + t] = sd[o < ks ? o : ks - 1];
            o++;
        }
    }
}

/* The query's row: itself, then its k - 1 nearest candidates by (distance, index). */
static amscr_status query_row(const size_t *cand, const double *dq, size_t m, graph *g)
{
    size_t k = g->k, q = g->n - 1, *order = amscr__malloc_array(m, sizeof *order);
    if (!order)
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    amscr_status st = amscr_topk(dq, m, k - 1, SIZE_MAX, order);
    if (st == AMSCR_OK) {
        g->j[q * k] = (uint32_t)q;
        g->d[q * k] = 0.0;
        for (size_t t = 1; t < k; t++) {
            g->j[q * k + t] = (uint32_t)cand[order[t - 1]];
            g->d[q * k + t] = dq[order[t - 1]];
        }
    }
    free(order);
    return st;
}

/* Affinities exp(-D / sqrt(s_i s_j)), row-normalized (as amscr_rerank_diffusion). */
static void weights(graph *g, double dmax)
{
    size_t k = g->k;
    double tiny = dmax > 0.0 ? 1e-12 * dmax : 1e-300;
    for (size_t i = 0; i < g->n; i++)
        g->s[i] = g->d[i * k + k - 1];
    for (size_t i = 0; i < g->n; i++) {
        double sum = 0.0;
        for (size_t t = 0; t < k; t++) {
            double s = sqrt((g->s[i] + tiny) * (g->s[g->j[i * k + t]] + tiny));
            g->w[i * k + t] = exp(-g->d[i * k + t] / s);
            sum += g->w[i * k + t];
        }
        for (size_t t = 0; t < k; t++)
            g->w[i * k + t] /= sum;
    }
}

/* v <- P v. */
static void apply_cols(const graph *g, double *v, double *tmp)
{
    for (size_t i = 0; i < g->n; i++) {
        double s = 0.0;
        for (size_t t = 0; t < g->k; t++)
            s += g->w[i * g->k + t] * v[g->j[i * g->k + t]];
        tmp[i] = s;
    }
    memcpy(v, tmp, g->n * sizeof *v);
}

/* a <- a P. */
static void apply_rows(const graph *g, double *a, double *tmp)
{
    memset(tmp, 0, g->n * sizeof *tmp);
    for (size_t i = 0; i < g->n; i++)
        if (a[i] != 0.0)
            for (size_t t = 0; t < g->k; t++)
                tmp[g->j[i * g->k + t]] += a[i] * g->w[i * g->k + t];
    memcpy(a, tmp, g->n * sizeof *a);
}

/* Row `start` of Q_T into r (g->n entries). */
static amscr_status diffusion_row(const graph *g, size_t start, unsigned iters, double *r)
{
    size_t n = g->n;
    double *a = amscr__calloc_array(n, sizeof *a), *v = amscr__malloc_array(n, sizeof *v);
    double *tmp = amscr__malloc_array(n, sizeof *tmp);
    amscr_status st = a && v && tmp ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK) {
        memset(r, 0, n * sizeof *r);
        a[start] = 1.0;
        for (unsigned t = 0; t <= iters; t++) {
            memcpy(v, a, n * sizeof *v);
            if (t == iters)
                apply_rows(g, v, tmp); /* the last term: e_q P^T P */
            for (unsigned u = 0; u < t; u++)
                apply_cols(g, v, tmp);
            for (size_t i = 0; i < n; i++)
                r[i] += v[i];
            if (t < iters)
                apply_rows(g, a, tmp);
        }
    }
    free(a);
    free(v);
    free(tmp);
    return st;
}

/* out[j] (j < n) from the diffused row r (len entries): halved 1 - r / max r where reached,
 * 0.5 + half the base distance / dmax for the matched shapes it does not reach, +inf for the
 * others; 0 for `self` (the library's normalization of the retrieval matrix). */
static void scores(const double *r, size_t len, size_t n, size_t self, const double *dfull, const unsigned char *have,
                   double dmax, double *out)
{
    double rmax = 0.0;
    for (size_t i = 0; i < len; i++)
        rmax = r[i] > rmax ? r[i] : rmax;
    for (size_t j = 0; j < n; j++) {
        if (j == self)
            out[j] = 0.0;
        else if (r[j] > 0.0 && rmax > 0.0)
            out[j] = 0.5 * (1.0 - r[j] / rmax);
        else
            out[j] = have[j] ? 0.5 * (1.0 + (dmax > 0.0 ? dfull[j] / dmax : 0.0)) : INFINITY;
    }
}

/* The diffusion's scores of row `self` (< n: a shape of the index; n: the query, with
 * distances dfull[j] where have[j]). */
static amscr_status diffuse(const amscr_index *x, size_t self, const size_t *cand, const double *dq, size_t m,
                            const double *dfull, const unsigned char *have, double *out)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db), rows = self == n ? n + 1 : n;
    size_t k = p->rerank_k < rows ? p->rerank_k : rows;
    double dmax = x->dmax;
    for (size_t t = 0; self == n && t < m; t++)
        dmax = dq[t] > dmax ? dq[t] : dmax;
    graph g = {0, 0, NULL, NULL, NULL, NULL};
    double *r = amscr__malloc_array(rows, sizeof *r);
    amscr_status st = r ? graph_alloc(&g, rows, k) : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    for (size_t i = 0; st == AMSCR_OK && i < n; i++)
        collection_row(x, i, dfull[i], self == n && have[i], &g);
    if (st == AMSCR_OK && self == n)
        st = query_row(cand, dq, m, &g);
    if (st == AMSCR_OK) {
        weights(&g, dmax);
        st = diffusion_row(&g, self, p->rerank_iterations, r);
    }
    if (st == AMSCR_OK)
        scores(r, rows, n, self, dfull, have, dmax, out);
    graph_free(&g);
    free(r);
    return st;
}

amscr_status amscr__index_scores(const amscr_index *x, size_t self, const size_t *cand, const double *dq, size_t m,
                                 double *out)
{
    size_t n = amscr_db_size(x->db);
    double *dfull = amscr__calloc_array(n, sizeof *dfull);
    unsigned char *have = amscr__calloc_array(n, 1);
    amscr_status st = dfull && have ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) {
        dfull[cand[t]] = dq[t];
        have[cand[t]] = 1;
    }
    if (st == AMSCR_OK && x->k == 0) { /* no re-ranking: the base distances */
        for (size_t j = 0; j < n; j++)
            out[j] = j == self ? 0.0 : have[j] ? dfull[j] : INFINITY;
    } else if (st == AMSCR_OK) {
        st = diffuse(x, self, cand, dq, m, dfull, have, out);
    }
    free(dfull);
    free(have);
    return st;
}

/* ------------------------------------------------------------------ public calls */

static amscr_status check_query(const amscr_index *x, const amscr_descriptor *q, size_t *out, size_t n,
                                const char *what)
{
    if (!amscr__params_compatible(amscr_db_params(x->db), &q->params, what))
        return AMSCR_E_INVALID_ARG;
    if (n != amscr_db_size(x->db) && out)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: the output holds %zu scores, the index %zu shapes", what, n,
                           amscr_db_size(x->db));
    return AMSCR_OK;
}

/* The shapes a query is matched with: every shape (0 or >= n) or at least k - 1. */
static size_t shortlist_size(const amscr_index *x, size_t candidates)
{
    size_t n = amscr_db_size(x->db);
    if (candidates == 0 || candidates >= n)
        return 0;
    return candidates + 1 < x->k ? x->k - 1 : candidates;
}

/* Scores of q (self == SIZE_MAX) or of shape self against every shape. */
static amscr_status query_scores(const amscr_index *x, const amscr_descriptor *q, size_t self, size_t candidates,
                                 amscr_progress_fn progress, void *user, double *out)
{
    size_t n = amscr_db_size(x->db), *cand = amscr__malloc_array(n, sizeof *cand);
    double *dq = amscr__malloc_array(n, sizeof *dq);
    float sig[AMSCR__SIG_DIM], lb[AMSCR__SIG_LB_DIM];
    amscr_status st = cand && dq ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    size_t m = 0;
    if (st == AMSCR_OK) {
        size_t want = shortlist_size(x, candidates);
        if (want > 0 && self < n) /* a member's signature is stored */
            memcpy(sig, x->sig + self * x->sig_dim, sizeof sig);
        else if (want > 0)
            amscr__shape_signature(q, sig);
        if (want > 0)
            amscr__sig_bound_vector(sig, lb);
        m = amscr__index_shortlist(x, sig, lb, want, self, cand);
        if (m == 0 && n > (self < n ? 1u : 0u))
            st = amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    }
    amscr__base b;
    amscr__base_init(&b, amscr_db_params(x->db), x->med_a, x->med_h);
    if (st == AMSCR_OK)
        st = amscr__base_row(&b, x->db, x->hf, q, self == SIZE_MAX ? SIZE_MAX : self, cand, m, progress, user, dq);
    if (st == AMSCR_OK)
        st = amscr__index_scores(x, self == SIZE_MAX ? n : self, cand, dq, m, out);
    free(cand);
    free(dq);
    return st;
}

amscr_status amscr_index_query_scores(const amscr_index *x, const amscr_descriptor *q, size_t candidates,
                                      double *out_scores, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_scores);
    amscr_status st = check_query(x, q, (size_t *)out_scores, n, "amscr_index_query_scores");
    return st == AMSCR_OK ? query_scores(x, q, SIZE_MAX, candidates, NULL, NULL, out_scores) : st;
}

amscr_status amscr_index_member_scores(const amscr_index *x, size_t i, size_t candidates, double *out_scores,
                                       size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR_CHECK_NULL(out_scores);
    if (n != amscr_db_size(x->db) || i >= n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_member_scores: shape %zu, %zu scores, %zu shapes", i,
                           n, amscr_db_size(x->db));
    return query_scores(x, amscr_db_descriptor(x->db, i), i, candidates, NULL, NULL, out_scores);
}

amscr_status amscr_index_query(const amscr_index *x, const amscr_descriptor *q, size_t candidates, size_t top,
                               size_t *out_idx, double *out_scores, size_t *out_count)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_idx);
    AMSCR_CHECK_NULL(out_scores);
    AMSCR_CHECK_NULL(out_count);
    amscr_status st = check_query(x, q, NULL, 0, "amscr_index_query");
    size_t n = amscr_db_size(x->db), k = top < n ? top : n;
    double *all = st == AMSCR_OK ? amscr__malloc_array(n, sizeof *all) : NULL;
    if (st == AMSCR_OK && !all)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_query: out of memory");
    if (st == AMSCR_OK)
        st = query_scores(x, q, SIZE_MAX, candidates, NULL, NULL, all);
    if (st == AMSCR_OK && k > 0)
        st = amscr_topk(all, n, k, SIZE_MAX, out_idx);
    for (size_t t = 0; st == AMSCR_OK && t < k; t++)
        out_scores[t] = all[out_idx[t]];
    if (st == AMSCR_OK)
        *out_count = k;
    free(all);
    return st;
}

/* The last row of the retrieval matrix of db plus q. */
static amscr_status query_by_matrix(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress,
                                    void *user, double *out)
{
    size_t n = amscr_db_size(db);
    amscr_db *all = NULL;
    amscr_status st = amscr_db_new(amscr_db_params(db), &all);
    for (size_t i = 0; st == AMSCR_OK && i < n; i++)
        st = amscr_db_add_descriptor(all, amscr_db_descriptor(db, i), amscr_db_label(db, i), NULL);
    if (st == AMSCR_OK)
        st = amscr_db_add_descriptor(all, q, -1, NULL);
    double *M = st == AMSCR_OK ? amscr__malloc_array((n + 1) * (n + 1), sizeof *M) : NULL;
    if (st == AMSCR_OK && !M)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_db_query_retrieval: out of memory");
    if (st == AMSCR_OK)
        st = amscr_db_retrieval_matrix(all, progress, user, M);
    if (st == AMSCR_OK)
        memcpy(out, M + n * (n + 1), n * sizeof *out);
    free(M);
    amscr_db_free(all);
    return st;
}

/* The base distances of q to every shape of db. */
static amscr_status plain_row(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress, void *user,
                              double *out)
{
    size_t n = amscr_db_size(db), *cand = amscr__malloc_array(n, sizeof *cand);
    if (!cand)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_query_retrieval: out of memory");
    for (size_t j = 0; j < n; j++)
        cand[j] = j;
    amscr__base b;
    amscr__base_init(&b, amscr_db_params(db), 0.0, 0.0);
    amscr_status st = amscr__base_row(&b, db, NULL, q, SIZE_MAX, cand, n, progress, user, out);
    free(cand);
    return st;
}

amscr_status amscr_db_query_retrieval(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress,
                                      void *user, double *out_scores, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_scores);
    if (n != amscr_db_size(db))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_db_query_retrieval: the output holds %zu scores, the "
                                                "collection %zu shapes", n, amscr_db_size(db));
    if (!amscr__params_compatible(amscr_db_params(db), &q->params, "amscr_db_query_retrieval"))
        return AMSCR_E_INVALID_ARG;
    const amscr_params *p = amscr_db_params(db);
    double w = p->channel_weight;
    if (w > 0.0 && w < 1.0) /* fused weights: the medians move with the query, so the whole matrix */
        return query_by_matrix(db, q, progress, user, out_scores);
    if (p->rerank_k == 0) /* the base distances alone: nothing of the collection's is needed */
        return plain_row(db, q, progress, user, out_scores);
    amscr_index *x = NULL;
    amscr_status st = amscr_index_build(db, 0, progress, user, &x);
    if (st == AMSCR_OK)
        st = query_scores(x, q, SIZE_MAX, 0, NULL, NULL, out_scores);
    amscr_index_free(x);
    return st;
}
