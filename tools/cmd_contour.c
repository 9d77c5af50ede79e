/* cmd_contour.c — `amscr contour IMG [-o FILE]`: the traced points of a silhouette. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "image.h"

static int write_points(FILE *fp, const amscr_contour *c)
{
    const double *xy = amscr_contour_xy(c);
    size_t n = amscr_contour_size(c);
    for (size_t i = 0; i < n; i++)
        if (fprintf(fp, "%.17g %.17g\n", xy[2 * i], xy[2 * i + 1]) < 0)
            return -1;
    return 0;
}

int cmd_contour(opts *o)
{
    amscr_contour *c = NULL;
    if (shape_load(o->pos[0], o->threshold, &c) != 0)
        return TOOL_EXIT_FAIL;
    tool_out out;
    if (tool_out_open(&out, o->out ? o->out : "-") != 0) {
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    if (write_points(out.fp, c) != 0) {
        tool_error(o->out ? o->out : "<stdout>", "write error: %s", strerror(errno));
        tool_out_abort(&out);
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    amscr_contour_free(c);
    return tool_out_commit(&out) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
}

