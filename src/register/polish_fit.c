/* polish_fit.c — the fit behind the polish (polish.c has the method, the stage that ranks the
 * starts, and why): the input curves in frames that keep their metric, their roughness (the
 * median squared second difference) and gaps, and one start's trimmed two-way point-to-line
 * Gauss-Newton fit from the smoother curve onto the rougher. */
#include "polish_fit.h"

#include "dense.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Converged when a step moves the curve by less than this RMS (frame of RMS radius sqrt 2:
 * 0.007 % of the size, far below any error that matters). */
#define POLISH_TOL 1e-4
/* Adaptive trimming: pairs within RESID_K (AMSCR__TRIM_K, match.h) times the median squared
 * distance. */
#define RESID_K AMSCR__TRIM_K
/* A polish refines a map; one that changed the moved curve's area by more than this factor
 * (or flipped it) collapsed instead: a fragment paired only onto the target can always shrink
 * onto a small piece of it (measured: a 50 % fragment of device6 onto 0.2 % of the target,
 * confidence 0.64). Such a result is refused and the map kept as it was. */
#define MAX_AREA_CHANGE 2.0
/* Each direction of the ranking cost keeps this share of its pairs (recover.c's rule). */
#define RANK_KEEP 0.7
/* An edge longer than GAP_RATIO times the curve's median edge is a gap (the chord that closes a
 * contour across a missing run), not boundary: nothing is paired onto it. */
#define GAP_RATIO 8.0
/* Roughness: for Gaussian noise of variance s^2 per coordinate, a second difference has
 * variance 6 s^2 per coordinate, and its squared length's median is 6 s^2 * 2 ln 2. */
#define ROUGH_DIV (6.0 * 2.0 * 0.6931471805599453)
/* Roughness below this share of the size^2 (a clean curve's rounding) counts as this much, so
 * two clean curves share the weight evenly. */
#define ROUGH_FLOOR 1e-10

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

void amscr__polish_to_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6],
                             double Y[6])
{
    double a[6], b[6];
    amscr__affine_compose(X, f->fwd, a);
    amscr__affine_compose(a, w->src.unsim, b);
    amscr__affine_compose(h->inv, b, a);
    amscr__affine_compose(w->tgt.sim, a, b);
    if (w->a == &w->src || !amscr__affine_inverse(b, Y))
        memcpy(Y, b, sizeof b);
}

void amscr__polish_from_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h,
                               const double Y[6], double X[6])
{
    double a[6], b[6];
    if (w->a == &w->src || !amscr__affine_inverse(Y, b))
        memcpy(b, Y, sizeof b);
    amscr__affine_compose(b, w->src.sim, a);
    amscr__affine_compose(a, f->inv, b);
    amscr__affine_compose(w->tgt.unsim, b, a);
    amscr__affine_compose(h->fwd, a, X);
}

void amscr__polish_free(polish_t *w)
{
    amscr__grid_free(&w->gb);
    amscr__grid_free(&w->gm);
    free(w->block);
    free(w->iblock);
}

/* Carves one curve's arrays (n points) from *b and *ib. */
static void curve_carve(curve_t *c, size_t n, double **b, size_t **ib)
{
    c->p = *b, c->en = *b + 2 * n, c->ft = *b + 4 * n, c->d2 = *b + 5 * n;
    *b += 6 * n;
    c->part = *ib;
    c->gap = *ib + n;
    *ib += 2 * n;
}

amscr_status amscr__polish_alloc(size_t ns, size_t nt, polish_t *w)
{
    memset(w, 0, sizeof *w);
    size_t nm = ns > nt ? ns : nt;
    w->block = amscr__malloc_array(6 * (ns + nt) + 3 * nm, sizeof *w->block);
    w->iblock = amscr__malloc_array(2 * (ns + nt), sizeof *w->iblock);
    if (!w->block || !w->iblock) {
        amscr__polish_free(w);
        return amscr__fail(AMSCR_E_NOMEM, "registration polish: out of memory");
    }
    double *b = w->block;
    size_t *ib = w->iblock;
    curve_carve(&w->src, ns, &b, &ib);
    curve_carve(&w->tgt, nt, &b, &ib);
    w->moved = b;
    w->sorted = b + 2 * nm;
    return AMSCR_OK;
}

/* Flags the edges of c longer than GAP_RATIO times its median edge (sorted: scratch). */
static void find_gaps(curve_t *c, double *sorted)
{
    for (size_t i = 0; i < c->n; i++) {
        size_t e = (i + 1) % c->n;
        double dx = c->p[2 * e] - c->p[2 * i], dy = c->p[2 * e + 1] - c->p[2 * i + 1];
        sorted[i] = dx * dx + dy * dy;
    }
    double cut = GAP_RATIO * GAP_RATIO * median(sorted, c->n);
    for (size_t i = 0; i < c->n; i++) {
        size_t e = (i + 1) % c->n;
        double dx = c->p[2 * e] - c->p[2 * i], dy = c->p[2 * e + 1] - c->p[2 * i + 1];
        c->gap[i] = dx * dx + dy * dy > cut;
    }
}

/* Partners of the nq points q on the closed polyline `onto` (the points of curve oc, maybe
 * moved): the nearest vertex (global: through the grid, else near the last partner), then the
 * closest point of its edges; a partner on a gap edge gets distance +inf (never paired). */
static void pair_side(const double *q, size_t nq, const double *onto, const curve_t *oc, const amscr__grid *g,
                      int global, curve_t *c)
{
    for (size_t j = 0; j < nq; j++) {
        double qx = q[2 * j], qy = q[2 * j + 1], d;
        size_t v = global ? amscr__grid_nearest(g, onto, qx, qy, &d)
                          : amscr__local_nearest(onto, oc->n, c->part[j], qx, qy, &d);
        c->d2[j] = amscr__edge_foot(onto, oc->n, v, qx, qy, &c->part[j], &c->ft[j]);
        if (oc->gap[c->part[j]])
            c->d2[j] = INFINITY;
    }
}

/* Y applied to a's points, the normals of the moved curve, and both sides' partners. */
static int pair_all(polish_t *w, const double Y[6], int global)
{
    const curve_t *a = w->a;
    for (size_t i = 0; i < a->n; i++) {
        w->moved[2 * i] = Y[0] * a->p[2 * i] + Y[1] * a->p[2 * i + 1] + Y[2];
        w->moved[2 * i + 1] = Y[3] * a->p[2 * i] + Y[4] * a->p[2 * i + 1] + Y[5];
    }
    if (!w->partial) { /* b's points onto the moved a */
        amscr__edge_normals(w->moved, a->n, w->a->en);
        int g = global ? amscr__grid_build(&w->gm, w->moved, a->n) : 1;
        w->nomem = w->nomem || g < 0;
        if (g <= 0)
            return 0;
        pair_side(w->b->p, w->b->n, w->moved, w->a, &w->gm, global, w->b);
    }
    pair_side(w->moved, a->n, w->b->p, w->b, &w->gb, global, w->a);
    return 1;
}

/* Adds weight (n . (Y [sx sy 1] - t))^2 to the normal equations of Y = {a11 a12 b1 a21 a22 b2}. */
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

/* The cut of one side's squared distances (RESID_K times their median) and how many it keeps. */
static double side_cut(const curve_t *c, double *sorted, double *kept)
{
    memcpy(sorted, c->d2, c->n * sizeof *sorted);
    double cut = RESID_K * median(sorted, c->n);
    *kept = 0.0;
    for (size_t i = 0; i < c->n; i++)
        *kept += c->d2[i] <= cut && isfinite(c->d2[i]);
    return cut;
}

/* The point on edge `seg` of polyline p (n) at position t. */
static void edge_point(const double *p, size_t n, size_t seg, double t, double *x, double *y)
{
    size_t e = (seg + 1) % n;
    *x = p[2 * seg] + t * (p[2 * e] - p[2 * seg]);
    *y = p[2 * seg + 1] + t * (p[2 * e + 1] - p[2 * seg + 1]);
}

/* The normal equations of one step from the current pairs. */
static void step_system(const polish_t *w, double N[36], double rhs[6])
{
    const curve_t *a = w->a, *b = w->b;
    double kept = 0.0, cut = w->partial ? -1.0 : side_cut(b, w->sorted, &kept), x, y;
    for (size_t j = 0; j < b->n && !w->partial; j++) /* b's points onto the moved a's edges */
        if (b->d2[j] <= cut && isfinite(b->d2[j])) {
            size_t s = b->part[j];
            edge_point(a->p, a->n, s, b->ft[j], &x, &y);
            add_row(N, rhs, w->wb / kept, x, y, a->en[2 * s], a->en[2 * s + 1], b->p[2 * j], b->p[2 * j + 1]);
        }
    cut = side_cut(a, w->sorted, &kept);
    for (size_t i = 0; i < a->n; i++) /* the moved a's points onto b's edges */
        if (a->d2[i] <= cut && isfinite(a->d2[i])) {
            size_t s = a->part[i];
            edge_point(b->p, b->n, s, a->ft[i], &x, &y);
            add_row(N, rhs, w->wa / kept, a->p[2 * i], a->p[2 * i + 1], b->en[2 * s], b->en[2 * s + 1], x, y);
        }
}

/* One point-to-line step from the current pairs into Y; *moved: the RMS displacement of a.
 * Returns 0 when the system is singular. */
static int polish_step(polish_t *w, double Y[6], double *moved)
{
    double N[36] = {0}, rhs[6] = {0}, m2 = 0.0;
    step_system(w, N, rhs);
    for (int i = 1; i < 6; i++)
        for (int j = 0; j < i; j++)
            N[6 * i + j] = N[6 * j + i];
    if (!amscr__gauss_solve(N, rhs, 6))
        return 0;
    for (int k = 0; k < 6; k++)
        if (!isfinite(rhs[k]))
            return 0;
    const curve_t *a = w->a;
    for (size_t i = 0; i < a->n; i++) {
        double x = a->p[2 * i], y = a->p[2 * i + 1];
        double dx = (rhs[0] - Y[0]) * x + (rhs[1] - Y[1]) * y + rhs[2] - Y[2];
        double dy = (rhs[3] - Y[3]) * x + (rhs[4] - Y[4]) * y + rhs[5] - Y[5];
        m2 += dx * dx + dy * dy;
    }
    *moved = sqrt(m2 / (double)a->n);
    memcpy(Y, rhs, 6 * sizeof *Y);
    return 1;
}

/* Mean of the lowest `share` of a side's squared distances. */
static double kept_share(const curve_t *c, double *sorted, double share)
{
    size_t keep = (size_t)(share * (double)c->n);
    keep = keep ? keep : 1;
    memcpy(sorted, c->d2, c->n * sizeof *sorted);
    amscr__select_kth(sorted, c->n, keep - 1);
    double sum = 0.0;
    for (size_t k = 0; k < keep; k++)
        sum += sorted[k];
    return sum / (double)keep;
}

/* Mean of the lowest RANK_KEEP share of a side's squared distances. */
static double kept_mean(const curve_t *c, double *sorted) { return kept_share(c, sorted, RANK_KEEP); }

/* The two-way trimmed cost of the current pairs. */
static double rank_cost(polish_t *w)
{
    return (w->partial ? 0.0 : w->wb * kept_mean(w->b, w->sorted)) + w->wa * kept_mean(w->a, w->sorted);
}

double amscr__polish_tie_cost(polish_t *w, const double Y[6], double share)
{
    if (!pair_all(w, Y, 1))
        return INFINITY;
    return (w->partial ? 0.0 : w->wb * kept_share(w->b, w->sorted, share)) +
           w->wa * kept_share(w->a, w->sorted, share);
}

double amscr__polish_one(polish_t *w, double Y[6], int iters)
{
    double Z[6], moved = 0.0, det0 = Y[0] * Y[4] - Y[1] * Y[3];
    memcpy(Z, Y, sizeof Z);
    if (!pair_all(w, Z, 1))
        return INFINITY;
    for (int it = 0; it < iters; it++) {
        if (!polish_step(w, Z, &moved) || !pair_all(w, Z, 0))
            return INFINITY;
        if (moved < POLISH_TOL)
            break;
    }
    double c = rank_cost(w), ratio = (Z[0] * Z[4] - Z[1] * Z[3]) / det0;
    if (!isfinite(c) || !(ratio >= 1.0 / MAX_AREA_CHANGE && ratio <= MAX_AREA_CHANGE))
        return INFINITY;
    memcpy(Y, Z, sizeof Z);
    return c;
}

int amscr__polish_prepare(polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6],
                          int partial)
{
    double Y[6];
    w->partial = partial;
    load_curve(f, &w->src);
    load_curve(h, &w->tgt);
    if (w->src.n < 3 || w->tgt.n < 3)
        return 0;
    w->src.rough = roughness(w->src.p, w->src.n, w->sorted);
    w->tgt.rough = roughness(w->tgt.p, w->tgt.n, w->sorted);
    find_gaps(&w->src, w->sorted);
    find_gaps(&w->tgt, w->sorted);
    w->a = &w->src; /* to_frames below: source -> target */
    amscr__polish_to_frames(w, f, h, X, Y);
    double rs = w->src.rough * fabs(Y[0] * Y[4] - Y[1] * Y[3]), rt = w->tgt.rough;
    int keep = rs <= rt || partial; /* a fragment is always the moved curve, paired alone */
    w->a = keep ? &w->src : &w->tgt;
    w->b = keep ? &w->tgt : &w->src;
    double ra = keep ? rs : rt, rb = keep ? rt : rs;
    w->wb = partial ? 0.0 : rb / (ra + rb);
    w->wa = partial ? 1.0 : ra / (ra + rb);
    amscr__edge_normals(w->b->p, w->b->n, w->b->en);
    return amscr__grid_build(&w->gb, w->b->p, w->b->n);
}

int amscr__polish_has_gap(const curve_t *c)
{
    for (size_t i = 0; i < c->n; i++)
        if (c->gap[i])
            return 1;
    return 0;
}
