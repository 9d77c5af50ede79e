/* method.c — the method at one start point (docs/method.md §3.3-3.6): per-scale least-squares
 * solves with exact sums (the 3x3 normal matrices of the source are precomputed in the
 * descriptor), residuals on the unsmoothed curves, scale selection, and the stacked solve of
 * the kept scales by its closed form. */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <string.h>

/* Cross sums R_0 (unsmoothed) .. R_p of f -> h at start (s, o); sets m's shift. */
static void cross_sums_at(const amscr_descriptor *f, const amscr_descriptor *h, double s, int o, amscr_workspace *ws,
                          double R[][6], match_t *m)
{
    size_t n = f->n;
    if (f->params.closed) {
        amscr__spectral_cross_sums(f, h, s, ws, R);
        double r = fmod(s, (double)n);
        if (r < 0)
            r += (double)n;
        m->fshift = r;
        size_t si = (size_t)floor(r + 0.5);
        m->shift = si >= n ? si - n : si;
        return;
    }
    amscr__cross_sums(f->base, h->base, n, 0, o, 0, R[0]);
    for (size_t k = 0; k < f->p; k++)
        amscr__cross_sums(f->scaled + 2 * n * k, h->scaled + 2 * n * k, n, 0, o, 0, R[k + 1]);
    m->fshift = 0.0;
    m->shift = 0;
}

void amscr__run_method(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h, double s, int o,
                       amscr_workspace *ws, match_t *m)
{
    size_t n = f->n, p = f->p;
    double R[AMSCR__MAX_SCALES + 1][6];
    STAGE_T0;
    cross_sums_at(f, h, s, o, ws, R, m);
    /* energy of the target as shifted: the band-limited interpolation keeps every frequency's
     * energy except the Nyquist term's (even N), which is scaled by cos^2(pi s) */
    double hn2 = h->norm2;
    if (f->params.closed && h->nyq2 > 0.0) {
        double sn = sin(AMSCR__PI * s);
        hn2 -= h->nyq2 * sn * sn;
    }
    m->p = p;
    m->reflected = o;
    m->refined = 0;
    m->rcut = 0.0;
    for (size_t k = 0; k < p; k++) {
        double X[6];
        if (!amscr__fit_x(prm, f->mom + 6 * (k + 1), f->minv + 9 * (k + 1), R[k + 1], X))
            memset(X, 0, sizeof X);
        m->resid[k] = amscr__resid_sum(X, f->mom, R[0], hn2) / (double)n;
    }
    STAGE_MARK(ws, 1);
    amscr__select_scales(prm, f->finest, m, ws->scratch);
    STAGE_MARK(ws, 2);
    double Ms[6] = {0, 0, 0, 0, 0, 0}, Rs[6] = {0, 0, 0, 0, 0, 0};
    for (size_t k = 0; k < p; k++) {
        if (!m->kept[k])
            continue;
        for (int j = 0; j < 6; j++) {
            Ms[j] += f->mom[6 * (k + 1) + j];
            Rs[j] += R[k + 1][j];
        }
    }
    if (!amscr__fit_x(prm, Ms, NULL, Rs, m->X)) {
        /* cannot happen for validated descriptors (each level is invertible); be safe */
        size_t fk = f->finest + 1;
        if (!amscr__fit_x(prm, f->mom + 6 * fk, f->minv + 9 * fk, R[fk], m->X))
            memset(m->X, 0, sizeof m->X);
    }
    m->dist = amscr__distance_of(prm, m->X, amscr__resid_sum(m->X, f->mom, R[0], hn2), n);
    STAGE_MARK(ws, 3);
}
