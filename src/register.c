/* register.c — matching a prepared source onto a prepared target (DESIGN.md §3, §9).
 *
 * Start point: for closed curves the 2x2 cross-correlation R(s) = Σ_a h(a+s) f(a)^T over all N
 * cyclic shifts comes from one FFT product (the reversed target is the conjugate spectrum);
 * circular smoothing of both curves at σ_k multiplies its spectrum by |G_k|^2, so the stacked
 * least-squares residual of every shift costs O(N log N) per pair (the search criterion). The
 * best few shifts (local minima of that criterion) then get the whole method — per-scale
 * solves, residuals on the unsmoothed curves, scale selection, stacked solve — and the lowest
 * final distance wins. Per-scale solves use exact sums (the 3x3 normal matrices of the source
 * are precomputed in the descriptor); amscr_register reports the final stacked solve from
 * LAPACKE QR, amscr_distance (the batch path) from the closed form; tests check they agree.
 */
#include "fft.h"
#include "internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define AMSCR__CANDIDATES 3

/* Per-stage timing, compiled only into the benchmark's copy of the library
 * (-DAMSCR_STAGE_TIMING): the product's hot path has no clock calls. */
#ifdef AMSCR_STAGE_TIMING
#include <time.h>
static double stage_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#define STAGE_T0 double stage_t = stage_now()
#define STAGE_MARK(ws, i)                                                                                      \
    do {                                                                                                       \
        double stage_t1 = stage_now();                                                                         \
        (ws)->stage[i] += stage_t1 - stage_t;                                                                  \
        stage_t = stage_t1;                                                                                    \
    } while (0)
#else
#define STAGE_T0 ((void)0)
#define STAGE_MARK(ws, i) ((void)0)
#endif
#define AMSCR__KMAX 16

struct amscr_workspace {
    size_t n, p;
    amscr__fft_plan plan;
    double *z;       /* 4N: two complex arrays */
    double *crit;    /* N */
    double *P;       /* 8 (N/2+1): products H_i conj(F_j) for ij = xx, xy, yx, yy (complex) */
    double *q;       /* 4 (N/2+1): their real parts at the current fractional shift */
    double *curve;   /* 2N * (p+1): shifted target curves for the reported solve */
    double *scratch; /* selection scratch */
    size_t scratch_cap;
    /* QR of the final stacked system */
    double *qa, *qb, *qw;
    int *qi;
    size_t qcap;
    /* refinement in the aligned frame: closest-point pairs and residuals */
    double *rbuf;
    size_t rcap;
#ifdef AMSCR_STAGE_TIMING
    double stage[4]; /* shift search, per-scale solves, selection, final solve */
#endif
};

#ifdef AMSCR_STAGE_TIMING
void amscr__workspace_stage_times(const amscr_workspace *ws, double out[4]);
void amscr__workspace_stage_times(const amscr_workspace *ws, double out[4])
{
    memcpy(out, ws->stage, sizeof ws->stage);
}
#endif

typedef struct {
    double X[6]; /* h ≈ A f + B in the normalized frames: {a11, a12, b1, a21, a22, b2} */
    double dist;
    size_t shift;
    double fshift; /* continuous shift (closed curves) */
    double rcut;   /* refined: the trimming cut-off of the closest-point pairs in ws->rbuf */
    double rcost;  /* refinement on: the trimmed closest-point cost of the final map */
    int refined;   /* the refinement replaced the method's solution */
    int reflected;
    size_t p;
    double resid[AMSCR__MAX_SCALES];
    int kept[AMSCR__MAX_SCALES];
    size_t nkept;
    size_t k;
    double sse[AMSCR__KMAX];
    size_t nsse;
    double w[AMSCR__KMAX], mu[AMSCR__KMAX], var[AMSCR__KMAX];
    size_t ncomp;
    double threshold;
} match_t;

struct amscr_result {
    amscr_method method;
    match_t m;
    double affine_in[6];
    double affine_norm[6];
};

/* ------------------------------------------------------------------ workspace */

amscr_status amscr_workspace_new(amscr_workspace **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    amscr_workspace *ws = calloc(1, sizeof *ws);
    if (!ws)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_workspace_new: out of memory");
    *out = ws;
    return AMSCR_OK;
}

static void ws_release(amscr_workspace *ws)
{
    amscr__fft_plan_free(&ws->plan);
    free(ws->z);
    free(ws->scratch);
    free(ws->qa);
    free(ws->qi);
    free(ws->rbuf);
    ws->rbuf = NULL;
    ws->rcap = 0;
    ws->z = ws->scratch = ws->qa = NULL;
    ws->qi = NULL;
    ws->n = ws->p = ws->qcap = ws->scratch_cap = 0;
}

void amscr_workspace_free(amscr_workspace *ws)
{
    if (!ws)
        return;
    ws_release(ws);
    free(ws);
}

static amscr_status ws_reserve(amscr_workspace *ws, size_t n, size_t p)
{
    if (ws->n == n && ws->p >= p && ws->z)
        return AMSCR_OK;
    ws_release(ws);
    size_t half = n / 2 + 1;
    ws->z = amscr__malloc_array(5 * n + 12 * half + 2 * n * (p + 1) + 2 * n, sizeof(double));
    size_t kmax = p < AMSCR__KMAX ? p : AMSCR__KMAX;
    size_t s1 = amscr__kmeans1d_scratch(p, kmax), s2 = amscr__gmm1d_small_scratch(p, kmax);
    ws->scratch_cap = (s1 > s2 ? s1 : s2) + 4 * p + 64;
    ws->scratch = amscr__malloc_array(ws->scratch_cap, sizeof(double));
    if (!ws->z || !ws->scratch || amscr__fft_plan_init(&ws->plan, n) != 0) {
        ws_release(ws);
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->crit = ws->z + 4 * n;
    ws->P = ws->z + 5 * n;
    ws->q = ws->P + 8 * half;
    ws->curve = ws->q + 4 * half;
    ws->n = n;
    ws->p = p;
    return AMSCR_OK;
}

static amscr_status ws_reserve_qr(amscr_workspace *ws, size_t rows)
{
    if (ws->qcap >= rows)
        return AMSCR_OK;
    free(ws->qa);
    free(ws->qi);
    size_t wsz = amscr__lstsq_work_size(rows, 3, 2);
    ws->qa = amscr__malloc_array(5 * rows + wsz + 16, sizeof(double));
    ws->qi = amscr__malloc_array(8, sizeof(int));
    if (!ws->qa || !ws->qi) {
        free(ws->qa);
        free(ws->qi);
        ws->qa = NULL;
        ws->qi = NULL;
        ws->qcap = 0;
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->qb = ws->qa + 3 * rows;
    ws->qw = ws->qb + 2 * rows;
    ws->qcap = rows;
    return AMSCR_OK;
}

/* ------------------------------------------------------------ small algebra */

/* Target index of source sample a under (shift s, orientation o): o = 0 -> (a+s) mod n;
 * o = 1 (reversed target, closed) -> -(a+s) mod n; open: o = 1 -> n-1-a. */
static inline size_t tgt_index(size_t a, size_t s, int o, int closed, size_t n)
{
    if (!closed)
        return o ? n - 1 - a : a;
    size_t b = a + s;
    if (b >= n)
        b -= n;
    return o ? (b == 0 ? 0 : n - b) : b;
}

/* Cross sums of one level: R = Σ h [f, 1]^T (2x3 row-major). */
static void cross_sums(const double *f, const double *h, size_t n, size_t s, int o, int closed, double R[6])
{
    double r0 = 0, r1 = 0, r2 = 0, r3 = 0, r4 = 0, r5 = 0;
    for (size_t a = 0; a < n; a++) {
        size_t b = tgt_index(a, s, o, closed, n);
        double fx = f[2 * a], fy = f[2 * a + 1], hx = h[2 * b], hy = h[2 * b + 1];
        r0 += hx * fx;
        r1 += hx * fy;
        r2 += hx;
        r3 += hy * fx;
        r4 += hy * fy;
        r5 += hy;
    }
    R[0] = r0;
    R[1] = r1;
    R[2] = r2;
    R[3] = r3;
    R[4] = r4;
    R[5] = r5;
}

/* X = R M^-1 with Minv 3x3 (row-major, symmetric). */
static int inv3_general(const double m[9], double out[9]);

static void solve_x(const double R[6], const double Minv[9], double X[6])
{
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 3; j++)
            X[3 * i + j] = R[3 * i] * Minv[j] + R[3 * i + 1] * Minv[3 + j] + R[3 * i + 2] * Minv[6 + j];
}

/* Solves a small dense system a x = b (n <= 6) by Gaussian elimination with partial pivoting.
 * Returns 0 when singular. a is destroyed. */
static int gauss_solve(double *a, double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r * n + c]) > fabs(a[piv * n + c]))
                piv = r;
        if (!(fabs(a[piv * n + c]) > 1e-300))
            return 0;
        if (piv != c) {
            for (int k = 0; k < n; k++) {
                double t = a[c * n + k];
                a[c * n + k] = a[piv * n + k];
                a[piv * n + k] = t;
            }
            double t = b[c];
            b[c] = b[piv];
            b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = a[r * n + c] / a[c * n + c];
            for (int k = c; k < n; k++)
                a[r * n + k] -= f * a[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        double v = b[c];
        for (int k = c + 1; k < n; k++)
            v -= a[c * n + k] * b[k];
        b[c] = v / a[c * n + c];
    }
    return 1;
}

/* The least-squares map of one system (moments mom of the source, cross sums R) restricted to
 * the invariance group of the params:
 *   affine      X = R M^-1 (Minv given, or computed);
 *   similarity  A = [[a, -b], [b, a]] from the centred sums (closed form);
 *   penalized   affine plus lambda * n * |A - sim(A)|_F^2 (6x6 normal equations).
 * Returns 0 when singular. */
static int fit_x(const amscr_params *prm, const double mom[6], const double *Minv, const double R[6], double X[6])
{
    if (prm->invariance == AMSCR_INVARIANCE_SIMILARITY) {
        double n = mom[5], fx = mom[3] / n, fy = mom[4] / n, hx = R[2] / n, hy = R[5] / n;
        double cxx = R[0] - n * hx * fx, cxy = R[1] - n * hx * fy, cyx = R[3] - n * hy * fx, cyy = R[4] - n * hy * fy;
        double sc = mom[0] + mom[2] - n * (fx * fx + fy * fy);
        if (!(sc > 0.0))
            return 0;
        double a = (cxx + cyy) / sc, b = (cyx - cxy) / sc;
        X[0] = a;
        X[1] = -b;
        X[3] = b;
        X[4] = a;
        X[2] = hx - (a * fx - b * fy);
        X[5] = hy - (b * fx + a * fy);
        return 1;
    }
    if (prm->invariance == AMSCR_INVARIANCE_PENALIZED) {
        /* unknowns u = (a11, a12, b1, a21, a22, b2); blockdiag(M, M) + Q, Q from
         * (lambda n / 2) ((a11 - a22)^2 + (a12 + a21)^2) = lambda n |A - sim(A)|_F^2 */
        double G[36] = {0}, r[6] = {R[0], R[1], R[2], R[3], R[4], R[5]};
        const double M9[9] = {mom[0], mom[1], mom[3], mom[1], mom[2], mom[4], mom[3], mom[4], mom[5]};
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                G[i * 6 + j] = M9[i * 3 + j];
                G[(i + 3) * 6 + (j + 3)] = M9[i * 3 + j];
            }
        /* normal equations of data + P: G u + grad(P) / 2 = r, grad P / 2 = (lambda n / 2) (...) */
        double w = 0.5 * prm->penalty * mom[5];
        G[0 * 6 + 0] += w;
        G[4 * 6 + 4] += w;
        G[0 * 6 + 4] -= w;
        G[4 * 6 + 0] -= w;
        G[1 * 6 + 1] += w;
        G[3 * 6 + 3] += w;
        G[1 * 6 + 3] += w;
        G[3 * 6 + 1] += w;
        if (!gauss_solve(G, r, 6))
            return 0;
        memcpy(X, r, 6 * sizeof(double));
        return 1;
    }
    double Mi[9];
    if (!Minv) {
        const double M9[9] = {mom[0], mom[1], mom[3], mom[1], mom[2], mom[4], mom[3], mom[4], mom[5]};
        if (!inv3_general(M9, Mi))
            return 0;
        Minv = Mi;
    }
    solve_x(R, Minv, X);
    return 1;
}

/* The penalty of the penalized mode for n points (0 otherwise). */
static double penalty_of(const amscr_params *prm, const double X[6], double n)
{
    if (prm->invariance != AMSCR_INVARIANCE_PENALIZED)
        return 0.0;
    double c = 0.5 * (X[0] - X[4]), d = 0.5 * (X[1] + X[3]);
    return prm->penalty * n * 2.0 * (c * c + d * d);
}

/* Σ_a |X [f;1] - h|^2 = tr(X M X^T) - 2 tr(X R^T) + |h|^2 with M the 3x3 moments of f. */
static double resid_sum(const double X[6], const double mom[6], const double R[6], double hn2)
{
    const double M[9] = {mom[0], mom[1], mom[3], mom[1], mom[2], mom[4], mom[3], mom[4], mom[5]};
    double q = 0, c = 0;
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 3; j++) {
            double mx = M[3 * j] * X[3 * i] + M[3 * j + 1] * X[3 * i + 1] + M[3 * j + 2] * X[3 * i + 2];
            q += X[3 * i + j] * mx;
            c += X[3 * i + j] * R[3 * i + j];
        }
    }
    double v = q - 2.0 * c + hn2;
    return v > 0.0 ? v : 0.0;
}

static int inv3_general(const double m[9], double out[9])
{
    double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5], g = m[6], h = m[7], i = m[8];
    double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    double det = a * A + b * B + c * C;
    double scale = fabs(a) + fabs(e) + fabs(i);
    if (!(fabs(det) > 1e-13 * scale * scale * scale))
        return 0;
    out[0] = A / det;
    out[3] = B / det;
    out[6] = C / det;
    out[1] = -(b * i - c * h) / det;
    out[4] = (a * i - c * g) / det;
    out[7] = -(a * h - b * g) / det;
    out[2] = (b * f - c * e) / det;
    out[5] = -(a * f - c * d) / det;
    out[8] = (a * e - b * d) / det;
    return 1;
}

/* ------------------------------------------------------------ scale selection */

static void select_scales(const amscr_params *prm, amscr_method method, size_t finest, match_t *m, double *scratch)
{
    size_t p = m->p;
    m->k = 0;
    m->nsse = 0;
    m->ncomp = 0;
    m->threshold = INFINITY;
    for (size_t k = 0; k < p; k++)
        m->kept[k] = 0;
    if (method == AMSCR_METHOD_ACMA) {
        m->kept[finest] = 1;
        m->nkept = 1;
        return;
    }
    if (method == AMSCR_METHOD_AMSCR || p < 2) {
        for (size_t k = 0; k < p; k++)
            m->kept[k] = 1;
        m->nkept = p;
        return;
    }
    size_t kmax = prm->kmax < p ? prm->kmax : p;
    if (kmax > AMSCR__KMAX)
        kmax = AMSCR__KMAX;
    size_t K;
    if (method == AMSCR_METHOD_BINARY_EM) {
        K = 2;
    } else {
        double *sorted = scratch;
        double *dp = scratch + p;
        for (size_t k = 0; k < p; k++)
            sorted[k] = m->resid[k];
        for (size_t i = 1; i < p; i++) { /* insertion sort: p is small */
            double v = sorted[i];
            size_t j = i;
            while (j > 0 && sorted[j - 1] > v) {
                sorted[j] = sorted[j - 1];
                j--;
            }
            sorted[j] = v;
        }
        amscr__kmeans1d_dp(sorted, p, kmax, dp, m->sse, NULL);
        m->nsse = kmax;
        K = amscr__elbow_choose(m->sse, kmax, 1);
    }
    m->k = K;
    if (K <= 1) {
        /* one class: the mixture is a single Gaussian and every scale is kept */
        double mean = 0.0, var = 0.0;
        for (size_t k = 0; k < p; k++)
            mean += m->resid[k];
        mean /= (double)p;
        for (size_t k = 0; k < p; k++)
            var += (m->resid[k] - mean) * (m->resid[k] - mean);
        var /= (double)p;
        m->ncomp = 1;
        m->w[0] = 1.0;
        m->mu[0] = mean;
        m->var[0] = var > 1e-300 ? var : 1e-300;
        for (size_t k = 0; k < p; k++)
            m->kept[k] = 1;
        m->nkept = p;
        return;
    }
    unsigned it;
    int conv;
    double ll;
    if (amscr__gmm1d_fit_small(m->resid, p, K, 100, 1e-6, 1e-6, m->w, m->mu, m->var, scratch, &it, &conv, &ll) !=
        AMSCR_OK) {
        /* cannot happen for finite residuals; keep every scale rather than guess */
        for (size_t k = 0; k < p; k++)
            m->kept[k] = 1;
        m->nkept = p;
        return;
    }
    m->ncomp = K;
    double s0;
    amscr_status st = amscr_bayes_threshold(m->w[0], m->mu[0], m->var[0], m->w[1], m->mu[1], m->var[1], &s0);
    if (st != AMSCR_OK && st != AMSCR_E_NOT_FOUND)
        s0 = 0.5 * (m->mu[0] + m->mu[1]);
    m->threshold = s0;
    size_t best = 0;
    m->nkept = 0;
    for (size_t k = 0; k < p; k++) {
        if (m->resid[k] < m->resid[best])
            best = k;
        if (m->resid[k] <= s0) {
            m->kept[k] = 1;
            m->nkept++;
        }
    }
    if (m->nkept == 0) {
        m->kept[best] = 1;
        m->nkept = 1;
    }
}

/* ---------------------------------------------------- spectral cross sums
 * For closed curves every cross sum R_k(s) = Σ_a h_k(a+s) [f_k(a), 1]^T is a trigonometric
 * polynomial in the shift s: R_k,ij(s) = (1/N) Σ_w |G_k(w)|^2 H_i(w) conj(F_j(w)) e^{2πiws/N}.
 * Evaluated at integer s it equals the direct sum; between samples it is the band-limited
 * interpolation, which makes the start point continuous instead of quantized to 1/N. */

/* P_ij(w) = H_i(w) conj(F_j(w)) for w = 0..N/2 (reversed target: conj(H)). */
static void spectral_prepare(const amscr_descriptor *f, const amscr_descriptor *h, int o, amscr_workspace *ws)
{
    size_t n = f->n, half = n / 2 + 1;
    const double *Fx = f->spec, *Fy = f->spec + 2 * n, *Hx = h->spec, *Hy = h->spec + 2 * n;
    double sg = o ? -1.0 : 1.0;
    for (size_t w = 0; w < half; w++) {
        double fxr = Fx[2 * w], fxi = -Fx[2 * w + 1], fyr = Fy[2 * w], fyi = -Fy[2 * w + 1];
        double hr[2] = {Hx[2 * w], Hy[2 * w]}, hi[2] = {sg * Hx[2 * w + 1], sg * Hy[2 * w + 1]};
        double *P = ws->P + 8 * w;
        for (int i = 0; i < 2; i++) {
            P[4 * i + 0] = hr[i] * fxr - hi[i] * fxi;
            P[4 * i + 1] = hr[i] * fxi + hi[i] * fxr;
            P[4 * i + 2] = hr[i] * fyr - hi[i] * fyi;
            P[4 * i + 3] = hr[i] * fyi + hi[i] * fyr;
        }
    }
}

/* q_ij(w) = c_w Re(P_ij(w) e^{2πiws/N}) / N, c = 1 at w = 0 and N/2 (even N), else 2. */
static void spectral_q(amscr_workspace *ws, size_t n, double s)
{
    size_t half = n / 2 + 1;
    double th = 2.0 * 3.14159265358979323846 * s / (double)n;
    double cs = cos(th), sn = sin(th), er = 1.0, ei = 0.0, inv_n = 1.0 / (double)n;
    for (size_t w = 0; w < half; w++) {
        if ((w & 255) == 0 && w > 0) { /* re-anchor the rotation recurrence (large N only) */
            er = cos(th * (double)w);
            ei = sin(th * (double)w);
        }
        double c = (w == 0 || (2 * w == n)) ? inv_n : 2.0 * inv_n;
        const double *P = ws->P + 8 * w;
        double *q = ws->q + 4 * w;
        for (int j = 0; j < 4; j++)
            q[j] = c * (P[2 * j] * er - P[2 * j + 1] * ei);
        double t = er * cs - ei * sn;
        ei = er * sn + ei * cs;
        er = t;
    }
}

/* R (2x3) of one level from ws->q; gain NULL = unsmoothed. dc: Σ h_x, Σ h_y. */
static void spectral_level(const amscr_workspace *ws, size_t n, const double *gain, const double dc[2], double R[6])
{
    size_t half = n / 2 + 1;
    double r0 = 0, r1 = 0, r3 = 0, r4 = 0;
    for (size_t w = 0; w < half; w++) {
        const double *q = ws->q + 4 * w;
        double g = gain ? gain[w] : 1.0;
        r0 += g * q[0];
        r1 += g * q[1];
        r3 += g * q[2];
        r4 += g * q[3];
    }
    R[0] = r0;
    R[1] = r1;
    R[2] = dc[0];
    R[3] = r3;
    R[4] = r4;
    R[5] = dc[1];
}

/* The search criterion: minus the explained part of the stacked smoothed least-squares
 * problem, -tr(C S^-1 C^T) with C = Σ_k R_k(s) (2x2) and S = Σ_k S_k over all scales (or the
 * finest scale for acma). Minimizing it over s minimizes that least-squares residual. */
static void crit_matrix(const amscr_descriptor *f, int use_finest, int sim, double Sinv[4])
{
    double Sxx = 0, Sxy = 0, Syy = 0;
    if (use_finest) {
        const double *mo = f->mom + 6 * (f->finest + 1);
        Sxx = mo[0];
        Sxy = mo[1];
        Syy = mo[2];
    } else {
        for (size_t k = 0; k < f->p; k++) {
            const double *mo = f->mom + 6 * (k + 1);
            Sxx += mo[0];
            Sxy += mo[1];
            Syy += mo[2];
        }
    }
    double det = Sxx * Syy - Sxy * Sxy;
    Sinv[0] = Syy / det;
    Sinv[1] = -Sxy / det;
    Sinv[2] = Sxx / det;
    Sinv[3] = 0.0;
    if (sim) { /* similarity: the explained part is ((Cxx + Cyy)^2 + (Cyx - Cxy)^2) / tr S */
        Sinv[0] = 1.0 / (Sxx + Syy);
        Sinv[3] = 1.0;
    }
}

static inline double crit_value(const double C[4], const double Si[4])
{
    if (Si[3] != 0.0) {
        double u = C[0] + C[3], v = C[2] - C[1];
        return -(u * u + v * v) * Si[0];
    }
    /* tr(C Si C^T) = Σ_i c_i^T Si c_i over the rows c_i of C */
    double t = 0.0;
    for (int i = 0; i < 2; i++) {
        double x = C[2 * i], y = C[2 * i + 1];
        t += x * (Si[0] * x + Si[1] * y) + y * (Si[1] * x + Si[2] * y);
    }
    return -t;
}

/* The criterion and its first two derivatives in s in one spectral pass:
 * d/ds Re(P e^{iks}) = -k Im(P e^{iks}), d2/ds2 = -k^2 Re(P e^{iks}), k = 2πw/N. */
static void crit_newton(const amscr_descriptor *f, int use_finest, const double Si[4], amscr_workspace *ws, double s,
                        double *val, double *d1, double *d2)
{
    size_t n = f->n, half = n / 2 + 1;
    const double *gain = use_finest ? f->gain + f->finest * n : f->gain + f->p * n;
    double base = 2.0 * 3.14159265358979323846 / (double)n, th = base * s;
    double cs = cos(th), sn = sin(th), er = 1.0, ei = 0.0;
    double C[4] = {0, 0, 0, 0}, D[4] = {0, 0, 0, 0}, E[4] = {0, 0, 0, 0};
    for (size_t w = 0; w < half; w++) {
        if ((w & 255) == 0 && w > 0) {
            er = cos(th * (double)w);
            ei = sin(th * (double)w);
        }
        double g = (w == 0 || 2 * w == n) ? gain[w] : 2.0 * gain[w];
        double k = base * (double)w;
        const double *P = ws->P + 8 * w;
        for (int j = 0; j < 4; j++) {
            double re = P[2 * j] * er - P[2 * j + 1] * ei, im = P[2 * j] * ei + P[2 * j + 1] * er;
            C[j] += g * re;
            D[j] -= g * k * im;
            E[j] -= g * k * k * re;
        }
        double t = er * cs - ei * sn;
        ei = er * sn + ei * cs;
        er = t;
    }
    double inv_n = 1.0 / (double)n;
    for (int j = 0; j < 4; j++) {
        C[j] *= inv_n;
        D[j] *= inv_n;
        E[j] *= inv_n;
    }
    if (Si[3] != 0.0) { /* similarity: crit = -(u^2 + v^2) / tr S */
        double u = C[0] + C[3], v = C[2] - C[1], du = D[0] + D[3], dv = D[2] - D[1], eu = E[0] + E[3],
               ev = E[2] - E[1];
        *val = -(u * u + v * v) * Si[0];
        *d1 = -2.0 * (u * du + v * dv) * Si[0];
        *d2 = -2.0 * (du * du + u * eu + dv * dv + v * ev) * Si[0];
        return;
    }
    /* crit = -tr(C Si C^T); crit' = -2 tr(D Si C^T); crit'' = -2 [tr(E Si C^T) + tr(D Si D^T)] */
    double t1 = 0, t2 = 0, t3 = 0;
    for (int i = 0; i < 2; i++) {
        double cx = C[2 * i], cy = C[2 * i + 1], dx = D[2 * i], dy = D[2 * i + 1], ex = E[2 * i], ey = E[2 * i + 1];
        double scx = Si[0] * cx + Si[1] * cy, scy = Si[1] * cx + Si[2] * cy;
        t1 += dx * scx + dy * scy;
        t2 += ex * scx + ey * scy;
        t3 += dx * (Si[0] * dx + Si[1] * dy) + dy * (Si[1] * dx + Si[2] * dy);
    }
    *val = crit_value(C, Si);
    *d1 = -2.0 * t1;
    *d2 = -2.0 * (t2 + t3);
}

/* Refinement of an integer shift s (a local minimum of the criterion) to a continuous one
 * by Newton's method with exact derivatives (at most two passes, steps within ±0.5; the last
 * step is taken with its quadratic prediction of the criterion, which only ranks candidates —
 * the distance is computed exactly afterwards). */
static double refine_shift(const amscr_descriptor *f, int use_finest, const double Si[4], amscr_workspace *ws,
                           size_t s, double *out_crit)
{
    size_t n = f->n;
    double x = (double)s, best_x = x, best_v = ws->crit[s];
    /* start: the vertex of the parabola through the integer neighbours (free: from the FFT) */
    double cm = ws->crit[(s + n - 1) % n], cp = ws->crit[(s + 1) % n], curv = cp - 2.0 * best_v + cm;
    if (curv > 0.0) {
        double step = -0.5 * (cp - cm) / curv;
        x += step > 0.5 ? 0.5 : (step < -0.5 ? -0.5 : step);
    }
    for (int it = 0; it < 2; it++) {
        double v, d1, d2;
        crit_newton(f, use_finest, Si, ws, x, &v, &d1, &d2);
        if (v <= best_v) {
            best_v = v;
            best_x = x;
        } else if (it > 0) {
            break; /* the last step went uphill: keep the best point */
        } else {
            x = best_x; /* the parabola overshot: restart Newton from the integer shift */
            crit_newton(f, use_finest, Si, ws, x, &v, &d1, &d2);
        }
        if (!(d2 > 0.0))
            break;
        double step = -d1 / d2;
        if (step > 0.5)
            step = 0.5;
        if (step < -0.5)
            step = -0.5;
        x += step;
        if (fabs(step) < 1e-3) { /* converged to well below a sample: take the step as is */
            best_v = v + 0.5 * d1 * step;
            best_x = x;
            break;
        }
        if (it == 1) { /* no pass left: accept the Newton prediction only if it is lower */
            double pred = v + d1 * step + 0.5 * d2 * step * step;
            if (pred < best_v) {
                best_v = pred;
                best_x = x;
            }
        }
    }
    *out_crit = best_v;
    return best_x;
}

/* The whole method at one (shift, orientation): fills m (normalized-frame solution by the
 * closed form). Closed curves: continuous shift s through the spectra in ws->P (prepared
 * for orientation o). Open curves: s is ignored (orientation only). */
static void run_method(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h, double s,
                       int o, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n, p = f->p;
    int closed = f->params.closed;
    double R[AMSCR__MAX_SCALES + 1][6];
    STAGE_T0;
    if (closed) {
        double dc[2] = {h->spec[0], h->spec[2 * n]};
        spectral_q(ws, n, s);
        spectral_level(ws, n, NULL, dc, R[0]);
        for (size_t k = 0; k < p; k++)
            spectral_level(ws, n, f->gain + k * n, dc, R[k + 1]);
        double r = fmod(s, (double)n);
        if (r < 0)
            r += (double)n;
        m->fshift = r;
        size_t si = (size_t)floor(r + 0.5);
        m->shift = si >= n ? si - n : si;
    } else {
        cross_sums(f->base, h->base, n, 0, o, 0, R[0]);
        for (size_t k = 0; k < p; k++)
            cross_sums(f->scaled + 2 * n * k, h->scaled + 2 * n * k, n, 0, o, 0, R[k + 1]);
        m->fshift = 0.0;
        m->shift = 0;
    }
    /* energy of the target as shifted: the band-limited interpolation keeps every frequency's
     * energy except the Nyquist term's (even N), which is scaled by cos^2(pi s) */
    double hn2 = h->norm2;
    if (closed && h->nyq2 > 0.0) {
        double sn = sin(3.14159265358979323846 * s);
        hn2 -= h->nyq2 * sn * sn;
    }
    m->p = p;
    m->reflected = o;
    m->refined = 0;
    m->rcut = 0.0;
    for (size_t k = 0; k < p; k++) {
        double X[6];
        if (!fit_x(prm, f->mom + 6 * (k + 1), f->minv + 9 * (k + 1), R[k + 1], X))
            memset(X, 0, sizeof X);
        m->resid[k] = resid_sum(X, f->mom, R[0], hn2) / (double)n;
    }
    STAGE_MARK(ws, 1);
    select_scales(prm, prm->method, f->finest, m, ws->scratch);
    STAGE_MARK(ws, 2);
    double Ms[6] = {0, 0, 0, 0, 0, 0}, Rs[6] = {0, 0, 0, 0, 0, 0}, Minv[9];
    for (size_t k = 0; k < p; k++) {
        if (!m->kept[k])
            continue;
        for (int j = 0; j < 6; j++) {
            Ms[j] += f->mom[6 * (k + 1) + j];
            Rs[j] += R[k + 1][j];
        }
    }
    (void)Minv;
    if (!fit_x(prm, Ms, NULL, Rs, m->X)) {
        /* cannot happen for validated descriptors (each level is invertible); be safe */
        if (!fit_x(prm, f->mom + 6 * (f->finest + 1), f->minv + 9 * (f->finest + 1), R[f->finest + 1], m->X))
            memset(m->X, 0, sizeof m->X);
    }
    m->dist = (resid_sum(m->X, f->mom, R[0], hn2) + penalty_of(prm, m->X, (double)n)) / (double)n;
    STAGE_MARK(ws, 3);
}

/* Criterion of every integer cyclic shift for one orientation (closed curves): one FFT
 * product and two complex inverse FFTs (x and y rows packed as real + imaginary parts); also
 * leaves the spectral products of this orientation in ws->P. */
static void shift_criterion(const amscr_descriptor *f, const amscr_descriptor *h, int o, int use_finest,
                            const double Si[4], amscr_workspace *ws)
{
    size_t n = f->n;
    spectral_prepare(f, h, o, ws);
    const double *gain = use_finest ? f->gain + f->finest * n : f->gain + f->p * n;
    double *z1 = ws->z, *z2 = ws->z + 2 * n;
    for (size_t w = 0; w < n; w++) {
        size_t wf = w <= n / 2 ? w : n - w;
        double cj = w <= n / 2 ? 1.0 : -1.0; /* Hermitian completion */
        const double *P = ws->P + 8 * wf;
        double g = gain[w];
        /* z = (P_ix + i P_iy) g */
        z1[2 * w] = g * (P[0] - cj * P[3]);
        z1[2 * w + 1] = g * (cj * P[1] + P[2]);
        z2[2 * w] = g * (P[4] - cj * P[7]);
        z2[2 * w + 1] = g * (cj * P[5] + P[6]);
    }
    amscr__fft(&ws->plan, z1, 1);
    amscr__fft(&ws->plan, z2, 1);
    double inv_n = 1.0 / (double)n;
    for (size_t s = 0; s < n; s++) {
        double C[4] = {z1[2 * s] * inv_n, z1[2 * s + 1] * inv_n, z2[2 * s] * inv_n, z2[2 * s + 1] * inv_n};
        ws->crit[s] = crit_value(C, Si);
    }
}

static int better(const match_t *a, const match_t *b)
{
    if (a->dist != b->dist)
        return a->dist < b->dist;
    if (a->reflected != b->reflected)
        return a->reflected < b->reflected;
    return a->shift < b->shift;
}

/* One direction f -> h: the best match over orientations and candidate shifts. */
/* The lowest (at most AMSCR__CANDIDATES) circular local minima of ws->crit, ascending. */
static size_t integer_candidates(const amscr_workspace *ws, size_t n, size_t *cand)
{
    size_t nc = 0;
    for (size_t s = 0; s < n; s++) {
        double v = ws->crit[s];
        double l = ws->crit[(s + n - 1) % n], r = ws->crit[(s + 1) % n];
        if (!(v <= l && v <= r))
            continue;
        size_t pos = nc;
        while (pos > 0 && ws->crit[cand[pos - 1]] > v)
            pos--;
        if (pos >= AMSCR__CANDIDATES)
            continue;
        size_t last = nc < AMSCR__CANDIDATES ? nc : AMSCR__CANDIDATES - 1;
        for (size_t j = last; j > pos; j--)
            cand[j] = cand[j - 1];
        cand[pos] = s;
        if (nc < AMSCR__CANDIDATES)
            nc++;
    }
    if (nc == 0) { /* flat criterion: take shift 0 */
        cand[0] = 0;
        nc = 1;
    }
    return nc;
}

static amscr_status match_one(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, match_t *best)
{
    size_t n = f->n;
    amscr_status st = ws_reserve(ws, n, f->p);
    if (st != AMSCR_OK)
        return st;
    int norient = prm->reflections ? 2 : 1;
    int use_finest = prm->method == AMSCR_METHOD_ACMA;
    if (!f->params.closed) {
        int have = 0;
        match_t cur;
        for (int o = 0; o < norient; o++) {
            run_method(prm, f, h, 0.0, o, ws, &cur);
            if (!have || better(&cur, best)) {
                *best = cur;
                have = 1;
            }
        }
        if (!isfinite(best->dist))
            return amscr__fail(AMSCR_E_NUMERIC, "registration: non-finite distance");
        return AMSCR_OK;
    }
    /* closed: for each orientation, the criterion of every integer shift by FFT; its lowest
     * local minima are refined to a continuous shift; the best (orientation, shift) by the
     * refined criterion gets the whole method. */
    double best_s = 0.0, best_c = INFINITY, Si[4];
    int best_o = 0;
    STAGE_T0;
    crit_matrix(f, use_finest, prm->invariance != AMSCR_INVARIANCE_AFFINE, Si);
    for (int o = 0; o < norient; o++) {
        shift_criterion(f, h, o, use_finest, Si, ws);
        size_t cand[AMSCR__CANDIDATES];
        size_t nc = integer_candidates(ws, n, cand);
        /* a candidate is worth refining only when its residual is close to the best one's:
         * refinement moves the residual by far less than a factor 1.25. The residual is
         * Σ_k |h_k|^2 + criterion; Σ_k |h_k|^2 is bounded by p |h|^2. */
        double hk2 = (use_finest ? 1.0 : (double)f->p) * h->norm2;
        double r0 = ws->crit[cand[0]] + hk2;
        for (size_t c = 0; c < nc; c++) {
            if (c > 0 && ws->crit[cand[c]] + hk2 > 1.25 * r0 + 1e-12 * hk2)
                break;
            double cv;
            double sc = refine_shift(f, use_finest, Si, ws, cand[c], &cv);
            if (cv < best_c) {
                best_c = cv;
                best_s = sc;
                best_o = o;
            }
        }
    }
    if (best_o != norient - 1)
        spectral_prepare(f, h, best_o, ws); /* ws->P holds the last orientation's products */
    STAGE_MARK(ws, 0);
    run_method(prm, f, h, best_s, best_o, ws, best);
    if (!isfinite(best->dist))
        return amscr__fail(AMSCR_E_NUMERIC, "registration: non-finite distance");
    return AMSCR_OK;
}

/* ------------------------------------------------- refinement (DESIGN.md §3.8)
 * Once (A, B) is known, A f + B and h nearly coincide in the target's frame, so a correspondence
 * that is not affine-invariant becomes usable: every source sample is paired with the closest
 * point of the target polygon (searched in a window around its current partner), the worst 10 %
 * of the pairs are trimmed (missing or extra parts of a contour), and the least squares is
 * re-solved — a trimmed ICP started from AMSCR's global, closed-form estimate, so it does not
 * fall into the local minima that sink ICP from arbitrary starts. Repeated while the trimmed
 * cost drops, at most `refine` times. The distance is then the mean squared closest-point
 * residual of all samples. */

#define AMSCR__TRIM 0.9
/* Costs are mean squared distances in the target's normalized frame (RMS radius sqrt 2): a
 * match whose trimmed cost is below this floor (an RMS misfit of 0.01 % of the size) is
 * already exact, and closest-point steps smaller than half of it are noise: both would only
 * let the map slide along the curve, which closest-point costs do not see. */
#define AMSCR__REFINE_FLOOR 1e-8
/* The target polygon the closest points are taken on: the N samples densified 4x by
 * Catmull-Rom interpolation (through the samples, following the curvature), so that chords of a
 * coarse polygon do not bias the fit. */
#define AMSCR__DENSE 4

static amscr_status ws_reserve_refine(amscr_workspace *ws, size_t n)
{
    if (ws->rcap >= n && ws->rbuf)
        return AMSCR_OK;
    free(ws->rbuf);
    /* q 2n, r2 n, sorted n, tmp 2n, hints 2n, dense target 2 * AMSCR__DENSE n */
    ws->rbuf = amscr__malloc_array((8 + 2 * AMSCR__DENSE) * n + 8, sizeof(double));
    if (!ws->rbuf) {
        ws->rcap = 0;
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->rcap = n;
    return AMSCR_OK;
}

/* Closest point to (px, py) on the polygon H (n vertices; closed: with the closing edge),
 * edges b0-w .. b0+w; *seg receives the edge index. */
static double closest_on_polygon(const double *H, size_t n, int closed, size_t b0, size_t w, double px, double py,
                                 double *qx, double *qy, size_t *seg)
{
    double best = INFINITY;
    size_t nedges = closed ? n : n - 1;
    size_t cnt = 2 * w + 1 < nedges ? 2 * w + 1 : nedges;
    size_t b;
    if (closed)
        b = (b0 + n - (cnt == nedges ? 0 : w % n)) % n;
    else
        b = b0 > w ? (b0 - w + cnt <= nedges ? b0 - w : nedges - cnt) : 0;
    for (size_t i = 0; i < cnt; i++) {
        size_t c = b + 1 == n ? 0 : b + 1;
        double ax = H[2 * b], ay = H[2 * b + 1], ex = H[2 * c] - ax, ey = H[2 * c + 1] - ay;
        double l2 = ex * ex + ey * ey, t = l2 > 0.0 ? ((px - ax) * ex + (py - ay) * ey) / l2 : 0.0;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        double cx = ax + t * ex, cy = ay + t * ey, d2 = (px - cx) * (px - cx) + (py - cy) * (py - cy);
        if (d2 < best) {
            best = d2;
            *qx = cx;
            *qy = cy;
            *seg = b;
        }
        b = c;
    }
    return best;
}

/* Partially orders v so that v[k] is the k-th smallest and v[0..k) are the smaller ones
 * (quickselect, median-of-three pivots): O(n), no allocation. */
static void select_kth(double *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (hi > lo) {
        size_t mid = lo + (hi - lo) / 2;
        double a = v[lo], b = v[mid], c = v[hi];
        double pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                double t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

/* Trimmed least squares X from pairs (f_a -> q_a) with r2_a <= cut. Returns 0 if singular. */
static int trimmed_solve(const amscr_params *prm, const double *f, const double *q, const double *r2, size_t n,
                         double cut, double X[6])
{
    double m[6] = {0, 0, 0, 0, 0, 0}, R[6] = {0, 0, 0, 0, 0, 0}, Minv[9];
    for (size_t a = 0; a < n; a++) {
        if (r2[a] > cut)
            continue;
        double x = f[2 * a], y = f[2 * a + 1], u = q[2 * a], v = q[2 * a + 1];
        m[0] += x * x;
        m[1] += x * y;
        m[2] += y * y;
        m[3] += x;
        m[4] += y;
        m[5] += 1.0;
        R[0] += u * x;
        R[1] += u * y;
        R[2] += u;
        R[3] += v * x;
        R[4] += v * y;
        R[5] += v;
    }
    (void)Minv;
    return fit_x(prm, m, NULL, R, X);
}

/* Catmull-Rom densification of the N target samples by AMSCR__DENSE (closed: periodic; open:
 * end points repeated). out: 2 * AMSCR__DENSE * n (closed) or AMSCR__DENSE * (n - 1) + 1 points. */
static size_t densify(const double *H, size_t n, int closed, double *out)
{
    size_t m = 0, nseg = closed ? n : n - 1;
    for (size_t i = 0; i < nseg; i++) {
        size_t i0 = closed ? (i + n - 1) % n : (i == 0 ? 0 : i - 1), i1 = i, i2 = closed ? (i + 1) % n : i + 1;
        size_t i3 = closed ? (i + 2) % n : (i + 2 < n ? i + 2 : n - 1);
        for (int k = 0; k < AMSCR__DENSE; k++) {
            double t = (double)k / AMSCR__DENSE, t2 = t * t, t3 = t2 * t;
            double c0 = -0.5 * t3 + t2 - 0.5 * t, c1 = 1.5 * t3 - 2.5 * t2 + 1.0, c2 = -1.5 * t3 + 2.0 * t2 + 0.5 * t,
                   c3 = 0.5 * t3 - 0.5 * t2;
            for (int d = 0; d < 2; d++)
                out[2 * m + d] = c0 * H[2 * i0 + d] + c1 * H[2 * i1 + d] + c2 * H[2 * i2 + d] + c3 * H[2 * i3 + d];
            m++;
        }
    }
    if (!closed) {
        out[2 * m] = H[2 * (n - 1)];
        out[2 * m + 1] = H[2 * (n - 1) + 1];
        m++;
    }
    return m;
}

/* One correspondence step: q_a = closest target point to X f_a; r2_a its squared distance;
 * returns the trimmed cost and the cut-off. hints (n values): the edge found last time per
 * sample, searched within ±8 edges; otherwise a window of N/8 around the method's partner. */
static double icp_pairs(const amscr_descriptor *f, const double *Hd, size_t nd, const match_t *m, const double X[6],
                        double *q, double *r2, double *sorted, double *hints, int use_hints, double *out_cut)
{
    size_t n = f->n, wide = AMSCR__DENSE * (n / 8 > 2 ? n / 8 : 2);
    int closed = f->params.closed;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double px = X[0] * fx + X[1] * fy + X[2], py = X[3] * fx + X[4] * fy + X[5];
        size_t b0, w, seg = 0;
        if (use_hints) {
            b0 = (size_t)hints[a];
            w = 3 * AMSCR__DENSE;
        } else {
            b0 = AMSCR__DENSE *
                 (closed ? tgt_index(a, m->shift, m->reflected, 1, n) : tgt_index(a, 0, m->reflected, 0, n));
            w = wide;
        }
        if (b0 >= nd)
            b0 = nd - 1;
        r2[a] = closest_on_polygon(Hd, nd, closed, b0, w, px, py, &q[2 * a], &q[2 * a + 1], &seg);
        hints[a] = (double)seg;
        sorted[a] = r2[a];
    }
    size_t keep = (size_t)(AMSCR__TRIM * (double)n);
    if (keep < 8)
        keep = n < 8 ? n : 8;
    select_kth(sorted, n, keep - 1);
    double cost = 0.0;
    for (size_t a = 0; a < keep; a++)
        cost += sorted[a];
    *out_cut = sorted[keep - 1];
    return cost / (double)keep;
}

/* Refines m in place (closed and open curves) with at most `iters` iterations. */
static amscr_status refine_match(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                 amscr_workspace *ws, match_t *m, unsigned iters, int *out_refined)
{
    *out_refined = 0;
    if (iters == 0)
        return AMSCR_OK;
    size_t n = f->n;
    amscr_status st = ws_reserve_refine(ws, n);
    if (st != AMSCR_OK)
        return st;
    double *q = ws->rbuf, *r2 = q + 2 * n, *sorted = r2 + n, *q2 = sorted + n, *hints = q2 + 2 * n;
    double *hints2 = hints + n, *Hd = hints2 + n;
    size_t nd = densify(h->base, n, f->params.closed, Hd);
    double X[6], cut;
    memcpy(X, m->X, sizeof X);
    double cost = icp_pairs(f, Hd, nd, m, X, q, r2, sorted, hints, 0, &cut);
    if (cost < AMSCR__REFINE_FLOOR)
        iters = 0;
    for (unsigned it = 0; it < iters; it++) {
        double Xn[6], cutn;
        if (!trimmed_solve(prm, f->base, q, r2, n, cut, Xn))
            break;
        memcpy(hints2, hints, n * sizeof *hints);
        double costn = icp_pairs(f, Hd, nd, m, Xn, q2, r2, sorted, hints2, 1, &cutn);
        if (!(costn < cost - 0.5 * AMSCR__REFINE_FLOOR)) {
            /* r2 now holds the rejected trial: restore the accepted pairs' residuals */
            cost = icp_pairs(f, Hd, nd, m, X, q, r2, sorted, hints, 1, &cut);
            break;
        }
        int converged = costn > cost * (1.0 - 1e-6);
        memcpy(X, Xn, sizeof X);
        memcpy(q, q2, 2 * n * sizeof *q);
        memcpy(hints, hints2, n * sizeof *hints);
        cost = costn;
        cut = cutn;
        *out_refined = 1;
        if (converged)
            break;
    }
    m->rcost = cost;
    if (*out_refined) {
        double all = 0.0;
        for (size_t a = 0; a < n; a++)
            all += r2[a];
        memcpy(m->X, X, sizeof X);
        m->dist = (all + penalty_of(prm, X, (double)n)) / (double)n;
        m->refined = 1;
        m->rcut = cut;
    }
    return AMSCR_OK;
}

/* With refinement on (registration of single pairs, where time matters less than
 * robustness): every candidate (orientation, continuous shift) — the lowest local minima of
 * the criterion for each orientation — gets the method and the refinement, and the one with
 * the lowest trimmed closest-point cost wins. A wrong start point caused by a missing part of
 * a contour is then caught by the geometry rather than by the criterion alone. */
static amscr_status match_explore(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                  amscr_workspace *ws, match_t *best)
{
    size_t n = f->n;
    amscr_status st = ws_reserve(ws, n, f->p);
    if (st != AMSCR_OK)
        return st;
    int norient = prm->reflections ? 2 : 1, use_finest = prm->method == AMSCR_METHOD_ACMA, have = 0;
    int best_o = 0;
    double Si[4], best_s = 0.0;
    crit_matrix(f, use_finest, prm->invariance != AMSCR_INVARIANCE_AFFINE, Si);
    for (int o = 0; o < norient; o++) {
        size_t cand[AMSCR__CANDIDATES];
        double shifts[AMSCR__CANDIDATES];
        shift_criterion(f, h, o, use_finest, Si, ws);
        size_t nc = integer_candidates(ws, n, cand);
        for (size_t c = 0; c < nc; c++) {
            double cv;
            shifts[c] = refine_shift(f, use_finest, Si, ws, cand[c], &cv);
        }
        for (size_t c = 0; c < nc; c++) {
            match_t cur;
            int refined;
            spectral_prepare(f, h, o, ws);
            run_method(prm, f, h, shifts[c], o, ws, &cur);
            st = refine_match(prm, f, h, ws, &cur, prm->refine < 2 ? prm->refine : 2, &refined);
            if (st != AMSCR_OK)
                return st;
            if (!have || cur.rcost < best->rcost || (cur.rcost == best->rcost && better(&cur, best))) {
                *best = cur;
                best_o = o;
                best_s = shifts[c];
                have = 1;
            }
        }
    }
    /* the winner gets the whole refinement (and leaves its pairs in the workspace for the
     * reported solve) */
    int refined;
    spectral_prepare(f, h, best_o, ws);
    run_method(prm, f, h, best_s, best_o, ws, best);
    st = refine_match(prm, f, h, ws, best, prm->refine, &refined);
    if (st != AMSCR_OK)
        return st;
    if (!isfinite(best->dist))
        return amscr__fail(AMSCR_E_NUMERIC, "registration: non-finite distance");
    return AMSCR_OK;
}

static amscr_status check_pair(const amscr_params **prm, const amscr_descriptor *src, const amscr_descriptor *tgt)
{
    if (!*prm)
        *prm = &src->params;
    if (!amscr__params_compatible(&src->params, &tgt->params, "registration (source vs target)"))
        return AMSCR_E_INVALID_ARG;
    if (!amscr__params_compatible(*prm, &src->params, "registration (params vs descriptors)"))
        return AMSCR_E_INVALID_ARG;
    return AMSCR_OK;
}

/* One direction: the method, then the optional refinement. */
static amscr_status match_dir(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, match_t *m)
{
    if (prm->refine > 0 && f->params.closed)
        return match_explore(prm, f, h, ws, m);
    amscr_status st = match_one(prm, f, h, ws, m);
    int refined;
    if (st == AMSCR_OK)
        st = refine_match(prm, f, h, ws, m, prm->refine, &refined);
    return st;
}

/* Distance (and match) honouring `symmetric`. */
static amscr_status match_pair(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                               amscr_workspace *ws, match_t *m)
{
    amscr_status st = match_dir(prm, src, tgt, ws, m);
    if (st == AMSCR_OK && prm->symmetric) {
        match_t back;
        st = match_dir(prm, tgt, src, ws, &back);
        if (st == AMSCR_OK)
            m->dist = 0.5 * (m->dist + back.dist);
    }
    return st;
}

amscr_status amscr__distance_ws(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                amscr_workspace *ws, double *out)
{
    match_t m;
    amscr_status st = match_pair(prm, src, tgt, ws, &m);
    if (st == AMSCR_OK)
        *out = m.dist;
    return st;
}

amscr_status amscr_distance(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                            amscr_workspace *ws, double *out_distance)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_distance);
    amscr_status st = check_pair(&p, src, tgt);
    if (st != AMSCR_OK)
        return st;
    amscr_workspace local = {0};
    amscr_workspace *w = ws ? ws : &local;
    st = amscr__distance_ws(p, src, tgt, w, out_distance);
    if (!ws)
        ws_release(&local);
    return st;
}

/* Target curve of one level shifted by a continuous s (closed curves): the band-limited
 * interpolation y(a) = h_o(a + s), smoothed by G_k when gain is given. out: 2N. */
static void shifted_target(const amscr_descriptor *h, int o, double s, const double *gain, amscr_workspace *ws,
                           double *out)
{
    size_t n = h->n;
    const double *Hx = h->spec, *Hy = h->spec + 2 * n;
    double *z = ws->z;
    double sg = o ? -1.0 : 1.0;
    for (size_t w = 0; w < n; w++) {
        size_t wf = w <= n / 2 ? w : n - w;
        double cj = w <= n / 2 ? 1.0 : -1.0;
        double g = gain ? sqrt(gain[wf]) : 1.0;
        double xr = Hx[2 * wf], xi = cj * sg * Hx[2 * wf + 1], yr = Hy[2 * wf], yi = cj * sg * Hy[2 * wf + 1];
        double er, ei;
        if (2 * w == n) {
            er = cos(3.14159265358979323846 * s);
            ei = 0.0;
            xi = yi = 0.0;
        } else {
            double wsym = w <= n / 2 ? (double)w : (double)w - (double)n;
            double th = 2.0 * 3.14159265358979323846 * wsym * s / (double)n;
            er = cos(th);
            ei = sin(th);
        }
        double axr = g * (xr * er - xi * ei), axi = g * (xr * ei + xi * er);
        double ayr = g * (yr * er - yi * ei), ayi = g * (yr * ei + yi * er);
        /* pack x + i y */
        z[2 * w] = axr - ayi;
        z[2 * w + 1] = axi + ayr;
    }
    amscr__fft(&ws->plan, z, 1);
    double inv_n = 1.0 / (double)n;
    for (size_t a = 0; a < n; a++) {
        out[2 * a] = z[2 * a] * inv_n;
        out[2 * a + 1] = z[2 * a + 1] * inv_n;
    }
}

/* The reported solve: the stacked system of the kept scales by LAPACKE QR, and the distance
 * summed directly on the unsmoothed curves (closed curves: at the continuous shift). */
static amscr_status final_qr(const amscr_descriptor *f, const amscr_descriptor *h, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n, rows = n * m->nkept;
    int closed = f->params.closed;
    amscr_status st = ws_reserve_qr(ws, rows);
    if (st != AMSCR_OK)
        return st;
    double *A = ws->qa, *B = ws->qb, *tc = ws->curve;
    size_t r = 0;
    for (size_t k = 0; k < f->p; k++) {
        if (!m->kept[k])
            continue;
        const double *fk = f->scaled + 2 * n * k, *hk = h->scaled + 2 * n * k;
        if (closed) {
            shifted_target(h, m->reflected, m->fshift, f->gain + k * n, ws, tc);
            hk = tc;
        }
        for (size_t a = 0; a < n; a++, r++) {
            size_t b = closed ? a : tgt_index(a, 0, m->reflected, 0, n);
            A[r] = fk[2 * a];
            A[rows + r] = fk[2 * a + 1];
            A[2 * rows + r] = 1.0;
            B[r] = hk[2 * b];
            B[rows + r] = hk[2 * b + 1];
        }
    }
    double x[6];
    st = amscr__lstsq_colmajor(A, rows, 3, B, 2, ws->qw, ws->qi, x, NULL);
    if (st != AMSCR_OK)
        return st;
    /* x column-major 3 x 2: column 0 -> x' coefficients (a11, a12, b1) */
    memcpy(m->X, x, sizeof m->X);
    const double *hb = h->base;
    if (closed) {
        shifted_target(h, m->reflected, m->fshift, NULL, ws, tc);
        hb = tc;
    }
    double sum = 0.0;
    for (size_t a = 0; a < n; a++) {
        size_t b = closed ? a : tgt_index(a, 0, m->reflected, 0, n);
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double dx = m->X[0] * fx + m->X[1] * fy + m->X[2] - hb[2 * b];
        double dy = m->X[3] * fx + m->X[4] * fy + m->X[5] - hb[2 * b + 1];
        sum += dx * dx + dy * dy;
    }
    m->dist = sum / (double)n;
    return AMSCR_OK;
}

/* The reported solve after refinement: QR on the kept closest-point pairs. */
static amscr_status final_qr_refined(const amscr_descriptor *f, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n;
    amscr_status st = ws_reserve_qr(ws, n);
    if (st != AMSCR_OK)
        return st;
    const double *q = ws->rbuf, *r2 = q + 2 * n;
    double *A = ws->qa, *B = ws->qb;
    size_t rows = 0;
    for (size_t a = 0; a < n; a++)
        if (r2[a] <= m->rcut)
            rows++;
    size_t r = 0;
    for (size_t a = 0; a < n; a++) {
        if (r2[a] > m->rcut)
            continue;
        A[r] = f->base[2 * a];
        A[rows + r] = f->base[2 * a + 1];
        A[2 * rows + r] = 1.0;
        B[r] = q[2 * a];
        B[rows + r] = q[2 * a + 1];
        r++;
    }
    double x[6];
    st = amscr__lstsq_colmajor(A, rows, 3, B, 2, ws->qw, ws->qi, x, NULL);
    if (st == AMSCR_OK)
        memcpy(m->X, x, sizeof m->X); /* equals the closed-form trimmed solve up to rounding */
    return st;
}

amscr_status amscr_register(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                            amscr_workspace *ws, amscr_result **out_result)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_result);
    amscr_status st = check_pair(&p, src, tgt);
    if (st != AMSCR_OK)
        return st;
    amscr_workspace local = {0};
    amscr_workspace *w = ws ? ws : &local;
    amscr_result *r = calloc(1, sizeof *r);
    if (!r)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_register: out of memory");
    if (st == AMSCR_OK)
        st = match_dir(p, src, tgt, w, &r->m);
    /* the reported solve by LAPACKE QR (affine); the constrained groups keep their closed form */
    if (st == AMSCR_OK && p->invariance == AMSCR_INVARIANCE_AFFINE)
        st = r->m.refined ? final_qr_refined(src, w, &r->m) : final_qr(src, tgt, w, &r->m);
    if (st == AMSCR_OK && p->symmetric) {
        match_t back;
        st = match_dir(p, tgt, src, w, &back);
        if (st == AMSCR_OK)
            r->m.dist = 0.5 * (r->m.dist + back.dist);
    }
    if (!ws)
        ws_release(&local);
    if (st != AMSCR_OK) {
        free(r);
        return st;
    }
    r->method = p->method;
    memcpy(r->affine_norm, r->m.X, sizeof r->affine_norm);
    /* input coordinates: inv_h ∘ X ∘ fwd_f */
    double t[6];
    amscr__affine_compose(r->m.X, src->fwd, t);
    amscr__affine_compose(tgt->inv, t, r->affine_in);
    *out_result = r;
    return AMSCR_OK;
}

amscr_status amscr_register_contours(const amscr_params *p, const amscr_contour *src, const amscr_contour *tgt,
                                     amscr_result **out_result)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(src);
    AMSCR_CHECK_NULL(tgt);
    AMSCR_CHECK_NULL(out_result);
    amscr_descriptor *a = NULL, *b = NULL;
    char detail[400];
    amscr_params preset;
    if (!p) {
        amscr__params_registration(&preset);
        p = &preset;
    }
    amscr_status st = amscr_descriptor_new(p, src, &a);
    if (st == AMSCR_OK) {
        st = amscr_descriptor_new(p, tgt, &b);
        if (st != AMSCR_OK) {
            snprintf(detail, sizeof detail, "%s", amscr_last_error_detail());
            amscr__fail(st, "target: %s", detail);
        }
    } else {
        snprintf(detail, sizeof detail, "%s", amscr_last_error_detail());
        amscr__fail(st, "source: %s", detail);
    }
    if (st == AMSCR_OK)
        st = amscr_register(p, a, b, NULL, out_result);
    amscr_descriptor_free(a);
    amscr_descriptor_free(b);
    return st;
}

/* ------------------------------------------------------------------ result */

void amscr_result_free(amscr_result *r) { free(r); }

double amscr_result_distance(const amscr_result *r) { return r ? r->m.dist : NAN; }

amscr_status amscr_result_affine(const amscr_result *r, double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(out_m6);
    memcpy(out_m6, r->affine_in, 6 * sizeof(double));
    return AMSCR_OK;
}

amscr_status amscr_result_affine_normalized(const amscr_result *r, double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(out_m6);
    memcpy(out_m6, r->affine_norm, 6 * sizeof(double));
    return AMSCR_OK;
}

size_t amscr_result_shift(const amscr_result *r) { return r ? r->m.shift : 0; }
int amscr_result_reflected(const amscr_result *r) { return r ? r->m.reflected : 0; }
amscr_method amscr_result_method(const amscr_result *r) { return r ? r->method : AMSCR_METHOD_MULTICLASS_EM; }
size_t amscr_result_num_scales(const amscr_result *r) { return r ? r->m.p : 0; }
size_t amscr_result_num_kept(const amscr_result *r) { return r ? r->m.nkept : 0; }
size_t amscr_result_k(const amscr_result *r) { return r ? r->m.k : 0; }
double amscr_result_threshold(const amscr_result *r) { return r ? r->m.threshold : NAN; }

static amscr_status copy_out(const double *src, size_t count, double *out, size_t *inout_n, const char *what)
{
    if (out) {
        if (*inout_n < count)
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: room for %zu values, %zu needed", what, *inout_n, count);
        if (src)
            memcpy(out, src, count * sizeof *out);
    }
    *inout_n = count;
    return AMSCR_OK;
}

amscr_status amscr_result_residuals(const amscr_result *r, double *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    return copy_out(r->m.resid, r->m.p, out, inout_n, "amscr_result_residuals");
}

amscr_status amscr_result_sse(const amscr_result *r, double *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    return copy_out(r->m.sse, r->m.nsse, out, inout_n, "amscr_result_sse");
}

amscr_status amscr_result_kept(const amscr_result *r, int *out, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    if (out) {
        if (*inout_n < r->m.p)
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_kept: room for %zu values, %zu needed", *inout_n,
                               r->m.p);
        memcpy(out, r->m.kept, r->m.p * sizeof *out);
    }
    *inout_n = r->m.p;
    return AMSCR_OK;
}

amscr_status amscr_result_mixture(const amscr_result *r, double *out_weights, double *out_means,
                                  double *out_variances, size_t *inout_n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(r);
    AMSCR_CHECK_NULL(inout_n);
    size_t k = r->m.ncomp;
    if ((out_weights || out_means || out_variances) && *inout_n < k)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_result_mixture: room for %zu, %zu needed", *inout_n, k);
    if (out_weights)
        memcpy(out_weights, r->m.w, k * sizeof(double));
    if (out_means)
        memcpy(out_means, r->m.mu, k * sizeof(double));
    if (out_variances)
        memcpy(out_variances, r->m.var, k * sizeof(double));
    *inout_n = k;
    return AMSCR_OK;
}
