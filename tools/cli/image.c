/* image.c — shape input of the amscr tool (see image.h): a file's format told by its magic
 * bytes, decoded by image_pgm.c or image_png.c, traced, or read as a text point list. */
#include "image.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h" /* TOOL_THRESHOLD_* */
#include "image_codec.h"
#include "util.h"

int image_have_png(void)
{
#if defined(AMSCR_TOOL_HAVE_PNG)
    return 1;
#else
    return 0;
#endif
}

/* ============================================================ detection */
static const unsigned char PNG_SIG[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};

static int is_ws(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f' || c == '#'; }

static tool_format sniff(const unsigned char *m, size_t n, const char **other)
{
    *other = NULL;
    if (n >= 8 && memcmp(m, PNG_SIG, 8) == 0)
        return TOOL_FMT_PNG;
    if (n >= 3 && m[0] == 'P' && (m[1] == '2' || m[1] == '5') && is_ws(m[2]))
        return TOOL_FMT_PGM;
    if (n >= 3 && m[0] == 'P' && (m[1] == '1' || m[1] == '3' || m[1] == '4' || m[1] == '6' || m[1] == '7') &&
        is_ws(m[2]))
        *other = "Netpbm other than PGM (P2/P5)";
    else if (n >= 3 && m[0] == 0xFF && m[1] == 0xD8 && m[2] == 0xFF)
        *other = "JPEG";
    else if (n >= 4 && memcmp(m, "GIF8", 4) == 0)
        *other = "GIF";
    else if (n >= 4 && (memcmp(m, "II*\0", 4) == 0 || memcmp(m, "MM\0*", 4) == 0))
        *other = "TIFF";
    else if (n >= 4 && memcmp(m, "RIFF", 4) == 0)
        *other = "RIFF/WebP";
    else if (n >= 2 && m[0] == 'B' && m[1] == 'M' && n >= 6)
        *other = "BMP";
    else if (n >= 5 && memcmp(m, "\x89PNG", 4) == 0)
        *other = "damaged PNG signature";
    return TOOL_FMT_TEXT;
}

/* The most a stream (a pipe, /dev/stdin) may hold: it is read whole into memory. */
#define TOOL_STREAM_MAX ((size_t)1 << 30)

/* The whole of fp, a stream that cannot be read twice, into memory (*len bytes, NUL-terminated);
 * NULL after an error line. */
static char *read_stream(FILE *fp, const char *path, size_t *len)
{
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    for (size_t got = 1; buf && got > 0;) {
        if (cap - n < 2) {
            char *nb = cap < TOOL_STREAM_MAX ? realloc(buf, 2 * cap) : NULL;
            if (!nb) {
                tool_error(path, cap < TOOL_STREAM_MAX ? "out of memory" : "more than 1 GiB through a pipe: give a file");
                free(buf);
                return NULL;
            }
            buf = nb;
            cap *= 2;
        }
        got = fread(buf + n, 1, cap - n - 1, fp);
        n += got;
    }
    if (buf && ferror(fp)) {
        tool_error(path, "read error: %s", strerror(errno));
        free(buf);
        return NULL;
    }
    if (!buf)
        tool_error(path, "out of memory");
    else
        buf[n] = '\0';
    *len = n;
    return buf;
}

/* The stream fp read whole into *mem and closed; the memory opened as a file in its place
 * (NULL after an error line: empty, out of memory). */
static FILE *reopen_in_memory(FILE *fp, const char *path, char **mem, size_t *mem_len)
{
    *mem = read_stream(fp, path, mem_len);
    fclose(fp);
    if (!*mem)
        return NULL;
    FILE *m = *mem_len ? fmemopen(*mem, *mem_len, "rb") : NULL;
    if (!m) {
        tool_error(path, *mem_len ? "out of memory" : "empty file");
        free(*mem);
        *mem = NULL;
    }
    return m;
}

/* Opens `path` for reading after checking it is a non-empty file. A stream that cannot be read
 * twice (a pipe, a FIFO, a device: /dev/stdin) is read whole into *mem (freed by the caller) and
 * opened from memory, so its format can be sniffed and the file read from its start. */
static FILE *open_input(const char *path, char **mem, size_t *mem_len)
{
    struct stat st;
    *mem = NULL;
    if (stat(path, &st) != 0) {
        tool_error(path, "cannot open: %s", strerror(errno));
        return NULL;
    }
    if (S_ISDIR(st.st_mode)) {
        tool_error(path, "is a directory, not an image or point list");
        return NULL;
    }
    FILE *fp = fopen(path, "rb");
    if (fp == NULL) {
        tool_error(path, "cannot open: %s", strerror(errno));
        return NULL;
    }
    if (!S_ISREG(st.st_mode))
        return reopen_in_memory(fp, path, mem, mem_len);
    if (st.st_size == 0) {
        fclose(fp);
        tool_error(path, "empty file");
        return NULL;
    }
    return fp;
}

int file_is_image(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (fp == NULL)
        return 0;
    unsigned char m[8];
    size_t n = fread(m, 1, sizeof m, fp);
    fclose(fp);
    const char *other;
    return sniff(m, n, &other) != TOOL_FMT_TEXT;
}

const char *file_image_other(const char *path)
{
    unsigned char m[8];
    FILE *fp = fopen(path, "rb");
    size_t n = fp ? fread(m, 1, sizeof m, fp) : 0;
    if (fp)
        fclose(fp);
    const char *other;
    sniff(m, n, &other);
    return other;
}

/* 1 when the first n bytes m of a file that is no image (`other`: the format it is, if known)
 * may start a point list; else -1 after the error line. */
static int text_or_error(const char *path, const unsigned char *m, size_t n, const char *other, int text_ok)
{
    if (other != NULL) {
        tool_error(path, "unsupported image format (%s): use PNG, PGM or a text point list", other);
        return -1;
    }
    if (!text_ok) {
        tool_error(path, "not a PNG or PGM image");
        return -1;
    }
    size_t ctrl = 0;
    for (size_t i = 0; i < n; i++)
        if (m[i] < 32 && m[i] != '\n' && m[i] != '\r' && m[i] != '\t' && m[i] != '\f' && m[i] != '\v')
            ctrl++;
    if (memchr(m, '\0', n) != NULL || ctrl * 20 > n) {
        tool_error(path, "unrecognized binary file: not a PNG or PGM image, nor a text point list");
        return -1;
    }
    return 1;
}

int image_read(const char *path, int text_ok, tool_image *out, tool_format *out_format)
{
    memset(out, 0, sizeof *out);
    *out_format = TOOL_FMT_TEXT;
    char *mem;
    size_t mem_len = 0;
    FILE *fp = open_input(path, &mem, &mem_len);
    if (fp == NULL)
        return -1;
    unsigned char m[512];
    size_t n = fread(m, 1, sizeof m, fp);
    if (n == 0) {
        fclose(fp);
        free(mem);
        tool_error(path, "empty file");
        return -1;
    }
    const char *other;
    tool_format f = sniff(m, n, &other);
    *out_format = f;
    if (f == TOOL_FMT_TEXT) {
        fclose(fp);
        int r = text_or_error(path, m, n, other, text_ok);
        if (r > 0 && mem) {
            out->text = mem;
            out->text_len = mem_len;
        } else {
            free(mem);
        }
        return r;
    }
    rewind(fp);
    int r;
    if (f == TOOL_FMT_PGM) {
        r = image_read_pgm(fp, path, m[1] == '2', out);
    } else {
#if defined(AMSCR_TOOL_HAVE_PNG)
        r = image_read_png(fp, path, out);
#else
        tool_error(path, "PNG input is not available: this amscr was built without libpng (PGM and point "
                         "lists are read; Debian/Ubuntu: apt-get install libpng-dev, then build or pip install again)");
        r = -1;
#endif
    }
    fclose(fp);
    free(mem);
    if (r < 0)
        image_free(out);
    return r;
}

/* ============================================================ shapes */
static int trace_flags; /* set once by the option parser (--pixel-chain), before any tracing */

void image_set_trace_flags(int flags) { trace_flags = flags; }

int image_trace_flags(void) { return trace_flags; }

/* The largest sample of img: of its 16-bit samples when it has them and `wide`, else of its
 * 8-bit ones. */
static unsigned image_max(const tool_image *img, int wide)
{
    size_t n = img->width * img->height;
    unsigned m = 0;
    for (size_t i = 0; i < n; i++) {
        unsigned v = wide && img->pix16 ? img->pix16[i] : img->pix[i];
        m = v > m ? v : m;
    }
    return m;
}

double image_level(const tool_image *img, int threshold, int *out_bits, const void **out_pixels)
{
    *out_bits = img->pix16 ? 16 : 8;
    *out_pixels = img->pix16 ? (const void *)img->pix16 : (const void *)img->pix;
    if (threshold == AMSCR_THRESHOLD_AUTO)
        return AMSCR_LEVEL_AUTO;
    if (threshold == TOOL_THRESHOLD_UNSET && image_max(img, 1) <= 1)
        return 0.5; /* a 0/1 mask, as NumPy and many label images store one */
    if (threshold == TOOL_THRESHOLD_UNSET)
        threshold = TOOL_THRESHOLD_DEFAULT;
    return img->pix16 ? (threshold + 0.5) * 257.0 : threshold + 0.5;
}

void image_no_shape_error(const char *path, const tool_image *img, int threshold, const char *what,
                          const char *detail)
{
    int zero_one = threshold == TOOL_THRESHOLD_UNSET && image_max(img, 1) <= 1; /* traced at 0.5 */
    int t = threshold == TOOL_THRESHOLD_UNSET ? TOOL_THRESHOLD_DEFAULT : threshold;
    unsigned m = image_max(img, 1), top = img->pix16 ? 65535u : 255u;
    double scale = img->pix16 ? 257.0 : 1.0;          /* image_level: (T + 0.5) * scale */
    unsigned below = (unsigned)ceil(m / scale - 0.5); /* the thresholds T < below leave m on */
    int dark = threshold != AMSCR_THRESHOLD_AUTO && !zero_one && m > 0 && m < (t + 0.5) * scale;
    if (dark && below > 0)
        tool_error(path, "%s: no pixel is above the threshold %d (the brightest is %u of %u): set --threshold "
                   "below %u, or --threshold auto", what, t, m, top, below);
    else if (dark)
        tool_error(path, "%s: no pixel is above the threshold %d (the brightest is %u of %u): use --threshold auto",
                   what, t, m, top);
    else if (detail[0])
        tool_error(path, "%s: %s", what, detail);
    else if (threshold == AMSCR_THRESHOLD_AUTO)
        tool_error(path, "%s at threshold auto", what);
    else
        tool_error(path, "%s at threshold %d", what, t);
}

int shape_load(const char *path, int threshold, amscr_contour **out)
{
    tool_image img;
    tool_format f;
    *out = NULL;
    int r = image_read(path, 1, &img, &f);
    if (r < 0)
        return -1;
    if (r > 0) {
        /* Not an image: a text point list (read already when it came through a pipe). */
        amscr_status st = img.text ? amscr_contour_parse_text(img.text, img.text_len, out)
                                   : amscr_contour_read_text(path, out);
        image_free(&img);
        if (st != AMSCR_OK) {
            const char *d = lib_detail();
            if (st == AMSCR_E_FORMAT && d[0] != '\0') {
                /* "path:line: problem" from the library names the file already. */
                size_t pl = strlen(path);
                if (strncmp(d, path, pl) == 0 && d[pl] == ':')
                    tool_error(NULL, "%s", d);
                else
                    tool_error(path, "not an image, and not a valid point list: %s", d);
            } else {
                tool_lib_error(path, st);
            }
            *out = NULL;
            return -1;
        }
        return 0;
    }
    int bits;
    const void *pixels;
    double level = image_level(&img, threshold, &bits, &pixels);
    amscr_status st = amscr_contour_from_image(pixels, img.width, img.height, img.width, bits, level, trace_flags, out);
    if (st != AMSCR_OK) {
        const char *d = lib_detail();
        switch (st) {
        case AMSCR_E_NOT_FOUND:
            image_no_shape_error(path, &img, threshold, "no foreground shape", d);
            break;
        case AMSCR_E_DEGENERATE:
            tool_error(path, "the shape is too small to trace%s%s", d[0] ? ": " : "", d);
            break;
        case AMSCR_E_LIMIT:
            tool_error(path, "image too large%s%s", d[0] ? ": " : "", d);
            break;
        default:
            tool_lib_error(path, st);
        }
        image_free(&img);
        *out = NULL;
        return -1;
    }
    image_free(&img);
    return 0;
}
