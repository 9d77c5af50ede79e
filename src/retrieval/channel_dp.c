/* channel_dp.c — the shape channel's banded DTW (the pair cost of channel.c): one pair, four
 * pairs at once in the four 32-bit lanes of SSE2 registers (elsewhere the four-pair entry runs
 * the one-pair DP four times), or eight in the eight lanes of AVX2 registers when the
 * processor has AVX2 (asked at run time; elsewhere the eight-pair entry runs the four-pair one
 * twice). The lanes run the one-pair DP's integer operations in the same order (the same
 * moves, the same ties), so their distances are bit for bit the one-pair ones; they exist
 * because the row's third move chains along the row, and independent chains side by side keep
 * the processor busy where one leaves it waiting on the previous cell. */
#include "channel.h"

#include <float.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

/* L1 distance of two quantized height vectors (integer: the same on every platform). */
static inline int32_t l1(const uint8_t *x, const uint8_t *y)
{
#if defined(__SSE2__)
    __m128i s = _mm_setzero_si128();
    for (size_t d = 0; d < AMSCR__HF_BINS; d += 16) {
        __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(x + d));
        __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(y + d));
        s = _mm_add_epi64(s, _mm_sad_epu8(a, b));
    }
    return _mm_cvtsi128_si32(s) + _mm_extract_epi16(s, 4);
#else
    int32_t s = 0;
    for (size_t d = 0; d < AMSCR__HF_BINS; d++)
        s += x[d] > y[d] ? x[d] - y[d] : y[d] - x[d];
    return s;
#endif
}

/* The band's geometry: m rows (samples of A visited), half width w, W = 2 w + 1 cells; the
 * samples of B the band visits, in order from its first cell (row 0, cell 0): R. */
typedef struct {
    size_t m, stride;
    long w, W;
    size_t R;
} band_t;

static band_t band_of(size_t n, size_t band, size_t stride)
{
    band_t g = {n / stride, stride, (long)(band / stride > 0 ? band / stride : 1), 0, 0};
    g.W = 2 * g.w + 1;
    g.R = (g.m - 1 + (size_t)g.W - 1) * stride + 1;
    return g;
}

/* B's samples as the band of shift s visits them, into out (g->R rows): row r is sample
 * s - w stride + r (cyclic), so cell kk of row i reads row (i + kk) stride, without wrapping.
 * The side-by-side DPs copy each lane's B once (R rows of 16 bytes, for m rows of W cells). */
static void band_samples(const uint8_t *B, size_t n, size_t s, const band_t *g, uint8_t *out)
{
    const size_t D = AMSCR__HF_BINS;
    size_t j = (s + n * g->stride - (size_t)g->w * g->stride) % n;
    for (size_t r = 0; r < g->R;) {
        size_t run = n - j < g->R - r ? n - j : g->R - r;
        memcpy(out + r * D, B + j * D, run * D);
        r += run;
        j = 0;
    }
}

/* The cell costs of row i against B shifted by s: cost[kk] for kk = 0..W-1. */
static void row_costs(const uint8_t *A, const uint8_t *B, size_t n, size_t s, const band_t *g, size_t i,
                      int32_t *cost)
{
    const size_t D = AMSCR__HF_BINS;
    const uint8_t *ai = A + i * g->stride * D;
    size_t jb = (s + i * g->stride + n * g->stride - (size_t)g->w * g->stride) % n;
    for (long kk = 0; kk < g->W; kk++) { /* independent, pipelined */
        cost[kk] = l1(ai, B + jb * D);
        jb += g->stride;
        if (jb >= n)
            jb -= n;
    }
}

/* The distance from the last row: the cheapest end, each paying `skip` per sample its path's
 * end offset differs from its start offset. */
static double band_end(const int32_t *last, const int32_t *start, size_t step, const band_t *g, int32_t skip)
{
    double best = DBL_MAX;
    for (long kk = 0; kk < g->W; kk++) {
        size_t c = (size_t)kk * step;
        double v = (double)last[c] + (double)skip * (double)labs((kk - g->w) - start[c]);
        if (v < best)
            best = v;
    }
    return best / ((double)g->m * AMSCR__HF_QUANT);
}

/* One row of the banded DTW: cur[kk] = cost[kk] + the cheapest of prev[kk] (a match),
 * prev[kk + 1] + skip (this row's sample matched twice) and cur[kk - 1] + skip (the other's),
 * ties kept in that order; cs[kk] the start offset its path came from. Two passes: the first
 * two moves are independent across the row (branch-free selects the compiler vectorizes),
 * only the third chains along it — the same values and ties as one pass over the three. */
static void band_row(const int32_t *restrict prev, const int32_t *restrict ps, const int32_t *restrict cost, long W,
                     int32_t skip, int32_t *restrict cur, int32_t *restrict cs)
{
    for (long kk = 0; kk + 1 < W; kk++) { /* masks, not branches: the choice is data-dependent */
        int32_t b = prev[kk], v = prev[kk + 1] + skip, m = -(int32_t)(v < b);
        cur[kk] = (v & m) | (b & ~m);
        cs[kk] = (ps[kk + 1] & m) | (ps[kk] & ~m);
    }
    cur[W - 1] = prev[W - 1];
    cs[W - 1] = ps[W - 1];
    int32_t c = cost[0] + cur[0];
    int32_t st = cs[0];
    cur[0] = c;
    for (long kk = 1; kk < W; kk++) { /* plain selects: conditional moves, the shortest chain */
        int32_t h = c + skip, b = cur[kk];
        int32_t sb = cs[kk];
        int lt = h < b;
        c = (lt ? h : b) + cost[kk];
        st = lt ? st : sb;
        cur[kk] = c;
        cs[kk] = st;
    }
}

double amscr__hf_band_dp(const uint8_t *A, const uint8_t *B, size_t n, size_t s, size_t band, size_t stride,
                         int32_t skip, amscr__hf_ws *ws)
{
    const band_t g = band_of(n, band, stride);
    int32_t *prev = ws->row, *cur = ws->row + g.W, *cost = ws->row + 2 * g.W;
    int32_t *ps = ws->start, *cs = ws->start + g.W;
    for (long kk = 0; kk < g.W; kk++) { /* before the first row: every start free, paths cost 0 */
        prev[kk] = 0;
        ps[kk] = (int32_t)(kk - g.w);
    }
    for (size_t i = 0; i < g.m; i++) {
        row_costs(A, B, n, s, &g, i, cost);
        band_row(prev, ps, cost, g.W, skip, cur, cs);
        int32_t *t = prev;
        prev = cur;
        cur = t;
        int32_t *u = ps;
        ps = cs;
        cs = u;
    }
    return band_end(prev, ps, 1, &g, skip);
}

#if defined(__SSE2__) && AMSCR__HF_BINS == 16
/* (m & x) | (~m & y), lane by lane */
static inline __m128i sel(__m128i m, __m128i x, __m128i y)
{
    return _mm_or_si128(_mm_and_si128(m, x), _mm_andnot_si128(m, y));
}

#define LD(p, kk) _mm_loadu_si128((const __m128i *)(const void *)((p) + 4 * (kk)))
#define ST(p, kk, v) _mm_storeu_si128((__m128i *)(void *)((p) + 4 * (kk)), (v))

/* band_row on four lanes, cell kk of lane l at [4 kk + l], one lane in each 32 bits of an SSE2
 * register: the same operations as band_row. */
static void band_row4(const int32_t *restrict prev, const int32_t *restrict ps, const int32_t *restrict cost, long W,
                      int32_t skip, int32_t *restrict cur, int32_t *restrict cs)
{
    const __m128i sk = _mm_set1_epi32(skip);
    for (long kk = 0; kk + 1 < W; kk++) {
        __m128i b = LD(prev, kk), v = _mm_add_epi32(LD(prev, kk + 1), sk), m = _mm_cmpgt_epi32(b, v); /* v < b */
        ST(cur, kk, sel(m, v, b));
        ST(cs, kk, sel(m, LD(ps, kk + 1), LD(ps, kk)));
    }
    ST(cur, W - 1, LD(prev, W - 1));
    ST(cs, W - 1, LD(ps, W - 1));
    __m128i c = _mm_add_epi32(LD(cost, 0), LD(cur, 0)), st = LD(cs, 0);
    ST(cur, 0, c);
    for (long kk = 1; kk < W; kk++) {
        __m128i h = _mm_add_epi32(c, sk), b = LD(cur, kk), lt = _mm_cmpgt_epi32(b, h); /* h < b */
        c = _mm_add_epi32(sel(lt, h, b), LD(cost, kk));
        st = sel(lt, st, LD(cs, kk));
        ST(cur, kk, c);
        ST(cs, kk, st);
    }
}
#undef LD
#undef ST

/* The cell costs of row i of the four lanes into cost[4 kk + l]: row_costs' values, lane l's
 * B samples at Bv + l R D (band_samples). */
static void row_costs4(const uint8_t *const *A, const uint8_t *Bv, const band_t *g, size_t i, int32_t *cost)
{
    /* each lane's row vector loaded once; the four sums of absolute differences gathered into
     * one register of four lanes (each below 2^12: the low 32 bits of the 64-bit halves) */
    const size_t D = AMSCR__HF_BINS, step = g->stride * D;
    __m128i a[4];
    const uint8_t *b[4];
    for (size_t l = 0; l < 4; l++) {
        a[l] = _mm_loadu_si128((const __m128i *)(const void *)(A[l] + i * step));
        b[l] = Bv + l * g->R * D + i * step;
    }
    for (long kk = 0; kk < g->W; kk++) {
        __m128i x[4];
        for (size_t l = 0; l < 4; l++)
            x[l] = _mm_sad_epu8(a[l], _mm_loadu_si128((const __m128i *)(const void *)(b[l] + (size_t)kk * step)));
        __m128i t01 = _mm_add_epi64(_mm_unpacklo_epi64(x[0], x[1]), _mm_unpackhi_epi64(x[0], x[1]));
        __m128i t23 = _mm_add_epi64(_mm_unpacklo_epi64(x[2], x[3]), _mm_unpackhi_epi64(x[2], x[3]));
        __m128 v = _mm_shuffle_ps(_mm_castsi128_ps(t01), _mm_castsi128_ps(t23), _MM_SHUFFLE(2, 0, 2, 0));
        _mm_storeu_si128((__m128i *)(void *)(cost + 4 * kk), _mm_castps_si128(v));
    }
}

/* A row's cell costs and its DP step on `nl` lanes side by side (row_costs4 / band_row4 and
 * their eight-lane forms). */
typedef void (*lane_costs_fn)(const uint8_t *const *A, const uint8_t *Bv, const band_t *g, size_t i, int32_t *cost);
typedef void (*lane_row_fn)(const int32_t *prev, const int32_t *ps, const int32_t *cost, long W, int32_t skip,
                            int32_t *cur, int32_t *cs);

/* amscr__hf_band_dp on nl lanes (4 or 8): lane l is (A[l], B[l], s[l]), cell kk of lane l at
 * [nl kk + l]. */
static void band_lanes(size_t nl, lane_costs_fn costs, lane_row_fn step, const uint8_t *const *A,
                       const uint8_t *const *B, const size_t *s, size_t n, size_t band, size_t stride, int32_t skip,
                       amscr__hf_ws *ws, double *out)
{
    const band_t g = band_of(n, band, stride);
    const size_t L = nl * (size_t)g.W;
    int32_t *prev = ws->lanes, *cur = prev + L, *cost = cur + L, *ps = cost + L, *cs = ps + L;
    for (size_t l = 0; l < nl; l++)
        band_samples(B[l], n, s[l], &g, ws->bands + l * g.R * AMSCR__HF_BINS);
    for (long kk = 0; kk < g.W; kk++)
        for (size_t l = 0; l < nl; l++) {
            prev[nl * (size_t)kk + l] = 0;
            ps[nl * (size_t)kk + l] = (int32_t)(kk - g.w);
        }
    for (size_t i = 0; i < g.m; i++) {
        costs(A, ws->bands, &g, i, cost);
        step(prev, ps, cost, g.W, skip, cur, cs);
        int32_t *t = prev;
        prev = cur;
        cur = t;
        t = ps;
        ps = cs;
        cs = t;
    }
    for (size_t l = 0; l < nl; l++)
        out[l] = band_end(prev + l, ps + l, nl, &g, skip);
}
#endif

void amscr__hf_band_dp4(const uint8_t *const A[4], const uint8_t *const B[4], const size_t s[4], size_t n, size_t band,
                        size_t stride, int32_t skip, amscr__hf_ws *ws, double out[4])
{
#if defined(__SSE2__) && AMSCR__HF_BINS == 16
    band_lanes(4, row_costs4, band_row4, A, B, s, n, band, stride, skip, ws, out);
#else
    for (size_t l = 0; l < 4; l++)
        out[l] = amscr__hf_band_dp(A[l], B[l], n, s[l], band, stride, skip, ws);
#endif
}

/* Eight lanes: AVX2 code in functions compiled for it (the rest of the library stays
 * baseline x86-64), called only when the processor reports AVX2. */
#if defined(__x86_64__) && AMSCR__HF_BINS == 16 && (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 5))
#define DP8 1
#include <immintrin.h>
#define AVX2 __attribute__((target("avx2")))

#define LD(p, kk) _mm256_loadu_si256((const __m256i *)(const void *)((p) + 8 * (kk)))
#define ST(p, kk, v) _mm256_storeu_si256((__m256i *)(void *)((p) + 8 * (kk)), (v))

/* band_row on eight lanes, cell kk of lane l at [8 kk + l]: band_row's selects written as a
 * minimum (the value v < b ? v : b is min(v, b)) and a blend of the start offsets by the
 * same comparison. */
AVX2 static void band_row8(const int32_t *restrict prev, const int32_t *restrict ps, const int32_t *restrict cost,
                           long W, int32_t skip, int32_t *restrict cur, int32_t *restrict cs)
{
    const __m256i sk = _mm256_set1_epi32(skip);
    for (long kk = 0; kk + 1 < W; kk++) {
        __m256i b = LD(prev, kk), v = _mm256_add_epi32(LD(prev, kk + 1), sk), m = _mm256_cmpgt_epi32(b, v);
        ST(cur, kk, _mm256_min_epi32(v, b));
        ST(cs, kk, _mm256_blendv_epi8(LD(ps, kk), LD(ps, kk + 1), m));
    }
    ST(cur, W - 1, LD(prev, W - 1));
    ST(cs, W - 1, LD(ps, W - 1));
    __m256i c = _mm256_add_epi32(LD(cost, 0), LD(cur, 0)), st = LD(cs, 0);
    ST(cur, 0, c);
    for (long kk = 1; kk < W; kk++) {
        __m256i h = _mm256_add_epi32(c, sk), b = LD(cur, kk), lt = _mm256_cmpgt_epi32(b, h); /* h < b */
        c = _mm256_add_epi32(_mm256_min_epi32(h, b), LD(cost, kk));
        st = _mm256_blendv_epi8(LD(cs, kk), st, lt);
        ST(cur, kk, c);
        ST(cs, kk, st);
    }
}
#undef LD
#undef ST

/* Two 16-byte rows in one register: lo in the low half, hi in the high half. */
AVX2 static inline __m256i two_rows(const uint8_t *lo, const uint8_t *hi)
{
    __m128i a = _mm_loadu_si128((const __m128i *)(const void *)lo);
    __m128i b = _mm_loadu_si128((const __m128i *)(const void *)hi);
    return _mm256_inserti128_si256(_mm256_castsi128_si256(a), b, 1);
}

/* The cell costs of row i of the eight lanes into cost[8 kk + l]: row_costs' values, lane l's
 * B samples at Bv + l R D (band_samples). Lanes p and p + 4 share a register (their sums of
 * absolute differences in its two halves), gathered into the lane order by the same unpack
 * and shuffle in each half. */
AVX2 static void row_costs8(const uint8_t *const *A, const uint8_t *Bv, const band_t *g, size_t i, int32_t *cost)
{
    const size_t D = AMSCR__HF_BINS, step = g->stride * D, lane = g->R * D;
    const uint8_t *b = Bv + i * step;
    __m256i a[4];
    for (size_t p = 0; p < 4; p++)
        a[p] = two_rows(A[p] + i * step, A[p + 4] + i * step);
    for (long kk = 0; kk < g->W; kk++, b += step) {
        __m256i x[4];
        for (size_t p = 0; p < 4; p++)
            x[p] = _mm256_sad_epu8(a[p], two_rows(b + p * lane, b + (p + 4) * lane));
        __m256i t01 = _mm256_add_epi64(_mm256_unpacklo_epi64(x[0], x[1]), _mm256_unpackhi_epi64(x[0], x[1]));
        __m256i t23 = _mm256_add_epi64(_mm256_unpacklo_epi64(x[2], x[3]), _mm256_unpackhi_epi64(x[2], x[3]));
        __m256 v = _mm256_shuffle_ps(_mm256_castsi256_ps(t01), _mm256_castsi256_ps(t23), _MM_SHUFFLE(2, 0, 2, 0));
        _mm256_storeu_si256((__m256i *)(void *)(cost + 8 * kk), _mm256_castps_si256(v));
    }
}

#undef AVX2
#endif

int amscr__hf_lanes(void)
{
#if defined(DP8)
    return __builtin_cpu_supports("avx2") ? 8 : 4;
#else
    return 4;
#endif
}

void amscr__hf_band_dp8(const uint8_t *const A[8], const uint8_t *const B[8], const size_t s[8], size_t n, size_t band,
                        size_t stride, int32_t skip, amscr__hf_ws *ws, double out[8])
{
#if defined(DP8)
    if (__builtin_cpu_supports("avx2")) {
        band_lanes(8, row_costs8, band_row8, A, B, s, n, band, stride, skip, ws, out);
        return;
    }
#endif
    amscr__hf_band_dp4(A, B, s, n, band, stride, skip, ws, out);
    amscr__hf_band_dp4(A + 4, B + 4, s + 4, n, band, stride, skip, ws, out + 4);
}
