/* signature_recall.c — the recall of an index query's signature shortlist: % of the exact top 10
 * (the retrieval preset's base distance before re-ranking, checked against
 * amscr_channel_distance) inside the M signature-nearest, and % of first hits, for seeded affine
 * queries per fold of mpeg7-dev/folds.tsv on mpeg7-dev, the MCD-style set and mpeg7-dev + affine
 * copies; then the CPU time of one query at 1400 shapes (docs/measurements.md, "Shortlist recall").
 *
 *   amscr-signature-recall DATASETS [QUERIES]     (QUERIES per fold, default 100) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "affine_signature.h"
#define BENCH_PROGRAM "amscr-signature-recall"
#include "bench_util.h"
#include "channel.h"
#include "mcd_set.h"

enum { DIM = AMSCR__AFFINE_SIG_DIM, TOP = 10, NM = 5, TIMED = 15 };
static const size_t MS[NM] = {16, 32, 64, 128, 256};

/* The library's signature (affine_signature.h); the variants measured against it: docs/decisions.md. */
static const char *const SIG_NAME = "height-bins, share 0.2 (channel's)";

typedef struct {
    size_t n;
    amscr_descriptor **d;
    amscr__hf *hf[2]; /* similarity, whitened frame */
    double *sig; /* n x DIM */
} prepared;

static void prepare_set(const amscr_params *p, amscr_contour *const *c, size_t n, prepared *s)
{
    s->n = n;
    s->d = xmalloc(n * sizeof *s->d);
    for (int f = 0; f < 2; f++)
        s->hf[f] = xmalloc(n * sizeof *s->hf[f]);
    s->sig = xmalloc(n * DIM * sizeof(double));
    for (size_t i = 0; i < n; i++) {
        s->d[i] = prepare(p, c[i]);
        for (int f = 0; f < 2; f++)
            if (amscr__hf_of_descriptor(p, f ? AMSCR_INVARIANCE_AFFINE : AMSCR_INVARIANCE_SIMILARITY, s->d[i],
                                        &s->hf[f][i]) != AMSCR_OK)
                die("height functions");
        amscr__affine_signature(s->d[i], s->sig + i * DIM);
    }
}

static void prepared_free(prepared *s)
{
    for (size_t i = 0; i < s->n; i++) {
        amscr_descriptor_free(s->d[i]);
        amscr__hf_free(&s->hf[0][i]);
        amscr__hf_free(&s->hf[1][i]);
    }
    free(s->d);
    free(s->hf[0]);
    free(s->hf[1]);
    free(s->sig);
}

/* The channel distance of collection shape i and query q (shape i first), as
 * amscr_channel_distance with the retrieval preset. */
static double two_frames(const amscr_params *p, const amscr__hf *a0, const amscr__hf *a1, const amscr__hf *b0,
                         const amscr__hf *b1, amscr__hf_ws *ws)
{
    amscr__hf_cfg cfg[2];
    amscr__hf_cfg_from(p, a0->n, 0, &cfg[0]);
    amscr__hf_cfg_from(p, a0->n, 1, &cfg[1]);
    double s = amscr_params_get_channel_affine_share(p);
    return (1.0 - s) * amscr__hf_distance(a0, b0, &cfg[0], ws) + s * amscr__hf_distance(a1, b1, &cfg[1], ws);
}

/* A channel workspace with room for both frames' bands. */
static void ws_init(const amscr_params *p, size_t n, amscr__hf_ws *ws)
{
    amscr__hf_cfg c0, c1;
    amscr__hf_cfg_from(p, n, 0, &c0);
    amscr__hf_cfg_from(p, n, 1, &c1);
    if (amscr__hf_ws_init(ws, n, c0.band > c1.band ? c0.band : c1.band) != AMSCR_OK)
        die("workspace");
}

typedef struct {
    size_t top[NM];   /* exact top-10 members inside the shortlist */
    size_t first[NM]; /* queries whose exact first hit is inside */
    size_t nq;
} tally;

/* Adds query k's recall to t: exact row e (n), signature rows. */
static void count(const prepared *c, const prepared *q, size_t k, const double *e, double *sd, size_t *rank,
                  tally *t)
{
    size_t n = c->n, best[TOP];
    if (amscr_topk(e, n, TOP, SIZE_MAX, best) != AMSCR_OK)
        die("top-k");
    for (size_t j = 0; j < n; j++)
        sd[j] = amscr__affine_signature_distance(q->sig + k * DIM, c->sig + j * DIM);
    if (amscr_topk(sd, n, n, SIZE_MAX, rank) != AMSCR_OK)
        die("top-k");
    for (size_t j = 0; j < n; j++) /* rank[] -> the position of every shape */
        sd[rank[j]] = (double)j;
    for (int m = 0; m < NM; m++) {
        for (size_t r = 0; r < TOP; r++)
            t->top[m] += sd[best[r]] < (double)MS[m];
        t->first[m] += sd[best[0]] < (double)MS[m];
    }
    t->nq++;
}

static void recall(const amscr_params *p, const prepared *c, const prepared *q, tally *t)
{
    size_t n = c->n;
    double *e = xmalloc(n * sizeof *e), *sd = xmalloc(n * sizeof *sd);
    size_t *rank = xmalloc(n * sizeof *rank);
    amscr__hf_ws ws;
    ws_init(p, c->d[0]->n, &ws);
    memset(t, 0, sizeof *t);
    for (size_t k = 0; k < q->n; k++) {
        for (size_t i = 0; i < n; i++)
            e[i] = two_frames(p, &c->hf[0][i], &c->hf[1][i], &q->hf[0][k], &q->hf[1][k], &ws);
        if (k == 0) { /* the exact distance is the library's */
            double ref;
            if (amscr_channel_distance(p, c->d[1], q->d[0], &ref) != AMSCR_OK || fabs(ref - e[1]) > 1e-9 * (1 + ref))
                die("the exact distance differs from amscr_channel_distance");
        }
        count(c, q, k, e, sd, rank, t);
    }
    amscr__hf_ws_free(&ws);
    free(e);
    free(sd);
    free(rank);
}

/* The CPU time (1 thread, median over TIMED queries) of a query's parts: t[0] the fixed part
 * (prepare, the query's height functions in both frames, its signature, the n signature
 * distances, the top 256), t[1] one candidate's match from stored height functions (two
 * frames), t[2] building one candidate's height functions (two frames). */
static void query_parts(const amscr_params *p, const prepared *c, amscr_contour *const *qc, size_t nq, double t[3])
{
    size_t n = c->n, *cand = xmalloc(n * sizeof *cand), m = n < 256 ? n : 256;
    double *sd = xmalloc(n * sizeof *sd), qs[DIM], ms[3][TIMED];
    amscr__hf_ws ws;
    ws_init(p, c->d[0]->n, &ws);
    nq = nq < TIMED ? nq : TIMED;
    for (size_t k = 0; k < nq; k++) {
        amscr__hf h[2], b[2];
        double t0 = cpu_now(), acc = 0.0;
        amscr_descriptor *dq = prepare(p, qc[k]);
        for (int f = 0; f < 2; f++)
            if (amscr__hf_of_descriptor(p, f ? AMSCR_INVARIANCE_AFFINE : AMSCR_INVARIANCE_SIMILARITY, dq, &h[f]))
                die("height functions");
        amscr__affine_signature(dq, qs);
        for (size_t j = 0; j < n; j++)
            sd[j] = amscr__affine_signature_distance(qs, c->sig + j * DIM);
        if (amscr_topk(sd, n, m, SIZE_MAX, cand) != AMSCR_OK)
            die("top-k");
        double t1 = cpu_now();
        for (size_t j = 0; j < m; j++)
            acc += two_frames(p, &c->hf[0][cand[j]], &c->hf[1][cand[j]], &h[0], &h[1], &ws);
        double t2 = cpu_now();
        for (size_t j = 0; j < 16; j++)
            for (int f = 0; f < 2; f++) {
                if (amscr__hf_of_descriptor(p, f ? AMSCR_INVARIANCE_AFFINE : AMSCR_INVARIANCE_SIMILARITY,
                                            c->d[cand[j]], &b[f]) != AMSCR_OK)
                    die("height functions");
                amscr__hf_free(&b[f]);
            }
        double t3 = cpu_now();
        ms[0][k] = 1e3 * (t1 - t0);
        ms[1][k] = 1e3 * (t2 - t1) / (double)m + 0.0 * acc;
        ms[2][k] = 1e3 * (t3 - t2) / 16.0;
        amscr__hf_free(&h[0]);
        amscr__hf_free(&h[1]);
        amscr_descriptor_free(dq);
    }
    for (int r = 0; r < 3; r++) {
        qsort(ms[r], nq, sizeof ms[r][0], cmp_double);
        t[r] = nq ? ms[r][nq / 2] : 0.0;
    }
    amscr__hf_ws_free(&ws);
    free(cand);
    free(sd);
}

static void print_times(const char *name, const amscr_params *p, const prepared *c, const shape_set *qs)
{
    double t[3];
    query_parts(p, c, qs->c, qs->n, t);
    printf("| %s | time | %s: query ms (stored height functions / built per candidate); fixed %.2f ms, "
           "%.1f + %.1f us per candidate |", name, SIG_NAME, t[0], 1e3 * t[1], 1e3 * t[2]);
    for (int m = 0; m < NM; m++)
        printf(" %.1f / %.0f |", t[0] + (double)MS[m] * t[1], t[0] + (double)MS[m] * (t[1] + t[2]));
    printf("\n");
}

/* nq random affine copies of shapes of s whose class is in fold `which` (0 A, 1 B). */
static void make_queries(const shape_set *s, const int32_t *fold, int which, size_t nq, unsigned long long seed,
                         shape_set *q)
{
    size_t *pool = xmalloc(s->n * sizeof *pool), np = 0;
    for (size_t i = 0; i < s->n; i++)
        if (fold[s->labels[i]] == which)
            pool[np++] = i;
    if (np == 0)
        die("no shape in the fold");
    q->n = nq;
    q->c = xmalloc(nq * sizeof *q->c);
    q->labels = xmalloc(nq * sizeof *q->labels);
    for (size_t k = 0; k < nq; k++) {
        size_t i = pool[(size_t)(warp_urand(&seed) * (double)np) % np];
        if (!(q->c[k] = warp_affine(s->c[i], &seed)))
            die("affine copy");
        q->labels[k] = s->labels[i];
    }
    free(pool);
}

/* mpeg7-dev plus one affine copy of every shape. */
static void make_mixed(const shape_set *s, shape_set *out)
{
    unsigned long long seed = 0x5DEECE66Dull;
    out->n = 2 * s->n;
    out->c = xmalloc(out->n * sizeof *out->c);
    out->labels = xmalloc(out->n * sizeof *out->labels);
    for (size_t i = 0; i < s->n; i++) {
        amscr_contour *copy = NULL;
        if (amscr_contour_new(amscr_contour_xy(s->c[i]), amscr_contour_size(s->c[i]), &copy) != AMSCR_OK)
            die("copy");
        out->c[i] = copy;
        if (!(out->c[s->n + i] = warp_affine(s->c[i], &seed)))
            die("affine copy");
        out->labels[i] = out->labels[s->n + i] = s->labels[i];
    }
}

static void run_set(const amscr_params *p, const char *name, const shape_set *s, const int32_t *fold, size_t nq,
                    int timing)
{
    prepared c;
    prepare_set(p, s->c, s->n, &c);
    for (char which = 'A'; which <= 'B'; which++) {
        shape_set qs;
        make_queries(s, fold, which - 'A', nq, 0x9E3779B97F4A7C15ull + (unsigned long long)which, &qs);
        prepared q;
        prepare_set(p, qs.c, qs.n, &q);
        tally t;
        recall(p, &c, &q, &t);
        printf("| %s | %c | %s |", name, which, SIG_NAME);
        for (int m = 0; m < NM; m++)
            printf(" %.1f / %.0f |", 100.0 * (double)t.top[m] / (double)(TOP * t.nq),
                   100.0 * (double)t.first[m] / (double)t.nq);
        printf("\n");
        fflush(stdout);
        if (timing && which == 'A')
            print_times(name, p, &c, &qs);
        prepared_free(&q);
        shape_set_free(&qs);
    }
    prepared_free(&c);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: amscr-signature-recall DATASETS [QUERIES]\n");
        return 2;
    }
    size_t nq = argc == 3 ? (size_t)strtoul(argv[2], NULL, 10) : 100;
    char manifest[4096];
    snprintf(manifest, sizeof manifest, "%s/mpeg7-dev/manifest.tsv", argv[1]);
    shape_set base, mixed, synth;
    amscr_params *p = NULL;
    int32_t fold[256];
    if (shape_set_load(manifest, &base) != 0 || shape_set_mcd(manifest, MCD_SEED, &synth) != 0 ||
        folds_tsv_read(manifest, fold, 256) != 0)
        return 77;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_params_set_num_threads(p, 1) != AMSCR_OK)
        die("params");
    make_mixed(&base, &mixed);
    printf("Shortlist recall: %% of the exact top %d inside the M signature-nearest / %% of queries whose exact "
           "first hit is inside; %zu affine queries per fold\n\n", TOP, nq);
    printf("| collection | fold | signature |");
    for (int m = 0; m < NM; m++)
        printf(" M = %zu |", MS[m]);
    printf("\n|---|---|---|---|---|---|---|---|\n");
    run_set(p, "mpeg7-dev (700)", &base, fold, nq, 0);
    run_set(p, "synthetic affine (490)", &synth, fold, nq, 0);
    run_set(p, "mpeg7-dev + affine copies (1400)", &mixed, fold, nq, 1);
    amscr_params_free(p);
    shape_set_free(&base);
    shape_set_free(&mixed);
    shape_set_free(&synth);
    return 0;
}
