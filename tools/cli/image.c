/* image.c — PGM/PNG decoding and shape loading for the amscr tool (see image.h).
 *
 * Luminance conversion:
 *   - gray: as is; 1/2/4-bit gray expanded to 0..255; 16-bit scaled (rounded) to 8 bits, and
 *     kept as 16-bit samples too (pix16) for gray and RGB without alpha and PGM maxval > 255,
 *     which the sub-pixel tracer follows;
 *   - RGB: Y = (299 R + 587 G + 114 B) / 1000 (Rec. 601 weights, on the stored values);
 *   - palette: through the palette's RGB, tRNS entries give alpha;
 *   - PGM: v * 255 / maxval, rounded (maxval 1..65535).
 * Alpha (gray+alpha, RGBA, tRNS): when every pixel has alpha >= 128 the alpha channel is
 * ignored. Otherwise transparent pixels (alpha < 128) are made background:
 *   - if the opaque pixels have (nearly) one colour (luminance range <= 16), the alpha
 *     channel is the silhouette: opaque -> 255, transparent -> 0;
 *   - otherwise the image is composited over a background that contrasts with the mean
 *     opaque colour (white under dark content, black under light content).
 * The polarity of the result does not matter: amscr_contour_from_mask makes the image
 * border background. */
#include "image.h"

#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "util.h"

#if defined(AMSCR_TOOL_HAVE_PNG)
#include <png.h>
#endif

int image_have_png(void)
{
#if defined(AMSCR_TOOL_HAVE_PNG)
    return 1;
#else
    return 0;
#endif
}

void image_free(tool_image *img)
{
    if (img) {
        free(img->pix);
        free(img->pix16);
        img->pix = NULL;
        img->pix16 = NULL;
        img->width = img->height = 0;
    }
}

/* The chunks libpng still reads into memory (png_set_input): at most this many bytes each and
 * this many in all (libpng's defaults in builds that set them). */
#define PNG_CHUNK_MAX_BYTES 8000000u
#define PNG_CHUNK_MAX_COUNT 1000u

static int check_limits(const char *path, const char *fmt, size_t w, size_t h)
{
    if (w == 0 || h == 0) {
        tool_error(path, "corrupt %s: image size is %zu x %zu", fmt, w, h);
        return -1;
    }
    if (w > AMSCR_MAX_IMAGE_SIDE || h > AMSCR_MAX_IMAGE_SIDE ||
        (double)w * (double)h > (double)AMSCR_MAX_IMAGE_PIXELS) {
        tool_error(path, "image too large: %zu x %zu pixels (limits: %d per side, %u pixels)", w, h,
                   AMSCR_MAX_IMAGE_SIDE, (unsigned)AMSCR_MAX_IMAGE_PIXELS);
        return -1;
    }
    return 0;
}

/* ================================================================== PGM */
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
    int digits = 0;
    while (c >= '0' && c <= '9') {
        if (v > 100000000ul) /* far beyond any limit; keeps the value exact */
            v = 100000000ul;
        else
            v = v * 10 + (unsigned long)(c - '0');
        digits++;
        c = getc(fp);
    }
    (void)digits;
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
    if (check_limits(path, "PGM", *w, *h) != 0)
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

static int read_pgm(FILE *fp, const char *path, int ascii, tool_image *out)
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

/* ================================================================== PNG */
#if defined(AMSCR_TOOL_HAVE_PNG)
/* ============================================================= alpha policy */
static void apply_alpha(uint8_t *lum, const uint8_t *alpha, size_t n)
{
    size_t transparent = 0, opaque = 0;
    int lo = 255, hi = 0;
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (alpha[i] < 128) {
            transparent++;
        } else {
            opaque++;
            if (lum[i] < lo)
                lo = lum[i];
            if (lum[i] > hi)
                hi = lum[i];
            sum += lum[i];
        }
    }
    if (transparent == 0)
        return; /* fully opaque: alpha carries nothing */
    if (opaque == 0 || hi - lo <= 16) {
        for (size_t i = 0; i < n; i++)
            lum[i] = alpha[i] >= 128 ? 255 : 0;
        return;
    }
    unsigned bg = sum / (double)opaque < 128.0 ? 255u : 0u;
    for (size_t i = 0; i < n; i++) {
        unsigned a = alpha[i];
        lum[i] = (uint8_t)((lum[i] * a + bg * (255u - a) + 127u) / 255u);
    }
}

typedef struct png_ctx {
    FILE *fp;
    int truncated;
    char msg[256];
    /* What a longjmp must free or report: volatile, as it changes between setjmp and longjmp. */
    uint8_t *volatile lum;
    uint16_t *volatile lum16;
    uint8_t *volatile alpha;
    uint8_t *volatile buf;
    png_bytep *volatile rows;
    volatile int limit_failed; /* reported already (a size limit, or too small a file) */
    size_t file_size;          /* bytes, 0 when unknown (not a regular file) */
} png_ctx;

static void png_err_fn(png_structp png, png_const_charp msg)
{
    png_ctx *ctx = (png_ctx *)png_get_error_ptr(png);
    if (ctx != NULL && ctx->msg[0] == '\0')
        snprintf(ctx->msg, sizeof ctx->msg, "%s", msg ? msg : "unknown libpng error");
    png_longjmp(png, 1);
}

static void png_warn_fn(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg; /* warnings (ancillary-chunk CRC, extra data, ...) are not errors */
}

static void png_read_fn(png_structp png, png_bytep data, png_size_t len)
{
    png_ctx *ctx = (png_ctx *)png_get_io_ptr(png);
    if (fread(data, 1, len, ctx->fp) != len) {
        ctx->truncated = 1;
        png_error(png, "unexpected end of file");
    }
}

static void to_luminance_row(const uint8_t *src, int channels, size_t w, uint8_t *lum, uint8_t *alpha)
{
    for (size_t x = 0; x < w; x++) {
        const uint8_t *p = src + (size_t)channels * x;
        switch (channels) {
        case 1:
            lum[x] = p[0];
            break;
        case 2:
            lum[x] = p[0];
            alpha[x] = p[1];
            break;
        case 3:
            lum[x] = (uint8_t)((299u * p[0] + 587u * p[1] + 114u * p[2] + 500u) / 1000u);
            break;
        default:
            lum[x] = (uint8_t)((299u * p[0] + 587u * p[1] + 114u * p[2] + 500u) / 1000u);
            alpha[x] = p[3];
            break;
        }
    }
}

/* The size limits are checked from IHDR before libpng reads on (a file truncated right after
 * a huge IHDR is "too large", not "truncated"). Leaves fp rewound. */
static int png_check_ihdr(FILE *fp, const char *path)
{
    unsigned char head[24];
    if (fread(head, 1, sizeof head, fp) == sizeof head && memcmp(head + 12, "IHDR", 4) == 0) {
        size_t w = ((size_t)head[16] << 24) | ((size_t)head[17] << 16) | ((size_t)head[18] << 8) | head[19];
        size_t h = ((size_t)head[20] << 24) | ((size_t)head[21] << 16) | ((size_t)head[22] << 8) | head[23];
        if (w > 0 && h > 0 && check_limits(path, "PNG", w, h) != 0)
            return -1;
    }
    rewind(fp);
    return 0;
}

/* A 16-bit gray or RGB file without alpha keeps its 16 bits (to_luminance_row16). */
static int png_keep16(png_structp png, png_infop info)
{
    int color = png_get_color_type(png, info);
    return png_get_bit_depth(png, info) == 16 && (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_RGB) &&
           !png_get_valid(png, info, PNG_INFO_tRNS);
}

/* 16-bit big-endian gray or RGB samples to 16- and 8-bit luminance (weights as above). */
static void to_luminance_row16(const uint8_t *src, int channels, size_t w, uint8_t *lum, uint16_t *lum16)
{
    for (size_t x = 0; x < w; x++) {
        const uint8_t *p = src + 2 * (size_t)channels * x;
        unsigned long v = ((unsigned long)p[0] << 8) | p[1];
        if (channels == 3) {
            unsigned long g = ((unsigned long)p[2] << 8) | p[3], b = ((unsigned long)p[4] << 8) | p[5];
            v = (299ul * v + 587ul * g + 114ul * b + 500ul) / 1000ul;
        }
        lum16[x] = (uint16_t)v;
        lum[x] = (uint8_t)((v * 255ul + 32767ul) / 65535ul);
    }
}

/* Asks libpng for 8-bit gray or RGB, with alpha when the file has any (16-bit when png_keep16);
 * returns the number of interlace passes. */
static int png_set_transforms(png_structp png, png_infop info)
{
    int color = png_get_color_type(png, info);
    int depth = png_get_bit_depth(png, info);
    if (color == PNG_COLOR_TYPE_PALETTE)
        png_set_palette_to_rgb(png);
    if (color == PNG_COLOR_TYPE_GRAY && depth < 8)
        png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS))
        png_set_tRNS_to_alpha(png);
    if (depth == 16 && !png_keep16(png, info)) {
#if defined(PNG_READ_SCALE_16_TO_8_SUPPORTED)
        png_set_scale_16(png);
#else
        png_set_strip_16(png);
#endif
    }
    int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    return passes;
}

/* Reads the pixels into lum (and alpha): an interlaced image whole into buf (rows[] pointing
 * into it: libpng fills it over 7 passes), else row by row through buf. */
static void png_read_pixels(png_structp png, int passes, uint8_t *buf, png_bytep *rows, size_t rowbytes,
                            int channels, size_t w, size_t h, uint8_t *lum, uint8_t *alpha, uint16_t *lum16)
{
    if (passes > 1) {
        for (size_t y = 0; y < h; y++)
            rows[y] = buf + y * rowbytes;
        png_read_image(png, rows);
    }
    for (size_t y = 0; y < h; y++) {
        const uint8_t *src = passes > 1 ? rows[y] : buf;
        if (passes <= 1)
            png_read_row(png, buf, NULL);
        if (lum16)
            to_luminance_row16(src, channels, w, lum + y * w, lum16 + y * w);
        else
            to_luminance_row(src, channels, w, lum + y * w, alpha ? alpha + y * w : NULL);
    }
}

/* libpng's read and info structs, reporting through ctx; -1 (reported) out of memory. */
static int png_create(png_ctx *ctx, const char *path, png_structp *out_png, png_infop *out_info)
{
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, ctx, png_err_fn, png_warn_fn);
    if (png == NULL) {
        tool_error(path, "out of memory (libpng)");
        return -1;
    }
    png_infop info = png_create_info_struct(png);
    if (info == NULL) {
        png_destroy_read_struct(&png, NULL, NULL);
        tool_error(path, "out of memory (libpng)");
        return -1;
    }
    *out_png = png;
    *out_info = info;
    return 0;
}

/* Reading through ctx's file, with the tool's limits instead of libpng's. Every ancillary chunk
 * but tRNS is skipped unread (none changes the luminance read here): libpng would otherwise
 * allocate what a text or profile chunk claims, up to 2 GiB, before finding the file ends
 * (fuzz_png: a 130-byte file with a 2 GB tEXt chunk; its "chunk data is too large" check is a
 * warning on read, so the chunk size limit alone does not stop it). */
static void png_set_input(png_structp png, png_ctx *ctx)
{
    png_set_read_fn(png, ctx, png_read_fn);
    png_set_user_limits(png, 0x7fffffffu, 0x7fffffffu); /* our own limits are checked in png_decode */
#if defined(PNG_HANDLE_AS_UNKNOWN_SUPPORTED)
    png_set_keep_unknown_chunks(png, PNG_HANDLE_CHUNK_NEVER, NULL, -1);
#endif
#if defined(PNG_SET_USER_LIMITS_SUPPORTED)
    png_set_chunk_malloc_max(png, PNG_CHUNK_MAX_BYTES);
    png_set_chunk_cache_max(png, PNG_CHUNK_MAX_COUNT);
#endif
}

/* The luminance and alpha planes and the read buffer (the whole image when interlaced), into ctx;
 * longjmps when out of memory. */
static void png_alloc(png_structp png, png_ctx *ctx, png_uint_32 w, png_uint_32 h, int passes, size_t rowbytes,
                      int has_alpha, int keep16)
{
    size_t npix = (size_t)w * (size_t)h;
    ctx->lum = malloc(npix);
    if (has_alpha)
        ctx->alpha = malloc(npix);
    if (keep16)
        ctx->lum16 = malloc(npix * sizeof *ctx->lum16);
    if (ctx->lum == NULL || (has_alpha && ctx->alpha == NULL) || (keep16 && ctx->lum16 == NULL)) {
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory for %u x %u pixels", (unsigned)w, (unsigned)h);
        png_longjmp(png, 1);
    }
    if (passes > 1 && rowbytes > SIZE_MAX / h) {
        snprintf(ctx->msg, sizeof ctx->msg, "image too large");
        png_longjmp(png, 1);
    }
    ctx->buf = malloc(passes > 1 ? rowbytes * h : rowbytes);
    if (passes > 1)
        ctx->rows = malloc(sizeof(png_bytep) * h);
    if (ctx->buf == NULL || (passes > 1 && ctx->rows == NULL)) {
        if (passes > 1)
            snprintf(ctx->msg, sizeof ctx->msg, "out of memory for %u x %u pixels", (unsigned)w, (unsigned)h);
        else
            snprintf(ctx->msg, sizeof ctx->msg, "out of memory");
        png_longjmp(png, 1);
    }
}

/* Deflate's largest compression ratio (a 258-byte match coded in 2 bits). */
#define PNG_DEFLATE_MAX_RATIO 1032.0

/* A file too small to hold the header's image even at deflate's largest ratio is truncated:
 * refused before the pixels are allocated (an 8 KB file claiming 2^28 pixels would otherwise
 * make the decoder take and fill gigabytes before it finds the data missing). */
static int png_check_data_size(png_structp png, png_infop info, const png_ctx *ctx, const char *path)
{
    if (ctx->file_size == 0)
        return 0;
    double bits = (double)png_get_bit_depth(png, info) * (double)png_get_channels(png, info);
    double w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    double raw = h * ceil(w * bits / 8.0); /* filtered rows without their filter bytes */
    if ((double)ctx->file_size * PNG_DEFLATE_MAX_RATIO >= raw)
        return 0;
    tool_error(path, "truncated PNG: %.0f x %.0f pixels need at least %.0f bytes of compressed data, the file has %zu",
               w, h, ceil(raw / PNG_DEFLATE_MAX_RATIO), ctx->file_size);
    return -1;
}

/* The image after the signature: header, size limits, conversion to 8-bit luminance (and
 * alpha), pixels, alpha policy; longjmps on any failure (ctx says why). */
static void png_decode(png_structp png, png_infop info, png_ctx *ctx, const char *path, tool_image *out)
{
    png_read_info(png, info);
    png_uint_32 w = png_get_image_width(png, info);
    png_uint_32 h = png_get_image_height(png, info);
    if (check_limits(path, "PNG", w, h) != 0 || png_check_data_size(png, info, ctx, path) != 0) {
        ctx->limit_failed = 1;
        png_longjmp(png, 1);
    }
    int keep16 = png_keep16(png, info);
    int passes = png_set_transforms(png, info);
    int channels = png_get_channels(png, info);
    size_t rowbytes = png_get_rowbytes(png, info), bps = keep16 ? 2 : 1;
    if (png_get_bit_depth(png, info) != 8 * (int)bps || channels < 1 || channels > 4 ||
        rowbytes != (size_t)w * (size_t)channels * bps) {
        snprintf(ctx->msg, sizeof ctx->msg, "unexpected pixel layout after conversion");
        png_longjmp(png, 1);
    }
    int has_alpha = channels == 2 || channels == 4;
    png_alloc(png, ctx, w, h, passes, rowbytes, has_alpha, keep16);
    png_read_pixels(png, passes, ctx->buf, ctx->rows, rowbytes, channels, w, h, ctx->lum, ctx->alpha, ctx->lum16);
    /* The image data is complete; the chunks after it are not needed. */
    if (has_alpha)
        apply_alpha(ctx->lum, ctx->alpha, (size_t)w * (size_t)h);
    free(ctx->alpha);
    free(ctx->buf);
    free(ctx->rows);
    ctx->alpha = NULL;
    ctx->buf = NULL;
    ctx->rows = NULL;
    out->pix = ctx->lum;
    out->pix16 = ctx->lum16;
    out->width = w;
    out->height = h;
    ctx->lum = NULL;
    ctx->lum16 = NULL;
}

static int read_png(FILE *fp, const char *path, tool_image *out)
{
    if (png_check_ihdr(fp, path) != 0)
        return -1;
    png_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.fp = fp;
    struct stat st;
    if (fstat(fileno(fp), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0)
        ctx.file_size = (size_t)st.st_size;
    png_structp png;
    png_infop info;
    if (png_create(&ctx, path, &png, &info) != 0)
        return -1;
    if (setjmp(png_jmpbuf(png))) {
        free(ctx.lum);
        free(ctx.lum16);
        free(ctx.alpha);
        free(ctx.buf);
        free(ctx.rows);
        png_destroy_read_struct(&png, &info, NULL);
        if (!ctx.limit_failed) {
            if (ctx.truncated)
                tool_error(path, "truncated PNG: unexpected end of file");
            else
                tool_error(path, "corrupt PNG: %s", ctx.msg[0] ? ctx.msg : "unknown error");
        }
        return -1;
    }
    png_set_input(png, &ctx);
    png_decode(png, info, &ctx, path, out);
    png_destroy_read_struct(&png, &info, NULL);
    return 0;
}
#endif /* AMSCR_TOOL_HAVE_PNG */

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

/* Opens `path` for reading after checking it is a non-empty regular file. */
static FILE *open_input(const char *path)
{
    struct stat st;
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
    if (S_ISREG(st.st_mode) && st.st_size == 0) {
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

int image_read(const char *path, int text_ok, tool_image *out, tool_format *out_format)
{
    out->pix = NULL;
    out->pix16 = NULL;
    out->width = out->height = 0;
    *out_format = TOOL_FMT_TEXT;
    FILE *fp = open_input(path);
    if (fp == NULL)
        return -1;
    unsigned char m[512];
    size_t n = fread(m, 1, sizeof m, fp);
    if (n == 0) {
        fclose(fp);
        tool_error(path, "empty file");
        return -1;
    }
    const char *other;
    tool_format f = sniff(m, n, &other);
    *out_format = f;
    if (f == TOOL_FMT_TEXT) {
        fclose(fp);
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
    rewind(fp);
    int r;
    if (f == TOOL_FMT_PGM) {
        r = read_pgm(fp, path, m[1] == '2', out);
    } else {
#if defined(AMSCR_TOOL_HAVE_PNG)
        r = read_png(fp, path, out);
#else
        tool_error(path, "PNG input is not available: amscr was built without libpng");
        r = -1;
#endif
    }
    fclose(fp);
    if (r < 0)
        image_free(out);
    return r;
}

/* ============================================================ shapes */
static int trace_flags; /* set once by the option parser (--pixel-chain), before any tracing */

void image_set_trace_flags(int flags) { trace_flags = flags; }

int image_trace_flags(void) { return trace_flags; }

double image_level(const tool_image *img, int threshold, int *out_bits, const void **out_pixels)
{
    *out_bits = img->pix16 ? 16 : 8;
    *out_pixels = img->pix16 ? (const void *)img->pix16 : (const void *)img->pix;
    if (threshold == AMSCR_THRESHOLD_AUTO)
        return AMSCR_LEVEL_AUTO;
    return img->pix16 ? (threshold + 0.5) * 257.0 : threshold + 0.5;
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
        /* Not an image: a text point list. */
        amscr_status st = amscr_contour_read_text(path, out);
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
        char thr[32];
        if (threshold == AMSCR_THRESHOLD_AUTO)
            snprintf(thr, sizeof thr, "auto");
        else
            snprintf(thr, sizeof thr, "%d", threshold);
        switch (st) {
        case AMSCR_E_NOT_FOUND:
            if (d[0])
                tool_error(path, "no foreground shape: %s", d);
            else
                tool_error(path, "no foreground shape at threshold %s", thr);
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
