/* check_trace.c — amscr_contour_from_mask on synthetic masks (and the Kimia silhouettes
 * when the datasets are present). */
#include <check.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"
#include "testutil.h"

/* ---------------------------------------------------------------- helpers */

/* A w x h image (stride w) filled with v. */
static uint8_t *img_new(size_t w, size_t h, uint8_t v)
{
    uint8_t *p = malloc(w * h);
    ck_assert_ptr_nonnull(p);
    memset(p, v, w * h);
    return p;
}

/* Fills the inclusive rectangle [x0, x1] x [y0, y1]. */
static void fill_rect(uint8_t *img, size_t stride, size_t x0, size_t y0, size_t x1, size_t y1, uint8_t v)
{
    for (size_t y = y0; y <= y1; y++)
        for (size_t x = x0; x <= x1; x++)
            img[y * stride + x] = v;
}

/* Fills the pixels whose centre is within r of (cx, cy). */
static void fill_disk(uint8_t *img, size_t w, size_t h, size_t stride, double cx, double cy, double r, uint8_t v)
{
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++)
            if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r)
                img[y * stride + x] = v;
}

/* Traces and asserts success. */
static amscr_contour *trace_ok(const uint8_t *img, size_t w, size_t h, size_t stride, int thr)
{
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_mask(img, w, h, stride, thr, &c);
    ck_assert_msg(st == AMSCR_OK, "status %d: %s", (int)st, amscr_last_error_detail());
    ck_assert_ptr_nonnull(c);
    return c;
}

/* Two contours are identical point for point. */
static void assert_same(const amscr_contour *a, const amscr_contour *b)
{
    ck_assert_uint_eq(amscr_contour_size(a), amscr_contour_size(b));
    ck_assert_int_eq(memcmp(amscr_contour_xy(a), amscr_contour_xy(b), 2 * amscr_contour_size(a) * sizeof(double)), 0);
}

/* Bounding box of the points. */
static void bbox(const amscr_contour *c, double *x0, double *y0, double *x1, double *y1)
{
    const double *p = amscr_contour_xy(c);
    *x0 = *x1 = p[0];
    *y0 = *y1 = p[1];
    for (size_t i = 1; i < amscr_contour_size(c); i++) {
        *x0 = fmin(*x0, p[2 * i]);
        *x1 = fmax(*x1, p[2 * i]);
        *y0 = fmin(*y0, p[2 * i + 1]);
        *y1 = fmax(*y1, p[2 * i + 1]);
    }
}

/* Independent check against a binary foreground mask fg (w x h, 0/1, polarity already
 * applied): the points are exactly the pixels of the largest 8-connected component (ties:
 * first in raster order) that have a 4-neighbour in the OUTER background (background
 * 4-connected to the frame outside the image; holes excluded), each at least once;
 * consecutive points (cyclically) are distinct 8-neighbours; the first point is the
 * component's first pixel; the area is positive. */
static void check_against_mask(const uint8_t *fg, size_t w, size_t h, const amscr_contour *c)
{
    size_t n = w * h;
    int *lab = calloc(n, sizeof *lab);
    size_t W = w + 2, H = h + 2;
    size_t *queue = malloc(W * H * sizeof *queue);
    ck_assert_ptr_nonnull(lab);
    ck_assert_ptr_nonnull(queue);
    int nl = 0, best = 0;
    size_t best_size = 0, best_first = 0;
    for (size_t i = 0; i < n; i++) {
        if (!fg[i] || lab[i])
            continue;
        nl++;
        size_t head = 0, tail = 0;
        queue[tail++] = i;
        lab[i] = nl;
        while (head < tail) {
            size_t p = queue[head++];
            long px = (long)(p % w), py = (long)(p / w);
            for (long dy = -1; dy <= 1; dy++)
                for (long dx = -1; dx <= 1; dx++) {
                    long qx = px + dx, qy = py + dy;
                    if (qx < 0 || qy < 0 || qx >= (long)w || qy >= (long)h)
                        continue;
                    size_t q = (size_t)qy * w + (size_t)qx;
                    if (fg[q] && !lab[q]) {
                        lab[q] = nl;
                        queue[tail++] = q;
                    }
                }
        }
        if (tail > best_size) {
            best_size = tail;
            best = nl;
            best_first = i;
        }
    }
    ck_assert_int_gt(best, 0);
    /* Outer background: 4-connected flood over off pixels of the padded image. */
    uint8_t *outer = calloc(W * H, 1);
    ck_assert_ptr_nonnull(outer);
    size_t head = 0, tail = 0;
    queue[tail++] = 0;
    outer[0] = 1;
    while (head < tail) {
        size_t p = queue[head++];
        long px = (long)(p % W), py = (long)(p / W);
        const long d4[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        for (int d = 0; d < 4; d++) {
            long qx = px + d4[d][0], qy = py + d4[d][1];
            if (qx < 0 || qy < 0 || qx >= (long)W || qy >= (long)H)
                continue;
            size_t q = (size_t)qy * W + (size_t)qx;
            int inside = qx >= 1 && qy >= 1 && qx <= (long)w && qy <= (long)h;
            if (outer[q] || (inside && fg[(size_t)(qy - 1) * w + (size_t)(qx - 1)]))
                continue;
            outer[q] = 1;
            queue[tail++] = q;
        }
    }
    /* Expected boundary: component pixels with a 4-neighbour in the outer background. */
    size_t expected = 0;
    uint8_t *want = calloc(n, 1), *seen = calloc(n, 1);
    ck_assert_ptr_nonnull(want);
    ck_assert_ptr_nonnull(seen);
    for (size_t i = 0; i < n; i++) {
        if (lab[i] != best)
            continue;
        size_t P = (i / w + 1) * W + (i % w + 1);
        if (outer[P - 1] || outer[P + 1] || outer[P - W] || outer[P + W]) {
            want[i] = 1;
            expected++;
        }
    }
    const double *p = amscr_contour_xy(c);
    size_t m = amscr_contour_size(c), distinct = 0;
    ck_assert_uint_ge(m, 3);
    ck_assert(p[0] == (double)(best_first % w) && p[1] == (double)(best_first / w));
    for (size_t i = 0; i < m; i++) {
        double x = p[2 * i], y = p[2 * i + 1];
        ck_assert(x >= 0 && y >= 0 && x < (double)w && y < (double)h && x == floor(x) && y == floor(y));
        size_t idx = (size_t)y * w + (size_t)x;
        ck_assert_msg(want[idx], "point %zu (%g, %g) is not an outer boundary pixel of the component", i, x, y);
        if (!seen[idx]) {
            seen[idx] = 1;
            distinct++;
        }
        size_t j = (i + 1) % m;
        double ddx = fabs(p[2 * j] - x), ddy = fabs(p[2 * j + 1] - y);
        ck_assert_msg(ddx <= 1 && ddy <= 1 && ddx + ddy > 0, "points %zu, %zu not distinct 8-neighbours", i, j);
    }
    ck_assert_uint_eq(distinct, expected);
    ck_assert(amscr_test_shoelace(p, m) > 0.0);
    free(lab);
    free(queue);
    free(outer);
    free(want);
    free(seen);
}

/* Binary mask (v > thr) of a stride-w image. */
static uint8_t *binarize(const uint8_t *img, size_t n, int thr, int invert)
{
    uint8_t *fg = malloc(n);
    ck_assert_ptr_nonnull(fg);
    for (size_t i = 0; i < n; i++)
        fg[i] = (uint8_t)((img[i] > thr) ^ (invert != 0));
    return fg;
}

/* ---------------------------------------------------------------- tests */

START_TEST(rectangle)
{
    size_t w = 20, h = 15;
    uint8_t *img = img_new(w, h, 0);
    fill_rect(img, w, 3, 4, 12, 10, 255); /* 10 x 7 */
    amscr_contour *c = trace_ok(img, w, h, w, 127);
    /* Perimeter pixels of a 10 x 7 block: 2*(10+7) - 4. */
    ck_assert_uint_eq(amscr_contour_size(c), 30);
    double x0, y0, x1, y1;
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 3 && x1 == 12 && y0 == 4 && y1 == 10);
    /* Polygon through the pixel centres: 9 x 6. */
    ck_assert_double_eq(amscr_test_shoelace(amscr_contour_xy(c), amscr_contour_size(c)), 54.0);
    ck_assert(amscr_contour_xy(c)[0] == 3 && amscr_contour_xy(c)[1] == 4);
    double area = 0.0;
    ck_assert_int_eq(amscr_contour_signed_area(c, &area), AMSCR_OK);
    ck_assert_double_eq_tol(area, 54.0, 1e-9);
    uint8_t *fg = binarize(img, w * h, 127, 0);
    check_against_mask(fg, w, h, c);
    free(fg);
    amscr_contour_free(c);
    free(img);
}
END_TEST

START_TEST(small_blocks)
{
    /* 2 x 2 block: 4 points, area 1; 3 x 3 minus a corner: the centre is skipped. */
    uint8_t img[5 * 5] = {0};
    fill_rect(img, 5, 1, 1, 2, 2, 9);
    amscr_contour *c = trace_ok(img, 5, 5, 5, 0);
    ck_assert_uint_eq(amscr_contour_size(c), 4);
    const double want[] = {1, 1, 2, 1, 2, 2, 1, 2};
    ck_assert_int_eq(memcmp(amscr_contour_xy(c), want, sizeof want), 0);
    amscr_contour_free(c);

    uint8_t img2[5 * 5] = {0};
    fill_rect(img2, 5, 1, 1, 3, 3, 200);
    img2[1 * 5 + 3] = 0;
    c = trace_ok(img2, 5, 5, 5, 127);
    const double want2[] = {1, 1, 2, 1, 3, 2, 3, 3, 2, 3, 1, 3, 1, 2};
    ck_assert_uint_eq(amscr_contour_size(c), 7);
    ck_assert_int_eq(memcmp(amscr_contour_xy(c), want2, sizeof want2), 0);
    amscr_contour_free(c);
}
END_TEST

START_TEST(disk_with_hole)
{
    size_t w = 64, h = 64;
    uint8_t *a = img_new(w, h, 0), *b = img_new(w, h, 0);
    fill_disk(a, w, h, w, 31.5, 30.0, 20.0, 255);
    fill_disk(b, w, h, w, 31.5, 30.0, 20.0, 255);
    fill_disk(b, w, h, w, 33.0, 31.0, 8.0, 0); /* hole */
    amscr_contour *ca = trace_ok(a, w, h, w, 127);
    amscr_contour *cb = trace_ok(b, w, h, w, 127);
    assert_same(ca, cb);
    uint8_t *fg = binarize(a, w * h, 127, 0);
    check_against_mask(fg, w, h, ca);
    free(fg);
    fg = binarize(b, w * h, 127, 0);
    check_against_mask(fg, w, h, cb);
    free(fg);
    amscr_contour_free(ca);
    amscr_contour_free(cb);
    free(a);
    free(b);
}
END_TEST

START_TEST(spur_at_start)
{
    /* The first pixel in raster order is the tip of a 1-pixel spur: the trace leaves
     * it and comes back up the spur, and must close without repeating it. */
    size_t w = 12, h = 10;
    uint8_t *img = img_new(w, h, 0);
    fill_rect(img, w, 2, 4, 8, 7, 255);
    fill_rect(img, w, 5, 1, 5, 3, 255); /* vertical spur above the block */
    img[2 * w + 9] = 255;               /* a diagonal spur at the right */
    img[1 * w + 10] = 255;
    amscr_contour *c = trace_ok(img, w, h, w, 127);
    ck_assert(amscr_contour_xy(c)[0] == 5 && amscr_contour_xy(c)[1] == 1);
    uint8_t *fg = binarize(img, w * h, 127, 0);
    check_against_mask(fg, w, h, c);
    /* The spur is walked up and down: its tip (5,1) once, (5,2) twice. */
    size_t n = amscr_contour_size(c);
    const double *p = amscr_contour_xy(c);
    size_t count51 = 0, count52 = 0;
    for (size_t i = 0; i < n; i++) {
        count51 += p[2 * i] == 5 && p[2 * i + 1] == 1;
        count52 += p[2 * i] == 5 && p[2 * i + 1] == 2;
    }
    ck_assert_uint_eq(count51, 1);
    ck_assert_uint_eq(count52, 2);
    free(fg);
    amscr_contour_free(c);
    free(img);
}
END_TEST

START_TEST(largest_component)
{
    size_t w = 40, h = 30;
    uint8_t *img = img_new(w, h, 0);
    fill_rect(img, w, 2, 1, 8, 5, 255);    /* small, first in raster order: 7 x 5 */
    fill_rect(img, w, 10, 10, 30, 25, 255); /* large: 21 x 16 */
    amscr_contour *c = trace_ok(img, w, h, w, 127);
    double x0, y0, x1, y1;
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 10 && x1 == 30 && y0 == 10 && y1 == 25);
    ck_assert_uint_eq(amscr_contour_size(c), 2 * (21 + 16) - 4);
    amscr_contour_free(c);

    /* A tie: two 5 x 5 blocks; the first in raster order wins. */
    memset(img, 0, w * h);
    fill_rect(img, w, 20, 2, 24, 6, 255);
    fill_rect(img, w, 2, 10, 6, 14, 255);
    c = trace_ok(img, w, h, w, 127);
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 20 && y0 == 2);
    amscr_contour_free(c);

    /* Diagonal contact joins two blocks into one 8-connected component. */
    memset(img, 0, w * h);
    fill_rect(img, w, 2, 2, 6, 6, 255);
    fill_rect(img, w, 7, 7, 9, 9, 255);
    fill_rect(img, w, 20, 20, 25, 25, 255); /* 36 pixels > 25 + 9 */
    c = trace_ok(img, w, h, w, 127);
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 20 && y0 == 20);
    amscr_contour_free(c);
    fill_rect(img, w, 20, 20, 25, 25, 0);
    fill_rect(img, w, 20, 20, 24, 25, 255); /* 30 pixels < 34 */
    c = trace_ok(img, w, h, w, 127);
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 2 && y0 == 2 && x1 == 9 && y1 == 9);
    uint8_t *fg = binarize(img, w * h, 127, 0);
    check_against_mask(fg, w, h, c);
    free(fg);
    amscr_contour_free(c);
    free(img);
}
END_TEST

START_TEST(specks_ignored)
{
    size_t w = 80, h = 60;
    uint8_t *a = img_new(w, h, 0), *b = img_new(w, h, 0);
    fill_disk(a, w, h, w, 40, 30, 15, 255);
    fill_disk(b, w, h, w, 40, 30, 15, 255);
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 7);
    for (int i = 0; i < 200; i++) {
        size_t x = (size_t)(amscr_test_uniform(&r) * (double)w), y = (size_t)(amscr_test_uniform(&r) * (double)h);
        double dx = (double)x - 40, dy = (double)y - 30;
        if (dx * dx + dy * dy > 18 * 18 && x > 0 && y > 0 && x < w - 1 && y < h - 1)
            b[y * w + x] = 255;
    }
    amscr_contour *ca = trace_ok(a, w, h, w, 127);
    amscr_contour *cb = trace_ok(b, w, h, w, 127);
    assert_same(ca, cb);
    amscr_contour_free(ca);
    amscr_contour_free(cb);
    free(a);
    free(b);
}
END_TEST

START_TEST(touching_all_borders)
{
    /* A cross whose arms reach all four borders (the border is mostly background). */
    size_t w = 20, h = 20;
    uint8_t *img = img_new(w, h, 0);
    fill_rect(img, w, 0, 8, 19, 11, 255);
    fill_rect(img, w, 8, 0, 11, 19, 255);
    amscr_contour *c = trace_ok(img, w, h, w, 127);
    double x0, y0, x1, y1;
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 0 && y0 == 0 && x1 == 19 && y1 == 19);
    uint8_t *fg = binarize(img, w * h, 127, 0);
    check_against_mask(fg, w, h, c);
    /* The polygon through the centres: the bar 19 x 3 plus two arms 3 x 8, plus a
     * triangle of 1/2 at each of the 4 concave corners (the corner pixel touches the
     * background only diagonally, so the trace cuts across the background there). */
    ck_assert_double_eq_tol(amscr_test_shoelace(amscr_contour_xy(c), amscr_contour_size(c)), 19.0 * 3 + 2 * 8 * 3 + 2.0,
                            1e-9);
    free(fg);
    amscr_contour_free(c);

    /* A full-width bar touching left and right only. */
    memset(img, 0, w * h);
    fill_rect(img, w, 0, 5, 19, 9, 255);
    c = trace_ok(img, w, h, w, 127);
    ck_assert_uint_eq(amscr_contour_size(c), 2 * (20 + 5) - 4);
    amscr_contour_free(c);
    free(img);
}
END_TEST

START_TEST(inverted_polarity)
{
    size_t w = 30, h = 25;
    uint8_t *a = img_new(w, h, 0), *b = img_new(w, h, 255);
    fill_disk(a, w, h, w, 14, 12, 9, 255);
    fill_disk(b, w, h, w, 14, 12, 9, 0);
    amscr_contour *ca = trace_ok(a, w, h, w, 127);
    amscr_contour *cb = trace_ok(b, w, h, w, 127);
    assert_same(ca, cb);
    uint8_t *fg = binarize(b, w * h, 127, 1);
    check_against_mask(fg, w, h, cb);
    free(fg);
    amscr_contour_free(ca);
    amscr_contour_free(cb);
    free(a);
    free(b);
}
END_TEST

START_TEST(stride_padding)
{
    size_t w = 33, h = 21, stride = 41;
    uint8_t *tight = img_new(w, h, 0);
    fill_disk(tight, w, h, w, 16, 10, 9, 255);
    fill_rect(tight, w, 20, 0, 32, 3, 255); /* touches the right border */
    uint8_t *pad = malloc(stride * h);
    ck_assert_ptr_nonnull(pad);
    memset(pad, 255, stride * h); /* garbage (all "on") in the padding */
    for (size_t y = 0; y < h; y++)
        memcpy(pad + y * stride, tight + y * w, w);
    amscr_contour *a = trace_ok(tight, w, h, w, 127);
    amscr_contour *b = trace_ok(pad, w, h, stride, 127);
    assert_same(a, b);
    /* The last row needs only `width` bytes: a buffer of (h-1)*stride + w is enough. */
    uint8_t *exact = malloc((h - 1) * stride + w);
    ck_assert_ptr_nonnull(exact);
    memcpy(exact, pad, (h - 1) * stride + w);
    amscr_contour *e = trace_ok(exact, w, h, stride, 127);
    assert_same(a, e);
    amscr_contour_free(a);
    amscr_contour_free(b);
    amscr_contour_free(e);
    free(tight);
    free(pad);
    free(exact);
}
END_TEST

START_TEST(threshold_auto)
{
    size_t w = 50, h = 40;
    uint8_t *img = img_new(w, h, 0);
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 3);
    for (size_t i = 0; i < w * h; i++)
        img[i] = (uint8_t)(30 + (int)(amscr_test_uniform(&r) * 20)); /* background 30..49 */
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
            double dx = (double)x - 25, dy = (double)y - 20;
            if (dx * dx / 400.0 + dy * dy / 144.0 <= 1.0)
                img[y * w + x] = (uint8_t)(180 + (int)(amscr_test_uniform(&r) * 40)); /* 180..219 */
        }
    amscr_contour *a = trace_ok(img, w, h, w, AMSCR_THRESHOLD_AUTO);
    amscr_contour *b = trace_ok(img, w, h, w, 127);
    assert_same(a, b);
    amscr_contour_free(a);
    amscr_contour_free(b);

    /* Two-valued image 10 / 20: AUTO separates them (a fixed 127 finds nothing). */
    memset(img, 10, w * h);
    fill_rect(img, w, 5, 5, 20, 30, 20);
    a = trace_ok(img, w, h, w, AMSCR_THRESHOLD_AUTO);
    ck_assert_uint_eq(amscr_contour_size(a), 2 * (16 + 26) - 4);
    amscr_contour_free(a);
    a = NULL;
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &a), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_null(a);
    free(img);
}
END_TEST

START_TEST(degenerate_and_not_found)
{
    size_t w = 10, h = 10;
    uint8_t *img = img_new(w, h, 0);
    amscr_contour *c = NULL;
    /* Empty. */
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "no foreground"));
    /* Everything on. */
    memset(img, 255, w * h);
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "everywhere"));
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, AMSCR_THRESHOLD_AUTO, &c), AMSCR_E_NOT_FOUND);
    /* A single pixel. */
    memset(img, 0, w * h);
    img[4 * w + 5] = 255;
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_DEGENERATE);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    /* Two pixels. */
    img[4 * w + 6] = 255;
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_DEGENERATE);
    /* A straight and a diagonal line: zero area. */
    fill_rect(img, w, 2, 4, 8, 4, 255);
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_DEGENERATE);
    memset(img, 0, w * h);
    for (size_t i = 1; i < 9; i++)
        img[i * w + i] = 255;
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &c), AMSCR_E_DEGENERATE);
    ck_assert_ptr_null(c);
    /* Three pixels in an L: a triangle of area 1/2. */
    memset(img, 0, w * h);
    img[3 * w + 3] = img[3 * w + 4] = img[4 * w + 3] = 255;
    c = trace_ok(img, w, h, w, 127);
    ck_assert_uint_eq(amscr_contour_size(c), 3);
    ck_assert_double_eq(amscr_test_shoelace(amscr_contour_xy(c), 3), 0.5);
    amscr_contour_free(c);
    /* A 1 x 1 image and 1-pixel-wide images. */
    uint8_t one = 255;
    c = NULL;
    ck_assert_int_eq(amscr_contour_from_mask(&one, 1, 1, 1, 127, &c), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_null(c);
    free(img);
}
END_TEST

START_TEST(invalid_args_and_limits)
{
    uint8_t img[16] = {0};
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_from_mask(NULL, 4, 4, 4, 127, &c), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 4, 4, 127, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 0, 4, 4, 127, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 0, 4, 127, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 4, 3, 127, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 4, 4, 255, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 4, 4, -2, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_mask(img, 4, 4, SIZE_MAX, 127, &c), AMSCR_E_INVALID_ARG);
    /* Limits are checked before any pixel is read. */
    ck_assert_int_eq(amscr_contour_from_mask(img, AMSCR_MAX_IMAGE_SIDE + 1, 1, AMSCR_MAX_IMAGE_SIDE + 1, 127, &c),
                     AMSCR_E_LIMIT);
    ck_assert_int_eq(amscr_contour_from_mask(img, 1, AMSCR_MAX_IMAGE_SIDE + 1, 1, 127, &c), AMSCR_E_LIMIT);
    ck_assert_int_eq(amscr_contour_from_mask(img, 16385, 16385, 16385, 127, &c), AMSCR_E_LIMIT);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_ptr_null(c);
}
END_TEST

/* Random rotated ellipses (convex, hence hole-free): the independent mask check. */
START_TEST(random_ellipses)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 1000 + (uint64_t)_i);
    size_t w = 20 + (size_t)(amscr_test_uniform(&r) * 80), h = 20 + (size_t)(amscr_test_uniform(&r) * 80);
    double cx = amscr_test_uniform(&r) * (double)w, cy = amscr_test_uniform(&r) * (double)h;
    double a = 2 + amscr_test_uniform(&r) * 40, b = 1 + amscr_test_uniform(&r) * 20;
    double th = amscr_test_uniform(&r) * 3.14159265358979;
    double ct = cos(th), st = sin(th);
    uint8_t *img = img_new(w, h, 0);
    size_t on = 0;
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
            double dx = (double)x - cx, dy = (double)y - cy;
            double u = ct * dx + st * dy, v = -st * dx + ct * dy;
            if (u * u / (a * a) + v * v / (b * b) <= 1.0) {
                img[y * w + x] = 255;
                on++;
            }
        }
    size_t border = 0, border_on = 0;
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++)
            if (x == 0 || y == 0 || x == w - 1 || y == h - 1) {
                border++;
                border_on += img[y * w + x] != 0;
            }
    if (on < 4 || 2 * border_on > border) { /* nothing useful, or the polarity flips */
        free(img);
        return;
    }
    amscr_contour *c = NULL;
    amscr_status s = amscr_contour_from_mask(img, w, h, w, 127, &c);
    if (s == AMSCR_E_DEGENERATE) { /* a thin digital line: fine */
        free(img);
        return;
    }
    ck_assert_msg(s == AMSCR_OK, "status %d: %s", (int)s, amscr_last_error_detail());
    uint8_t *fg = binarize(img, w * h, 127, 0);
    check_against_mask(fg, w, h, c);
    free(fg);
    amscr_contour_free(c);
    free(img);
}
END_TEST

/* Random blobs with diagonal-only contacts, spurs, thin parts and holes (the border row
 * and column stay background, so the polarity never flips). */
START_TEST(random_blobs)
{
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 5000 + (uint64_t)_i);
    size_t w = 8 + (size_t)(amscr_test_uniform(&r) * 40), h = 8 + (size_t)(amscr_test_uniform(&r) * 40);
    uint8_t *img = img_new(w, h, 0);
    double p = 0.15 + 0.55 * amscr_test_uniform(&r);
    for (size_t y = 1; y + 1 < h; y++)
        for (size_t x = 1; x + 1 < w; x++)
            img[y * w + x] = amscr_test_uniform(&r) < p ? 255 : 0;
    amscr_contour *c = NULL;
    amscr_status s = amscr_contour_from_mask(img, w, h, w, 127, &c);
    if (s == AMSCR_OK) {
        uint8_t *fg = binarize(img, w * h, 127, 0);
        check_against_mask(fg, w, h, c);
        free(fg);
        amscr_contour_free(c);
    } else {
        ck_assert_msg(s == AMSCR_E_DEGENERATE || s == AMSCR_E_NOT_FOUND, "status %d: %s", (int)s,
                      amscr_last_error_detail());
    }
    free(img);
}
END_TEST

START_TEST(large_image)
{
    /* 4096 x 4096 with a big disk (~10^7 pixels) and long 1-pixel lines: no recursion,
     * and the BFS stays fast. */
    size_t w = 4096, h = 4096;
    uint8_t *img = img_new(w, h, 0);
    fill_disk(img, w, h, w, 2048, 2048, 1800, 255);
    for (size_t y = 8; y < 200; y += 4) /* separate lines, each smaller than the disk */
        fill_rect(img, w, 4, y, 4000, y, 255);
    amscr_contour *c = trace_ok(img, w, h, w, 127);
    double x0, y0, x1, y1;
    bbox(c, &x0, &y0, &x1, &y1);
    ck_assert(x0 == 248 && x1 == 3848 && y0 == 248 && y1 == 3848);
    ck_assert(amscr_test_shoelace(amscr_contour_xy(c), amscr_contour_size(c)) > 0.9 * 3.14159 * 1800 * 1800);
    amscr_contour_free(c);
    free(img);
}
END_TEST

/* Traces every PNG of one dataset folder. Returns the number traced. */
static int trace_folder(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int count = 0;
    struct dirent *e;
    char path[4096];
    while ((e = readdir(d)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 5 || strcmp(e->d_name + len - 4, ".png") != 0)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        unsigned char *px = NULL;
        size_t w = 0, h = 0;
        ck_assert_msg(amscr_test_read_png_gray(path, &px, &w, &h) == 0, "cannot read %s", path);
        amscr_contour *c = NULL;
        amscr_status st = amscr_contour_from_mask(px, w, h, w, 127, &c);
        ck_assert_msg(st == AMSCR_OK, "%s: status %d: %s", path, (int)st, amscr_last_error_detail());
        ck_assert_msg(amscr_contour_size(c) >= 50, "%s: only %zu points", path, amscr_contour_size(c));
        double area = 0.0;
        ck_assert_int_eq(amscr_contour_signed_area(c, &area), AMSCR_OK);
        ck_assert_msg(area > 0.0, "%s: area %g", path, area);
        ck_assert(amscr_test_shoelace(amscr_contour_xy(c), amscr_contour_size(c)) > 0.0);
        amscr_contour_free(c);
        free(px);
        count++;
    }
    closedir(d);
    return count;
}

START_TEST(kimia_datasets)
{
    const char *root = amscr_test_datasets_or_skip("trace");
    if (!root)
        return;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/kimia99", root);
    int n99 = trace_folder(dir);
    snprintf(dir, sizeof dir, "%s/kimia216", root);
    int n216 = trace_folder(dir);
    ck_assert_int_ge(n99, 99);
    ck_assert_int_ge(n216, 216);
}
END_TEST

Suite *amscr_suite_trace(void)
{
    Suite *s = suite_create("trace");
    TCase *tc = tcase_create("synthetic");
    tcase_add_test(tc, rectangle);
    tcase_add_test(tc, small_blocks);
    tcase_add_test(tc, disk_with_hole);
    tcase_add_test(tc, spur_at_start);
    tcase_add_test(tc, largest_component);
    tcase_add_test(tc, specks_ignored);
    tcase_add_test(tc, touching_all_borders);
    tcase_add_test(tc, inverted_polarity);
    tcase_add_test(tc, stride_padding);
    tcase_add_test(tc, threshold_auto);
    tcase_add_test(tc, degenerate_and_not_found);
    tcase_add_test(tc, invalid_args_and_limits);
    tcase_add_loop_test(tc, random_ellipses, 0, 60);
    tcase_add_loop_test(tc, random_blobs, 0, 200);
    tcase_add_test(tc, large_image);
    suite_add_tcase(s, tc);
    TCase *td = tcase_create("datasets");
    tcase_set_timeout(td, 600);
    tcase_add_test(td, kimia_datasets);
    suite_add_tcase(s, td);
    return s;
}
