/* folds_band.c — the channel's band (the DP's tolerance to articulation) judged on many class
 * subsets (`amscr-retrieval-folds DATASETS band`): for each band, the mean gain over band 0.08 (the
 * setting before 0.6) on 24 seeded random subsets of mpeg7-dev's classes at 7, 17 and 28 classes
 * (each subset its own collection, bull's eye), re-ranked and before re-ranking, with how many
 * subsets it helps and hurts; then every whole collection of the audit. */
#include "folds.h"

#include <stdio.h>
#include <stdlib.h>

enum { NB = 5, NH = 24 };
/* The last row: band 0.15 in the similarity frame, 0.08 in the affine frame (MIXED). */
static const double BANDS[NB] = {0.08, 0.11, 0.15, 0.20, 0.15};
enum { MIXED = NB - 1 };
static const char *band_name(int b)
{
    static char buf[NB][32];
    snprintf(buf[b], sizeof buf[b], b == MIXED ? "%.2f / affine 0.08" : "%.2f", BANDS[b]);
    return buf[b];
}

/* base_t of band b: the mixed row borrows the affine frame of band 0 (not freed twice). */
static base_t mixed_base(const base_t *bd, int b)
{
    base_t m = bd[b];
    if (b == MIXED)
        m.ha = bd[0].ha;
    return m;
}

/* The mean gain of each band over BANDS[0] on NH random subsets of C classes. */
static void band_subsets(const folds_data *fd, base_t *bd, int C)
{
    size_t n = fd->dev.s.n, *idx = malloc(n * sizeof *idx);
    int L = 0;
    for (size_t i = 0; i < n; i++)
        L = fd->dev.s.labels[i] + 1 > L ? fd->dev.s.labels[i] + 1 : L;
    int *in = malloc((size_t)L * sizeof *in), *perm = malloc((size_t)L * sizeof *perm);
    double sum[NB][2] = {{0}}, base[2] = {0};
    int wins[NB][2] = {{0}}, loss[NB][2] = {{0}};
    unsigned long long seed = 0x9E3779B97F4A7C15ull + (unsigned long long)C;
    for (int h = 0; h < NH; h++) {
        size_t m = folds_subset(fd, C, L, &seed, perm, in, idx);
        for (int z = 0; z < 2; z++) {
            post_cfg p = POST_DEFAULT;
            if (z)
                p.k = 0;
            double ref = eval_sub(&bd[0], &fd->dev, idx, m, &p);
            base[z] += ref / NH;
            for (int b = 1; b < NB; b++) {
                base_t mb = mixed_base(bd, b);
                double v = eval_sub(&mb, &fd->dev, idx, m, &p);
                sum[b][z] += (v - ref) / NH;
                wins[b][z] += v > ref + 1e-9;
                loss[b][z] += v < ref - 1e-9;
            }
        }
    }
    printf("\n%d random collections of %d of mpeg7-dev's %d classes (seeded); band 0.08: %.2f %% re-ranked, "
           "%.2f %% before\n\n| band | mean gain re-ranked | better / worse (of %d) | mean gain before re-ranking | "
           "better / worse |\n|---|---|---|---|---|\n",
           NH, C, L, base[0], base[1], NH);
    for (int b = 1; b < NB; b++)
        printf("| %s | %+.2f | %d / %d | %+.2f | %d / %d |\n", band_name(b), sum[b][0], wins[b][0], loss[b][0],
               sum[b][1], wins[b][1], loss[b][1]);
    free(idx);
    free(in);
    free(perm);
}

/* Every whole collection (bull's eye % or top-k sum), re-ranked / before re-ranking, per band. */
static int band_collections(const folds_data *fd)
{
    const coll_t *cs[5] = {&fd->dev, &fd->k99, &fd->k216, &fd->devwarp, &fd->devk216};
    printf("\n| band | mpeg7-dev | Kimia-99 | Kimia-216 | %s | %s |\n|---|---|---|---|---|---|\n", fd->devwarp.name,
           fd->devk216.name);
    for (int b = 0; b < NB; b++) {
        raw_cfg r = RAW_DEFAULT, r0 = RAW_DEFAULT;
        r.band = BANDS[b];
        printf("| %s |", band_name(b));
        for (int c = 0; c < 5; c++) {
            base_t bd[NB];
            if (base_get(cs[c], &r, 0, 0, &bd[b]) != 0 || (b == MIXED && base_get(cs[c], &r0, 0, 0, &bd[0]) != 0))
                return 1;
            base_t mb = mixed_base(bd, b);
            double v[2];
            for (int z = 0; z < 2; z++) {
                post_cfg p = POST_DEFAULT;
                if (z)
                    p.k = 0;
                v[z] = eval_sub(&mb, cs[c], NULL, 0, &p);
            }
            printf(cs[c]->kind ? " %.0f / %.0f |" : " %.2f / %.2f |", v[0], v[1]);
            fflush(stdout);
            base_free(&bd[b]);
            if (b == MIXED)
                base_free(&bd[0]);
        }
        printf("\n");
    }
    return 0;
}

int folds_band(const folds_data *fd)
{
    base_t bd[NB];
    for (int b = 0; b < MIXED; b++) {
        raw_cfg r = RAW_DEFAULT;
        r.band = BANDS[b];
        if (base_get(&fd->dev, &r, 0, 0, &bd[b]) != 0)
            return 1;
    }
    bd[MIXED] = bd[2]; /* its similarity frame; mixed_base adds band 0.08's affine frame */
    static const int sizes[] = {7, 17, 28};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        band_subsets(fd, bd, sizes[s]);
    for (int b = 0; b < MIXED; b++)
        base_free(&bd[b]);
    return band_collections(fd);
}
