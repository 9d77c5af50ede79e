/* cmd_register.c — `amscr register SRC TGT`: the affine map, distance and scale selection of
 * one pair, as text or JSON, with an optional overlay picture and plot. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "components.h"
#include "draw.h"
#include "image.h"
#include "json.h"
#include "names.h"
#include "cmd_params.h"

/* What the result says, read once through the getters. */
typedef struct reg_report {
    double m[6];                /* the affine map */
    size_t np;                  /* scales */
    double *scales, *resid;     /* np each */
    int *kept;                  /* np */
    double *sse;                /* nsse: the elbow curve SSE(K) */
    size_t nsse;
    double mw[TOOL_KMAX_MAX], mm[TOOL_KMAX_MAX], mv[TOOL_KMAX_MAX]; /* the mixture: at most Kmax components */
    size_t nmix;
    double dist, thr;
    size_t shift, K, nkept, N;
    int refl;
    const char *mname;
    /* confidence, the part of the target covered, dense correspondences */
    double conf, amb, inl, overlap, fb, se, symamb, part[2];
    size_t ncorr;
    double *corr_param, *corr_xy; /* ncorr and 2 ncorr */
    /* the pipeline's stages and whether each ran; the maps that fit about as well (0.5) */
    size_t nstages, nalt;
    const char **stage_name; /* nstages, the library's strings */
    int *stage_ran;          /* nstages */
    double *alt, *alt_cost;  /* 6 nalt and nalt: maps in input coordinates, ranking costs */
} reg_report;

static void report_free(reg_report *r)
{
    free(r->scales);
    free(r->resid);
    free(r->kept);
    free(r->sse);
    free(r->corr_param);
    free(r->corr_xy);
    free(r->stage_name);
    free(r->stage_ran);
    free(r->alt);
    free(r->alt_cost);
}

/* Prepares both shapes; --partial: the source open, the target closed. */
static int prepare_pair(const amscr_params *p, const opts *o, const amscr_contour *src, const amscr_contour *tgt,
                        amscr_descriptor **ds, amscr_descriptor **dt)
{
    amscr_params *ps = NULL, *pt = NULL;
    int ret = -1;
    if (amscr_params_copy(p, &ps) != AMSCR_OK || amscr_params_copy(p, &pt) != AMSCR_OK) {
        tool_lib_error("register", AMSCR_E_NOMEM);
        goto done;
    }
    if (amscr_params_get_partial(p) &&
        (amscr_params_set_closed(ps, 0) != AMSCR_OK || amscr_params_set_closed(pt, 1) != AMSCR_OK))
        goto done;
    ret = prepare(ps, o->pos[0], src, ds) != 0 || prepare(pt, o->pos[1], tgt, dt) != 0 ? -1 : 0;
done:
    amscr_params_free(ps);
    amscr_params_free(pt);
    return ret;
}

/* Loads, prepares and registers the pair; *src, *tgt, *res owned by the caller. */
static int register_pair(const opts *o, const amscr_params *p, amscr_contour **src, amscr_contour **tgt,
                         amscr_result **res)
{
    const char *spath = o->pos[0], *tpath = o->pos[1];
    amscr_descriptor *ds = NULL, *dt = NULL;
    int ret = -1;
    /* an image's other large pieces near its largest component are part of the shape (an
     * occluder cut it): joined to the outline (sub-pixel tracing) */
    image_set_trace_flags(image_trace_flags() | AMSCR_TRACE_JOIN);
    if (shape_load_opts(o, spath, src) != 0 || shape_load_opts(o, tpath, tgt) != 0)
        goto done;
    if (prepare_pair(p, o, *src, *tgt, &ds, &dt) != 0)
        goto done;
    amscr_status st = amscr_register(p, ds, dt, NULL, res);
    if (st != AMSCR_OK) {
        char what[512];
        snprintf(what, sizeof what, "%s -> %s", spath, tpath);
        tool_lib_error(what, st);
        goto done;
    }
    ret = 0;
done:
    amscr_descriptor_free(ds);
    amscr_descriptor_free(dt);
    return ret;
}

/* The arrays of the report (errors name "register"). */
static int read_arrays(const amscr_result *res, const amscr_params *p, reg_report *r)
{
    amscr_status st = amscr_result_affine(res, r->m);
    size_t np = amscr_result_num_scales(res), nsc = 0, nr = np, nk = np;
    r->np = np;
    r->scales = params_scales(p, &nsc);
    r->resid = xmalloc_array(np ? np : 1, sizeof(double));
    r->kept = xmalloc_array(np ? np : 1, sizeof(int));
    if (st == AMSCR_OK)
        st = amscr_result_sse(res, NULL, &r->nsse);
    r->sse = xcalloc_array(r->nsse ? r->nsse : 1, sizeof(double));
    if (st != AMSCR_OK || r->scales == NULL || r->resid == NULL || r->kept == NULL || r->sse == NULL) {
        if (st != AMSCR_OK)
            tool_lib_error("register", st);
        return -1;
    }
    if (nsc != np) {
        tool_error("register", "the result has %zu scales but the parameters %zu", np, nsc);
        return -1;
    }
    st = amscr_result_residuals(res, r->resid, &nr);
    if (st == AMSCR_OK)
        st = amscr_result_kept(res, r->kept, &nk);
    if (st == AMSCR_OK && r->nsse > 0)
        st = amscr_result_sse(res, r->sse, &r->nsse);
    r->nmix = TOOL_KMAX_MAX;
    if (amscr_result_mixture(res, r->mw, r->mm, r->mv, &r->nmix) != AMSCR_OK)
        r->nmix = 0;
    if (st != AMSCR_OK) {
        tool_lib_error("register", st);
        return -1;
    }
    return 0;
}

/* The stages and the alternatives of the report. */
static int read_stages(const amscr_result *res, reg_report *r)
{
    r->nstages = amscr_result_num_stages(res);
    r->nalt = amscr_result_num_alternatives(res);
    r->stage_name = xmalloc_array(r->nstages ? r->nstages : 1, sizeof *r->stage_name);
    r->stage_ran = xmalloc_array(r->nstages ? r->nstages : 1, sizeof *r->stage_ran);
    r->alt = xmalloc_array(r->nalt ? 6 * r->nalt : 1, sizeof *r->alt);
    r->alt_cost = xmalloc_array(r->nalt ? r->nalt : 1, sizeof *r->alt_cost);
    if (!r->stage_name || !r->stage_ran || !r->alt || !r->alt_cost)
        return -1;
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; i < r->nstages && st == AMSCR_OK; i++)
        st = amscr_result_stage(res, i, &r->stage_name[i], &r->stage_ran[i]);
    for (size_t i = 0; i < r->nalt && st == AMSCR_OK; i++)
        st = amscr_result_alternative(res, i, r->alt + 6 * i, &r->alt_cost[i]);
    if (st != AMSCR_OK) {
        tool_lib_error("register", st);
        return -1;
    }
    return 0;
}

static int read_report(const amscr_result *res, const amscr_params *p, reg_report *r)
{
    if (read_arrays(res, p, r) != 0 || read_stages(res, r) != 0)
        return -1;
    r->dist = amscr_result_distance(res);
    r->thr = amscr_result_threshold(res);
    r->shift = amscr_result_shift(res);
    r->K = amscr_result_k(res);
    r->nkept = amscr_result_num_kept(res);
    r->refl = amscr_result_reflected(res);
    r->mname = name_of(&METHOD_NAMES, (int)amscr_result_method(res));
    r->N = amscr_params_get_num_samples(p);
    r->conf = amscr_result_confidence(res);
    r->amb = amscr_result_ambiguity(res);
    r->inl = amscr_result_inlier_fraction(res);
    r->overlap = amscr_result_overlap(res);
    r->fb = amscr_result_backward_error(res);
    r->se = amscr_result_standard_error(res);
    r->symamb = amscr_result_symmetry_ambiguity(res);
    if (amscr_result_part(res, &r->part[0], &r->part[1]) != AMSCR_OK ||
        amscr_result_correspondences(res, NULL, NULL, NULL, &r->ncorr) != AMSCR_OK)
    {
        tool_lib_error("register", AMSCR_E_INTERNAL);
        return -1;
    }
    r->corr_param = xmalloc_array(r->ncorr ? r->ncorr : 1, sizeof(double));
    r->corr_xy = xmalloc_array(r->ncorr ? 2 * r->ncorr : 1, sizeof(double));
    if (!r->corr_param || !r->corr_xy)
        return -1;
    amscr_status st = amscr_result_correspondences(res, NULL, r->corr_param, r->corr_xy, &r->ncorr);
    if (st != AMSCR_OK) {
        tool_lib_error("register", st);
        return -1;
    }
    return 0;
}

/* --overlay and --plot: neither an input file, and both can be made (checked before the
 * registration, so a failure leaves neither). */
static int pictures_writable(const opts *o)
{
    const char *outs[2][2] = {{"--overlay", o->overlay}, {"--plot", o->plot}};
    for (int i = 0; i < 2; i++)
        if (outs[i][1] && (tool_out_not_input(outs[i][0], outs[i][1], (const char *const *)o->pos, 2) != 0 ||
                           tool_out_probe(outs[i][1]) != 0))
            return -1;
    if (o->overlay && o->plot && strcmp(o->overlay, o->plot) == 0) {
        tool_error(o->plot, "--overlay and --plot name the same file");
        return -1;
    }
    return 0;
}

/* --overlay and --plot, each written (see draw_pictures). */
static int draw_each_picture(const opts *o, const amscr_contour *src, const amscr_contour *tgt, const reg_report *r)
{
    const char *spath = o->pos[0], *tpath = o->pos[1];
    size_t ns = amscr_contour_size(src);
    char d1[32];
    if (o->overlay) {
        double *after = xmalloc_array(2 * ns, sizeof(double));
        if (after == NULL)
            return -1;
        amscr_status st = amscr_affine_apply(r->m, amscr_contour_xy(src), ns, after);
        if (st != AMSCR_OK) {
            tool_lib_error("register", st);
            free(after);
            return -1;
        }
        char cap[200];
        if (o->partial)
            snprintf(cap, sizeof cap, "distance %s, partial: %.3f .. %.3f of the target's boundary%s",
                     fmt_num(d1, r->dist), r->part[0], r->part[1], r->refl ? ", reflected" : "");
        else
            snprintf(cap, sizeof cap, "distance %s, %s, %zu of %zu scales kept%s", fmt_num(d1, r->dist), r->mname,
                     r->nkept, r->np, r->refl ? ", reflected" : "");
        overlay_input ov = {amscr_contour_xy(tgt), amscr_contour_size(tgt), amscr_contour_xy(src), ns, after, ns,
                            !o->open, o->partial, tpath, spath, cap};
        int drawn = draw_overlay(o->overlay, &ov);
        free(after);
        if (drawn != 0)
            return -1;
    }
    if (o->plot) {
        char title[600];
        snprintf(title, sizeof title, "%s -> %s: %s, distance %s", path_base(spath), path_base(tpath), r->mname,
                 fmt_num(d1, r->dist));
        plot_input pi = {r->scales, r->resid, r->kept, r->np, r->thr, r->sse, r->nsse, r->K, title};
        if (draw_plot_svg(o->plot, &pi) != 0)
            return -1;
    }
    return 0;
}

/* --overlay and --plot: drawn before anything is printed, so a failure there comes first; named
 * together once both are written (tool_out_hold), so a failure leaves neither. */
static int draw_pictures(const opts *o, const amscr_contour *src, const amscr_contour *tgt, const reg_report *r)
{
    tool_out_hold();
    int drawn = draw_each_picture(o, src, tgt, r);
    return tool_out_release(drawn == 0) == 0 && drawn == 0 ? 0 : -1;
}

/* Confidence, part and correspondences ({"param": [...], "points": [[x, y], ...]}). */
static void json_confidence(sbuf *b, const opts *o, const reg_report *r)
{
    sb_puts(b, ", \"confidence\": ");
    sb_json_num(b, r->conf);
    sb_puts(b, ", \"ambiguity\": ");
    sb_json_num(b, r->amb);
    sb_puts(b, ", \"inlier_fraction\": ");
    sb_json_num(b, r->inl);
    sb_puts(b, ", \"overlap\": ");
    sb_json_num(b, r->overlap);
    sb_puts(b, ", \"backward_error\": ");
    sb_json_num(b, r->fb);
    sb_puts(b, ", \"symmetry_ambiguity\": ");
    sb_json_num(b, r->symamb);
    sb_puts(b, ", \"standard_error\": ");
    sb_json_num(b, r->se);
    sb_printf(b, ", \"partial\": %s, \"part\": ", o->partial ? "true" : "false");
    sb_json_nums(b, r->part, NULL, 2);
    sb_puts(b, ", \"correspondences\": {\"param\": ");
    sb_json_nums(b, r->corr_param, NULL, r->ncorr);
    sb_puts(b, ", \"points\": [");
    for (size_t a = 0; a < r->ncorr; a++) {
        if (a)
            sb_puts(b, ", ");
        sb_json_nums(b, r->corr_xy + 2 * a, NULL, 2);
    }
    sb_puts(b, "]}");
}

/* A map m6 as "A": [[a11, a12], [a21, a22]], "B": [b1, b2] (after `lead`). */
static void json_map(sbuf *b, const char *lead, const double *m)
{
    double a0[2] = {m[0], m[1]}, a1[2] = {m[3], m[4]}, t[2] = {m[2], m[5]};
    sb_puts(b, lead);
    sb_puts(b, "\"A\": [");
    sb_json_nums(b, a0, NULL, 2);
    sb_puts(b, ", ");
    sb_json_nums(b, a1, NULL, 2);
    sb_puts(b, "], \"B\": ");
    sb_json_nums(b, t, NULL, 2);
}

/* "stages": {name: ran, ...} in pipeline order; "alternatives": [{"A", "B", "cost"}, ...]. */
static void json_stages(sbuf *b, const reg_report *r)
{
    sb_puts(b, ", \"stages\": {");
    for (size_t i = 0; i < r->nstages; i++) {
        sb_puts(b, i ? ", " : "");
        sb_json_str(b, r->stage_name[i]);
        sb_puts(b, r->stage_ran[i] ? ": true" : ": false");
    }
    sb_puts(b, "}, \"alternatives\": [");
    for (size_t i = 0; i < r->nalt; i++) {
        json_map(b, i ? ", {" : "{", r->alt + 6 * i);
        sb_puts(b, ", \"cost\": ");
        sb_json_num(b, r->alt_cost[i]);
        sb_puts(b, "}");
    }
    sb_puts(b, "]");
}

static void format_json(sbuf *b, const opts *o, const amscr_contour *src, const amscr_contour *tgt,
                        const reg_report *r)
{
    const double *m = r->m;
    sb_puts(b, "{\"source\": ");
    sb_json_str(b, o->pos[0]);
    sb_puts(b, ", \"target\": ");
    sb_json_str(b, o->pos[1]);
    json_map(b, ", ", m);
    sb_puts(b, ", \"distance\": ");
    sb_json_num(b, r->dist);
    sb_puts(b, ", \"method\": ");
    sb_json_str(b, r->mname);
    sb_puts(b, ", \"scales\": ");
    sb_json_nums(b, r->scales, NULL, r->np);
    sb_puts(b, ", \"residuals\": "); /* a partial match has no per-scale systems */
    if (o->partial)
        sb_puts(b, "null");
    else
        sb_json_nums(b, r->resid, NULL, r->np);
    sb_puts(b, ", \"kept\": ");
    sb_json_nums(b, r->scales, r->kept, r->np);
    sb_printf(b, ", \"shift\": %zu, \"reflected\": %s, \"k\": %zu, \"threshold\": ", r->shift,
              r->refl ? "true" : "false", r->K);
    sb_json_num(b, r->thr);
    sb_puts(b, ", \"sse\": ");
    sb_json_nums(b, r->sse, NULL, r->nsse);
    const char *mix_keys[3] = {"weights", "means", "variances"};
    const double *mix[3] = {r->mw, r->mm, r->mv};
    for (int i = 0; i < 3; i++) {
        sb_printf(b, "%s\"%s\": ", i ? ", " : ", \"mixture\": {", mix_keys[i]);
        sb_json_nums(b, mix[i], NULL, r->nmix);
    }
    sb_printf(b, "}, \"samples\": %zu, \"closed\": %s, \"source_points\": %zu, \"target_points\": %zu", r->N,
              o->open ? "false" : "true", amscr_contour_size(src), amscr_contour_size(tgt));
    json_confidence(b, o, r);
    json_stages(b, r);
    sb_puts(b, "}\n");
}

/* The scale selection's lines: K, the threshold, the kept scales, the residuals, the shift. */
static void text_scales(sbuf *b, const reg_report *r)
{
    char n1[32], n2[32];
    if (r->K > 0)
        sb_printf(b, "K           %zu (elbow over K = 1..%zu)\n", r->K, r->nsse);
    if (isfinite(r->thr))
        sb_printf(b, "threshold   %s (Bayes)\n", fmt_num(n1, r->thr));
    else
        sb_printf(b, "threshold   none (every scale kept)\n");
    sb_printf(b, "kept        %zu of %zu scales:", r->nkept, r->np);
    for (size_t k = 0; k < r->np; k++)
        if (r->kept[k])
            sb_printf(b, " %s", fmt_num(n1, r->scales[k]));
    sb_puts(b, "\n");
    sb_puts(b, "residuals  ");
    for (size_t k = 0; k < r->np; k++)
        sb_printf(b, " %s:%s%s", fmt_num(n1, r->scales[k]), fmt_num(n2, r->resid[k]), r->kept[k] ? "*" : "");
    sb_puts(b, "   (scale:residual, * = kept)\n");
    sb_printf(b, "shift       %zu (of %zu samples)\n", r->shift, r->N);
}

/* Significant digits for B in the text report: 6, and as many more as B's size over the target's
 * extent needs for its last digit to stay below a millionth of the target (far from the origin,
 * 6 digits of B would move the map by whole units); at most 17, as --json writes. */
static int b_digits(const double m[6], const amscr_contour *tgt)
{
    const double *xy = amscr_contour_xy(tgt);
    size_t n = amscr_contour_size(tgt);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (size_t i = 0; i < 2 * n; i++) {
        lo[i % 2] = fmin(lo[i % 2], xy[i]);
        hi[i % 2] = fmax(hi[i % 2], xy[i]);
    }
    double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]), mag = fmax(fabs(m[2]), fabs(m[5]));
    if (!(ext > 0.0) || !(mag > ext))
        return 6;
    double more = ceil(log10(mag / ext));
    return more >= 11.0 ? 17 : 6 + (int)more;
}

static void format_text(sbuf *b, const opts *o, const amscr_contour *src, const amscr_contour *tgt,
                        const reg_report *r)
{
    const double *m = r->m;
    char n1[32];
    sb_printf(b, "source      %s (%zu points)\n", o->pos[0], amscr_contour_size(src));
    sb_printf(b, "target      %s (%zu points)\n", o->pos[1], amscr_contour_size(tgt));
    if (o->partial)
        sb_printf(b, "method      partial: the open source placed along the closed target (N = %zu samples; "
                     "no scale selection)\n", r->N);
    else
        sb_printf(b, "method      %s (N = %zu samples, %s curves)\n", r->mname, r->N, o->open ? "open" : "closed");
    sb_printf(b, "distance    %s\n", fmt_num(n1, r->dist));
    sb_printf(b, "A           [ %12.6g %12.6g ]\n", m[0], m[1]);
    sb_printf(b, "            [ %12.6g %12.6g ]\n", m[3], m[4]);
    int bd = b_digits(m, tgt);
    sb_printf(b, "B           [ %12.*g %12.*g ]   (target = A * source + B)\n", bd, m[2], bd, m[5]);
    if (!o->partial)
        text_scales(b, r);
    sb_printf(b, "reflected   %s\n", r->refl ? "yes" : "no");
    sb_printf(b, "confidence  %.3f (ambiguity %.3f, inliers %.1f %%", r->conf, r->amb, 100.0 * r->inl);
    if (isfinite(r->overlap))
        sb_printf(b, ", overlap %.1f %%", 100.0 * r->overlap);
    if (isfinite(r->se))
        sb_printf(b, ", standard error %.2f %%", 100.0 * r->se);
    sb_printf(b, ")%s\n", r->conf < 0.25 ? "  LOW: the map may be wrong" : "");
    if (o->partial)
        sb_printf(b, "part        %.4f .. %.4f of the target's boundary\n", r->part[0], r->part[1]);
    if (r->nalt > 1)
        sb_printf(b, "alternatives %zu distinct maps fit about as well (--json: \"alternatives\")\n", r->nalt - 1);
    sb_puts(b, "stages     ");
    for (size_t i = 0; i < r->nstages; i++)
        if (r->stage_ran[i])
            sb_printf(b, " %s", r->stage_name[i]);
    sb_puts(b, "   (the stages that ran)\n");
    if (o->overlay)
        sb_printf(b, "overlay     %s\n", o->overlay);
    if (o->plot)
        sb_printf(b, "plot        %s\n", o->plot);
}

int cmd_register(opts *o)
{
    amscr_params *p = NULL;
    amscr_contour *src = NULL, *tgt = NULL;
    amscr_result *res = NULL;
    reg_report rep;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    memset(&rep, 0, sizeof rep);
    sb_init(&b);

    if (o->partial && o->plot)
        return usage_error("--plot", "a partial registration selects no scales: there is no plot to draw");
    int r = make_params(o, 1, &p);
    if (r != 0)
        return r;
    if (pictures_writable(o) != 0 || register_pair(o, p, &src, &tgt, &res) != 0 || read_report(res, p, &rep) != 0 ||
        draw_pictures(o, src, tgt, &rep) != 0)
        goto done;
    if (o->json)
        format_json(&b, o, src, tgt, &rep);
    else
        format_text(&b, o, src, tgt, &rep);
    if (sb_write_stdout(&b) == 0)
        ret = TOOL_EXIT_OK;
done:
    sb_free(&b);
    report_free(&rep);
    amscr_result_free(res);
    amscr_contour_free(src);
    amscr_contour_free(tgt);
    amscr_params_free(p);
    return ret;
}
