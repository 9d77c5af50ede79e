/* index_graph.c — the kNN graph P of the collection plus a query, whose diffusion
 * (index_diffuse.c) gives the query's row of the retrieval scores: the row-normalized affinities
 * of the n + 1 shapes, each row built from the stored lists when the diffusion first reaches it.
 * Adding the query changes the neighbour list of every shape it is nearer to than that shape's
 * K-th neighbour, and nothing else, so the stored lists (plus the query) give P exactly. With
 * the inner distance's graph, P = (1 - s) P1 + s P2: a row holds both lists (2K entries), each
 * normalized to its share, and the query enters each list by its own distance. A row the query
 * enters neither directly nor through a neighbour's list has the affinities the index computed
 * once (x->w_fixed): the query copies them instead of recomputing its exponentials. */
#include "index_graph.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Rows a graph first has room for (it grows by doubling). */
enum { GRAPH_ROWS0 = 256 };

amscr_status amscr__graph_alloc(amscr__graph *g, size_t n, size_t k, size_t k2)
{
    g->n = n;
    g->k = k;
    g->k2 = k2;
    g->kk = k + k2;
    g->cap = (n < GRAPH_ROWS0 ? n : GRAPH_ROWS0) + 1;
    g->used = 1; /* slot 0: the spare row */
    g->oom = 0;
    g->j = amscr__malloc_array(g->cap, g->kk * sizeof *g->j);
    g->d = amscr__malloc_array(g->cap, g->kk * sizeof *g->d);
    g->w = amscr__malloc_array(g->cap, g->kk * sizeof *g->w);
    g->slot = amscr__malloc_array(n ? n : 1, sizeof *g->slot);
    g->state = amscr__calloc_array(n ? n : 1, 1);
    return g->j && g->d && g->w && g->slot && g->state ? AMSCR_OK
                                                        : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
}

void amscr__graph_free(amscr__graph *g)
{
    free(g->j);
    free(g->d);
    free(g->w);
    free(g->slot);
    free(g->state);
}

/* Room for row i (not built yet): the next slot, the storage doubled when full; out of memory,
 * the spare slot 0 and g->oom. */
static void claim(amscr__graph *g, size_t i)
{
    if (g->used == g->cap) {
        size_t cap = 2 * g->cap < g->n + 1 ? 2 * g->cap : g->n + 1, kk = g->kk ? g->kk : 1;
        uint32_t *j = cap > SIZE_MAX / kk / sizeof *j ? NULL : realloc(g->j, cap * kk * sizeof *j);
        if (j)
            g->j = j;
        double *d = j && cap <= SIZE_MAX / kk / sizeof *d ? realloc(g->d, cap * kk * sizeof *d) : NULL;
        if (d)
            g->d = d;
        double *w = d ? realloc(g->w, cap * kk * sizeof *w) : NULL;
        if (w) {
            g->w = w;
            g->cap = cap;
        }
    }
    if (g->used == g->cap) {
        g->oom = 1;
        g->slot[i] = 0;
        return;
    }
    g->slot[i] = (uint32_t)g->used++;
}

/* k entries (j, d) of a row from a stored list (sj, sd: ks entries) with the query (index q,
 * distance dq) merged in by (distance, index) when `have`. */
static void merge_row(const uint32_t *sj, const double *sd, size_t ks, size_t q, double dq, int have, size_t k,
                      uint32_t *j, double *d)
{
    size_t o = 0;
    int placed = !have;
    for (size_t t = 0; t < k; t++) {
        if (!placed && (o >= ks || (o > 0 && sd[o] > dq))) { /* ties: the query's index is the highest */
            j[t] = (uint32_t)q;
            d[t] = dq;
            placed = 1;
        } else { /* (past the stored list only for a shape the query was not matched with) */
            j[t] = sj[o < ks ? o : ks - 1];
            d[t] = sd[o < ks ? o : ks - 1];
            o++;
        }
    }
}

/* Row i of the graph: its stored lists with the query (index g->n - 1) merged in when `have`. */
static void collection_row(const amscr_index *x, size_t i, int have, amscr__graph *g)
{
    size_t o = amscr__graph_row(g, i), q = g->n - 1;
    merge_row(x->nb_idx + i * x->k, x->nb_dist + i * x->k, x->k, q, have ? g->dfull[i] : 0.0, have, g->k,
              g->j + o, g->d + o);
    if (g->k2 > 0)
        merge_row(x->in_idx + i * x->k2, x->in_dist + i * x->k2, x->k2, q, have ? g->dfull2[i] : 0.0, have, g->k2,
                  g->j + o + g->k, g->d + o + g->k);
}

/* The query's k entries from (off): itself, then its k - 1 nearest candidates by (distance dq,
 * index). */
static amscr_status query_part(const size_t *cand, const double *dq, size_t m, size_t k, size_t off, amscr__graph *g)
{
    size_t q = g->n - 1, o = amscr__graph_row(g, q) + off, *order = amscr__malloc_array(m ? m : 1, sizeof *order);
    if (!order)
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    amscr_status st = amscr_topk(dq, m, k - 1, SIZE_MAX, order);
    if (st == AMSCR_OK) {
        g->j[o] = (uint32_t)q;
        g->d[o] = 0.0;
        for (size_t t = 1; t < k; t++) {
            g->j[o + t] = (uint32_t)cand[order[t - 1]];
            g->d[o + t] = dq[order[t - 1]];
        }
    }
    free(order);
    return st;
}

amscr_status amscr__graph_query_row(amscr__graph *g, const amscr__qrow *q)
{
    claim(g, g->n - 1);
    if (g->oom)
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    amscr_status st = query_part(q->cand, q->dq, q->m, g->k, 0, g);
    if (st == AMSCR_OK && g->k2 > 0)
        st = query_part(q->cand, q->dq2, q->m, g->k2, g->k, g);
    if (st == AMSCR_OK)
        g->state[g->n - 1] = 1;
    return st;
}

static void need_row(amscr__graph *g, size_t i)
{
    if (g->state[i] == 0) {
        claim(g, i);
        collection_row(g->x, i, g->query && g->have[i], g);
        g->state[i] = 1;
    }
}

/* The affinities of a row's k entries from `off` (one graph's part) exp(-D / sqrt(s_i s_j)),
 * normalized to sum `mass` (as amscr_rerank_diffusion), with s the rows' k-th distances. */
static void part_weights(amscr__graph *g, size_t i, size_t off, size_t k, double tiny, double mass)
{
    size_t o = amscr__graph_row(g, i) + off;
    double sum = 0.0, si = g->d[o + k - 1], *w = g->w + o;
    const uint32_t *jj = g->j + o;
    const double *d = g->d + o;
    for (size_t t = 0; t < k; t++) {
        double s = sqrt((si + tiny) * (g->d[amscr__graph_row(g, jj[t]) + off + k - 1] + tiny));
        w[t] = exp(-d[t] / s);
        sum += w[t];
    }
    for (size_t t = 0; t < k; t++)
        w[t] = mass * (w[t] / sum); /* exactly w / sum for one amscr__graph */
}

/* Whether the query enters stored row i's list (either graph's), as merge_row places it: before
 * the k-th entry, ties after the stored ones. */
static int entered(const amscr__graph *g, size_t i)
{
    const amscr_index *x = g->x;
    if (!g->query || !g->have[i])
        return 0;
    if (g->k >= 2 && (g->k > x->k || x->nb_dist[i * x->k + g->k - 1] > g->dfull[i]))
        return 1;
    return g->k2 >= 2 && (g->k2 > x->k2 || x->in_dist[i * x->k2 + g->k2 - 1] > g->dfull2[i]);
}

/* Whether stored row i keeps the affinities of x->w_fixed: the query enters neither its lists
 * nor its neighbours' (whose k-th distances scale its affinities). */
static int left_alone(const amscr__graph *g, size_t i)
{
    const amscr_index *x = g->x;
    if (!g->fixed || (g->query && i == g->n - 1) || entered(g, i))
        return 0;
    for (size_t t = 0; t < g->k; t++)
        if (entered(g, x->nb_idx[i * x->k + t]))
            return 0;
    for (size_t t = 0; t < g->k2; t++)
        if (entered(g, x->in_idx[i * x->k2 + t]))
            return 0;
    return 1;
}

/* Row i's affinities, each graph's part normalized to its share of the row's mass. */
void amscr__graph_weights(amscr__graph *g, size_t i)
{
    size_t kk = g->kk;
    if (g->state[i] == 2)
        return;
    need_row(g, i);
    if (left_alone(g, i)) {
        memcpy(g->w + amscr__graph_row(g, i), g->fixed + i * kk, kk * sizeof *g->w);
        g->state[i] = 2;
        return;
    }
    for (size_t t = 0; t < kk; t++) /* (each may move the rows: i's offset read anew) */
        need_row(g, g->j[amscr__graph_row(g, i) + t]);
    part_weights(g, i, 0, g->k, g->tiny, g->k2 > 0 ? 1.0 - g->share : 1.0);
    if (g->k2 > 0)
        part_weights(g, i, g->k, g->k2, g->tiny2, g->share);
    g->state[i] = 2;
}

/* The largest of d0 and the m values d. */
static double largest(double d0, const double *d, size_t m)
{
    for (size_t t = 0; t < m; t++)
        d0 = d[t] > d0 ? d[t] : d0;
    return d0;
}

void amscr__graph_setup(amscr__graph *g, const amscr_index *x, size_t self, const amscr__qrow *q)
{
    size_t n = amscr_db_size(x->db);
    double dmax = self == n ? largest(x->dmax, q->dq, q->m) : x->dmax;
    double dmax2 = self == n && q->dq2 ? largest(x->dmax2, q->dq2, q->m) : x->dmax2;
    g->x = x;
    g->dmax = dmax;
    g->dfull = q->dfull;
    g->dfull2 = q->dfull2;
    g->have = q->have;
    g->query = self == n;
    g->tiny = dmax > 0.0 ? 1e-12 * dmax : 1e-300;
    g->tiny2 = dmax2 > 0.0 ? 1e-12 * dmax2 : 1e-300;
    g->share = amscr_db_params(x->db)->rerank_inner_share;
    g->cand = q->cand;
    g->m = self == n ? q->m : 0;
    int fixed_holds = g->k == x->w_k && g->kk == x->w_kk && g->k <= x->k && g->k2 <= x->k2 && g->tiny == x->w_tiny &&
                      g->tiny2 == x->w_tiny2;
    g->fixed = x->w_fixed && fixed_holds ? x->w_fixed : NULL;
}

/* A query that enters no row: n + 1 rows, the collection's largest distances (x->w_fixed NULL
 * on entry: the graph copies none). */
amscr_status amscr__graph_fixed_weights(amscr_index *x)
{
    size_t n = amscr_db_size(x->db), k = amscr__rerank_k(amscr_db_params(x->db), n + 1);
    amscr__graph g = {0};
    unsigned char *have = amscr__calloc_array(n ? n : 1, 1);
    amscr__qrow q = {NULL, NULL, NULL, 0, NULL, NULL, have};
    amscr_status st = have ? amscr__graph_alloc(&g, n + 1, k, x->k2 > 0 ? k : 0)
                           : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    double *w = st == AMSCR_OK ? amscr__malloc_array(n ? n : 1, g.kk * sizeof *w) : NULL;
    if (st == AMSCR_OK && !w)
        st = amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    if (st == AMSCR_OK) {
        amscr__graph_setup(&g, x, n, &q);
        for (size_t i = 0; i < n; i++)
            amscr__graph_weights(&g, i);
        if (g.oom)
            st = amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    }
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) /* by row */
        memcpy(w + i * g.kk, g.w + amscr__graph_row(&g, i), g.kk * sizeof *w);
    if (st == AMSCR_OK) {
        x->w_fixed = w;
        w = NULL;
        x->w_k = k;
        x->w_kk = g.kk;
        x->w_tiny = g.tiny;
        x->w_tiny2 = g.tiny2;
    }
    amscr__graph_free(&g);
    free(have);
    free(w);
    return st;
}
