/* index_diffuse.c — one row of an index's retrieval scores from the row's distances to its
 * candidates: those distances themselves without re-ranking, else the row's diffusion
 * (amscr_db_retrieval_matrix: amscr_rerank_diffusion halved into [0, 1]) on the graph P of the
 * collection plus the query (index_graph.c), from the stored neighbour lists alone.
 *
 * With Q_0 = P and Q <- P Q P^T + I for T iterations,
 *     Q_T = sum_{t=0}^{T-1} P^t (P^T)^t + P^T P (P^T)^T   (powers),
 * so row q is sum_t P^t (e_q P^t)^T + P^T (e_q P^T P)^T (as columns), summed by Horner's rule:
 * 2T + 1 sparse vector products, O(T (n+1) K) instead of the O(T n^2 K) of the whole matrix.
 * A product P v visits only the rows that hold a shape of v's support (the lists' reverse,
 * index_reverse.c). */
#include "index_graph.h"

#include <math.h>
#include <stdlib.h>

/* In an index with the quantizer (from AMSCR__INDEX_IVF_MIN shapes) a shortlist query's
 * diffusion drops, at every step, the entries of its vectors below this share of the vector's
 * largest: a large collection's near copies would
 * otherwise let one query reach a share of the collection that grows with it. 1e-3 keeps the
 * exact top 10 of affine-warped queries on warped mpeg7-dev and Kimia-216 collections of 10,000
 * shapes and warped mpeg7-dev of 100,000 (1e-2 loses 0.2 %, 1e-1 5 %; docs/decisions.md). */
#define PRUNE 0.001

/* The pruning of a row of x's n shapes matched with m candidates: only in an index with the
 * quantizer (a shortlist build of AMSCR__INDEX_IVF_MIN shapes or more) and with a shortlist
 * (m < n - 1; every shape matched is the exact row). */
static double prune_share(const amscr_index *x, size_t n, size_t m)
{
    return x->ivf.nc > 0 && m + 1 < n ? PRUNE : 0.0;
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

/* Scratch of the products: a marked set (unmarked between calls) and a value vector, set where
 * a product marks or computes a row before it is read. */
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
static void apply_rows(amscr__graph *g, const svec *in, svec *out, sscratch *s)
{
    size_t k = g->kk, c = 0;
    for (size_t u = 0; u < in->len; u++) {
        size_t i = in->sup[u];
        if (in->v[i] == 0.0)
            continue;
        amscr__graph_weights(g, i);
        size_t o = amscr__graph_row(g, i);
        for (size_t t = 0; t < k; t++) {
            size_t j = g->j[o + t];
            if (!s->mark[j]) {
                s->mark[j] = 1;
                s->list[c++] = j;
                s->tmp[j] = 0.0; /* (tmp is not zeroed beforehand) */
            }
            s->tmp[j] += in->v[i] * g->w[o + t];
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
static void reach_rows(const amscr__graph *g, const svec *v, sscratch *s, size_t *c)
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
static void apply_cols(amscr__graph *g, svec *v, sscratch *s)
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
        amscr__graph_weights(g, i);
        size_t o = amscr__graph_row(g, i);
        double sum = 0.0;
        for (size_t t = 0; t < k; t++)
            sum += g->w[o + t] * v->v[g->j[o + t]];
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

/* x without the entries below eps times its largest (eps 0: x as it is); the support's order
 * kept. */
static void prune(svec *x, double eps)
{
    if (eps <= 0.0 || x->len == 0)
        return;
    double top = 0.0;
    for (size_t u = 0; u < x->len; u++)
        top = fabs(x->v[x->sup[u]]) > top ? fabs(x->v[x->sup[u]]) : top;
    size_t len = 0;
    for (size_t u = 0; u < x->len; u++) {
        size_t i = x->sup[u];
        if (fabs(x->v[i]) >= eps * top)
            x->sup[len++] = i;
        else
            x->v[i] = 0.0;
    }
    x->len = len;
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
static amscr_status row_powers(amscr__graph *g, unsigned iters, double eps, svec *a, svec *b, sscratch *s,
                               spacked *rows, svec *last)
{
    amscr_status st = AMSCR_OK;
    for (unsigned t = 0; st == AMSCR_OK && t < iters; t++) {
        st = pack(a, &rows[t]);
        apply_rows(g, a, b, s);
        svec_copy(a, b);
        prune(a, eps);
    }
    if (st == AMSCR_OK) {
        apply_rows(g, a, last, s); /* e_start P^iters P */
        prune(last, eps);
    }
    return st;
}

/* Row `start` of Q_T into r (g->n entries, zero on entry); its support into rsup / rlen. With
 * v_t = (e_start P^t)^T for t < T and v_T = (e_start P^(T+1))^T the row is
 * sum_t P^t v_t = v_0 + P (v_1 + P (... + P v_T)), by Horner's rule: T products P v (not the
 * T (T + 1) / 2 of the sum term by term); the values are the same to rounding. */
static amscr_status diffusion_row(amscr__graph *g, size_t start, unsigned iters, double eps, double *r, size_t *rsup,
                                  size_t *rlen)
{
    size_t n = g->n; /* a and b are read only on their support; v (P v reads any row) is zeroed */
    svec a = {amscr__malloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    svec v = {amscr__calloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    svec b = {amscr__malloc_array(n, sizeof(double)), amscr__malloc_array(n, sizeof(size_t)), 0};
    sscratch s = {amscr__malloc_array(n, sizeof(double)), amscr__calloc_array(n, 1),
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
        st = row_powers(g, iters, eps, &a, &b, &s, rows, &v);
    }
    for (unsigned t = iters; st == AMSCR_OK && t-- > 0;) {
        apply_cols(g, &v, &s);
        add_packed(&v, &rows[t]);
        prune(&v, eps);
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
 * others; 0 for `self` (the library's normalization of the retrieval matrix). Past the fill with
 * +inf, only the candidates and the support are visited. */
static void scores(const double *r, const size_t *rsup, size_t rlen, size_t n, size_t self, const amscr__qrow *q,
                   double dmax, double *out)
{
    double rmax = 0.0;
    for (size_t u = 0; u < rlen; u++)
        rmax = r[rsup[u]] > rmax ? r[rsup[u]] : rmax;
    for (size_t j = 0; j < n; j++)
        out[j] = INFINITY;
    for (size_t t = 0; t < q->m; t++) {
        size_t j = q->cand[t];
        out[j] = 0.5 * (1.0 + (dmax > 0.0 ? q->dfull[j] / dmax : 0.0));
    }
    for (size_t u = 0; rmax > 0.0 && u < rlen; u++) {
        size_t j = rsup[u];
        if (j < n && r[j] > 0.0)
            out[j] = 0.5 * (1.0 - r[j] / rmax);
    }
    if (self < n)
        out[self] = 0.0;
}

/* The diffusion's scores of row `self` (< n: a shape of the index; n: the query). */
static amscr_status diffuse(const amscr_index *x, size_t self, const amscr__qrow *q, double *out)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db), rows = self == n ? n + 1 : n, rlen = 0;
    size_t k = amscr__rerank_k(p, rows);
    amscr__graph g = {0};
    size_t *rs = x->rev_start ? NULL : amscr__malloc_array(n + 1, sizeof *rs), *rsup = NULL;
    uint32_t *rv = x->rev_start ? NULL : amscr__malloc_array(n ? n : 1, (x->k + x->k2) * sizeof *rv);
    double *r = amscr__malloc_array(rows, sizeof *r); /* read only on its support rsup */
    rsup = amscr__malloc_array(rows, sizeof *rsup);
    int have_rev = x->rev_start || (rs && rv);
    amscr_status st = r && rsup && have_rev ? amscr__graph_alloc(&g, rows, k, x->k2 > 0 ? k : 0)
                                            : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK && !x->rev_start)
        amscr__index_reverse_lists(x, n, rs, rv);
    amscr__graph_setup(&g, x, self, q);
    g.rs = x->rev_start ? x->rev_start : rs;
    g.rv = x->rev_start ? x->rev : rv;
    if (st == AMSCR_OK && self == n)
        st = amscr__graph_query_row(&g, q);
    if (st == AMSCR_OK)
        st = diffusion_row(&g, self, p->rerank_iterations, prune_share(x, n, q->m), r, rsup, &rlen);
    if (st == AMSCR_OK && g.oom)
        st = amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK)
        scores(r, rsup, rlen, n, self, q, g.dmax, out);
    amscr__graph_free(&g);
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
    /* dfull and dfull2 are read only where `have` (zeroed) is set */
    amscr__qrow q = {cand, dq, dq2, m, amscr__malloc_array(n ? n : 1, sizeof(double)), NULL, amscr__calloc_array(n ? n : 1, 1)};
    q.dfull2 = dq2 ? amscr__malloc_array(n ? n : 1, sizeof(double)) : NULL;
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
