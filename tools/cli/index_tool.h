/* index_tool.h — the tool's face of the library's retrieval index (amscr_index, one file
 * format: a collection file with an index section): opening an index where a collection is
 * accepted, its names as a collection, the options the user set checked against the index's
 * params, and the manifest bookkeeping of `index` and `index --add`. The retrieval itself is
 * the library's (amscr_index_build/add/query). Tool-internal. */
#ifndef AMSCR_TOOL_INDEX_TOOL_H
#define AMSCR_TOOL_INDEX_TOOL_H

#include "amscr.h"
#include "cli.h"
#include "collection.h"

/* Non-zero when the file at path is an amscr binary file (an index, a collection file, or an
 * index of the tool before 0.4), not a folder or a manifest. */
int index_file_is(const char *path);
/* Reads an index file (lazy != 0: AMSCR_INDEX_LAZY, for a command that queries it once or
 * only reads its collection); 0, or -1 after printing one error line (the library's: a
 * collection file without an index or an old tool index says to rebuild it). */
int index_open(const char *path, int lazy, amscr_index **out);
/* The index's file names, classes and groups as a collection (item paths are the names). The
 * classes are the index's distinct labels in ascending order, as the collection's labels
 * 0..k-1 (an index from Python may label its shapes 1..4 or 10, 20, ...), each named by the
 * index's class name or the label's number. */
int index_collection(const amscr_index *x, collection *out);
/* The number of distinct labels of the index (0 when out of memory, printed). */
size_t index_num_classes(const amscr_index *x);
/* Stores the file names and groups of collection c into shapes from..from+c->n-1 of the
 * index. 0 or -1 (error printed). */
int index_store_names(amscr_index *x, const collection *c, size_t from);
/* The params of an index with the options the user set: the same as the index's or a clear
 * error naming the option (threads and --rerank/--no-rerank may differ). 0 or an exit code. */
int index_params(const opts *o, const char *path, const amscr_params *built, amscr_params **out);
/* The index's shapes in a new db with params p (the user's threads and re-ranking); 0 or -1
 * (error printed naming path). */
int index_db_with_params(const amscr_index *x, const amscr_params *p, const char *path, amscr_db **out);
/* `index --add`: appends the shapes of collection c to the index (saved by the caller). */
int index_add(const opts *o, amscr_index *x, collection *c);

#endif
