/* signature.c — the shortlist signature of a prepared shape: magnitudes of harmonics
 * 1..AMSCR__SIG_DIM of its radius function (distance of the samples from their centroid,
 * divided by its mean). Invariant to the start point, rotation, scale and mirror images, so
 * similar shapes have near signatures. The samples are the whitened ones under the affine
 * group (so the signature is affine-invariant too), else the sampled input points, whose
 * aspect tells shapes apart. */
#include "signature.h"

#include <math.h>

void amscr__shape_signature(const amscr_descriptor *d, double *out)
{
    size_t n = d->n;
    const double *p = d->params.invariance == AMSCR_INVARIANCE_AFFINE ? d->base : d->input;
    double cx = 0.0, cy = 0.0, mean = 0.0;
    for (size_t i = 0; i < n; i++) {
        cx += p[2 * i] / (double)n;
        cy += p[2 * i + 1] / (double)n;
    }
    for (size_t i = 0; i < n; i++)
        mean += hypot(p[2 * i] - cx, p[2 * i + 1] - cy) / (double)n;
    for (size_t h = 1; h <= AMSCR__SIG_DIM; h++) { /* a DFT of the few harmonics kept */
        double re = 0.0, im = 0.0, w = 2.0 * 3.14159265358979323846 * (double)h / (double)n;
        for (size_t i = 0; i < n; i++) {
            double r = mean > 0.0 ? hypot(p[2 * i] - cx, p[2 * i + 1] - cy) / mean : 0.0;
            re += r * cos(w * (double)i);
            im -= r * sin(w * (double)i);
        }
        out[h - 1] = hypot(re, im) / (double)n;
    }
}
