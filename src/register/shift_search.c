/* shift_search.c — the start point of a match f -> h (docs/method.md §3, §9): which cyclic shift of
 * the target (closed curves) and which orientation the method starts from.
 *
 * For closed curves the 2x2 cross-correlation R(s) = Σ_a h(a+s) f(a)^T over all N cyclic shifts
 * comes from one FFT product (the reversed target is the conjugate spectrum); circular
 * smoothing of both curves at σ_k multiplies its spectrum by |G_k|^2, so the stacked
 * least-squares residual of every shift costs O(N log N) per pair (the search criterion). The
 * lowest few local minima of that criterion per orientation are the candidates, each refined to
 * a continuous shift: the lowest AMSCR__CANDIDATES and, in the ranked search (refinement on),
 * when those are distinct maps that all score about as well as the winner (a shape with three
 * or more symmetries), every further local minimum, up to AMSCR__CANDIDATES_MAX — so that each
 * symmetry of a square or a regular star is ranked (the geometry judges it, not the criterion,
 * which reads an imperfect symmetry's shift far worse than its map fits) and listed as an
 * alternative. The further minima of an orientation whose lowest ones did not score alike here
 * are held as integer shifts: the polish, whose ranking judges them anew, asks for them when it
 * finds them alike (amscr__search_held). Open curves have one candidate per orientation (no
 * shift).
 *
 * One ranking rule picks the winner: the lowest score, ties broken by the lower distance, then
 * by the earlier candidate (orientations in order, each one's candidates best criterion first);
 * the further minima are scored and ranked alike (the alternatives, the ambiguity) and win only
 * when clearly better (AMSCR__HELD_WIN: below 0.9x the best score).
 * The score is the cheapest quantity that judges the start point (see score_start). The winner
 * gets the whole method and the refinement.
 */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <string.h>

/* Criterion ranking only: a candidate is refined only when its residual is within this factor
 * of the best one's — refinement to a continuous shift moves the residual far less than that. */
#define AMSCR__PRUNE_RATIO 1.25
/* With refinement on, each candidate is scored after at most this many closest-point steps
 * (the winner then gets all of them). */
#define AMSCR__SCORE_REFINE 2

/* The search criterion: minus the explained part of the stacked smoothed least-squares
 * problem, -tr(C S^-1 C^T) with C = Σ_k R_k(s) (2x2) and S = Σ_k S_k over all scales (or the
 * finest scale for acma). Minimizing it over s minimizes that least-squares residual. */
static void crit_matrix(const amscr_descriptor *f, int use_finest, int sim, double Sinv[4])
{
    double Sxx = 0, Sxy = 0, Syy = 0;
    if (use_finest) {
        const double *mo = f->mom + 6 * (f->finest + 1);
        Sxx = mo[0];
        Sxy = mo[1];
        Syy = mo[2];
    } else {
        for (size_t k = 0; k < f->p; k++) {
            const double *mo = f->mom + 6 * (k + 1);
            Sxx += mo[0];
            Sxy += mo[1];
            Syy += mo[2];
        }
    }
    double det = Sxx * Syy - Sxy * Sxy;
    Sinv[0] = Syy / det;
    Sinv[1] = -Sxy / det;
    Sinv[2] = Sxx / det;
    Sinv[3] = 0.0;
    if (sim) { /* similarity: the explained part is ((Cxx + Cyy)^2 + (Cyx - Cxy)^2) / tr S */
        Sinv[0] = 1.0 / (Sxx + Syy);
        Sinv[3] = 1.0;
    }
}

static inline double crit_value(const double C[4], const double Si[4])
{
    if (Si[3] != 0.0) {
        double u = C[0] + C[3], v = C[2] - C[1];
        return -(u * u + v * v) * Si[0];
    }
    /* tr(C Si C^T) = Σ_i c_i^T Si c_i over the rows c_i of C */
    double t = 0.0;
    for (int i = 0; i < 2; i++) {
        double x = C[2 * i], y = C[2 * i + 1];
        t += x * (Si[0] * x + Si[1] * y) + y * (Si[1] * x + Si[2] * y);
    }
    return -t;
}

/* The criterion and its first two derivatives in s in one spectral pass:
 * d/ds Re(P e^{iks}) = -k Im(P e^{iks}), d2/ds2 = -k^2 Re(P e^{iks}), k = 2πw/N. */
static void crit_newton(const amscr_descriptor *f, int use_finest, const double Si[4], amscr_workspace *ws, double s,
                        double *val, double *d1, double *d2)
{
    size_t n = f->n, half = n / 2 + 1;
    const double *gain = use_finest ? f->gain + f->finest * n : f->gain + f->p * n;
    double base = 2.0 * AMSCR__PI / (double)n, th = base * s;
    double cs = cos(th), sn = sin(th), er = 1.0, ei = 0.0;
    double C[4] = {0, 0, 0, 0}, D[4] = {0, 0, 0, 0}, E[4] = {0, 0, 0, 0};
    for (size_t w = 0; w < half; w++) {
        if ((w & AMSCR__REANCHOR) == 0 && w > 0) {
            er = cos(th * (double)w);
            ei = sin(th * (double)w);
        }
        double g = (w == 0 || 2 * w == n) ? gain[w] : 2.0 * gain[w];
        double k = base * (double)w;
        const double *P = ws->P + 8 * w;
        for (int j = 0; j < 4; j++) {
            double re = P[2 * j] * er - P[2 * j + 1] * ei, im = P[2 * j] * ei + P[2 * j + 1] * er;
            C[j] += g * re;
            D[j] -= g * k * im;
            E[j] -= g * k * k * re;
        }
        double t = er * cs - ei * sn;
        ei = er * sn + ei * cs;
        er = t;
    }
    double inv_n = 1.0 / (double)n;
    for (int j = 0; j < 4; j++) {
        C[j] *= inv_n;
        D[j] *= inv_n;
        E[j] *= inv_n;
    }
    if (Si[3] != 0.0) { /* similarity: crit = -(u^2 + v^2) / tr S */
        double u = C[0] + C[3], v = C[2] - C[1], du = D[0] + D[3], dv = D[2] - D[1], eu = E[0] + E[3],
               ev = E[2] - E[1];
        *val = -(u * u + v * v) * Si[0];
        *d1 = -2.0 * (u * du + v * dv) * Si[0];
        *d2 = -2.0 * (du * du + u * eu + dv * dv + v * ev) * Si[0];
        return;
    }
    /* crit = -tr(C Si C^T); crit' = -2 tr(D Si C^T); crit'' = -2 [tr(E Si C^T) + tr(D Si D^T)] */
    double t1 = 0, t2 = 0, t3 = 0;
    for (int i = 0; i < 2; i++) {
        double cx = C[2 * i], cy = C[2 * i + 1], dx = D[2 * i], dy = D[2 * i + 1], ex = E[2 * i], ey = E[2 * i + 1];
        double scx = Si[0] * cx + Si[1] * cy, scy = Si[1] * cx + Si[2] * cy;
        t1 += dx * scx + dy * scy;
        t2 += ex * scx + ey * scy;
        t3 += dx * (Si[0] * dx + Si[1] * dy) + dy * (Si[1] * dx + Si[2] * dy);
    }
    *val = crit_value(C, Si);
    *d1 = -2.0 * t1;
    *d2 = -2.0 * (t2 + t3);
}

/* Newton on the shift: an integer local minimum's basin is one sample wide, so a step stays
 * within half a sample; two passes reach well below a sample from the parabola's vertex; a
 * step under a thousandth of a sample has converged. */
#define AMSCR__SHIFT_MAX_STEP 0.5
#define AMSCR__SHIFT_PASSES 2
#define AMSCR__SHIFT_TOL 1e-3

/* Refinement of an integer shift s (a local minimum of the criterion) to a continuous one
 * by Newton's method with exact derivatives (at most two passes, steps within ±0.5; the last
 * step is taken with its quadratic prediction of the criterion, which only ranks candidates —
 * the distance is computed exactly afterwards). */
static double refine_shift(const amscr_descriptor *f, int use_finest, const double Si[4], amscr_workspace *ws,
                           size_t s, double *out_crit)
{
    size_t n = f->n;
    double x = (double)s, best_x = x, best_v = ws->crit[s];
    /* start: the vertex of the parabola through the integer neighbours (free: from the FFT) */
    double cm = ws->crit[(s + n - 1) % n], cp = ws->crit[(s + 1) % n], curv = cp - 2.0 * best_v + cm;
    if (curv > 0.0) {
        double step = -0.5 * (cp - cm) / curv;
        x += step > AMSCR__SHIFT_MAX_STEP ? AMSCR__SHIFT_MAX_STEP
                                          : (step < -AMSCR__SHIFT_MAX_STEP ? -AMSCR__SHIFT_MAX_STEP : step);
    }
    for (int it = 0; it < AMSCR__SHIFT_PASSES; it++) {
        double v, d1, d2;
        crit_newton(f, use_finest, Si, ws, x, &v, &d1, &d2);
        if (v <= best_v) {
            best_v = v;
            best_x = x;
        } else if (it > 0) {
            break; /* the last step went uphill: keep the best point */
        } else {
            x = best_x; /* the parabola overshot: restart Newton from the integer shift */
            crit_newton(f, use_finest, Si, ws, x, &v, &d1, &d2);
        }
        if (!(d2 > 0.0))
            break;
        double step = -d1 / d2;
        if (step > AMSCR__SHIFT_MAX_STEP)
            step = AMSCR__SHIFT_MAX_STEP;
        if (step < -AMSCR__SHIFT_MAX_STEP)
            step = -AMSCR__SHIFT_MAX_STEP;
        x += step;
        if (fabs(step) < AMSCR__SHIFT_TOL) { /* converged to well below a sample: take the step as is */
            best_v = v + 0.5 * d1 * step;
            best_x = x;
            break;
        }
        if (it == AMSCR__SHIFT_PASSES - 1) { /* no pass left: accept the Newton prediction only if lower */
            double pred = v + d1 * step + 0.5 * d2 * step * step;
            if (pred < best_v) {
                best_v = pred;
                best_x = x;
            }
        }
    }
    *out_crit = best_v;
    return best_x;
}

/* Criterion of every integer cyclic shift for one orientation (closed curves): one FFT
 * product and two complex inverse FFTs (x and y rows packed as real + imaginary parts); also
 * leaves the spectral products of this orientation in ws->P. */
static void shift_criterion(const amscr_descriptor *f, const amscr_descriptor *h, int o, int use_finest,
                            const double Si[4], amscr_workspace *ws)
{
    size_t n = f->n;
    amscr__spectral_prepare(f, h, o, ws);
    const double *gain = use_finest ? f->gain + f->finest * n : f->gain + f->p * n;
    double *z1 = ws->z, *z2 = ws->z + 2 * n;
    for (size_t w = 0; w < n; w++) {
        size_t wf = w <= n / 2 ? w : n - w;
        double cj = w <= n / 2 ? 1.0 : -1.0; /* Hermitian completion */
        const double *P = ws->P + 8 * wf;
        double g = gain[w];
        /* z = (P_ix + i P_iy) g */
        z1[2 * w] = g * (P[0] - cj * P[3]);
        z1[2 * w + 1] = g * (cj * P[1] + P[2]);
        z2[2 * w] = g * (P[4] - cj * P[7]);
        z2[2 * w + 1] = g * (cj * P[5] + P[6]);
    }
    amscr__fft(&ws->plan, z1, 1);
    amscr__fft(&ws->plan, z2, 1);
    double inv_n = 1.0 / (double)n;
    for (size_t s = 0; s < n; s++) {
        double C[4] = {z1[2 * s] * inv_n, z1[2 * s + 1] * inv_n, z2[2 * s] * inv_n, z2[2 * s + 1] * inv_n};
        ws->crit[s] = crit_value(C, Si);
    }
}

/* The lowest (at most cap) circular local minima of ws->crit, ascending (ties: lower shift first). */
static size_t integer_candidates(const amscr_workspace *ws, size_t n, size_t cap, size_t *cand)
{
    size_t nc = 0;
    for (size_t s = 0; s < n; s++) {
        double v = ws->crit[s];
        double l = ws->crit[(s + n - 1) % n], r = ws->crit[(s + 1) % n];
        if (!(v <= l && v <= r))
            continue;
        size_t pos = nc;
        while (pos > 0 && ws->crit[cand[pos - 1]] > v)
            pos--;
        if (pos >= cap)
            continue;
        size_t last = nc < cap ? nc : cap - 1;
        for (size_t j = last; j > pos; j--)
            cand[j] = cand[j - 1];
        cand[pos] = s;
        if (nc < cap)
            nc++;
    }
    if (nc == 0) { /* flat criterion: take shift 0 */
        cand[0] = 0;
        nc = 1;
    }
    return nc;
}

/* One start point: orientation, continuous shift (closed curves) and the shift criterion. */
typedef struct {
    int o;
    double s;
} start_t;

/* The candidates of f -> h, in ranking order of ties (orientation, then criterion). Closed
 * curves: per orientation the lowest AMSCR__CANDIDATES local minima of the criterion refined to
 * a continuous shift; `prune` drops those far above the orientation's best (criterion ranking).
 * Without `prune` (the ranked search) each orientation's further minima, up to
 * AMSCR__CANDIDATES_MAX in all, lowest first, are held in s as integer shifts: the symmetries of
 * a shape with more than three, refined and ranked only when the orientation's lowest minima
 * score alike (score_held). On return ws->P holds orientation `norient - 1`'s spectra; crit[i]
 * is candidate i's criterion. */
static size_t collect_starts(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                             int prune, amscr_workspace *ws, start_t *out, double *crit, amscr__search *s)
{
    int norient = prm->reflections ? 2 : 1, use_finest = prm->method == AMSCR_METHOD_ACMA;
    size_t n = f->n, count = 0;
    s->nheld = 0;
    if (!f->params.closed) {
        for (int o = 0; o < norient; o++) {
            out[count].o = o;
            out[count].s = 0.0;
            crit[count++] = 0.0;
        }
        return count;
    }
    double Si[4];
    crit_matrix(f, use_finest, prm->invariance != AMSCR_INVARIANCE_AFFINE, Si);
    /* The residual is Σ_k |h_k|^2 + criterion; Σ_k |h_k|^2 is bounded by p |h|^2. The pruning
     * test allows a rounding-sized 1e-12 of it so that equal residuals always stay in. */
    double hk2 = (use_finest ? 1.0 : (double)f->p) * h->norm2;
    size_t cap = prune ? AMSCR__CANDIDATES : AMSCR__CANDIDATES_MAX;
    for (int o = 0; o < norient; o++) {
        shift_criterion(f, h, o, use_finest, Si, ws);
        size_t cand[AMSCR__CANDIDATES_MAX];
        size_t nc = integer_candidates(ws, n, cap, cand);
        double r0 = ws->crit[cand[0]] + hk2;
        for (size_t c = 0; c < nc && c < AMSCR__CANDIDATES; c++) {
            if (prune && c > 0 && ws->crit[cand[c]] + hk2 > AMSCR__PRUNE_RATIO * r0 + 1e-12 * hk2)
                break;
            out[count].o = o;
            out[count].s = refine_shift(f, use_finest, Si, ws, cand[c], &crit[count]);
            count++;
        }
        for (size_t c = AMSCR__CANDIDATES; c < nc; c++) {
            s->held_i[s->nheld] = cand[c];
            s->held_o[s->nheld++] = o;
        }
    }
    return count;
}

/* The ways to score a start point, cheapest first. */
typedef enum {
    SCORE_CRITERION, /* closed, no refinement: the refined shift criterion (the batch path) */
    SCORE_METHOD,    /* open curves: no criterion, two starts at most; the method's distance */
    SCORE_GEOMETRY   /* closed with refinement: the trimmed closest-point cost after a short
                        refinement — a wrong start caused by a missing part of a contour is caught by
                        the geometry rather than by the criterion alone */
} score_kind;

/* Runs the method (and the refinement) at start st into m, with ws->P prepared for it. */
static amscr_status run_start(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              const start_t *st, int *prepared_o, unsigned iters, amscr_workspace *ws, match_t *m)
{
    if (f->params.closed && *prepared_o != st->o) {
        amscr__spectral_prepare(f, h, st->o, ws);
        *prepared_o = st->o;
    }
    amscr__run_method(prm, f, h, st->s, st->o, ws, m);
    return amscr__refine_match(prm, f, h, ws, m, iters);
}

/* Ambiguity: the chosen candidate's score over the best score of a clearly different candidate
 * map (1: as good; 0: none, or far worse). */
static double ambiguity_of(const amscr_descriptor *f, const double X[][6], const double *score, size_t count, size_t best)
{
    double amb = 0.0;
    for (size_t i = 0; i < count; i++) {
        if (i == best || !(amscr__map_gap2(f, X[i], X[best]) > AMSCR__DISTINCT_GAP2))
            continue;
        double r = (score[best] + AMSCR__AMBIGUITY_FLOOR) / (score[i] + AMSCR__AMBIGUITY_FLOOR);
        if (r > amb)
            amb = r > 1.0 ? 1.0 : r;
    }
    return amb;
}

/* Candidates from..s->count-1 scored (the cheap kinds need no run of the method) into s; the
 * winner by the one ranking rule among the first s->nbase (the further minima are ranked for the
 * alternatives and the ambiguity, and win only when clearly better: amscr__held_wins). */
static amscr_status score_starts(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                 const double *crit, size_t from, amscr_workspace *ws, amscr__search *s)
{
    for (size_t i = from; i < s->count; i++) {
        double score = crit[i], dist = crit[i];
        if (s->kind != SCORE_CRITERION) {
            match_t cur;
            unsigned iters = prm->refine < AMSCR__SCORE_REFINE ? prm->refine : AMSCR__SCORE_REFINE;
            start_t st0 = {s->o[i], s->s[i]};
            amscr_status st = run_start(prm, f, h, &st0, &s->prepared_o, s->kind == SCORE_GEOMETRY ? iters : 0, ws,
                                        &cur);
            if (st != AMSCR_OK)
                return st;
            score = s->kind == SCORE_GEOMETRY ? cur.rcost : cur.dist;
            dist = cur.dist;
            memcpy(s->X[i], cur.X, sizeof s->X[i]);
        }
        s->score[i] = score;
        s->dist[i] = dist;
        /* the one ranking rule: lower score, then lower distance, then the earlier candidate */
        double bs = s->score[s->best], bd = s->dist[s->best];
        if (i == 0 || (i < s->nbase && (score < bs || (score == bs && dist < bd))) ||
            (i >= s->nbase && amscr__held_wins(score, bs)))
            s->best = i;
    }
    return AMSCR_OK;
}

int amscr__held_wins(double cost, double best)
{
    return cost < AMSCR__HELD_WIN * best;
}

/* The held further minima of orientation o refined to a continuous shift (its criterion
 * computed again: ws->crit holds the last orientation's, and ws->P may hold anything after the
 * search) and scored into s after its other candidates; they are no longer held. */
static amscr_status score_held(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                               amscr_workspace *ws, amscr__search *s, int o)
{
    int use_finest = prm->method == AMSCR_METHOD_ACMA, ready = 0;
    double Si[4], crit[2 * AMSCR__CANDIDATES_MAX];
    size_t from = s->count, kept = 0;
    crit_matrix(f, use_finest, prm->invariance != AMSCR_INVARIANCE_AFFINE, Si);
    for (size_t i = 0; i < s->nheld; i++) {
        if (s->held_o[i] != o) {
            s->held_i[kept] = s->held_i[i];
            s->held_o[kept++] = s->held_o[i];
            continue;
        }
        if (!ready) {
            shift_criterion(f, h, o, use_finest, Si, ws);
            s->prepared_o = o;
            ready = 1;
        }
        s->o[s->count] = o;
        s->s[s->count] = refine_shift(f, use_finest, Si, ws, s->held_i[i], &crit[s->count]);
        s->count++;
    }
    s->nheld = kept;
    return score_starts(prm, f, h, crit, from, ws, s);
}

int amscr__lowest_alike(const amscr_descriptor *f, double X[][6], const int *ro, const double *cost, size_t nbase,
                        size_t best, int o)
{
    double c0 = cost[best] + AMSCR__AMBIGUITY_FLOOR;
    size_t k = 0;
    for (size_t i = 0; i < nbase; i++) {
        if (ro[i] != o)
            continue;
        if (!(c0 / (cost[i] + AMSCR__AMBIGUITY_FLOOR) >= AMSCR__ALT_RATIO))
            return 0;
        for (size_t j = 0; j < i; j++)
            if (ro[j] == o && !(amscr__map_gap2(f, X[i], X[j]) > AMSCR__DISTINCT_GAP2))
                return 0;
        k++;
    }
    return k == AMSCR__CANDIDATES;
}

amscr_status amscr__search_starts(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                  amscr_workspace *ws, amscr__search *s)
{
    amscr_status st = amscr__ws_reserve(ws, f->n, f->p);
    if (st != AMSCR_OK)
        return st;
    s->kind = !f->params.closed ? SCORE_METHOD : prm->refine > 0 ? SCORE_GEOMETRY : SCORE_CRITERION;
    start_t starts[2 * AMSCR__CANDIDATES];
    double crit[2 * AMSCR__CANDIDATES];
    STAGE_T0;
    size_t nbase = collect_starts(prm, f, h, s->kind == SCORE_CRITERION, ws, starts, crit, s);
    for (size_t i = 0; i < nbase; i++) {
        s->s[i] = starts[i].s;
        s->o[i] = starts[i].o;
    }
    s->count = s->nbase = nbase;
    s->prepared_o = (prm->reflections ? 2 : 1) - 1;
    s->best = 0;
    st = score_starts(prm, f, h, crit, 0, ws, s);
    for (int o = 0; o < 2 && st == AMSCR_OK && s->nheld; o++) /* the further minima of a symmetric shape */
        if (amscr__lowest_alike(f, s->X, s->o, s->score, s->nbase, s->best, o))
            st = score_held(prm, f, h, ws, s, o);
    STAGE_MARK(ws, 0);
    return st;
}

/* The search's ranking into m: its distinct maps for the polish and the alternatives. */
static void keep_ranking(const amscr_descriptor *f, const amscr__search *s, match_t *m)
{
    int ranked = s->kind != SCORE_CRITERION;
    m->ambiguity = ranked ? ambiguity_of(f, s->X, s->score, s->count, s->best) : 0.0;
    m->ncand = ranked ? s->count : 0; /* further starts for polish.c */
    m->ncand_base = ranked ? s->nbase : 0;
    m->nrank = m->ncand;
    m->rank_best = s->best;
    m->rank_nbase = m->ncand_base;
    if (!m->ncand)
        return;
    memcpy(m->cand, s->X, s->count * sizeof s->X[0]);
    memcpy(m->cand_o, s->o, s->count * sizeof s->o[0]);
    memcpy(m->rank_X, s->X, s->count * sizeof s->X[0]);
    memcpy(m->rank_o, s->o, s->count * sizeof s->o[0]);
    memcpy(m->rank_cost, s->score, s->count * sizeof s->score[0]);
}

amscr_status amscr__method_at(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, amscr__search *s, match_t *m)
{
    start_t win = {s->o[s->best], s->s[s->best]};
    amscr_status st = run_start(prm, f, h, &win, &s->prepared_o, prm->refine, ws, m);
    if (st != AMSCR_OK)
        return st;
    keep_ranking(f, s, m);
    if (!isfinite(m->dist))
        return amscr__fail(AMSCR_E_NUMERIC, "registration: non-finite distance");
    return AMSCR_OK;
}

amscr_status amscr__search_held(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                amscr_workspace *ws, amscr__search *s, int o, double X[][6], size_t *out_n)
{
    size_t from = s->count;
    amscr_status st = score_held(prm, f, h, ws, s, o);
    *out_n = st == AMSCR_OK ? s->count - from : 0;
    if (*out_n)
        memcpy(X, s->X + from, *out_n * sizeof X[0]);
    return st;
}

amscr_status amscr__match_dir(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, match_t *m)
{
    amscr__search s;
    amscr_status st = amscr__search_starts(prm, f, h, ws, &s);
    return st == AMSCR_OK ? amscr__method_at(prm, f, h, ws, &s, m) : st;
}
