/* heldout.c — the retrieval matrix of a collection with each group held out in turn
 * (amscr_db_retrieval_matrix_heldout): the pair distances once, then per group the fusion's
 * medians and the re-ranking's graph of the other groups alone, the group's shapes scored as
 * new queries against them. */
#include "channel.h"
#include "inner.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median (the fusion's: entry m / 2 of the sorted m values) of M's off-diagonal entries
 * between shapes not held out (v: scratch of n * n). */
static double held_median(const double *M, size_t n, const unsigned char *held, double *v)
{
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; !held[i] && j < n; j++)
            if (i != j && !held[j])
                v[m++] = M[i * n + j];
    if (m == 0)
        return 0.0;
    qsort(v, m, sizeof *v, cmp_double);
    return v[m / 2];
}

/* The matrices every group reuses: A the symmetrized AMSCR distance (NULL: channel alone), H the
 * channel (NULL: none), I the inner distance (NULL: no inner graph). */
typedef struct {
    double *A, *H, *I, *B, *R, *v;
    unsigned char *held;
} ho_bufs;

static void ho_free(ho_bufs *b)
{
    free(b->A);
    free(b->H);
    free(b->I);
    free(b->B);
    free(b->R);
    free(b->v);
    free(b->held);
}

static amscr_status ho_pairs(const amscr_db *db, amscr_progress_fn progress, void *user, ho_bufs *b)
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    double w = p->channel_weight;
    int with_a = w < 1.0, with_h = w > 0.0, with_i = p->rerank_k > 0 && p->rerank_inner_share > 0.0;
    if (with_h && !p->closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_db_retrieval_matrix_heldout: the shape channel needs closed "
                                                "curves; set the channel weight to 0 for open ones");
    b->A = with_a ? amscr__malloc_array(n * n, sizeof *b->A) : NULL;
    b->H = with_h ? amscr__malloc_array(n * n, sizeof *b->H) : NULL;
    b->I = with_i ? amscr__malloc_array(n * n, sizeof *b->I) : NULL;
    b->B = amscr__malloc_array(n * n, sizeof *b->B);
    b->R = amscr__malloc_array(n * n, sizeof *b->R);
    b->v = with_a && with_h ? amscr__malloc_array(n * n, sizeof *b->v) : NULL;
    b->held = amscr__calloc_array(n, 1);
    if ((with_a && !b->A) || (with_h && !b->H) || (with_i && !b->I) || !b->B || !b->R || (with_a && with_h && !b->v) ||
        !b->held)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_retrieval_matrix_heldout: out of memory (n = %zu)", n);
    amscr__stages sp = {progress, user, 0, (size_t)with_a + (size_t)with_h};
    amscr_status st = AMSCR_OK;
    if (with_a) {
        st = amscr_db_distance_matrix(db, progress ? amscr__stage_cb : NULL, &sp, b->A);
        sp.stage++;
        for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
            b->A[i * n + i] = 0.0;
            for (size_t j = i + 1; j < n; j++)
                b->A[i * n + j] = b->A[j * n + i] = 0.5 * (b->A[i * n + j] + b->A[j * n + i]);
        }
    }
    if (st == AMSCR_OK && with_h)
        st = amscr_db_channel_matrix(db, progress ? amscr__stage_cb : NULL, &sp, b->H);
    if (st == AMSCR_OK && with_i)
        st = amscr__inner_matrix(db, amscr__resolve_threads(p->num_threads), NULL, NULL, b->I);
    return st;
}

/* Group g held out: B the fused distance with the others' medians, re-ranked on the others'
 * graph into R; g's rows of R into out, its own group's entries +infinity (diagonal 0). */
static amscr_status ho_group(const amscr_db *db, const int32_t *groups, int32_t g, ho_bufs *b, double *out)
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db), m = 0;
    for (size_t i = 0; i < n; i++) {
        b->held[i] = groups[i] == g;
        m += !b->held[i];
    }
    double w = p->channel_weight;
    if (b->A && b->H) {
        double sa, sh;
        amscr__fuse_scales(w, held_median(b->A, n, b->held, b->v), held_median(b->H, n, b->held, b->v), &sa, &sh);
        for (size_t i = 0; i < n * n; i++)
            b->B[i] = sa * b->A[i] + sh * b->H[i];
    } else
        memcpy(b->B, b->A ? b->A : b->H, n * n * sizeof *b->B);
    amscr_status st = AMSCR_OK;
    const double *R = b->B;
    if (p->rerank_k > 0) {
        const double *d[2] = {b->B, b->I};
        double share[2] = {0.0, p->rerank_inner_share};
        size_t k = amscr__rerank_k(p, m + 1); /* the others plus one query, as a new query sees them */
        st = amscr__rerank_held(d, share, b->I ? 2 : 1, n, k, p->rerank_iterations,
                                amscr__resolve_threads(p->num_threads), b->held, b->R);
        R = b->R;
    }
    for (size_t i = 0; st == AMSCR_OK && i < n; i++)
        if (b->held[i])
            for (size_t j = 0; j < n; j++)
                out[i * n + j] = i == j ? 0.0 : b->held[j] ? INFINITY : R[i * n + j];
    return st;
}

/* amscr_db_retrieval_matrix_heldout once its arguments are checked. */
static amscr_status heldout(const amscr_db *db, const int32_t *groups, size_t n, amscr_progress_fn progress,
                            void *user, double *out_dist)
{
    static const char fn[] = "amscr_db_retrieval_matrix_heldout";
    size_t distinct = 0;
    for (size_t i = 0; i < n && distinct < 2; i++)
        distinct = groups[i] != groups[0] ? 2 : 1;
    if (distinct < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: needs at least 2 groups", fn);
    if (n > 65536)
        return amscr__fail(AMSCR_E_LIMIT, "%s: n = %zu exceeds 65536", fn, n);
    ho_bufs b;
    memset(&b, 0, sizeof b);
    amscr_status st = ho_pairs(db, progress, user, &b);
    unsigned char *done = st == AMSCR_OK ? amscr__calloc_array(n, 1) : NULL;
    if (st == AMSCR_OK && !done)
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", fn);
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        if (done[i])
            continue;
        st = ho_group(db, groups, groups[i], &b, out_dist);
        for (size_t j = i; j < n; j++)
            done[j] |= groups[j] == groups[i];
    }
    free(done);
    ho_free(&b);
    return st;
}

amscr_status amscr_db_retrieval_matrix_heldout(const amscr_db *db, const int32_t *groups, size_t n,
                                               amscr_progress_fn progress, void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(groups);
    AMSCR_CHECK_NULL(out_dist);
    if (n != amscr_db_size(db)) /* the output's size is not known: nothing set */
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_db_retrieval_matrix_heldout: %zu groups for %zu shapes", n,
                           amscr_db_size(db));
    return amscr__nan_on_failure(heldout(db, groups, n, progress, user, out_dist), out_dist, n, n);
}
