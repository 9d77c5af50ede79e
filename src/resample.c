/* resample.c — Euclidean and affine arc-length resampling, whitening normalization. */
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
    if (n < 2 || m < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_euclidean: n = %zu and m = %zu must be >= 2", n, m);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_euclidean: non-finite coordinates");
    return amscr__resample_euclid(xy, n, closed ? 1 : 0, m, out_xy);
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

/* The core of the parametrizations: P0 is a dense uniform (Euclidean) resampling of the
 * curve with M points; the output is m points of P0 equally spaced in the requested
 * parameter. */
amscr_status amscr__parametrize(const double *P0, size_t M, int closed, amscr_parametrization kind, double sigma0_frac,
                                unsigned passes, size_t m, double *out)
{
    amscr_status st = AMSCR_OK;
    double *buf = amscr__malloc_array(7 * M + m + 4, sizeof *buf);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "parametrization: out of memory");
    double *pos = buf;           /* M index positions on P0 */
    double *P = buf + M;         /* 2M current samples */
    double *cum = buf + 3 * M;   /* M */
    double *tgt = buf + 4 * M;   /* M */
    double *newpos = buf + 5 * M; /* M */
    double *finalpos = buf + 6 * M; /* m */
    double total = 0.0;

    if (kind == AMSCR_PARAM_EUCLIDEAN || kind == AMSCR_PARAM_WHITENED) {
        double W[4] = {1, 0, 0, 1};
        if (kind == AMSCR_PARAM_WHITENED) {
            double cx, cy, cov[3];
            int ok = closed ? region_moments(P0, M, &cx, &cy, cov) : 0;
            if (!ok || !amscr__sym2_invsqrt(cov, W, NULL)) {
                /* open curves (or a failed region): point moments */
                double mx = 0, my = 0;
                for (size_t i = 0; i < M; i++) {
                    mx += P0[2 * i];
                    my += P0[2 * i + 1];
                }
                mx /= (double)M;
                my /= (double)M;
                cov[0] = cov[1] = cov[2] = 0;
                for (size_t i = 0; i < M; i++) {
                    double dx = P0[2 * i] - mx, dy = P0[2 * i + 1] - my;
                    cov[0] += dx * dx;
                    cov[1] += dx * dy;
                    cov[2] += dy * dy;
                }
                if (!amscr__sym2_invsqrt(cov, W, NULL)) {
                    free(buf);
                    return amscr__fail(AMSCR_E_DEGENERATE, "parametrization: singular moments (collinear curve)");
                }
            }
        }
        cum[0] = 0.0;
        for (size_t i = 1; i <= M; i++) {
            if (i == M && !closed)
                break;
            size_t a = i - 1, b = (i == M) ? 0 : i;
            double dx = P0[2 * b] - P0[2 * a], dy = P0[2 * b + 1] - P0[2 * a + 1];
            double len = hypot(W[0] * dx + W[1] * dy, W[2] * dx + W[3] * dy);
            if (i < M)
                cum[i] = cum[i - 1] + len;
            else
                total = cum[M - 1] + len;
        }
        if (!closed)
            total = cum[M - 1];
        if (!(total > 0.0)) {
            free(buf);
            return amscr__fail(AMSCR_E_DEGENERATE, "parametrization: zero length");
        }
        equal_params(total, m, closed, tgt);
        invert_cum(cum, M, closed, total, tgt, m, finalpos);
        sample_by_index(P0, M, closed, finalpos, m, out);
        free(buf);
        return AMSCR_OK;
    }

    /* Affine arc length, iterated: each pass measures the affine length over the previous
     * pass's parameter and re-samples the ORIGINAL dense polygon (no cumulative corner cutting). */
    for (size_t i = 0; i < M; i++)
        pos[i] = (double)i;
    double sigma0 = sigma0_frac * (double)M;
    for (unsigned pass = 0; pass < passes; pass++) {
        sample_by_index(P0, M, closed, pos, M, P);
        st = amscr__affine_cum(P, M, closed, sigma0, cum, &total);
        if (st != AMSCR_OK)
            break;
        int last = (pass + 1 == passes);
        size_t cnt = last ? m : M;
        equal_params(total, cnt, closed, tgt);
        double *dst = last ? finalpos : newpos;
        invert_cum(cum, M, closed, total, tgt, cnt, dst);
        /* dst holds positions in the index space of P (= pos); map back to P0 positions */
        for (size_t k = 0; k < cnt; k++) {
            double q = dst[k], fl = floor(q);
            size_t a = (size_t)fl;
            double u = q - fl;
            double pa = pos[a % M];
            double pb;
            if (a + 1 < M)
                pb = pos[a + 1];
            else
                pb = closed ? pos[0] + (double)M : pos[M - 1];
            dst[k] = pa + u * (pb - pa);
            if (closed && dst[k] >= (double)M)
                dst[k] -= (double)M;
        }
        if (!last)
            memcpy(pos, newpos, M * sizeof *pos);
    }
    if (st == AMSCR_OK)
        sample_by_index(P0, M, closed, finalpos, m, out);
    free(buf);
    return st;
}

amscr_status amscr_resample_affine(const double *xy, size_t n, int closed, double sigma0, unsigned passes, size_t m,
                                   double *out_xy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_xy);
    if (n < 5 || m < 4)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: n = %zu (>= 5) and m = %zu (>= 4)", n, m);
    if (!(sigma0 >= 0.0) || !(sigma0 <= 0.25))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: sigma0 = %g must be a fraction in [0, 0.25]",
                           sigma0);
    if (passes < 1 || passes > 10)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: passes = %u must be in 1..10", passes);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_resample_affine: non-finite coordinates");
    closed = closed ? 1 : 0;
    size_t M = 8 * m > n ? 8 * m : n;
    double *P0 = amscr__malloc_array(2 * M, sizeof *P0);
    if (!P0)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_resample_affine: out of memory");
    amscr_status st = amscr__resample_euclid(xy, n, closed, M, P0);
    if (st == AMSCR_OK)
        st = amscr__parametrize(P0, M, closed, AMSCR_PARAM_AFFINE, sigma0, passes, m, out_xy);
    free(P0);
    return st;
}

amscr_status amscr__whiten(const double *xy, size_t n, double *out_xy, double fwd[6], double inv[6])
{
    double cx = 0, cy = 0;
    for (size_t i = 0; i < n; i++) {
        cx += xy[2 * i];
        cy += xy[2 * i + 1];
    }
    cx /= (double)n;
    cy /= (double)n;
    double cov[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        double dx = xy[2 * i] - cx, dy = xy[2 * i + 1] - cy;
        cov[0] += dx * dx;
        cov[1] += dx * dy;
        cov[2] += dy * dy;
    }
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
