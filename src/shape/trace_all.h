/* trace_all.h — internal: the threshold and polarity rules of amscr_contour_from_mask
 * (trace.c), shared with amscr_contours_from_mask (trace_all.c). */
#ifndef AMSCR_TRACE_ALL_H
#define AMSCR_TRACE_ALL_H

#include <stddef.h>
#include <stdint.h>

/* The threshold (Otsu's when AMSCR_THRESHOLD_AUTO) into *out_t, and *out_invert = 1 when most
 * of the image border is "on" (on/off are then swapped so the border is background). The
 * arguments are validated by the caller. */
void amscr__mask_threshold(const uint8_t *pixels, size_t w, size_t h, size_t stride, int threshold, int *out_t,
                           int *out_invert);

#endif
