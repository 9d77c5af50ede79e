/* retrieval_io.c — the retrieval settings block of the saved collection (format versions 2 and up;
 * layout in internal.h). Little-endian whatever the host. */
#include "internal.h"

#include <string.h>

static void put_u32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static void put_f64(unsigned char *b, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t get_u32(const unsigned char *b)
{
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)b[i] << (8 * i);
    return v;
}

static double get_f64(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)b[i] << (8 * i);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

void amscr__retrieval_block_write(const amscr_params *p, unsigned char *out, size_t size)
{
    put_f64(out, p->channel_weight);
    put_u32(out + 8, (uint32_t)p->channel_invariance);
    put_f64(out + 12, p->channel_affine_share);
    put_f64(out + 20, p->channel_band);
    put_f64(out + 28, p->channel_skip);
    put_f64(out + 36, p->channel_locality);
    put_u32(out + 44, p->rerank_k);
    put_u32(out + 48, p->rerank_iterations);
    if (size >= AMSCR__RETRIEVAL_BLOCK_V2)
        put_f64(out + 52, p->channel_affine_band);
    if (size >= AMSCR__RETRIEVAL_BLOCK_V3)
        put_f64(out + 60, p->rerank_inner_share);
    if (size >= AMSCR__RETRIEVAL_BLOCK_V4)
        put_f64(out + 68, p->inner_closing);
    if (size >= AMSCR__RETRIEVAL_BLOCK_V5)
        put_f64(out + 76, p->channel_affine_view);
}

amscr_status amscr__retrieval_block_read(const unsigned char *in, size_t size, amscr_params *p)
{
    amscr_params q = *p;
    uint32_t inv = get_u32(in + 8);
    double affine_band = size >= AMSCR__RETRIEVAL_BLOCK_V2 ? get_f64(in + 52) : get_f64(in + 20);
    double inner_share = size >= AMSCR__RETRIEVAL_BLOCK_V3 ? get_f64(in + 60) : 0.0;
    double closing = size >= AMSCR__RETRIEVAL_BLOCK_V4 ? get_f64(in + 68) : 0.0;
    double view = size >= AMSCR__RETRIEVAL_BLOCK_V5 ? get_f64(in + 76) : 0.0;
    if (inv > 1u || amscr_params_set_channel_weight(&q, get_f64(in)) != AMSCR_OK ||
        amscr_params_set_channel_invariance(&q, (amscr_invariance)inv) != AMSCR_OK ||
        amscr_params_set_channel_affine_share(&q, get_f64(in + 12)) != AMSCR_OK ||
        amscr_params_set_channel_band(&q, get_f64(in + 20)) != AMSCR_OK ||
        amscr_params_set_channel_affine_band(&q, affine_band) != AMSCR_OK ||
        amscr_params_set_channel_skip(&q, get_f64(in + 28)) != AMSCR_OK ||
        amscr_params_set_channel_locality(&q, get_f64(in + 36)) != AMSCR_OK ||
        amscr_params_set_rerank_k(&q, get_u32(in + 44)) != AMSCR_OK ||
        amscr_params_set_rerank_iterations(&q, get_u32(in + 48)) != AMSCR_OK ||
        amscr_params_set_rerank_inner_share(&q, inner_share) != AMSCR_OK ||
        amscr_params_set_inner_closing(&q, closing) != AMSCR_OK ||
        amscr_params_set_channel_affine_view(&q, view) != AMSCR_OK) {
        amscr__clear_error();
        return AMSCR_E_FORMAT;
    }
    *p = q;
    return AMSCR_OK;
}
