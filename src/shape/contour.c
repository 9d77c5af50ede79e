/* contour.c — the contour object, validation and orientation. */
#include "dense.h"
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

amscr_status amscr__contour_wrap(double *xy, size_t n, amscr_contour **out)
{
    amscr_contour *c = malloc(sizeof *c);
    if (!c) {
        free(xy);
        return amscr__fail(AMSCR_E_NOMEM, "contour: out of memory");
    }
    c->n = n;
    c->xy = xy;
    *out = c;
    return AMSCR_OK;
}

amscr_status amscr_contour_new(const double *xy, size_t n, amscr_contour **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out);
    if (n == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_new: no points");
    if (n > AMSCR_MAX_POINTS)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_contour_new: %zu points exceed the limit %u", n,
                           (unsigned)AMSCR_MAX_POINTS);
    double *copy = amscr__malloc_array(2 * n, sizeof *copy);
    if (!copy)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_new: out of memory");
    memcpy(copy, xy, 2 * n * sizeof *copy);
    return amscr__contour_wrap(copy, n, out);
}

void amscr_contour_free(amscr_contour *c)
{
    if (!c)
        return;
    free(c->xy);
    free(c);
}

size_t amscr_contour_size(const amscr_contour *c) { return c ? c->n : 0; }

const double *amscr_contour_xy(const amscr_contour *c) { return c ? c->xy : NULL; }

double amscr__signed_area(const double *xy, size_t n)
{
    /* Shoelace formula, centred on the first point for accuracy. */
    double s = 0.0, x0 = xy[0], y0 = xy[1];
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1 == n) ? 0 : i + 1;
        double xi = xy[2 * i] - x0, yi = xy[2 * i + 1] - y0;
        double xj = xy[2 * j] - x0, yj = xy[2 * j + 1] - y0;
        s += xi * yj - xj * yi;
    }
    return 0.5 * s;
}

amscr_status amscr_contour_signed_area(const amscr_contour *c, double *out_area)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(c);
    AMSCR_CHECK_NULL(out_area);
    if (!amscr__all_finite(c->xy, 2 * c->n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "contour has non-finite coordinates");
    *out_area = c->n ? amscr__signed_area(c->xy, c->n) : 0.0;
    return AMSCR_OK;
}

void amscr__reverse_points(double *xy, size_t n)
{
    for (size_t i = 0, j = n ? n - 1 : 0; i < j; i++, j--) {
        double tx = xy[2 * i], ty = xy[2 * i + 1];
        xy[2 * i] = xy[2 * j];
        xy[2 * i + 1] = xy[2 * j + 1];
        xy[2 * j] = tx;
        xy[2 * j + 1] = ty;
    }
}

amscr_status amscr_contour_orient_ccw(amscr_contour *c)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(c);
    if (!amscr__all_finite(c->xy, 2 * c->n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "contour has non-finite coordinates");
    if (c->n >= 3 && amscr__signed_area(c->xy, c->n) < 0.0)
        amscr__reverse_points(c->xy, c->n);
    return AMSCR_OK;
}

void amscr__points_extent(const double *p, size_t n, double lo[2], double hi[2])
{
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], p[2 * i + k]);
            hi[k] = fmax(hi[k], p[2 * i + k]);
        }
}

size_t amscr__dedupe_points(const double *xy, size_t n, int closed, double *out)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        if (m > 0 && out[2 * (m - 1)] == x && out[2 * (m - 1) + 1] == y)
            continue;
        out[2 * m] = x;
        out[2 * m + 1] = y;
        m++;
    }
    if (closed)
        while (m > 1 && out[0] == out[2 * (m - 1)] && out[1] == out[2 * (m - 1) + 1])
            m--;
    return m;
}

amscr_status amscr__validate_points(const double *xy, size_t n, int closed, const char *what)
{
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: non-finite coordinates", what);
    /* count distinct consecutive points */
    size_t m = n ? 1 : 0;
    for (size_t i = 1; i < n; i++)
        if (xy[2 * i] != xy[2 * i - 2] || xy[2 * i + 1] != xy[2 * i - 1])
            m++;
    if (closed && m > 1 && xy[0] == xy[2 * (n - 1)] && xy[1] == xy[2 * (n - 1) + 1])
        m--;
    if (m < 8)
        return amscr__fail(AMSCR_E_DEGENERATE, "%s: %zu distinct points, at least 8 are needed", what, m);
    /* extent, for a scale-aware tolerance */
    double lo[2], hi[2];
    amscr__bounds(xy, n, lo, hi);
    double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    if (!(ext > 0.0))
        return amscr__fail(AMSCR_E_DEGENERATE, "%s: all points coincide", what);
    if (!(ext >= AMSCR__EXTENT_MIN && ext <= AMSCR__EXTENT_MAX))
        return amscr__fail(AMSCR_E_DEGENERATE, "%s: the points span %g, outside %g to %g: rescale them", what, ext,
                           AMSCR__EXTENT_MIN, AMSCR__EXTENT_MAX);
    double far = fmax(fabs(0.5 * lo[0] + 0.5 * hi[0]), fabs(0.5 * lo[1] + 0.5 * hi[1]));
    if (!(far <= AMSCR__OFFSET_MAX * ext))
        return amscr__fail(AMSCR_E_DEGENERATE, "%s: the points lie %g from the origin, %.3g times their extent %g: "
                           "doubles there hold too few of their digits; subtract an offset (e.g. the first point)",
                           what, far, far / ext, ext);
    /* second moments: collinear points have a singular covariance */
    double cx, cy, cov[3];
    amscr__centroid(xy, n, &cx, &cy);
    amscr__scatter(xy, n, cx, cy, ext, cov);
    double sxx = cov[0] / (double)n, sxy = cov[1] / (double)n, syy = cov[2] / (double)n;
    double det = sxx * syy - sxy * sxy, tr = sxx + syy;
    if (!(det > 1e-10 * tr * tr))
        return amscr__fail(AMSCR_E_DEGENERATE, "%s: points are (nearly) collinear", what);
    if (closed) {
        double area = fabs(amscr__signed_area(xy, n));
        if (!(area > 1e-9 * ext * ext))
            return amscr__fail(AMSCR_E_DEGENERATE, "%s: closed curve with zero area", what);
    }
    return AMSCR_OK;
}

amscr_status amscr_contour_validate(const amscr_contour *c, int closed)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(c);
    AMSCR_CHECK_FLAG(closed);
    return amscr__validate_points(c->xy, c->n, closed, "contour");
}
