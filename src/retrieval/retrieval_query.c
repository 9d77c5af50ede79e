/* retrieval_query.c — which scores a collection ranks its shapes by (amscr_params_ranking), and
 * one query's retrieval scores against a collection (amscr_db_query_retrieval): the base
 * distances alone when nothing of the collection's is needed, else from an exact index of the
 * collection kept with it — built by the first such query, brought up to date by the first
 * query after shapes were added (their rows and the lists they enter), so each query costs
 * O(n) matches. */
#include "db_io.h"
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

/* The index a collection keeps for its queries, and the shapes it covers. */
typedef struct {
    amscr_index *x;
    size_t n;
} kept_index;

static void kept_free(void *p)
{
    kept_index *k = p;
    if (k)
        amscr_index_free(k->x);
    free(k);
}

/* k brought to db's size: the new shapes entered, or a rebuild when the lists' K changes with
 * the size. On failure k holds no index. */
static amscr_status kept_refresh(const amscr_db *db, kept_index *k, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(db);
    amscr_status st = AMSCR_OK;
    if (k->x && k->n > 0 && amscr__rerank_k(amscr_db_params(db), n) == k->x->k)
        st = amscr__index_extend(k->x, k->n, progress, user);
    else {
        amscr_index_free(k->x);
        k->x = NULL;
        st = amscr__index_build_on(db, progress, user, &k->x);
    }
    if (st != AMSCR_OK) {
        amscr_index_free(k->x);
        k->x = NULL;
    }
    k->n = st == AMSCR_OK ? n : 0;
    return st;
}

/* The index db keeps for its queries, up to date (built or extended under the collection's lock).
 * A query that must bring it up to date reports that as the first of its two stages (sp). */
static amscr_status kept(const amscr_db *db, amscr__stages *sp, const amscr_index **out)
{
    void **slot = amscr__db_kept_lock(db, kept_free);
    if (!slot)
        return amscr__fail(AMSCR_E_STATE, "amscr_db_query_retrieval: called from the progress callback of a query "
                                          "on the same collection, which holds its lock (query another collection "
                                          "there, or after the call returns)");
    kept_index *k = *slot;
    amscr_status st = AMSCR_OK;
    if (!k && (k = calloc(1, sizeof *k)) == NULL)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_db_query_retrieval: out of memory");
    else
        *slot = k;
    if (st == AMSCR_OK && (!k->x || k->n != amscr_db_size(db))) {
        sp->stages = 2;
        st = kept_refresh(db, k, sp->fn ? amscr__stage_cb : NULL, sp);
        sp->stage = 1;
    }
    *out = st == AMSCR_OK ? k->x : NULL;
    amscr__db_kept_unlock(db);
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

/* amscr_db_query_retrieval (member 0) or amscr_db_search_retrieval (member 1). */
static amscr_status db_query(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress, void *user,
                             double *out_scores, size_t n, int member, const char *what)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL_IN(what, db);
    AMSCR_CHECK_NULL_IN(what, q);
    AMSCR_CHECK_NULL_IN(what, out_scores);
    if (n != amscr_db_size(db))
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: the output holds %zu scores, the collection %zu shapes", what,
                           n, amscr_db_size(db));
    if (!amscr__params_compatible(amscr_db_params(db), &q->params, what))
        return AMSCR_E_INVALID_ARG;
    amscr_status st;
    if (!amscr__member_rule_applies(amscr_db_params(db))) /* the base distances alone: nothing of the collection's */
        st = plain_row(db, q, progress, user, out_scores);
    else {
        const amscr_index *x = NULL;
        amscr__stages sp = {progress, user, 0, 1};
        st = kept(db, &sp, &x);
        if (st == AMSCR_OK) /* every shape a candidate */
            st = amscr__index_row(x, q, member, progress ? amscr__stage_cb : NULL, &sp, out_scores);
    }
    return amscr__nan_on_failure(st, out_scores, 1, n); /* never a partial row */
}

amscr_status amscr_db_query_retrieval(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress,
                                      void *user, double *out_scores, size_t n)
{
    return db_query(db, q, progress, user, out_scores, n, 0, "amscr_db_query_retrieval");
}

amscr_status amscr_db_search_retrieval(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress,
                                       void *user, double *out_scores, size_t n)
{
    return db_query(db, q, progress, user, out_scores, n, 1, "amscr_db_search_retrieval");
}
