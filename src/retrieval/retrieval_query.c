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

/* The lowest shape of db with q's prepared samples, bit for bit, into *out (SIZE_MAX: none):
 * the member rule's shape, found without an index. */
static amscr_status db_member(const amscr_db *db, const amscr_descriptor *q, size_t *out)
{
    size_t n = amscr_db_size(db), N = amscr_db_params(db)->num_samples;
    double *buf = amscr__malloc_array(2 * N + 2 * AMSCR__OUTLINE_N, sizeof *buf);
    amscr_status st = buf ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "amscr_db_search_retrieval: out of memory");
    *out = SIZE_MAX;
    for (size_t j = 0; st == AMSCR_OK && j < n && *out == SIZE_MAX; j++) {
        amscr_descriptor sd, *tmp = NULL;
        const amscr_descriptor *d = &sd;
        st = amscr__db_shallow(db, j, &sd, buf, buf + 2 * N) ? AMSCR_OK : amscr__db_peek(db, j, &d, &tmp);
        if (st == AMSCR_OK && d->n == q->n && memcmp(d->input, q->input, 2 * q->n * sizeof *q->input) == 0)
            *out = j;
        amscr_descriptor_free(tmp);
    }
    free(buf);
    return st;
}

/* The base distances of q to every shape of db, each pair as the matrix cell of the two with q at
 * index qpos (SIZE_MAX: after every shape; a member's copy: the member's row, 0 on itself). */
static amscr_status plain_row(const amscr_db *db, const amscr_descriptor *q, size_t qpos, amscr_progress_fn progress,
                              void *user, double *out)
{
    size_t n = amscr_db_size(db), m = 0, *cand = amscr__malloc_array(n ? n : 1, sizeof *cand);
    if (!cand)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_query_retrieval: out of memory");
    for (size_t j = 0; j < n; j++)
        if (j != qpos)
            cand[m++] = j;
    double *row = qpos < n ? amscr__malloc_array(n, sizeof *row) : out;
    amscr__base b;
    amscr__base_init(&b, amscr_db_params(db), 0.0, 0.0);
    amscr_status st = row ? amscr__base_row(&b, db, NULL, q, qpos, cand, m, progress, user, row)
                          : amscr__fail(AMSCR_E_NOMEM, "amscr_db_query_retrieval: out of memory");
    if (st == AMSCR_OK && row != out) {
        for (size_t t = 0; t < m; t++)
            out[cand[t]] = row[t];
        out[qpos] = 0.0;
    }
    if (row != out)
        free(row);
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
    const amscr_params *p = amscr_db_params(db);
    amscr_status st;
    if (p->rerank_k == 0 && (p->channel_weight == 0.0 || p->channel_weight == 1.0)) {
        /* the base distances alone: nothing of the collection's, but the pair's order (the
         * member rule, when it applies: a member's copy gets the member's row) */
        size_t qpos = SIZE_MAX;
        st = member && amscr__member_rule_applies(p) ? db_member(db, q, &qpos) : AMSCR_OK;
        if (st == AMSCR_OK)
            st = plain_row(db, q, qpos, progress, user, out_scores);
    } else {
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
