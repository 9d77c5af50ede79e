/* raster.h — the drawing primitives of the tool's pictures (raster.c, picture_file.c) that draw.c,
 * sheet.c and eval_plot.c use: an RGB float raster with anti-aliased coverage layers, the 5x7 bitmap font,
 * PNG and text files written atomically, SVG text escaping. Tool-internal. */
#ifndef AMSCR_TOOL_RASTER_H
#define AMSCR_TOOL_RASTER_H

#include <stddef.h>

#include "util.h"

typedef struct raster {
    int w, h;
    float *rgb; /* 3 floats per pixel, 0..255 */
    float *cov; /* coverage of the current layer */
} raster;

/* Clears the coverage layer. */
void cov_clear(raster *r);
/* Blends colour col into the picture with the layer's coverage. */
void cov_composite(raster *r, const unsigned char col[3]);
/* Thick anti-aliased polyline (canvas coordinates); dash = {on, off} in pixels or NULL. */
void cov_polyline(raster *r, const double *cxy, size_t n, int closed, double width, const double *dash);
/* Even-odd polygon fill. */
void cov_fill(raster *r, const double *cxy, size_t n);
/* Text with its top-left at (x, y), `px` pixels per font dot (6 * px per character). */
void raster_text(raster *r, int x, int y, const char *text, int px, const unsigned char col[3]);
/* Writes w x h RGB bytes as a PNG (atomically). Returns 0, or -1 after printing one error line. */
int write_png_file(const char *path, const unsigned char *rgb, int w, int h);
/* Writes the picture as a PNG (as write_png_file), rounded to bytes in out (3 w h of them). */
int raster_write_png(const raster *r, unsigned char *out, const char *path);
/* Writes the text of b (atomically). Returns 0, or -1 after printing one error line. */
int write_text_file(const char *path, const sbuf *b);
/* Appends s with <, >, & and " escaped, each control character as its control picture (U+2400 +
 * c) and each byte that is not UTF-8 as U+FFFD: well-formed XML text or attribute value. */
void svg_escape(sbuf *b, const char *s);

/* As svg_escape, s cut to its first max_chars - 1 characters and an ellipsis when it has more
 * than max_chars. */
void svg_escape_max(sbuf *b, const char *s, size_t max_chars);

#endif
