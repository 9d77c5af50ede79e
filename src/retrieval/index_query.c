/* index_query.c — one query against an index: base distances (fuse.c, pair by pair) to the
 * candidate shapes and, with re-ranking, the query's row of the retrieval matrix's diffusion
 * (amscr_db_retrieval_matrix: amscr_rerank_diffusion halved into [0, 1]) on the collection
 * plus the query, from the stored neighbour lists alone.
 *
 * With P the row-normalized kNN affinities of the n + 1 shapes, Q_0 = P and
 * Q <- P Q P^T + I for T iterations give
 *     Q_T = sum_{t=0}^{T-1} P^t (P^T)^t + P^T P (P^T)^T   (powers),
 * so row q is sum_t P^t (e_q P^t)^T + P^T (e_q P^T P)^T (as columns), summed by Horner's rule:
 * 2T + 1 sparse vector products, O(T (n+1) K) instead of the O(T n^2 K) of the whole matrix
 * (O(T^2 (n+1) K) term by term, as before 0.8). Adding the query
 * changes the neighbour list of every shape it is nearer to than that shape's K-th
 * neighbour, and nothing else, so the stored lists (plus the query) give P exactly. With the
 * inner distance's graph, P = (1 - s) P1 + s P2: a row holds both lists (2K entries), each
 * normalized to its share, and the query enters each list by its own distance. A row the query
 * enters neither directly nor through a neighbour's list has the affinities the index computed
 * once (x->w_fixed): the query copies them instead of recomputing its exponentials. */
#include "index.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The graph of the n + 1 (or n) shapes, its rows built on demand: a query touches only the
 * shapes its diffusion reaches, never the whole collection. */
typedef struct {
    size_t n, k, k2, kk;   /* rows (the query last, when there is one), kk = k + k2 entries each: k of the
                            * base distance's graph, then k2 of the inner distance's (0: one graph) */
    uint32_t *j;           /* neighbours */
    double *d, *w;         /* base (then inner) distances, then the affinities */
    unsigned char *state;  /* per row: 0 not built, 1 list built, 2 affinities too */
    const amscr_index *x;
    const double *dfull;   /* the query's distances (dfull[i] where have[i]) */
    const double *dfull2;  /* and its inner distances (with the inner graph) */
    const unsigned char *have;
    int query;             /* row n - 1 is the query */
    double dmax;           /* largest base distance (the query's included) */
    double tiny, tiny2;
    double share;          /* the inner graph's share of a row's mass */
    const size_t *rs;      /* the stored lists' reverse (x's or built for this query) */
    const uint32_t *rv;
    const size_t *cand;    /* the query's candidates (the rows it may enter) */
    size_t m;
    const double *fixed;   /* the stored rows' affinities (x->w_fixed) when they hold for this graph, else NULL */
} graph;

static amscr_status graph_alloc(graph *g, size_t n, size_t k, size_t k2)
{
    g->n = n;
    g->k = k;
    g->k2 = k2;
    g->kk = k + k2;
    g->j = amscr__malloc_array(n, g->kk * sizeof *g->j);
    g->d = amscr__malloc_array(n, g->kk * sizeof *g->d);
    g->w = amscr__malloc_array(n, g->kk * sizeof *g->w);
    g->state = amscr__calloc_array(n, 1);
    return g->j && g->d && g->w && g->state ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
}

static void graph_free(graph *g)
{
    free(g->j);
    free(g->d);
    free(g->w);
    free(g->state);
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
static void collection_row(const amscr_index *x, size_t i, int have, graph *g)
{
    size_t kk = g->kk, q = g->n - 1;
    merge_row(x->nb_idx + i * x->k, x->nb_dist + i * x->k, x->k, q, have ? g->dfull[i] : 0.0, have, g->k,
              g->j + i * kk, g->d + i * kk);
    if (g->k2 > 0)
        merge_row(x->in_idx + i * x->k2, x->in_dist + i * x->k2, x->k2, q, have ? g->dfull2[i] : 0.0, have, g->k2,
                  g->j + i * kk + g->k, g->d + i * kk + g->k);
}

/* The query's k entries from (off): itself, then its k - 1 nearest candidates by (distance dq,
 * index). */
static amscr_status query_part(const size_t *cand, const double *dq, size_t m, size_t k, size_t off, graph *g)
{
    size_t kk = g->kk, q = g->n - 1, *order = amscr__malloc_array(m ? m : 1, sizeof *order);
    if (!order)
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    amscr_status st = amscr_topk(dq, m, k - 1, SIZE_MAX, order);
    if (st == AMSCR_OK) {
        g->j[q * kk + off] = (uint32_t)q;
        g->d[q * kk + off] = 0.0;
        for (size_t t = 1; t < k; t++) {
            g->j[q * kk + off + t] = (uint32_t)cand[order[t - 1]];
            g->d[q * kk + off + t] = dq[order[t - 1]];
        }
    }
    free(order);
    return st;
}

/* The query's row: each graph's part (dq2: the inner distances to the candidates). */
static amscr_status query_row(const size_t *cand, const double *dq, const double *dq2, size_t m, graph *g)
{
    amscr_status st = query_part(cand, dq, m, g->k, 0, g);
    if (st == AMSCR_OK && g->k2 > 0)
        st = query_part(cand, dq2, m, g->k2, g->k, g);
    if (st == AMSCR_OK)
        g->state[g->n - 1] = 1;
    return st;
}

static void need_row(graph *g, size_t i)
{
    if (g->state[i] == 0) {
        collection_row(g->x, i, g->query && g->have[i], g);
        g->state[i] = 1;
    }
}

/* The affinities of a row's k entries from `off` (one graph's part) exp(-D / sqrt(s_i s_j)),
 * normalized to sum `mass` (as amscr_rerank_diffusion), with s the rows' k-th distances. */
static void part_weights(graph *g, size_t i, size_t off, size_t k, double tiny, double mass)
{
    size_t kk = g->kk;
    double sum = 0.0, si = g->d[i * kk + off + k - 1], *w = g->w + i * kk + off;
    const uint32_t *jj = g->j + i * kk + off;
    const double *d = g->d + i * kk + off;
    for (size_t t = 0; t < k; t++) {
        double s = sqrt((si + tiny) * (g->d[(size_t)jj[t] * kk + off + k - 1] + tiny));
        w[t] = exp(-d[t] / s);
        sum += w[t];
    }
    for (size_t t = 0; t < k; t++)
        w[t] = mass * (w[t] / sum); /* exactly w / sum for one graph */
}

/* Whether the query enters stored row i's list (either graph's), as merge_row places it: before
 * the k-th entry, ties after the stored ones. */
static int entered(const graph *g, size_t i)
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
static int left_alone(const graph *g, size_t i)
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
static void need_weights(graph *g, size_t i)
{
    size_t kk = g->kk;
    if (g->state[i] == 2)
        return;
    need_row(g, i);
    if (left_alone(g, i)) {
        memcpy(g->w + i * kk, g->fixed + i * kk, kk * sizeof *g->w);
        g->state[i] = 2;
        return;
    }
    for (size_t t = 0; t < kk; t++)
        need_row(g, g->j[i * kk + t]);
    part_weights(g, i, 0, g->k, g->tiny, g->k2 > 0 ? 1.0 - g->share : 1.0);
    if (g->k2 > 0)
        part_weights(g, i, g->k, g->k2, g->tiny2, g->share);
    g->state[i] = 2;
}

/* A sparse vector: dense values (zero outside sup) and its support, ascending. */
typedef struct {
    double *v;
    size_t *sup, len;
} svec;

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* Scratch of the products: a marked set and a value vector (zero, unmarked between calls). */
typedef struct {
    double *tmp;
    unsigned char *mark;
    size_t *list;
} sscratch;

/* The c entries of list (each marked in mark, of n) in ascending order: sorted, or, when they
 * are many, read off the marks (the same order, without the sort's cost). */
static void order_marked(size_t *list, size_t c, const unsigned char *mark, size_t n)
{
    if (c < 2)
        return;
    if (c * 16 < n) {
        qsort(list, c, sizeof *list, cmp_size);
        return;
    }
    size_t u = 0;
    for (size_t j = 0; j < n && u < c; j++)
        if (mark[j])
            list[u++] = j;
}

/* out <- in P (in's rows pushed to their neighbours, rows in ascending order as the dense sum). */
static void apply_rows(graph *g, const svec *in, svec *out, sscratch *s)
{
    size_t k = g->kk, c = 0;
    for (size_t u = 0; u < in->len; u++) {
        size_t i = in->sup[u];
        if (in->v[i] == 0.0)
            continue;
        need_weights(g, i);
        for (size_t t = 0; t < k; t++) {
            size_t j = g->j[i * k + t];
            if (!s->mark[j]) {
                s->mark[j] = 1;
                s->list[c++] = j;
            }
            s->tmp[j] += in->v[i] * g->w[i * k + t];
        }
    }
    order_marked(s->list, c, s->mark, g->n);
    for (size_t u = 0; u < out->len; u++)
        out->v[out->sup[u]] = 0.0;
    for (size_t u = 0; u < c; u++) {
        size_t j = s->list[u];
        out->v[j] = s->tmp[j];
        out->sup[u] = j;
        s->tmp[j] = 0.0;
        s->mark[j] = 0;
    }
    out->len = c;
}

/* Marks row i as a row P in may reach. */
static void reach(sscratch *s, size_t i, size_t *c)
{
    if (!s->mark[i]) {
        s->mark[i] = 1;
        s->list[(*c)++] = i;
    }
}

/* The rows P v may make nonzero into s->list (c, ascending; marked): those holding a shape of
 * v's support (the stored lists' reverse), the shapes themselves, the query and the rows it may
 * enter. */
static void reach_rows(const graph *g, const svec *v, sscratch *s, size_t *c)
{
    size_t n = g->query ? g->n - 1 : g->n;
    int to_query = 0;
    for (size_t u = 0; u < v->len; u++) {
        size_t j = v->sup[u];
        if (j >= n) {
            to_query = 1;
            continue;
        }
        for (size_t r = g->rs[j]; r < g->rs[j + 1]; r++)
            reach(s, g->rv[r], c);
        reach(s, j, c);
    }
    if (g->query && v->len > 0)
        reach(s, n, c);
    for (size_t t = 0; to_query && t < g->m; t++)
        reach(s, g->cand[t], c);
    order_marked(s->list, *c, s->mark, g->n);
}

/* v <- P v: only the rows reach_rows finds can be nonzero; when v covers a quarter of the rows,
 * every row is computed instead of finding them. */
static void apply_cols(graph *g, svec *v, sscratch *s)
{
    size_t k = g->kk, c = 0;
    if (v->len * 4 >= g->n) { /* most rows reachable: every row, in order (the others sum to 0) */
        for (c = 0; c < g->n; c++)
            s->list[c] = c;
    } else {
        reach_rows(g, v, s, &c);
    }
    for (size_t u = 0; u < c; u++) {
        size_t i = s->list[u];
        need_weights(g, i);
        double sum = 0.0;
        for (size_t t = 0; t < k; t++)
            sum += g->w[i * k + t] * v->v[g->j[i * k + t]];
        s->tmp[i] = sum;
    }
    for (size_t u = 0; u < v->len; u++)
        v->v[v->sup[u]] = 0.0;
    size_t len = 0;
    for (size_t u = 0; u < c; u++) {
        size_t i = s->list[u];
        s->mark[i] = 0;
        if (s->tmp[i] != 0.0) {
            v->v[i] = s->tmp[i];
            v->sup[len++] = i;
        }
        s->tmp[i] = 0.0;
    }
    v->len = len;
}

static void svec_copy(svec *dst, const svec *src)
{
    for (size_t u = 0; u < dst->len; u++)
        dst->v[dst->sup[u]] = 0.0;
    for (size_t u = 0; u < src->len; u++) {
        dst->v[src->sup[u]] = src->v[src->sup[u]];
        dst->sup[u] = src->sup[u];
    }
    dst->len = src->len;
}

/* A sparse vector's values on its support, kept while the diffusion goes on. */
typedef struct {
    double *v;
    size_t *sup, len;
} spacked;

static amscr_status pack(const svec *x, spacked *out)
{
    out->len = x->len;
    out->v = amscr__malloc_array(x->len ? x->len : 1, sizeof *out->v);
    out->sup = amscr__malloc_array(x->len ? x->len : 1, sizeof *out->sup);
    if (!out->v || !out->sup)
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    for (size_t u = 0; u < x->len; u++) {
        out->sup[u] = x->sup[u];
        out->v[u] = x->v[x->sup[u]];
    }
    return AMSCR_OK;
}

/* y += x (y's values are positive on its support and zero elsewhere; x's zeros are skipped). */
static void add_packed(svec *y, const spacked *x)
{
    for (size_t u = 0; u < x->len; u++) {
        size_t i = x->sup[u];
        if (x->v[u] == 0.0)
            continue;
        if (y->v[i] == 0.0)
            y->sup[y->len++] = i;
        y->v[i] += x->v[u];
    }
}

/* The row vectors a_t = e_start P^t, t = 0..iters - 1, packed into rows[t], and a_(iters + 1)
 * into last (a, b: work vectors, a holding e_start on entry). */
static amscr_status row_powers(graph *g, unsigned iters, svec *a, svec *b, sscratch *s, spacked *rows, svec *last)
{
    amscr_status st = AMSCR_OK;
    for (unsigned t = 0; st == AMSCR_OK && t < iters; t++) {
        st = pack(a, &rows[t]);
        apply_rows(g, a, b, s);
        svec_copy(a, b);
    }
    if (st == AMSCR_OK)
        apply_rows(g, a, last, s); /* e_start P^iters P */
    return st;
}

/* Row `start` of Q_T into r (g->n entries, zero on entry); its support into rsup / rlen. With
 * v_t = (e_start P^t)^T for t < T and v_T = (e_start P^(T+1))^T the row is
 * sum_t P^t v_t = v_0 + P (v_1 + P (... + P v_T)), by Horner's rule: T products P v (not the
 * T (T + 1) / 2 of the sum term by term); the values are the same to rounding. */
static amscr_status diffusion_row(graph *g, size_t start, unsigned iters, double *r, size_t *rsup, size_t *rlen)
{
    size_t n = g->n;
    svec a = {amscr__calloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    svec v = {amscr__calloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    svec b = {amscr__calloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    sscratch s = {amscr__calloc_array(n, sizeof(double)), amscr__calloc_array(n, 1),
                  amscr__malloc_array(n, sizeof(size_t))};
    spacked *rows = calloc(iters ? iters : 1, sizeof *rows);
    amscr_status st = a.v && a.sup && v.v && v.sup && b.v && b.sup && s.tmp && s.mark && s.list && rows
                          ? AMSCR_OK
                          : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    *rlen = 0;
    if (st == AMSCR_OK) {
        a.v[start] = 1.0;
        a.sup[0] = start;
        a.len = 1;
        st = row_powers(g, iters, &a, &b, &s, rows, &v);
    }
    for (unsigned t = iters; st == AMSCR_OK && t-- > 0;) {
        apply_cols(g, &v, &s);
        add_packed(&v, &rows[t]);
    }
    for (size_t u = 0; st == AMSCR_OK && u < v.len; u++) {
        r[v.sup[u]] = v.v[v.sup[u]];
        rsup[(*rlen)++] = v.sup[u];
    }
    for (unsigned t = 0; rows && t < iters; t++) {
        free(rows[t].v);
        free(rows[t].sup);
    }
    free(rows);
    free(a.v);
    free(a.sup);
    free(v.v);
    free(v.sup);
    free(b.v);
    free(b.sup);
    free(s.tmp);
    free(s.mark);
    free(s.list);
    return st;
}

/* out[j] (j < n) from the diffused row r (support rsup): halved 1 - r / max r where reached,
 * 0.5 + half the base distance / dmax for the matched shapes it does not reach, +inf for the
 * others; 0 for `self` (the library's normalization of the retrieval matrix). */
static void scores(const double *r, const size_t *rsup, size_t rlen, size_t n, size_t self, const double *dfull,
                   const unsigned char *have, double dmax, double *out)
{
    double rmax = 0.0;
    for (size_t u = 0; u < rlen; u++)
        rmax = r[rsup[u]] > rmax ? r[rsup[u]] : rmax;
    for (size_t j = 0; j < n; j++) {
        if (j == self)
            out[j] = 0.0;
        else if (r[j] > 0.0 && rmax > 0.0)
            out[j] = 0.5 * (1.0 - r[j] / rmax);
        else
            out[j] = have[j] ? 0.5 * (1.0 + (dmax > 0.0 ? dfull[j] / dmax : 0.0)) : INFINITY;
    }
}

/* The stored lists' reverse of x (n shapes, k + k2 each: both graphs') into rs (n + 1) and rv. */
static void reverse_lists(const amscr_index *x, size_t n, size_t *rs, uint32_t *rv)
{
    size_t k = x->k, k2 = x->k2;
    memset(rs, 0, (n + 1) * sizeof *rs);
    for (size_t e = 0; e < n * k; e++)
        rs[x->nb_idx[e] + 1]++;
    for (size_t e = 0; e < n * k2; e++)
        rs[x->in_idx[e] + 1]++;
    for (size_t j = 0; j < n; j++)
        rs[j + 1] += rs[j];
    for (size_t i = 0; i < n; i++) { /* rs[j] runs ahead while filling, then shifts back */
        for (size_t t = 0; t < k; t++)
            rv[rs[x->nb_idx[i * k + t]]++] = (uint32_t)i;
        for (size_t t = 0; t < k2; t++)
            rv[rs[x->in_idx[i * k2 + t]]++] = (uint32_t)i;
    }
    for (size_t j = n; j > 0; j--)
        rs[j] = rs[j - 1];
    rs[0] = 0;
}

void amscr__index_reverse_free(amscr_index *x)
{
    free(x->rev_start);
    free(x->rev);
    free(x->w_fixed);
    x->rev_start = NULL;
    x->rev = NULL;
    x->w_fixed = NULL;
}

/* What a row knows of the query: its candidates cand (m) with their base distances dq and, with
 * the inner graph, inner distances dq2; the same by shape (dfull[j], dfull2[j] where have[j]). */
typedef struct {
    const size_t *cand;
    const double *dq, *dq2;
    size_t m;
    double *dfull, *dfull2;
    unsigned char *have;
} qrow;

/* The largest of d0 and the m values d. */
static double largest(double d0, const double *d, size_t m)
{
    for (size_t t = 0; t < m; t++)
        d0 = d[t] > d0 ? d[t] : d0;
    return d0;
}

/* The graph's fixed parts for row `self` (n: the query). */
static void graph_setup(graph *g, const amscr_index *x, size_t self, const qrow *q)
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
}

/* x->w_fixed: every stored row's affinities in the graph of a query that enters no row (n + 1
 * rows, the collection's largest distances), computed by the query's own code. */
static amscr_status fixed_weights(amscr_index *x)
{
    size_t n = amscr_db_size(x->db), k = amscr__rerank_k(amscr_db_params(x->db), n + 1);
    graph g = {0};
    unsigned char *have = amscr__calloc_array(n ? n : 1, 1);
    qrow q = {NULL, NULL, NULL, 0, NULL, NULL, have};
    amscr_status st = have ? graph_alloc(&g, n + 1, k, x->k2 > 0 ? k : 0)
                           : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    if (st == AMSCR_OK) {
        graph_setup(&g, x, n, &q);
        for (size_t i = 0; i < n; i++)
            need_weights(&g, i);
        x->w_fixed = g.w;
        g.w = NULL;
        x->w_k = k;
        x->w_kk = g.kk;
        x->w_tiny = g.tiny;
        x->w_tiny2 = g.tiny2;
    }
    graph_free(&g);
    free(have);
    return st;
}

amscr_status amscr__index_reverse(amscr_index *x)
{
    size_t n = amscr_db_size(x->db);
    amscr__index_reverse_free(x);
    if (x->k == 0)
        return AMSCR_OK;
    x->rev_start = amscr__malloc_array(n + 1, sizeof *x->rev_start);
    x->rev = amscr__malloc_array(n ? n : 1, (x->k + x->k2) * sizeof *x->rev);
    if (!x->rev_start || !x->rev) {
        amscr__index_reverse_free(x);
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    }
    reverse_lists(x, n, x->rev_start, x->rev);
    amscr_status st = n > 0 && x->k <= n ? fixed_weights(x) : AMSCR_OK;
    if (st != AMSCR_OK)
        amscr__index_reverse_free(x);
    return st;
}

/* The diffusion's scores of row `self` (< n: a shape of the index; n: the query). */
static amscr_status diffuse(const amscr_index *x, size_t self, const qrow *q, double *out)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db), rows = self == n ? n + 1 : n, rlen = 0;
    size_t k = amscr__rerank_k(p, rows);
    graph g = {0};
    size_t *rs = x->rev_start ? NULL : amscr__malloc_array(n + 1, sizeof *rs), *rsup = NULL;
    uint32_t *rv = x->rev_start ? NULL : amscr__malloc_array(n ? n : 1, (x->k + x->k2) * sizeof *rv);
    double *r = amscr__calloc_array(rows, sizeof *r);
    rsup = amscr__malloc_array(rows, sizeof *rsup);
    int have_rev = x->rev_start || (rs && rv);
    amscr_status st = r && rsup && have_rev ? graph_alloc(&g, rows, k, x->k2 > 0 ? k : 0)
                                            : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK && !x->rev_start)
        reverse_lists(x, n, rs, rv);
    graph_setup(&g, x, self, q);
    if (x->w_fixed && g.k == x->w_k && g.kk == x->w_kk && g.k <= x->k && g.k2 <= x->k2 && g.tiny == x->w_tiny &&
        g.tiny2 == x->w_tiny2)
        g.fixed = x->w_fixed;
    g.rs = x->rev_start ? x->rev_start : rs;
    g.rv = x->rev_start ? x->rev : rv;
    if (st == AMSCR_OK && self == n)
        st = query_row(q->cand, q->dq, q->dq2, q->m, &g);
    if (st == AMSCR_OK)
        st = diffusion_row(&g, self, p->rerank_iterations, r, rsup, &rlen);
    if (st == AMSCR_OK)
        scores(r, rsup, rlen, n, self, q->dfull, q->have, g.dmax, out);
    graph_free(&g);
    free(r);
    free(rsup);
    free(rs);
    free(rv);
    return st;
}

amscr_status amscr__index_scores(const amscr_index *x, size_t self, const size_t *cand, const double *dq,
                                 const double *dq2, size_t m, double *out)
{
    size_t n = amscr_db_size(x->db);
    qrow q = {cand, dq, dq2, m, amscr__calloc_array(n, sizeof(double)), NULL, amscr__calloc_array(n, 1)};
    q.dfull2 = dq2 ? amscr__calloc_array(n, sizeof(double)) : NULL;
    amscr_status st = q.dfull && q.have && (!dq2 || q.dfull2) ? AMSCR_OK
                                                            : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) {
        q.dfull[cand[t]] = dq[t];
        if (dq2)
            q.dfull2[cand[t]] = dq2[t];
        q.have[cand[t]] = 1;
    }
    if (st == AMSCR_OK && x->k == 0) { /* no re-ranking: the base distances */
        for (size_t j = 0; j < n; j++)
            out[j] = j == self ? 0.0 : q.have[j] ? q.dfull[j] : INFINITY;
    } else if (st == AMSCR_OK) {
        st = diffuse(x, self, &q, out);
    }
    free(q.dfull);
    free(q.dfull2);
    free(q.have);
    return st;
}

/* The inner distances of q to the m candidates (the query's inner graph). */
static amscr_status query_inner(const amscr_index *x, const amscr_descriptor *q, const size_t *cand, size_t m,
                                double *out)
{
    amscr__inner_ws ws;
    amscr__inner *f = malloc(sizeof *f);
    if (!f || amscr__inner_ws_init(&ws) != AMSCR_OK) {
        free(f);
        return amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    }
    amscr_status st = amscr__inner_build_shape(q, amscr_db_params(x->db)->inner_closing, f, &ws);
    int refl = amscr_db_params(x->db)->reflections;
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) /* cell (j, query): the query's index is the highest */
        out[t] = amscr__inner_distance(&x->inner[cand[t]], f, refl, &ws);
    amscr__inner_ws_free(&ws);
    free(f);
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
    double *dq2 = st == AMSCR_OK && x->k2 > 0 && self == SIZE_MAX ? amscr__malloc_array(n ? n : 1, sizeof *dq2)
                                                                   : NULL;
    if (st == AMSCR_OK && x->k2 > 0 && self == SIZE_MAX)
        st = dq2 ? query_inner(x, q, cand, m, dq2) : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK)
        st = amscr__index_scores(x, self == SIZE_MAX ? n : self, cand, dq, dq2, m, out);
    free(cand);
    free(dq);
    free(dq2);
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
    /* fused weights: the medians move with the query: the whole matrix */
    if (w > 0.0 && w < 1.0)
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
