/* smooth.c — FIR Gaussian kernel and smoothing of curves (circular or mirrored). */
#include "internal.h"

#include <stdint.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

size_t amscr__kernel_radius(double sigma) { return (size_t)ceil(4.0 * sigma); }

void amscr__kernel_fill(double sigma, size_t r, double *taps)
{
    double sum = 0.0;
    for (size_t i = 0; i <= 2 * r; i++) {
        double d = (double)i - (double)r;
        taps[i] = exp(-0.5 * d * d / (sigma * sigma));
        sum += taps[i];
    }
    for (size_t i = 0; i <= 2 * r; i++)
        taps[i] /= sum;
}

amscr_status amscr_gaussian_kernel(double sigma, double *taps, size_t *inout_ntaps)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(inout_ntaps);
    if (!(sigma > 0.0) || !(sigma <= 1e6))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gaussian_kernel: sigma = %g must be in (0, 1e6]", sigma);
    size_t r = amscr__kernel_radius(sigma), count = 2 * r + 1;
    if (taps) {
        if (*inout_ntaps < count)
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gaussian_kernel: room for %zu taps, %zu needed",
                               *inout_ntaps, count);
        amscr__kernel_fill(sigma, r, taps);
    }
    *inout_ntaps = count;
    return AMSCR_OK;
}

/* Index of a mirrored ("reflect", half-sample symmetric) extension: period 2n. */
static size_t mirror_index(long long k, size_t n)
{
    long long p = 2 * (long long)n;
    long long m = k % p;
    if (m < 0)
        m += p;
    return (size_t)(m < (long long)n ? m : p - 1 - m);
}

/* Smooths 2-D points with taps g (2r+1). closed: the kernel is first folded onto the
 * period n, so any radius is exact. wrapped: scratch of n doubles (closed only). */
void amscr__smooth_with_kernel(const double *xy, size_t n, int closed, const double *g, size_t r, double *wrapped,
                               double *out)
{
    if (closed && 2 * r + 1 <= n) {
        for (size_t i = 0; i < n; i++) {
            double sx = 0.0, sy = 0.0;
            size_t k = (i + n - (r % n)) % n;
            for (size_t j = 0; j <= 2 * r; j++) {
                sx += g[j] * xy[2 * k];
                sy += g[j] * xy[2 * k + 1];
                if (++k == n)
                    k = 0;
            }
            out[2 * i] = sx;
            out[2 * i + 1] = sy;
        }
        return;
    }
    if (closed) {
        /* fold: w[m] = sum of g[j] with (j - r) ≡ m (mod n) */
        memset(wrapped, 0, n * sizeof *wrapped);
        for (size_t j = 0; j <= 2 * r; j++) {
            long long off = ((long long)j - (long long)r) % (long long)n;
            if (off < 0)
                off += (long long)n;
            wrapped[off] += g[j];
        }
        for (size_t i = 0; i < n; i++) {
            double sx = 0.0, sy = 0.0;
            size_t idx = i;
            for (size_t m = 0; m < n; m++) {
                if (wrapped[m] != 0.0) {
                    sx += wrapped[m] * xy[2 * idx];
                    sy += wrapped[m] * xy[2 * idx + 1];
                }
                if (++idx == n)
                    idx = 0;
            }
            out[2 * i] = sx;
            out[2 * i + 1] = sy;
        }
        return;
    }
    for (size_t i = 0; i < n; i++) {
        double sx = 0.0, sy = 0.0;
        for (size_t j = 0; j <= 2 * r; j++) {
            size_t k = mirror_index((long long)i + (long long)j - (long long)r, n);
            sx += g[j] * xy[2 * k];
            sy += g[j] * xy[2 * k + 1];
        }
        out[2 * i] = sx;
        out[2 * i + 1] = sy;
    }
}

amscr_status amscr__smooth(const double *xy, size_t n, int closed, double sigma, double *out)
{
    if (sigma == 0.0) {
        memcpy(out, xy, 2 * n * sizeof *out);
        return AMSCR_OK;
    }
    size_t r = amscr__kernel_radius(sigma);
    double *g = amscr__malloc_array(2 * r + 1 + n, sizeof *g);
    if (!g)
        return amscr__fail(AMSCR_E_NOMEM, "smoothing: out of memory");
    amscr__kernel_fill(sigma, r, g);
    amscr__smooth_with_kernel(xy, n, closed, g, r, g + 2 * r + 1, out);
    free(g);
    return AMSCR_OK;
}

amscr_status amscr_smooth_gaussian(const double *xy, size_t n, int closed, double sigma, double *out_xy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(xy);
    AMSCR_CHECK_NULL(out_xy);
    AMSCR_CHECK_FLAG(closed);
    if (n == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_smooth_gaussian: no points");
    if (!(sigma >= 0.0) || !(sigma <= 1e6))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_smooth_gaussian: sigma = %g must be in [0, 1e6]", sigma);
    if (!amscr__all_finite(xy, 2 * n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_smooth_gaussian: non-finite coordinates");
    uintptr_t in = (uintptr_t)xy, out = (uintptr_t)out_xy, bytes = 2 * n * sizeof *xy;
    if (out < in + bytes && in < out + bytes) /* the passes read what they would overwrite */
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_smooth_gaussian: out_xy overlaps xy");
    return amscr__smooth(xy, n, closed, sigma, out_xy);
}

/* Box smoothing of one pass: out[i] = mean of in[i-r .. i+r] (circular, or mirrored at open
 * ends). Running sums: O(n) whatever r. */
static void box_pass(const double *in, size_t n, int closed, size_t r, double *out)
{
    double sx = 0.0, sy = 0.0, inv = 1.0 / (double)(2 * r + 1);
    for (long long j = -(long long)r; j <= (long long)r; j++) {
        size_t k = closed ? (size_t)(((j % (long long)n) + (long long)n) % (long long)n) : mirror_index(j, n);
        sx += in[2 * k];
        sy += in[2 * k + 1];
    }
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = sx * inv;
        out[2 * i + 1] = sy * inv;
        long long add = (long long)i + (long long)r + 1, del = (long long)i - (long long)r;
        size_t ka = closed ? (size_t)(((add % (long long)n) + (long long)n) % (long long)n) : mirror_index(add, n);
        size_t kd = closed ? (size_t)(((del % (long long)n) + (long long)n) % (long long)n) : mirror_index(del, n);
        sx += in[2 * ka] - in[2 * kd];
        sy += in[2 * ka + 1] - in[2 * kd + 1];
    }
}

/* Approximately Gaussian smoothing by three box passes of equal variance (3 (w^2 - 1) / 12 =
 * sigma^2, w = 2r + 1), O(n) whatever sigma: used where only a smooth curve is needed to
 * MEASURE a parameter (the parametrizations), not for the scale space. Linear, hence
 * affine-covariant. Falls back to the FIR Gaussian when the box would exceed the curve.
 * scratch: 2n doubles. */
amscr_status amscr__smooth_box3(const double *xy, size_t n, int closed, double sigma, double *out, double *scratch)
{
    double w = sqrt(4.0 * sigma * sigma + 1.0);
    size_t r = (size_t)floor(0.5 * (w - 1.0) + 0.5);
    if (sigma <= 0.0 || r == 0) {
        memcpy(out, xy, 2 * n * sizeof *out);
        return AMSCR_OK;
    }
    if (2 * r + 1 > n)
        return amscr__smooth(xy, n, closed, sigma, out);
    box_pass(xy, n, closed, r, out);
    box_pass(out, n, closed, r, scratch);
    box_pass(scratch, n, closed, r, out);
    return AMSCR_OK;
}
