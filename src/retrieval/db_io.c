/* db_io.c — the collection file, little-endian whatever the host.
 * Header: "AMSCRDB\0", u32 version, u32 reserved, params, (version >= 2) the retrieval
 * settings (retrieval_io.c), u64 count, u64 N, u64 p; per shape: i32 label, f64 fwd[6],
 * f64 inv[6], f64 input[2N], base[2N], scaled[2Np], and (versions 10 and 11, closed curves whose
 * params close the inner distance's silhouette) f64 outline[2 AMSCR__OUTLINE_N], the vertices
 * of its inner distance (inner.h); (version 3) u64 length and the index
 * section (index_io.c); trailer: u64 checksum of everything before it (FNV-1a; versions 4, 6
 * and 8: amscr__sum64). A collection file does not store the shape channel (derived from the
 * prepared shapes on demand); an index file of version 4, 6 or 8 does, in its section. */
#include "db_io.h"
#include "inner.h" /* amscr__inner_vertices */

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

uint64_t amscr__db_checksum(uint32_t version, const unsigned char *p, size_t n)
{
    return amscr__db_has_features(version) ? amscr__sum64(p, n) : amscr__fnv1a(p, n);
}

static void w_params(amscr__wbuf *w, const amscr_params *p)
{
    amscr__w_u64(w, p->num_samples);
    amscr__w_u64(w, p->num_scales);
    amscr__w_f64s(w, p->scales, p->num_scales);
    amscr__w_u32(w, (uint32_t)p->method);
    amscr__w_u32(w, (uint32_t)p->closed);
    amscr__w_u32(w, (uint32_t)p->reflections);
    amscr__w_u32(w, (uint32_t)p->parametrization);
    amscr__w_f64(w, p->presmooth);
    amscr__w_u32(w, p->arclength_passes);
    amscr__w_u32(w, p->oversampling);
    amscr__w_u32(w, p->kmax);
    amscr__w_u32(w, (uint32_t)p->symmetric);
    amscr__w_u32(w, p->refine);
    amscr__w_u32(w, p->num_threads);
    amscr__w_u32(w, (uint32_t)p->invariance);
    amscr__w_f64(w, p->penalty);
}

/* Shape d's full record (label, maps, input, levels, and the outline the version keeps). */
static void write_full(const amscr_descriptor *d, int32_t label, uint32_t version, const amscr_params *prm,
                       amscr__wbuf *w)
{
    size_t N = prm->num_samples, p = prm->num_scales;
    amscr__w_u32(w, (uint32_t)label);
    amscr__w_f64s(w, d->fwd, 6);
    amscr__w_f64s(w, d->inv, 6);
    amscr__w_f64s(w, d->input, 2 * N);
    amscr__w_f64s(w, d->base, 2 * N);
    amscr__w_f64s(w, d->scaled, 2 * N * p);
    double V[2 * AMSCR__OUTLINE_N];
    if (amscr__db_has_outline(version, prm) && amscr__inner_vertices(d, prm->inner_closing, V) == AMSCR_OK)
        amscr__w_f64s(w, V, 2 * AMSCR__OUTLINE_N);
    else if (amscr__db_has_outline(version, prm))
        w->oom = 1; /* only out of memory: a prepared shape's samples always resample */
}

amscr_status amscr__db_write(const amscr_db *db, uint32_t version, amscr__wbuf *w)
{
    amscr_status st = AMSCR_OK;
    const amscr_params *prm = amscr_db_params(db);
    amscr__w_bytes(w, AMSCR__DB_MAGIC, 8);
    amscr__w_u32(w, version);
    amscr__w_u32(w, 0);
    w_params(w, prm);
    unsigned char rblock[AMSCR__RETRIEVAL_BLOCK_V5];
    size_t rsize = amscr__db_retrieval_block(version);
    amscr__retrieval_block_write(prm, rblock, rsize);
    amscr__w_bytes(w, rblock, rsize);
    size_t N = prm->num_samples, p = prm->num_scales, n = amscr_db_size(db);
    amscr__w_u64(w, n);
    amscr__w_u64(w, N);
    amscr__w_u64(w, p);
    for (size_t i = 0; i < n && st == AMSCR_OK; i++) {
        const unsigned char *rec = amscr__db_compact(version) ? amscr__db_record(db, i) : NULL;
        amscr_descriptor *tmp = NULL; /* a lazy collection's shape decoded for its record only */
        const amscr_descriptor *d = NULL;
        if (rec) /* a record kept as one copied */
            amscr__w_bytes(w, rec, (size_t)amscr__db_shape_bytes(version, prm));
        else if ((st = amscr__db_peek(db, i, &d, &tmp)) == AMSCR_OK && amscr__db_compact(version)) {
            if (!amscr__db_write_compact(d, amscr_db_label(db, i), prm, w))
                w->oom = 1;
        } else if (st == AMSCR_OK)
            write_full(d, amscr_db_label(db, i), version, prm, w);
        amscr_descriptor_free(tmp);
    }
    return st;
}

amscr_status amscr_db_save_memory(const amscr_db *db, void **out_buf, size_t *out_len)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_buf);
    AMSCR_CHECK_NULL(out_len);
    amscr__wbuf w = {NULL, 0, 0, 0}; /* a lazy load's shapes decoded one by one, none kept */
    amscr_status st = amscr__db_write(db, AMSCR__DB_VERSION_PLAIN_VIEW, &w);
    if (st == AMSCR_OK && !w.oom)
        amscr__w_u64(&w, amscr__fnv1a(w.buf, w.len));
    if (st != AMSCR_OK || w.oom) {
        free(w.buf);
        return st != AMSCR_OK ? st : amscr__fail(AMSCR_E_NOMEM, "amscr_db_save: out of memory");
    }
    *out_buf = w.buf;
    *out_len = w.len;
    return AMSCR_OK;
}

amscr_status amscr_db_save(const amscr_db *db, const char *path)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(path);
    void *buf = NULL;
    size_t len = 0;
    amscr_status st = amscr_db_save_memory(db, &buf, &len);
    if (st == AMSCR_OK)
        st = amscr__file_write_atomic(path, buf, len);
    free(buf);
    return st;
}

/* The params of the header (after magic and version) validated through the setters' rules. */
static amscr_status r_params(amscr__rbuf *r, uint32_t version, amscr_params *prm)
{
    amscr__params_defaults(prm);
    uint64_t N = amscr__r_u64(r), p = amscr__r_u64(r);
    if (r->bad || N < 16 || N > AMSCR_MAX_SAMPLES || p < 1 || p > AMSCR_MAX_SCALES)
        return amscr__fail(AMSCR_E_FORMAT, "collection header: bad N or scale count");
    prm->num_samples = (size_t)N;
    prm->num_scales = (size_t)p;
    if (!amscr__r_f64s(r, prm->scales, (size_t)p))
        return amscr__fail(AMSCR_E_FORMAT, "collection header: bad scales");
    for (size_t k = 0; k < (size_t)p; k++)
        if (!(prm->scales[k] >= 0.0 && prm->scales[k] <= (double)N))
            return amscr__fail(AMSCR_E_FORMAT, "collection header: scale %g is outside 0..N", prm->scales[k]);
    amscr_params q = *prm, chk;
    q.method = (amscr_method)amscr__r_u32(r);
    q.closed = (int)amscr__r_u32(r);
    q.reflections = (int)amscr__r_u32(r);
    q.parametrization = (amscr_parametrization)amscr__r_u32(r);
    q.presmooth = amscr__r_f64(r);
    q.arclength_passes = amscr__r_u32(r);
    q.oversampling = amscr__r_u32(r);
    q.kmax = amscr__r_u32(r);
    q.symmetric = (int)amscr__r_u32(r);
    q.refine = amscr__r_u32(r);
    q.num_threads = amscr__r_u32(r);
    q.invariance = (amscr_invariance)amscr__r_u32(r);
    q.penalty = amscr__r_f64(r);
    amscr__params_defaults(&chk);
    if (r->bad || amscr_params_set_method(&chk, q.method) || amscr_params_set_closed(&chk, q.closed) ||
        amscr_params_set_reflections(&chk, q.reflections) ||
        amscr_params_set_parametrization(&chk, q.parametrization) || amscr_params_set_presmooth(&chk, q.presmooth) ||
        amscr_params_set_arclength_passes(&chk, q.arclength_passes) ||
        amscr_params_set_oversampling(&chk, q.oversampling) || amscr_params_set_kmax(&chk, q.kmax) ||
        amscr_params_set_symmetric(&chk, q.symmetric) || amscr_params_set_refine(&chk, q.refine) ||
        amscr_params_set_num_threads(&chk, q.num_threads) || amscr_params_set_invariance(&chk, q.invariance) ||
        amscr_params_set_penalty(&chk, q.penalty))
        return amscr__fail(AMSCR_E_FORMAT, "collection header: invalid parameters");
    amscr__clear_error();
    size_t rsize = amscr__db_retrieval_block(version);
    if (rsize > 0) {
        if (r->bad || r->len - r->pos < rsize || amscr__retrieval_block_read(r->p + r->pos, rsize, &q) != AMSCR_OK)
            return amscr__fail(AMSCR_E_FORMAT, "collection header: invalid retrieval settings");
        r->pos += rsize;
    }
    *prm = q;
    return AMSCR_OK;
}

/* The shapes of a file, decoded on threads: shape i's bytes start at pos0 + i * per (a fixed
 * size), each thread takes every nt-th shape. A lazy load (check_only) decodes none: it checks
 * what a decode would (finite values, no degenerate level), the shapes decoded when asked for
 * (db.c). */
typedef struct {
    const unsigned char *p;
    size_t pos0, per;
    int compact;
    const amscr_params *prm;
    uint64_t count;
    amscr_descriptor **d; /* count entries, NULL until decoded */
    int32_t *label;
    unsigned char *bad; /* per shape: 0, or 1 truncated / not finite, 2 degenerate, 3 out of memory */
    int check_only;
    int rebuild_check; /* full records of an index: their input must rebuild (db_record.c) */
    unsigned t, nt;
} shapes_job;

/* Shape i checked as a decode would, in scratch (2N doubles). */
static void check_shape(const shapes_job *j, uint64_t i, double *scratch)
{
    size_t N = j->prm->num_samples, p = j->prm->num_scales, at = j->pos0 + (size_t)i * j->per;
    amscr__rbuf r = {j->p, at + j->per, at, 0};
    if (j->compact) { /* finite samples with extent (a prepared shape's smoothed levels then have it) */
        j->label[i] = (int32_t)amscr__r_u32(&r);
        if (!amscr__r_f64s(&r, scratch, 2 * N))
            j->bad[i] = 1;
        else if (!amscr__db_level_ok(scratch, N))
            j->bad[i] = 2;
        else if (amscr__db_outline_kept(j->per, 1, j->prm) && !amscr__r_f64s(&r, scratch, 2 * AMSCR__OUTLINE_N))
            j->bad[i] = 1;
        return;
    }
    j->label[i] = (int32_t)amscr__r_u32(&r);
    if (!amscr__r_f64s(&r, scratch, 12) || !amscr__r_f64s(&r, scratch, 2 * N)) {
        j->bad[i] = 1;
        return;
    }
    if (!amscr__db_level_ok(scratch, N)) /* the input, as a compact record's */
        j->bad[i] = 2;
    for (size_t k = 0; k <= p; k++) {
        if (!amscr__r_f64s(&r, scratch, 2 * N)) {
            j->bad[i] = 1;
            return;
        }
        if (!amscr__db_level_ok(scratch, N))
            j->bad[i] = 2;
    }
    if (amscr__db_outline_kept(j->per, 0, j->prm) && !amscr__r_f64s(&r, scratch, 2 * AMSCR__OUTLINE_N))
        j->bad[i] = 1;
}

static void read_shape(const shapes_job *j, uint64_t i)
{
    j->bad[i] = (unsigned char)amscr__db_decode_shape(j->p, j->pos0 + (size_t)i * j->per, j->per, j->compact,
                                                      j->rebuild_check, j->prm, &j->label[i], &j->d[i]);
}

static void *shapes_worker(void *arg)
{
    const shapes_job *j = arg;
    size_t len = 2 * j->prm->num_samples > 2 * AMSCR__OUTLINE_N ? 2 * j->prm->num_samples : 2 * AMSCR__OUTLINE_N;
    double *scratch = j->check_only ? amscr__malloc_array(len, sizeof *scratch) : NULL;
    for (uint64_t i = j->t; i < j->count; i += j->nt)
        if (!j->check_only)
            read_shape(j, i);
        else if (j->rebuild_check) { /* an old index's full record: checked as its decode (the rebuild) */
            read_shape(j, i);
            amscr_descriptor_free(j->d[i]);
            j->d[i] = NULL;
        } else if (scratch)
            check_shape(j, i, scratch);
        else
            j->bad[i] = 3;
    free(scratch);
    return NULL;
}

/* Runs job j (t, nt unset) on up to the params' threads (the calling thread too). */
static void run_shapes(shapes_job *j)
{
    enum { MAX_THREADS = 64, MIN_SHAPES = 32 }; /* a thread for at least MIN_SHAPES shapes */
    unsigned nt = amscr__resolve_threads(j->prm->num_threads), started = 0;
    if (nt > MAX_THREADS)
        nt = MAX_THREADS;
    if ((uint64_t)nt * MIN_SHAPES > j->count)
        nt = j->count / MIN_SHAPES > 0 ? (unsigned)(j->count / MIN_SHAPES) : 1u;
    shapes_job part[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    for (unsigned t = 0; t < nt; t++) {
        part[t] = *j;
        part[t].t = t;
        part[t].nt = nt;
    }
    for (unsigned t = 1; t < nt; t++)
        if (pthread_create(&tid[t], NULL, shapes_worker, &part[t]) == 0)
            started = t;
        else
            break;
    for (unsigned t = started + 1; t < nt; t++) /* threads that did not start: done here */
        shapes_worker(&part[t]);
    shapes_worker(&part[0]);
    for (unsigned t = 1; t <= started; t++)
        pthread_join(tid[t], NULL);
}

/* The count shapes into db (params prm), decoded on the params' threads, entered in order
 * (lazy: checked, and left to decode from r's buffer when asked for). */
static amscr_status r_shapes(amscr__rbuf *r, uint32_t version, const amscr_params *prm, uint64_t count, int lazy,
                             amscr_db *db)
{
    size_t per = (size_t)amscr__db_shape_bytes(version, prm);
    shapes_job j = {r->p, r->pos, per, amscr__db_compact(version), prm, count, NULL, NULL, NULL, lazy,
                    !amscr__db_compact(version) && amscr__db_is_index(version), 0, 1};
    j.d = amscr__calloc_array(count ? count : 1, sizeof *j.d);
    j.label = amscr__malloc_array(count ? count : 1, sizeof *j.label);
    j.bad = amscr__calloc_array(count ? count : 1, 1);
    amscr_status st = j.d && j.label && j.bad ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "collection: out of memory");
    if (st == AMSCR_OK)
        run_shapes(&j); /* count * per bytes are there: amscr__db_parse checked */
    for (uint64_t i = 0; i < count && st == AMSCR_OK; i++) {
        if (j.bad[i] == 1)
            st = amscr__fail(AMSCR_E_FORMAT, "collection: shape %llu is truncated or has non-finite values",
                             (unsigned long long)i);
        else if (j.bad[i] == 2)
            st = amscr__fail(AMSCR_E_FORMAT, "collection: shape %llu is degenerate", (unsigned long long)i);
        else if (j.bad[i] == 3)
            st = amscr__fail(AMSCR_E_NOMEM, "collection: out of memory");
        else
            st = amscr__db_push(db, j.d[i], j.label[i], NULL);
        if (st == AMSCR_OK)
            j.d[i] = NULL; /* the collection's now */
    }
    if (st == AMSCR_OK && lazy)
        amscr__db_set_source(db, r->p, r->pos, j.per, j.compact, (size_t)count);
    for (uint64_t i = 0; j.d && i < count; i++)
        amscr_descriptor_free(j.d[i]);
    r->pos += st == AMSCR_OK ? (size_t)count * j.per : 0;
    free(j.d);
    free(j.label);
    free(j.bad);
    return st;
}

/* Magic, version and checksum of buf into *version. */
static amscr_status check_envelope(const unsigned char *buf, size_t len, uint32_t *version)
{
    if (len >= 8 && memcmp(buf, "AMSCRIDX", 8) == 0)
        return amscr__fail(AMSCR_E_FORMAT, "an index file of the amscr tool before 0.4 (format AMSCRIDX): "
                                           "rebuild it with `amscr index`");
    if (len < 8 + 8 + 8 || memcmp(buf, AMSCR__DB_MAGIC, 8) != 0)
        return amscr__fail(AMSCR_E_FORMAT, "not an amscr collection (bad magic)");
    amscr__rbuf r = {buf, len, 8, 0}, t = {buf, len, len - 8, 0};
    *version = amscr__r_u32(&r);
    if (*version > AMSCR__DB_VERSION_NEWEST)
        return amscr__fail(AMSCR_E_FORMAT, "collection format version %u is newer than this library's (%u)",
                           (unsigned)*version, AMSCR__DB_VERSION_NEWEST);
    if (*version == 0)
        return amscr__fail(AMSCR_E_FORMAT, "collection format version 0 is invalid");
    if (amscr__db_checksum(*version, buf, len - 8) != amscr__r_u64(&t))
        return amscr__fail(AMSCR_E_FORMAT, "collection checksum mismatch (corrupt or truncated file)");
    return AMSCR_OK;
}

amscr_status amscr__db_parse(const unsigned char *buf, size_t len, int lazy, amscr_db **out, size_t *out_pos,
                             uint32_t *out_version)
{
    uint32_t version = 0;
    amscr_status st = check_envelope(buf, len, &version);
    if (st != AMSCR_OK)
        return st;
    amscr__rbuf r = {buf, len - 8, 16, 0}; /* the trailer is not content */
    amscr_params prm;
    st = r_params(&r, version, &prm);
    if (st != AMSCR_OK)
        return st;
    uint64_t count = amscr__r_u64(&r), N = amscr__r_u64(&r), p = amscr__r_u64(&r);
    if (r.bad || N != prm.num_samples || p != prm.num_scales)
        return amscr__fail(AMSCR_E_FORMAT, "collection header: inconsistent sizes");
    uint64_t per = amscr__db_shape_bytes(version, &prm);
    if (count > (r.len - r.pos) / per)
        return amscr__fail(AMSCR_E_FORMAT, "collection: %llu shapes announced, the file is too short",
                           (unsigned long long)count);
    amscr_db *db = NULL;
    st = amscr_db_new(&prm, &db);
    if (st == AMSCR_OK)
        st = r_shapes(&r, version, &prm, count, lazy, db);
    if (st != AMSCR_OK) {
        amscr_db_free(db);
        return st;
    }
    *out = db;
    *out_pos = r.pos;
    *out_version = version;
    return AMSCR_OK;
}

amscr_status amscr_db_load_memory(const void *buf, size_t len, amscr_db **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(buf);
    AMSCR_CHECK_NULL(out);
    amscr_db *db = NULL;
    size_t pos = 0;
    uint32_t version = 0;
    amscr_status st = amscr__db_parse(buf, len, 0, &db, &pos, &version);
    if (st != AMSCR_OK)
        return st;
    if (amscr__db_is_index(version)) { /* an index file: its collection, the section skipped */
        amscr__rbuf r = {buf, len - 8, pos, 0};
        uint64_t sec = amscr__r_u64(&r);
        if (r.bad || sec != r.len - r.pos)
            st = amscr__fail(AMSCR_E_FORMAT, "index file: bad index section length");
        else
            pos = r.len;
    }
    if (st == AMSCR_OK && pos != len - 8)
        st = amscr__fail(AMSCR_E_FORMAT, "collection: %zu unexpected trailing bytes", len - 8 - pos);
    if (st != AMSCR_OK) {
        amscr_db_free(db);
        return st;
    }
    *out = db;
    return AMSCR_OK;
}

amscr_status amscr_db_load(const char *path, amscr_db **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(path);
    AMSCR_CHECK_NULL(out);
    unsigned char *buf = NULL;
    size_t len = 0;
    amscr_status st = amscr__file_read(path, &buf, &len);
    if (st != AMSCR_OK)
        return st;
    st = amscr_db_load_memory(buf, len, out);
    if (st != AMSCR_OK) {
        char d[400];
        snprintf(d, sizeof d, "%s", amscr_last_error_detail());
        amscr__fail(st, "%s: %s", path, d);
    }
    free(buf);
    return st;
}
