/* spectral.c — the cross sums of closed curves as functions of the continuous shift
 * (docs/method.md §3, §9), shared by the start-point search and the method.
 *
 * For closed curves every cross sum R_k(s) = Σ_a h_k(a+s) [f_k(a), 1]^T is a trigonometric
 * polynomial in the shift s: R_k,ij(s) = (1/N) Σ_w |G_k(w)|^2 H_i(w) conj(F_j(w)) e^{2πiws/N}.
 * Evaluated at integer s it equals the direct sum; between samples it is the band-limited
 * interpolation, which makes the start point continuous instead of quantized to 1/N. */
#include "dense.h"
#include "match.h"

#include <math.h>

/* P_ij(w) = H_i(w) conj(F_j(w)) for w = 0..N/2 (reversed target: conj(H)). */
void amscr__spectral_prepare(const amscr_descriptor *f, const amscr_descriptor *h, int o, amscr_workspace *ws)
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
    double th = 2.0 * AMSCR__PI * s / (double)n;
    double cs = cos(th), sn = sin(th), er = 1.0, ei = 0.0, inv_n = 1.0 / (double)n;
    for (size_t w = 0; w < half; w++) {
        if ((w & AMSCR__REANCHOR) == 0 && w > 0) { /* re-anchor the rotation recurrence (large N only) */
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

void amscr__spectral_cross_sums(const amscr_descriptor *f, const amscr_descriptor *h, double s, amscr_workspace *ws,
                                double R[][6])
{
    size_t n = f->n;
    double dc[2] = {h->spec[0], h->spec[2 * n]};
    spectral_q(ws, n, s);
    spectral_level(ws, n, NULL, dc, R[0]);
    for (size_t k = 0; k < f->p; k++)
        spectral_level(ws, n, f->gain + k * n, dc, R[k + 1]);
}
