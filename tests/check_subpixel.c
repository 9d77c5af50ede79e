/* check_subpixel.c — amscr_contour_from_image / amscr_contours_from_image: sub-pixel iso-lines
 * of 8- and 16-bit images (binary, antialiased), holes and hierarchy, bad input, and the old
 * pixel-centre calls unchanged. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"

/* A disk (centre cx, cy, radius r) or, with r < 0, the rectangle [cx, cy] x [-r, ...]: rendered
 * by its area coverage (16 x 16 samples a pixel), scaled to maxval. */
static double coverage_disk(double px, double py, double cx, double cy, double r)
{
    int in = 0;
    for (int j = 0; j < 16; j++)
        for (int i = 0; i < 16; i++) {
            double x = px - 0.5 + (i + 0.5) / 16, y = py - 0.5 + (j + 0.5) / 16;
            in += (x - cx) * (x - cx) + (y - cy) * (y - cy) < r * r;
        }
    return in / 256.0;
}

static double overlap(double a0, double a1, double b0, double b1)
{
    double lo = a0 > b0 ? a0 : b0, hi = a1 < b1 ? a1 : b1;
    return hi > lo ? hi - lo : 0.0;
}

static double coverage_rect(double px, double py, const double R[4])
{
    return overlap(px - 0.5, px + 0.5, R[0], R[2]) * overlap(py - 0.5, py + 0.5, R[1], R[3]);
}

static amscr_contour *trace_ok(const void *pix, size_t w, size_t h, int bits, double level, int flags)
{
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_image(pix, w, h, w, bits, level, flags, &c);
    ck_assert_msg(st == AMSCR_OK, "status %d: %s", (int)st, amscr_last_error_detail());
    double a = 0.0;
    ck_assert_int_eq(amscr_contour_signed_area(c, &a), AMSCR_OK);
    ck_assert(a > 0.0);
    return c;
}

/* An antialiased axis-aligned rectangle whose edges sit on half-covered pixels: every iso-line
 * point away from the corners within 0.05 px of the true edge; 8 and 16 bits; binary: halfway. */
START_TEST(rectangle_edges)
{
    const size_t w = 40, h = 30;
    const double R[4] = {8.0, 6.0, 31.0, 22.0}; /* x0, y0, x1, y1: edges through pixel centres */
    uint8_t *p8 = malloc(w * h);
    uint16_t *p16 = malloc(w * h * 2);
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
            double c = coverage_rect((double)x, (double)y, R);
            p8[y * w + x] = (uint8_t)lround(255 * c);
            p16[y * w + x] = (uint16_t)lround(65535 * c);
        }
    for (int k = 0; k < 3; k++) {
        amscr_contour *c = k == 0   ? trace_ok(p8, w, h, 8, 127.5, 0)
                           : k == 1 ? trace_ok(p16, w, h, 16, 32767.5, 0)
                                    : trace_ok(p16, w, h, 16, AMSCR_LEVEL_AUTO, 0);
        const double *xy = amscr_contour_xy(c);
        size_t n = amscr_contour_size(c), checked = 0;
        for (size_t i = 0; i < n; i++) {
            double x = xy[2 * i], y = xy[2 * i + 1];
            double dx = fmin(fabs(x - R[0]), fabs(x - R[2])), dy = fmin(fabs(y - R[1]), fabs(y - R[3]));
            if (dx < 1.5 && dy < 1.5)
                continue; /* a corner: cut */
            ck_assert_msg(fmin(dx, dy) < 0.05, "point (%g, %g) off the edge by %g", x, y, fmin(dx, dy));
            checked++;
        }
        ck_assert_uint_gt(checked, 60);
        amscr_contour_free(c);
    }
    /* binary: the edge halfway between the last foreground and first background centre */
    for (size_t i = 0; i < w * h; i++)
        p8[i] = p8[i] > 127 ? 255 : 0;
    amscr_contour *c = trace_ok(p8, w, h, 8, AMSCR_LEVEL_AUTO, 0);
    const double *xy = amscr_contour_xy(c);
    double lo[2] = {1e9, 1e9}, hi[2] = {-1e9, -1e9};
    for (size_t i = 0; i < amscr_contour_size(c); i++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], xy[2 * i + d]);
            hi[d] = fmax(hi[d], xy[2 * i + d]);
        }
    ck_assert(lo[0] == 7.5 && lo[1] == 5.5 && hi[0] == 31.5 && hi[1] == 22.5); /* pixels 8..31 x 6..22 */
    amscr_contour_free(c);
    free(p8);
    free(p16);
}
END_TEST

/* An antialiased disk: the mean radial error within 0.05 px; every point within 0.1 px (the
 * bias of linear interpolation on a box-filtered edge is at most 0.09 px). */
START_TEST(disk_radius)
{
    const size_t w = 60, h = 56;
    const double cx = 29.37, cy = 27.81, r = 20.3;
    uint16_t *p = malloc(w * h * 2);
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++)
            p[y * w + x] = (uint16_t)lround(65535 * coverage_disk((double)x, (double)y, cx, cy, r));
    amscr_contour *c = trace_ok(p, w, h, 16, AMSCR_LEVEL_AUTO, 0);
    const double *xy = amscr_contour_xy(c);
    size_t n = amscr_contour_size(c);
    double sum = 0.0, worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        double e = hypot(xy[2 * i] - cx, xy[2 * i + 1] - cy) - r;
        sum += e;
        worst = fmax(worst, fabs(e));
    }
    ck_assert_msg(fabs(sum / (double)n) < 0.05, "mean radial error %g", sum / (double)n);
    ck_assert_msg(worst < 0.1, "worst radial error %g", worst);
    amscr_contour_free(c);
    free(p);
}
END_TEST

/* Nested square ring: outer, hole, island; parents; areas of the sub-pixel polygons; border
 * contact and inverted polarity. */
START_TEST(holes_and_hierarchy)
{
    const size_t w = 50, h = 40;
    uint8_t *img = calloc(w * h, 1);
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++) {
            int ring = x >= 4 && x <= 35 && y >= 4 && y <= 35 && !(x >= 10 && x <= 29 && y >= 10 && y <= 29);
            int island = x >= 15 && x <= 24 && y >= 15 && y <= 24;
            img[y * w + x] = ring || island ? 255 : 0;
        }
    amscr_contour_set *s = NULL;
    ck_assert_int_eq(amscr_contours_from_image(img, w, h, w, 8, AMSCR_LEVEL_AUTO, 0, 0.0, &s), AMSCR_OK);
    ck_assert_uint_eq(amscr_contour_set_size(s), 3);
    ck_assert(!amscr_contour_set_is_hole(s, 0) && amscr_contour_set_is_hole(s, 1) && !amscr_contour_set_is_hole(s, 2));
    ck_assert(amscr_contour_set_parent(s, 0) == AMSCR_NO_PARENT);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 1), 0);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 2), 1);
    ck_assert(fabs(amscr_contour_set_area(s, 0) - 1023.5) < 1e-9);
    ck_assert(fabs(amscr_contour_set_area(s, 1) - 399.5) < 1e-9);
    ck_assert(fabs(amscr_contour_set_area(s, 2) - 99.5) < 1e-9);
    double a = 0.0;
    ck_assert_int_eq(amscr_contour_signed_area(amscr_contour_set_contour(s, 1), &a), AMSCR_OK);
    ck_assert(a < 0.0);
    amscr_contour_set_free(s);
    /* min_area drops the hole and the island inside it */
    ck_assert_int_eq(amscr_contours_from_image(img, w, h, w, 8, 127.5, 0, 500.0, &s), AMSCR_OK);
    ck_assert_uint_eq(amscr_contour_set_size(s), 1);
    amscr_contour_set_free(s);
    /* inverted polarity (the border is bright) and a shape touching the border: closes at -0.5 */
    for (size_t i = 0; i < w * h; i++)
        img[i] = 255;
    for (size_t y = 0; y < 20; y++)
        for (size_t x = 0; x < 20; x++)
            img[y * w + x] = 0;
    amscr_contour *c = trace_ok(img, w, h, 8, AMSCR_LEVEL_AUTO, 0);
    const double *xy = amscr_contour_xy(c);
    double xmin = 1e9, ymin = 1e9;
    for (size_t i = 0; i < amscr_contour_size(c); i++) {
        xmin = fmin(xmin, xy[2 * i]);
        ymin = fmin(ymin, xy[2 * i + 1]);
    }
    ck_assert(xmin == -0.5 && ymin == -0.5);
    amscr_contour_free(c);
    free(img);
}
END_TEST

START_TEST(bad_input)
{
    uint8_t px[16] = {0};
    px[5] = 255;
    amscr_contour *c = NULL;
    amscr_contour_set *s = NULL;
    ck_assert_int_eq(amscr_contour_from_image(NULL, 4, 4, 4, 8, -1, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 4, 8, -1, 0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 0, 4, 4, 8, -1, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 0, 4, 8, -1, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 3, 8, -1, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 4, 12, -1, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 4, 8, NAN, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 4, 8, 255.0, 0, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 4, 4, 4, 8, -1, 4, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_from_image(px, 40000, 4, 40000, 8, -1, 0, &c), AMSCR_E_LIMIT);
    ck_assert_int_eq(amscr_contour_from_image(px, 20000, 20000, 20000, 8, -1, 0, &c), AMSCR_E_LIMIT);
    ck_assert_int_eq(amscr_contours_from_image(px, 4, 4, 4, 8, -1, 0, -1.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_image(px, 4, 4, 4, 8, -1, 0, 0.0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(c);
    ck_assert_ptr_null(s);
    ck_assert(strlen(amscr_last_error_detail()) > 0);
    uint8_t zero[16] = {0};
    ck_assert_int_eq(amscr_contour_from_image(zero, 4, 4, 4, 8, 127.5, 0, &c), AMSCR_E_NOT_FOUND);
    ck_assert_int_eq(amscr_contour_from_image(zero, 4, 4, 4, 8, -1, 0, &c), AMSCR_E_NOT_FOUND);
    ck_assert_int_eq(amscr_contours_from_image(zero, 4, 4, 4, 8, -1, 0, 0.0, &s), AMSCR_E_NOT_FOUND);
    /* a single pixel: a diamond of area 0.5 */
    c = trace_ok(px, 4, 4, 8, 127.5, 0);
    ck_assert_uint_eq(amscr_contour_size(c), 4);
    amscr_contour_free(c);
}
END_TEST

/* The old calls keep their pixel centres; the flag AMSCR_TRACE_PIXEL_CHAIN gives the same. */
START_TEST(old_calls_unchanged)
{
    const size_t w = 30, h = 24;
    uint8_t *img = calloc(w * h, 1);
    for (size_t y = 0; y < h; y++)
        for (size_t x = 0; x < w; x++)
            img[y * w + x] = (uint8_t)(coverage_disk((double)x, (double)y, 14.2, 11.7, 8.3) * 255);
    amscr_contour *a = NULL, *b = NULL;
    ck_assert_int_eq(amscr_contour_from_mask(img, w, h, w, 127, &a), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_from_image(img, w, h, w, 8, 127.5, AMSCR_TRACE_PIXEL_CHAIN, &b), AMSCR_OK);
    ck_assert_uint_eq(amscr_contour_size(a), amscr_contour_size(b));
    const double *pa = amscr_contour_xy(a), *pb = amscr_contour_xy(b);
    for (size_t i = 0; i < 2 * amscr_contour_size(a); i++) {
        ck_assert(pa[i] == floor(pa[i]));
        ck_assert(pa[i] == pb[i]);
    }
    amscr_contour_free(a);
    amscr_contour_free(b);
    amscr_contour_set *s = NULL, *t = NULL;
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, 0.0, &s), AMSCR_OK);
    ck_assert_int_eq(amscr_contours_from_image(img, w, h, w, 8, 127.5, AMSCR_TRACE_PIXEL_CHAIN, 0.0, &t), AMSCR_OK);
    ck_assert_uint_eq(amscr_contour_set_size(s), amscr_contour_set_size(t));
    ck_assert(amscr_contour_set_area(s, 0) == amscr_contour_set_area(t, 0));
    amscr_contour_set_free(s);
    amscr_contour_set_free(t);
    free(img);
}
END_TEST

/* AMSCR_TRACE_JOIN: a bar cut in two by a gap (the halves 24 and 16 px long) is one outline
 * holding both halves' areas and reaching both ends; a speck (below 5 % of the largest) and a
 * piece beyond the largest's RMS radius stay out; without the flag the largest half alone;
 * amscr_contours_from_image refuses the flag. */
START_TEST(join_pieces)
{
    const size_t w = 80, h = 40;
    uint8_t *img = calloc(w * h, 1);
    for (size_t y = 10; y < 16; y++) {
        for (size_t x = 10; x < 34; x++)
            img[y * w + x] = 255; /* left half: 24 x 6 */
        for (size_t x = 38; x < 54; x++)
            img[y * w + x] = 255; /* right half: 16 x 6, 4 px away */
    }
    img[30 * w + 20] = 255; /* a speck */
    amscr_contour *a = trace_ok(img, w, h, 8, 127.5, 0), *b = trace_ok(img, w, h, 8, 127.5, AMSCR_TRACE_JOIN);
    double area_a = 0.0, area_b = 0.0;
    ck_assert_int_eq(amscr_contour_signed_area(a, &area_a), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_signed_area(b, &area_b), AMSCR_OK);
    ck_assert_msg(fabs(area_a - (24 * 6 - 0.5)) < 1e-9, "largest alone: area %g", area_a);
    ck_assert_msg(fabs(area_b - (24 * 6 - 0.5) - (16 * 6 - 0.5)) < 1e-9, "joined: area %g", area_b);
    const double *xy = amscr_contour_xy(b);
    double xmin = 1e9, xmax = -1e9, ymax = -1e9;
    for (size_t i = 0; i < amscr_contour_size(b); i++) {
        xmin = fmin(xmin, xy[2 * i]);
        xmax = fmax(xmax, xy[2 * i]);
        ymax = fmax(ymax, xy[2 * i + 1]);
    }
    ck_assert(xmin == 9.5 && xmax == 53.5 && ymax == 15.5); /* both ends, not the speck (row 30) */
    amscr_contour_free(a);
    amscr_contour_free(b);
    /* a second piece far away (beyond the RMS radius, about 7 px): not joined */
    memset(img, 0, w * h);
    for (size_t y = 10; y < 16; y++)
        for (size_t x = 10; x < 34; x++)
            img[y * w + x] = 255;
    for (size_t y = 30; y < 36; y++)
        for (size_t x = 60; x < 76; x++)
            img[y * w + x] = 255;
    b = trace_ok(img, w, h, 8, 127.5, AMSCR_TRACE_JOIN);
    ck_assert_int_eq(amscr_contour_signed_area(b, &area_b), AMSCR_OK);
    ck_assert_msg(fabs(area_b - (24 * 6 - 0.5)) < 1e-9, "far piece joined: area %g", area_b);
    amscr_contour_free(b);
    amscr_contour_set *s = NULL;
    ck_assert_int_eq(amscr_contours_from_image(img, w, h, w, 8, 127.5, AMSCR_TRACE_JOIN, 0.0, &s),
                     AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(s);
    free(img);
}
END_TEST

Suite *amscr_suite_subpixel(void)
{
    Suite *s = suite_create("subpixel");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, rectangle_edges);
    tcase_add_test(tc, disk_radius);
    tcase_add_test(tc, holes_and_hierarchy);
    tcase_add_test(tc, bad_input);
    tcase_add_test(tc, old_calls_unchanged);
    tcase_add_test(tc, join_pieces);
    suite_add_tcase(s, tc);
    return s;
}
