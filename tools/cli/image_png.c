/* image_png.c — PNG decoding through libpng for the amscr tool (image_codec.h).
 *
 * Luminance conversion:
 *   - gray: as is; 1/2/4-bit gray expanded to 0..255; 16-bit scaled (rounded) to 8 bits, and
 *     kept as 16-bit samples too (pix16) for gray and RGB without alpha and PGM maxval > 255,
 *     which the sub-pixel tracer follows;
 *   - RGB: Y = (299 R + 587 G + 114 B) / 1000 (Rec. 601 weights, on the stored values);
 *   - palette: through the palette's RGB, tRNS entries give alpha;
 * Alpha (gray+alpha, RGBA, tRNS): when every pixel has alpha >= 128 the alpha channel is
 * ignored. Otherwise transparent pixels (alpha < 128) are made background:
 *   - if most of the image border is transparent (an object cut out on a transparent
 *     background, as image editors export one), or the opaque pixels have (nearly) one colour
 *     (luminance range <= 16), the alpha channel is the silhouette: the luminance is the alpha
 *     (antialiased alpha edges keep their coverage, which the sub-pixel tracer follows), so an
 *     object of light and dark parts stays whole;
 *   - otherwise (transparent holes or corners in an opaque picture) the image is composited
 *     over a background that contrasts with the mean opaque colour (white under dark content,
 *     black under light content).
 * The polarity of the result does not matter: amscr_contour_from_mask makes the image
 * border background. */
#include "image_codec.h"

#if defined(AMSCR_TOOL_HAVE_PNG)
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "util.h"

/* The chunks libpng still reads into memory (png_set_input): at most this many bytes each and
 * this many in all (libpng's defaults in builds that set them). */
#define PNG_CHUNK_MAX_BYTES 8000000u
#define PNG_CHUNK_MAX_COUNT 1000u

/* ============================================================= alpha policy */
/* Non-zero when more than half of the border pixels of the w x h alpha plane are transparent. */
static int border_transparent(const uint8_t *alpha, size_t w, size_t h)
{
    size_t border = 0, clear = 0;
    for (size_t y = 0; y < h; y++) {
        const uint8_t *row = alpha + y * w;
        if (y == 0 || y == h - 1) {
            for (size_t x = 0; x < w; x++)
                clear += row[x] < 128;
            border += w;
        } else {
            clear += (row[0] < 128) + (w > 1 && row[w - 1] < 128);
            border += w > 1 ? 2 : 1;
        }
    }
    return 2 * clear > border;
}

static void apply_alpha(uint8_t *lum, const uint8_t *alpha, size_t w, size_t h)
{
    const size_t n = w * h;
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
    if (opaque == 0) {
        memset(lum, 0, n);
        return;
    }
    if (hi - lo <= 16 || border_transparent(alpha, w, h)) {
        memcpy(lum, alpha, n); /* the coverage: an antialiased edge stays sub-pixel */
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
        if (w > 0 && h > 0 && image_check_limits(path, "PNG", w, h) != 0)
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
    if (image_check_limits(path, "PNG", w, h) != 0 || png_check_data_size(png, info, ctx, path) != 0) {
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
        apply_alpha(ctx->lum, ctx->alpha, w, h);
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

int image_read_png(FILE *fp, const char *path, tool_image *out)
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
