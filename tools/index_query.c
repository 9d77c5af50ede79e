/* index_query.c — one query against an index (`amscr search QUERY INDEX`): distances to the
 * candidate shapes and, with re-ranking, the query's row of amscr_rerank_diffusion on the
 * collection plus the query, from the stored neighbour lists alone.
 *
 * The diffusion's row of the query: with P the row-normalized kNN affinities of the n + 1
 * shapes, Q_0 = P and Q <- P Q P^T + I for T iterations give
 *     Q_T = sum_{t=0}^{T-1} P^t (P^T)^t + P^T P (P^T)^T   (powers),
 * so row q is sum_t P^t (e_q P^t)^T + P^T (e_q P^T P)^T (as columns): sparse vector products
 * only, O(T^2 (n+1) K) instead of the O(T n^2 K) of the whole matrix. Adding the query changes
 * the neighbour list of every shape it is nearer to than that shape's K-th neighbour, and
 * nothing else, so the stored lists (plus the query) give P exactly. */
#include "index_query.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

typedef struct graph {
    size_t n, k;  /* n + 1 rows (the query last), k entries each */
    uint32_t *j;  /* neighbours */
    double *d, *w; /* symmetrized distances, then the row-normalized affinities */
    double *s;    /* scales: each row's k-th distance */
} graph;

/* Row i (< n) of the graph: its stored list, with the query inserted when nearer than its k-th. */
static void collection_row(const tool_index *x, size_t i, double dq, int have_dq, graph *g)
{
    size_t k = g->k, q = g->n - 1;
    uint32_t *j = g->j + i * k;
    double *d = g->d + i * k;
    for (size_t t = 0; t < k; t++) {
        j[t] = x->nb_idx[i * x->k + t];
        d[t] = x->nb_dist[i * x->k + t];
    }
    if (have_dq && k > 1 && dq < d[k - 1]) { /* ties: the query has the highest index and loses */
        size_t t = k - 1;
        while (t > 1 && d[t - 1] > dq) {
            j[t] = j[t - 1];
            d[t] = d[t - 1];
            t--;
        }
        j[t] = (uint32_t)q;
        d[t] = dq;
    }
}

/* The query's row: itself, then its k - 1 nearest candidates by (distance, index): cand is
 * ascending, and amscr_topk breaks ties by position. */
static int query_row(const size_t *cand, const double *dsym, size_t m, graph *g)
{
    size_t k = g->k, q = g->n - 1, *order = xmalloc_array(m ? m : 1, sizeof(size_t));
    if (order == NULL || amscr_topk(dsym, m, k - 1, SIZE_MAX, order) != AMSCR_OK) {
        free(order);
        return -1;
    }
    g->j[q * k] = (uint32_t)q;
    g->d[q * k] = 0.0;
    for (size_t t = 1; t < k; t++) {
        g->j[q * k + t] = (uint32_t)cand[order[t - 1]];
        g->d[q * k + t] = dsym[order[t - 1]];
    }
    free(order);
    return 0;
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

/* v <- P v (tmp: scratch of n). */
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

/* The query's row of Q_T into r (n + 1 entries). */
static int diffusion_row(const graph *g, unsigned iters, double *r)
{
    size_t n = g->n;
    double *a = xcalloc_array(n, sizeof(double)), *v = xmalloc_array(n, sizeof(double));
    double *tmp = xmalloc_array(n, sizeof(double));
    if (!a || !v || !tmp) {
        free(a);
        free(v);
        free(tmp);
        return -1;
    }
    memset(r, 0, n * sizeof *r);
    a[n - 1] = 1.0;
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
    free(a);
    free(v);
    free(tmp);
    return 0;
}

int rerank_query_row(const tool_index *x, size_t k, unsigned iters, const size_t *cand, const double *dsym, size_t m,
                     double *out)
{
    size_t n = x->coll.n;
    graph g = {n + 1, k, NULL, NULL, NULL, NULL};
    g.j = xmalloc_array(g.n, k * sizeof(uint32_t));
    g.d = xmalloc_array(g.n, k * sizeof(double));
    g.w = xmalloc_array(g.n, k * sizeof(double));
    g.s = xmalloc_array(g.n, sizeof(double));
    double *dq = xmalloc_array(n, sizeof(double)), *r = xmalloc_array(g.n, sizeof(double));
    unsigned char *have = xcalloc_array(n, 1);
    int ret = -1;
    if (!g.j || !g.d || !g.w || !g.s || !dq || !r || !have)
        goto done;
    double dmax = x->dmax;
    for (size_t t = 0; t < m; t++) {
        dq[cand[t]] = dsym[t];
        have[cand[t]] = 1;
        if (dsym[t] > dmax)
            dmax = dsym[t];
    }
    for (size_t i = 0; i < n; i++)
        collection_row(x, i, dq[i], have[i], &g);
    if (query_row(cand, dsym, m, &g) != 0)
        goto done;
    weights(&g, dmax);
    if (diffusion_row(&g, iters, r) != 0)
        goto done;
    double rmax = 0.0;
    for (size_t i = 0; i < g.n; i++)
        rmax = r[i] > rmax ? r[i] : rmax;
    for (size_t j = 0; j < n; j++) {
        if (r[j] > 0.0 && rmax > 0.0)
            out[j] = 1.0 - r[j] / rmax;
        else
            out[j] = have[j] ? 1.0 + (dmax > 0.0 ? dq[j] / dmax : 0.0) : INFINITY;
    }
    ret = 0;
done:
    free(g.j);
    free(g.d);
    free(g.w);
    free(g.s);
    free(dq);
    free(r);
    free(have);
    return ret;
}

/* The m candidates (ascending): every shape, or the m whose signatures are nearest the query's. */
static size_t candidates(const tool_index *x, const amscr_descriptor *dq, size_t m, size_t *cand)
{
    size_t n = x->coll.n;
    double *sd = m < n ? xmalloc_array(n, sizeof(double)) : NULL;
    if (sd == NULL) {
        for (size_t j = 0; j < n; j++)
            cand[j] = j;
        return n;
    }
    double qs[INDEX_SIG_DIM];
    index_signature(dq, qs);
    for (size_t j = 0; j < n; j++) {
        double s = 0.0;
        for (size_t t = 0; t < INDEX_SIG_DIM; t++) {
            double e = x->sig[j * INDEX_SIG_DIM + t] - qs[t];
            s += e * e;
        }
        sd[j] = s;
    }
    if (amscr_topk(sd, n, m, SIZE_MAX, cand) != AMSCR_OK)
        m = 0;
    free(sd);
    for (size_t i = 1; i < m; i++) { /* ascending indices (insertion sort: m is small) */
        size_t v = cand[i], t = i;
        for (; t > 0 && cand[t - 1] > v; t--)
            cand[t] = cand[t - 1];
        cand[t] = v;
    }
    return m;
}

/* d(q -> cand) into fwd and, for re-ranking, the symmetrized distances into sym. */
static int match(const amscr_db *cdb, const amscr_params *p, const amscr_descriptor *dq, int both, double *fwd,
                 double *sym, size_t m)
{
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = amscr_db_query(cdb, dq, progress_cb, &pr, fwd);
    amscr_db *qdb = NULL;
    if (st == AMSCR_OK && both && !amscr_params_get_symmetric(p)) {
        st = amscr_db_new(p, &qdb);
        if (st == AMSCR_OK)
            st = amscr_db_add_descriptor(qdb, dq, -1, NULL);
        if (st == AMSCR_OK)
            st = amscr_db_cross_distances(cdb, qdb, progress_cb, &pr, sym); /* d(cand -> q) */
        for (size_t t = 0; st == AMSCR_OK && t < m; t++)
            sym[t] = 0.5 * (fwd[t] + sym[t]);
    } else if (st == AMSCR_OK && both) {
        memcpy(sym, fwd, m * sizeof *sym);
    }
    progress_end(&pr);
    amscr_db_free(qdb);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return -1;
    }
    return 0;
}

int index_search(const tool_index *x, const amscr_params *p, const amscr_descriptor *dq, size_t ncand, size_t rerank_k,
                 unsigned iters, double *out)
{
    size_t n = x->coll.n, k = rerank_k < n + 1 ? rerank_k : n + 1;
    size_t m = ncand == 0 || ncand >= n || k > n ? n : ncand;
    size_t *cand = xmalloc_array(n, sizeof(size_t));
    double *fwd = xmalloc_array(n, sizeof(double)), *sym = xmalloc_array(n, sizeof(double));
    amscr_db *cdb = NULL;
    int ret = -1;
    if (!cand || !fwd || !sym)
        goto done;
    m = candidates(x, dq, m, cand);
    if (m == 0 || index_fetch(x, p, cand, m, &cdb) != 0 || match(cdb, p, dq, k > 0, fwd, sym, m) != 0)
        goto done;
    if (k == 0) {
        for (size_t j = 0; j < n; j++)
            out[j] = INFINITY;
        for (size_t t = 0; t < m; t++)
            out[cand[t]] = fwd[t];
        ret = 0;
    } else if (k - 1 > m) {
        tool_error(NULL, "--rerank %zu needs at least %zu candidates", k, k - 1);
    } else {
        ret = rerank_query_row(x, k, iters, cand, sym, m, out);
    }
done:
    amscr_db_free(cdb);
    free(cand);
    free(fwd);
    free(sym);
    return ret;
}
