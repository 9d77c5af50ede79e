/* hf_matrix.c — the shape channel over a whole collection: the height functions of every
 * shape (once), then the upper triangle of the pair distances on POSIX threads (rows handed
 * out dynamically; every cell computed by the same code, so the result does not depend on
 * the thread count), mirrored into a symmetric matrix with a zero diagonal. */
#include "channel.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const amscr__hf *hf;
    size_t n;
    const amscr__hf_cfg *cfg;
    double *out;
    pthread_mutex_t lock;
    size_t next, done;
    int failed, cancel;
} hfm_t;

static int hfm_take(hfm_t *m, size_t *row)
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

static void hfm_row(hfm_t *m, size_t i, amscr__hf_ws *ws)
{
    for (size_t j = i + 1; j < m->n; j++)
        m->out[i * m->n + j] = amscr__hf_distance(&m->hf[i], &m->hf[j], m->cfg, ws);
    pthread_mutex_lock(&m->lock);
    m->done++;
    pthread_mutex_unlock(&m->lock);
}

static void *hfm_worker(void *arg)
{
    hfm_t *m = arg;
    amscr__hf_ws ws;
    if (amscr__hf_ws_init(&ws, m->hf[0].n, m->cfg->band) != AMSCR_OK) {
        pthread_mutex_lock(&m->lock);
        m->failed = 1;
        pthread_mutex_unlock(&m->lock);
        return NULL;
    }
    size_t i;
    while (hfm_take(m, &i))
        hfm_row(m, i, &ws);
    amscr__hf_ws_free(&ws);
    return NULL;
}

/* The calling thread: works like the others and is the only one that reports progress
 * (in cells of the n x n matrix: a row i stands for n cells). */
static void hfm_main(hfm_t *m, amscr_progress_fn progress, void *user)
{
    amscr__hf_ws ws;
    if (amscr__hf_ws_init(&ws, m->hf[0].n, m->cfg->band) != AMSCR_OK) {
        pthread_mutex_lock(&m->lock);
        m->failed = 1;
        pthread_mutex_unlock(&m->lock);
        return;
    }
    size_t i;
    for (;;) {
        if (progress) {
            pthread_mutex_lock(&m->lock);
            size_t done = m->done;
            pthread_mutex_unlock(&m->lock);
            if (progress(user, done * m->n, m->n * m->n) != 0) {
                pthread_mutex_lock(&m->lock);
                m->cancel = 1;
                pthread_mutex_unlock(&m->lock);
            }
        }
        if (!hfm_take(m, &i))
            break;
        hfm_row(m, i, &ws);
    }
    amscr__hf_ws_free(&ws);
}

amscr_status amscr__hf_matrix(const amscr__hf *hf, size_t n, const amscr__hf_cfg *cfg, unsigned threads,
                              amscr_progress_fn progress, void *user, double *out)
{
    if (n == 0)
        return AMSCR_OK;
    hfm_t m;
    memset(&m, 0, sizeof m);
    m.hf = hf;
    m.n = n;
    m.cfg = cfg;
    m.out = out;
    pthread_mutex_init(&m.lock, NULL);
    if (threads > n)
        threads = (unsigned)n;
    if (threads < 1)
        threads = 1;
    pthread_t *tid = threads > 1 ? malloc((threads - 1) * sizeof *tid) : NULL;
    unsigned started = 0;
    if (tid)
        for (unsigned t = 0; t + 1 < threads; t++) {
            if (pthread_create(&tid[t], NULL, hfm_worker, &m) != 0)
                break;
            started++;
        }
    hfm_main(&m, progress, user);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    pthread_mutex_destroy(&m.lock);
    if (m.failed || m.cancel) {
        for (size_t i = 0; i < n * n; i++)
            out[i] = NAN;
        if (m.failed)
            return amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
        return amscr__fail(AMSCR_E_CANCELLED, "shape channel: cancelled by the progress callback");
    }
    if (progress && progress(user, n * n, n * n) != 0)
        return amscr__fail(AMSCR_E_CANCELLED, "shape channel: cancelled by the progress callback at the end");
    for (size_t i = 0; i < n; i++) {
        out[i * n + i] = 0.0;
        for (size_t j = i + 1; j < n; j++)
            out[j * n + i] = out[i * n + j];
    }
    return AMSCR_OK;
}
