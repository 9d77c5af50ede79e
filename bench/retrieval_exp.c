/* retrieval_exp.c — the retrieval experiment driver: loads labelled collections
 * (manifest.tsv), builds the MCD-style affine set from one (seeded), prepares, computes the
 * AMSCR matrix and the shape channel, fuses, re-ranks and prints bull's eye / top-k sums and
 * per-stage times. Deterministic.
 *
 *   amscr-retrieval-exp [options] SET...   SET = kind:path, kind = bullseye | topk | mcd
 *   (mcd:path builds 14 random affine copies of the first shape of every class of path)
 * Options: --inv affine|similarity (AMSCR frame), --hf-inv affine|similarity (channel frame),
 *   --refine R, --band B, --skip S, --loc L, --weight W (channel weight in the fusion; 0 = AMSCR
 *   only, -1 = channel only), --k K, --iters T, --both, --threads T, --fuse median|knn. */
#include "channel.h"
#include "collection.h"
#include "image.h"
#include "mcd_set.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct {
    amscr_invariance inv, hf_inv;
    unsigned refine, threads, iters;
    size_t k, band;
    double skip, loc, weight;
    int both, fuse_knn, no_amscr;
    double wa, w2;
    int hf2; /* -1 none, else the invariance of a second channel frame */
    size_t stride;
    int core;   /* > 0: the library's retrieval preset end to end, the set loaded `core` times */
    int rowmax; /* re-ranking output normalized by the row maximum (0.1) instead of the core's cosine */
} cfg_t;

static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
    amscr_contour **c;
    int32_t *labels;
    size_t n;
    int kind; /* 0 bullseye, 1 topk */
    size_t per_class;
} set_t;

static int load_set(const char *spec, set_t *s, double *t_load)
{
    const char *colon = strchr(spec, ':');
    if (!colon)
        return -1;
    int mcd = strncmp(spec, "mcd", 3) == 0;
    s->kind = strncmp(spec, "topk", 4) == 0;
    double t0 = now();
    shape_set ss;
    if ((mcd ? shape_set_mcd(colon + 1, MCD_SEED, &ss) : shape_set_load(colon + 1, &ss)) != 0)
        return -1;
    s->c = ss.c; /* the set's arrays move into s */
    s->labels = ss.labels;
    s->n = ss.n;
    *t_load = now() - t0;
    return 0;
}

static double score(const set_t *s, const double *D)
{
    if (s->kind == 1) {
        size_t counts[16] = {0}, kmax = s->n > 100 ? 11 : 10, sum = 0;
        if (amscr_score_topk_table(D, s->n, s->labels, kmax, counts) != AMSCR_OK)
            return -1;
        for (size_t r = 0; r < kmax; r++)
            sum += counts[r];
        return (double)sum;
    }
    double sc = 0;
    if (amscr_score_bullseye(D, s->n, s->labels, 0, &sc) != AMSCR_OK)
        return -1;
    return 100.0 * sc;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Divides every row of the symmetric-ized matrix by a robust scale: the median of all
 * off-diagonal values (median), or the mean of each row's k nearest (knn, then symmetric
 * mean of the two rows' scales). */
static void normalize(double *D, size_t n, int knn, size_t k)
{
    double *tmp = malloc(n * n * sizeof *tmp);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++)
            tmp[i * n + j] = 0.5 * (D[i * n + j] + D[j * n + i]);
    memcpy(D, tmp, n * n * sizeof *D);
    if (!knn) {
        qsort(tmp, n * n, sizeof *tmp, cmp_d);
        double med = tmp[n + (n * n - n) / 2];
        for (size_t i = 0; i < n * n; i++)
            D[i] /= med;
    } else {
        double *sc = malloc(n * sizeof *sc);
        for (size_t i = 0; i < n; i++) {
            qsort(tmp + i * n, n, sizeof *tmp, cmp_d);
            double m = 0;
            for (size_t t = 1; t <= k; t++)
                m += tmp[i * n + t];
            sc[i] = m / (double)k;
        }
        for (size_t i = 0; i < n; i++)
            for (size_t j = 0; j < n; j++)
                D[i * n + j] /= sqrt(sc[i] * sc[j]);
        free(sc);
    }
    free(tmp);
}

static amscr_db *prepare(const set_t *s, amscr_invariance inv, const cfg_t *c)
{
    amscr_params *p = NULL;
    if (amscr_params_new(&p) != AMSCR_OK)
        return NULL;
    if (amscr_params_set_invariance(p, inv) || amscr_params_set_refine(p, c->refine) ||
        amscr_params_set_reflections(p, 1) || amscr_params_set_num_threads(p, c->threads))
        return NULL;
    amscr_db *db = NULL;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        return NULL;
    amscr_params_free(p);
    for (size_t i = 0; i < s->n; i++)
        if (amscr_db_add_contour(db, s->c[i], s->labels[i], NULL) != AMSCR_OK) {
            fprintf(stderr, "shape %zu: %s\n", i, amscr_last_error_detail());
            return NULL;
        }
    return db;
}

/* Matrix cache for parameter sweeps (key: everything the matrix depends on). */
static int cache_io(const char *key, double *M, size_t n, int write)
{
    char path[512];
    unsigned long long h = 1469598103934665603ull;
    for (const char *q = key; *q; q++)
        h = (h ^ (unsigned char)*q) * 1099511628211ull;
    snprintf(path, sizeof path, "/tmp/retexp-cache/%016llx.bin", h);
    FILE *f = fopen(path, write ? "wb" : "rb");
    if (!f)
        return -1;
    size_t got = write ? fwrite(M, sizeof *M, n * n, f) : fread(M, sizeof *M, n * n, f);
    fclose(f);
    return got == n * n ? 0 : -1;
}

static void run_set(const char *spec, const cfg_t *c)
{
    set_t s;
    memset(&s, 0, sizeof s);
    double tl = 0;
    if (load_set(spec, &s, &tl) != 0) {
        fprintf(stderr, "cannot load %s\n", spec);
        return;
    }
    size_t n = s.n;
    double t0 = now();
    amscr_db *db = prepare(&s, c->inv, c);
    amscr_db *dbh = c->hf_inv == c->inv ? db : prepare(&s, c->hf_inv, c);
    double tprep = now() - t0;
    double *A = malloc(n * n * sizeof *A), *H = malloc(n * n * sizeof *H), *F = malloc(n * n * sizeof *F);
    t0 = now();
    char keyA[600], keyH[600];
    snprintf(keyA, sizeof keyA, "A %s %d %u", spec, (int)c->inv, c->refine);
    snprintf(keyH, sizeof keyH, "H6 %s %d %zu %g %g %d %zu", spec, (int)c->hf_inv, c->band, c->skip, c->loc, c->both, c->stride);
    int cached = cache_io(keyA, A, n, 0) == 0;
    if (!cached && !c->no_amscr && amscr_db_distance_matrix(db, NULL, NULL, A) != AMSCR_OK) {
        fprintf(stderr, "matrix: %s\n", amscr_last_error_detail());
        return;
    }
    if (!cached && !c->no_amscr)
        cache_io(keyA, A, n, 1);
    double tam = now() - t0;
    t0 = now();
    amscr__hf *hf = calloc(n, sizeof *hf);
    for (size_t i = 0; i < n; i++)
        if (amscr__hf_build(amscr_descriptor_base_points(amscr_db_descriptor(dbh, i)), 128, c->loc, &hf[i]) != AMSCR_OK)
            return;
    double thb = now() - t0;
    amscr__hf_cfg hc = {c->band, c->skip, 1, c->both, c->stride};
    t0 = now();
    double c0 = cpu();
    if (cache_io(keyH, H, n, 0) != 0) {
        amscr__hf_matrix(hf, n, &hc, c->threads ? c->threads : 2, NULL, NULL, H);
        cache_io(keyH, H, n, 1);
    }
    double thm = now() - t0, chm = cpu() - c0;
    double sa = c->no_amscr ? -1 : score(&s, A), sh = score(&s, H);
    t0 = now();
    if (c->weight < 0) {
        memcpy(F, H, n * n * sizeof *F);
    } else {
        normalize(A, n, c->fuse_knn, c->k);
        normalize(H, n, c->fuse_knn, c->k);
        for (size_t i = 0; i < n * n; i++)
            F[i] = A[i] + c->weight * H[i];
    }
    if (c->weight >= 0 && c->wa != 1.0)
        for (size_t i = 0; i < n * n; i++)
            F[i] += (c->wa - 1.0) * A[i];
    if (c->hf2 >= 0) {
        amscr_db *db2 = prepare(&s, (amscr_invariance)c->hf2, c);
        double *H2 = malloc(n * n * sizeof *H2);
        char key2[600];
        snprintf(key2, sizeof key2, "H6 %s %d %zu %g %g %d %zu", spec, c->hf2, c->band, c->skip, c->loc, c->both, c->stride);
        if (cache_io(key2, H2, n, 0) != 0) {
            amscr__hf *h2 = calloc(n, sizeof *h2);
            for (size_t i = 0; i < n; i++)
                amscr__hf_build(amscr_descriptor_base_points(amscr_db_descriptor(db2, i)), 128, c->loc, &h2[i]);
            amscr__hf_matrix(h2, n, &hc, c->threads ? c->threads : 2, NULL, NULL, H2);
            cache_io(key2, H2, n, 1);
            for (size_t i = 0; i < n; i++)
                amscr__hf_free(&h2[i]);
            free(h2);
        }
        printf("  hf2 alone %6.2f\n", score(&s, H2));
        normalize(H2, n, c->fuse_knn, c->k);
        for (size_t i = 0; i < n * n; i++)
            F[i] += c->w2 * H2[i];
        free(H2);
        amscr_db_free(db2);
    }
    double sf = score(&s, F);
    if ((c->rowmax ? amscr_rerank_diffusion(F, n, c->k, c->iters, F)
                   : amscr__rerank_normalized(F, n, c->k, c->iters, amscr__resolve_threads(0), F)) != AMSCR_OK)
        return;
    double tfr = now() - t0;
    double sr = score(&s, F);
    printf("%-40s n=%4zu amscr %6.2f hf %6.2f fused %6.2f rerank %6.2f | load %.1fs prep %.1fs amscr %.1fs "
           "hfbuild %.2fs hfmat %.1fs (%.1f us cpu/pair) fuse+rr %.1fs\n",
           spec, n, sa, sh, sf, sr, tl, tprep, tam, thb, thm,
           1e6 * chm / (0.5 * (double)n * (double)(n - 1)), tfr);
    fflush(stdout);
    for (size_t i = 0; i < n; i++) {
        amscr__hf_free(&hf[i]);
        amscr_contour_free(s.c[i]);
    }
    free(hf);
    free(s.c);
    free(s.labels);
    free(A);
    free(H);
    free(F);
    if (dbh != db)
        amscr_db_free(dbh);
    amscr_db_free(db);
}

/* The library's retrieval preset end to end: decode + trace (load), prepare, the retrieval
 * matrix (channel + fusion + re-ranking); `repeat` > 1 loads the set that many times (a
 * bigger collection for timing, e.g. 2 x mpeg7-dev = 1400 shapes). */
static void run_core(const char *spec, const cfg_t *c, int repeat)
{
    double t0 = now();
    set_t s;
    memset(&s, 0, sizeof s);
    double tl = 0;
    set_t *parts = calloc((size_t)repeat, sizeof *parts);
    size_t n = 0;
    for (int r = 0; r < repeat; r++) {
        if (load_set(spec, &parts[r], &tl) != 0)
            return;
        n += parts[r].n;
    }
    s.c = calloc(n, sizeof *s.c);
    s.labels = calloc(n, sizeof *s.labels);
    s.kind = parts[0].kind;
    for (int r = 0; r < repeat; r++) {
        memcpy(s.c + s.n, parts[r].c, parts[r].n * sizeof *s.c);
        for (size_t i = 0; i < parts[r].n; i++)
            s.labels[s.n + i] = parts[r].labels[i] + 100000 * r;
        s.n += parts[r].n;
        free(parts[r].c);
        free(parts[r].labels);
    }
    free(parts);
    double tload = now() - t0;
    amscr_params *p = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK)
        return;
    if (c->threads && amscr_params_set_num_threads(p, c->threads) != AMSCR_OK)
        return;
    if (c->weight >= 0 && amscr_params_set_channel_weight(p, c->weight) != AMSCR_OK)
        return;
    if (amscr_params_set_rerank_k(p, (unsigned)c->k) != AMSCR_OK)
        return;
    t0 = now();
    amscr_db *db = NULL;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        return;
    for (size_t i = 0; i < n; i++)
        if (amscr_db_add_contour(db, s.c[i], s.labels[i], NULL) != AMSCR_OK)
            return;
    double tprep = now() - t0;
    double *R = malloc(n * n * sizeof *R);
    t0 = now();
    double c0 = cpu();
    if (amscr_db_retrieval_matrix(db, NULL, NULL, R) != AMSCR_OK) {
        fprintf(stderr, "retrieval: %s\n", amscr_last_error_detail());
        return;
    }
    double tmat = now() - t0, cmat = cpu() - c0;
    double self = 0.0;
    for (size_t i = 0; i < n; i++)
        self += R[i * n + i];
    printf("core %-36s x%d n=%4zu score %7.2f | load+trace %.1fs prepare %.1fs matrix+fusion+rerank %.1fs (cpu %.1fs) "
           "total %.1fs, sum of self scores %g\n",
           spec, repeat, n, score(&s, R), tload, tprep, tmat, cmat, tload + tprep + tmat, self);
    fflush(stdout);
    for (size_t i = 0; i < n; i++)
        amscr_contour_free(s.c[i]);
    free(s.c);
    free(s.labels);
    free(R);
    amscr_db_free(db);
    amscr_params_free(p);
}

static amscr_invariance parse_inv(const char *v)
{
    return strcmp(v, "affine") == 0 ? AMSCR_INVARIANCE_AFFINE : AMSCR_INVARIANCE_SIMILARITY;
}

int main(int argc, char **argv)
{
    cfg_t c = {AMSCR_INVARIANCE_AFFINE, AMSCR_INVARIANCE_AFFINE, 0, 2, 20, 5, 8, 1.0, 4.0, 1.0, 0, 0, 0, 1.0, 1.0, -1, 1, 0, 0};
    int i = 1;
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : "0";
        if (strcmp(o, "--both") == 0) {
            c.both = 1;
            continue;
        }
        if (strcmp(o, "--rowmax") == 0) {
            c.rowmax = 1;
            continue;
        }
        if (strcmp(o, "--no-amscr") == 0) {
            c.no_amscr = 1;
            continue;
        }
        i++;
        if (strcmp(o, "--inv") == 0)
            c.inv = parse_inv(v);
        else if (strcmp(o, "--hf-inv") == 0)
            c.hf_inv = parse_inv(v);
        else if (strcmp(o, "--refine") == 0)
            c.refine = (unsigned)atoi(v);
        else if (strcmp(o, "--band") == 0)
            c.band = (size_t)atoi(v);
        else if (strcmp(o, "--skip") == 0)
            c.skip = atof(v);
        else if (strcmp(o, "--loc") == 0)
            c.loc = atof(v);
        else if (strcmp(o, "--weight") == 0)
            c.weight = atof(v);
        else if (strcmp(o, "--stride") == 0)
            c.stride = (size_t)atoi(v);
        else if (strcmp(o, "--core") == 0)
            c.core = atoi(v);
        else if (strcmp(o, "--wa") == 0)
            c.wa = atof(v);
        else if (strcmp(o, "--w2") == 0)
            c.w2 = atof(v);
        else if (strcmp(o, "--hf2") == 0)
            c.hf2 = strcmp(v, "none") == 0 ? -1 : (int)parse_inv(v);
        else if (strcmp(o, "--k") == 0)
            c.k = (size_t)atoi(v);
        else if (strcmp(o, "--iters") == 0)
            c.iters = (unsigned)atoi(v);
        else if (strcmp(o, "--threads") == 0)
            c.threads = (unsigned)atoi(v);
        else if (strcmp(o, "--fuse") == 0)
            c.fuse_knn = strcmp(v, "knn") == 0;
        else {
            fprintf(stderr, "unknown option %s\n", o);
            return 2;
        }
    }
    for (; i < argc; i++) {
        if (c.core)
            run_core(argv[i], &c, c.core);
        else
            run_set(argv[i], &c);
    }
    return 0;
}
