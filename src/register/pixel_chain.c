/* pixel_chain.c — a target (or source) given as a pixel chain, traced again at sub-pixel
 * (docs/method.md §11.7).
 *
 * A pixel chain is the sequence of a binary image's boundary pixel centres: integer points, each
 * 8-adjacent to the next and the last to the first (OpenCV's findContours without approximation,
 * amscr_contour_from_mask, the tool's --pixel-chain). It runs half a pixel inside the boundary
 * the image had before it was thresholded, so on a small image it is biased as a whole: the shape
 * is thinner by a pixel, a thin part by most of itself. The image is exactly recoverable from the
 * chain: its pixels are the chain's own and those whose centre the chain encloses (no other pixel
 * centre lies between two 8-adjacent ones). That image traced at half level is the sub-pixel
 * target amscr_contour_from_image makes, and the pixel_grid stage's correction then applies to it
 * (pixel_grid.c). Where the pixel_grid stage is on and its condition holds for the chain (the
 * chain and the source under the search's map within the grid's limit), register.c registers the
 * source onto that trace instead, and the pixel_grid stage runs on it; a source given as a pixel
 * chain is traced again too, so that a chain registered onto itself still reads the identity. A
 * small chain source is traced again onto any target traced from an image (register.c). */
#include "match.h"

#include <math.h>
#include <stdlib.h>

/* Every point integer, each 8-adjacent to the next, the last to the first; at least 4. */
static int is_chain(const double *p, size_t n)
{
    if (n < 4)
        return 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = i + 1 == n ? 0 : i + 1;
        double x = p[2 * i], y = p[2 * i + 1];
        if (!(fabs(x) < 1e9 && fabs(y) < 1e9) || x != floor(x) || y != floor(y))
            return 0;
        double dx = fabs(p[2 * j] - x), dy = fabs(p[2 * j + 1] - y);
        if (dx > 1.0 || dy > 1.0 || dx + dy == 0.0)
            return 0;
    }
    return 1;
}

int amscr__is_pixel_chain(const amscr_descriptor *d)
{
    return d->raw && d->params.closed && is_chain(d->raw, d->nraw);
}

/* The image the chain bounds, in a box one pixel beyond it: *out (w * h bytes, 255 foreground). */
static amscr_status chain_image(const double *p, size_t n, long x0, long y0, size_t w, size_t h, uint8_t **out)
{
    *out = amscr__malloc_array(w, h);
    if (!*out)
        return amscr__fail(AMSCR_E_NOMEM, "pixel chain: out of memory");
    amscr_status st = amscr__raster_centres(p, n, x0, y0, w, h, *out);
    for (size_t i = 0; st == AMSCR_OK && i < n; i++)
        (*out)[(size_t)((long)p[2 * i + 1] - y0) * w + (size_t)((long)p[2 * i] - x0)] = 255;
    return st;
}

/* The trace c started as h was: at its point nearest h's first sample (the boundary parameter
 * of amscr_result_part runs from there; both run counter-clockwise, as every closed curve is
 * prepared). */
static void as_given(const amscr_descriptor *h, amscr_contour *c)
{
    size_t k = 0;
    double best = INFINITY;
    for (size_t i = 0; i < c->n; i++) {
        double dx = c->xy[2 * i] - h->input[0], dy = c->xy[2 * i + 1] - h->input[1];
        if (dx * dx + dy * dy < best)
            best = dx * dx + dy * dy, k = i;
    }
    amscr__reverse_points(c->xy, k); /* rotated left by k: three reversals */
    amscr__reverse_points(c->xy + 2 * k, c->n - k);
    amscr__reverse_points(c->xy, c->n);
}

amscr_status amscr__chain_retrace(const amscr_descriptor *h, amscr_descriptor **out)
{
    const double *p = h->raw;
    size_t n = h->nraw;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    amscr__points_extent(p, n, lo, hi);
    long x0 = (long)lo[0] - 1, y0 = (long)lo[1] - 1;
    size_t w = (size_t)(hi[0] - lo[0]) + 3, hh = (size_t)(hi[1] - lo[1]) + 3;
    uint8_t *img = NULL;
    amscr_contour *c = NULL;
    *out = NULL;
    amscr_status st = chain_image(p, n, x0, y0, w, hh, &img);
    if (st == AMSCR_OK)
        st = amscr_contour_from_image(img, w, hh, w, 8, 127.5, 0, &c);
    for (size_t i = 0; st == AMSCR_OK && i < c->n; i++) {
        c->xy[2 * i] += (double)x0;
        c->xy[2 * i + 1] += (double)y0;
    }
    if (st == AMSCR_OK) {
        as_given(h, c);
        st = amscr_descriptor_new(&h->params, c, out);
    }
    free(img);
    amscr_contour_free(c);
    return st;
}
