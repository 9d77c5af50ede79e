/* The retrieval area (src/retrieval/): collections and what ranks their shapes (docs/method.md
 * §4, §10), from the bottom up: a file calls only files listed above it, except db.c and
 * db_io.c (the collection and its file format), which call each other.
 *   rank.c          the one ranking order, (distance, index), and the neighbour lists kept in it
 *   rows.c          a collection's rows on threads
 *   bytes.c, retrieval_io.c  little-endian readers and writers; the retrieval settings block
 *   inner.c         the inner distance of one pair
 *   channel.c, channel_dp.c  the shape channel (height functions) of one pair
 *   db.c, db_io.c   the collection object (amscr_db): prepared shapes with labels, distance
 *                   matrices on threads, progress and cancellation; its versioned binary format;
 *                   db_batch.c many shapes at once
 *   hf_matrix.c, inner_matrix.c  the channel and the inner distance over a whole collection
 *   rerank.c        contextual re-ranking of a matrix by affinity diffusion
 *   fuse.c          the fused, re-ranked retrieval matrix
 *   scores.c        retrieval scores (this file); protocols.c the evaluation protocols
 *   affine_signature.c, signature.c  the shortlist signature and its search
 *   index.c         the index object (amscr_index) and the rules its files share
 *   index_pairs.c   the base distance pair by pair
 *   index_graph.c, index_reverse.c, index_diffuse.c  one row's re-ranked scores from the
 *                   neighbour lists (the graph, the lists' reverse, the diffusion)
 *   index_features.c  each shape's kept features
 *   index_refine.c, index_inner.c, index_build.c, index_add.c  the neighbour lists (rows on threads)
 *   index_query.c   one query against an index; index_io.c the index's file section
 *   retrieval_query.c  one query against a collection that keeps no index
 *
 * scores.c — retrieval scores on a distance matrix (docs/method.md §4): top-k selection,
 * bull's eye, the Kimia top-k table and 1-NN accuracies. Ranking is by distance
 * ascending, ties broken by the lower index (rank.c); +inf is allowed, NaN is rejected.
 * Cost: O(n^2 log w) for the matrix scores (w the window or kmax), with one allocation
 * per call. */
#include "internal.h"
#include "rank.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* 1 when any of the n values is NaN. */
static int rt_has_nan(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (isnan(v[i]))
            return 1;
    return 0;
}

/* Checks an r x c matrix size and its values. */
static amscr_status rt_check_matrix(const char *fn, const double *dist, size_t r, size_t c)
{
    if (c != 0 && r > SIZE_MAX / sizeof(double) / c)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: matrix %zu x %zu too large", fn, r, c);
    if (rt_has_nan(dist, r * c))
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: NaN distance", fn);
    return AMSCR_OK;
}

amscr_status amscr_topk(const double *dist, size_t n, size_t k, size_t exclude, size_t *out_indices)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(out_indices);
    if (exclude != SIZE_MAX && exclude >= n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_topk: exclude %zu out of range (n = %zu)", exclude, n);
    size_t avail = n - (exclude != SIZE_MAX ? 1 : 0);
    if (k > avail)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_topk: k = %zu > %zu candidates", k, avail);
    if (rt_has_nan(dist, n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_topk: NaN distance");
    amscr__rank_select(dist, NULL, n, k, exclude, out_indices);
    return AMSCR_OK;
}

/* A (label, index) pair for sorting by label. */
typedef struct {
    int32_t label;
    size_t index;
} rt_pair;

static int rt_cmp_pair(const void *a, const void *b)
{
    const rt_pair *x = a, *y = b;
    if (x->label != y->label)
        return x->label < y->label ? -1 : 1;
    return (x->index > y->index) - (x->index < y->index);
}

/* Class size of every item: counts[i] = number of j with labels[j] == labels[i].
 * Uses a sorted copy of (label, index) pairs. Returns 0 on allocation failure. */
static int rt_class_sizes(const int32_t *labels, size_t n, size_t *counts)
{
    rt_pair *p = amscr__malloc_array(n, sizeof *p);
    if (!p)
        return 0;
    for (size_t i = 0; i < n; i++) {
        p[i].label = labels[i];
        p[i].index = i;
    }
    qsort(p, n, sizeof *p, rt_cmp_pair);
    for (size_t a = 0; a < n;) {
        size_t b = a + 1;
        while (b < n && p[b].label == p[a].label)
            b++;
        for (size_t i = a; i < b; i++)
            counts[p[i].index] = b - a;
        a = b;
    }
    free(p);
    return 1;
}

amscr_status amscr_score_bullseye(const double *dist, size_t n, const int32_t *labels, size_t window,
                                  double *out_score)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(out_score);
    if (n == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_bullseye: n = 0");
    amscr_status st = rt_check_matrix("amscr_score_bullseye", dist, n, n);
    if (st != AMSCR_OK)
        return st;
    size_t *counts = amscr__malloc_array(n, sizeof *counts);
    size_t *idx = amscr__malloc_array(n, sizeof *idx);
    if (!counts || !idx || !rt_class_sizes(labels, n, counts)) {
        free(counts);
        free(idx);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_score_bullseye: out of memory (n = %zu)", n);
    }
    double hits = 0.0, denom = 0.0;
    for (size_t i = 0; i < n; i++) {
        size_t w = window ? window : 2 * counts[i];
        if (w > n)
            w = n;
        amscr__rank_select(dist + i * n, NULL, n, w, SIZE_MAX, idx);
        size_t h = 0;
        for (size_t r = 0; r < w; r++)
            h += labels[idx[r]] == labels[i];
        hits += (double)h;
        denom += (double)counts[i];
    }
    free(counts);
    free(idx);
    *out_score = hits / denom;
    return AMSCR_OK;
}

amscr_status amscr_score_topk_table(const double *dist, size_t n, const int32_t *labels, size_t kmax,
                                    size_t *out_counts)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(out_counts);
    if (n < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_topk_table: n = %zu < 2", n);
    if (kmax < 1 || kmax > n - 1)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_topk_table: kmax = %zu not in 1..%zu", kmax, n - 1);
    amscr_status st = rt_check_matrix("amscr_score_topk_table", dist, n, n);
    if (st != AMSCR_OK)
        return st;
    size_t *idx = amscr__malloc_array(kmax, sizeof *idx);
    size_t *counts = amscr__calloc_array(kmax, sizeof *counts);
    if (!idx || !counts) {
        free(idx);
        free(counts);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_score_topk_table: out of memory");
    }
    for (size_t i = 0; i < n; i++) {
        amscr__rank_select(dist + i * n, NULL, n, kmax, i, idx);
        for (size_t r = 0; r < kmax; r++)
            counts[r] += labels[idx[r]] == labels[i];
    }
    memcpy(out_counts, counts, kmax * sizeof *counts);
    free(idx);
    free(counts);
    return AMSCR_OK;
}

amscr_status amscr_score_nn_accuracy(const double *dist, size_t n, const int32_t *labels, double *out_accuracy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(out_accuracy);
    if (n < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_nn_accuracy: n = %zu < 2", n);
    amscr_status st = rt_check_matrix("amscr_score_nn_accuracy", dist, n, n);
    if (st != AMSCR_OK)
        return st;
    size_t correct = 0;
    for (size_t i = 0; i < n; i++)
        correct += labels[amscr__rank_argmin(dist + i * n, n, i)] == labels[i];
    *out_accuracy = (double)correct / (double)n;
    return AMSCR_OK;
}

amscr_status amscr_score_nn_split(const double *dist, size_t ntest, size_t ntrain, const int32_t *test_labels,
                                  const int32_t *train_labels, double *out_accuracy)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(test_labels);
    AMSCR_CHECK_NULL(train_labels);
    AMSCR_CHECK_NULL(out_accuracy);
    if (ntest == 0 || ntrain == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_nn_split: empty set (ntest = %zu, ntrain = %zu)", ntest,
                           ntrain);
    amscr_status st = rt_check_matrix("amscr_score_nn_split", dist, ntest, ntrain);
    if (st != AMSCR_OK)
        return st;
    size_t correct = 0;
    for (size_t i = 0; i < ntest; i++)
        correct += train_labels[amscr__rank_argmin(dist + i * ntrain, ntrain, SIZE_MAX)] == test_labels[i];
    *out_accuracy = (double)correct / (double)ntest;
    return AMSCR_OK;
}
