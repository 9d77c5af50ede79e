/* image.h — input shapes for the amscr tool: PGM (P2/P5) and PNG (libpng) decoding to
 * 8-bit luminance, format detection by magic bytes, and the text point-list fallback.
 * Decoding lives in the tool, not in libamscr (STYLE.md: codecs stay out of the core). */
#ifndef AMSCR_TOOL_IMAGE_H
#define AMSCR_TOOL_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"
#include "image_codec.h" /* tool_image, image_free */


typedef enum tool_format {
    TOOL_FMT_TEXT = 0, /* anything that is not an image magic: a text point list */
    TOOL_FMT_PGM = 1,
    TOOL_FMT_PNG = 2
} tool_format;

/* Decodes a PGM or PNG file into 8-bit luminance. On failure prints one error line
 * naming `path` and returns -1. Size limits (AMSCR_MAX_IMAGE_SIDE, AMSCR_MAX_IMAGE_PIXELS)
 * are checked before the pixel buffer is allocated. *out_format tells which format the
 * magic bytes said. A file that is not an image returns 1 without a message when `text_ok`
 * is non-zero (the caller reads it as a point list), else -1 with a message. */
int image_read(const char *path, int text_ok, tool_image *out, tool_format *out_format);

/* Loads a shape: an image (traced with amscr_contour_from_image at the level of `threshold`,
 * 0..254 or AMSCR_THRESHOLD_AUTO: see image_level) or a text point list. On failure prints
 * one error line naming `path` and returns -1. The caller frees *out with amscr_contour_free. */
int shape_load(const char *path, int threshold, amscr_contour **out);

/* How the tool traces images: 0 (sub-pixel iso-lines, the default) or AMSCR_TRACE_PIXEL_CHAIN
 * (--pixel-chain). Set once, while the options are parsed. */
void image_set_trace_flags(int flags);
int image_trace_flags(void);

/* The iso-level of amscr_contour_from_image for the tool's 8-bit `threshold` on img: T + 0.5
 * (the pixels > T), scaled by 257 for 16-bit samples; AMSCR_LEVEL_AUTO for
 * AMSCR_THRESHOLD_AUTO; for TOOL_THRESHOLD_UNSET (no --threshold), 0.5 when every sample is 0
 * or 1 (a 0/1 mask), else the level of TOOL_THRESHOLD_DEFAULT. *out_bits and *out_pixels: the
 * samples to trace. */
double image_level(const tool_image *img, int threshold, int *out_bits, const void **out_pixels);

/* The error line for an image where the tracing found no shape (AMSCR_E_NOT_FOUND): "path:
 * what: ...", with the library's `detail`, or, when every pixel is dark but not black (the
 * brightest at or below the threshold, above 1), the brightest value and what to set. */
void image_no_shape_error(const char *path, const tool_image *img, int threshold, const char *what,
                          const char *detail);

/* Non-zero when the file starts with PNG or PGM (P2/P5) magic bytes. */
int file_is_image(const char *path);
/* The name of the image format the file's first bytes say the tool cannot read ("JPEG",
 * "GIF", "TIFF", ...: the name `unsupported image format` errors give); NULL for PNG, PGM,
 * text, anything else, or a file that cannot be read. */
const char *file_image_other(const char *path);

/* Non-zero when the tool was built with libpng. */
int image_have_png(void);

#endif
