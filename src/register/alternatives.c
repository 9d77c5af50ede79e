/* alternatives.c — the distinct maps that fit about as well as the chosen one (symmetric shapes:
 * a square's quarter turns, a triangle's thirds), so that a caller can choose among them.
 *
 * They come from the last ranking of distinct starts the registration made: the start-point
 * search's (every candidate after a short refinement, scored by its trimmed closest-point cost)
 * or, when the polish re-ranked the starts (the search was ambiguous), the polish's (each start
 * polished a few steps, scored by the two-way trimmed cost). Within one ranking the costs
 * compare. Entry 0 is always the reported map (amscr_result_affine) with its ranking cost (NaN
 * when the registration ranked no starts — no refinement, partial matching — or when the
 * recovery moved the map away from the ranked winner: the ranking no longer describes it). Another ranked map
 * is listed when it is distinct — it differs from the chosen start and from every map listed
 * before by more than the ambiguity's AMSCR__DISTINCT_GAP2 (an RMS displacement of 10 % of the
 * normalized frame's RMS radius) — and about as good: (chosen cost + floor) / (its cost +
 * floor) >= AMSCR__ALT_RATIO, the ratio amscr_result_ambiguity takes the largest of. So a
 * listed alternative means an ambiguity >= 0.75 and a confidence <= 0.25. Each alternative's
 * map is as its ranking left it (a few refinement or polish steps). */
#include "match.h"

#include <math.h>
#include <string.h>

/* X (normalized frames f -> h) in input coordinates: inv_h o X o fwd_f. */
static void to_input(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6], double out[6])
{
    double t[6];
    amscr__affine_compose(X, f->fwd, t);
    amscr__affine_compose(h->inv, t, out);
}

static int finite6(const double X[6])
{
    for (int k = 0; k < 6; k++)
        if (!isfinite(X[k]))
            return 0;
    return 1;
}

/* The ranked maps' indices by ascending cost (ties: ranking order). */
static void by_cost(const match_t *m, size_t *idx)
{
    for (size_t i = 0; i < m->nrank; i++) {
        size_t j = i;
        while (j > 0 && m->rank_cost[idx[j - 1]] > m->rank_cost[i]) {
            idx[j] = idx[j - 1];
            j--;
        }
        idx[j] = i;
    }
}

/* Whether ranked map k is distinct from the chosen start and from the maps listed (norm). */
static int distinct(const amscr_descriptor *f, const match_t *m, size_t k, double norm[][6], size_t count)
{
    if (!finite6(m->rank_X[k]) || !(amscr__map_gap2(f, m->rank_X[k], m->rank_X[m->rank_best]) > AMSCR__DISTINCT_GAP2))
        return 0;
    for (size_t j = 1; j < count; j++)
        if (!(amscr__map_gap2(f, m->rank_X[k], norm[j]) > AMSCR__DISTINCT_GAP2))
            return 0;
    return 1;
}

void amscr__alternatives(const amscr_descriptor *f, const amscr_descriptor *h, amscr_result *r)
{
    const match_t *m = &r->m;
    double norm[AMSCR__MAX_ALTERNATIVES][6];
    size_t idx[AMSCR__MAX_ALTERNATIVES];
    /* a later stage (the recovery) that moved the map off the ranked start leaves a ranking that
     * no longer describes it */
    int ranked = m->nrank && amscr__map_gap2(f, m->X, m->rank_X[m->rank_best]) <= AMSCR__DISTINCT_GAP2;
    to_input(f, h, m->X, r->alt[0]);
    r->alt_cost[0] = ranked ? m->rank_cost[m->rank_best] : NAN;
    r->nalt = 1;
    if (!ranked)
        return;
    by_cost(m, idx);
    double best = r->alt_cost[0] + AMSCR__AMBIGUITY_FLOOR;
    for (size_t i = 0; i < m->nrank; i++) {
        size_t k = idx[i];
        double cost = m->rank_cost[k];
        if (k == m->rank_best || !(best / (cost + AMSCR__AMBIGUITY_FLOOR) >= AMSCR__ALT_RATIO))
            continue;
        if (!distinct(f, m, k, norm, r->nalt))
            continue;
        memcpy(norm[r->nalt], m->rank_X[k], sizeof norm[0]);
        to_input(f, h, m->rank_X[k], r->alt[r->nalt]);
        r->alt_cost[r->nalt++] = cost;
    }
}
