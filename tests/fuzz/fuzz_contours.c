/* fuzz_contours.c — amscr_contours_from_mask on arbitrary 8-bit images.
 * Input as fuzz_mask.c: byte 0 = width - 1, byte 1 = height - 1, byte 2 = stride - width
 * (mod 16), byte 3 = threshold (255 means AMSCR_THRESHOLD_AUTO), then byte 4 = min_area, then
 * the pixel rows, copied into a buffer of exactly stride*(height-1)+width bytes.
 * Properties on success: >= 1 contour; each has >= 3 integer points inside the image,
 * consecutive points (cyclically) 8-adjacent and distinct, |signed area| = the reported area
 * >= min_area, positive for outer contours and negative for holes; parents come first and
 * alternate outer / hole; with a fixed threshold an outer contour's pixels are all on one
 * side of it and a hole's on the other. */
#include <math.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

static void check_contour(const amscr_contour_set *s, size_t i, const uint8_t *buf, size_t w, size_t h,
                          size_t stride, int thr, double min_area, int *side)
{
    const amscr_contour *c = amscr_contour_set_contour(s, i);
    FUZZ_CHECK(c != NULL);
    size_t n = amscr_contour_size(c), par = amscr_contour_set_parent(s, i);
    const double *xy = amscr_contour_xy(c);
    int hole = amscr_contour_set_is_hole(s, i);
    FUZZ_CHECK(n >= 3);
    FUZZ_CHECK(par == AMSCR_NO_PARENT || (par < i && amscr_contour_set_is_hole(s, par) != hole));
    FUZZ_CHECK(par != AMSCR_NO_PARENT || !hole);
    for (size_t k = 0; k < n; k++) {
        double x = xy[2 * k], y = xy[2 * k + 1];
        FUZZ_CHECK(x >= 0 && x <= (double)(w - 1) && y >= 0 && y <= (double)(h - 1));
        FUZZ_CHECK(x == floor(x) && y == floor(y));
        size_t j = (k + 1) % n;
        double dx = fabs(xy[2 * j] - x), dy = fabs(xy[2 * j + 1] - y);
        FUZZ_CHECK(dx <= 1 && dy <= 1 && dx + dy > 0);
        if (thr != AMSCR_THRESHOLD_AUTO) {
            int on = (buf[(size_t)y * stride + (size_t)x] > thr) ^ hole; /* 1: the component's side */
            if (*side < 0)
                *side = on;
            FUZZ_CHECK(on == *side);
        }
    }
    double a = 0.0;
    FUZZ_CHECK(amscr_contour_signed_area(c, &a) == AMSCR_OK);
    FUZZ_CHECK(hole ? a < 0 : a > 0);
    FUZZ_CHECK(fabs(fabs(a) - amscr_contour_set_area(s, i)) <= 1e-9 * (1 + fabs(a)));
    FUZZ_CHECK(fabs(a) >= min_area);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 6)
        return 0;
    size_t w = (size_t)data[0] + 1, h = (size_t)data[1] + 1, stride = w + data[2] % 16;
    int thr = data[3] == 255 ? AMSCR_THRESHOLD_AUTO : data[3];
    double min_area = (double)data[4];
    const uint8_t *px = data + 5;
    size_t avail = size - 5;
    if (avail < w) {
        w = avail;
        stride = w + data[2] % 16;
        h = 1;
    } else if (stride * (h - 1) + w > avail) {
        h = (avail - w) / stride + 1;
    }
    size_t need = stride * (h - 1) + w;
    uint8_t *buf = malloc(need);
    if (!buf)
        return 0;
    memcpy(buf, px, need);
    amscr_contour_set *s = NULL;
    amscr_status st = amscr_contours_from_mask(buf, w, h, stride, thr, min_area, &s);
    if (st != AMSCR_OK) {
        FUZZ_CHECK(s == NULL);
        FUZZ_CHECK(st == AMSCR_E_NOT_FOUND);
        free(buf);
        return 0;
    }
    FUZZ_CHECK(amscr_contour_set_size(s) >= 1);
    int side = -1; /* the polarity is the same for every contour: on/off of the component */
    for (size_t i = 0; i < amscr_contour_set_size(s); i++)
        check_contour(s, i, buf, w, h, stride, thr, min_area, &side);
    amscr_contour_set_free(s);
    free(buf);
    return 0;
}
