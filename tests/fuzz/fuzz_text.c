/* fuzz_text.c — the text point-list parser, amscr_contour_parse_text, on arbitrary bytes.
 * Properties: success gives 1..AMSCR_MAX_POINTS finite points; failure gives a non-empty
 * detail and no object; the contour then goes through the cheap contour calls. */
#include <math.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_parse_text((const char *)data, size, &c);
    if (st != AMSCR_OK) {
        FUZZ_CHECK(c == NULL);
        FUZZ_CHECK(st == AMSCR_E_FORMAT || st == AMSCR_E_LIMIT || st == AMSCR_E_NOMEM);
        FUZZ_CHECK(amscr_last_error_detail()[0] != '\0');
        return 0;
    }
    FUZZ_CHECK(c != NULL);
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    FUZZ_CHECK(n >= 1 && n <= AMSCR_MAX_POINTS && xy != NULL);
    for (size_t i = 0; i < 2 * n; i++)
        FUZZ_CHECK(isfinite(xy[i]));
    double area = 0.0;
    FUZZ_CHECK(amscr_contour_signed_area(c, &area) == AMSCR_OK);
    st = amscr_contour_validate(c, 1);
    FUZZ_CHECK(st == AMSCR_OK || st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG);
    st = amscr_contour_validate(c, 0);
    FUZZ_CHECK(st == AMSCR_OK || st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG);
    FUZZ_CHECK(amscr_contour_orient_ccw(c) == AMSCR_OK);
    amscr_contour_free(c);
    return 0;
}
