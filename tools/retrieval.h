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

#endif
