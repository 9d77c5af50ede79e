/* index_pairs.c — the base distance of the retrieval matrix (fuse.c) pair by pair: one shape
 * against a list of shapes, each value computed as the matrix computes its cell, so the
 * index's neighbour lists and a query's distances agree with amscr_db_retrieval_matrix to
 * the bit. Rows of pairs are split over POSIX threads; the calling thread works too and is
 * the only one that reports progress. */
#include "db_io.h"
#include "index.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void amscr__base_init(amscr__base *b, const amscr_params *p, double med_a, double med_h)
{
    b->p = p;
    b->w = p->channel_weight;
    amscr__fuse_scales(b->w, med_a, med_h, &b->sa, &b->sh);
    b->nf = b->w > 0.0 ? amscr__channel_frames(p, b->frames, b->share) : 0;
    b->threads = amscr__resolve_threads(p->num_threads);
}

amscr_status amscr__pair_ws_init(const amscr__base *b, amscr__pair_ws *pw)
{
    memset(pw, 0, sizeof *pw);
    amscr_status st = b->w < 1.0 ? amscr_workspace_new(&pw->ws) : AMSCR_OK;
    if (st == AMSCR_OK && b->nf > 0) {
        amscr__hf_cfg_from(b->p, b->p->num_samples, 0, &pw->cfg[0]);
        amscr__hf_cfg_from(b->p, b->p->num_samples, 1, &pw->cfg[1]);
        size_t band = pw->cfg[0].band > pw->cfg[1].band ? pw->cfg[0].band : pw->cfg[1].band;
        st = amscr__hf_ws_init(&pw->hws, b->p->num_samples, band); /* room for the wider band */
        pw->have_hws = st == AMSCR_OK;
    }
    if (st != AMSCR_OK)
        amscr__pair_ws_free(pw);
    return st;
}

void amscr__pair_ws_free(amscr__pair_ws *pw)
{
    amscr_workspace_free(pw->ws);
    if (pw->have_hws)
        amscr__hf_ws_free(&pw->hws);
    memset(pw, 0, sizeof *pw);
}

amscr_status amscr__pair_ws_new(const amscr__base *b, void **out)
{
    amscr__pair_ws *pw = malloc(sizeof *pw);
    if (!pw)
        return AMSCR_E_NOMEM;
    amscr_status st = amscr__pair_ws_init(b, pw);
    if (st != AMSCR_OK)
        free(pw);
    else
        *out = pw;
    return st;
}

void amscr__pair_ws_delete(void *pw)
{
    amscr__pair_ws_free(pw);
    free(pw);
}

amscr_status amscr__base_hf(const amscr__base *b, const amscr_descriptor *d, amscr__hf hf[2])
{
    memset(hf, 0, (size_t)b->nf * sizeof *hf);
    amscr_status st = AMSCR_OK;
    for (int f = 0; f < b->nf && st == AMSCR_OK; f++)
        st = amscr__hf_of_descriptor(b->p, b->frames[f], d, &hf[f]);
    if (st != AMSCR_OK)
        amscr__base_hf_free(b, hf);
    return st;
}

void amscr__base_hf_free(const amscr__base *b, amscr__hf hf[2])
{
    for (int f = 0; f < b->nf; f++)
        amscr__hf_free(&hf[f]);
}

/* out[f]: stored[f] (its arrays shared, not copied) with what a pair reads of it and it lacks
 * made here: the spectra (a lazy load's heights, with ws's FFT plan when it has one) and, when
 * the pair reads the mirrored orientation (`mirror`: the shape is the pair's higher index), the
 * mirrored spectra (an index keeps the forward orientation's only) and heights (a lazy load of a
 * file from version 16, which stores the forward ones), from the shape's input samples.
 * own[f] marks what was made: bit 0 spec[0], bit 1 seq[1], bit 2 spec[1]. */
static amscr_status complete(const amscr__base *b, const amscr_db *db, size_t c, const amscr__hf *stored,
                             int mirror, amscr__hf_ws *ws, amscr__hf out[2], int own[2])
{
    amscr_status st = AMSCR_OK;
    amscr_descriptor sd, *tmp = NULL;
    const amscr_descriptor *d = NULL;
    double *buf = NULL;
    own[0] = own[1] = 0;
    for (int f = 0; f < b->nf; f++) {
        out[f] = stored[f];
        if (!mirror || out[f].seq[1])
            continue;
        if (!d) {
            size_t N = b->p->num_samples;
            buf = amscr__malloc_array(2 * N + 2 * AMSCR__OUTLINE_N, sizeof *buf);
            if (!buf) {
                st = amscr__fail(AMSCR_E_NOMEM, "index: out of memory");
                break;
            }
            if (amscr__db_shallow(db, c, &sd, buf, buf + 2 * N))
                d = &sd;
            else if ((st = amscr__db_peek(db, c, &d, &tmp)) != AMSCR_OK)
                break;
        }
        st = amscr__hf_mirror_of_descriptor(b->p, b->frames[f], d, &out[f]);
        if (st != AMSCR_OK)
            break;
        own[f] |= 2;
    }
    free(buf);
    amscr_descriptor_free(tmp);
    for (int f = 0; f < b->nf && st == AMSCR_OK; f++) {
        int had0 = out[f].spec[0] != NULL, had1 = out[f].spec[1] != NULL;
        if (!mirror && out[f].spec[0])
            continue;
        st = amscr__hf_spectra(&out[f], ws);
        own[f] |= (!had0 && out[f].spec[0] ? 1 : 0) | (!had1 && out[f].spec[1] ? 4 : 0);
    }
    return st;
}

static void complete_free(const amscr__base *b, amscr__hf out[2], const int own[2])
{
    for (int f = 0; f < b->nf; f++) {
        if (own[f] & 1)
            free(out[f].spec[0]);
        if (own[f] & 2)
            free(out[f].seq[1]);
        if (own[f] & 4)
            free(out[f].spec[1]);
    }
}

/* A candidate's side of a pair: its channel sequences (stored, or built here: not kept, not
 * built yet by a lazy load, or completed: complete()) and, when the pair reads it, its prepared
 * shape (a lazy load decodes it here). */
typedef struct {
    amscr__hf built[2];
    const amscr__hf *hf;
    const amscr_descriptor *d;
    int build, part, own[2];
} side_t;

static amscr_status side_open(const amscr__base *b, const amscr_db *db, const amscr__hf *hfs, size_t c, int mirror,
                              amscr__pair_ws *pw, side_t *o)
{
    const amscr__hf *stored = hfs ? hfs + c * (size_t)b->nf : NULL;
    o->build = !stored || (b->nf > 0 && stored[0].seq[0] == NULL);
    o->part = !o->build && b->nf > 0 &&
              (stored[0].spec[0] == NULL || (mirror && (stored[0].seq[1] == NULL || stored[0].spec[1] == NULL)));
    o->hf = o->build || o->part ? o->built : stored;
    o->d = NULL;
    amscr_status st = o->build || b->w < 1.0 ? amscr__db_shape(db, c, &o->d) : AMSCR_OK;
    if (st == AMSCR_OK && o->build)
        st = amscr__base_hf(b, o->d, o->built);
    else if (st == AMSCR_OK && o->part) {
        st = complete(b, db, c, stored, mirror, pw->have_hws ? &pw->hws : NULL, o->built, o->own);
        if (st != AMSCR_OK)
            complete_free(b, o->built, o->own);
    }
    if (st != AMSCR_OK)
        o->build = o->part = 0; /* nothing to release */
    return st;
}

static void side_close(const amscr__base *b, side_t *o)
{
    if (o->build)
        amscr__base_hf_free(b, o->built);
    if (o->part)
        complete_free(b, o->built, o->own);
}

/* out[t] for m <= AMSCR__HF_GROUP pairs: the base distance of lo[t] and hi[t] (lo the lower
 * index), their channel sequences hlo[t], hhi[t]; the channel's DPs side by side (the same
 * values). */
static amscr_status base_group(const amscr__base *b, const amscr_descriptor *const lo[],
                               const amscr__hf *const hlo[], const amscr_descriptor *const hi[],
                               const amscr__hf *const hhi[], size_t m, amscr__pair_ws *pw, double *out)
{
    double ch[2][AMSCR__HF_GROUP] = {{0.0}};
    for (int f = 0; f < b->nf; f++) {
        const amscr__hf *a[AMSCR__HF_GROUP], *c[AMSCR__HF_GROUP];
        for (size_t t = 0; t < m; t++) {
            a[t] = &hlo[t][f];
            c[t] = &hhi[t][f];
        }
        amscr__hf_distances(a, c, m, &pw->cfg[f], &pw->hws, ch[f]);
    }
    for (size_t t = 0; t < m; t++) {
        double sym = 0.0, f = 0.0, r = 0.0;
        if (b->w < 1.0) {
            amscr_status st = amscr__distance_ws(b->p, lo[t], hi[t], pw->ws, &f);
            if (st == AMSCR_OK)
                st = amscr__distance_ws(b->p, hi[t], lo[t], pw->ws, &r);
            if (st != AMSCR_OK)
                return st;
            sym = 0.5 * (f + r);
        }
        double c = amscr__channel_combine(b->p, b->nf, b->share, ch[0][t], ch[1][t]);
        out[t] = amscr__fuse_pair(b->w, b->sa, b->sh, sym, c);
    }
    return AMSCR_OK;
}

amscr_status amscr__base_pairs(const amscr__base *b, const amscr_db *db, const amscr__hf *hfs,
                               const amscr_descriptor *q, const amscr__hf hq[2], size_t qpos, const size_t *cand,
                               size_t m, amscr__pair_ws *pw, double *out)
{
    amscr_status st = AMSCR_OK;
    enum { G = AMSCR__HF_GROUP };
    amscr__hf qfull[2];
    int qown[2] = {0, 0}, qpart = b->nf > 0 && hq && qpos < amscr_db_size(db) && (!hq[0].seq[1] || !hq[0].spec[1]);
    if (qpart) { /* an index's row (its shape's forward orientation kept): the pairs may read its mirror */
        st = complete(b, db, qpos, hq, 1, pw->have_hws ? &pw->hws : NULL, qfull, qown);
        hq = qfull;
    }
    for (size_t t0 = 0; t0 < m && st == AMSCR_OK; t0 += G) {
        size_t g = m - t0 < G ? m - t0 : G, open = 0;
        side_t side[G];
        const amscr_descriptor *lo[G], *hi[G];
        const amscr__hf *hlo[G], *hhi[G];
        for (; open < g && st == AMSCR_OK; open++) {
            size_t c = cand[t0 + open];
            int first = c < qpos; /* the candidate is the pair's lower index */
            st = side_open(b, db, hfs, c, !first, pw, &side[open]);
            lo[open] = first ? side[open].d : q;
            hlo[open] = first ? side[open].hf : hq;
            hi[open] = first ? q : side[open].d;
            hhi[open] = first ? hq : side[open].hf;
        }
        if (st == AMSCR_OK)
            st = base_group(b, lo, hlo, hi, hhi, g, pw, out + t0);
        for (size_t t = 0; t < open; t++)
            side_close(b, &side[t]);
    }
    if (qpart)
        complete_free(b, qfull, qown);
    return st;
}

/* ---------------------------------------------------------------- one row on threads */

enum { CHUNK = AMSCR__HF_GROUP };

typedef struct {
    const amscr__base *b;
    const amscr_db *db;
    const amscr__hf *hfs;
    const amscr_descriptor *q;
    const amscr__hf *hq;
    size_t qpos, m;
    const size_t *cand;
    double *out;
    pthread_mutex_t lock;
    size_t next, done;
    int cancel;
    amscr_status st;
    char detail[256];
} row_job;

/* Runs chunks until none is left; reports (the calling thread only) between them. */
static void row_work(row_job *j, amscr_progress_fn progress, void *user)
{
    amscr__pair_ws pw;
    amscr_status st = amscr__pair_ws_init(j->b, &pw);
    int have_pw = st == AMSCR_OK;
    for (;;) {
        pthread_mutex_lock(&j->lock);
        if (st != AMSCR_OK && j->st == AMSCR_OK) {
            j->st = st;
            snprintf(j->detail, sizeof j->detail, "%s", amscr_last_error_detail());
        }
        size_t c = j->next, done = j->done;
        int live = j->st == AMSCR_OK && !j->cancel, go = live && c < j->m; /* no report once cancelled */
        if (go)
            j->next += CHUNK;
        pthread_mutex_unlock(&j->lock);
        if (live && progress && progress(user, done, j->m) != 0) {
            pthread_mutex_lock(&j->lock);
            j->cancel = 1;
            pthread_mutex_unlock(&j->lock);
        }
        if (!go)
            break;
        size_t e = c + CHUNK < j->m ? c + CHUNK : j->m;
        st = amscr__base_pairs(j->b, j->db, j->hfs, j->q, j->hq, j->qpos, j->cand + c, e - c, &pw, j->out + c);
        pthread_mutex_lock(&j->lock);
        j->done += e - c;
        pthread_mutex_unlock(&j->lock);
    }
    if (have_pw)
        amscr__pair_ws_free(&pw);
}

static void *row_worker(void *arg)
{
    row_work(arg, NULL, NULL);
    return NULL;
}

amscr_status amscr__base_row(const amscr__base *b, const amscr_db *db, const amscr__hf *hfs,
                             const amscr_descriptor *q, size_t qpos, const size_t *cand, size_t m,
                             amscr_progress_fn progress, void *user, double *out)
{
    if (m == 0) /* no work: no report (a percentage callback would divide by 0) */
        return AMSCR_OK;
    amscr__hf hq[2];
    amscr_status st = amscr__base_hf(b, q, hq);
    if (st != AMSCR_OK)
        return st;
    row_job j = {b, db, hfs, q, hq, qpos, m, cand, out, PTHREAD_MUTEX_INITIALIZER, 0, 0, 0, AMSCR_OK, ""};
    unsigned nt = b->threads, started = 0;
    size_t chunks = (m + CHUNK - 1) / CHUNK;
    if (nt > chunks)
        nt = chunks ? (unsigned)chunks : 1u;
    pthread_t tid[64];
    for (unsigned t = 1; t < nt && t < 64; t++)
        if (pthread_create(&tid[started], NULL, row_worker, &j) == 0)
            started++;
    row_work(&j, progress, user);
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    amscr__base_hf_free(b, hq);
    pthread_mutex_destroy(&j.lock);
    if (j.st != AMSCR_OK)
        return amscr__fail(j.st, "%s", j.detail);
    if (j.cancel)
        return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback");
    if (progress && progress(user, m, m) != 0)
        return amscr__fail(AMSCR_E_CANCELLED, "cancelled by the progress callback at the end");
    return AMSCR_OK;
}
