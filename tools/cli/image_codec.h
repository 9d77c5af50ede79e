/* image_codec.h — the decoded image and the decoders behind image_read (image.h): each reads an
 * open file whose magic bytes were checked, checks the size limits before it allocates
 * (image_codec.c), and on failure prints one error line naming `path` and returns -1.
 * Tool-internal. */
#ifndef AMSCR_TOOL_IMAGE_CODEC_H
#define AMSCR_TOOL_IMAGE_CODEC_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* An 8-bit luminance image, rows packed (stride == width); pix16: the same image with 16-bit
 * samples when the file had more than 8 bits a sample (16-bit PNG without alpha, PGM with
 * maxval > 255), else NULL. */
typedef struct tool_image {
    uint8_t *pix;
    size_t width, height;
    uint16_t *pix16;
    char *text;      /* a point list read from a stream (a pipe, /dev/stdin): its bytes, else NULL */
    size_t text_len;
} tool_image;

/* Frees an image's samples (image_codec.c); the struct is left empty. */
void image_free(tool_image *img);

/* 0 when a w x h image of format `fmt` ("PGM", "PNG") is within AMSCR_MAX_IMAGE_SIDE and
 * AMSCR_MAX_IMAGE_PIXELS and not empty; else -1 after one error line (image_codec.c). */
int image_check_limits(const char *path, const char *fmt, size_t w, size_t h);

/* PGM: `ascii` for P2, else P5. */
int image_read_pgm(FILE *fp, const char *path, int ascii, tool_image *out);

#if defined(AMSCR_TOOL_HAVE_PNG)
int image_read_png(FILE *fp, const char *path, tool_image *out);
#endif

#endif
