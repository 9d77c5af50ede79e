/* db_matrix.c — the cells of a distance matrix on POSIX threads (a collection's 1-vs-many,
 * many-vs-many and cross matrices, db.c), with progress and cancellation; bit-identical for any
 * thread count: every cell is computed independently by the same code.
 *
 * Threads: the calling thread works too and is the only one that calls the progress
 * callback. The batch path makes no BLAS/LAPACK calls (closed-form 3x3 solves), so
 * OpenBLAS's own threads never compete with ours. */
#include "rows.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const amscr_params *prm;
    const amscr_descriptor *const *rows; /* sources */
    const amscr_descriptor *const *cols; /* targets */
    size_t nrows, ncols;
    int skip_diag;
    double *out;
    size_t rows_per_item; /* items are row blocks */
    size_t cols_per_item; /* ... or column blocks when nrows == 1 */
    size_t nitems;
    pthread_mutex_t lock;
    size_t next, done;
    int cancel;
    amscr_status status;
    char detail[256];
} batch_t;

static void batch_item(batch_t *b, amscr_workspace *ws, size_t item, amscr_status *st)
{
    size_t r0, r1, c0, c1;
    if (b->nrows == 1) {
        r0 = 0;
        r1 = 1;
        c0 = item * b->cols_per_item;
        c1 = c0 + b->cols_per_item < b->ncols ? c0 + b->cols_per_item : b->ncols;
    } else {
        r0 = item * b->rows_per_item;
        r1 = r0 + b->rows_per_item < b->nrows ? r0 + b->rows_per_item : b->nrows;
        c0 = 0;
        c1 = b->ncols;
    }
    for (size_t i = r0; i < r1 && *st == AMSCR_OK; i++)
        for (size_t j = c0; j < c1; j++) {
            double *cell = b->out + i * b->ncols + j;
            if (b->skip_diag && i == j) {
                *cell = 0.0;
                continue;
            }
            *st = amscr__distance_ws(b->prm, b->rows[i], b->cols[j], ws, cell);
            if (*st != AMSCR_OK)
                break;
        }
}

/* Takes the next item; returns 0 when there is none (or cancelled/failed). */
static int batch_take(batch_t *b, size_t *item)
{
    int ok = 0;
    pthread_mutex_lock(&b->lock);
    if (!b->cancel && b->status == AMSCR_OK && b->next < b->nitems) {
        *item = b->next++;
        ok = 1;
    }
    pthread_mutex_unlock(&b->lock);
    return ok;
}

static void batch_finish_item(batch_t *b, amscr_status st)
{
    pthread_mutex_lock(&b->lock);
    b->done++;
    if (st != AMSCR_OK && b->status == AMSCR_OK) {
        b->status = st;
        snprintf(b->detail, sizeof b->detail, "%s", amscr_last_error_detail());
    }
    pthread_mutex_unlock(&b->lock);
}

static void *batch_worker(void *arg)
{
    batch_t *b = arg;
    amscr_workspace *ws = NULL;
    if (amscr_workspace_new(&ws) != AMSCR_OK) {
        batch_finish_item(b, AMSCR_E_NOMEM);
        return NULL;
    }
    size_t item;
    while (batch_take(b, &item)) {
        amscr_status st = AMSCR_OK;
        batch_item(b, ws, item, &st);
        batch_finish_item(b, st);
    }
    amscr_workspace_free(ws);
    return NULL;
}

/* Items of b (row blocks, or column blocks of a single row) and the shared state reset. */
static void batch_setup(batch_t *b)
{
    if (b->nrows == 1) {
        b->cols_per_item = 32;
        b->nitems = (b->ncols + 31) / 32;
    } else {
        b->rows_per_item = 1;
        b->nitems = b->nrows;
    }
    b->next = b->done = 0;
    b->cancel = 0;
    b->status = AMSCR_OK;
    b->detail[0] = '\0';
}

/* The cells of `done` items: the unit of the progress callback and of the cancel's detail. */
static size_t batch_cells(const batch_t *b, size_t done)
{
    return b->nrows == 1 ? (done * b->cols_per_item < b->ncols ? done * b->cols_per_item : b->ncols) : done * b->ncols;
}

/* The calling thread's report of the cells done so far, when it changed since *last (a
 * callback asking to stop sets b->cancel). */
static void batch_report(batch_t *b, amscr_progress_fn progress, void *user, size_t *last)
{
    pthread_mutex_lock(&b->lock);
    size_t done = b->done;
    pthread_mutex_unlock(&b->lock);
    if (done == *last)
        return;
    *last = done;
    if (progress(user, batch_cells(b, done), b->nrows * b->ncols) != 0) {
        pthread_mutex_lock(&b->lock);
        b->cancel = 1;
        pthread_mutex_unlock(&b->lock);
    }
}

/* The calling thread works too, and reports progress between its items. */
static void batch_own_items(batch_t *b, amscr_progress_fn progress, void *user, size_t *last)
{
    amscr_workspace *ws = NULL;
    amscr_status own = amscr_workspace_new(&ws);
    size_t item;
    if (own != AMSCR_OK) {
        amscr_workspace_free(ws);
        batch_finish_item(b, own);
        return;
    }
    for (;;) {
        if (progress)
            batch_report(b, progress, user, last);
        if (!batch_take(b, &item))
            break;
        amscr_status st = AMSCR_OK;
        batch_item(b, ws, item, &st);
        batch_finish_item(b, st);
    }
    amscr_workspace_free(ws);
}

/* The outcome of a finished run: a failure or a cancel leaves every cell NaN (never a silently
 * partial matrix); a run that ends with a callback not yet told so reports the end. */
static amscr_status batch_result(batch_t *b, amscr_progress_fn progress, void *user, size_t last)
{
    size_t total_cells = b->nrows * b->ncols;
    if (b->status != AMSCR_OK || b->cancel) {
        for (size_t i = 0; i < total_cells; i++)
            b->out[i] = NAN;
        if (b->status != AMSCR_OK)
            return amscr__fail(b->status, "%s", b->detail);
        return amscr__fail(AMSCR_E_CANCELLED,
                           "cancelled by the progress callback after %zu of %zu distances (every output set to NaN)",
                           batch_cells(b, b->done), total_cells);
    }
    if (progress && last != b->nitems)
        if (progress(user, total_cells, total_cells) != 0)
            return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback at the end");
    return AMSCR_OK;
}

static amscr_status batch_run(batch_t *b, unsigned threads, amscr_progress_fn progress, void *user)
{
    batch_setup(b);
    if (b->nrows * b->ncols == 0)
        return AMSCR_OK;
    pthread_mutex_init(&b->lock, NULL);
    if (threads > b->nitems)
        threads = (unsigned)b->nitems;
    if (threads < 1)
        threads = 1;
    /* The first report (0 done) comes before any worker starts, so every callback sees the
     * start and (batch_result) the end, whatever the scheduling. */
    size_t last = (size_t)-1;
    if (progress) {
        last = 0;
        if (progress(user, 0, b->nrows * b->ncols) != 0)
            b->cancel = 1;
    }
    pthread_t *tid = NULL;
    unsigned started = 0;
    if (threads > 1 && !b->cancel) {
        tid = malloc((threads - 1) * sizeof *tid);
        for (unsigned t = 0; tid && t + 1 < threads && pthread_create(&tid[t], NULL, batch_worker, b) == 0; t++)
            started++;
    }
    batch_own_items(b, progress, user, &last);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    pthread_mutex_destroy(&b->lock);
    return batch_result(b, progress, user, last);
}

amscr_status amscr__distance_cells(const amscr_params *prm, const amscr_descriptor *const *rows, size_t nrows,
                                   const amscr_descriptor *const *cols, size_t ncols, int skip_diag,
                                   amscr_progress_fn progress, void *user, double *out)
{
    batch_t b;
    memset(&b, 0, sizeof b);
    b.prm = prm;
    b.rows = rows;
    b.cols = cols;
    b.nrows = nrows;
    b.ncols = ncols;
    b.skip_diag = skip_diag;
    b.out = out;
    return batch_run(&b, amscr__resolve_threads(prm->num_threads), progress, user);
}
