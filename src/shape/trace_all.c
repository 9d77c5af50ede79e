/* trace_all.c — every contour of an 8-bit mask with its hierarchy: amscr_contours_from_mask.
 *
 * Steps: threshold and polarity as amscr_contour_from_mask (trace.c); on the image padded
 * with one pixel of background, regions in raster order of their first pixel: foreground
 * 8-connected, background 4-connected (the dual connectivities, so a region's boundary is a
 * single closed curve), each by breadth-first search with an explicit queue. The background
 * region of the padding is the outside; every other background region is a hole.
 *
 * Hierarchy (OpenCV findContours RETR_TREE): the first pixel of a foreground region has
 * background on its left (else that pixel would be in the region and come first), and the
 * region of that pixel is the hole around it (or the outside: no parent); the first pixel of
 * a hole has foreground above it, the region around the hole. A parent's first pixel comes
 * before its child's, so one pass in region order knows each parent's fate first.
 *
 * Each region's boundary is traced with Moore-neighbour tracing and Jacob's stopping
 * criterion over the region's own pixels (a hole: its background pixels). Outer contours are
 * counter-clockwise (positive signed area, as amscr_contour_from_mask), holes clockwise.
 * A contour is kept when it has >= 3 points, its polygon area is >= min_area and its parent
 * is kept (a child lies inside its parent's polygon, so a dropped parent's children are
 * small too).
 *
 * Memory: (width+2)*(height+2) * 9 bytes (mask, labels, queue, tracing states) plus the
 * contours. */
#include "internal.h"
#include "trace_all.h"

#include <stdlib.h>
#include <string.h>

struct amscr_contour_set {
    size_t n;
    amscr_contour **c;
    size_t *parent;       /* AMSCR_NO_PARENT or an index < i */
    unsigned char *hole;
    double *area;         /* polygon area, >= 0 */
};

/* The 8 neighbours, clockwise on screen (y down): W, NW, N, NE, E, SE, S, SW (as trace.c). */
static const int ta_dx[8] = {-1, -1, 0, 1, 1, 1, 0, -1};
static const int ta_dy[8] = {0, -1, -1, -1, 0, 1, 1, 1};
static const int ta_newback[8] = {6, 6, 0, 0, 2, 2, 4, 4};

typedef amscr__regions regions;

static int regions_push(regions *R, uint32_t first, unsigned char fg)
{
    if (R->n + 1 == R->cap) {
        size_t ncap = R->cap * 2;
        uint32_t *f = realloc(R->first, ncap * sizeof *f);
        if (f)
            R->first = f;
        unsigned char *g = f ? realloc(R->fg, ncap) : NULL;
        if (g)
            R->fg = g;
        if (!f || !g)
            return -1;
        R->cap = ncap;
    }
    R->n++;
    R->first[R->n] = first;
    R->fg[R->n] = fg;
    return 0;
}

/* Breadth-first from queue[0..tail): each pixel's neighbours of the same kind (8 for the
 * foreground, W N E S for the background) that have no label get `label`. Every queued pixel
 * lies inside the ring, so all its neighbours exist. Returns the queue's length. */
static size_t flood(const uint8_t *on, const ptrdiff_t off[8], uint8_t kind, uint32_t label, uint32_t *queue,
                    size_t tail, uint32_t *lab)
{
    int step = kind ? 1 : 2;
    for (size_t head = 0; head < tail; head++) {
        size_t p = queue[head];
        for (int d = 0; d < 8; d += step) {
            size_t q = (size_t)((ptrdiff_t)p + off[d]);
            if (lab[q] == 0 && on[q] == kind) {
                lab[q] = label;
                queue[tail++] = (uint32_t)q;
            }
        }
    }
    return tail;
}

/* Labels every pixel of the padded mask `on` (W x H >= 3 x 3; its one-pixel ring is background)
 * by BFS; queue has W*H entries. The ring is labelled first as the outer background's (label
 * 1, first pixel 0), with the background 4-adjacent to it queued; after that every region lies
 * inside the ring and needs no bounds tests. Labels follow the raster order of each region's
 * first pixel. */
static amscr_status label_regions(const uint8_t *on, size_t W, size_t H, uint32_t *queue, regions *R)
{
    ptrdiff_t off[8];
    for (int d = 0; d < 8; d++)
        off[d] = (ptrdiff_t)ta_dy[d] * (ptrdiff_t)W + ta_dx[d];
    if (regions_push(R, 0, 0) != 0)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu regions)", R->n);
    for (size_t x = 0; x < W; x++)
        R->lab[x] = R->lab[(H - 1) * W + x] = 1;
    for (size_t y = 0; y < H; y++)
        R->lab[y * W] = R->lab[y * W + W - 1] = 1;
    size_t tail = 0;
    for (size_t y = 1; y + 1 < H; y++) /* the inner pixels 4-adjacent to the ring */
        for (size_t x = 1; x + 1 < W; x += (y == 1 || y + 2 == H || x + 2 == W) ? 1 : W - 3) {
            size_t q = y * W + x;
            if (R->lab[q] == 0 && on[q] == 0) {
                R->lab[q] = 1;
                queue[tail++] = (uint32_t)q;
            }
        }
    flood(on, off, 0, 1, queue, tail, R->lab);
    for (size_t idx = W + 1; idx + W + 1 < W * H; idx++) {
        if (R->lab[idx] != 0)
            continue;
        uint8_t kind = on[idx];
        if (regions_push(R, (uint32_t)idx, kind) != 0)
            return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu regions)", R->n);
        uint32_t label = (uint32_t)R->n;
        R->lab[idx] = label;
        queue[0] = (uint32_t)idx;
        flood(on, off, kind, label, queue, 1, R->lab);
    }
    return AMSCR_OK;
}

/* The traced pixels pts (*n) cut to their cycle (from index `first`, where the walk came back)
 * and started at the start pixel when it is on it (as trace.c). */
static amscr_status keep_cycle(uint32_t *pts, size_t *n, size_t first, size_t start)
{
    if (first > 0 && first < *n) {
        memmove(pts, pts + first, (*n - first) * sizeof *pts);
        *n -= first;
    }
    size_t rot = 0;
    while (rot < *n && pts[rot] != start)
        rot++;
    if (rot == 0 || rot >= *n)
        return AMSCR_OK;
    uint32_t *tmp = malloc(rot * sizeof *tmp);
    if (!tmp)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory");
    memcpy(tmp, pts, rot * sizeof *tmp);
    memmove(pts, pts + rot, (*n - rot) * sizeof *pts);
    memcpy(pts + *n - rot, tmp, rot * sizeof *tmp);
    free(tmp);
    return AMSCR_OK;
}

/* Moore tracing of region `label` from its first pixel (backtrack W); the cycle's pixel
 * indices into *pts (grown as needed), their count into *np. `st` holds 4 state bits a
 * pixel and is left cleared. */
static amscr_status trace_region(const uint32_t *lab, uint8_t *st, size_t W, size_t start, uint32_t label,
                                 uint32_t **pts, size_t *cap, size_t *np)
{
    ptrdiff_t off[8];
    for (int d = 0; d < 8; d++)
        off[d] = (ptrdiff_t)ta_dy[d] * (ptrdiff_t)W + ta_dx[d];
    size_t n = 0, p = start, first = 0;
    int back = 0;
    amscr_status s = AMSCR_OK;
    (*pts)[n++] = (uint32_t)p;
    st[p] |= (uint8_t)(1u << (back >> 1));
    uint8_t *backs = malloc(*cap);
    if (!backs)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory");
    backs[0] = 0;
    for (;;) {
        int dir = -1;
        for (int i = 1; i < 8 && dir < 0; i++) {
            int d = (back + i) & 7;
            if (lab[(size_t)((ptrdiff_t)p + off[d])] == label)
                dir = d;
        }
        if (dir < 0) /* a single pixel */
            break;
        size_t q = (size_t)((ptrdiff_t)p + off[dir]);
        int nback = ta_newback[dir];
        uint8_t bit = (uint8_t)(1u << (nback >> 1));
        if (st[q] & bit) { /* a state repeats: the cycle is closed */
            for (first = 0; first < n; first++)
                if ((*pts)[first] == q && backs[first] == nback)
                    break;
            break;
        }
        st[q] |= bit;
        if ((s = amscr__trace_grow(pts, &backs, n, cap, "amscr_contours_from_mask")) != AMSCR_OK)
            break;
        (*pts)[n] = (uint32_t)q;
        backs[n++] = (uint8_t)nback;
        p = q;
        back = nback;
    }
    for (size_t i = 0; i < n; i++)
        st[(*pts)[i]] = 0;
    free(backs);
    if (s == AMSCR_OK)
        s = keep_cycle(*pts, &n, first, start);
    *np = n;
    return s;
}

/* The traced pixels as an oriented contour (outer: positive area, hole: negative), or
 * *out NULL when degenerate (< 3 points, zero area) or smaller than min_area. */
static amscr_status make_contour(const uint32_t *pts, size_t n, size_t W, int hole, double min_area,
                                 amscr_contour **out, double *out_area)
{
    *out = NULL;
    if (n < 3)
        return AMSCR_OK;
    double a2 = 0.0;
    for (size_t i = 0; i < n; i++) {
        size_t j = i + 1 == n ? 0 : i + 1;
        double xi = (double)(pts[i] % W), yi = (double)(pts[i] / W), xj = (double)(pts[j] % W),
               yj = (double)(pts[j] / W);
        a2 += xi * yj - xj * yi;
    }
    double area = 0.5 * (a2 < 0 ? -a2 : a2);
    if (area == 0.0 || area < min_area)
        return AMSCR_OK;
    double *xy = amscr__malloc_array(n, 2 * sizeof *xy);
    if (!xy)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu points)", n);
    int reverse = (a2 > 0.0) == (hole != 0); /* outer: keep a2 > 0; hole: make it < 0 */
    for (size_t i = 0; i < n; i++) {
        size_t k = reverse ? n - 1 - i : i;
        xy[2 * i] = (double)(pts[k] % W) - 1.0;
        xy[2 * i + 1] = (double)(pts[k] / W) - 1.0;
    }
    *out_area = area;
    return amscr__contour_wrap(xy, n, out);
}

static amscr_status set_new(size_t cap, amscr_contour_set **out)
{
    amscr_contour_set *s = calloc(1, sizeof *s);
    if (s) {
        s->c = amscr__calloc_array(cap, sizeof *s->c);
        s->parent = amscr__malloc_array(cap, sizeof *s->parent);
        s->hole = amscr__malloc_array(cap, 1);
        s->area = amscr__malloc_array(cap, sizeof *s->area);
    }
    if (!s || !s->c || !s->parent || !s->hole || !s->area) {
        amscr_contour_set_free(s);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu contours)", cap);
    }
    *out = s;
    return AMSCR_OK;
}

/* Traces every region of R (labels 2..n) with `tracer` into the set s (room for n entries). */
static amscr_status trace_all(const regions *R, size_t W, amscr__region_tracer tracer, void *ctx, double min_area,
                              amscr_contour_set *s)
{
    size_t *index = amscr__malloc_array(R->n + 1, sizeof *index); /* region -> set index */
    amscr_status e = AMSCR_OK;
    if (!index)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu regions)", R->n);
    index[1] = AMSCR_NO_PARENT; /* the outside */
    for (size_t r = 2; e == AMSCR_OK && r <= R->n; r++) {
        size_t p = R->first[r];
        size_t par = index[R->lab[R->fg[r] ? p - 1 : p - W]];
        index[r] = SIZE_MAX - 1; /* dropped */
        if (par == SIZE_MAX - 1)
            continue; /* inside a dropped contour */
        amscr_contour *c = NULL;
        double area = 0.0;
        e = tracer(ctx, R, r, min_area, &c, &area);
        if (e != AMSCR_OK || c == NULL)
            continue;
        index[r] = s->n;
        s->c[s->n] = c;
        s->parent[s->n] = par;
        s->hole[s->n] = !R->fg[r];
        s->area[s->n++] = area;
    }
    free(index);
    return e;
}

/* The pixel-centre tracer of amscr_contours_from_mask (an amscr__region_tracer). */
typedef struct chain_ctx {
    uint8_t *st; /* W*H tracing states */
    size_t W, cap;
    uint32_t *pts;
} chain_ctx;

static amscr_status chain_tracer(void *vctx, const regions *R, size_t r, double min_area, amscr_contour **out,
                                 double *out_area)
{
    chain_ctx *c = vctx;
    size_t np = 0;
    amscr_status e = trace_region(R->lab, c->st, c->W, R->first[r], (uint32_t)r, &c->pts, &c->cap, &np);
    if (e != AMSCR_OK)
        return e;
    return make_contour(c->pts, np, c->W, !R->fg[r], min_area, out, out_area);
}

static amscr_status check_args(const uint8_t *pixels, size_t width, size_t height, size_t stride, int threshold,
                               double min_area, amscr_contour_set **out)
{
    AMSCR_CHECK_NULL_IN("amscr_contours_from_mask", pixels);
    AMSCR_CHECK_NULL_IN("amscr_contours_from_mask", out);
    if (width == 0 || height == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contours_from_mask: empty image (%zu x %zu)", width, height);
    if (width > AMSCR_MAX_IMAGE_SIDE || height > AMSCR_MAX_IMAGE_SIDE || width * height > AMSCR_MAX_IMAGE_PIXELS)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_contours_from_mask: image %zu x %zu exceeds the limits", width,
                           height);
    if (stride < width || (height > 1 && stride > (SIZE_MAX - width) / (height - 1)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contours_from_mask: bad stride %zu (width %zu)", stride,
                           width);
    if (threshold != AMSCR_THRESHOLD_AUTO && (threshold < 0 || threshold > 254))
        return amscr__fail(AMSCR_E_INVALID_ARG,
                           "amscr_contours_from_mask: threshold %d not in 0..254 or AMSCR_THRESHOLD_AUTO", threshold);
    if (!(min_area >= 0.0) || min_area > 1e300)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contours_from_mask: min_area must be finite and >= 0");
    return AMSCR_OK;
}

amscr_status amscr__regions_label(const uint8_t *on, size_t W, size_t H, amscr__regions *R)
{
    uint32_t *queue = amscr__malloc_array(W * H, sizeof *queue);
    R->lab = amscr__calloc_array(W * H, sizeof *R->lab);
    R->first = malloc(64 * sizeof *R->first);
    R->fg = malloc(64);
    R->n = 0;
    R->cap = 64;
    amscr_status e = AMSCR_OK;
    if (!queue || !R->lab || !R->first || !R->fg)
        e = amscr__fail(AMSCR_E_NOMEM, "contour tracing: out of memory (%zu x %zu labels)", W, H);
    else
        e = label_regions(on, W, H, queue, R);
    free(queue);
    if (e != AMSCR_OK)
        amscr__regions_free(R);
    return e;
}

void amscr__regions_free(amscr__regions *R)
{
    free(R->lab);
    free(R->first);
    free(R->fg);
    R->lab = R->first = NULL;
    R->fg = NULL;
    R->n = 0;
}

amscr_status amscr__contours_build(const uint8_t *on, size_t W, size_t H, amscr__region_tracer tracer, void *ctx,
                                   double min_area, const char *fn, amscr_contour_set **out)
{
    regions R;
    amscr_contour_set *s = NULL;
    amscr_status e = amscr__regions_label(on, W, H, &R);
    if (e != AMSCR_OK)
        return e;
    e = set_new(R.n, &s);
    if (e == AMSCR_OK)
        e = trace_all(&R, W, tracer, ctx, min_area, s);
    if (e == AMSCR_OK && s->n == 0)
        e = amscr__fail(AMSCR_E_NOT_FOUND, "%s: no contour of area >= %g", fn, min_area);
    amscr__regions_free(&R);
    if (e != AMSCR_OK) {
        amscr_contour_set_free(s);
        return e;
    }
    *out = s;
    return AMSCR_OK;
}

amscr_status amscr_contours_from_mask(const uint8_t *pixels, size_t width, size_t height, size_t stride,
                                      int threshold, double min_area, amscr_contour_set **out)
{
    amscr__clear_error();
    amscr_status e = check_args(pixels, width, height, stride, threshold, min_area, out);
    if (e != AMSCR_OK)
        return e;
    int t, invert;
    amscr__mask_threshold(pixels, width, height, stride, threshold, &t, &invert);
    const size_t W = width + 2, H = height + 2;
    chain_ctx c = {amscr__calloc_array(W * H, 1), W, 1024, malloc(1024 * sizeof(uint32_t))};
    uint8_t *on = amscr__calloc_array(W * H, 1);
    size_t fg = 0;
    if (!on || !c.st || !c.pts) {
        e = amscr__fail(AMSCR_E_NOMEM, "amscr_contours_from_mask: out of memory (%zu x %zu mask)", W, H);
        goto done;
    }
    for (size_t y = 0; y < height; y++)
        for (size_t x = 0; x < width; x++) {
            uint8_t v = (uint8_t)((pixels[y * stride + x] > (uint8_t)t) ^ invert);
            on[(y + 1) * W + x + 1] = v;
            fg += v;
        }
    if (fg == 0)
        e = amscr__fail(AMSCR_E_NOT_FOUND, "amscr_contours_from_mask: %s (threshold %d)",
                        invert ? "foreground everywhere" : "no foreground pixels", t);
    else
        e = amscr__contours_build(on, W, H, chain_tracer, &c, min_area, "amscr_contours_from_mask", out);
done:
    free(on);
    free(c.st);
    free(c.pts);
    return e;
}

void amscr_contour_set_free(amscr_contour_set *s)
{
    if (s == NULL)
        return;
    for (size_t i = 0; s->c && i < s->n; i++)
        amscr_contour_free(s->c[i]);
    free(s->c);
    free(s->parent);
    free(s->hole);
    free(s->area);
    free(s);
}

size_t amscr_contour_set_size(const amscr_contour_set *s) { return s ? s->n : 0; }

const amscr_contour *amscr_contour_set_contour(const amscr_contour_set *s, size_t i)
{
    return s && i < s->n ? s->c[i] : NULL;
}

size_t amscr_contour_set_parent(const amscr_contour_set *s, size_t i)
{
    return s && i < s->n ? s->parent[i] : AMSCR_NO_PARENT;
}

int amscr_contour_set_is_hole(const amscr_contour_set *s, size_t i) { return s && i < s->n ? s->hole[i] : 0; }

double amscr_contour_set_area(const amscr_contour_set *s, size_t i) { return s && i < s->n ? s->area[i] : 0.0; }
