/* partial.c — partial matching: the source f is an open fragment of the closed
 * target h. Where on h the fragment lies and how long it is are unknown; the method's one-to-one
 * correspondence of whole curves does not apply.
 *
 * Affine arc length (∫ |det(x', x'')|^(1/3)) is carried by an affine map up to the one factor
 * det(A)^(1/3), so the fragment covers a fixed fraction φ of the target's affine length and
 * sample a at affine position u_a of the fragment corresponds to the target's position
 * t0 + φ u_a. The search tries every start t0 (PART_STARTS of them) and a geometric grid of φ,
 * fits the affine map of each by least squares (closed form, PART_K points) and keeps the
 * lowest normalized residuals at distinct starts; each is then refined by trimmed closest points
 * against the whole (densified) target — as refine.c, started from this global estimate — and
 * the lowest trimmed cost wins. The others give the ambiguity (a short fragment fits several
 * places). */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Fragment points of the placement search: enough to see the shape of the fragment, few enough
 * that the search stays about a millisecond. */
#define PART_K 64
/* The target resampled uniformly in affine arc length, and the start positions tried. */
#define PART_U 1024
#define PART_STARTS 128
/* Fragment length fractions tried: PART_PHI_MIN.. 1 in steps of the factor PART_PHI_STEP
 * (4 %: the closest-point refinement absorbs the rest). */
#define PART_PHI_MIN 0.2
#define PART_PHI_STEP 1.04
/* Smoothing (in samples) of the curves the affine speed is measured on: the second derivative
 * of a pixel contour is noise below a few samples. */
#define PART_SIGMA 3.0
/* Placements carried through the refinement; a placement is distinct from a better one when
 * its start is more than 1/16 of the boundary away. */
#define PART_KEEP 4
#define PART_DISTINCT (PART_U / 16)
/* Closest-point partners of the first refinement step are searched within ±N/8 samples of the
 * placement's partner, later ones within ±3 samples of the last one (as refine.c). */
#define PART_WINDOW_DIV 8
#define PART_HINT 3
#define PART_TRIM 0.9
#define PART_ITERS 20
/* A placement whose refinement changed the map's area (|det|) by more than this factor, or its
 * sign, has collapsed the fragment onto a straight or flat piece of the target (a tiny one-way
 * cost, the wrong place): it wins only when every placement did (measured on the fragments of
 * bench/registration_heldout.py --sets: the right placements change by at most ~15 %, the
 * collapsed ones by 10-1000x). As the polish's MAX_AREA_CHANGE. The caller's fragments only
 * (either_way): on the recovery's pieces of a closed source it lost traced bite pairs. */
#define PART_AREA_CHANGE 2.0

typedef struct {
    size_t s;  /* start index in the uniform target */
    double phi;
    int o;     /* 1: the target traversed backwards (a mirror, or the fragment run the other way) */
    double cost;
    double X[6];  /* the search's fit, then the refined map */
    double X0[6]; /* the search's fit */
    double tcost; /* after refinement */
} placement;

/* Point at arc position t of a polyline with cumulative lengths cum (closed: total L wraps). */
static void point_at(const double *P, const double *cum, size_t n, int closed, double L, double t, double *x,
                     double *y, double *param)
{
    if (closed) {
        t = fmod(t, L);
        if (t < 0.0)
            t += L;
    } else if (t > cum[n - 1]) {
        t = cum[n - 1];
    }
    size_t lo = 0, hi = n - 1;
    while (hi > lo + 1) { /* cum[lo] <= t < cum[hi] */
        size_t mid = (lo + hi) / 2;
        if (cum[mid] <= t)
            lo = mid;
        else
            hi = mid;
    }
    if (closed && t >= cum[n - 1])
        lo = n - 1;
    size_t nx = lo + 1 < n ? lo + 1 : 0;
    double end = nx == 0 ? L : cum[nx], len = end - cum[lo];
    double w = len > 0.0 ? (t - cum[lo]) / len : 0.0;
    *x = P[2 * lo] + w * (P[2 * nx] - P[2 * lo]);
    *y = P[2 * lo + 1] + w * (P[2 * nx + 1] - P[2 * lo + 1]);
    if (param)
        *param = ((double)lo + w) / (double)n;
}

/* Relative residual of the affine fit of the fragment points F (moments inverse Minv) onto the
 * target points at uniform indices s + o·round(phi U j/(K-1)): 1 - explained scatter. */
static double place_cost(const amscr_params *prm, const double *F, const double mom[6], const double Minv[9],
                         const double *Hu, size_t s, double phi, int o, double X[6])
{
    double R[6] = {0, 0, 0, 0, 0, 0}, hh = 0.0;
    double step = phi * (double)PART_U / (double)(PART_K - 1);
    for (size_t j = 0; j < PART_K; j++) {
        size_t off = (size_t)((double)j * step + 0.5) % PART_U;
        size_t i = o ? (s + PART_U - off) % PART_U : (s + off) % PART_U;
        double u = Hu[2 * i], v = Hu[2 * i + 1], x = F[2 * j], y = F[2 * j + 1];
        amscr__cross_add(R, u, v, x, y);
        hh += u * u + v * v;
    }
    if (!amscr__fit_x(prm, mom, Minv, R, X))
        return INFINITY;
    double scat = hh - (R[2] * R[2] + R[5] * R[5]) / (double)PART_K;
    if (!(scat > 0.0))
        return INFINITY;
    return amscr__resid_sum(X, mom, R, hh) / scat;
}

/* Keeps the PART_KEEP lowest placements at distinct starts (best[] ascending by cost). */
static void keep_placement(placement *best, size_t *nb, const placement *c)
{
    for (size_t i = 0; i < *nb; i++) {
        size_t d = c->s > best[i].s ? c->s - best[i].s : best[i].s - c->s;
        if (d > PART_U - d)
            d = PART_U - d;
        if (d <= PART_DISTINCT && c->o == best[i].o) {
            if (c->cost >= best[i].cost)
                return;
            for (size_t k = i; k + 1 < *nb; k++) /* replaced below: drop it */
                best[k] = best[k + 1];
            (*nb)--;
            break;
        }
    }
    size_t pos = *nb;
    while (pos > 0 && best[pos - 1].cost > c->cost)
        pos--;
    if (pos >= PART_KEEP)
        return;
    size_t last = *nb < PART_KEEP ? *nb : PART_KEEP - 1;
    for (size_t k = last; k > pos; k--)
        best[k] = best[k - 1];
    best[pos] = *c;
    if (*nb < PART_KEEP)
        (*nb)++;
}

/* One closest-point pass: partners of X f_a on the dense target's nd edges E (closed) within
 * b[a] ± w; q, r2, b updated; returns the trimmed cost, *cut its cut-off. */
static double pairs(const amscr_descriptor *f, const double *E, size_t nd, const double X[6],
                    size_t w, double *q, double *r2, double *sorted, double *b, double *cut)
{
    size_t n = f->n;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double px = X[0] * fx + X[1] * fy + X[2], py = X[3] * fx + X[4] * fy + X[5];
        size_t seg = (size_t)b[a];
        r2[a] = amscr__closest_on_closed(E, nd, seg, w, px, py, &q[2 * a], &q[2 * a + 1], &seg);
        b[a] = (double)seg;
        sorted[a] = r2[a];
    }
    size_t keep = (size_t)(PART_TRIM * (double)n);
    amscr__select_kth(sorted, n, keep - 1);
    double cost = 0.0;
    for (size_t a = 0; a < keep; a++)
        cost += sorted[a];
    *cut = sorted[keep - 1];
    return cost / (double)keep;
}

/* Trimmed closest-point refinement of placement pl (X in/out); returns the trimmed cost.
 * b: the initial partners (dense edge per sample), updated. */
static double refine_placement(const amscr_params *prm, const amscr_descriptor *f, const double *Hd,
                               const double *E, size_t nd, double X[6], double *b, double *q, double *r2,
                               double *sorted, double *out_cut)
{
    size_t n = f->n, wide = AMSCR__DENSE * (n / PART_WINDOW_DIV), near = AMSCR__DENSE * PART_HINT;
    double cut, cost = pairs(f, E, nd, X, wide, q, r2, sorted, b, &cut);
    for (unsigned it = 0; it < PART_ITERS; it++) {
        double Xn[6], cutn;
        if (!amscr__plane_solve(prm, f->base, q, r2, b, Hd, nd, n, cut, Xn))
            break;
        double costn = pairs(f, E, nd, Xn, it == 0 ? wide : near, q, r2, sorted, b, &cutn);
        int done = !(costn < cost * (1.0 - 1e-6));
        memcpy(X, Xn, 6 * sizeof *X);
        cost = costn;
        cut = cutn;
        if (done)
            break;
    }
    *out_cut = cut;
    return cost;
}

/* Whether the refined map X kept the area of the search's fit X0 (within PART_AREA_CHANGE). */
static int kept_area(const double X0[6], const double X[6])
{
    double ratio = (X[0] * X[4] - X[1] * X[3]) / (X0[0] * X0[4] - X0[1] * X0[3]);
    return ratio >= 1.0 / PART_AREA_CHANGE && ratio <= PART_AREA_CHANGE;
}

/* Partners (dense target edges) of the samples under placement pl: sample a at fragment
 * position u_a -> uniform target index s ± phi U u_a -> its dense edge. */
static void initial_partners(const placement *pl, const double *cumF, double LF, const double *Hp, size_t n,
                             size_t nd, double *b)
{
    for (size_t a = 0; a < n; a++) {
        double off = pl->phi * (double)PART_U * cumF[a] / LF;
        double i = pl->o ? (double)pl->s - off : (double)pl->s + off;
        i = fmod(i, (double)PART_U);
        if (i < 0.0)
            i += (double)PART_U;
        size_t ii = (size_t)(i + 0.5) % PART_U;
        b[a] = (double)((size_t)(Hp[ii] * (double)nd) % nd);
    }
}

/* The placement search over (start, length, orientation); best[] ascending. norient: the
 * target's traversals tried (2: also backwards); keep_sign: only fits whose determinant has
 * this sign (0: either). */
static size_t search_placements(const amscr_params *prm, const double *F, const double *Hu, double phi_min,
                                int norient, int keep_sign, placement *best)
{
    double mom[6] = {0, 0, 0, 0, 0, 0}, M9[9], Minv[9];
    for (size_t j = 0; j < PART_K; j++)
        amscr__moment_add(mom, F[2 * j], F[2 * j + 1]);
    amscr__moment_matrix(mom, M9);
    if (!amscr__inv3(M9, Minv))
        return 0;
    size_t nb = 0;
    for (int o = 0; o < norient; o++)
        for (double phi = phi_min; phi <= 1.0 + 1e-9; phi *= PART_PHI_STEP)
            for (size_t k = 0; k < PART_STARTS; k++) {
                placement c = {k * (PART_U / PART_STARTS), phi, o, 0.0, {0}, {0}, 0.0};
                c.cost = place_cost(prm, F, mom, Minv, Hu, c.s, phi, o, c.X);
                if (isfinite(c.cost) && (!keep_sign || keep_sign * (c.X[0] * c.X[4] - c.X[1] * c.X[3]) > 0.0))
                    keep_placement(best, &nb, &c);
            }
    return nb;
}

amscr_status amscr__match_partial(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                  amscr_workspace *ws, match_t *m)
{
    return amscr__match_partial_min(prm, f, h, PART_PHI_MIN, 1, ws, m);
}

/* The sign of the determinant of a map in the normalized frames f -> h once in input coordinates
 * (h->inv o X o f->fwd) is that of X times this. */
static int frames_sign(const amscr_descriptor *f, const amscr_descriptor *h)
{
    double a = f->fwd[0] * f->fwd[4] - f->fwd[1] * f->fwd[3], b = h->inv[0] * h->inv[4] - h->inv[1] * h->inv[3];
    return a * b < 0.0 ? -1 : 1;
}

/* The fragment f and the target h sampled along their affine arc lengths (each smoothed at
 * PART_SIGMA first; sm: 2n scratch): PART_K points of f from end to end into F, PART_U points
 * around h into Hu with their arc positions Hp; cumF / cumH (n each) and the lengths LF / LH
 * kept for the partners. */
static amscr_status partial_samples(const amscr_descriptor *f, const amscr_descriptor *h, double *sm, double *cumF,
                                    double *cumH, double *LF, double *LH, double *F, double *Hu, double *Hp)
{
    size_t n = f->n;
    amscr_status st = amscr__smooth(f->base, n, 0, PART_SIGMA, sm);
    if (st == AMSCR_OK)
        st = amscr__affine_cum(sm, n, 0, 0.0, cumF, LF);
    if (st == AMSCR_OK)
        st = amscr__smooth(h->base, n, 1, PART_SIGMA, sm);
    if (st == AMSCR_OK)
        st = amscr__affine_cum(sm, n, 1, 0.0, cumH, LH);
    if (st != AMSCR_OK)
        return st;
    for (size_t j = 0; j < PART_K; j++)
        point_at(f->base, cumF, n, 0, *LF, *LF * (double)j / (double)(PART_K - 1), &F[2 * j], &F[2 * j + 1], NULL);
    for (size_t i = 0; i < PART_U; i++)
        point_at(h->base, cumH, n, 1, *LH, *LH * (double)i / (double)PART_U, &Hu[2 * i], &Hu[2 * i + 1], &Hp[i]);
    return AMSCR_OK;
}

/* The ambiguity of the winner among nb refined placements: the largest ratio of its cost to
 * a distinct placement's (both floored), at most 1; 0 when no other placement is distinct. */
static double partial_ambiguity(const amscr_descriptor *f, const placement *best, size_t nb, size_t win)
{
    double amb = 0.0;
    for (size_t c = 0; c < nb; c++)
        if (c != win && amscr__map_gap2(f, best[c].X, best[win].X) > AMSCR__DISTINCT_GAP2) {
            double ratio = (best[win].tcost + AMSCR__AMBIGUITY_FLOOR) / (best[c].tcost + AMSCR__AMBIGUITY_FLOOR);
            if (ratio > amb)
                amb = ratio > 1.0 ? 1.0 : ratio;
        }
    return amb;
}

amscr_status amscr__match_partial_min(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                      double phi_min, int either_way, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n;
    /* no per-scale systems here: the scale diagnostics are zero, nothing kept, no threshold */
    memset(m, 0, sizeof *m);
    m->p = f->p;
    m->threshold = INFINITY;
    amscr_status st = amscr__ws_reserve_refine(ws, n);
    if (st != AMSCR_OK)
        return st;
    double *buf = amscr__malloc_array((6 + 5 * AMSCR__DENSE) * n + 2 * PART_K + 3 * PART_U, sizeof *buf);
    double *b = amscr__malloc_array(n, sizeof *b);
    if (!buf || !b) {
        free(buf);
        free(b);
        return amscr__fail(AMSCR_E_NOMEM, "partial registration: out of memory");
    }
    double *sm = buf, *cumF = sm + 2 * n, *cumH = cumF + n, *F = cumH + n, *Hu = F + 2 * PART_K,
           *Hp = Hu + 2 * PART_U, *E = Hp + PART_U;
    double LF, LH;
    st = partial_samples(f, h, sm, cumF, cumH, &LF, &LH, F, Hu, Hp);
    if (st != AMSCR_OK) {
        free(buf);
        free(b);
        return st;
    }
    placement best[PART_KEEP];
    /* The fragment's points may run either way along the target (an open curve has no
     * orientation of its own): with either_way both traversals are searched, and without
     * reflections only the maps that keep the orientation (determinant > 0 in input coordinates)
     * are placements; else the traversal as given, mirrored too with reflections. */
    int sign = frames_sign(f, h);
    size_t nb = either_way ? search_placements(prm, F, Hu, phi_min, 2, prm->reflections ? 0 : sign, best)
                           : search_placements(prm, F, Hu, phi_min, prm->reflections ? 2 : 1, 0, best);
    double *q = ws->rbuf, *r2 = q + 2 * n, *sorted = r2 + n, *Hd = q + 8 * n;
    size_t nd = amscr__densify(h->base, n, 1, Hd);
    amscr__closed_edges(Hd, nd, E);
    size_t win = 0;
    int kept[PART_KEEP], any_kept = 0;
    double cut = 0.0;
    for (size_t c = 0; c < nb; c++) {
        memcpy(best[c].X0, best[c].X, sizeof best[c].X0);
        initial_partners(&best[c], cumF, LF, Hp, n, nd, b);
        best[c].tcost = refine_placement(prm, f, Hd, E, nd, best[c].X, b, q, r2, sorted, &cut);
        kept[c] = !either_way || kept_area(best[c].X0, best[c].X);
        any_kept |= kept[c];
    }
    for (size_t c = 1; c < nb; c++) /* the lowest cost among the placements that kept their area */
        if ((kept[c] || !any_kept) && (!(kept[win] || !any_kept) || best[c].tcost < best[win].tcost))
            win = c;
    for (size_t c = 0; c < nb && any_kept; c++) /* a collapsed placement is no alternative either */
        if (!kept[c])
            best[c].tcost = INFINITY;
    if (nb == 0) {
        free(buf);
        free(b);
        return amscr__fail(AMSCR_E_DEGENERATE, "partial registration: no placement of the fragment fits");
    }
    m->ambiguity = partial_ambiguity(f, best, nb, win);
    /* the winner again, so that ws->rbuf holds its pairs for the reported QR solve (they are
     * there already when it was the last refined: the refinement is deterministic) */
    double X[6], cost = best[win].tcost;
    memcpy(X, best[win].X, sizeof X);
    if (win + 1 != nb) {
        memcpy(X, best[win].X0, sizeof X);
        initial_partners(&best[win], cumF, LF, Hp, n, nd, b);
        cost = refine_placement(prm, f, Hd, E, nd, X, b, q, r2, sorted, &cut);
    }
    double all = 0.0;
    for (size_t a = 0; a < n; a++)
        all += r2[a];
    memcpy(m->X, X, sizeof X);
    m->dist = amscr__distance_of(prm, X, all, n);
    m->rcost = cost;
    m->rcut = cut;
    m->refined = 1;
    m->reflected = either_way ? sign * (X[0] * X[4] - X[1] * X[3]) < 0.0 : best[win].o;
    free(buf);
    free(b);
    return isfinite(m->dist) ? AMSCR_OK : amscr__fail(AMSCR_E_NUMERIC, "partial registration: non-finite distance");
}
