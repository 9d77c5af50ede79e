/* rerank.c — contextual re-ranking of a distance matrix by affinity diffusion on a kNN
 * tensor-product graph (Yang, Prasad, Latecki, CVPR 2012). See amscr_rerank_diffusion in
 * amscr.h for the definition. */
#include "rank.h" /* amscr__knn_select: the neighbour order the index stores too */
#include "rows.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Output normalizations of the diffused affinity Q. */
enum { NORM_ROW_MAX = 0, NORM_UNIT = 1 };

static amscr_status check_args(const double *dist, size_t n, size_t k, unsigned iterations, const double *out_dist,
                               const char *what)
{
    AMSCR_CHECK_NULL_IN(what, dist);
    AMSCR_CHECK_NULL_IN(what, out_dist);
    if (n == 0 || k < 1 || k > n || iterations < 1 || iterations > 1000)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: need n >= 1, 1 <= k <= n, 1 <= iterations "
                                                "<= 1000 (n=%zu k=%zu iterations=%u)",
                           what, n, k, iterations);
    if (n > 65536)
        return amscr__fail(AMSCR_E_LIMIT, "%s: n = %zu exceeds 65536", what, n);
    for (size_t i = 0; i < n * n; i++)
        if (!isfinite(dist[i]) || dist[i] < 0.0)
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: distance %zu is negative or not finite", what, i);
    return AMSCR_OK;
}

/* The working buffers: D the symmetrized distances (D2 the other graphs' in turn), Q the
 * diffused affinity, T a product, sc the self-tuning scales, (pj, pw) the kNN graph P (kk
 * entries a row: k neighbours of each graph); row (0..n-1) and nb (k) the neighbour
 * selection's scratch. */
typedef struct {
    double *D, *D2, *Q, *T, *sc, *pw, *cd;
    size_t *pj, *row;
    uint32_t *nb;
    size_t kk;
    const unsigned char *held; /* shapes out of every list but their own (NULL: none) */
    size_t nrow;               /* with held: the shapes not held out, in row[0..nrow-1] */
} rerank_buf;

static void buf_free(rerank_buf *b)
{
    free(b->D);
    free(b->D2);
    free(b->Q);
    free(b->T);
    free(b->sc);
    free(b->pw);
    free(b->pj);
    free(b->row);
    free(b->nb);
    free(b->cd);
}

static int buf_alloc(rerank_buf *b, size_t n, size_t k, int graphs)
{
    memset(b, 0, sizeof *b);
    b->kk = k * (size_t)graphs;
    b->D = amscr__malloc_array(n * n, sizeof *b->D);
    b->D2 = graphs > 1 ? amscr__malloc_array(n * n, sizeof *b->D2) : NULL;
    b->Q = amscr__malloc_array(n * n, sizeof *b->Q);
    b->T = amscr__malloc_array(n * n, sizeof *b->T);
    b->sc = amscr__malloc_array(n, sizeof *b->sc);
    b->pw = amscr__malloc_array(n * b->kk, sizeof *b->pw);
    b->pj = amscr__malloc_array(n * b->kk, sizeof *b->pj);
    b->row = amscr__malloc_array(n, sizeof *b->row);
    b->nb = amscr__malloc_array(k, sizeof *b->nb);
    b->cd = amscr__malloc_array(n, sizeof *b->cd);
    if (b->D && (graphs < 2 || b->D2) && b->Q && b->T && b->sc && b->pw && b->pj && b->row && b->nb && b->cd)
        return 1;
    buf_free(b);
    return 0;
}

/* D = the symmetrized input with a zero diagonal; returns its largest entry. */
static double symmetrize(const double *dist, size_t n, double *D)
{
    double dmax = 0.0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            D[i * n + j] = i == j ? 0.0 : 0.5 * (dist[i * n + j] + dist[j * n + i]);
            if (D[i * n + j] > dmax)
                dmax = D[i * n + j];
        }
    return dmax;
}

/* One kNN graph of D into the entries [off, off + k) of P's rows: each row's k neighbours
 * (itself first: distance 0, ties by index), weighted by exp(-d / s) with self-tuning scales s
 * and normalized to sum `mass`. */
static amscr_status knn_graph(rerank_buf *b, const double *D, size_t n, size_t k, size_t off, double mass,
                              double dmax)
{
    size_t kk = b->kk, m = 0;
    for (size_t j = 0; j < n; j++)
        if (!b->held || !b->held[j])
            b->row[m++] = j;
    for (size_t i = 0; i < n; i++) {
        const double *cd = D + i * n; /* every shape a candidate: the row itself */
        if (b->held) {                /* the shapes not held out (and the row itself, first) */
            for (size_t t = 0; t < m; t++)
                b->cd[t] = D[i * n + b->row[t]];
            cd = b->cd;
        }
        amscr_status st = amscr__knn_select(i, b->row, cd, m, k, b->nb, b->pw + i * kk + off);
        if (st != AMSCR_OK)
            return st;
        for (size_t t = 0; t < k; t++)
            b->pj[i * kk + off + t] = b->nb[t];
        b->sc[i] = D[i * n + b->pj[i * kk + off + k - 1]];
    }
    double tiny = dmax > 0.0 ? 1e-12 * dmax : 1e-300;
    for (size_t i = 0; i < n; i++) {
        double sum = 0.0, *w = b->pw + i * kk + off;
        const size_t *pj = b->pj + i * kk + off;
        for (size_t t = 0; t < k; t++) {
            double s = sqrt((b->sc[i] + tiny) * (b->sc[pj[t]] + tiny));
            w[t] = exp(-D[i * n + pj[t]] / s);
            sum += w[t];
        }
        for (size_t t = 0; t < k; t++)
            w[t] = mass * (w[t] / sum); /* exactly w / sum for one graph */
    }
    return AMSCR_OK;
}

/* One row of a diffusion step: T_i = (P Q)_i, or Q_i = (T P^T)_i + e_i (Q_ij = Σ_t P_jt T_i,pj(t)). */
typedef struct {
    const rerank_buf *b;
    size_t n;
} diffuse_job;

static amscr_status product_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    const diffuse_job *j = ctx;
    size_t n = j->n, k = j->b->kk;
    const double *pw = j->b->pw;
    const size_t *pj = j->b->pj;
    double *ti = j->b->T + i * n;
    memset(ti, 0, n * sizeof *ti);
    for (size_t t = 0; t < k; t++) {
        double w = pw[i * k + t];
        const double *qr = j->b->Q + pj[i * k + t] * n;
        for (size_t c = 0; c < n; c++)
            ti[c] += w * qr[c];
    }
    return AMSCR_OK;
}

static amscr_status transpose_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    const diffuse_job *j = ctx;
    size_t n = j->n, k = j->b->kk;
    const double *pw = j->b->pw, *ti = j->b->T + i * n;
    const size_t *pj = j->b->pj;
    double *qi = j->b->Q + i * n;
    for (size_t c = 0; c < n; c++) {
        double v = 0.0;
        for (size_t t = 0; t < k; t++)
            v += pw[c * k + t] * ti[pj[c * k + t]];
        qi[c] = v + (i == c ? 1.0 : 0.0);
    }
    return AMSCR_OK;
}

/* Q = P, then `iterations` times Q <- P Q P^T + I (P sparse: k entries a row), each step's
 * rows on `threads` threads (a row is computed the same way on any thread). */
static amscr_status diffuse(rerank_buf *b, size_t n, unsigned iterations, unsigned threads)
{
    size_t k = b->kk;
    memset(b->Q, 0, n * n * sizeof *b->Q);
    for (size_t i = 0; i < n; i++)
        for (size_t t = 0; t < k; t++)
            b->Q[i * n + b->pj[i * k + t]] += b->pw[i * k + t];
    diffuse_job j = {b, n};
    amscr__rows_fn product = {NULL, NULL, product_row, &j, "re-ranking"};
    amscr__rows_fn transpose = {NULL, NULL, transpose_row, &j, "re-ranking"};
    amscr_status st = AMSCR_OK;
    for (unsigned it = 0; it < iterations && st == AMSCR_OK; it++) {
        st = amscr__run_rows(&product, 0, n, threads, NULL, NULL);
        if (st == AMSCR_OK)
            st = amscr__run_rows(&transpose, 0, n, threads, NULL, NULL);
    }
    return st;
}

/* The output distances from the diffused affinity Q, row by row: 1 - q / (the row's largest q),
 * shapes the diffusion does not reach after them in the order of the input distance D. */
static void to_distances(const double *Q, const double *D, size_t n, double dmax, int norm, double *out_dist)
{
    for (size_t i = 0; i < n; i++) {
        double qmax = 0.0;
        for (size_t j = 0; j < n; j++)
            if (Q[i * n + j] > qmax)
                qmax = Q[i * n + j];
        for (size_t j = 0; j < n; j++) {
            double q = Q[i * n + j];
            out_dist[i * n + j] = (q > 0.0 && qmax > 0.0) ? 1.0 - q / qmax
                                                           : 1.0 + (dmax > 0.0 ? D[i * n + j] / dmax : 0.0);
            /* unit: the same order halved into [0, 1]: below 0.5 for shapes the diffusion
             * reaches, 0.5 and above for the others (in the order of the input distance), 0
             * for the shape itself (its own affinity is the row's largest; if not, it still
             * ranks first) */
            if (norm == NORM_UNIT)
                out_dist[i * n + j] = i == j ? 0.0 : 0.5 * out_dist[i * n + j];
        }
    }
}

/* The mass of graph 0 in every row: 1 minus the other graphs' shares (exactly 1 for one). */
static double first_mass(const double *share, int graphs)
{
    double rest = 0.0;
    for (int g = 1; g < graphs; g++)
        rest += share[g];
    return graphs > 1 ? 1.0 - rest : 1.0;
}

/* dist[0] and the graphs' distances dist[1..graphs-1], each entering with share[g] of every
 * row's mass (graph 0 with the rest; share[0] is not read). */
static amscr_status rerank(const double *const *dist, const double *share, int graphs, size_t n, size_t k,
                           unsigned iterations, unsigned threads, int norm, const unsigned char *held,
                           double *out_dist, const char *what)
{
    amscr__clear_error();
    amscr_status st = AMSCR_OK;
    for (int g = 0; g < graphs && st == AMSCR_OK; g++)
        st = check_args(dist[g], n, k, iterations, out_dist, what);
    if (st != AMSCR_OK)
        return st;
    rerank_buf b;
    if (!buf_alloc(&b, n, k, graphs))
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", what);
    b.held = held;
    double dmax = symmetrize(dist[0], n, b.D);
    st = knn_graph(&b, b.D, n, k, 0, first_mass(share, graphs), dmax);
    for (int g = 1; g < graphs && st == AMSCR_OK; g++) /* b.D2 is reused graph by graph */
        st = knn_graph(&b, b.D2, n, k, (size_t)g * k, share[g], symmetrize(dist[g], n, b.D2));
    if (st == AMSCR_OK)
        st = diffuse(&b, n, iterations, threads);
    if (st == AMSCR_OK)
        to_distances(b.Q, b.D, n, dmax, norm, out_dist);
    buf_free(&b);
    return st;
}

amscr_status amscr_rerank_diffusion(const double *dist, size_t n, size_t k, unsigned iterations, double *out_dist)
{
    double share = 1.0;
    return rerank(&dist, &share, 1, n, k, iterations, 1, NORM_ROW_MAX, NULL, out_dist, "amscr_rerank_diffusion");
}

amscr_status amscr__rerank_normalized(const double *dist, size_t n, size_t k, unsigned iterations, unsigned threads,
                                      double *out_dist)
{
    double share = 1.0;
    return rerank(&dist, &share, 1, n, k, iterations, threads, NORM_UNIT, NULL, out_dist, "re-ranking");
}

amscr_status amscr__rerank_normalized2(const double *dist, const double *dist2, double share, size_t n, size_t k,
                                       unsigned iterations, unsigned threads, double *out_dist)
{
    const double *d[2] = {dist, dist2};
    double sh[2] = {1.0 - share, share};
    return rerank(d, sh, dist2 ? 2 : 1, n, k, iterations, threads, NORM_UNIT, NULL, out_dist, "re-ranking");
}

amscr_status amscr__rerank_graphs(const double *const *dist, const double *share, int graphs, size_t n, size_t k,
                                  unsigned iterations, unsigned threads, double *out_dist)
{
    if (!dist || !share || graphs < 1 || graphs > AMSCR__RERANK_GRAPHS)
        return amscr__fail(AMSCR_E_INVALID_ARG, "re-ranking: 1 to %d graphs", AMSCR__RERANK_GRAPHS);
    return rerank(dist, share, graphs, n, k, iterations, threads, NORM_UNIT, NULL, out_dist, "re-ranking");
}

amscr_status amscr__rerank_held(const double *const *dist, const double *share, int graphs, size_t n, size_t k,
                                unsigned iterations, unsigned threads, const unsigned char *held, double *out_dist)
{
    if (!dist || !share || !held || graphs < 1 || graphs > AMSCR__RERANK_GRAPHS)
        return amscr__fail(AMSCR_E_INVALID_ARG, "re-ranking: 1 to %d graphs", AMSCR__RERANK_GRAPHS);
    return rerank(dist, share, graphs, n, k, iterations, threads, NORM_UNIT, held, out_dist, "re-ranking");
}
