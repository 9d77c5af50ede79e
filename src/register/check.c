/* check.c — how far a finished registration can be trusted, by construction (docs/method.md
 * §11.5): besides the ambiguity (alternatives.c) and the inlier fraction (correspond.c),
 *   the overlap   the intersection over union of the two closed contours as regions, the
 *                 source's under the map and the target's, computed from the polygons alone;
 *   a symmetry    when less than AMSCR__SYM_SHARE of the shape agrees, the source's own
 *                 symmetries (the source registered onto itself) composed with the map and
 *                 refined on the target: the ambiguity near a symmetry;
 *   the way back  when less than AMSCR__CHECK_SHARE agrees, the target registered onto the
 *                 source on its own: the two maps must compose to the identity. Their
 *                 forward-backward error is the RMS displacement of the source samples under
 *                 the composition, in units of the source's RMS radius (normalized frames).
 * The confidence combines them (amscr__confidence, result.c). None of it changes the map; it
 * runs once the stages have finished a result (register.c), never for the check's own
 * registrations. */
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Horizontal lines the overlap integrates over (the midpoint rule on equal strips of the union's
 * height): the error is about 1e-3 of the area for 256-sample contours. A resolution, not a
 * constant chosen on data. */
#define AMSCR__OVERLAP_LINES 256

static double covered(const double *xs, size_t c)
{
    double s = 0.0;
    for (size_t k = 0; k < c; k += 2)
        s += xs[k + 1] - xs[k];
    return s;
}

/* Length of the intersection of two sorted interval lists (pairs of crossings). */
static double common(const double *a, size_t na, const double *b, size_t nb)
{
    double s = 0.0;
    size_t i = 0, j = 0;
    while (i < na && j < nb) {
        double lo = fmax(a[i], b[j]), hi = fmin(a[i + 1], b[j + 1]);
        if (hi > lo)
            s += hi - lo;
        if (a[i + 1] < b[j + 1])
            i += 2;
        else
            j += 2;
    }
    return s;
}

amscr_status amscr__overlap(const double *P, size_t n, const double *Q, size_t m, double *out)
{
    double *xs = amscr__malloc_array(n + m, sizeof *xs);
    if (!xs)
        return amscr__fail(AMSCR_E_NOMEM, "overlap: out of memory");
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++)
        lo = fmin(lo, P[2 * i + 1]), hi = fmax(hi, P[2 * i + 1]);
    for (size_t i = 0; i < m; i++)
        lo = fmin(lo, Q[2 * i + 1]), hi = fmax(hi, Q[2 * i + 1]);
    double inter = 0.0, uni = 0.0, dy = (hi - lo) / AMSCR__OVERLAP_LINES;
    for (int k = 0; k < AMSCR__OVERLAP_LINES && dy > 0.0; k++) {
        double y = lo + (k + 0.5) * dy;
        size_t na = amscr__crossings(P, n, y, xs), nb = amscr__crossings(Q, m, y, xs + n);
        double c = common(xs, na, xs + n, nb);
        inter += c;
        uni += covered(xs, na) + covered(xs + n, nb) - c;
    }
    free(xs);
    *out = uni > 0.0 && isfinite(uni) ? inter / uni : 0.0;
    return AMSCR_OK;
}

/* The overlap of r's map: the source samples mapped into the target's normalized frame. */
static amscr_status map_overlap(const amscr_descriptor *f, const amscr_descriptor *h, amscr_result *r)
{
    const double *X = r->m.X;
    double *P = amscr__malloc_array(2 * f->n, sizeof *P);
    if (!P)
        return amscr__fail(AMSCR_E_NOMEM, "overlap: out of memory");
    for (size_t a = 0; a < f->n; a++) {
        double x = f->base[2 * a], y = f->base[2 * a + 1];
        P[2 * a] = X[0] * x + X[1] * y + X[2];
        P[2 * a + 1] = X[3] * x + X[4] * y + X[5];
    }
    amscr_status st = amscr__overlap(P, f->n, h->base, h->n, &r->overlap);
    free(P);
    return st;
}

/* The source's own distinct turns: the source registered onto itself ranks its candidate
 * turns, each refined to convergence (S[1..], cost[1..]; S[0] the identity). Returns how many
 * in all (1: none), or 0 with the status in *st. */
static size_t self_turns(const amscr_params *prm, const amscr_descriptor *f, amscr_workspace *ws, double S[][6],
                         double *cost, amscr_status *st)
{
    amscr_result *s = calloc(1, sizeof *s);
    amscr_params self = *prm; /* the source onto itself: a clean pair, the polish has nothing to add */
    self.polish = 0;
    *st = s ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "symmetric ambiguity: out of memory");
    if (*st == AMSCR_OK) {
        s->backward = 1;
        *st = amscr__run_stages(&self, f, f, ws, s);
    }
    const double I[6] = {1, 0, 0, 0, 1, 0};
    size_t n = 1;
    memcpy(S[0], I, sizeof S[0]);
    for (size_t k = 0; *st == AMSCR_OK && k < s->m.nrank && n <= AMSCR__MAX_ALTERNATIVES; k++)
        if (amscr__map_gap2(f, s->m.rank_X[k], I) > AMSCR__DISTINCT_GAP2)
            memcpy(S[n++], s->m.rank_X[k], sizeof S[0]);
    if (*st == AMSCR_OK)
        *st = amscr__rank_converged(prm, f, f, S + 1, n - 1, cost + 1);
    amscr_result_free(s);
    return *st == AMSCR_OK ? n : 0;
}

/* The ambiguity near a symmetry of the source, from its own distinct turns S[1..n-1] and their
 * costs onto itself: each that, converged, maps the source onto itself about as well as the
 * identity (within the ambiguity's floor: a symmetry) gives the alternative X o S, refined on
 * the target in turn; the ambiguity is the largest ratio of costs, as the search's. When part of
 * the target is missing, the ranking's few refinement steps can leave such a turn far from its
 * minimum, where converged it fits exactly as well (a 4-armed cross with an arm cut: every
 * quarter turn). Every other turn is tried on the target too: one that, converged there, fits it
 * clearly better than the map itself (amscr__held_wins) shows that the map is not the best fit
 * of a near-symmetric source: ambiguity 1. */
static amscr_status turns_on_target(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                    double S[][6], const double *self_cost, size_t n, amscr_result *r)
{
    const double I[6] = {1, 0, 0, 0, 1, 0};
    double T[AMSCR__MAX_ALTERNATIVES + 1][6], cost[AMSCR__MAX_ALTERNATIVES + 1];
    unsigned char symmetry[AMSCR__MAX_ALTERNATIVES + 1];
    size_t nt = 1;
    memcpy(T[0], r->m.X, sizeof T[0]);
    for (size_t k = 1; k < n; k++)
        if (amscr__map_gap2(f, S[k], I) > AMSCR__DISTINCT_GAP2) {
            symmetry[nt] = AMSCR__AMBIGUITY_FLOOR / (self_cost[k] + AMSCR__AMBIGUITY_FLOOR) >= AMSCR__ALT_RATIO;
            amscr__affine_compose(r->m.X, S[k], T[nt++]);
        }
    amscr_status st = nt > 1 ? amscr__rank_converged(prm, f, h, T, nt, cost) : AMSCR_OK;
    double amb = 0.0;
    for (size_t k = 1; st == AMSCR_OK && k < nt; k++) {
        if (!(amscr__map_gap2(f, T[k], T[0]) > AMSCR__DISTINCT_GAP2))
            continue;
        double q = (cost[0] + AMSCR__AMBIGUITY_FLOOR) / (cost[k] + AMSCR__AMBIGUITY_FLOOR);
        if (!symmetry[k])
            q = amscr__held_wins(cost[k], cost[0]) ? 1.0 : 0.0;
        amb = q > amb ? (q > 1.0 ? 1.0 : q) : amb;
    }
    if (st == AMSCR_OK)
        r->amb_conv = amb;
    return st;
}

/* The ambiguity near a symmetry of the source (r->amb_conv; left NaN when either registration
 * fails: no evidence either way). */
static amscr_status symmetric_ambiguity(const amscr_params *prm, const amscr_descriptor *f,
                                        const amscr_descriptor *h, amscr_workspace *ws, amscr_result *r)
{
    double (*S)[6] = amscr__malloc_array(AMSCR__MAX_ALTERNATIVES + 1, sizeof *S);
    double *cost = amscr__malloc_array(AMSCR__MAX_ALTERNATIVES + 1, sizeof *cost);
    amscr_status st = S && cost ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "symmetric ambiguity: out of memory");
    size_t n = st == AMSCR_OK ? self_turns(prm, f, ws, S, cost, &st) : 0;
    if (st == AMSCR_OK)
        st = turns_on_target(prm, f, h, S, cost, n, r);
    if (st != AMSCR_OK && st != AMSCR_E_NOMEM) {
        st = AMSCR_OK; /* no evidence either way */
        amscr__clear_error();
    }
    free(S);
    free(cost);
    return st;
}

amscr_status amscr__check(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                          amscr_workspace *ws, amscr_result *r)
{
    r->fb = NAN;
    r->overlap = NAN;
    r->amb_conv = NAN;
    if (prm->partial || !f->params.closed || !h->params.closed)
        return AMSCR_OK;
    amscr_status st = map_overlap(f, h, r);
    if (st != AMSCR_OK)
        return st;
    /* the dearer evidence only where the cheap one leaves doubt: a map confident without it whose
     * boundary or region agree over less than AMSCR__SYM_SHARE (the symmetry test; a clean
     * registration of the source onto itself) or AMSCR__CHECK_SHARE (the way back: a
     * registration of the damaged target) of the shape */
    double share = r->overlap < r->inlier ? r->overlap : r->inlier;
    if (amscr__confidence(r) >= AMSCR__CONFIDENT && share < AMSCR__SYM_SHARE) {
        st = symmetric_ambiguity(prm, f, h, ws, r);
        if (st != AMSCR_OK)
            return st;
    }
    if (!(amscr__confidence(r) >= AMSCR__CONFIDENT && share < AMSCR__CHECK_SHARE))
        return AMSCR_OK;
    amscr_result *b = calloc(1, sizeof *b);
    if (!b)
        return amscr__fail(AMSCR_E_NOMEM, "forward-backward check: out of memory");
    b->backward = 1;
    st = amscr__run_stages(prm, h, f, ws, b);
    if (st == AMSCR_OK) {
        double C[6], I[6] = {1, 0, 0, 0, 1, 0};
        amscr__affine_compose(b->m.X, r->m.X, C); /* f -> h -> f */
        r->fb = sqrt(amscr__map_gap2(f, C, I) / 2.0); /* the normalized frame's RMS radius is sqrt 2 */
    } else if (st != AMSCR_E_NOMEM) {
        st = AMSCR_OK; /* the way back failed where the way there did not: no evidence either way */
        amscr__clear_error();
    }
    amscr_result_free(b);
    return st;
}
