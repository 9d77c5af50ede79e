/* channel.c — the articulation-tolerant second distance channel (docs/method.md §10): height
 * functions along the prepared curve (Wang, Bai, Wang, Zhou, Liu, Tu, "Shape matching and
 * classification using height functions", Pattern Recognition Letters 2012), compared by an
 * order-preserving dynamic-programming correspondence in a narrow band around the best
 * cyclic shift and orientation.
 *
 * Per shape (once): for every sample i of the N normalized points (the descriptor's frame:
 * whitened under the affine group, similarity-normalized otherwise), the signed distances
 * of all other samples to the tangent line at i, averaged in AMSCR__HF_BINS bins of equal
 * index width and weighted by how close the bin lies along the curve (local detail counts
 * more than far parts, which articulation moves). Because the frame is normalized and the
 * samples follow the prepared (group-invariant) parametrization, the sequence changes with
 * the group only by a cyclic shift; a reflection reverses it, so the mirrored sequence is
 * kept as well. The low frequencies of every bin column's DFT (those the shift search reads)
 * are kept.
 *
 * Per pair: the cyclic shift (and orientation) that maximizes the correlation of the two
 * sequences, low-passed to the first N/8 frequencies (the band absorbs the coarser shift;
 * one inverse FFT for both orientations), then a banded DTW with a cost `skip` for
 * every sample matched twice (a skipped stretch on the other side) and free start/end
 * within the band (the difference of the end and start offsets pays `skip` per sample, so
 * a path that does not close costs what its missing samples would). Heights are quantized
 * to bytes (AMSCR__HF_QUANT), so the cell cost is an exact integer sum of absolute
 * differences (one SSE2 instruction per 16 bins) and the result is the same on every
 * platform. Cost O(N * band * bins) per pair; 0 for a shape against itself; d(a, b) and
 * d(b, a) agree unless the two shift searches pick different candidates. The DP itself is in
 * channel_dp.c (one pair, or four side by side for a collection's rows: the same values). */
#include "channel.h"

#include <float.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void amscr__hf_free(amscr__hf *h)
{
    if (!h)
        return;
    free(h->seq[0]);
    free(h->seq[1]);
    free(h->spec[0]);
    free(h->spec[1]);
    memset(h, 0, sizeof *h);
}

/* Bin weight for a bin whose centre lies `frac` of the curve away (0..0.5). */
static double bin_weight(double frac, double locality) { return 1.0 / (1.0 + locality * frac); }

/* Heights of the closed curve P (n points) into seq (n * AMSCR__HF_BINS bytes); cum: 2 (2 n + 1)
 * doubles. A bin's sum of the signed distances to sample i's tangent line is its points' sum
 * less count times sample i, along the normal: the points' sums from running sums along the
 * curve (twice round), O(n bins) rather than O(n^2). */
static void heights(const double *P, size_t n, double locality, uint8_t *seq, double *cum)
{
    const size_t D = AMSCR__HF_BINS;
    size_t jlo[AMSCR__HF_BINS], jhi[AMSCR__HF_BINS], cnt[AMSCR__HF_BINS] = {0};
    for (size_t b = 0; b < D; b++)
        jlo[b] = jhi[b] = 0;
    for (size_t j = 1, b = 0, next = n - 1; j < n; j++) { /* bin (j - 1) D / (n - 1) */
        while ((j - 1) * D >= next) {
            b++;
            next += n - 1;
        }
        if (cnt[b]++ == 0)
            jlo[b] = j;
        jhi[b] = j;
    }
    double wt[AMSCR__HF_BINS], cb[AMSCR__HF_BINS];
    for (size_t b = 0; b < D; b++) {
        double centre = ((double)b + 0.5) / (double)D; /* fraction of the curve ahead */
        wt[b] = bin_weight(centre < 0.5 ? centre : 1.0 - centre, locality);
        cb[b] = (double)cnt[b];
        jhi[b] += 1; /* the running sums' end */
    }
    double *cx = cum, *cy = cum + 2 * n + 1;
    cx[0] = cy[0] = 0.0;
    for (size_t t = 0; t < 2 * n; t++) {
        size_t q = t < n ? t : t - n;
        cx[t + 1] = cx[t] + P[2 * q];
        cy[t + 1] = cy[t] + P[2 * q + 1];
    }
    for (size_t i = 0; i < n; i++) {
        size_t ip = (i + 1) % n, im = (i + n - 1) % n;
        double tx = P[2 * ip] - P[2 * im], ty = P[2 * ip + 1] - P[2 * im + 1];
        double tl = sqrt(tx * tx + ty * ty);
        double nx = tl > 0.0 ? -ty / tl : 0.0, ny = tl > 0.0 ? tx / tl : 0.0;
        const double *ax = cx + i, *ay = cy + i, px = P[2 * i], py = P[2 * i + 1];
        uint8_t *out = seq + i * D;
        for (size_t b = 0; b < D; b++) { /* every bin holds a sample: n > D */
            double c = cb[b], sx = ax[jhi[b]] - ax[jlo[b]], sy = ay[jhi[b]] - ay[jlo[b]];
            double v = ((sx - c * px) * nx + (sy - c * py) * ny) / c;
            double q = 128.0 + AMSCR__HF_QUANT * v * wt[b];
            /* rounded half up: q + 0.5 >= 0.5, so the conversion's truncation is the floor */
            out[b] = (uint8_t)(q < 0.0 ? 0.0 : q > 255.0 ? 255.0 : q + 0.5);
        }
    }
}

/* The kept frequencies of every bin column's DFT into spec (AMSCR__HF_SPEC(nfreq) values, in
 * units of *scale: the largest magnitude / AMSCR__HF_SPEC_Q, rounded to the nearest): bin b's
 * real parts at spec + 2 b P, its imaginary parts at spec + (2 b + 1) P, P =
 * AMSCR__HF_PAD(nfreq), the 3 values after the last zero. tmp: AMSCR__HF_SPEC(nfreq) doubles. */
static amscr_status spectra(const uint8_t *seq, size_t n, size_t nfreq, int16_t *spec, double *scale,
                           amscr__fft_plan *plan, double *z, double *tmp)
{
    const size_t D = AMSCR__HF_BINS, P = AMSCR__HF_PAD(nfreq), S = AMSCR__HF_SPEC(nfreq);
    memset(tmp, 0, S * sizeof *tmp);
    for (size_t b = 0; b < D; b++) {
        for (size_t i = 0; i < n; i++) {
            z[2 * i] = (double)seq[i * D + b] - 128.0;
            z[2 * i + 1] = 0.0;
        }
        amscr__fft(plan, z, 0);
        for (size_t f = 0; f < nfreq; f++) {
            tmp[2 * b * P + f] = z[2 * f];
            tmp[(2 * b + 1) * P + f] = z[2 * f + 1];
        }
    }
    double top = 0.0;
    for (size_t t = 0; t < S; t++)
        top = fabs(tmp[t]) > top ? fabs(tmp[t]) : top;
    *scale = top / AMSCR__HF_SPEC_Q;
    for (size_t t = 0; t < S; t++) {
        double q = top > 0.0 ? tmp[t] / *scale : 0.0;
        spec[t] = (int16_t)(q > AMSCR__HF_SPEC_Q ? AMSCR__HF_SPEC_Q : q < -AMSCR__HF_SPEC_Q ? -AMSCR__HF_SPEC_Q : lround(q));
    }
    return AMSCR_OK;
}

amscr_status amscr__hf_build(const double *base, size_t n, double locality, amscr__hf *out)
{
    const size_t D = AMSCR__HF_BINS;
    memset(out, 0, sizeof *out);
    if (n < D + 1)
        return amscr__fail(AMSCR_E_INVALID_ARG, "shape channel: N = %zu is below %zu", n, D + 1);
    out->n = n;
    out->nfreq = AMSCR__HF_FREQS(n) + 1;
    double *mir = amscr__malloc_array(2 * n, sizeof *mir);
    double *z = amscr__malloc_array(2 * n + AMSCR__HF_SPEC(out->nfreq), sizeof *z);
    double *cum = amscr__malloc_array(2 * (2 * n + 1), sizeof *cum);
    amscr__fft_plan plan;
    int have_plan = amscr__fft_plan_init(&plan, n) == 0;
    amscr_status st = AMSCR_OK;
    for (int o = 0; o < 2; o++) {
        out->seq[o] = amscr__malloc_array(n * D, sizeof(uint8_t));
        out->spec[o] = amscr__malloc_array(AMSCR__HF_SPEC(out->nfreq), sizeof(int16_t));
        if (!out->seq[o] || !out->spec[o])
            st = AMSCR_E_NOMEM;
    }
    if (!mir || !z || !cum || !have_plan || st != AMSCR_OK) {
        st = amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    } else {
        /* mirror image (x -> -x), traversed backwards so it stays counter-clockwise */
        for (size_t i = 0; i < n; i++) {
            mir[2 * i] = -base[2 * (n - 1 - i)];
            mir[2 * i + 1] = base[2 * (n - 1 - i) + 1];
        }
        heights(base, n, locality, out->seq[0], cum);
        heights(mir, n, locality, out->seq[1], cum);
        for (int o = 0; o < 2; o++)
            spectra(out->seq[o], n, out->nfreq, out->spec[o], &out->scale[o], &plan, z, z + 2 * n);
    }
    if (have_plan)
        amscr__fft_plan_free(&plan);
    free(mir);
    free(z);
    free(cum);
    if (st != AMSCR_OK)
        amscr__hf_free(out);
    return st;
}

amscr_status amscr__hf_build_mirror(const double *base, size_t n, double locality, amscr__hf *h)
{
    const size_t D = AMSCR__HF_BINS;
    double *mir = amscr__malloc_array(2 * n, sizeof *mir);
    double *cum = amscr__malloc_array(2 * (2 * n + 1), sizeof *cum);
    uint8_t *seq = amscr__malloc_array(n * D, sizeof *seq);
    amscr_status st = mir && cum && seq ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    if (st == AMSCR_OK && n < D + 1)
        st = amscr__fail(AMSCR_E_INVALID_ARG, "shape channel: N = %zu is below %zu", n, D + 1);
    if (st == AMSCR_OK) { /* as amscr__hf_build makes it */
        for (size_t i = 0; i < n; i++) {
            mir[2 * i] = -base[2 * (n - 1 - i)];
            mir[2 * i + 1] = base[2 * (n - 1 - i) + 1];
        }
        heights(mir, n, locality, seq, cum);
        h->seq[1] = seq;
        seq = NULL;
    }
    free(mir);
    free(cum);
    free(seq);
    return st;
}

amscr_status amscr__hf_spectra(amscr__hf *h, amscr__hf_ws *ws)
{
    amscr__fft_plan plan;
    int own = !ws || ws->n != h->n || !ws->have_plan;
    double *z = own ? amscr__malloc_array(2 * h->n + AMSCR__HF_SPEC(h->nfreq), sizeof *z) : ws->z;
    int have_plan = own && amscr__fft_plan_init(&plan, h->n) == 0;
    amscr_status st = z && (have_plan || !own) ? AMSCR_OK : AMSCR_E_NOMEM;
    for (int o = 0; o < 2 && st == AMSCR_OK; o++) {
        if (h->spec[o] || !h->seq[o])
            continue; /* kept, or an orientation not held */
        h->spec[o] = amscr__malloc_array(AMSCR__HF_SPEC(h->nfreq), sizeof(int16_t));
        if (h->spec[o])
            spectra(h->seq[o], h->n, h->nfreq, h->spec[o], &h->scale[o], own ? &plan : &ws->plan, z, z + 2 * h->n);
        else
            st = AMSCR_E_NOMEM;
    }
    if (have_plan)
        amscr__fft_plan_free(&plan);
    if (own)
        free(z);
    return st == AMSCR_OK ? st : amscr__fail(st, "shape channel: out of memory");
}

amscr_status amscr__hf_ws_init(amscr__hf_ws *ws, size_t n, size_t band)
{
    memset(ws, 0, sizeof *ws);
    size_t W = 2 * band + 1;
    ws->n = n;
    ws->z = amscr__malloc_array(2 * n + AMSCR__HF_SPEC(AMSCR__HF_FREQS(n) + 1), sizeof *ws->z); /* + spectra()'s */
    ws->acc = amscr__malloc_array(4 * (AMSCR__HF_FREQS(n) + 1), sizeof *ws->acc);
    ws->row = amscr__malloc_array(4 * W, sizeof *ws->row);
    ws->start = amscr__malloc_array(4 * W, sizeof *ws->start);
    ws->lanes = amscr__malloc_array(5 * 8 * W, sizeof *ws->lanes); /* 5 arrays of up to 8 lanes */
    ws->bands = amscr__malloc_array(8 * (n + 2 * band + 4) * AMSCR__HF_BINS, sizeof *ws->bands); /* strides 1, 2 */
    int ok = amscr__fft_plan_init(&ws->plan, n) == 0;
    ws->have_plan = ok;
    if (!ws->z || !ws->acc || !ws->row || !ws->start || !ws->lanes || !ws->bands || !ok) {
        amscr__hf_ws_free(ws);
        return amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    }
    return AMSCR_OK;
}

void amscr__hf_ws_free(amscr__hf_ws *ws)
{
    if (ws->have_plan)
        amscr__fft_plan_free(&ws->plan);
    free(ws->z);
    free(ws->acc);
    free(ws->row);
    free(ws->start);
    free(ws->lanes);
    free(ws->bands);
    memset(ws, 0, sizeof *ws);
}

/* The low-passed cross-spectra conj(A) B summed over the bins, for orientation 0 of b and,
 * when `both`, orientation 1: acc[4 f + 2 o] real, acc[4 f + 2 o + 1] imaginary part. Four
 * frequencies at a time side by side (vector registers), each summed over the bins in order:
 * products of the int16 values, exact in double whatever the order, then scaled. */
static void cross_spectra(const amscr__hf *a, const amscr__hf *b, int both, double *restrict acc)
{
    const size_t D = AMSCR__HF_BINS, F = a->nfreq, P = AMSCR__HF_PAD(F);
    const double sc[2] = {a->scale[0] * b->scale[0], a->scale[0] * b->scale[1]};
    for (size_t f0 = 0; f0 < F; f0 += 4) {
        double re[2][4] = {{0.0}}, im[2][4] = {{0.0}};
        for (size_t bin = 0; bin < D; bin++) {
            const int16_t *ar = a->spec[0] + 2 * bin * P + f0, *ai = ar + P;
            for (int o = 0; o < (both ? 2 : 1); o++) {
                const int16_t *br = b->spec[o] + 2 * bin * P + f0, *bi = br + P;
                for (size_t t = 0; t < 4; t++) {
                    re[o][t] += (double)ar[t] * br[t] + (double)ai[t] * bi[t];
                    im[o][t] += (double)ar[t] * bi[t] - (double)ai[t] * br[t];
                }
            }
        }
        for (size_t t = 0; t < 4 && f0 + t < F; t++)
            for (int o = 0; o < 2; o++) {
                acc[4 * (f0 + t) + 2 * (size_t)o] = re[o][t] * sc[o];
                acc[4 * (f0 + t) + 2 * (size_t)o + 1] = im[o][t] * sc[o];
            }
    }
}

/* The spectrum whose inverse FFT carries both orientations' correlations into z: orientation
 * 0's cross-spectrum X0 as it is, orientation 1's X1 times i (both correlations are real, so
 * the second rides in the imaginary part), each with its Hermitian half. */
static void pack_spectra(const double *acc, size_t n, int both, double *z)
{
    const size_t half = n / 2, fmax = AMSCR__HF_FREQS(n);
    memset(z, 0, 2 * n * sizeof *z);
    for (int q = 0; q < (both ? 2 : 1); q++)
        for (size_t f = 0; f <= fmax; f++) {
            double re = acc[4 * f + 2 * q], im = acc[4 * f + 2 * q + 1];
            double xr = q ? -im : re, xi = q ? re : im;
            z[2 * f] += xr;
            z[2 * f + 1] += xi;
            if (f > 0 && n - f > half) {
                z[2 * (n - f)] += q ? im : re;
                z[2 * (n - f) + 1] += q ? re : -im;
            }
        }
}

/* The first s of the largest z[2 s + o], o < no (orientation o's correlations over the n
 * shifts), into best[o] and its value into top[o]: the shift a scan keeping the first strict
 * maximum picks. The maximum by eight independent running maxima (two orientations x four
 * shifts: no chain of comparisons through all n), then its first place. */
static void first_max(const double *z, size_t n, size_t no, size_t best[2], double top[2])
{
    double m[8];
    for (size_t i = 0; i < 8; i++)
        m[i] = z[i % 2];
    size_t s4 = n / 4 * 4;
    for (size_t s = 0; s < s4; s += 4)
        for (size_t i = 0; i < 8; i++)
            m[i] = z[2 * s + i] > m[i] ? z[2 * s + i] : m[i];
    for (size_t s = s4; s < n; s++)
        for (size_t o = 0; o < 2; o++)
            m[o] = z[2 * s + o] > m[o] ? z[2 * s + o] : m[o];
    for (size_t o = 0; o < no; o++) {
        double t = m[o];
        for (size_t k = 1; k < 4; k++)
            t = m[2 * k + o] > t ? m[2 * k + o] : t;
        size_t s = 0;
        while (s + 1 < n && z[2 * s + o] != t)
            s++;
        best[o] = s;
        top[o] = t;
    }
}

/* The cyclic shift of b that maximizes its correlation with a, for orientation 0 and, when
 * `both`, orientation 1 — one inverse FFT for the two. shift[o] and corr[o] receive them. */
static void best_shifts(const amscr__hf *a, const amscr__hf *b, int both, amscr__hf_ws *ws, size_t shift[2],
                        double corr[2])
{
    const size_t n = a->n;
    double *z = ws->z;
    cross_spectra(a, b, both, ws->acc);
    pack_spectra(ws->acc, n, both, z);
    amscr__fft(&ws->plan, z, 1);
    first_max(z, n, both ? 2 : 1, shift, corr);
}

/* The DP jobs of the pair (a, b): the orientation(s) of b and their shifts; returns 1 or 2. */
static int pair_jobs(const amscr__hf *a, const amscr__hf *b, const amscr__hf_cfg *cfg, amscr__hf_ws *ws,
                     const uint8_t *seq[2], size_t shift[2])
{
    size_t sh[2] = {0, 0};
    double corr[2] = {0.0, -DBL_MAX};
    best_shifts(a, b, cfg->reflections, ws, sh, corr);
    if (cfg->reflections && cfg->both_orientations) {
        seq[0] = b->seq[0];
        seq[1] = b->seq[1];
        shift[0] = sh[0];
        shift[1] = sh[1];
        return 2;
    }
    int o = corr[1] > corr[0] ? 1 : 0;
    seq[0] = b->seq[o];
    shift[0] = sh[o];
    return 1;
}

static size_t pair_band(const amscr__hf *a, const amscr__hf_cfg *cfg)
{
    return cfg->band < a->n / 2 ? cfg->band : a->n / 2;
}

static int32_t pair_skip(const amscr__hf_cfg *cfg) { return (int32_t)lround(cfg->skip * AMSCR__HF_QUANT); }

double amscr__hf_distance(const amscr__hf *a, const amscr__hf *b, const amscr__hf_cfg *cfg, amscr__hf_ws *ws)
{
    const uint8_t *seq[2];
    size_t shift[2];
    int jobs = pair_jobs(a, b, cfg, ws, seq, shift);
    double d = DBL_MAX;
    for (int t = 0; t < jobs; t++) {
        double v =
            amscr__hf_band_dp(a->seq[0], seq[t], a->n, shift[t], pair_band(a, cfg), cfg->stride, pair_skip(cfg), ws);
        d = v < d ? v : d;
    }
    return d;
}

/* The DPs of the jobs (A[j], B[j], s[j]), j < jobs, into d[j]: eight side by side while more
 * than four remain and the processor runs eight, else four (a short group repeats its last). */
static void band_dps(const uint8_t *const A[], const uint8_t *const B[], const size_t s[], size_t jobs,
                     const amscr__hf *a, const amscr__hf_cfg *cfg, amscr__hf_ws *ws, double *d)
{
    size_t lanes = (size_t)amscr__hf_lanes();
    for (size_t j0 = 0; j0 < jobs;) {
        size_t g = jobs - j0 > 4 && lanes == 8 ? 8 : 4;
        const uint8_t *gA[8], *gB[8];
        size_t gs[8];
        double gd[8];
        for (size_t l = 0; l < g; l++) {
            size_t j = j0 + l < jobs ? j0 + l : jobs - 1;
            gA[l] = A[j];
            gB[l] = B[j];
            gs[l] = s[j];
        }
        if (g == 8)
            amscr__hf_band_dp8(gA, gB, gs, a->n, pair_band(a, cfg), cfg->stride, pair_skip(cfg), ws, gd);
        else
            amscr__hf_band_dp4(gA, gB, gs, a->n, pair_band(a, cfg), cfg->stride, pair_skip(cfg), ws, gd);
        for (size_t l = 0; l < g && j0 + l < jobs; l++)
            d[j0 + l] = gd[l];
        j0 += g;
    }
}

void amscr__hf_distances(const amscr__hf *const a[], const amscr__hf *const b[], size_t count,
                         const amscr__hf_cfg *cfg, amscr__hf_ws *ws, double *out)
{
    enum { J = 2 * AMSCR__HF_GROUP };
    const uint8_t *A[J], *B[J];
    size_t shift[J], owner[J], jobs = 0;
    double d[J];
    for (size_t p = 0; p < count; p++) {
        int k = pair_jobs(a[p], b[p], cfg, ws, B + jobs, shift + jobs);
        for (int t = 0; t < k; t++) {
            owner[jobs + (size_t)t] = p;
            A[jobs + (size_t)t] = a[p]->seq[0];
        }
        jobs += (size_t)k;
        out[p] = DBL_MAX;
    }
    if (jobs == 0)
        return;
    band_dps(A, B, shift, jobs, a[0], cfg, ws, d);
    for (size_t j = 0; j < jobs; j++)
        if (d[j] < out[owner[j]])
            out[owner[j]] = d[j];
}
