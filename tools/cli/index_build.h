/* index_build.h — `amscr index COLLECTION -o FILE [--add]`, and opening a collection that
 * may be an index for search, matrix and eval. Tool-internal. */
#ifndef AMSCR_TOOL_INDEX_BUILD_H
#define AMSCR_TOOL_INDEX_BUILD_H

#include <stddef.h>
#include <stdint.h>

#include "cli.h"
#include "index_dist.h"
#include "index_file.h"

/* Shapes on which a candidate-only build estimates the medians of a fused distance. */
enum { INDEX_MEDIAN_SAMPLE = 256 };

/* Row i's k nearest neighbours (itself first, then by distance, ties by index) among m
 * candidates (cj[t], cd[t] its symmetrized distance; i itself may be among them). */
void knn_select(size_t i, const size_t *cj, const double *cd, size_t m, size_t k, uint32_t *out_idx,
                double *out_dist);

/* Signatures of the index's shapes from..n-1 (the db's order). 0 or -1. */
int index_signatures_from(tool_index *x, size_t from);
/* --add: appends the collection c to the loaded index x (cmd_index.c writes it). */
int index_add(const opts *o, tool_index *x, collection *c);

/* The neighbour lists (x->k a shape) and x->dmax from each shape's m signature-nearest
 * shapes under the base distance b, on the threads of b->p (index_knn.c). 0 or -1 (error
 * printed). */
int knn_from_candidates(tool_index *x, const base_dist *b, size_t m);

/* Opens the COLLECTION argument: an index (its db and names; params from the index, options
 * the user set checked against it) or a folder / manifest (prepared with make_params).
 * *x is zeroed for a folder. Returns 0, or an exit code after printing one error line. */
int open_shapes(const opts *o, const char *path, tool_index *x, int *is_index);

/* The params of an index with the options the user set: the same as the index's or a clear
 * error (threads may differ). Returns 0 or an exit code. */
int index_params(const opts *o, const char *path, const tool_index *x, amscr_params **out);

#endif
