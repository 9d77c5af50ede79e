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

int index_serialize(const tool_index *x, unsigned char **out, size_t *out_len)
{
    const collection *c = &x->coll;
    size_t n = c->n;
    wbuf w = {NULL, 0, 0, 0};
    void *blob = NULL;
    size_t blen = 0;
    if (amscr_db_save_memory(x->db, &blob, &blen) != AMSCR_OK) {
        tool_lib_error(NULL, AMSCR_E_NOMEM);
        return -1;
    }
    w_bytes(&w, MAGIC, 8);
    w_u32(&w, INDEX_VERSION);
    w_u32(&w, 0);
    w_u64(&w, n);
    w_u32(&w, (uint32_t)x->threshold);
    w_u32(&w, x->rerank_iters);
    w_u64(&w, x->k);
    w_f64(&w, x->dmax);
    w_u64(&w, c->nclasses);
    for (size_t i = 0; i < c->nclasses; i++)
        w_str(&w, c->classes[i]);
    w_u64(&w, c->ngroups);
    for (size_t i = 0; i < c->ngroups; i++)
        w_str(&w, c->groups[i]);
    for (size_t i = 0; i < n; i++) {
        w_str(&w, c->items[i].name);
        w_u32(&w, (uint32_t)c->items[i].label);
        w_u32(&w, (uint32_t)c->items[i].group);
    }
    w_u32(&w, INDEX_SIG_DIM);
    for (size_t i = 0; i < n * INDEX_SIG_DIM; i++)
        w_f64(&w, x->sig[i]);
    for (size_t i = 0; i < n * x->k; i++) {
        w_u32(&w, x->nb_idx[i]);
        w_f64(&w, x->nb_dist[i]);
    }
    w_u64(&w, blen);
    w_bytes(&w, blob, blen);
    amscr_free(blob);
    if (!w.oom)
        w_u64(&w, index_checksum(w.p, w.len));
    if (w.oom) {
        free(w.p);
        tool_error(NULL, "out of memory");
        return -1;
    }
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
    if (r->bad || r->len - r->pos < n) {
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

static int parse_items(rbuf *r, tool_index *x, size_t n)
{
    collection *c = &x->coll;
    c->items = xcalloc_array(n ? n : 1, sizeof(coll_item));
    if (c->items == NULL)
        return -1;
    c->n = n;
    for (size_t i = 0; i < n && !r->bad; i++) {
        coll_item *it = &c->items[i];
        it->name = r_str(r);
        it->path = it->name ? xstrdup(it->name) : NULL;
        it->label = (int32_t)r_u32(r);
        it->group = (int32_t)r_u32(r);
        if (it->path == NULL || it->label < 0 || (size_t)it->label >= c->nclasses || it->group < -1 ||
            (it->group >= 0 && (size_t)it->group >= c->ngroups) || (c->ngroups > 0) != (it->group >= 0))
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
    x->sig = xmalloc_array(n ? n * INDEX_SIG_DIM : 1, sizeof(double));
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
    return r->bad ? -1 : 0;
}

/* The db blob: loads, and agrees with the items. */
static int parse_db(rbuf *r, tool_index *x, size_t n, char *msg, size_t cap)
{
    uint64_t blen = r_u64(r);
    if (r->bad || blen != r->len - r->pos)
        return fail(msg, cap, "bad size of the prepared shapes");
    amscr_status st = amscr_db_load_memory(r->p + r->pos, (size_t)blen, &x->db);
    if (st != AMSCR_OK) {
        snprintf(msg, cap, "prepared shapes: %s", lib_detail()[0] ? lib_detail() : amscr_strerror(st));
        return -1;
    }
    if (amscr_db_size(x->db) != n)
        return fail(msg, cap, "the prepared shapes do not match the file list");
    for (size_t i = 0; i < n; i++)
        if (amscr_db_label(x->db, i) != x->coll.items[i].label)
            return fail(msg, cap, "the prepared shapes' classes do not match the file list");
    return 0;
}

int index_parse(const unsigned char *buf, size_t len, tool_index *x, char *msg, size_t cap)
{
    memset(x, 0, sizeof *x);
    if (len < 16 || memcmp(buf, MAGIC, 8) != 0)
        return fail(msg, cap, "not an amscr index (bad magic)");
    rbuf r = {buf, len, 8, 0};
    uint32_t version = r_u32(&r);
    if (version != INDEX_VERSION) {
        snprintf(msg, cap, "index format version %u; this amscr reads version %d (rebuild the index)",
                 (unsigned)version, INDEX_VERSION);
        return -1;
    }
    rbuf tail = {buf, len, len - 8, 0};
    if (len < 24 || index_checksum(buf, len - 8) != r_u64(&tail))
        return fail(msg, cap, "truncated or corrupt index (checksum mismatch)");
    r.len = len - 8; /* the checksum is not part of the sections */
    r.pos = 16;      /* past the reserved word */
    size_t n = r_count(&r, 13);
    x->threshold = (int32_t)r_u32(&r);
    x->rerank_iters = r_u32(&r);
    uint64_t k = r_u64(&r);
    x->dmax = r_f64(&r);
    if (r.bad || n == 0 || k > n || k > 100000 || !(x->dmax >= 0.0) || !isfinite(x->dmax) ||
        x->rerank_iters > 1000 || (x->threshold != AMSCR_THRESHOLD_AUTO && (x->threshold < 0 || x->threshold > 254)))
        return fail(msg, cap, "bad index header");
    x->k = (size_t)k;
    if (r_names(&r, &x->coll.classes, &x->coll.nclasses) != 0 || x->coll.nclasses == 0 ||
        r_names(&r, &x->coll.groups, &x->coll.ngroups) != 0)
        return fail(msg, cap, "bad class or group names");
    if (parse_items(&r, x, n) != 0)
        return fail(msg, cap, "bad file list");
    if (parse_tables(&r, x, n) != 0)
        return fail(msg, cap, "bad signatures or neighbour lists");
    return parse_db(&r, x, n, msg, cap);
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

void index_free(tool_index *x)
{
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
    const double *p = amscr_descriptor_base_points(d);
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
