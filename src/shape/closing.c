/* closing.c — a closed curve's silhouette closed at a scale (docs/method.md §10.4): the region
 * the curve bounds, drawn on a grid, closed morphologically by a disk of radius
 * c sqrt(area), and traced again. Cracks, slots and gaps narrower than the disk disappear from
 * the outline; parts, and inlets wider than it, stay. The inner distance takes its paths inside
 * this silhouette: a cut that reaches the outline no longer forces a detour around it.
 *
 * The grid: sqrt(area) spans AMSCR__CLOSING_GRID pixels (fewer when the curve is so elongated
 * that the grid would exceed AMSCR__CLOSING_PIXELS); a pixel is inside when its centre is
 * inside the curve (even-odd rule) or the curve passes through it, so parts thinner than a
 * pixel stay whole. The closing is two exact Euclidean distance transforms (Felzenszwalb and
 * Huttenlocher, "Distance transforms of sampled functions", Theory of Computing 2012): the
 * pixels within r of the region, then those farther than r from the rest. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define AMSCR__CLOSING_GRID 64.0
#define AMSCR__CLOSING_PIXELS ((size_t)1 << 20)
#define AMSCR__CLOSING_MAX_POINTS 4096
#define FAR 1e12 /* a squared distance beyond any on the grid */

typedef struct {
    double x0, y0, h; /* pixel (u, v) has its centre at (x0 + u h, y0 + v h) */
    size_t w, hgt;
    uint8_t *on;
} grid;

/* The grid over the curve's bounding box with a margin of r + 2 pixels, for a disk of radius r (*r_px
 * in pixels); 0 when no grid of at most AMSCR__CLOSING_PIXELS covers it. */
static int grid_size(const double *xy, size_t n, double s, double r, grid *g, double *r_px)
{
    double lo[2] = {xy[0], xy[1]}, hi[2] = {xy[0], xy[1]};
    for (size_t i = 1; i < n; i++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], xy[2 * i + d]);
            hi[d] = fmax(hi[d], xy[2 * i + d]);
        }
    double h = s / AMSCR__CLOSING_GRID;
    for (int tries = 0; tries < 64; tries++, h *= 1.25) {
        double pad = ceil(r / h) + 2.0;
        double w = floor((hi[0] - lo[0]) / h) + 1.0 + 2.0 * pad, hg = floor((hi[1] - lo[1]) / h) + 1.0 + 2.0 * pad;
        if (w * hg <= (double)AMSCR__CLOSING_PIXELS) {
            g->x0 = lo[0] - pad * h;
            g->y0 = lo[1] - pad * h;
            g->h = h;
            g->w = (size_t)w;
            g->hgt = (size_t)hg;
            *r_px = r / h;
            return 1;
        }
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The rows v whose centre line y crosses edge a-b ((a_y > y) != (b_y > y)): first..last-1. */
static void rows_crossed(const grid *g, const double *a, const double *b, size_t *first, size_t *last)
{
    double lo = (fmin(a[1], b[1]) - g->y0) / g->h, hi = (fmax(a[1], b[1]) - g->y0) / g->h;
    /* y = y0 + v h crosses when lo <= v < hi (the half-open rule of the even-odd test) */
    double f = ceil(lo), l = ceil(hi);
    *first = f < 0.0 ? 0 : (size_t)f;
    *last = l < 0.0 ? 0 : l > (double)g->hgt ? g->hgt : (size_t)l;
}

/* Pixels whose centre the curve encloses (even-odd: each row's crossings, counted, bucketed by
 * row and sorted), then every pixel the curve passes through. */
static amscr_status draw(const double *xy, size_t n, grid *g)
{
    size_t *start = amscr__calloc_array(g->hgt + 1, sizeof *start), total = 0, f, l;
    if (!start)
        return AMSCR_E_NOMEM;
    for (size_t i = 0; i < n; i++) {
        rows_crossed(g, xy + 2 * i, xy + 2 * ((i + 1) % n), &f, &l);
        for (size_t v = f; v < l; v++)
            start[v + 1]++;
    }
    for (size_t v = 0; v < g->hgt; v++)
        start[v + 1] += start[v];
    total = start[g->hgt];
    double *cross = amscr__malloc_array(total ? total : 1, sizeof *cross);
    size_t *fill = amscr__calloc_array(g->hgt, sizeof *fill);
    if (!cross || !fill) {
        free(start), free(cross), free(fill);
        return AMSCR_E_NOMEM;
    }
    for (size_t i = 0; i < n; i++) {
        const double *a = xy + 2 * i, *b = xy + 2 * ((i + 1) % n);
        rows_crossed(g, a, b, &f, &l);
        for (size_t v = f; v < l; v++) {
            double y = g->y0 + (double)v * g->h;
            cross[start[v] + fill[v]++] = ((a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1])) - g->x0) / g->h;
        }
    }
    for (size_t v = 0; v < g->hgt; v++) {
        double *c = cross + start[v];
        size_t m = start[v + 1] - start[v];
        qsort(c, m, sizeof *c, cmp_double);
        for (size_t k = 0; k + 1 < m; k += 2)
            for (double u = ceil(c[k]); u <= c[k + 1]; u += 1.0)
                g->on[v * g->w + (size_t)u] = 1;
    }
    free(start), free(cross), free(fill);
    for (size_t i = 0; i < n; i++) {
        const double *a = xy + 2 * i, *b = xy + 2 * ((i + 1) % n);
        double du = (b[0] - a[0]) / g->h, dv = (b[1] - a[1]) / g->h;
        size_t steps = (size_t)ceil(2.0 * hypot(du, dv)) + 1;
        for (size_t t = 0; t <= steps; t++) {
            double frac = (double)t / (double)steps;
            double u = (a[0] - g->x0) / g->h + frac * du, v = (a[1] - g->y0) / g->h + frac * dv;
            g->on[(size_t)floor(v + 0.5) * g->w + (size_t)floor(u + 0.5)] = 1;
        }
    }
    return AMSCR_OK;
}

/* The squared distance transform of f along one line of n samples, `step` apart, in place
 * (the lower envelope of parabolas). s: 2n + 1 doubles and n size_t of scratch. */
static void edt_line(double *f, size_t n, size_t step, double *s, size_t *v)
{
    double *g = s, *z = s + n;
    for (size_t q = 0; q < n; q++)
        g[q] = f[q * step];
    size_t k = 0;
    v[0] = 0;
    z[0] = -INFINITY;
    z[1] = INFINITY;
    for (size_t q = 1; q < n; q++) {
        double fq = g[q] + (double)q * (double)q, p, x;
        for (;;) {
            p = (double)v[k];
            x = (fq - (g[v[k]] + p * p)) / (2.0 * ((double)q - p));
            if (x > z[k] || k == 0)
                break;
            k--;
        }
        k++;
        v[k] = q;
        z[k] = x;
        z[k + 1] = INFINITY;
    }
    k = 0;
    for (size_t q = 0; q < n; q++) {
        while (z[k + 1] < (double)q)
            k++;
        double d = (double)q - (double)v[k];
        f[q * step] = d * d + g[v[k]];
    }
}

/* d[i] = the squared distance from pixel i to the nearest pixel where on[i] == want. */
static void edt(const uint8_t *on, uint8_t want, size_t w, size_t hgt, double *d, double *s, size_t *v)
{
    for (size_t i = 0; i < w * hgt; i++)
        d[i] = on[i] == want ? 0.0 : FAR;
    for (size_t u = 0; u < w; u++)
        edt_line(d + u, hgt, w, s, v);
    for (size_t r = 0; r < hgt; r++)
        edt_line(d + r * w, w, 1, s, v);
}

/* The closing of g->on by a disk of radius r pixels, in place. */
static amscr_status close_grid(grid *g, double r)
{
    size_t np = g->w * g->hgt, len = g->w > g->hgt ? g->w : g->hgt;
    double *d = amscr__malloc_array(np, sizeof *d), *s = amscr__malloc_array(2 * len + 1, sizeof *s);
    size_t *v = amscr__malloc_array(len, sizeof *v);
    if (!d || !s || !v) {
        free(d), free(s), free(v);
        return AMSCR_E_NOMEM;
    }
    double r2 = r * r;
    edt(g->on, 1, g->w, g->hgt, d, s, v); /* dilation: within r of the region */
    for (size_t i = 0; i < np; i++)
        g->on[i] = d[i] <= r2;
    edt(g->on, 0, g->w, g->hgt, d, s, v); /* erosion: farther than r from the rest */
    for (size_t i = 0; i < np; i++)
        g->on[i] = d[i] > r2;
    free(d), free(s), free(v);
    return AMSCR_OK;
}

/* The outline of the closed grid, back in the curve's coordinates (counter-clockwise). */
static amscr_status trace(const grid *g, double **out, size_t *out_n)
{
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_mask(g->on, g->w, g->hgt, g->w, 0, &c);
    if (st != AMSCR_OK)
        return st;
    for (size_t i = 0; i < c->n; i++) {
        c->xy[2 * i] = g->x0 + c->xy[2 * i] * g->h;
        c->xy[2 * i + 1] = g->y0 + c->xy[2 * i + 1] * g->h;
    }
    *out = c->xy;
    *out_n = c->n;
    c->xy = NULL;
    c->n = 0;
    amscr_contour_free(c);
    return AMSCR_OK;
}

amscr_status amscr__close_curve(const double *xy, size_t n, double c, double **out, size_t *out_n)
{
    *out = NULL;
    *out_n = 0;
    double s = n >= 3 ? sqrt(fabs(amscr__signed_area(xy, n))) : 0.0;
    grid g = {0};
    double r;
    if (!(s > 0.0) || !isfinite(s) || !(c > 0.0) || !grid_size(xy, n, s, c * s, &g, &r))
        return AMSCR_E_DEGENERATE;
    g.on = amscr__calloc_array(g.w * g.hgt, 1);
    amscr_status st = g.on ? draw(xy, n, &g) : AMSCR_E_NOMEM;
    if (st == AMSCR_OK)
        st = close_grid(&g, r);
    if (st == AMSCR_OK)
        st = trace(&g, out, out_n);
    free(g.on);
    return st;
}

amscr_status amscr__outline(const double *xy, size_t n, double c, double *V)
{
    size_t k = (n + AMSCR__CLOSING_MAX_POINTS - 1) / AMSCR__CLOSING_MAX_POINTS, m = 0;
    double *pts = amscr__malloc_array(2 * (n / (k ? k : 1) + 1), sizeof *pts), *out = NULL;
    if (!pts)
        return AMSCR_E_NOMEM;
    for (size_t i = 0; i < n; i += k, m++) {
        pts[2 * m] = xy[2 * i];
        pts[2 * m + 1] = xy[2 * i + 1];
    }
    size_t nout = 0;
    amscr_status st = amscr__close_curve(pts, m, c, &out, &nout);
    if (st == AMSCR_OK)
        st = amscr__resample_euclid(out, nout, 1, AMSCR__OUTLINE_N, V);
    free(pts);
    free(out);
    if (st != AMSCR_OK && st != AMSCR_E_NOMEM) {
        amscr__clear_error();
        st = AMSCR_E_DEGENERATE;
    }
    return st;
}
