/* precision.c — how far apart maps lie, and how precisely the data pin a finished map down
 * (docs/method.md §11.5). The gap between two maps is their mean squared displacement of the
 * source's samples (amscr__map_gap2): every stage that tells maps apart reads it. The
 * standard error is a block jackknife of the point-to-line fit at the map's closest points.
 * The source's samples, in their order along the curve, fall into B = floor(sqrt(n)) blocks of
 * consecutive samples (blocks as long as they are many: a residual that runs along a part of
 * the curve, a thin part traced a pixel off, stays in one block). Each block in turn is left
 * out and the map re-solved, one linearized point-to-line step from the reported map on the
 * other blocks' pairs (the inliers the polish's trimming keeps: correspond.c); the spread of
 * those B maps is the jackknife's variance of the map. The standard error is its RMS
 * displacement of the source samples, in units of the target's RMS radius: the scale of the
 * forward-backward error. */
#include "dense.h"
#include "match.h"

#include <math.h>
#include <stdlib.h>

/* Fewer blocks than this (fewer than 9 samples) give no variance worth reading. */
#define AMSCR__JK_MIN_BLOCKS 3

/* The normal equations of block b: 36 entries of N, then 6 of the right-hand side. */
#define AMSCR__JK_ROW 42

double amscr__map_gap2(const amscr_descriptor *f, const double X1[6], const double X2[6])
{
    const double *mo = f->mom; /* level 0: the base samples */
    double M9[9], s = 0.0;
    amscr__moment_matrix(mo, M9);
    for (int i = 0; i < 2; i++) {
        double d[3] = {X1[3 * i] - X2[3 * i], X1[3 * i + 1] - X2[3 * i + 1], X1[3 * i + 2] - X2[3 * i + 2]};
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                s += d[r] * M9[3 * r + c] * d[c];
    }
    return s / (double)f->n;
}

static void accumulate(const double *f, const double *nr, size_t n, size_t nb, double *acc)
{
    for (size_t a = 0; a < n; a++) {
        const double *s = nr + 3 * a;
        if (!(s[0] != 0.0 || s[1] != 0.0))
            continue; /* not an inlier */
        double x = f[2 * a], y = f[2 * a + 1];
        double g[6] = {s[0] * x, s[0] * y, s[0], s[1] * x, s[1] * y, s[1]};
        double *N = acc + AMSCR__JK_ROW * (a * nb / n);
        for (int i = 0; i < 6; i++) {
            for (int j = 0; j < 6; j++)
                N[6 * i + j] += g[i] * g[j];
            N[36 + i] -= g[i] * s[2];
        }
    }
}

amscr_status amscr__map_precision(const amscr_descriptor *f, const double *nr, size_t n, double *out)
{
    size_t nb = (size_t)floor(sqrt((double)n));
    *out = NAN;
    if (nb < AMSCR__JK_MIN_BLOCKS)
        return AMSCR_OK;
    double *acc = calloc((nb + 1) * AMSCR__JK_ROW + 6 * nb, sizeof *acc);
    if (!acc)
        return amscr__fail(AMSCR_E_NOMEM, "standard error: out of memory");
    double *tot = acc + nb * AMSCR__JK_ROW, *D = tot + AMSCR__JK_ROW, mean[6] = {0};
    accumulate(f->base, nr, n, nb, acc);
    for (size_t b = 0; b < nb; b++)
        for (int i = 0; i < AMSCR__JK_ROW; i++)
            tot[i] += acc[AMSCR__JK_ROW * b + i];
    size_t k = 0;
    for (size_t b = 0; b < nb; b++) {
        double N[36], *d = D + 6 * k;
        for (int i = 0; i < 36; i++)
            N[i] = tot[i] - acc[AMSCR__JK_ROW * b + i];
        for (int i = 0; i < 6; i++)
            d[i] = tot[36 + i] - acc[AMSCR__JK_ROW * b + 36 + i];
        if (!amscr__gauss_solve(N, d, 6))
            continue; /* the other blocks alone do not fix the map: left out of the spread */
        for (int i = 0; i < 6; i++)
            mean[i] += d[i];
        k++;
    }
    double var = 0.0;
    if (k >= AMSCR__JK_MIN_BLOCKS) {
        for (int i = 0; i < 6; i++)
            mean[i] /= (double)k;
        for (size_t j = 0; j < k; j++)
            var += amscr__map_gap2(f, D + 6 * j, mean);
        var *= (double)(k - 1) / (double)k;
    }
    free(acc);
    if (k >= AMSCR__JK_MIN_BLOCKS && isfinite(var))
        *out = sqrt(var / 2.0); /* the target's normalized frame has RMS radius sqrt 2 */
    return AMSCR_OK;
}
