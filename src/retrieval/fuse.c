/* fuse.c — retrieval beyond one aligned distance (docs/method.md §10): the shape channel of a
 * prepared shape in its own frame, the channel alone (pair and collection), and the fused,
 * re-ranked retrieval matrix. */
#include "channel.h"
#include "db_io.h"
#include "inner.h"
#include "rows.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void amscr__hf_cfg_from(const amscr_params *p, size_t n, int second, amscr__hf_cfg *cfg)
{
    size_t band = (size_t)floor((second ? p->channel_affine_band : p->channel_band) * (double)n + 0.5);
    cfg->band = band < 1 ? 1 : band;
    cfg->skip = p->channel_skip;
    cfg->reflections = p->reflections;
    cfg->both_orientations = 0;
    cfg->stride = 1;
}

/* The N prepared samples (input coordinates, group-invariant parametrization) moved into
 * the channel's frame: centroid at the origin and either whitened (affine) or scaled to an
 * RMS radius of sqrt(2) (similarity; the trace of the covariance is 2 in both frames). */
static amscr_status channel_frame(amscr_invariance frame, const amscr_descriptor *d, double *out)
{
    size_t n = d->n;
    if (frame == AMSCR_INVARIANCE_AFFINE) {
        double fwd[6], inv[6];
        return amscr__whiten(d->input, n, out, fwd, inv);
    }
    double cx = 0, cy = 0, s = 0;
    for (size_t i = 0; i < n; i++) {
        cx += d->input[2 * i];
        cy += d->input[2 * i + 1];
    }
    cx /= (double)n;
    cy /= (double)n;
    for (size_t i = 0; i < n; i++) {
        double dx = d->input[2 * i] - cx, dy = d->input[2 * i + 1] - cy;
        s += dx * dx + dy * dy;
    }
    s = sqrt(s / (double)n);
    if (!(s > 0.0))
        return amscr__fail(AMSCR_E_DEGENERATE, "shape channel: all samples coincide");
    double k = sqrt(2.0) / s;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = k * (d->input[2 * i] - cx);
        out[2 * i + 1] = k * (d->input[2 * i + 1] - cy);
    }
    return AMSCR_OK;
}

typedef amscr_status (*hf_builder)(const double *xy, size_t n, double locality, amscr__hf *out);

/* d's samples in `frame`, then `build` of them (the forward or the mirrored heights). */
static amscr_status hf_in_frame(const amscr_params *p, amscr_invariance frame, const amscr_descriptor *d,
                                hf_builder build, amscr__hf *out)
{
    double *xy = amscr__malloc_array(2 * d->n, sizeof *xy);
    if (!xy)
        return amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    amscr_status st = channel_frame(frame, d, xy);
    if (st == AMSCR_OK)
        st = build(xy, d->n, p->channel_locality, out);
    free(xy);
    return st;
}

amscr_status amscr__hf_of_descriptor(const amscr_params *p, amscr_invariance frame, const amscr_descriptor *d,
                                     amscr__hf *out)
{
    if (!d->params.closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "shape channel: needs closed curves");
    return hf_in_frame(p, frame, d, amscr__hf_build, out);
}

amscr_status amscr__hf_mirror_of_descriptor(const amscr_params *p, amscr_invariance frame,
                                            const amscr_descriptor *d, amscr__hf *h)
{
    return hf_in_frame(p, frame, d, amscr__hf_build_mirror, h);
}

/* The frames of the channel and their shares: the primary frame, plus the whitened frame with
 * channel_affine_share when the primary one is the similarity frame. Returns the count. */
int amscr__channel_frames(const amscr_params *p, amscr_invariance frames[2], double share[2])
{
    frames[0] = frames[1] = AMSCR_INVARIANCE_AFFINE;
    share[0] = 1.0;
    share[1] = 0.0;
    if (p->channel_invariance == AMSCR_INVARIANCE_AFFINE || p->channel_affine_share >= 1.0)
        return 1;
    frames[0] = p->channel_invariance;
    if (p->channel_affine_share <= 0.0)
        return 1;
    share[1] = p->channel_affine_share;
    share[0] = 1.0 - share[1];
    return 2;
}

/* The channel of a and b in frame `frame`, the second of amscr__channel_frames when `second`. */
static amscr_status pair_in_frame(const amscr_params *p, amscr_invariance frame, int second,
                                  const amscr_descriptor *a, const amscr_descriptor *b, double *out)
{
    amscr__hf ha, hb;
    amscr__hf_ws ws;
    amscr__hf_cfg cfg;
    amscr__hf_cfg_from(p, a->n, second, &cfg);
    amscr_status st = amscr__hf_of_descriptor(p, frame, a, &ha);
    if (st != AMSCR_OK)
        return st;
    st = amscr__hf_of_descriptor(p, frame, b, &hb);
    if (st != AMSCR_OK) {
        amscr__hf_free(&ha);
        return st;
    }
    st = amscr__hf_ws_init(&ws, a->n, cfg.band);
    if (st == AMSCR_OK) {
        *out = amscr__hf_distance(&ha, &hb, &cfg, &ws);
        amscr__hf_ws_free(&ws);
    }
    amscr__hf_free(&ha);
    amscr__hf_free(&hb);
    return st;
}

amscr_status amscr_channel_distance(const amscr_params *p, const amscr_descriptor *a, const amscr_descriptor *b,
                                    double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(a);
    AMSCR_CHECK_NULL(b);
    AMSCR_CHECK_NULL(out_dist);
    if (!p)
        p = &a->params;
    if (a->n != b->n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_channel_distance: N differs (%zu vs %zu)", a->n, b->n);
    amscr_invariance frames[2];
    double share[2], d[2] = {0.0, 0.0};
    int nf = amscr__channel_frames(p, frames, share);
    for (int f = 0; f < nf; f++) {
        amscr_status st = pair_in_frame(p, frames[f], f, a, b, &d[f]);
        if (st != AMSCR_OK)
            return st;
    }
    *out_dist = amscr__channel_combine(p, nf, share, d[0], d[1]);
    return AMSCR_OK;
}

static void free_hfs(amscr__hf *hf, size_t n)
{
    if (!hf)
        return;
    for (size_t i = 0; i < n; i++)
        amscr__hf_free(&hf[i]);
    free(hf);
}

/* The features of every shape in one frame, a row each (on the collection's threads). */
typedef struct {
    const amscr_db *db;
    amscr_invariance frame;
    amscr__hf *hf;
} frame_job;

static amscr_status frame_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    const frame_job *j = ctx;
    const amscr_descriptor *d;
    amscr_status st = amscr__db_shape(j->db, i, &d);
    return st == AMSCR_OK ? amscr__hf_of_descriptor(amscr_db_params(j->db), j->frame, d, &j->hf[i]) : st;
}

/* The channel matrix in one frame (the second of amscr__channel_frames when `second`) into out. */
static amscr_status matrix_in_frame(const amscr_db *db, amscr_invariance frame, int second,
                                    amscr_progress_fn progress, void *user, double *out)
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    amscr__hf *hf = calloc(n, sizeof *hf);
    if (!hf)
        return amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    unsigned threads = amscr__resolve_threads(p->num_threads);
    frame_job job = {db, frame, hf};
    amscr__rows_fn rows = {NULL, NULL, frame_row, &job, "shape channel"};
    amscr_status st = amscr__run_rows(&rows, 0, n, threads, NULL, NULL);
    if (st == AMSCR_OK) {
        amscr__hf_cfg cfg;
        amscr__hf_cfg_from(p, hf[0].n, second, &cfg);
        st = amscr__hf_matrix(hf, n, &cfg, threads, progress, user, out);
    }
    free_hfs(hf, n);
    return st;
}

static amscr_status channel_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out)
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    if (n == 0)
        return AMSCR_OK;
    if (!p->closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "shape channel: needs closed curves (the collection is open)");
    amscr_invariance frames[2];
    double share[2];
    int nf = amscr__channel_frames(p, frames, share);
    amscr__stages sp = {progress, user, 0, (size_t)nf};
    amscr_status st = matrix_in_frame(db, frames[0], 0, progress ? amscr__stage_cb : NULL, &sp, out);
    if (st != AMSCR_OK || nf == 1)
        return st;
    double *second = amscr__malloc_array(n * n, sizeof *second);
    if (!second)
        st = amscr__fail(AMSCR_E_NOMEM, "shape channel: out of memory");
    sp.stage = 1;
    if (st == AMSCR_OK)
        st = matrix_in_frame(db, frames[1], 1, progress ? amscr__stage_cb : NULL, &sp, second);
    for (size_t i = 0; st == AMSCR_OK && i < n * n; i++)
        out[i] = amscr__channel_combine(p, nf, share, out[i], second[i]);
    free(second); /* NaN on failure: amscr_db_channel_matrix */
    return st;
}

amscr_status amscr_db_channel_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_dist);
    size_t n = amscr_db_size(db);
    return amscr__nan_on_failure(channel_matrix(db, progress, user, out_dist), out_dist, n, n);
}

/* ------------------------------------------------------------ fusion */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median of the off-diagonal entries of the n x n matrix M (n >= 2). */
static amscr_status offdiag_median(const double *M, size_t n, double *out)
{
    size_t m = n * n - n, k = 0;
    double *v = amscr__malloc_array(m, sizeof *v);
    if (!v)
        return amscr__fail(AMSCR_E_NOMEM, "retrieval: out of memory");
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            if (i != j)
                v[k++] = M[i * n + j];
    qsort(v, m, sizeof *v, cmp_double);
    *out = v[m / 2];
    free(v);
    return AMSCR_OK;
}

void amscr__fuse_scales(double w, double med_a, double med_h, double *sa, double *sh)
{
    *sa = med_a > 0.0 ? (1.0 - w) / med_a : 1.0 - w;
    *sh = med_h > 0.0 ? w / med_h : w;
}

double amscr__fuse_pair(double w, double sa, double sh, double sym, double ch)
{
    if (w >= 1.0)
        return ch;
    if (w <= 0.0)
        return sym;
    return sa * sym + sh * ch;
}

/* A = (1 - w) sym(A) / median(A) + w H / median(H), zero diagonal (A unused when w = 1); the
 * medians into med[0], med[1] (0 when unused). */
static amscr_status fuse(double *A, const double *H, size_t n, double w, double med[2])
{
    med[0] = med[1] = 0.0;
    if (H && w >= 1.0) {
        memcpy(A, H, n * n * sizeof *A);
        return AMSCR_OK;
    }
    for (size_t i = 0; i < n; i++) {
        A[i * n + i] = 0.0;
        for (size_t j = i + 1; j < n; j++)
            A[i * n + j] = A[j * n + i] = 0.5 * (A[i * n + j] + A[j * n + i]);
    }
    if (!H || n < 2)
        return AMSCR_OK;
    amscr_status st = offdiag_median(A, n, &med[0]);
    if (st == AMSCR_OK)
        st = offdiag_median(H, n, &med[1]);
    if (st != AMSCR_OK)
        return st;
    double sa, sh;
    amscr__fuse_scales(w, med[0], med[1], &sa, &sh);
    for (size_t i = 0; i < n * n; i++)
        A[i] = sa * A[i] + sh * H[i];
    return AMSCR_OK;
}

amscr_status amscr__base_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist,
                                double med[2])
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    int with_channel = p->channel_weight > 0.0;
    med[0] = med[1] = 0.0;
    if (with_channel && !p->closed)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_db_retrieval_matrix: the shape channel needs closed curves; "
                                                "set the channel weight to 0 for open ones");
    int with_amscr = p->channel_weight < 1.0; /* the channel alone needs no AMSCR matrix */
    amscr__stages sp = {progress, user, 0, (size_t)with_channel + (size_t)with_amscr};
    amscr_status st = AMSCR_OK;
    if (with_amscr) {
        st = amscr_db_distance_matrix(db, progress ? amscr__stage_cb : NULL, &sp, out_dist);
        sp.stage = 1;
    }
    if (st != AMSCR_OK || n == 0)
        return st;
    double *H = NULL;
    if (with_channel) {
        H = amscr__malloc_array(n * n, sizeof *H);
        if (!H)
            st = amscr__fail(AMSCR_E_NOMEM, "amscr_db_retrieval_matrix: out of memory");
        if (st == AMSCR_OK)
            st = channel_matrix(db, progress ? amscr__stage_cb : NULL, &sp, H);
    }
    if (st == AMSCR_OK)
        st = fuse(out_dist, H, n, p->channel_weight, med);
    free(H);
    return st;
}

/* The re-ranking of the base matrix D (n x n, in place): on its kNN graph, and on the inner
 * distance's too when the params give it a share. */
static amscr_status rerank_base(const amscr_db *db, size_t n, double *D)
{
    const amscr_params *p = amscr_db_params(db);
    size_t k = amscr__rerank_k(p, n);
    unsigned threads = amscr__resolve_threads(p->num_threads);
    if (!(p->rerank_inner_share > 0.0))
        return amscr__rerank_normalized(D, n, k, p->rerank_iterations, threads, D);
    double *I = amscr__malloc_array(n * n, sizeof *I);
    if (!I)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_db_retrieval_matrix: out of memory");
    amscr_status st = amscr__inner_matrix(db, threads, NULL, NULL, I);
    if (st == AMSCR_OK)
        st = amscr__rerank_normalized2(D, I, p->rerank_inner_share, n, k, p->rerank_iterations, threads, D);
    free(I);
    return st;
}

amscr_status amscr_db_retrieval_matrix(const amscr_db *db, amscr_progress_fn progress, void *user, double *out_dist)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(db);
    AMSCR_CHECK_NULL(out_dist);
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    double med[2];
    amscr_status st = amscr__base_matrix(db, progress, user, out_dist, med);
    if (st == AMSCR_OK && n > 0 && p->rerank_k > 0)
        st = rerank_base(db, n, out_dist);
    return amscr__nan_on_failure(st, out_dist, n, n);
}
