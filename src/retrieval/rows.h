/* rows.h — a collection's rows on POSIX threads (rows.c): row i of n handed out dynamically,
 * each thread with its own scratch, so a result computed row by row does not depend on the
 * thread count. Never installed. */
#ifndef AMSCR_ROWS_H
#define AMSCR_ROWS_H

#include "internal.h"

typedef struct {
    /* a thread's scratch (*ws; may stay NULL): AMSCR_OK or AMSCR_E_NOMEM */
    amscr_status (*ws_init)(const void *ctx, void **ws);
    void (*ws_free)(void *ws);
    /* row i's work (must not fail: a row that can fail records it in ctx) */
    void (*row)(const void *ctx, size_t i, void *ws);
    const char *what; /* the error messages' subject, e.g. "shape channel" */
} amscr__rows_ops;

/* Runs ops->row for i = 0..n-1 on `threads` threads (the calling one too, which alone
 * reports progress: `cells` cells a row, of n * cells). AMSCR_E_NOMEM when a scratch could
 * not be made, AMSCR_E_CANCELLED when progress asked to stop (rows may then be missing). */
amscr_status amscr__rows_run(size_t n, const amscr__rows_ops *ops, const void *ctx, unsigned threads, size_t cells,
                             amscr_progress_fn progress, void *user);

#endif
