/* rank.c — the one ranking order (rank.h): the k first of a row by (distance, index) with a
 * bounded max-heap, the nearest of a row, and the neighbour lists built and kept in that
 * order. +inf ranks last; NaN is refused by the public callers. */
#include "rank.h"

#include <stdlib.h>

/* Entry a before entry b: (d[a], index of a) < (d[b], index of b) lexicographically. */
static inline int before(const double *d, const size_t *id, size_t a, size_t b)
{
    return d[a] < d[b] || (d[a] == d[b] && (id ? id[a] < id[b] : a < b));
}

/* Max-heap (by `before`) sift-down of heap[0..len-1] from position i. */
static void sift_down(const double *d, const size_t *id, size_t *heap, size_t len, size_t i)
{
    size_t v = heap[i];
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= len)
            break;
        if (c + 1 < len && before(d, id, heap[c], heap[c + 1]))
            c++;
        if (!before(d, id, v, heap[c]))
            break;
        heap[i] = heap[c];
        i = c;
    }
    heap[i] = v;
}

size_t amscr__rank_select(const double *d, const size_t *id, size_t n, size_t k, size_t exclude, size_t *out)
{
    if (k == 0)
        return 0;
    size_t len = 0;
    for (size_t i = 0; i < n; i++) {
        if ((id ? id[i] : i) == exclude)
            continue;
        if (len < k) {
            /* sift up */
            size_t j = len++;
            while (j > 0) {
                size_t p = (j - 1) / 2;
                if (!before(d, id, out[p], i))
                    break;
                out[j] = out[p];
                j = p;
            }
            out[j] = i;
        } else if (before(d, id, i, out[0])) {
            out[0] = i;
            sift_down(d, id, out, len, 0);
        }
    }
    /* Heap sort in place: ascending. */
    for (size_t end = len; end > 1; end--) {
        size_t t = out[0];
        out[0] = out[end - 1];
        out[end - 1] = t;
        sift_down(d, id, out, end - 1, 0);
    }
    return len;
}

size_t amscr__rank_argmin(const double *row, size_t n, size_t exclude)
{
    size_t best = SIZE_MAX;
    for (size_t j = 0; j < n; j++) {
        if (j == exclude)
            continue;
        if (best == SIZE_MAX || row[j] < row[best])
            best = j;
    }
    return best;
}

amscr_status amscr__knn_select(size_t i, const size_t *cj, const double *cd, size_t m, size_t k, uint32_t *out_idx,
                               double *out_dist)
{
    if (k == 0)
        return AMSCR_OK;
    size_t *pos = amscr__malloc_array(k > 1 ? k - 1 : 1, sizeof *pos);
    if (!pos)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    size_t take = amscr__rank_select(cd, cj, m, k - 1, i, pos);
    out_idx[0] = (uint32_t)i; /* itself first, as amscr_rerank_diffusion */
    out_dist[0] = 0.0;
    for (size_t t = 1; t < k; t++) {
        size_t p = take ? pos[t - 1 < take ? t - 1 : take - 1] : 0;
        out_idx[t] = take ? (uint32_t)cj[p] : (uint32_t)i;
        out_dist[t] = take ? cd[p] : -1.0;
    }
    free(pos);
    return AMSCR_OK;
}

void amscr__knn_enter(uint32_t *idx, double *dist, size_t k, size_t j, double d)
{
    if (k < 2 || !(d < dist[k - 1]))
        return;
    size_t t = k - 1;
    while (t > 1 && dist[t - 1] > d) {
        idx[t] = idx[t - 1];
        dist[t] = dist[t - 1];
        t--;
    }
    idx[t] = (uint32_t)j;
    dist[t] = d;
}
