/* index_graph.h — the kNN graph P whose diffusion gives one row of an index's retrieval scores
 * (index_graph.c): the collection's shapes plus, for a query, the query itself, each row built
 * from the stored neighbour lists when the diffusion first reaches it. Read by the diffusion
 * (index_diffuse.c) and by the lists' reverse (index_reverse.c). Never installed. */
#ifndef AMSCR_INDEX_GRAPH_H
#define AMSCR_INDEX_GRAPH_H

#include "index.h"

/* What a row knows of the query: its candidates cand (m) with their base distances dq and, with
 * the inner graph, inner distances dq2; the same by shape (dfull[j], dfull2[j] where have[j]). */
typedef struct {
    const size_t *cand;
    const double *dq, *dq2;
    size_t m;
    double *dfull, *dfull2;
    unsigned char *have;
} amscr__qrow;

/* The graph of the n + 1 (or n) shapes, its rows built on demand: a query touches only the
 * shapes its diffusion reaches, never the whole collection. The rows built are stored one after
 * the other (row i at slot[i], in the order they were built), so a query's graph holds only
 * what its diffusion reaches. */
typedef struct {
    size_t n, k, k2, kk;   /* rows (the query last, when there is one), kk = k + k2 entries each: k of the
                            * base distance's graph, then k2 of the inner distance's (0: one graph) */
    uint32_t *j;           /* neighbours, kk a row built */
    double *d, *w;         /* base (then inner) distances, then the affinities */
    uint32_t *slot;        /* n: where row i is stored (j + slot[i] * kk; set once state[i] > 0) */
    size_t used, cap;      /* rows stored and room for (slot 0: a spare row, for a row met out of memory) */
    int oom;               /* a row found no room: the diffusion fails (AMSCR_E_NOMEM) */
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
} amscr__graph;

/* The offset of built row i's entries in j, d and w. */
static inline size_t amscr__graph_row(const amscr__graph *g, size_t i) { return (size_t)g->slot[i] * g->kk; }

amscr_status amscr__graph_alloc(amscr__graph *g, size_t n, size_t k, size_t k2);
void amscr__graph_free(amscr__graph *g);
/* The graph's fixed parts for row `self` of x (n: the query, which q describes), with the
 * stored rows' affinities x->w_fixed when they hold for this graph. */
void amscr__graph_setup(amscr__graph *g, const amscr_index *x, size_t self, const amscr__qrow *q);
/* The query's row (the last): each graph's part from the query's candidates. */
amscr_status amscr__graph_query_row(amscr__graph *g, const amscr__qrow *q);
/* Row i's affinities (its list, and its neighbours', built first when needed). */
void amscr__graph_weights(amscr__graph *g, size_t i);
/* x->w_fixed (and the graph they hold for): every stored row's affinities in the graph of a
 * query that enters no row, computed by the query's own code. */
amscr_status amscr__graph_fixed_weights(amscr_index *x);

#endif
