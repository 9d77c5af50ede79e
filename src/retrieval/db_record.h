/* db_record.h — the versions of the collection file (db_io.h) and one shape's record in it
 * (db_record.c): its layout, the compact record a save writes, a record decoded with the checks a
 * load makes. Never installed. */
#ifndef AMSCR_DB_RECORD_H
#define AMSCR_DB_RECORD_H

#include "bytes.h"
#include "internal.h"

#define AMSCR__DB_MAGIC "AMSCRDB"
/* 1 (0.1); 2 (0.2): the retrieval settings follow the params; 3 (0.4): an index section
 * (u64 length, then index_io.c's bytes) follows the shapes; 4 (0.5): the index section holds
 * the shapes' channel features too, and the trailing checksum is amscr__sum64 instead of
 * FNV-1a; 5 and 6 (0.6): 2 and 4 (FNV-1a and amscr__sum64) with the longer retrieval block (the whitened frame's band
 * after the others; AMSCR__RETRIEVAL_BLOCK_V2); 7 and 8 (0.7): the same with the inner-distance
 * graph's share after those (AMSCR__RETRIEVAL_BLOCK_V3); 9 (0.8): 8 whose index section ends with
 * the inner distance's graph (its lists and the shapes' inner features); 10 and 11 (0.9): 7 and 9
 * with the inner distance's closing after the share (AMSCR__RETRIEVAL_BLOCK_V4); 12 and 13
 * (0.11): 10 and 11 with the channel's affine-view factor after the closing
 * (AMSCR__RETRIEVAL_BLOCK_V5); 14 (0.14): 13 with compact shape records (a shape's input samples
 * and outline only: the rest recomputed, amscr__descriptor_rebuild). Every version loads. */
#define AMSCR__DB_VERSION_PLAIN 2u
#define AMSCR__DB_VERSION_INDEX 3u
#define AMSCR__DB_VERSION_FEATURES 4u
#define AMSCR__DB_VERSION_PLAIN_BANDS 5u
#define AMSCR__DB_VERSION_INDEX_BANDS 6u
#define AMSCR__DB_VERSION_PLAIN_INNER 7u
#define AMSCR__DB_VERSION_INDEX_INNER 8u
#define AMSCR__DB_VERSION_INDEX_GRAPHS 9u
#define AMSCR__DB_VERSION_PLAIN_CLOSING 10u
#define AMSCR__DB_VERSION_INDEX_CLOSING 11u
#define AMSCR__DB_VERSION_PLAIN_VIEW 12u
#define AMSCR__DB_VERSION_INDEX_VIEW 13u
#define AMSCR__DB_VERSION_INDEX_COMPACT 14u
/* Version 15: version 14 with the inner features in float32 (index_io.c). */
#define AMSCR__DB_VERSION_INDEX_F32 15u
/* Version 16: version 15 with the inner features as int16 and a scale, and the coarse quantizer
 * of the signatures after the inner graph (index_io.c: write_quantizer / read_quantizer). */
#define AMSCR__DB_VERSION_INDEX_I16 16u
#define AMSCR__DB_VERSION_NEWEST AMSCR__DB_VERSION_INDEX_I16

/* Whether a file of `version` is an index file (an index section after the shapes). */
static inline int amscr__db_is_index(uint32_t version)
{
    return version == AMSCR__DB_VERSION_INDEX || version == AMSCR__DB_VERSION_FEATURES ||
           version == AMSCR__DB_VERSION_INDEX_BANDS || version == AMSCR__DB_VERSION_INDEX_INNER ||
           version == AMSCR__DB_VERSION_INDEX_GRAPHS || version == AMSCR__DB_VERSION_INDEX_CLOSING ||
           version == AMSCR__DB_VERSION_INDEX_VIEW || version == AMSCR__DB_VERSION_INDEX_COMPACT ||
           version == AMSCR__DB_VERSION_INDEX_F32 || version == AMSCR__DB_VERSION_INDEX_I16;
}

/* Whether an index file of `version` stores the shapes' channel features. */
static inline int amscr__db_has_features(uint32_t version)
{
    return version == AMSCR__DB_VERSION_FEATURES || version == AMSCR__DB_VERSION_INDEX_BANDS ||
           version == AMSCR__DB_VERSION_INDEX_INNER || version == AMSCR__DB_VERSION_INDEX_GRAPHS ||
           version == AMSCR__DB_VERSION_INDEX_CLOSING || version == AMSCR__DB_VERSION_INDEX_VIEW ||
           version == AMSCR__DB_VERSION_INDEX_COMPACT || version == AMSCR__DB_VERSION_INDEX_F32 ||
           version == AMSCR__DB_VERSION_INDEX_I16;
}

/* The bytes of the retrieval block in a file of `version` (0: none). */
static inline size_t amscr__db_retrieval_block(uint32_t version)
{
    return version >= AMSCR__DB_VERSION_PLAIN_VIEW      ? AMSCR__RETRIEVAL_BLOCK_V5
           : version >= AMSCR__DB_VERSION_PLAIN_CLOSING ? AMSCR__RETRIEVAL_BLOCK_V4
           : version >= AMSCR__DB_VERSION_PLAIN_INNER ? AMSCR__RETRIEVAL_BLOCK_V3
           : version >= AMSCR__DB_VERSION_PLAIN_BANDS ? AMSCR__RETRIEVAL_BLOCK_V2
           : version >= AMSCR__DB_VERSION_PLAIN     ? AMSCR__RETRIEVAL_BLOCK
                                                    : 0;
}

/* Whether the shapes of a file of `version` with params p keep their outline (versions 10 to
 * 13: closed curves whose params close the inner distance's silhouette). */
static inline int amscr__db_has_outline(uint32_t version, const amscr_params *p)
{
    return version >= AMSCR__DB_VERSION_PLAIN_CLOSING && p->closed && p->inner_closing > 0.0;
}

/* Whether the shapes of a file of `version` are compact records: i32 label, f64 input[2N] and
 * (amscr__db_has_outline) f64 outline[2 AMSCR__OUTLINE_N]; the rest of the prepared shape is
 * recomputed from the input (amscr__descriptor_rebuild, bit for bit). */
static inline int amscr__db_compact(uint32_t version) { return version >= AMSCR__DB_VERSION_INDEX_COMPACT; }

/* The bytes of one shape in a file of `version` with params p (db_io.c's layout). */
static inline uint64_t amscr__db_shape_bytes(uint32_t version, const amscr_params *p)
{
    uint64_t N = p->num_samples, np = p->num_scales;
    uint64_t outline = amscr__db_has_outline(version, p) ? 2 * AMSCR__OUTLINE_N : 0;
    if (amscr__db_compact(version))
        return 4 + 8 * (2 * N + outline);
    return 4 + 8 * (12 + 4 * N + 2 * N * np + outline);
}

/* One shape of d as a compact record (amscr__db_compact) into w; 0 when its outline cannot be
 * made (out of memory). */
int amscr__db_write_compact(const amscr_descriptor *d, int32_t label, const amscr_params *prm, amscr__wbuf *w);
/* Whether shape records of `per` bytes (params prm; compact or full) end with an outline. */
int amscr__db_outline_kept(size_t per, int compact, const amscr_params *prm);
/* Whether the curve xy (n points) has an invertible moment matrix (a prepared level's test). */
int amscr__db_level_ok(const double *xy, size_t n);
/* Shape bytes [at, at + per) decoded into *out and *label: 0, or 1 truncated / not finite, 2
 * degenerate, 3 out of memory. A full record's input must have extent and, with rebuild_check,
 * rebuild (an index's). */
int amscr__db_decode_shape(const unsigned char *p, size_t at, size_t per, int compact, int rebuild_check,
                           const amscr_params *prm, int32_t *label, amscr_descriptor **out);
/* Shape bytes [at, at + per) of a file with params prm decoded into *out (caller frees);
 * *label when label is not NULL; compact: a compact record (amscr__db_compact). AMSCR_E_FORMAT
 * when truncated, not finite or degenerate. */
amscr_status amscr__db_decode(const unsigned char *p, size_t at, size_t per, int compact, const amscr_params *prm,
                              int32_t *label, amscr_descriptor **out);

#endif
