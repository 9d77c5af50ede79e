/* db.c — a collection of prepared shapes with labels: 1-vs-many, many-vs-many and cross
 * matrices on POSIX threads (bit-identical for any thread count: every cell is computed
 * independently by the same code), progress and cancellation, and a versioned binary format.
 *
 * Threads: the calling thread works too and is the only one that calls the progress
 * callback. The batch path makes no BLAS/LAPACK calls (closed-form 3x3 solves), so
 * OpenBLAS's own threads never compete with ours. */
#include "internal.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

struct amscr_db {
    amscr_params params;
    size_t n, cap;
    amscr_descriptor **d;
    int32_t *labels;
};

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
    *out = db;
    return AMSCR_OK;
}

void amscr_db_free(amscr_db *db)
{
    if (!db)
        return;
    for (size_t i = 0; i < db->n; i++)
        amscr_descriptor_free(db->d[i]);
    free(db->d);
    free(db->labels);
    free(db);
}

static amscr_status db_push(amscr_db *db, amscr_descriptor *d, int32_t label, size_t *out_index)
{
    if (db->n == db->cap) {
        size_t cap = db->cap ? 2 * db->cap : 64;
        amscr_descriptor **nd = realloc(db->d, cap * sizeof *nd);
        if (!nd)
            return amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
        db->d = nd;
        int32_t *nl = realloc(db->labels, cap * sizeof *nl);
        if (!nl)
            return amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
        db->labels = nl;
        db->cap = cap;
    }
    db->d[db->n] = d;
    db->labels[db->n] = label;
    if (out_index)
        *out_index = db->n;
    db->n++;
    return AMSCR_OK;
}

amscr_status amscr_db_add_contour(amscr_db *db, const amscr_contour *c, int32_t label, size_t *out_index)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(c);
    amscr_descriptor *d = NULL;
    amscr_status st = amscr_descriptor_new(&db->params, c, &d);
    if (st != AMSCR_OK)
        return st;
    free(d->raw); /* a collection keeps no input points: it never polishes a registration */
    d->raw = NULL;
    d->nraw = 0;
    st = db_push(db, d, label, out_index);
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
    st = db_push(db, copy, label, out_index);
    if (st != AMSCR_OK)
        amscr_descriptor_free(copy);
    return st;
}

size_t amscr_db_size(const amscr_db *db) { return db ? db->n : 0; }
int32_t amscr_db_label(const amscr_db *db, size_t i) { return (db && i < db->n) ? db->labels[i] : 0; }
const amscr_descriptor *amscr_db_descriptor(const amscr_db *db, size_t i) { return (db && i < db->n) ? db->d[i] : NULL; }
const amscr_params *amscr_db_params(const amscr_db *db) { return db ? &db->params : NULL; }

/* ------------------------------------------------------------ batch engine */

typedef struct {
    const amscr_params *prm;
    const amscr_descriptor *const *rows; /* sources */
    const amscr_descriptor *const *cols; /* targets */
    size_t nrows, ncols;
    int skip_diag;
    double *out;
    size_t rows_per_item; /* items are row blocks */
    size_t cols_per_item; /* ... or column blocks when nrows == 1 */
    size_t nitems;
    pthread_mutex_t lock;
    size_t next, done;
    int cancel;
    amscr_status status;
    char detail[256];
} batch_t;

static void batch_item(batch_t *b, amscr_workspace *ws, size_t item, amscr_status *st)
{
    size_t r0, r1, c0, c1;
    if (b->nrows == 1) {
        r0 = 0;
        r1 = 1;
        c0 = item * b->cols_per_item;
        c1 = c0 + b->cols_per_item < b->ncols ? c0 + b->cols_per_item : b->ncols;
    } else {
        r0 = item * b->rows_per_item;
        r1 = r0 + b->rows_per_item < b->nrows ? r0 + b->rows_per_item : b->nrows;
        c0 = 0;
        c1 = b->ncols;
    }
    for (size_t i = r0; i < r1 && *st == AMSCR_OK; i++)
        for (size_t j = c0; j < c1; j++) {
            double *cell = b->out + i * b->ncols + j;
            if (b->skip_diag && i == j) {
                *cell = 0.0;
                continue;
            }
            *st = amscr__distance_ws(b->prm, b->rows[i], b->cols[j], ws, cell);
            if (*st != AMSCR_OK)
                break;
        }
}

/* Takes the next item; returns 0 when there is none (or cancelled/failed). */
static int batch_take(batch_t *b, size_t *item)
{
    int ok = 0;
    pthread_mutex_lock(&b->lock);
    if (!b->cancel && b->status == AMSCR_OK && b->next < b->nitems) {
        *item = b->next++;
        ok = 1;
    }
    pthread_mutex_unlock(&b->lock);
    return ok;
}

static void batch_finish_item(batch_t *b, amscr_status st)
{
    pthread_mutex_lock(&b->lock);
    b->done++;
    if (st != AMSCR_OK && b->status == AMSCR_OK) {
        b->status = st;
        snprintf(b->detail, sizeof b->detail, "%s", amscr_last_error_detail());
    }
    pthread_mutex_unlock(&b->lock);
}

static void *batch_worker(void *arg)
{
    batch_t *b = arg;
    amscr_workspace *ws = NULL;
    if (amscr_workspace_new(&ws) != AMSCR_OK) {
        batch_finish_item(b, AMSCR_E_NOMEM);
        return NULL;
    }
    size_t item;
    while (batch_take(b, &item)) {
        amscr_status st = AMSCR_OK;
        batch_item(b, ws, item, &st);
        batch_finish_item(b, st);
    }
    amscr_workspace_free(ws);
    return NULL;
}

static amscr_status batch_run(batch_t *b, unsigned threads, amscr_progress_fn progress, void *user)
{
    size_t total_cells = b->nrows * b->ncols;
    if (b->nrows == 1) {
        b->cols_per_item = 32;
        b->nitems = (b->ncols + 31) / 32;
    } else {
        b->rows_per_item = 1;
        b->nitems = b->nrows;
    }
    if (total_cells == 0)
        return AMSCR_OK;
    pthread_mutex_init(&b->lock, NULL);
    b->next = b->done = 0;
    b->cancel = 0;
    b->status = AMSCR_OK;
    b->detail[0] = '\0';
    if (threads > b->nitems)
        threads = (unsigned)b->nitems;
    if (threads < 1)
        threads = 1;
    /* The first report (0 done) comes before any worker starts, so every callback sees the
     * start and (below) the end, whatever the scheduling. */
    size_t last_reported = (size_t)-1;
    if (progress) {
        last_reported = 0;
        if (progress(user, 0, total_cells) != 0)
            b->cancel = 1;
    }
    pthread_t *tid = NULL;
    unsigned started = 0;
    if (threads > 1 && !b->cancel) {
        tid = malloc((threads - 1) * sizeof *tid);
        if (tid)
            for (unsigned t = 0; t + 1 < threads; t++) {
                if (pthread_create(&tid[t], NULL, batch_worker, b) != 0)
                    break;
                started++;
            }
    }
    /* the calling thread works too, and reports progress between its items */
    amscr_workspace *ws = NULL;
    amscr_status own = amscr_workspace_new(&ws);
    size_t item;
    if (own != AMSCR_OK) {
        batch_finish_item(b, own);
    } else {
        for (;;) {
            if (progress) {
                pthread_mutex_lock(&b->lock);
                size_t done = b->done;
                pthread_mutex_unlock(&b->lock);
                if (done != last_reported) {
                    last_reported = done;
                    size_t cells = b->nrows == 1 ? (done * b->cols_per_item < b->ncols ? done * b->cols_per_item
                                                                                         : b->ncols)
                                                 : done * b->ncols;
                    if (progress(user, cells, total_cells) != 0) {
                        pthread_mutex_lock(&b->lock);
                        b->cancel = 1;
                        pthread_mutex_unlock(&b->lock);
                    }
                }
            }
            if (!batch_take(b, &item))
                break;
            amscr_status st = AMSCR_OK;
            batch_item(b, ws, item, &st);
            batch_finish_item(b, st);
        }
    }
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
    amscr_workspace_free(ws);
    pthread_mutex_destroy(&b->lock);
    if (b->status != AMSCR_OK || b->cancel) {
        /* never a silently partial matrix: every cell becomes NaN */
        for (size_t i = 0; i < total_cells; i++)
            b->out[i] = NAN;
        if (b->status != AMSCR_OK)
            return amscr__fail(b->status, "%s", b->detail);
        return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback after %zu of %zu items", b->done,
                           b->nitems);
    }
    if (progress && last_reported != b->nitems)
        if (progress(user, total_cells, total_cells) != 0)
            return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback at the end");
    return AMSCR_OK;
}

amscr_status amscr_db_query(const amscr_db *db, const amscr_descriptor *q, amscr_progress_fn progress, void *user,
                            double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_dist);
    if (!amscr__params_compatible(&db->params, &q->params, "amscr_db_query"))
        return AMSCR_E_INVALID_ARG;
    batch_t b;
    memset(&b, 0, sizeof b);
    b.prm = &db->params;
    b.rows = &q;
    b.cols = (const amscr_descriptor *const *)db->d;
    b.nrows = 1;
    b.ncols = db->n;
    b.out = out_dist;
    return batch_run(&b, amscr__resolve_threads(db->params.num_threads), progress, user);
}

amscr_status amscr_db_distance_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_dist);
    batch_t b;
    memset(&b, 0, sizeof b);
    b.prm = &db->params;
    b.rows = (const amscr_descriptor *const *)db->d;
    b.cols = (const amscr_descriptor *const *)db->d;
    b.nrows = db->n;
    b.ncols = db->n;
    b.skip_diag = 1;
    b.out = out_dist;
    if (db->n == 1) {
        if (progress && progress(user, 1, 1) != 0) {
            out_dist[0] = NAN;
            return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
        }
        out_dist[0] = 0.0;
        return AMSCR_OK;
    }
    return batch_run(&b, amscr__resolve_threads(db->params.num_threads), progress, user);
}

amscr_status amscr_db_cross_distances(const amscr_db *queries, const amscr_db *targets, amscr_progress_fn progress,
                                      void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(queries);
    AMSCR_CHECK_NULL(targets);
    AMSCR_CHECK_NULL(out_dist);
    if (!amscr__params_compatible(&queries->params, &targets->params, "amscr_db_cross_distances"))
        return AMSCR_E_INVALID_ARG;
    batch_t b;
    memset(&b, 0, sizeof b);
    b.prm = &queries->params;
    b.rows = (const amscr_descriptor *const *)queries->d;
    b.cols = (const amscr_descriptor *const *)targets->d;
    b.nrows = queries->n;
    b.ncols = targets->n;
    b.out = out_dist;
    return batch_run(&b, amscr__resolve_threads(queries->params.num_threads), progress, user);
}

/* ------------------------------------------------------------ serialization
 * Little-endian. Header: "AMSCRDB\0", u32 version, u32 reserved, params, u64 count, u64 N,
 * u64 p; per shape: i32 label, f64 fwd[6], f64 inv[6], f64 input[2N], base[2N], scaled[2Np];
 * trailer: u64 FNV-1a of everything before it. Version 2 adds, right after the params, the
 * retrieval settings (retrieval_io.c); the shape channel itself is derived from the prepared
 * shapes on demand and is not stored. */

#define DB_MAGIC "AMSCRDB"
#define DB_VERSION 2u /* 2 (0.2): the retrieval settings follow the params; 1 still loads */

typedef struct {
    unsigned char *buf;
    size_t len, cap;
    int oom;
} wbuf;

static void w_bytes(wbuf *w, const void *p, size_t n)
{
    if (w->oom)
        return;
    if (w->len + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->len + n)
            cap *= 2;
        unsigned char *nb = realloc(w->buf, cap);
        if (!nb) {
            w->oom = 1;
            return;
        }
        w->buf = nb;
        w->cap = cap;
    }
    memcpy(w->buf + w->len, p, n);
    w->len += n;
}

static void w_u64(wbuf *w, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    w_bytes(w, b, 8);
}

static void w_u32(wbuf *w, uint32_t v)
{
    unsigned char b[4];
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    w_bytes(w, b, 4);
}

static void w_f64(wbuf *w, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    w_u64(w, v);
}

static void w_f64s(wbuf *w, const double *d, size_t n)
{
    for (size_t i = 0; i < n; i++)
        w_f64(w, d[i]);
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

static void w_params(wbuf *w, const amscr_params *p)
{
    w_u64(w, p->num_samples);
    w_u64(w, p->num_scales);
    w_f64s(w, p->scales, p->num_scales);
    w_u32(w, (uint32_t)p->method);
    w_u32(w, (uint32_t)p->closed);
    w_u32(w, (uint32_t)p->reflections);
    w_u32(w, (uint32_t)p->parametrization);
    w_f64(w, p->presmooth);
    w_u32(w, p->arclength_passes);
    w_u32(w, p->oversampling);
    w_u32(w, p->kmax);
    w_u32(w, (uint32_t)p->symmetric);
    w_u32(w, p->refine);
    w_u32(w, p->num_threads);
    w_u32(w, (uint32_t)p->invariance);
    w_f64(w, p->penalty);
}

amscr_status amscr_db_save_memory(const amscr_db *db, void **out_buf, size_t *out_len)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_buf);
    AMSCR_CHECK_NULL(out_len);
    wbuf w = {NULL, 0, 0, 0};
    w_bytes(&w, DB_MAGIC, 8);
    w_u32(&w, DB_VERSION);
    w_u32(&w, 0);
    w_params(&w, &db->params);
    unsigned char rblock[AMSCR__RETRIEVAL_BLOCK];
    amscr__retrieval_block_write(&db->params, rblock);
    w_bytes(&w, rblock, sizeof rblock);
    size_t N = db->params.num_samples, p = db->params.num_scales;
    w_u64(&w, db->n);
    w_u64(&w, N);
    w_u64(&w, p);
    for (size_t i = 0; i < db->n; i++) {
        const amscr_descriptor *d = db->d[i];
        w_u32(&w, (uint32_t)db->labels[i]);
        w_f64s(&w, d->fwd, 6);
        w_f64s(&w, d->inv, 6);
        w_f64s(&w, d->input, 2 * N);
        w_f64s(&w, d->base, 2 * N);
        w_f64s(&w, d->scaled, 2 * N * p);
    }
    if (!w.oom)
        w_u64(&w, fnv1a(w.buf, w.len));
    if (w.oom) {
        free(w.buf);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_save: out of memory");
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
    if (st != AMSCR_OK)
        return st;
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 16);
    if (!tmp) {
        free(buf);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_save: out of memory");
    }
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp.XXXXXX", 12);
    int fd = mkstemp(tmp);
    if (fd < 0) {
        st = amscr__fail(AMSCR_E_IO, "%s: cannot create a temporary file: %s", path, strerror(errno));
    } else {
        FILE *f = fdopen(fd, "wb");
        int ok = f && fwrite(buf, 1, len, f) == len;
        if (f)
            ok = (fclose(f) == 0) && ok;
        else
            close(fd);
        if (!ok || rename(tmp, path) != 0) {
            st = amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, strerror(errno));
            remove(tmp);
        }
    }
    free(tmp);
    free(buf);
    return st;
}

typedef struct {
    const unsigned char *p;
    size_t len, pos;
    int bad;
} rbuf;

static uint64_t r_u64(rbuf *r)
{
    if (r->bad || r->len - r->pos < 8) {
        r->bad = 1;
        return 0;
    }
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)r->p[r->pos + i] << (8 * i);
    r->pos += 8;
    return v;
}

static uint32_t r_u32(rbuf *r)
{
    if (r->bad || r->len - r->pos < 4) {
        r->bad = 1;
        return 0;
    }
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)r->p[r->pos + i] << (8 * i);
    r->pos += 4;
    return v;
}

static double r_f64(rbuf *r)
{
    uint64_t v = r_u64(r);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

static int r_f64s(rbuf *r, double *d, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        d[i] = r_f64(r);
        if (!isfinite(d[i]))
            r->bad = 1;
    }
    return !r->bad;
}

amscr_status amscr_db_load_memory(const void *buf, size_t len, amscr_db **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(buf);
    AMSCR_CHECK_NULL(out);
    rbuf r = {buf, len, 0, 0};
    if (len < 8 + 8 + 8 || memcmp(buf, DB_MAGIC, 8) != 0)
        return amscr__fail(AMSCR_E_FORMAT, "not an amscr collection (bad magic)");
    r.pos = 8;
    uint32_t version = r_u32(&r);
    if (version > DB_VERSION)
        return amscr__fail(AMSCR_E_FORMAT, "collection format version %u is newer than this library's (%u)",
                           (unsigned)version, DB_VERSION);
    if (version == 0)
        return amscr__fail(AMSCR_E_FORMAT, "collection format version 0 is invalid");
    uint64_t stored = 0;
    {
        rbuf t = {buf, len, len - 8, 0};
        stored = r_u64(&t);
    }
    if (fnv1a(buf, len - 8) != stored)
        return amscr__fail(AMSCR_E_FORMAT, "collection checksum mismatch (corrupt or truncated file)");
    r_u32(&r);
    amscr_params prm;
    amscr__params_defaults(&prm);
    uint64_t N = r_u64(&r), p = r_u64(&r);
    if (r.bad || N < 16 || N > AMSCR_MAX_SAMPLES || p < 1 || p > AMSCR_MAX_SCALES)
        return amscr__fail(AMSCR_E_FORMAT, "collection header: bad N or scale count");
    prm.num_samples = (size_t)N;
    prm.num_scales = (size_t)p;
    if (!r_f64s(&r, prm.scales, (size_t)p))
        return amscr__fail(AMSCR_E_FORMAT, "collection header: bad scales");
    for (size_t k = 0; k < (size_t)p; k++)
        if (!(prm.scales[k] >= 0.0 && prm.scales[k] <= (double)N))
            return amscr__fail(AMSCR_E_FORMAT, "collection header: scale %g is outside 0..N", prm.scales[k]);
    prm.method = (amscr_method)r_u32(&r);
    prm.closed = (int)r_u32(&r);
    prm.reflections = (int)r_u32(&r);
    prm.parametrization = (amscr_parametrization)r_u32(&r);
    prm.presmooth = r_f64(&r);
    prm.arclength_passes = r_u32(&r);
    prm.oversampling = r_u32(&r);
    prm.kmax = r_u32(&r);
    prm.symmetric = (int)r_u32(&r);
    prm.refine = r_u32(&r);
    prm.num_threads = r_u32(&r);
    prm.invariance = (amscr_invariance)r_u32(&r);
    prm.penalty = r_f64(&r);
    /* validate through the setters' rules */
    amscr_params chk;
    amscr__params_defaults(&chk);
    if (r.bad || amscr_params_set_method(&chk, prm.method) || amscr_params_set_closed(&chk, prm.closed) ||
        amscr_params_set_reflections(&chk, prm.reflections) ||
        amscr_params_set_parametrization(&chk, prm.parametrization) ||
        amscr_params_set_presmooth(&chk, prm.presmooth) ||
        amscr_params_set_arclength_passes(&chk, prm.arclength_passes) ||
        amscr_params_set_oversampling(&chk, prm.oversampling) || amscr_params_set_kmax(&chk, prm.kmax) ||
        amscr_params_set_symmetric(&chk, prm.symmetric) || amscr_params_set_refine(&chk, prm.refine) ||
        amscr_params_set_num_threads(&chk, prm.num_threads) || amscr_params_set_invariance(&chk, prm.invariance) ||
        amscr_params_set_penalty(&chk, prm.penalty))
        return amscr__fail(AMSCR_E_FORMAT, "collection header: invalid parameters");
    amscr__clear_error();
    if (version >= 2) {
        if (r.bad || len - r.pos < AMSCR__RETRIEVAL_BLOCK ||
            amscr__retrieval_block_read(r.p + r.pos, &prm) != AMSCR_OK)
            return amscr__fail(AMSCR_E_FORMAT, "collection header: invalid retrieval settings");
        r.pos += AMSCR__RETRIEVAL_BLOCK;
    }
    uint64_t count = r_u64(&r), N2 = r_u64(&r), p2 = r_u64(&r);
    if (r.bad || N2 != N || p2 != p)
        return amscr__fail(AMSCR_E_FORMAT, "collection header: inconsistent sizes");
    uint64_t per = 4 + 8 * (12 + 4 * N + 2 * N * p);
    if (count > (len - r.pos) / per)
        return amscr__fail(AMSCR_E_FORMAT, "collection: %llu shapes announced, the file is too short",
                           (unsigned long long)count);
    amscr_db *db = NULL;
    amscr_status st = amscr_db_new(&prm, &db);
    if (st != AMSCR_OK)
        return st;
    for (uint64_t i = 0; i < count && st == AMSCR_OK; i++) {
        int32_t label = (int32_t)r_u32(&r);
        amscr_descriptor *d = NULL;
        st = amscr__descriptor_alloc((size_t)N, (size_t)p, &d);
        if (st != AMSCR_OK)
            break;
        d->params = prm;
        if (!r_f64s(&r, d->fwd, 6) || !r_f64s(&r, d->inv, 6) || !r_f64s(&r, d->input, 2 * N) ||
            !r_f64s(&r, d->base, 2 * N) || !r_f64s(&r, d->scaled, 2 * N * p)) {
            st = amscr__fail(AMSCR_E_FORMAT, "collection: shape %llu is truncated or has non-finite values",
                             (unsigned long long)i);
        }
        if (st == AMSCR_OK) {
            st = amscr__descriptor_finish(d);
            if (st != AMSCR_OK)
                st = amscr__fail(AMSCR_E_FORMAT, "collection: shape %llu is degenerate", (unsigned long long)i);
        }
        if (st == AMSCR_OK)
            st = db_push(db, d, label, NULL);
        if (st != AMSCR_OK)
            amscr_descriptor_free(d);
    }
    if (st == AMSCR_OK && r.pos != len - 8)
        st = amscr__fail(AMSCR_E_FORMAT, "collection: %zu unexpected trailing bytes", len - 8 - r.pos);
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
    FILE *f = fopen(path, "rb");
    if (!f)
        return amscr__fail(AMSCR_E_IO, "%s: %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    unsigned char *buf = malloc(cap);
    amscr_status st = AMSCR_OK;
    while (buf) {
        if (len == cap) {
            if (cap > ((size_t)1 << 40)) {
                st = amscr__fail(AMSCR_E_LIMIT, "%s: file too large", path);
                break;
            }
            unsigned char *nb = realloc(buf, 2 * cap);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
    }
    int err = ferror(f);
    fclose(f);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    if (st == AMSCR_OK && err)
        st = amscr__fail(AMSCR_E_IO, "%s: read error", path);
    if (st == AMSCR_OK) {
        st = amscr_db_load_memory(buf, len, out);
        if (st != AMSCR_OK) {
            char d[400];
            snprintf(d, sizeof d, "%s", amscr_last_error_detail());
            amscr__fail(st, "%s: %s", path, d);
        }
    }
    free(buf);
    return st;
}
