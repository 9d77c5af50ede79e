/* scale_select.c — which scales enter the stacked solve (docs/method.md §3.4): every scale (amscr),
 * the finest (acma), or those whose residual falls below the Bayes threshold between the two
 * lowest classes of a 1-D Gaussian mixture fitted to the per-scale residuals (binary EM: two
 * classes; multiclass EM: the class count chosen by the elbow of exact K-means). */
#include "dense.h"
#include "match.h"

#include <math.h>

/* EM settings of the per-scale residual mixture: p <= 64 values converge in a few dozen
 * iterations, so 100 is a cap, not a budget; the relative log-likelihood tolerance and the
 * variance floor (relative to the data's variance) are far below a residual's rounding. */
#define AMSCR__EM_MAX_ITER 100
#define AMSCR__EM_TOL 1e-6
#define AMSCR__EM_VAR_FLOOR 1e-6
/* Smallest variance of a one-class mixture (all residuals equal): keeps it a proper density. */
#define AMSCR__VAR_MIN 1e-300

size_t amscr__select_scratch(size_t p)
{
    size_t kmax = p < AMSCR__KMAX ? p : AMSCR__KMAX;
    /* the EM's layout: the sorted residuals, then room for the K-means DP and the EM's work
     * (the multiclass choice runs its DP in the same place first) */
    return amscr__gmm1d_small_scratch(p, kmax);
}

static void keep_all(match_t *m)
{
    for (size_t k = 0; k < m->p; k++)
        m->kept[k] = 1;
    m->nkept = m->p;
}

/* One class: the mixture is a single Gaussian and every scale is kept. */
static void one_class(match_t *m)
{
    size_t p = m->p;
    double mean = 0.0, var = 0.0;
    for (size_t k = 0; k < p; k++)
        mean += m->resid[k];
    mean /= (double)p;
    for (size_t k = 0; k < p; k++)
        var += (m->resid[k] - mean) * (m->resid[k] - mean);
    var /= (double)p;
    m->ncomp = 1;
    m->w[0] = 1.0;
    m->mu[0] = mean;
    m->var[0] = var > AMSCR__VAR_MIN ? var : AMSCR__VAR_MIN;
    keep_all(m);
}

/* Keeps the scales whose residual is at or below the Bayes threshold of the two lowest
 * components (at least the best scale). */
static void keep_below_threshold(match_t *m)
{
    double s0;
    amscr_status st = amscr_bayes_threshold(m->w[0], m->mu[0], m->var[0], m->w[1], m->mu[1], m->var[1], &s0);
    if (st != AMSCR_OK && st != AMSCR_E_NOT_FOUND)
        s0 = 0.5 * (m->mu[0] + m->mu[1]);
    m->threshold = s0;
    size_t best = 0;
    m->nkept = 0;
    for (size_t k = 0; k < m->p; k++) {
        if (m->resid[k] < m->resid[best])
            best = k;
        if (m->resid[k] <= s0) {
            m->kept[k] = 1;
            m->nkept++;
        }
    }
    if (m->nkept == 0) {
        m->kept[best] = 1;
        m->nkept = 1;
    }
}

void amscr__select_scales(const amscr_params *prm, size_t finest, match_t *m, double *scratch)
{
    size_t p = m->p;
    m->k = 0;
    m->nsse = 0;
    m->ncomp = 0;
    m->threshold = INFINITY;
    for (size_t k = 0; k < p; k++)
        m->kept[k] = 0;
    if (prm->method == AMSCR_METHOD_ACMA) {
        m->kept[finest] = 1;
        m->nkept = 1;
        return;
    }
    if (prm->method == AMSCR_METHOD_AMSCR || p < 2) {
        keep_all(m);
        return;
    }
    /* the residuals sorted once: the K-means DP and the EM both read them ascending */
    double *sorted = scratch;
    for (size_t k = 0; k < p; k++)
        sorted[k] = m->resid[k];
    amscr__sort_doubles(sorted, p);
    size_t K = 2;
    if (prm->method != AMSCR_METHOD_BINARY_EM) {
        size_t kmax = prm->kmax < p ? prm->kmax : p;
        if (kmax > AMSCR__KMAX)
            kmax = AMSCR__KMAX;
        amscr__kmeans1d_dp(sorted, p, kmax, scratch + p, m->sse, NULL);
        m->nsse = kmax;
        K = amscr__elbow_choose(m->sse, kmax, 1);
    }
    m->k = K;
    if (K <= 1) {
        one_class(m);
        return;
    }
    unsigned it;
    int conv;
    double ll;
    if (amscr__gmm1d_fit_sorted(sorted, p, K, AMSCR__EM_MAX_ITER, AMSCR__EM_TOL, AMSCR__EM_VAR_FLOOR, m->w, m->mu,
                                m->var, scratch, &it, &conv, &ll) != AMSCR_OK) {
        /* cannot happen for finite residuals; keep every scale rather than guess */
        keep_all(m);
        return;
    }
    m->ncomp = K;
    keep_below_threshold(m);
}
