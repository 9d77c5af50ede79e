/* fuzz_subpixel.c — amscr_contour_from_image and amscr_contours_from_image (sub-pixel
 * iso-lines) on arbitrary 8- and 16-bit images.
 * Input: byte 0 = width - 1, byte 1 = height - 1, byte 2 = stride - width (mod 16) with bit 0x80
 * for 16-bit samples, byte 3 = level byte L (255: automatic; else L + 0.5, times 257 for 16
 * bits), byte 4 = mode (bit 0: every contour, bit 1: AMSCR_TRACE_PIXEL_CHAIN, bit 2:
 * AMSCR_TRACE_JOIN, which every contour refuses), then the samples
 * (16-bit: two bytes each, native order). The height (and if needed the width) shrinks to what
 * the input holds; the samples are copied into a buffer of exactly the size the image needs.
 * Properties on success: >= 3 finite points inside the padded image, each on a pixel-grid line
 * (x or y an integer) for the sub-pixel path, consecutive points distinct, outer contours with
 * positive signed area and holes negative, parents before their children. */
#include <math.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

static void check_contour(const amscr_contour *c, size_t w, size_t h, int subpixel, int hole)
{
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    FUZZ_CHECK(n >= 3);
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        FUZZ_CHECK(isfinite(x) && isfinite(y));
        FUZZ_CHECK(x >= -0.5 && x <= (double)w - 0.5 && y >= -0.5 && y <= (double)h - 0.5);
        if (subpixel)
            FUZZ_CHECK(x == floor(x) || y == floor(y));
        size_t j = (i + 1) % n;
        FUZZ_CHECK(xy[2 * j] != x || xy[2 * j + 1] != y);
    }
    double area = 0.0;
    FUZZ_CHECK(amscr_contour_signed_area(c, &area) == AMSCR_OK);
    FUZZ_CHECK(hole ? area < 0.0 : area > 0.0);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 6)
        return 0;
    int bits = data[2] & 0x80 ? 16 : 8;
    size_t bps = (size_t)bits / 8;
    size_t w = (size_t)data[0] + 1, h = (size_t)data[1] + 1, pad = (size_t)(data[2] & 0x7f) % 16;
    double level = data[3] == 255 ? AMSCR_LEVEL_AUTO : (data[3] + 0.5) * (bits == 16 ? 257.0 : 1.0);
    int all = data[4] & 1, chain = data[4] & 2 ? AMSCR_TRACE_PIXEL_CHAIN : 0;
    int flags = chain | (data[4] & 4 ? AMSCR_TRACE_JOIN : 0);
    size_t avail = (size - 5) / bps;
    if (avail < w) {
        w = avail;
        h = 1;
    } else if ((w + pad) * (h - 1) + w > avail) {
        h = (avail - w) / (w + pad) + 1;
    }
    size_t stride = w + pad, need = stride * (h - 1) + w;
    void *buf = malloc(need * bps);
    if (!buf)
        return 0;
    memcpy(buf, data + 5, need * bps);
    if (!all) {
        amscr_contour *c = NULL;
        amscr_status st = amscr_contour_from_image(buf, w, h, stride, bits, level, flags, &c);
        if (st == AMSCR_OK)
            check_contour(c, w, h, !chain, 0);
        else
            FUZZ_CHECK(c == NULL && (st == AMSCR_E_NOT_FOUND || st == AMSCR_E_DEGENERATE ||
                                     (w == 0 && st == AMSCR_E_INVALID_ARG)));
        amscr_contour_free(c);
    } else {
        amscr_contour_set *s = NULL;
        amscr_status st = amscr_contours_from_image(buf, w, h, stride, bits, level, flags, 0.0, &s);
        if (st == AMSCR_OK) {
            FUZZ_CHECK(amscr_contour_set_size(s) >= 1);
            for (size_t i = 0; i < amscr_contour_set_size(s); i++) {
                size_t p = amscr_contour_set_parent(s, i);
                FUZZ_CHECK(p == AMSCR_NO_PARENT || p < i);
                check_contour(amscr_contour_set_contour(s, i), w, h, !chain, amscr_contour_set_is_hole(s, i));
            }
            FUZZ_CHECK(!(flags & AMSCR_TRACE_JOIN));
        } else {
            FUZZ_CHECK(s == NULL && (st == AMSCR_E_NOT_FOUND ||
                                     ((w == 0 || (flags & AMSCR_TRACE_JOIN)) && st == AMSCR_E_INVALID_ARG)));
        }
        amscr_contour_set_free(s);
    }
    free(buf);
    return 0;
}
