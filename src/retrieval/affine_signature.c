/* affine_signature.c — the shortlist signature of a prepared shape (affine_signature.h).
 *
 * An index query matches only the shapes whose signatures are nearest its own, so the
 * signature must rank shapes as the shape channel does (docs/method.md §10.2): the channel's
 * own features, summarized so that no alignment is needed. For every sample i of the N
 * prepared points, the channel's height function h(i, b) (signed distances of the other
 * samples to the tangent at i, averaged in AMSCR__SIG_BINS bins along the curve, weighted by
 * 1 / (1 + locality * distance along the curve)), unquantized; then, per bin b, the
 * magnitudes |sum_i h(i, b) exp(-2 pi j k i / N)| / N for k < AMSCR__SIG_FREQS. A cyclic
 * shift of the samples (another start point) changes only the phases, so the magnitudes
 * are shift-invariant; by Parseval the distance of the magnitude vectors is at most the
 * distance of the aligned sequences' low frequencies, which is what the channel compares.
 *
 * The prepared samples follow a group-invariant parametrization (Euclidean arc length after
 * whitening by region moments), so in the whitened frame an affine map of the input changes
 * the sequence only by a shift (and a reflection reverses it): that block is affine-invariant.
 * The similarity frame (centroid at the origin, RMS radius sqrt(2)) keeps aspect and shear,
 * which tell many articulated classes apart. Each block is scaled by its frame's share in the
 * channel, so the signature distance mixes the frames as the channel does.
 *
 * The frames are affine maps of the prepared input samples, applied on the fly: nothing is
 * allocated, O(N^2 * bins) per frame. */
#include "affine_signature.h"

#include "dense.h"

#include <math.h>
#include <string.h>

#define SIG_PI 3.14159265358979323846

/* The frame map p -> M (p - c) of the input samples: whitened (affine) or scaled to an RMS
 * radius of sqrt(2) (similarity). 0 when the frame cannot be built (coincident or collinear
 * samples). */
static int frame_map(const amscr_descriptor *d, int whitened, double M[4], double c[2])
{
    size_t n = d->n;
    double cov[3], Winv[4];
    amscr__centroid(d->input, n, &c[0], &c[1]);
    amscr__scatter(d->input, n, c[0], c[1], 1.0, cov);
    for (int t = 0; t < 3; t++)
        cov[t] /= (double)n;
    if (!(cov[0] + cov[2] > 0.0) || !isfinite(cov[0] + cov[1] + cov[2]))
        return 0;
    if (whitened)
        return amscr__sym2_invsqrt(cov, M, Winv);
    double k = sqrt(2.0 / (cov[0] + cov[2]));
    M[0] = M[3] = k;
    M[1] = M[2] = 0.0;
    return 1;
}

static void point(const amscr_descriptor *d, const double M[4], const double c[2], size_t i, double *x, double *y)
{
    double dx = d->input[2 * i] - c[0], dy = d->input[2 * i + 1] - c[1];
    *x = M[0] * dx + M[1] * dy;
    *y = M[2] * dx + M[3] * dy;
}

/* The height bins of sample i into v (the channel's heights, channel.c, unquantized) and into
 * w the bins of the mirror image's sample (bins of the samples behind: the mirror image,
 * traversed counter-clockwise, runs the other way, with the same tangent line and heights). */
static void heights_at(const amscr_descriptor *d, const double M[4], const double c[2], size_t i, double locality,
                       double *v, double *w)
{
    const size_t D = AMSCR__SIG_BINS, n = d->n;
    double acc[2][AMSCR__SIG_BINS] = {{0}}, xi, yi, xp, yp, xm, ym;
    size_t cnt[AMSCR__SIG_BINS] = {0};
    point(d, M, c, i, &xi, &yi);
    point(d, M, c, (i + 1) % n, &xp, &yp);
    point(d, M, c, (i + n - 1) % n, &xm, &ym);
    double tx = xp - xm, ty = yp - ym, tl = sqrt(tx * tx + ty * ty);
    double nx = tl > 0.0 ? -ty / tl : 0.0, ny = tl > 0.0 ? tx / tl : 0.0;
    for (size_t j = 1; j < n; j++) {
        double xq, yq, h;
        size_t b = (j - 1) * D / (n - 1);
        point(d, M, c, (i + j) % n, &xq, &yq);
        h = (xq - xi) * nx + (yq - yi) * ny;
        acc[0][b] += h;
        point(d, M, c, (i + n - j) % n, &xq, &yq);
        h = (xq - xi) * nx + (yq - yi) * ny;
        acc[1][b] += h;
        cnt[b]++;
    }
    for (size_t b = 0; b < D; b++) {
        double centre = ((double)b + 0.5) / (double)D, frac = centre < 0.5 ? centre : 1.0 - centre;
        double wt = (cnt[b] ? 1.0 / (double)cnt[b] : 0.0) / (1.0 + locality * frac);
        v[b] = acc[0][b] * wt;
        w[b] = acc[1][b] * wt;
    }
}

/* One frame's block (orientations x bins x frequencies) into out, scaled by `weight`; zeros
 * when the frame cannot be built. */
static void frame_block(const amscr_descriptor *d, int whitened, double weight, double *out)
{
    enum { BK = AMSCR__SIG_BINS * AMSCR__SIG_FREQS };
    const size_t D = AMSCR__SIG_BINS, K = AMSCR__SIG_FREQS, n = d->n;
    double M[4], c[2], re[2 * BK] = {0}, im[2 * BK] = {0};
    memset(out, 0, 2 * BK * sizeof *out);
    if (weight <= 0.0 || n <= D || !frame_map(d, whitened, M, c))
        return;
    double locality = d->params.channel_locality;
    for (size_t i = 0; i < n; i++) {
        double v[2][AMSCR__SIG_BINS];
        heights_at(d, M, c, i, locality, v[0], v[1]);
        for (size_t k = 0; k < K; k++) {
            double w = 2.0 * SIG_PI * (double)((k * i) % n) / (double)n, cs = cos(w), sn = sin(w);
            for (size_t o = 0; o < 2; o++)
                for (size_t b = 0; b < D; b++) {
                    re[o * BK + b * K + k] += v[o][b] * cs;
                    im[o * BK + b * K + k] -= v[o][b] * sn;
                }
        }
    }
    for (size_t t = 0; t < 2 * BK; t++) {
        double m = weight * hypot(re[t], im[t]) / (double)n;
        out[t] = isfinite(m) ? m : 0.0;
    }
}

void amscr__affine_signature_share(const amscr_descriptor *d, double affine_share, double *out)
{
    const size_t B = 2 * AMSCR__SIG_BINS * AMSCR__SIG_FREQS;
    double s = affine_share < 0.0 ? 0.0 : affine_share > 1.0 ? 1.0 : affine_share;
    frame_block(d, 0, 1.0 - s, out);
    frame_block(d, 1, s, out + B);
}

void amscr__affine_signature(const amscr_descriptor *d, double *out)
{
    const amscr_params *p = &d->params;
    double share = p->channel_invariance == AMSCR_INVARIANCE_AFFINE ? 1.0 : p->channel_affine_share;
    amscr__affine_signature_share(d, share, out);
}

double amscr__affine_signature_distance(const double *a, const double *b)
{
    const size_t BK = AMSCR__SIG_BINS * AMSCR__SIG_FREQS;
    double sum = 0.0;
    for (size_t f = 0; f < 2; f++) {
        const double *x = a + 2 * f * BK, *y = b + 2 * f * BK;
        double same = 0.0, mirror = 0.0; /* each term both ways round: symmetric */
        for (size_t t = 0; t < BK; t++) {
            double e = x[t] - y[t], e2 = x[BK + t] - y[BK + t], m = x[t] - y[BK + t], m2 = x[BK + t] - y[t];
            same += 0.5 * (e * e + e2 * e2);
            mirror += 0.5 * (m * m + m2 * m2);
        }
        sum += sqrt(same < mirror ? same : mirror);
    }
    return sum;
}
