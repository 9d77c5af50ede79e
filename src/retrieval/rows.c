/* rows.c — a collection's rows on POSIX threads (the index's lists, the shape channel's and the
 * inner distance's matrices): rows handed out one at a time, each computed by the same code
 * whatever thread runs it (so results do not depend on the thread count); the calling thread
 * works too and is the only one that reports progress. */
#include "rows.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct {
    const amscr__rows_fn *f;
    size_t first, n;
    pthread_mutex_t lock;
    size_t next, done;
    int cancel;
    amscr_status st;
    char detail[256];
} rows_job;

static void record(rows_job *j, amscr_status st)
{
    if (st != AMSCR_OK && j->st == AMSCR_OK) {
        j->st = st;
        const char *what = j->f->what ? j->f->what : "index";
        if (st == AMSCR_E_NOMEM)
            snprintf(j->detail, sizeof j->detail, "%s: out of memory", what);
        else
            snprintf(j->detail, sizeof j->detail, "%s", amscr_last_error_detail());
    }
}

static void rows_work(rows_job *j, amscr_progress_fn progress, void *user)
{
    void *scratch = NULL;
    amscr_status st = j->f->init ? j->f->init(j->f->ctx, &scratch) : AMSCR_OK;
    int have = st == AMSCR_OK;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        record(j, st);
        size_t i = j->next, done = j->done;
        int live = j->st == AMSCR_OK && !j->cancel, go = live && i < j->n; /* no report once cancelled */
        if (go)
            j->next++;
        pthread_mutex_unlock(&j->lock);
        if (live && progress && progress(user, done - j->first, j->n - j->first) != 0) {
            pthread_mutex_lock(&j->lock);
            j->cancel = 1;
            pthread_mutex_unlock(&j->lock);
        }
        if (!go)
            break;
        st = j->f->row(j->f->ctx, i, scratch);
        pthread_mutex_lock(&j->lock);
        j->done++;
        pthread_mutex_unlock(&j->lock);
    }
    if (have && j->f->fini)
        j->f->fini(scratch);
}

static void *rows_worker(void *arg)
{
    rows_work(arg, NULL, NULL);
    return NULL;
}

amscr_status amscr__run_rows(const amscr__rows_fn *f, size_t first, size_t n, unsigned threads,
                             amscr_progress_fn progress, void *user)
{
    if (first >= n)
        return AMSCR_OK;
    rows_job j = {f, first, n, PTHREAD_MUTEX_INITIALIZER, first, first, 0, AMSCR_OK, ""};
    unsigned nt = threads < 1 ? 1u : threads, started = 0;
    if (nt > n - first)
        nt = (unsigned)(n - first);
    pthread_t tid[64];
    for (unsigned t = 1; t < nt && t < 64; t++)
        if (pthread_create(&tid[started], NULL, rows_worker, &j) == 0)
            started++;
    rows_work(&j, progress, user);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    pthread_mutex_destroy(&j.lock);
    if (j.st != AMSCR_OK)
        return amscr__fail(j.st, "%s", j.detail);
    if (!j.cancel && progress && progress(user, n - first, n - first) != 0)
        j.cancel = 1;
    if (j.cancel)
        return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    return AMSCR_OK;
}
