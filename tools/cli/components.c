/* components.c — every contour of an image (see components.h). */
#include "components.h"

#include "image.h"
#include "util.h"

int shape_contours(const char *path, int threshold, double min_area, amscr_contour_set **out)
{
    tool_image img;
    tool_format f;
    int r = image_read(path, 1, &img, &f);
    if (r < 0)
        return -1;
    if (r > 0) {
        image_free(&img);
        tool_error(path, "not an image: every contour (--all, --component) needs a PNG or PGM image");
        return -1;
    }
    int bits;
    const void *pixels;
    double level = image_level(&img, threshold, &bits, &pixels);
    amscr_status st = amscr_contours_from_image(pixels, img.width, img.height, img.width, bits, level,
                                                image_trace_flags() & AMSCR_TRACE_PIXEL_CHAIN, min_area, out);
    if (st == AMSCR_E_NOT_FOUND)
        image_no_shape_error(path, &img, threshold, "no contour", lib_detail());
    else if (st != AMSCR_OK)
        tool_lib_error(path, st);
    image_free(&img);
    return st == AMSCR_OK ? 0 : -1;
}

int shape_load_opts(const opts *o, const char *path, amscr_contour **out)
{
    if (o->component < 0)
        return shape_load(path, o->threshold, out);
    amscr_contour_set *s = NULL;
    if (shape_contours(path, o->threshold, o->min_area, &s) != 0)
        return -1;
    size_t n = amscr_contour_set_size(s), k = (size_t)o->component;
    if (k >= n) {
        tool_error(path, "--component %zu: the image has %zu contour%s of area >= %g (0..%zu; see 'amscr contour "
                   "--all')", k, n, n == 1 ? "" : "s", o->min_area, n - 1);
        amscr_contour_set_free(s);
        return -1;
    }
    const amscr_contour *c = amscr_contour_set_contour(s, k);
    amscr_status st = amscr_contour_new(amscr_contour_xy(c), amscr_contour_size(c), out);
    if (st == AMSCR_OK)
        st = amscr_contour_orient_ccw(*out);
    amscr_contour_set_free(s);
    if (st != AMSCR_OK) {
        amscr_contour_free(*out);
        *out = NULL;
        tool_lib_error(path, st);
        return -1;
    }
    return 0;
}
