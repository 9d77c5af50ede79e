/* retrieval_query.c — which scores a collection ranks its shapes by (amscr_params_ranking), and
 * one query's retrieval scores against a collection that keeps no index
 * (amscr_db_query_retrieval): the base distances alone without re-ranking, the collection's
 * neighbour lists built for the call (an exact index) with it, and the matrix of the collection
 * plus the query when the fusion's medians move with the query. */
#include "index.h"

#include <stdlib.h>
#include <string.h>

amscr_status amscr_params_ranking(const amscr_params *p, amscr_ranking *out_ranking)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(out_ranking);
    *out_ranking = p->channel_weight > 0.0 || p->rerank_k > 0 ? AMSCR_RANKING_RETRIEVAL : AMSCR_RANKING_DISTANCE;
    return AMSCR_OK;
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
        st = amscr_index_query_scores(x, q, 0, out_scores, n); /* every shape a candidate */
    amscr_index_free(x);
    return st;
}

