/* index_shard.c — what an index split in shards needs of the library (Python's
 * amscr.distributed.build_index): the pair distances of a shape to each shape of an index (a
 * shard), each computed as the cell of the whole collection's matrix, and the neighbour graph of
 * the whole collection without its shapes, which turns a query's distances to every shard into
 * the single index's scores (the same diffusion, index_diffuse.c). */
#include "db_io.h"
#include "index.h"
#include "rows.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

struct amscr_index_graph {
    amscr_index *x; /* lists and normalisers; its db holds n empty slots (no shapes) */
};

/* The inner distances of q (features f) to shapes first.. of x on threads, each pair with the lower
 * index first. */
typedef struct {
    const amscr_index *x;
    const amscr__inner *f;
    size_t qpos;
    const size_t *cand; /* the shapes of x matched, ascending */
    int refl;
    double *out;
} inner_ctx;

static amscr_status inner_init(void *ctx, void **scratch)
{
    (void)ctx;
    amscr__inner_ws *ws = malloc(sizeof *ws);
    if (!ws || amscr__inner_ws_init(ws) != AMSCR_OK) {
        free(ws);
        return AMSCR_E_NOMEM;
    }
    *scratch = ws;
    return AMSCR_OK;
}

static void inner_fini(void *scratch)
{
    if (scratch)
        amscr__inner_ws_free(scratch);
    free(scratch);
}

static amscr_status inner_row(void *ctx, size_t j, void *scratch)
{
    inner_ctx *c = ctx;
    size_t i = c->cand[j];
    c->out[j] = i < c->qpos ? amscr__inner_distance(&c->x->inner[i], c->f, c->refl, scratch)
                            : amscr__inner_distance(c->f, &c->x->inner[i], c->refl, scratch);
    return AMSCR_OK;
}

static amscr_status pair_inner(const amscr_index *x, const amscr_descriptor *q, size_t qpos, const size_t *cand,
                               size_t m, double *out)
{
    amscr__inner_ws ws;
    amscr__inner *f = malloc(sizeof *f);
    if (!f || amscr__inner_ws_init(&ws) != AMSCR_OK) {
        free(f);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_pair_distances: out of memory");
    }
    const amscr_params *p = amscr_db_params(x->db);
    amscr_status st = amscr__inner_build_shape(q, p->inner_closing, f, &ws);
    amscr__inner_ws_free(&ws);
    inner_ctx c = {x, f, qpos, cand, p->reflections, out};
    amscr__rows_fn fn = {inner_init, inner_fini, inner_row, &c, "amscr_index_pair_distances"};
    if (st == AMSCR_OK)
        st = amscr__run_rows(&fn, 0, m, amscr__resolve_threads(p->num_threads), NULL, NULL);
    free(f);
    return st;
}

/* The base (out_base may be NULL) and inner distances of q to shapes cand[0..m-1] of x. */
static amscr_status pairs_of(const amscr_index *x, const amscr_descriptor *q, size_t qpos, const size_t *cand,
                             size_t m, double *out_base, double *out_inner)
{
    const amscr_params *p = amscr_db_params(x->db);
    amscr_status st = AMSCR_OK;
    if (out_base && m > 0) {
        amscr__base b;
        amscr__base_init(&b, p, x->med_a, x->med_h);
        st = amscr__base_row(&b, x->db, x->hf, q, qpos, cand, m, NULL, NULL, out_base);
    }
    if (st == AMSCR_OK && out_inner) {
        if (x->k2 > 0 && m > 0)
            st = pair_inner(x, q, qpos, cand, m, out_inner);
        else if (m > 0)
            memset(out_inner, 0, m * sizeof *out_inner);
    }
    return st;
}

amscr_status amscr_index_pair_distances(const amscr_index *x, const amscr_descriptor *q, size_t qpos, size_t first,
                                        double *out_base, double *out_inner, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out_base);
    const amscr_params *p = amscr_db_params(x->db);
    if (!amscr__params_compatible(p, &q->params, "amscr_index_pair_distances"))
        return AMSCR_E_INVALID_ARG;
    size_t size = amscr_db_size(x->db);
    if (first > size || n != size - first)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_pair_distances: shapes %zu.. of %zu, the output holds "
                                                "%zu distances", first, size, n);
    size_t *cand = amscr__malloc_array(n ? n : 1, sizeof *cand);
    if (!cand)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_pair_distances: out of memory");
    for (size_t j = 0; j < n; j++)
        cand[j] = first + j;
    amscr_status st = pairs_of(x, q, qpos, cand, n, out_base, out_inner);
    free(cand);
    return st;
}

amscr_status amscr_index_pair_distances_at(const amscr_index *x, const amscr_descriptor *q, size_t qpos,
                                           const size_t *cand, size_t m, double *out_base, double *out_inner)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    AMSCR_CHECK_NULL(q);
    if (!amscr__params_compatible(amscr_db_params(x->db), &q->params, "amscr_index_pair_distances_at"))
        return AMSCR_E_INVALID_ARG;
    size_t size = amscr_db_size(x->db);
    if (m > 0 && (!cand || (!out_base && !out_inner)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_pair_distances_at: NULL shapes or outputs");
    for (size_t t = 0; t < m; t++)
        if (cand[t] >= size || (t > 0 && cand[t] <= cand[t - 1]))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_pair_distances_at: shape %zu (%zu) is not below "
                                                    "%zu and above the one before", t, cand[t], size);
    return pairs_of(x, q, qpos, cand, m, out_base, out_inner);
}

/* ------------------------------------------------ signatures and shortlists */

size_t amscr_signature_size(void) { return AMSCR__SIG_DIM; }

amscr_status amscr_index_signatures(const amscr_index *x, float *out, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    size_t size = amscr_db_size(x->db);
    if (n != size * AMSCR__SIG_DIM || (n > 0 && (!out || !x->sigq || x->sig_dim != AMSCR__SIG_DIM)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_signatures: the output holds %zu floats, %zu shapes "
                                                "need %zu", n, size, size * (size_t)AMSCR__SIG_DIM);
    for (size_t i = 0; i < size; i++) /* the values the index searches by */
        amscr__index_sig(x, i, out + i * AMSCR__SIG_DIM);
    return AMSCR_OK;
}

amscr_status amscr_shape_signature(const amscr_descriptor *q, float *out, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(q);
    AMSCR_CHECK_NULL(out);
    if (n != AMSCR__SIG_DIM)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_shape_signature: the output holds %zu floats, a signature "
                                                "%d", n, (int)AMSCR__SIG_DIM);
    amscr__shape_signature(q, out);
    return AMSCR_OK;
}

size_t amscr_index_build_shortlist(const amscr_params *p, size_t n, size_t candidates)
{
    size_t k = 0;
    amscr_index_graph_widths(p, n, &k, NULL);
    if (candidates > 0 && candidates + 1 < k)
        candidates = k - 1;
    if (!p || candidates == 0 || n <= 1 || candidates >= n - 1)
        return 0;
    size_t mb = candidates < AMSCR__INDEX_BUILD_SHORTLIST ? candidates : AMSCR__INDEX_BUILD_SHORTLIST;
    return mb + 1 < k ? k - 1 : mb;
}

amscr_status amscr_index_signatures_packed(const amscr_index *x, uint16_t *out_q, int32_t *out_e, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(x);
    AMSCR__CHECK_INDEX_WHOLE(__func__, x);
    size_t size = amscr_db_size(x->db);
    if (n != size || (n > 0 && (!out_q || !out_e || !x->sigq || x->sig_dim != AMSCR__SIG_DIM)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_signatures_packed: room for %zu shapes, the index has "
                                                "%zu", n, size);
    if (n > 0) {
        memcpy(out_q, x->sigq, n * AMSCR__SIG_DIM * sizeof *out_q);
        memcpy(out_e, x->sige, n * sizeof *out_e);
    }
    return AMSCR_OK;
}

typedef struct {
    amscr__sig_rows rows;
    const float *lbs, *qsigs;
    size_t n, first, m;
    size_t *out;
} near_ctx;

static amscr_status near_row(void *ctx, size_t r, void *scratch)
{
    (void)scratch;
    near_ctx *c = ctx;
    float lb[AMSCR__SIG_LB_DIM];
    const float *sig = c->qsigs + r * AMSCR__SIG_DIM;
    amscr__sig_bound_vector(sig, lb);
    size_t got = amscr__sig_nearest(&c->rows, c->lbs, c->n, sig, lb, c->m,
                                    c->first == SIZE_MAX ? SIZE_MAX : c->first + r, c->out + r * c->m);
    return got == c->m ? AMSCR_OK : AMSCR_E_NOMEM;
}

/* The arguments of the shortlists: the counts and the queries (finite). */
static amscr_status check_shortlists(const char *fn, size_t n, const float *qsigs, size_t nq, size_t first, size_t m,
                                     const size_t *out, size_t out_len)
{
    size_t avail = first == SIZE_MAX ? n : n - 1;
    if ((nq > 0 && (!qsigs || !out)) || (first != SIZE_MAX && (first > n || nq > n - first)) || m == 0 ||
        m > avail || out_len != nq * m)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %zu nearest of %zu signatures for %zu queries from %zu, the "
                                                "output holds %zu", fn, m, n, nq, first, out_len);
    for (size_t t = 0; t < nq * AMSCR__SIG_DIM; t++)
        if (!isfinite(qsigs[t]))
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: query %zu is not finite", fn, t / AMSCR__SIG_DIM);
    return AMSCR_OK;
}

/* The shortlists over the rows (checked): each row's bound vector, then the queries on threads. */
static amscr_status shortlists(const char *fn, const amscr__sig_rows *rows, size_t n, const float *qsigs, size_t nq,
                               size_t first, size_t m, unsigned threads, size_t *out)
{
    float *lbs = amscr__malloc_array(n ? n : 1, AMSCR__SIG_LB_DIM * sizeof *lbs);
    if (!lbs)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", fn);
    float row[AMSCR__SIG_DIM];
    for (size_t j = 0; j < n; j++) {
        const float *sig = rows->f ? rows->f + j * AMSCR__SIG_DIM : row;
        if (!rows->f)
            amscr__sig_dequantize(rows->q + j * AMSCR__SIG_DIM, rows->e[j], row);
        amscr__sig_bound_vector(sig, lbs + j * AMSCR__SIG_LB_DIM);
    }
    near_ctx c = {*rows, lbs, qsigs, n, first, m, out};
    amscr__rows_fn rf = {NULL, NULL, near_row, &c, fn};
    amscr_status st = amscr__run_rows(&rf, 0, nq, amscr__resolve_threads(threads), NULL, NULL);
    free(lbs);
    return st == AMSCR_E_NOMEM ? amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", fn) : st;
}

amscr_status amscr_signature_shortlists(const float *sigs, size_t n, const float *qsigs, size_t nq, size_t first,
                                        size_t m, unsigned threads, size_t *out, size_t out_len)
{
    static const char fn[] = "amscr_signature_shortlists";
    amscr__clear_error();
    if (n > 0 && !sigs)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: NULL signatures", fn);
    amscr_status st = check_shortlists(fn, n, qsigs, nq, first, m, out, out_len);
    for (size_t t = 0; st == AMSCR_OK && t < n * AMSCR__SIG_DIM; t++)
        if (!isfinite(sigs[t]))
            st = amscr__fail(AMSCR_E_INVALID_ARG, "%s: signature %zu is not finite", fn, t / AMSCR__SIG_DIM);
    amscr__sig_rows rows = {sigs, NULL, NULL};
    return st == AMSCR_OK ? shortlists(fn, &rows, n, qsigs, nq, first, m, threads, out) : st;
}

amscr_status amscr_signature_shortlists_packed(const uint16_t *q, const int32_t *e, size_t n, const float *qsigs,
                                               size_t nq, size_t first, size_t m, unsigned threads, size_t *out,
                                               size_t out_len)
{
    static const char fn[] = "amscr_signature_shortlists_packed";
    amscr__clear_error();
    if (n > 0 && (!q || !e))
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: NULL signatures", fn);
    amscr_status st = check_shortlists(fn, n, qsigs, nq, first, m, out, out_len);
    for (size_t j = 0; st == AMSCR_OK && j < n; j++)
        if (e[j] < AMSCR_SIGNATURE_EXP_MIN || e[j] > AMSCR_SIGNATURE_EXP_MAX)
            st = amscr__fail(AMSCR_E_INVALID_ARG, "%s: signature %zu has the exponent %ld (%d to %d)", fn, j,
                             (long)e[j], AMSCR_SIGNATURE_EXP_MIN, AMSCR_SIGNATURE_EXP_MAX);
    amscr__sig_rows rows = {NULL, q, e};
    return st == AMSCR_OK ? shortlists(fn, &rows, n, qsigs, nq, first, m, threads, out) : st;
}

void amscr_index_graph_widths(const amscr_params *p, size_t n, size_t *out_k, size_t *out_k2)
{
    size_t k = p && n > 0 ? amscr__rerank_k(p, n) : 0;
    if (out_k)
        *out_k = k;
    if (out_k2)
        *out_k2 = p ? amscr__index_k2(p, k) : 0;
}

/* Row i of a list (k entries): itself first, the others below n, distances finite and >= 0. */
static int bad_row(const uint32_t *idx, const double *dist, size_t i, size_t k, size_t n)
{
    if (k > 0 && idx[0] != i)
        return 1;
    for (size_t t = 0; t < k; t++)
        if (idx[t] >= n || !(dist[t] >= 0.0) || !isfinite(dist[t]))
            return 1;
    return 0;
}

static amscr_status copy_lists(const uint32_t *idx, const double *dist, size_t n, size_t k, uint32_t **oi,
                               double **od)
{
    *oi = amscr__malloc_array(n ? n : 1, (k ? k : 1) * sizeof **oi);
    *od = amscr__malloc_array(n ? n : 1, (k ? k : 1) * sizeof **od);
    if (!*oi || !*od)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_index_graph_new: out of memory");
    if (n * k > 0) {
        memcpy(*oi, idx, n * k * sizeof **oi);
        memcpy(*od, dist, n * k * sizeof **od);
    }
    return AMSCR_OK;
}

amscr_status amscr_index_graph_new(const amscr_params *p, size_t n, const uint32_t *nb_idx, const double *nb_dist,
                                   const uint32_t *in_idx, const double *in_dist, double dmax, double dmax2,
                                   amscr_index_graph **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(out);
    size_t k, k2;
    amscr_index_graph_widths(p, n, &k, &k2);
    if (n > UINT32_MAX)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_index_graph_new: %zu shapes exceed 2^32 - 1", n);
    if ((k > 0 && (!nb_idx || !nb_dist)) || (k2 > 0 && (!in_idx || !in_dist)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_new: NULL lists (%zu shapes, %zu and %zu "
                                                "neighbours a shape)", n, k, k2);
    if (!(dmax >= 0.0) || !isfinite(dmax) || !(dmax2 >= 0.0) || !isfinite(dmax2))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_new: largest distances %g, %g", dmax, dmax2);
    for (size_t i = 0; i < n; i++) {
        if (bad_row(nb_idx + i * k, nb_dist + i * k, i, k, n))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_new: row %zu of the base lists is not "
                                                    "itself first, then shapes below %zu at distances >= 0", i, n);
        if (k2 > 0 && bad_row(in_idx + i * k2, in_dist + i * k2, i, k2, n))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_new: row %zu of the inner lists is not "
                                                    "itself first, then shapes below %zu at distances >= 0", i, n);
    }
    amscr_index_graph *g = calloc(1, sizeof *g);
    amscr_index *x = calloc(1, sizeof *x);
    amscr_status st = g && x ? amscr__db_new_slots(p, n, &x->db)
                             : amscr__fail(AMSCR_E_NOMEM, "amscr_index_graph_new: out of memory");
    if (g)
        g->x = x;
    if (st == AMSCR_OK) {
        x->sig_dim = AMSCR__SIG_DIM;
        x->k = k;
        x->k2 = k2;
        x->dmax = dmax;
        x->dmax2 = k2 > 0 ? dmax2 : 0.0;
        st = copy_lists(nb_idx, nb_dist, n, k, &x->nb_idx, &x->nb_dist);
    }
    if (st == AMSCR_OK && k2 > 0)
        st = copy_lists(in_idx, in_dist, n, k2, &x->in_idx, &x->in_dist);
    if (st == AMSCR_OK)
        st = amscr__index_reverse(x);
    if (st != AMSCR_OK) {
        amscr_index_graph_free(g);
        if (!g)
            amscr_index_free(x);
        return st;
    }
    *out = g;
    return AMSCR_OK;
}

amscr_status amscr_index_graph_scores(const amscr_index_graph *g, const size_t *cand, const double *dq,
                                      const double *dq2, size_t m, double *out_scores, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(g);
    AMSCR_CHECK_NULL(out_scores);
    const amscr_index *x = g->x;
    size_t size = amscr_db_size(x->db);
    if (n != size)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_scores: the output holds %zu scores, the graph "
                                                "%zu shapes", n, size);
    if (m > 0 && (!cand || !dq || (x->k2 > 0 && !dq2)))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_scores: NULL candidates or distances%s",
                           x->k2 > 0 ? " (this graph needs the inner distances too)" : "");
    for (size_t t = 0; t < m; t++) {
        if (cand[t] >= size || (t > 0 && cand[t] <= cand[t - 1]))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_scores: candidate %zu (%zu) is not below "
                                                    "%zu and above the one before", t, cand[t], size);
        if (!(dq[t] >= 0.0) || !isfinite(dq[t]) || (x->k2 > 0 && (!(dq2[t] >= 0.0) || !isfinite(dq2[t]))))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_scores: candidate %zu's distance is not "
                                                    "finite and >= 0", t);
    }
    return amscr__index_scores(x, size, cand, dq, x->k2 > 0 ? dq2 : NULL, m, out_scores);
}

amscr_status amscr_index_graph_member_scores(const amscr_index_graph *g, size_t i, const size_t *cand,
                                             const double *dq, size_t m, double *out_scores, size_t n)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(g);
    AMSCR_CHECK_NULL(out_scores);
    const amscr_index *x = g->x;
    size_t size = amscr_db_size(x->db);
    if (n != size || i >= size)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_member_scores: shape %zu, %zu scores, the graph "
                                                "%zu shapes", i, n, size);
    if (m > 0 && (!cand || !dq))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_member_scores: NULL candidates or distances");
    for (size_t t = 0; t < m; t++) {
        if (cand[t] >= size || cand[t] == i || (t > 0 && cand[t] <= cand[t - 1]))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_member_scores: candidate %zu (%zu) is not "
                                                    "below %zu, above the one before and not the shape", t, cand[t],
                               size);
        if (!(dq[t] >= 0.0) || !isfinite(dq[t]))
            return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_index_graph_member_scores: candidate %zu's distance is "
                                                    "not finite and >= 0", t);
    }
    return amscr__index_scores(x, i, cand, dq, NULL, m, out_scores);
}

size_t amscr_index_graph_size(const amscr_index_graph *g) { return g ? amscr_db_size(g->x->db) : 0; }

void amscr_index_graph_free(amscr_index_graph *g)
{
    if (!g)
        return;
    amscr_index_free(g->x);
    free(g);
}
