/* draw.c — the registration overlay of the amscr tool (draw.h): target, source before and
 * after, and a legend, as a PNG (raster.h) or an SVG. */
#include "draw.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "raster.h"
#include "util.h"

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
    cov_polyline(&r, cb, in->nb, in->closed && !in->source_open, 2.0, dash);
    cov_composite(&r, COL_BEFORE);
    cov_clear(&r);
    cov_polyline(&r, ca, in->na, in->closed && !in->source_open, 2.0, NULL);
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
    int source_closed = in->closed && !in->source_open;
    svg_poly(&b, L, in->before, in->nb, source_closed, SVG_BEFORE, "none", " stroke-dasharray=\"7 5\"");
    svg_poly(&b, L, in->after, in->na, source_closed, SVG_AFTER, "none", NULL);
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
