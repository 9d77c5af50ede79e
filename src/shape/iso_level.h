/* iso_level.h — internal: the grey level a sub-pixel contour follows and the padded field the
 * marching squares walk (iso_level.c, march.c, trace_image.c). */
#ifndef AMSCR_ISO_LEVEL_H
#define AMSCR_ISO_LEVEL_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"

/* An 8- or 16-bit image seen as the field f = sign * (v - level), padded with a one-pixel frame
 * of value `pad` (< 0, background). A pixel is foreground when f > 0. Padded coordinates:
 * pixel (x, y) of the image is (x + 1, y + 1). */
typedef struct amscr__iso {
    const uint8_t *p8;   /* 8-bit samples, or NULL */
    const uint16_t *p16; /* 16-bit samples, or NULL */
    size_t w, h, stride; /* stride in samples */
    double level;        /* the iso-level, in sample units */
    double sign;         /* +1, or -1 when the polarity is inverted (border mostly above level) */
    double pad;          /* the frame's field value: the background's mean level, < 0 */
} amscr__iso;

/* Otsu's split t (class 0: v <= t) on nb bins: the middle of the plateau of maxima of the
 * between-class variance; -1 when the image has one value (used by trace.c too). */
long amscr__otsu(const uint64_t *hist, size_t nb);

/* The level (given, or automatic when level < 0: halfway between the medians of the two
 * classes of Otsu's split), the polarity and the frame value. Arguments are validated by the caller. */
amscr_status amscr__iso_setup(const void *pixels, size_t w, size_t h, size_t stride, int bits, double level,
                              amscr__iso *out);

/* The field at padded coordinates (X, Y), 0 <= X < w + 2, 0 <= Y < h + 2. A frame position
 * next to a foreground border pixel takes that pixel's value negated, so the iso-line crosses
 * the image's edge halfway (at -0.5 or side - 0.5); elsewhere the frame is `pad`. */
static inline double amscr__iso_at(const amscr__iso *f, size_t X, size_t Y)
{
    int frame = X == 0 || Y == 0 || X > f->w || Y > f->h;
    size_t x = X == 0 ? 0 : X > f->w ? f->w - 1 : X - 1, y = Y == 0 ? 0 : Y > f->h ? f->h - 1 : Y - 1;
    size_t i = y * f->stride + x;
    double g = f->sign * ((f->p8 ? (double)f->p8[i] : (double)f->p16[i]) - f->level);
    if (!frame)
        return g;
    return g > 0.0 ? -g : f->pad;
}

/* The padded foreground mask ((w+2) x (h+2) bytes, 1 where f > 0) and its foreground count. */
amscr_status amscr__iso_mask(const amscr__iso *f, uint8_t **out_on, size_t *out_fg);

/* The closed iso-line through the entry edge `entry` (0 top, 1 right, 2 bottom, 3 left) of the
 * cell whose top-left corner is padded pixel (cx, cy), walked by marching squares with linear
 * interpolation; saddle cells join their foreground corners (foreground 8-connected, as the
 * pixel labelling). Points in image coordinates (pixel centres at integers), consecutive
 * repeats dropped; fn names the public call in messages. */
amscr_status amscr__march(const amscr__iso *f, size_t cx, size_t cy, int entry, const char *fn, double **out_xy,
                          size_t *out_n);

struct amscr__regions;
/* AMSCR_TRACE_JOIN (join.c): joins to the outline xy (n points, counter-clockwise) of component
 * `largest` of R (count: pixels per label) the outlines of the other large components near it;
 * xy and n are replaced. */
amscr_status amscr__join_pieces(const amscr__iso *f, const struct amscr__regions *R, const size_t *count,
                                size_t largest, double **xy, size_t *n);

#endif
