/* retrieval_ablation.c — the ablation table of the retrieval default (`amscr-retrieval-bench
 * ablation DATASETS`; the sets, rows and columns: docs/measurements.md, "One default for
 * articulated and affine-distorted collections"). On each set the base matrices (AMSCR, the
 * channel's similarity and affine frames, the inner distance closed and as traced) are computed
 * once through the library and every row is composed from them as amscr_db_retrieval_matrix
 * composes them (eth80-dev's held-out rows as amscr_db_retrieval_matrix_heldout). A row's
 * time: the base matrices it needs plus its fusion and re-ranking. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define BENCH_PROGRAM "amscr-retrieval-bench"
#include "bench_util.h"
#include "channel.h"
#include "inner.h"
#include "internal.h"
#include "mcd_set.h"
#include "collection.h"

enum { M_AMSCR, M_SIM, M_AFF, M_INNER, M_INNER_OPEN, NBASE };

typedef struct {
    const char *name;
    int use[NBASE];     /* base matrices: AMSCR, channel similarity, channel affine, inner distance (closed
                         * silhouette, silhouette as traced) */
    double weight;      /* channel weight of the fusion with AMSCR (used when both are in) */
    double share;       /* affine share of the channel (when both frames are in) */
    int rerank;         /* re-ranking k 8, 10 iterations */
    double view;        /* the affine-view factor f (both frames): min(mix, f d_affine); 0: the mix */
    double inner;       /* with an inner distance: its graph's share of the re-ranking */
    int k;              /* re-ranking k (8 in the default) */
} row_t;

static const row_t ROWS[] = {
    {"paper's method (AMSCR, affine, no re-ranking)", {1, 0, 0, 0}, 0, 0, 0, 0, 0, 8},
    {"AMSCR + re-ranking", {1, 0, 0, 0}, 0, 0, 1, 0, 0, 8},
    {"channel, similarity frame", {0, 1, 0, 0}, 1, 0, 0, 0, 0, 8},
    {"channel, affine frame (band 0.08)", {0, 0, 1, 0}, 1, 1, 0, 0, 0, 8},
    {"channel, both frames (0.8 / 0.2)", {0, 1, 1, 0}, 1, 0.2, 0, 0, 0, 8},
    {"AMSCR + channel fused (w 0.5)", {1, 1, 1, 0}, 0.5, 0.2, 0, 0, 0, 8},
    {"inner distance alone (closed silhouette)", {0, 0, 0, 1}, 1, 0, 0, 0, 0, 8},
    {"channel, similarity frame + re-ranking", {0, 1, 0, 0}, 1, 0, 1, 0, 0, 8},
    {"channel, affine frame (band 0.08) + re-ranking", {0, 0, 1, 0}, 1, 1, 1, 0, 0, 8},
    {"AMSCR + channel fused (w 0.5) + re-ranking", {1, 1, 1, 0}, 0.5, 0.2, 1, 0, 0, 8},
    {"channel, both frames + re-ranking on one graph (0.6's default)", {0, 1, 1, 0}, 1, 0.2, 1, 0, 0, 8},
    {"channel, both frames + two graphs, the silhouette as traced (0.8's default)", {0, 1, 1, 0, 1}, 1, 0.2, 1, 0,
     0.05, 8},
    {"channel, both frames + re-ranking on two graphs (0.10's default)", {0, 1, 1, 1}, 1, 0.2, 1, 0, 0.05, 8},
    {"channel, both frames, affine views by the affine frame + two graphs (0.11's default)", {0, 1, 1, 1}, 1, 0.2,
     1, 2.0, 0.05, 8},
    {"channel, similarity frame + re-ranking on two graphs (--fast)", {0, 1, 0, 1}, 1, 0, 1, 0, 0.1, 8},
    {"**default: channel, both frames, affine views by the affine frame + two graphs, the inner one at 0.1**",
     {0, 1, 1, 1}, 1, 0.2, 1, 2.0, 0.1, 8},
    {"default without the affine-view rule", {0, 1, 1, 1}, 1, 0.2, 1, 0, 0.1, 8},
    {"default without the inner graph", {0, 1, 1, 0}, 1, 0.2, 1, 2.0, 0, 8},
    {"default, the inner distance on the silhouette as traced", {0, 1, 1, 0, 1}, 1, 0.2, 1, 2.0, 0.1, 8},
    {"default without re-ranking", {0, 1, 1, 0}, 1, 0.2, 0, 2.0, 0, 8},
    {"default, re-ranking k 4", {0, 1, 1, 1}, 1, 0.2, 1, 2.0, 0.1, 4},
    {"default, re-ranking k 16", {0, 1, 1, 1}, 1, 0.2, 1, 2.0, 0.1, 16},
};
enum { DEFAULT_ROW = 15 };
enum { NROWS = sizeof ROWS / sizeof ROWS[0] };

typedef struct {
    const char *title;
    int kind; /* 0 bull's eye %, 1 top-k sum, 2 leave one group out 1-NN % */
    shape_set s;
    int32_t *groups; /* kind 2: each shape's group (object) */
    double t_load, t_prep, t_base[NBASE];
    double *base[NBASE];
    double score[NROWS], secs[NROWS], spread[NROWS];
} set_run;

/* The median off-diagonal value among the shapes not held out (held: NULL for none). */
static double offdiag_median(const double *M, size_t n, const unsigned char *held)
{
    size_t m = 0;
    double *v = xmalloc(n * n * sizeof *v);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            if (i != j && !(held && (held[i] || held[j])))
                v[m++] = M[i * n + j];
    qsort(v, m, sizeof *v, cmp_double);
    double med = v[m / 2];
    free(v);
    return med;
}

/* The base matrices of r->s through the library (one db per channel frame). */
static void compute_bases(set_run *r)
{
    size_t n = r->s.n;
    amscr_params *p = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_params_set_channel_affine_share(p, 0.0) != AMSCR_OK)
        die("params");
    for (int b = 0; b < NBASE; b++) {
        /* the affine frame as the default mixes it in: at the whitened frame's own band */
        if (b == M_AFF && (amscr_params_set_channel_invariance(p, AMSCR_INVARIANCE_AFFINE) != AMSCR_OK ||
                           amscr_params_set_channel_band(p, amscr_params_get_channel_affine_band(p)) != AMSCR_OK))
            die("params");
        if (b == M_INNER_OPEN && amscr_params_set_inner_closing(p, 0.0) != AMSCR_OK)
            die("params");
        double t0 = now();
        amscr_db *db = NULL;
        if (amscr_db_new(p, &db) != AMSCR_OK)
            die("db");
        for (size_t i = 0; i < n; i++)
            if (amscr_db_add_contour(db, r->s.c[i], r->s.labels[i], NULL) != AMSCR_OK)
                die("prepare");
        if (b == 0)
            r->t_prep = now() - t0;
        r->base[b] = xmalloc(n * n * sizeof(double));
        t0 = now();
        amscr_status st = b == M_AMSCR   ? amscr_db_distance_matrix(db, NULL, NULL, r->base[b])
                          : b >= M_INNER ? amscr__inner_matrix(db, amscr__resolve_threads(0), NULL, NULL, r->base[b])
                                         : amscr_db_channel_matrix(db, NULL, NULL, r->base[b]);
        if (st != AMSCR_OK)
            die("matrix");
        r->t_base[b] = now() - t0;
        amscr_db_free(db);
    }
    amscr_params_free(p);
}

/* Row w of the table into out (n x n), as amscr_db_retrieval_matrix composes it; with held
 * (kind 2: one object out), as amscr_db_retrieval_matrix_heldout composes the held-out rows. */
static void compose(const set_run *r, const row_t *w, const unsigned char *held, double *out)
{
    size_t n = r->s.n, nn = n * n;
    int ch = w->use[M_SIM] || w->use[M_AFF];
    if (!ch && !w->use[M_AMSCR]) { /* the inner distance alone */
        memcpy(out, r->base[M_INNER], nn * sizeof *out);
        return;
    }
    double *H = xmalloc(nn * sizeof *H);
    amscr_params vp; /* the frames' rule of the row: its share and affine-view factor */
    memset(&vp, 0, sizeof vp);
    vp.channel_affine_view = w->view;
    const double share[2] = {1.0 - w->share, w->share};
    for (size_t i = 0; ch && i < nn; i++)
        H[i] = !w->use[M_AFF] ? r->base[M_SIM][i]
             : !w->use[M_SIM] ? r->base[M_AFF][i]
                              : amscr__channel_combine(&vp, 2, share, r->base[M_SIM][i], r->base[M_AFF][i]);
    if (!w->use[M_AMSCR]) {
        memcpy(out, H, nn * sizeof *out);
    } else {
        memcpy(out, r->base[M_AMSCR], nn * sizeof *out);
        if (ch || w->rerank) { /* the plain paper's row keeps the directional matrix */
            for (size_t i = 0; i < n; i++) {
                out[i * n + i] = 0.0;
                for (size_t j = i + 1; j < n; j++)
                    out[i * n + j] = out[j * n + i] = 0.5 * (out[i * n + j] + out[j * n + i]);
            }
        }
        if (ch) {
            double sa = (1.0 - w->weight) / offdiag_median(out, n, held), sh = w->weight / offdiag_median(H, n, held);
            for (size_t i = 0; i < nn; i++)
                out[i] = sa * out[i] + sh * H[i];
        }
    }
    free(H);
    size_t k = n < (size_t)w->k ? n : (size_t)w->k;
    const double *inner = w->use[M_INNER] ? r->base[M_INNER] : w->use[M_INNER_OPEN] ? r->base[M_INNER_OPEN] : NULL;
    const double *d[2] = {out, inner}, sh[2] = {0.0, w->inner};
    if (w->rerank && held && amscr__rerank_held(d, sh, inner ? 2 : 1, n, k, 10, amscr__resolve_threads(0), held, out))
        die("re-ranking");
    if (w->rerank && !held &&
        (inner ? amscr__rerank_normalized2(out, inner, w->inner, n, k, 10, amscr__resolve_threads(0), out)
               : amscr__rerank_normalized(out, n, k, 10, amscr__resolve_threads(0), out)) != AMSCR_OK)
        die("re-ranking");
}

/* The standard error of a figure that is the mean of m units' scores u (times scale). */
static double std_error(const double *u, size_t m, double scale)
{
    double mean = 0, ss = 0;
    for (size_t i = 0; i < m; i++)
        mean += u[i] / (double)m;
    for (size_t i = 0; i < m; i++)
        ss += (u[i] - mean) * (u[i] - mean);
    return m > 1 ? scale * sqrt(ss / (double)(m - 1) / (double)m) : 0.0;
}

/* Row k's figure of r from D, and its spread over the units (classes, or groups for kind 2). */
static void score_one(set_run *r, const double *D, int k)
{
    size_t n = r->s.n, m = 0;
    const int32_t *units = r->kind == 2 ? r->groups : r->s.labels;
    int32_t *cls = xmalloc(n * sizeof *cls), *lab = xmalloc(n * sizeof *lab);
    double *u = xmalloc(n * sizeof *u);
    m = n;
    if (amscr_score_classes(units, n, cls, NULL, &m) != AMSCR_OK)
        die("classes");
    r->score[k] = 0;
    if (r->kind == 1) { /* top-k sum; a class's hits with every other class's labels made unique */
        size_t counts[16] = {0}, kmax = n > 100 ? 11 : 10;
        for (size_t c = 0; c < m; c++) {
            for (size_t i = 0; i < n; i++)
                lab[i] = r->s.labels[i] == cls[c] ? cls[c] : -1 - (int32_t)i;
            if (amscr_score_topk_table(D, n, lab, kmax, counts) != AMSCR_OK)
                die("top-k");
            u[c] = 0;
            for (size_t q = 0; q < kmax; q++)
                u[c] += (double)counts[q];
            r->score[k] += u[c];
        }
        r->spread[k] = std_error(u, m, (double)m);
    } else if (r->kind == 2) {
        if (amscr_score_nn_groups(D, n, r->s.labels, r->groups, m, 0, &r->score[k], u, NULL) != AMSCR_OK)
            die("groups");
        r->score[k] *= 100.0;
        r->spread[k] = std_error(u, m, 100.0);
    } else {
        if (amscr_score_bullseye(D, n, r->s.labels, 0, &r->score[k]) != AMSCR_OK ||
            amscr_score_per_class(D, n, r->s.labels, m, u, NULL) != AMSCR_OK)
            die("bull's eye");
        r->score[k] *= 100.0;
        r->spread[k] = std_error(u, m, 100.0);
    }
    free(cls);
    free(lab);
    free(u);
}

static void score_rows(set_run *r)
{
    size_t n = r->s.n;
    double *D = xmalloc(n * n * sizeof *D), *G = xmalloc(n * n * sizeof *G);
    unsigned char *held = xmalloc(n); /* set for every shape before each use */
    for (int k = 0; k < NROWS; k++) {
        double t0 = now();
        compose(r, &ROWS[k], NULL, D);
        /* one object out: each object's rows from the fusion and graph of the others alone */
        const row_t *w = &ROWS[k];
        int fused = w->use[M_AMSCR] && (w->use[M_SIM] || w->use[M_AFF]);
        for (size_t i = 0; r->kind == 2 && (w->rerank || fused) && i < n; i++) {
            size_t first = 0;
            while (r->groups[first] != r->groups[i])
                first++;
            if (first < i)
                continue; /* the object's rows are done */
            for (size_t j = 0; j < n; j++)
                held[j] = r->groups[j] == r->groups[i];
            compose(r, &ROWS[k], held, G);
            for (size_t j = 0; j < n; j++)
                if (held[j])
                    memcpy(D + j * n, G + j * n, n * sizeof *D);
        }
        r->secs[k] = now() - t0;
        for (int b = 0; b < NBASE; b++)
            r->secs[k] += ROWS[k].use[b] ? r->t_base[b] : 0.0;
        score_one(r, D, k);
    }
    free(D);
    free(G);
    free(held);
}

static void free_bases(set_run *r)
{
    for (int b = 0; b < NBASE; b++)
        free(r->base[b]);
}

/* The fold `which` of the set `all` as its own collection: sub-matrices of the base matrices
 * (a pair's distance does not depend on the rest; the medians and the re-ranking graph are the
 * fold's own); its times are the fusion and re-ranking only. */
static void fold_set(const set_run *all, const int32_t *fold_of_class, int which, set_run *f)
{
    size_t n = all->s.n, m = 0;
    size_t *idx = xmalloc(n * sizeof *idx);
    for (size_t i = 0; i < n; i++)
        if (fold_of_class[all->s.labels[i]] == which)
            idx[m++] = i;
    f->s.c = NULL;
    f->s.n = m;
    f->s.labels = xmalloc(m * sizeof *f->s.labels);
    for (int b = 0; b < NBASE; b++) {
        f->base[b] = xmalloc(m * m * sizeof(double));
        for (size_t i = 0; i < m; i++)
            for (size_t j = 0; j < m; j++)
                f->base[b][i * m + j] = all->base[b][idx[i] * n + idx[j]];
    }
    for (size_t i = 0; i < m; i++)
        f->s.labels[i] = all->s.labels[idx[i]];
    free(idx);
}

int ablation_main(const char *dir);

/* The groups of the manifest at path (its `group` column) into r->groups; -1 without them. */
static int load_groups(const char *path, set_run *r)
{
    collection col;
    if (collection_open(path, &col) != 0)
        return -1;
    int ok = col.ngroups > 1 && col.n == r->s.n && (r->groups = malloc(col.n * sizeof *r->groups)) != NULL;
    for (size_t i = 0; ok && i < col.n; i++)
        r->groups[i] = col.items[i].group;
    collection_free(&col);
    return ok ? 0 : -1;
}

/* Row k's mean of the four collections in % (mpeg7-dev's folds averaged, Kimia's sums as shares). */
static double mean_of_four(const set_run *sets, const set_run *folds, int k)
{
    double m7 = 0.5 * (folds[0].score[k] + folds[1].score[k]);
    double kim = 50.0 * (sets[2].score[k] / 990.0 + sets[3].score[k] / 2376.0);
    return 0.25 * (m7 + sets[1].score[k] + kim + sets[4].score[k]);
}

int ablation_main(const char *dir)
{
    enum { NSETS = 5 };
    static set_run sets[NSETS], folds[2];
    static int32_t fold_of_class[4096];
    int nfolds = 0, nsets = NSETS;
    const char *titles[NSETS] = {"mpeg7-dev (bull's eye %)", "MCD-style (bull's eye %)", "Kimia-99 (top-10 sum /990)",
                                 "Kimia-216 (top-11 sum /2376)", "eth80-dev (one object out, 1-NN %)"};
    const char *dirs[NSETS] = {"mpeg7-dev", "mpeg7-dev", "kimia99", "kimia216", "eth80-dev"};
    for (int k = 0; k < nsets; k++) {
        sets[k].title = titles[k];
        sets[k].kind = k == 4 ? 2 : k >= 2;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s/manifest.tsv", dir, dirs[k]);
        if (access(path, R_OK) != 0 && k == 4) { /* the column is left out without the set */
            fprintf(stderr, "amscr-retrieval-bench: %s not found: no eth80-dev column\n", path);
            nsets = 4;
            break;
        }
        if (access(path, R_OK) != 0) {
            fprintf(stderr, "amscr-retrieval-bench: %s not found\n", path);
            return 77;
        }
        double t0 = now();
        if ((k == 1 ? shape_set_mcd(path, MCD_SEED, &sets[k].s) : shape_set_load(path, &sets[k].s)) != 0)
            return 1;
        if (k == 4 && load_groups(path, &sets[k]) != 0) {
            fprintf(stderr, "amscr-retrieval-bench: %s: no `group` column\n", path);
            return 1;
        }
        sets[k].t_load = now() - t0;
        compute_bases(&sets[k]);
        score_rows(&sets[k]);
        if (k == 0 && folds_tsv_read(path, fold_of_class, sizeof fold_of_class / sizeof fold_of_class[0]) == 0) {
            for (int w = 0; w < 2; w++) {
                fold_set(&sets[0], fold_of_class, w, &folds[w]);
                folds[w].title = w ? "fold B (bull's eye %)" : "fold A (bull's eye %)";
                score_rows(&folds[w]);
                free_bases(&folds[w]);
            }
            nfolds = 2;
        }
        free_bases(&sets[k]);
        fprintf(stderr, "ablation: %s done\n", dirs[k]);
    }
    int mean4 = nsets == NSETS && nfolds == 2;
    double la[3] = {-1, -1, -1};
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf %lf %lf", &la[0], &la[1], &la[2]) != 3)
            la[0] = -1;
        fclose(f);
    }
    printf("Ablation (amscr-retrieval-bench ablation; %ld cores online, load average at the end %.2f %.2f %.2f). "
           "Score, then wall seconds of the matrices the row needs plus its fusion and re-ranking.\n\n",
           sysconf(_SC_NPROCESSORS_ONLN), la[0], la[1], la[2]);
    printf("| setting |");
    for (int k = 0; k < nsets; k++)
        printf(" %s | s |", sets[k].title);
    for (int w = 0; w < nfolds; w++)
        printf(" %s |", folds[w].title);
    printf(mean4 ? " mean of four (%%) |\n|---|" : "\n|---|");
    for (int k = 0; k < nsets; k++)
        printf("---|---|");
    for (int w = 0; w < nfolds + mean4; w++)
        printf("---|");
    printf("\n");
    for (int r = 0; r < NROWS; r++) {
        printf("| %s |", ROWS[r].name);
        for (int k = 0; k < nsets; k++)
            printf(sets[k].kind == 1 ? " %.0f | %.1f |" : " %.2f | %.1f |", sets[k].score[r], sets[k].secs[r]);
        for (int w = 0; w < nfolds; w++)
            printf(" %.2f |", folds[w].score[r]);
        if (mean4)
            printf(" %.2f |", mean_of_four(sets, folds, r));
        printf("\n");
    }
    printf("| (decode + trace, prepare: s) |");
    for (int k = 0; k < nsets; k++)
        printf(" %.1f + %.1f | |", sets[k].t_load, sets[k].t_prep);
    for (int w = 0; w < nfolds + mean4; w++)
        printf(" |");
    printf("\n| (spread of the default: standard error over classes, objects in eth80-dev) |");
    for (int k = 0; k < nsets; k++)
        printf(sets[k].kind == 1 ? " ±%.1f | |" : " ±%.2f | |", sets[k].spread[DEFAULT_ROW]);
    for (int w = 0; w < nfolds; w++)
        printf(" ±%.2f |", folds[w].spread[DEFAULT_ROW]);
    printf(mean4 ? " |\n" : "\n");
    for (int k = 0; k < nsets; k++) {
        shape_set_free(&sets[k].s);
        free(sets[k].groups);
    }
    for (int w = 0; w < nfolds; w++)
        shape_set_free(&folds[w].s);
    return 0;
}
