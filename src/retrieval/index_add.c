/* index_add.c — new shapes into an index: each new shape's list from its base distances to
 * every shape (or its shortlist, for an index built with one), and the older lists it enters.
 * With a full index and channel weight 0 or 1 the lists equal a rebuild's; with fused
 * weights the fusion keeps the build's medians. */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>
#include <string.h>

/* The first option in which a and b differ, or NULL. */
static const char *differing_option(const amscr_params *a, const amscr_params *b)
{
    if (a->num_samples != b->num_samples)
        return "num_samples";
    if (a->num_scales != b->num_scales || memcmp(a->scales, b->scales, a->num_scales * sizeof *a->scales) != 0)
        return "scales";
#define CMP(f)                                                                                               \
    if (a->f != b->f)                                                                                        \
        return #f;
    CMP(method) CMP(closed) CMP(reflections) CMP(parametrization) CMP(presmooth) CMP(arclength_passes)
    CMP(oversampling) CMP(kmax) CMP(symmetric) CMP(refine) CMP(invariance) CMP(penalty) CMP(channel_weight)
    CMP(channel_invariance) CMP(channel_affine_share) CMP(channel_band) CMP(channel_affine_band) CMP(channel_skip)
    CMP(channel_locality) CMP(rerank_k) CMP(rerank_iterations) CMP(rerank_inner_share)
    CMP(inner_closing) CMP(channel_affine_view)
#undef CMP
    return NULL;
}

/* New rows j0..j1-1 computed on threads: each one's shortlist and base distances. */
typedef struct {
    amscr_index *x;
    amscr__base b;
    size_t j0, n;
    size_t *cand; /* (j1 - j0) x n */
    double *cd;
    double *cd2;  /* the inner distances (with the inner graph) */
    size_t *m;
} add_ctx;

/* A thread's scratch: the base distance's, and the inner distance's (with the inner graph). */
typedef struct {
    void *pw, *iw;
} add_ws;

static void add_ws_free(void *scratch)
{
    add_ws *w = scratch;
    if (w->pw)
        amscr__pair_ws_delete(w->pw);
    amscr__inner_ws_delete(w->iw);
    free(w);
}

static amscr_status add_ws_init(void *ctx, void **scratch)
{
    add_ctx *c = ctx;
    add_ws *w = calloc(1, sizeof *w);
    if (!w)
        return AMSCR_E_NOMEM;
    amscr_status st = amscr__pair_ws_new(&c->b, &w->pw);
    if (st == AMSCR_OK && c->x->k2 > 0)
        st = amscr__inner_ws_new(&w->iw);
    if (st != AMSCR_OK) {
        add_ws_free(w);
        return st;
    }
    *scratch = w;
    return AMSCR_OK;
}

static amscr_status add_distances(void *ctx, size_t j, void *scratch)
{
    add_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t r = j - c->j0, *cand = c->cand + r * c->n;
    float sig[AMSCR__SIG_DIM];
    amscr__index_sig(x, j, sig);
    size_t m = amscr__index_shortlist(x, sig, x->sig_lb + j * AMSCR__SIG_LB_DIM, x->candidates, j, cand);
    if (m == 0 && c->n > 1)
        return AMSCR_E_NOMEM;
    c->m[r] = m;
    const amscr__hf *hq = x->nf ? x->hf + j * (size_t)x->nf : NULL;
    add_ws *w = scratch;
    for (size_t t = 0; x->k2 > 0 && t < m; t++)
        c->cd2[r * c->n + t] = amscr__index_inner_pair(x, cand[t], j, w->iw);
    const amscr_descriptor *q;
    amscr_status st = amscr__db_shape(x->db, j, &q);
    return st == AMSCR_OK ? amscr__base_pairs(&c->b, x->db, x->hf, q, hq, j, cand, m, w->pw, c->cd + r * c->n) : st;
}

/* Rows j0..j1-1 (new): their distances on threads, then (in order) the older rows they enter
 * and their own lists. */
static amscr_status add_rows(add_ctx *c, size_t j1, size_t n0)
{
    amscr_index *x = c->x;
    amscr__rows_fn f = {add_ws_init, add_ws_free, add_distances, c, NULL};
    amscr_status st = amscr__run_rows(&f, c->j0, j1, c->b.threads, NULL, NULL);
    size_t k = x->k, k2 = x->k2;
    for (size_t j = c->j0; st == AMSCR_OK && j < j1; j++) {
        size_t r = j - c->j0, m = c->m[r], *cand = c->cand + r * c->n;
        double *cd = c->cd + r * c->n, *cd2 = c->cd2 + r * c->n;
        for (size_t t = 0; t < m; t++) {
            x->dmax = cd[t] > x->dmax ? cd[t] : x->dmax;
            if (cand[t] < n0)
                amscr__knn_enter(x->nb_idx + cand[t] * k, x->nb_dist + cand[t] * k, k, j, cd[t]);
        }
        for (size_t t = 0; k2 > 0 && t < m; t++) {
            x->dmax2 = cd2[t] > x->dmax2 ? cd2[t] : x->dmax2;
            if (cand[t] < n0)
                amscr__knn_enter(x->in_idx + cand[t] * k2, x->in_dist + cand[t] * k2, k2, j, cd2[t]);
        }
        if (k > 0)
            st = amscr__knn_select(j, cand, cd, m, k, x->nb_idx + j * k, x->nb_dist + j * k);
        if (st == AMSCR_OK && k2 > 0)
            st = amscr__knn_select(j, cand, cd2, m, k2, x->in_idx + j * k2, x->in_dist + j * k2);
    }
    return st;
}

/* Moves the names, groups and class names of x's first n0 shapes into y, built on them and more. */
static void move_names(amscr_index *x, amscr_index *y, size_t n0)
{
    for (size_t i = 0; i < n0; i++) {
        y->names[i] = x->names[i];
        y->groups[i] = x->groups[i];
        x->names[i] = x->groups[i] = NULL;
    }
    char **classes = y->classes;
    size_t nclasses = y->nclasses;
    y->classes = x->classes;
    y->nclasses = x->nclasses;
    x->classes = classes;
    x->nclasses = nclasses;
}

/* x built again on its shapes and `shapes`, its names, groups and class names kept: the lists of
 * an index of fewer than twice its re-ranking k grow with its size (amscr__rerank_k), which an
 * add cannot give the old rows. x is left as it was on failure. */
static amscr_status add_rebuilding(amscr_index *x, const amscr_db *shapes, amscr_progress_fn progress, void *user)
{
    size_t n0 = amscr_db_size(x->db), n = n0 + amscr_db_size(shapes);
    amscr_db *all = NULL;
    amscr_index *y = NULL;
    amscr_status st = amscr_db_new(amscr_db_params(x->db), &all);
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        const amscr_db *from = i < n0 ? x->db : shapes;
        size_t j = i < n0 ? i : i - n0;
        st = amscr__db_add_from(all, from, j, amscr_db_label(from, j));
    }
    if (st == AMSCR_OK)
        st = amscr_index_build(all, x->candidates, progress, user, &y);
    amscr_db_free(all);
    if (st != AMSCR_OK)
        return st;
    move_names(x, y, n0);
    amscr_index old = *x;
    *x = *y;
    *y = old;
    amscr_index_free(y);
    return AMSCR_OK;
}

amscr_status amscr_index_add(amscr_index *x, const amscr_db *shapes, amscr_progress_fn progress, void *user)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(shapes);
    const amscr_params *p = amscr_db_params(x->db);
    const char *diff = differing_option(p, amscr_db_params(shapes));
    if (diff)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_add: the shapes were prepared with another %s than the "
                                                "index (rebuild the index to change it)", diff);
    size_t n0 = amscr_db_size(x->db), add = amscr_db_size(shapes), n = n0 + add;
    amscr_status st = amscr__index_check_db(shapes, "amscr_index_add");
    if (st == AMSCR_OK && add == 0)
        return AMSCR_OK; /* nothing to do, nothing reported */
    size_t kp = amscr__rerank_k(p, n);
    if (st == AMSCR_OK && kp != x->k && n0 > 0) /* a list grows with the collection */
        return add_rebuilding(x, shapes, progress, user);
    if (st == AMSCR_OK && n0 == 0) {
        x->k = kp;
        x->k2 = amscr__index_k2(p, kp);
    }
    if (st == AMSCR_OK)
        st = amscr__index_reserve(x, n);
    for (size_t i = 0; st == AMSCR_OK && i < add; i++)
        st = amscr__db_add_from(x->db, shapes, i, amscr_db_label(shapes, i));
    if (st == AMSCR_OK)
        st = amscr__index_extend(x, n0, progress, user);
    if (st != AMSCR_OK && amscr_db_size(x->db) != n0)
        x->failed = 1; /* its new shapes lack their lists (the header: free it) */
    return st == AMSCR_OK ? amscr__db_compact_tail(x->db) : st; /* kept as the others are */
}

amscr_status amscr__index_extend(amscr_index *x, size_t n0, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db), add = n - n0;
    amscr__stages sp = {progress, user, 0, 2}; /* the new shapes' features, then their rows */
    amscr_progress_fn cb = progress ? amscr__stage_cb : NULL;
    amscr_status st = amscr__index_reserve(x, n);
    if (st == AMSCR_OK)
        st = amscr__index_features(x, n0, 0, cb, &sp);
    sp.stage = 1;
    if (st == AMSCR_OK && x->ivf.nc > 0) /* the new shapes into the quantizer's lists */
        st = amscr__sig_ivf_add(&x->ivf, x->sig_lb, n);
    add_ctx c = {x, {0}, n0, n, NULL, NULL, NULL, NULL};
    amscr__base_init(&c.b, amscr_db_params(x->db), x->med_a, x->med_h);
    size_t batch = 4 * (size_t)c.b.threads; /* rows computed together (memory: batch x n) */
    c.cand = st == AMSCR_OK ? amscr__malloc_array(batch, n * sizeof *c.cand) : NULL;
    c.cd = st == AMSCR_OK ? amscr__malloc_array(batch, n * sizeof *c.cd) : NULL;
    c.cd2 = st == AMSCR_OK && x->k2 > 0 ? amscr__malloc_array(batch, n * sizeof *c.cd2) : NULL;
    c.m = st == AMSCR_OK ? amscr__malloc_array(batch, sizeof *c.m) : NULL;
    if (st == AMSCR_OK && (!c.cand || !c.cd || (x->k2 > 0 && !c.cd2) || !c.m))
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_add: out of memory");
    for (size_t j = n0; st == AMSCR_OK && j < n; j += batch) {
        if (cb && cb(&sp, j - n0, add) != 0)
            st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
        c.j0 = j;
        if (st == AMSCR_OK)
            st = add_rows(&c, j + batch < n ? j + batch : n, n0);
    }
    if (st == AMSCR_OK && cb && cb(&sp, add, add) != 0)
        st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    if (st == AMSCR_OK)
        st = amscr__index_reverse(x); /* the lists changed: their reverse for the queries */
    amscr__index_drop_mirrors(x, n0);
    free(c.cand);
    free(c.cd);
    free(c.cd2);
    free(c.m);
    return st;
}
