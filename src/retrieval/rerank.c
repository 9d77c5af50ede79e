/* rerank.c — contextual re-ranking of a distance matrix by affinity diffusion on a kNN
 * tensor-product graph (Yang, Prasad, Latecki, CVPR 2012). See amscr_rerank_diffusion in
 * amscr.h for the definition. */
#include "index.h" /* amscr__knn_select: the neighbour order the index stores too */

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Output normalizations of the diffused affinity Q. */
enum { NORM_ROW_MAX = 0, NORM_UNIT = 1 };

static amscr_status rerank(const double *dist, size_t n, size_t k, unsigned iterations, int norm, double *out_dist,
                           const char *what)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(out_dist);
    if (n == 0 || k < 1 || k > n || iterations < 1 || iterations > 1000)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: need n >= 1, 1 <= k <= n, 1 <= iterations "
                                                "<= 1000 (n=%zu k=%zu iterations=%u)",
                           what, n, k, iterations);
    if (n > 65536)
        return amscr__fail(AMSCR_E_LIMIT, "%s: n = %zu exceeds 65536", what, n);
    for (size_t i = 0; i < n * n; i++)
        if (!isfinite(dist[i]) || dist[i] < 0.0)
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: distance %zu is negative or not finite", what, i);
    double *D = amscr__malloc_array(n * n, sizeof *D), *Q = amscr__malloc_array(n * n, sizeof *Q);
    double *T = amscr__malloc_array(n * n, sizeof *T), *sc = amscr__malloc_array(n, sizeof *sc);
    double *pw = amscr__malloc_array(n * k, sizeof *pw);
    size_t *pj = amscr__malloc_array(n * k, sizeof *pj);
    size_t *row = amscr__malloc_array(n, sizeof *row);
    uint32_t *nb = amscr__malloc_array(k, sizeof *nb);
    if (!D || !Q || !T || !sc || !pw || !pj || !row || !nb) {
        free(D);
        free(Q);
        free(T);
        free(sc);
        free(pw);
        free(pj);
        free(row);
        free(nb);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_rerank_diffusion: out of memory");
    }
    double dmax = 0.0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            D[i * n + j] = i == j ? 0.0 : 0.5 * (dist[i * n + j] + dist[j * n + i]);
            if (D[i * n + j] > dmax)
                dmax = D[i * n + j];
        }
    /* neighbours (itself first: distance 0, ties by index) and self-tuning scales */
    for (size_t j = 0; j < n; j++)
        row[j] = j;
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        st = amscr__knn_select(i, row, D + i * n, n, k, nb, pw + i * k);
        for (size_t t = 0; st == AMSCR_OK && t < k; t++)
            pj[i * k + t] = nb[t];
        sc[i] = D[i * n + pj[i * k + k - 1]];
    }
    if (st != AMSCR_OK)
        goto done;
    double tiny = dmax > 0.0 ? 1e-12 * dmax : 1e-300;
    for (size_t i = 0; i < n; i++) {
        double sum = 0.0;
        for (size_t t = 0; t < k; t++) {
            size_t j = pj[i * k + t];
            double s = sqrt((sc[i] + tiny) * (sc[j] + tiny));
            pw[i * k + t] = exp(-D[i * n + j] / s);
            sum += pw[i * k + t];
        }
        for (size_t t = 0; t < k; t++)
            pw[i * k + t] /= sum;
    }
    /* Q = P, then Q <- P Q P^T + I (P sparse: k entries a row) */
    memset(Q, 0, n * n * sizeof *Q);
    for (size_t i = 0; i < n; i++)
        for (size_t t = 0; t < k; t++)
            Q[i * n + pj[i * k + t]] += pw[i * k + t];
    for (unsigned it = 0; it < iterations; it++) {
        /* T = P Q */
        for (size_t i = 0; i < n; i++) {
            double *ti = T + i * n;
            memset(ti, 0, n * sizeof *ti);
            for (size_t t = 0; t < k; t++) {
                double w = pw[i * k + t];
                const double *qr = Q + pj[i * k + t] * n;
                for (size_t j = 0; j < n; j++)
                    ti[j] += w * qr[j];
            }
        }
        /* Q = T P^T + I: Q_ij = Σ_t P_jt T_i,pj(t) */
        for (size_t i = 0; i < n; i++) {
            const double *ti = T + i * n;
            for (size_t j = 0; j < n; j++) {
                double v = 0.0;
                for (size_t t = 0; t < k; t++)
                    v += pw[j * k + t] * ti[pj[j * k + t]];
                Q[i * n + j] = v + (i == j ? 1.0 : 0.0);
            }
        }
    }
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
done:
    free(D);
    free(Q);
    free(T);
    free(sc);
    free(pw);
    free(pj);
    free(row);
    free(nb);
    return st;
}

amscr_status amscr_rerank_diffusion(const double *dist, size_t n, size_t k, unsigned iterations, double *out_dist)
{
    return rerank(dist, n, k, iterations, NORM_ROW_MAX, out_dist, "amscr_rerank_diffusion");
}

amscr_status amscr__rerank_normalized(const double *dist, size_t n, size_t k, unsigned iterations, double *out_dist)
{
    return rerank(dist, n, k, iterations, NORM_UNIT, out_dist, "re-ranking");
}
