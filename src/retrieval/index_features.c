/* index_features.c — what an index keeps of each shape for matching, computed once per shape
 * (after a build, an add or a load) on the params' threads: its shortlist signature with the
 * signature's lower-bound vector (signature.h), its channel features in every frame of the
 * channel (channel.h) and, with the inner distance's graph, its inner features (inner.h), so a
 * query or a row matches a shape without rebuilding anything. A load from a file that holds
 * the features' heights computes only their spectra (the inner features it reads); a lazy load
 * nothing (index_pairs.c computes what a pair needs). The mirrored orientation of a build's or
 * an add's features lives in one pool until their rows are built (index_mirror.c). */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>

typedef struct {
    amscr_index *x;
    amscr__base b;
    int have_sig;
} feat_job;

static amscr_status feat_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    feat_job *j = ctx;
    amscr_index *x = j->x;
    if (!j->have_sig) { /* a load has set them (index_io.c) */
        const amscr_descriptor *d;
        amscr_status st = amscr__db_shape(x->db, i, &d);
        if (st != AMSCR_OK)
            return st;
        float sig[AMSCR__SIG_DIM];
        amscr__shape_signature(d, sig);
        amscr__index_set_sig(x, i, sig);
    }
    amscr__hf *hf = x->hf + i * (size_t)x->nf;
    if (x->nf == 0 || (x->lazy && j->have_sig))
        return AMSCR_OK; /* a lazy load: built by the pairs that need them (index_pairs.c) */
    if (j->have_sig && hf[0].seq[0] != NULL) { /* the heights came with the file: their spectra */
        amscr__index_mirror_free(hf, x->nf, NULL, 0); /* an older file's mirrored heights: not kept */
        amscr_status st = AMSCR_OK;
        for (int f = 0; f < x->nf && st == AMSCR_OK; f++)
            st = hf[f].spec[0] ? AMSCR_OK : amscr__hf_spectra(&hf[f], NULL);
        return st;
    }
    const amscr_descriptor *d; /* a lazy load's: decoded here */
    amscr_status st = amscr__db_shape(x->db, i, &d);
    if (st != AMSCR_OK)
        return st;
    for (int f = 0; f < x->nf; f++)
        amscr__hf_free(&hf[f]);
    st = amscr__base_hf(&j->b, d, hf);
    if (st == AMSCR_OK && x->mirror_pool && i >= x->pool_first)
        amscr__index_mirror_to_pool(x, i);
    else if (st == AMSCR_OK && j->have_sig) /* a load of a file without the heights: no rows follow */
        amscr__index_mirror_free(hf, x->nf, NULL, 0);
    return st;
}

amscr_status amscr__index_features(amscr_index *x, size_t first, int have_sig, amscr_progress_fn progress,
                                    void *user)
{
    feat_job j;
    j.x = x;
    j.have_sig = have_sig;
    amscr__base_init(&j.b, amscr_db_params(x->db), x->med_a, x->med_h);
    size_t n = amscr_db_size(x->db), N = amscr_db_params(x->db)->num_samples;
    if (!have_sig && x->nf > 0 && !x->mirror_pool && n > first) { /* a build's or an add's rows follow */
        x->mirror_pool = amscr__malloc_array(n - first, (size_t)x->nf * amscr__index_pool_frame(N));
        x->pool_first = first; /* without a pool (out of memory), each shape's own blocks */
    }
    amscr__rows_fn f = {NULL, NULL, feat_row, &j, NULL};
    amscr__index_reverse_free(x);
    int inner = !have_sig && x->k2 > 0; /* a load reads the inner features (index_io.c) */
    amscr__stages sp = {progress, user, 0, inner ? 2 : 1};
    amscr_progress_fn cb = progress ? amscr__stage_cb : NULL;
    amscr_status st = amscr__run_rows(&f, first, amscr_db_size(x->db), j.b.threads, cb, &sp);
    sp.stage = 1;
    if (st == AMSCR_OK && inner)
        st = amscr__inner_features(x->db, first, j.b.threads, x->inner, cb, &sp);
    return st == AMSCR_OK && have_sig && first == 0 ? amscr__index_reverse(x) : st;
}
