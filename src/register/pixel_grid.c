/* pixel_grid.c — the pixel_grid stage: a target traced from a binary image (docs/method.md §11.7).
 *
 * Such a target's points lie on the pixel lattice, halfway between a foreground and a background
 * pixel centre: each has one integer and one half-integer coordinate (a sub-pixel trace of a
 * two-valued image: amscr_contour_from_image, scikit-image's find_contours at level 0.5). Where
 * the grid is coarse against the shape, the tracing is biased: corners are cut, a thin part is
 * narrowed or lost. The stage simulates that bias under the map found: the source under the map
 * is rendered on the target's grid as a camera and a threshold at half level would
 * (amscr__raster_cover), traced as the target was, and each target point moved back by the bias
 * its nearest synthetic point shows against the mapped source. The source is registered again
 * onto the corrected points, and the new map kept only when its rendering differs from the target
 * image (the pixels whose centre the traced target contains) in fewer pixels than the first
 * map's. A kept map's inliers, correspondences and standard error are then measured on the target
 * as traced (correspond.c), as its check is (check.c): the corrected points would flatter it.
 * register.c runs the second registration between amscr__grid_target and amscr__grid_choose, once
 * the stage table has finished (the table records whether the stage's condition held). */
#include "dense.h"
#include "match.h"
#include "nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The stage runs where the target, and the source under the map found, have an RMS radius of at
 * most this many pixels (a shape up to about 120 px across): there the tracing's bias (about a
 * quarter pixel RMS) is a measurable share of the radius. Chosen on data (docs/decisions.md,
 * the constants table): below it the stage gains on the three sets at 30-80 px across (radii up
 * to 38 px); at 200 px (radii from 58 px) it gains and loses alike under damage and costs 70 %
 * more time. The mapped source counts too: a large target cut to a small piece is damaged, not
 * coarse, and the pixels it differs in would favour a map shrunk onto the piece. */
#define AMSCR__GRID_RADIUS_MAX 40.0

/* Every point has one integer and one half-integer coordinate. */
static int on_lattice(const double *p, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double x = 2.0 * p[2 * i], y = 2.0 * p[2 * i + 1];
        if (!(fabs(x) < 1e15 && fabs(y) < 1e15) || x != floor(x) || y != floor(y))
            return 0;
        int hx = fmod(fabs(x), 2.0) == 1.0, hy = fmod(fabs(y), 2.0) == 1.0;
        if (hx == hy)
            return 0;
    }
    return n > 0;
}

/* The map in input coordinates of a map of normalized frames X (f onto a target of inverse
 * frame inv). */
static void input_map(const amscr_descriptor *f, const double inv[6], const double X[6], double A[6])
{
    double t[6];
    amscr__affine_compose(X, f->fwd, t);
    amscr__affine_compose(inv, t, A);
}

static void map_points(const double A[6], const double *p, size_t n, double *out)
{
    for (size_t i = 0; i < n; i++) {
        double x = p[2 * i], y = p[2 * i + 1];
        out[2 * i] = A[0] * x + A[1] * y + A[2];
        out[2 * i + 1] = A[3] * x + A[4] * y + A[5];
    }
}

/* The source's points under a map of normalized frames X (f onto a target of inverse frame inv):
 * *out (2 f->nraw, caller frees). */
static amscr_status mapped_source(const amscr_descriptor *f, const double inv[6], const double X[6], double **out)
{
    double A[6];
    input_map(f, inv, X, A);
    *out = amscr__malloc_array(2 * f->nraw, sizeof **out);
    if (!*out)
        return amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    map_points(A, f->raw, f->nraw, *out);
    return AMSCR_OK;
}

/* The RMS radius of the n points p under the linear part of A: sqrt(trace(A C A^T)), C their
 * covariance (no allocation: a stage's condition cannot fail). */
static double mapped_radius(const double A[6], const double *p, size_t n)
{
    double cx, cy, sxx = 0.0, sxy = 0.0, syy = 0.0;
    amscr__centroid(p, n, &cx, &cy);
    for (size_t i = 0; i < n; i++) {
        double x = p[2 * i] - cx, y = p[2 * i + 1] - cy;
        sxx += x * x, sxy += x * y, syy += y * y;
    }
    double r2 = 0.0;
    for (int k = 0; k < 2; k++) {
        double a = A[3 * k], b = A[3 * k + 1];
        r2 += a * a * sxx + 2.0 * a * b * sxy + b * b * syy;
    }
    return sqrt(r2 / (double)n);
}

int amscr__grid_small(const double *p, size_t n)
{
    static const double I[6] = {1, 0, 0, 0, 1, 0};
    return mapped_radius(I, p, n) <= AMSCR__GRID_RADIUS_MAX;
}

int amscr__grid_mapped_small(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6])
{
    double A[6];
    input_map(f, h->inv, X, A);
    return f->raw && mapped_radius(A, f->raw, f->nraw) <= AMSCR__GRID_RADIUS_MAX;
}

int amscr__on_pixel_lattice(const amscr_descriptor *d)
{
    return d->raw && on_lattice(d->raw, d->nraw);
}

int amscr__pixel_grid_applies(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6])
{
    return amscr__on_pixel_lattice(h) && amscr__grid_small(h->raw, h->nraw) && amscr__grid_mapped_small(f, h, X);
}

/* ---- the grid ---- */
typedef struct {
    long x0, y0;
    size_t w, h;
} box_t;

void amscr__points_extent(const double *p, size_t n, double lo[2], double hi[2])
{
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], p[2 * i + k]);
            hi[k] = fmax(hi[k], p[2 * i + k]);
        }
}

/* The pixels around the target (T) and the mapped source (M), two pixels beyond either, at most
 * the target's own extent beyond the target (a map far off is far off by any count). */
static box_t grid_box(const double *T, size_t nt, const double *M, size_t nm)
{
    double tl[2] = {INFINITY, INFINITY}, th[2] = {-INFINITY, -INFINITY};
    amscr__points_extent(T, nt, tl, th);
    double lo[2] = {tl[0], tl[1]}, hi[2] = {th[0], th[1]};
    amscr__points_extent(M, nm, lo, hi);
    long b[2][2];
    for (int k = 0; k < 2; k++) {
        double span = th[k] - tl[k];
        b[k][0] = (long)floor(fmax(lo[k], tl[k] - span)) - 2;
        b[k][1] = (long)ceil(fmin(hi[k], th[k] + span)) + 2;
    }
    box_t box = {b[0][0], b[1][0], (size_t)(b[0][1] - b[0][0] + 1), (size_t)(b[1][1] - b[1][0] + 1)};
    return box;
}

/* The mapped source M as the camera would see it on the target T's grid: the box around both
 * and its pixels (img, b.w * b.h bytes, caller frees). */
typedef struct {
    box_t b;
    uint8_t *img;
} rendering_t;

static amscr_status render(const double *M, size_t nm, const double *T, size_t nt, rendering_t *out)
{
    out->b = grid_box(T, nt, M, nm);
    out->img = amscr__malloc_array(out->b.w, out->b.h);
    if (!out->img)
        return amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    return amscr__raster_cover(M, nm, out->b.x0, out->b.y0, out->b.w, out->b.h, out->img);
}

/* The pixels where the rendering differs from the target image (T's pixel centres). */
static amscr_status pixels_differing(const rendering_t *rd, const double *T, size_t nt, size_t *out)
{
    box_t b = rd->b;
    uint8_t *tgt = amscr__malloc_array(b.w, b.h);
    if (!tgt)
        return amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    amscr_status st = amscr__raster_centres(T, nt, b.x0, b.y0, b.w, b.h, tgt);
    size_t d = 0;
    for (size_t i = 0; st == AMSCR_OK && i < b.w * b.h; i++)
        d += rd->img[i] != tgt[i];
    *out = d;
    free(tgt);
    return st;
}

/* The rendering traced as the target was: *out (2 *out_n, input coordinates, caller frees).
 * AMSCR_E_NOT_FOUND or AMSCR_E_DEGENERATE when nothing of the mapped source survives the grid. */
static amscr_status synthetic_trace(const rendering_t *rd, double **out, size_t *out_n)
{
    box_t b = rd->b;
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_image(rd->img, b.w, b.h, b.w, 8, 127.5, AMSCR_TRACE_JOIN, &c);
    if (st != AMSCR_OK)
        return st;
    for (size_t i = 0; i < c->n; i++) {
        c->xy[2 * i] += (double)b.x0;
        c->xy[2 * i + 1] += (double)b.y0;
    }
    *out = c->xy;
    *out_n = c->n;
    c->xy = NULL;
    amscr_contour_free(c);
    return AMSCR_OK;
}

/* Each synthetic point's bias against the mapped source M: its offset from its closest point on
 * M's polygon, into bias (2 nc). */
static amscr_status trace_bias(const double *M, size_t nm, const double *C, size_t nc, double *bias)
{
    amscr__grid g = {0};
    int ok = amscr__grid_build(&g, M, nm);
    if (ok <= 0) {
        amscr__grid_free(&g);
        return ok < 0 ? amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory")
                      : amscr__fail(AMSCR_E_DEGENERATE, "pixel grid: the mapped source is not finite");
    }
    for (size_t k = 0; k < nc; k++) {
        double qx = C[2 * k], qy = C[2 * k + 1], d2, t;
        size_t seg, v = amscr__grid_nearest(&g, M, qx, qy, &d2);
        amscr__edge_foot(M, nm, v, qx, qy, &seg, &t);
        size_t nx = seg + 1 == nm ? 0 : seg + 1;
        bias[2 * k] = qx - (M[2 * seg] + t * (M[2 * nx] - M[2 * seg]));
        bias[2 * k + 1] = qy - (M[2 * seg + 1] + t * (M[2 * nx + 1] - M[2 * seg + 1]));
    }
    amscr__grid_free(&g);
    return AMSCR_OK;
}

/* The target's points T moved back by the bias of their nearest synthetic point (the rendering
 * rd of the mapped source M traced): *out (a new contour). AMSCR_E_NOT_FOUND /
 * AMSCR_E_DEGENERATE: nothing to correct by. */
static amscr_status corrected_target(const double *M, size_t nm, const rendering_t *rd, const double *T, size_t nt,
                                     amscr_contour **out)
{
    double *C = NULL, *bias = NULL, *xy = amscr__malloc_array(2 * nt, sizeof *xy);
    size_t nc = 0;
    amscr__grid g = {0};
    amscr_status st = xy ? synthetic_trace(rd, &C, &nc) : AMSCR_E_NOMEM;
    if (st == AMSCR_OK)
        st = (bias = amscr__malloc_array(2 * nc, sizeof *bias)) ? trace_bias(M, nm, C, nc, bias) : AMSCR_E_NOMEM;
    if (st == AMSCR_OK && amscr__grid_build(&g, C, nc) < 0)
        st = AMSCR_E_NOMEM;
    if (st == AMSCR_E_NOMEM)
        amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    for (size_t i = 0; st == AMSCR_OK && i < nt; i++) {
        double d2;
        size_t k = amscr__grid_nearest(&g, C, T[2 * i], T[2 * i + 1], &d2);
        xy[2 * i] = T[2 * i] - bias[2 * k];
        xy[2 * i + 1] = T[2 * i + 1] - bias[2 * k + 1];
    }
    amscr__grid_free(&g);
    free(C);
    free(bias);
    if (st == AMSCR_OK)
        return amscr__contour_wrap(xy, nt, out); /* takes xy */
    free(xy);
    return st;
}

/* The first map's result r gives way to the second's, r2 (of f onto h2, the corrected target):
 * its map carried into h's normalized frame (the first alternative is that map, bit for bit as
 * the result reports it), its correspondences and standard error measured on h. r keeps its
 * record of the stages that ran. */
static amscr_status adopt(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                          const amscr_descriptor *h2, amscr_result *r, amscr_result *r2)
{
    unsigned char ran[AMSCR__NUM_STAGES];
    memcpy(ran, r->ran, sizeof ran);
    free(r->corr);
    *r = *r2;
    r2->corr = NULL;
    memcpy(r->ran, ran, sizeof ran);
    r->backward = 0;
    double t[6];
    amscr__affine_compose(h2->inv, r->m.X, t);
    amscr__affine_compose(h->fwd, t, r->m.X);
    input_map(f, h->inv, r->m.X, r->alt[0]); /* the chosen map first, as the result reports it */
    return amscr__correspond(prm, f, h, r);
}

amscr_status amscr__grid_target(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_result *r,
                                amscr_descriptor **out_h2, size_t *out_differ)
{
    double *M = NULL;
    amscr_contour *c = NULL;
    rendering_t rd = {{0, 0, 0, 0}, NULL};
    *out_h2 = NULL;
    amscr_status st = mapped_source(f, h->inv, r->m.X, &M);
    if (st == AMSCR_OK)
        st = render(M, f->nraw, h->raw, h->nraw, &rd);
    if (st == AMSCR_OK)
        st = pixels_differing(&rd, h->raw, h->nraw, out_differ);
    if (st == AMSCR_OK)
        st = corrected_target(M, f->nraw, &rd, h->raw, h->nraw, &c);
    if (st == AMSCR_OK)
        st = amscr_descriptor_new(&h->params, c, out_h2);
    free(rd.img);
    free(M);
    amscr_contour_free(c);
    if (st != AMSCR_OK && st != AMSCR_E_NOMEM) {
        st = AMSCR_OK; /* nothing of the mapped source survived the grid: no correction */
        amscr__clear_error();
    }
    return st;
}

amscr_status amscr__grid_choose(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                const amscr_descriptor *h2, size_t first_differ, amscr_result *r,
                                amscr_result *r2)
{
    double *M2 = NULL;
    rendering_t rd = {{0, 0, 0, 0}, NULL};
    size_t second_differ = 0;
    amscr_status st = mapped_source(f, h2->inv, r2->m.X, &M2);
    if (st == AMSCR_OK)
        st = render(M2, f->nraw, h->raw, h->nraw, &rd);
    if (st == AMSCR_OK)
        st = pixels_differing(&rd, h->raw, h->nraw, &second_differ);
    free(rd.img);
    free(M2);
    if (st == AMSCR_OK && second_differ < first_differ)
        st = adopt(prm, f, h, h2, r, r2);
    return st;
}
