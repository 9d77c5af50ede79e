/* folds_inner.c — the share of the inner-distance graph in the re-ranking judged on many class
 * subsets (`amscr-retrieval-folds DATASETS inner`): for each share, the mean gain over one graph
 * (share 0, the setting before 0.7) on 24 seeded random subsets of mpeg7-dev's classes at 7, 17
 * and 28 classes (each subset its own collection, bull's eye), with how many subsets it helps
 * and hurts; then the two class folds of mpeg7-dev and every whole collection of the audit. The
 * channel as the retrieval preset computes it (band 0.15, the whitened frame's 0.08). */
#include "folds.h"

#include <stdio.h>
#include <stdlib.h>

enum { NS = 6, NH = 24 };
static const double SHARES[NS] = {0.0, 0.025, 0.05, 0.1, 0.2, 0.3};

/* The base matrices of c as the library's preset computes them: the similarity frame at band
 * 0.15, the whitened frame at 0.08 (RAW_DEFAULT's band, the audit's reference before 0.6). */
static int preset_base(const coll_t *c, base_t *b)
{
    raw_cfg r = RAW_DEFAULT;
    r.band = 0.15;
    base_t aux;
    if (base_get(c, &r, 0, 0, b) != 0 || base_get(c, &RAW_DEFAULT, 0, 0, &aux) != 0)
        return 1;
    double *t = b->ha;
    b->ha = aux.ha;
    aux.ha = t;
    base_free(&aux);
    return 0;
}

static double score_share(const base_t *b, const coll_t *c, const size_t *idx, size_t m, double share)
{
    post_cfg p = POST_DEFAULT;
    p.inner = share;
    return eval_sub(b, c, idx, m, &p);
}

/* The mean gain of each share over share 0 on NH random subsets of C classes. */
static void inner_subsets(const folds_data *fd, const base_t *b, int C)
{
    size_t n = fd->dev.s.n, *idx = malloc(n * sizeof *idx);
    int L = 0;
    for (size_t i = 0; i < n; i++)
        L = fd->dev.s.labels[i] + 1 > L ? fd->dev.s.labels[i] + 1 : L;
    int *in = malloc((size_t)L * sizeof *in), *perm = malloc((size_t)L * sizeof *perm);
    double sum[NS] = {0}, base = 0.0;
    int wins[NS] = {0}, loss[NS] = {0};
    unsigned long long seed = 0x9E3779B97F4A7C15ull + (unsigned long long)C; /* folds_band's subsets */
    for (int h = 0; h < NH; h++) {
        size_t m = folds_subset(fd, C, L, &seed, perm, in, idx);
        double ref = score_share(b, &fd->dev, idx, m, 0.0);
        base += ref / NH;
        for (int s = 1; s < NS; s++) {
            double v = score_share(b, &fd->dev, idx, m, SHARES[s]);
            sum[s] += (v - ref) / NH;
            wins[s] += v > ref + 1e-9;
            loss[s] += v < ref - 1e-9;
        }
    }
    printf("\n%d random collections of %d of mpeg7-dev's %d classes (seeded); one graph: %.2f %%\n\n"
           "| inner share | mean gain | better / worse (of %d) |\n|---|---|---|\n", NH, C, L, base, NH);
    for (int s = 1; s < NS; s++)
        printf("| %.3g | %+.2f | %d / %d |\n", SHARES[s], sum[s], wins[s], loss[s]);
    free(idx);
    free(in);
    free(perm);
}

/* The folds of mpeg7-dev and every whole collection (bull's eye % or top-k sum) per share. */
static int inner_collections(const folds_data *fd, const base_t *dev)
{
    size_t n = fd->dev.s.n, na = 0, nb = 0, *ia = malloc(n * sizeof *ia), *ib = malloc(n * sizeof *ib);
    for (size_t i = 0; i < n; i++) {
        if (fd->fold[i])
            ib[nb++] = i;
        else
            ia[na++] = i;
    }
    const coll_t *cs[4] = {&fd->k99, &fd->k216, &fd->devwarp, &fd->devk216};
    base_t b[4];
    for (int c = 0; c < 4; c++)
        if (preset_base(cs[c], &b[c]) != 0)
            return 1;
    printf("\n| inner share | fold A | fold B | mpeg7-dev | Kimia-99 | Kimia-216 | %s | %s |\n"
           "|---|---|---|---|---|---|---|---|\n", fd->devwarp.name, fd->devk216.name);
    for (int s = 0; s < NS; s++) {
        printf("| %.3g | %.2f | %.2f | %.2f |", SHARES[s], score_share(dev, &fd->dev, ia, na, SHARES[s]),
               score_share(dev, &fd->dev, ib, nb, SHARES[s]), score_share(dev, &fd->dev, NULL, 0, SHARES[s]));
        for (int c = 0; c < 4; c++)
            printf(cs[c]->kind ? " %.0f |" : " %.2f |", score_share(&b[c], cs[c], NULL, 0, SHARES[s]));
        printf("\n");
        fflush(stdout);
    }
    for (int c = 0; c < 4; c++)
        base_free(&b[c]);
    free(ia);
    free(ib);
    return 0;
}

int folds_inner(const folds_data *fd)
{
    base_t b;
    if (preset_base(&fd->dev, &b) != 0)
        return 1;
    static const int sizes[] = {7, 17, 28};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++)
        inner_subsets(fd, &b, sizes[s]);
    int r = inner_collections(fd, &b);
    base_free(&b);
    return r;
}
