/* params.c — the registration options object: documented defaults, presets, the scale list and the
 * stage switches (its numbers and flags, with their setters and getters: options.c). */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Defaults: chosen by measurement (docs/measurements.md, "Choosing the defaults"). */
static const double default_scales[] = {1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 16.0};

/* The retrieval options (0.2): off in the plain defaults (amscr_db_distance_matrix is the
 * AMSCR distance exactly as in 0.1); the channel's own settings are those measured in
 * docs/decisions.md, so turning the channel on needs only a weight. */
static void retrieval_defaults(amscr_params *p)
{
    p->channel_weight = 0.0;
    p->channel_invariance = AMSCR_INVARIANCE_SIMILARITY;
    p->channel_affine_share = 0.2;
    p->channel_band = 0.15;
    p->channel_affine_band = 0.08;
    p->channel_skip = 1.0;
    p->channel_locality = 4.0;
    p->rerank_k = 0;
    p->rerank_iterations = 10;
    p->rerank_inner_share = 0.0;
    p->inner_closing = 0.0;
    p->channel_affine_view = 0.0;
}

void amscr__params_defaults(amscr_params *p)
{
    memset(p, 0, sizeof *p);
    p->num_samples = 128;
    p->num_scales = sizeof default_scales / sizeof default_scales[0];
    memcpy(p->scales, default_scales, sizeof default_scales);
    p->method = AMSCR_METHOD_MULTICLASS_EM;
    p->closed = 1;
    p->reflections = 0;
    p->parametrization = AMSCR_PARAM_WHITENED;
    p->presmooth = 0.01;
    p->arclength_passes = 3;
    p->oversampling = 8;
    p->kmax = 5;
    p->symmetric = 0;
    p->refine = 0;
    p->num_threads = 0;
    p->invariance = AMSCR_INVARIANCE_AFFINE;
    p->penalty = 0.5;
    /* Opt-in stages (amscr_params_set_stage): despike, order and even_spacing changed no map of
     * the 216 traced pairs of fold A of bench/registration_traced.py (either tracer; fold B
     * confirmed it), which chose this; they help point lists with stray points or synthetic
     * noise (docs/decisions.md). */
    p->stages_off = AMSCR__STAGE_BIT(AMSCR__STAGE_DESPIKE) | AMSCR__STAGE_BIT(AMSCR__STAGE_ORDER) |
                    AMSCR__STAGE_BIT(AMSCR__STAGE_EVEN);
    retrieval_defaults(p);
}

/* A new params filled by `preset`; `who` names the public call in the error detail. */
static amscr_status new_preset(void (*preset)(amscr_params *), const char *who, amscr_params **out)
{
    amscr__clear_error();
    if (out == NULL)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: out is NULL", who);
    amscr_params *p = malloc(sizeof *p);
    if (!p)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", who);
    preset(p);
    *out = p;
    return AMSCR_OK;
}

amscr_status amscr_params_new(amscr_params **out)
{
    return new_preset(amscr__params_defaults, "amscr_params_new", out);
}

void amscr__params_registration(amscr_params *p)
{
    amscr__params_defaults(p);
    p->num_samples = 256;
    p->refine = 20;
    p->polish = 1;
}

amscr_status amscr_params_new_registration(amscr_params **out)
{
    return new_preset(amscr__params_registration, "amscr_params_new_registration", out);
}

void amscr__params_retrieval(amscr_params *p)
{
    amscr__params_defaults(p);
    p->reflections = 1;
    p->channel_weight = 1.0;
    p->rerank_k = 8;
    p->rerank_inner_share = 0.1;
    p->inner_closing = 0.04;
    p->channel_affine_view = 2.0;
}

amscr_status amscr_params_new_retrieval(amscr_params **out)
{
    return new_preset(amscr__params_retrieval, "amscr_params_new_retrieval", out);
}

amscr_status amscr_params_copy(const amscr_params *p, amscr_params **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(out);
    amscr_params *q = malloc(sizeof *q);
    if (!q)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_params_copy: out of memory");
    *q = *p;
    *out = q;
    return AMSCR_OK;
}

void amscr_params_free(amscr_params *p) { free(p); }

/* The numbers and flags, each with its named pair and its key: options.c. */

amscr_status amscr_params_set_scales(amscr_params *p, const double *sigmas, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(sigmas);
    if (n == 0 || n > AMSCR_MAX_SCALES)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_params_set_scales: %zu scales (1..%u allowed)", n,
                           (unsigned)AMSCR_MAX_SCALES);
    for (size_t i = 0; i < n; i++)
        if (!isfinite(sigmas[i]) || sigmas[i] < 0.0 || sigmas[i] > (double)p->num_samples)
            return amscr__fail(AMSCR_E_INVALID_ARG,
                               "amscr_params_set_scales: scale %zu = %g is not in 0..N (N = %zu)", i, sigmas[i],
                               p->num_samples);
    memcpy(p->scales, sigmas, n * sizeof *sigmas);
    p->num_scales = n;
    return AMSCR_OK;
}

amscr_status amscr_params_get_scales(const amscr_params *p, double *out_sigmas, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(inout_n);
    if (out_sigmas) {
        if (*inout_n < p->num_scales)
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_params_get_scales: room for %zu, %zu needed", *inout_n,
                               p->num_scales);
        memcpy(out_sigmas, p->scales, p->num_scales * sizeof *out_sigmas);
    }
    *inout_n = p->num_scales;
    return AMSCR_OK;
}

/* ---- switchable stages of amscr_register (their names: stage_names.c) ---- */
amscr_status amscr_params_set_stage(amscr_params *p, const char *name, int on)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(name);
    int i = amscr__stage_switch(name);
    if (i < 0)
        return amscr__fail(AMSCR_E_INVALID_ARG,
                           "amscr_params_set_stage: '%s' is not a switchable stage (despike, recovery, polish, "
                           "order, even_spacing, pixel_grid)", name);
    if (on != 0 && on != 1)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_params_set_stage: %d is not 0 or 1", on);
    if (on)
        p->stages_off &= ~AMSCR__STAGE_BIT(i);
    else
        p->stages_off |= AMSCR__STAGE_BIT(i);
    return AMSCR_OK;
}

int amscr_params_get_stage(const amscr_params *p, const char *name)
{
    int i = p ? amscr__stage_switch(name) : -1;
    return i < 0 ? -1 : AMSCR__STAGE_ON(p, i);
}
