/* channel.h — internals of the shape channel (channel.c) and of the fused retrieval
 * matrix (fuse.c). Never installed. */
#ifndef AMSCR_CHANNEL_H
#define AMSCR_CHANNEL_H

#include "fft.h"
#include "internal.h"

/* Bins of the height function of one sample (the descriptor's dimension). */
#define AMSCR__HF_BINS 16
/* Quantization of the heights (units of the normalized frame, RMS radius ~1.4): steps of
 * 1/16, range +-8; the pair cost is then an exact integer sum of absolute differences. */
#define AMSCR__HF_QUANT 16.0
/* Frequencies used by the shift search (the correlation is low-passed; the DP band absorbs
 * the coarser shift): the first N/8, at most N/2. */
#define AMSCR__HF_FREQS(n) ((n) / 8 < (n) / 2 ? (n) / 8 : (n) / 2)
/* The kept frequencies of every bin's DFT are stored back to back (AMSCR__HF_PAD: no padding
 * between the bins), and the values of one orientation's spectra: real and imaginary parts of
 * every bin, then 3 zeros (the shift search reads four frequencies at a time, past a bin's last
 * into the next one's, whose products it drops; past the last bin's into the zeros). */
#define AMSCR__HF_PAD(nfreq) (nfreq)
#define AMSCR__HF_SPEC(nfreq) (2 * AMSCR__HF_BINS * (nfreq) + 3)

/* A shape's height-function sequences: forward and mirrored, with the DFT of every bin (only
 * the frequencies the shift search reads). */
typedef struct {
    size_t n;
    size_t nfreq;    /* frequencies kept of each bin's DFT: AMSCR__HF_FREQS(n) + 1 */
    uint8_t *seq[2]; /* n * AMSCR__HF_BINS, weighted heights, quantized: 128 + QUANT * h */
    int16_t *spec[2]; /* AMSCR__HF_SPEC(nfreq): per bin nfreq real parts, then imaginary,
                       * in units of scale[o] (amscr__hf_quantize: the shift search's correlations,
                       * summed exactly in double, then scaled) */
    double scale[2];
} amscr__hf;

/* The largest magnitude of an orientation's spectra held as this int16 (the scale is that
 * magnitude / AMSCR__HF_SPEC_Q): a spectrum value is off by at most half a step. */
#define AMSCR__HF_SPEC_Q 32767.0

typedef struct {
    size_t band;           /* half width of the DP band, samples */
    double skip;           /* cost of a sample matched twice (a skipped one on the other side) */
    int reflections;       /* also try the mirrored sequence */
    int both_orientations; /* run the DP on both orientations (else the better correlation) */
    size_t stride;         /* the DP visits every stride-th sample of both curves (1 or 2) */
} amscr__hf_cfg;

/* Per-thread scratch of the pair distance. */
struct amscr__hf_ws {
    size_t n;
    amscr__fft_plan plan;
    int have_plan;
    double *z;
    double *acc; /* the shift search's cross-spectra: 4 (AMSCR__HF_FREQS(n) + 1) */
    int32_t *row;
    int32_t *start;
    int32_t *lanes; /* the side-by-side DPs' rows: 5 arrays of 8 lanes x (2 band + 1) */
    uint8_t *bands; /* their B samples in band order: 8 lanes x (n + 2 band + 4) x AMSCR__HF_BINS */
};

amscr_status amscr__hf_build(const double *base, size_t n, double locality, amscr__hf *out);
void amscr__hf_free(amscr__hf *h);
typedef struct amscr__hf_ws amscr__hf_ws;
/* The mirrored heights of h (seq[1], allocated here) from its frame's points base: bit for bit
 * amscr__hf_build's (an index keeps a shape's forward orientation only: the one a pair reads of
 * its lower index; channel.h's pair calls read both of the higher). */
amscr_status amscr__hf_build_mirror(const double *base, size_t n, double locality, amscr__hf *h);
/* The spectra of h's orientations that have heights and no spectra yet (allocated here; free with amscr__hf_free or free()) from its
 * height sequences, n and nfreq: bit for bit amscr__hf_build's (an index file keeps the heights
 * only, index_io.c). ws (may be NULL): a pair scratch whose FFT plan is used when it fits. */
amscr_status amscr__hf_spectra(amscr__hf *h, amscr__hf_ws *ws);
amscr_status amscr__hf_ws_init(amscr__hf_ws *ws, size_t n, size_t band);
void amscr__hf_ws_free(amscr__hf_ws *ws);
/* The channel distance of two shapes built with the same n (>= 0, 0 for identical ones). */
double amscr__hf_distance(const amscr__hf *a, const amscr__hf *b, const amscr__hf_cfg *cfg, amscr__hf_ws *ws);

/* Pairs amscr__hf_distances takes at once. */
#define AMSCR__HF_GROUP 8
/* The channel distances of the pairs (a[t], b[t]), t < count <= AMSCR__HF_GROUP, into out[t]:
 * bit for bit amscr__hf_distance's, their DPs run side by side. */
void amscr__hf_distances(const amscr__hf *const a[], const amscr__hf *const b[], size_t count,
                         const amscr__hf_cfg *cfg, amscr__hf_ws *ws, double *out);
/* The banded DTW of A against B cyclically shifted by s (channel_dp.c; see channel.c's file
 * comment), and the same for four or eight (A, B, s) at once, bit for bit. */
double amscr__hf_band_dp(const uint8_t *A, const uint8_t *B, size_t n, size_t s, size_t band, size_t stride,
                         int32_t skip, amscr__hf_ws *ws);
void amscr__hf_band_dp4(const uint8_t *const A[4], const uint8_t *const B[4], const size_t s[4], size_t n,
                        size_t band, size_t stride, int32_t skip, amscr__hf_ws *ws, double out[4]);
void amscr__hf_band_dp8(const uint8_t *const A[8], const uint8_t *const B[8], const size_t s[8], size_t n,
                        size_t band, size_t stride, int32_t skip, amscr__hf_ws *ws, double out[8]);
/* The lanes this processor runs side by side: 8 with AVX2 (amscr__hf_band_dp8 in one pass),
 * else 4 (amscr__hf_band_dp8 runs amscr__hf_band_dp4 twice). */
int amscr__hf_lanes(void);

/* Symmetric n x n matrix of channel distances (zero diagonal), on `threads` threads. */
amscr_status amscr__hf_matrix(const amscr__hf *hf, size_t n, const amscr__hf_cfg *cfg, unsigned threads,
                              amscr_progress_fn progress, void *user, double *out);
/* out (n x n) from its upper triangle: mirrored below, a zero diagonal. */
void amscr__mirror_upper(double *out, size_t n);
/* The channel's sequences of a prepared shape in `frame`, with the settings of p. */
amscr_status amscr__hf_of_descriptor(const amscr_params *p, amscr_invariance frame, const amscr_descriptor *d,
                                     amscr__hf *out);
/* Its mirrored heights only, into h->seq[1] (amscr__hf_build_mirror; d may be a shallow
 * descriptor: its input samples are all that is read). */
amscr_status amscr__hf_mirror_of_descriptor(const amscr_params *p, amscr_invariance frame,
                                            const amscr_descriptor *d, amscr__hf *h);
/* The channel's pair settings from p for N samples. */
void amscr__hf_cfg_from(const amscr_params *p, size_t n, int second, amscr__hf_cfg *cfg);

/* The frames of the channel and their shares (fuse.c): the primary frame, plus the whitened
 * frame with channel_affine_share when the primary one is the similarity frame. Returns the
 * count (1 or 2); the channel distance combines the frames' distances (amscr__channel_combine). */
int amscr__channel_frames(const amscr_params *p, amscr_invariance frames[2], double share[2]);
/* A pair's channel distance from its distances d0, d1 in the frames of amscr__channel_frames
 * (nf of them): the shares' sum m = s0 d0 + s1 d1; with channel_affine_view f > 0 and two
 * frames, min(m, f d1): a pair the whitened frame alone finds f times nearer (an affine view)
 * is ranked by it. */
static inline double amscr__channel_combine(const amscr_params *p, int nf, const double share[2], double d0,
                                            double d1)
{
    if (nf < 2)
        return d0;
    double m = share[0] * d0 + share[1] * d1, a = p->channel_affine_view * d1;
    return p->channel_affine_view > 0.0 && a < m ? a : m;
}
/* The weights sa, sh of the fusion (fuse.c) for channel weight w and the medians. */
void amscr__fuse_scales(double w, double med_a, double med_h, double *sa, double *sh);
/* The base distance of one pair, as the fusion computes its cell: sym (the symmetrized AMSCR
 * distance, lower index's direction first) alone for w <= 0, ch (the channel) alone for
 * w >= 1, else sa sym + sh ch. */
double amscr__fuse_pair(double w, double sa, double sh, double sym, double ch);
/* The retrieval matrix before its re-ranking (the fused base matrix, n x n) into out_dist,
 * and the fusion's medians into med[0] (AMSCR) and med[1] (channel), 0 when unused. */
amscr_status amscr__base_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist,
                                double med[2]);

#endif
