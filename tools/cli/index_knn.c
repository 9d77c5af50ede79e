/* index_knn.c — the neighbour lists of a large collection without its full matrix: each
 * shape is matched (the base distance, index_dist.h) with the `m` shapes whose signatures are nearest its own, and
 * its K nearest are taken among those. Rows are split over threads (amscr_distance is
 * reentrant with a workspace per thread). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "index_build.h"
#include "util.h"

typedef struct knn_job {
    tool_index *x;
    const base_dist *b;
    size_t m;            /* candidates a shape */
    size_t from, step;   /* rows from, from + step, ... */
    double dmax;         /* this thread's largest distance */
    size_t done;         /* rows finished; thread 0 shows done * threads as the progress */
    amscr_status st;
} knn_job;

/* The m shapes nearest shape i by signature (i itself excluded) into cand. */
static size_t sig_candidates(const tool_index *x, size_t i, size_t m, double *sd, size_t *cand)
{
    size_t n = x->coll.n;
    const double *si = x->sig + i * INDEX_SIG_DIM;
    for (size_t j = 0; j < n; j++) {
        double s = 0.0;
        for (size_t t = 0; t < INDEX_SIG_DIM; t++) {
            double e = x->sig[j * INDEX_SIG_DIM + t] - si[t];
            s += e * e;
        }
        sd[j] = s;
    }
    m = m < n - 1 ? m : n - 1;
    return amscr_topk(sd, n, m, i, cand) == AMSCR_OK ? m : 0;
}

static void *knn_rows(void *arg)
{
    knn_job *jb = arg;
    tool_index *x = jb->x;
    size_t n = x->coll.n, k = x->k;
    double *sd = malloc(n * sizeof *sd), *cd = malloc((jb->m + 1) * sizeof *cd);
    size_t *cand = malloc((jb->m + 1) * sizeof *cand);
    amscr_workspace *ws = NULL;
    jb->st = sd && cd && cand ? amscr_workspace_new(&ws) : AMSCR_E_NOMEM;
    tool_progress pr;
    progress_init(&pr, "neighbours");
    pr.enabled = pr.enabled && jb->from == 0;
    for (size_t i = jb->from; jb->st == AMSCR_OK && i < n; i += jb->step) {
        const amscr_descriptor *di = amscr_db_descriptor(x->db, i);
        size_t m = sig_candidates(x, i, jb->m, sd, cand);
        for (size_t t = 0; jb->st == AMSCR_OK && t < m; t++) {
            const amscr_descriptor *dj = amscr_db_descriptor(x->db, cand[t]);
            cd[t] = 0.0;
            jb->st = i < cand[t] ? base_pair(jb->b, di, dj, ws, &cd[t]) : base_pair(jb->b, dj, di, ws, &cd[t]);
            jb->dmax = cd[t] > jb->dmax ? cd[t] : jb->dmax;
        }
        knn_select(i, cand, cd, m, k, x->nb_idx + i * k, x->nb_dist + i * k);
        jb->done++;
        progress_update(&pr, jb->done * jb->step, n);
    }
    progress_end(&pr);
    amscr_workspace_free(ws);
    free(sd);
    free(cd);
    free(cand);
    return NULL;
}

int knn_from_candidates(tool_index *x, const base_dist *b, size_t m)
{
    const amscr_params *p = b->p;
    size_t n = x->coll.n, k = x->k;
    unsigned nt = amscr_params_get_num_threads(p);
    if (nt == 0) {
        long c = sysconf(_SC_NPROCESSORS_ONLN);
        nt = c > 0 ? (unsigned)c : 1u;
    }
    if (nt > 64)
        nt = 64;
    x->nb_idx = xmalloc_array(n * k > 0 ? n * k : 1, sizeof(uint32_t));
    x->nb_dist = xmalloc_array(n * k > 0 ? n * k : 1, sizeof(double));
    knn_job jobs[64];
    pthread_t th[64];
    if (!x->nb_idx || !x->nb_dist)
        return -1;
    unsigned started = 0;
    for (unsigned t = 0; t < nt; t++) {
        jobs[t] = (knn_job){x, b, m, t, nt, 0.0, 0, AMSCR_OK};
        if (t > 0 && pthread_create(&th[t], NULL, knn_rows, &jobs[t]) != 0)
            break;
        started = t + 1;
    }
    knn_rows(&jobs[0]);
    x->dmax = jobs[0].dmax;
    amscr_status st = jobs[0].st;
    for (unsigned t = 1; t < started; t++) {
        pthread_join(th[t], NULL);
        x->dmax = jobs[t].dmax > x->dmax ? jobs[t].dmax : x->dmax;
        if (st == AMSCR_OK)
            st = jobs[t].st;
    }
    for (unsigned t = started; t < nt && st == AMSCR_OK; t++) /* threads that did not start: here */
        knn_rows(&jobs[t]), st = jobs[t].st;
    if (st != AMSCR_OK) {
        tool_lib_error("index", st);
        return -1;
    }
    return 0;
}
