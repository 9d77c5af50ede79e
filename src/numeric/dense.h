/* The numeric area (src/numeric/): the numerical building blocks, independent of shapes:
 *   lstsq.c   least squares by Householder QR through LAPACKE
 *   fft.c     a small complex FFT with plans (fft.h)
 *   dense.c   small dense numerics (this header)
 *   kmeans.c  deterministic K-means (exact in 1-D) and the elbow choice of K
 *   gmm1d.c   1-D Gaussian mixture by EM and the Bayes threshold
 *   smooth.c  FIR Gaussian smoothing of curves
 *   affine.c  fitting, applying and inverting 2-D affine maps
 *
 * dense.h — small dense numerics shared by the geometry and the registration (never installed):
 * centroid and scatter of a point set, the moment sums of a least-squares fit, 3x3 inverse,
 * a small Gaussian elimination, the sort of a short array and the k-th smallest of an array. */
#ifndef AMSCR_DENSE_H
#define AMSCR_DENSE_H

#include <stddef.h>

/* π, written once (C99 has no M_PI). */
#define AMSCR__PI 3.14159265358979323846

/* Mean point of n points xy (2n). */
void amscr__centroid(const double *xy, size_t n, double *cx, double *cy);
/* The bounding box of n >= 1 points xy (2n): lo = (min x, min y), hi = (max x, max y). */
void amscr__bounds(const double *xy, size_t n, double lo[2], double hi[2]);

/* Scatter about (cx, cy) in units of `unit`: cov = Σ (d/unit)(d/unit)^T, d = p - c, as
 * {xx, xy, yy} (not divided by n; unit 1 for plain coordinates). */
void amscr__scatter(const double *xy, size_t n, double cx, double cy, double unit, double cov[3]);

/* Moment sums of a least-squares fit x ≈ X [f; 1]: m = {Σ fx², Σ fx fy, Σ fy², Σ fx, Σ fy, count}. */
static inline void amscr__moment_add(double m[6], double x, double y)
{
    m[0] += x * x;
    m[1] += x * y;
    m[2] += y * y;
    m[3] += x;
    m[4] += y;
    m[5] += 1.0;
}

/* Adds the target point (u, v) matched to the source point (x, y) to the cross sums
 * R = [sum u x, sum u y, sum u, sum v x, sum v y, sum v] of a least-squares affine fit. */
static inline void amscr__cross_add(double R[6], double u, double v, double x, double y)
{
    R[0] += u * x;
    R[1] += u * y;
    R[2] += u;
    R[3] += v * x;
    R[4] += v * y;
    R[5] += v;
}

/* The moment sums of n points (see amscr__moment_add). */
void amscr__moments(const double *xy, size_t n, double m[6]);

/* The 3x3 normal matrix [[sxx sxy sx] [sxy syy sy] [sx sy n]] of moment sums (row-major). */
void amscr__moment_matrix(const double mom[6], double M[9]);

/* Inverse of a 3x3 matrix (row-major) by cofactors; returns 0 when it is numerically singular
 * (|det| <= AMSCR__INV3_TOL (|m00| + |m11| + |m22|)^3). */
int amscr__inv3(const double m[9], double out[9]);

/* Solves a x = b (n x n, n <= 6) by Gaussian elimination with partial pivoting; the solution
 * replaces b, a is destroyed. Returns 0 when singular. */
int amscr__gauss_solve(double *a, double *b, int n);

/* Sorts n values ascending in place (insertion sort when short, qsort otherwise). */
void amscr__sort_doubles(double *v, size_t n);

/* Partially orders v (n >= 1) so that v[k] is the k-th smallest and v[0..k) are the smaller
 * ones (quickselect, median-of-three pivots): O(n), no allocation. */
void amscr__select_kth(double *v, size_t n, size_t k);

#endif
