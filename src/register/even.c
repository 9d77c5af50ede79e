/* even.c — the polished map refined on the evidence that a noisy curve's points were taken
 * evenly along it.
 *
 * The order stage (ordered.c) lets each step of a noisy curve's order advance anywhere from 0 to
 * a few mean steps, so a long or thin part's position along itself stays loosely held (a spoon's
 * handle, a car stretched 5:1). Contours resampled to a point count are evenly spaced, though,
 * and then the index says where along the curve each point was taken: point i lies at the share
 * off + i / nb (or off - i / nb) of the moved curve's length. This stage fits the map and off to
 * that model by Levenberg-Marquardt (the residual of each point against its place; the places
 * move with the map, since the moved curve's arc length does: the Jacobian has both parts), and
 * keeps the result only where the points bear the model out (the gates below): unevenly sampled
 * points (a pen that slowed down, 1.25 : 1 on alternating quarters already) leave residuals 5 to
 * 800 times their distances from the curve, evenly sampled ones 1.7 to 2.6 times; points spaced
 * evenly along another version of the curve drift along it (Kuiper's test).
 *
 * Measured (docs/decisions.md; bench/registration_heldout.py, 280 held-out pairs, after the order stage): 2 % noise
 * within 2 %: 98.2 -> 99.6 %, median error 0.43 -> 0.27 %; 1 % noise median 0.22 -> 0.13 %. */
#include "even.h"

#include "dense.h"
#include "internal.h"
#include "match.h"
#include "nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Kept when the mean squared residual is at most this many times the mean squared distance from
 * the curve (even sampling: 2 in theory, 1.7 - 2.6 measured on 560 held-out pairs; 1.25 : 1
 * uneven sampling: 5.2 and more). */
#define EVEN_MAX_RATIO 3.0
/* Runs only when the points scatter across the curve by at least this share of their median
 * spacing (noise sigma; a pixel chain's staircase reads below it: its spacing says where its
 * points are) ... */
#define EVEN_MIN_SCATTER 0.35
/* ... and the map given explains them within this many times their own noise variance (mean
 * squared distance from the curve: 0.66 - 1.14 on the noisy held-out pairs; a missing run the
 * gap test did not see, 40 and more). */
#define EVEN_MAX_FIT 2.0
/* ... and where the residuals along the curve are white: Kuiper's statistic of their running sum
 * (its range over sd sqrt(nb); white noise exceeds 2.0 with probability 1 %) at most this. Points
 * taken evenly along another version of the curve (a smoothed contour, a 4-connected trace) drift
 * along it instead. Measured on the held-out contours at 1 and 2 % noise (bench/
 * registration_convention.py): 0.8 - 1.65 (5th - 95th percentile) when the points were taken
 * along the same polyline; 2.6 - 19.8 along a smoothed or 4-connected one, where the fit without
 * this test cost 2 % noise 95.7 -> 80.7 % within 2 %; beyond 4 on unevenly sampled points. */
#define EVEN_MAX_KUIPER 2.0
/* Probe points per observed point along the moved curve for the starting places. */
#define EVEN_PROBES 8
/* Parameters: the map's six and the offset. */
#define EVEN_NP 7
/* The fit starts from the offset found and from it +- this share of a spacing; the lowest cost
 * is kept (the cost is rough along the offset at that scale: a car stretched 5:1 ended 2.1 %
 * off from one start, 1.1 % from the others). */
#define EVEN_START_SHIFT 0.5
/* Levenberg-Marquardt: at most this many steps; the damping's start, factor and limit; the
 * relative fall in cost below which it stops. */
#define EVEN_ITERS 30
#define EVEN_MU0 1e-3
#define EVEN_MU_STEP 4.0
#define EVEN_MU_MAX 1e8
#define EVEN_TOL 1e-5
/* A result changing the map's area by more than this factor (or flipping it) is refused. */
#define EVEN_MAX_AREA 2.0
/* Fewest points for the fit. */
#define EVEN_MIN_POINTS 16

typedef struct {
    const double *a, *b;
    size_t na, nb;
    double dir;   /* +1: b runs with a's order, -1 against */
    double *cum;  /* na + 1 arc lengths of the moved a */
    double *grad; /* 4 (na + 1): their derivatives by the map's linear part (Y0 Y1 Y3 Y4) */
    int nomem;    /* an allocation failed */
} even_t;

/* The moved length of a's edge k under the linear part of x; into d (when not NULL) its
 * derivatives by Y0, Y1, Y3, Y4. */
static double edge_length(const even_t *e, const double x[EVEN_NP], size_t k, double d[4])
{
    size_t n = (k + 1) % e->na;
    double ex = e->a[2 * n] - e->a[2 * k], ey = e->a[2 * n + 1] - e->a[2 * k + 1];
    double mx = x[0] * ex + x[1] * ey, my = x[3] * ex + x[4] * ey, l = sqrt(mx * mx + my * my);
    if (d && l > 0.0)
        d[0] = mx * ex / l, d[1] = mx * ey / l, d[2] = my * ex / l, d[3] = my * ey / l;
    else if (d)
        d[0] = d[1] = d[2] = d[3] = 0.0;
    return l;
}

/* Fills e->cum (and e->grad when `grad`) for the map in x; returns the moved length (0 when
 * degenerate). */
static double moved_cum(const even_t *e, const double x[EVEN_NP], int grad)
{
    double d[4];
    e->cum[0] = 0.0;
    if (grad)
        memset(e->grad, 0, 4 * sizeof *e->grad);
    for (size_t k = 0; k < e->na; k++) {
        e->cum[k + 1] = e->cum[k] + edge_length(e, x, k, grad ? d : NULL);
        for (int q = 0; grad && q < 4; q++)
            e->grad[4 * (k + 1) + q] = e->grad[4 * k + q] + d[q];
    }
    double L = e->cum[e->na];
    return L > 0.0 && isfinite(L) ? L : 0.0;
}

/* The edge j of a holding the share phi (0..1) of the moved length L (e->cum), searched from
 * edge `from` (the places of successive points are near each other); the position along it
 * (0..1) into *f. */
static size_t locate(const even_t *e, double L, double phi, size_t from, double *f)
{
    double t = L * phi;
    size_t j = from < e->na ? from : 0;
    while (j + 1 < e->na && e->cum[j + 1] <= t)
        j++;
    while (j > 0 && e->cum[j] > t)
        j--;
    double len = e->cum[j + 1] - e->cum[j], g = len > 0.0 ? (t - e->cum[j]) / len : 0.0;
    *f = g < 0.0 ? 0.0 : g > 1.0 ? 1.0 : g;
    return j;
}

/* The point of a (its own frame) at position f of edge j. */
static void edge_point(const even_t *e, size_t j, double f, double q[2])
{
    size_t n = (j + 1) % e->na;
    q[0] = e->a[2 * j] + f * (e->a[2 * n] - e->a[2 * j]);
    q[1] = e->a[2 * j + 1] + f * (e->a[2 * n + 1] - e->a[2 * j + 1]);
}

/* The share of the moved length at which point i of b is placed. */
static double share(const even_t *e, const double x[EVEN_NP], size_t i)
{
    double u = x[6] + e->dir * (double)i / (double)e->nb;
    return u - floor(u);
}

/* The sum of squared residuals of b against their places for the parameters x (INFINITY for a
 * degenerate map). */
static double cost(const even_t *e, const double x[EVEN_NP])
{
    double L = moved_cum(e, x, 0), ss = 0.0, q[2], f;
    if (L == 0.0)
        return INFINITY;
    for (size_t i = 0, j = 0; i < e->nb; i++) {
        j = locate(e, L, share(e, x, i), j, &f);
        edge_point(e, j, f, q);
        double rx = x[0] * q[0] + x[1] * q[1] + x[2] - e->b[2 * i];
        double ry = x[3] * q[0] + x[4] * q[1] + x[5] - e->b[2 * i + 1];
        ss += rx * rx + ry * ry;
    }
    return isfinite(ss) ? ss : INFINITY;
}

/* Point i's two Jacobian rows Jx, Jy by the parameters (the place moves with the map, since the
 * moved length does) and its residual r; the moved length L and e->cum / e->grad are x's. The
 * place's edge is searched from `from`; returns it. */
static size_t point_rows(const even_t *e, const double x[EVEN_NP], double L, size_t i, size_t from,
                         double Jx[EVEN_NP], double Jy[EVEN_NP], double r[2])
{
    double f, q[2], phi = share(e, x, i), dl[4];
    size_t j = locate(e, L, phi, from, &f);
    edge_point(e, j, f, q);
    double len = e->cum[j + 1] - e->cum[j], ex = 0.0, ey = 0.0;
    for (int k = 0; k < 4; k++)
        dl[k] = e->grad[4 * (j + 1) + k] - e->grad[4 * j + k];
    if (len > 0.0) { /* the moved edge per unit of arc length */
        size_t n = (j + 1) % e->na;
        double ax = e->a[2 * n] - e->a[2 * j], ay = e->a[2 * n + 1] - e->a[2 * j + 1];
        ex = (x[0] * ax + x[1] * ay) / len, ey = (x[3] * ax + x[4] * ay) / len;
    }
    static const int lin[4] = {0, 1, 3, 4};
    double direct[4][2] = {{q[0], 0.0}, {q[1], 0.0}, {0.0, q[0]}, {0.0, q[1]}};
    for (int k = 0; k < 4; k++) { /* d(arc length to the place) = phi dL - dcum_j - f dlen_j */
        double dt = phi * e->grad[4 * e->na + k] - e->grad[4 * j + k] - f * dl[k];
        Jx[lin[k]] = direct[k][0] + ex * dt;
        Jy[lin[k]] = direct[k][1] + ey * dt;
    }
    Jx[2] = 1.0, Jy[2] = 0.0, Jx[5] = 0.0, Jy[5] = 1.0;
    Jx[6] = ex * L, Jy[6] = ey * L;
    r[0] = x[0] * q[0] + x[1] * q[1] + x[2] - e->b[2 * i];
    r[1] = x[3] * q[0] + x[4] * q[1] + x[5] - e->b[2 * i + 1];
    return j;
}

/* The normal equations N (EVEN_NP^2) and gradient g = J^T r at x; returns the cost there
 * (INFINITY for a degenerate map). */
static double normal_equations(const even_t *e, const double x[EVEN_NP], double N[EVEN_NP * EVEN_NP],
                               double g[EVEN_NP])
{
    double L = moved_cum(e, x, 1), ss = 0.0, Jx[EVEN_NP], Jy[EVEN_NP], r[2];
    if (L == 0.0)
        return INFINITY;
    memset(N, 0, EVEN_NP * EVEN_NP * sizeof *N);
    memset(g, 0, EVEN_NP * sizeof *g);
    for (size_t i = 0, j = 0; i < e->nb; i++) {
        j = point_rows(e, x, L, i, j, Jx, Jy, r);
        ss += r[0] * r[0] + r[1] * r[1];
        for (int c = 0; c < EVEN_NP; c++) {
            g[c] += Jx[c] * r[0] + Jy[c] * r[1];
            for (int d = 0; d <= c; d++)
                N[c * EVEN_NP + d] += Jx[c] * Jx[d] + Jy[c] * Jy[d];
        }
    }
    for (int c = 0; c < EVEN_NP; c++)
        for (int d = c + 1; d < EVEN_NP; d++)
            N[c * EVEN_NP + d] = N[d * EVEN_NP + c];
    return isfinite(ss) ? ss : INFINITY;
}

/* The damped step (N + mu diag N) step = -g, solved with N scaled to a unit diagonal. Returns 0
 * when singular. */
static int damped_step(const double N[EVEN_NP * EVEN_NP], const double g[EVEN_NP], double mu, double step[EVEN_NP])
{
    double A[EVEN_NP * EVEN_NP], D[EVEN_NP];
    for (int c = 0; c < EVEN_NP; c++) {
        if (!(N[c * EVEN_NP + c] > 0.0))
            return 0;
        D[c] = 1.0 / sqrt(N[c * EVEN_NP + c]);
    }
    for (int c = 0; c < EVEN_NP; c++) {
        for (int d = 0; d < EVEN_NP; d++)
            A[c * EVEN_NP + d] = N[c * EVEN_NP + d] * D[c] * D[d];
        A[c * EVEN_NP + c] += mu;
        step[c] = -g[c] * D[c];
    }
    if (!amscr__gauss_solve(A, step, EVEN_NP))
        return 0;
    for (int c = 0; c < EVEN_NP; c++)
        step[c] *= D[c];
    return 1;
}

/* The fall in cost the linear model predicts for the step. */
static double predicted_fall(const double N[EVEN_NP * EVEN_NP], const double g[EVEN_NP], const double step[EVEN_NP])
{
    double fall = 0.0;
    for (int c = 0; c < EVEN_NP; c++) {
        double nc = 0.0;
        for (int d = 0; d < EVEN_NP; d++)
            nc += N[c * EVEN_NP + d] * step[d];
        fall -= 2.0 * g[c] * step[c] + step[c] * nc;
    }
    return fall;
}

/* Levenberg-Marquardt from x (refined in place); returns the cost of the result. It stops when
 * a step would lower the cost by less than EVEN_TOL of it (taken or, by the linear model,
 * foreseen). */
static double levenberg_marquardt(const even_t *e, double x[EVEN_NP])
{
    double N[EVEN_NP * EVEN_NP], g[EVEN_NP], step[EVEN_NP], y[EVEN_NP], mu = EVEN_MU0;
    double now = normal_equations(e, x, N, g);
    for (int it = 0; it < EVEN_ITERS && now < INFINITY; it++) {
        double c = INFINITY;
        for (; mu <= EVEN_MU_MAX; mu *= EVEN_MU_STEP) {
            if (!damped_step(N, g, mu, step))
                continue;
            if (predicted_fall(N, g, step) <= EVEN_TOL * now)
                return now;
            for (int k = 0; k < EVEN_NP; k++)
                y[k] = x[k] + step[k];
            if ((c = cost(e, y)) < now)
                break;
        }
        if (!(c < now))
            break;
        memcpy(x, y, sizeof y);
        mu /= EVEN_MU_STEP;
        if (now - c <= EVEN_TOL * c)
            return c;
        now = normal_equations(e, x, N, g);
    }
    return now;
}

/* v wrapped into [-1/2, 1/2). */
static double wrap_share(double v)
{
    return v - floor(v + 0.5);
}

/* Sets e->dir (the way most steps between the places go) and x[6] (the circular median of place
 * minus even advance) from the places k (of K probes) of b's points; s (nb) is scratch. */
static void start_offset(even_t *e, const long *k, size_t K, double x[EVEN_NP], double *s)
{
    size_t nb = e->nb;
    double turn = 0.0, c = 0.0, si = 0.0;
    for (size_t i = 1; i < nb; i++) { /* the majority of the steps (noise makes big ones both ways) */
        double d = wrap_share((double)(k[i] - k[i - 1]) / (double)K);
        turn += (d > 0.0) - (d < 0.0);
    }
    e->dir = turn < 0.0 ? -1.0 : 1.0;
    for (size_t i = 0; i < nb; i++) {
        s[i] = (double)k[i] / (double)K - e->dir * (double)i / (double)nb;
        c += cos(2.0 * AMSCR__PI * s[i]), si += sin(2.0 * AMSCR__PI * s[i]);
    }
    double mean = atan2(si, c) / (2.0 * AMSCR__PI);
    for (size_t i = 0; i < nb; i++)
        s[i] = wrap_share(s[i] - mean);
    amscr__select_kth(s, nb, nb / 2);
    x[6] = mean + s[nb / 2];
}

/* The starting parameters: Y, and the offset from each point's nearest of EVEN_PROBES * nb
 * probes evenly along Y a (start_offset). Returns the points' mean squared distance from the
 * curve (INFINITY when it cannot). */
static double start_places(even_t *e, const double Y[6], double x[EVEN_NP])
{
    size_t K = EVEN_PROBES * e->nb, nb = e->nb;
    double *p = amscr__malloc_array(2 * K + nb, sizeof *p), d2 = 0.0, q[2], f, one;
    long *k = amscr__malloc_array(nb, sizeof *k);
    amscr__grid g = {0};
    memcpy(x, Y, 6 * sizeof *x);
    double L = moved_cum(e, x, 0);
    e->nomem = !p || !k;
    int ok = p && k && L > 0.0;
    for (size_t j = 0, s = 0; ok && j < K; j++) {
        s = locate(e, L, (double)j / (double)K, s, &f);
        edge_point(e, s, f, q);
        p[2 * j] = Y[0] * q[0] + Y[1] * q[1] + Y[2], p[2 * j + 1] = Y[3] * q[0] + Y[4] * q[1] + Y[5];
    }
    int built = ok ? amscr__grid_build(&g, p, K) : 0;
    e->nomem = e->nomem || built < 0;
    ok = built > 0;
    for (size_t i = 0; ok && i < nb; i++) {
        k[i] = (long)amscr__grid_nearest(&g, p, e->b[2 * i], e->b[2 * i + 1], &one);
        d2 += one / (double)nb;
    }
    if (ok)
        start_offset(e, k, K, x, p + 2 * K);
    amscr__grid_free(&g);
    free(p), free(k);
    return ok && isfinite(d2) ? d2 : INFINITY;
}

/* Whether b's points scatter across the curve by EVEN_MIN_SCATTER of their spacing (-1: out of
 * memory). */
static int scattered(const double *b, size_t nb, double rough_b)
{
    double *scratch = amscr__malloc_array(nb, sizeof *scratch);
    if (!scratch)
        return -1;
    double spacing = amscr__median_edge(b, nb, 1, scratch);
    free(scratch);
    return sqrt(rough_b) >= EVEN_MIN_SCATTER * spacing;
}

/* Kuiper's statistic of b's residuals along the moved curve (their component along the tangent
 * at each place) for the parameters x: the range of the running sum of their deviations from
 * their mean, over their sd times sqrt(nb); tau (nb) is scratch. */
static double along_kuiper(const even_t *e, const double x[EVEN_NP], double *tau)
{
    double L = moved_cum(e, x, 1), Jx[EVEN_NP], Jy[EVEN_NP], r[2], mean = 0.0, var = 0.0;
    if (L == 0.0)
        return INFINITY;
    for (size_t i = 0, j = 0; i < e->nb; i++) {
        j = point_rows(e, x, L, i, j, Jx, Jy, r); /* Jx[6], Jy[6]: the tangent times L */
        tau[i] = (r[0] * Jx[6] + r[1] * Jy[6]) / L;
        mean += tau[i] / (double)e->nb;
    }
    double sum = 0.0, lo = 0.0, hi = 0.0;
    for (size_t i = 0; i < e->nb; i++) {
        double d = tau[i] - mean;
        var += d * d / (double)e->nb;
        sum += d;
        lo = sum < lo ? sum : lo, hi = sum > hi ? sum : hi;
    }
    return var > 0.0 ? (hi - lo) / sqrt(var * (double)e->nb) : INFINITY;
}

/* The fit from x (the starting parameters) and from its result with the offset shifted by
 * +-EVEN_START_SHIFT of a spacing; the lowest-cost parameters into best. Returns their cost. */
static double fit_from_starts(const even_t *e, double x[EVEN_NP], double best[EVEN_NP])
{
    double low = levenberg_marquardt(e, x);
    memcpy(best, x, EVEN_NP * sizeof *best);
    for (int s = -1; s <= 1 && low < INFINITY; s += 2) {
        double y[EVEN_NP];
        memcpy(y, x, sizeof y);
        y[6] += EVEN_START_SHIFT * (double)s / (double)e->nb;
        double c = levenberg_marquardt(e, y);
        if (c < low)
            low = c, memcpy(best, y, sizeof y);
    }
    return low;
}

int amscr__even_fit(const double *a, size_t na, const double *b, size_t nb, double rough_b, double Y[6])
{
    if (na < 3 || nb < EVEN_MIN_POINTS || !(rough_b > 0.0))
        return 0;
    int sc = scattered(b, nb, rough_b);
    if (sc <= 0)
        return sc;
    even_t e = {.a = a, .b = b, .na = na, .nb = nb};
    double *block = amscr__malloc_array(5 * (na + 1) + nb, sizeof *block), x[EVEN_NP], best[EVEN_NP];
    if (!block)
        return -1;
    e.cum = block, e.grad = block + na + 1;
    double d2 = start_places(&e, Y, x);
    if (e.nomem) {
        free(block);
        return -1;
    }
    double low = d2 <= EVEN_MAX_FIT * rough_b ? fit_from_starts(&e, x, best) : INFINITY;
    int white = low < INFINITY && along_kuiper(&e, best, block + 5 * (na + 1)) <= EVEN_MAX_KUIPER;
    free(block);
    if (!white || !(low / (double)nb <= EVEN_MAX_RATIO * d2))
        return 0;
    double ratio = (best[0] * best[4] - best[1] * best[3]) / (Y[0] * Y[4] - Y[1] * Y[3]);
    if (!(ratio >= 1.0 / EVEN_MAX_AREA && ratio <= EVEN_MAX_AREA))
        return 0;
    memcpy(Y, best, 6 * sizeof *Y);
    return 1;
}
