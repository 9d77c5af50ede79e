/* index.c — the retrieval index object: allocation, the per-shape arrays, names, getters, and
 * the rules every index file shares: what an index with given params keeps (the channel's
 * frames, the inner distance's graph), which collections can be indexed, a shape's shortlist.
 * It calls no other index file. */
#include "db_io.h"
#include "index.h"

#include <stdlib.h>
#include <string.h>

/* Neighbour lists (*idx, *dist) grown to cap rows of k; 0 when out of memory (what grew kept). */
static int grow_lists(uint32_t **idx, double **dist, size_t cap, size_t k)
{
    uint32_t *ni = cap > SIZE_MAX / k / sizeof *ni ? NULL : realloc(*idx, cap * k * sizeof *ni);
    if (ni)
        *idx = ni;
    double *nd = cap > SIZE_MAX / k / sizeof *nd ? NULL : realloc(*dist, cap * k * sizeof *nd);
    if (nd)
        *dist = nd;
    return ni && nd;
}

/* The inner graph's arrays grown to cap rows (nothing without the graph); 0 when out of memory. */
static int reserve_inner(amscr_index *x, size_t cap)
{
    if (x->k2 == 0)
        return 1;
    amscr__inner *f = cap > SIZE_MAX / sizeof *f ? NULL : realloc(x->inner, cap * sizeof *f);
    if (f)
        x->inner = f;
    return grow_lists(&x->in_idx, &x->in_dist, cap, x->k2) && f;
}

amscr_status amscr__index_reserve(amscr_index *x, size_t n)
{
    if (n <= x->cap)
        return AMSCR_OK;
    size_t cap = x->cap ? x->cap : 64, k = x->k ? x->k : 1;
    while (cap < n)
        cap *= 2;
    uint16_t *sig = x->sig_dim && cap > SIZE_MAX / x->sig_dim / sizeof *sig
                        ? NULL
                        : realloc(x->sigq, cap * x->sig_dim * sizeof *sig);
    if (sig)
        x->sigq = sig;
    int32_t *sige = realloc(x->sige, cap * sizeof *sige);
    if (sige)
        x->sige = sige;
    float *lb = cap > SIZE_MAX / AMSCR__SIG_LB_DIM / sizeof *lb ? NULL
                                                                : realloc(x->sig_lb, cap * AMSCR__SIG_LB_DIM * sizeof *lb);
    if (lb)
        x->sig_lb = lb;
    size_t nf = x->nf > 0 ? (size_t)x->nf : 1;
    amscr__hf *hf = cap > SIZE_MAX / nf / sizeof *hf ? NULL : realloc(x->hf, cap * nf * sizeof *hf);
    if (hf) {
        x->hf = hf;
        memset(hf + x->cap * nf, 0, (cap - x->cap) * nf * sizeof *hf);
    }
    int lists_ok = grow_lists(&x->nb_idx, &x->nb_dist, cap, k);
    int inner_ok = reserve_inner(x, cap);
    char **nm = realloc(x->names, cap * sizeof *nm);
    if (nm) {
        x->names = nm;
        for (size_t i = x->cap; i < cap; i++)
            nm[i] = NULL;
    }
    char **gr = realloc(x->groups, cap * sizeof *gr);
    if (gr) {
        x->groups = gr;
        for (size_t i = x->cap; i < cap; i++)
            gr[i] = NULL;
    }
    if (!sig || !sige || !lb || !hf || !lists_ok || !inner_ok || !nm || !gr)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory for %zu shapes", n);
    x->cap = cap;
    return AMSCR_OK;
}

void amscr__index_take_lists(uint32_t **idx, double **dist, uint32_t **nidx, double **ndist, size_t keep)
{
    memcpy(*nidx, *idx, keep * sizeof **nidx);
    memcpy(*ndist, *dist, keep * sizeof **ndist);
    free(*idx);
    free(*dist);
    *idx = *nidx;
    *dist = *ndist;
    *nidx = NULL;
    *ndist = NULL;
}

int amscr__index_frames(const amscr_params *p)
{
    amscr_invariance frames[2];
    double share[2];
    return p->channel_weight > 0.0 ? amscr__channel_frames(p, frames, share) : 0;
}

size_t amscr__index_k2(const amscr_params *p, size_t k)
{
    return p->rerank_k > 0 && p->rerank_inner_share > 0.0 ? k : 0;
}

amscr_status amscr__index_check_db(const amscr_db *db, const char *what)
{
    const amscr_params *p = amscr_db_params(db);
    if (p->channel_weight > 0.0 && !p->closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: the shape channel needs closed curves; set the channel weight "
                                                "to 0 for open ones", what);
    if (amscr_db_size(db) > UINT32_MAX)
        return amscr__fail(AMSCR_E_LIMIT, "%s: %zu shapes exceed 2^32 - 1", what, amscr_db_size(db));
    return AMSCR_OK;
}

/* An empty index for db's params and size: on db itself (borrow) or on a copy of it. */
static amscr_status index_alloc(const amscr_db *db, int borrow, amscr_index **out)
{
    amscr_index *x = calloc(1, sizeof *x);
    if (!x)
        return amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    x->sig_dim = AMSCR__SIG_DIM;
    x->nf = amscr__index_frames(p);
    x->k = n > 0 ? amscr__rerank_k(p, n) : 0;
    x->k2 = amscr__index_k2(p, x->k);
    x->db_borrowed = borrow;
    amscr_status st = AMSCR_OK;
    if (borrow)
        x->db = (amscr_db *)(uintptr_t)db; /* never changed through x: see amscr__index_build_on */
    else
        st = amscr_db_new(p, &x->db);
    for (size_t i = 0; !borrow && st == AMSCR_OK && i < n; i++)
        st = amscr__db_add_from(x->db, db, i, amscr_db_label(db, i));
    if (st == AMSCR_OK)
        st = amscr__index_reserve(x, n);
    if (st != AMSCR_OK) {
        amscr_index_free(x);
        return st;
    }
    *out = x;
    return AMSCR_OK;
}

amscr_status amscr__index_alloc(const amscr_db *db, amscr_index **out) { return index_alloc(db, 0, out); }

amscr_status amscr__index_compact_db(amscr_index *x)
{
    amscr_db *c = NULL;
    amscr_status st = amscr__db_compact_copy(x->db, &c);
    if (st != AMSCR_OK)
        return st;
    if (!x->db_borrowed)
        amscr_db_free(x->db);
    x->db = c;
    x->db_borrowed = 0;
    return AMSCR_OK;
}

amscr_status amscr__index_alloc_on(const amscr_db *db, amscr_index **out) { return index_alloc(db, 1, out); }

void amscr__index_sig(const amscr_index *x, size_t i, float *out)
{
    amscr__sig_dequantize(x->sigq + i * x->sig_dim, x->sige[i], out);
}

void amscr__index_set_sig(amscr_index *x, size_t i, const float *sig)
{
    float kept[AMSCR__SIG_DIM];
    amscr__sig_quantize(sig, x->sigq + i * x->sig_dim, &x->sige[i]);
    amscr__index_sig(x, i, kept);
    amscr__sig_bound_vector(kept, x->sig_lb + i * AMSCR__SIG_LB_DIM);
}

size_t amscr__index_shortlist(const amscr_index *x, const float *sig, const float *lb, size_t m, size_t exclude,
                              size_t *cand)
{
    size_t n = amscr_db_size(x->db), avail = exclude < n ? n - 1 : n;
    if (m == 0 || m >= avail) {
        size_t c = 0;
        for (size_t j = 0; j < n; j++)
            if (j != exclude)
                cand[c++] = j;
        return c;
    }
    amscr__sig_rows rows = {NULL, x->sigq, x->sige};
    if (x->ivf.nc > 0 && x->ivf.n == n)
        return amscr__sig_ivf_nearest(&x->ivf, &rows, x->sig_lb, n, sig, lb, m, exclude, cand);
    return amscr__sig_nearest(&rows, x->sig_lb, n, sig, lb, m, exclude, cand);
}

void amscr__index_detach_map(amscr_index *x)
{
    for (size_t e = 0; x->map && x->hf && e < x->cap * (size_t)x->nf; e++)
        for (int o = 0; o < 2; o++)
            if ((uintptr_t)x->hf[e].seq[o] - (uintptr_t)x->map < x->map_len) /* points into the map */
                x->hf[e].seq[o] = NULL;
    x->map = NULL;
    x->map_len = 0;
}

void amscr__index_reverse_free(amscr_index *x)
{
    free(x->rev_start);
    free(x->rev);
    free(x->w_fixed);
    x->rev_start = NULL;
    x->rev = NULL;
    x->w_fixed = NULL;
}

void amscr_index_free(amscr_index *x)
{
    if (!x)
        return;
    if (x->map) {
        unsigned char *map = x->map;
        size_t len = x->map_len;
        amscr__index_detach_map(x);
        amscr__file_unmap(map, len, 1);
    }
    for (size_t i = 0; x->names && i < x->cap; i++)
        free(x->names[i]);
    for (size_t i = 0; x->groups && i < x->cap; i++)
        free(x->groups[i]);
    free(x->groups);
    for (size_t c = 0; c < x->nclasses; c++)
        free(x->classes[c]);
    free(x->names);
    free(x->classes);
    amscr__index_drop_mirrors(x, x->mirror_pool ? x->pool_first : amscr_db_size(x->db)); /* a failed build's */
    for (size_t i = 0; x->hf && i < x->cap * (size_t)x->nf; i++)
        amscr__hf_free(&x->hf[i]);
    free(x->hf);
    free(x->sigq);
    free(x->sige);
    free(x->sig_lb);
    amscr__sig_ivf_free(&x->ivf);
    free(x->nb_idx);
    free(x->nb_dist);
    free(x->inner);
    free(x->in_idx);
    free(x->in_dist);
    amscr__index_reverse_free(x);
    if (!x->db_borrowed)
        amscr_db_free(x->db);
    free(x);
}

size_t amscr_index_size(const amscr_index *x) { return x ? amscr_db_size(x->db) : 0; }
const amscr_db *amscr_index_db(const amscr_index *x) { return x ? x->db : NULL; }
int32_t amscr_index_label(const amscr_index *x, size_t i) { return x ? amscr_db_label(x->db, i) : 0; }
size_t amscr_index_neighbours(const amscr_index *x) { return x ? x->k : 0; }

const char *amscr_index_name(const amscr_index *x, size_t i)
{
    return (x && i < amscr_db_size(x->db)) ? x->names[i] : NULL;
}

const char *amscr_index_group(const amscr_index *x, size_t i)
{
    return (x && i < amscr_db_size(x->db)) ? x->groups[i] : NULL;
}

const char *amscr_index_class_name(const amscr_index *x, int32_t label)
{
    return (x && label >= 0 && (size_t)label < x->nclasses) ? x->classes[label] : NULL;
}

/* A copy of s (NULL for NULL) into *out; 0 when out of memory. */
static int dup_str(const char *s, char **out)
{
    *out = NULL;
    if (!s)
        return 1;
    size_t n = strlen(s);
    *out = malloc(n + 1);
    if (*out)
        memcpy(*out, s, n + 1);
    return *out != NULL;
}

amscr_status amscr_index_set_name(amscr_index *x, size_t i, const char *name)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    if (i >= amscr_db_size(x->db))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_set_name: shape %zu of %zu", i, amscr_db_size(x->db));
    char *s = NULL;
    if (!dup_str(name, &s))
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_set_name: out of memory");
    free(x->names[i]);
    x->names[i] = s;
    return AMSCR_OK;
}

amscr_status amscr_index_set_group(amscr_index *x, size_t i, const char *group)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    if (i >= amscr_db_size(x->db))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_set_group: shape %zu of %zu", i, amscr_db_size(x->db));
    char *s = NULL;
    if (!dup_str(group, &s))
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_set_group: out of memory");
    free(x->groups[i]);
    x->groups[i] = s;
    return AMSCR_OK;
}

amscr_status amscr_index_set_class_name(amscr_index *x, int32_t label, const char *name)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    if (label < 0 || label > 1000000)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_set_class_name: label %d is outside 0..1000000",
                           (int)label);
    char *s = NULL;
    if (!dup_str(name, &s))
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_set_class_name: out of memory");
    if ((size_t)label >= x->nclasses) {
        char **c = realloc(x->classes, ((size_t)label + 1) * sizeof *c);
        if (!c) {
            free(s);
            return amscr__fail(AMSCR_E_NOMEM, "amscr_index_set_class_name: out of memory");
        }
        for (size_t t = x->nclasses; t <= (size_t)label; t++)
            c[t] = NULL;
        x->classes = c;
        x->nclasses = (size_t)label + 1;
    }
    free(x->classes[label]);
    x->classes[label] = s;
    return AMSCR_OK;
}

size_t amscr_index_default_candidates(size_t n)
{
    return n <= AMSCR_INDEX_EXACT_MAX ? 0 : AMSCR_INDEX_CANDIDATES;
}
