/* draw.c — overlay (PNG/SVG) and scale-selection plot (SVG) of the amscr tool.
 *
 * PNG output: an RGB raster, anti-aliased lines from per-layer coverage buffers, a
 * built-in 5x7 bitmap font for the legend; written with libpng when the tool has it,
 * otherwise as an uncompressed (stored-deflate) PNG. */
#include "draw.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "raster.h"
#include "util.h"

#if defined(AMSCR_TOOL_HAVE_PNG)
#include <png.h>
#include <setjmp.h>
#endif

/* Colours: target (grey fill, dark outline), source before (blue, dashed), after (red). */
static const unsigned char COL_TARGET_FILL[3] = {0xdd, 0xdd, 0xdd};
static const unsigned char COL_TARGET[3] = {0x33, 0x33, 0x33};
static const unsigned char COL_BEFORE[3] = {0x1f, 0x77, 0xb4};
static const unsigned char COL_AFTER[3] = {0xd6, 0x27, 0x28};
#define SVG_TARGET_FILL "#dddddd"
#define SVG_TARGET "#333333"
#define SVG_BEFORE "#1f77b4"
#define SVG_AFTER "#d62728"

int draw_overlay_ext_ok(const char *path)
{
    char ext[16];
    path_ext(path, ext);
    return strcmp(ext, ".png") == 0 || strcmp(ext, ".svg") == 0;
}

/* ============================================================ geometry */
typedef struct layout {
    double scale, ox, oy; /* canvas = (p - min) * scale + o */
    double minx, miny;
    int width, height;
    int legend_h;
} layout;

static void bbox_add(const double *xy, size_t n, double *mnx, double *mny, double *mxx, double *mxy)
{
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        if (!isfinite(x) || !isfinite(y))
            continue;
        if (x < *mnx) *mnx = x;
        if (x > *mxx) *mxx = x;
        if (y < *mny) *mny = y;
        if (y > *mxy) *mxy = y;
    }
}

static void make_layout(const overlay_input *in, layout *L)
{
    double mnx = DBL_MAX, mny = DBL_MAX, mxx = -DBL_MAX, mxy = -DBL_MAX;
    bbox_add(in->target, in->nt, &mnx, &mny, &mxx, &mxy);
    bbox_add(in->before, in->nb, &mnx, &mny, &mxx, &mxy);
    bbox_add(in->after, in->na, &mnx, &mny, &mxx, &mxy);
    if (mnx > mxx) { mnx = mny = 0; mxx = mxy = 1; }
    double bw = mxx - mnx, bh = mxy - mny;
    if (bw <= 0) bw = 1;
    if (bh <= 0) bh = 1;
    const double margin = 24, maxw = 640, maxh = 560;
    double s = maxw / bw;
    if (bh * s > maxh)
        s = maxh / bh;
    L->scale = s;
    L->minx = mnx;
    L->miny = mny;
    L->legend_h = 4 * 20 + 16;
    double cw = bw * s + 2 * margin;
    if (cw < 420) cw = 420;
    L->width = (int)ceil(cw);
    L->ox = (L->width - bw * s) / 2.0;
    L->oy = L->legend_h + margin;
    L->height = (int)ceil(L->legend_h + bh * s + 2 * margin);
}

static void to_canvas(const layout *L, double x, double y, double *cx, double *cy)
{
    *cx = (x - L->minx) * L->scale + L->ox;
    *cy = (y - L->miny) * L->scale + L->oy;
}

/* ============================================================ raster (raster.h) */
void cov_clear(raster *r) { memset(r->cov, 0, sizeof(float) * (size_t)r->w * (size_t)r->h); }

void cov_composite(raster *r, const unsigned char col[3])
{
    size_t n = (size_t)r->w * (size_t)r->h;
    for (size_t i = 0; i < n; i++) {
        float c = r->cov[i];
        if (c <= 0.f)
            continue;
        for (int k = 0; k < 3; k++)
            r->rgb[3 * i + k] = r->rgb[3 * i + k] * (1.f - c) + (float)col[k] * c;
    }
}

/* A pixel index in 0..n-1 from a double (NaN -> 0). */
static int clamp_px(double v, int n)
{
    if (!(v > 0))
        return 0;
    if (v > n - 1)
        return n - 1;
    return (int)v;
}

/* Thick anti-aliased polyline into the coverage buffer; dash = {on, off} in pixels or NULL. */
void cov_polyline(raster *r, const double *cxy, size_t n, int closed, double width, const double *dash)
{
    if (n < 2)
        return;
    double hw = width / 2.0, s0 = 0.0;
    size_t nseg = closed ? n : n - 1;
    for (size_t i = 0; i < nseg; i++) {
        double x0 = cxy[2 * i], y0 = cxy[2 * i + 1];
        double x1 = cxy[2 * ((i + 1) % n)], y1 = cxy[2 * ((i + 1) % n) + 1];
        double dx = x1 - x0, dy = y1 - y0, len2 = dx * dx + dy * dy, len = sqrt(len2);
        if (!isfinite(len2))
            continue; /* never cast a non-finite or huge coordinate to int */
        int xa = clamp_px(floor(fmin(x0, x1) - hw - 1), r->w), xb = clamp_px(ceil(fmax(x0, x1) + hw + 1), r->w);
        int ya = clamp_px(floor(fmin(y0, y1) - hw - 1), r->h), yb = clamp_px(ceil(fmax(y0, y1) + hw + 1), r->h);
        for (int y = ya; y <= yb; y++) {
            for (int x = xa; x <= xb; x++) {
                double px = x + 0.5, py = y + 0.5, t = 0.0;
                if (len2 > 0) {
                    t = ((px - x0) * dx + (py - y0) * dy) / len2;
                    if (t < 0) t = 0;
                    if (t > 1) t = 1;
                }
                double ex = x0 + t * dx - px, ey = y0 + t * dy - py;
                double d = sqrt(ex * ex + ey * ey);
                double c = hw + 0.5 - d;
                if (c <= 0)
                    continue;
                if (c > 1)
                    c = 1;
                if (dash != NULL) {
                    double s = fmod(s0 + t * len, dash[0] + dash[1]);
                    if (s > dash[0])
                        continue;
                }
                float *cv = &r->cov[(size_t)y * (size_t)r->w + (size_t)x];
                if ((float)c > *cv)
                    *cv = (float)c;
            }
        }
        s0 += len;
    }
}

/* Even-odd polygon fill (4x vertical supersampling for soft edges). */
void cov_fill(raster *r, const double *cxy, size_t n)
{
    if (n < 3)
        return;
    double *xs = malloc(sizeof(double) * n);
    if (xs == NULL)
        return;
    const int sub = 4;
    for (int y = 0; y < r->h; y++) {
        for (int s = 0; s < sub; s++) {
            double py = y + (s + 0.5) / sub;
            size_t m = 0;
            for (size_t i = 0; i < n; i++) {
                double x0 = cxy[2 * i], y0 = cxy[2 * i + 1];
                double x1 = cxy[2 * ((i + 1) % n)], y1 = cxy[2 * ((i + 1) % n) + 1];
                if ((y0 <= py && y1 > py) || (y1 <= py && y0 > py))
                    xs[m++] = x0 + (py - y0) / (y1 - y0) * (x1 - x0);
            }
            /* insertion sort: m is small per row */
            for (size_t i = 1; i < m; i++) {
                double v = xs[i];
                size_t j = i;
                while (j > 0 && xs[j - 1] > v) {
                    xs[j] = xs[j - 1];
                    j--;
                }
                xs[j] = v;
            }
            for (size_t i = 0; i + 1 < m; i += 2) {
                if (!isfinite(xs[i]) || !isfinite(xs[i + 1]) || xs[i + 1] < 0.5 || xs[i] > r->w)
                    continue;
                int xa = clamp_px(ceil(xs[i] - 0.5), r->w), xb = clamp_px(floor(xs[i + 1] - 0.5), r->w);
                for (int x = xa; x <= xb; x++)
                    r->cov[(size_t)y * (size_t)r->w + (size_t)x] += 1.0f / sub;
            }
        }
    }
    free(xs);
}

/* ------------------------------------------------------------ 5x7 font */
typedef struct glyph {
    char c;
    const char *rows; /* 7 rows of 5, '#' = on */
} glyph;

static const glyph FONT[] = {
    {'a', ".....\0.....\0.###.\0....#\0.####\0#...#\0.####"},
    {'b', "#....\0#....\0####.\0#...#\0#...#\0#...#\0####."},
    {'c', ".....\0.....\0.###.\0#....\0#....\0#...#\0.###."},
    {'d', "....#\0....#\0.####\0#...#\0#...#\0#...#\0.####"},
    {'e', ".....\0.....\0.###.\0#...#\0#####\0#....\0.###."},
    {'f', "..##.\0.#..#\0.#...\0###..\0.#...\0.#...\0.#..."},
    {'g', ".....\0.####\0#...#\0#...#\0.####\0....#\0.###."},
    {'h', "#....\0#....\0#.##.\0##..#\0#...#\0#...#\0#...#"},
    {'i', "..#..\0.....\0.##..\0..#..\0..#..\0..#..\0.###."},
    {'j', "...#.\0.....\0..##.\0...#.\0...#.\0#..#.\0.##.."},
    {'k', "#....\0#....\0#..#.\0#.#..\0##...\0#.#..\0#..#."},
    {'l', ".##..\0..#..\0..#..\0..#..\0..#..\0..#..\0.###."},
    {'m', ".....\0.....\0##.#.\0#.#.#\0#.#.#\0#...#\0#...#"},
    {'n', ".....\0.....\0#.##.\0##..#\0#...#\0#...#\0#...#"},
    {'o', ".....\0.....\0.###.\0#...#\0#...#\0#...#\0.###."},
    {'p', ".....\0.....\0####.\0#...#\0####.\0#....\0#...."},
    {'q', ".....\0.....\0.####\0#...#\0.####\0....#\0....#"},
    {'r', ".....\0.....\0#.##.\0##..#\0#....\0#....\0#...."},
    {'s', ".....\0.....\0.####\0#....\0.###.\0....#\0####."},
    {'t', ".#...\0.#...\0###..\0.#...\0.#...\0.#..#\0..##."},
    {'u', ".....\0.....\0#...#\0#...#\0#...#\0#..##\0.##.#"},
    {'v', ".....\0.....\0#...#\0#...#\0#...#\0.#.#.\0..#.."},
    {'w', ".....\0.....\0#...#\0#...#\0#.#.#\0#.#.#\0.#.#."},
    {'x', ".....\0.....\0#...#\0.#.#.\0..#..\0.#.#.\0#...#"},
    {'y', ".....\0.....\0#...#\0#...#\0.####\0....#\0.###."},
    {'z', ".....\0.....\0#####\0...#.\0..#..\0.#...\0#####"},
    {'0', ".###.\0#...#\0#..##\0#.#.#\0##..#\0#...#\0.###."},
    {'1', "..#..\0.##..\0..#..\0..#..\0..#..\0..#..\0.###."},
    {'2', ".###.\0#...#\0....#\0...#.\0..#..\0.#...\0#####"},
    {'3', "#####\0...#.\0..#..\0...#.\0....#\0#...#\0.###."},
    {'4', "...#.\0..##.\0.#.#.\0#..#.\0#####\0...#.\0...#."},
    {'5', "#####\0#....\0####.\0....#\0....#\0#...#\0.###."},
    {'6', "..##.\0.#...\0#....\0####.\0#...#\0#...#\0.###."},
    {'7', "#####\0....#\0...#.\0..#..\0.#...\0.#...\0.#..."},
    {'8', ".###.\0#...#\0#...#\0.###.\0#...#\0#...#\0.###."},
    {'9', ".###.\0#...#\0#...#\0.####\0....#\0...#.\0.##.."},
    {' ', ".....\0.....\0.....\0.....\0.....\0.....\0....."},
    {'.', ".....\0.....\0.....\0.....\0.....\0.##..\0.##.."},
    {',', ".....\0.....\0.....\0.....\0.##..\0..#..\0.#..."},
    {'-', ".....\0.....\0.....\0#####\0.....\0.....\0....."},
    {'+', ".....\0..#..\0..#..\0#####\0..#..\0..#..\0....."},
    {'=', ".....\0.....\0#####\0.....\0#####\0.....\0....."},
    {':', ".....\0.##..\0.##..\0.....\0.##..\0.##..\0....."},
    {'(', "...#.\0..#..\0.#...\0.#...\0.#...\0..#..\0...#."},
    {')', ".#...\0..#..\0...#.\0...#.\0...#.\0..#..\0.#..."},
    {'/', ".....\0....#\0...#.\0..#..\0.#...\0#....\0....."},
    {'_', ".....\0.....\0.....\0.....\0.....\0.....\0#####"},
    {'%', "##...\0##..#\0...#.\0..#..\0.#...\0#..##\0...##"},
    {'?', ".###.\0#...#\0....#\0...#.\0..#..\0.....\0..#.."},
};

static const char *glyph_rows(char c)
{
    if (c >= 'A' && c <= 'Z')
        c = (char)(c - 'A' + 'a');
    for (size_t i = 0; i < sizeof FONT / sizeof FONT[0]; i++)
        if (FONT[i].c == c)
            return FONT[i].rows;
    return glyph_rows('?');
}

/* Draws text with its top-left at (x, y), pixel size `px` per font dot. */
void raster_text(raster *r, int x, int y, const char *text, int px, const unsigned char col[3])
{
    for (const char *t = text; *t; t++, x += 6 * px) {
        const char *rows = glyph_rows(*t);
        for (int gy = 0; gy < 7; gy++) {
            const char *row = rows + 6 * gy;
            for (int gx = 0; gx < 5; gx++) {
                if (row[gx] != '#')
                    continue;
                for (int yy = 0; yy < px; yy++)
                    for (int xx = 0; xx < px; xx++) {
                        int X = x + gx * px + xx, Y = y + gy * px + yy;
                        if (X < 0 || Y < 0 || X >= r->w || Y >= r->h)
                            continue;
                        float *p = &r->rgb[3 * ((size_t)Y * (size_t)r->w + (size_t)X)];
                        p[0] = col[0];
                        p[1] = col[1];
                        p[2] = col[2];
                    }
            }
        }
    }
}

/* ------------------------------------------------------------ PNG writing */
static uint32_t crc_table[256];
static int crc_ready;

static uint32_t crc32_update(uint32_t crc, const unsigned char *buf, size_t len)
{
    if (!crc_ready) {
        for (uint32_t n = 0; n < 256; n++) {
            uint32_t c = n;
            for (int k = 0; k < 8; k++)
                c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
            crc_table[n] = c;
        }
        crc_ready = 1;
    }
    crc = ~crc;
    for (size_t i = 0; i < len; i++)
        crc = crc_table[(crc ^ buf[i]) & 0xff] ^ (crc >> 8);
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
        tool_out_abort(&o);
        tool_error(path, "cannot encode the PNG picture");
        return -1;
    }
    return tool_out_commit(&o);
}

/* ============================================================ overlay */
static double *map_points(const layout *L, const double *xy, size_t n)
{
    double *c = xmalloc_array(n ? 2 * n : 2, sizeof(double));
    if (c == NULL)
        return NULL;
    for (size_t i = 0; i < n; i++)
        to_canvas(L, xy[2 * i], xy[2 * i + 1], &c[2 * i], &c[2 * i + 1]);
    return c;
}

static int overlay_png(const char *path, const overlay_input *in, const layout *L)
{
    raster r;
    r.w = L->width;
    r.h = L->height;
    size_t npix = (size_t)r.w * (size_t)r.h;
    r.rgb = xmalloc_array(npix * 3, sizeof(float));
    r.cov = xmalloc_array(npix, sizeof(float));
    double *ct = map_points(L, in->target, in->nt);
    double *cb = map_points(L, in->before, in->nb);
    double *ca = map_points(L, in->after, in->na);
    unsigned char *out = xmalloc_array(npix, 3);
    int ret = -1;
    if (!r.rgb || !r.cov || !ct || !cb || !ca || !out)
        goto done;
    for (size_t i = 0; i < 3 * npix; i++)
        r.rgb[i] = 255.f;
    if (in->closed) {
        cov_clear(&r);
        cov_fill(&r, ct, in->nt);
        cov_composite(&r, COL_TARGET_FILL);
    }
    cov_clear(&r);
    cov_polyline(&r, ct, in->nt, in->closed, 2.0, NULL);
    cov_composite(&r, COL_TARGET);
    const double dash[2] = {7.0, 5.0};
    cov_clear(&r);
    cov_polyline(&r, cb, in->nb, in->closed, 2.0, dash);
    cov_composite(&r, COL_BEFORE);
    cov_clear(&r);
    cov_polyline(&r, ca, in->na, in->closed, 2.0, NULL);
    cov_composite(&r, COL_AFTER);

    /* legend */
    static const unsigned char black[3] = {0x22, 0x22, 0x22};
    const char *labels[3] = {"target", "source (before)", "source registered (after)"};
    const unsigned char *cols[3] = {COL_TARGET, COL_BEFORE, COL_AFTER};
    const char *names[3] = {in->target_name, in->source_name, in->source_name};
    for (int k = 0; k < 3; k++) {
        double y = 14 + 20 * k + 7;
        double seg[4] = {14, y, 54, y};
        cov_clear(&r);
        cov_polyline(&r, seg, 2, 0, 3.0, k == 1 ? dash : NULL);
        cov_composite(&r, cols[k]);
        char line[160];
        snprintf(line, sizeof line, "%s: %s", labels[k], names[k] ? path_base(names[k]) : "");
        raster_text(&r, 64, (int)y - 7, line, 2, black);
    }
    if (in->caption)
        raster_text(&r, 14, 14 + 60, in->caption, 2, black);
    ret = raster_write_png(&r, out, path);
done:
    free(r.rgb);
    free(r.cov);
    free(ct);
    free(cb);
    free(ca);
    free(out);
    return ret;
}

void svg_escape(sbuf *b, const char *s)
{
    for (; s && *s; s++) {
        switch (*s) {
        case '<': sb_puts(b, "&lt;"); break;
        case '>': sb_puts(b, "&gt;"); break;
        case '&': sb_puts(b, "&amp;"); break;
        case '"': sb_puts(b, "&quot;"); break;
        default: {
            char c[2] = {*s, 0};
            sb_puts(b, c);
        }
        }
    }
}

static void svg_poly(sbuf *b, const layout *L, const double *xy, size_t n, int closed, const char *stroke,
                     const char *fill, const char *extra)
{
    sb_printf(b, "<%s fill=\"%s\" stroke=\"%s\" stroke-width=\"2\" stroke-linejoin=\"round\"%s points=\"",
              closed ? "polygon" : "polyline", fill, stroke, extra ? extra : "");
    for (size_t i = 0; i < n; i++) {
        double cx, cy;
        to_canvas(L, xy[2 * i], xy[2 * i + 1], &cx, &cy);
        sb_printf(b, "%s%.2f,%.2f", i ? " " : "", cx, cy);
    }
    sb_puts(b, "\"/>\n");
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
        tool_out_abort(&o);
        tool_error(path, "write error");
        return -1;
    }
    return tool_out_commit(&o);
}

static int overlay_svg(const char *path, const overlay_input *in, const layout *L)
{
    sbuf b;
    sb_init(&b);
    sb_printf(&b,
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
              "font-family=\"sans-serif\" font-size=\"14\">\n"
              "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
              L->width, L->height, L->width, L->height);
    svg_poly(&b, L, in->target, in->nt, in->closed, SVG_TARGET, in->closed ? SVG_TARGET_FILL : "none", NULL);
    svg_poly(&b, L, in->before, in->nb, in->closed, SVG_BEFORE, "none", " stroke-dasharray=\"7 5\"");
    svg_poly(&b, L, in->after, in->na, in->closed, SVG_AFTER, "none", NULL);
    const char *labels[3] = {"target", "source (before)", "source registered (after)"};
    const char *cols[3] = {SVG_TARGET, SVG_BEFORE, SVG_AFTER};
    const char *names[3] = {in->target_name, in->source_name, in->source_name};
    sb_puts(&b, "<g id=\"legend\">\n");
    for (int k = 0; k < 3; k++) {
        int y = 14 + 20 * k + 7;
        sb_printf(&b, "<line x1=\"14\" y1=\"%d\" x2=\"54\" y2=\"%d\" stroke=\"%s\" stroke-width=\"3\"%s/>\n", y, y,
                  cols[k], k == 1 ? " stroke-dasharray=\"7 5\"" : "");
        sb_printf(&b, "<text x=\"64\" y=\"%d\">", y + 5);
        svg_escape(&b, labels[k]);
        sb_puts(&b, ": ");
        svg_escape(&b, names[k] ? path_base(names[k]) : "");
        sb_puts(&b, "</text>\n");
    }
    if (in->caption) {
        sb_printf(&b, "<text x=\"14\" y=\"%d\">", 14 + 60 + 12);
        svg_escape(&b, in->caption);
        sb_puts(&b, "</text>\n");
    }
    sb_puts(&b, "</g>\n</svg>\n");
    int r = write_text_file(path, &b);
    sb_free(&b);
    return r;
}

int draw_overlay(const char *path, const overlay_input *in)
{
    layout L;
    make_layout(in, &L);
    char ext[16];
    path_ext(path, ext);
    if (strcmp(ext, ".png") == 0)
        return overlay_png(path, in, &L);
    if (strcmp(ext, ".svg") == 0)
        return overlay_svg(path, in, &L);
    tool_error(path, "unknown picture format: use a .png or .svg file name");
    return -1;
}

/* ============================================================ plot */
/* "Nice" tick step for a range. */
static double nice_step(double range, int target_ticks)
{
    if (!(range > 0) || !isfinite(range))
        return 1.0;
    double raw = range / target_ticks;
    double mag = pow(10.0, floor(log10(raw)));
    double f = raw / mag;
    double nf = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
    return nf * mag;
}

typedef struct panel {
    double x, y, w, h;    /* plotting area in SVG units */
    double x0, x1, y0, y1; /* data range */
} panel;

static double px_of(const panel *P, double v) { return P->x + (v - P->x0) / (P->x1 - P->x0) * P->w; }
static double py_of(const panel *P, double v) { return P->y + P->h - (v - P->y0) / (P->y1 - P->y0) * P->h; }

static void svg_axes(sbuf *b, const panel *P, const char *title, const char *xlabel, const char *ylabel)
{
    sb_printf(b, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#444\"/>\n",
              P->x, P->y, P->w, P->h);
    double step = nice_step(P->y1 - P->y0, 5);
    char buf[32];
    for (double v = ceil(P->y0 / step) * step; v <= P->y1 + 1e-9 * step; v += step) {
        double y = py_of(P, v);
        sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", P->x, y,
                  P->x + P->w, y);
        double vv = fabs(v) < 1e-9 * step ? 0.0 : v;
        int dec = (int)-floor(log10(step) + 1e-9);
        if (dec >= 0 && dec <= 8 && fabs(vv) < 1e5)
            snprintf(buf, sizeof buf, "%.*f", dec, vv);
        else if (dec < 0 && fabs(vv) < 1e9)
            snprintf(buf, sizeof buf, "%.0f", vv);
        else
            snprintf(buf, sizeof buf, "%.3g", vv);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" font-size=\"11\">%s</text>\n", P->x - 5,
                  y + 4, buf);
    }
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"14\" font-weight=\"bold\">",
              P->x + P->w / 2, P->y - 12);
    svg_escape(b, title);
    sb_puts(b, "</text>\n");
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"12\">", P->x + P->w / 2,
              P->y + P->h + 36);
    svg_escape(b, xlabel);
    sb_puts(b, "</text>\n");
    sb_printf(b,
              "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"12\" "
              "transform=\"rotate(-90 %.1f %.1f)\">",
              P->x - 74, P->y + P->h / 2, P->x - 74, P->y + P->h / 2);
    svg_escape(b, ylabel);
    sb_puts(b, "</text>\n");
}

/* The data range of the residual panel: the residuals and the threshold (when drawn), padded;
 * zero-based only when they spread widely. */
static void residual_range(const plot_input *in, int thr_drawn, panel *P)
{
    double ymin = INFINITY, ymax = -INFINITY;
    for (size_t k = 0; k < in->p; k++)
        if (isfinite(in->residuals[k])) {
            if (in->residuals[k] > ymax) ymax = in->residuals[k];
            if (in->residuals[k] < ymin) ymin = in->residuals[k];
        }
    if (thr_drawn) {
        if (in->threshold > ymax) ymax = in->threshold;
        if (in->threshold < ymin) ymin = in->threshold;
    }
    if (!(ymax >= ymin)) {
        ymin = 0;
        ymax = 1;
    }
    if (ymax - ymin <= 1e-12 * fabs(ymax)) {
        double h = ymax != 0 ? 0.05 * fabs(ymax) : 1.0;
        ymin -= h;
        ymax += h;
    }
    double pad = 0.08 * (ymax - ymin);
    P->y0 = ymin - pad;
    P->y1 = ymax + pad;
    if (P->y0 < 0 || ymin < 0.25 * ymax)
        P->y0 = ymin >= 0 ? 0 : P->y0;
    if (in->p <= 1) {
        P->x0 = -1;
        P->x1 = 1;
    }
}

/* Panel 1: the residual per scale, kept scales filled, the Bayes threshold dashed. */
static void residual_panel(sbuf *b, const plot_input *in)
{
    panel P = {104, 70, 356, 250, -0.5, (double)in->p - 0.5, 0, 1};
    int thr_drawn = isfinite(in->threshold) && in->threshold >= 0;
    char buf[32];
    residual_range(in, thr_drawn, &P);
    svg_axes(b, &P, "Residual per scale (eq. 13)", "scale sigma_k (samples)", "residual L2_k");
    for (size_t k = 0; k < in->p; k++) {
        double x = px_of(&P, (double)k);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%s</text>\n", x,
                  P.y + P.h + 16, fmt_num(buf, in->scales[k]));
    }
    if (in->p > 1) {
        sb_puts(b, "<polyline fill=\"none\" stroke=\"#888\" stroke-width=\"1.5\" points=\"");
        for (size_t k = 0; k < in->p; k++)
            sb_printf(b, "%s%.1f,%.1f", k ? " " : "", px_of(&P, (double)k),
                      py_of(&P, isfinite(in->residuals[k]) ? in->residuals[k] : 0));
        sb_puts(b, "\"/>\n");
    }
    if (thr_drawn) {
        double y = py_of(&P, in->threshold);
        sb_printf(b,
                  "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" stroke-width=\"1.5\" "
                  "stroke-dasharray=\"6 4\"/>\n",
                  P.x, y, P.x + P.w, y);
    } else {
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" fill=\"#d62728\" font-size=\"11\">no "
                      "threshold: every scale kept</text>\n",
                  P.x + P.w - 4, P.y + 14);
    }
    for (size_t k = 0; k < in->p; k++) {
        double x = px_of(&P, (double)k), y = py_of(&P, isfinite(in->residuals[k]) ? in->residuals[k] : 0);
        if (in->kept[k])
            sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"#2ca02c\" stroke=\"#1b6e1b\"/>\n", x, y);
        else
            sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"white\" stroke=\"#777\" "
                          "stroke-width=\"1.5\"/>\n",
                      x, y);
    }
    /* legend of panel 1 */
    double lx = P.x - 16, ly = P.y + P.h + 52;
    sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"#2ca02c\" stroke=\"#1b6e1b\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\">kept scale</text>\n",
              lx, ly, lx + 10, ly + 4);
    sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"white\" stroke=\"#777\" stroke-width=\"1.5\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\">dropped scale</text>\n",
              lx + 110, ly, lx + 120, ly + 4);
    sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" stroke-width=\"1.5\" "
                  "stroke-dasharray=\"6 4\"/><text x=\"%.1f\" y=\"%.1f\">Bayes threshold s0%s%s</text>\n",
              lx + 230, ly, lx + 260, ly, lx + 266, ly + 4, thr_drawn ? " = " : "",
              thr_drawn ? fmt_num(buf, in->threshold) : "");

}

/* Panel 2: the elbow curve SSE(K), the chosen K marked. */
static void elbow_panel(sbuf *b, const plot_input *in)
{
    panel Q = {560, 70, 360, 250, 0.5, (double)in->kmax + 0.5, 0, 1};
    int have_sse = 0;
    double smax = 0;
    for (size_t k = 0; in->sse && k < in->kmax; k++) {
        if (isfinite(in->sse[k]) && in->sse[k] > smax)
            smax = in->sse[k];
        if (in->sse[k] != 0)
            have_sse = 1;
    }
    if (in->kmax == 0) {
        Q.x0 = 0.5;
        Q.x1 = 1.5;
    }
    Q.y1 = smax > 0 ? smax * 1.1 : 1;
    svg_axes(b, &Q, "Elbow: K-means SSE(K) (eq. 14)", "number of classes K", "SSE(K)");
    for (size_t k = 1; k <= in->kmax; k++)
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%zu</text>\n",
                  px_of(&Q, (double)k), Q.y + Q.h + 16, k);
    if (!have_sse || in->kmax == 0) {
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" fill=\"#555\">no elbow: this method "
                      "does not select scales by K-means</text>\n",
                  Q.x + Q.w / 2, Q.y + Q.h / 2);
    } else {
        if (in->kmax > 1) {
            sb_printf(b,
                      "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#aaa\" stroke-dasharray=\"4 4\"/>\n",
                      px_of(&Q, 1), py_of(&Q, in->sse[0]), px_of(&Q, (double)in->kmax),
                      py_of(&Q, in->sse[in->kmax - 1]));
            sb_puts(b, "<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" points=\"");
            for (size_t k = 0; k < in->kmax; k++)
                sb_printf(b, "%s%.1f,%.1f", k ? " " : "", px_of(&Q, (double)(k + 1)), py_of(&Q, in->sse[k]));
            sb_puts(b, "\"/>\n");
        }
        for (size_t k = 0; k < in->kmax; k++) {
            double x = px_of(&Q, (double)(k + 1)), y = py_of(&Q, in->sse[k]);
            if (k + 1 == in->k)
                sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"#d62728\"/>"
                              "<text x=\"%.1f\" y=\"%.1f\" fill=\"#d62728\">K* = %zu</text>\n",
                          x, y, x + 10, y - 10, in->k);
            else
                sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"#1f77b4\"/>\n", x, y);
        }
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\">dashed: chord from K = 1 to K = %zu; K* farthest below it</text>\n",
                  Q.x + 8, Q.y + Q.h + 70, in->kmax);
    }
}

int draw_plot_svg(const char *path, const plot_input *in)
{
    sbuf b;
    sb_init(&b);
    const int W = 960, H = 400;
    sb_printf(&b,
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
              "font-family=\"sans-serif\" font-size=\"12\">\n"
              "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
              W, H, W, H);
    if (in->title) {
        sb_printf(&b, "<text x=\"%d\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">", W / 2);
        svg_escape(&b, in->title);
        sb_puts(&b, "</text>\n");
    }

    residual_panel(&b, in);
    elbow_panel(&b, in);
    sb_puts(&b, "</svg>\n");
    int r = write_text_file(path, &b);
    sb_free(&b);
    return r;
}
