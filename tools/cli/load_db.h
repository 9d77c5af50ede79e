/* load_db.h — a collection's shapes loaded into a db: decoded, traced and prepared on the
 * params' threads (load_db.c). Part of the tool's shape input library (amscr_shapeio: image.h,
 * collection.h, util.h, load_db.h), which the benchmarks link too. */
#ifndef AMSCR_TOOL_LOAD_DB_H
#define AMSCR_TOOL_LOAD_DB_H

#include "amscr.h"
#include "collection.h"

/* Loads every shape of collection c into a new db (params p), decoding, tracing (shape_load at
 * `threshold`) and preparing on the params' threads; the db is the one a loop over the shapes
 * builds. On failure prints the error naming the first bad file in order and returns -1. */
int load_db(const amscr_params *p, const collection *c, int threshold, amscr_db **out);

#endif
