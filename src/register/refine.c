/* refine.c — trimmed closest-point refinement of a match (docs/method.md §3.8).
 * Once (A, B) is known, A f + B and h nearly coincide in the target's frame, so a correspondence
 * that is not affine-invariant becomes usable: every source sample is paired with the closest
 * point of the target polygon (searched in a window around its current partner), the worst 10 %
 * of the pairs are trimmed (missing or extra parts of a contour), and the least squares is
 * re-solved — a trimmed ICP started from AMSCR's global, closed-form estimate, so it does not
 * fall into the local minima that sink ICP from arbitrary starts. Repeated while the trimmed
 * cost drops, at most `refine` times. The distance is then the mean squared closest-point
 * residual of all samples. */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <string.h>


/* The share of closest-point pairs kept: the worst 10 % are taken as missing or extra parts. */
#define AMSCR__TRIM 0.9
/* Fewest pairs a trimmed solve keeps (a 2-D affine map has 6 unknowns). */
#define AMSCR__TRIM_MIN_PAIRS 8
/* Without a previous closest edge, a sample's partner is searched within ±N/32 samples of the
 * method's correspondence (at least ±2): the continuous start point leaves the method's
 * partners within a sample or two of the closest point. Measured (0.3): ±N/8 and ±N/32 give
 * the same maps within 2 % on every held-out condition and the Kimia suite; this search was
 * most of a registration's time (preset, 760-point contours: 2.1 -> 1.3 ms with the next). */
#define AMSCR__WINDOW_DIV 32
#define AMSCR__WINDOW_MIN 2
/* With the previous closest edge known, ±3 sample spacings (±3 AMSCR__DENSE dense edges)
 * cover how far one step moves a partner. */
#define AMSCR__HINT_SAMPLES 3
/* A step that lowers the trimmed cost by less than this fraction has converged. */
#define AMSCR__REFINE_RTOL 1e-6
/* Costs are mean squared distances in the target's normalized frame (RMS radius sqrt 2): a
 * match whose trimmed cost is below this floor (an RMS misfit of 0.01 % of the size) is
 * already exact, and closest-point steps smaller than half of it are noise: both would only
 * let the map slide along the curve, which closest-point costs do not see. */
#define AMSCR__REFINE_FLOOR 1e-8
/* The foot's position num / l2 on an edge, clamped to [0, 1], dividing only inside (most edges
 * of a window project outside): the quotient's clamp (num < 0 < l2 gives a negative one,
 * num > l2 one of at least 1; a NaN stays NaN). */
static inline double edge_foot(double num, double l2)
{
    if (num < 0.0 || !(l2 > 0.0))
        return 0.0;
    return num > l2 ? 1.0 : num / l2;
}

/* Closest point to (px, py) on the polygon H (n vertices; closed: with the closing edge),
 * edges b0-w .. b0+w; *seg receives the edge index. */
static double closest_on_polygon(const double *H, size_t n, int closed, size_t b0, size_t w, double px, double py,
                                 double *qx, double *qy, size_t *seg)
{
    double best = INFINITY;
    size_t nedges = closed ? n : n - 1;
    size_t cnt = 2 * w + 1 < nedges ? 2 * w + 1 : nedges;
    size_t b;
    if (closed)
        b = (b0 + n - (cnt == nedges ? 0 : w % n)) % n;
    else
        b = b0 > w ? (b0 - w + cnt <= nedges ? b0 - w : nedges - cnt) : 0;
    for (size_t i = 0; i < cnt; i++) {
        size_t c = b + 1 == n ? 0 : b + 1;
        double ax = H[2 * b], ay = H[2 * b + 1], ex = H[2 * c] - ax, ey = H[2 * c + 1] - ay;
        double l2 = ex * ex + ey * ey, num = (px - ax) * ex + (py - ay) * ey, t;
        t = edge_foot(num, l2);
        double cx = ax + t * ex, cy = ay + t * ey, d2 = (px - cx) * (px - cx) + (py - cy) * (py - cy);
        if (d2 < best) {
            best = d2;
            *qx = cx;
            *qy = cy;
            *seg = b;
        }
        b = c;
    }
    return best;
}

/* Trimmed least squares X from pairs (f_a -> q_a) with r2_a <= cut. Returns 0 if singular. */
static int trimmed_solve(const amscr_params *prm, const double *f, const double *q, const double *r2, size_t n,
                         double cut, double X[6])
{
    double m[6] = {0, 0, 0, 0, 0, 0}, R[6] = {0, 0, 0, 0, 0, 0};
    for (size_t a = 0; a < n; a++) {
        if (r2[a] > cut)
            continue;
        double x = f[2 * a], y = f[2 * a + 1], u = q[2 * a], v = q[2 * a + 1];
        amscr__moment_add(m, x, y);
        amscr__cross_add(R, u, v, x, y);
    }
    return amscr__fit_x(prm, m, NULL, R, X);
}

/* Catmull-Rom densification of the N target samples by AMSCR__DENSE (closed: periodic; open:
 * end points repeated). out: 2 * AMSCR__DENSE * n (closed) or AMSCR__DENSE * (n - 1) + 1 points. */
static size_t densify(const double *H, size_t n, int closed, double *out)
{
    size_t m = 0, nseg = closed ? n : n - 1;
    for (size_t i = 0; i < nseg; i++) {
        size_t i0 = closed ? (i + n - 1) % n : (i == 0 ? 0 : i - 1), i1 = i, i2 = closed ? (i + 1) % n : i + 1;
        size_t i3 = closed ? (i + 2) % n : (i + 2 < n ? i + 2 : n - 1);
        for (int k = 0; k < AMSCR__DENSE; k++) {
            double t = (double)k / AMSCR__DENSE, t2 = t * t, t3 = t2 * t;
            double c0 = -0.5 * t3 + t2 - 0.5 * t, c1 = 1.5 * t3 - 2.5 * t2 + 1.0, c2 = -1.5 * t3 + 2.0 * t2 + 0.5 * t,
                   c3 = 0.5 * t3 - 0.5 * t2;
            for (int d = 0; d < 2; d++)
                out[2 * m + d] = c0 * H[2 * i0 + d] + c1 * H[2 * i1 + d] + c2 * H[2 * i2 + d] + c3 * H[2 * i3 + d];
            m++;
        }
    }
    if (!closed) {
        out[2 * m] = H[2 * (n - 1)];
        out[2 * m + 1] = H[2 * (n - 1) + 1];
        m++;
    }
    return m;
}

/* One correspondence step: q_a = closest target point to X f_a; r2_a its squared distance;
 * returns the trimmed cost and the cut-off. hints (n values): the dense edge found last time
 * per sample, searched within ±AMSCR__HINT_SAMPLES sample spacings; otherwise a window of
 * ±N/AMSCR__WINDOW_DIV samples around the method's partner. */
static double icp_pairs(const amscr_descriptor *f, const double *Hd, size_t nd, const match_t *m, const double X[6],
                        double *q, double *r2, double *sorted, double *hints, int use_hints, double *out_cut)
{
    size_t n = f->n, wide = AMSCR__DENSE * (n / AMSCR__WINDOW_DIV > AMSCR__WINDOW_MIN ? n / AMSCR__WINDOW_DIV
                                                                                        : AMSCR__WINDOW_MIN);
    int closed = f->params.closed;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double px = X[0] * fx + X[1] * fy + X[2], py = X[3] * fx + X[4] * fy + X[5];
        size_t b0, w, seg = 0;
        if (use_hints) {
            b0 = (size_t)hints[a];
            w = AMSCR__HINT_SAMPLES * AMSCR__DENSE;
        } else {
            b0 = AMSCR__DENSE *
                 (closed ? amscr__tgt_index(a, m->shift, m->reflected, 1, n) : amscr__tgt_index(a, 0, m->reflected, 0, n));
            w = wide;
        }
        if (b0 >= nd)
            b0 = nd - 1;
        r2[a] = closest_on_polygon(Hd, nd, closed, b0, w, px, py, &q[2 * a], &q[2 * a + 1], &seg);
        hints[a] = (double)seg;
        sorted[a] = r2[a];
    }
    size_t keep = (size_t)(AMSCR__TRIM * (double)n);
    if (keep < AMSCR__TRIM_MIN_PAIRS)
        keep = n < AMSCR__TRIM_MIN_PAIRS ? n : AMSCR__TRIM_MIN_PAIRS;
    amscr__select_kth(sorted, n, keep - 1);
    double cost = 0.0;
    for (size_t a = 0; a < keep; a++)
        cost += sorted[a];
    *out_cut = sorted[keep - 1];
    return cost / (double)keep;
}

amscr_status amscr__refine_match(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                 amscr_workspace *ws, match_t *m, unsigned iters)
{
    if (iters == 0)
        return AMSCR_OK;
    size_t n = f->n;
    int refined = 0;
    amscr_status st = amscr__ws_reserve_refine(ws, n);
    if (st != AMSCR_OK)
        return st;
    double *q = ws->rbuf, *r2 = q + 2 * n, *sorted = r2 + n, *q2 = sorted + n, *hints = q2 + 2 * n;
    double *hints2 = hints + n, *Hd = hints2 + n;
    size_t nd = densify(h->base, n, f->params.closed, Hd);
    double X[6], cut;
    memcpy(X, m->X, sizeof X);
    double cost = icp_pairs(f, Hd, nd, m, X, q, r2, sorted, hints, 0, &cut);
    if (cost < AMSCR__REFINE_FLOOR)
        iters = 0;
    for (unsigned it = 0; it < iters; it++) {
        double Xn[6], cutn;
        if (!amscr__plane_solve(prm, f->base, q, r2, hints, Hd, nd, n, cut, Xn))
            break;
        memcpy(hints2, hints, n * sizeof *hints);
        double costn = icp_pairs(f, Hd, nd, m, Xn, q2, r2, sorted, hints2, 1, &cutn);
        if (!(costn < cost - 0.5 * AMSCR__REFINE_FLOOR)) {
            /* r2 now holds the rejected trial: restore the accepted pairs' residuals */
            cost = icp_pairs(f, Hd, nd, m, X, q, r2, sorted, hints, 1, &cut);
            break;
        }
        int converged = costn > cost * (1.0 - AMSCR__REFINE_RTOL);
        memcpy(X, Xn, sizeof X);
        memcpy(q, q2, 2 * n * sizeof *q);
        memcpy(hints, hints2, n * sizeof *hints);
        cost = costn;
        cut = cutn;
        refined = 1;
        if (converged)
            break;
    }
    m->rcost = cost;
    if (refined) {
        double all = 0.0;
        for (size_t a = 0; a < n; a++)
            all += r2[a];
        memcpy(m->X, X, sizeof X);
        m->dist = amscr__distance_of(prm, X, all, n);
        m->refined = 1;
        m->rcut = cut;
    }
    return AMSCR_OK;
}


/* ---- robust registration: the closest-point pieces shared with partial.c and
 * correspond.c (thin exported names of the statics above) ---- */
double amscr__closest_on_polygon(const double *H, size_t n, int closed, size_t b0, size_t w, double px, double py,
                                 double *qx, double *qy, size_t *seg)
{
    return closest_on_polygon(H, n, closed, b0, w, px, py, qx, qy, seg);
}

size_t amscr__densify(const double *H, size_t n, int closed, double *out) { return densify(H, n, closed, out); }

void amscr__closed_edges(const double *H, size_t n, double *E)
{
    double *ax = E, *ay = E + n, *ex = E + 2 * n, *ey = E + 3 * n, *l2 = E + 4 * n;
    for (size_t b = 0; b < n; b++) {
        size_t c = b + 1 == n ? 0 : b + 1;
        ax[b] = H[2 * b];
        ay[b] = H[2 * b + 1];
        ex[b] = H[2 * c] - ax[b];
        ey[b] = H[2 * c + 1] - ay[b];
        l2[b] = ex[b] * ex[b] + ey[b] * ey[b];
    }
}

/* Edges b .. e - 1 (no wrap) of closest_on_polygon's search, from the edges E: its arithmetic,
 * dividing only when the foot is inside the edge (num / l2 clamped to [0, 1] is 0 when
 * num < 0 < l2 and 1 when num > l2 > 0; a NaN stays NaN), the first strictly lowest kept. */
static void closest_run(const double *E, size_t n, size_t b, size_t e, double px, double py, double *best,
                        double *qx, double *qy, size_t *seg)
{
    const double *AX = E, *AY = E + n, *EX = E + 2 * n, *EY = E + 3 * n, *L2 = E + 4 * n;
    for (; b < e; b++) {
        double ax = AX[b], ay = AY[b], ex = EX[b], ey = EY[b], l2 = L2[b];
        double num = (px - ax) * ex + (py - ay) * ey, t = edge_foot(num, l2);
        double cx = ax + t * ex, cy = ay + t * ey, d2 = (px - cx) * (px - cx) + (py - cy) * (py - cy);
        if (d2 < *best) {
            *best = d2;
            *qx = cx;
            *qy = cy;
            *seg = b;
        }
    }
}

double amscr__closest_on_closed(const double *E, size_t n, size_t b0, size_t w, double px, double py, double *qx,
                                double *qy, size_t *seg)
{
    double best = INFINITY;
    size_t cnt = 2 * w + 1 < n ? 2 * w + 1 : n;
    size_t c0 = b0 < n ? b0 : b0 % n, back = cnt == n ? 0 : w; /* w < n here: no division */
    size_t b = c0 >= back ? c0 - back : c0 + n - back, first = n - b < cnt ? n - b : cnt;
    closest_run(E, n, b, b + first, px, py, &best, qx, qy, seg); /* up to the wrap */
    closest_run(E, n, 0, cnt - first, px, py, &best, qx, qy, seg);
    return best;
}

/* Point-to-line weight of the pairs' tangential part: the solve minimizes
 * Σ (n·e)^2 + AMSCR__PLANE_MU |e|^2 over the kept pairs, e = X f - q and n the target's normal
 * at q. Closest-point pairs slide along the curve only slowly under point-to-point costs; the
 * normal part converges in a few steps, the small tangential part keeps the 6 unknowns
 * determined on straight stretches. */
#define AMSCR__PLANE_MU 0.1

int amscr__plane_solve(const amscr_params *prm, const double *f, const double *q, const double *r2,
                       const double *seg, const double *Hd, size_t nd, size_t n, double cut, double X[6])
{
    if (prm->invariance != AMSCR_INVARIANCE_AFFINE)
        return trimmed_solve(prm, f, q, r2, n, cut, X);
    double N[36] = {0}, rhs[6] = {0};
    for (size_t a = 0; a < n; a++) {
        if (r2[a] > cut)
            continue;
        size_t s = (size_t)seg[a], c = s + 1 == nd ? 0 : s + 1;
        double tx = Hd[2 * c] - Hd[2 * s], ty = Hd[2 * c + 1] - Hd[2 * s + 1], tl = sqrt(tx * tx + ty * ty);
        double nx = tl > 0.0 ? -ty / tl : 0.0, ny = tl > 0.0 ? tx / tl : 0.0;
        double x = f[2 * a], y = f[2 * a + 1], qx = q[2 * a], qy = q[2 * a + 1], nq = nx * qx + ny * qy;
        double g[6] = {nx * x, nx * y, nx, ny * x, ny * y, ny}, jx[3] = {x, y, 1.0};
        for (int i = 0; i < 6; i++) {
            for (int j = 0; j < 6; j++)
                N[6 * i + j] += g[i] * g[j];
            rhs[i] += g[i] * nq;
        }
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++) {
                N[6 * i + j] += AMSCR__PLANE_MU * jx[i] * jx[j];
                N[6 * (i + 3) + j + 3] += AMSCR__PLANE_MU * jx[i] * jx[j];
            }
            rhs[i] += AMSCR__PLANE_MU * jx[i] * qx;
            rhs[i + 3] += AMSCR__PLANE_MU * jx[i] * qy;
        }
    }
    if (!amscr__gauss_solve(N, rhs, 6))
        return 0;
    for (int i = 0; i < 6; i++)
        if (!isfinite(rhs[i]))
            return 0;
    memcpy(X, rhs, 6 * sizeof *X);
    return 1;
}
