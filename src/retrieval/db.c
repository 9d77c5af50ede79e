/* db.c — a collection of prepared shapes with labels (decoded when first asked for when it is
 * loaded lazily), and its 1-vs-many, many-vs-many and cross matrices, whose cells db_matrix.c
 * computes on POSIX threads. The file format is db_io.c's. */
#include "db_io.h"
#include "rows.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

struct amscr_db {
    amscr_params params;
    size_t n, cap;
    amscr_descriptor **d;
    int32_t *labels;
    /* A lazy load (amscr__db_set_source): shapes below nsrc are decoded from src (the file,
     * kept by the index that owns the collection) when first asked for; d[i] NULL until then,
     * under lock (a const collection stays safe for concurrent readers). */
    const unsigned char *src;
    size_t src_pos0, src_per, nsrc;
    int src_compact;          /* src holds compact records (db_io.h) */
    unsigned char *src_owned; /* src when the collection owns it (amscr__db_compact_copy) */
    int compact_owned;        /* its shapes are kept as compact records it owns (added ones too) */
    pthread_mutex_t lock;
    /* What one-vs-many retrieval keeps between queries (retrieval_query.c): owned, released by
     * kept_free, taken under kept_lock (queries of a const collection prepare it once). */
    void *kept;
    void (*kept_free)(void *);
    pthread_mutex_t kept_lock;
};

/* The kept index's lock, error-checking: a query from the progress callback of a query that builds
 * the kept index (the same thread, the lock held) is refused rather than deadlocked
 * (amscr__db_kept_lock). 0 on success. */
static int init_kept_lock(pthread_mutex_t *m)
{
    pthread_mutexattr_t a;
    int e = pthread_mutexattr_init(&a);
    if (e == 0) {
        e = pthread_mutexattr_settype(&a, PTHREAD_MUTEX_ERRORCHECK);
        if (e == 0)
            e = pthread_mutex_init(m, &a);
        pthread_mutexattr_destroy(&a);
    }
    return e == 0 ? 0 : pthread_mutex_init(m, NULL);
}

amscr_status amscr_db_new(const amscr_params *p, amscr_db **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    amscr_db *db = calloc(1, sizeof *db);
    if (!db)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_new: out of memory");
    if (p)
        db->params = *p;
    else
        amscr__params_defaults(&db->params);
    if (init_kept_lock(&db->kept_lock) != 0) {
        free(db);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_new: cannot make the collection's lock");
    }
    *out = db;
    return AMSCR_OK;
}

void amscr_db_free(amscr_db *db)
{
    if (!db)
        return;
    if (db->kept) /* it may refer to the shapes */
        db->kept_free(db->kept);
    for (size_t i = 0; i < db->n; i++)
        amscr_descriptor_free(db->d[i]);
    if (db->src)
        pthread_mutex_destroy(&db->lock);
    pthread_mutex_destroy(&db->kept_lock);
    free(db->d);
    free(db->labels);
    free(db->src_owned);
    free(db);
}

amscr_status amscr__db_reserve(amscr_db *db, size_t extra)
{
    if (extra <= db->cap - db->n)
        return AMSCR_OK;
    if (extra > SIZE_MAX / 2 / sizeof(amscr_descriptor *) - db->n)
        return amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
    size_t cap = db->cap ? 2 * db->cap : 64;
    if (cap < db->n + extra)
        cap = db->n + extra;
    amscr_descriptor **nd = realloc(db->d, cap * sizeof *nd);
    if (!nd)
        return amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
    db->d = nd;
    int32_t *nl = realloc(db->labels, cap * sizeof *nl);
    if (!nl)
        return amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
    db->labels = nl;
    db->cap = cap;
    return AMSCR_OK;
}

amscr_status amscr__db_new_slots(const amscr_params *p, size_t n, amscr_db **out)
{
    amscr_db *db = NULL;
    amscr_status st = amscr_db_new(p, &db);
    if (st == AMSCR_OK && n > 0)
        st = amscr__db_reserve(db, n);
    if (st != AMSCR_OK) {
        amscr_db_free(db);
        return st;
    }
    for (size_t i = 0; i < n; i++) {
        db->d[i] = NULL;
        db->labels[i] = -1;
    }
    db->n = n;
    *out = db;
    return AMSCR_OK;
}

amscr_status amscr__db_push(amscr_db *db, amscr_descriptor *d, int32_t label, size_t *out_index)
{
    amscr_status st = amscr__db_reserve(db, 1);
    if (st != AMSCR_OK)
        return st;
    db->d[db->n] = d;
    db->labels[db->n] = label;
    if (out_index)
        *out_index = db->n;
    db->n++;
    return AMSCR_OK;
}

amscr_status amscr__db_prepare(const amscr_params *p, const amscr_contour *c, amscr_descriptor **out)
{
    amscr_status st = amscr_descriptor_new(p, c, out);
    if (st == AMSCR_OK) { /* a collection keeps no input points: it never polishes a registration */
        free((*out)->raw);
        (*out)->raw = NULL;
        (*out)->nraw = 0;
    }
    return st;
}

amscr_status amscr_db_add_contour(amscr_db *db, const amscr_contour *c, int32_t label, size_t *out_index)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(c);
    amscr_descriptor *d = NULL;
    amscr_status st = amscr__db_prepare(&db->params, c, &d);
    if (st != AMSCR_OK)
        return st;
    st = amscr__db_push(db, d, label, out_index);
    if (st != AMSCR_OK)
        amscr_descriptor_free(d);
    return st;
}

static amscr_status descriptor_copy(const amscr_descriptor *s, amscr_descriptor **out)
{
    amscr_descriptor *d = NULL;
    amscr_status st = amscr__descriptor_alloc(s->n, s->p, &d);
    if (st != AMSCR_OK)
        return st;
    size_t n = s->n, p = s->p;
    d->params = s->params;
    memcpy(d->input, s->input, 2 * n * sizeof(double));
    memcpy(d->base, s->base, 2 * n * sizeof(double));
    memcpy(d->scaled, s->scaled, 2 * n * p * sizeof(double));
    memcpy(d->mom, s->mom, 6 * (p + 1) * sizeof(double));
    memcpy(d->minv, s->minv, 9 * (p + 1) * sizeof(double));
    memcpy(d->spec, s->spec, 4 * n * sizeof(double));
    memcpy(d->gain, s->gain, (p + 1) * n * sizeof(double));
    memcpy(d->fwd, s->fwd, sizeof d->fwd);
    memcpy(d->inv, s->inv, sizeof d->inv);
    d->norm2 = s->norm2;
    d->nyq2 = s->nyq2;
    d->finest = s->finest;
    if (s->outline) {
        d->outline = amscr__malloc_array(2 * AMSCR__OUTLINE_N, sizeof *d->outline);
        if (!d->outline) {
            amscr_descriptor_free(d);
            return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
        }
        memcpy(d->outline, s->outline, 2 * AMSCR__OUTLINE_N * sizeof *d->outline);
    }
    *out = d;
    return AMSCR_OK;
}

amscr_status amscr_db_add_descriptor(amscr_db *db, const amscr_descriptor *d, int32_t label, size_t *out_index)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(d);
    if (!amscr__params_compatible(&db->params, &d->params, "amscr_db_add_descriptor"))
        return AMSCR_E_INVALID_ARG;
    amscr_descriptor *copy = NULL;
    amscr_status st = descriptor_copy(d, &copy);
    if (st != AMSCR_OK)
        return st;
    st = amscr__db_push(db, copy, label, out_index);
    if (st != AMSCR_OK)
        amscr_descriptor_free(copy);
    return st;
}

void **amscr__db_kept_lock(const amscr_db *db, void (*free_fn)(void *))
{
    amscr_db *m = (amscr_db *)(uintptr_t)db; /* the kept state of a const collection, under its lock */
    if (pthread_mutex_lock(&m->kept_lock) != 0) /* EDEADLK: this thread holds it (a progress callback) */
        return NULL;
    m->kept_free = free_fn;
    return &m->kept;
}

void amscr__db_kept_unlock(const amscr_db *db)
{
    pthread_mutex_unlock(&((amscr_db *)(uintptr_t)db)->kept_lock);
}

size_t amscr_db_size(const amscr_db *db) { return db ? db->n : 0; }
int32_t amscr_db_label(const amscr_db *db, size_t i) { return (db && i < db->n) ? db->labels[i] : 0; }
void amscr__db_set_source(amscr_db *db, const unsigned char *src, size_t pos0, size_t per, int compact, size_t count)
{
    pthread_mutex_init(&db->lock, NULL);
    db->src = src;
    db->src_pos0 = pos0;
    db->src_per = per;
    db->src_compact = compact;
    db->nsrc = count;
}

amscr_status amscr__db_compact_copy(const amscr_db *db, amscr_db **out)
{
    const amscr_params *p = &db->params;
    size_t n = db->n, per = (size_t)amscr__db_shape_bytes(AMSCR__DB_VERSION_INDEX_COMPACT, p);
    amscr_db *c = NULL;
    amscr_status st = amscr_db_new(p, &c);
    if (st == AMSCR_OK)
        st = amscr__db_reserve(c, n);
    amscr__wbuf w = {NULL, 0, 0, 0};
    w.buf = st == AMSCR_OK && n > 0 ? amscr__malloc_array(n, per) : NULL; /* its size: never grown */
    w.cap = w.buf ? n * per : 0;
    for (size_t i = 0; st == AMSCR_OK && i < n && !w.oom; i++) {
        amscr_descriptor *tmp = NULL;
        const amscr_descriptor *d = NULL;
        st = amscr__db_peek(db, i, &d, &tmp);
        if (st == AMSCR_OK && !amscr__db_write_compact(d, db->labels[i], p, &w))
            w.oom = 1;
        amscr_descriptor_free(tmp);
        if (st == AMSCR_OK && !w.oom)
            st = amscr__db_push(c, NULL, db->labels[i], NULL);
    }
    if (st == AMSCR_OK && (w.oom || w.len != n * per))
        st = amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    if (st != AMSCR_OK) {
        free(w.buf);
        amscr_db_free(c);
        return st;
    }
    c->src_owned = w.buf;
    c->compact_owned = 1;
    amscr__db_set_source(c, w.buf, 0, per, 1, n);
    *out = c;
    return AMSCR_OK;
}

/* Shape i's record decoded into *out: AMSCR_OK; AMSCR_E_NOMEM; AMSCR_E_FORMAT naming the shape
 * when the record does not decode (a load checks the records' samples, not every smoothed level:
 * only a damaged file whose checksum was made again fails here). */
static amscr_status db_decode(const amscr_db *db, size_t i, amscr_descriptor **out)
{
    amscr_status st = amscr__db_decode(db->src, db->src_pos0 + i * db->src_per, db->src_per, db->src_compact,
                                       &db->params, NULL, out);
    if (st == AMSCR_E_FORMAT)
        return amscr__fail(st, "collection: shape %zu cannot be read (a damaged file)", i);
    return st;
}

/* The decoded shape i kept by the collection, or NULL. */
static amscr_descriptor *db_kept(const amscr_db *db, size_t i)
{
    if (i >= db->nsrc)
        return db->d[i];
    amscr_db *m = (amscr_db *)(uintptr_t)db; /* the cache of a const collection, under its lock */
    pthread_mutex_lock(&m->lock);
    amscr_descriptor *d = m->d[i];
    pthread_mutex_unlock(&m->lock);
    return d;
}

/* Shape i into *out, decoded from the source when it is not yet and kept (db_decode's status).
 * Decoded outside the lock (threads decode different shapes at once); the first decode of a
 * shape is kept. */
static amscr_status db_get(const amscr_db *db, size_t i, const amscr_descriptor **out)
{
    amscr_descriptor *d = db_kept(db, i), *mine = NULL;
    amscr_status st = d ? AMSCR_OK : db_decode(db, i, &mine);
    if (st != AMSCR_OK || d) {
        *out = d;
        return st;
    }
    amscr_db *m = (amscr_db *)(uintptr_t)db;
    pthread_mutex_lock(&m->lock);
    if (!m->d[i])
        m->d[i] = mine;
    else
        amscr_descriptor_free(mine); /* another thread's came first */
    *out = m->d[i];
    pthread_mutex_unlock(&m->lock);
    return AMSCR_OK;
}

amscr_status amscr__db_peek(const amscr_db *db, size_t i, const amscr_descriptor **out, amscr_descriptor **tmp)
{
    *tmp = NULL;
    *out = db_kept(db, i);
    if (*out)
        return AMSCR_OK;
    amscr_status st = db_decode(db, i, tmp);
    *out = *tmp;
    return st;
}

size_t amscr__db_decoded(const amscr_db *db)
{
    amscr_db *m = (amscr_db *)(uintptr_t)db;
    size_t count = 0;
    pthread_mutex_lock(&m->lock);
    for (size_t i = 0; i < db->nsrc; i++)
        count += db->d[i] != NULL;
    pthread_mutex_unlock(&m->lock);
    return count;
}

const unsigned char *amscr__db_record(const amscr_db *db, size_t i)
{
    return i < db->nsrc && db->src_compact ? db->src + db->src_pos0 + i * db->src_per : NULL;
}

int amscr__db_shallow(const amscr_db *db, size_t i, amscr_descriptor *sd, double *input, double *outline)
{
    const unsigned char *rec = amscr__db_record(db, i);
    if (!rec)
        return 0;
    size_t N = db->params.num_samples;
    amscr__rbuf r = {rec, db->src_per, 4, 0};
    memset(sd, 0, sizeof *sd);
    sd->params = db->params;
    sd->n = N;
    sd->p = db->params.num_scales;
    sd->input = input;
    int ok = amscr__r_f64s(&r, input, 2 * N);
    if (ok && r.pos < r.len) {
        sd->outline = outline;
        ok = amscr__r_f64s(&r, outline, 2 * AMSCR__OUTLINE_N);
    }
    return ok;
}

amscr_status amscr__db_compact_tail(amscr_db *db)
{
    if (!db->compact_owned || db->nsrc == db->n)
        return AMSCR_OK;
    size_t per = db->src_per, n = db->n;
    unsigned char *grown = n <= SIZE_MAX / per ? realloc(db->src_owned, n * per) : NULL;
    if (!grown)
        return AMSCR_OK; /* the shapes stay decoded */
    amscr__wbuf w = {grown, db->nsrc * per, n * per, 0};
    for (size_t i = db->nsrc; i < n && !w.oom; i++)
        if (!amscr__db_write_compact(db->d[i], db->labels[i], &db->params, &w))
            w.oom = 1;
    db->src = db->src_owned = grown;
    if (w.oom || w.len != n * per)
        return AMSCR_OK; /* as above: the records past nsrc are not read */
    for (size_t i = db->nsrc; i < n; i++) {
        amscr_descriptor_free(db->d[i]);
        db->d[i] = NULL;
    }
    db->nsrc = n;
    return AMSCR_OK;
}

amscr_status amscr__db_own_source(amscr_db *db)
{
    if (!db->src || db->src_owned || !db->src_compact)
        return AMSCR_OK;
    unsigned char *own = db->nsrc > 0 ? amscr__malloc_array(db->nsrc, db->src_per) : NULL;
    if (db->nsrc > 0 && !own)
        return amscr__fail(AMSCR_E_NOMEM, "collection: out of memory");
    if (own)
        memcpy(own, db->src + db->src_pos0, db->nsrc * db->src_per);
    db->src = db->src_owned = own;
    db->src_pos0 = 0;
    return AMSCR_OK;
}

amscr_status amscr__db_decode_all(const amscr_db *db)
{
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; i < db->nsrc && st == AMSCR_OK; i++) {
        const amscr_descriptor *d;
        st = db_get(db, i, &d);
    }
    return st;
}

const amscr_descriptor *amscr_db_descriptor(const amscr_db *db, size_t i)
{
    const amscr_descriptor *d = NULL;
    return db && i < db->n && db_get(db, i, &d) == AMSCR_OK ? d : NULL;
}

amscr_status amscr__db_shape(const amscr_db *db, size_t i, const amscr_descriptor **out)
{
    return db_get(db, i, out);
}

amscr_status amscr__db_add_from(amscr_db *dst, const amscr_db *src, size_t i, int32_t label)
{
    const amscr_descriptor *d;
    amscr_status st = amscr__db_shape(src, i, &d);
    return st == AMSCR_OK ? amscr_db_add_descriptor(dst, d, label, NULL) : st;
}

const amscr_params *amscr_db_params(const amscr_db *db) { return db ? &db->params : NULL; }

/* amscr_db_query once db and out_dist are known. */
static amscr_status db_query(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress, void *user,
                             double *out_dist)
{
    AMSCR_CHECK_NULL_IN("amscr_db_query", q);
    if (!amscr__params_compatible(&db->params, &q->params, "amscr_db_query"))
        return AMSCR_E_INVALID_ARG;
    amscr_status st = amscr__db_decode_all(db);
    if (st != AMSCR_OK)
        return st;
    return amscr__distance_cells(&db->params, &q, 1, (const amscr_descriptor *const *)db->d, db->n, 0, progress, user,
                                 out_dist);
}

amscr_status amscr_db_query(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress, void *user,
                            double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_dist);
    return amscr__nan_on_failure(db_query(db, q, progress, user, out_dist), out_dist, 1, db->n);
}

amscr_status amscr_db_distance_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_dist);
    amscr_status st = amscr__db_decode_all(db);
    if (st != AMSCR_OK)
        return amscr__nan_on_failure(st, out_dist, db->n, db->n);
    if (db->n == 1) {
        if (progress && progress(user, 1, 1) != 0) {
            out_dist[0] = NAN;
            return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
        }
        out_dist[0] = 0.0;
        return AMSCR_OK;
    }
    const amscr_descriptor *const *all = (const amscr_descriptor *const *)db->d;
    return amscr__distance_cells(&db->params, all, db->n, all, db->n, 1, progress, user, out_dist);
}

/* amscr_db_cross_distances once its arguments are known. */
static amscr_status cross_distances(const amscr_db *queries, const amscr_db *targets, amscr_progress_fn progress,
                                    void *user, double *out_dist)
{
    if (!amscr__params_compatible(&queries->params, &targets->params, "amscr_db_cross_distances"))
        return AMSCR_E_INVALID_ARG;
    amscr_status st = amscr__db_decode_all(queries);
    if (st == AMSCR_OK)
        st = amscr__db_decode_all(targets);
    if (st != AMSCR_OK)
        return st;
    return amscr__distance_cells(&queries->params, (const amscr_descriptor *const *)queries->d, queries->n,
                                 (const amscr_descriptor *const *)targets->d, targets->n, 0, progress, user, out_dist);
}

amscr_status amscr_db_cross_distances(const amscr_db *queries, const amscr_db *targets, amscr_progress_fn progress,
                                      void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(queries);
    AMSCR_CHECK_NULL(targets);
    AMSCR_CHECK_NULL(out_dist);
    return amscr__nan_on_failure(cross_distances(queries, targets, progress, user, out_dist), out_dist, queries->n,
                                 targets->n);
}
