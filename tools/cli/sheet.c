/* sheet.c — the contact sheet of `amscr search --sheet` (see sheet.h). */
#include "sheet.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "raster.h"
#include "util.h"

enum {
    TILE_W = 240,    /* a thumbnail and its caption: 20 characters of the 2x font */
    TILE_DRAW = 200, /* the drawing inside a tile */
    TILE_CAP = 44,   /* caption: a title line (2x font) and a file name line (1x font) */
    TILE_COLS = 4,
    NAME_CHARS = 36, /* of the file name in an SVG tile (11 px font) */
    SHEET_MARGIN = 12,
    TILE_H = TILE_W + TILE_CAP - 20 /* a row of tiles */
};

static const unsigned char FILL[3] = {0xdd, 0xdd, 0xdd}, QUERY[3] = {0x33, 0x33, 0x33},
                           HIT[3] = {0xd6, 0x27, 0x28}, GREY[3] = {0x66, 0x66, 0x66};

/* Canvas transform of one tile: canvas = (p - min) * s + o. */
typedef struct tile_map {
    double s, ox, oy, mnx, mny;
} tile_map;

static void bbox(const double *xy, size_t n, double b[4])
{
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        if (!isfinite(x) || !isfinite(y))
            continue;
        b[0] = x < b[0] ? x : b[0];
        b[1] = y < b[1] ? y : b[1];
        b[2] = x > b[2] ? x : b[2];
        b[3] = y > b[3] ? y : b[3];
    }
}

/* The transform of tile i on the sheet, or with `local` in a raster of the tile alone. */
static tile_map tile_layout(const sheet_tile *t, size_t i, int local)
{
    double b[4] = {DBL_MAX, DBL_MAX, -DBL_MAX, -DBL_MAX};
    bbox(t->base, t->nb, b);
    if (t->over)
        bbox(t->over, t->no, b);
    if (b[0] > b[2])
        b[0] = b[1] = 0, b[2] = b[3] = 1;
    double w = b[2] - b[0] > 0 ? b[2] - b[0] : 1, h = b[3] - b[1] > 0 ? b[3] - b[1] : 1;
    double s = TILE_DRAW / (w > h ? w : h);
    double x0 = local ? 0 : SHEET_MARGIN + (double)(i % TILE_COLS) * TILE_W,
           y0 = local ? 0 : SHEET_MARGIN + (double)(i / TILE_COLS) * TILE_H;
    tile_map m = {s, x0 + (TILE_W - w * s) / 2.0, y0 + 10 + (TILE_DRAW - h * s) / 2.0, b[0], b[1]};
    return m;
}

static void sheet_size(size_t n, int *w, int *h)
{
    size_t cols = n < TILE_COLS ? n : TILE_COLS, rows = (n + TILE_COLS - 1) / TILE_COLS;
    *w = (int)(2 * SHEET_MARGIN + cols * TILE_W);
    *h = (int)(2 * SHEET_MARGIN + rows * TILE_H);
}

static double *to_canvas(const tile_map *m, const double *xy, size_t n)
{
    double *c = xmalloc_array(n ? 2 * n : 2, sizeof(double));
    for (size_t i = 0; c && i < n; i++) {
        c[2 * i] = (xy[2 * i] - m->mnx) * m->s + m->ox;
        c[2 * i + 1] = (xy[2 * i + 1] - m->mny) * m->s + m->oy;
    }
    return c;
}

/* One tile into r, a raster of the tile alone (TILE_W x TILE_H). */
static int png_tile(raster *r, const sheet_tile *t, size_t i, int closed)
{
    tile_map m = tile_layout(t, i, 1);
    double *cb = to_canvas(&m, t->base, t->nb), *co = t->over ? to_canvas(&m, t->over, t->no) : NULL;
    if (cb == NULL || (t->over && co == NULL)) {
        free(cb);
        free(co);
        return -1;
    }
    if (closed) {
        cov_clear(r);
        cov_fill(r, cb, t->nb);
        cov_composite(r, FILL);
    }
    cov_clear(r);
    cov_polyline(r, cb, t->nb, closed, 1.5, NULL);
    cov_composite(r, QUERY);
    if (co) {
        cov_clear(r);
        cov_polyline(r, co, t->no, closed, 2.0, NULL);
        cov_composite(r, HIT);
    }
    int x = 8, y = 10 + TILE_DRAW + 6;
    char name[24];
    snprintf(name, sizeof name, "%.19s", t->name);
    raster_text(r, x, y, t->title, 2, t->over ? HIT : QUERY);
    raster_text(r, x, y + 18, name, 2, GREY);
    free(cb);
    free(co);
    return 0;
}

/* Each tile is drawn in a raster of its own and rounded into the sheet's bytes: a layer of the
 * whole sheet per tile took time quadratic in the hits (--top 500: minutes) and 19 bytes a
 * pixel of the sheet. */
static int sheet_png(const char *path, const sheet_tile *tiles, size_t n, int closed)
{
    int w, h;
    sheet_size(n, &w, &h);
    size_t npix = (size_t)w * (size_t)h, ntile = (size_t)TILE_W * TILE_H;
    raster r;
    r.w = TILE_W;
    r.h = TILE_H;
    r.rgb = xmalloc_array(ntile * 3, sizeof(float));
    r.cov = xmalloc_array(ntile, sizeof(float));
    unsigned char *out = xmalloc_array(npix, 3);
    int ret = -1;
    if (!r.rgb || !r.cov || !out)
        goto done;
    memset(out, 255, 3 * npix);
    for (size_t i = 0; i < n; i++) {
        for (size_t k = 0; k < 3 * ntile; k++)
            r.rgb[k] = 255.f;
        if (png_tile(&r, &tiles[i], i, closed) != 0)
            goto done;
        size_t x0 = SHEET_MARGIN + (i % TILE_COLS) * TILE_W, y0 = SHEET_MARGIN + (i / TILE_COLS) * TILE_H;
        for (size_t y = 0; y < TILE_H; y++)
            for (size_t k = 0; k < 3 * (size_t)TILE_W; k++) {
                float v = r.rgb[3 * y * TILE_W + k];
                out[3 * ((y0 + y) * (size_t)w + x0) + k] = (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : (int)(v + 0.5f));
            }
    }
    ret = write_png_file(path, out, w, h);
done:
    free(r.rgb);
    free(r.cov);
    free(out);
    return ret;
}

static void svg_points(sbuf *b, const tile_map *m, const double *xy, size_t n, int closed, const char *style)
{
    sb_printf(b, "<%s %s points=\"", closed ? "polygon" : "polyline", style);
    for (size_t i = 0; i < n; i++)
        sb_printf(b, "%s%.2f,%.2f", i ? " " : "", (xy[2 * i] - m->mnx) * m->s + m->ox,
                  (xy[2 * i + 1] - m->mny) * m->s + m->oy);
    sb_puts(b, "\"/>\n");
}

static int sheet_svg(const char *path, const sheet_tile *tiles, size_t n, int closed)
{
    int w, h;
    sheet_size(n, &w, &h);
    sbuf b;
    sb_init(&b);
    sb_printf(&b,
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
              "font-family=\"sans-serif\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
              w, h, w, h);
    for (size_t i = 0; i < n; i++) {
        const sheet_tile *t = &tiles[i];
        tile_map m = tile_layout(t, i, 0);
        sb_printf(&b, "<g class=\"%s\">\n", t->over ? "hit" : "query");
        svg_points(&b, &m, t->base, t->nb, closed,
                   closed ? "fill=\"#dddddd\" stroke=\"#333333\" stroke-width=\"1.5\"" : "fill=\"none\" stroke=\"#333333\" stroke-width=\"1.5\"");
        if (t->over)
            svg_points(&b, &m, t->over, t->no, closed, "fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\"");
        int x = SHEET_MARGIN + (int)(i % TILE_COLS) * TILE_W + 8;
        int y = SHEET_MARGIN + (int)(i / TILE_COLS) * TILE_H + 10 + TILE_DRAW + 18;
        sb_printf(&b, "<text x=\"%d\" y=\"%d\" font-size=\"15\">", x, y);
        svg_escape(&b, t->title);
        sb_printf(&b, "</text>\n<text x=\"%d\" y=\"%d\" font-size=\"11\" fill=\"#555\">", x, y + 16);
        svg_escape_max(&b, t->name, NAME_CHARS); /* a longer one ran into the next tile's */
        sb_puts(&b, "</text>\n</g>\n");
    }
    sb_puts(&b, "</svg>\n");
    int r = write_text_file(path, &b);
    sb_free(&b);
    return r;
}

int draw_sheet(const char *path, const sheet_tile *tiles, size_t n, int closed)
{
    char ext[16];
    path_ext(path, ext);
    if (strcmp(ext, ".png") == 0)
        return sheet_png(path, tiles, n, closed);
    if (strcmp(ext, ".svg") == 0)
        return sheet_svg(path, tiles, n, closed);
    tool_error(path, "unknown picture format: use a .png or .svg file name");
    return -1;
}
