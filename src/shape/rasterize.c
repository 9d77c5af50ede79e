/* rasterize.c — closed polygons on a pixel grid (docs/method.md §11.7), even-odd rule:
 *   amscr__crossings        a horizontal line's sorted crossings of a polygon (also the
 *                           overlap's strips, register/check.c);
 *   amscr__raster_cover     the pixels a polygon covers by at least half their area: what a
 *                           camera's area sampling and a threshold at half level make of it,
 *                           by AMSCR__RASTER_SS x AMSCR__RASTER_SS samples a pixel;
 *   amscr__raster_centres   the pixels whose centre a polygon contains: the binary image a
 *                           sub-pixel trace of a two-valued image came from.
 * Pixel (i, j) of a w x h grid is centred at (x0 + i, y0 + j), 255 on and 0 off. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Samples a pixel side for the coverage: its area is known to 1/128, finer than a threshold at
 * half level can tell. A resolution, not a constant chosen on data. */
#define AMSCR__RASTER_SS 8

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

size_t amscr__crossings(const double *P, size_t n, double y, double *xs)
{
    size_t c = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = i + 1 == n ? 0 : i + 1;
        double yi = P[2 * i + 1], yj = P[2 * j + 1];
        if ((yi <= y) != (yj <= y))
            xs[c++] = P[2 * i] + (y - yi) * (P[2 * j] - P[2 * i]) / (yj - yi);
    }
    qsort(xs, c, sizeof *xs, cmp_double);
    return c & ~(size_t)1;
}

/* The first of `cells` cells (cell q centred at q / k + offset) whose centre lies at or beyond x. */
static size_t first_at(double x, double offset, double k, size_t cells)
{
    double q = ceil((x - offset) * k);
    return !(q > 0.0) ? 0 : q >= (double)cells ? cells : (size_t)q; /* NaN: none */
}

/* Adds the samples of one sample line inside [xs[k], xs[k+1]) to the row's pixels: `part` holds
 * the partly covered end pixels' counts, `run` the difference array of the whole ones. */
static void add_spans(const double *xs, size_t c, double x0, size_t w, long *part, long *run)
{
    const size_t ss = AMSCR__RASTER_SS, cells = ss * w;
    const double offset = x0 - 0.5 + 0.5 / (double)ss; /* sample q at x0 - 0.5 + (q + 0.5) / ss */
    for (size_t k = 0; k < c; k += 2) {
        size_t qa = first_at(xs[k], offset, (double)ss, cells), qb = first_at(xs[k + 1], offset, (double)ss, cells);
        if (qa >= qb)
            continue;
        size_t pa = qa / ss, pb = (qb - 1) / ss;
        if (pa == pb) {
            part[pa] += (long)(qb - qa);
            continue;
        }
        part[pa] += (long)(ss * (pa + 1) - qa);
        part[pb] += (long)(qb - ss * pb);
        run[pa + 1] += (long)ss;
        run[pb] -= (long)ss;
    }
}

amscr_status amscr__raster_cover(const double *P, size_t n, long x0, long y0, size_t w, size_t h, uint8_t *out)
{
    const size_t ss = AMSCR__RASTER_SS;
    double *xs = amscr__malloc_array(n, sizeof *xs);
    long *part = amscr__malloc_array(2 * (w + 1), sizeof *part);
    if (!xs || !part) {
        free(xs);
        free(part);
        return amscr__fail(AMSCR_E_NOMEM, "rasterize: out of memory");
    }
    long *run = part + w + 1;
    for (size_t j = 0; j < h; j++) {
        memset(part, 0, 2 * (w + 1) * sizeof *part);
        for (size_t s = 0; s < ss; s++) {
            double y = (double)y0 + (double)j - 0.5 + ((double)s + 0.5) / (double)ss;
            add_spans(xs, amscr__crossings(P, n, y, xs), (double)x0, w, part, run);
        }
        long whole = 0;
        for (size_t i = 0; i < w; i++) {
            whole += run[i];
            out[j * w + i] = 2 * (part[i] + whole) >= (long)(ss * ss) ? 255 : 0;
        }
    }
    free(xs);
    free(part);
    return AMSCR_OK;
}

amscr_status amscr__raster_centres(const double *P, size_t n, long x0, long y0, size_t w, size_t h, uint8_t *out)
{
    double *xs = amscr__malloc_array(n, sizeof *xs);
    if (!xs)
        return amscr__fail(AMSCR_E_NOMEM, "rasterize: out of memory");
    memset(out, 0, w * h);
    for (size_t j = 0; j < h; j++) {
        size_t c = amscr__crossings(P, n, (double)y0 + (double)j, xs);
        for (size_t k = 0; k < c; k += 2) {
            size_t ia = first_at(xs[k], (double)x0, 1.0, w), ib = first_at(xs[k + 1], (double)x0, 1.0, w);
            if (ia < ib)
                memset(out + j * w + ia, 255, ib - ia);
        }
    }
    free(xs);
    return AMSCR_OK;
}
