/* rows.h — a collection's rows on POSIX threads (rows.c): rows handed out one at a time, each
 * computed by the same code whatever thread runs it, so a result computed row by row does not
 * depend on the thread count; and the cells of a distance matrix alike (db_matrix.c). Never
 * installed. */
#ifndef AMSCR_ROWS_H
#define AMSCR_ROWS_H

#include "internal.h"

/* Work on rows first..n-1: row(ctx, i, scratch) with a scratch per thread from init (may be
 * NULL) freed by fini; `what` (NULL: "index") names the work in error details. */
typedef struct {
    amscr_status (*init)(void *ctx, void **scratch);
    void (*fini)(void *scratch);
    amscr_status (*row)(void *ctx, size_t i, void *scratch);
    void *ctx;
    const char *what;
} amscr__rows_fn;

/* Runs f's rows on `threads` threads (the calling one too, which alone reports progress: rows
 * done of n - first, and n - first of n - first at the end). The first failing row's status
 * and detail; AMSCR_E_CANCELLED when progress asked to stop. */
amscr_status amscr__run_rows(const amscr__rows_fn *f, size_t first, size_t n, unsigned threads,
                             amscr_progress_fn progress, void *user);

/* The nrows x ncols distances rows[i] -> cols[j] (prm) into out, row-major, on prm's threads
 * (db_matrix.c: row blocks, or column blocks of a single row; the calling thread works too and
 * alone reports progress, in cells, from 0 before any worker starts to the total at the end).
 * skip_diag: cell (i, i) is 0, not computed. A failure or a cancel leaves every cell NaN. */
amscr_status amscr__distance_cells(const amscr_params *prm, const amscr_descriptor *const *rows, size_t nrows,
                                   const amscr_descriptor *const *cols, size_t ncols, int skip_diag,
                                   amscr_progress_fn progress, void *user, double *out);

#endif
