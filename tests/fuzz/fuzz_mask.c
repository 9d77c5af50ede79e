/* fuzz_mask.c — amscr_contour_from_mask on arbitrary 8-bit images.
 * Input: byte 0 = width - 1, byte 1 = height - 1, byte 2 = stride - width (mod 16),
 * byte 3 = threshold (255 means AMSCR_THRESHOLD_AUTO), then the pixel rows. The height (and
 * if needed the width) shrinks to what the input holds; the pixels are copied into a buffer
 * of exactly stride*(height-1)+width bytes, so any read past the last pixel is caught.
 * Properties on success: >= 3 points, integer pixel centres inside the image, consecutive
 * points (cyclically) 8-adjacent and distinct, signed area >= 0, and with a fixed threshold
 * every boundary pixel on the same side of it. */
#include <math.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 5)
        return 0;
    size_t w = (size_t)data[0] + 1, h = (size_t)data[1] + 1, stride = w + data[2] % 16;
    int thr = data[3] == 255 ? AMSCR_THRESHOLD_AUTO : data[3];
    const uint8_t *px = data + 4;
    size_t avail = size - 4;
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
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_mask(buf, w, h, stride, thr, &c);
    if (st != AMSCR_OK) {
        FUZZ_CHECK(c == NULL);
        FUZZ_CHECK(st == AMSCR_E_NOT_FOUND || st == AMSCR_E_DEGENERATE);
        free(buf);
        return 0;
    }
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    FUZZ_CHECK(n >= 3);
    int side = -1;
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        FUZZ_CHECK(x >= 0 && x <= (double)(w - 1) && y >= 0 && y <= (double)(h - 1));
        FUZZ_CHECK(x == floor(x) && y == floor(y));
        size_t j = (i + 1) % n;
        double dx = fabs(xy[2 * j] - x), dy = fabs(xy[2 * j + 1] - y);
        FUZZ_CHECK(dx <= 1 && dy <= 1 && dx + dy > 0);
        if (thr != AMSCR_THRESHOLD_AUTO) {
            int on = buf[(size_t)y * stride + (size_t)x] > thr;
            if (side < 0)
                side = on;
            FUZZ_CHECK(on == side);
        }
    }
    double area = 0.0;
    FUZZ_CHECK(amscr_contour_signed_area(c, &area) == AMSCR_OK);
    FUZZ_CHECK(area >= 0.0);
    amscr_contour_free(c);
    free(buf);
    return 0;
}
