/* ordered.c — the polished map refined by the order of a noisy curve's points.
 *
 * A point-to-curve fit sees only how far each noisy point lies from the moved clean curve, not
 * where along it the point was taken: when the noise is as large as the spacing of the points,
 * the position of a long or thin part along itself is fixed by its ends' few points, and the
 * closest-point fit drifts there (a fork's tines, a car stretched 5:1). But the points come in
 * order along the curve, each a little further on than the one before. This stage uses that: a
 * hidden Markov model whose states are places on the moved clean curve a (ORDER_STATES per
 * observed point, evenly spaced along it), each observed point b_i emitted from its state with
 * isotropic Gaussian noise, and each step of the order advancing the state by 0 to `speed`
 * times the mean step (any advance in that range equally likely: the sampling need not be even;
 * `speed` is measured from the points, at least 2).
 * EM: the forward-backward pass gives each point's posterior over its place on a; the map is
 * then the weighted least-squares fit of those places onto the points. The states are rebuilt
 * from the new map each round; the steps are over-relaxed while the likelihood rises (plain EM
 * creeps along a long axis, where the likelihood is flat). Each point only looks at a band of states around where its
 * neighbours' closest points put it (a running median; later rounds: its place in the round
 * before), ORDER_BAND sigmas either side.
 *
 * Measured (docs/decisions.md; bench/registration_heldout.py, 280 held-out pairs at 2 % noise): median map error
 * 0.57 -> 0.43 % of the size, 95th percentile 1.65 -> 1.21 %, within 2 %: 96.8 -> 98.2 %. It runs
 * only on markedly noisy curves (polish.c decides) and never on missing runs or fragments. */
#include "ordered.h"

#include "dense.h"
#include "internal.h"
#include "match.h"
#include "nearest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* States per observed point (evenly spaced along the moved curve; 2 measured no better). */
#define ORDER_STATES 1
/* A step of the order advances 0 .. `speed` times the mean step along the curve, `speed`
 * measured from the points (measured_speed): their steps smoothed over SPEED_SMOOTH points (a
 * window of +-SPEED_HALF), the largest over the mean times SPEED_MARGIN, within SPEED_MIN ..
 * SPEED_MAX. Measured on 140 noisy pairs sampled 1 / 6 / 10 / 20 times denser on half the
 * curve (bench/registration_uneven.py, within 2 %): a fixed 0-2x range 99.3 / 83.6 / 79.3 /
 * 82.1 %, measured 99.3 / 97.1 / 93.6 / 87.1 %, without the stage 99.3 / 95.0 / 94.3 / 89.3 %. */
#define SPEED_SMOOTH 4.0
#define SPEED_HALF 12
#define SPEED_MARGIN 1.25
#define SPEED_MIN 2.0
#define SPEED_MAX 16.0
/* EM rounds (measured on the held-out pairs at 2 % noise, median error: 0.57 % without the
 * stage; plain EM 0.455 % after 8 rounds, 0.428 % after 40; over-relaxed 0.437 % after 8, 0.431 %
 * after 12, 0.429 % after 16). */
#define ORDER_ITERS 12
/* Each point's band: its place +- this many noise sigmas along the curve, plus a step (4
 * measured the same). */
#define ORDER_BAND 3.0
/* The widest band (states); beyond it the noise is too large for the order to say much. */
#define ORDER_MAX_WIDTH 127
/* The stage runs when the points' noise sigma is at least this share of their median spacing:
 * for noise much larger than the spacing the median edge is 1.66 sigma (ratio 0.6); a pixel
 * chain's staircase reads below 0.35; the clean resampled curves of the held-out pairs 0.04. */
#define ORDER_MIN_SCATTER 0.45
/* A result that moved the curve by more than this many noise sigmas (RMS) is not trusted. */
#define ORDER_MAX_MOVE 4.0
/* The largest stretch of an EM step (accelerated_em; 8, 16, 32 measured alike). */
#define ETA_MAX 16.0
/* Half-width of the running median that centres the bands (points). */
#define ORDER_MEDIAN_HALF 8

/* Emissions below e^-EXP_CUT and message entries below TINY are zero: never a denormal (they
 * would slow every product tenfold and weigh nothing). */
#define EXP_CUT 40.0
#define TINY 1e-30

typedef struct {
    const double *a, *b;
    size_t na, nb, K, W, S;
    double sig2;
    double *sp, *sa;  /* 2K states: on the moved curve (b's frame), and in a's frame */
    double *em;       /* nb * W emissions */
    double *fw, *bw;  /* nb * W forward and backward messages */
    double *wk, *tk;  /* K posterior weights, 2K weighted sums of the points */
    double *cum, *r;  /* na + 1 arc lengths; nb band offsets (scratch) */
    double *pre;      /* W + 1 prefix sums */
    long *c;          /* nb nearest states, then the bands' first states */
    double *mean;     /* nb posterior mean places (states, from the band's first) */
    int reversed;     /* the states run against a's order */
    amscr__grid g;
    double *block;
    int nomem; /* an allocation failed */
} order_t;

static void order_free(order_t *o)
{
    amscr__grid_free(&o->g);
    free(o->block);
    free(o->c);
}

static int order_alloc(order_t *o)
{
    size_t K = o->K, nb = o->nb, W = o->W;
    size_t n = 4 * K + 3 * nb * W + 3 * K + o->na + 1 + 2 * nb + W + 1;
    o->block = amscr__malloc_array(n, sizeof *o->block);
    o->c = amscr__malloc_array(nb, sizeof *o->c);
    if (!o->block || !o->c)
        return 0;
    double *p = o->block;
    o->sp = p, p += 2 * K;
    o->sa = p, p += 2 * K;
    o->em = p, p += nb * W;
    o->fw = p, p += nb * W;
    o->bw = p, p += nb * W;
    o->wk = p, p += K;
    o->tk = p, p += 2 * K;
    o->cum = p, p += o->na + 1;
    o->r = p, p += nb;
    o->mean = p, p += nb;
    o->pre = p;
    return 1;
}

/* K states evenly spaced along Y a: sp (moved), sa (a's frame). Returns the step, 0 if none. */
static double build_states(order_t *o, const double Y[6])
{
    const double *a = o->a;
    size_t na = o->na;
    o->cum[0] = 0.0;
    for (size_t i = 0; i < na; i++) {
        size_t e = (i + 1) % na;
        double dx = a[2 * e] - a[2 * i], dy = a[2 * e + 1] - a[2 * i + 1];
        o->cum[i + 1] = o->cum[i] + hypot(Y[0] * dx + Y[1] * dy, Y[3] * dx + Y[4] * dy);
    }
    double L = o->cum[na];
    if (!(L > 0.0) || !isfinite(L))
        return 0.0;
    for (size_t k = 0, i = 0; k < o->K; k++) {
        double t = L * (double)k / (double)o->K;
        while (i + 1 < na && o->cum[i + 1] < t)
            i++;
        size_t e = (i + 1) % na;
        double len = o->cum[i + 1] - o->cum[i], f = len > 0.0 ? (t - o->cum[i]) / len : 0.0;
        double x = a[2 * i] + f * (a[2 * e] - a[2 * i]), y = a[2 * i + 1] + f * (a[2 * e + 1] - a[2 * i + 1]);
        o->sa[2 * k] = x, o->sa[2 * k + 1] = y;
        o->sp[2 * k] = Y[0] * x + Y[1] * y + Y[2];
        o->sp[2 * k + 1] = Y[3] * x + Y[4] * y + Y[5];
    }
    return L / (double)o->K;
}

/* d wrapped into (-K/2, K/2]. */
static long wrap(long d, long K)
{
    d %= K;
    if (d > K / 2)
        d -= K;
    if (d <= -K / 2 - (K % 2))
        d += K;
    return d;
}

/* Reverses the states' order (b runs the other way round the moved curve). */
static void reverse_states(order_t *o)
{
    for (size_t k = 0, j = o->K - 1; k < j; k++, j--)
        for (int q = 0; q < 2; q++) {
            double t = o->sp[2 * k + q];
            o->sp[2 * k + q] = o->sp[2 * j + q], o->sp[2 * j + q] = t;
            t = o->sa[2 * k + q];
            o->sa[2 * k + q] = o->sa[2 * j + q], o->sa[2 * j + q] = t;
        }
}

/* The first round's bands: nearest states of b's points; the noise variance per coordinate (their
 * mean squared distance); the states turned to run with b; each band centred on the running
 * median of its neighbours' places; the bands' first states in o->c. Returns 0 when it cannot. */
static int first_bands(order_t *o)
{
    long K = (long)o->K;
    double s2 = 0.0, d2;
    int g = amscr__grid_build(&o->g, o->sp, o->K);
    o->nomem = g < 0;
    if (g <= 0)
        return 0;
    for (size_t i = 0; i < o->nb; i++) {
        o->c[i] = (long)amscr__grid_nearest(&o->g, o->sp, o->b[2 * i], o->b[2 * i + 1], &d2);
        s2 += d2;
    }
    o->sig2 = s2 / (double)o->nb;
    long turn = 0;
    for (size_t i = 1; i < o->nb; i++) { /* the majority of the steps (noise makes big ones both ways) */
        long d = wrap(o->c[i] - o->c[i - 1], K);
        turn += (d > 0) - (d < 0);
    }
    o->reversed = turn < 0;
    if (o->reversed) {
        reverse_states(o);
        for (size_t i = 0; i < o->nb; i++)
            o->c[i] = K - 1 - o->c[i];
    }
    double mu = (double)K / (double)o->nb, u = (double)o->c[0];
    for (size_t i = 0; i < o->nb; i++) { /* unwrapped place minus the even advance */
        if (i)
            u += (double)wrap(o->c[i] - o->c[i - 1], K);
        o->r[i] = u - mu * (double)i;
    }
    double win[2 * ORDER_MEDIAN_HALF + 1];
    long half = (long)(o->W / 2);
    for (size_t i = 0; i < o->nb; i++) {
        size_t lo = i > ORDER_MEDIAN_HALF ? i - ORDER_MEDIAN_HALF : 0, hi = i + ORDER_MEDIAN_HALF, n = 0;
        for (size_t j = lo; j <= hi && j < o->nb; j++)
            win[n++] = o->r[j];
        amscr__select_kth(win, n, n / 2);
        long centre = lround(win[n / 2] + mu * (double)i);
        o->c[i] = ((centre - half) % K + K) % K;
    }
    return o->sig2 > 0.0 && isfinite(o->sig2);
}

/* Later rounds' bands: centred on each point's posterior mean place of the round before (the
 * states keep their places along a while the map moves a little). */
static void next_bands(order_t *o)
{
    long K = (long)o->K, half = (long)(o->W / 2);
    if (o->reversed)
        reverse_states(o);
    for (size_t i = 0; i < o->nb; i++) {
        long centre = o->c[i] + lround(o->mean[i]);
        o->c[i] = ((centre - half) % K + K) % K;
    }
}

/* Emissions of each point over its band, scaled so the largest is 1; returns the log of the
 * scales (the sum of -lo / 2 sigma^2). */
static double emissions(order_t *o)
{
    size_t W = o->W, K = o->K;
    double logscale = 0.0;
    for (size_t i = 0; i < o->nb; i++) {
        double *e = o->em + i * W, lo = INFINITY;
        for (size_t j = 0; j < W; j++) {
            size_t k = ((size_t)o->c[i] + j) % K;
            double dx = o->b[2 * i] - o->sp[2 * k], dy = o->b[2 * i + 1] - o->sp[2 * k + 1];
            e[j] = dx * dx + dy * dy;
            lo = e[j] < lo ? e[j] : lo;
        }
        for (size_t j = 0; j < W; j++) { /* beyond e^-EXP_CUT: 0 (no denormals downstream) */
            double x = (e[j] - lo) / (2.0 * o->sig2);
            e[j] = x < EXP_CUT ? exp(-x) : 0.0;
        }
        logscale -= lo / (2.0 * o->sig2);
    }
    return logscale;
}

/* v (W) scaled to sum 1; when it is all zero (the band lost the chain), set to `fallback`.
 * Returns the sum it had (0 for a fallback). */
static double normalize(double *v, size_t W, const double *fallback)
{
    double s = 0.0, had;
    for (size_t j = 0; j < W; j++)
        s += v[j];
    had = s;
    if (!(s > 0.0) || !isfinite(s)) {
        s = had = 0.0;
        for (size_t j = 0; j < W; j++)
            s += (v[j] = fallback ? fallback[j] : 1.0);
    }
    for (size_t j = 0; j < W; j++) {
        v[j] /= s;
        v[j] = v[j] > TINY ? v[j] : 0.0;
    }
    return had;
}

/* The log of a forward step's sum; a lost chain counts as a very unlikely step. */
static double log_step(double sum)
{
    return sum > 0.0 ? log(sum) : -2.0 * EXP_CUT;
}

/* Prefix sums pre (W + 1) of v, or of v * e. */
static void window_sums(const double *v, const double *e, size_t W, double *pre)
{
    pre[0] = 0.0;
    for (size_t j = 0; j < W; j++)
        pre[j + 1] = pre[j] + (e ? v[j] * e[j] : v[j]);
}

/* The sum of entries lo..hi (clipped to 0..W-1) from their prefix sums. */
static double range_sum(const double *pre, size_t W, long lo, long hi)
{
    lo = lo < 0 ? 0 : lo;
    hi = hi >= (long)W ? (long)W - 1 : hi;
    return hi >= lo ? pre[hi + 1] - pre[lo] : 0.0;
}

/* Forward messages: each point's place given the points before it. Returns the log of the
 * scaled emissions' likelihood (up to constants). */
static double forward(order_t *o)
{
    size_t W = o->W;
    long K = (long)o->K;
    memcpy(o->fw, o->em, W * sizeof *o->fw);
    double ll = log_step(normalize(o->fw, W, o->em));
    for (size_t i = 1; i < o->nb; i++) {
        const double *prev = o->fw + (i - 1) * W, *e = o->em + i * W;
        double *cur = o->fw + i * W;
        long off = wrap(o->c[i] - o->c[i - 1], K); /* band i's first state in band i-1's terms */
        window_sums(prev, NULL, W, o->pre);
        for (size_t j = 0; j < W; j++) /* states j + off - S .. j + off of band i-1 */
            cur[j] = range_sum(o->pre, W, (long)j + off - (long)o->S, (long)j + off) * e[j];
        ll += log_step(normalize(cur, W, e));
    }
    return ll;
}

/* Backward messages: the points after each one given its place. */
static void backward(order_t *o)
{
    size_t W = o->W, nb = o->nb;
    long K = (long)o->K;
    double *last = o->bw + (nb - 1) * W;
    for (size_t j = 0; j < W; j++)
        last[j] = 1.0;
    for (size_t i = nb - 1; i-- > 0;) {
        const double *next = o->bw + (i + 1) * W, *e = o->em + (i + 1) * W;
        double *cur = o->bw + i * W;
        long off = wrap(o->c[i + 1] - o->c[i], K); /* band i+1's first state in band i's terms */
        window_sums(next, e, W, o->pre);
        for (size_t j = 0; j < W; j++) /* states j - off .. j - off + S of band i+1 */
            cur[j] = range_sum(o->pre, W, (long)j - off, (long)j - off + (long)o->S);
        normalize(cur, W, NULL);
    }
}

/* Posterior weights of the states and the weighted sums of the points they explain. */
static void posteriors(order_t *o)
{
    size_t W = o->W, K = o->K;
    double r2 = 0.0, mass = 0.0;
    memset(o->wk, 0, K * sizeof *o->wk);
    memset(o->tk, 0, 2 * K * sizeof *o->tk);
    for (size_t i = 0; i < o->nb; i++) {
        const double *f = o->fw + i * W, *g = o->bw + i * W;
        double s = 0.0, mj = 0.0;
        for (size_t j = 0; j < W; j++)
            s += f[j] * g[j];
        o->mean[i] = (double)(W / 2);
        if (!(s > 0.0) || !isfinite(s))
            continue;
        for (size_t j = 0; j < W; j++) {
            size_t k = ((size_t)o->c[i] + j) % K;
            double p = f[j] * g[j] / s, dx = o->b[2 * i] - o->sp[2 * k], dy = o->b[2 * i + 1] - o->sp[2 * k + 1];
            o->wk[k] += p;
            o->tk[2 * k] += p * o->b[2 * i];
            o->tk[2 * k + 1] += p * o->b[2 * i + 1];
            mj += p * (double)j;
            r2 += p * (dx * dx + dy * dy);
        }
        o->mean[i] = mj;
        mass += 1.0;
    }
    if (mass > 0.0 && r2 > 0.0) /* the next round's noise variance per coordinate */
        o->sig2 = r2 / (2.0 * mass);
}

/* The map that carries the states (a's frame) onto the points they explain, weighted. */
static int weighted_fit(const order_t *o, double Y[6])
{
    double N[9] = {0}, rx[3] = {0}, ry[3] = {0};
    for (size_t k = 0; k < o->K; k++) {
        double v[3] = {o->sa[2 * k], o->sa[2 * k + 1], 1.0}, w = o->wk[k];
        for (int p = 0; p < 3; p++) {
            for (int q = 0; q < 3; q++)
                N[3 * p + q] += w * v[p] * v[q];
            rx[p] += v[p] * o->tk[2 * k];
            ry[p] += v[p] * o->tk[2 * k + 1];
        }
    }
    double N2[9];
    memcpy(N2, N, sizeof N);
    if (!amscr__gauss_solve(N, rx, 3) || !amscr__gauss_solve(N2, ry, 3))
        return 0;
    double Z[6] = {rx[0], rx[1], rx[2], ry[0], ry[1], ry[2]};
    for (int k = 0; k < 6; k++)
        if (!isfinite(Z[k]))
            return 0;
    memcpy(Y, Z, sizeof Z);
    return 1;
}

/* RMS displacement of a's points between the maps Y and Z. */
static double rms_move(const double *a, size_t na, const double Y[6], const double Z[6])
{
    double s = 0.0;
    for (size_t i = 0; i < na; i++) {
        double x = a[2 * i], y = a[2 * i + 1];
        double dx = (Z[0] - Y[0]) * x + (Z[1] - Y[1]) * y + Z[2] - Y[2];
        double dy = (Z[3] - Y[3]) * x + (Z[4] - Y[4]) * y + Z[5] - Y[5];
        s += dx * dx + dy * dy;
    }
    return sqrt(s / (double)na);
}

/* One EM round: states from Z, bands, forward-backward, the weighted fit into Z; *ll: the log
 * likelihood of the Z given (and the noise variance it was evaluated with), up to constants. */
static int em_round(order_t *o, double Z[6], int first, double *ll)
{
    if (build_states(o, Z) <= 0.0)
        return 0;
    if (first && !first_bands(o))
        return 0;
    if (!first)
        next_bands(o);
    *ll = emissions(o) - (double)o->nb * log(o->sig2);
    *ll += forward(o);
    backward(o);
    posteriors(o);
    return weighted_fit(o, Z);
}

/* ORDER_ITERS rounds of EM from Z, over-relaxed: each round's EM step is stretched by eta,
 * doubled (up to ETA_MAX) while the likelihood rises and reset to a plain step from the last
 * EM point when it fell (EM creeps along directions the likelihood is flat in, like a long
 * axis). Z ends at the last EM point that raised the likelihood. */
static int accelerated_em(order_t *o, double Z[6])
{
    double last[6], M[6], ll, best = -INFINITY, eta = 1.0;
    memcpy(last, Z, sizeof last);
    for (int it = 0; it < ORDER_ITERS; it++) {
        memcpy(M, Z, sizeof M);
        if (!em_round(o, Z, it == 0, &ll))
            return 0;
        if (ll < best) { /* overshot: back to the EM point before, plain steps */
            memcpy(Z, last, sizeof last);
            eta = 1.0;
            best = -INFINITY;
            continue;
        }
        best = ll;
        memcpy(last, Z, sizeof last);
        for (int k = 0; k < 6; k++)
            Z[k] = M[k] + eta * (Z[k] - M[k]);
        eta = 2.0 * eta < ETA_MAX ? 2.0 * eta : ETA_MAX;
    }
    memcpy(Z, last, sizeof last);
    return 1;
}

/* How far one step of the order may advance, in mean steps: the largest step of b smoothed
 * along its order (a Gaussian of SPEED_SMOOTH points averages the noise out of the spacing) over
 * the mean one, times SPEED_MARGIN, within SPEED_MIN .. SPEED_MAX. Evenly sampled points read
 * below SPEED_MIN; a pen's samples, dense where it slowed, far more (scratch: nb values). */
static double measured_speed(const double *b, size_t nb, double *scratch)
{
    double w[2 * SPEED_HALF + 1], wsum = 0.0, px = 0.0, py = 0.0, mean = 0.0, top = 0.0;
    for (long k = -SPEED_HALF; k <= SPEED_HALF; k++)
        wsum += (w[k + SPEED_HALF] = exp(-0.5 * (double)(k * k) / (SPEED_SMOOTH * SPEED_SMOOTH)));
    for (long i = 0; i <= (long)nb; i++) {
        double sx = 0.0, sy = 0.0;
        for (long k = -SPEED_HALF; k <= SPEED_HALF; k++) {
            size_t j = (size_t)(((i + k) % (long)nb + (long)nb) % (long)nb);
            sx += w[k + SPEED_HALF] * b[2 * j], sy += w[k + SPEED_HALF] * b[2 * j + 1];
        }
        sx /= wsum, sy /= wsum;
        if (i) {
            scratch[i - 1] = hypot(sx - px, sy - py);
            mean += scratch[i - 1] / (double)nb;
            top = scratch[i - 1] > top ? scratch[i - 1] : top;
        }
        px = sx, py = sy;
    }
    double q = mean > 0.0 ? SPEED_MARGIN * top / mean : SPEED_MAX;
    return q < SPEED_MIN ? SPEED_MIN : q > SPEED_MAX ? SPEED_MAX : q;
}

/* The length of the closed polyline a moved by Y. */
static double moved_length(const double *a, size_t na, const double Y[6])
{
    double L = 0.0;
    for (size_t i = 0; i < na; i++) {
        size_t e = (i + 1) % na;
        double dx = a[2 * e] - a[2 * i], dy = a[2 * e + 1] - a[2 * i + 1];
        L += hypot(Y[0] * dx + Y[1] * dy, Y[3] * dx + Y[4] * dy);
    }
    return L;
}

/* The band width (states) for noise sigma `sigma` along a curve of state step `step`. */
static size_t band_width(double sigma, double step, size_t S)
{
    double half = ceil(ORDER_BAND * sigma / step) + (double)S;
    return half * 2.0 + 1.0 <= ORDER_MAX_WIDTH ? (size_t)(half * 2.0 + 1.0) : 0;
}

int amscr__ordered_fit(const double *a, size_t na, const double *b, size_t nb, double rough_b, double Y[6])
{
    if (na < 3 || nb < 2 * ORDER_MEDIAN_HALF + 1 || !(rough_b > 0.0))
        return 0;
    order_t o = {.a = a, .b = b, .na = na, .nb = nb, .K = ORDER_STATES * nb};
    double *scratch = amscr__malloc_array(nb, sizeof *scratch), sigma = sqrt(rough_b), Z[6];
    if (!scratch)
        return -1;
    double spacing = amscr__median_edge(b, nb, 1, scratch), speed = measured_speed(b, nb, scratch);
    free(scratch);
    o.S = (size_t)ceil(speed * ORDER_STATES);
    if (!(sigma >= ORDER_MIN_SCATTER * spacing))
        return 0;
    memcpy(Z, Y, sizeof Z);
    double L = moved_length(a, na, Z);
    o.W = L > 0.0 && isfinite(L) ? band_width(sigma, L / (double)o.K, o.S) : 0;
    if (o.W == 0 || o.W > o.K)
        return 0;
    if (!order_alloc(&o)) {
        order_free(&o);
        return -1;
    }
    int ok = accelerated_em(&o, Z);
    order_free(&o);
    if (o.nomem)
        return -1;
    if (!ok || rms_move(a, na, Y, Z) > ORDER_MAX_MOVE * sigma)
        return 0;
    memcpy(Y, Z, sizeof Z);
    return 1;
}
