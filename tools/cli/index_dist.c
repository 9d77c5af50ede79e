/* index_dist.c — the base distance of an index (index_dist.h): the library's fusion
 * (src/retrieval/fuse.c) repeated pair by pair, with the collection's medians. */
#include "index_dist.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

int base_uses_amscr(const base_dist *b)
{
    return b->w < 1.0;
}

int base_uses_channel(const base_dist *b)
{
    return b->w > 0.0;
}

/* The weights of the two distances, exactly as the library's fusion computes them. */
static void scales(const base_dist *b, double *sa, double *sh)
{
    *sa = b->med_a > 0.0 ? (1.0 - b->w) / b->med_a : 1.0 - b->w;
    *sh = b->med_h > 0.0 ? b->w / b->med_h : b->w;
}

amscr_status base_pair(const base_dist *b, const amscr_descriptor *lo, const amscr_descriptor *hi,
                       amscr_workspace *ws, double *out)
{
    double s = 0.0, h = 0.0;
    amscr_status st = AMSCR_OK;
    if (base_uses_amscr(b)) {
        double f = 0.0, r = 0.0;
        st = amscr_distance(b->p, lo, hi, ws, &f);
        if (st == AMSCR_OK)
            st = amscr_distance(b->p, hi, lo, ws, &r);
        s = 0.5 * (f + r);
    }
    if (st == AMSCR_OK && base_uses_channel(b))
        st = amscr_channel_distance(b->p, lo, hi, &h);
    if (st != AMSCR_OK)
        return st;
    *out = base_combine(b, s, h);
    return AMSCR_OK;
}

double base_combine(const base_dist *b, double sym, double ch)
{
    if (!base_uses_channel(b))
        return sym;
    if (!base_uses_amscr(b))
        return ch;
    double sa, sh;
    scales(b, &sa, &sh);
    return sa * sym + sh * ch;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of the off-diagonal entries of the n x n matrix m (n >= 2), as the library's. */
static int offdiag_median(const double *m, size_t n, double *out)
{
    size_t cnt = n * n - n, k = 0;
    double *v = xmalloc_array(cnt ? cnt : 1, sizeof *v);
    if (v == NULL)
        return -1;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            if (i != j)
                v[k++] = m[i * n + j];
    qsort(v, cnt, sizeof *v, cmp_double);
    *out = v[cnt / 2];
    free(v);
    return 0;
}

/* Symmetrizes the directional AMSCR matrix a in place, zero diagonal. */
static void symmetrize(double *a, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        a[i * n + i] = 0.0;
        for (size_t j = i + 1; j < n; j++)
            a[i * n + j] = a[j * n + i] = 0.5 * (a[i * n + j] + a[j * n + i]);
    }
}

int base_fuse(base_dist *b, double *a, double *h, size_t n, double **out)
{
    if (a == NULL) {
        *out = h;
        return 0;
    }
    symmetrize(a, n);
    *out = a;
    if (h == NULL || n < 2)
        return 0;
    if (offdiag_median(a, n, &b->med_a) != 0 || offdiag_median(h, n, &b->med_h) != 0)
        return -1;
    double sa, sh;
    scales(b, &sa, &sh);
    for (size_t i = 0; i < n * n; i++)
        a[i] = sa * a[i] + sh * h[i];
    return 0;
}

/* The AMSCR and channel matrices of db (as b needs) into *a, *h (malloc'ed or NULL). */
static amscr_status matrices(const amscr_db *db, const base_dist *b, double **a, double **h)
{
    size_t n = amscr_db_size(db);
    amscr_status st = AMSCR_OK;
    tool_progress pr;
    progress_init(&pr, "matching");
    *a = base_uses_amscr(b) ? xmalloc_array(n * n > 0 ? n * n : 1, sizeof(double)) : NULL;
    *h = base_uses_channel(b) ? xmalloc_array(n * n > 0 ? n * n : 1, sizeof(double)) : NULL;
    if ((base_uses_amscr(b) && *a == NULL) || (base_uses_channel(b) && *h == NULL))
        st = AMSCR_E_NOMEM;
    if (st == AMSCR_OK && *a)
        st = amscr_db_distance_matrix(db, progress_cb, &pr, *a);
    if (st == AMSCR_OK && *h)
        st = amscr_db_channel_matrix(db, progress_cb, &pr, *h);
    progress_end(&pr);
    return st;
}

int base_matrix(const amscr_db *db, base_dist *b, const char *what, double **out)
{
    size_t n = amscr_db_size(db);
    if (n != 0 && n > SIZE_MAX / n / sizeof(double)) {
        tool_error(what, "too many shapes for a matrix (%zu)", n);
        return -1;
    }
    double *a = NULL, *h = NULL;
    amscr_status st = matrices(db, b, &a, &h);
    if (st != AMSCR_OK) {
        tool_lib_error(what, st);
    } else if (base_fuse(b, a, h, n, out) != 0) {
        tool_error(what, "out of memory");
        st = AMSCR_E_NOMEM;
    }
    if (st != AMSCR_OK) {
        free(a);
        free(h);
        return -1;
    }
    if (*out != a)
        free(a);
    if (*out != h)
        free(h);
    return 0;
}

int base_medians_sampled(const amscr_db *db, base_dist *b, size_t sample)
{
    size_t n = amscr_db_size(db), m = n < sample ? n : sample;
    if (!base_uses_amscr(b) || !base_uses_channel(b) || m < 2)
        return 0;
    amscr_db *sub = NULL;
    amscr_status st = amscr_db_new(amscr_db_params(db), &sub);
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) /* evenly spread: shape t * n / m */
        st = amscr_db_add_descriptor(sub, amscr_db_descriptor(db, (size_t)((double)t * (double)n / (double)m)), -1,
                                     NULL);
    double *a = NULL, *h = NULL, *f = NULL;
    if (st == AMSCR_OK)
        st = matrices(sub, b, &a, &h);
    if (st == AMSCR_OK && base_fuse(b, a, h, m, &f) != 0)
        st = AMSCR_E_NOMEM;
    free(a);
    free(h);
    amscr_db_free(sub);
    if (st != AMSCR_OK) {
        tool_lib_error("index", st);
        return -1;
    }
    return 0;
}
