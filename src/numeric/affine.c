/* affine.c — fitting, applying and inverting 2-D affine maps {a11, a12, tx, a21, a22, ty}. */
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

amscr_status amscr_affine_fit(const double *src_xy, const double *dst_xy, size_t n, double out_m6[6], double *out_rms)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src_xy);
    AMSCR_CHECK_NULL(dst_xy);
    AMSCR_CHECK_NULL(out_m6);
    if (n < 3)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_affine_fit: %zu points, at least 3 needed", n);
    double *a = amscr__malloc_array(3 * n, sizeof *a);
    if (!a)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_affine_fit: out of memory");
    for (size_t i = 0; i < n; i++) {
        a[3 * i] = src_xy[2 * i];
        a[3 * i + 1] = src_xy[2 * i + 1];
        a[3 * i + 2] = 1.0;
    }
    double x[6], res[2];
    amscr_status st = amscr_lstsq_qr(a, n, 3, dst_xy, 2, x, res);
    free(a);
    if (st != AMSCR_OK) {
        if (st == AMSCR_E_NUMERIC)
            amscr__fail(st, "amscr_affine_fit: the source points are collinear (or coincide)");
        return st;
    }
    /* x is 3 x 2 row-major: column 0 -> x', column 1 -> y' */
    out_m6[0] = x[0];
    out_m6[1] = x[2];
    out_m6[2] = x[4];
    out_m6[3] = x[1];
    out_m6[4] = x[3];
    out_m6[5] = x[5];
    if (out_rms)
        *out_rms = sqrt((res[0] * res[0] + res[1] * res[1]) / (double)n);
    return AMSCR_OK;
}

amscr_status amscr_affine_apply(const double m6[6], const double *xy, size_t n, double *out_xy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(m6);
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_xy);
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        out_xy[2 * i] = m6[0] * x + m6[1] * y + m6[2];
        out_xy[2 * i + 1] = m6[3] * x + m6[4] * y + m6[5];
    }
    return AMSCR_OK;
}

amscr_status amscr_affine_invert(const double m6[6], double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(m6);
    AMSCR_CHECK_NULL(out_m6);
    if (!amscr__all_finite(m6, 6))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_affine_invert: non-finite map");
    /* the linear part scaled by a power of 2 to entries below 1: its determinant neither overflows
     * nor underflows (1e300 or 1e-200 on the diagonal are regular maps), and the inverse is the
     * unscaled one's bit for bit wherever that one's determinant is representable */
    double big = fmax(fmax(fabs(m6[0]), fabs(m6[1])), fmax(fabs(m6[3]), fabs(m6[4])));
    int e = 0;
    (void)frexp(big, &e);
    double s = ldexp(1.0, -e), a = m6[0] * s, b = m6[1] * s, c = m6[3] * s, d = m6[4] * s;
    double det = a * d - b * c, scale = fabs(a) + fabs(b) + fabs(c) + fabs(d);
    if (!(fabs(det) > 1e-14 * scale * scale))
        return amscr__fail(AMSCR_E_DEGENERATE, "amscr_affine_invert: singular map (det = %g x 2^%d)", det, 2 * e);
    double i0 = d / det * s, i1 = -b / det * s, i3 = -c / det * s, i4 = a / det * s;
    double r[6] = {i0, i1, -(i0 * m6[2] + i1 * m6[5]), i3, i4, -(i3 * m6[2] + i4 * m6[5])};
    if (!amscr__all_finite(r, 6))
        return amscr__fail(AMSCR_E_DEGENERATE, "amscr_affine_invert: the inverse map overflows a double");
    memcpy(out_m6, r, sizeof r);
    return AMSCR_OK;
}

int amscr__affine_inverse(const double m[6], double out[6])
{
    double det = m[0] * m[4] - m[1] * m[3];
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return 0;
    double i0 = m[4] / det, i1 = -m[1] / det, i3 = -m[3] / det, i4 = m[0] / det;
    double r[6] = {i0, i1, -(i0 * m[2] + i1 * m[5]), i3, i4, -(i3 * m[2] + i4 * m[5])};
    memcpy(out, r, sizeof r);
    return 1;
}

/* out = a ∘ b (apply b first). */
void amscr__affine_compose(const double a[6], const double b[6], double out[6])
{
    double r[6];
    r[0] = a[0] * b[0] + a[1] * b[3];
    r[1] = a[0] * b[1] + a[1] * b[4];
    r[2] = a[0] * b[2] + a[1] * b[5] + a[2];
    r[3] = a[3] * b[0] + a[4] * b[3];
    r[4] = a[3] * b[1] + a[4] * b[4];
    r[5] = a[3] * b[2] + a[4] * b[5] + a[5];
    memcpy(out, r, sizeof r);
}
