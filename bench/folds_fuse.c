/* folds_fuse.c — a proportion channel fused by principle (`amscr-retrieval-folds DATASETS fuse`):
 * the global Fourier magnitudes or four low-order moments (folds_base.c) added to the shape
 * channel either over the off-diagonal medians (the library's fusion rule) or in units of each
 * channel's own neighbourhood scale (the distance of a shape to its k-th neighbour in that
 * channel, k = the re-ranking's), optionally weighted per query by each channel's confidence.
 * Every row on fold A and fold B (re-ranked and before re-ranking: fold B sits at 100 % after
 * it), mpeg7-dev, Kimia-99 / 216 and the MCD-style affine views. */
#include "folds.h"

#include <stdio.h>
#include <stdlib.h>

#include "collection.h"

static int fold_idx(const folds_data *fd, int which, size_t *idx)
{
    int m = 0;
    for (size_t i = 0; i < fd->dev.s.n; i++)
        if (fd->fold[i] == which)
            idx[m++] = i;
    return m;
}

static const base_t *g_bdk, *g_bdw; /* the 916- and 1400-shape collections' base matrices */

static int row(const folds_data *fd, const base_t *bd, const base_t *b99, const base_t *b216, const base_t *bm,
               const coll_t *mcd, const size_t *ia, size_t na, const size_t *ib, size_t nb, const post_cfg *p,
               const char *label)
{
    post_cfg p0 = *p;
    p0.k = 0;
    double t0 = folds_now();
    double a = eval_sub(bd, &fd->dev, ia, na, p), b = eval_sub(bd, &fd->dev, ib, nb, p);
    double a0 = eval_sub(bd, &fd->dev, ia, na, &p0), b0 = eval_sub(bd, &fd->dev, ib, nb, &p0);
    double dev = eval_sub(bd, &fd->dev, NULL, 0, p), k99 = eval_sub(b99, &fd->k99, NULL, 0, p);
    double k216 = eval_sub(b216, &fd->k216, NULL, 0, p), mc = eval_sub(bm, mcd, NULL, 0, p);
    double dk = eval_sub(g_bdk, &fd->devk216, NULL, 0, p), dw = eval_sub(g_bdw, &fd->devwarp, NULL, 0, p);
    printf("| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.2f | %.2f | %.2f | %.1f |\n", label, a, b, a0, b0,
           dev, k99, k216, mc, dk, dw, folds_now() - t0);
    fflush(stdout);
    return 0;
}

int folds_fuse(const folds_data *fd, const char *datasets)
{
    static const char *props[] = {"Fourier", "moments", "moments, affine frame", "moments, both frames"};
    static const char *modes[] = {"medians", "local scales", "local + confidence"};
    static const double ws[] = {0.02, 0.05, 0.1, 0.2, 0.5};
    char path[1024], label[160];
    coll_t mcd = {"mcd", {0}, 0};
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", datasets);
    base_t bd, b99, b216, bm, bdk, bdw;
    if (shape_set_mcd(path, MCD_SEED, &mcd.s) != 0 || base_get(&fd->dev, &RAW_DEFAULT, 0, 2, &bd) != 0 ||
        base_get(&fd->k99, &RAW_DEFAULT, 0, 2, &b99) != 0 || base_get(&fd->k216, &RAW_DEFAULT, 0, 2, &b216) != 0 ||
        base_get(&mcd, &RAW_DEFAULT, 0, 2, &bm) != 0 || base_get(&fd->devk216, &RAW_DEFAULT, 0, 2, &bdk) != 0 ||
        base_get(&fd->devwarp, &RAW_DEFAULT, 0, 2, &bdw) != 0)
        return 1;
    g_bdk = &bdk;
    g_bdw = &bdw;
    size_t *ia = malloc(fd->dev.s.n * sizeof *ia), *ib = malloc(fd->dev.s.n * sizeof *ib);
    size_t na = (size_t)fold_idx(fd, 0, ia), nb = (size_t)fold_idx(fd, 1, ib);
    const char *only = getenv("FUSE_ONLY"); /* "d": the default rows only */
    for (int fast = 0; fast < 2; fast++) {
        printf("\n%s\n\n| proportion channel, fusion, weight | fold A | fold B | fold A k 0 | fold B k 0 | mpeg7-dev | "
               "Kimia-99 | Kimia-216 | MCD-style | dev+K216 (916) | dev+warped (1400) | s |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
               fast ? "--fast (affine share 0)" : "default (affine share 0.2)");
        post_cfg p = POST_DEFAULT;
        p.share = fast ? 0.0 : POST_DEFAULT.share;
        row(fd, &bd, &b99, &b216, &bm, &mcd, ia, na, ib, nb, &p, "none (the preset) *");
        p.fmode = 1;
        row(fd, &bd, &b99, &b216, &bm, &mcd, ia, na, ib, nb, &p, "none, channel in local scales");
        int pr0 = getenv("FUSE_PROP") ? atoi(getenv("FUSE_PROP")) : 0;
        for (int pr = pr0; pr < 4 && !(only && *only == 'd'); pr++)
            for (int fm = 0; fm < 3; fm++)
                for (size_t w = 0; w < sizeof ws / sizeof ws[0]; w++) {
                    p.prop = pr;
                    p.fmode = fm;
                    p.wfd = ws[w];
                    snprintf(label, sizeof label, "%s, %s, %g", props[pr], modes[fm], ws[w]);
                    row(fd, &bd, &b99, &b216, &bm, &mcd, ia, na, ib, nb, &p, label);
                }
    }
    base_free(&bd);
    base_free(&b99);
    base_free(&b216);
    base_free(&bm);
    base_free(&bdk);
    base_free(&bdw);
    shape_set_free(&mcd.s);
    free(ia);
    free(ib);
    return 0;
}

/* The channel rescaled before re-ranking (`amscr-retrieval-folds DATASETS local`): local scaling by
 * the lsk-th neighbour's distance, by the mean distance to the lsk nearest (NICDM), and mutual
 * proximity (empirical and Gaussian: no parameter), on every split re-ranked and before
 * re-ranking, plus the larger collections of the scale sweep (916 and 1400 shapes). */
int folds_local(const folds_data *fd, const char *datasets)
{
    static const struct {
        int how;
        size_t k;
        const char *name;
    } rows[] = {{0, 0, "as is (the preset) *"}, {1, 1, "local, 1st neighbour"},  {1, 2, "local, 2nd"},
                {1, 4, "local, 4th"},          {1, 6, "local, 6th"},             {1, 8, "local, 8th"},
                {1, 12, "local, 12th"},        {2, 2, "NICDM, mean of 2"},       {2, 4, "NICDM, mean of 4"},
                {2, 8, "NICDM, mean of 8"},    {3, 0, "mutual proximity, empirical"},
                {4, 0, "mutual proximity, Gaussian"}};
    char path[1024];
    coll_t mcd = {"mcd", {0}, 0};
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", datasets);
    base_t bd, b99, b216, bm, bdk, bdw;
    if (shape_set_mcd(path, MCD_SEED, &mcd.s) != 0 || base_get(&fd->dev, &RAW_DEFAULT, 0, 0, &bd) != 0 ||
        base_get(&fd->k99, &RAW_DEFAULT, 0, 0, &b99) != 0 || base_get(&fd->k216, &RAW_DEFAULT, 0, 0, &b216) != 0 ||
        base_get(&mcd, &RAW_DEFAULT, 0, 0, &bm) != 0 || base_get(&fd->devk216, &RAW_DEFAULT, 0, 0, &bdk) != 0 ||
        base_get(&fd->devwarp, &RAW_DEFAULT, 0, 0, &bdw) != 0)
        return 1;
    size_t *ia = malloc(fd->dev.s.n * sizeof *ia), *ib = malloc(fd->dev.s.n * sizeof *ib);
    size_t na = (size_t)fold_idx(fd, 0, ia), nb = (size_t)fold_idx(fd, 1, ib);
    const char *ks = getenv("LOCAL_K"); /* re-ranking k (default 8) */
    for (int fast = 0; fast < 2; fast++) {
        printf("\n%s, re-ranking k %s: re-ranked / before re-ranking (k 0)\n\n| channel before re-ranking | fold A | "
               "fold B | mpeg7-dev | Kimia-99 | Kimia-216 | MCD-style | dev+K216 (916) | dev+warped (1400) | s |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n",
               fast ? "--fast (affine share 0)" : "default (affine share 0.2)", ks ? ks : "8");
        for (size_t r = 0; r < sizeof rows / sizeof rows[0]; r++) {
            post_cfg p = POST_DEFAULT, p0;
            p.share = fast ? 0.0 : POST_DEFAULT.share;
            p.k = ks ? (size_t)atoi(ks) : POST_DEFAULT.k;
            p.scale = rows[r].how;
            p.lsk = rows[r].k;
            p0 = p;
            p0.k = 0;
            double t0 = folds_now(), v[16];
            const post_cfg *pp[2] = {&p, &p0};
            for (int z = 0; z < 2; z++) {
                v[z] = eval_sub(&bd, &fd->dev, ia, na, pp[z]);
                v[2 + z] = eval_sub(&bd, &fd->dev, ib, nb, pp[z]);
                v[4 + z] = eval_sub(&bd, &fd->dev, NULL, 0, pp[z]);
                v[6 + z] = eval_sub(&b99, &fd->k99, NULL, 0, pp[z]);
                v[8 + z] = eval_sub(&b216, &fd->k216, NULL, 0, pp[z]);
                v[10 + z] = eval_sub(&bm, &mcd, NULL, 0, pp[z]);
                v[12 + z] = eval_sub(&bdk, &fd->devk216, NULL, 0, pp[z]);
                v[14 + z] = eval_sub(&bdw, &fd->devwarp, NULL, 0, pp[z]);
            }
            printf("| %s | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.0f / %.0f | %.0f / %.0f | %.2f / %.2f | %.2f / "
                   "%.2f | %.2f / %.2f | %.1f |\n",
                   rows[r].name, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13],
                   v[14], v[15], folds_now() - t0);
            fflush(stdout);
        }
    }
    base_free(&bd);
    base_free(&b99);
    base_free(&b216);
    base_free(&bm);
    base_free(&bdk);
    base_free(&bdw);
    shape_set_free(&mcd.s);
    free(ia);
    free(ib);
    return 0;
}

size_t folds_subset(const folds_data *fd, int C, int L, unsigned long long *seed, int *perm, int *in, size_t *idx)
{
    folds_shuffle(perm, L, seed);
    for (int c = 0; c < L; c++)
        in[perm[c]] = c < C;
    size_t m = 0;
    for (size_t i = 0; i < fd->dev.s.n; i++)
        if (in[fd->dev.s.labels[i]])
            idx[m++] = i;
    return m;
}

/* Candidates against the preset on many random class halves of mpeg7-dev (`... halves`): each half
 * (17 or 18 of the 35 classes, seeded; HALVES_CLASSES=C: C and 35 - C) is its own collection; per
 * candidate the mean gain over the preset and the share of halves it helps (re-ranked and before
 * re-ranking). One fixed fold pair can be lucky; a rule that generalizes helps on most class
 * subsets. */
int folds_halves(const folds_data *fd)
{
    static const struct {
        int prop, fmode, scale;
        double w;
        const char *name;
    } cand[] = {{0, 0, 0, 0.0, "the preset"},
                {0, 1, 0, 0.0, "channel in local scales"},
                {0, 0, 4, 0.0, "mutual proximity (Gaussian)"},
                {1, 0, 0, 0.02, "moments, medians, 0.02"},
                {1, 1, 0, 0.02, "moments, local scales, 0.02"},
                {1, 2, 0, 0.05, "moments, local + confidence, 0.05"},
                {2, 1, 0, 0.02, "moments (affine frame), local scales, 0.02"},
                {2, 2, 0, 0.02, "moments (affine frame), local + confidence, 0.02"},
                {3, 1, 0, 0.02, "moments (both frames, 0.8 / 0.2), local scales, 0.02"},
                {3, 1, 0, 0.1, "moments (both frames, 0.8 / 0.2), local scales, 0.1"},
                {0, 1, 0, 0.05, "Fourier, local scales, 0.05"}};
    enum { NC = sizeof cand / sizeof cand[0], NH = 24 };
    base_t bd;
    if (base_get(&fd->dev, &RAW_DEFAULT, 0, 2, &bd) != 0)
        return 1;
    size_t n = fd->dev.s.n, *idx = malloc(n * sizeof *idx);
    int32_t maxl = 0;
    for (size_t i = 0; i < n; i++)
        maxl = fd->dev.s.labels[i] > maxl ? fd->dev.s.labels[i] : maxl;
    int *in = malloc(((size_t)maxl + 1) * sizeof *in), *perm = malloc(((size_t)maxl + 1) * sizeof *perm);
    double sum[2][NC][2] = {{{0}}}, wins[2][NC][2] = {{{0}}}, loss[2][NC][2] = {{{0}}}, base[2][2] = {{0}};
    unsigned long long seed = 0x2545F4914F6CDD1Dull;
    for (int h = 0; h < NH; h++) {
        int L = maxl + 1;
        folds_shuffle(perm, L, &seed);
        int C = getenv("HALVES_CLASSES") ? atoi(getenv("HALVES_CLASSES")) : L / 2; /* classes of the first */
        for (int half = 0; half < 2; half++) {
            for (int c = 0; c < L; c++)
                in[perm[c]] = half ? c >= C : c < C;
            size_t m = 0;
            for (size_t i = 0; i < n; i++)
                if (in[fd->dev.s.labels[i]])
                    idx[m++] = i;
            double ref[2] = {0};
            for (int c = 0; c < NC; c++)
                for (int z = 0; z < 2; z++) {
                    post_cfg p = POST_DEFAULT;
                    p.prop = cand[c].prop;
                    p.fmode = cand[c].fmode;
                    p.scale = cand[c].scale;
                    p.wfd = cand[c].w;
                    if (z)
                        p.k = 0;
                    double v = eval_sub(&bd, &fd->dev, idx, m, &p);
                    if (c == 0) {
                        ref[z] = v;
                        base[half][z] += v / NH;
                    }
                    sum[half][c][z] += (v - ref[z]) / NH;
                    wins[half][c][z] += v > ref[z] + 1e-9;
                    loss[half][c][z] += v < ref[z] - 1e-9;
                }
        }
    }
    int C = getenv("HALVES_CLASSES") ? atoi(getenv("HALVES_CLASSES")) : (maxl + 1) / 2;
    for (int half = 0; half < 2; half++) {
        printf("\n%d random collections of %d of mpeg7-dev's %d classes (seeded); the preset's mean: %.2f %% "
               "re-ranked, %.2f %% before\n\n| candidate | mean gain re-ranked | better / worse (of %d) | mean gain before "
               "re-ranking | better / worse |\n|---|---|---|---|---|\n",
               NH, half ? maxl + 1 - C : C, maxl + 1, base[half][0], base[half][1], NH);
        for (int c = 1; c < NC; c++)
            printf("| %s | %+.2f | %.0f / %.0f | %+.2f | %.0f / %.0f |\n", cand[c].name, sum[half][c][0],
                   wins[half][c][0], loss[half][c][0], sum[half][c][1], wins[half][c][1], loss[half][c][1]);
    }
    base_free(&bd);
    free(idx);
    free(in);
    free(perm);
    return 0;
}

/* Where the candidates win and lose (`... classes`): 1-NN accuracy (the leaf and ETH-80 protocol)
 * on mpeg7-dev, Kimia-99, Kimia-216 and the 916-shape collection (with its bull's eye), and the
 * mpeg7-dev classes' bull's eye. out: bull's eye % and 1-NN %, class-size weighted. */
static void part_scores(const double *F, const coll_t *c, double out[2])
{
    size_t n = c->s.n, nc = 0;
    out[0] = out[1] = 0.0;
    if (amscr_score_classes(c->s.labels, n, NULL, NULL, &nc) != AMSCR_OK)
        return;
    double *be = malloc(nc * sizeof *be), *nn = malloc(nc * sizeof *nn);
    int32_t *cls = malloc(nc * sizeof *cls);
    size_t *sz = malloc(nc * sizeof *sz);
    if (amscr_score_classes(c->s.labels, n, cls, sz, &nc) == AMSCR_OK &&
        amscr_score_per_class(F, n, c->s.labels, nc, be, nn) == AMSCR_OK)
        for (size_t k = 0; k < nc; k++) {
            out[0] += 100.0 * be[k] * (double)sz[k] / (double)n;
            out[1] += 100.0 * nn[k] * (double)sz[k] / (double)n;
        }
    free(be);
    free(nn);
    free(cls);
    free(sz);
}

int folds_classes(const folds_data *fd, const char *datasets)
{
    static const struct {
        int prop, fmode;
        double w;
        const char *name;
    } cand[] = {{0, 0, 0.0, "the preset"},
                {0, 1, 0.0, "channel in local scales"},
                {3, 1, 0.02, "moments (both frames), local scales, 0.02"},
                {3, 1, 0.1, "moments (both frames), local scales, 0.1"},
                {2, 1, 0.02, "moments (affine frame), local scales, 0.02"}};
    enum { NC = sizeof cand / sizeof cand[0] };
    const coll_t *cs[4] = {&fd->dev, &fd->k99, &fd->k216, &fd->devk216};
    base_t b[4];
    for (int t = 0; t < 4; t++)
        if (base_get(cs[t], &RAW_DEFAULT, 0, 2, &b[t]) != 0)
            return 1;
    size_t n = fd->dev.s.n, nc = 0;
    if (amscr_score_classes(fd->dev.s.labels, n, NULL, NULL, &nc) != AMSCR_OK)
        return 1;
    double *be[NC];
    printf("| candidate | 1-NN mpeg7-dev | 1-NN Kimia-99 | 1-NN Kimia-216 | 916: 1-NN | 916: bull's eye (class-size "
           "weighted) |\n|---|---|---|---|---|---|\n");
    for (int c = 0; c < NC; c++) {
        post_cfg p = POST_DEFAULT;
        p.prop = cand[c].prop;
        p.fmode = cand[c].fmode;
        p.wfd = cand[c].w;
        double v[4][2] = {{0}};
        be[c] = malloc(nc * sizeof *be[c]);
        for (int t = 0; t < 4; t++) {
            double *F = eval_matrix(&b[t], NULL, 0, &p);
            if (!F)
                return 1;
            part_scores(F, cs[t], v[t]);
            if (t == 0 && amscr_score_per_class(F, n, fd->dev.s.labels, nc, be[c], NULL) != AMSCR_OK)
                return 1;
            free(F);
        }
        printf("| %s | %.2f | %.2f | %.2f | %.2f | %.2f |\n", cand[c].name, v[0][1], v[1][1], v[2][1], v[3][1],
               v[3][0]);
    }
    char path[1024];
    collection col;
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", datasets);
    if (collection_open(path, &col) != 0)
        return 1;
    printf("\nmpeg7-dev classes, bull's eye %% (fold in brackets): the preset, then each candidate\n\n| class |");
    for (int c = 0; c < NC; c++)
        printf(" %s |", cand[c].name);
    printf("\n|---|");
    for (int c = 0; c < NC; c++)
        printf("---|");
    printf("\n");
    for (size_t k = 0; k < nc && k < col.nclasses; k++) {
        int fold = 0;
        for (size_t i = 0; i < n; i++)
            if (fd->dev.s.labels[i] == (int32_t)k)
                fold = fd->fold[i];
        printf("| %s (%c) |", col.classes[k], fold ? 'B' : 'A');
        for (int c = 0; c < NC; c++)
            printf(" %.1f |", 100.0 * be[c][k]);
        printf("\n");
    }
    collection_free(&col);
    for (int c = 0; c < NC; c++)
        free(be[c]);
    for (int t = 0; t < 4; t++)
        base_free(&b[t]);
    return 0;
}
