/* draw.h — pictures of the amscr tool: the registration overlay (PNG or SVG) and the
 * scale-selection plot (SVG: residual per scale with the Bayes threshold, elbow curve).
 * Files are written atomically (temporary name + rename). */
#ifndef AMSCR_TOOL_DRAW_H
#define AMSCR_TOOL_DRAW_H

#include <stddef.h>

typedef struct overlay_input {
    const double *target; /* interleaved points, input coordinates */
    size_t nt;
    const double *before; /* the source as given */
    size_t nb;
    const double *after; /* the source mapped by (A, B) */
    size_t na;
    int closed;
    int source_open; /* the source is an open fragment of the closed target (--partial) */
    const char *target_name;
    const char *source_name;
    const char *caption; /* one line under the legend, may be NULL */
} overlay_input;

/* Writes the overlay; the format comes from the extension (.png or .svg, case-insensitive).
 * Coordinates are drawn with y pointing down (image convention), aspect ratio kept.
 * Returns 0, or -1 after printing one error line. */
int draw_overlay(const char *path, const overlay_input *in);

typedef struct plot_input {
    const double *scales;    /* p scale values sigma_k */
    const double *residuals; /* p residuals L2_k */
    const int *kept;         /* p flags */
    size_t p;
    double threshold;        /* Bayes threshold s0 (+inf: no threshold) */
    const double *sse;       /* SSE(K), K = 1..kmax (may be NULL / zeros for acma, amscr) */
    size_t kmax;
    size_t k;                /* K chosen by the elbow (0 when none) */
    const char *title;
} plot_input;

/* Writes the two-panel SVG plot. Returns 0, or -1 after printing one error line. */
int draw_plot_svg(const char *path, const plot_input *in);

/* Non-zero when `path` has an extension the overlay accepts (.png, .svg). */
int draw_overlay_ext_ok(const char *path);

#endif
