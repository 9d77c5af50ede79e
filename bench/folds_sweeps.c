/* folds_sweeps.c — the audit's sweeps: one setting at a time around the default (and --fast), a
 * markdown row per value (fold A, fold B, mpeg7-dev, Kimia-99, Kimia-216), then the verdict:
 * the best value on each fold and what it gives on the other. */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

typedef enum { S_SHARE, S_K, S_ITERS, S_WEIGHT, S_WFD, S_N, S_BAND, S_SKIP, S_LOC, S_REFL } setting;

typedef struct {
    const char *name;
    setting s;
    int nv;
    double v[9];
} sweep_t;

static void apply(setting s, double v, raw_cfg *r, post_cfg *p)
{
    switch (s) {
    case S_SHARE: p->share = v; break;
    case S_K: p->k = (size_t)v; break;
    case S_ITERS: p->iters = (unsigned)v; break;
    case S_WEIGHT: p->weight = v; break;
    case S_WFD: p->wfd = v; break;
    case S_N: r->N = (size_t)v; break;
    case S_BAND: r->band = v; break;
    case S_SKIP: r->skip = v; break;
    case S_LOC: r->loc = v; break;
    case S_REFL: r->refl = (int)v; break;
    }
}

/* Index of the best value on fold A (which 0) or B (which 1); ties: the first. */
static int best_of(const row_scores *rs, int nv, int which)
{
    int b = 0;
    for (int i = 1; i < nv; i++)
        if ((which ? rs[i].b : rs[i].a) > (which ? rs[b].b : rs[b].a))
            b = i;
    return b;
}

static void verdict(const sweep_t *w, const row_scores *rs, int idef)
{
    int ba = best_of(rs, w->nv, 0), bb = best_of(rs, w->nv, 1);
    printf("\n%s: best on fold A = %g (A %.2f, B %.2f: %+.2f vs the default on B); best on fold B = %g (B %.2f, A %.2f: "
           "%+.2f vs the default on A); Kimia at A's best %g / %g\n\n",
           w->name, w->v[ba], rs[ba].a, rs[ba].b, rs[ba].b - rs[idef].b, w->v[bb], rs[bb].b, rs[bb].a,
           rs[bb].a - rs[idef].a, rs[ba].k99, rs[ba].k216);
}

static int run_sweep(const folds_data *fd, const sweep_t *w, const raw_cfg *r0, const post_cfg *p0, const char *tag)
{
    row_scores rs[9] = {{0}};
    int idef = 0;
    printf("| %s (%s) | fold A | fold B | mpeg7-dev | Kimia-99 | Kimia-216 | s |\n|---|---|---|---|---|---|---|\n",
           w->name, tag);
    for (int i = 0; i < w->nv; i++) {
        raw_cfg r = *r0;
        post_cfg p = *p0;
        apply(w->s, w->v[i], &r, &p);
        raw_cfg rd = *r0;
        post_cfg pd = *p0;
        if (memcmp(&r, &rd, sizeof r) == 0 && memcmp(&p, &pd, sizeof p) == 0)
            idef = i;
        double t0 = folds_now();
        if (score_row(fd, &r, &p, &rs[i]) != 0)
            return 1;
        printf("| %g%s | %.2f | %.2f | %.2f | %.0f | %.0f | %.1f |\n", w->v[i], i == idef && memcmp(&p, &pd, sizeof p) == 0 && memcmp(&r, &rd, sizeof r) == 0 ? " *" : "",
               rs[i].a, rs[i].b, rs[i].dev, rs[i].k99, rs[i].k216, folds_now() - t0);
        fflush(stdout);
    }
    verdict(w, rs, idef);
    return 0;
}

int folds_sweep_post(const folds_data *fd)
{
    static const sweep_t sw[] = {
        {"affine share", S_SHARE, 7, {0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0}},
        {"rerank k", S_K, 9, {0, 4, 6, 8, 10, 12, 16, 20, 24}},
        {"rerank iterations", S_ITERS, 7, {1, 2, 3, 5, 10, 20, 40}},
        {"channel weight (AMSCR fusion)", S_WEIGHT, 5, {1.0, 0.9, 0.8, 0.7, 0.5}},
    };
    post_cfg fast = POST_DEFAULT;
    fast.share = 0.0;
    for (size_t i = 0; i < sizeof sw / sizeof sw[0]; i++) {
        if (run_sweep(fd, &sw[i], &RAW_DEFAULT, &POST_DEFAULT, "default") != 0)
            return 1;
        if (sw[i].s != S_SHARE && sw[i].s != S_WEIGHT && run_sweep(fd, &sw[i], &RAW_DEFAULT, &fast, "--fast") != 0)
            return 1;
    }
    return 0;
}

int folds_sweep_raw(const folds_data *fd)
{
    static const sweep_t sw[] = {
        {"band (fraction of N)", S_BAND, 5, {0.04, 0.06, 0.08, 0.11, 0.15}},
        {"skip", S_SKIP, 5, {0.25, 0.5, 1.0, 1.5, 2.0}},
        {"locality", S_LOC, 5, {0, 1, 2, 4, 8}},
        {"reflections", S_REFL, 2, {0, 1}},
        {"N samples", S_N, 3, {96, 128, 160}},
    };
    post_cfg fast = POST_DEFAULT;
    fast.share = 0.0;
    for (size_t i = 0; i < sizeof sw / sizeof sw[0]; i++)
        if (run_sweep(fd, &sw[i], &RAW_DEFAULT, &POST_DEFAULT, "default") != 0 ||
            run_sweep(fd, &sw[i], &RAW_DEFAULT, &fast, "--fast") != 0)
            return 1;
    return 0;
}

int folds_fourier(const folds_data *fd)
{
    static const sweep_t sw = {"Fourier proportion channel weight", S_WFD, 7, {0, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0}};
    post_cfg fast = POST_DEFAULT;
    fast.share = 0.0;
    return run_sweep(fd, &sw, &RAW_DEFAULT, &POST_DEFAULT, "default") || run_sweep(fd, &sw, &RAW_DEFAULT, &fast, "--fast");
}

/* The MCD-style affine views (mcd_set.h, built from mpeg7-dev): bull's eye by band and affine
 * share, re-ranking as the default. */
int folds_mcd(const char *datasets)
{
    static const double bands[] = {0.08, 0.11, 0.15}, shares[] = {0.0, 0.1, 0.2, 0.3};
    char path[1024];
    coll_t c = {"mcd", {0}, 0};
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", datasets);
    if (shape_set_mcd(path, MCD_SEED, &c.s) != 0)
        return 1;
    printf("| MCD-style views (%zu) | share 0 | share 0.1 | share 0.2 | share 0.3 |\n|---|---|---|---|---|\n", c.s.n);
    for (int i = 0; i < 3; i++) {
        raw_cfg r = RAW_DEFAULT;
        r.band = bands[i];
        base_t b;
        if (base_get(&c, &r, 0, 0, &b) != 0)
            return 1;
        printf("| band %g |", bands[i]);
        for (int j = 0; j < 4; j++) {
            post_cfg p = POST_DEFAULT;
            p.share = shares[j];
            printf(" %.2f |", eval_sub(&b, &c, NULL, 0, &p));
        }
        printf("\n");
        fflush(stdout);
        base_free(&b);
    }
    shape_set_free(&c.s);
    return 0;
}

/* One row for a combination: `row N BAND SKIP LOC SHARE K ITERS [STRIDE]` -> the five splits and the
 * MCD-style views (built from mpeg7-dev). */
int folds_row(const folds_data *fd, const char *datasets, char **v)
{
    raw_cfg r = {(size_t)atoi(v[0]), atof(v[1]), atof(v[2]), atof(v[3]), 1, v[7] ? (size_t)atoi(v[7]) : 1};
    post_cfg p = POST_DEFAULT;
    p.share = atof(v[4]);
    p.k = (size_t)atoi(v[5]);
    p.iters = (unsigned)atoi(v[6]);
    row_scores rs;
    if (score_row(fd, &r, &p, &rs) != 0)
        return 1;
    char path[1024];
    coll_t c = {"mcd", {0}, 0};
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", datasets);
    base_t b;
    if (shape_set_mcd(path, MCD_SEED, &c.s) != 0 || base_get(&c, &r, 0, 0, &b) != 0)
        return 1;
    printf("| N %zu band %g skip %g loc %g share %g k %zu iters %u%s | %.2f | %.2f | %.2f | %.0f | %.0f | %.2f |\n", r.N,
           r.band, r.skip, r.loc, p.share, p.k, p.iters, r.stride > 1 ? " stride 2" : "", rs.a, rs.b, rs.dev, rs.k99, rs.k216,
           eval_sub(&b, &c, NULL, 0, &p));
    base_free(&b);
    shape_set_free(&c.s);
    return 0;
}

/* CPU cost of the channel (similarity frame) on Kimia-216 per (N, band, stride), in microseconds of
 * process CPU time per pair (robust to the load of a shared machine, unlike wall time); the
 * configurations are interleaved `rounds` times and the minimum is kept. */
int folds_cost(const folds_data *fd)
{
    static const size_t Ns[] = {128, 128, 128, 96, 96, 112, 128, 128};
    static const double bands[] = {0.08, 0.11, 0.15, 0.11, 0.15, 0.13, 0.15, 0.08};
    static const size_t strides[] = {1, 1, 1, 1, 1, 1, 2, 2};
    enum { NCFG = sizeof Ns / sizeof Ns[0], ROUNDS = 3 };
    double best[NCFG];
    for (int c = 0; c < NCFG; c++)
        best[c] = 1e300;
    for (int round = 0; round < ROUNDS; round++)
        for (int c = 0; c < NCFG; c++) {
            raw_cfg r = RAW_DEFAULT;
            r.N = Ns[c];
            r.band = bands[c];
            r.stride = strides[c];
            double us = folds_channel_cpu(&fd->k216, &r);
            if (us < 0)
                return 1;
            if (us < best[c])
                best[c] = us;
        }
    printf("| N | band | stride | channel CPU us / pair (one frame, Kimia-216, min of %d) | relative |\n"
           "|---|---|---|---|---|\n", ROUNDS);
    for (int c = 0; c < NCFG; c++)
        printf("| %zu | %g | %zu | %.2f | %.2f |\n", Ns[c], bands[c], strides[c], best[c], best[c] / best[0]);
    return 0;
}
