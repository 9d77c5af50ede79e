/* stages.c — the stage table of amscr_register (docs/method.md §12): every stage's function and
 * when it runs, in pipeline order (the names: base/stage_names.c). The runner calls each stage whose condition
 * holds, records that it ran (amscr_result_stage) and stops at the first status that is not
 * AMSCR_OK, which it returns unchanged (an allocation failure anywhere reaches the caller as
 * AMSCR_E_NOMEM). The batch path (amscr_distance, register.c) runs search, method and the
 * symmetric way back only.
 *
 * Switchable stages (amscr_params_set_stage) are the optional ones: despike, recovery, polish,
 * order, even_spacing, pixel_grid. The despike runs when a shape is prepared
 * (amscr_descriptor_new); its entry records that it did for either shape. The pixel_grid stage
 * registers the pair again: register.c runs it once the table has finished, when its entry here
 * records that its condition held. */
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* What the stages share: the pair, the result they fill and the state passed on between them. */
typedef struct {
    const amscr_params *prm;
    const amscr_descriptor *f, *h;
    amscr_workspace *ws;
    amscr_result *r;
    amscr__search search;     /* the search's candidates, for the method */
    amscr__polish_state *pol; /* the polish's state, for its order and even-spacing steps */
} stage_ctx;

/* A stage's function and condition; its name and whether it is switchable are in
 * base/stage_names.c, under the same index. */
typedef struct {
    amscr_status (*run)(stage_ctx *c); /* NULL: its work runs outside the table (despike: when a
                                          shape is prepared; pixel_grid: register.c, once the table
                                          has finished, as it registers the pair again) */
    int (*when)(const stage_ctx *c);
} stage_t;

static int affine(const stage_ctx *c) { return c->prm->invariance == AMSCR_INVARIANCE_AFFINE; }
static int is_on(const stage_ctx *c, int i) { return AMSCR__STAGE_ON(c->prm, i); }

/* ---- conditions ---- */
static int despiked(const amscr_descriptor *d)
{
    return d->params.polish && AMSCR__STAGE_ON(&d->params, AMSCR__STAGE_DESPIKE);
}
static int when_despike(const stage_ctx *c) { return despiked(c->f) || despiked(c->h); }
static int always(const stage_ctx *c) { return c != NULL; }
static int when_recovery(const stage_ctx *c)
{
    return !c->prm->partial && affine(c) && c->f->params.closed && is_on(c, AMSCR__STAGE_RECOVERY) &&
           amscr__recover_applies(c->f, c->h, c->ws, &c->r->m);
}
/* The reported QR solve: affine invariance, and every partial match (its pairs' affine fit). */
static int when_final(const stage_ctx *c) { return affine(c) || c->prm->partial; }
static int when_symmetric(const stage_ctx *c) { return c->prm->symmetric && !c->prm->partial; }
static int when_polish(const stage_ctx *c)
{
    const amscr_descriptor *f = c->f, *h = c->h;
    return c->prm->polish && is_on(c, AMSCR__STAGE_POLISH) && f->raw && h->raw && h->params.closed &&
           (c->prm->partial || f->params.closed) && affine(c);
}
static int when_order(const stage_ctx *c)
{
    return c->pol && is_on(c, AMSCR__STAGE_ORDER) && amscr__polish_steps_apply(c->pol);
}
static int when_even(const stage_ctx *c)
{
    return c->pol && is_on(c, AMSCR__STAGE_EVEN) && amscr__polish_steps_apply(c->pol);
}
/* A closed pair under affine invariance whose input points the polish kept, the target's or the
 * source's on the pixel lattice of a small binary image (pixel_grid.c); never within a check's or
 * this stage's own registrations. */
static int when_pixel_grid(const stage_ctx *c)
{
    return !c->r->backward && c->r->ran[AMSCR__STAGE_POLISH] && !c->prm->partial &&
           is_on(c, AMSCR__STAGE_PIXEL_GRID) && amscr__pixel_grid_side(c->f, c->h, c->r->m.X) != 0;
}

/* ---- stages ---- */
/* The start-point search (partial: the fragment's placement, refined). */
static amscr_status run_search(stage_ctx *c)
{
    if (c->prm->partial)
        return amscr__match_partial(c->prm, c->f, c->h, c->ws, &c->r->m);
    return amscr__search_starts(c->prm, c->f, c->h, c->ws, &c->search);
}
/* The method and its refinement at the chosen start (partial: the adaptive refinement). */
static amscr_status run_method(stage_ctx *c)
{
    if (c->prm->partial)
        return amscr__refine_adaptive(c->prm, c->f, c->h, c->ws, &c->r->m);
    return amscr__method_at(c->prm, c->f, c->h, c->ws, &c->search, &c->r->m);
}
static amscr_status run_recovery(stage_ctx *c) { return amscr__recover_missing(c->prm, c->f, c->h, c->ws, &c->r->m); }
static amscr_status run_final(stage_ctx *c) { return amscr__final_solve(c->prm, c->f, c->h, c->ws, &c->r->m); }
/* The distance of a symmetric match: the mean of both directions' (the reported map stays). */
static amscr_status run_symmetric(stage_ctx *c)
{
    match_t back;
    amscr_status st = amscr__match_dir(c->prm, c->h, c->f, c->ws, &back);
    if (st == AMSCR_OK)
        c->r->m.dist = 0.5 * (c->r->m.dist + back.dist);
    return st;
}
/* The polish's ranking judges anew whether an orientation's lowest minima are alike (a shape with
 * three or more symmetries): where it finds them alike and the search did not, the further
 * minima the search held back are ranked too, so that each symmetry is listed. */
static amscr_status rank_held(stage_ctx *c)
{
    match_t *m = &c->r->m;
    for (int o = 0; o < 2; o++) {
        double X[2 * AMSCR__CANDIDATES_MAX][6];
        size_t n = 0;
        if (!amscr__lowest_alike(c->f, m->rank_X, m->rank_o, m->rank_cost, m->rank_nbase, m->rank_best, o))
            continue;
        amscr_status st = amscr__search_held(c->prm, c->f, c->h, c->ws, &c->search, o, X, &n);
        if (st != AMSCR_OK)
            return st;
        st = amscr__polish_rank_more(c->pol, X, n, o, m);
        if (st != AMSCR_OK)
            return st;
    }
    return AMSCR_OK;
}
static amscr_status run_polish(stage_ctx *c)
{
    amscr_status st = amscr__polish_fit(c->f, c->h, c->prm->partial, &c->r->m, &c->pol);
    if (st != AMSCR_OK || c->prm->partial || !amscr__polish_reranked(c->pol) || !c->search.nheld)
        return st;
    return rank_held(c);
}
static amscr_status run_order(stage_ctx *c) { return amscr__polish_order(c->pol, &c->r->m); }
static amscr_status run_even(stage_ctx *c) { return amscr__polish_even(c->pol, &c->r->m); }
static amscr_status run_alternatives(stage_ctx *c)
{
    amscr__alternatives(c->f, c->h, c->r);
    return AMSCR_OK;
}
static amscr_status run_correspond(stage_ctx *c) { return amscr__correspond(c->prm, c->f, c->h, c->r); }

/* The pipeline, in order (indexed by AMSCR__STAGE_*). */
static const stage_t STAGES[AMSCR__NUM_STAGES] = {
    [AMSCR__STAGE_DESPIKE] = {NULL, when_despike},
    [AMSCR__STAGE_SEARCH] = {run_search, always},
    [AMSCR__STAGE_METHOD] = {run_method, always},
    [AMSCR__STAGE_RECOVERY] = {run_recovery, when_recovery},
    [AMSCR__STAGE_FINAL_SOLVE] = {run_final, when_final},
    [AMSCR__STAGE_SYMMETRIC] = {run_symmetric, when_symmetric},
    [AMSCR__STAGE_POLISH] = {run_polish, when_polish},
    [AMSCR__STAGE_ORDER] = {run_order, when_order},
    [AMSCR__STAGE_EVEN] = {run_even, when_even},
    [AMSCR__STAGE_ALTERNATIVES] = {run_alternatives, always},
    [AMSCR__STAGE_CORRESPOND] = {run_correspond, always},
    [AMSCR__STAGE_PIXEL_GRID] = {NULL, when_pixel_grid},
};

amscr_status amscr__run_stages(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                               amscr_workspace *ws, amscr_result *r)
{
    stage_ctx c;
    memset(&c, 0, sizeof c);
    c.prm = prm, c.f = src, c.h = tgt, c.ws = ws, c.r = r;
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; i < AMSCR__NUM_STAGES && st == AMSCR_OK; i++) {
        if (!STAGES[i].when(&c))
            continue;
        r->ran[i] = 1;
        if (STAGES[i].run)
            st = STAGES[i].run(&c);
    }
    amscr__polish_end(c.pol);
    return st;
}
