/* index_features.c — what an index keeps of each shape for matching, computed once per shape
 * (after a build, an add or a load) on the params' threads: its shortlist signature with the
 * signature's lower-bound vector (signature.h), its channel features in every frame of the
 * channel (channel.h) and, with the inner distance's graph, its inner features (inner.h), so a
 * query or a row matches a shape without rebuilding anything. A load from a file that holds
 * the features' heights computes only their spectra (the inner features it reads); a lazy load
 * nothing (index_pairs.c computes what a pair needs). */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>

typedef struct {
    amscr_index *x;
    amscr__base b;
    int have_sig;
} feat_job;

/* The mirrored heights of shape i (a file from version 16 keeps the forward ones only), from its
 * input samples (its compact record: nothing decoded). */
static amscr_status mirror_heights(const feat_job *j, size_t i, amscr__hf *hf)
{
    const amscr_db *db = j->x->db;
    size_t N = amscr_db_params(db)->num_samples;
    double *buf = amscr__malloc_array(2 * N + 2 * AMSCR__OUTLINE_N, sizeof *buf);
    amscr_descriptor sd, *tmp = NULL;
    const amscr_descriptor *d = !buf                                       ? NULL
                                : amscr__db_shallow(db, i, &sd, buf, buf + 2 * N) ? &sd
                                                                           : amscr__db_descriptor_peek(db, i, &tmp);
    amscr_status st = d ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    for (int f = 0; f < j->x->nf && st == AMSCR_OK; f++)
        st = amscr__hf_mirror_of_descriptor(j->b.p, j->b.frames[f], d, &hf[f]);
    amscr_descriptor_free(tmp);
    free(buf);
    return st;
}

static amscr_status feat_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    feat_job *j = ctx;
    amscr_index *x = j->x;
    float *sig = x->sig + i * x->sig_dim;
    if (!j->have_sig) {
        const amscr_descriptor *d = amscr_db_descriptor(x->db, i);
        if (!d)
            return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
        amscr__shape_signature(d, sig);
    }
    amscr__sig_bound_vector(sig, x->sig_lb + i * AMSCR__SIG_LB_DIM);
    amscr__hf *hf = x->hf + i * (size_t)x->nf;
    if (x->nf == 0 || (x->lazy && j->have_sig))
        return AMSCR_OK; /* a lazy load: built by the pairs that need them (index_pairs.c) */
    if (j->have_sig && hf[0].seq[0] != NULL) { /* the heights came with the file: their spectra */
        amscr_status st = hf[0].seq[1] == NULL ? mirror_heights(j, i, hf) : AMSCR_OK;
        for (int f = 0; f < x->nf && st == AMSCR_OK; f++)
            st = hf[f].spec[0] ? AMSCR_OK : amscr__hf_spectra(&hf[f], NULL);
        return st;
    }
    const amscr_descriptor *d = amscr_db_descriptor(x->db, i); /* a lazy load's: decoded here */
    if (!d)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    for (int f = 0; f < x->nf; f++)
        amscr__hf_free(&hf[f]);
    return amscr__base_hf(&j->b, d, hf);
}

amscr_status amscr__index_features(amscr_index *x, size_t first, int have_sig)
{
    feat_job j;
    j.x = x;
    j.have_sig = have_sig;
    amscr__base_init(&j.b, amscr_db_params(x->db), x->med_a, x->med_h);
    amscr__rows_fn f = {NULL, NULL, feat_row, &j, NULL};
    amscr__index_reverse_free(x);
    amscr_status st = amscr__run_rows(&f, first, amscr_db_size(x->db), j.b.threads, NULL, NULL);
    if (st == AMSCR_OK && !have_sig && x->k2 > 0) /* a load reads the inner features (index_io.c) */
        st = amscr__inner_features(x->db, first, j.b.threads, x->inner);
    return st == AMSCR_OK && have_sig && first == 0 ? amscr__index_reverse(x) : st;
}
