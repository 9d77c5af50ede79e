/* The register area (src/register/): the registration engine, matching one prepared shape onto
 * another. match.h is its internal header and names every stage file in pipeline order
 * (docs/method.md §12); this file holds the public entry points.
 *
 * register.c — matching a prepared source onto a prepared target (docs/method.md §3, §9), top-down:
 *   amscr_register    checks the pair, runs the stage table (stages.c: despike, search, method,
 *                     recovery, final solve, symmetric, polish, order, even spacing,
 *                     alternatives, correspondences, pixel_grid) on the pair, a small pixel
 *                     chain (target, or source onto a target traced from an image) replaced
 *                     by the image it bounds traced at sub-pixel (pixel_chain.c),
 *                     registers a small binary image's target (or source) again when the
 *                     pixel_grid stage's condition held (pixel_grid.c), checks the result (check.c) and
 *                     fills the result's maps;
 *   amscr_distance    checks the pair, then match_pair: one direction f -> h by
 *                     amscr__match_dir (shift_search.c: candidate start points ranked by one
 *                     rule, the winner through the method and the refinement) and, symmetric,
 *                     h -> f.
 * The distance of the batch path (amscr_distance) is the method's closed form; amscr_register
 * reports the QR solve; tests check they agree. */
#include "match.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static amscr_status check_partial(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt);
static amscr_status check_pair(const amscr_params **prm, const amscr_descriptor *src, const amscr_descriptor *tgt);
static amscr_status match_pair(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                               amscr_workspace *ws, match_t *m);
static amscr_status again_on_pixel_grid(const amscr_params *prm, const amscr_descriptor *src,
                                        const amscr_descriptor *tgt, amscr_workspace *ws, amscr_result *r);
static amscr_status chain_images(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                 amscr_workspace *ws, amscr_descriptor *g[2]);

amscr_status amscr_register(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                            amscr_workspace *ws, amscr_result **out_result)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_result);
    amscr_status st = check_pair(&p, src, tgt);
    if (st != AMSCR_OK)
        return st;
    amscr_descriptor *g[2] = {NULL, NULL}; /* pixel chains' images traced at sub-pixel (pixel_chain.c) */
    amscr_workspace local = {0};
    amscr_workspace *w = ws ? ws : &local;
    amscr_result *r = calloc(1, sizeof *r);
    if (!r)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_register: out of memory");
    if (st == AMSCR_OK)
        st = chain_images(p, src, tgt, w, g);
    const amscr_descriptor *f = g[0] ? g[0] : src, *h = g[1] ? g[1] : tgt;
    if (st == AMSCR_OK)
        st = amscr__run_stages(p, f, h, w, r);
    if (st == AMSCR_OK && r->ran[AMSCR__STAGE_PIXEL_GRID]) /* a small binary image (pixel_grid.c) */
        st = again_on_pixel_grid(p, f, h, w, r);
    if (st == AMSCR_OK) /* how far the result can be trusted: its overlap and checks (check.c) */
        st = amscr__check(p, f, h, w, r);
    if (!ws)
        amscr__ws_release(&local);
    if (st == AMSCR_OK) {
        r->method = p->method;
        memcpy(r->affine_norm, r->m.X, sizeof r->affine_norm);
        /* input coordinates: inv_h ∘ X ∘ fwd_f */
        double t[6];
        amscr__affine_compose(r->m.X, f->fwd, t);
        amscr__affine_compose(h->inv, t, r->affine_in);
        *out_result = r;
    } else {
        amscr_result_free(r);
    }
    amscr_descriptor_free(g[0]);
    amscr_descriptor_free(g[1]);
    return st;
}

/* Whether a source given as a pixel chain is traced again: with the target (target: its
 * condition held), or, small itself (its RMS radius within the grid's limit), onto a target traced
 * from an image too (a pixel chain or a binary image's sub-pixel tracing, of any size); a target
 * made from the chain's own points (a warped copy) keeps the chain as given. */
static int source_retraced(const amscr_descriptor *src, const amscr_descriptor *tgt, int target)
{
    if (!amscr__is_pixel_chain(src))
        return 0;
    return target || ((amscr__is_pixel_chain(tgt) || amscr__on_pixel_lattice(tgt)) &&
                      amscr__grid_small(src->raw, src->nraw));
}

/* Pixel chains traced again (pixel_chain.c), with the pixel_grid stage on: a target given as a
 * small pixel chain, the source under the search's map as small (the stage's condition), is
 * replaced by the image the chain bounds traced at sub-pixel (g[1]); a source given as a pixel
 * chain too where source_retraced says (g[0]). Else, or where the search fails or an image cannot
 * be traced again, g NULL: the pair as given. */
static amscr_status chain_images(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                 amscr_workspace *ws, amscr_descriptor *g[2])
{
    g[0] = g[1] = NULL;
    if (prm->partial || !prm->polish || !AMSCR__STAGE_ON(prm, AMSCR__STAGE_POLISH) ||
        !AMSCR__STAGE_ON(prm, AMSCR__STAGE_PIXEL_GRID) || !src->raw)
        return AMSCR_OK;
    amscr_status st = AMSCR_OK;
    int target = 0; /* the target's condition held */
    if (amscr__is_pixel_chain(tgt) && amscr__grid_small(tgt->raw, tgt->nraw)) {
        match_t m;
        st = amscr__match_dir(prm, src, tgt, ws, &m);
        target = st == AMSCR_OK && amscr__grid_mapped_small(src, tgt, m.X);
    }
    if (st == AMSCR_OK && target)
        st = amscr__chain_retrace(tgt, &g[1]);
    if (st == AMSCR_OK && source_retraced(src, tgt, target))
        st = amscr__chain_retrace(src, &g[0]);
    if (st == AMSCR_OK)
        return st;
    for (int k = 0; k < 2; k++) {
        amscr_descriptor_free(g[k]);
        g[k] = NULL;
    }
    if (st != AMSCR_E_NOMEM) {
        st = AMSCR_OK;
        amscr__clear_error();
    }
    return st;
}

amscr_status amscr_distance(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                            amscr_workspace *ws, double *out_distance)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_distance);
    amscr_status st = check_pair(&p, src, tgt);
    if (st != AMSCR_OK)
        return st;
    amscr_workspace local = {0};
    amscr_workspace *w = ws ? ws : &local;
    st = amscr__distance_ws(p, src, tgt, w, out_distance);
    if (!ws)
        amscr__ws_release(&local);
    return st;
}

amscr_status amscr__distance_ws(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                amscr_workspace *ws, double *out)
{
    match_t m;
    amscr_status st = match_pair(prm, src, tgt, ws, &m);
    if (st == AMSCR_OK)
        *out = m.dist;
    return st;
}

/* The pixel_grid stage (docs/method.md §11.7): the pair registered again with its small binary
 * image's side (pixel_grid.c says which) corrected for its tracing's bias, through the same stages
 * (r2->backward: no standard error, and no pixel_grid stage of its own), and the map that matches
 * that image better kept in r. A registration that fails there leaves r as it was: no evidence to
 * change the map by. */
static amscr_status again_on_pixel_grid(const amscr_params *prm, const amscr_descriptor *src,
                                        const amscr_descriptor *tgt, amscr_workspace *ws, amscr_result *r)
{
    amscr_descriptor *d2 = NULL;
    amscr_result *r2 = NULL;
    size_t first_differ = 0;
    int side = amscr__pixel_grid_side(src, tgt, r->m.X);
    amscr_status st = amscr__grid_correct(src, tgt, r, side, &d2, &first_differ);
    if (st == AMSCR_OK && d2) {
        r2 = calloc(1, sizeof *r2);
        st = r2 ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    }
    if (r2) {
        r2->backward = 1;
        int source = side == AMSCR__GRID_SOURCE;
        st = amscr__run_stages(prm, source ? d2 : src, source ? tgt : d2, ws, r2);
        if (st == AMSCR_OK)
            st = amscr__grid_choose(prm, src, tgt, d2, side, first_differ, r, r2);
        else if (st != AMSCR_E_NOMEM) {
            st = AMSCR_OK;
            amscr__clear_error();
        }
    }
    amscr_result_free(r2);
    amscr_descriptor_free(d2);
    return st;
}

/* Partial matching: an open source and a closed target, otherwise compatible. */
static amscr_status check_partial(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt)
{
    if (src->params.closed || !tgt->params.closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "partial registration: the source must be prepared open and the "
                                                "target closed (source %s, target %s)",
                           src->params.closed ? "closed" : "open", tgt->params.closed ? "closed" : "open");
    amscr_params a = src->params, b = tgt->params, c = *prm;
    a.closed = b.closed = c.closed = 1;
    if (!amscr__params_compatible(&a, &b, "partial registration (source vs target)") ||
        !amscr__params_compatible(&c, &a, "partial registration (params vs descriptors)"))
        return AMSCR_E_INVALID_ARG;
    return AMSCR_OK;
}

/* Null params: the source's. Both descriptors and the params must describe compatible shapes. */
static amscr_status check_pair(const amscr_params **prm, const amscr_descriptor *src, const amscr_descriptor *tgt)
{
    if (!*prm)
        *prm = &src->params;
    if ((*prm)->partial)
        return check_partial(*prm, src, tgt);
    if (!amscr__params_compatible(&src->params, &tgt->params, "registration (source vs target)"))
        return AMSCR_E_INVALID_ARG;
    if (!amscr__params_compatible(*prm, &src->params, "registration (params vs descriptors)"))
        return AMSCR_E_INVALID_ARG;
    return AMSCR_OK;
}

/* The distance of src -> tgt (the batch path): the search and the method (partial: the
 * fragment's placement); symmetric: the mean of both directions'. amscr_register runs the whole
 * stage table instead (stages.c). */
static amscr_status match_pair(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                               amscr_workspace *ws, match_t *m)
{
    if (prm->partial)
        return amscr__match_partial(prm, src, tgt, ws, m);
    amscr_status st = amscr__match_dir(prm, src, tgt, ws, m);
    if (st == AMSCR_OK && prm->symmetric) {
        match_t back;
        st = amscr__match_dir(prm, tgt, src, ws, &back);
        if (st == AMSCR_OK)
            m->dist = 0.5 * (m->dist + back.dist);
    }
    return st;
}

amscr_status amscr_register_contours(const amscr_params *p, const amscr_contour *src, const amscr_contour *tgt,
                                     amscr_result **out_result)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_result);
    amscr_descriptor *a = NULL, *b = NULL;
    char detail[400];
    amscr_params preset;
    if (!p) {
        amscr__params_registration(&preset);
        p = &preset;
    }
    amscr_params ps = *p, pt = *p; /* partial: the source open, the target closed */
    if (p->partial) {
        ps.closed = 0;
        pt.closed = 1;
    }
    amscr_status st = amscr_descriptor_new(&ps, src, &a);
    if (st == AMSCR_OK) {
        st = amscr_descriptor_new(&pt, tgt, &b);
        if (st != AMSCR_OK) {
            snprintf(detail, sizeof detail, "%s", amscr_last_error_detail());
            amscr__fail(st, "target: %s", detail);
        }
    } else {
        snprintf(detail, sizeof detail, "%s", amscr_last_error_detail());
        amscr__fail(st, "source: %s", detail);
    }
    if (st == AMSCR_OK)
        st = amscr_register(p, a, b, NULL, out_result);
    amscr_descriptor_free(a);
    amscr_descriptor_free(b);
    return st;
}
