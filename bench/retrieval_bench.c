/* retrieval_bench.c — the default retrieval pipeline measured (docs/measurements.md):
 *
 *   amscr-retrieval-bench timing DATASETS    the retrieval preset and its fast setting on 1400
 *       shapes (mpeg7-dev twice; without it kimia216's MCD-style set repeated): per-stage wall
 *       times, pairs/s; then the tool's path (amscr eval's loader and the same matrix)
 *   amscr-retrieval-bench ablation DATASETS  the ablation table (retrieval_ablation.c)
 *   amscr-retrieval-bench mcd-check MANIFEST the MCD-style set from MANIFEST must reach >= 99 %
 *       bull's eye with the retrieval preset (exit 0, 1 below, 77 = skipped: no data)
 *
 * DATASETS holds kimia99/, kimia216/, mpeg7-dev/ (manifest.tsv each). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define BENCH_PROGRAM "amscr-retrieval-bench"
#include "bench_util.h"
#include "mcd_set.h"
#include "collection.h"
#include "load_db.h"

/* A prepared db of the set with params p; *secs = the preparation's wall time. */
static amscr_db *prepare_set(const amscr_params *p, const shape_set *s, double *secs)
{
    double t0 = now();
    amscr_db *db = NULL;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        die("db");
    for (size_t i = 0; i < s->n; i++)
        if (amscr_db_add_contour(db, s->c[i], s->labels[i], NULL) != AMSCR_OK)
            die("prepare");
    *secs = now() - t0;
    return db;
}

/* ------------------------------------------------------------------ timing */

/* Progress of amscr_db_retrieval_matrix: the time the channel stage ends (its last report) into *user. */
static int clock_cb(void *user, size_t done, size_t total)
{
    if (done == total)
        *(double *)user = now();
    return 0;
}

static void time_setting(const char *name, const shape_set *s, double t_load, double share)
{
    amscr_params *p = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_params_set_channel_affine_share(p, share) != AMSCR_OK)
        die("params");
    double t_prep;
    amscr_db *db = prepare_set(p, s, &t_prep);
    size_t n = s->n;
    double *R = xmalloc(n * n * sizeof *R), t_end = 0.0, t0 = now();
    if (amscr_db_retrieval_matrix(db, clock_cb, &t_end, R) != AMSCR_OK)
        die("retrieval matrix");
    double t1 = now(), t_ch = t_end - t0, t_rest = t1 - t_end;
    double frames = share > 0.0 ? 2.0 : 1.0, pairs = frames * (double)n * (double)(n - 1) / 2.0;
    printf("| %s | %zu | %.1f | %.1f | %.1f | %.2f | %.1f | %.0f |\n", name, n, t_load, t_prep, t_ch, t_rest,
           t_load + t_prep + (t1 - t0), pairs / t_ch);
    fflush(stdout);
    free(R);
    amscr_db_free(db);
    amscr_params_free(p);
}

/* The tool's path (amscr eval, search, matrix): the collection decoded, traced and prepared
 * on the threads (load_db), then the retrieval matrix; mpeg7-dev listed twice (1400 shapes). */
static void time_tool(const char *manifest)
{
    collection a, b;
    if (collection_open(manifest, &a) != 0 || collection_open(manifest, &b) != 0)
        die("collection");
    coll_item *items = realloc(a.items, (a.n + b.n) * sizeof *items);
    if (!items)
        die("memory");
    memcpy(items + a.n, b.items, b.n * sizeof *items);
    a.items = items;
    a.n += b.n;
    free(b.items);
    b.items = NULL;
    b.n = 0;
    amscr_params *p = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK)
        die("params");
    double t0 = now();
    amscr_db *db = NULL;
    if (load_db(p, &a, 127 /* the tool's default threshold */, &db) != 0)
        die("load");
    double t1 = now();
    size_t n = a.n;
    double *R = xmalloc(n * n * sizeof *R), t_end = 0.0;
    if (amscr_db_retrieval_matrix(db, clock_cb, &t_end, R) != AMSCR_OK)
        die("retrieval matrix");
    double t2 = now(), pairs = 2.0 * (double)n * (double)(n - 1) / 2.0;
    printf("| the tool's path (load on threads, default) | %zu | %.1f (decode, trace, prepare) | | %.1f | %.2f | %.1f | %.0f |\n",
           n, t1 - t0, t_end - t1, t2 - t_end, t2 - t0, pairs / (t_end - t1));
    fflush(stdout);
    free(R);
    amscr_db_free(db);
    amscr_params_free(p);
    collection_free(&a);
    collection_free(&b);
}

static int run_timing(const char *dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/mpeg7-dev/manifest.tsv", dir);
    int have = access(path, R_OK) == 0;
    double t0 = now();
    shape_set a, b;
    if (!have)
        snprintf(path, sizeof path, "%s/kimia216/manifest.tsv", dir);
    if (access(path, R_OK) != 0) {
        fprintf(stderr, "amscr-retrieval-bench: no datasets in %s\n", dir);
        return 77;
    }
    /* mpeg7-dev twice = 1400 shapes; else the MCD-style set of kimia216 (18 x 14 = 252) with
     * other seeds until 1400 */
    if ((have ? shape_set_load(path, &a) : shape_set_mcd(path, MCD_SEED, &a)) != 0)
        return 1;
    while (a.n < 1400) {
        if ((have ? shape_set_load(path, &b) : shape_set_mcd(path, MCD_SEED + a.n, &b)) != 0)
            return 1;
        size_t m = a.n + b.n > 1400 ? 1400 - a.n : b.n;
        a.c = realloc(a.c, (a.n + m) * sizeof *a.c);
        a.labels = realloc(a.labels, (a.n + m) * sizeof *a.labels);
        if (!a.c || !a.labels)
            die("memory");
        for (size_t i = 0; i < m; i++) {
            a.c[a.n + i] = b.c[i];
            a.labels[a.n + i] = b.labels[i];
            b.c[i] = NULL;
        }
        a.n += m;
        for (size_t i = m; i < b.n; i++)
            amscr_contour_free(b.c[i]);
        b.n = 0;
        shape_set_free(&b);
    }
    double t_load = now() - t0;
    double la[3] = {0};
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf %lf %lf", &la[0], &la[1], &la[2]) != 3)
            la[0] = la[1] = la[2] = -1;
        fclose(f);
    }
    printf("retrieval pipeline, %s x%s, %ld cores online, load average %.2f %.2f %.2f\n\n",
           have ? "mpeg7-dev" : "MCD-style kimia216", have ? "2" : " (seeds)", sysconf(_SC_NPROCESSORS_ONLN),
           la[0], la[1], la[2]);
    printf("| setting | shapes | decode+trace s | prepare s | channel matrix s | inner distance + re-ranking s | total s | "
           "channel pairs/s |\n|---|---|---|---|---|---|---|---|\n");
    time_setting("default (retrieval preset)", &a, t_load, 0.2);
    time_setting("fast (--fast: affine share 0)", &a, t_load, 0.0);
    shape_set_free(&a);
    if (have)
        time_tool(path);
    return 0;
}

/* ------------------------------------------------------------------ mcd-check */

static int run_mcd_check(const char *manifest)
{
    if (access(manifest, R_OK) != 0) {
        fprintf(stderr, "amscr-retrieval-bench: %s not found: skipped\n", manifest);
        return 77;
    }
    shape_set s;
    if (shape_set_mcd(manifest, MCD_SEED, &s) != 0)
        return 1;
    amscr_params *p = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK)
        die("params");
    double tp;
    amscr_db *db = prepare_set(p, &s, &tp);
    double *R = xmalloc(s.n * s.n * sizeof *R), be = 0.0;
    if (amscr_db_retrieval_matrix(db, NULL, NULL, R) != AMSCR_OK)
        die("retrieval matrix");
    if (amscr_score_bullseye(R, s.n, s.labels, 0, &be) != AMSCR_OK)
        die("bull's eye");
    be *= 100.0;
    printf("MCD-style set of %s (%zu shapes): bull's eye %.2f %% with the retrieval preset (>= 99 required)\n",
           manifest, s.n, be);
    free(R);
    amscr_db_free(db);
    amscr_params_free(p);
    shape_set_free(&s);
    return be >= 99.0 ? 0 : 1;
}

int ablation_main(const char *dir);

int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "timing") == 0)
        return run_timing(argv[2]);
    if (argc == 3 && strcmp(argv[1], "mcd-check") == 0)
        return run_mcd_check(argv[2]);
    if (argc == 3 && strcmp(argv[1], "ablation") == 0)
        return ablation_main(argv[2]);
    fprintf(stderr, "usage: amscr-retrieval-bench timing|ablation DATASETS | mcd-check MANIFEST\n");
    return 2;
}
