/* polish_rank.c — the starts the polish tries and their ranking (polish.c): the chosen map,
 * and the search's other distinct candidates when it could not tell them apart; the ambiguity
 * among the polished starts; their ranking kept in the match for the alternatives. */
#include "match.h"

#include <math.h>
#include <string.h>

/* The search's other candidates are polished too when its ambiguity is at least this: another
 * start scored within a factor 2 of the chosen one (near-symmetric shapes, where noise decides;
 * measured on the held-out pairs: 0.6-1.0 for those, below 0.35 for every other pair). */
#define AMBIGUOUS_SEARCH 0.5

/* The start maps: the chosen one first, then — when the search could not tell its candidates
 * apart (ambiguity at least AMBIGUOUS_SEARCH) — each candidate that differs from all before.
 * may_win[k]: start k may become the reported map by the ranking's lowest cost (the search's
 * further minima are polished and ranked for the alternatives, and win only when clearly better:
 * AMSCR__HELD_WIN). */
size_t amscr__polish_starts(const amscr_descriptor *f, const match_t *m, double S[][6], int *so, unsigned char *may_win)
{
    size_t count = 1;
    memcpy(S[0], m->X, sizeof S[0]);
    so[0] = m->reflected;
    may_win[0] = 1;
    for (size_t c = 0; m->ambiguity >= AMBIGUOUS_SEARCH && c < m->ncand; c++) {
        int fresh = 1;
        for (int k = 0; k < 6; k++)
            fresh = fresh && isfinite(m->cand[c][k]);
        for (size_t k = 0; k < count && fresh; k++)
            fresh = amscr__map_gap2(f, m->cand[c], S[k]) > AMSCR__DISTINCT_GAP2;
        if (fresh) {
            may_win[count] = c < m->ncand_base;
            so[count] = m->cand_o[c];
            memcpy(S[count++], m->cand[c], sizeof S[0]);
        }
    }
    return count;
}

/* The ambiguity of start `best` among the polished starts S (costs cost): its cost over the
 * best cost of a clearly different map (1: as good; 0: none). */
double amscr__polished_ambiguity(const amscr_descriptor *f, double S[][6], const double *cost, size_t count,
                                 size_t best)
{
    double amb = 0.0;
    for (size_t k = 0; k < count; k++)
        if (k != best && amscr__map_gap2(f, S[k], S[best]) > AMSCR__DISTINCT_GAP2) {
            double r = (cost[best] + AMSCR__AMBIGUITY_FLOOR) / (cost[k] + AMSCR__AMBIGUITY_FLOOR);
            amb = r > amb ? (r > 1.0 ? 1.0 : r) : amb;
        }
    return amb;
}

/* The re-ranked starts as the match's ranking (the alternatives read it); the starts that may
 * win come first (amscr__polish_starts), so they are its lowest minima. */
void amscr__polish_keep_ranking(double S[][6], const int *so, const unsigned char *may_win, const double *cost,
                                size_t count, size_t best, match_t *m)
{
    m->nrank = count;
    m->rank_best = best;
    m->rank_nbase = 0;
    while (m->rank_nbase < count && may_win[m->rank_nbase])
        m->rank_nbase++;
    memcpy(m->rank_X, S, count * sizeof S[0]);
    memcpy(m->rank_o, so, count * sizeof *so);
    memcpy(m->rank_cost, cost, count * sizeof *cost);
}
