/* eval_plot.h — the picture of `amscr eval --plot FILE.svg`: each class's scores as
 * horizontal bars, and the precision-recall curve of the collection. Tool-internal. */
#ifndef AMSCR_TOOL_EVAL_PLOT_H
#define AMSCR_TOOL_EVAL_PLOT_H

#include <stddef.h>

typedef struct score_series {
    const char *name;    /* "1-NN", "bull's eye", ... */
    const double *value; /* one per class, in 0..1 (NaN: not drawn) */
} score_series;

typedef struct eval_plot_input {
    const char *title;
    char *const *classes;
    size_t nclasses;
    const score_series *series; /* up to 3 */
    size_t nseries;
    const double *recall, *precision; /* the curve, npr points (npr 0: no curve panel) */
    size_t npr;
} eval_plot_input;

/* Writes the SVG. Returns 0, or -1 after printing one error line. */
int draw_eval_plot(const char *path, const eval_plot_input *in);

#endif
