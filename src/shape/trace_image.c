/* trace_image.c — contours of 8- and 16-bit grey images at sub-pixel accuracy:
 * amscr_contour_from_image and amscr_contours_from_image (docs/method.md §5).
 *
 * The level and polarity come from iso_level.c; the pixels above the level are labelled as in
 * amscr_contours_from_mask (trace_all.c: foreground 8-connected, background 4-connected, the
 * image padded with background); each region's boundary is then the iso-line through the
 * pixel edge next to its first pixel in raster order (a component: the edge to its left
 * neighbour; a hole: the edge to the foreground above it), walked by march.c. The flag
 * AMSCR_TRACE_PIXEL_CHAIN instead classifies the pixels the same way and hands the binary
 * mask to the pixel-centre tracers (trace.c, trace_all.c). */
#include "internal.h"
#include "iso_level.h"
#include "trace_all.h"

#include <math.h>
#include <stdlib.h>

static amscr_status ti_check(const void *pixels, size_t width, size_t height, size_t stride, int bits, double level,
                             int flags, int allowed, const char *fn)
{
    if (pixels == NULL)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: pixels is NULL", fn);
    if (width == 0 || height == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: empty image (%zu x %zu)", fn, width, height);
    if (width > AMSCR_MAX_IMAGE_SIDE || height > AMSCR_MAX_IMAGE_SIDE || width * height > AMSCR_MAX_IMAGE_PIXELS)
        return amscr__fail(AMSCR_E_LIMIT, "%s: image %zu x %zu exceeds the limits (%d per side, %u pixels)", fn,
                           width, height, AMSCR_MAX_IMAGE_SIDE, (unsigned)AMSCR_MAX_IMAGE_PIXELS);
    if (stride < width || (height > 1 && stride > (SIZE_MAX / 2 - width) / (height - 1)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: bad stride %zu (width %zu)", fn, stride, width);
    if (bits != 8 && bits != 16)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: bits %d: expected 8 or 16", fn, bits);
    double maxval = bits == 8 ? 255.0 : 65535.0;
    if (isnan(level) || level >= maxval)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: level %g not in [0, %g) nor negative (automatic)", fn, level,
                           maxval);
    if (flags & ~allowed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: unknown flags 0x%x", fn, (unsigned)flags);
    return AMSCR_OK;
}

/* The padded foreground mask of f; AMSCR_E_NOT_FOUND when it is empty. */
static amscr_status ti_mask(const amscr__iso *f, const char *fn, uint8_t **out_on)
{
    size_t fg = 0;
    amscr_status st = amscr__iso_mask(f, out_on, &fg);
    if (st != AMSCR_OK || fg > 0)
        return st;
    free(*out_on);
    *out_on = NULL;
    return amscr__fail(AMSCR_E_NOT_FOUND, "%s: %s (level %g)", fn,
                       f->sign < 0 ? "foreground everywhere" : "no foreground pixels", f->level);
}

/* The pixels above f's level (before polarity) as a 0/255 mask for the pixel-centre tracers. */
static amscr_status ti_binary(const amscr__iso *f, const char *fn, uint8_t **out)
{
    uint8_t *m = amscr__malloc_array(f->w, f->h);
    if (!m)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (%zu x %zu mask)", fn, f->w, f->h);
    for (size_t y = 0; y < f->h; y++)
        for (size_t x = 0; x < f->w; x++)
            m[y * f->w + x] = f->sign * amscr__iso_at(f, x + 1, y + 1) > 0.0 ? 255 : 0;
    *out = m;
    return AMSCR_OK;
}

/* The iso-line of region r of R (entry edge: see the file's comment), oriented (outer
 * counter-clockwise, hole clockwise); *out NULL when it has < 3 points, no area or an area
 * below min_area. An amscr__region_tracer; ctx is the field. */
static amscr_status ti_region(void *ctx, const amscr__regions *R, size_t r, double min_area, amscr_contour **out,
                              double *out_area)
{
    const amscr__iso *f = ctx;
    const size_t W = f->w + 2, p = R->first[r], X = p % W, Y = p / W;
    const int hole = !R->fg[r];
    double *xy = NULL;
    size_t n = 0;
    *out = NULL;
    amscr_status st = amscr__march(f, X - 1, Y - 1, hole ? 1 : 2, "amscr_contours_from_image", &xy, &n);
    if (st != AMSCR_OK)
        return st;
    double a = n >= 3 ? amscr__signed_area(xy, n) : 0.0;
    double area = fabs(a);
    if (n < 3 || area == 0.0 || area < min_area) {
        free(xy);
        return AMSCR_OK;
    }
    if ((a > 0.0) == (hole != 0))
        amscr__reverse_points(xy, n);
    *out_area = area;
    return amscr__contour_wrap(xy, n, out);
}

/* Pixels per label of R (R->n + 1 counts) into *out_count, and the largest foreground region
 * (ties: the first in raster order) into *out_label; returns its size, 0 when out of memory. */
static size_t ti_largest(const amscr__regions *R, size_t npix, size_t **out_count, size_t *out_label)
{
    size_t *count = amscr__calloc_array(R->n + 1, sizeof *count);
    *out_count = count;
    if (!count)
        return 0;
    for (size_t i = 0; i < npix; i++)
        count[R->lab[i]]++;
    size_t best = 0, best_size = 0;
    for (size_t r = 2; r <= R->n; r++)
        if (R->fg[r] && count[r] > best_size) {
            best = r;
            best_size = count[r];
        }
    *out_label = best;
    return best_size;
}

/* The outer iso-line of the largest component of the padded mask `on`, counter-clockwise;
 * with AMSCR_TRACE_JOIN in flags the other large pieces joined to it (join.c). */
static amscr_status ti_outer(const amscr__iso *f, const uint8_t *on, int flags, double **out_xy, size_t *out_n)
{
    static const char fn[] = "amscr_contour_from_image";
    const size_t W = f->w + 2, H = f->h + 2;
    amscr__regions R;
    amscr_status st = amscr__regions_label(on, W, H, &R);
    if (st != AMSCR_OK)
        return st;
    size_t label = 0, *count = NULL, size = ti_largest(&R, W * H, &count, &label);
    if (size == 0) {
        free(count);
        amscr__regions_free(&R);
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (%zu regions)", fn, R.n);
    }
    size_t p = R.first[label];
    double *xy = NULL;
    size_t n = 0;
    st = amscr__march(f, p % W - 1, p / W - 1, 2, fn, &xy, &n);
    double a = st == AMSCR_OK && n >= 3 ? amscr__signed_area(xy, n) : 0.0;
    if (st == AMSCR_OK && a == 0.0)
        st = amscr__fail(AMSCR_E_DEGENERATE, "%s: largest component (%zu pixels) has no area", fn, size);
    if (st == AMSCR_OK && a < 0.0)
        amscr__reverse_points(xy, n);
    if (st == AMSCR_OK && (flags & AMSCR_TRACE_JOIN))
        st = amscr__join_pieces(f, &R, count, label, &xy, &n);
    free(count);
    amscr__regions_free(&R);
    if (st != AMSCR_OK) {
        free(xy);
        return st;
    }
    *out_xy = xy;
    *out_n = n;
    return AMSCR_OK;
}

amscr_status amscr_contour_from_image(const void *pixels, size_t width, size_t height, size_t stride, int bits,
                                      double level, int flags, amscr_contour **out)
{
    static const char fn[] = "amscr_contour_from_image";
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    amscr_status st =
        ti_check(pixels, width, height, stride, bits, level, flags, AMSCR_TRACE_PIXEL_CHAIN | AMSCR_TRACE_JOIN, fn);
    amscr__iso f;
    if (st == AMSCR_OK)
        st = amscr__iso_setup(pixels, width, height, stride, bits, level, &f);
    if (st != AMSCR_OK)
        return st;
    if (flags & AMSCR_TRACE_PIXEL_CHAIN) {
        uint8_t *m = NULL;
        st = ti_binary(&f, fn, &m);
        if (st == AMSCR_OK)
            st = amscr_contour_from_mask(m, width, height, width, 127, out);
        free(m);
        return st;
    }
    uint8_t *on = NULL;
    st = ti_mask(&f, fn, &on);
    if (st != AMSCR_OK)
        return st;
    double *xy = NULL;
    size_t n = 0;
    st = ti_outer(&f, on, flags, &xy, &n);
    free(on);
    if (st != AMSCR_OK)
        return st;
    return amscr__contour_wrap(xy, n, out); /* takes xy, also on failure */
}

amscr_status amscr_contours_from_image(const void *pixels, size_t width, size_t height, size_t stride, int bits,
                                       double level, int flags, double min_area, amscr_contour_set **out)
{
    static const char fn[] = "amscr_contours_from_image";
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    amscr_status st = ti_check(pixels, width, height, stride, bits, level, flags, AMSCR_TRACE_PIXEL_CHAIN, fn);
    if (st == AMSCR_OK && (!(min_area >= 0.0) || min_area > 1e300))
        st = amscr__fail(AMSCR_E_INVALID_ARG, "%s: min_area must be finite and >= 0", fn);
    amscr__iso f;
    if (st == AMSCR_OK)
        st = amscr__iso_setup(pixels, width, height, stride, bits, level, &f);
    if (st != AMSCR_OK)
        return st;
    if (flags & AMSCR_TRACE_PIXEL_CHAIN) {
        uint8_t *m = NULL;
        st = ti_binary(&f, fn, &m);
        if (st == AMSCR_OK)
            st = amscr_contours_from_mask(m, width, height, width, 127, min_area, out);
        free(m);
        return st;
    }
    uint8_t *on = NULL;
    st = ti_mask(&f, fn, &on);
    if (st != AMSCR_OK)
        return st;
    st = amscr__contours_build(on, width + 2, height + 2, ti_region, &f, min_area, fn, out);
    free(on);
    return st;
}
