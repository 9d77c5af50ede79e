/* result.c — the result object of amscr_register and its getters. */
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void amscr_result_free(amscr_result *r)
{
    if (r)
        free(r->corr);
    free(r);
}

double amscr_result_distance(const amscr_result *r) { return r ? r->m.dist : NAN; }

amscr_status amscr_result_affine(const amscr_result *r, double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(out_m6);
    memcpy(out_m6, r->affine_in, 6 * sizeof(double));
    return AMSCR_OK;
}

amscr_status amscr_result_affine_normalized(const amscr_result *r, double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(out_m6);
    memcpy(out_m6, r->affine_norm, 6 * sizeof(double));
    return AMSCR_OK;
}

size_t amscr_result_shift(const amscr_result *r) { return r ? r->m.shift : 0; }
int amscr_result_reflected(const amscr_result *r) { return r ? r->m.reflected : 0; }
amscr_method amscr_result_method(const amscr_result *r) { return r ? r->method : (amscr_method)-1; }
size_t amscr_result_num_scales(const amscr_result *r) { return r ? r->m.p : 0; }
size_t amscr_result_num_kept(const amscr_result *r) { return r ? r->m.nkept : 0; }
size_t amscr_result_k(const amscr_result *r) { return r ? r->m.k : 0; }
double amscr_result_threshold(const amscr_result *r) { return r ? r->m.threshold : NAN; }

static amscr_status copy_out(const double *src, size_t count, double *out, size_t *inout_n, const char *what)
{
    if (out) {
        if (*inout_n < count)
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: room for %zu values, %zu needed", what, *inout_n, count);
        if (src)
            memcpy(out, src, count * sizeof *out);
    }
    *inout_n = count;
    return AMSCR_OK;
}

amscr_status amscr_result_residuals(const amscr_result *r, double *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    return copy_out(r->m.resid, r->m.p, out, inout_n, "amscr_result_residuals");
}

amscr_status amscr_result_sse(const amscr_result *r, double *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    return copy_out(r->m.sse, r->m.nsse, out, inout_n, "amscr_result_sse");
}

amscr_status amscr_result_kept(const amscr_result *r, int *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    if (out) {
        if (*inout_n < r->m.p)
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_kept: room for %zu values, %zu needed", *inout_n,
                               r->m.p);
        memcpy(out, r->m.kept, r->m.p * sizeof *out);
    }
    *inout_n = r->m.p;
    return AMSCR_OK;
}

amscr_status amscr_result_mixture(const amscr_result *r, double *out_weights, double *out_means,
                                  double *out_variances, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    size_t k = r->m.ncomp;
    if ((out_weights || out_means || out_variances) && *inout_n < k)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_mixture: room for %zu, %zu needed", *inout_n, k);
    if (out_weights)
        memcpy(out_weights, r->m.w, k * sizeof(double));
    if (out_means)
        memcpy(out_means, r->m.mu, k * sizeof(double));
    if (out_variances)
        memcpy(out_variances, r->m.var, k * sizeof(double));
    *inout_n = k;
    return AMSCR_OK;
}

/* ---- robust registration: confidence, part, dense correspondences ---- */
double amscr__confidence(const amscr_result *r)
{
    double fb = isfinite(r->fb) ? r->fb / AMSCR__FB_SCALE : 0.0;
    double se = isfinite(r->se) ? r->se / AMSCR__FB_SCALE : 0.0;
    /* isless/isgreater: NaN (not computed; an open curve's overlap) compared quietly */
    double share = isless(r->overlap, r->inlier) ? r->overlap : r->inlier;
    double amb = isgreater(r->amb_conv, r->m.ambiguity) ? r->amb_conv : r->m.ambiguity;
    return (1.0 - amb) * share / (1.0 + fb * fb) / (1.0 + se * se);
}

double amscr_result_ambiguity(const amscr_result *r) { return r ? r->m.ambiguity : NAN; }
double amscr_result_inlier_fraction(const amscr_result *r) { return r ? r->inlier : NAN; }
double amscr_result_confidence(const amscr_result *r) { return r ? amscr__confidence(r) : NAN; }
double amscr_result_overlap(const amscr_result *r) { return r ? r->overlap : NAN; }
double amscr_result_backward_error(const amscr_result *r) { return r ? r->fb : NAN; }
double amscr_result_standard_error(const amscr_result *r) { return r ? r->se : NAN; }
double amscr_result_symmetry_ambiguity(const amscr_result *r) { return r ? r->amb_conv : NAN; }

amscr_status amscr_result_part(const amscr_result *r, double *out_start, double *out_end)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(out_start);
    AMSCR_CHECK_NULL(out_end);
    *out_start = r->part[0];
    *out_end = r->part[1];
    return AMSCR_OK;
}

amscr_status amscr_result_correspondences(const amscr_result *r, double *out_src_xy, double *out_param,
                                          double *out_tgt_xy, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    size_t n = r->ncorr;
    if ((out_src_xy || out_param || out_tgt_xy) && *inout_n < n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_correspondences: room for %zu samples, %zu needed",
                           *inout_n, n);
    for (size_t a = 0; a < n; a++) {
        const double *c = r->corr + 5 * a;
        if (out_src_xy) {
            out_src_xy[2 * a] = c[0];
            out_src_xy[2 * a + 1] = c[1];
        }
        if (out_param)
            out_param[a] = c[2];
        if (out_tgt_xy) {
            out_tgt_xy[2 * a] = c[3];
            out_tgt_xy[2 * a + 1] = c[4];
        }
    }
    *inout_n = n;
    return AMSCR_OK;
}

/* ---- the stages that ran (stages.c) and the alternatives (alternatives.c) ---- */
size_t amscr_result_num_stages(const amscr_result *r) { return r ? (size_t)AMSCR__NUM_STAGES : 0; }

amscr_status amscr_result_stage(const amscr_result *r, size_t i, const char **out_name, int *out_ran)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    if (i >= AMSCR__NUM_STAGES)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_stage: stage %zu of %d", i, (int)AMSCR__NUM_STAGES);
    if (out_name)
        *out_name = amscr__stage_name(i);
    if (out_ran)
        *out_ran = r->ran[i];
    return AMSCR_OK;
}

size_t amscr_result_num_alternatives(const amscr_result *r) { return r ? r->nalt : 0; }

amscr_status amscr_result_alternative(const amscr_result *r, size_t i, double out_m6[6], double *out_cost)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    if (i >= r->nalt)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_alternative: alternative %zu of %zu", i, r->nalt);
    if (out_m6)
        memcpy(out_m6, r->alt[i], sizeof r->alt[i]);
    if (out_cost)
        *out_cost = r->alt_cost[i];
    return AMSCR_OK;
}
