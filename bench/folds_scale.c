/* folds_scale.c — re-ranking k against the collection's size and class size: bull's eye of the
 * default channel at every k on fold A (360 shapes), fold B (340), mpeg7-dev (700),
 * mpeg7-dev + Kimia-216 (916: Kimia-216 labelled by class name, classes of 20 and 32) and
 * mpeg7-dev + a mild affine copy of every shape (1400: twice the class size); then k = c sqrt(n),
 * and k = 1 + the median count of mutual neighbours among each shape's K nearest (the mutual-kNN
 * graph: a class-size estimate). */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static const double KS[] = {0, 4, 6, 8, 10, 12, 16, 20, 24, 32, 40};
static const double CS[] = {0.2, 0.3, 0.4, 0.5};
static const double MK[] = {16, 24, 32, 48};
enum { NK = sizeof KS / sizeof KS[0], NC = sizeof CS / sizeof CS[0], NM = sizeof MK / sizeof MK[0] };

static void row(const char *name, const base_t *b, const coll_t *c, const size_t *idx, size_t m, const post_cfg *p0)
{
    post_cfg p = *p0;
    printf("| %s (%zu) |", name, idx ? m : b->n);
    for (int i = 0; i < NK; i++) {
        p.kmode = 0;
        p.k = (size_t)KS[i];
        printf(" %.2f |", eval_sub(b, c, idx, m, &p));
        fflush(stdout);
    }
    for (int i = 0; i < NC; i++) {
        p.kmode = 1;
        p.kfrac = CS[i];
        printf(" %.2f |", eval_sub(b, c, idx, m, &p));
        fflush(stdout);
    }
    for (int i = 0; i < NM; i++) {
        p.kmode = 2;
        p.kfrac = MK[i];
        double sc = eval_sub(b, c, idx, m, &p);
        printf(" %.2f (k %zu) |", sc, last_k);
        fflush(stdout);
    }
    printf("\n");
}

static int table(const folds_data *fd, const post_cfg *p, const char *tag)
{
    printf("\n%s: bull's eye %% by re-ranking k (10 iterations), then k = c sqrt(n)\n\n| collection |", tag);
    for (int i = 0; i < NK; i++)
        printf(" k %g |", KS[i]);
    for (int i = 0; i < NC; i++)
        printf(" %g sqrt(n) |", CS[i]);
    for (int i = 0; i < NM; i++)
        printf(" mutual in %g |", MK[i]);
    printf("\n|---|");
    for (int i = 0; i < NK + NC + NM; i++)
        printf("---|");
    printf("\n");
    size_t n = fd->dev.s.n, na = 0, nb = 0;
    size_t *ia = malloc(n * sizeof *ia), *ib = malloc(n * sizeof *ib);
    for (size_t i = 0; i < n; i++) {
        if (fd->fold[i])
            ib[nb++] = i;
        else
            ia[na++] = i;
    }
    base_t b;
    if (base_get(&fd->dev, &RAW_DEFAULT, 0, 0, &b) != 0)
        return 1;
    row("fold A", &b, &fd->dev, ia, na, p);
    row("fold B", &b, &fd->dev, ib, nb, p);
    row("mpeg7-dev", &b, &fd->dev, NULL, 0, p);
    base_free(&b);
    free(ia);
    free(ib);
    if (base_get(&fd->devk216, &RAW_DEFAULT, 0, 0, &b) != 0)
        return 1;
    row("mpeg7-dev + Kimia-216", &b, &fd->devk216, NULL, 0, p);
    base_free(&b);
    if (base_get(&fd->devwarp, &RAW_DEFAULT, 0, 0, &b) != 0)
        return 1;
    row("mpeg7-dev + affine copies", &b, &fd->devwarp, NULL, 0, p);
    base_free(&b);
    return 0;
}

int folds_scale(const folds_data *fd)
{
    post_cfg fast = POST_DEFAULT;
    fast.share = 0.0;
    return table(fd, &POST_DEFAULT, "default (affine share 0.2)") || table(fd, &fast, "--fast (affine share 0)");
}
