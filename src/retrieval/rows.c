/* rows.c — a collection's rows on POSIX threads (see rows.h). */
#include "rows.h"

#include <pthread.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const amscr__rows_ops *ops;
    const void *ctx;
    size_t n;
    pthread_mutex_t lock;
    size_t next, done;
    int failed, cancel;
} rows_t;

static int take(rows_t *m, size_t *row)
{
    int ok = 0;
    pthread_mutex_lock(&m->lock);
    if (!m->failed && !m->cancel && m->next < m->n) {
        *row = m->next++;
        ok = 1;
    }
    pthread_mutex_unlock(&m->lock);
    return ok;
}

static void run_row(rows_t *m, size_t i, void *ws)
{
    m->ops->row(m->ctx, i, ws);
    pthread_mutex_lock(&m->lock);
    m->done++;
    pthread_mutex_unlock(&m->lock);
}

static int scratch(rows_t *m, void **ws)
{
    *ws = NULL;
    if (!m->ops->ws_init || m->ops->ws_init(m->ctx, ws) == AMSCR_OK)
        return 1;
    pthread_mutex_lock(&m->lock);
    m->failed = 1;
    pthread_mutex_unlock(&m->lock);
    return 0;
}

static void scratch_free(rows_t *m, void *ws)
{
    if (m->ops->ws_free)
        m->ops->ws_free(ws);
}

static void *worker(void *arg)
{
    rows_t *m = arg;
    void *ws;
    size_t i;
    if (!scratch(m, &ws))
        return NULL;
    while (take(m, &i))
        run_row(m, i, ws);
    scratch_free(m, ws);
    return NULL;
}

/* The calling thread: works like the others and is the only one that reports progress. */
static void main_thread(rows_t *m, size_t cells, amscr_progress_fn progress, void *user)
{
    void *ws;
    size_t i;
    if (!scratch(m, &ws))
        return;
    for (;;) {
        if (progress) {
            pthread_mutex_lock(&m->lock);
            size_t done = m->done;
            pthread_mutex_unlock(&m->lock);
            if (progress(user, done * cells, m->n * cells) != 0) {
                pthread_mutex_lock(&m->lock);
                m->cancel = 1;
                pthread_mutex_unlock(&m->lock);
            }
        }
        if (!take(m, &i))
            break;
        run_row(m, i, ws);
    }
    scratch_free(m, ws);
}

amscr_status amscr__rows_run(size_t n, const amscr__rows_ops *ops, const void *ctx, unsigned threads, size_t cells,
                             amscr_progress_fn progress, void *user)
{
    if (n == 0)
        return AMSCR_OK;
    rows_t m;
    memset(&m, 0, sizeof m);
    m.ops = ops;
    m.ctx = ctx;
    m.n = n;
    pthread_mutex_init(&m.lock, NULL);
    if (threads > n)
        threads = (unsigned)n;
    if (threads < 1)
        threads = 1;
    pthread_t *tid = threads > 1 ? malloc((threads - 1) * sizeof *tid) : NULL;
    unsigned started = 0;
    if (tid)
        for (unsigned t = 0; t + 1 < threads; t++) {
            if (pthread_create(&tid[t], NULL, worker, &m) != 0)
                break;
            started++;
        }
    main_thread(&m, cells, progress, user);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    pthread_mutex_destroy(&m.lock);
    if (m.failed)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", ops->what);
    if (m.cancel)
        return amscr__fail(AMSCR_E_CANCELLED, "%s: cancelled by the progress callback", ops->what);
    if (progress && progress(user, n * cells, n * cells) != 0)
        return amscr__fail(AMSCR_E_CANCELLED, "%s: cancelled by the progress callback at the end", ops->what);
    return AMSCR_OK;
}
