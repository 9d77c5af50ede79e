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
