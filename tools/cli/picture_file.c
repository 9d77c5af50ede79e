/* picture_file.c — the tool's pictures written to files (raster.h): PNG through libpng when the
 * tool has it, otherwise uncompressed (stored-deflate) PNG; SVG and other text; each written
 * atomically (temporary name + rename). */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"
#include "raster.h"
#include "util.h"

#if defined(AMSCR_TOOL_HAVE_PNG)
#include <png.h>
#include <setjmp.h>
#endif

/* CRC-32 of PNG chunks, bit by bit (no table: the fallback writer has no shared state). */
static uint32_t crc32_update(uint32_t crc, const unsigned char *buf, size_t len)
{
    crc = ~crc;
    for (size_t i = 0; i < len; i++) {
        crc ^= buf[i];
        for (int k = 0; k < 8; k++)
            crc = (crc & 1) ? 0xedb88320u ^ (crc >> 1) : crc >> 1;
    }
    return ~crc;
}

static void put_be32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

static void write_chunk(FILE *fp, const char *type, const unsigned char *data, size_t len)
{
    unsigned char hdr[8];
    put_be32(hdr, (uint32_t)len);
    memcpy(hdr + 4, type, 4);
    fwrite(hdr, 1, 8, fp);
    if (len)
        fwrite(data, 1, len, fp);
    uint32_t crc = crc32_update(0, hdr + 4, 4);
    crc = crc32_update(crc, data, len);
    unsigned char c[4];
    put_be32(c, crc);
    fwrite(c, 1, 4, fp);
}

/* Uncompressed PNG (zlib stored blocks): used when the tool is built without libpng. */
static int write_png_stored(FILE *fp, const unsigned char *rgb, int w, int h)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
    fwrite(sig, 1, 8, fp);
    unsigned char ihdr[13];
    put_be32(ihdr, (uint32_t)w);
    put_be32(ihdr + 4, (uint32_t)h);
    ihdr[8] = 8;  /* depth */
    ihdr[9] = 2;  /* RGB */
    ihdr[10] = 0;
    ihdr[11] = 0;
    ihdr[12] = 0;
    write_chunk(fp, "IHDR", ihdr, 13);
    size_t rowlen = (size_t)w * 3 + 1, raw = rowlen * (size_t)h;
    size_t nblocks = (raw + 65534) / 65535;
    size_t zlen = 2 + raw + 5 * nblocks + 4;
    unsigned char *z = malloc(zlen);
    unsigned char *flat = malloc(raw);
    if (z == NULL || flat == NULL) {
        free(z);
        free(flat);
        return -1;
    }
    for (int y = 0; y < h; y++) {
        flat[(size_t)y * rowlen] = 0;
        memcpy(flat + (size_t)y * rowlen + 1, rgb + (size_t)y * (size_t)w * 3, (size_t)w * 3);
    }
    size_t o = 0;
    z[o++] = 0x78;
    z[o++] = 0x01;
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < raw; i++) {
        a = (a + flat[i]) % 65521u;
        b = (b + a) % 65521u;
    }
    for (size_t pos = 0; pos < raw || (raw == 0 && pos == 0);) {
        size_t len = raw - pos > 65535 ? 65535 : raw - pos;
        z[o++] = (unsigned char)(pos + len >= raw ? 1 : 0);
        z[o++] = (unsigned char)(len & 0xff);
        z[o++] = (unsigned char)(len >> 8);
        z[o++] = (unsigned char)(~len & 0xff);
        z[o++] = (unsigned char)((~len >> 8) & 0xff);
        memcpy(z + o, flat + pos, len);
        o += len;
        pos += len;
        if (raw == 0)
            break;
    }
    put_be32(z + o, (b << 16) | a);
    o += 4;
    write_chunk(fp, "IDAT", z, o);
    write_chunk(fp, "IEND", NULL, 0);
    free(z);
    free(flat);
    return 0;
}

#if defined(AMSCR_TOOL_HAVE_PNG)
static void png_w_err(png_structp png, png_const_charp msg)
{
    (void)msg;
    png_longjmp(png, 1);
}
static void png_w_warn(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static int write_png_lib(FILE *fp, const unsigned char *rgb, int w, int h)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, png_w_err, png_w_warn);
    if (png == NULL)
        return -1;
    png_infop info = png_create_info_struct(png);
    if (info == NULL) {
        png_destroy_write_struct(&png, NULL);
        return -1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_init_io(png, fp);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < h; y++)
        png_write_row(png, (png_const_bytep)(rgb + (size_t)y * (size_t)w * 3));
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return 0;
}
#endif

int raster_write_png(const raster *r, unsigned char *out, const char *path)
{
    size_t n = 3 * (size_t)r->w * (size_t)r->h;
    for (size_t i = 0; i < n; i++) {
        float v = r->rgb[i];
        out[i] = (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : (int)(v + 0.5f));
    }
    return write_png_file(path, out, r->w, r->h);
}

int write_png_file(const char *path, const unsigned char *rgb, int w, int h)
{
    tool_out o;
    if (tool_out_open(&o, path) != 0)
        return -1;
    int r;
#if defined(AMSCR_TOOL_HAVE_PNG)
    r = write_png_lib(o.fp, rgb, w, h);
#else
    r = write_png_stored(o.fp, rgb, w, h);
#endif
    (void)write_png_stored; /* referenced in both builds */
    if (r != 0) {
        int e = ferror(o.fp) ? errno : 0; /* a failed write, else the encoder's failure */
        tool_out_abort(&o);
        if (e)
            tool_error(path, "cannot write the PNG picture: %s", strerror(e));
        else
            tool_error(path, "cannot encode the PNG picture");
        return -1;
    }
    return tool_out_commit(&o);
}

/* One byte of SVG text. A stray byte (a name that is not UTF-8: a file name is bytes) is U+FFFD,
 * the replacement character, so the SVG stays UTF-8. */
static void svg_byte(sbuf *b, unsigned char c, int stray)
{
    if (stray) {
        sb_puts(b, "\xef\xbf\xbd");
        return;
    }
    switch (c) {
    case '<': sb_puts(b, "&lt;"); break;
    case '>': sb_puts(b, "&gt;"); break;
    case '&': sb_puts(b, "&amp;"); break;
    case '"': sb_puts(b, "&quot;"); break;
    default:
        if (c < 0x20 || c == 0x7f) /* not allowed in XML 1.0 (or lost as white space): its control
                                    * picture, U+2400+c (DEL U+2421) */
            sb_printf(b, "&#x%x;", c == 0x7f ? 0x2421u : 0x2400u + c);
        else {
            char one[2] = {(char)c, 0};
            sb_puts(b, one);
        }
    }
}

void svg_escape(sbuf *b, const char *s)
{
    sb_utf8_each(b, s, svg_byte);
}

void svg_escape_max(sbuf *b, const char *s, size_t max_chars)
{
    size_t cut = utf8_prefix(s, max_chars > 0 ? max_chars - 1 : 0);
    if (s[utf8_prefix(s, max_chars)] == '\0') {
        svg_escape(b, s);
        return;
    }
    char *head = malloc(cut + 1);
    if (head == NULL) {
        b->oom = 1;
        return;
    }
    memcpy(head, s, cut);
    head[cut] = '\0';
    svg_escape(b, head);
    sb_puts(b, "\xe2\x80\xa6"); /* U+2026, the ellipsis */
    free(head);
}

int write_text_file(const char *path, const sbuf *b)
{
    if (b->oom) {
        tool_error(path, "out of memory");
        return -1;
    }
    tool_out o;
    if (tool_out_open(&o, path) != 0)
        return -1;
    if (b->len && fwrite(b->s, 1, b->len, o.fp) != b->len) {
        int e = errno;
        tool_out_abort(&o);
        tool_error(path, "write error: %s", strerror(e));
        return -1;
    }
    return tool_out_commit(&o);
}
