/* sheet.h — the contact sheet of `amscr search --sheet FILE.png|svg`: the query and its hits
 * as thumbnails, each hit drawn registered onto the query, with rank, class, distance and
 * file name under it. Tool-internal. */
#ifndef AMSCR_TOOL_SHEET_H
#define AMSCR_TOOL_SHEET_H

#include <stddef.h>

typedef struct sheet_tile {
    const double *base; /* the query's points (filled grey, dark outline) */
    size_t nb;
    const double *over; /* the hit mapped onto the query (red outline); NULL on the query's tile */
    size_t no;
    char title[64];     /* "query" or "1  bird  0.0123" */
    const char *name;   /* file name (not copied) */
} sheet_tile;

/* Writes the sheet (format from the extension: .png or .svg), tiles in rows of up to 4.
 * Coordinates are drawn y down (image convention), each tile scaled to fit its shapes.
 * Returns 0, or -1 after printing one error line. */
int draw_sheet(const char *path, const sheet_tile *tiles, size_t n, int closed);

#endif
