/* recover.c — registration when part of the target's boundary is missing.
 *
 * The method's one-to-one correspondence of whole curves assumes both boundaries complete. When a
 * run of the target is missing (occlusion, a broken trace), the target's parametrization is
 * distorted everywhere and the refinement may start outside the right basin. The source then
 * sees more than the target — but a fragment of the source that avoids the missing run IS an
 * open fragment of the target's boundary, which partial matching (partial.c) places without
 * any whole-curve correspondence. So, when the reported map leaves too many source samples
 * without a target boundary near them (the inlier share below AMSCR__RECOVER_INLIERS):
 *   1. RECOVER_FRAGS fragments of the source (RECOVER_SHARE of its boundary each, starts
 *      evenly spaced: one of them avoids any missing run up to 1 - RECOVER_SHARE - 1/RECOVER_FRAGS
 *      of the boundary) are placed on the target by partial matching, those the reported
 *      map's outliers touch least first;
 *   2. each placement's map, and the reported one, is refined on the whole source by trimmed
 *      closest points whose cut adapts to the residuals (RECOVER_TRIM_K times their median:
 *      a fixed share would keep part of a missing run); the first partners come from a grid
 *      over the target's dense vertices;
 *   2b. as soon as two of these refined maps agree (RECOVER_AGREE), one of them the best so far
 *      by the cost of 3., no further fragment is placed (placements: ~60 % of the stage's time);
 *      after an ambiguous whole-curve search (RECOVER_AMBIGUOUS) two fragments must agree;
 *   3. the candidates are ranked by a two-way trimmed cost — source samples to the target and
 *      target samples to the mapped source — so a map that collapses the source onto a piece
 *      of the target (low one-way cost) loses to one that covers the target.
 * The winner's closest-point pairs are left in ws->rbuf for the reported QR solve. */
#include "dense.h"
#include "match.h"
#include "nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Below this share of source samples within the inlier distance the map is re-examined. */
#define RECOVER_INLIERS 0.95
/* The inlier distance: 5 % of the target's RMS radius (sqrt 2 in the normalized frame), as
 * correspond.c's inlier fraction. */
#define RECOVER_INLIER_DIST (0.05 * 1.4142135623730951)
/* Source fragments tried and their share of the boundary. */
#define RECOVER_FRAGS 5
#define RECOVER_SHARE 0.6
/* A fragment of 60 % of the source covers at least about as much of a target that lacks a part;
 * its share of the target's affine length is searched from 2/3 of that (measured: 20 % missing
 * 95.7 % from the partial default 0.2, 98.6 % from 0.35 or 0.45). */
#define RECOVER_PHI_MIN (RECOVER_SHARE * 2.0 / 3.0)
/* Adaptive trimming: pairs within RECOVER_TRIM_K times the median squared residual (a 3x
 * distance), never fewer than half of them. */
#define RECOVER_TRIM_K 9.0
#define RECOVER_TRIM_MIN 0.5
#define RECOVER_ITERS 30
/* Partners after the first step are searched within ±RECOVER_HINT samples of the last. */
#define RECOVER_HINT 3
/* When a fragment's refined map lands within this RMS displacement (2 % of the RMS radius, sqrt 2
 * in the normalized frame) of the refined reported map or of an earlier fragment's, two
 * independent estimates agree and the remaining fragments are not tried (the fragments are
 * tried fewest-outliers first, so the first is the likeliest to avoid the missing run). */
#define RECOVER_AGREE (0.02 * 1.4142135623730951)
/* ... but the reported map counts only when the whole-curve search was not ambiguous (ambiguity
 * below this): on a symmetric shape it may be a wrong turn that the first fragment, fitting
 * equally well, agrees with (measured: a 12-fold star with 10 % missing stopped on one that a
 * later fragment beats); two fragments must then agree. */
#define RECOVER_AMBIGUOUS 0.5
/* Share of the samples each direction of the ranking cost keeps. */
#define RECOVER_RANK_KEEP 0.7

/* Scratch of one refinement/ranking at n samples (doubles). */
typedef struct {
    double *q, *r2, *sorted, *seg, *Hd, *P;
    size_t nd;
    amscr__grid grid; /* over Hd's vertices: the global search's first guess */
} scratch_t;

/* Closest target points of X f (global search when `global`, else around seg), the adaptive
 * cut; returns the sum of the kept squared residuals over the kept count. */
static double pairs(const amscr_descriptor *f, scratch_t *s, const double X[6], int global, double *cut)
{
    size_t n = f->n;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1], qx, qy;
        double px = X[0] * fx + X[1] * fy + X[2], py = X[3] * fx + X[4] * fy + X[5];
        size_t b0 = (size_t)s->seg[a], seg = 0;
        if (global) { /* the nearest dense vertex, then its neighbouring edges (as the local step) */
            double d2;
            b0 = amscr__grid_nearest(&s->grid, s->Hd, px, py, &d2);
        }
        s->r2[a] = amscr__closest_on_polygon(s->Hd, s->nd, 1, b0, RECOVER_HINT * AMSCR__DENSE, px, py, &qx, &qy,
                                             &seg);
        s->q[2 * a] = qx;
        s->q[2 * a + 1] = qy;
        s->seg[a] = (double)seg;
        s->sorted[a] = s->r2[a];
    }
    size_t half = n / 2, lo = (size_t)(RECOVER_TRIM_MIN * (double)n);
    amscr__select_kth(s->sorted, n, half);
    double c = RECOVER_TRIM_K * s->sorted[half];
    amscr__select_kth(s->sorted, n, lo);
    if (c < s->sorted[lo])
        c = s->sorted[lo];
    double sum = 0.0;
    size_t kept = 0;
    for (size_t a = 0; a < n; a++)
        if (s->r2[a] <= c) {
            sum += s->r2[a];
            kept++;
        }
    *cut = c;
    return sum / (double)kept;
}

/* Adaptive trimmed closest-point refinement of X on the whole source; leaves the final pairs in
 * s. Returns the final cut. */
static double refine_adaptive(const amscr_params *prm, const amscr_descriptor *f, scratch_t *s, double X[6])
{
    double cut, cost = pairs(f, s, X, 1, &cut);
    for (int it = 0; it < RECOVER_ITERS; it++) {
        double Xn[6], cutn;
        if (!amscr__plane_solve(prm, f->base, s->q, s->r2, s->seg, s->Hd, s->nd, f->n, cut, Xn))
            break;
        double costn = pairs(f, s, Xn, 0, &cutn);
        memcpy(X, Xn, 6 * sizeof *X);
        cut = cutn;
        if (!(costn < cost * (1.0 - 1e-6)))
            break;
        cost = costn;
    }
    return cut;
}

/* Mean of the smallest RECOVER_RANK_KEEP share of v (n values; reordered). */
static double trimmed_mean(double *v, size_t n)
{
    size_t keep = (size_t)(RECOVER_RANK_KEEP * (double)n);
    if (keep < 1)
        keep = 1;
    amscr__select_kth(v, n, keep - 1);
    double sum = 0.0;
    for (size_t a = 0; a < keep; a++)
        sum += v[a];
    return sum / (double)keep;
}

/* The two-way ranking cost of X, whose source-to-target residuals are in s->r2. */
static double two_way_cost(const amscr_descriptor *f, const amscr_descriptor *h, scratch_t *s, const double X[6])
{
    size_t n = f->n;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        s->P[2 * a] = X[0] * fx + X[1] * fy + X[2];
        s->P[2 * a + 1] = X[3] * fx + X[4] * fy + X[5];
        s->sorted[a] = s->r2[a];
    }
    double there = trimmed_mean(s->sorted, n);
    for (size_t b = 0; b < h->n; b++) {
        double qx, qy;
        size_t seg;
        s->sorted[b] = amscr__closest_on_polygon(s->P, n, f->params.closed, 0, n, h->base[2 * b], h->base[2 * b + 1],
                                                 &qx, &qy, &seg);
    }
    return there + trimmed_mean(s->sorted, h->n);
}

static double inlier_share(const double *r2, size_t n)
{
    size_t in = 0;
    for (size_t a = 0; a < n; a++)
        in += r2[a] <= RECOVER_INLIER_DIST * RECOVER_INLIER_DIST;
    return (double)in / (double)n;
}

/* The fragments in the order they are tried: fewest samples without a target boundary near
 * them under the reported map (r2: its squared residuals) first, so the first one tried is the
 * one most likely to avoid the missing run. */
static void fragment_order(const double *r2, size_t n, size_t order[RECOVER_FRAGS])
{
    size_t len = (size_t)(RECOVER_SHARE * (double)n), out[RECOVER_FRAGS];
    for (size_t k = 0; k < RECOVER_FRAGS; k++) {
        size_t start = k * n / RECOVER_FRAGS;
        out[k] = 0;
        for (size_t j = 0; j < len; j++)
            out[k] += r2[(start + j) % n] > RECOVER_INLIER_DIST * RECOVER_INLIER_DIST;
        order[k] = k;
    }
    for (size_t k = 1; k < RECOVER_FRAGS; k++) /* insertion sort, stable: ties keep k's order */
        for (size_t j = k; j > 0 && out[order[j]] < out[order[j - 1]]; j--) {
            size_t t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
}

/* The map of fragment k of f placed on h by partial matching, in f's normalized frame.
 * Returns a failure status when the fragment cannot be placed. */
static amscr_status fragment_start(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                   size_t k, amscr_workspace *ws, double *pts, double X[6])
{
    size_t n = f->n, len = (size_t)(RECOVER_SHARE * (double)n), start = k * n / RECOVER_FRAGS;
    for (size_t j = 0; j < len; j++)
        memcpy(pts + 2 * j, f->base + 2 * ((start + j) % n), 2 * sizeof *pts);
    amscr_params pp = *prm;
    pp.partial = 1;
    pp.closed = 0;
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    match_t mf;
    amscr_status st = amscr_contour_new(pts, len, &c);
    if (st == AMSCR_OK)
        st = amscr_descriptor_new(&pp, c, &d);
    pp.closed = 1;
    if (st == AMSCR_OK)
        st = amscr__match_partial_min(&pp, d, h, RECOVER_PHI_MIN, 0, ws, &mf);
    if (st == AMSCR_OK) /* d's input frame is f's normalized frame */
        amscr__affine_compose(mf.X, d->fwd, X);
    amscr_descriptor_free(d);
    amscr_contour_free(c);
    return st; /* a fragment that cannot be placed is skipped; out of memory is not */
}

/* Refines `best` once more, stores the map in m and its pairs in ws->rbuf (the reported
 * solve reads them). m->dist stays the one the batch path computes (amscr_distance agrees with
 * the result's distance, amscr.h): the distance ranks shapes, the map is what is recovered. */
static amscr_status finish(const amscr_params *prm, const amscr_descriptor *f, scratch_t *s, amscr_workspace *ws,
                           double best[6], match_t *m)
{
    size_t n = f->n;
    amscr_status st = amscr__ws_reserve_refine(ws, n);
    if (st != AMSCR_OK)
        return st;
    double cut = refine_adaptive(prm, f, s, best), kept = 0.0, sum = 0.0;
    memcpy(ws->rbuf, s->q, 2 * n * sizeof *s->q);
    memcpy(ws->rbuf + 2 * n, s->r2, n * sizeof *s->r2);
    for (size_t a = 0; a < n; a++) {
        if (s->r2[a] <= cut) {
            sum += s->r2[a];
            kept += 1.0;
        }
    }
    memcpy(m->X, best, 6 * sizeof *best);
    m->rcut = cut;
    m->rcost = sum / kept;
    m->refined = 1;
    return AMSCR_OK;
}

static void scratch_free(scratch_t *s)
{
    free(s->q);
    amscr__grid_free(&s->grid);
    s->q = NULL;
}

static amscr_status scratch_new(const amscr_descriptor *f, const amscr_descriptor *h, scratch_t *s)
{
    size_t n = f->n;
    double *buf = amscr__malloc_array(2 * AMSCR__DENSE * n + 10 * n, sizeof *buf);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "registration: out of memory");
    memset(s, 0, sizeof *s);
    s->q = buf;
    s->r2 = buf + 2 * n;
    s->sorted = buf + 3 * n;
    s->seg = buf + 4 * n;
    s->Hd = buf + 5 * n;
    s->P = buf + 5 * n + 2 * AMSCR__DENSE * n;
    s->nd = amscr__densify(h->base, n, 1, s->Hd);
    if (amscr__grid_build(&s->grid, s->Hd, s->nd) != 1) {
        scratch_free(s);
        return amscr__fail(AMSCR_E_NOMEM, "registration: out of memory (or a non-finite target)");
    }
    return AMSCR_OK;
}

amscr_status amscr__refine_adaptive(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                    amscr_workspace *ws, match_t *m)
{
    if (f->n != h->n || !h->params.closed)
        return AMSCR_OK;
    scratch_t s = {0};
    amscr_status st = scratch_new(f, h, &s);
    if (st != AMSCR_OK)
        return st;
    double best[6];
    memcpy(best, m->X, sizeof best);
    st = finish(prm, f, &s, ws, best, m);
    scratch_free(&s);
    return st;
}

int amscr__recover_applies(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_workspace *ws,
                           const match_t *m)
{
    return m->refined && f->n == h->n && inlier_share(ws->rbuf + 2 * f->n, f->n) < RECOVER_INLIERS;
}

amscr_status amscr__recover_missing(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                    amscr_workspace *ws, match_t *m)
{
    size_t n = f->n;
    if (!amscr__recover_applies(f, h, ws, m))
        return AMSCR_OK;
    scratch_t s = {0};
    amscr_status st = scratch_new(f, h, &s);
    if (st != AMSCR_OK)
        return st;
    double *pts = s.P + 2 * n;
    double best[6], tried[RECOVER_FRAGS + 1][6], cost[RECOVER_FRAGS + 1], best_cost;
    size_t order[RECOVER_FRAGS];
    fragment_order(ws->rbuf + 2 * n, n, order);
    memcpy(best, m->X, sizeof best);
    refine_adaptive(prm, f, &s, best);
    memcpy(tried[0], best, sizeof best);
    best_cost = cost[0] = two_way_cost(f, h, &s, best);
    for (size_t i = 0, nt = 1; i < RECOVER_FRAGS; i++) {
        double *X = tried[nt];
        st = fragment_start(prm, f, h, order[i], ws, pts, X);
        if (st == AMSCR_E_NOMEM)
            break;
        if (st != AMSCR_OK)
            continue;
        refine_adaptive(prm, f, &s, X);
        double c = cost[nt] = two_way_cost(f, h, &s, X);
        if (c < best_cost) {
            best_cost = c;
            memcpy(best, X, sizeof best);
        }
        int agree = 0; /* with an earlier map (tried[0]: the reported one), one of the two the best so far */
        for (size_t j = m->ambiguity < RECOVER_AMBIGUOUS ? 0 : 1; j < nt && !agree; j++)
            agree = (c <= best_cost || cost[j] <= best_cost) &&
                    amscr__map_gap2(f, X, tried[j]) <= RECOVER_AGREE * RECOVER_AGREE;
        nt++;
        if (agree)
            break;
    }
    if (st == AMSCR_E_NOMEM) {
        scratch_free(&s);
        return st;
    }
    amscr__clear_error();
    st = finish(prm, f, &s, ws, best, m);
    scratch_free(&s);
    return st;
}

amscr_status amscr__rank_converged(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                   double X[][6], size_t count, double *cost)
{
    if (f->n != h->n || !h->params.closed)
        return AMSCR_OK;
    scratch_t s = {0};
    amscr_status st = scratch_new(f, h, &s);
    if (st != AMSCR_OK)
        return st;
    for (size_t k = 0; k < count; k++) {
        refine_adaptive(prm, f, &s, X[k]);
        cost[k] = two_way_cost(f, h, &s, X[k]);
    }
    scratch_free(&s);
    return AMSCR_OK;
}
