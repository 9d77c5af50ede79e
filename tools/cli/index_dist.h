/* index_dist.h — the base distance of an index: what the retrieval matrix re-ranks (the
 * library's amscr_db_retrieval_matrix before its diffusion), pair by pair, so the neighbour
 * lists of an index and the distances of one query agree with the folder's matrix.
 *   channel weight 1: the shape channel (amscr_channel_distance, lower index first, as
 *                     amscr_db_channel_matrix fills both cells from d(i, j), i < j);
 *   channel weight 0: the symmetrized AMSCR distance (d(i -> j) + d(j -> i)) / 2;
 *   otherwise:        (1 - w) sym / median(sym) + w channel / median(channel), the medians
 *                     being the collection's off-diagonal ones at build time (stored in the
 *                     index; with --candidates they are estimated on a sample, see
 *                     index_dist_medians). Tool-internal. */
#ifndef AMSCR_TOOL_INDEX_DIST_H
#define AMSCR_TOOL_INDEX_DIST_H

#include <stddef.h>

#include "amscr.h"

typedef struct base_dist {
    const amscr_params *p;
    double w;        /* channel weight */
    double med_a;    /* median of the symmetrized AMSCR distance (0 < w < 1 only) */
    double med_h;    /* median of the channel distance (0 < w < 1 only) */
} base_dist;

/* 1 when the base distance needs the AMSCR distance / the shape channel. */
int base_uses_amscr(const base_dist *b);
int base_uses_channel(const base_dist *b);

/* The base distance from the symmetrized AMSCR distance sym and the channel distance ch
 * (each ignored when unused). */
double base_combine(const base_dist *b, double sym, double ch);

/* The base distance of shapes lo and hi (lo the lower index of the collection, the query
 * counting as the last one); ws for the AMSCR distance (may be NULL). */
amscr_status base_pair(const base_dist *b, const amscr_descriptor *lo, const amscr_descriptor *hi,
                       amscr_workspace *ws, double *out);

/* The n x n base matrix of db from its AMSCR matrix a (directional; NULL when unused) and its
 * channel matrix h (NULL when unused), into a (or h when a is NULL: the result is returned in
 * *out, pointing at one of them); computes b->med_a, b->med_h when 0 < w < 1. Bit for bit
 * the library's fusion. 0, or -1 (out of memory). */
int base_fuse(base_dist *b, double *a, double *h, size_t n, double **out);

/* The n x n base matrix of db (malloc'ed), with b->med_* set; 0 or -1 (error printed). */
int base_matrix(const amscr_db *db, base_dist *b, const char *what, double **out);

/* b->med_a and b->med_h estimated on at most `sample` shapes of db spread evenly (the
 * candidate-only build of a large index: no full matrix). 0 or -1 (error printed). */
int base_medians_sampled(const amscr_db *db, base_dist *b, size_t sample);

#endif
