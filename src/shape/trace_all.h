/* trace_all.h — internal: the threshold and polarity rules and the boundary's growth of
 * amscr_contour_from_mask (trace.c), shared with amscr_contours_from_mask (trace_all.c); the
 * region labelling and hierarchy of trace_all.c, shared with the sub-pixel tracer
 * (trace_image.c). */
#ifndef AMSCR_TRACE_ALL_H
#define AMSCR_TRACE_ALL_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"

/* The threshold (Otsu's when AMSCR_THRESHOLD_AUTO) into *out_t, and *out_invert = 1 when most
 * of the image border is "on" (on/off are then swapped so the border is background). The
 * arguments are validated by the caller. */
void amscr__mask_threshold(const uint8_t *pixels, size_t w, size_t h, size_t stride, int threshold, int *out_t,
                           int *out_invert);

/* Room for one more boundary point of a Moore trace: pts and backs (*cap entries each) grow
 * together, doubled up to AMSCR_MAX_POINTS; AMSCR_E_LIMIT when np reached it (fn names the
 * public call in messages). */
amscr_status amscr__trace_grow(uint32_t **pts, uint8_t **backs, size_t np, size_t *cap, const char *fn);

/* Regions of a padded mask (W x H, a frame of background): foreground 8-connected, background
 * 4-connected, labelled in raster order of their first pixel. */
typedef struct amscr__regions {
    uint32_t *lab; /* W*H labels, 1-based; 1 is the outside */
    uint32_t *first; /* first pixel (padded index) of each label */
    unsigned char *fg;
    size_t n, cap; /* labels 1..n are used; index 0 unused */
} amscr__regions;

/* Labels the padded mask `on` (W x H; 1 = foreground; its one-pixel ring must be background,
 * as every caller pads). On failure R holds nothing to free. */
amscr_status amscr__regions_label(const uint8_t *on, size_t W, size_t H, amscr__regions *R);
void amscr__regions_free(amscr__regions *R);

/* Traces region r of R into *out (NULL: dropped: fewer than 3 points, no area, or an area below
 * min_area) with its polygon area (>= 0); outer contours counter-clockwise, holes clockwise. */
typedef amscr_status (*amscr__region_tracer)(void *ctx, const amscr__regions *R, size_t r, double min_area,
                                             amscr_contour **out, double *out_area);

/* Every contour of the padded mask `on` (W x H, at least one foreground pixel) with the
 * hierarchy of amscr_contours_from_mask, each region traced by `tracer`. fn names the public
 * call in messages. AMSCR_E_NOT_FOUND when no contour is kept. */
amscr_status amscr__contours_build(const uint8_t *on, size_t W, size_t H, amscr__region_tracer tracer, void *ctx,
                                   double min_area, const char *fn, amscr_contour_set **out);

#endif
