/* image_pgm.c — PGM (P2, P5) decoding for the amscr tool (image_codec.h): v * 255 / maxval,
 * rounded (maxval 1..65535); maxval > 255 keeps the 16-bit samples too (pix16). */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image_codec.h"
#include "util.h"

/* Reads the next header integer, skipping whitespace and '#' comments. Returns -1 at EOF
 * or on a non-digit. */
static int pgm_int(FILE *fp, unsigned long *out)
{
    int c;
    for (;;) {
        c = getc(fp);
        if (c == '#') {
            while (c != EOF && c != '\n' && c != '\r')
                c = getc(fp);
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f')
            continue;
        break;
    }
    if (c == EOF)
        return -2;
    if (c < '0' || c > '9')
        return -1;
    unsigned long v = 0;
    while (c >= '0' && c <= '9') {
        unsigned long d = (unsigned long)(c - '0');
        v = v > (ULONG_MAX - d) / 10 ? ULONG_MAX : v * 10 + d; /* exact, or ULONG_MAX (past any limit) */
        c = getc(fp);
    }
    if (c != EOF)
        ungetc(c, fp);
    *out = v;
    return 0;
}

/* The header after the magic number: width, height and maxval, then the one whitespace
 * character that ends it. */
static int pgm_header(FILE *fp, const char *path, unsigned long *w, unsigned long *h, unsigned long *maxval)
{
    const char *what[3] = {"width", "height", "maxval"};
    unsigned long *vals[3] = {w, h, maxval};
    (void)getc(fp);
    (void)getc(fp); /* "P5" / "P2" */
    for (int i = 0; i < 3; i++) {
        int r = pgm_int(fp, vals[i]);
        if (r == -2) {
            tool_error(path, "truncated PGM: header ends before the %s", what[i]);
            return -1;
        }
        if (r != 0) {
            tool_error(path, "corrupt PGM: bad %s in the header", what[i]);
            return -1;
        }
    }
    if (*maxval < 1 || *maxval > 65535) {
        tool_error(path, "corrupt PGM: maxval %lu out of range 1..65535", *maxval);
        return -1;
    }
    if (image_check_limits(path, "PGM", *w, *h) != 0)
        return -1;
    /* Exactly one whitespace character ends the header (a comment may sit before it). */
    int c = getc(fp);
    if (c == '#') {
        while (c != EOF && c != '\n' && c != '\r')
            c = getc(fp);
    }
    if (c == EOF) {
        tool_error(path, "truncated PGM: no pixel data");
        return -1;
    }
    if (!(c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f')) {
        tool_error(path, "corrupt PGM: no whitespace after maxval");
        return -1;
    }
    return 0;
}

/* Binary (P5) samples, 1 or 2 bytes each (big-endian), scaled to 0..255 into pix (and to
 * 0..65535 into pix16 when not NULL). */
static int pgm_binary(FILE *fp, const char *path, size_t w, size_t h, unsigned long maxval, uint8_t *pix,
                      uint16_t *pix16)
{
    unsigned long half = maxval / 2;
    size_t bps = maxval < 256 ? 1 : 2;
    uint8_t *row = xmalloc_array(w, bps);
    if (row == NULL)
        return -1;
    for (size_t y = 0; y < h; y++) {
        size_t got = fread(row, bps, w, fp);
        if (got != w) {
            tool_error(path, "truncated PGM: pixel data ends in row %zu of %lu", y + 1, (unsigned long)h);
            free(row);
            return -1;
        }
        for (size_t x = 0; x < w; x++) {
            unsigned long v = bps == 1 ? row[x] : ((unsigned long)row[2 * x] << 8) | row[2 * x + 1];
            if (v > maxval) {
                tool_error(path, "corrupt PGM: sample %lu at (%zu, %zu) exceeds maxval %lu", v, x, y, maxval);
                free(row);
                return -1;
            }
            pix[y * w + x] = (uint8_t)((v * 255 + half) / maxval);
            if (pix16)
                pix16[y * w + x] = (uint16_t)((v * 65535 + half) / maxval);
        }
    }
    free(row);
    return 0;
}

/* ASCII (P2) samples, scaled to 0..255 into pix (and to 0..65535 into pix16 when not NULL). */
static int pgm_ascii(FILE *fp, const char *path, size_t w, size_t h, unsigned long maxval, uint8_t *pix,
                     uint16_t *pix16)
{
    unsigned long half = maxval / 2;
    size_t npix = w * h;
    for (size_t i = 0; i < npix; i++) {
        unsigned long v;
        int r = pgm_int(fp, &v);
        if (r == -2) {
            tool_error(path, "truncated PGM: %zu of %zu samples", i, npix);
            return -1;
        }
        if (r != 0) {
            tool_error(path, "corrupt PGM: sample %zu is not a number", i + 1);
            return -1;
        }
        if (v > maxval) {
            tool_error(path, "corrupt PGM: sample %lu at (%zu, %zu) exceeds maxval %lu", v, i % w, i / w, maxval);
            return -1;
        }
        pix[i] = (uint8_t)((v * 255 + half) / maxval);
        if (pix16)
            pix16[i] = (uint16_t)((v * 65535 + half) / maxval);
    }
    return 0;
}

int image_read_pgm(FILE *fp, const char *path, int ascii, tool_image *out)
{
    unsigned long w, h, maxval;
    if (pgm_header(fp, path, &w, &h, &maxval) != 0)
        return -1;
    size_t npix = (size_t)w * (size_t)h;
    uint8_t *pix = xmalloc_array(npix, 1);
    uint16_t *pix16 = maxval > 255 && pix ? xmalloc_array(npix, sizeof *pix16) : NULL;
    if (pix == NULL || (maxval > 255 && pix16 == NULL)) {
        free(pix);
        return -1;
    }
    int r = ascii ? pgm_ascii(fp, path, w, h, maxval, pix, pix16) : pgm_binary(fp, path, w, h, maxval, pix, pix16);
    if (r != 0) {
        free(pix);
        free(pix16);
        return -1;
    }
    out->pix = pix;
    out->pix16 = pix16;
    out->width = w;
    out->height = h;
    return 0;
}
