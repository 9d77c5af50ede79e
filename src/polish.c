/* polish.c — the reported map polished on the input points themselves (issue 14).
 *
 * The method and its refinement see N resampled samples, and the refinement pairs each source
 * sample with the closest point of the target. Both are right for clean contours; under noise
 * they are not: resampling a noisy polyline keeps its noise but drops most of its points, and
 * the closest point ON a noisy curve is biased (a zig-zag always offers a nearer point than the
 * true curve), so a map fitted source -> noisy target slides along thin parts.
 *
 * If one curve is clean and the other noisy, the maximum-likelihood map pairs each point of the
 * noisy curve with the closest point of the clean one (the noise is then only a residual, not a
 * bias). Which curve is noisier is measured, not assumed: the roughness of each input polyline
 * (median squared second difference, in the shape's own size) sets the weight of the two
 * directions — points of the target onto the mapped source, and mapped source points onto the
 * target — so two clean curves are fitted both ways equally and a noisy target is fitted onto
 * the clean source. Each iteration is a point-to-line Gauss-Newton step (the line: the partner
 * curve's tangent at the partner vertex) over pairs trimmed adaptively (RESID_K x the median
 * squared distance, at least half of them: missing runs drop out).
 *
 * The chosen map and the other distinct start-point candidates of the search are polished
 * alike and ranked by a two-way trimmed cost (the polished map must beat the unpolished one),
 * so a noisy symmetric-looking shape gets the start the points favour. Runs on closed curves
 * under affine invariance when the params ask for it (the registration preset does); the
 * reported distance stays the batch path's. */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Each start is polished SCORE_ITERS steps and ranked; the winner is polished on to at most
 * POLISH_ITERS steps in all (measured: 6-12 steps typical, a few slow ones on thin shapes). */
#define SCORE_ITERS 2
#define POLISH_ITERS 30
/* Converged when a step moves the source by less than this RMS (frame of RMS radius sqrt 2:
 * 0.007 % of the size, far below any error that matters). */
#define POLISH_TOL 1e-4
/* Adaptive trimming: pairs within RESID_K times the median squared distance (5x the median
 * distance: 3.4 sigma of Gaussian noise, which keeps all but 0.07 % of noisy pairs — a tighter
 * cut drops the tails that carry a thin part's tip and lets the map slide; measured: 3x the
 * distance 98.6 / 95.7 %, 5x 100 / 97.1 % at 1 / 2 % noise). A missing run's pairs lie far
 * beyond it. */
#define RESID_K 25.0
/* Each direction of the ranking cost keeps this share of its pairs (recover.c's rule). */
#define RANK_KEEP 0.7
/* The search's other candidates are polished too when its ambiguity is at least this: another
 * start scored within a factor 2 of the chosen one (near-symmetric shapes, where noise decides;
 * measured on the held-out pairs: 0.6-1.0 for those, below 0.35 for every other pair). */
#define AMBIGUOUS_SEARCH 0.5
/* Partners after the first (global) search are looked for within ±HINT vertices of the last,
 * and further along while they keep getting closer. */
#define HINT 3
/* Edge normals from the chord one vertex beyond each end (measured on 1 and 2 % noise: 0
 * (the edge itself) 77 / 41 %, 1: 100 / 97 %, 2-6: 97-99 / 96-97 %). */
#define NORMAL_SPAN 1
/* Roughness: for Gaussian noise of variance s^2 per coordinate, a second difference has
 * variance 6 s^2 per coordinate, and its squared length's median is 6 s^2 * 2 ln 2. */
#define ROUGH_DIV (6.0 * 2.0 * 0.6931471805599453)
/* Roughness below this share of the size^2 (a clean curve's rounding) counts as this much, so
 * two clean curves share the weight evenly. */
#define ROUGH_FLOOR 1e-10

/* A uniform grid over a point set: the cell of every point, for the first (global) partner
 * search. */
typedef struct {
    double x0, y0, inv;
    long nx, ny;
    size_t *start, *item; /* nx*ny + 1 offsets, n point indices */
} grid_t;

/* One input curve in its normalized frame and its partner bookkeeping. */
typedef struct {
    double *p;    /* 2n points */
    double *en;   /* 2n unit normals of the curve's edges (the source's: as mapped) */
    size_t *part; /* n partners: the first vertex of the other curve's closest edge */
    double *ft;   /* n positions of the closest point along that edge, 0..1 */
    double *d2;   /* n squared distances to it */
    size_t n;
    double rough; /* roughness (squared), in the curve's frame */
    double sim[6], unsim[6]; /* input -> the curve's frame, and back */
} curve_t;

typedef struct {
    curve_t s, t;   /* source (input frame of f normalized), target */
    double *mapped; /* 2 ns: X s */
    double *sorted; /* max(ns, nt) scratch */
    double wt, ws;  /* weights of the directions target -> source and source -> target */
    grid_t gt, gm;  /* grids over the target and over the mapped source */
    double *block;
    size_t *iblock;
} polish_t;

static void grid_free(grid_t *g)
{
    free(g->start);
    free(g->item);
    g->start = g->item = NULL;
}

/* Cells about as wide as sqrt(area / n): a few points per occupied cell of a curve. */
static int grid_build(grid_t *g, const double *p, size_t n)
{
    double lo[2] = {p[0], p[1]}, hi[2] = {p[0], p[1]};
    for (size_t i = 1; i < n; i++)
        for (int d = 0; d < 2; d++) {
            lo[d] = p[2 * i + d] < lo[d] ? p[2 * i + d] : lo[d];
            hi[d] = p[2 * i + d] > hi[d] ? p[2 * i + d] : hi[d];
        }
    double w = hi[0] - lo[0], h = hi[1] - lo[1], cell = sqrt((w * h > 0.0 ? w * h : (w + h) * (w + h)) / (double)n);
    if (!(cell > 0.0))
        cell = 1.0;
    g->x0 = lo[0];
    g->y0 = lo[1];
    g->inv = 1.0 / cell;
    g->nx = (long)(w * g->inv) + 1;
    g->ny = (long)(h * g->inv) + 1;
    free(g->start);
    free(g->item);
    g->start = amscr__malloc_array((size_t)(g->nx * g->ny) + 1, sizeof *g->start);
    g->item = amscr__malloc_array(n, sizeof *g->item);
    if (!g->start || !g->item)
        return 0;
    memset(g->start, 0, ((size_t)(g->nx * g->ny) + 1) * sizeof *g->start);
    for (size_t i = 0; i < n; i++) {
        long cx = (long)((p[2 * i] - g->x0) * g->inv), cy = (long)((p[2 * i + 1] - g->y0) * g->inv);
        g->start[cy * g->nx + cx + 1]++;
    }
    for (long c = 0; c < g->nx * g->ny; c++)
        g->start[c + 1] += g->start[c];
    for (size_t i = 0; i < n; i++) { /* counting sort; start[c] advances, restored below */
        long cx = (long)((p[2 * i] - g->x0) * g->inv), cy = (long)((p[2 * i + 1] - g->y0) * g->inv);
        g->item[g->start[cy * g->nx + cx]++] = i;
    }
    for (long c = g->nx * g->ny; c > 0; c--)
        g->start[c] = g->start[c - 1];
    g->start[0] = 0;
    return 1;
}

/* Nearest point of the grid's set to (qx, qy): rings of cells around the query's cell until
 * the ring cannot hold a nearer point. */
static size_t grid_nearest(const grid_t *g, const double *p, double qx, double qy, double *d2)
{
    long cx = (long)floor((qx - g->x0) * g->inv), cy = (long)floor((qy - g->y0) * g->inv);
    double best = INFINITY;
    size_t bi = 0;
    long far = (g->nx > g->ny ? g->nx : g->ny) + labs(cx) + labs(cy) + 1;
    for (long r = 0; r <= far; r++) {
        for (long y = cy - r; y <= cy + r; y++) {
            if (y < 0 || y >= g->ny)
                continue;
            long step = (y == cy - r || y == cy + r) ? 1 : 2 * r;
            for (long x = cx - r; x <= cx + r; x += step ? step : 1) {
                if (x < 0 || x >= g->nx)
                    continue;
                for (size_t k = g->start[y * g->nx + x]; k < g->start[y * g->nx + x + 1]; k++) {
                    size_t i = g->item[k];
                    double dx = p[2 * i] - qx, dy = p[2 * i + 1] - qy, d = dx * dx + dy * dy;
                    if (d < best) {
                        best = d;
                        bi = i;
                    }
                }
            }
        }
        double reach = (double)r / g->inv;
        if (best <= reach * reach)
            break;
    }
    *d2 = best;
    return bi;
}

/* Nearest vertex of the closed polyline p (n) to (qx, qy) near i0: ±HINT, then on while closer. */
static size_t local_nearest(const double *p, size_t n, size_t i0, double qx, double qy, double *d2)
{
    size_t w = 2 * HINT + 1 < n ? HINT : (n - 1) / 2, bi = i0 % n;
    double best = INFINITY;
    for (size_t k = 0; k <= 2 * w; k++) {
        size_t i = (i0 + n - w + k) % n;
        double dx = p[2 * i] - qx, dy = p[2 * i + 1] - qy, d = dx * dx + dy * dy;
        if (d < best) {
            best = d;
            bi = i;
        }
    }
    for (int dir = 0; dir < 2; dir++) /* walk on while the next vertex is closer */
        for (size_t steps = 0; steps < n; steps++) {
            size_t i = dir ? (bi + 1) % n : (bi + n - 1) % n;
            double dx = p[2 * i] - qx, dy = p[2 * i + 1] - qy, d = dx * dx + dy * dy;
            if (!(d < best))
                break;
            best = d;
            bi = i;
        }
    *d2 = best;
    return bi;
}

/* The closest point to (qx, qy) on the two edges of the closed polyline p (n) at vertex i: the
 * edge's first vertex into *seg, the position along it into *t; returns the squared distance. */
static double foot(const double *p, size_t n, size_t i, double qx, double qy, size_t *seg, double *t)
{
    double best = INFINITY;
    for (size_t e = 0; e < 2; e++) {
        size_t a = e ? i : (i + n - 1) % n, b = (a + 1) % n;
        double ex = p[2 * b] - p[2 * a], ey = p[2 * b + 1] - p[2 * a + 1], l2 = ex * ex + ey * ey;
        double u = l2 > 0.0 ? ((qx - p[2 * a]) * ex + (qy - p[2 * a + 1]) * ey) / l2 : 0.0;
        u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
        double dx = p[2 * a] + u * ex - qx, dy = p[2 * a + 1] + u * ey - qy, d = dx * dx + dy * dy;
        if (d < best) {
            best = d;
            *seg = a;
            *t = u;
        }
    }
    return best;
}

/* The unit normals at the edges a -> a+1 of the closed polyline p (n), each from the chord
 * of the polyline from NORMAL_SPAN vertices before a to as many after a+1 (a pixel chain's own
 * edges point in 8 directions only); 0 for a zero-length chord. */
static void edge_normals(const double *p, size_t n, double *en)
{
    size_t k = NORMAL_SPAN < n / 4 ? NORMAL_SPAN : n / 4;
    for (size_t a = 0; a < n; a++) {
        size_t b = (a + 1 + k) % n, c = (a + n - k) % n;
        double ex = p[2 * b] - p[2 * c], ey = p[2 * b + 1] - p[2 * c + 1], l = sqrt(ex * ex + ey * ey);
        en[2 * a] = l > 0.0 ? -ey / l : 0.0;
        en[2 * a + 1] = l > 0.0 ? ex / l : 0.0;
    }
}

/* The median of v (n values; v is reordered). */
static double median(double *v, size_t n)
{
    amscr__select_kth(v, n, n / 2);
    return v[n / 2];
}

/* Squared noise level of a closed polyline from its second differences. */
static double roughness(const double *p, size_t n, double *scratch)
{
    for (size_t i = 0; i < n; i++) {
        size_t a = (i + n - 1) % n, b = (i + 1) % n;
        double dx = p[2 * a] - 2.0 * p[2 * i] + p[2 * b], dy = p[2 * a + 1] - 2.0 * p[2 * i + 1] + p[2 * b + 1];
        scratch[i] = dx * dx + dy * dy;
    }
    double r = median(scratch, n) / ROUGH_DIV;
    return r > ROUGH_FLOOR ? r : ROUGH_FLOOR;
}

/* The descriptor's kept input points in a frame that keeps their metric (noise is isotropic in
 * the input, not in the whitened frame): centred, scaled to an RMS radius of sqrt 2 (the
 * normalized frames' size, so costs compare with the engine's constants). c->sim: input -> frame. */
static void load_curve(const amscr_descriptor *d, curve_t *c)
{
    double cx, cy, r2 = 0.0;
    amscr__centroid(d->raw, d->nraw, &cx, &cy);
    for (size_t i = 0; i < d->nraw; i++)
        r2 += (d->raw[2 * i] - cx) * (d->raw[2 * i] - cx) + (d->raw[2 * i + 1] - cy) * (d->raw[2 * i + 1] - cy);
    double k = sqrt(2.0 * (double)d->nraw / (r2 > 0.0 ? r2 : 1.0));
    double sim[6] = {k, 0.0, -k * cx, 0.0, k, -k * cy}, back[6] = {1.0 / k, 0.0, cx, 0.0, 1.0 / k, cy};
    memcpy(c->sim, sim, sizeof sim);
    memcpy(c->unsim, back, sizeof back);
    c->n = d->nraw;
    for (size_t i = 0; i < d->nraw; i++) {
        c->p[2 * i] = k * (d->raw[2 * i] - cx);
        c->p[2 * i + 1] = k * (d->raw[2 * i + 1] - cy);
    }
}

/* X (normalized frames f -> h) as Y (the curves' frames), and back. */
static void to_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6],
                      double Y[6])
{
    double a[6], b[6];
    amscr__affine_compose(X, f->fwd, a);
    amscr__affine_compose(a, w->s.unsim, b);
    amscr__affine_compose(h->inv, b, a);
    amscr__affine_compose(w->t.sim, a, Y);
}

static void from_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double Y[6],
                        double X[6])
{
    double a[6], b[6];
    amscr__affine_compose(Y, w->s.sim, a);
    amscr__affine_compose(a, f->inv, b);
    amscr__affine_compose(w->t.unsim, b, a);
    amscr__affine_compose(h->fwd, a, X);
}

static void polish_free(polish_t *w)
{
    grid_free(&w->gt);
    grid_free(&w->gm);
    free(w->block);
    free(w->iblock);
}

static amscr_status polish_alloc(size_t ns, size_t nt, polish_t *w)
{
    memset(w, 0, sizeof *w);
    size_t nm = ns > nt ? ns : nt;
    w->block = amscr__malloc_array(8 * ns + 6 * nt + nm, sizeof *w->block);
    w->iblock = amscr__malloc_array(ns + nt, sizeof *w->iblock);
    if (!w->block || !w->iblock) {
        polish_free(w);
        return amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory");
    }
    double *b = w->block;
    w->s.p = b, w->s.ft = b + 2 * ns, w->s.d2 = b + 3 * ns, w->mapped = b + 4 * ns, w->s.en = b + 6 * ns;
    b += 8 * ns;
    w->t.p = b, w->t.ft = b + 2 * nt, w->t.d2 = b + 3 * nt, w->t.en = b + 4 * nt;
    w->sorted = b + 6 * nt;
    w->s.part = w->iblock;
    w->t.part = w->iblock + ns;
    return AMSCR_OK;
}

/* Partners of the nq points q on the closed polyline `onto` (no points): the nearest vertex
 * (global: through the grid, else near the last partner), then the closest point of its edges. */
static void pair_side(const double *q, size_t nq, const double *onto, size_t no, const grid_t *g, int global,
                      curve_t *c)
{
    for (size_t j = 0; j < nq; j++) {
        double qx = q[2 * j], qy = q[2 * j + 1], d;
        size_t v = global ? grid_nearest(g, onto, qx, qy, &d) : local_nearest(onto, no, c->part[j], qx, qy, &d);
        c->d2[j] = foot(onto, no, v, qx, qy, &c->part[j], &c->ft[j]);
    }
}

/* X applied to the source points, the normals of the mapped curve, and both sides' partners. */
static int pair_all(polish_t *w, const double X[6], int global)
{
    const double *s = w->s.p;
    for (size_t i = 0; i < w->s.n; i++) {
        w->mapped[2 * i] = X[0] * s[2 * i] + X[1] * s[2 * i + 1] + X[2];
        w->mapped[2 * i + 1] = X[3] * s[2 * i] + X[4] * s[2 * i + 1] + X[5];
    }
    edge_normals(w->mapped, w->s.n, w->s.en);
    if (global && !grid_build(&w->gm, w->mapped, w->s.n))
        return 0;
    pair_side(w->t.p, w->t.n, w->mapped, w->s.n, &w->gm, global, &w->t);
    pair_side(w->mapped, w->s.n, w->t.p, w->t.n, &w->gt, global, &w->s);
    return 1;
}

/* Adds weight (n . (X [sx sy 1] - t))^2 to the normal equations of X = {a11 a12 b1 a21 a22 b2}. */
static void add_row(double N[36], double rhs[6], double weight, double sx, double sy, double nx, double ny, double tx,
                    double ty)
{
    double g[6] = {nx * sx, nx * sy, nx, ny * sx, ny * sy, ny}, v = weight * (nx * tx + ny * ty);
    for (int i = 0; i < 6; i++) {
        double wg = weight * g[i];
        for (int j = i; j < 6; j++) /* upper triangle: mirrored before the solve */
            N[6 * i + j] += wg * g[j];
        rhs[i] += g[i] * v;
    }
}

/* The cut of one side's squared distances: RESID_K times their median. */
static double side_cut(const double *d2, size_t n, double *sorted)
{
    memcpy(sorted, d2, n * sizeof *sorted);
    return RESID_K * median(sorted, n);
}

/* One point-to-line step from the current pairs into X; *moved: the RMS displacement of the
 * source. Returns 0 when the system is singular. */
static int polish_step(polish_t *w, double X[6], double *moved)
{
    double N[36] = {0}, rhs[6] = {0};
    const curve_t *s = &w->s, *t = &w->t;
    double cut = side_cut(t->d2, t->n, w->sorted), kept = 0;
    for (size_t j = 0; j < t->n; j++)
        kept += t->d2[j] <= cut;
    for (size_t j = 0; j < t->n; j++) /* target points onto the mapped source's edges */
        if (t->d2[j] <= cut) {
            size_t a = t->part[j], b = (a + 1) % s->n;
            double u = t->ft[j];
            add_row(N, rhs, w->wt / kept, s->p[2 * a] + u * (s->p[2 * b] - s->p[2 * a]),
                    s->p[2 * a + 1] + u * (s->p[2 * b + 1] - s->p[2 * a + 1]), s->en[2 * a], s->en[2 * a + 1],
                    t->p[2 * j], t->p[2 * j + 1]);
        }
    cut = side_cut(s->d2, s->n, w->sorted);
    kept = 0;
    for (size_t i = 0; i < s->n; i++)
        kept += s->d2[i] <= cut;
    for (size_t i = 0; i < s->n; i++) /* mapped source points onto the target's edges */
        if (s->d2[i] <= cut) {
            size_t a = s->part[i], b = (a + 1) % t->n;
            double u = s->ft[i];
            add_row(N, rhs, w->ws / kept, s->p[2 * i], s->p[2 * i + 1], t->en[2 * a], t->en[2 * a + 1],
                    t->p[2 * a] + u * (t->p[2 * b] - t->p[2 * a]), t->p[2 * a + 1] + u * (t->p[2 * b + 1] - t->p[2 * a + 1]));
        }
    for (int i = 1; i < 6; i++)
        for (int j = 0; j < i; j++)
            N[6 * i + j] = N[6 * j + i];
    if (!amscr__gauss_solve(N, rhs, 6))
        return 0;
    double m2 = 0.0;
    for (int k = 0; k < 6; k++)
        if (!isfinite(rhs[k]))
            return 0;
    for (size_t i = 0; i < s->n; i++) {
        double x = s->p[2 * i], y = s->p[2 * i + 1];
        double dx = (rhs[0] - X[0]) * x + (rhs[1] - X[1]) * y + rhs[2] - X[2];
        double dy = (rhs[3] - X[3]) * x + (rhs[4] - X[4]) * y + rhs[5] - X[5];
        m2 += dx * dx + dy * dy;
    }
    *moved = sqrt(m2 / (double)s->n);
    memcpy(X, rhs, 6 * sizeof *X);
    return 1;
}

/* Mean of the lowest RANK_KEEP share of n squared distances. */
static double kept_mean(const double *d2, size_t n, double *sorted)
{
    size_t keep = (size_t)(RANK_KEEP * (double)n);
    keep = keep ? keep : 1;
    memcpy(sorted, d2, n * sizeof *sorted);
    amscr__select_kth(sorted, n, keep - 1);
    double sum = 0.0;
    for (size_t k = 0; k < keep; k++)
        sum += sorted[k];
    return sum / (double)keep;
}

/* The two-way trimmed cost of the current pairs. */
static double rank_cost(polish_t *w)
{
    return w->wt * kept_mean(w->t.d2, w->t.n, w->sorted) + w->ws * kept_mean(w->s.d2, w->s.n, w->sorted);
}

/* Polishes X in place; returns its ranking cost (INFINITY when it failed: X is then as given). */
static double polish_one(polish_t *w, double X[6], int iters)
{
    double Y[6], moved = 0.0;
    memcpy(Y, X, sizeof Y);
    if (!pair_all(w, Y, 1))
        return INFINITY;
    for (int it = 0; it < iters; it++) {
        if (!polish_step(w, Y, &moved) || !pair_all(w, Y, 0))
            return INFINITY;
        if (moved < POLISH_TOL)
            break;
    }
    double c = rank_cost(w);
    if (isfinite(c))
        memcpy(X, Y, sizeof Y);
    return isfinite(c) ? c : INFINITY;
}

/* Loads both curves into the normalized frames and measures their noise; sets the weights. */
static int polish_prepare(polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6])
{
    double Y[6];
    load_curve(f, &w->s);
    load_curve(h, &w->t);
    to_frames(w, f, h, X, Y);
    if (w->s.n < 3 || w->t.n < 3)
        return 0;
    w->s.rough = roughness(w->s.p, w->s.n, w->sorted);
    w->t.rough = roughness(w->t.p, w->t.n, w->sorted);
    edge_normals(w->t.p, w->t.n, w->t.en);
    double rs = w->s.rough * fabs(Y[0] * Y[4] - Y[1] * Y[3]), rt = w->t.rough;
    w->wt = rt / (rs + rt);
    w->ws = rs / (rs + rt);
    return grid_build(&w->gt, w->t.p, w->t.n);
}

/* The start maps: the chosen one first, then — when the search could not tell its candidates
 * apart (ambiguity at least AMBIGUOUS_SEARCH) — each candidate that differs from all before. */
static size_t polish_starts(const amscr_descriptor *f, const match_t *m, double S[][6])
{
    size_t count = 1;
    memcpy(S[0], m->X, sizeof S[0]);
    for (size_t c = 0; m->ambiguity >= AMBIGUOUS_SEARCH && c < m->ncand; c++) {
        int fresh = 1;
        for (size_t k = 0; k < count && fresh; k++)
            fresh = amscr__map_gap2(f, m->cand[c], S[k]) > AMSCR__DISTINCT_GAP2;
        if (fresh)
            memcpy(S[count++], m->cand[c], sizeof S[0]);
    }
    return count;
}

/* The ambiguity of start `best` among the polished starts S (costs cost): its cost over the
 * best cost of a clearly different map (1: as good; 0: none). */
static double polished_ambiguity(const amscr_descriptor *f, double S[][6], const double *cost, size_t count,
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

amscr_status amscr__polish(const amscr_descriptor *f, const amscr_descriptor *h, match_t *m)
{
    polish_t w;
    amscr_status st = polish_alloc(f->nraw, h->nraw, &w);
    if (st != AMSCR_OK)
        return st;
    double S[1 + 2 * AMSCR__CANDIDATES][6], Y[1 + 2 * AMSCR__CANDIDATES][6], cost[1 + 2 * AMSCR__CANDIDATES];
    size_t count = polish_starts(f, m, S), best = count;
    if (polish_prepare(&w, f, h, m->X)) {
        for (size_t k = 0; k < count; k++) { /* every start a few steps, ranked */
            to_frames(&w, f, h, S[k], Y[k]);
            cost[k] = polish_one(&w, Y[k], SCORE_ITERS);
            from_frames(&w, f, h, Y[k], S[k]);
            if (cost[k] < (best < count ? cost[best] : INFINITY))
                best = k;
        }
    }
    if (best < count) { /* the winner polished on */
        double c = polish_one(&w, Y[best], POLISH_ITERS - SCORE_ITERS);
        if (count > 1)
            m->ambiguity = polished_ambiguity(f, S, cost, count, best);
        if (c < INFINITY)
            from_frames(&w, f, h, Y[best], S[best]);
        memcpy(m->X, S[best], sizeof m->X);
    }
    polish_free(&w);
    return AMSCR_OK;
}
