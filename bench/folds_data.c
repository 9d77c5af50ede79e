/* folds_data.c — the audit's collections (mpeg7-dev with its class folds, Kimia-99, Kimia-216,
 * mpeg7-dev + a seeded affine copy of every shape, mpeg7-dev + Kimia-216) and their base
 * matrices, computed through the library's internals and cached on disk. */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "channel.h"
#include "collection.h"

const raw_cfg RAW_DEFAULT = {128, 0.08, 1.0, 4.0, 1, 1};
const post_cfg POST_DEFAULT = {0.2, 1.0, 8, 10, 0.0, 0, 0.0, 0, 0, 0, 0, 0.05};

double folds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double urand(unsigned long long *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}

/* A mild random affine copy: any rotation, axis scales log-uniform in 0.75..1.33, shear
 * +-0.25 (a second view of the same object, not the MCD set's extreme distortions). */
static amscr_contour *warp_copy(const amscr_contour *c, unsigned long long *seed)
{
    size_t n = amscr_contour_size(c);
    const double *xy = amscr_contour_xy(c);
    double th = 6.283185307179586 * urand(seed);
    double sx = exp(log(0.75) + log(1.33 / 0.75) * urand(seed));
    double sy = exp(log(0.75) + log(1.33 / 0.75) * urand(seed));
    double sh = -0.25 + 0.5 * urand(seed), cs = cos(th), sn = sin(th);
    double a = cs * sx, b = cs * sx * sh - sn * sy, c2 = sn * sx, d = sn * sx * sh + cs * sy;
    double *out = malloc(2 * n * sizeof *out);
    amscr_contour *ct = NULL;
    if (!out)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = a * xy[2 * i] + b * xy[2 * i + 1];
        out[2 * i + 1] = c2 * xy[2 * i] + d * xy[2 * i + 1];
    }
    if (amscr_contour_new(out, n, &ct) != AMSCR_OK)
        ct = NULL;
    free(out);
    return ct;
}

/* c = a followed by b (contours copied), b's labels shifted by `shift`; b NULL: a warped copy. */
static int concat(const shape_set *a, const shape_set *b, int32_t shift, shape_set *c)
{
    size_t nb = b ? b->n : a->n;
    c->n = a->n + nb;
    c->c = calloc(c->n, sizeof *c->c);
    c->labels = calloc(c->n, sizeof *c->labels);
    unsigned long long seed = 0x5DEECE66Dull;
    for (size_t i = 0; i < c->n; i++) {
        const shape_set *src = i < a->n ? a : (b ? b : a);
        size_t j = i < a->n ? i : i - a->n;
        if (i >= a->n && !b)
            c->c[i] = warp_copy(a->c[j], &seed);
        else if (amscr_contour_new(amscr_contour_xy(src->c[j]), amscr_contour_size(src->c[j]), &c->c[i]) != AMSCR_OK)
            c->c[i] = NULL;
        c->labels[i] = src->labels[j] + (i >= a->n && b ? shift : 0);
        if (!c->c[i])
            return -1;
    }
    return 0;
}

/* fold of every mpeg7-dev shape from folds.tsv (class<TAB>A|B). */
static int read_folds(const char *dir, const shape_set *s, int *fold)
{
    char path[1024], line[256];
    collection col;
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", dir);
    if (collection_open(path, &col) != 0)
        return -1;
    int *fc = calloc(col.nclasses, sizeof *fc);
    snprintf(path, sizeof path, "%s/mpeg7-dev/folds.tsv", dir);
    FILE *f = fopen(path, "r");
    if (!f || !fc)
        return -1;
    while (fgets(line, sizeof line, f)) {
        char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        *tab = '\0';
        for (size_t k = 0; k < col.nclasses; k++)
            if (strcmp(col.classes[k], line) == 0)
                fc[k] = tab[1] == 'B';
    }
    fclose(f);
    for (size_t i = 0; i < s->n; i++)
        fold[i] = fc[s->labels[i]];
    free(fc);
    collection_free(&col);
    return 0;
}

/* Kimia-216's 18 classes are MPEG-7 classes (its images are MPEG-7 shapes redrawn): in
 * mpeg7-dev + Kimia-216 a Kimia shape of a class mpeg7-dev has takes that class's label, so the
 * same object is never counted as two classes (a bird's nearest shape is an mpeg7-dev bird). */
static int same_class_names(const char *dir, shape_set *s, size_t ndev)
{
    char path[1024];
    collection cd, ck;
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", dir);
    if (collection_open(path, &cd) != 0)
        return -1;
    snprintf(path, sizeof path, "%s/kimia216/manifest.tsv", dir);
    if (collection_open(path, &ck) != 0) {
        collection_free(&cd);
        return -1;
    }
    for (size_t i = ndev; i < s->n; i++) {
        const char *name = ck.classes[s->labels[i] - 1000];
        for (size_t k = 0; k < cd.nclasses; k++)
            if (strcmp(cd.classes[k], name) == 0)
                s->labels[i] = (int32_t)k;
    }
    collection_free(&cd);
    collection_free(&ck);
    return 0;
}

int folds_load(const char *dir, folds_data *fd)
{
    char path[1024];
    memset(fd, 0, sizeof *fd);
    coll_t *simple[3] = {&fd->dev, &fd->k99, &fd->k216};
    const char *names[3] = {"mpeg7-dev", "kimia99", "kimia216"};
    for (int t = 0; t < 3; t++) {
        snprintf(path, sizeof path, "%s/%s/manifest.tsv", dir, names[t]);
        simple[t]->name = names[t];
        simple[t]->kind = t > 0;
        if (shape_set_load(path, &simple[t]->s) != 0)
            return -1;
    }
    fd->fold = calloc(fd->dev.s.n, sizeof *fd->fold);
    if (!fd->fold || read_folds(dir, &fd->dev.s, fd->fold) != 0)
        return -1;
    fd->devwarp.name = "mpeg7-dev+warped";
    fd->devk216.name = "mpeg7-dev+kimia216";
    if (concat(&fd->dev.s, NULL, 0, &fd->devwarp.s) != 0 || concat(&fd->dev.s, &fd->k216.s, 1000, &fd->devk216.s) != 0)
        return -1;
    return same_class_names(dir, &fd->devk216.s, fd->dev.s.n);
}

void folds_free(folds_data *fd)
{
    coll_t *all[5] = {&fd->dev, &fd->k99, &fd->k216, &fd->devwarp, &fd->devk216};
    for (int t = 0; t < 5; t++)
        shape_set_free(&all[t]->s);
    free(fd->fold);
}

void base_free(base_t *b)
{
    free(b->hs);
    free(b->ha);
    free(b->am);
    free(b->fd);
    free(b->gm);
    free(b->ga);
    free(b->in);
    memset(b, 0, sizeof *b);
}
