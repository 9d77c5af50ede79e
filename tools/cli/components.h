/* components.h — every contour of an image for the tool: `contour --all` and the
 * `--component N` of register and search (amscr_contours_from_image). Tool-internal. */
#ifndef AMSCR_TOOL_COMPONENTS_H
#define AMSCR_TOOL_COMPONENTS_H

#include "amscr.h"
#include "cli.h"

/* Every contour of the image at `path` (an image, not a point list). On failure prints one
 * error line naming path and returns -1. */
int shape_contours(const char *path, int threshold, double min_area, amscr_contour_set **out);

/* The shape the command uses from `path`: the largest outer contour (shape_load), or with
 * --component N (o->component >= 0) contour N of `contour --all`, oriented counter-clockwise.
 * On failure prints one error line and returns -1. */
int shape_load_opts(const opts *o, const char *path, amscr_contour **out);

#endif
