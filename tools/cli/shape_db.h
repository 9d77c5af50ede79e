/* shape_db.h — the collection steps that search, matrix and eval share: a db of every shape
 * of a collection, and its retrieval distance matrix (as the db's params say). */
#ifndef AMSCR_TOOL_SHAPE_DB_H
#define AMSCR_TOOL_SHAPE_DB_H

#include "amscr.h"
#include "cli.h"
#include "collection.h"
#include "load_db.h"

/* Images of a collection and of a query are traced as `amscr register` traces them: the other
 * large pieces near the largest component (a thin part low resolution or damage broke off) are
 * joined to its outline (AMSCR_TRACE_JOIN; sub-pixel tracing only). Called by search, matrix,
 * eval and index before any image is read. */
void retrieval_tracing(void);
/* 1 when the params rank by the AMSCR distance alone (amscr_params_ranking: channel weight 0,
 * no re-ranking): the plain, directional matrix of 0.1 (amscr_db_distance_matrix), bit for bit. */
int retrieval_is_plain(const amscr_params *p);
/* The n x n retrieval matrix of db (malloc'ed): amscr_db_retrieval_matrix (shape channel,
 * fusion, re-ranking), or the plain matrix when retrieval_is_plain; on failure prints the
 * error naming `what` and returns -1. */
int compute_matrix(const amscr_db *db, const char *what, double **out);

/* The db of the COLLECTION argument: an index (its prepared shapes; params from the index,
 * the options the user set checked against it) or a folder / manifest (prepared with the
 * options). check (may be NULL) vets the collection before any shape is prepared. On
 * success the caller owns *p, *c and *db; returns 0 or an exit code (one error printed). */
int open_collection_db(const opts *o, const char *path, int (*check)(const opts *, const collection *),
                       amscr_params **p, collection *c, amscr_db **db);

#endif
