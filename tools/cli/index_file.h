/* index_file.h — the index of `amscr index`: a prepared collection with its file names,
 * classes and groups, the shape options it was built with (the db's params), a shape
 * signature per shape (the candidate filter of large collections) and each shape's K nearest
 * neighbours under the base distance of the retrieval matrix (index_dist.h: the shape channel
 * with the default channel weight 1, the fused distance below it; what contextual re-ranking
 * needs, so one query never recomputes the collection's matrix). The params (the library's
 * collection format 2) hold the channel and re-ranking settings the index was built with.
 *
 * File format, little-endian, version 2 (version 1, before the shape channel, is refused):
 *   "AMSCRIDX" u32 version u32 0 u64 file length
 *   u64 meta length, the meta section, u64 FNV-1a 64 of the meta section
 *   the shapes: n blobs, each a one-shape amscr_db_save_memory (checksummed by the library)
 * Meta section:
 *   u64 n, i32 threshold, u32 0, u64 k, f64 dmax, f64 median AMSCR, f64 median channel
 *   u64 len, the params (amscr_db_save_memory of an empty db)
 *   u64 nclasses, nclasses strings; u64 ngroups, ngroups strings   (string: u32 len, bytes)
 *   n x (string name, i32 class, i32 group or -1, u64 blob offset, u64 blob length)
 *   u32 sig_dim, n x sig_dim f64 signatures
 *   n x k x (u32 neighbour, f64 distance)        (each row: itself first, then by distance)
 * A search reads the meta section and only the shapes it matches (a 10,000-shape index is
 * ~200 MB); matrix, eval and --add read every shape. A damaged shape is an error when it is
 * read; a truncated file always (its length is in the header). Written to a temporary name
 * and renamed. Tool-internal. */
#ifndef AMSCR_TOOL_INDEX_FILE_H
#define AMSCR_TOOL_INDEX_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"
#include "collection.h"

enum { INDEX_VERSION = 2, INDEX_SIG_DIM = 24 };

typedef struct tool_index {
    amscr_db *db;            /* every shape, or (index_open_lazy) none: the params only */
    collection coll;         /* names, classes, groups (item paths are the names) */
    int threshold;           /* used to trace the collection's images */
    size_t k;                /* neighbours per shape: min(the params' rerank_k, n) */
    double dmax;             /* largest base distance of the collection (index_dist.h) */
    double med_a, med_h;     /* the base distance's medians (fused channel weights only, else 0) */
    double *sig;             /* n x INDEX_SIG_DIM */
    uint32_t *nb_idx;        /* n x k */
    double *nb_dist;         /* n x k */
    uint64_t *blob_off, *blob_len; /* n each: the shapes' blobs, from the start of the blobs */
    const unsigned char *mem; /* index_parse: the buffer (blobs read from it) */
    void *fp;                /* index_open_lazy: the open file (blobs read on demand) */
    uint64_t blobs_at;       /* offset of the first blob in the buffer or file */
} tool_index;

/* Non-zero when the file at path starts with the index magic. */
int index_file_is(const char *path);
/* Serializes into a malloc'ed buffer; 0 or -1 (out of memory printed). */
int index_serialize(const tool_index *x, unsigned char **out, size_t *out_len);
/* Parses a buffer with every shape; 0, or -1 with a message in msg. */
int index_parse(const unsigned char *buf, size_t len, tool_index *out, char *msg, size_t cap);
/* Reads a file with every shape; 0, or -1 after printing one error line naming path. */
int index_load(const char *path, tool_index *out);
/* Reads the file's meta section only (x->db holds the params and no shape); shapes are read
 * with index_fetch. 0, or -1 after printing one error line naming path. */
int index_open_lazy(const char *path, tool_index *out);
/* A new db (params p, NULL: the index's) of shapes idx[0..m-1], in that order, read from the
 * buffer or file; 0, or -1 after printing one error line. */
int index_fetch(const tool_index *x, const amscr_params *p, const size_t *idx, size_t m, amscr_db **out);
/* Writes atomically; 0, or -1 after printing one error line. */
int index_save(const char *path, const tool_index *x);
void index_free(tool_index *x);
/* FNV-1a 64 of n bytes (the file's last 8 bytes hold it for the bytes before). */
uint64_t index_checksum(const unsigned char *p, size_t n);

/* The signature of a prepared shape: magnitudes of harmonics 1..INDEX_SIG_DIM of its radius
 * function (distance of the samples from their centroid, divided by its mean): invariant to
 * the start point, rotation, scale and mirror images, so similar shapes have near signatures.
 * The samples are the input points, or the whitened ones under the affine group (so the
 * signature is affine-invariant too). */
void index_signature(const amscr_descriptor *d, double *out);

#endif
