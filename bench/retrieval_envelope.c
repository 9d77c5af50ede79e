/* retrieval_envelope.c — probe: the shape channel on the silhouette's envelope (the silhouette
 * closed at a scale) beside the channel on the silhouette itself (docs/results-retrieval.md,
 * "The channel on the closed silhouette").
 *
 *   amscr-retrieval-envelope DATASETS [C1,C2,...] [--one-frame]
 *   AMSCR_ENVELOPE_HALVES=1 ...   also 24 random class halves of mpeg7-dev (each its own
 *                                 collection): each row's mean gain over the first, and how many
 *                                 halves it lifts / lowers
 *   AMSCR_ENVELOPE_CLASSES=1 ...  each class's bull's eye of every row on stderr
 *   AMSCR_ENVELOPE_OUTLINE=1 ...  E from each contour's 64-point closed outline (amscr__outline,
 *                                 the inner distance's) instead of the traced closed curve
 *   AMSCR_ENVELOPE_DUMP=DIR ...   also write each collection's matrices for probes in NumPy:
 *                                 DIR/NAME_labels.i32 (int32), NAME_C.f64, NAME_I.f64 and
 *                                 NAME_E<closing>.f64 (float64, n x n, C order; NAME mpeg7-dev,
 *                                 kimia99, kimia216 or mcd)
 *
 * For each collection (mpeg7-dev with its class folds A and B as collections of their own,
 * Kimia-99, Kimia-216): the default's base channel matrix C (amscr_db_channel_matrix of the
 * retrieval preset: both frames, the affine-view rule) and its inner-distance graph I (the
 * silhouette closed at the preset's 0.04); then, for every closing c, the channel matrix E of
 * the contours closed at c (amscr__close_curve: the region a contour bounds closed by a disk of
 * radius c sqrt(area) on a grid where sqrt(area) spans 64 pixels, traced; a contour that bounds
 * no area keeps itself), prepared as any contour (--one-frame: E in the similarity frame
 * alone). The rows re-rank as the default does (k 8,
 * 10 iterations), with I at 0.11's share 0.05 unless said:
 *
 *   0.11      C (0.11's default)
 *   min       min(C, E): a pair whose envelopes match better is ranked by them
 *   mean      (C + E) / 2
 *   graph s   C, with E as a third graph of the re-ranking: (1 - 0.05 - s) P_C + 0.05 P_I + s P_E
 *   inner i   C, the inner distance's graph at share i instead of 0.05 (E not used)
 *
 * Scores: bull's eye % (mpeg7-dev and its folds, and the MCD-style set of mpeg7-dev's first
 * shapes: mcd_set.h, seed 7), top-k sums (Kimia). Images are traced as the tool's retrieval
 * commands trace them (broken pieces joined: AMSCR_TRACE_JOIN). Deterministic; ~15 s a closing
 * on 2 cores, ~1 min with the halves. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "image.h"
#include "folds_tsv.h"
#include "inner.h"
#include "internal.h"
#include "mcd_set.h"

enum { ROWS = 9, MAXC = 8 };
static const char *ROW_NAMES[ROWS] = {"0.11 (inner 0.05)", "min", "mean", "graph 0.05", "graph 0.1", "graph 0.2",
                                      "inner 0.1", "inner 0.15", "inner 0.1, graph 0.1"};
static const double GRAPH_SHARE[ROWS] = {0, 0, 0, 0.05, 0.1, 0.2, 0, 0, 0.1};
static const double INNER_SHARE[ROWS] = {0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.1, 0.15, 0.1};

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
static int ONE_FRAME; /* --one-frame: E in the similarity frame alone */
static int OUTLINE;   /* AMSCR_ENVELOPE_OUTLINE: E from the 64-point outline */

static double *channel_of(const shape_set *s, double c, double *I)
{
    amscr_params *p = NULL;
    amscr_db *db = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK ||
        (c > 0.0 && ONE_FRAME && amscr_params_set_channel_affine_share(p, 0.0) != AMSCR_OK) ||
        amscr_db_new(p, &db) != AMSCR_OK)
        die("db");
    for (size_t i = 0; i < s->n; i++) {
        double *xy = NULL;
        size_t m = 0;
        amscr_contour *ci = s->c[i];
        if (c > 0.0 && OUTLINE) { /* the inner distance's 64-point outline */
            xy = xmalloc(2 * AMSCR__OUTLINE_N * sizeof *xy);
            m = AMSCR__OUTLINE_N;
            if (amscr__outline(amscr_contour_xy(s->c[i]), amscr_contour_size(s->c[i]), c, xy) != AMSCR_OK ||
                amscr_contour_new(xy, m, &ci) != AMSCR_OK)
                die("outline");
        } else if (c > 0.0 && amscr__close_curve(amscr_contour_xy(s->c[i]), amscr_contour_size(s->c[i]), c, &xy, &m) ==
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

/* Each class's bull's eye of row r on stderr (AMSCR_ENVELOPE_CLASSES set): "class r label %". */
static void per_class(const double *B, size_t m, const int32_t *lab, int r)
{
    size_t nc = 0;
    for (size_t a = 0; a < m; a++)
        nc = (size_t)lab[a] + 1 > nc ? (size_t)lab[a] + 1 : nc;
    int32_t *cls = xmalloc(m * sizeof *cls);
    double *be = xmalloc(nc * sizeof *be);
    size_t ncl = m;
    if (amscr_score_classes(lab, m, cls, NULL, &ncl) != AMSCR_OK ||
        amscr_score_per_class(B, m, lab, ncl, be, NULL) != AMSCR_OK)
        die("per class");
    for (size_t c = 0; c < ncl; c++)
        fprintf(stderr, "class %d %d %.2f\n", r, cls[c], 100.0 * be[c]);
    free(cls);
    free(be);
}

/* The score of row r on the sub-collection idx (m shapes) of base matrices C, E, I (n x n). */
static double score(int r, const double *C, const double *E, const double *I, size_t n, const size_t *idx,
                    size_t m, const int32_t *labels, int topk)
{
    double *B = xmalloc(m * m * sizeof *B), *J = xmalloc(m * m * sizeof *J);
    double *G = GRAPH_SHARE[r] > 0.0 ? xmalloc(m * m * sizeof *G) : NULL;
    int32_t *lab = xmalloc(m * sizeof *lab);
    for (size_t a = 0; a < m; a++) {
        lab[a] = labels[idx[a]];
        for (size_t b = 0; b < m; b++) {
            size_t q = idx[a] * n + idx[b];
            B[a * m + b] = r == 1 ? (E[q] < C[q] ? E[q] : C[q]) : r == 2 ? 0.5 * (C[q] + E[q]) : C[q];
            J[a * m + b] = I[q];
            if (G)
                G[a * m + b] = E[q];
        }
    }
    const double *dist[3] = {B, J, G};
    double share[3] = {0.0, INNER_SHARE[r], GRAPH_SHARE[r]};
    if (amscr__rerank_graphs(dist, share, G ? 3 : 2, m, m < 8 ? m : 8, 10, amscr__resolve_threads(0), B) != AMSCR_OK)
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
        if (getenv("AMSCR_ENVELOPE_CLASSES"))
            per_class(B, m, lab, r);
    }
    free(B);
    free(J);
    free(G);
    free(lab);
    return v;
}

/* Random class halves of s (HALVES seeded shuffles, both halves of each: 2 HALVES collections):
 * each row's mean gain over the first (0.11's default) and how many halves it lifts / lowers, for
 * closing k. */
enum { HALVES = 12 };
static double half_gain[MAXC + 1][ROWS], half_up[MAXC + 1][ROWS], half_down[MAXC + 1][ROWS];

static void halves(const shape_set *s, int k, const double *C, const double *E, const double *I)
{
    int32_t L = 0;
    for (size_t i = 0; i < s->n; i++)
        L = s->labels[i] + 1 > L ? s->labels[i] + 1 : L;
    int *perm = xmalloc((size_t)L * sizeof *perm);
    size_t *idx = xmalloc(s->n * sizeof *idx);
    unsigned long long seed = 0x2545F4914F6CDD1Dull;
    for (int h = 0; h < 2 * HALVES; h++) {
        if (h % 2 == 0)
            folds_shuffle(perm, L, &seed);
        size_t m = 0;
        for (size_t i = 0; i < s->n; i++)
            if ((perm[s->labels[i]] < L / 2) == (h % 2 == 0))
                idx[m++] = i;
        double ref = score(0, C, E, I, s->n, idx, m, s->labels, 0);
        for (int r = 3; r < ROWS; r++) {
            double v = score(r, C, E, I, s->n, idx, m, s->labels, 0);
            half_gain[k][r] += (v - ref) / (2 * HALVES);
            half_up[k][r] += v > ref + 1e-9;
            half_down[k][r] += v < ref - 1e-9;
        }
    }
    free(perm);
    free(idx);
}

/* Writes n doubles (or int32 labels when d is NULL) to $AMSCR_ENVELOPE_DUMP/NAME_WHAT. */
static void dump(const char *name, const char *what, const double *d, const int32_t *lab, size_t n)
{
    const char *dir = getenv("AMSCR_ENVELOPE_DUMP");
    if (!dir)
        return;
    char path[4096];
    snprintf(path, sizeof path, "%s/%s_%s", dir, name, what);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(d ? (const void *)d : (const void *)lab, d ? sizeof *d : sizeof *lab, n, f) != n ||
        fclose(f) != 0) {
        fprintf(stderr, "amscr-retrieval-envelope: cannot write %s\n", path);
        exit(1);
    }
}

/* One collection's columns: the whole (and its folds when fold_of_class is not NULL); mcd: the
 * MCD-style set of its first shapes instead. */
static int columns(const char *dir, const char *name, const double *cs, int nc, int topk, int mcd,
                   double out[][MAXC + 1][ROWS])
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s/manifest.tsv", dir, name);
    shape_set s;
    if (access(path, R_OK) != 0 || (mcd ? shape_set_mcd(path, 7, &s) : shape_set_load(path, &s)) != 0)
        return -1;
    size_t n = s.n, m[3] = {0, 0, 0};
    static int32_t fold_of_class[4096];
    int folds = !topk && !mcd && folds_tsv_read(path, fold_of_class, 4096) == 0;
    size_t *idx[3];
    for (int g = 0; g < 3; g++)
        idx[g] = xmalloc(n * sizeof(size_t));
    for (size_t i = 0; i < n; i++) {
        idx[0][m[0]++] = i;
        if (folds)
            idx[1 + fold_of_class[s.labels[i]]][m[1 + fold_of_class[s.labels[i]]]++] = i;
    }
    double *I = xmalloc(n * n * sizeof *I), *C = channel_of(&s, 0.0, I);
    const char *tag = mcd ? "mcd" : name;
    dump(tag, "labels.i32", NULL, s.labels, n);
    dump(tag, "C.f64", C, NULL, n * n);
    dump(tag, "I.f64", I, NULL, n * n);
    for (int k = 0; k <= nc; k++) { /* k 0: the default row alone */
        double *E = k ? channel_of(&s, cs[k - 1], NULL) : C;
        if (k) {
            char what[64];
            snprintf(what, sizeof what, "E%g.f64", cs[k - 1]);
            dump(tag, what, E, NULL, n * n);
        }
        for (int g = 0; g < (folds ? 3 : 1); g++)
            for (int r = k ? 1 : 0; r < (k ? ROWS : 1); r++)
                out[g][k][r] = score(r, C, E, I, n, idx[g], m[g], s.labels, topk);
        if (folds && k > 0 && getenv("AMSCR_ENVELOPE_HALVES"))
            halves(&s, k, C, E, I);
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
    image_set_trace_flags(AMSCR_TRACE_JOIN); /* trace as the tool's retrieval commands */
    ONE_FRAME = argc > 3 && strcmp(argv[3], "--one-frame") == 0;
    OUTLINE = getenv("AMSCR_ENVELOPE_OUTLINE") != NULL;
    if (argc < 2 || argc > 4 || (argc == 4 && !ONE_FRAME)) {
        fprintf(stderr, "usage: amscr-retrieval-envelope DATASETS [C1,C2,...] [--one-frame]\n");
        return 2;
    }
    double cs[MAXC];
    int nc = 0;
    for (char *t = strtok(argc > 2 ? argv[2] : (char[]){"0.04,0.08,0.12"}, ","); t && nc < MAXC; t = strtok(NULL, ","))
        cs[nc++] = atof(t);
    static double dev[3][MAXC + 1][ROWS], k99[1][MAXC + 1][ROWS], k216[1][MAXC + 1][ROWS], mcd[1][MAXC + 1][ROWS];
    int g = columns(argv[1], "mpeg7-dev", cs, nc, 0, 0, dev);
    if (g < 0 || columns(argv[1], "kimia99", cs, nc, 1, 0, k99) < 0 ||
        columns(argv[1], "kimia216", cs, nc, 1, 0, k216) < 0 || columns(argv[1], "mpeg7-dev", cs, nc, 0, 1, mcd) < 0) {
        fprintf(stderr, "amscr-retrieval-envelope: the datasets are not in %s\n", argv[1]);
        return 77;
    }
    int h = getenv("AMSCR_ENVELOPE_HALVES") != NULL;
    printf("| row | closing | mpeg7-dev | fold A | fold B | Kimia-99 | Kimia-216 | MCD-style |%s\n"
           "|---|---|---|---|---|---|---|---|%s\n",
           h ? " halves: mean gain (up / down of 24) |" : "", h ? "---|" : "");
    for (int k = 0; k <= nc; k++)
        for (int r = k ? 1 : 0; r < (k ? ROWS : 1); r++) {
            char cl[32] = "-";
            if (k)
                snprintf(cl, sizeof cl, "%g", cs[k - 1]);
            printf("| %s | %s | %.2f | %.2f | %.2f | %.0f | %.0f | %.2f |", ROW_NAMES[r], cl, dev[0][k][r],
                   g == 3 ? dev[1][k][r] : NAN, g == 3 ? dev[2][k][r] : NAN, k99[0][k][r], k216[0][k][r],
                   mcd[0][k][r]);
            if (h && r >= 3)
                printf(" %+.2f (%.0f / %.0f) |", half_gain[k][r], half_up[k][r], half_down[k][r]);
            else if (h)
                printf(" |");
            printf("\n");
        }
    return 0;
}
