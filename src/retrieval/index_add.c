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
    CMP(channel_invariance) CMP(channel_affine_share) CMP(channel_band) CMP(channel_skip) CMP(channel_locality)
    CMP(rerank_k) CMP(rerank_iterations)
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

/* Row j (new) and the older rows it enters, from its shortlist. */
static amscr_status add_row(amscr_index *x, const amscr__base *b, size_t j, size_t n0, size_t *cand, double *cd)
{
    size_t m = amscr__index_shortlist(x, x->sig + j * x->sig_dim, x->candidates, j, cand);
    amscr_status st = amscr__base_row(b, x->db, amscr_db_descriptor(x->db, j), j, cand, m, NULL, NULL, cd);
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) {
        x->dmax = cd[t] > x->dmax ? cd[t] : x->dmax;
        if (cand[t] < n0)
            enter_list(x, cand[t], j, cd[t]);
    }
    if (st == AMSCR_OK && x->k > 0)
        st = amscr__knn_select(j, cand, cd, m, x->k, x->nb_idx + j * x->k, x->nb_dist + j * x->k);
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
    size_t kp = p->rerank_k < n ? p->rerank_k : n;
    if (st == AMSCR_OK && kp != x->k && n0 > 0) /* a list grows with the collection: rebuild */
        return amscr__fail(AMSCR_E_STATE, "amscr_index_add: the index holds %zu neighbours a shape and needs %zu "
                                          "with %zu shapes; rebuild it", x->k, kp, n);
    if (st == AMSCR_OK && n0 == 0)
        x->k = kp;
    if (st == AMSCR_OK)
        st = amscr__index_reserve(x, n);
    for (size_t i = 0; st == AMSCR_OK && i < add; i++)
        st = amscr_db_add_descriptor(x->db, amscr_db_descriptor(shapes, i), amscr_db_label(shapes, i), NULL);
    for (size_t i = n0; st == AMSCR_OK && i < n; i++)
        amscr__shape_signature(amscr_db_descriptor(x->db, i), x->sig + i * x->sig_dim);
    size_t *cand = st == AMSCR_OK ? amscr__malloc_array(n, sizeof *cand) : NULL;
    double *cd = st == AMSCR_OK ? amscr__malloc_array(n, sizeof *cd) : NULL;
    if (st == AMSCR_OK && (!cand || !cd))
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_add: out of memory");
    amscr__base b;
    amscr__base_init(&b, p, x->med_a, x->med_h);
    for (size_t j = n0; st == AMSCR_OK && j < n; j++) {
        if (progress && progress(user, j - n0, add) != 0)
            st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
        if (st == AMSCR_OK)
            st = add_row(x, &b, j, n0, cand, cd);
    }
    if (st == AMSCR_OK && progress && progress(user, add, add) != 0)
        st = amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    free(cand);
    free(cd);
    return st;
}
