/* retrieval.h — the collection steps that search, matrix and eval share: a db of every shape
 * of a collection, and its distance matrix (re-ranked as the options say). */
#ifndef AMSCR_TOOL_RETRIEVAL_H
#define AMSCR_TOOL_RETRIEVAL_H

#include "amscr.h"
#include "cli.h"
#include "collection.h"

/* Loads every shape of collection c into a new db (params p); on failure prints the error
 * naming the file and returns -1. */
int load_db(const amscr_params *p, const collection *c, int threshold, amscr_db **out);
/* The n x n distance matrix of db (malloc'ed), re-ranked when o->rerank_k > 0; on failure
 * prints the error naming `what` and returns -1. */
int compute_matrix(const amscr_db *db, const char *what, const opts *o, double **out);

/* The db of the COLLECTION argument: an index (its prepared shapes; params from the index,
 * the options the user set checked against it) or a folder / manifest (prepared with the
 * options). check (may be NULL) vets the collection before any shape is prepared. On
 * success the caller owns *p, *c and *db; returns 0 or an exit code (one error printed). */
int open_collection_db(const opts *o, const char *path, int (*check)(const opts *, const collection *),
                       amscr_params **p, collection *c, amscr_db **db);

#endif
