/* correspond.c — what a finished registration says beyond the map: for every source
 * sample the closest point of the target's boundary to its image (dense correspondences, for
 * landmark transfer), the share of samples that found the boundary near them (inliers), where
 * the source's first and last samples fall on the target (the part it covers), and, from the
 * inliers' residuals along the boundary's normal, the map's standard error (precision.c). */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A sample is an inlier when its image lies within 5 % of the target's RMS radius (sqrt 2 in
 * the normalized frame) of the target's boundary: 2.5 standard deviations of 2 % noise. */
#define AMSCR__INLIER_DIST (0.05 * 1.4142135623730951)
/* Partners after the first are searched within ±N/32 samples of the previous sample's (the
 * next sample's partner lies a sample or so further; ±N/8 gave the same results, 4x slower);
 * a partner found there beyond the inlier distance is searched again on the whole boundary (a
 * window that followed an extra object's outline would lose the shape's boundary for good). */
#define AMSCR__CORR_WINDOW_DIV 32

/* The pairs whose residual lies beyond AMSCR__TRIM_K times the median squared distance (the n
 * values at nr + 3n, reordered) lose their normal: the jackknife leaves them out, as the
 * polish's fit does. */
static void trim_pairs(double *nr, size_t n)
{
    double *d2 = nr + 3 * n;
    amscr__select_kth(d2, n, n / 2);
    double cut = AMSCR__TRIM_K * d2[n / 2];
    for (size_t a = 0; a < n; a++)
        if (nr[3 * a + 2] * nr[3 * a + 2] > cut)
            nr[3 * a] = nr[3 * a + 1] = 0.0;
}

amscr_status amscr__correspond(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                               amscr_result *r)
{
    size_t n = f->n;
    int closed = h->params.closed;
    double *Hd = amscr__malloc_array(2 * AMSCR__DENSE * h->n, sizeof *Hd);
    double *corr = amscr__malloc_array(5 * n, sizeof *corr);
    double *nr = amscr__malloc_array(4 * n, sizeof *nr); /* a kept pair's normal and residual; d2 */
    if (!Hd || !corr || !nr) {
        free(Hd);
        free(corr);
        free(nr);
        return amscr__fail(AMSCR_E_NOMEM, "correspondences: out of memory");
    }
    size_t nd = amscr__densify(h->base, h->n, closed, Hd), nedge = closed ? nd : nd - 1;
    size_t w = AMSCR__DENSE * (h->n / AMSCR__CORR_WINDOW_DIV), prev = 0, inl = 0;
    const double *X = r->m.X, *iv = h->inv;
    for (size_t a = 0; a < n; a++) {
        double fx = f->base[2 * a], fy = f->base[2 * a + 1];
        double px = X[0] * fx + X[1] * fy + X[2], py = X[3] * fx + X[4] * fy + X[5], qx, qy;
        size_t seg = 0;
        double d2 = amscr__closest_on_polygon(Hd, nd, closed, a == 0 ? 0 : prev, a == 0 ? nd : w, px, py, &qx, &qy,
                                              &seg);
        if (a > 0 && !(sqrt(d2) <= AMSCR__INLIER_DIST)) /* the window lost the boundary: search it all */
            d2 = amscr__closest_on_polygon(Hd, nd, closed, 0, nd, px, py, &qx, &qy, &seg);
        prev = seg;
        size_t nx = seg + 1 == nd ? 0 : seg + 1;
        double ex = Hd[2 * nx] - Hd[2 * seg], ey = Hd[2 * nx + 1] - Hd[2 * seg + 1], l2 = ex * ex + ey * ey;
        double t = l2 > 0.0 ? ((qx - Hd[2 * seg]) * ex + (qy - Hd[2 * seg + 1]) * ey) / l2 : 0.0;
        double *c = corr + 5 * a;
        c[0] = f->input[2 * a];
        c[1] = f->input[2 * a + 1];
        c[2] = fmod(((double)seg + t) / (double)nedge, 1.0);
        c[3] = iv[0] * qx + iv[1] * qy + iv[2];
        c[4] = iv[3] * qx + iv[4] * qy + iv[5];
        int near = sqrt(d2) <= AMSCR__INLIER_DIST;
        double el = near && l2 > 0.0 ? sqrt(l2) : 0.0, *s = nr + 3 * a;
        s[0] = el > 0.0 ? -ey / el : 0.0; /* an inlier's unit normal; 0: not used */
        s[1] = el > 0.0 ? ex / el : 0.0;
        s[2] = s[0] * (px - qx) + s[1] * (py - qy);
        nr[3 * n + a] = d2;
        inl += (size_t)near;
    }
    /* the jackknife re-solves an affine map (other groups' maps have fewer freedoms) from the
     * inliers the polish's trimming keeps; a check's own registration (r->backward) reports
     * no confidence and skips it */
    r->se = NAN;
    amscr_status st = AMSCR_OK;
    if (prm->invariance == AMSCR_INVARIANCE_AFFINE && !r->backward) {
        trim_pairs(nr, n);
        st = amscr__map_precision(f, nr, n, &r->se);
    }
    free(nr);
    free(Hd);
    if (st != AMSCR_OK) {
        free(corr);
        return st;
    }
    free(r->corr);
    r->corr = corr;
    r->ncorr = n;
    r->inlier = (double)inl / (double)n;
    r->part[0] = corr[2];
    r->part[1] = corr[5 * (n - 1) + 2];
    return AMSCR_OK;
}
