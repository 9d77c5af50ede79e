/* dense.c — small dense numerics shared by the geometry and the registration (see dense.h). */
#include "dense.h"

#include <math.h>
#include <stdlib.h>

/* A 3x3 normal matrix whose determinant is below this fraction of its diagonal scale cubed is
 * treated as singular: its inverse would amplify rounding by more than ~1e13. */
#define AMSCR__INV3_TOL 1e-13
/* A pivot at or below this is zero: it is near the smallest normal double, so dividing by it
 * overflows rather than solves. */
#define AMSCR__PIVOT_MIN 1e-300
/* Up to this length insertion sort beats qsort (no call per comparison). */
#define AMSCR__SORT_SHORT 64

void amscr__centroid(const double *xy, size_t n, double *cx, double *cy)
{
    double sx = 0, sy = 0;
    for (size_t i = 0; i < n; i++) {
        sx += xy[2 * i];
        sy += xy[2 * i + 1];
    }
    *cx = sx / (double)n;
    *cy = sy / (double)n;
}

void amscr__bounds(const double *xy, size_t n, double lo[2], double hi[2])
{
    lo[0] = hi[0] = xy[0];
    lo[1] = hi[1] = xy[1];
    for (size_t i = 1; i < n; i++)
        for (int a = 0; a < 2; a++) {
            lo[a] = fmin(lo[a], xy[2 * i + a]);
            hi[a] = fmax(hi[a], xy[2 * i + a]);
        }
}

void amscr__scatter(const double *xy, size_t n, double cx, double cy, double unit, double cov[3])
{
    double sxx = 0, sxy = 0, syy = 0;
    for (size_t i = 0; i < n; i++) {
        double dx = (xy[2 * i] - cx) / unit, dy = (xy[2 * i + 1] - cy) / unit;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    cov[0] = sxx;
    cov[1] = sxy;
    cov[2] = syy;
}

void amscr__moments(const double *xy, size_t n, double m[6])
{
    double sxx = 0, sxy = 0, syy = 0, sx = 0, sy = 0;
    for (size_t a = 0; a < n; a++) {
        double x = xy[2 * a], y = xy[2 * a + 1];
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        sx += x;
        sy += y;
    }
    m[0] = sxx;
    m[1] = sxy;
    m[2] = syy;
    m[3] = sx;
    m[4] = sy;
    m[5] = (double)n;
}

void amscr__moment_matrix(const double mom[6], double M[9])
{
    M[0] = mom[0];
    M[1] = mom[1];
    M[2] = mom[3];
    M[3] = mom[1];
    M[4] = mom[2];
    M[5] = mom[4];
    M[6] = mom[3];
    M[7] = mom[4];
    M[8] = mom[5];
}

int amscr__inv3(const double m[9], double out[9])
{
    double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5], g = m[6], h = m[7], i = m[8];
    double A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    double det = a * A + b * B + c * C;
    double scale = fabs(a) + fabs(e) + fabs(i);
    if (!(fabs(det) > AMSCR__INV3_TOL * scale * scale * scale))
        return 0;
    out[0] = A / det;
    out[3] = B / det;
    out[6] = C / det;
    out[1] = -(b * i - c * h) / det;
    out[4] = (a * i - c * g) / det;
    out[7] = -(a * h - b * g) / det;
    out[2] = (b * f - c * e) / det;
    out[5] = -(a * f - c * d) / det;
    out[8] = (a * e - b * d) / det;
    return 1;
}

int amscr__gauss_solve(double *a, double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r * n + c]) > fabs(a[piv * n + c]))
                piv = r;
        if (!(fabs(a[piv * n + c]) > AMSCR__PIVOT_MIN))
            return 0;
        if (piv != c) {
            for (int k = 0; k < n; k++) {
                double t = a[c * n + k];
                a[c * n + k] = a[piv * n + k];
                a[piv * n + k] = t;
            }
            double t = b[c];
            b[c] = b[piv];
            b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            double f = a[r * n + c] / a[c * n + c];
            for (int k = c; k < n; k++)
                a[r * n + k] -= f * a[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; c--) {
        double v = b[c];
        for (int k = c + 1; k < n; k++)
            v -= a[c * n + k] * b[k];
        b[c] = v / a[c * n + c];
    }
    return 1;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

void amscr__sort_doubles(double *v, size_t n)
{
    if (n > AMSCR__SORT_SHORT) {
        qsort(v, n, sizeof *v, cmp_double);
        return;
    }
    for (size_t i = 1; i < n; i++) {
        double t = v[i];
        size_t j = i;
        while (j > 0 && v[j - 1] > t) {
            v[j] = v[j - 1];
            j--;
        }
        v[j] = t;
    }
}

void amscr__select_kth(double *v, size_t n, size_t k)
{
    size_t lo = 0, hi = n - 1;
    while (hi > lo) {
        size_t mid = lo + (hi - lo) / 2;
        double a = v[lo], b = v[mid], c = v[hi];
        double pivot = a < b ? (b < c ? b : (a < c ? c : a)) : (a < c ? a : (b < c ? c : b));
        size_t i = lo, j = hi;
        while (i <= j) {
            while (v[i] < pivot)
                i++;
            while (v[j] > pivot)
                j--;
            if (i <= j) {
                double t = v[i];
                v[i] = v[j];
                v[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}
