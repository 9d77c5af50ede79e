/* scores.h — the ranking primitives of scores.c shared with protocols.c (never installed).
 * Ranking is by distance ascending, ties broken by the lower index. */
#ifndef AMSCR_SCORES_H
#define AMSCR_SCORES_H

#include <stddef.h>

/* The k first indices of row d[0..n-1] in (distance, index) order, skipping `exclude`
 * (SIZE_MAX or >= n for none), written ascending to out[0..k-1]. k must not exceed the
 * number of candidates. O(n log k). */
void amscr__rank_select(const double *d, size_t n, size_t k, size_t exclude, size_t *out);

/* Index of the smallest of row[0..n-1] other than `exclude` (ties: lower index); SIZE_MAX
 * when there is no candidate. */
size_t amscr__rank_argmin(const double *row, size_t n, size_t exclude);

#endif
