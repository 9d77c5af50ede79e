/* gmm1d.c — 1-D Gaussian mixture by EM, started from exact 1-D K-means, and the Bayes
 * threshold between two weighted Gaussians (docs/method.md §3.4c-d).
 *
 * EM (one pass per iteration over the data, sorted ascending so the result does not
 * depend on the input order):
 *   E: log p_c(x) = log w_c - log(2 pi var_c)/2 - (x - mu_c)^2 / (2 var_c);
 *      responsibilities r_c = exp(log p_c - logsumexp), loglik += logsumexp.
 *   M: with d = x - mu_c (old mean), mu_c += sum r d / sum r,
 *      var_c = sum r d^2 / sum r - (sum r d / sum r)^2 (floored), w_c = sum r / n
 *      (floored at 1e-12, renormalized).
 *   Stop when |loglik - previous| <= tol * (1 + |loglik|) (converged) or at the cap.
 * Variance floor: max(floor_rel * var(data), 1e-300 * max(1, |mean|)^2). */
#include "dense.h"
#include "internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GMM_WEIGHT_FLOOR 1e-12
#define GMM_LOG_2PI 1.8378770664093454835606594728112

/* Scratch (doubles) of one fit: the sorted copy, the K-means DP scratch, k SSE values
 * and 6k EM work values. */
size_t amscr__gmm1d_small_scratch(size_t n, size_t k)
{
    return n + amscr__kmeans1d_scratch(n, k) + 7 * k;
}

/* One E pass at the current parameters: returns the log-likelihood (NaN/-inf when a point
 * has zero density under every component) and accumulates, per component, sum r,
 * sum r d and sum r d^2 with d = x - mu_c. */
static double gmm_pass(const double *x, size_t n, size_t k, const double *w, const double *mu, const double *var,
                       double *lc, double *iv, double *lp, double *sr, double *srd, double *srd2)
{
    for (size_t c = 0; c < k; c++) {
        lc[c] = log(w[c]) - 0.5 * (GMM_LOG_2PI + log(var[c]));
        iv[c] = 1.0 / var[c];
        sr[c] = srd[c] = srd2[c] = 0.0;
    }
    double ll = 0.0;
    for (size_t i = 0; i < n; i++) {
        const double xi = x[i];
        double mx = -INFINITY;
        for (size_t c = 0; c < k; c++) {
            double d = xi - mu[c];
            lp[c] = lc[c] - 0.5 * d * d * iv[c];
            if (lp[c] > mx)
                mx = lp[c];
        }
        if (!(mx > -INFINITY))
            return NAN;
        double s = 0.0;
        for (size_t c = 0; c < k; c++) {
            lp[c] = exp(lp[c] - mx);
            s += lp[c];
        }
        ll += mx + log(s);
        const double is = 1.0 / s;
        for (size_t c = 0; c < k; c++) {
            double r = lp[c] * is, d = xi - mu[c];
            sr[c] += r;
            srd[c] += r * d;
            srd2[c] += r * d * d;
        }
    }
    return ll;
}

/* Sorts the k components by mean (stable insertion sort). */
static void gmm_sort_components(size_t k, double *w, double *mu, double *var)
{
    for (size_t i = 1; i < k; i++) {
        double tw = w[i], tm = mu[i], tv = var[i];
        size_t j = i;
        while (j > 0 && mu[j - 1] > tm) {
            w[j] = w[j - 1];
            mu[j] = mu[j - 1];
            var[j] = var[j - 1];
            j--;
        }
        w[j] = tw;
        mu[j] = tm;
        var[j] = tv;
    }
}

/* The variance floor: floor_rel times the data's variance (two passes), and at least
 * 1e-300 times its squared magnitude. */
static double gmm_variance_floor(const double *x, size_t n, double floor_rel)
{
    double m = 0.0;
    for (size_t i = 0; i < n; i++)
        m += x[i];
    m /= (double)n;
    double v = 0.0;
    for (size_t i = 0; i < n; i++)
        v += (x[i] - m) * (x[i] - m);
    v /= (double)n;
    double am = fabs(m) > 1.0 ? fabs(m) : 1.0;
    double vfloor = 1e-300 * am * am;
    if (!(vfloor <= DBL_MAX))
        vfloor = DBL_MAX;
    if (floor_rel * v > vfloor)
        vfloor = floor_rel * v;
    return vfloor;
}

/* The components of the K-means split of sorted data (row: the k clusters' first indices):
 * each cluster's share, mean and variance (at least vfloor). */
static void gmm_start(const double *sorted, size_t n, size_t k, const size_t *row, double vfloor, double *w,
                      double *mu, double *var)
{
    for (size_t c = 0; c < k; c++) {
        size_t a = row[c], b = c + 1 < k ? row[c + 1] : n;
        double s = 0.0;
        for (size_t i = a; i < b; i++)
            s += sorted[i];
        double cm = s / (double)(b - a);
        double q = 0.0;
        for (size_t i = a; i < b; i++)
            q += (sorted[i] - cm) * (sorted[i] - cm);
        q /= (double)(b - a);
        w[c] = (double)(b - a) / (double)n;
        mu[c] = cm;
        var[c] = q > vfloor ? q : vfloor;
    }
}

/* The M step from the statistics of the last pass (sr: responsibilities, srd / srd2: their
 * first and second moments about the old means). */
static void gmm_m_step(size_t n, size_t k, const double *sr, const double *srd, const double *srd2, double vfloor,
                       double *w, double *mu, double *var)
{
    double wsum = 0.0;
    for (size_t c = 0; c < k; c++) {
        if (sr[c] > 0.0) {
            double dm = srd[c] / sr[c];
            double vc = srd2[c] / sr[c] - dm * dm;
            mu[c] += dm;
            var[c] = vc > vfloor ? vc : vfloor;
        }
        w[c] = sr[c] / (double)n;
        if (!(w[c] >= GMM_WEIGHT_FLOOR))
            w[c] = GMM_WEIGHT_FLOOR;
        wsum += w[c];
    }
    for (size_t c = 0; c < k; c++)
        w[c] /= wsum;
}

/* The fit shared by amscr_gmm1d_fit and amscr__gmm1d_fit_small/_sorted. x: n finite values
 * (ascending when presorted; may then be scratch itself), 1 <= k <= n; scratch:
 * amscr__gmm1d_small_scratch(n, k) doubles; split: k*k. */
static amscr_status gmm_fit_core(const double *x, int presorted, size_t n, size_t k, unsigned max_iter, double tol,
                                 double floor_rel, double *w, double *mu, double *var, double *scratch,
                                 size_t *split, unsigned *out_iter, int *out_converged, double *out_loglik)
{
    double *sorted = scratch;
    double *dp = sorted + n;
    double *sse = dp + amscr__kmeans1d_scratch(n, k);
    double *lc = sse + k, *iv = lc + k, *lp = iv + k, *sr = lp + k, *srd = sr + k, *srd2 = srd + k;

    if (x != sorted)
        memcpy(sorted, x, n * sizeof *sorted);
    if (!presorted)
        amscr__sort_doubles(sorted, n);

    double vfloor = gmm_variance_floor(sorted, n, floor_rel);
    amscr__kmeans1d_dp(sorted, n, k, dp, sse, split); /* the start: exact 1-D K-means */
    gmm_start(sorted, n, k, split + (k - 1) * k, vfloor, w, mu, var);
    double ll = gmm_pass(sorted, n, k, w, mu, var, lc, iv, lp, sr, srd, srd2);
    if (!isfinite(ll))
        return amscr__fail(AMSCR_E_NUMERIC, "gmm1d: non-finite log-likelihood at the start");
    unsigned it = 0;
    int converged = 0;
    while (it < max_iter) {
        gmm_m_step(n, k, sr, srd, srd2, vfloor, w, mu, var);
        it++;
        double ll_new = gmm_pass(sorted, n, k, w, mu, var, lc, iv, lp, sr, srd, srd2);
        if (!isfinite(ll_new))
            return amscr__fail(AMSCR_E_NUMERIC, "gmm1d: non-finite log-likelihood at iteration %u", it);
        double gain = fabs(ll_new - ll);
        ll = ll_new;
        if (gain <= tol * (1.0 + fabs(ll))) {
            converged = 1;
            break;
        }
    }
    gmm_sort_components(k, w, mu, var);
    if (out_iter)
        *out_iter = it;
    if (out_converged)
        *out_converged = converged;
    if (out_loglik)
        *out_loglik = ll;
    return AMSCR_OK;
}

static amscr_status fit_small(const double *x, int presorted, size_t n, size_t k, unsigned max_iter, double tol,
                              double var_floor_rel, double *w, double *mu, double *var, double *scratch,
                              unsigned *out_iter, int *out_converged, double *out_loglik)
{
    if (!x || !w || !mu || !var || !scratch)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr__gmm1d_fit_small: NULL argument");
    if (k < 1 || k > AMSCR__KMAX || k > n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr__gmm1d_fit_small: k = %zu (n = %zu, k <= %d)", k, n,
                           AMSCR__KMAX);
    if (max_iter < 1 || !(tol >= 0.0) || !(var_floor_rel >= 0.0 && var_floor_rel <= 1.0))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr__gmm1d_fit_small: bad settings");
    size_t split[AMSCR__KMAX * AMSCR__KMAX];
    return gmm_fit_core(x, presorted, n, k, max_iter, tol, var_floor_rel, w, mu, var, scratch, split, out_iter,
                        out_converged, out_loglik);
}

/* Hot-path fit without allocation: K-component mixture of n finite values (1 <= k <= 16,
 * k <= n; meant for n <= 64 but any n works), max_iter >= 1, tol >= 0, var_floor_rel in
 * [0, 1]. Writes k weights/means/variances sorted by mean; out_* may be NULL.
 * scratch: amscr__gmm1d_small_scratch(n, k) doubles. Gives exactly what amscr_gmm1d_fit
 * gives with the same settings. Returns AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NUMERIC. */
amscr_status amscr__gmm1d_fit_small(const double *x, size_t n, size_t k, unsigned max_iter, double tol,
                                    double var_floor_rel, double *w, double *mu, double *var, double *scratch,
                                    unsigned *out_iter, int *out_converged, double *out_loglik)
{
    return fit_small(x, 0, n, k, max_iter, tol, var_floor_rel, w, mu, var, scratch, out_iter, out_converged,
                     out_loglik);
}

amscr_status amscr__gmm1d_fit_sorted(const double *sorted, size_t n, size_t k, unsigned max_iter, double tol,
                                     double var_floor_rel, double *w, double *mu, double *var, double *scratch,
                                     unsigned *out_iter, int *out_converged, double *out_loglik)
{
    return fit_small(sorted, 1, n, k, max_iter, tol, var_floor_rel, w, mu, var, scratch, out_iter, out_converged,
                     out_loglik);
}

/* ======================================================================
 * The amscr_gmm1d object
 * ====================================================================== */

struct amscr_gmm1d {
    size_t k;
    unsigned max_iterations;
    double tol;
    double var_floor;
    double *params; /* 3k: weights, means, variances; NULL before a fit */
    double loglik;
    unsigned iterations;
    int converged;
};

amscr_status amscr_gmm1d_new(size_t k, amscr_gmm1d **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    if (k == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_new: k must be >= 1");
    if (k > SIZE_MAX / 64)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_new: k = %zu too large", k);
    amscr_gmm1d *g = malloc(sizeof *g);
    if (!g)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_gmm1d_new: out of memory");
    g->k = k;
    g->max_iterations = 200;
    g->tol = 1e-10;
    g->var_floor = 1e-6;
    g->params = NULL;
    g->loglik = NAN;
    g->iterations = 0;
    g->converged = 0;
    *out = g;
    return AMSCR_OK;
}

void amscr_gmm1d_free(amscr_gmm1d *g)
{
    if (!g)
        return;
    free(g->params);
    free(g);
}

AMSCR__SETTER(amscr_gmm1d_set_max_iterations, amscr_gmm1d, g, unsigned, max_iterations,
              AMSCR__REQUIRE(v >= 1, "amscr_gmm1d_set_max_iterations: must be >= 1"))
AMSCR__SETTER(amscr_gmm1d_set_tolerance, amscr_gmm1d, g, double, tol,
              AMSCR__REQUIRE(v >= 0.0 && isfinite(v), "amscr_gmm1d_set_tolerance: %g is not a finite value >= 0", v))
AMSCR__SETTER(amscr_gmm1d_set_variance_floor, amscr_gmm1d, g, double, var_floor,
              AMSCR__REQUIRE(v >= 0.0 && v <= 1.0, "amscr_gmm1d_set_variance_floor: %g not in [0, 1]", v))

AMSCR__GETTER(amscr_gmm1d_get_max_iterations, amscr_gmm1d, unsigned, max_iterations)
AMSCR__GETTER(amscr_gmm1d_get_tolerance, amscr_gmm1d, double, tol)
AMSCR__GETTER(amscr_gmm1d_get_variance_floor, amscr_gmm1d, double, var_floor)
size_t amscr_gmm1d_num_components(const amscr_gmm1d *g) { return g ? g->k : 0; }
const double *amscr_gmm1d_weights(const amscr_gmm1d *g) { return g && g->params ? g->params : NULL; }
const double *amscr_gmm1d_means(const amscr_gmm1d *g) { return g && g->params ? g->params + g->k : NULL; }
const double *amscr_gmm1d_variances(const amscr_gmm1d *g) { return g && g->params ? g->params + 2 * g->k : NULL; }
double amscr_gmm1d_loglik(const amscr_gmm1d *g) { return g && g->params ? g->loglik : NAN; }
unsigned amscr_gmm1d_iterations(const amscr_gmm1d *g) { return g && g->params ? g->iterations : 0; }
int amscr_gmm1d_converged(const amscr_gmm1d *g) { return g && g->params ? g->converged : 0; }

amscr_status amscr_gmm1d_fit(amscr_gmm1d *g, const double *x, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(g);
    AMSCR_CHECK_NULL(x);
    const size_t k = g->k;
    if (n < k)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_fit: n = %zu < k = %zu", n, k);
    if (!amscr__all_finite(x, n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_fit: non-finite data");
    size_t ns = amscr__gmm1d_small_scratch(n, k);
    if (n > SIZE_MAX / 16 / (k + 8) || k > SIZE_MAX / sizeof(size_t) / k)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_fit: problem too large (n = %zu, k = %zu)", n, k);
    double *scratch = amscr__malloc_array(ns, sizeof *scratch);
    size_t *split = amscr__malloc_array(k * k, sizeof *split);
    double *params = amscr__malloc_array(3 * k, sizeof *params);
    if (!scratch || !split || !params) {
        free(scratch);
        free(split);
        free(params);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_gmm1d_fit: out of memory (n = %zu, k = %zu)", n, k);
    }
    unsigned it = 0;
    int conv = 0;
    double ll = NAN;
    amscr_status st = gmm_fit_core(x, 0, n, k, g->max_iterations, g->tol, g->var_floor, params, params + k,
                                   params + 2 * k, scratch, split, &it, &conv, &ll);
    free(scratch);
    free(split);
    if (st != AMSCR_OK) {
        free(params);
        return st;
    }
    free(g->params);
    g->params = params;
    g->loglik = ll;
    g->iterations = it;
    g->converged = conv;
    return AMSCR_OK;
}

amscr_status amscr_gmm1d_posterior(const amscr_gmm1d *g, double x, double *out_post)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(g);
    AMSCR_CHECK_NULL(out_post);
    if (!g->params)
        return amscr__fail(AMSCR_E_STATE, "amscr_gmm1d_posterior: not fitted");
    if (!isfinite(x))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_posterior: x is not finite");
    const size_t k = g->k;
    const double *w = g->params, *mu = w + k, *var = mu + k;
    double mx = -INFINITY;
    for (size_t c = 0; c < k; c++) {
        double d = x - mu[c];
        double l = log(w[c]) - 0.5 * log(var[c]) - 0.5 * d * d / var[c];
        if (l > mx)
            mx = l;
    }
    if (!(mx > -INFINITY))
        return amscr__fail(AMSCR_E_NUMERIC, "amscr_gmm1d_posterior: zero density under every component");
    double s = 0.0;
    for (size_t c = 0; c < k; c++) {
        double d = x - mu[c];
        s += exp(log(w[c]) - 0.5 * log(var[c]) - 0.5 * d * d / var[c] - mx);
    }
    for (size_t c = 0; c < k; c++) {
        double d = x - mu[c];
        out_post[c] = exp(log(w[c]) - 0.5 * log(var[c]) - 0.5 * d * d / var[c] - mx) / s;
    }
    return AMSCR_OK;
}

/* Bayes threshold. With m = (mu1+mu2)/2, t = s - m, d1 = mu1 - m, d2 = mu2 - m, equal
 * log-densities times -2*var1*var2 give a t^2 + b t + c = 0 with
 *   a = var2 - var1,  b = -2 (d1 var2 - d2 var1),
 *   c = d1^2 var2 - d2^2 var1 + var1 var2 (log(var1/var2) - 2 log(w1/w2)).
 * Equal variances (relative 1e-12): the line b t + c = 0, i.e.
 * s = m + var log(w1/w2) / (mu2 - mu1). Otherwise the stable quadratic formula
 * q = -(b + sign(b) sqrt(b^2 - 4ac)) / 2, roots q/a and c/q. */
amscr_status amscr_bayes_threshold(double w1, double mu1, double var1, double w2, double mu2, double var2,
                                   double *out_threshold)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out_threshold);
    if (!isfinite(w1) || !isfinite(w2) || !isfinite(mu1) || !isfinite(mu2) || !isfinite(var1) || !isfinite(var2))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_bayes_threshold: non-finite argument");
    if (!(w1 > 0.0) || !(w2 > 0.0))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_bayes_threshold: weights must be > 0 (%g, %g)", w1, w2);
    if (!(var1 > 0.0) || !(var2 > 0.0))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_bayes_threshold: variances must be > 0 (%g, %g)", var1,
                           var2);
    const double mid = 0.5 * mu1 + 0.5 * mu2;
    const double lo = mu1 < mu2 ? mu1 : mu2, hi = mu1 < mu2 ? mu2 : mu1;
    if (!(lo < hi)) {
        *out_threshold = mid;
        return amscr__fail(AMSCR_E_NOT_FOUND, "amscr_bayes_threshold: equal means (%g)", mu1);
    }
    const double d1 = mu1 - mid, d2 = mu2 - mid;
    const double lr = log(var1 / var2) - 2.0 * (log(w1) - log(w2));
    double roots[2];
    int nr = 0;
    const double vmax = var1 > var2 ? var1 : var2;
    if (fabs(var1 - var2) <= 1e-12 * vmax) {
        /* Linear: with v the common variance, -2 (d1 - d2) v t + v^2 lr = 0. */
        double v = 0.5 * var1 + 0.5 * var2;
        roots[nr++] = v * lr / (2.0 * (d1 - d2));
    } else {
        const double a = var2 - var1;
        const double b = -2.0 * (d1 * var2 - d2 * var1);
        const double c = d1 * d1 * var2 - d2 * d2 * var1 + var1 * var2 * lr;
        const double disc = b * b - 4.0 * a * c;
        if (disc >= 0.0 && isfinite(disc)) {
            double sq = sqrt(disc);
            double q = -0.5 * (b + (b >= 0.0 ? sq : -sq));
            if (q != 0.0) {
                roots[nr++] = q / a;
                roots[nr++] = c / q;
            } else {
                roots[nr++] = 0.0; /* b = 0 and c = 0: double root at t = 0 */
            }
        }
    }
    /* The root strictly between the means (the one nearest the midpoint if two are). */
    int found = 0;
    double best = mid;
    for (int i = 0; i < nr; i++) {
        double s = mid + roots[i];
        if (isfinite(s) && s > lo && s < hi && (!found || fabs(roots[i]) < fabs(best - mid))) {
            best = s;
            found = 1;
        }
    }
    *out_threshold = found ? best : mid;
    if (!found)
        return amscr__fail(AMSCR_E_NOT_FOUND, "amscr_bayes_threshold: no crossing strictly between %g and %g", lo,
                           hi);
    return AMSCR_OK;
}

amscr_status amscr_gmm1d_bayes_threshold(const amscr_gmm1d *g, size_t i, size_t j, double *out_threshold)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(g);
    AMSCR_CHECK_NULL(out_threshold);
    if (!g->params)
        return amscr__fail(AMSCR_E_STATE, "amscr_gmm1d_bayes_threshold: not fitted");
    if (i >= g->k || j >= g->k || i == j)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_gmm1d_bayes_threshold: components %zu, %zu (k = %zu)", i, j,
                           g->k);
    const double *w = g->params, *mu = w + g->k, *var = mu + g->k;
    return amscr_bayes_threshold(w[i], mu[i], var[i], w[j], mu[j], var[j], out_threshold);
}
