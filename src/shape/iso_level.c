/* iso_level.c — the grey level a sub-pixel contour follows (docs/method.md §5).
 *
 * The contour is the iso-line of the grey image at the level halfway between background and
 * foreground: given, or automatic — Otsu's split of the histogram (256 bins for 8-bit images,
 * 65536 for 16-bit), then halfway between the two classes' medians, the level where an
 * antialiased edge (a pixel's value proportional to its covered area) is half covered. Polarity as
 * amscr_contour_from_mask: when most of the image border is above the level, the field is
 * negated so the border is background. The padding frame is background: next to a foreground
 * border pixel it mirrors that pixel's value, so a shape touching the border closes at the
 * image's edge (half a pixel beyond the border pixel centres). */
#include "internal.h"
#include "iso_level.h"

#include <stdlib.h>
#include <string.h>

static double iso_sample(const amscr__iso *f, size_t x, size_t y)
{
    size_t i = y * f->stride + x;
    return f->p8 ? (double)f->p8[i] : (double)f->p16[i];
}

long amscr__otsu(const uint64_t *hist, size_t nb)
{
    double total = 0.0, sum_all = 0.0;
    for (size_t v = 0; v < nb; v++) {
        total += (double)hist[v];
        sum_all += (double)v * (double)hist[v];
    }
    double n0 = 0.0, s0 = 0.0, best = -1.0;
    long t_first = -1, t_last = -1;
    for (size_t t = 0; t + 1 < nb; t++) {
        n0 += (double)hist[t];
        s0 += (double)t * (double)hist[t];
        double n1 = total - n0;
        if (n0 <= 0.0 || n1 <= 0.0)
            continue;
        double d = s0 / n0 - (sum_all - s0) / n1;
        double vb = n0 * n1 * d * d;
        if (vb > best) {
            best = vb;
            t_first = t_last = (long)t;
        } else if (vb == best && t_last == (long)t - 1) {
            t_last = (long)t;
        }
    }
    return t_first < 0 ? -1 : (t_first + t_last) / 2;
}

/* The median value of the pixels in bins lo..hi (n of them, n > 0). */
static double iso_median(const uint64_t *hist, size_t lo, size_t hi, uint64_t n)
{
    uint64_t half = (n + 1) / 2, seen = 0;
    for (size_t v = lo; v <= hi; v++) {
        seen += hist[v];
        if (seen >= half)
            return (double)v;
    }
    return (double)hi;
}

/* The automatic level: halfway between the medians of the two classes of Otsu's split (the
 * one value, when the image has one value: nothing is then above it). Medians, not means: the
 * edge pixels of an antialiased image sit in both classes and would pull the means (and the
 * level) towards them, by a share that grows as the image gets smaller. */
static amscr_status iso_auto_level(const amscr__iso *f, double *out)
{
    size_t nb = f->p8 ? 256 : 65536;
    uint64_t *hist = amscr__calloc_array(nb, sizeof *hist);
    if (!hist)
        return amscr__fail(AMSCR_E_NOMEM, "contour tracing: out of memory (histogram)");
    for (size_t y = 0; y < f->h; y++)
        for (size_t x = 0; x < f->w; x++)
            hist[(size_t)iso_sample(f, x, y)]++;
    long t = amscr__otsu(hist, nb);
    uint64_t n0 = 0, n = (uint64_t)f->w * f->h;
    for (long v = 0; v <= t; v++)
        n0 += hist[v];
    if (t < 0)
        *out = iso_median(hist, 0, nb - 1, n);
    else
        *out = 0.5 * (iso_median(hist, 0, (size_t)t, n0) + iso_median(hist, (size_t)t + 1, nb - 1, n - n0));
    free(hist);
    return AMSCR_OK;
}

/* Polarity (1 when most border pixels are above the level) and the background's mean level. */
static void iso_polarity(amscr__iso *f)
{
    size_t border = 0, border_on = 0;
    for (size_t y = 0; y < f->h; y++)
        for (size_t x = 0; x < f->w; x++) {
            if (y != 0 && y != f->h - 1 && x != 0 && x != f->w - 1)
                continue;
            border_on += iso_sample(f, x, y) > f->level;
            border++;
        }
    f->sign = 2 * border_on > border ? -1.0 : 1.0;
    double n = 0.0, s = 0.0;
    for (size_t y = 0; y < f->h; y++)
        for (size_t x = 0; x < f->w; x++) {
            double g = f->sign * (iso_sample(f, x, y) - f->level);
            if (g <= 0.0) {
                n += 1.0;
                s += g;
            }
        }
    double pad = n > 0.0 ? s / n : -0.5;
    f->pad = pad < -0.5 ? pad : -0.5; /* strictly background, even when it sits at the level */
}

amscr_status amscr__iso_setup(const void *pixels, size_t w, size_t h, size_t stride, int bits, double level,
                              amscr__iso *out)
{
    memset(out, 0, sizeof *out);
    if (bits == 8)
        out->p8 = pixels;
    else
        out->p16 = pixels;
    out->w = w;
    out->h = h;
    out->stride = stride;
    out->level = level;
    if (level < 0.0) {
        amscr_status st = iso_auto_level(out, &out->level);
        if (st != AMSCR_OK)
            return st;
    }
    iso_polarity(out);
    return AMSCR_OK;
}

amscr_status amscr__iso_mask(const amscr__iso *f, uint8_t **out_on, size_t *out_fg)
{
    const size_t W = f->w + 2, H = f->h + 2;
    uint8_t *on = amscr__calloc_array(W * H, 1);
    if (!on)
        return amscr__fail(AMSCR_E_NOMEM, "contour tracing: out of memory (%zu x %zu mask)", W, H);
    size_t fg = 0;
    for (size_t Y = 1; Y <= f->h; Y++)
        for (size_t X = 1; X <= f->w; X++) {
            uint8_t v = amscr__iso_at(f, X, Y) > 0.0;
            on[Y * W + X] = v;
            fg += v;
        }
    *out_on = on;
    *out_fg = fg;
    return AMSCR_OK;
}
