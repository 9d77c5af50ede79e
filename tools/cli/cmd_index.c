/* cmd_index.c — `amscr index COLLECTION -o FILE [--add]`: the prepared collection with what
 * query-time re-ranking needs (index_file.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "collection.h"
#include "index_build.h"
#include "index_dist.h"
#include "index_file.h"
#include "cmd_params.h"
#include "shape_db.h"

typedef struct nb_t {
    double d;
    size_t j;
} nb_t;

static int cmp_nb(const void *a, const void *b)
{
    const nb_t *x = a, *y = b;
    if (x->d != y->d)
        return x->d < y->d ? -1 : 1;
    return x->j < y->j ? -1 : (x->j > y->j);
}

void knn_select(size_t i, const size_t *cj, const double *cd, size_t m, size_t k, uint32_t *out_idx,
                double *out_dist)
{
    nb_t *row = malloc((m + 1) * sizeof *row);
    size_t r = 0;
    if (row == NULL) { /* callers check k <= m; fall back to the self-only row */
        for (size_t t = 0; t < k; t++) {
            out_idx[t] = (uint32_t)i;
            out_dist[t] = 0.0;
        }
        return;
    }
    row[r++] = (nb_t){-1.0, i}; /* itself first, as amscr_rerank_diffusion */
    for (size_t t = 0; t < m; t++)
        if (cj[t] != i)
            row[r++] = (nb_t){cd[t], cj[t]};
    qsort(row, r, sizeof *row, cmp_nb);
    for (size_t t = 0; t < k; t++) {
        out_idx[t] = (uint32_t)row[t < r ? t : r - 1].j;
        out_dist[t] = t == 0 ? 0.0 : row[t < r ? t : r - 1].d;
    }
    free(row);
}

/* Signatures of shapes from..n-1 of the db. */
int index_signatures_from(tool_index *x, size_t from)
{
    size_t n = amscr_db_size(x->db);
    double *s = realloc(x->sig, n * INDEX_SIG_DIM * sizeof *s);
    if (s == NULL) {
        tool_error(NULL, "out of memory");
        return -1;
    }
    x->sig = s;
    for (size_t i = from; i < n; i++)
        index_signature(amscr_db_descriptor(x->db, i), s + i * INDEX_SIG_DIM);
    return 0;
}

/* The neighbour lists of every shape from the full n x n matrix d (symmetrized). */
static int knn_from_matrix(tool_index *x, const double *d, size_t n)
{
    size_t k = x->k, *cj = xmalloc_array(n, sizeof(size_t));
    double *cd = xmalloc_array(n, sizeof(double));
    x->nb_idx = xmalloc_array(n * k > 0 ? n * k : 1, sizeof(uint32_t));
    x->nb_dist = xmalloc_array(n * k > 0 ? n * k : 1, sizeof(double));
    int ok = cj && cd && x->nb_idx && x->nb_dist;
    x->dmax = 0.0;
    for (size_t i = 0; ok && i < n; i++) {
        for (size_t j = 0; j < n; j++) {
            cj[j] = j;
            cd[j] = i == j ? 0.0 : 0.5 * (d[i * n + j] + d[j * n + i]);
            if (cd[j] > x->dmax)
                x->dmax = cd[j];
        }
        if (k > 0)
            knn_select(i, cj, cd, n, k, x->nb_idx + i * k, x->nb_dist + i * k);
    }
    free(cj);
    free(cd);
    return ok ? 0 : -1;
}

/* A new index of collection c (moved into x): the neighbour lists of the base distance of
 * the retrieval matrix (index_dist.h), K = the params' rerank_k. */
static int build(const opts *o, collection *c, tool_index *x)
{
    amscr_params *p = NULL;
    int r = make_params(o, 0, &p);
    if (r != 0)
        return r;
    x->coll = *c;
    memset(c, 0, sizeof *c);
    x->threshold = o->threshold;
    size_t n = x->coll.n, kp = amscr_params_get_rerank_k(p), m = o->candidates_set ? o->candidates : 0;
    x->k = kp < n ? kp : n;
    int ret = TOOL_EXIT_FAIL;
    double *d = NULL;
    base_dist b = {p, amscr_params_get_channel_weight(p), 0.0, 0.0};
    if (load_db(p, &x->coll, o->threshold, &x->db) == 0 && index_signatures_from(x, 0) == 0) {
        if (m > 0 && m < n - 1) { /* a large collection: each shape's candidates only */
            if (base_medians_sampled(x->db, &b, INDEX_MEDIAN_SAMPLE) == 0 && knn_from_candidates(x, &b, m) == 0)
                ret = 0;
        } else if (base_matrix(x->db, &b, o->pos[0], &d) == 0 && knn_from_matrix(x, d, n) == 0) {
            ret = 0;
        }
        x->med_a = b.med_a;
        x->med_h = b.med_h;
    }
    free(d);
    amscr_params_free(p);
    return ret;
}

int cmd_index(opts *o)
{
    if (o->out == NULL || strcmp(o->out, "-") == 0)
        return usage_error("index", "missing -o FILE (the index file)");
    tool_index x;
    collection c;
    memset(&x, 0, sizeof x);
    int r;
    if (o->add) {
        if (index_load(o->out, &x) != 0)
            return TOOL_EXIT_FAIL;
        if (collection_open(o->pos[0], &c) != 0) {
            index_free(&x);
            return TOOL_EXIT_FAIL;
        }
        r = index_add(o, &x, &c);
    } else {
        if (collection_open(o->pos[0], &c) != 0)
            return TOOL_EXIT_FAIL;
        r = build(o, &c, &x);
    }
    collection_free(&c);
    if (r == 0 && index_save(o->out, &x) != 0)
        r = TOOL_EXIT_FAIL;
    if (r == 0)
        printf("index %s: %zu shapes, %zu classes, %zu neighbours per shape\n", o->out, x.coll.n, x.coll.nclasses,
               x.k);
    index_free(&x);
    return r;
}
