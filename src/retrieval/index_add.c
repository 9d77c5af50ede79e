/* index_add.c — new shapes into an index: each new shape's list from its base distances to
 * every shape (or its shortlist, for an index built with one), and the older lists it enters.
 * With a full index and channel weight 0 or 1 the lists equal a rebuild's; with fused
 * weights the fusion keeps the build's medians. */
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
    CMP(channel_locality) CMP(rerank_k) CMP(rerank_iterations)
#undef CMP
    return NULL;
}

/* Shape j (new) into row i's list when it is nearer than the list's last entry (ties: j has the
 * highest index so far and stays behind). */
static void enter_list(amscr_index *x, size_t i, size_t j, double d)
{
    size_t k = x->k;
    uint32_t *ni = x->nb_idx + i * k;
    double *nd = x->nb_dist + i * k;
    if (k < 2 || !(d < nd[k - 1]))
        return;
    size_t t = k - 1;
    while (t > 1 && nd[t - 1] > d) {
        ni[t] = ni[t - 1];
        nd[t] = nd[t - 1];
        t--;
    }
    ni[t] = (uint32_t)j;
    nd[t] = d;
}

/* New rows j0..j1-1 computed on threads: each one's shortlist and base distances. */
typedef struct {
    amscr_index *x;
    amscr__base b;
    size_t j0, n;
    size_t *cand; /* (j1 - j0) x n */
    double *cd;
    size_t *m;
} add_ctx;

static amscr_status add_pw_init(void *ctx, void **scratch)
{
    return amscr__pair_ws_new(&((add_ctx *)ctx)->b, scratch);
}

static amscr_status add_distances(void *ctx, size_t j, void *scratch)
{
    add_ctx *c = ctx;
    amscr_index *x = c->x;
    size_t r = j - c->j0, *cand = c->cand + r * c->n;
    size_t m = amscr__index_shortlist(x, x->sig + j * x->sig_dim, x->sig_lb + j * AMSCR__SIG_LB_DIM, x->candidates,
                                      j, cand);
    if (m == 0 && c->n > 1)
        return AMSCR_E_NOMEM;
    c->m[r] = m;
    const amscr__hf *hq = x->nf ? x->hf + j * (size_t)x->nf : NULL;
    return amscr__base_pairs(&c->b, x->db, x->hf, amscr_db_descriptor(x->db, j), hq, j, cand, m, scratch,
                             c->cd + r * c->n);
}

/* Rows j0..j1-1 (new): their distances on threads, then (in order) the older rows they enter
 * and their own lists. */
static amscr_status add_rows(add_ctx *c, size_t j1, size_t n0)
{
    amscr_index *x = c->x;
    amscr__rows_fn f = {add_pw_init, amscr__pair_ws_delete, add_distances, c, NULL};
    amscr_status st = amscr__run_rows(&f, c->j0, j1, c->b.threads, NULL, NULL);
    for (size_t j = c->j0; st == AMSCR_OK && j < j1; j++) {
        size_t r = j - c->j0, m = c->m[r], *cand = c->cand + r * c->n;
        double *cd = c->cd + r * c->n;
        for (size_t t = 0; t < m; t++) {
            x->dmax = cd[t] > x->dmax ? cd[t] : x->dmax;
            if (cand[t] < n0)
                enter_list(x, cand[t], j, cd[t]);
        }
        if (x->k > 0)
            st = amscr__knn_select(j, cand, cd, m, x->k, x->nb_idx + j * x->k, x->nb_dist + j * x->k);
    }
    return st;
}

amscr_status amscr_index_add(amscr_index *x, const amscr_db *shapes, amscr_progress_fn progress, void *user)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR_CHECK_NULL(shapes);
    const amscr_params *p = amscr_db_params(x->db);
    const char *diff = differing_option(p, amscr_db_params(shapes));
    if (diff)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_add: the shapes were prepared with another %s than the "
                                                "index (rebuild the index to change it)", diff);
    size_t n0 = amscr_db_size(x->db), add = amscr_db_size(shapes), n = n0 + add;
    amscr_status st = amscr__index_check_db(shapes, "amscr_index_add");
    size_t kp = amscr__rerank_k(p, n);
    if (st == AMSCR_OK && kp != x->k && n0 > 0) /* a list grows with the collection: rebuild */
        return amscr__fail(AMSCR_E_STATE, "amscr_index_add: the index holds %zu neighbours a shape and needs %zu "
                                          "with %zu shapes; rebuild it", x->k, kp, n);
    if (st == AMSCR_OK && n0 == 0)
        x->k = kp;
    if (st == AMSCR_OK)
        st = amscr__index_reserve(x, n);
    for (size_t i = 0; st == AMSCR_OK && i < add; i++)
        st = amscr_db_add_descriptor(x->db, amscr_db_descriptor(shapes, i), amscr_db_label(shapes, i), NULL);
    if (st == AMSCR_OK)
        st = amscr__index_features(x, n0, 0);
    add_ctx c = {x, {0}, n0, n, NULL, NULL, NULL};
    amscr__base_init(&c.b, p, x->med_a, x->med_h);
    size_t batch = 4 * (size_t)c.b.threads; /* rows computed together (memory: batch x n) */
    c.cand = st == AMSCR_OK ? amscr__malloc_array(batch, n * sizeof *c.cand) : NULL;
    c.cd = st == AMSCR_OK ? amscr__malloc_array(batch, n * sizeof *c.cd) : NULL;
    c.m = st == AMSCR_OK ? amscr__malloc_array(batch, sizeof *c.m) : NULL;
    if (st == AMSCR_OK && (!c.cand || !c.cd || !c.m))
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_add: out of memory");
    for (size_t j = n0; st == AMSCR_OK && j < n; j += batch) {
        if (progress && progress(user, j - n0, add) != 0)
            st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
        c.j0 = j;
        if (st == AMSCR_OK)
            st = add_rows(&c, j + batch < n ? j + batch : n, n0);
    }
    if (st == AMSCR_OK && progress && progress(user, add, add) != 0)
        st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    if (st == AMSCR_OK)
        st = amscr__index_reverse(x); /* the lists changed: their reverse for the queries */
    free(c.cand);
    free(c.cd);
    free(c.m);
    return st;
}
