/* group_fit.c — the least-squares map of one system (source moments, cross sums) within the
 * invariance group of the params (affine, similarity, penalized affine), its residual, and the
 * one distance every path reports. */
#include "dense.h"
#include "match.h"

#include <string.h>

void amscr__cross_sums(const double *f, const double *h, size_t n, size_t s, int o, int closed, double R[6])
{
    double r0 = 0, r1 = 0, r2 = 0, r3 = 0, r4 = 0, r5 = 0;
    for (size_t a = 0; a < n; a++) {
        size_t b = amscr__tgt_index(a, s, o, closed, n);
        double fx = f[2 * a], fy = f[2 * a + 1], hx = h[2 * b], hy = h[2 * b + 1];
        r0 += hx * fx;
        r1 += hx * fy;
        r2 += hx;
        r3 += hy * fx;
        r4 += hy * fy;
        r5 += hy;
    }
    R[0] = r0;
    R[1] = r1;
    R[2] = r2;
    R[3] = r3;
    R[4] = r4;
    R[5] = r5;
}

/* Similarity: A = [[a, -b], [b, a]] from the centred sums (closed form). */
static int fit_similarity(const double mom[6], const double R[6], double X[6])
{
    double n = mom[5], fx = mom[3] / n, fy = mom[4] / n, hx = R[2] / n, hy = R[5] / n;
    double cxx = R[0] - n * hx * fx, cxy = R[1] - n * hx * fy, cyx = R[3] - n * hy * fx, cyy = R[4] - n * hy * fy;
    double sc = mom[0] + mom[2] - n * (fx * fx + fy * fy);
    if (!(sc > 0.0))
        return 0;
    double a = (cxx + cyy) / sc, b = (cyx - cxy) / sc;
    X[0] = a;
    X[1] = -b;
    X[3] = b;
    X[4] = a;
    X[2] = hx - (a * fx - b * fy);
    X[5] = hy - (b * fx + a * fy);
    return 1;
}

/* Penalized: affine plus lambda n |A - sim(A)|_F^2 (6x6 normal equations). Unknowns
 * u = (a11, a12, b1, a21, a22, b2); blockdiag(M, M) + Q, Q from
 * (lambda n / 2) ((a11 - a22)^2 + (a12 + a21)^2) = lambda n |A - sim(A)|_F^2. */
static int fit_penalized(double penalty, const double mom[6], const double R[6], double X[6])
{
    double G[36] = {0}, r[6] = {R[0], R[1], R[2], R[3], R[4], R[5]}, M9[9];
    amscr__moment_matrix(mom, M9);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            G[i * 6 + j] = M9[i * 3 + j];
            G[(i + 3) * 6 + (j + 3)] = M9[i * 3 + j];
        }
    /* normal equations of data + P: G u + grad(P) / 2 = r, grad P / 2 = (lambda n / 2) (...) */
    double w = 0.5 * penalty * mom[5];
    G[0 * 6 + 0] += w;
    G[4 * 6 + 4] += w;
    G[0 * 6 + 4] -= w;
    G[4 * 6 + 0] -= w;
    G[1 * 6 + 1] += w;
    G[3 * 6 + 3] += w;
    G[1 * 6 + 3] += w;
    G[3 * 6 + 1] += w;
    if (!amscr__gauss_solve(G, r, 6))
        return 0;
    memcpy(X, r, 6 * sizeof(double));
    return 1;
}

int amscr__fit_x(const amscr_params *prm, const double mom[6], const double *Minv, const double R[6], double X[6])
{
    if (prm->invariance == AMSCR_INVARIANCE_SIMILARITY)
        return fit_similarity(mom, R, X);
    if (prm->invariance == AMSCR_INVARIANCE_PENALIZED)
        return fit_penalized(prm->penalty, mom, R, X);
    /* affine: X = R M^-1 */
    double Mi[9];
    if (!Minv) {
        double M9[9];
        amscr__moment_matrix(mom, M9);
        if (!amscr__inv3(M9, Mi))
            return 0;
        Minv = Mi;
    }
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 3; j++)
            X[3 * i + j] = R[3 * i] * Minv[j] + R[3 * i + 1] * Minv[3 + j] + R[3 * i + 2] * Minv[6 + j];
    return 1;
}

/* Σ_a |X [f;1] - h|^2 = tr(X M X^T) - 2 tr(X R^T) + |h|^2 with M the 3x3 moments of f. */
double amscr__resid_sum(const double X[6], const double mom[6], const double R[6], double hn2)
{
    double M[9];
    amscr__moment_matrix(mom, M);
    double q = 0, c = 0;
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 3; j++) {
            double mx = M[3 * j] * X[3 * i] + M[3 * j + 1] * X[3 * i + 1] + M[3 * j + 2] * X[3 * i + 2];
            q += X[3 * i + j] * mx;
            c += X[3 * i + j] * R[3 * i + j];
        }
    }
    double v = q - 2.0 * c + hn2;
    return v > 0.0 ? v : 0.0;
}

/* The penalty of the penalized mode for n points (0 otherwise). */
static double penalty_of(const amscr_params *prm, const double X[6], double n)
{
    if (prm->invariance != AMSCR_INVARIANCE_PENALIZED)
        return 0.0;
    double c = 0.5 * (X[0] - X[4]), d = 0.5 * (X[1] + X[3]);
    return prm->penalty * n * 2.0 * (c * c + d * d);
}

double amscr__distance_of(const amscr_params *prm, const double X[6], double sq, size_t n)
{
    return (sq + penalty_of(prm, X, (double)n)) / (double)n;
}
