/* rank.h — the one ranking order of the retrieval area (rank.c): by distance ascending, ties
 * broken by the lower index. The scores, the protocols, the re-ranking's kNN graph and an
 * index's neighbour lists all select through it. Never installed. */
#ifndef AMSCR_RANK_H
#define AMSCR_RANK_H

#include "internal.h"

/* The positions of the k first of d[0..n-1] in (distance, index) order, written ascending to
 * out[0..k-1] (all of them when fewer are left); returns how many. An entry's index is id[t]
 * (NULL: its position t); entries whose index is `exclude` (SIZE_MAX for none) are skipped.
 * O(n log k). */
size_t amscr__rank_select(const double *d, const size_t *id, size_t n, size_t k, size_t exclude, size_t *out);

/* Index of the smallest of row[0..n-1] other than `exclude` (ties: lower index); SIZE_MAX
 * when there is no candidate. */
size_t amscr__rank_argmin(const double *row, size_t n, size_t exclude);

/* Row i's neighbour list of k entries: itself first (distance 0), then its k - 1 nearest among
 * the m candidates cj[t] at distances cd[t] (i itself skipped) in (distance, index) order.
 * With fewer candidates the last entry repeats (itself at distance -1 when there is none). */
amscr_status amscr__knn_select(size_t i, const size_t *cj, const double *cd, size_t m, size_t k, uint32_t *out_idx,
                               double *out_dist);

/* Shape j, at distance d and of an index above every listed one, into a neighbour list (idx,
 * dist: k entries, itself first) when nearer than its last entry (ties: j stays behind). */
void amscr__knn_enter(uint32_t *idx, double *dist, size_t k, size_t j, double d);

#endif
