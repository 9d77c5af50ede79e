/* check_trace_all.c — amscr_contours_from_mask: every component and hole with its parent. */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "suites.h"

static uint8_t *img_new(size_t w, size_t h, uint8_t v)
{
    uint8_t *p = malloc(w * h);
    ck_assert_ptr_nonnull(p);
    memset(p, v, w * h);
    return p;
}

static void fill_rect(uint8_t *img, size_t w, size_t x0, size_t y0, size_t x1, size_t y1, uint8_t v)
{
    for (size_t y = y0; y <= y1; y++)
        for (size_t x = x0; x <= x1; x++)
            img[y * w + x] = v;
}

static double signed_area(const amscr_contour *c)
{
    double a = 0.0;
    ck_assert_int_eq(amscr_contour_signed_area(c, &a), AMSCR_OK);
    return a;
}

static amscr_contour_set *all_ok(const uint8_t *img, size_t w, size_t h, double min_area)
{
    amscr_contour_set *s = NULL;
    amscr_status st = amscr_contours_from_mask(img, w, h, w, 127, min_area, &s);
    ck_assert_msg(st == AMSCR_OK, "status %d: %s", (int)st, amscr_last_error_detail());
    return s;
}

/* A square ring with a square blob in its hole, and a separate small square. */
static uint8_t *nested_image(size_t w, size_t h)
{
    uint8_t *img = img_new(w, h, 0);
    fill_rect(img, w, 4, 4, 35, 35, 255);   /* outer square */
    fill_rect(img, w, 10, 10, 29, 29, 0);   /* its hole */
    fill_rect(img, w, 15, 15, 24, 24, 255); /* a blob in the hole */
    fill_rect(img, w, 42, 5, 45, 8, 255);   /* a small separate square (4 x 4 pixels) */
    return img;
}

START_TEST(hierarchy_of_nested_shapes)
{
    size_t w = 50, h = 40;
    uint8_t *img = nested_image(w, h);
    amscr_contour_set *s = all_ok(img, w, h, 0.0);
    /* raster order of first pixels: outer (4,4), small square (42,5), hole (10,10), blob (15,15) */
    ck_assert_uint_eq(amscr_contour_set_size(s), 4);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 0), AMSCR_NO_PARENT);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 1), AMSCR_NO_PARENT);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 2), 0);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 3), 2);
    int holes[4] = {0, 0, 1, 0};
    double areas[4] = {31.0 * 31.0, 3.0 * 3.0, 19.0 * 19.0, 9.0 * 9.0}; /* polygons through pixel centres */
    for (size_t i = 0; i < 4; i++) {
        const amscr_contour *c = amscr_contour_set_contour(s, i);
        ck_assert_ptr_nonnull(c);
        ck_assert_int_eq(amscr_contour_set_is_hole(s, i), holes[i]);
        ck_assert_double_eq_tol(amscr_contour_set_area(s, i), areas[i], 1e-9);
        ck_assert_double_eq_tol(signed_area(c), holes[i] ? -areas[i] : areas[i], 1e-9);
    }
    /* the hole's contour runs through its own (background) boundary pixels */
    const amscr_contour *hole = amscr_contour_set_contour(s, 2);
    const double *xy = amscr_contour_xy(hole);
    for (size_t i = 0; i < amscr_contour_size(hole); i++) {
        ck_assert(xy[2 * i] >= 10 && xy[2 * i] <= 29 && xy[2 * i + 1] >= 10 && xy[2 * i + 1] <= 29);
        ck_assert_int_eq(img[(size_t)xy[2 * i + 1] * w + (size_t)xy[2 * i]], 0);
    }
    ck_assert_ptr_null(amscr_contour_set_contour(s, 4));
    ck_assert_uint_eq(amscr_contour_set_parent(s, 4), AMSCR_NO_PARENT);
    amscr_contour_set_free(s);
    free(img);
}
END_TEST

START_TEST(min_area_drops_small_contours_and_their_children)
{
    size_t w = 50, h = 40;
    uint8_t *img = nested_image(w, h);
    amscr_contour_set *s = all_ok(img, w, h, 10.0); /* drops the 3x3 square */
    ck_assert_uint_eq(amscr_contour_set_size(s), 3);
    ck_assert_uint_eq(amscr_contour_set_parent(s, 2), 1);
    amscr_contour_set_free(s);
    s = all_ok(img, w, h, 400.0); /* drops the hole (361) and so the blob inside it */
    ck_assert_uint_eq(amscr_contour_set_size(s), 1);
    ck_assert_int_eq(amscr_contour_set_is_hole(s, 0), 0);
    amscr_contour_set_free(s);
    amscr_contour_set *none = NULL;
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, 1e6, &none), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_null(none);
    free(img);
}
END_TEST

/* The largest outer contour is amscr_contour_from_mask's, point for point. */
START_TEST(largest_outer_is_the_single_trace)
{
    size_t w = 64, h = 48;
    uint8_t *img = img_new(w, h, 0);
    unsigned seed = 12345u + (unsigned)_i;
    for (int k = 0; k < 6; k++) { /* random overlapping discs: shapes with holes and parts */
        seed = seed * 1103515245u + 12345u;
        double cx = (double)(seed >> 8 & 63), cy = (double)(seed >> 16 & 47), r = 3 + (double)(seed >> 24 & 15);
        int ring = k % 2;
        for (size_t y = 0; y < h; y++)
            for (size_t x = 0; x < w; x++) {
                double d = sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy));
                if (d <= r && (!ring || d >= r / 2))
                    img[y * w + x] = 255;
            }
    }
    amscr_contour *one = NULL;
    amscr_status st1 = amscr_contour_from_mask(img, w, h, w, 127, &one);
    amscr_contour_set *s = NULL;
    amscr_status st2 = amscr_contours_from_mask(img, w, h, w, 127, 0.0, &s);
    if (st1 == AMSCR_OK) {
        ck_assert_int_eq(st2, AMSCR_OK);
        /* every contour: closed 8-connected chain, parents before children */
        int found = 0;
        for (size_t i = 0; i < amscr_contour_set_size(s); i++) {
            const amscr_contour *c = amscr_contour_set_contour(s, i);
            size_t n = amscr_contour_size(c), par = amscr_contour_set_parent(s, i);
            const double *xy = amscr_contour_xy(c);
            ck_assert(par == AMSCR_NO_PARENT || par < i);
            if (par != AMSCR_NO_PARENT)
                ck_assert_int_ne(amscr_contour_set_is_hole(s, par), amscr_contour_set_is_hole(s, i));
            for (size_t k = 0; k < n; k++) {
                size_t j = (k + 1) % n;
                ck_assert(fabs(xy[2 * j] - xy[2 * k]) <= 1 && fabs(xy[2 * j + 1] - xy[2 * k + 1]) <= 1);
            }
            if (n == amscr_contour_size(one) && memcmp(xy, amscr_contour_xy(one), 2 * n * sizeof *xy) == 0)
                found = 1;
        }
        ck_assert_msg(found, "the single trace is one of the contours");
    }
    amscr_contour_free(one);
    amscr_contour_set_free(s);
    free(img);
}
END_TEST

START_TEST(polarity_and_errors)
{
    size_t w = 20, h = 20;
    uint8_t *img = img_new(w, h, 255);
    fill_rect(img, w, 5, 5, 14, 14, 0); /* dark square on a bright background */
    amscr_contour_set *s = all_ok(img, w, h, 0.0);
    ck_assert_uint_eq(amscr_contour_set_size(s), 1);
    ck_assert_double_eq_tol(amscr_contour_set_area(s, 0), 81.0, 1e-12);
    amscr_contour_set_free(s);
    s = NULL;
    ck_assert_int_eq(amscr_contours_from_mask(NULL, w, h, w, 127, 0.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, 0.0, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, 0, h, w, 127, 0.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w - 1, 127, 0.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 255, 0.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, -1.0, &s), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, NAN, &s), AMSCR_E_INVALID_ARG);
    memset(img, 0, w * h);
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, 0.0, &s), AMSCR_E_NOT_FOUND);
    img[3 * w + 3] = 255; /* one pixel: no area */
    ck_assert_int_eq(amscr_contours_from_mask(img, w, h, w, 127, 0.0, &s), AMSCR_E_NOT_FOUND);
    ck_assert_ptr_null(s);
    ck_assert_uint_eq(amscr_contour_set_size(NULL), 0);
    amscr_contour_set_free(NULL);
    free(img);
}
END_TEST

Suite *amscr_suite_trace_all(void)
{
    Suite *s = suite_create("trace_all");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, hierarchy_of_nested_shapes);
    tcase_add_test(tc, min_area_drops_small_contours_and_their_children);
    tcase_add_loop_test(tc, largest_outer_is_the_single_trace, 0, 100);
    tcase_add_test(tc, polarity_and_errors);
    suite_add_tcase(s, tc);
    return s;
}
