/* final_solve.c — the reported solve of amscr_register (affine invariance): the stacked
 * system of the kept scales by LAPACKE QR with the distance summed directly on the unsmoothed
 * curves, or after refinement the QR of the kept closest-point pairs. amscr_distance (the
 * batch path) keeps the closed form of method.c; the tests check that both agree. */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <string.h>

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
            er = cos(AMSCR__PI * s);
            ei = 0.0;
            xi = yi = 0.0;
        } else {
            double wsym = w <= n / 2 ? (double)w : (double)w - (double)n;
            double th = 2.0 * AMSCR__PI * wsym * s / (double)n;
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
static amscr_status final_qr(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n, rows = n * m->nkept;
    int closed = f->params.closed;
    amscr_status st = amscr__ws_reserve_qr(ws, rows);
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
            size_t b = closed ? a : amscr__tgt_index(a, 0, m->reflected, 0, n);
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
        size_t b = closed ? a : amscr__tgt_index(a, 0, m->reflected, 0, n);
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double dx = m->X[0] * fx + m->X[1] * fy + m->X[2] - hb[2 * b];
        double dy = m->X[3] * fx + m->X[4] * fy + m->X[5] - hb[2 * b + 1];
        sum += dx * dx + dy * dy;
    }
    m->dist = amscr__distance_of(prm, m->X, sum, n);
    return AMSCR_OK;
}

/* The reported solve after refinement: QR on the kept closest-point pairs. */
static amscr_status final_qr_refined(const amscr_descriptor *f, amscr_workspace *ws, match_t *m)
{
    size_t n = f->n;
    amscr_status st = amscr__ws_reserve_qr(ws, n);
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


amscr_status amscr__final_solve(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                amscr_workspace *ws, match_t *m)
{
    return m->refined ? final_qr_refined(f, ws, m) : final_qr(prm, f, h, ws, m);
}
