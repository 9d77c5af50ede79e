/* index_reverse.c — what an index precomputes from its neighbour lists for its queries: the
 * lists' reverse (the rows that hold each shape, which a diffusion product visits) and every
 * stored row's affinities in the graph of a query that enters no row (index_graph.c). */
#include "index_graph.h"

#include <stdlib.h>
#include <string.h>

void amscr__index_reverse_lists(const amscr_index *x, size_t n, size_t *rs, uint32_t *rv)
{
    size_t k = x->k, k2 = x->k2;
    memset(rs, 0, (n + 1) * sizeof *rs);
    for (size_t e = 0; e < n * k; e++)
        rs[x->nb_idx[e] + 1]++;
    for (size_t e = 0; e < n * k2; e++)
        rs[x->in_idx[e] + 1]++;
    for (size_t j = 0; j < n; j++)
        rs[j + 1] += rs[j];
    for (size_t i = 0; i < n; i++) { /* rs[j] runs ahead while filling, then shifts back */
        for (size_t t = 0; t < k; t++)
            rv[rs[x->nb_idx[i * k + t]]++] = (uint32_t)i;
        for (size_t t = 0; t < k2; t++)
            rv[rs[x->in_idx[i * k2 + t]]++] = (uint32_t)i;
    }
    for (size_t j = n; j > 0; j--)
        rs[j] = rs[j - 1];
    rs[0] = 0;
}

amscr_status amscr__index_reverse(amscr_index *x)
{
    size_t n = amscr_db_size(x->db);
    amscr__index_reverse_free(x);
    if (x->k == 0)
        return AMSCR_OK;
    x->rev_start = amscr__malloc_array(n + 1, sizeof *x->rev_start);
    x->rev = amscr__malloc_array(n ? n : 1, (x->k + x->k2) * sizeof *x->rev);
    if (!x->rev_start || !x->rev) {
        amscr__index_reverse_free(x);
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    }
    amscr__index_reverse_lists(x, n, x->rev_start, x->rev);
    amscr_status st = n > 0 && x->k <= n ? amscr__graph_fixed_weights(x) : AMSCR_OK;
    if (st != AMSCR_OK)
        amscr__index_reverse_free(x);
    return st;
}
