/* image_codec.h — the image decoders behind image_read (image.h): each reads an open file whose
 * magic bytes were checked, checks the size limits before it allocates, and on failure prints
 * one error line naming `path` and returns -1. Tool-internal. */
#ifndef AMSCR_TOOL_IMAGE_CODEC_H
#define AMSCR_TOOL_IMAGE_CODEC_H

#include <stddef.h>
#include <stdio.h>

#include "image.h"

/* 0 when a w x h image of format `fmt` ("PGM", "PNG") is within AMSCR_MAX_IMAGE_SIDE and
 * AMSCR_MAX_IMAGE_PIXELS and not empty; else -1 after one error line. */
int image_check_limits(const char *path, const char *fmt, size_t w, size_t h);

/* PGM: `ascii` for P2, else P5. */
int image_read_pgm(FILE *fp, const char *path, int ascii, tool_image *out);

#if defined(AMSCR_TOOL_HAVE_PNG)
int image_read_png(FILE *fp, const char *path, tool_image *out);
#endif

#endif
