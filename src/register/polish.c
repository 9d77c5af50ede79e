/* polish.c — the reported map polished on the input points themselves.
 *
 * The method and its refinement see N resampled samples, and the refinement pairs each source
 * sample with the closest point of the target. Both are right for clean contours; under noise
 * they are not: resampling a noisy polyline keeps its noise but drops most of its points, and
 * the closest point ON a noisy curve is biased (a zig-zag always offers a nearer point than the
 * true curve), so a map fitted source -> noisy target slides along thin parts.
 *
 * If one curve is clean and the other noisy, the maximum-likelihood fit moves the CLEAN curve
 * (its points are the regressors: noisy regressors would shrink the map, as in any
 * errors-in-variables regression) and pairs each point of the NOISY curve with the closest point
 * of the moved clean one (the noise is then only a residual). Which curve is noisier is
 * measured, not assumed: the roughness of each input polyline (median squared second
 * difference). The map is fitted from the smoother curve `a` onto the rougher `b` (for a noisy
 * source that is the inverse map, inverted at the end), point-to-line in both directions — b's
 * points onto the moved a, and the moved a's points onto b — each weighted by the roughness of
 * the curve whose points it pairs, so two clean curves are fitted both ways equally. Each
 * iteration is a Gauss-Newton step over pairs trimmed beyond RESID_K (polish_fit.c) times the median squared
 * distance (missing runs drop out).
 *
 * When the start-point search could not tell its candidates apart, the other distinct
 * candidates are polished alike and ranked by a two-way trimmed cost, so a noisy
 * symmetric-looking shape gets the start the points favour (the search's further minima of a
 * shape with more than three symmetries are polished and ranked too, for the alternatives, and
 * become the reported map only when clearly better, AMSCR__HELD_WIN; where the polished ranking
 * finds an orientation's lowest starts alike and the search did not, the stage asks the search
 * for the further minima it held back and ranks them the same way: amscr__polish_rank_more).
 * When the rougher curve is markedly the noisier, the winner is refined by the order of its
 * points (ordered.c), then by their even spacing where the points bear that out (even.c). Runs
 * on closed curves under affine invariance when the params ask for it (the registration preset
 * does); the reported distance stays the batch path's. This file is the stage; the fit of one start
 * is polish_fit.c, the starts and their ranking polish_rank.c. */
#include "even.h"
#include "match.h"
#include "ordered.h"
#include "polish_fit.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Each start is polished SCORE_ITERS steps and ranked; the winner is polished on to at most
 * POLISH_ITERS steps in all (measured: 6-12 steps typical, a few slow ones on thin shapes). */
#define SCORE_ITERS 2
#define POLISH_ITERS 30
/* The order of the rougher curve's points refines the polished map (ordered.c) when that curve
 * is markedly the noisier — its noise variance at least ORDER_NOISIER times the smoother one's
 * (weight wb >= 0.8) — so that the smoother is a clean model of the curve the points scatter
 * about; never across a gap (a missing run breaks the order's even advance). */
#define ORDER_NOISIER 4.0
/* When one curve is markedly the noisier (ORDER_NOISIER), starts whose ranking costs are within
 * this ratio of the best rank alike, and among them the lowest cost keeping TIE_KEEP of each
 * direction's pairs wins: a near symmetry under noise shows in the pairs the ranking trims
 * (measured on bench/registration_heldout.py --sets, 8 draws: 1 % noise procedural 99.6 -> 100 %,
 * 2 % noise fold A 98.6 -> 99.3 %, nothing lost; 0.75 or a keep of 1.0 the same; without the
 * gate a traced low-resolution pair of a near-symmetric star took a wrong turn). */
#define TIE_RATIO 0.9
#define TIE_KEEP 0.9

/* The polish between its fit and its order and even-spacing steps. */
struct amscr__polish_state {
    polish_t w;
    const amscr_descriptor *f, *h;
    double Y[6];  /* the polished map, a -> b in the curves' frames */
    int reranked; /* the match's ranking is the polish's */
};

/* Every start a few steps, ranked; the index of the best that may win (count when none finished). */
static size_t rank_starts(amscr__polish_state *ps, double S[][6], double Y[][6], double *cost,
                          const unsigned char *may_win, size_t count)
{
    size_t best = count;
    for (size_t k = 0; k < count; k++) {
        amscr__polish_to_frames(&ps->w, ps->f, ps->h, S[k], Y[k]);
        cost[k] = amscr__polish_one(&ps->w, Y[k], SCORE_ITERS);
        amscr__polish_from_frames(&ps->w, ps->f, ps->h, Y[k], S[k]);
        if (may_win[k] && cost[k] < (best < count ? cost[best] : INFINITY))
            best = k;
    }
    size_t held = best; /* a further minimum wins only when clearly better (AMSCR__HELD_WIN) */
    for (size_t k = 0; k < count && best < count; k++)
        if (!may_win[k] && amscr__held_wins(cost[k], cost[best]) && cost[k] < cost[held])
            held = k;
    if (held != best || best == count || !(ps->w.wb >= ORDER_NOISIER * ps->w.wa))
        return held;
    /* one curve markedly the noisier (a noisy point list, as for the order step): of the starts of
     * distinct maps that rank alike (within TIE_RATIO) the one whose less trimmed cost is lowest
     * wins (a near symmetry under noise shows in the pairs the ranking trims) */
    double tb = NAN;
    size_t win = best;
    for (size_t k = 0; k < count; k++) {
        if (k == best || !may_win[k] || !(cost[best] >= TIE_RATIO * cost[k]) ||
            !(amscr__map_gap2(ps->f, S[k], S[best]) > AMSCR__DISTINCT_GAP2))
            continue;
        if (isnan(tb))
            tb = amscr__polish_tie_cost(&ps->w, Y[best], TIE_KEEP);
        double tk = amscr__polish_tie_cost(&ps->w, Y[k], TIE_KEEP);
        if (tk < tb) {
            tb = tk;
            win = k;
        }
    }
    return win;
}

/* Polishes the winner on; returns whether it finished (ps->Y then holds it). */
static int polish_winner(amscr__polish_state *ps, double S[][6], const int *so, const unsigned char *may_win,
                         double Y[][6], const double *cost, size_t count, size_t best, match_t *m)
{
    if (count > 1) {
        m->ambiguity = amscr__polished_ambiguity(ps->f, S, cost, count, best);
        amscr__polish_keep_ranking(S, so, may_win, cost, count, best, m);
        ps->reranked = 1;
    }
    int done = amscr__polish_one(&ps->w, Y[best], POLISH_ITERS - SCORE_ITERS) < INFINITY;
    if (done) {
        memcpy(ps->Y, Y[best], sizeof ps->Y);
        amscr__polish_from_frames(&ps->w, ps->f, ps->h, Y[best], S[best]);
    }
    memcpy(m->X, S[best], sizeof m->X);
    return done;
}

void amscr__polish_end(amscr__polish_state *ps)
{
    if (!ps)
        return;
    amscr__polish_free(&ps->w);
    free(ps);
}

amscr_status amscr__polish_fit(const amscr_descriptor *f, const amscr_descriptor *h, int partial, match_t *m,
                               amscr__polish_state **out)
{
    *out = NULL;
    amscr__polish_state *ps = calloc(1, sizeof *ps);
    if (!ps)
        return amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory");
    amscr_status st = amscr__polish_alloc(f->nraw, h->nraw, &ps->w);
    if (st != AMSCR_OK) {
        free(ps);
        return st;
    }
    ps->f = f;
    ps->h = h;
    double S[1 + 2 * AMSCR__CANDIDATES_MAX][6], Y[1 + 2 * AMSCR__CANDIDATES_MAX][6],
        cost[1 + 2 * AMSCR__CANDIDATES_MAX];
    unsigned char may_win[1 + 2 * AMSCR__CANDIDATES_MAX];
    int so[1 + 2 * AMSCR__CANDIDATES_MAX];
    size_t count = amscr__polish_starts(f, m, S, so, may_win), best = count;
    int ready = amscr__polish_prepare(&ps->w, f, h, m->X, partial);
    if (ready > 0)
        best = rank_starts(ps, S, Y, cost, may_win, count);
    if (ready < 0 || ps->w.nomem) {
        amscr__polish_end(ps);
        return amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory");
    }
    int done = best < count && polish_winner(ps, S, so, may_win, Y, cost, count, best, m);
    if (ps->w.nomem) {
        amscr__polish_end(ps);
        return amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory");
    }
    if (done)
        *out = ps;
    else
        amscr__polish_end(ps);
    return AMSCR_OK;
}

int amscr__polish_reranked(const amscr__polish_state *ps) { return ps && ps->reranked; }

amscr_status amscr__polish_rank_more(amscr__polish_state *ps, double X[][6], size_t n, int o, match_t *m)
{
    size_t best = m->rank_best;
    for (size_t i = 0; i < n && m->nrank < 1 + 2 * AMSCR__CANDIDATES_MAX; i++) {
        int fresh = 1;
        for (int k = 0; k < 6; k++)
            fresh = fresh && isfinite(X[i][k]);
        for (size_t k = 0; k < m->nrank && fresh; k++)
            fresh = amscr__map_gap2(ps->f, X[i], m->rank_X[k]) > AMSCR__DISTINCT_GAP2;
        if (!fresh)
            continue;
        double Y[6], *S = m->rank_X[m->nrank];
        amscr__polish_to_frames(&ps->w, ps->f, ps->h, X[i], Y);
        double cost = amscr__polish_one(&ps->w, Y, SCORE_ITERS);
        amscr__polish_from_frames(&ps->w, ps->f, ps->h, Y, S);
        m->rank_o[m->nrank] = o;
        m->rank_cost[m->nrank++] = cost;
        /* amscr__polished_ambiguity's term */
        if (amscr__map_gap2(ps->f, S, m->rank_X[best]) > AMSCR__DISTINCT_GAP2) {
            double r = (m->rank_cost[best] + AMSCR__AMBIGUITY_FLOOR) / (cost + AMSCR__AMBIGUITY_FLOOR);
            m->ambiguity = r > m->ambiguity ? (r > 1.0 ? 1.0 : r) : m->ambiguity;
        }
        if (amscr__held_wins(cost, m->rank_cost[best]) &&
            amscr__polish_one(&ps->w, Y, POLISH_ITERS - SCORE_ITERS) < INFINITY) { /* clearly better: it wins */
            best = m->nrank - 1;
            memcpy(ps->Y, Y, sizeof ps->Y);
            amscr__polish_from_frames(&ps->w, ps->f, ps->h, Y, S);
            memcpy(m->X, S, sizeof m->X);
            m->reflected = o;
        }
    }
    if (best != m->rank_best) {
        m->rank_best = best;
        m->ambiguity = amscr__polished_ambiguity(ps->f, m->rank_X, m->rank_cost, m->nrank, best);
    }
    return ps->w.nomem ? amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory") : AMSCR_OK;
}

int amscr__polish_steps_apply(const amscr__polish_state *ps)
{
    const polish_t *w = &ps->w;
    return !w->partial && w->wb >= ORDER_NOISIER * w->wa && !amscr__polish_has_gap(w->a) &&
           !amscr__polish_has_gap(w->b);
}

amscr_status amscr__polish_order(amscr__polish_state *ps, match_t *m)
{
    const polish_t *w = &ps->w;
    if (amscr__ordered_fit(w->a->p, w->a->n, w->b->p, w->b->n, w->b->rough, ps->Y) < 0)
        return amscr__fail(AMSCR_E_NOMEM, "registration polish (order): out of memory");
    amscr__polish_from_frames(w, ps->f, ps->h, ps->Y, m->X);
    return AMSCR_OK;
}

amscr_status amscr__polish_even(amscr__polish_state *ps, match_t *m)
{
    const polish_t *w = &ps->w;
    if (amscr__even_fit(w->a->p, w->a->n, w->b->p, w->b->n, w->b->rough, ps->Y) < 0)
        return amscr__fail(AMSCR_E_NOMEM, "registration polish (even spacing): out of memory");
    amscr__polish_from_frames(w, ps->f, ps->h, ps->Y, m->X);
    return AMSCR_OK;
}
