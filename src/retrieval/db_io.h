/* db_io.h — the collection file (db_io.c), shared by amscr_db_save/load and the index file,
 * which is a collection file of version 3 with an index section after its shapes, and the
 * collection's internals its load and the index use (db.c). Its versions and one shape's record:
 * db_record.h. Never installed. */
#ifndef AMSCR_DB_IO_H
#define AMSCR_DB_IO_H

#include "bytes.h"
#include "db_record.h"
#include "internal.h"

/* The trailing checksum of a file of `version` over its first n bytes. */
uint64_t amscr__db_checksum(uint32_t version, const unsigned char *p, size_t n);

/* Appends db.c's row (db_push) to a collection. */
amscr_status amscr__db_push(amscr_db *db, amscr_descriptor *d, int32_t label, size_t *out_index);
/* c prepared with p as a collection keeps it (amscr_descriptor_new without the input points). */
amscr_status amscr__db_prepare(const amscr_params *p, const amscr_contour *c, amscr_descriptor **out);
/* Room for `extra` more shapes, so that as many pushes cannot fail. */
amscr_status amscr__db_reserve(amscr_db *db, size_t extra);
/* A collection of n empty slots (no shapes, labels -1) with params p: the size of a graph that
 * holds lists without shapes (index_shard.c); never handed to a caller. */
amscr_status amscr__db_new_slots(const amscr_params *p, size_t n, amscr_db **out);
/* The slot of what one-vs-many retrieval keeps between queries of db (retrieval_query.c), locked;
 * amscr_db_free releases what it holds with free_fn. Unlock with amscr__db_kept_unlock. NULL (not
 * locked) when the calling thread holds the lock already: a query from the progress callback of
 * a query on the same collection. */
void **amscr__db_kept_lock(const amscr_db *db, void (*free_fn)(void *));
void amscr__db_kept_unlock(const amscr_db *db);

/* A lazy collection (db.c): its count shapes, at pos0 + i * per of src (which outlives it;
 * compact records when compact), are decoded when first asked for; amscr__db_decode_all
 * decodes every one (the batch calls' and a save's). */
void amscr__db_set_source(amscr_db *db, const unsigned char *src, size_t pos0, size_t per, int compact, size_t count);
/* A copy of db whose shapes are held as compact records (~3 KB a shape at the defaults, decoded
 * when first read), its labels and params db's. */
amscr_status amscr__db_compact_copy(const amscr_db *db, amscr_db **out);
/* Shape i of db into *out as the collection gives it (kept), or, when a lazy collection has not
 * decoded it yet, decoded into *tmp for the caller to free (the collection keeps nothing):
 * AMSCR_OK; AMSCR_E_NOMEM; AMSCR_E_FORMAT naming the shape when its record does not decode. */
amscr_status amscr__db_peek(const amscr_db *db, size_t i, const amscr_descriptor **out, amscr_descriptor **tmp);
/* How many of the shapes db decodes from its source are decoded and kept (the memory its reads
 * added: tests). */
size_t amscr__db_decoded(const amscr_db *db);
/* Shape i's compact record (amscr__db_shape_bytes of AMSCR__DB_VERSION_INDEX_COMPACT bytes) when
 * a lazy collection holds it as one, else NULL. */
const unsigned char *amscr__db_record(const amscr_db *db, size_t i);
/* Shape i's input samples (2N into input) and outline (2 AMSCR__OUTLINE_N into outline, when
 * its record has one) read from its compact record into a shallow descriptor sd (params, n, p,
 * input, outline; the rest NULL: for amscr__inner_vertices, nothing that reads the prepared
 * levels); 0 when shape i is not held as a compact record. */
int amscr__db_shallow(const amscr_db *db, size_t i, amscr_descriptor *sd, double *input, double *outline);
/* A collection made by amscr__db_compact_copy keeps the shapes added since as compact records
 * too (their decoded copies freed); nothing for any other (or when out of memory: they stay
 * decoded). Exclusive on db. */
amscr_status amscr__db_compact_tail(amscr_db *db);
/* A lazy collection of compact records read from a caller's buffer takes a copy of them (its
 * source then outlives the buffer); nothing for any other collection. */
amscr_status amscr__db_own_source(amscr_db *db);
amscr_status amscr__db_decode_all(const amscr_db *db);
/* Shape i of db into *out (amscr_db_descriptor, which decodes a lazy collection's shape when first
 * read, and keeps it): as amscr__db_peek, where amscr_db_descriptor gives NULL. */
amscr_status amscr__db_shape(const amscr_db *db, size_t i, const amscr_descriptor **out);
/* Shape i of src added to dst with `label` (amscr_db_add_descriptor of amscr__db_shape). */
amscr_status amscr__db_add_from(amscr_db *dst, const amscr_db *src, size_t i, int32_t label);

/* Writes the collection part of a file of `version`: magic, version, params, retrieval
 * settings, the shapes (no section, no checksum). AMSCR_OK (w->oom says whether memory ran
 * out), or amscr__db_peek's failure for a lazy collection's shape. */
amscr_status amscr__db_write(const amscr_db *db, uint32_t version, amscr__wbuf *w);
/* Checks the magic, version and trailing checksum of buf and parses its collection part:
 * *out (caller frees) and *out_pos just after the shapes, *out_version. lazy: the shapes are
 * checked but not decoded; *out decodes them from buf (which must outlive it) when asked for. */
amscr_status amscr__db_parse(const unsigned char *buf, size_t len, int lazy, amscr_db **out, size_t *out_pos,
                             uint32_t *out_version);

#endif
