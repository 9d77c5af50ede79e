/* index_query.c — one query against an index: its shortlist of candidate shapes (their
 * signatures nearest the query's), its base distances to them (index_pairs.c) and its inner
 * distances (with the inner graph), then its row of the retrieval scores (index_diffuse.c);
 * and the search calls' member rule: a query whose prepared samples are a member's, bit for
 * bit, is scored as that member (its row of the collection's retrieval matrix). */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>
#include <string.h>

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

/* Scores of q (self == SIZE_MAX) or of shape self against every shape; progress (may be NULL)
 * counts the base distances. */
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
            amscr__index_sig(x, self, sig);
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
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
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
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(out_scores);
    if (n != amscr_db_size(x->db) || i >= n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_member_scores: shape %zu, %zu scores, %zu shapes", i,
                           n, amscr_db_size(x->db));
    const amscr_descriptor *d;
    amscr_descriptor *tmp = NULL;
    amscr_status st = amscr__db_peek(x->db, i, &d, &tmp);
    if (st == AMSCR_OK)
        st = query_scores(x, d, i, candidates, NULL, NULL, out_scores);
    amscr_descriptor_free(tmp);
    return st;
}

/* Signature-nearest shapes among which the member rule looks for the query's copy: a copy's
 * signature is the query's (distance 0), and copies tie by index, so the lowest-index copy is
 * among them unless this many shapes have the query's very signature without its samples. */
enum { MEMBER_SHORTLIST = 32 };

/* Whether shape j of x has q's prepared samples, bit for bit, into *same: read from its record
 * when the collection keeps it as one (buf: 2 N + 2 AMSCR__OUTLINE_N values), else from the
 * shape, decoded and not kept (amscr__db_peek's status). Queries keep no decoded shape, so an
 * index's memory does not grow with the shapes they read. */
static amscr_status same_samples(const amscr_index *x, size_t j, const amscr_descriptor *q, double *buf, int *same)
{
    size_t N = amscr_db_params(x->db)->num_samples;
    amscr_descriptor sd, *tmp = NULL;
    const amscr_descriptor *d = &sd;
    amscr_status st = amscr__db_shallow(x->db, j, &sd, buf, buf + 2 * N) ? AMSCR_OK : amscr__db_peek(x->db, j, &d, &tmp);
    *same = st == AMSCR_OK && d->n == q->n && memcmp(d->input, q->input, 2 * q->n * sizeof *q->input) == 0;
    amscr_descriptor_free(tmp);
    return st;
}

/* The member rule's shape for q (compatible params checked) into *out, SIZE_MAX for none;
 * *out is written only on success. */
static amscr_status find_member(const amscr_index *x, const amscr_descriptor *q, size_t *out)
{
    size_t n = amscr_db_size(x->db), m = n < MEMBER_SHORTLIST ? n : MEMBER_SHORTLIST, found = SIZE_MAX;
    size_t cand[MEMBER_SHORTLIST];
    float sig[AMSCR__SIG_DIM], lb[AMSCR__SIG_LB_DIM];
    double *buf = amscr__malloc_array(2 * amscr_db_params(x->db)->num_samples + 2 * AMSCR__OUTLINE_N, sizeof *buf);
    amscr_status st = buf ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    if (st == AMSCR_OK && m > 0) {
        amscr__shape_signature(q, sig);
        amscr__sig_bound_vector(sig, lb);
        if (amscr__index_shortlist(x, sig, lb, m, SIZE_MAX, cand) != m)
            st = amscr__fail(AMSCR_E_NOMEM, "index query: out of memory");
    }
    /* ascending index: the first copy is the lowest */
    for (size_t t = 0; st == AMSCR_OK && t < m && found == SIZE_MAX; t++) {
        int same;
        st = same_samples(x, cand[t], q, buf, &same);
        found = same ? cand[t] : SIZE_MAX;
    }
    free(buf);
    if (st == AMSCR_OK)
        *out = found;
    return st;
}

/* Whether a search scores a member's copy by the member's row: scores that depend on the
 * collection (re-ranking, or a fusion of both distances), as amscr_db_query_retrieval's, or on
 * the pair's order (the shape channel's distance is taken from the lower index to the higher,
 * so a copy of shape i, after every shape, would get d(j, i) where the matrix has d(i, j)). */
int amscr__member_rule_applies(const amscr_params *p)
{
    return p->rerank_k > 0 || p->channel_weight > 0.0;
}

amscr_status amscr_index_find_member(const amscr_index *x, const amscr_descriptor *q, size_t *out_i)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_i);
    amscr_status st = check_query(x, q, NULL, 0, "amscr_index_find_member");
    return st == AMSCR_OK ? find_member(x, q, out_i) : st;
}

/* amscr_index_query_scores with the member rule. */
static amscr_status search_scores(const amscr_index *x, const amscr_descriptor *q, size_t candidates,
                                  amscr_progress_fn progress, void *user, double *out)
{
    size_t member = SIZE_MAX;
    amscr_status st = amscr__member_rule_applies(amscr_db_params(x->db)) ? find_member(x, q, &member) : AMSCR_OK;
    const amscr_descriptor *d = q;
    amscr_descriptor *tmp = NULL;
    if (st == AMSCR_OK && member != SIZE_MAX)
        st = amscr__db_peek(x->db, member, &d, &tmp);
    if (st == AMSCR_OK)
        st = query_scores(x, d, member, candidates, progress, user, out);
    amscr_descriptor_free(tmp);
    return st;
}

amscr_status amscr_index_search_scores(const amscr_index *x, const amscr_descriptor *q, size_t candidates,
                                       double *out_scores, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_scores);
    amscr_status st = check_query(x, q, (size_t *)out_scores, n, "amscr_index_search_scores");
    return st == AMSCR_OK ? search_scores(x, q, candidates, NULL, NULL, out_scores) : st;
}

amscr_status amscr__index_row(const amscr_index *x, const amscr_descriptor *q, int member,
                              amscr_progress_fn progress, void *user, double *out)
{
    return member ? search_scores(x, q, 0, progress, user, out) : query_scores(x, q, SIZE_MAX, 0, progress, user, out);
}

/* The top best of the query's scores (the member rule when `member`): the body of
 * amscr_index_query and amscr_index_search. */
static amscr_status best_hits(const amscr_index *x, const amscr_descriptor *q, size_t candidates, size_t top,
                              int member, size_t *out_idx, double *out_scores, size_t *out_count, const char *fn)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL_IN(fn, x);
    AMSCR__CHECK_INDEX_WHOLE(fn, x);
    AMSCR_CHECK_NULL_IN(fn, q);
    AMSCR_CHECK_NULL_IN(fn, out_idx);
    AMSCR_CHECK_NULL_IN(fn, out_scores);
    AMSCR_CHECK_NULL_IN(fn, out_count);
    amscr_status st = check_query(x, q, NULL, 0, fn);
    size_t n = amscr_db_size(x->db), k = top < n ? top : n;
    double *all = st == AMSCR_OK ? amscr__malloc_array(n, sizeof *all) : NULL;
    if (st == AMSCR_OK && !all)
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", fn);
    if (st == AMSCR_OK)
        st = member ? search_scores(x, q, candidates, NULL, NULL, all)
                    : query_scores(x, q, SIZE_MAX, candidates, NULL, NULL, all);
    if (st == AMSCR_OK && k > 0)
        st = amscr_topk(all, n, k, SIZE_MAX, out_idx);
    for (size_t t = 0; st == AMSCR_OK && t < k; t++)
        out_scores[t] = all[out_idx[t]];
    if (st == AMSCR_OK)
        *out_count = k;
    free(all);
    return st;
}

amscr_status amscr_index_query(const amscr_index *x, const amscr_descriptor *q, size_t candidates, size_t top,
                               size_t *out_idx, double *out_scores, size_t *out_count)
{
    return best_hits(x, q, candidates, top, 0, out_idx, out_scores, out_count, "amscr_index_query");
}

amscr_status amscr_index_search(const amscr_index *x, const amscr_descriptor *q, size_t candidates, size_t top,
                                size_t *out_idx, double *out_scores, size_t *out_count)
{
    return best_hits(x, q, candidates, top, 1, out_idx, out_scores, out_count, "amscr_index_search");
}
