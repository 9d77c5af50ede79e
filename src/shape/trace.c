/* trace.c — outer boundary of the largest 8-connected component of an 8-bit mask.
 *
 * Steps (docs/method.md §5): threshold (fixed or Otsu), automatic polarity (the border is
 * background), 8-connected components by breadth-first search with an explicit queue
 * (no recursion), Moore-neighbour tracing with Jacob's stopping criterion on a copy
 * padded with one pixel of background, orientation to positive signed area.
 *
 * Memory: (width+2)*(height+2) bytes for the padded mask plus 4 bytes per foreground
 * pixel for the queue, plus the boundary itself. */
#include "internal.h"
#include "iso_level.h"
#include "trace_all.h"

#include <stdlib.h>
#include <string.h>

/* The 8 neighbours, clockwise on screen (y down): W, NW, N, NE, E, SE, S, SW. */
static const int tr_dx[8] = {-1, -1, 0, 1, 1, 1, 0, -1};
static const int tr_dy[8] = {0, -1, -1, -1, 0, 1, 1, 1};
/* After a move in direction d, the last background neighbour examined (direction d-1
 * from the old pixel) seen from the new pixel: the new backtrack direction. */
static const int tr_newback[8] = {6, 6, 0, 0, 2, 2, 4, 4};

/* Bits of the padded mask: foreground, enqueued by the BFS, and four "state seen" flags
 * (backtrack W, N, E, S) for the tracer. */
#define TR_ON 0x01u
#define TR_SEEN 0x02u
#define TR_STATE0 0x10u

/* Otsu's threshold on a 256-bin histogram: the t in 0..254 maximizing the between-class
 * variance of {v <= t} and {v > t}; on a plateau of maxima (e.g. a two-valued image) the
 * middle of the plateau. A one-valued image gives a threshold that leaves the image
 * all on (value 255) or all off. */
static int tr_otsu(const uint64_t hist[256])
{
    long t = amscr__otsu(hist, 256);
    if (t < 0) { /* one value only */
        for (int v = 0; v < 256; v++)
            if (hist[v])
                return v >= 255 ? 254 : v;
        return 0;
    }
    return (int)t;
}

/* Step 0: the arguments. */
static amscr_status tr_check_args(size_t width, size_t height, size_t stride, int threshold)
{
    if (width == 0 || height == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_from_mask: empty image (%zu x %zu)", width, height);
    if (width > AMSCR_MAX_IMAGE_SIDE || height > AMSCR_MAX_IMAGE_SIDE)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_contour_from_mask: image %zu x %zu: a side exceeds %d", width,
                           height, AMSCR_MAX_IMAGE_SIDE);
    if (width * height > AMSCR_MAX_IMAGE_PIXELS)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_contour_from_mask: image %zu x %zu exceeds %u pixels", width,
                           height, (unsigned)AMSCR_MAX_IMAGE_PIXELS);
    if (stride < width)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_from_mask: stride %zu < width %zu", stride, width);
    if (height > 1 && stride > (SIZE_MAX - width) / (height - 1))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_from_mask: stride %zu too large", stride);
    if (threshold != AMSCR_THRESHOLD_AUTO && (threshold < 0 || threshold > 254))
        return amscr__fail(AMSCR_E_INVALID_ARG,
                           "amscr_contour_from_mask: threshold %d not in 0..254 or AMSCR_THRESHOLD_AUTO", threshold);
    return AMSCR_OK;
}

/* Step 1: the threshold (the given one, or Otsu's on the image's histogram). */
static int tr_threshold(const uint8_t *pixels, size_t w, size_t h, size_t stride, int threshold)
{
    if (threshold != AMSCR_THRESHOLD_AUTO)
        return threshold;
    uint64_t hist[256];
    memset(hist, 0, sizeof hist);
    for (size_t y = 0; y < h; y++) {
        const uint8_t *row = pixels + y * stride;
        for (size_t x = 0; x < w; x++)
            hist[row[x]]++;
    }
    return tr_otsu(hist);
}

/* Step 2: polarity — 1 when most border pixels are "on" (the border is background, so the
 * image is inverted). Each border pixel is counted once. */
static uint8_t tr_invert(const uint8_t *pixels, size_t w, size_t h, size_t stride, uint8_t thr)
{
    size_t border = 0, border_on = 0;
    for (size_t y = 0; y < h; y++) {
        const uint8_t *row = pixels + y * stride;
        if (y == 0 || y == h - 1) {
            for (size_t x = 0; x < w; x++)
                border_on += row[x] > thr;
            border += w;
        } else {
            border_on += row[0] > thr;
            border++;
            if (w > 1) {
                border_on += row[w - 1] > thr;
                border++;
            }
        }
    }
    return 2 * border_on > border;
}

/* Step 3: the padded mask ((w+2) x (h+2)): TR_ON = foreground, 0 = background (the one-pixel
 * frame included); *fg: the foreground count. */
static amscr_status tr_padded_mask(const uint8_t *pixels, size_t w, size_t h, size_t stride, uint8_t thr,
                                   uint8_t invert, uint8_t **out_map, size_t *fg)
{
    const size_t W = w + 2, H = h + 2;
    uint8_t *map = amscr__calloc_array(W * H, 1);
    if (!map)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_mask: out of memory (%zu x %zu mask)", W, H);
    size_t count = 0;
    for (size_t y = 0; y < h; y++) {
        const uint8_t *row = pixels + y * stride;
        uint8_t *m = map + (y + 1) * W + 1;
        for (size_t x = 0; x < w; x++) {
            uint8_t on = (uint8_t)((row[x] > thr) ^ invert);
            m[x] = on;
            count += on;
        }
    }
    *out_map = map;
    *fg = count;
    return AMSCR_OK;
}

/* Step 4: the largest 8-connected component by BFS (explicit queue; bit TR_SEEN is set when a
 * pixel is enqueued): its size and first pixel in raster order. The padded index fits in 32
 * bits: W*H <= (2^15+2)^2 < 2^32. */
static amscr_status tr_largest_component(uint8_t *map, size_t w, size_t h, const ptrdiff_t off[8], size_t fg,
                                         size_t *out_size, size_t *out_seed)
{
    const size_t W = w + 2;
    uint32_t *queue = amscr__malloc_array(fg, sizeof *queue);
    if (!queue)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_mask: out of memory (%zu pixels)", fg);
    size_t best_size = 0, best_seed = 0;
    for (size_t y = 1; y <= h; y++) {
        for (size_t x = 1; x <= w; x++) {
            size_t idx = y * W + x;
            if (map[idx] != TR_ON)
                continue;
            size_t head = 0, tail = 0;
            queue[tail++] = (uint32_t)idx;
            map[idx] |= TR_SEEN;
            while (head < tail) {
                size_t p = queue[head++];
                for (int d = 0; d < 8; d++) {
                    size_t q = (size_t)((ptrdiff_t)p + off[d]);
                    if (map[q] == TR_ON) {
                        map[q] |= TR_SEEN;
                        queue[tail++] = (uint32_t)q;
                    }
                }
            }
            if (tail > best_size) { /* strictly larger: ties keep the first in raster order */
                best_size = tail;
                best_seed = idx;
            }
        }
    }
    free(queue);
    *out_size = best_size;
    *out_seed = best_seed;
    return AMSCR_OK;
}

amscr_status amscr__trace_grow(uint32_t **pts, uint8_t **backs, size_t np, size_t *cap, const char *fn)
{
    if (np == AMSCR_MAX_POINTS)
        return amscr__fail(AMSCR_E_LIMIT, "%s: a boundary exceeds %u points", fn, (unsigned)AMSCR_MAX_POINTS);
    if (np < *cap)
        return AMSCR_OK;
    size_t ncap = 2 * *cap > AMSCR_MAX_POINTS ? AMSCR_MAX_POINTS : 2 * *cap;
    uint32_t *npts = realloc(*pts, ncap * sizeof *npts);
    if (npts)
        *pts = npts;
    uint8_t *nbacks = npts ? realloc(*backs, ncap) : NULL;
    if (nbacks)
        *backs = nbacks;
    if (!npts || !nbacks)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (%zu boundary points)", fn, ncap);
    *cap = ncap;
    return AMSCR_OK;
}

/* First boundary allocation (points); doubled as needed. */
#define TR_INITIAL_CAP 1024

/* Step 5: Moore-neighbour tracing from the component's first pixel in raster order: its west
 * neighbour is background, so we "entered" it from the west (backtrack W). Every
 * neighbour reached is 8-adjacent, hence in the same component. A state is (pixel,
 * backtrack); backtracks are always W, N, E or S, so the states seen are 4 flag bits
 * per pixel. Jacob's stopping criterion, in its exact form: stop when a pixel is
 * entered a second time in the same manner (a state repeats); the boundary is the
 * cycle pts[*first..*np-1] from that state's first occurrence (in practice the whole
 * sequence). */
static amscr_status tr_trace(uint8_t *map, const ptrdiff_t off[8], size_t start, uint32_t **out_pts, size_t *out_np,
                             size_t *out_first)
{
    size_t cap = TR_INITIAL_CAP, np = 0, first = 0;
    uint32_t *pts = malloc(cap * sizeof *pts);
    uint8_t *backs = malloc(cap);
    if (!pts || !backs) {
        free(pts);
        free(backs);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_mask: out of memory");
    }
    size_t p = start;
    int back = 0;
    pts[np] = (uint32_t)p;
    backs[np++] = (uint8_t)back;
    map[p] |= (uint8_t)(TR_STATE0 << (back >> 1));
    amscr_status st = AMSCR_OK;
    for (;;) {
        int dir = -1;
        for (int i = 1; i < 8; i++) {
            int d = (back + i) & 7;
            if (map[(size_t)((ptrdiff_t)p + off[d])] & TR_ON) {
                dir = d;
                break;
            }
        }
        if (dir < 0) /* isolated pixel */
            break;
        size_t q = (size_t)((ptrdiff_t)p + off[dir]);
        int nback = tr_newback[dir];
        uint8_t bit = (uint8_t)(TR_STATE0 << (nback >> 1));
        if (map[q] & bit) { /* state seen: the cycle is closed */
            for (first = 0; first < np; first++)
                if (pts[first] == q && backs[first] == nback)
                    break;
            break;
        }
        map[q] |= bit;
        st = amscr__trace_grow(&pts, &backs, np, &cap, "amscr_contour_from_mask");
        if (st != AMSCR_OK)
            break;
        pts[np] = (uint32_t)q;
        backs[np++] = (uint8_t)nback;
        p = q;
        back = nback;
    }
    free(backs);
    if (st == AMSCR_OK && first >= np) /* cannot happen: the repeated state was recorded */
        st = amscr__fail(AMSCR_E_INTERNAL, "amscr_contour_from_mask: boundary tracing lost its cycle");
    if (st != AMSCR_OK) {
        free(pts);
        return st;
    }
    *out_pts = pts;
    *out_np = np;
    *out_first = first;
    return AMSCR_OK;
}

/* Step 6: the cycle pts[first..np-1] as coordinates, started at the start pixel when it is on
 * it, oriented to positive signed area. Frees pts. */
static amscr_status tr_cycle_points(uint32_t *pts, size_t first, size_t np, size_t start, size_t W, size_t comp_size,
                                    double **out_xy, size_t *out_n)
{
    size_t ncyc = np - first, rot = 0;
    for (size_t i = 0; i < ncyc; i++)
        if (pts[first + i] == start) {
            rot = i;
            break;
        }
    if (ncyc < 3) {
        free(pts);
        return amscr__fail(AMSCR_E_DEGENERATE,
                           "amscr_contour_from_mask: largest component (%zu pixels) has %zu boundary points (< 3)",
                           comp_size, ncyc);
    }
    double *xy = amscr__malloc_array(ncyc, 2 * sizeof *xy);
    if (!xy) {
        free(pts);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_mask: out of memory (%zu points)", ncyc);
    }
    for (size_t i = 0; i < ncyc; i++) {
        size_t idx = pts[first + (rot + i) % ncyc];
        xy[2 * i] = (double)(idx % W - 1);
        xy[2 * i + 1] = (double)(idx / W - 1);
    }
    free(pts);
    /* Signed area (shoelace, twice the area). */
    double a2 = 0.0;
    for (size_t i = 0; i < ncyc; i++) {
        size_t j = i + 1 == ncyc ? 0 : i + 1;
        a2 += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
    }
    if (a2 == 0.0) {
        free(xy);
        return amscr__fail(AMSCR_E_DEGENERATE,
                           "amscr_contour_from_mask: largest component (%zu pixels) is a line: zero area", comp_size);
    }
    if (a2 < 0.0)
        amscr__reverse_points(xy, ncyc);
    *out_xy = xy;
    *out_n = ncyc;
    return AMSCR_OK;
}

amscr_status amscr_contour_from_mask(const uint8_t *pixels, size_t width, size_t height, size_t stride,
                                     int threshold, amscr_contour **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(pixels);
    AMSCR_CHECK_NULL(out);
    amscr_status st = tr_check_args(width, height, stride, threshold);
    if (st != AMSCR_OK)
        return st;
    const size_t w = width, h = height, W = w + 2;
    int t = tr_threshold(pixels, w, h, stride, threshold);
    const uint8_t thr = (uint8_t)t;
    const uint8_t invert = tr_invert(pixels, w, h, stride, thr);
    uint8_t *map = NULL;
    size_t fg = 0;
    st = tr_padded_mask(pixels, w, h, stride, thr, invert, &map, &fg);
    if (st != AMSCR_OK)
        return st;
    if (fg == 0) {
        free(map);
        if (invert)
            return amscr__fail(AMSCR_E_NOT_FOUND, "amscr_contour_from_mask: foreground everywhere (threshold %d)", t);
        return amscr__fail(AMSCR_E_NOT_FOUND, "amscr_contour_from_mask: no foreground pixels (threshold %d)", t);
    }
    /* Neighbour offsets in the padded mask. */
    ptrdiff_t off[8];
    for (int d = 0; d < 8; d++)
        off[d] = (ptrdiff_t)tr_dy[d] * (ptrdiff_t)W + tr_dx[d];
    size_t comp_size = 0, start = 0, np = 0, first = 0, n = 0;
    uint32_t *pts = NULL;
    double *xy = NULL;
    st = tr_largest_component(map, w, h, off, fg, &comp_size, &start);
    if (st == AMSCR_OK)
        st = tr_trace(map, off, start, &pts, &np, &first);
    free(map);
    if (st == AMSCR_OK)
        st = tr_cycle_points(pts, first, np, start, W, comp_size, &xy, &n);
    if (st != AMSCR_OK)
        return st;
    /* amscr__contour_wrap takes ownership of xy (also on failure). */
    return amscr__contour_wrap(xy, n, out);
}

/* ------------------------------------------------------------------ shared with trace_all.c */

void amscr__mask_threshold(const uint8_t *pixels, size_t w, size_t h, size_t stride, int threshold, int *out_t,
                           int *out_invert)
{
    int t = threshold;
    if (t == AMSCR_THRESHOLD_AUTO) {
        uint64_t hist[256];
        memset(hist, 0, sizeof hist);
        for (size_t y = 0; y < h; y++)
            for (size_t x = 0; x < w; x++)
                hist[pixels[y * stride + x]]++;
        t = tr_otsu(hist);
    }
    /* polarity as amscr_contour_from_mask: each border pixel counted once */
    size_t border = 0, border_on = 0;
    for (size_t y = 0; y < h; y++) {
        const uint8_t *row = pixels + y * stride;
        for (size_t x = 0; x < w; x++) {
            if (y != 0 && y != h - 1 && x != 0 && x != w - 1)
                continue;
            border_on += row[x] > (uint8_t)t;
            border++;
        }
    }
    *out_t = t;
    *out_invert = 2 * border_on > border;
}
