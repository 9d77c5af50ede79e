/* lstsq.c — least squares by Householder QR through LAPACKE (dgeqrf + dormqr + dtrtrs),
 * with a condition check on R: rank deficiency is an error, never a silent answer. */
#include "internal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define AMSCR__RCOND_MIN 1e-12

size_t amscr__lstsq_work_size(size_t m, size_t n, size_t nrhs)
{
    (void)m;
    /* tau (n) + dgeqrf work (64 n) + dormqr work (64 nrhs) + dtrcon work (3 n) */
    return n + 64 * n + 64 * (nrhs > 0 ? nrhs : 1) + 3 * n + 16;
}

/* Column-major in place: A (m x n, lda m) is overwritten by its QR factors, B (m x nrhs,
 * ldb m) by Q^T B, and X = first n rows. work: amscr__lstsq_work_size doubles, iwork n ints.
 * On success x (n x nrhs, column-major, ld n) and residual norms (may be NULL). */
amscr_status amscr__lstsq_colmajor(double *A, size_t m, size_t n, double *B, size_t nrhs, double *work, int *iwork,
                                   double *x, double *resid)
{
    lapack_int M = (lapack_int)m, N = (lapack_int)n, R = (lapack_int)nrhs;
    double *tau = work, *w = work + n;
    lapack_int lw1 = (lapack_int)(64 * n), lw2 = (lapack_int)(64 * (nrhs > 0 ? nrhs : 1));
    lapack_int info = LAPACKE_dgeqrf_work(LAPACK_COL_MAJOR, M, N, A, M, tau, w, lw1);
    if (info != 0)
        return amscr__fail(AMSCR_E_NUMERIC, "least squares: dgeqrf failed (info %d)", (int)info);
    double rcond = 0.0;
    info = LAPACKE_dtrcon_work(LAPACK_COL_MAJOR, '1', 'U', 'N', N, A, M, &rcond, w, (lapack_int *)iwork);
    if (info != 0)
        return amscr__fail(AMSCR_E_NUMERIC, "least squares: dtrcon failed (info %d)", (int)info);
    if (!(rcond >= AMSCR__RCOND_MIN))
        return amscr__fail(AMSCR_E_NUMERIC,
                           "least squares: the matrix is rank-deficient or ill-conditioned (rcond of R = %.3g < %g)",
                           rcond, AMSCR__RCOND_MIN);
    info = LAPACKE_dormqr_work(LAPACK_COL_MAJOR, 'L', 'T', M, R, N, A, M, tau, B, M, w, lw2);
    if (info != 0)
        return amscr__fail(AMSCR_E_NUMERIC, "least squares: dormqr failed (info %d)", (int)info);
    info = LAPACKE_dtrtrs_work(LAPACK_COL_MAJOR, 'U', 'N', 'N', N, R, A, M, B, M);
    if (info != 0)
        return amscr__fail(AMSCR_E_NUMERIC, "least squares: R is singular (dtrtrs info %d)", (int)info);
    for (size_t j = 0; j < nrhs; j++) {
        for (size_t i = 0; i < n; i++)
            x[j * n + i] = B[j * m + i];
        if (resid) {
            double s = 0.0;
            for (size_t i = n; i < m; i++)
                s += B[j * m + i] * B[j * m + i];
            resid[j] = sqrt(s);
        }
    }
    return AMSCR_OK;
}

amscr_status amscr_lstsq_qr(const double *a, size_t m, size_t n, const double *b, size_t nrhs, double *out_x,
                            double *out_residual_norms)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(a);
    AMSCR_CHECK_NULL(b);
    AMSCR_CHECK_NULL(out_x);
    if (n == 0 || nrhs == 0 || m < n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_lstsq_qr: need m >= n >= 1 and nrhs >= 1 (m=%zu n=%zu nrhs=%zu)",
                           m, n, nrhs);
    if (m > (size_t)1 << 30 || n > 4096 || nrhs > 4096)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_lstsq_qr: problem too large");
    if (!amscr__all_finite(a, m * n) || !amscr__all_finite(b, m * nrhs))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_lstsq_qr: non-finite input");
    size_t wsz = amscr__lstsq_work_size(m, n, nrhs);
    double *buf = amscr__malloc_array(m * n + m * nrhs + wsz + n * nrhs + nrhs, sizeof *buf);
    int *iwork = amscr__malloc_array(n, sizeof *iwork);
    if (!buf || !iwork) {
        free(buf);
        free(iwork);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_lstsq_qr: out of memory");
    }
    double *A = buf, *B = A + m * n, *W = B + m * nrhs, *X = W + wsz, *res = X + n * nrhs;
    for (size_t i = 0; i < m; i++) {
        for (size_t j = 0; j < n; j++)
            A[j * m + i] = a[i * n + j];
        for (size_t j = 0; j < nrhs; j++)
            B[j * m + i] = b[i * nrhs + j];
    }
    amscr_status st = amscr__lstsq_colmajor(A, m, n, B, nrhs, W, iwork, X, res);
    if (st == AMSCR_OK) {
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < nrhs; j++)
                out_x[i * nrhs + j] = X[j * n + i];
        if (out_residual_norms)
            memcpy(out_residual_norms, res, nrhs * sizeof *res);
    }
    free(buf);
    free(iwork);
    return st;
}
