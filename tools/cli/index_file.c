/* index_file.c — reading and writing the index of `amscr index` (see index_file.h). */
#include "index_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"

static const char MAGIC[8] = {'A', 'M', 'S', 'C', 'R', 'I', 'D', 'X'};

/* ------------------------------------------------------------ writing */
typedef struct wbuf {
    unsigned char *p;
    size_t len, cap;
    int oom;
} wbuf;

static void w_bytes(wbuf *w, const void *s, size_t n)
{
    if (w->oom)
        return;
    if (w->len + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->len + n)
            cap *= 2;
        unsigned char *p = realloc(w->p, cap);
        if (p == NULL) {
            w->oom = 1;
            return;
        }
        w->p = p;
        w->cap = cap;
    }
    memcpy(w->p + w->len, s, n);
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

static void w_f64(wbuf *w, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    w_u64(w, u);
}

static void w_str(wbuf *w, const char *s)
{
    size_t n = strlen(s);
    w_u32(w, (uint32_t)n);
    w_bytes(w, s, n);
}

uint64_t index_checksum(const unsigned char *p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

/* A one-shape db blob of shape i (or, i == SIZE_MAX, an empty db: the params) appended to w. */
static int w_db_blob(wbuf *w, const amscr_db *db, size_t i)
{
    amscr_db *one = NULL;
    void *blob = NULL;
    size_t blen = 0;
    amscr_status st = amscr_db_new(amscr_db_params(db), &one);
    if (st == AMSCR_OK && i != SIZE_MAX)
        st = amscr_db_add_descriptor(one, amscr_db_descriptor(db, i), amscr_db_label(db, i), NULL);
    if (st == AMSCR_OK)
        st = amscr_db_save_memory(one, &blob, &blen);
    amscr_db_free(one);
    if (st != AMSCR_OK)
        return -1;
    if (i == SIZE_MAX)
        w_u64(w, blen);
    w_bytes(w, blob, blen);
    amscr_free(blob);
    return 0;
}

static void w_meta(wbuf *w, const tool_index *x, const uint64_t *off, const uint64_t *len)
{
    const collection *c = &x->coll;
    size_t n = c->n;
    w_u64(w, n);
    w_u32(w, (uint32_t)x->threshold);
    w_u32(w, 0); /* reserved */
    w_u64(w, x->k);
    w_f64(w, x->dmax);
    w_f64(w, x->med_a);
    w_f64(w, x->med_h);
    if (w_db_blob(w, x->db, SIZE_MAX) != 0)
        w->oom = 1;
    w_u64(w, c->nclasses);
    for (size_t i = 0; i < c->nclasses; i++)
        w_str(w, c->classes[i]);
    w_u64(w, c->ngroups);
    for (size_t i = 0; i < c->ngroups; i++)
        w_str(w, c->groups[i]);
    for (size_t i = 0; i < n; i++) {
        w_str(w, c->items[i].name);
        w_u32(w, (uint32_t)c->items[i].label);
        w_u32(w, (uint32_t)c->items[i].group);
        w_u64(w, off[i]);
        w_u64(w, len[i]);
    }
    w_u32(w, INDEX_SIG_DIM);
    for (size_t i = 0; i < n * INDEX_SIG_DIM; i++)
        w_f64(w, x->sig[i]);
    for (size_t i = 0; i < n * x->k; i++) {
        w_u32(w, x->nb_idx[i]);
        w_f64(w, x->nb_dist[i]);
    }
}

static void put_u64_at(unsigned char *p, uint64_t v)
{
    for (int i = 0; i < 8; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

int index_serialize(const tool_index *x, unsigned char **out, size_t *out_len)
{
    size_t n = x->coll.n;
    wbuf blobs = {NULL, 0, 0, 0}, meta = {NULL, 0, 0, 0}, w = {NULL, 0, 0, 0};
    uint64_t *off = xmalloc_array(n, sizeof *off), *len = xmalloc_array(n, sizeof *len);
    int ok = off && len && amscr_db_size(x->db) == n;
    for (size_t i = 0; ok && i < n; i++) {
        off[i] = blobs.len;
        ok = w_db_blob(&blobs, x->db, i) == 0 && !blobs.oom;
        len[i] = blobs.len - off[i];
    }
    if (ok)
        w_meta(&meta, x, off, len);
    free(off);
    free(len);
    if (ok && !meta.oom) {
        w_bytes(&w, MAGIC, 8);
        w_u32(&w, INDEX_VERSION);
        w_u32(&w, 0);
        w_u64(&w, 0); /* the file length, filled in below */
        w_u64(&w, meta.len);
        w_bytes(&w, meta.p, meta.len);
        w_u64(&w, index_checksum(meta.p, meta.len));
        w_bytes(&w, blobs.p, blobs.len);
    }
    free(meta.p);
    free(blobs.p);
    if (!ok || meta.oom || w.oom) {
        free(w.p);
        tool_error(NULL, "out of memory writing the index");
        return -1;
    }
    put_u64_at(w.p + 16, w.len);
    *out = w.p;
    *out_len = w.len;
    return 0;
}

int index_save(const char *path, const tool_index *x)
{
    unsigned char *buf = NULL;
    size_t len = 0;
    if (index_serialize(x, &buf, &len) != 0)
        return -1;
    tool_out o;
    int r = -1;
    if (tool_out_open(&o, path) == 0) {
        if (fwrite(buf, 1, len, o.fp) != len) {
            tool_out_abort(&o);
            tool_error(path, "write error");
        } else {
            r = tool_out_commit(&o);
        }
    }
    free(buf);
    return r;
}

/* ------------------------------------------------------------ reading */
typedef struct rbuf {
    const unsigned char *p;
    size_t len, pos;
    int bad;
} rbuf;

static int r_need(rbuf *r, size_t n)
{
    if (r->bad || r->pos > r->len || r->len - r->pos < n) {  /* pos may lie past the end */
        r->bad = 1;
        return 0;
    }
    return 1;
}

static uint64_t r_u64(rbuf *r)
{
    if (!r_need(r, 8))
        return 0;
    uint64_t v = 0;
    for (int i = 7; i >= 0; i--)
        v = v << 8 | r->p[r->pos + (size_t)i];
    r->pos += 8;
    return v;
}

static uint32_t r_u32(rbuf *r)
{
    if (!r_need(r, 4))
        return 0;
    uint32_t v = 0;
    for (int i = 3; i >= 0; i--)
        v = v << 8 | r->p[r->pos + (size_t)i];
    r->pos += 4;
    return v;
}

static double r_f64(rbuf *r)
{
    uint64_t u = r_u64(r);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

/* A string of at most 4096 bytes without NUL; NULL (r->bad set) otherwise. */
static char *r_str(rbuf *r)
{
    uint32_t n = r_u32(r);
    if (n == 0 || n > 4096 || !r_need(r, n) || memchr(r->p + r->pos, '\0', n) != NULL) {
        r->bad = 1;
        return NULL;
    }
    char *s = malloc((size_t)n + 1);
    if (s == NULL) {
        r->bad = 1;
        return NULL;
    }
    memcpy(s, r->p + r->pos, n);
    s[n] = '\0';
    r->pos += n;
    return s;
}

/* A count whose entries take at least `each` bytes: bounded by what is left. */
static size_t r_count(rbuf *r, size_t each)
{
    uint64_t v = r_u64(r);
    if (r->bad || v > (uint64_t)((r->len - r->pos) / each)) {
        r->bad = 1;
        return 0;
    }
    return (size_t)v;
}

static int fail(char *msg, size_t cap, const char *what)
{
    snprintf(msg, cap, "%s", what);
    return -1;
}

/* Names of classes or groups: count, then strings. */
static int r_names(rbuf *r, char ***names, size_t *n)
{
    *n = r_count(r, 5);
    *names = xcalloc_array(*n ? *n : 1, sizeof(char *));
    if (*names == NULL)
        return -1;
    for (size_t i = 0; i < *n && !r->bad; i++)
        (*names)[i] = r_str(r);
    return r->bad ? -1 : 0;
}

static int parse_items(rbuf *r, tool_index *x, size_t n, uint64_t blobs_len)
{
    collection *c = &x->coll;
    c->items = xcalloc_array(n, sizeof(coll_item));
    x->blob_off = xmalloc_array(n, sizeof(uint64_t));
    x->blob_len = xmalloc_array(n, sizeof(uint64_t));
    if (c->items == NULL || x->blob_off == NULL || x->blob_len == NULL)
        return -1;
    c->n = n;
    for (size_t i = 0; i < n && !r->bad; i++) {
        coll_item *it = &c->items[i];
        it->name = r_str(r);
        it->path = it->name ? xstrdup(it->name) : NULL;
        it->label = (int32_t)r_u32(r);
        it->group = (int32_t)r_u32(r);
        x->blob_off[i] = r_u64(r);
        x->blob_len[i] = r_u64(r);
        if (it->path == NULL || it->label < 0 || (size_t)it->label >= c->nclasses || it->group < -1 ||
            (it->group >= 0 && (size_t)it->group >= c->ngroups) || (c->ngroups > 0) != (it->group >= 0) ||
            x->blob_off[i] > blobs_len || x->blob_len[i] > blobs_len - x->blob_off[i] || x->blob_len[i] == 0)
            r->bad = 1;
    }
    return r->bad ? -1 : 0;
}

static int parse_tables(rbuf *r, tool_index *x, size_t n)
{
    if (r_u32(r) != INDEX_SIG_DIM)
        return -1;
    if (!r_need(r, n * INDEX_SIG_DIM * 8) || (x->k > 0 && !r_need(r, n * x->k * 12)))
        return -1;
    x->sig = xmalloc_array(n * INDEX_SIG_DIM, sizeof(double));
    x->nb_idx = xmalloc_array(n * x->k > 0 ? n * x->k : 1, sizeof(uint32_t));
    x->nb_dist = xmalloc_array(n * x->k > 0 ? n * x->k : 1, sizeof(double));
    if (!x->sig || !x->nb_idx || !x->nb_dist)
        return -1;
    for (size_t i = 0; i < n * INDEX_SIG_DIM; i++)
        if (!isfinite(x->sig[i] = r_f64(r)))
            return -1;
    for (size_t i = 0; i < n * x->k; i++) {
        x->nb_idx[i] = r_u32(r);
        x->nb_dist[i] = r_f64(r);
        size_t row = i / x->k, t = i % x->k;
        if (x->nb_idx[i] >= n || !(x->nb_dist[i] >= 0.0) || !isfinite(x->nb_dist[i]) ||
            (t == 0 && x->nb_idx[i] != row) || (t > 0 && x->nb_dist[i] < x->nb_dist[i - 1]))
            return -1;
    }
    return r->bad || r->pos != r->len ? -1 : 0;
}

/* The params blob: an empty db. */
static int parse_params(rbuf *r, tool_index *x, char *msg, size_t cap)
{
    uint64_t blen = r_u64(r);
    if (r->bad || !r_need(r, blen))
        return fail(msg, cap, "bad size of the shape options");
    amscr_status st = amscr_db_load_memory(r->p + r->pos, (size_t)blen, &x->db);
    if (st != AMSCR_OK || amscr_db_size(x->db) != 0) {
        snprintf(msg, cap, "shape options: %s", st != AMSCR_OK && lib_detail()[0] ? lib_detail() : "not valid");
        return -1;
    }
    r->pos += (size_t)blen;
    return 0;
}

/* The meta section (r covers it exactly), the blobs being blobs_len bytes. */
static int parse_meta(rbuf *r, tool_index *x, uint64_t blobs_len, char *msg, size_t cap)
{
    size_t n = r_count(r, 13);
    x->threshold = (int32_t)r_u32(r);
    uint32_t reserved = r_u32(r);
    uint64_t k = r_u64(r);
    x->dmax = r_f64(r);
    x->med_a = r_f64(r);
    x->med_h = r_f64(r);
    if (r->bad || n == 0 || k > n || k > 100000 || !(x->dmax >= 0.0) || !isfinite(x->dmax) || reserved != 0 ||
        !(x->med_a >= 0.0) || !isfinite(x->med_a) || !(x->med_h >= 0.0) || !isfinite(x->med_h) || (x->threshold != AMSCR_THRESHOLD_AUTO && (x->threshold < 0 || x->threshold > 254)))
        return fail(msg, cap, "bad index header");
    x->k = (size_t)k;
    if (parse_params(r, x, msg, cap) != 0)
        return -1;
    if (r_names(r, &x->coll.classes, &x->coll.nclasses) != 0 || x->coll.nclasses == 0 ||
        r_names(r, &x->coll.groups, &x->coll.ngroups) != 0)
        return fail(msg, cap, "bad class or group names");
    if (parse_items(r, x, n, blobs_len) != 0)
        return fail(msg, cap, "bad file list");
    if (parse_tables(r, x, n) != 0)
        return fail(msg, cap, "bad signatures or neighbour lists");
    return 0;
}

/* The header and the meta section of a file of `total` bytes whose first `len` are in buf. */
static int parse_head(const unsigned char *buf, size_t len, uint64_t total, tool_index *x, char *msg, size_t cap)
{
    memset(x, 0, sizeof *x);
    if (len < 8 || memcmp(buf, MAGIC, 8) != 0)
        return fail(msg, cap, "not an amscr index (bad magic)");
    rbuf r = {buf, len, 8, 0};
    uint32_t version = r_u32(&r);
    if (r.bad)
        return fail(msg, cap, "truncated index");
    if (version != INDEX_VERSION) {
        snprintf(msg, cap, "index format version %u; this amscr reads version %d (rebuild the index)",
                 (unsigned)version, INDEX_VERSION);
        return -1;
    }
    r.pos = 16;
    uint64_t flen = r_u64(&r), mlen = r_u64(&r);
    if (r.bad || flen != total)
        return fail(msg, cap, "truncated index (its length differs from the header's)");
    if (mlen > len - r.pos || len - r.pos - mlen < 8)
        return fail(msg, cap, "truncated index");
    rbuf m = {buf + r.pos, (size_t)mlen, 0, 0}, sum = {buf, len, r.pos + (size_t)mlen, 0};
    if (index_checksum(m.p, m.len) != r_u64(&sum))
        return fail(msg, cap, "corrupt index (checksum mismatch)");
    x->blobs_at = r.pos + mlen + 8;
    return parse_meta(&m, x, total - x->blobs_at, msg, cap);
}

int index_parse(const unsigned char *buf, size_t len, tool_index *x, char *msg, size_t cap)
{
    if (parse_head(buf, len, len, x, msg, cap) != 0)
        return -1;
    x->mem = buf;
    size_t n = x->coll.n, *all = xmalloc_array(n, sizeof(size_t));
    amscr_db *db = NULL;
    if (all == NULL)
        return fail(msg, cap, "out of memory");
    for (size_t i = 0; i < n; i++)
        all[i] = i;
    int r = index_fetch(x, NULL, all, n, &db);
    free(all);
    x->mem = NULL;
    if (r != 0)
        return fail(msg, cap, "damaged shapes");
    amscr_db_free(x->db);
    x->db = db;
    return 0;
}

/* The blob of shape i into a new buffer. */
static unsigned char *read_blob(const tool_index *x, size_t i)
{
    unsigned char *b = malloc(x->blob_len[i] ? (size_t)x->blob_len[i] : 1);
    if (b == NULL)
        return NULL;
    if (x->mem) {
        memcpy(b, x->mem + x->blobs_at + x->blob_off[i], (size_t)x->blob_len[i]);
        return b;
    }
    FILE *fp = x->fp;
    if (fseek(fp, (long)(x->blobs_at + x->blob_off[i]), SEEK_SET) != 0 ||
        fread(b, 1, (size_t)x->blob_len[i], fp) != x->blob_len[i]) {
        free(b);
        return NULL;
    }
    return b;
}

int index_fetch(const tool_index *x, const amscr_params *p, const size_t *idx, size_t m, amscr_db **out)
{
    amscr_db *db = NULL;
    amscr_status st = amscr_db_new(p ? p : amscr_db_params(x->db), &db);
    for (size_t t = 0; st == AMSCR_OK && t < m; t++) {
        size_t i = idx[t];
        unsigned char *b = read_blob(x, i);
        amscr_db *one = NULL;
        st = b ? amscr_db_load_memory(b, (size_t)x->blob_len[i], &one) : AMSCR_E_IO;
        free(b);
        if (st == AMSCR_OK && (amscr_db_size(one) != 1 || amscr_db_label(one, 0) != x->coll.items[i].label))
            st = AMSCR_E_FORMAT;
        if (st == AMSCR_OK)
            st = amscr_db_add_descriptor(db, amscr_db_descriptor(one, 0), amscr_db_label(one, 0), NULL);
        amscr_db_free(one);
        if (st != AMSCR_OK)
            tool_error(x->coll.items[i].name, "damaged shape in the index (%s)", amscr_strerror(st));
    }
    if (st != AMSCR_OK) {
        amscr_db_free(db);
        return -1;
    }
    *out = db;
    return 0;
}

int index_file_is(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (fp == NULL)
        return 0;
    char m[8];
    int is = fread(m, 1, 8, fp) == 8 && memcmp(m, MAGIC, 8) == 0;
    fclose(fp);
    return is;
}

int index_load(const char *path, tool_index *out)
{
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "rb");
    if (fp == NULL) {
        tool_error(path, "cannot open the index");
        return -1;
    }
    size_t cap = 1 << 16, len = 0, got;
    unsigned char *buf = malloc(cap);
    while (buf != NULL && (got = fread(buf + len, 1, cap - len, fp)) > 0) {
        len += got;
        if (len == cap) {
            unsigned char *p = cap < ((size_t)1 << 40) ? realloc(buf, cap * 2) : NULL;
            if (p == NULL) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = p;
            cap *= 2;
        }
    }
    int err = ferror(fp);
    fclose(fp);
    if (buf == NULL || err) {
        free(buf);
        tool_error(path, buf == NULL ? "out of memory reading the index" : "read error");
        return -1;
    }
    char msg[300];
    int r = index_parse(buf, len, out, msg, sizeof msg);
    free(buf);
    if (r != 0) {
        index_free(out);
        tool_error(path, "%s", msg);
        return -1;
    }
    return 0;
}

int index_open_lazy(const char *path, tool_index *out)
{
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "rb");
    if (fp == NULL) {
        tool_error(path, "cannot open the index");
        return -1;
    }
    unsigned char head[32];
    char msg[300];
    long total = -1;
    if (fread(head, 1, sizeof head, fp) == sizeof head && fseek(fp, 0, SEEK_END) == 0)
        total = ftell(fp);
    rbuf r = {head, sizeof head, 24, 0};
    uint64_t mlen = r_u64(&r);
    unsigned char *buf = NULL;
    int ok = total >= 32 && mlen <= (uint64_t)total - 32 && (buf = malloc((size_t)(32 + mlen + 8))) != NULL &&
             fseek(fp, 0, SEEK_SET) == 0 && fread(buf, 1, (size_t)(32 + mlen + 8), fp) == 32 + mlen + 8;
    int rc = -1;
    msg[0] = '\0';
    if (ok)
        rc = parse_head(buf, (size_t)(32 + mlen + 8), (uint64_t)total, out, msg, sizeof msg);
    else if (total >= 0) /* shorter than its header says: the header parse names the problem */
        parse_head(head, (size_t)total < sizeof head ? (size_t)total : sizeof head, (uint64_t)total, out, msg,
                   sizeof msg);
    free(buf);
    if (rc != 0) {
        fclose(fp);
        index_free(out);
        tool_error(path, "%s", msg[0] ? msg : "truncated index");
        return -1;
    }
    out->fp = fp;
    return 0;
}

void index_free(tool_index *x)
{
    if (x->fp)
        fclose(x->fp);
    free(x->blob_off);
    free(x->blob_len);
    amscr_db_free(x->db);
    collection_free(&x->coll);
    free(x->sig);
    free(x->nb_idx);
    free(x->nb_dist);
    memset(x, 0, sizeof *x);
}

void index_signature(const amscr_descriptor *d, double *out)
{
    size_t n = amscr_descriptor_num_samples(d);
    /* under the affine group the whitened points (aspect and shear normalized away); else the
     * sampled input points, whose aspect tells shapes apart */
    int affine = amscr_params_get_invariance(amscr_descriptor_params(d)) == AMSCR_INVARIANCE_AFFINE;
    const double *p = affine ? amscr_descriptor_base_points(d) : amscr_descriptor_input_points(d);
    double cx = 0.0, cy = 0.0, mean = 0.0;
    for (size_t i = 0; i < n; i++) {
        cx += p[2 * i] / (double)n;
        cy += p[2 * i + 1] / (double)n;
    }
    for (size_t i = 0; i < n; i++)
        mean += hypot(p[2 * i] - cx, p[2 * i + 1] - cy) / (double)n;
    for (size_t h = 1; h <= INDEX_SIG_DIM; h++) { /* a DFT of the few harmonics kept: n * 24 terms */
        double re = 0.0, im = 0.0, w = 2.0 * 3.14159265358979323846 * (double)h / (double)n;
        for (size_t i = 0; i < n; i++) {
            double r = mean > 0.0 ? hypot(p[2 * i] - cx, p[2 * i + 1] - cy) / mean : 0.0;
            re += r * cos(w * (double)i);
            im -= r * sin(w * (double)i);
        }
        out[h - 1] = hypot(re, im) / (double)n;
    }
}
