/* resample.c — Euclidean and affine arc-length resampling, whitening normalization. */
#include "dense.h"
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>




/* Samples the polygon xy (n vertices) at m parameter values t (ascending, in the units of
 * cum: cum[i] is the parameter of vertex i, cum[0] = 0; closed: the closing edge spans
 * cum[n-1]..total). Linear interpolation. */
static void sample_polygon(const double *xy, size_t n, int closed, const double *cum, double total, const double *t,
                           size_t m, double *out)
{
    size_t seg = 0; /* current edge: vertex seg -> seg+1 */
    size_t nseg = closed ? n : n - 1;
    for (size_t k = 0; k < m; k++) {
        double tk = t[k];
        while (seg + 1 < nseg && tk >= cum[seg + 1])
            seg++;
        size_t a = seg, b = (seg + 1 == n) ? 0 : seg + 1;
        double t0 = cum[a], t1 = (seg + 1 == n) ? total : cum[b];
        double u = (t1 > t0) ? (tk - t0) / (t1 - t0) : 0.0;
        if (u < 0.0)
            u = 0.0;
        if (u > 1.0)
            u = 1.0;
        out[2 * k] = xy[2 * a] + u * (xy[2 * b] - xy[2 * a]);
        out[2 * k + 1] = xy[2 * a + 1] + u * (xy[2 * b + 1] - xy[2 * a + 1]);
    }
}

/* Cumulative Euclidean length at each vertex; returns the total (closed: with closing edge). */
static double euclid_cum(const double *xy, size_t n, int closed, double *cum)
{
    cum[0] = 0.0;
    for (size_t i = 1; i < n; i++)
        cum[i] = cum[i - 1] + hypot(xy[2 * i] - xy[2 * i - 2], xy[2 * i + 1] - xy[2 * i - 1]);
    double total = cum[n - 1];
    if (closed)
        total += hypot(xy[0] - xy[2 * n - 2], xy[1] - xy[2 * n - 1]);
    return total;
}

/* Equally spaced parameters: closed k*total/m, open k*total/(m-1). */
static void equal_params(double total, size_t m, int closed, double *t)
{
    for (size_t k = 0; k < m; k++)
        t[k] = closed ? total * (double)k / (double)m : total * (double)k / (double)(m - 1);
    if (!closed)
        t[m - 1] = total;
}

amscr_status amscr__resample_euclid(const double *xy, size_t n, int closed, size_t m, double *out)
{
    double *cum = amscr__malloc_array(n + m, sizeof *cum);
    if (!cum)
        return amscr__fail(AMSCR_E_NOMEM, "resampling: out of memory");
    double total = euclid_cum(xy, n, closed, cum);
    if (!(total > 0.0) || !isfinite(total)) {
        free(cum);
        return amscr__fail(AMSCR_E_DEGENERATE, "resampling: the curve has zero length");
    }
    double *t = cum + n;
    equal_params(total, m, closed, t);
    sample_polygon(xy, n, closed, cum, total, t, m, out);
    free(cum);
    return AMSCR_OK;
}

amscr_status amscr_resample_euclidean(const double *xy, size_t n, int closed, size_t m, double *out_xy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_xy);
    AMSCR_CHECK_FLAG(closed);
    if (n < 2 || m < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_euclidean: n = %zu and m = %zu must be >= 2", n, m);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_euclidean: non-finite coordinates");
    return amscr__resample_euclid(xy, n, closed, m, out_xy);
}

/* Affine speed at each sample of an (already smoothed) uniformly indexed curve, and the
 * cumulative trapezoid sum. Returns AMSCR_E_DEGENERATE when the curve is numerically straight. */
static amscr_status affine_cum_from_smoothed(const double *s, size_t n, int closed, double *v, double *cum,
                                             double *out_total)
{
    double sum_det = 0.0, sum_d1c = 0.0;
    for (size_t i = 0; i < n; i++) {
        /* centre c, neighbours im/ip: periodic when closed; at open ends the derivatives of
         * the nearest interior sample are used */
        size_t c, ip, im;
        if (closed) {
            c = i;
            ip = (i + 1 == n) ? 0 : i + 1;
            im = (i == 0) ? n - 1 : i - 1;
        } else {
            c = i == 0 ? 1 : (i + 1 == n ? n - 2 : i);
            ip = c + 1;
            im = c - 1;
        }
        double d1x, d1y, d2x, d2y;
        d1x = 0.5 * (s[2 * ip] - s[2 * im]);
        d1y = 0.5 * (s[2 * ip + 1] - s[2 * im + 1]);
        d2x = s[2 * ip] - 2.0 * s[2 * c] + s[2 * im];
        d2y = s[2 * ip + 1] - 2.0 * s[2 * c + 1] + s[2 * im + 1];
        double det = fabs(d1x * d2y - d2x * d1y);
        double sp = hypot(d1x, d1y);
        sum_det += det;
        sum_d1c += sp * sp * sp;
        v[i] = cbrt(det);
    }
    if (!(sum_det > 1e-10 * sum_d1c) || !isfinite(sum_det))
        return amscr__fail(AMSCR_E_DEGENERATE, "affine arc length: the curve is (numerically) straight");
    cum[0] = 0.0;
    for (size_t i = 1; i < n; i++)
        cum[i] = cum[i - 1] + 0.5 * (v[i - 1] + v[i]);
    *out_total = cum[n - 1] + (closed ? 0.5 * (v[n - 1] + v[0]) : 0.0);
    return AMSCR_OK;
}

amscr_status amscr__affine_cum(const double *xy, size_t n, int closed, double sigma0, double *cum, double *out_total)
{
    double *buf = amscr__malloc_array(3 * n, sizeof *buf);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "affine arc length: out of memory");
    double *s = buf, *v = buf + 2 * n;
    amscr_status st = amscr__smooth(xy, n, closed, sigma0, s);
    if (st == AMSCR_OK)
        st = affine_cum_from_smoothed(s, n, closed, v, cum, out_total);
    free(buf);
    return st;
}

amscr_status amscr_affine_arclength(const double *xy, size_t n, int closed, double sigma0, double *out_cumulative,
                                    double *out_total)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_cumulative);
    AMSCR_CHECK_NULL(out_total);
    AMSCR_CHECK_FLAG(closed);
    if (n < 5)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_affine_arclength: %zu points, at least 5 needed", n);
    if (!(sigma0 >= 0.0) || !(sigma0 <= 1e6))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_affine_arclength: sigma0 = %g must be in [0, 1e6]", sigma0);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_affine_arclength: non-finite coordinates");
    return amscr__affine_cum(xy, n, closed ? 1 : 0, sigma0, out_cumulative, out_total);
}

/* Region moments of a closed polygon (area centroid, second central moments / area), used by
 * the whitened parametrization. Returns 0 when the area vanishes. */
static int region_moments(const double *xy, size_t n, double *cx, double *cy, double cov[3])
{
    double x0 = xy[0], y0 = xy[1];
    double a = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1 == n) ? 0 : i + 1;
        double xi = xy[2 * i] - x0, yi = xy[2 * i + 1] - y0, xj = xy[2 * j] - x0, yj = xy[2 * j + 1] - y0;
        double c = xi * yj - xj * yi;
        a += c;
        sx += (xi + xj) * c;
        sy += (yi + yj) * c;
        sxx += (xi * xi + xi * xj + xj * xj) * c;
        syy += (yi * yi + yi * yj + yj * yj) * c;
        sxy += (xi * yj + 2 * xi * yi + 2 * xj * yj + xj * yi) * c;
    }
    a *= 0.5;
    if (!(fabs(a) > 0.0))
        return 0;
    double mx = sx / (6 * a), my = sy / (6 * a);
    double ixx = sxx / (12 * a), iyy = syy / (12 * a), ixy = sxy / (24 * a);
    *cx = mx + x0;
    *cy = my + y0;
    cov[0] = ixx - mx * mx;
    cov[1] = ixy - mx * my;
    cov[2] = iyy - my * my;
    return 1;
}

/* Inverse square root of a 2x2 SPD matrix [a b; b c] (and its square root). 0 if not SPD. */
int amscr__sym2_invsqrt(const double cov[3], double W[4], double Winv[4])
{
    double a = cov[0], b = cov[1], c = cov[2];
    double tr = a + c, det = a * c - b * b;
    if (!(det > 1e-300) || !(tr > 0.0) || !(det > 1e-14 * tr * tr))
        return 0;
    double s = sqrt(det), t = sqrt(tr + 2.0 * s);
    /* sqrt(M) = (M + s I) / t */
    double R[4] = {(a + s) / t, b / t, b / t, (c + s) / t};
    double rdet = R[0] * R[3] - R[1] * R[2];
    if (Winv)
        memcpy(Winv, R, sizeof R);
    if (W) {
        W[0] = R[3] / rdet;
        W[1] = -R[1] / rdet;
        W[2] = -R[2] / rdet;
        W[3] = R[0] / rdet;
    }
    return 1;
}

/* Parameter positions along a dense polygon P (n vertices, parameter = vertex index, the
 * closing edge from n-1 to n) -> sampled points. t: m values in [0, n) (closed) or [0, n-1]. */
static void sample_by_index(const double *P, size_t n, int closed, const double *t, size_t m, double *out)
{
    for (size_t k = 0; k < m; k++) {
        double tk = t[k];
        double fl = floor(tk);
        size_t a = (size_t)fl;
        double u = tk - fl;
        if (a >= n) {
            a = closed ? a % n : n - 1;
        }
        size_t b = (a + 1 == n) ? (closed ? 0 : a) : a + 1;
        out[2 * k] = P[2 * a] + u * (P[2 * b] - P[2 * a]);
        out[2 * k + 1] = P[2 * a + 1] + u * (P[2 * b + 1] - P[2 * a + 1]);
    }
}

/* Inverts a cumulative parameter: given cum over indices 0..n-1 (and total for the closed
 * edge), the index positions where cum takes the values `targets` (ascending). */
static void invert_cum(const double *cum, size_t n, int closed, double total, const double *targets, size_t m,
                       double *out_index)
{
    size_t seg = 0, nseg = closed ? n : n - 1;
    for (size_t k = 0; k < m; k++) {
        double tk = targets[k];
        while (seg + 1 < nseg && tk >= cum[seg + 1])
            seg++;
        double t0 = cum[seg], t1 = (seg + 1 == n) ? total : cum[seg + 1];
        double u = (t1 > t0) ? (tk - t0) / (t1 - t0) : 0.0;
        if (u < 0.0)
            u = 0.0;
        if (u > 1.0)
            u = 1.0;
        out_index[k] = (double)seg + u;
    }
}

/* Whitening matrix of a polygon: region moments when closed (exactly affine-covariant and
 * noise-robust), point moments otherwise. Returns 0 when singular. */
static int polygon_whitener(const double *P, size_t n, int closed, double W[4])
{
    double cx, cy, cov[3];
    if (closed && region_moments(P, n, &cx, &cy, cov) && amscr__sym2_invsqrt(cov, W, NULL))
        return 1;
    double mx, my;
    amscr__centroid(P, n, &mx, &my);
    amscr__scatter(P, n, mx, my, 1.0, cov);
    return amscr__sym2_invsqrt(cov, W, NULL);
}

/* Cumulative W-length over the vertices of a polygon (closed: total includes the closing edge). */
static double wlength_cum(const double *Q, size_t n, int closed, const double W[4], double *cum)
{
    cum[0] = 0.0;
    double total = 0.0;
    for (size_t i = 1; i <= n; i++) {
        if (i == n && !closed)
            break;
        size_t a = i - 1, b = (i == n) ? 0 : i;
        double dx = Q[2 * b] - Q[2 * a], dy = Q[2 * b + 1] - Q[2 * a + 1];
        double len = hypot(W[0] * dx + W[1] * dy, W[2] * dx + W[3] * dy);
        if (i < n)
            cum[i] = cum[i - 1] + len;
        else
            total = cum[n - 1] + len;
    }
    return closed ? total : cum[n - 1];
}

/* dst (cnt): positions in the index space of the M samples taken at positions pos of a polygon
 * of np vertices, mapped in place to positions on the polygon (vertex index + fraction). */
static void positions_on_polygon(const double *pos, size_t M, size_t np, int closed, double *dst, size_t cnt)
{
    for (size_t k = 0; k < cnt; k++) {
        double q = dst[k], fl = floor(q);
        size_t a = (size_t)fl;
        double u = q - fl;
        if (a >= M)
            a = M - 1;
        double pa = pos[a], pb;
        if (a + 1 < M)
            pb = pos[a + 1];
        else
            pb = closed ? pos[0] + (double)np : pos[M - 1];
        if (pb < pa) /* wrapped past the end of a closed polygon */
            pb += (double)np;
        dst[k] = pa + u * (pb - pa);
        if (closed && dst[k] >= (double)np)
            dst[k] -= (double)np;
    }
}

/* The parametrizations. P: the input polygon (np vertices). It is first densified to M
 * points equally spaced in arc length of the polygon after the whitening W (W = I for the
 * Euclidean and affine kinds; region moments for the whitened kind, which makes the
 * densification exactly affine-covariant). Each pass then measures the parameter on a copy
 * of the current samples smoothed over their index (sigma0_frac of the length; a linear filter,
 * so affine-covariant) — affine speed |det(f', f'')|^(1/3) for the affine kind, W-length
 * otherwise — and re-places the samples; positions always refer to the ORIGINAL polygon, so
 * nothing is lost to repeated interpolation. Output: m points of P. */
amscr_status amscr__parametrize(const double *P, size_t np, int closed, amscr_parametrization kind, double sigma0_frac,
                                unsigned passes, size_t M, size_t m, double *out)
{
    amscr_status st = AMSCR_OK;
    double W[4] = {1, 0, 0, 1};
    if (kind == AMSCR_PARAM_WHITENED && !polygon_whitener(P, np, closed, W))
        return amscr__fail(AMSCR_E_DEGENERATE, "parametrization: singular moments (collinear curve)");
    size_t big = M > np ? M : np;
    double *buf = amscr__malloc_array(10 * big + m + 8, sizeof *buf);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "parametrization: out of memory");
    double *pos = buf;               /* M positions on P (vertex index + fraction) */
    double *C = buf + big;           /* 2M current samples */
    double *S = buf + 3 * big;       /* 2M smoothed copy */
    double *cum = buf + 5 * big;     /* max(M, np) */
    double *tgt = buf + 6 * big;     /* M targets */
    double *newpos = buf + 7 * big;  /* M */
    double *tmp2 = buf + 8 * big;     /* 2M box-filter scratch */
    double *finalpos = buf + 10 * big; /* m */
    double total = wlength_cum(P, np, closed, W, cum);
    if (!(total > 0.0) || !isfinite(total)) {
        free(buf);
        return amscr__fail(AMSCR_E_DEGENERATE, "parametrization: zero length");
    }
    equal_params(total, M, closed, tgt);
    invert_cum(cum, np, closed, total, tgt, M, pos);
    double sigma0 = sigma0_frac * (double)M;
    for (unsigned pass = 0; pass < passes && st == AMSCR_OK; pass++) {
        sample_by_index(P, np, closed, pos, M, C);
        if (kind == AMSCR_PARAM_AFFINE) {
            st = amscr__affine_cum(C, M, closed, sigma0, cum, &total);
        } else {
            const double *Q = C;
            if (sigma0 > 0.0) {
                st = amscr__smooth_box3(C, M, closed, sigma0, S, tmp2);
                Q = S;
            }
            if (st == AMSCR_OK) {
                total = wlength_cum(Q, M, closed, W, cum);
                if (!(total > 0.0))
                    st = amscr__fail(AMSCR_E_DEGENERATE, "parametrization: zero length");
            }
        }
        if (st != AMSCR_OK)
            break;
        int last = (pass + 1 == passes);
        size_t cnt = last ? m : M;
        equal_params(total, cnt, closed, tgt);
        double *dst = last ? finalpos : newpos;
        invert_cum(cum, M, closed, total, tgt, cnt, dst);
        positions_on_polygon(pos, M, np, closed, dst, cnt);
        if (!last)
            memcpy(pos, newpos, M * sizeof *pos);
    }
    if (st == AMSCR_OK)
        sample_by_index(P, np, closed, finalpos, m, out);
    free(buf);
    return st;
}

amscr_status amscr_resample_affine(const double *xy, size_t n, int closed, double sigma0, unsigned passes, size_t m,
                                   double *out_xy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_xy);
    AMSCR_CHECK_FLAG(closed);
    if (n < 5 || m < 4)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: n = %zu (>= 5) and m = %zu (>= 4)", n, m);
    if (!(sigma0 >= 0.0) || !(sigma0 <= 0.25))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: sigma0 = %g must be a fraction in [0, 0.25]",
                           sigma0);
    if (passes < 1 || passes > 10)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: passes = %u must be in 1..10", passes);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: non-finite coordinates");
    size_t M = 8 * m > n ? 8 * m : n;
    return amscr__parametrize(xy, n, closed ? 1 : 0, AMSCR_PARAM_AFFINE, sigma0, passes, M, m, out_xy);
}

amscr_status amscr__whiten(const double *xy, size_t n, double *out_xy, double fwd[6], double inv[6])
{
    double cx, cy, cov[3];
    amscr__centroid(xy, n, &cx, &cy);
    amscr__scatter(xy, n, cx, cy, 1.0, cov);
    cov[0] /= (double)n;
    cov[1] /= (double)n;
    cov[2] /= (double)n;
    double W[4], R[4];
    if (!amscr__sym2_invsqrt(cov, W, R))
        return amscr__fail(AMSCR_E_DEGENERATE, "whitening: singular covariance (collinear points)");
    double f[6] = {W[0], W[1], -(W[0] * cx + W[1] * cy), W[2], W[3], -(W[2] * cx + W[3] * cy)};
    if (out_xy)
        for (size_t i = 0; i < n; i++) {
            double dx = xy[2 * i] - cx, dy = xy[2 * i + 1] - cy;
            out_xy[2 * i] = W[0] * dx + W[1] * dy;
            out_xy[2 * i + 1] = W[2] * dx + W[3] * dy;
        }
    if (fwd)
        memcpy(fwd, f, sizeof f);
    if (inv) {
        inv[0] = R[0];
        inv[1] = R[1];
        inv[2] = cx;
        inv[3] = R[2];
        inv[4] = R[3];
        inv[5] = cy;
    }
    return AMSCR_OK;
}

amscr_status amscr_normalize_whiten(const double *xy, size_t n, double *out_xy, double out_forward[6],
                                    double out_inverse[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    if (n == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_normalize_whiten: no points");
    if (n < 3)
        return amscr__fail(AMSCR_E_DEGENERATE, "amscr_normalize_whiten: %zu points, at least 3 needed", n);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_normalize_whiten: non-finite coordinates");
    return amscr__whiten(xy, n, out_xy, out_forward, out_inverse);
}
