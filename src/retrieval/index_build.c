/* index_build.c — building an index: each shape's signature and its K nearest shapes under
 * the base distance of the retrieval matrix (fuse.c), from the full matrix (exact: a query
 * then equals the matrix of the collection plus the query) or, for large collections, among
 * each shape's M signature-nearest shapes (rows on threads). */
#include "index.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Shapes on which a shortlist build estimates the medians of a fused distance. */
enum { MEDIAN_SAMPLE = 256 };

typedef struct {
    double d;
    size_t j;
} nb_t;

static int cmp_nb(const void *a, const void *b)
{
    const nb_t *x = a, *y = b;
    if (x->d != y->d)
        return x->d < y->d ? -1 : 1;
    return x->j < y->j ? -1 : (x->j > y->j);
}

amscr_status amscr__knn_select(size_t i, const size_t *cj, const double *cd, size_t m, size_t k, uint32_t *out_idx,
                               double *out_dist)
{
    nb_t *row = amscr__malloc_array(m + 1, sizeof *row);
    if (!row)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    size_t r = 0;
    row[r++] = (nb_t){-1.0, i}; /* itself first, as amscr_rerank_diffusion */
    for (size_t t = 0; t < m; t++)
        if (cj[t] != i)
            row[r++] = (nb_t){cd[t], cj[t]};
    qsort(row, r, sizeof *row, cmp_nb);
    for (size_t t = 0; t < k; t++) {
        out_idx[t] = (uint32_t)row[t < r ? t : r - 1].j;
        out_dist[t] = t == 0 ? 0.0 : row[t < r ? t : r - 1].d;
    }
    free(row);
    return AMSCR_OK;
}

size_t amscr__index_shortlist(const amscr_index *x, const double *sig, size_t m, size_t exclude, size_t *cand)
{
    size_t n = amscr_db_size(x->db), avail = exclude < n ? n - 1 : n;
    if (m == 0 || m >= avail) {
        size_t c = 0;
        for (size_t j = 0; j < n; j++)
            if (j != exclude)
                cand[c++] = j;
        return c;
    }
    double *sd = amscr__malloc_array(n, sizeof *sd);
    if (!sd)
        return 0;
    for (size_t j = 0; j < n; j++) {
        double s = 0.0;
        for (size_t t = 0; t < x->sig_dim; t++) {
            double e = x->sig[j * x->sig_dim + t] - sig[t];
            s += e * e;
        }
        sd[j] = s;
    }
    if (amscr_topk(sd, n, m, exclude, cand) != AMSCR_OK)
        m = 0;
    free(sd);
    for (size_t i = 1; i < m; i++) { /* ascending indices (insertion sort: m is small) */
        size_t v = cand[i], t = i;
        for (; t > 0 && cand[t - 1] > v; t--)
            cand[t] = cand[t - 1];
        cand[t] = v;
    }
    return m;
}

/* Lists and dmax from the full base matrix (the retrieval matrix before its re-ranking). */
static amscr_status build_full(amscr_index *x, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(x->db), k = x->k;
    double *D = amscr__malloc_array(n * n, sizeof *D), med[2] = {0.0, 0.0};
    size_t *cj = amscr__malloc_array(n, sizeof *cj);
    amscr_status st = D && cj ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "amscr_index_build: out of memory");
    if (st == AMSCR_OK)
        st = amscr__base_matrix(x->db, progress, user, D, med);
    x->med_a = med[0];
    x->med_h = med[1];
    x->dmax = 0.0;
    for (size_t j = 0; j < n; j++)
        cj[j] = j;
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        for (size_t j = 0; j < n; j++)
            x->dmax = D[i * n + j] > x->dmax ? D[i * n + j] : x->dmax;
        if (k > 0)
            st = amscr__knn_select(i, cj, D + i * n, n, k, x->nb_idx + i * k, x->nb_dist + i * k);
    }
    free(D);
    free(cj);
    return st;
}

/* The fusion's medians estimated on at most MEDIAN_SAMPLE shapes spread evenly. */
static amscr_status sampled_medians(amscr_index *x)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db), m = n < MEDIAN_SAMPLE ? n : MEDIAN_SAMPLE;
    if (!(p->channel_weight > 0.0 && p->channel_weight < 1.0) || m < 2)
        return AMSCR_OK;
    amscr_db *sub = NULL;
    amscr_status st = amscr_db_new(p, &sub);
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) /* evenly spread: shape t * n / m */
        st = amscr_db_add_descriptor(sub, amscr_db_descriptor(x->db, (size_t)((double)t * (double)n / (double)m)), -1,
                                     NULL);
    double *D = st == AMSCR_OK ? amscr__malloc_array(m * m, sizeof *D) : NULL, med[2] = {0.0, 0.0};
    if (st == AMSCR_OK && !D)
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_index_build: out of memory");
    if (st == AMSCR_OK)
        st = amscr__base_matrix(sub, NULL, NULL, D, med);
    x->med_a = med[0];
    x->med_h = med[1];
    free(D);
    amscr_db_free(sub);
    return st;
}

/* ------------------------------------------------ shortlist build: rows on threads */

typedef struct {
    amscr_index *x;
    const amscr__base *b;
    size_t m, first; /* shortlist size; rows first..n-1 */
    pthread_mutex_t lock;
    size_t next, done;
    double dmax;
    int cancel;
    amscr_status st;
    char detail[256];
} rows_job;

/* Row i: its shortlist's base distances and its k nearest; the row's largest distance. */
static amscr_status one_row(rows_job *j, size_t i, amscr__pair_ws *pw, size_t *cand, double *cd, double *rmax)
{
    amscr_index *x = j->x;
    const amscr_descriptor *q = amscr_db_descriptor(x->db, i);
    size_t m = amscr__index_shortlist(x, x->sig + i * x->sig_dim, j->m, i, cand);
    amscr__hf hq[2];
    amscr_status st = amscr__base_hf(j->b, q, hq);
    if (st != AMSCR_OK)
        return st;
    st = amscr__base_pairs(j->b, x->db, q, hq, i, cand, m, pw, cd);
    amscr__base_hf_free(j->b, hq);
    *rmax = 0.0;
    for (size_t t = 0; st == AMSCR_OK && t < m; t++)
        *rmax = cd[t] > *rmax ? cd[t] : *rmax;
    if (st == AMSCR_OK && x->k > 0)
        st = amscr__knn_select(i, cand, cd, m, x->k, x->nb_idx + i * x->k, x->nb_dist + i * x->k);
    return st;
}

static void rows_work(rows_job *j, amscr_progress_fn progress, void *user)
{
    size_t n = amscr_db_size(j->x->db);
    amscr__pair_ws pw;
    size_t *cand = amscr__malloc_array(n, sizeof *cand);
    double *cd = amscr__malloc_array(n, sizeof *cd), rmax = 0.0;
    amscr_status st = cand && cd ? amscr__pair_ws_init(j->b, &pw) : AMSCR_E_NOMEM;
    int have_pw = st == AMSCR_OK;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        if (st != AMSCR_OK && j->st == AMSCR_OK) {
            j->st = st;
            snprintf(j->detail, sizeof j->detail, "%s", st == AMSCR_E_NOMEM ? "index: out of memory"
                                                                            : amscr_last_error_detail());
        }
        j->dmax = rmax > j->dmax ? rmax : j->dmax;
        size_t i = j->next, done = j->done;
        int go = j->st == AMSCR_OK && !j->cancel && i < n;
        if (go)
            j->next++;
        pthread_mutex_unlock(&j->lock);
        if (progress && progress(user, done - j->first, n - j->first) != 0) {
            pthread_mutex_lock(&j->lock);
            j->cancel = 1;
            pthread_mutex_unlock(&j->lock);
        }
        if (!go)
            break;
        st = one_row(j, i, &pw, cand, cd, &rmax);
        pthread_mutex_lock(&j->lock);
        j->done++;
        pthread_mutex_unlock(&j->lock);
    }
    if (have_pw)
        amscr__pair_ws_free(&pw);
    free(cand);
    free(cd);
}

static void *rows_worker(void *arg)
{
    rows_work(arg, NULL, NULL);
    return NULL;
}

/* Rows first..n-1 from their M signature-nearest shapes; x->dmax grows to their largest. */
amscr_status amscr__index_rows(amscr_index *x, size_t first, size_t m, amscr_progress_fn progress, void *user)
{
    amscr__base b;
    amscr__base_init(&b, amscr_db_params(x->db), x->med_a, x->med_h);
    rows_job j = {x, &b, m, first, PTHREAD_MUTEX_INITIALIZER, first, first, x->dmax, 0, AMSCR_OK, ""};
    size_t n = amscr_db_size(x->db);
    unsigned nt = b.threads, started = 0;
    if (nt > n - first)
        nt = n > first ? (unsigned)(n - first) : 1u;
    pthread_t tid[64];
    for (unsigned t = 1; t < nt && t < 64; t++)
        if (pthread_create(&tid[started], NULL, rows_worker, &j) == 0)
            started++;
    rows_work(&j, progress, user);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    pthread_mutex_destroy(&j.lock);
    x->dmax = j.dmax;
    if (j.st != AMSCR_OK)
        return amscr__fail(j.st, "%s", j.detail);
    if (j.cancel)
        return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    return AMSCR_OK;
}

amscr_status amscr__index_check_db(const amscr_db *db, const char *what)
{
    const amscr_params *p = amscr_db_params(db);
    if (p->channel_weight > 0.0 && !p->closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: the shape channel needs closed curves; set the channel weight "
                                                "to 0 for open ones", what);
    if (amscr_db_size(db) > UINT32_MAX)
        return amscr__fail(AMSCR_E_LIMIT, "%s: %zu shapes exceed 2^32 - 1", what, amscr_db_size(db));
    return AMSCR_OK;
}

amscr_status amscr_index_build(const amscr_db *db, size_t candidates, amscr_progress_fn progress, void *user,
                               amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out);
    amscr_status st = amscr__index_check_db(db, "amscr_index_build");
    if (st != AMSCR_OK)
        return st;
    amscr_index *x = NULL;
    st = amscr__index_alloc(db, &x);
    if (st != AMSCR_OK)
        return st;
    size_t n = amscr_db_size(db);
    for (size_t i = 0; i < n; i++)
        amscr__shape_signature(amscr_db_descriptor(x->db, i), x->sig + i * x->sig_dim);
    if (candidates > 0 && candidates + 1 < x->k)
        candidates = x->k - 1; /* a shortlist holds at least the K - 1 neighbours */
    x->candidates = candidates > 0 && n > 1 && candidates < n - 1 ? candidates : 0;
    if (x->candidates == 0) {
        st = build_full(x, progress, user);
    } else {
        st = sampled_medians(x);
        if (st == AMSCR_OK)
            st = amscr__index_rows(x, 0, x->candidates, progress, user);
    }
    if (st != AMSCR_OK) {
        amscr_index_free(x);
        return st;
    }
    *out = x;
    return AMSCR_OK;
}
