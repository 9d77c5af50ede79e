/* march.c — one closed iso-line by marching squares with linear interpolation
 * (docs/method.md §5).
 *
 * A cell is the square between four pixel centres c0 (top-left), c1 (top-right), c2
 * (bottom-right), c3 (bottom-left) of the padded field; its edge k joins c(k) and c(k+1).
 * The line crosses edge k where the field changes sign, at the linearly interpolated zero;
 * it enters the cell through an edge with foreground at c(k) and leaves through one with
 * foreground at c(k+1), so the foreground stays on the same side all along. A saddle cell
 * (two opposite foreground corners) has two entries and two exits: the exit taken is the
 * first after the entry in corner order, which joins the foreground corners (foreground
 * 8-connected, background 4-connected: the topology of the pixel labelling in trace_all.c,
 * so every iso-line separates one foreground region from one background region). The
 * padding frame is background, so every line closes inside the padded image. */
#include "internal.h"
#include "iso_level.h"

#include <stdlib.h>

static const int mc_ox[4] = {0, 1, 1, 0};
static const int mc_oy[4] = {0, 0, 1, 1};

/* Appends (x, y) unless it repeats the last point; grows the buffer. */
static amscr_status mc_push(double **xy, size_t *n, size_t *cap, double x, double y, const char *fn)
{
    if (*n > 0 && (*xy)[2 * *n - 2] == x && (*xy)[2 * *n - 1] == y)
        return AMSCR_OK;
    if (*n == AMSCR_MAX_POINTS)
        return amscr__fail(AMSCR_E_LIMIT, "%s: a boundary exceeds %u points", fn, (unsigned)AMSCR_MAX_POINTS);
    if (*n == *cap) {
        size_t ncap = 2 * *cap > AMSCR_MAX_POINTS ? AMSCR_MAX_POINTS : 2 * *cap;
        double *nxy = realloc(*xy, ncap * 2 * sizeof *nxy);
        if (!nxy)
            return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (%zu boundary points)", fn, ncap);
        *xy = nxy;
        *cap = ncap;
    }
    (*xy)[2 * *n] = x;
    (*xy)[2 * *n + 1] = y;
    (*n)++;
    return AMSCR_OK;
}

/* One step: the crossing on entry edge k of cell (cx, cy) into (*x, *y) (image coordinates)
 * and the exit edge, or -1 when k is not an entry. */
static int mc_step(const amscr__iso *f, size_t cx, size_t cy, int k, double *x, double *y)
{
    double v[4];
    int on[4];
    for (int i = 0; i < 4; i++) {
        v[i] = amscr__iso_at(f, cx + (size_t)mc_ox[i], cy + (size_t)mc_oy[i]);
        on[i] = v[i] > 0.0;
    }
    int k1 = (k + 1) & 3;
    if (!on[k] || on[k1])
        return -1;
    double t = v[k] / (v[k] - v[k1]);
    *x = (double)cx + mc_ox[k] + t * (mc_ox[k1] - mc_ox[k]) - 1.0;
    *y = (double)cy + mc_oy[k] + t * (mc_oy[k1] - mc_oy[k]) - 1.0;
    for (int i = 1; i < 4; i++) {
        int j = (k + i) & 3;
        if (!on[j] && on[(j + 1) & 3])
            return j;
    }
    return -1;
}

amscr_status amscr__march(const amscr__iso *f, size_t cx, size_t cy, int entry, const char *fn, double **out_xy,
                          size_t *out_n)
{
    const size_t cw = f->w + 1, ch = f->h + 1; /* cells of the padded field */
    const size_t max_steps = 4 * cw * ch + 4;
    size_t n = 0, cap = 16, x0 = cx, y0 = cy; /* grown by doubling: a speck's contour keeps 16 points' room, not 256 */
    const int e0 = entry;
    double *xy = malloc(cap * 2 * sizeof *xy);
    if (!xy)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", fn);
    amscr_status st = AMSCR_OK;
    for (size_t step = 0;; step++) {
        double x, y;
        int j = mc_step(f, cx, cy, entry, &x, &y);
        if (j < 0 || step > max_steps) {
            st = amscr__fail(AMSCR_E_INTERNAL, "%s: the iso-line walk lost its way", fn);
            break;
        }
        st = mc_push(&xy, &n, &cap, x, y, fn);
        if (st != AMSCR_OK)
            break;
        static const int nx[4] = {0, 1, 0, -1}, ny[4] = {-1, 0, 1, 0};
        if ((j == 0 && cy == 0) || (j == 1 && cx + 1 >= cw) || (j == 2 && cy + 1 >= ch) || (j == 3 && cx == 0)) {
            st = amscr__fail(AMSCR_E_INTERNAL, "%s: the iso-line left the padded image", fn);
            break;
        }
        cx = (size_t)((ptrdiff_t)cx + nx[j]);
        cy = (size_t)((ptrdiff_t)cy + ny[j]);
        entry = (j + 2) & 3;
        if (cx == x0 && cy == y0 && entry == e0)
            break;
    }
    if (st == AMSCR_OK && n > 1 && xy[0] == xy[2 * n - 2] && xy[1] == xy[2 * n - 1])
        n--; /* no repeated closing point */
    if (st != AMSCR_OK) {
        free(xy);
        return st;
    }
    *out_xy = xy;
    *out_n = n;
    return AMSCR_OK;
}
