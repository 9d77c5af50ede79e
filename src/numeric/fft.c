/* fft.c — a small complex FFT for the start-point search: iterative radix-2 for powers of
 * two, a direct DFT otherwise. A plan (twiddles, bit reversal) is made once per size and
 * kept in the per-thread workspace or the descriptor: no global state. */
#include "fft.h"
#include "dense.h"

#include <math.h>
#include <stdlib.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

int amscr__fft_plan_init(amscr__fft_plan *p, size_t n)
{
    p->n = n;
    p->pow2 = n >= 2 && (n & (n - 1)) == 0;
    p->tw = malloc(2 * n * sizeof *p->tw);
    p->rev = p->pow2 ? malloc(n * sizeof *p->rev) : NULL;
    p->tmp = p->pow2 ? NULL : malloc(2 * n * sizeof *p->tmp);
    if (!p->tw || (p->pow2 && !p->rev) || (!p->pow2 && !p->tmp)) {
        amscr__fft_plan_free(p);
        return -1;
    }
    for (size_t k = 0; k < n; k++) {
        double a = -2.0 * AMSCR__PI * (double)k / (double)n;
        p->tw[2 * k] = cos(a);
        p->tw[2 * k + 1] = sin(a);
    }
    if (p->pow2) {
        size_t bits = 0;
        while (((size_t)1 << bits) < n)
            bits++;
        for (size_t i = 0; i < n; i++) {
            size_t r = 0;
            for (size_t b = 0; b < bits; b++)
                if (i & ((size_t)1 << b))
                    r |= (size_t)1 << (bits - 1 - b);
            p->rev[i] = r;
        }
    }
    return 0;
}

void amscr__fft_plan_free(amscr__fft_plan *p)
{
    free(p->tw);
    free(p->rev);
    free(p->tmp);
    p->tw = NULL;
    p->rev = NULL;
    p->tmp = NULL;
}

/* One radix-2 stage of butterflies of length len: b * w added to and taken from a. With SSE2
 * a complex value is one register and x = b w is (b0 wr - b1 wi, b1 wr + b0 wi): the scalar
 * products and sums (a difference as the sum of the negated product), so the same values. */
static void stage(const amscr__fft_plan *p, double *z, size_t len, double sgn)
{
    size_t n = p->n, half = len >> 1, step = n / len;
    for (size_t i = 0; i < n; i += len)
        for (size_t j = 0; j < half; j++) {
            double wr = p->tw[2 * j * step], wi = sgn * p->tw[2 * j * step + 1];
            double *a = z + 2 * (i + j), *b = z + 2 * (i + j + half);
#if defined(__SSE2__)
            __m128d B = _mm_loadu_pd(b), A = _mm_loadu_pd(a);
            __m128d P = _mm_mul_pd(B, _mm_set1_pd(wr));
            __m128d Q = _mm_mul_pd(_mm_shuffle_pd(B, B, 1), _mm_set1_pd(wi)); /* (b1 wi, b0 wi) */
            __m128d X = _mm_add_pd(P, _mm_xor_pd(Q, _mm_set_pd(0.0, -0.0)));  /* (-b1 wi, b0 wi) */
            _mm_storeu_pd(b, _mm_sub_pd(A, X));
            _mm_storeu_pd(a, _mm_add_pd(A, X));
#else
            double xr = b[0] * wr - b[1] * wi, xi = b[0] * wi + b[1] * wr;
            b[0] = a[0] - xr;
            b[1] = a[1] - xi;
            a[0] += xr;
            a[1] += xi;
#endif
        }
}

/* In-place transform of n interleaved complex values. inverse: e^{+i...}, unscaled. */
void amscr__fft(const amscr__fft_plan *p, double *z, int inverse)
{
    size_t n = p->n;
    double sgn = inverse ? -1.0 : 1.0;
    if (!p->pow2) {
        double *t = p->tmp; /* plan scratch: a plan is used by one thread at a time */
        for (size_t k = 0; k < n; k++) {
            double re = 0.0, im = 0.0;
            size_t idx = 0;
            for (size_t j = 0; j < n; j++) {
                double c = p->tw[2 * idx], s = sgn * p->tw[2 * idx + 1];
                re += z[2 * j] * c - z[2 * j + 1] * s;
                im += z[2 * j] * s + z[2 * j + 1] * c;
                idx += k;
                if (idx >= n)
                    idx -= n;
            }
            t[2 * k] = re;
            t[2 * k + 1] = im;
        }
        for (size_t k = 0; k < 2 * n; k++)
            z[k] = t[k];
        return;
    }
    for (size_t i = 0; i < n; i++) {
        size_t r = p->rev[i];
        if (r > i) {
            double tr = z[2 * i], ti = z[2 * i + 1];
            z[2 * i] = z[2 * r];
            z[2 * i + 1] = z[2 * r + 1];
            z[2 * r] = tr;
            z[2 * r + 1] = ti;
        }
    }
    /* the first two stages have trivial twiddles (1, and -i or +i): no multiplications */
    size_t start = 2;
    if (n >= 4) {
        for (size_t i = 0; i < n; i += 4) {
            double *a = z + 2 * i;
            double r0 = a[0] + a[2], i0 = a[1] + a[3], r1 = a[0] - a[2], i1 = a[1] - a[3];
            double r2 = a[4] + a[6], i2 = a[5] + a[7], r3 = a[4] - a[6], i3 = a[5] - a[7];
            /* forward: w = -i; inverse: w = +i (sgn) */
            double t3r = sgn * i3, t3i = -sgn * r3;
            a[0] = r0 + r2;
            a[1] = i0 + i2;
            a[4] = r0 - r2;
            a[5] = i0 - i2;
            a[2] = r1 + t3r;
            a[3] = i1 + t3i;
            a[6] = r1 - t3r;
            a[7] = i1 - t3i;
        }
        start = 8;
    }
    for (size_t len = start; len <= n; len <<= 1)
        stage(p, z, len, sgn);
}
