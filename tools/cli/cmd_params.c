/* cmd_params.c — library params from the tool's options (see cmd_params.h). */
#include "cmd_params.h"

#include <stdlib.h>
#include <string.h>

/* registration: the library's registration preset (N 256, 20 refinement iterations: measured
 * in docs/measurements.md). Retrieval (search/matrix/eval): the library's retrieval preset (the shape
 * channel in the similarity frame with 0.2 of the affine frame, re-ranking k 8, 10 iterations,
 * reflections on: docs/decisions.md); the AMSCR distance in it (a channel weight
 * below 1) is the affine group without refinement, the paper's method. make_params adds the
 * options. */
static amscr_status base_params(int registration, amscr_params **out)
{
    return registration ? amscr_params_new_registration(out) : amscr_params_new_retrieval(out);
}

int make_params(const opts *o, int registration, amscr_params **out)
{
    amscr_params *p = NULL;
    amscr_status st = base_params(registration, &p);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return TOOL_EXIT_FAIL;
    }
    const char *opt = NULL;
#define SET(flag, name, call)                                                                                \
    do {                                                                                                     \
        if (st == AMSCR_OK && (flag)) {                                                                      \
            opt = name;                                                                                      \
            st = call;                                                                                       \
        }                                                                                                    \
    } while (0)
    SET(o->points_set, "--points", amscr_params_set_num_samples(p, o->points));
    SET(o->scales_set, "--scales", amscr_params_set_scales(p, o->scales, o->nscales));
    SET(o->method_set, "--method", amscr_params_set_method(p, o->method));
    SET(1, "--reflections", amscr_params_set_reflections(p, o->reflections < 0 ? !registration : o->reflections));
    SET(o->open, "--open", amscr_params_set_closed(p, 0));
    SET(o->partial, "--partial", amscr_params_set_partial(p, 1));
    SET(o->no_polish, "--no-polish", amscr_params_set_polish(p, 0));
    SET(o->refine_set, "--refine", amscr_params_set_refine(p, o->refine));
    for (size_t i = 0; i < o->nstages; i++)
        SET(1, "--stage", amscr_params_set_stage(p, o->stage_name[i], o->stage_on[i]));
    SET(o->threads_set, "--threads", amscr_params_set_num_threads(p, o->threads));
    SET(o->kmax_set, "--kmax", amscr_params_set_kmax(p, o->kmax));
    SET(o->symmetric, "--symmetric", amscr_params_set_symmetric(p, 1));
    SET(o->param_set, "--parametrization", amscr_params_set_parametrization(p, o->param));
    SET(o->inv_set, "--invariance", amscr_params_set_invariance(p, o->inv));
    /* the shape channel needs closed curves: open ones get the AMSCR distance alone */
    SET(o->open && !registration && !o->channel_weight_set, "--open", amscr_params_set_channel_weight(p, 0.0));
    SET(o->channel_weight_set, "--channel-weight", amscr_params_set_channel_weight(p, o->channel_weight));
    SET(o->affine_share_set, "--affine-share", amscr_params_set_channel_affine_share(p, o->affine_share));
    SET(o->affine_view_set, "--affine-view", amscr_params_set_channel_affine_view(p, o->affine_view));
    SET(o->inner_share_set, "--inner-share", amscr_params_set_rerank_inner_share(p, o->inner_share));
    SET(o->inner_closing_set, "--inner-closing", amscr_params_set_inner_closing(p, o->inner_closing));
    SET(o->rerank_set, "--rerank", amscr_params_set_rerank_k(p, (unsigned)o->rerank_k));
    SET(o->rerank_set && o->rerank_k > 0, "--rerank", amscr_params_set_rerank_iterations(p, o->rerank_iters));
#undef SET
    if (st != AMSCR_OK) {
        const char *d = lib_detail(); /* valid until the next library call: report first */
        int r = TOOL_EXIT_FAIL;
        if (st == AMSCR_E_INVALID_ARG)
            r = usage_error(opt, "%s", d[0] ? d : amscr_strerror(st));
        else
            tool_lib_error(opt, st);
        amscr_params_free(p);
        return r;
    }
    *out = p;
    return 0;
}

int default_params(int registration, amscr_params **out)
{
    opts o;
    memset(&o, 0, sizeof o);
    o.reflections = -1;
    return make_params(&o, registration, out);
}

int prepare(const amscr_params *p, const char *path, const amscr_contour *c, amscr_descriptor **out)
{
    amscr_status st = amscr_descriptor_new(p, c, out);
    if (st != AMSCR_OK) {
        const char *d = lib_detail();
        if (st == AMSCR_E_DEGENERATE)
            tool_error(path, "cannot use this shape: %s", d[0] ? d : "degenerate (too few points, or no area)");
        else
            tool_lib_error(path, st);
        return -1;
    }
    return 0;
}

double *params_scales(const amscr_params *p, size_t *n)
{
    size_t k = 0;
    if (amscr_params_get_scales(p, NULL, &k) != AMSCR_OK)
        return NULL;
    double *s = xmalloc_array(k ? k : 1, sizeof(double));
    if (s && amscr_params_get_scales(p, s, &k) != AMSCR_OK) {
        free(s);
        return NULL;
    }
    *n = k;
    return s;
}
