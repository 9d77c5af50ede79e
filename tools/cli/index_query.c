/* index_query.c — one query against an index (`amscr search QUERY INDEX`): base distances
 * (index_dist.h) to the candidate shapes and, with re-ranking, the query's row of the
 * retrieval matrix's diffusion (amscr_db_retrieval_matrix: amscr_rerank_diffusion halved into
 * [0, 1], 0 for the query itself) on the collection plus the query, from the stored neighbour
 * lists alone. A query that is one of the index's shapes (the same prepared samples, bit for
 * bit) gets that shape's row of the collection's matrix instead, as a folder search does for
 * a member file; so with every shape a candidate (--candidates 0), an index built from the
 * full matrix gives the folder's scores (fused channel weights: with the medians of the
 * index's build, where the folder's matrix recomputes them with the query).
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

/* Row `start` of Q_T into r (g->n entries). */
static int diffusion_row(const graph *g, size_t start, unsigned iters, double *r)
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
    free(a);
    free(v);
    free(tmp);
    return 0;
}

/* out[j] (j < n) from the diffused row r (len entries): halved 1 - r / max r where reached,
 * 0.5 + half the base distance / dmax for the matched shapes it does not reach, +inf for the
 * others; 0 for `self` (the library's normalization of the retrieval matrix). */
static void scores(const double *r, size_t len, size_t n, size_t self, const double *dq, const unsigned char *have,
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
            out[j] = have[j] ? 0.5 * (1.0 + (dmax > 0.0 ? dq[j] / dmax : 0.0)) : INFINITY;
    }
}

/* A graph of n rows of k neighbours; returns 0 when out of memory (graph_free releases). */
static int graph_alloc(graph *g, size_t n, size_t k)
{
    graph e = {n, k, NULL, NULL, NULL, NULL};
    *g = e;
    g->j = xmalloc_array(n, k * sizeof(uint32_t));
    g->d = xmalloc_array(n, k * sizeof(double));
    g->w = xmalloc_array(n, k * sizeof(double));
    g->s = xmalloc_array(n, sizeof(double));
    return g->j && g->d && g->w && g->s;
}

static void graph_free(graph *g)
{
    free(g->j);
    free(g->d);
    free(g->w);
    free(g->s);
}

/* Row `member` of the collection's re-ranked matrix (the query is that shape): the stored
 * lists alone, K = k <= x->k; dsym[t] the base distance of the member and cand[t]. */
static int member_row(const tool_index *x, size_t k, unsigned iters, size_t member, const size_t *cand,
                      const double *dsym, size_t m, double *out)
{
    size_t n = x->coll.n;
    graph g;
    int ok = graph_alloc(&g, n, k);
    double *dq = xmalloc_array(n, sizeof(double)), *r = xmalloc_array(n, sizeof(double));
    unsigned char *have = xcalloc_array(n, 1);
    int ret = -1;
    if (ok && dq && r && have) {
        for (size_t t = 0; t < m; t++) {
            dq[cand[t]] = dsym[t];
            have[cand[t]] = 1;
        }
        for (size_t i = 0; i < n; i++)
            collection_row(x, i, 0.0, 0, &g);
        weights(&g, x->dmax);
        if (diffusion_row(&g, member, iters, r) == 0) {
            scores(r, n, n, member, dq, have, x->dmax, out);
            ret = 0;
        }
    }
    graph_free(&g);
    free(dq);
    free(r);
    free(have);
    return ret;
}

int rerank_query_row(const tool_index *x, size_t k, unsigned iters, const size_t *cand, const double *dsym, size_t m,
                     double *out)
{
    size_t n = x->coll.n;
    graph g;
    int ok = graph_alloc(&g, n + 1, k);
    double *dq = xmalloc_array(n, sizeof(double)), *r = xmalloc_array(g.n, sizeof(double));
    unsigned char *have = xcalloc_array(n, 1);
    int ret = -1;
    if (!ok || !dq || !r || !have)
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
    if (diffusion_row(&g, n, iters, r) != 0)
        goto done;
    scores(r, g.n, n, SIZE_MAX, dq, have, dmax, out);
    ret = 0;
done:
    graph_free(&g);
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

/* The candidate (position in cand) whose prepared samples are the query's, bit for bit, or
 * SIZE_MAX: the query is that shape of the index. */
static size_t member_of(const amscr_db *cdb, const amscr_descriptor *dq, size_t m)
{
    size_t ns = amscr_descriptor_num_samples(dq);
    const double *q = amscr_descriptor_input_points(dq);
    for (size_t t = 0; t < m; t++) {
        const amscr_descriptor *d = amscr_db_descriptor(cdb, t);
        if (amscr_descriptor_num_samples(d) == ns && memcmp(amscr_descriptor_input_points(d), q, 2 * ns * sizeof *q) == 0)
            return t;
    }
    return SIZE_MAX;
}

/* d(q -> cand) into fwd (the plain distance) and, when `base`, the base distances of the
 * candidates and the query into bd: the query last (index_dist.h), or, when it is shape
 * `member` of the index, in that shape's place (the channel's lower index first). */
static int match(const tool_index *x, const amscr_db *cdb, const size_t *cand, size_t member, const amscr_params *p,
                 const amscr_descriptor *dq, int base, double *fwd, double *bd, size_t m)
{
    base_dist b = {p, amscr_params_get_channel_weight(p), x->med_a, x->med_h};
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = AMSCR_OK;
    int amscr = !base || base_uses_amscr(&b);
    if (amscr)
        st = amscr_db_query(cdb, dq, progress_cb, &pr, fwd);
    amscr_db *qdb = NULL;
    if (st == AMSCR_OK && base && amscr) { /* d(cand -> q), symmetrized */
        st = amscr_db_new(p, &qdb);
        if (st == AMSCR_OK)
            st = amscr_db_add_descriptor(qdb, dq, -1, NULL);
        if (st == AMSCR_OK)
            st = amscr_db_cross_distances(cdb, qdb, progress_cb, &pr, bd);
        for (size_t t = 0; st == AMSCR_OK && t < m; t++)
            bd[t] = 0.5 * (bd[t] + fwd[t]);
    }
    for (size_t t = 0; st == AMSCR_OK && base && t < m; t++) {
        double h = 0.0;
        const amscr_descriptor *dc = amscr_db_descriptor(cdb, t);
        if (base_uses_channel(&b))
            st = member != SIZE_MAX && cand[t] > member ? amscr_channel_distance(p, dq, dc, &h)
                                                        : amscr_channel_distance(p, dc, dq, &h);
        bd[t] = base_combine(&b, amscr ? bd[t] : 0.0, h);
    }
    progress_end(&pr);
    amscr_db_free(qdb);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return -1;
    }
    return 0;
}

int index_search(const tool_index *x, const amscr_params *p, const amscr_descriptor *dq, size_t ncand, double *out)
{
    size_t n = x->coll.n, rk = amscr_params_get_rerank_k(p), k = rk < n + 1 ? rk : n + 1;
    unsigned iters = amscr_params_get_rerank_iterations(p);
    int plain = amscr_params_get_channel_weight(p) <= 0.0 && k == 0; /* as the folder's search */
    size_t m = ncand == 0 || ncand >= n || k > n ? n : ncand;
    size_t *cand = xmalloc_array(n, sizeof(size_t));
    double *fwd = xmalloc_array(n, sizeof(double)), *bd = xmalloc_array(n, sizeof(double));
    amscr_db *cdb = NULL;
    int ret = -1;
    if (!cand || !fwd || !bd)
        goto done;
    m = candidates(x, dq, m, cand);
    if (m == 0 || index_fetch(x, p, cand, m, &cdb) != 0)
        goto done;
    /* a member query: ranked by its row of the collection's matrix, as a folder search (which
     * reads the matrix unless the channel alone is used without re-ranking) */
    int by_matrix = k > 0 || amscr_params_get_channel_weight(p) < 1.0;
    size_t member = by_matrix ? member_of(cdb, dq, m) : SIZE_MAX;
    if (match(x, cdb, cand, member == SIZE_MAX ? SIZE_MAX : cand[member], p, dq, !plain, fwd, bd, m) != 0)
        goto done;
    if (k == 0) {
        for (size_t j = 0; j < n; j++)
            out[j] = INFINITY;
        for (size_t t = 0; t < m; t++)
            out[cand[t]] = plain ? fwd[t] : bd[t];
        ret = 0;
    } else if (member != SIZE_MAX) {
        ret = member_row(x, rk < n ? rk : n, iters, cand[member], cand, bd, m, out);
    } else if (k - 1 > m) {
        tool_error(NULL, "--rerank %zu needs at least %zu candidates", k, k - 1);
    } else {
        ret = rerank_query_row(x, k, iters, cand, bd, m, out);
    }
done:
    amscr_db_free(cdb);
    free(cand);
    free(fwd);
    free(bd);
    return ret;
}
