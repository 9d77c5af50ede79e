/* affine_warp.c — the benches' affine-warped copies and their generator (affine_warp.h). */
#include "affine_warp.h"

#include <math.h>
#include <stdlib.h>

double warp_urand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

amscr_contour *warp_affine(const amscr_contour *c, unsigned long long *seed)
{
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    double th = 6.283185307179586 * warp_urand(seed);
    double sx = exp(log(0.5) + log(4.0) * warp_urand(seed)), sy = exp(log(0.5) + log(4.0) * warp_urand(seed));
    double sh = -0.5 + warp_urand(seed), cs = cos(th), sn = sin(th);
    double A[4] = {cs * sx, cs * sx * sh - sn * sy, sn * sx, sn * sx * sh + cs * sy};
    double *out = malloc(2 * n * sizeof *out), cx = 0, cy = 0, r = 0;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = A[0] * xy[2 * i] + A[1] * xy[2 * i + 1];
        out[2 * i + 1] = A[2] * xy[2 * i] + A[3] * xy[2 * i + 1];
        cx += out[2 * i] / (double)n;
        cy += out[2 * i + 1] / (double)n;
    }
    for (size_t i = 0; i < n; i++)
        r += ((out[2 * i] - cx) * (out[2 * i] - cx) + (out[2 * i + 1] - cy) * (out[2 * i + 1] - cy)) / (double)n;
    r = sqrt(r);
    for (size_t i = 0; i < 2 * n; i++) {
        double u = warp_urand(seed), w = warp_urand(seed);
        out[i] += 0.005 * r * sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * w);
    }
    amscr_contour *ct = NULL;
    if (amscr_contour_new(out, n, &ct) != AMSCR_OK)
        ct = NULL;
    free(out);
    return ct;
}
