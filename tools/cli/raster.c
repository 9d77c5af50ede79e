/* raster.c — the drawing primitives of the tool's pictures (raster.h): an RGB float raster,
 * anti-aliased coverage layers (thick polylines, even-odd fills) and a built-in 5x7 bitmap font. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "raster.h"

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
