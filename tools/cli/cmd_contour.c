/* cmd_contour.c — `amscr contour IMG [-o FILE] [--join | --all [--json]]`: the traced points of a
 * silhouette, or every contour of the image with its hierarchy. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "components.h"
#include "image.h"
#include "json.h"

static int write_points(FILE *fp, const amscr_contour *c)
{
    const double *xy = amscr_contour_xy(c);
    size_t n = amscr_contour_size(c);
    for (size_t i = 0; i < n; i++)
        if (fprintf(fp, "%.17g %.17g\n", xy[2 * i], xy[2 * i + 1]) < 0)
            return -1;
    return 0;
}

/* Text: per contour a comment line "# contour I: outer|hole, parent P|-, area A, N points",
 * its points, and a blank line between contours. */
static void format_all_text(sbuf *b, const amscr_contour_set *s)
{
    for (size_t i = 0; i < amscr_contour_set_size(s); i++) {
        const amscr_contour *c = amscr_contour_set_contour(s, i);
        size_t par = amscr_contour_set_parent(s, i), n = amscr_contour_size(c);
        char a[32];
        sb_printf(b, "%s# contour %zu: %s, parent ", i ? "\n" : "", i, amscr_contour_set_is_hole(s, i) ? "hole" : "outer");
        if (par == AMSCR_NO_PARENT)
            sb_puts(b, "-");
        else
            sb_printf(b, "%zu", par);
        sb_printf(b, ", area %s, %zu points\n", fmt_num(a, amscr_contour_set_area(s, i)), n);
        const double *xy = amscr_contour_xy(c);
        for (size_t k = 0; k < n; k++)
            sb_printf(b, "%.17g %.17g\n", xy[2 * k], xy[2 * k + 1]);
    }
}

static void format_all_json(sbuf *b, const char *path, const amscr_contour_set *s)
{
    sb_puts(b, "{\"image\": ");
    sb_json_str(b, path);
    sb_printf(b, ", \"count\": %zu, \"contours\": [", amscr_contour_set_size(s));
    for (size_t i = 0; i < amscr_contour_set_size(s); i++) {
        const amscr_contour *c = amscr_contour_set_contour(s, i);
        size_t par = amscr_contour_set_parent(s, i), n = amscr_contour_size(c);
        sb_printf(b, "%s{\"index\": %zu, \"parent\": ", i ? ", " : "", i);
        if (par == AMSCR_NO_PARENT)
            sb_puts(b, "null");
        else
            sb_printf(b, "%zu", par);
        sb_printf(b, ", \"hole\": %s, \"area\": ", amscr_contour_set_is_hole(s, i) ? "true" : "false");
        sb_json_num(b, amscr_contour_set_area(s, i));
        sb_puts(b, ", \"points\": [");
        const double *xy = amscr_contour_xy(c);
        for (size_t k = 0; k < n; k++) {
            sb_puts(b, k ? ", [" : "[");
            sb_json_num(b, xy[2 * k]);
            sb_puts(b, ", ");
            sb_json_num(b, xy[2 * k + 1]);
            sb_puts(b, "]");
        }
        sb_puts(b, "]}");
    }
    sb_puts(b, "]}\n");
}

/* Writes b to -o FILE (atomically) or stdout. */
static int write_out(const opts *o, const sbuf *b)
{
    if (o->out == NULL || strcmp(o->out, "-") == 0)
        return sb_write_stdout(b) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
    if (b->oom) {
        tool_error(NULL, "out of memory");
        return TOOL_EXIT_FAIL;
    }
    tool_out out;
    if (tool_out_open(&out, o->out) != 0)
        return TOOL_EXIT_FAIL;
    if (b->len && fwrite(b->s, 1, b->len, out.fp) != b->len) {
        tool_error(o->out, "write error: %s", strerror(errno));
        tool_out_abort(&out);
        return TOOL_EXIT_FAIL;
    }
    return tool_out_commit(&out) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
}

static int contour_all(opts *o)
{
    amscr_contour_set *s = NULL;
    if (shape_contours(o->pos[0], o->threshold, o->min_area, &s) != 0)
        return TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    if (o->json)
        format_all_json(&b, o->pos[0], s);
    else
        format_all_text(&b, s);
    amscr_contour_set_free(s);
    int r = write_out(o, &b);
    sb_free(&b);
    return r;
}

int cmd_contour(opts *o)
{
    if (tool_out_not_input("-o", o->out, (const char *const *)o->pos, 1) != 0)
        return TOOL_EXIT_FAIL;
    if (o->json && !o->all)
        return usage_error("--json", "only with --all (the single contour is a plain point list)");
    if (o->join && (o->all || (image_trace_flags() & AMSCR_TRACE_PIXEL_CHAIN)))
        return usage_error("--join", "joins pieces to the one sub-pixel outline (not with %s)",
                           o->all ? "--all" : "--pixel-chain");
    if (o->all)
        return contour_all(o);
    if (o->join)
        image_set_trace_flags(image_trace_flags() | AMSCR_TRACE_JOIN);
    amscr_contour *c = NULL;
    if (shape_load(o->pos[0], o->threshold, &c) != 0)
        return TOOL_EXIT_FAIL;
    tool_out out;
    if (tool_out_open(&out, o->out ? o->out : "-") != 0) {
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    if (write_points(out.fp, c) != 0) {
        tool_error(o->out && strcmp(o->out, "-") != 0 ? o->out : "<stdout>", "write error: %s", strerror(errno));
        tool_out_abort(&out);
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    amscr_contour_free(c);
    return tool_out_commit(&out) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
}
