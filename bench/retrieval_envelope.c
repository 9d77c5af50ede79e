/* retrieval_envelope.c — probe: the shape channel on the silhouette's envelope (the silhouette
 * closed at a scale) beside the channel on the silhouette itself (docs/results-retrieval.md,
 * "The channel on the closed silhouette").
 *
 *   amscr-retrieval-envelope DATASETS [C1,C2,...]
 *
 * For each collection (mpeg7-dev with its class folds A and B as collections of their own,
 * Kimia-99, Kimia-216): the default's base channel matrix C (amscr_db_channel_matrix of the
 * retrieval preset: both frames, the affine-view rule) and its inner-distance graph I (the
 * silhouette closed at the preset's 0.04); then, for every closing c, the channel matrix E of
 * the contours closed at c (amscr__close_curve: the region a contour bounds closed by a disk of
 * radius c sqrt(area) on a grid where sqrt(area) spans 64 pixels, traced; a contour that bounds
 * no area keeps itself), prepared as any contour. The rows re-rank, as the default does (k 8,
 * 10 iterations, I at 0.05):
 *
 *   default   C
 *   min       min(C, E): a pair whose envelopes match better is ranked by them
 *   mean      (C + E) / 2
 *
 * Scores: bull's eye % (mpeg7-dev and its folds), top-k sums (Kimia). Deterministic; ~2 min a
 * closing on 2 cores. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "folds_tsv.h"
#include "inner.h"
#include "internal.h"
#include "mcd_set.h"

enum { ROWS = 3, MAXC = 8 };
static const char *ROW_NAMES[ROWS] = {"default", "min", "mean"};

static void die(const char *what)
{
    fprintf(stderr, "amscr-retrieval-envelope: %s: %s\n", what, amscr_last_error_detail());
    exit(1);
}

static void *xmalloc(size_t bytes)
{
    void *p = malloc(bytes);
    if (!p)
        die("memory");
    return p;
}

/* The channel matrix of s's contours under the retrieval preset, each closed at c first (c 0:
 * as they are); with the inner distance's matrix into I when I is not NULL. */
static double *channel_of(const shape_set *s, double c, double *I)
{
    amscr_params *p = NULL;
    amscr_db *db = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_db_new(p, &db) != AMSCR_OK)
        die("db");
    for (size_t i = 0; i < s->n; i++) {
        double *xy = NULL;
        size_t m = 0;
        amscr_contour *ci = s->c[i];
        if (c > 0.0 && amscr__close_curve(amscr_contour_xy(s->c[i]), amscr_contour_size(s->c[i]), c, &xy, &m) ==
                           AMSCR_OK) {
            if (amscr_contour_new(xy, m, &ci) != AMSCR_OK)
                die("closed contour");
        }
        amscr__clear_error();
        if (amscr_db_add_contour(db, ci, s->labels[i], NULL) != AMSCR_OK)
            die("prepare");
        if (ci != s->c[i])
            amscr_contour_free(ci);
        free(xy);
    }
    double *M = xmalloc(s->n * s->n * sizeof *M);
    if (amscr_db_channel_matrix(db, NULL, NULL, M) != AMSCR_OK)
        die("channel matrix");
    if (I && amscr__inner_matrix(db, amscr__resolve_threads(0), NULL, NULL, I) != AMSCR_OK)
        die("inner matrix");
    amscr_db_free(db);
    amscr_params_free(p);
    return M;
}

/* The score of row r on the sub-collection idx (m shapes) of base matrices C, E, I (n x n). */
static double score(int r, const double *C, const double *E, const double *I, size_t n, const size_t *idx,
                    size_t m, const int32_t *labels, int topk)
{
    double *B = xmalloc(m * m * sizeof *B), *J = xmalloc(m * m * sizeof *J);
    int32_t *lab = xmalloc(m * sizeof *lab);
    for (size_t a = 0; a < m; a++) {
        lab[a] = labels[idx[a]];
        for (size_t b = 0; b < m; b++) {
            size_t q = idx[a] * n + idx[b];
            B[a * m + b] = r == 0 ? C[q] : r == 1 ? (E[q] < C[q] ? E[q] : C[q]) : 0.5 * (C[q] + E[q]);
            J[a * m + b] = I[q];
        }
    }
    if (amscr__rerank_normalized2(B, J, 0.05, m, m < 8 ? m : 8, 10, amscr__resolve_threads(0), B) != AMSCR_OK)
        die("re-ranking");
    double v = 0.0;
    if (topk) {
        size_t counts[16] = {0}, kmax = m > 100 ? 11 : 10;
        if (amscr_score_topk_table(B, m, lab, kmax, counts) != AMSCR_OK)
            die("top-k");
        for (size_t q = 0; q < kmax; q++)
            v += (double)counts[q];
    } else if (amscr_score_bullseye(B, m, lab, 0, &v) != AMSCR_OK) {
        die("bull's eye");
    } else {
        v *= 100.0;
    }
    free(B);
    free(J);
    free(lab);
    return v;
}

/* One collection's columns: the whole (and its folds when fold_of_class is not NULL). */
static int columns(const char *dir, const char *name, const double *cs, int nc, int topk, double out[][MAXC + 1][3])
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s/manifest.tsv", dir, name);
    shape_set s;
    if (access(path, R_OK) != 0 || shape_set_load(path, &s) != 0)
        return -1;
    size_t n = s.n, m[3] = {0, 0, 0};
    static int32_t fold_of_class[4096];
    int folds = !topk && folds_tsv_read(path, fold_of_class, 4096) == 0;
    size_t *idx[3];
    for (int g = 0; g < 3; g++)
        idx[g] = xmalloc(n * sizeof(size_t));
    for (size_t i = 0; i < n; i++) {
        idx[0][m[0]++] = i;
        if (folds)
            idx[1 + fold_of_class[s.labels[i]]][m[1 + fold_of_class[s.labels[i]]]++] = i;
    }
    double *I = xmalloc(n * n * sizeof *I), *C = channel_of(&s, 0.0, I);
    for (int k = 0; k <= nc; k++) { /* k 0: the default row alone */
        double *E = k ? channel_of(&s, cs[k - 1], NULL) : C;
        for (int g = 0; g < (folds ? 3 : 1); g++)
            for (int r = k ? 1 : 0; r < (k ? ROWS : 1); r++)
                out[g][k][r] = score(r, C, E, I, n, idx[g], m[g], s.labels, topk);
        if (E != C)
            free(E);
        fprintf(stderr, "envelope: %s closing %g done\n", name, k ? cs[k - 1] : 0.0);
    }
    free(C);
    free(I);
    for (int g = 0; g < 3; g++)
        free(idx[g]);
    shape_set_free(&s);
    return folds ? 3 : 1;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: amscr-retrieval-envelope DATASETS [C1,C2,...]\n");
        return 2;
    }
    double cs[MAXC];
    int nc = 0;
    for (char *t = strtok(argc > 2 ? argv[2] : (char[]){"0.04,0.08,0.12"}, ","); t && nc < MAXC; t = strtok(NULL, ","))
        cs[nc++] = atof(t);
    static double dev[3][MAXC + 1][3], k99[1][MAXC + 1][3], k216[1][MAXC + 1][3];
    int g = columns(argv[1], "mpeg7-dev", cs, nc, 0, dev);
    if (g < 0 || columns(argv[1], "kimia99", cs, nc, 1, k99) < 0 || columns(argv[1], "kimia216", cs, nc, 1, k216) < 0) {
        fprintf(stderr, "amscr-retrieval-envelope: the datasets are not in %s\n", argv[1]);
        return 77;
    }
    printf("| row | closing | mpeg7-dev | fold A | fold B | Kimia-99 | Kimia-216 |\n|---|---|---|---|---|---|---|\n");
    for (int k = 0; k <= nc; k++)
        for (int r = k ? 1 : 0; r < (k ? ROWS : 1); r++)
        {
            char cl[32] = "-";
            if (k)
                snprintf(cl, sizeof cl, "%g", cs[k - 1]);
            printf("| %s | %s | %.2f | %.2f | %.2f | %.0f | %.0f |\n", ROW_NAMES[r], cl, dev[0][k][r],
                   g == 3 ? dev[1][k][r] : NAN, g == 3 ? dev[2][k][r] : NAN, k99[0][k][r], k216[0][k][r]);
        }
    return 0;
}
