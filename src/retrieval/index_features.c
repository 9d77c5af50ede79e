/* index_features.c — what an index keeps of each shape for matching, computed once per shape
 * (after a build, an add or a load) on the params' threads: its shortlist signature with the
 * signature's lower-bound vector (signature.h), its channel features in every frame of the
 * channel (channel.h) and, with the inner distance's graph, its inner features (inner.h), so a
 * query or a row matches a shape without rebuilding anything. A load from a file that holds
 * the features' heights computes only their spectra (the inner features it reads); a lazy load
 * nothing (index_pairs.c computes what a pair needs). */
#include "db_io.h"
#include "index.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    amscr_index *x;
    amscr__base b;
    int have_sig;
} feat_job;

/* Bytes of one frame's mirrored orientation in the pool: its heights, then its spectra (each
 * rounded up to 16 bytes, as malloc aligns them). */
static size_t pool_heights(size_t N) { return (N * AMSCR__HF_BINS + 15) / 16 * 16; }
static size_t pool_frame(size_t N)
{
    return pool_heights(N) + (AMSCR__HF_SPEC(AMSCR__HF_FREQS(N) + 1) * sizeof(int16_t) + 15) / 16 * 16;
}

/* The mirrored orientation of a shape's features (nf frames) freed (what points into pool
 * forgotten): a pair that reads it (the shape is its higher index: a member's query, a row of an
 * add) makes it from the shape's input samples (index_pairs.c); an index keeps the forward one
 * only, 6.6 KB a shape less. */
static void mirror_free(amscr__hf *hf, int nf, const unsigned char *pool, size_t pool_len)
{
    for (int f = 0; f < nf; f++) {
        if ((uintptr_t)hf[f].seq[1] - (uintptr_t)pool >= pool_len)
            free(hf[f].seq[1]);
        if ((uintptr_t)hf[f].spec[1] - (uintptr_t)pool >= pool_len)
            free(hf[f].spec[1]);
        hf[f].seq[1] = NULL;
        hf[f].spec[1] = NULL;
    }
}

void amscr__index_drop_mirrors(amscr_index *x, size_t first)
{
    size_t n = amscr_db_size(x->db);
    size_t len = x->mirror_pool ? (n - x->pool_first) * (size_t)x->nf * pool_frame(amscr_db_params(x->db)->num_samples)
                                : 0;
    for (size_t i = first; x->hf && i < n; i++)
        mirror_free(x->hf + i * (size_t)x->nf, x->nf, x->mirror_pool, len);
    free(x->mirror_pool);
    x->mirror_pool = NULL;
}

/* Shape i's mirrored features moved into the pool (their own blocks freed for the next shape's:
 * the pool is freed whole, the heap keeps no holes). */
static void mirror_to_pool(amscr_index *x, size_t i)
{
    size_t N = amscr_db_params(x->db)->num_samples, S = AMSCR__HF_SPEC(AMSCR__HF_FREQS(N) + 1);
    amscr__hf *hf = x->hf + i * (size_t)x->nf;
    for (int f = 0; f < x->nf; f++) {
        unsigned char *at = x->mirror_pool + ((i - x->pool_first) * (size_t)x->nf + (size_t)f) * pool_frame(N);
        memcpy(at, hf[f].seq[1], N * AMSCR__HF_BINS);
        memcpy(at + pool_heights(N), hf[f].spec[1], S * sizeof(int16_t));
        free(hf[f].seq[1]);
        free(hf[f].spec[1]);
        hf[f].seq[1] = at;
        hf[f].spec[1] = (int16_t *)(void *)(at + pool_heights(N));
    }
}

static amscr_status feat_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    feat_job *j = ctx;
    amscr_index *x = j->x;
    if (!j->have_sig) { /* a load has set them (index_io.c) */
        const amscr_descriptor *d = amscr_db_descriptor(x->db, i);
        if (!d)
            return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
        float sig[AMSCR__SIG_DIM];
        amscr__shape_signature(d, sig);
        amscr__index_set_sig(x, i, sig);
    }
    amscr__hf *hf = x->hf + i * (size_t)x->nf;
    if (x->nf == 0 || (x->lazy && j->have_sig))
        return AMSCR_OK; /* a lazy load: built by the pairs that need them (index_pairs.c) */
    if (j->have_sig && hf[0].seq[0] != NULL) { /* the heights came with the file: their spectra */
        mirror_free(hf, x->nf, NULL, 0); /* an older file's mirrored heights: not kept */
        amscr_status st = AMSCR_OK;
        for (int f = 0; f < x->nf && st == AMSCR_OK; f++)
            st = hf[f].spec[0] ? AMSCR_OK : amscr__hf_spectra(&hf[f], NULL);
        return st;
    }
    const amscr_descriptor *d = amscr_db_descriptor(x->db, i); /* a lazy load's: decoded here */
    if (!d)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    for (int f = 0; f < x->nf; f++)
        amscr__hf_free(&hf[f]);
    amscr_status st = amscr__base_hf(&j->b, d, hf);
    if (st == AMSCR_OK && x->mirror_pool && i >= x->pool_first)
        mirror_to_pool(x, i);
    else if (st == AMSCR_OK && j->have_sig) /* a load of a file without the heights: no rows follow */
        mirror_free(hf, x->nf, NULL, 0);
    return st;
}

amscr_status amscr__index_features(amscr_index *x, size_t first, int have_sig)
{
    feat_job j;
    j.x = x;
    j.have_sig = have_sig;
    amscr__base_init(&j.b, amscr_db_params(x->db), x->med_a, x->med_h);
    size_t n = amscr_db_size(x->db), N = amscr_db_params(x->db)->num_samples;
    if (!have_sig && x->nf > 0 && !x->mirror_pool && n > first) { /* a build's or an add's rows follow */
        x->mirror_pool = amscr__malloc_array(n - first, (size_t)x->nf * pool_frame(N));
        x->pool_first = first; /* without a pool (out of memory), each shape's own blocks */
    }
    amscr__rows_fn f = {NULL, NULL, feat_row, &j, NULL};
    amscr__index_reverse_free(x);
    amscr_status st = amscr__run_rows(&f, first, amscr_db_size(x->db), j.b.threads, NULL, NULL);
    if (st == AMSCR_OK && !have_sig && x->k2 > 0) /* a load reads the inner features (index_io.c) */
        st = amscr__inner_features(x->db, first, j.b.threads, x->inner);
    return st == AMSCR_OK && have_sig && first == 0 ? amscr__index_reverse(x) : st;
}
