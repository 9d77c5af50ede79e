/* pixel_grid.c — the pixel_grid stage: a shape traced from a small binary image (docs/method.md
 * §11.7), the target or, where the target is not one, the source.
 *
 * Such a shape's points lie on the pixel lattice, halfway between a foreground and a background
 * pixel centre: each has one integer and one half-integer coordinate (a sub-pixel trace of a
 * two-valued image: amscr_contour_from_image, scikit-image's find_contours at level 0.5). Where
 * the grid is coarse against the shape, the tracing is biased: corners are cut, a thin part is
 * narrowed or lost. The stage simulates that bias under the map found: the other shape under the
 * map (the source, or the target under its inverse) is rendered on the small shape's grid as a
 * camera and a threshold at half level would (amscr__raster_cover), traced as the small shape
 * was, and each of the small shape's points moved back by the bias its nearest synthetic point
 * shows against the mapped shape. The pair is registered again with the corrected points, and
 * the new map kept only when its rendering differs from the small shape's image (the pixels whose
 * centre its trace contains) in fewer pixels than the first map's. A kept map's inliers,
 * correspondences and standard error are then measured on the pair as traced (correspond.c), as
 * its check is (check.c): the corrected points would flatter it. register.c runs the second
 * registration between amscr__grid_correct and amscr__grid_choose, once the stage table has
 * finished (the table records whether the stage's condition held; amscr__pixel_grid_side says
 * for which side). */
#include "dense.h"
#include "match.h"
#include "nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The stage runs where the small shape, and the other under the map found, have an RMS radius of
 * at most this many pixels (a shape up to about 120 px across): there the tracing's bias (about a
 * quarter pixel RMS) is a measurable share of the radius. Chosen on data (docs/decisions.md,
 * the constants table): below it the stage gains on the three sets at 30-80 px across (radii up
 * to 38 px); at 200 px (radii from 58 px) it gains and loses alike under damage and costs 70 %
 * more time. The mapped shape counts too: a large target cut to a small piece is damaged, not
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

/* The map X (f onto h) in input coordinates, from the other shape into the small side's: inverted
 * when the side is the source. 0 when it cannot be inverted (no allocation, no error). */
static int side_map(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6], int side, double A[6])
{
    input_map(f, h->inv, X, A);
    return side != AMSCR__GRID_SOURCE || amscr__affine_inverse(A, A);
}

/* Whether the shape d, small and on the pixel lattice, can be corrected against the other, o,
 * under the map A from o into d (the stage's condition for that side). */
static int side_small(const amscr_descriptor *d, const amscr_descriptor *o, const double A[6])
{
    return amscr__on_pixel_lattice(d) && amscr__grid_small(d->raw, d->nraw) && o->raw &&
           mapped_radius(A, o->raw, o->nraw) <= AMSCR__GRID_RADIUS_MAX;
}

int amscr__pixel_grid_side(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6])
{
    double A[6];
    if (side_map(f, h, X, AMSCR__GRID_TARGET, A) && side_small(h, f, A))
        return AMSCR__GRID_TARGET;
    if ((amscr__on_pixel_lattice(h) || amscr__is_pixel_chain(h)) && side_map(f, h, X, AMSCR__GRID_SOURCE, A) &&
        side_small(f, h, A))
        return AMSCR__GRID_SOURCE;
    return 0;
}

/* ---- the grid ---- */
typedef struct {
    long x0, y0;
    size_t w, h;
} box_t;

/* The pixels around the small shape (T) and the other mapped (M), two pixels beyond either, at
 * most T's own extent beyond T (a map far off is far off by any count). */
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

/* The mapped shape M as the camera would see it on the small shape T's grid: the box around both
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

/* The pixels where the rendering differs from the small shape's image (T's pixel centres). */
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

/* The rendering traced as the small shape was: *out (2 *out_n, input coordinates, caller frees).
 * AMSCR_E_NOT_FOUND or AMSCR_E_DEGENERATE when nothing of the mapped shape survives the grid. */
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

/* Each synthetic point's bias against the mapped shape M: its offset from its closest point on
 * M's polygon, into bias (2 nc). */
static amscr_status trace_bias(const double *M, size_t nm, const double *C, size_t nc, double *bias)
{
    amscr__grid g = {0};
    int ok = amscr__grid_build(&g, M, nm);
    if (ok <= 0) {
        amscr__grid_free(&g);
        return ok < 0 ? amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory")
                      : amscr__fail(AMSCR_E_DEGENERATE, "pixel grid: the mapped shape is not finite");
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

/* The small shape's points T moved back by the bias of their nearest synthetic point (the
 * rendering rd of the other shape mapped, M, traced): *out (a new contour). AMSCR_E_NOT_FOUND /
 * AMSCR_E_DEGENERATE: nothing to correct by. */
static amscr_status corrected_points(const double *M, size_t nm, const rendering_t *rd, const double *T, size_t nt,
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

/* The small side's descriptor (the one corrected) and the other's. */
static const amscr_descriptor *small_of(const amscr_descriptor *f, const amscr_descriptor *h, int side)
{
    return side == AMSCR__GRID_SOURCE ? f : h;
}
static const amscr_descriptor *other_of(const amscr_descriptor *f, const amscr_descriptor *h, int side)
{
    return side == AMSCR__GRID_SOURCE ? h : f;
}

/* The other shape's points under the map X (f onto h) in the small side's coordinates: *out
 * (2 nraw of the other, caller frees); AMSCR_E_DEGENERATE when the map cannot be inverted. */
static amscr_status mapped_other(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6], int side,
                                 double **out)
{
    const amscr_descriptor *o = other_of(f, h, side);
    double A[6];
    *out = NULL;
    if (!side_map(f, h, X, side, A))
        return amscr__fail(AMSCR_E_DEGENERATE, "pixel grid: the map cannot be inverted");
    *out = amscr__malloc_array(2 * o->nraw, sizeof **out);
    if (!*out)
        return amscr__fail(AMSCR_E_NOMEM, "pixel grid: out of memory");
    map_points(A, o->raw, o->nraw, *out);
    return AMSCR_OK;
}

/* The map X2 of the pair with the small side replaced by d2, carried into the frames of f and h
 * (in place). */
static void carried(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_descriptor *d2, int side,
                    double X[6])
{
    double t[6];
    if (side == AMSCR__GRID_SOURCE) { /* X' = X2 o fwd(f2) o inv(f) */
        amscr__affine_compose(d2->fwd, f->inv, t);
        amscr__affine_compose(X, t, X);
    } else { /* X' = fwd(h) o inv(h2) o X2 */
        amscr__affine_compose(d2->inv, X, t);
        amscr__affine_compose(h->fwd, t, X);
    }
}

/* The first map's result r gives way to the second's, r2 (of the pair with the small side
 * corrected, d2): its map carried into the frames of f and h (the first alternative is that map,
 * bit for bit as the result reports it), its correspondences and standard error measured on f and
 * h. r keeps its record of the stages that ran. */
static amscr_status adopt(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                          const amscr_descriptor *d2, int side, amscr_result *r, amscr_result *r2)
{
    unsigned char ran[AMSCR__NUM_STAGES];
    memcpy(ran, r->ran, sizeof ran);
    free(r->corr);
    *r = *r2;
    r2->corr = NULL;
    memcpy(r->ran, ran, sizeof ran);
    r->backward = 0;
    carried(f, h, d2, side, r->m.X);
    input_map(f, h->inv, r->m.X, r->alt[0]); /* the chosen map first, as the result reports it */
    return amscr__correspond(prm, f, h, r);
}

amscr_status amscr__grid_correct(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_result *r, int side,
                                 amscr_descriptor **out_d2, size_t *out_differ)
{
    const amscr_descriptor *d = small_of(f, h, side), *o = other_of(f, h, side);
    double *M = NULL;
    amscr_contour *c = NULL;
    rendering_t rd = {{0, 0, 0, 0}, NULL};
    *out_d2 = NULL;
    amscr_status st = mapped_other(f, h, r->m.X, side, &M);
    if (st == AMSCR_OK)
        st = render(M, o->nraw, d->raw, d->nraw, &rd);
    if (st == AMSCR_OK)
        st = pixels_differing(&rd, d->raw, d->nraw, out_differ);
    if (st == AMSCR_OK)
        st = corrected_points(M, o->nraw, &rd, d->raw, d->nraw, &c);
    if (st == AMSCR_OK)
        st = amscr_descriptor_new(&d->params, c, out_d2);
    free(rd.img);
    free(M);
    amscr_contour_free(c);
    if (st != AMSCR_OK && st != AMSCR_E_NOMEM) {
        st = AMSCR_OK; /* nothing of the mapped shape survived the grid: no correction */
        amscr__clear_error();
    }
    return st;
}

/* A second map that cannot be inverted is not kept. */
static amscr_status keep_first(void)
{
    amscr__clear_error();
    return AMSCR_OK;
}

amscr_status amscr__grid_choose(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                const amscr_descriptor *d2, int side, size_t first_differ, amscr_result *r,
                                amscr_result *r2)
{
    const amscr_descriptor *d = small_of(f, h, side), *o = other_of(f, h, side);
    double *M2 = NULL;
    rendering_t rd = {{0, 0, 0, 0}, NULL};
    size_t second_differ = 0;
    amscr_status st = side == AMSCR__GRID_SOURCE ? mapped_other(d2, h, r2->m.X, side, &M2)
                                                 : mapped_other(f, d2, r2->m.X, side, &M2);
    if (st == AMSCR_OK)
        st = render(M2, o->nraw, d->raw, d->nraw, &rd);
    if (st == AMSCR_OK)
        st = pixels_differing(&rd, d->raw, d->nraw, &second_differ);
    free(rd.img);
    free(M2);
    if (st != AMSCR_OK || second_differ >= first_differ)
        return st == AMSCR_E_DEGENERATE ? keep_first() : st;
    double X[6];
    memcpy(X, r2->m.X, sizeof X);
    carried(f, h, d2, side, X);
    /* a clearly different map chosen by the image: the first is its alternative, by pixels */
    double amb = amscr__map_gap2(f, X, r->m.X) > AMSCR__DISTINCT_GAP2 ? (double)second_differ / (double)first_differ
                                                                      : 0.0;
    st = adopt(prm, f, h, d2, side, r, r2);
    if (st == AMSCR_OK && amb > r->m.ambiguity)
        r->m.ambiguity = amb;
    return st;
}

