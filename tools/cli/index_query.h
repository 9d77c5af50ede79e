/* index_query.h — one query against an index (see index_query.c). Tool-internal. */
#ifndef AMSCR_TOOL_INDEX_QUERY_H
#define AMSCR_TOOL_INDEX_QUERY_H

#include <stddef.h>

#include "amscr.h"
#include "index_dist.h"
#include "index_file.h"

/* out[j] (n entries) = the query's score against shape j, as a folder search computes it
 * with the params p (the index's, with the user's --rerank): without re-ranking the plain
 * d(q -> j) (channel weight 0) or the base distance (index_dist.h); with it the query's row of
 * the retrieval matrix's diffusion (K = the params' rerank_k, their iterations; in [0, 1], 0
 * for the query itself), computed from the stored neighbour lists. Only `ncand` candidates
 * are matched (the shapes whose signatures are nearest; 0 or >= n: every shape); shapes
 * neither matched nor reached by the diffusion get +inf. The index must hold at least
 * min(rerank_k, n) neighbours a shape (the caller checks). Returns 0, or -1 after printing
 * one error line. */
int index_search(const tool_index *x, const amscr_params *p, const amscr_descriptor *dq, size_t ncand, double *out);

/* The re-ranked row of the query (halved, as the retrieval matrix) from the neighbour lists
 * and the base distances to the m candidates (ascending indices cand[], at least k - 1 of them). */
int rerank_query_row(const tool_index *x, size_t k, unsigned iters, const size_t *cand, const double *dsym, size_t m,
                     double *out);

#endif
