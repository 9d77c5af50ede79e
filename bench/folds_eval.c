/* folds_eval.c — a sub-collection's retrieval matrix composed from the base matrices exactly as
 * amscr_db_retrieval_matrix composes them (channel frames mixed by the affine share; fusion with
 * AMSCR = each matrix over its median off-diagonal value; re-ranking, on the inner distance's
 * graph too when pc->inner > 0), plus the optional Fourier
 * proportion channel, and its score. */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double offdiag_median(const double *M, size_t m)
{
    double *v = malloc((m * m - m) * sizeof *v);
    size_t t = 0;
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++)
            if (i != j)
                v[t++] = M[i * m + j];
    qsort(v, t, sizeof *v, cmp_d);
    double med = v[t / 2];
    free(v);
    return med;
}

/* out = the m x m sub-matrix idx of the n x n matrix M, symmetrized. */
static void sub(const double *M, size_t n, const size_t *idx, size_t m, double *out)
{
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++) {
            size_t a = idx[i], b = idx[j];
            out[i * m + j] = i == j ? 0.0 : 0.5 * (M[a * n + b] + M[b * n + a]);
        }
}

/* F += w * X / median(X) after F /= median(F) (F and X m x m). */
static void add_normalized(double *F, const double *X, size_t m, double wf, double wx)
{
    double mf = offdiag_median(F, m), mx = offdiag_median(X, m);
    for (size_t i = 0; i < m * m; i++)
        F[i] = wf * F[i] / mf + wx * X[i] / mx;
}

void folds_local_scale(const double *M, size_t m, size_t k, double *sigma)
{
    double *v = malloc(m * sizeof *v);
    if (k + 1 > m)
        k = m - 1;
    for (size_t i = 0; i < m; i++) {
        size_t t = 0;
        for (size_t j = 0; j < m; j++)
            if (j != i)
                v[t++] = M[i * m + j];
        qsort(v, t, sizeof *v, cmp_d);
        sigma[i] = v[k - 1] > 0.0 ? v[k - 1] : 1e-12;
    }
    free(v);
}

/* Median of each row's off-diagonal entries. */
static void row_medians(const double *M, size_t m, double *med)
{
    double *v = malloc(m * sizeof *v);
    for (size_t i = 0; i < m; i++) {
        size_t t = 0;
        for (size_t j = 0; j < m; j++)
            if (j != i)
                v[t++] = M[i * m + j];
        qsort(v, t, sizeof *v, cmp_d);
        med[i] = v[t / 2];
    }
    free(v);
}

/* F = F / sqrt(sF_i sF_j) + w_ij X / sqrt(sX_i sX_j): each distance in units of its own
 * neighbourhood scale (the distance of a shape to its k-th neighbour in that channel). conf: w_ij =
 * w sqrt(q_i q_j), q = 2 cX / (cX + cF) with c = 1 - sigma / row median (how much nearer a
 * channel's k nearest are than its typical shape: the channel's confidence for that query). X NULL:
 * F alone, locally scaled. */
static void fuse_local(double *F, const double *X, size_t m, size_t k, double w, int conf)
{
    double *sf = malloc(m * sizeof *sf), *sx = malloc(m * sizeof *sx), *q = malloc(m * sizeof *q);
    folds_local_scale(F, m, k, sf);
    for (size_t i = 0; i < m; i++)
        q[i] = 1.0;
    if (X) {
        folds_local_scale(X, m, k, sx);
        if (conf) {
            double *mf = malloc(m * sizeof *mf), *mx = malloc(m * sizeof *mx);
            row_medians(F, m, mf);
            row_medians(X, m, mx);
            for (size_t i = 0; i < m; i++) {
                double cf = fmax(0.0, 1.0 - sf[i] / mf[i]), cx = fmax(0.0, 1.0 - sx[i] / mx[i]);
                q[i] = cf + cx > 0.0 ? 2.0 * cx / (cf + cx) : 1.0;
            }
            free(mf);
            free(mx);
        }
    }
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++) {
            double v = F[i * m + j] / sqrt(sf[i] * sf[j]);
            if (X)
                v += w * sqrt(q[i] * q[j]) * X[i * m + j] / sqrt(sx[i] * sx[j]);
            F[i * m + j] = i == j ? 0.0 : v;
        }
    free(sf);
    free(sx);
    free(q);
}

/* The rescalings of the channel matrix F (m x m, symmetric) before re-ranking (post_cfg.scale). */
static void rescale(double *F, size_t m, int how, size_t k)
{
    double *s = malloc(m * sizeof *s), *sd = malloc(m * sizeof *sd), *v = malloc(m * sizeof *v);
    double *R = malloc(m * m * sizeof *R);
    if (k + 1 > m)
        k = m - 1;
    for (size_t i = 0; i < m; i++) {
        size_t t = 0;
        for (size_t j = 0; j < m; j++)
            if (j != i)
                v[t++] = F[i * m + j];
        qsort(v, t, sizeof *v, cmp_d);
        double mean = 0, var = 0;
        for (size_t u = 0; u < t; u++)
            mean += v[u] / (double)t;
        for (size_t u = 0; u < t; u++)
            var += (v[u] - mean) * (v[u] - mean) / (double)t;
        if (how == 1)
            s[i] = v[k - 1];
        else if (how == 2) {
            s[i] = 0;
            for (size_t u = 0; u < k; u++)
                s[i] += v[u] / (double)k;
        } else {
            s[i] = mean;
            sd[i] = sqrt(var) > 0 ? sqrt(var) : 1e-12;
        }
        if (!(s[i] > 0))
            s[i] = 1e-12;
        if (how == 3) /* empirical: the share of the others farther from i than j is */
            for (size_t j = 0; j < m; j++) {
                double d = F[i * m + j];
                size_t lo = 0, hi = t; /* first index with v > d */
                while (lo < hi) {
                    size_t mid = (lo + hi) / 2;
                    if (v[mid] > d)
                        hi = mid;
                    else
                        lo = mid + 1;
                }
                R[i * m + j] = (double)(t - lo) / (double)t;
            }
    }
    for (size_t i = 0; i < m; i++)
        for (size_t j = 0; j < m; j++) {
            double d = F[i * m + j], x;
            if (i == j)
                x = 0.0;
            else if (how <= 2)
                x = d / sqrt(s[i] * s[j]);
            else if (how == 3)
                x = 1.0 - R[i * m + j] * R[j * m + i];
            else
                x = 1.0 - 0.25 * erfc((d - s[i]) / (sd[i] * 1.4142135623730951)) *
                              erfc((d - s[j]) / (sd[j] * 1.4142135623730951));
            F[i * m + j] = x; /* F is read only through v, s and sd here */
        }
    free(s);
    free(sd);
    free(v);
    free(R);
}

static double score_of(const double *F, size_t m, const int32_t *labels, int kind)
{
    if (kind == 1) {
        size_t counts[16] = {0}, kmax = m > 100 ? 11 : 10, sum = 0;
        if (amscr_score_topk_table(F, m, labels, kmax, counts) != AMSCR_OK)
            return -1;
        for (size_t r = 0; r < kmax; r++)
            sum += counts[r];
        return (double)sum;
    }
    double sc = 0;
    if (amscr_score_bullseye(F, m, labels, 0, &sc) != AMSCR_OK)
        return -1;
    return 100.0 * sc;
}

static int cmp_sz(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return (x > y) - (x < y);
}

/* k from the mutual-kNN graph: each shape's count of mutual neighbours among its K nearest
 * (itself excluded; shape j is mutual when i is also among j's K nearest); k = the median
 * count + 1 (itself, the re-ranking's first neighbour). */
static size_t mutual_k(const double *F, size_t m, size_t K)
{
    if (K + 1 > m)
        K = m - 1;
    size_t *nb = malloc(m * K * sizeof *nb), *cnt = malloc(m * sizeof *cnt);
    for (size_t i = 0; i < m; i++) {
        if (amscr_topk(F + i * m, m, K, i, nb + i * K) != AMSCR_OK)
            memset(nb + i * K, 0, K * sizeof *nb);
    }
    for (size_t i = 0; i < m; i++) {
        cnt[i] = 0;
        for (size_t t = 0; t < K; t++) {
            size_t j = nb[i * K + t];
            for (size_t u = 0; u < K; u++)
                if (nb[j * K + u] == i) {
                    cnt[i]++;
                    break;
                }
        }
    }
    qsort(cnt, m, sizeof *cnt, cmp_sz);
    size_t k = cnt[m / 2] + 1;
    free(nb);
    free(cnt);
    return k;
}

size_t last_k;

double *eval_matrix(const base_t *b, const size_t *idx, size_t m, const post_cfg *pc)
{
    size_t n = b->n, *all = NULL;
    if (!idx) {
        all = malloc(n * sizeof *all);
        for (size_t i = 0; i < n; i++)
            all[i] = i;
        idx = all;
        m = n;
    }
    double *F = malloc(m * m * sizeof *F), *X = malloc(m * m * sizeof *X);
    sub(b->hs, n, idx, m, F);
    sub(b->ha, n, idx, m, X);
    for (size_t i = 0; i < m * m; i++)
        F[i] = (1.0 - pc->share) * F[i] + pc->share * X[i];
    if (pc->weight < 1.0) {
        sub(b->am, n, idx, m, X);
        add_normalized(F, X, m, pc->weight, 1.0 - pc->weight);
    }
    size_t ks = pc->k ? pc->k : POST_DEFAULT.k; /* the local scales' neighbour: the re-ranking's k */
    if (pc->wfd > 0.0) {
        sub(pc->prop == 0 ? b->fd : pc->prop == 1 ? b->gm : b->ga, n, idx, m, X);
        if (pc->prop == 3) {
            double *Y = malloc(m * m * sizeof *Y);
            sub(b->gm, n, idx, m, Y);
            for (size_t i = 0; i < m * m; i++)
                X[i] = (1.0 - pc->share) * Y[i] + pc->share * X[i];
            free(Y);
        }
        if (pc->fmode == 0)
            add_normalized(F, X, m, 1.0, pc->wfd);
        else
            fuse_local(F, X, m, ks, pc->wfd, pc->fmode == 2);
    } else if (pc->fmode > 0)
        fuse_local(F, NULL, m, ks, 0.0, 0);
    if (pc->scale > 0)
        rescale(F, m, pc->scale, pc->lsk ? pc->lsk : ks);
    size_t k = pc->kmode == 1 ? (size_t)floor(pc->kfrac * sqrt((double)m) + 0.5)
               : pc->kmode == 2 ? mutual_k(F, m, (size_t)pc->kfrac) : pc->k;
    last_k = k;
    if (k > m)
        k = m;
    amscr_status st = AMSCR_OK;
    if (k != 0 && pc->inner > 0.0) { /* the inner-distance graph beside the fused distance's */
        sub(b->in, n, idx, m, X);
        st = amscr__rerank_normalized2(F, X, pc->inner, m, k, pc->iters, amscr__resolve_threads(0), F);
    } else if (k != 0)
        st = amscr__rerank_normalized(F, m, k, pc->iters, amscr__resolve_threads(0), F);
    if (st != AMSCR_OK) {
        free(F);
        F = NULL;
    }
    free(X);
    free(all);
    return F;
}

double eval_sub(const base_t *b, const coll_t *c, const size_t *idx, size_t m, const post_cfg *pc)
{
    if (!idx)
        m = b->n;
    double *F = eval_matrix(b, idx, m, pc), s = -1;
    int32_t *lab = malloc(m * sizeof *lab);
    for (size_t i = 0; i < m; i++)
        lab[i] = c->s.labels[idx ? idx[i] : i];
    if (F)
        s = score_of(F, m, lab, c->kind);
    free(F);
    free(lab);
    return s;
}

int score_row(const folds_data *fd, const raw_cfg *r, const post_cfg *pc, row_scores *out)
{
    size_t n = fd->dev.s.n, na = 0, nb = 0;
    size_t *ia = malloc(n * sizeof *ia), *ib = malloc(n * sizeof *ib);
    for (size_t i = 0; i < n; i++) {
        if (fd->fold[i])
            ib[nb++] = i;
        else
            ia[na++] = i;
    }
    base_t b;
    int am = pc->weight < 1.0, fo = pc->wfd > 0.0 ? 1 + pc->prop : 0, st = -1;
    if (base_get(&fd->dev, r, am, fo, &b) == 0) {
        out->a = eval_sub(&b, &fd->dev, ia, na, pc);
        out->b = eval_sub(&b, &fd->dev, ib, nb, pc);
        out->dev = eval_sub(&b, &fd->dev, NULL, 0, pc);
        base_free(&b);
        if (base_get(&fd->k99, r, am, fo, &b) == 0) {
            out->k99 = eval_sub(&b, &fd->k99, NULL, 0, pc);
            base_free(&b);
            if (base_get(&fd->k216, r, am, fo, &b) == 0) {
                out->k216 = eval_sub(&b, &fd->k216, NULL, 0, pc);
                st = 0;
            }
        }
    }
    base_free(&b);
    free(ia);
    free(ib);
    return st;
}
