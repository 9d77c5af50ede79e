/* index_io.c — the index file: a collection file (db_io.c) of version 16 (15 and 14 in 0.14, 13 in 0.11 to 0.13, 11
 * in 0.9, 9 in 0.8, 8 in 0.7, 6 in 0.6, 4 in 0.5, 3 in 0.4) whose index section follows the
 * shapes, so amscr_db_load of an index file gives its collection. From version 14 the shapes are
 * compact records (their input samples and outline: db_io.h), which the index keeps as they are
 * (decoded when read); the section is version 13's.
 * Little-endian:
 *   u64 section length (the bytes up to the trailing checksum), then
 *   u32 sig_dim, u32 4 (bytes of a signature value), u64 k, u64 candidates (0: full lists),
 *   f64 dmax, f64 median AMSCR, f64 median channel, n x sig_dim f32 signatures (signature.h),
 *   n x k x (u32 neighbour, f64 distance)
 *   (each row: itself first, then by distance), n names, u64 nclasses, nclasses class names
 *   (string: u32 length and bytes, 0xffffffff for none), then
 *   version 3: when a shape has a group, n group names (absent: no shape has one);
 *   versions 4, 6 and 8: u32 1 and n group names, or u32 0 (no shape has one); then the channel
 *     features: u32 frames F (0: no channel), u32 samples N, u32 bins B (AMSCR__HF_BINS), and
 *     per shape, per frame, its quantized height sequences (channel.h), forward then mirrored:
 *     2 N B bytes (F = 2, N = 128: 8 KB a shape); from version 16 the forward one only (N B
 *     bytes, 4 KB a shape: a load makes the mirrored one from the shape's input samples);
 *   versions 9, 11 and 13: then the inner distance's graph: u32 K2 (0: none; else K, when the params give it a
 *     share), f64 its largest distance, n x K2 x (u32 neighbour, f64 distance) as the lists above,
 *     and per shape its inner features (inner.h): F K f64 re, F K f64 im, f64 norm2 (8.7 KB a
 *     shape; the reversed orientation's twist is recomputed); from version 15 re and im are F K
 *     f32 each (4.4 KB a shape); from version 16 f64 scale, then re and im as F K i16 each in
 *     units of the scale, norm2 recomputed from them (2.2 KB a shape: the features as an index
 *     holds them in memory, inner.h; an older file's values are rounded so at load);
 *   version 16: then the coarse quantizer of the signatures (write_quantizer below).
 * Every count is bounded by the bytes left before anything is allocated; F, N and B must be the
 * params' (any byte is a valid height). The features' spectra are not stored: a load computes
 * them from the heights (an FFT, a fifth of building the features), or, with AMSCR_INDEX_LAZY,
 * a query computes those of its candidates. A lazy load of a file also leaves the prepared
 * shapes in the mapped file (checked as a decode would, db_io.c): each is decoded when first
 * read (a fused query's candidates, a member query, a save, an add, the collection's calls), so a
 * channel-only query decodes none. A version 3 file has no features: they are
 * rebuilt from the shapes (index_features.c). */
#include "db_io.h"
#include "index.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void write_section(const amscr_index *x, amscr__wbuf *w)
{
    size_t n = amscr_db_size(x->db), k = x->k;
    amscr__w_u32(w, (uint32_t)x->sig_dim);
    amscr__w_u32(w, (uint32_t)sizeof(float));
    amscr__w_u64(w, k);
    amscr__w_u64(w, x->candidates);
    amscr__w_f64(w, x->dmax);
    amscr__w_f64(w, x->med_a);
    amscr__w_f64(w, x->med_h);
    for (size_t i = 0; i < n; i++) { /* the 16-bit values as floats (exact) */
        float sig[AMSCR__SIG_DIM];
        amscr__index_sig(x, i, sig);
        amscr__w_f32s(w, sig, AMSCR__SIG_DIM);
    }
    for (size_t i = 0; i < n * k; i++) {
        amscr__w_u32(w, x->nb_idx[i]);
        amscr__w_f64(w, x->nb_dist[i]);
    }
    for (size_t i = 0; i < n; i++)
        amscr__w_str(w, x->names[i]);
    amscr__w_u64(w, x->nclasses);
    for (size_t c = 0; c < x->nclasses; c++)
        amscr__w_str(w, x->classes[c]);
    int groups = 0;
    for (size_t i = 0; i < n && !groups; i++)
        groups = x->groups[i] != NULL;
    amscr__w_u32(w, (uint32_t)groups);
    for (size_t i = 0; groups && i < n; i++)
        amscr__w_str(w, x->groups[i]);
}

/* The channel features: every shape's height sequences (built here where a lazy load left
 * them unbuilt). */
static amscr_status write_features(const amscr_index *x, uint32_t version, amscr__wbuf *w)
{
    size_t n = amscr_db_size(x->db), N = amscr_db_params(x->db)->num_samples, bytes = N * AMSCR__HF_BINS;
    amscr__w_u32(w, (uint32_t)x->nf);
    amscr__w_u32(w, (uint32_t)N);
    amscr__w_u32(w, AMSCR__HF_BINS);
    amscr__base b;
    amscr__base_init(&b, amscr_db_params(x->db), x->med_a, x->med_h);
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; i < n && x->nf > 0 && st == AMSCR_OK; i++) {
        const amscr__hf *hf = x->hf + i * (size_t)x->nf;
        amscr__hf built[2];
        int orients = version >= AMSCR__DB_VERSION_INDEX_I16 ? 1 : 2; /* from 16: the forward one */
        int build = hf[0].seq[0] == NULL || (orients == 2 && hf[0].seq[1] == NULL);
        const amscr_descriptor *d = NULL;
        if (build)
            st = amscr__db_shape(x->db, i, &d);
        if (build && st == AMSCR_OK)
            st = amscr__base_hf(&b, d, built);
        if (st != AMSCR_OK)
            break;
        for (int f = 0; f < x->nf; f++)
            for (int o = 0; o < orients; o++)
                amscr__w_bytes(w, (build ? built : hf)[f].seq[o], bytes);
        if (build)
            amscr__base_hf_free(&b, built);
    }
    return st;
}

/* The inner distance's graph (version 9). */
static void write_inner(const amscr_index *x, uint32_t version, amscr__wbuf *w)
{
    size_t fk = AMSCR__INNER_F * AMSCR__INNER_K;
    size_t n = amscr_db_size(x->db), k2 = x->k2;
    amscr__w_u32(w, (uint32_t)k2);
    if (k2 == 0)
        return;
    amscr__w_f64(w, x->dmax2);
    for (size_t i = 0; i < n * k2; i++) {
        amscr__w_u32(w, x->in_idx[i]);
        amscr__w_f64(w, x->in_dist[i]);
    }
    for (size_t i = 0; i < n; i++) {
        const amscr__inner *f = &x->inner[i];
        const int16_t *v = &f->re[0][0];
        if (version >= AMSCR__DB_VERSION_INDEX_I16) {
            amscr__w_f64(w, f->scale);
            for (size_t j = 0; j < 2 * fk; j++) { /* re, then im */
                uint16_t u = (uint16_t)v[j];
                unsigned char b2[2] = {(unsigned char)(u & 0xff), (unsigned char)(u >> 8)};
                amscr__w_bytes(w, b2, 2);
            }
            continue;
        }
        for (size_t j = 0; j < 2 * fk; j++) /* the values as they are held: exact in float32 and f64 */
            if (version >= AMSCR__DB_VERSION_INDEX_F32) {
                float u = (float)(v[j] * f->scale);
                amscr__w_f32s(w, &u, 1);
            } else {
                amscr__w_f64(w, v[j] * f->scale);
            }
        amscr__w_f64(w, f->norm2);
    }
}

/* ------------------------------------------- the coarse quantizer (version 16; signature.h)
 * After the inner graph: u32 lists L (0: none: every bound scanned), then, when L > 0, u32 D
 * (AMSCR__SIG_LB_DIM), L x D f32 centroids and n u32, each shape's list (< L); a load rebuilds
 * the lists from them (the quantizer of a shortlist build of AMSCR__INDEX_IVF_MIN shapes or
 * more, kept for its queries: 4 bytes a shape, 1 KB a list). */
static void write_quantizer(const amscr_index *x, amscr__wbuf *w)
{
    size_t n = amscr_db_size(x->db);
    int have = x->ivf.nc > 0 && x->ivf.n == n;
    amscr__w_u32(w, have ? (uint32_t)x->ivf.nc : 0u);
    if (!have)
        return;
    amscr__w_u32(w, AMSCR__SIG_LB_DIM);
    amscr__w_f32s(w, x->ivf.cent, x->ivf.nc * AMSCR__SIG_LB_DIM);
    for (size_t i = 0; i < n; i++)
        amscr__w_u32(w, x->ivf.cell[i]);
}

static amscr_status read_quantizer(amscr__rbuf *r, amscr_index *x)
{
    size_t n = amscr_db_size(x->db);
    uint32_t nc = amscr__r_u32(r), dim = nc > 0 ? amscr__r_u32(r) : AMSCR__SIG_LB_DIM;
    if (r->bad)
        return amscr__fail(AMSCR_E_FORMAT, "index file: the quantizer is truncated");
    if (nc == 0)
        return AMSCR_OK;
    if (dim != AMSCR__SIG_LB_DIM || nc > n)
        return amscr__fail(AMSCR_E_FORMAT, "index file: a quantizer of %u lists of dimension %u for %zu shapes",
                           (unsigned)nc, (unsigned)dim, n);
    if (((uint64_t)nc * AMSCR__SIG_LB_DIM + n) * 4u > r->len - r->pos)
        return amscr__fail(AMSCR_E_FORMAT, "index file: the quantizer is truncated");
    amscr__sig_ivf *v = &x->ivf;
    v->nc = nc;
    v->n = n;
    v->cent = amscr__malloc_array(nc, AMSCR__SIG_LB_DIM * sizeof *v->cent);
    v->cell = amscr__malloc_array(n ? n : 1, sizeof *v->cell);
    if (!v->cent || !v->cell) {
        amscr__sig_ivf_free(v);
        return amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
    }
    int ok = amscr__r_f32s(r, v->cent, (size_t)nc * AMSCR__SIG_LB_DIM); /* finite */
    for (size_t i = 0; ok && i < n; i++) {
        v->cell[i] = amscr__r_u32(r);
        ok = !r->bad && v->cell[i] < nc;
    }
    if (!ok || r->bad) {
        amscr__sig_ivf_free(v);
        return amscr__fail(AMSCR_E_FORMAT, "index file: a quantizer centroid is not finite or a list is out of range");
    }
    if (!amscr__sig_ivf_lists(v)) {
        amscr__sig_ivf_free(v);
        return amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
    }
    return AMSCR_OK;
}

amscr_status amscr__index_write(const amscr_index *x, uint32_t version, void **out_buf, size_t *out_len)
{
    amscr_status st = AMSCR_OK;
    amscr__wbuf w = {NULL, 0, 0, 0}; /* a lazy load's shapes: none decoded and kept (db_io.c) */
    st = amscr__db_write(x->db, version, &w);
    size_t at = w.len;
    amscr__w_u64(&w, 0); /* the section's length, filled in below */
    write_section(x, &w);
    if (st == AMSCR_OK)
        st = write_features(x, version, &w);
    if (st == AMSCR_OK)
        write_inner(x, version, &w);
    if (st == AMSCR_OK && version >= AMSCR__DB_VERSION_INDEX_I16)
        write_quantizer(x, &w);
    if (st != AMSCR_OK) {
        free(w.buf);
        return st;
    }
    if (!w.oom) {
        uint64_t sec = (uint64_t)(w.len - at - 8);
        for (int i = 0; i < 8; i++)
            w.buf[at + (size_t)i] = (unsigned char)(sec >> (8 * i));
        amscr__w_u64(&w, amscr__db_checksum(version, w.buf, w.len));
    }
    if (w.oom) {
        free(w.buf);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_save: out of memory");
    }
    *out_buf = w.buf;
    *out_len = w.len;
    return AMSCR_OK;
}

amscr_status amscr_index_save_memory(const amscr_index *x, void **out_buf, size_t *out_len)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(out_buf);
    AMSCR_CHECK_NULL(out_len);
    return amscr__index_write(x, AMSCR__DB_VERSION_NEWEST, out_buf, out_len);
}

amscr_status amscr_index_save(const amscr_index *x, const char *path)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(path);
    void *buf = NULL;
    size_t len = 0;
    amscr_status st = amscr_index_save_memory(x, &buf, &len);
    if (st == AMSCR_OK)
        st = amscr__file_write_atomic(path, buf, len);
    free(buf);
    return st;
}

/* The fixed header of the section into x; the sizes checked against the collection. */
static amscr_status read_header(amscr__rbuf *r, amscr_index *x)
{
    const amscr_params *p = amscr_db_params(x->db);
    size_t n = amscr_db_size(x->db);
    uint32_t sig_dim = amscr__r_u32(r), sig_bytes = amscr__r_u32(r);
    uint64_t k = amscr__r_u64(r), m = amscr__r_u64(r);
    x->dmax = amscr__r_f64(r);
    x->med_a = amscr__r_f64(r);
    x->med_h = amscr__r_f64(r);
    if (r->bad)
        return amscr__fail(AMSCR_E_FORMAT, "index file: the index section is truncated");
    if (sig_dim != AMSCR__SIG_DIM || sig_bytes != sizeof(float))
        return amscr__fail(AMSCR_E_FORMAT, "index file: signatures of dimension %u (%u bytes a value), this "
                                           "library's have %u (%u); rebuild the index", (unsigned)sig_dim,
                           (unsigned)sig_bytes, (unsigned)AMSCR__SIG_DIM, (unsigned)sizeof(float));
    size_t k05 = p->rerank_k < n ? p->rerank_k : n; /* the rule of 0.5's files */
    if ((k != amscr__rerank_k(p, n) && k != k05) || (m != 0 && m + 1 >= n))
        return amscr__fail(AMSCR_E_FORMAT, "index file: %llu neighbours or %llu candidates do not fit %zu shapes "
                                           "with re-ranking k %u", (unsigned long long)k, (unsigned long long)m, n,
                           p->rerank_k);
    if (!(x->dmax >= 0.0 && x->med_a >= 0.0 && x->med_h >= 0.0 && isfinite(x->dmax) && isfinite(x->med_a) &&
          isfinite(x->med_h)))
        return amscr__fail(AMSCR_E_FORMAT, "index file: bad largest distance or medians");
    x->k = (size_t)k;
    x->k2 = amscr__index_k2(p, x->k);
    x->candidates = (size_t)m;
    uint64_t need = (uint64_t)n * (4u * sig_dim + 12u * k);
    if ((n && need / n != 4u * sig_dim + 12u * k) || need > r->len - r->pos) /* an empty index: need 0 */
        return amscr__fail(AMSCR_E_FORMAT, "index file: the index section is truncated");
    return amscr__index_reserve(x, n);
}

/* n lists of k (neighbour, distance) into idx, dist: row i itself first, then by distance. */
static amscr_status read_list(amscr__rbuf *r, size_t n, size_t k, uint32_t *idx, double *dist, const char *what)
{
    for (size_t i = 0; i < n; i++)
        for (size_t t = 0; t < k; t++) {
            uint32_t j = amscr__r_u32(r);
            double d = amscr__r_f64(r);
            if (r->bad || j >= n || (t == 0) != (j == i) || !(d >= 0.0) || !isfinite(d) ||
                (t > 0 && d < dist[i * k + t - 1]))
                return amscr__fail(AMSCR_E_FORMAT, "index file: shape %zu's %sneighbour %zu is invalid", i, what, t);
            idx[i * k + t] = j;
            dist[i * k + t] = d;
        }
    return AMSCR_OK;
}

/* Signatures and neighbour lists. */
static amscr_status read_lists(amscr__rbuf *r, amscr_index *x)
{
    size_t n = amscr_db_size(x->db);
    for (size_t i = 0; i < n; i++) { /* kept in 16 bits: the values this release writes, exactly */
        float sig[AMSCR__SIG_DIM];
        if (!amscr__r_f32s(r, sig, AMSCR__SIG_DIM))
            return amscr__fail(AMSCR_E_FORMAT, "index file: a signature is not finite");
        for (size_t t = 0; t < AMSCR__SIG_DIM; t++)
            if (sig[t] < 0.0f)
                return amscr__fail(AMSCR_E_FORMAT, "index file: a signature value is negative");
        amscr__index_set_sig(x, i, sig);
    }
    return read_list(r, n, x->k, x->nb_idx, x->nb_dist, "");
}

/* Shape names and class names, then the groups (version 3: when bytes are left). */
static amscr_status read_names(amscr__rbuf *r, amscr_index *x, uint32_t version)
{
    size_t n = amscr_db_size(x->db);
    int oom = 0;
    for (size_t i = 0; i < n; i++)
        if (!amscr__r_str(r, &x->names[i], &oom))
            return oom ? amscr__fail(AMSCR_E_NOMEM, "index file: out of memory")
                       : amscr__fail(AMSCR_E_FORMAT, "index file: shape %zu's name is truncated or invalid", i);
    uint64_t nc = amscr__r_u64(r);
    if (r->bad || nc > (r->len - r->pos) / 4)
        return amscr__fail(AMSCR_E_FORMAT, "index file: bad class count");
    x->classes = nc ? calloc((size_t)nc, sizeof *x->classes) : NULL;
    if (nc && !x->classes)
        return amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
    x->nclasses = (size_t)nc;
    for (size_t c = 0; c < x->nclasses; c++)
        if (!amscr__r_str(r, &x->classes[c], &oom))
            return oom ? amscr__fail(AMSCR_E_NOMEM, "index file: out of memory")
                       : amscr__fail(AMSCR_E_FORMAT, "index file: class name %zu is truncated or invalid", c);
    uint32_t groups = amscr__db_has_features(version) ? amscr__r_u32(r) : r->pos < r->len;
    if (r->bad || groups > 1)
        return amscr__fail(AMSCR_E_FORMAT, "index file: bad groups flag");
    for (size_t i = 0; groups && i < n; i++) /* the groups, when a shape has one */
        if (!amscr__r_str(r, &x->groups[i], &oom))
            return oom ? amscr__fail(AMSCR_E_NOMEM, "index file: out of memory")
                       : amscr__fail(AMSCR_E_FORMAT, "index file: shape %zu's group is truncated or invalid", i);
    return AMSCR_OK;
}

/* The channel features of a version 4, 6 or 8 file: each shape's height sequences (index.h's x->hf,
 * their spectra not yet computed). */
static amscr_status read_features(amscr__rbuf *r, amscr_index *x, uint32_t version)
{
    size_t n = amscr_db_size(x->db), N = amscr_db_params(x->db)->num_samples;
    uint32_t nf = amscr__r_u32(r), ns = amscr__r_u32(r), bins = amscr__r_u32(r);
    if (r->bad || nf != (uint32_t)x->nf || ns != N || bins != AMSCR__HF_BINS)
        return amscr__fail(AMSCR_E_FORMAT, "index file: channel features of %u frames, %u samples, %u bins; the "
                                           "params give %d, %zu, %d", (unsigned)nf, (unsigned)ns, (unsigned)bins,
                           x->nf, N, AMSCR__HF_BINS);
    int orients = version >= AMSCR__DB_VERSION_INDEX_I16 ? 1 : 2; /* from 16: the forward one */
    size_t bytes = N * AMSCR__HF_BINS, per = (size_t)orients * nf * bytes;
    if (per > 0 && (r->len - r->pos) / per < n)
        return amscr__fail(AMSCR_E_FORMAT, "index file: the channel features are truncated");
    for (size_t e = 0; e < n * nf; e++) {
        amscr__hf *h = &x->hf[e];
        amscr__hf_free(h);
        h->n = N;
        h->nfreq = AMSCR__HF_FREQS(N) + 1;
        for (int o = 0; o < orients; o++) {
            h->seq[o] = x->map ? (uint8_t *)(x->map + r->pos) : malloc(bytes); /* mapped: read in place */
            if (!h->seq[o])
                return amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
            if (!x->map)
                memcpy(h->seq[o], r->p + r->pos, bytes);
            r->pos += bytes;
        }
    }
    return AMSCR_OK;
}

/* The inner distance's graph of a file of version 9 or later (its K2 must be the params'): the
 * features of a file before version 16 (float32 or double values) rounded as a build rounds them. */
static amscr_status read_inner(amscr__rbuf *r, amscr_index *x, uint32_t version)
{
    int f32 = version >= AMSCR__DB_VERSION_INDEX_F32, i16 = version >= AMSCR__DB_VERSION_INDEX_I16;
    size_t n = amscr_db_size(x->db), fk = AMSCR__INNER_F * AMSCR__INNER_K;
    uint32_t k2 = amscr__r_u32(r);
    if (r->bad || k2 != x->k2)
        return amscr__fail(AMSCR_E_FORMAT, "index file: an inner graph of %u neighbours a shape; the params give %zu",
                           (unsigned)k2, x->k2);
    if (k2 == 0)
        return AMSCR_OK;
    x->dmax2 = amscr__r_f64(r);
    if (r->bad || !(x->dmax2 >= 0.0) || !isfinite(x->dmax2))
        return amscr__fail(AMSCR_E_FORMAT, "index file: bad largest inner distance");
    size_t per = 12 * (size_t)k2 + (i16 ? 2 * 2 * fk + 8 : (f32 ? 4 : 8) * 2 * fk + 8);
    if ((r->len - r->pos) / per < n)
        return amscr__fail(AMSCR_E_FORMAT, "index file: the inner graph is truncated");
    amscr_status st = read_list(r, n, k2, x->in_idx, x->in_dist, "inner ");
    double(*v)[AMSCR__INNER_F][AMSCR__INNER_K] = malloc(2 * sizeof *v);
    if (st == AMSCR_OK && !v)
        st = amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
    for (size_t i = 0; st == AMSCR_OK && i < n; i++) {
        amscr__inner *f = &x->inner[i];
        int ok = 1;
        if (i16) {
            double scale = amscr__r_f64(r), sum = 0.0;
            int16_t *q = &f->re[0][0];
            for (size_t j = 0; j < 2 * fk; j++, r->pos += 2)
                q[j] = (int16_t)(uint16_t)(r->p[r->pos] | (unsigned)r->p[r->pos + 1] << 8);
            for (size_t j = 0; j < 2 * fk; j++) /* the norm as a build computes it */
                sum += ((j % fk) / AMSCR__INNER_K == 0 ? 1.0 : 2.0) * ((double)q[j] * q[j]);
            ok = !r->bad && scale >= 0.0 && scale <= FLT_MAX;
            f->scale = scale;
            f->norm2 = sum * scale * scale / (double)AMSCR__INNER_N;
        } else {
            double *d = &v[0][0][0], norm2 = 0.0;
            for (size_t j = 0; j < 2 * fk && ok; j++) {
                float u = 0.0f;
                ok = f32 ? amscr__r_f32s(r, &u, 1) : amscr__r_f64s(r, &d[j], 1);
                if (f32)
                    d[j] = u;
                ok = ok && fabs(d[j]) <= FLT_MAX;
            }
            ok = ok && amscr__r_f64s(r, &norm2, 1) && norm2 >= 0.0 && amscr__inner_quantize(f, &v[0][0][0]);
        }
        if (!ok)
            st = amscr__fail(AMSCR_E_FORMAT, "index file: shape %zu's inner features are invalid", i);
    }
    free(v);
    return st;
}

/* What follows the names: the features (versions 4, 6, 8, 9 and 11), the inner graph (9, 11), then
 * nothing. */
static amscr_status read_rest(amscr__rbuf *r, amscr_index *x, uint32_t version)
{
    amscr_status st = amscr__db_has_features(version) ? read_features(r, x, version) : AMSCR_OK;
    if (st == AMSCR_OK && version >= AMSCR__DB_VERSION_INDEX_GRAPHS)
        st = read_inner(r, x, version);
    else if (st == AMSCR_OK && x->k2 > 0)
        st = amscr__fail(AMSCR_E_FORMAT, "index file: format %u has no inner graph, its params give one",
                         (unsigned)version);
    if (st == AMSCR_OK && version >= AMSCR__DB_VERSION_INDEX_I16)
        st = read_quantizer(r, x);
    if (st == AMSCR_OK && r->pos != r->len)
        st = amscr__fail(AMSCR_E_FORMAT, "index file: %zu unexpected bytes after the index section",
                         r->len - r->pos);
    return st;
}

static amscr_status check_flags(unsigned flags, const char *what)
{
    if (flags & ~(unsigned)AMSCR_INDEX_LAZY)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: unknown flags 0x%x", what, flags & ~(unsigned)AMSCR_INDEX_LAZY);
    return AMSCR_OK;
}

/* The index in buf; map: buf is the file mapped for this load, which a lazy load keeps (the
 * index unmaps it) and reads the heights from in place. */
static amscr_status load_memory(const void *buf, size_t len, unsigned flags, int map, amscr_index **out)
{
    amscr_db *db = NULL;
    size_t pos = 0;
    uint32_t version = 0;
    int lazy = map && (flags & AMSCR_INDEX_LAZY); /* the shapes decoded from the kept mapping when needed */
    const unsigned char *b = buf;
    uint32_t v0 = len >= 12 ? (uint32_t)b[8] | (uint32_t)b[9] << 8 | (uint32_t)b[10] << 16 | (uint32_t)b[11] << 24 : 0;
    /* compact records stay records (checked now, decoded when read) */
    amscr_status st = amscr__db_parse(buf, len, lazy || amscr__db_compact(v0), &db, &pos, &version);
    if (st != AMSCR_OK)
        return st;
    amscr_index *x = calloc(1, sizeof *x);
    if (!x) {
        amscr_db_free(db);
        return amscr__fail(AMSCR_E_NOMEM, "index file: out of memory");
    }
    x->db = db;
    x->sig_dim = AMSCR__SIG_DIM;
    x->nf = amscr__index_frames(amscr_db_params(db));
    x->lazy = (flags & AMSCR_INDEX_LAZY) != 0;
    if (map && x->lazy) {
        x->map = (unsigned char *)(uintptr_t)buf;
        x->map_len = len;
    }
    amscr__rbuf r = {buf, len - 8, pos, 0};
    uint64_t sec = amscr__db_is_index(version) ? amscr__r_u64(&r) : 0;
    if (!amscr__db_is_index(version))
        st = amscr__fail(AMSCR_E_FORMAT, "a collection file without an index (format version %u): build an index "
                                         "of it (amscr_index_build of amscr_db_load's collection; Python "
                                         "amscr.Index(amscr.Collection.load(FILE)).save(OUT); `amscr index` of "
                                         "the folder or manifest of its shapes)",
                         (unsigned)version);
    else if (r.bad || sec != r.len - r.pos)
        st = amscr__fail(AMSCR_E_FORMAT, "index file: bad index section length");
    if (st == AMSCR_OK)
        st = amscr__index_check_db(db, "index file");
    if (st == AMSCR_OK)
        st = read_header(&r, x);
    if (st == AMSCR_OK)
        st = read_lists(&r, x);
    if (st == AMSCR_OK)
        st = read_names(&r, x, version);
    if (st == AMSCR_OK)
        st = read_rest(&r, x, version);
    if (st == AMSCR_OK)
        st = amscr__index_features(x, 0, 1, NULL, NULL);
    if (st == AMSCR_OK && !x->map) /* the shapes kept as the file's compact records (an older file's decoded) */
        st = amscr__db_own_source(x->db);
    if (st != AMSCR_OK) {
        amscr__index_detach_map(x); /* the caller unmaps */
        amscr_index_free(x);
        return st;
    }
    *out = x;
    return AMSCR_OK;
}

amscr_status amscr_index_load_memory_with(const void *buf, size_t len, unsigned flags, amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(buf);
    AMSCR_CHECK_NULL(out);
    amscr_status st = check_flags(flags, "amscr_index_load_memory_with");
    return st == AMSCR_OK ? load_memory(buf, len, flags, 0, out) : st;
}

amscr_status amscr_index_load_memory(const void *buf, size_t len, amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(buf);
    AMSCR_CHECK_NULL(out);
    return load_memory(buf, len, 0, 0, out);
}

amscr_status amscr__index_load_mapped(unsigned char *buf, size_t len, unsigned flags, amscr_index **out)
{
    amscr_status st = load_memory(buf, len, flags, 1, out);
    if (st != AMSCR_OK || !(*out)->map) /* else the index keeps the mapping */
        amscr__file_unmap(buf, len, 1);
    return st;
}

/* amscr_index_load_with after its arguments' checks. */
static amscr_status load_file(const char *path, unsigned flags, amscr_index **out)
{
    unsigned char *buf = NULL;
    size_t len = 0;
    int mapped = 0;
    amscr_status st = amscr__file_map(path, &buf, &len, &mapped);
    if (st != AMSCR_OK)
        return st;
    st = mapped ? amscr__index_load_mapped(buf, len, flags, out) : load_memory(buf, len, flags, 0, out);
    if (st != AMSCR_OK) {
        char d[400];
        snprintf(d, sizeof d, "%s", amscr_last_error_detail());
        amscr__fail(st, "%s: %s", path, d);
    }
    if (!mapped)
        free(buf);
    return st;
}

amscr_status amscr_index_load_with(const char *path, unsigned flags, amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(path);
    AMSCR_CHECK_NULL(out);
    amscr_status st = check_flags(flags, "amscr_index_load_with");
    return st == AMSCR_OK ? load_file(path, flags, out) : st;
}

amscr_status amscr_index_load(const char *path, amscr_index **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(path);
    AMSCR_CHECK_NULL(out);
    return load_file(path, 0, out);
}
