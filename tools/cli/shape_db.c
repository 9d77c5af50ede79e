/* shape_db.c — the collection steps that search, matrix and eval share (see shape_db.h). */
#include "shape_db.h"

#include <stdint.h>
#include <stdlib.h>

#include "image.h"

void retrieval_tracing(void) { image_set_trace_flags(image_trace_flags() | AMSCR_TRACE_JOIN); }

int retrieval_is_plain(const amscr_params *p)
{
    amscr_ranking r = AMSCR_RANKING_RETRIEVAL;
    return amscr_params_ranking(p, &r) == AMSCR_OK && r == AMSCR_RANKING_DISTANCE;
}

int compute_matrix(const amscr_db *db, const char *what, double **out)
{
    size_t n = amscr_db_size(db);
    if (n != 0 && n > SIZE_MAX / n / sizeof(double)) {
        tool_error(what, "too many shapes for a matrix (%zu)", n);
        return -1;
    }
    double *d = xmalloc_array(n * n, sizeof(double));
    if (d == NULL)
        return -1;
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = retrieval_is_plain(amscr_db_params(db)) ? amscr_db_distance_matrix(db, progress_cb, &pr, d)
                                                              : amscr_db_retrieval_matrix(db, progress_cb, &pr, d);
    progress_end(&pr);
    if (st != AMSCR_OK) {
        tool_lib_error(what, st);
        free(d);
        return -1;
    }
    *out = d;
    return 0;
}
