/* index_mirror.c — the mirrored orientation of an index's channel features: a pair reads it
 * only when the shape is its higher index (a member's query, a row of a build or an add), so an
 * index keeps the forward orientation only (6.6 KB a shape less). While a build's or an add's
 * rows are computed, the new shapes' mirrored features live in one pool (the heap keeps no
 * holes); once the rows are built they are dropped with it (index_pairs.c makes them again from a
 * shape's input samples when a pair needs them). */
#include "index.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Bytes of one frame's mirrored heights in the pool, rounded up to 16 bytes as malloc aligns. */
static size_t pool_heights(size_t N) { return (N * AMSCR__HF_BINS + 15) / 16 * 16; }
size_t amscr__index_pool_frame(size_t N)
{
    return pool_heights(N) + (AMSCR__HF_SPEC(AMSCR__HF_FREQS(N) + 1) * sizeof(int16_t) + 15) / 16 * 16;
}

void amscr__index_mirror_free(amscr__hf *hf, int nf, const unsigned char *pool, size_t pool_len)
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
    size_t N = amscr_db_params(x->db)->num_samples;
    size_t len = x->mirror_pool ? (n - x->pool_first) * (size_t)x->nf * amscr__index_pool_frame(N) : 0;
    for (size_t i = first; x->hf && i < n; i++)
        amscr__index_mirror_free(x->hf + i * (size_t)x->nf, x->nf, x->mirror_pool, len);
    free(x->mirror_pool);
    x->mirror_pool = NULL;
}

void amscr__index_mirror_to_pool(amscr_index *x, size_t i)
{
    size_t N = amscr_db_params(x->db)->num_samples, S = AMSCR__HF_SPEC(AMSCR__HF_FREQS(N) + 1);
    amscr__hf *hf = x->hf + i * (size_t)x->nf;
    for (int f = 0; f < x->nf; f++) {
        size_t frame = (i - x->pool_first) * (size_t)x->nf + (size_t)f;
        unsigned char *at = x->mirror_pool + frame * amscr__index_pool_frame(N);
        memcpy(at, hf[f].seq[1], N * AMSCR__HF_BINS);
        memcpy(at + pool_heights(N), hf[f].spec[1], S * sizeof(int16_t));
        free(hf[f].seq[1]);
        free(hf[f].spec[1]);
        hf[f].seq[1] = at;
        hf[f].spec[1] = (int16_t *)(void *)(at + pool_heights(N));
    }
}
