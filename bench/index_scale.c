/* index_scale.c — the library's retrieval index: build time, one query's time and the
 * shortlist's recall against the exact query, then how build and query grow with the
 * collection (docs/measurements.md, "The index: build, query, recall").
 *
 *   amscr-index-bench DATASETS [SIZES...]      (default sizes: 1000 10000)
 *
 * Part 1 (retrieval preset, 2 threads): mpeg7-dev + one seeded affine copy of every shape
 * (1400 shapes). Build with the default shortlist (AMSCR_INDEX_CANDIDATES) and with every shape
 * (candidates 0, exact); save / load; 50 seeded affine-warped queries (a random collection shape
 * under any rotation, axis scales x0.5-2 log-uniform, shear +-0.5, 0.5 % noise): the median
 * time of one query at the default shortlist, and its recall against the exact query (the full
 * index, candidates 0): % of the exact top 10 in the shortlist query's top 10, % of queries
 * with the same first hit.
 * Then the neighbour lists (K = 8) of builds with candidates 32, 64, 128, 256 against the exact
 * lists: % of the exact neighbours kept (the build seeks them among min(candidates, its build
 * shortlist) shapes), and the same of the inner distance's graph.
 * Part 2: collections of SIZES shapes, each an affine-warped, noisy copy of an mpeg7-dev shape
 * (shape i % 700, its own seed): build time at the default shortlist, the process's peak
 * resident memory (max RSS) and its growth per shape over the collection, the bytes a shape
 * of the index (channel and inner features, signature and bound vector, neighbour lists and
 * their reverse) and of the collection (the prepared shape) holds, load time, median of 50 queries;
 * and the build's shortlist search per row: exact (every bound) against the coarse quantizer
 * (signature.h), with the quantizer's recall of the exact shortlist; from 20,000 shapes (the
 * index keeps its quantizer) each query also against the same index's query without it (every
 * bound scanned, the diffusion not pruned: the query of 0.14): % of its top 10 kept, same first hit. Times are wall clock
 * with the process's CPU seconds (all threads) in parentheses: on a busy machine CPU / threads
 * is what idle cores would give. Environment: INDEX_BENCH_NO_MIXED skips part 1,
 * INDEX_BENCH_NO_LOAD part 2's load, INDEX_BENCH_QUANTIZE gives part 2's indexes below 20,000
 * shapes the quantizer too, INDEX_BENCH_SET=NAME draws from DATASETS/NAME instead of mpeg7-dev. Exit 77 without the datasets. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <sys/resource.h>

#define BENCH_PROGRAM "amscr-index-bench"
#include "amscr.h"
#include "bench_util.h"
#include "db_io.h"
#include "index.h"
#include "mcd_set.h"

enum { TOP = 10, NQ = 50, NQ_SCALE = 50, NQ_EXACT = 10, SEARCH_ROWS = 200, BUILD_M = 192 };

/* CPU seconds of the process (all threads). */
static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double rss_mb(void)
{
    long pages = 0, res = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2)
            res = 0;
        fclose(f);
    }
    return (double)res * (double)sysconf(_SC_PAGESIZE) / 1e6;
}

static double max_rss_mb(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_maxrss / 1e3;
}

/* A random affine copy of c (mcd_set.h), prepared with p. */
static amscr_descriptor *warped(const amscr_params *p, const amscr_contour *c, unsigned long long *seed)
{
    amscr_contour *ct = warp_affine(c, seed);
    amscr_descriptor *d = NULL;
    if (!ct || amscr_descriptor_new(p, ct, &d) != AMSCR_OK)
        die("affine copy");
    amscr_contour_free(ct);
    return d;
}

static void add(amscr_db *db, amscr_descriptor *d, int32_t label)
{
    if (amscr_db_add_descriptor(db, d, label, NULL) != AMSCR_OK)
        die("add");
    amscr_descriptor_free(d);
}

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    return n ? v[n / 2] : 0.0;
}

/* Wall and CPU seconds (all threads) of a build. */
static amscr_index *build(const amscr_db *db, size_t cand, double secs[2])
{
    amscr_index *x = NULL;
    double t = now(), c = cpu();
    if (amscr_index_build(db, cand, NULL, NULL, &x) != AMSCR_OK)
        die("build");
    secs[0] = now() - t;
    secs[1] = cpu() - c;
    return x;
}

/* Adds to *in the members of b (nb) in a (TOP) and to *first whether both start alike. */
static void overlap(const size_t *a, const size_t *b, size_t nb, size_t *in, size_t *first)
{
    for (size_t u = 0; u < nb; u++)
        for (size_t v = 0; v < TOP; v++)
            *in += a[v] == b[u];
    *first += a[0] == b[0];
}

/* One query's wall and CPU time into w[q], c[q]. */
static void timed_query(const amscr_index *x, const amscr_descriptor *d, size_t M, size_t *a, double *sa, double *w,
                        double *c)
{
    size_t ca = 0;
    double t = now(), u = cpu();
    if (amscr_index_query(x, d, M, TOP, a, sa, &ca) != AMSCR_OK)
        die("query");
    *w = now() - t;
    *c = cpu() - u;
}

/* Save to memory and load back: the load time and the file size. */
static void load_time(const amscr_index *x, double *secs, double *mb)
{
    void *buf = NULL;
    size_t len = 0;
    amscr_index *y = NULL;
    if (amscr_index_save_memory(x, &buf, &len) != AMSCR_OK)
        die("save");
    double t = now();
    if (amscr_index_load_memory(buf, len, &y) != AMSCR_OK)
        die("load");
    *secs = now() - t;
    *mb = (double)len / 1e6;
    amscr_index_free(y);
    amscr_free(buf);
}

/* The share of the K - 1 neighbours (itself left out) of lists (n x k) kept by lists got; *rows:
 * the share of rows that keep them all. */
static double kept_share(const uint32_t *got, const uint32_t *exact, size_t n, size_t k, double *rows)
{
    size_t kept = 0, all = 0;
    for (size_t i = 0; i < n; i++) {
        size_t here = 0;
        for (size_t a = 1; a < k; a++)
            for (size_t b = 1; b < k; b++)
                here += got[i * k + a] == exact[i * k + b];
        kept += here;
        all += here == k - 1;
    }
    *rows = 100.0 * (double)all / (double)n;
    return 100.0 * (double)kept / (double)(n * (k - 1));
}

/* The lists of builds with candidates c against the exact lists of full: the base distance's
 * and the inner distance's (its graph's: among the build's shortlist and the base list). */
static void list_recall(const amscr_db *db, const amscr_index *full)
{
    static const size_t cs[] = {32, 64, 128, 256};
    size_t n = amscr_db_size(db), k = full->k;
    printf("\n| candidates | build (M) | exact neighbours kept | rows with all kept | inner graph: kept | rows "
           "|\n|---|---|---|---|---|---|\n");
    for (size_t u = 0; u < sizeof cs / sizeof *cs; u++) {
        double tb[2], rows, rows2 = 0.0;
        amscr_index *x = build(db, cs[u], tb);
        double kept = kept_share(x->nb_idx, full->nb_idx, n, k, &rows);
        double kept2 = x->k2 ? kept_share(x->in_idx, full->in_idx, n, x->k2, &rows2) : 0.0;
        printf("| %zu | %.1f s (%.1f) | %.2f %% | %.1f %% | %.2f %% | %.1f %% |\n", cs[u], tb[0], tb[1], kept, rows,
               kept2, rows2);
        fflush(stdout);
        amscr_index_free(x);
    }
}

/* Bytes a shape of x holds: channel features, signature with its bound vector, lists and reverse,
 * and its shape as the index keeps it (a compact record: input samples and outline). */
static void index_bytes(const amscr_index *x, double b[4])
{
    b[3] = (double)amscr__db_shape_bytes(AMSCR__DB_VERSION_NEWEST, amscr_db_params(x->db));
    size_t n = amscr_db_size(x->db), hf = 0;
    for (size_t i = 0; i < n * (size_t)x->nf; i++) /* the orientations held */
        for (int o = 0; o < 2; o++)
            hf += (x->hf[i].seq[o] ? x->hf[i].n * AMSCR__HF_BINS : 0) +
                  (x->hf[i].spec[o] ? AMSCR__HF_SPEC(x->hf[i].nfreq) * sizeof *x->hf[i].spec[0] : 0);
    b[0] = (double)hf / (double)n;
    b[1] = (double)x->sig_dim * sizeof *x->sigq + sizeof *x->sige + AMSCR__SIG_LB_DIM * sizeof(float);
    b[2] = (double)(x->k + x->k2) * (sizeof(uint32_t) + sizeof(double)) + (x->rev ? (double)(x->k + x->k2) * 4 + 8
                                                                                  : 0.0);
    b[0] += x->k2 ? (double)sizeof(amscr__inner) : 0.0; /* the inner features with the channel's */
}

/* The build's shortlist search of SEARCH_ROWS rows: exact against the quantizer, ms a row, and
 * the % of the exact shortlist the quantizer finds. */
static void search_cost(const amscr_index *x, size_t m, double out[3])
{
    size_t n = amscr_db_size(x->db), *a = xmalloc(m * sizeof *a), *b = xmalloc(m * sizeof *b), same = 0;
    amscr__sig_ivf v = x->ivf; /* the index's own from AMSCR__INDEX_IVF_MIN shapes */
    amscr__sig_rows rows = {NULL, x->sigq, x->sige};
    if (v.nc == 0 && amscr__sig_ivf_build(x->sig_lb, n, &v) != AMSCR_OK)
        die("out of memory");
    double te = 0.0, ti = 0.0;
    for (size_t r = 0; r < SEARCH_ROWS; r++) {
        size_t i = r * n / SEARCH_ROWS;
        float sig[AMSCR__SIG_DIM];
        const float *lb = x->sig_lb + i * AMSCR__SIG_LB_DIM;
        amscr__index_sig(x, i, sig);
        double t = cpu_now();
        if (amscr__sig_nearest(&rows, x->sig_lb, n, sig, lb, m, i, a) != m)
            die("search");
        te += cpu_now() - t;
        t = cpu_now();
        if (amscr__sig_ivf_nearest(&v, &rows, x->sig_lb, n, sig, lb, m, i, b) != m)
            die("search");
        ti += cpu_now() - t;
        for (size_t u = 0, w = 0; u < m; u++) { /* both ascending */
            while (w < m && b[w] < a[u])
                w++;
            same += w < m && b[w] == a[u];
        }
    }
    out[0] = 1e3 * te / SEARCH_ROWS;
    out[1] = 1e3 * ti / SEARCH_ROWS;
    out[2] = 100.0 * (double)same / (double)(m * SEARCH_ROWS);
    if (v.cent != x->ivf.cent)
        amscr__sig_ivf_free(&v);
    free(a);
    free(b);
}

/* Part 1: the 1400-shape collection. */
static void part_mixed(const amscr_params *p, const shape_set *s)
{
    amscr_db *db = NULL;
    unsigned long long seed = 0x5DEECE66Dull, qseed = 0xC0FFEEull;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        die("db");
    for (size_t i = 0; i < s->n; i++)
        add(db, prepare(p, s->c[i]), s->labels[i]);
    for (size_t i = 0; i < s->n; i++)
        add(db, warped(p, s->c[i], &seed), s->labels[i]);
    size_t n = amscr_db_size(db), M = AMSCR_INDEX_CANDIDATES;
    double tb[2], tf[2], tl, mb;
    amscr_index *x = build(db, M, tb), *full = build(db, 0, tf);
    load_time(x, &tl, &mb);
    double times[NQ], ctimes[NQ];
    size_t top_in = 0, same_first = 0;
    for (size_t q = 0; q < NQ; q++) {
        amscr_descriptor *d = warped(p, s->c[(size_t)(warp_urand(&qseed) * (double)s->n) % s->n], &qseed);
        size_t a[TOP], b[TOP], cb = 0;
        double sa[TOP], sb[TOP];
        timed_query(x, d, M, a, sa, &times[q], &ctimes[q]);
        if (amscr_index_query(full, d, 0, TOP, b, sb, &cb) != AMSCR_OK)
            die("exact query");
        overlap(a, b, cb, &top_in, &same_first);
        amscr_descriptor_free(d);
    }
    printf("| mpeg7-dev + affine copies | %zu | %zu | %.1f s (%.1f) | %.1f s (%.1f) | %.2f s, %.0f MB | %.1f ms (%.1f) | "
           "%.1f %% | %.0f %% |\n", n, M, tb[0], tb[1], tf[0], tf[1], tl, mb, 1e3 * median(times, NQ),
           1e3 * median(ctimes, NQ), 100.0 * (double)top_in / (double)(TOP * NQ),
           100.0 * (double)same_first / (double)NQ);
    fflush(stdout);
    list_recall(db, full);
    amscr_index_free(x);
    amscr_index_free(full);
    amscr_db_free(db);
}

/* Part 2: n warped copies. */
static void part_scale(const amscr_params *p, const shape_set *s, size_t n)
{
    amscr_db *db = NULL;
    unsigned long long seed = 0xABCDEF12345ull + n, qseed = 0x1234ull;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        die("db");
    double empty = rss_mb();
    for (size_t i = 0; i < n; i++)
        add(db, warped(p, s->c[i % s->n], &seed), s->labels[i % s->n]);
    size_t M = AMSCR_INDEX_CANDIDATES;
    double before = rss_mb(), tb[2], tl, mb, times[NQ_SCALE], ctimes[NQ_SCALE], ib[4], sc[3];
    double prepared = (before - empty) * 1e6 / (double)n;
    amscr_index *x = build(db, M, tb);
    if (getenv("INDEX_BENCH_QUANTIZE") && x->ivf.nc == 0 && amscr__sig_ivf_build(x->sig_lb, n, &x->ivf) != AMSCR_OK)
        die("quantizer"); /* the build's quantizer below 20,000 shapes too */
    double per_shape = (rss_mb() - before) * 1e3 / (double)n, peak = max_rss_mb();
    index_bytes(x, ib);
    tl = mb = NAN;
    if (!getenv("INDEX_BENCH_NO_LOAD")) /* a load rebuilds every shape's features */
        load_time(x, &tl, &mb);
    size_t top_in = 0, same_first = 0, scan_in = 0, scan_first = 0;
    amscr__sig_ivf ivf = x->ivf, none = {0, 0, NULL, NULL, NULL, NULL};
    for (size_t q = 0; q < NQ_SCALE; q++) {
        amscr_descriptor *d = warped(p, s->c[(size_t)(warp_urand(&qseed) * (double)s->n) % s->n], &qseed);
        size_t a[TOP], b[TOP], cb = 0;
        double sa[TOP], sb[TOP];
        timed_query(x, d, M, a, sa, &times[q], &ctimes[q]);
        x->ivf = none; /* the query without the quantizer: every bound scanned, the diffusion not pruned */
        if (ivf.nc > 0 && amscr_index_query(x, d, M, TOP, b, sb, &cb) == AMSCR_OK)
            overlap(a, b, TOP, &scan_in, &scan_first);
        x->ivf = ivf;
        if (q < NQ_EXACT && amscr_index_query(x, d, 0, TOP, b, sb, &cb) == AMSCR_OK) /* every shape matched */
            overlap(a, b, TOP, &top_in, &same_first);
        amscr_descriptor_free(d);
    }
    search_cost(x, BUILD_M, sc);
    double cmed = median(ctimes, NQ_SCALE), cp90 = ctimes[NQ_SCALE * 9 / 10]; /* sorted by median() */
    char load[48] = "not run", scan[48] = "no quantizer (the same query)";
    if (!isnan(tl))
        snprintf(load, sizeof load, "%.2f s, %.0f MB", tl, mb);
    if (ivf.nc)
        snprintf(scan, sizeof scan, "%.1f %% / %.0f %%", 100.0 * (double)scan_in / (TOP * NQ_SCALE),
                 100.0 * (double)scan_first / NQ_SCALE);
    printf("| warped copies | %zu | %zu | %.1f s (%.1f) | %.0f MB | %.1f KB | %.0f + %.0f + %.0f + %.0f B | %.0f B | "
           "%s | %.1f ms (%.1f; p90 %.1f) | %.1f %% / %.0f %% | %s | %.3f / %.3f ms, %.1f %% |\n", n, M, tb[0], tb[1],
           peak, per_shape, ib[0], ib[1], ib[2], ib[3], prepared, load, 1e3 * median(times, NQ_SCALE), 1e3 * cmed,
           1e3 * cp90, 100.0 * (double)top_in / (double)(TOP * NQ_EXACT), 100.0 * (double)same_first / (double)NQ_EXACT,
           scan, sc[0], sc[1], sc[2]);
    fflush(stdout);
    amscr_index_free(x);
    amscr_db_free(db);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: amscr-index-bench DATASETS [SIZES...]\n");
        return 2;
    }
    char manifest[4096];
    const char *set = getenv("INDEX_BENCH_SET");
    snprintf(manifest, sizeof manifest, "%s/%s/manifest.tsv", argv[1], set ? set : "mpeg7-dev");
    shape_set s;
    amscr_params *p = NULL;
    if (shape_set_load(manifest, &s) != 0)
        return 77;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_params_set_num_threads(p, 2) != AMSCR_OK)
        die("params");
    if (!getenv("INDEX_BENCH_NO_MIXED")) {
        printf("| collection | shapes | M | build (M) | build (exact) | load, file | query (median of %d) | exact top %d "
               "kept | same first hit |\n|---|---|---|---|---|---|---|---|---|\n", NQ, TOP);
        part_mixed(p, &s);
        printf("\n");
    }
    printf("| collection | shapes | M | build | max RSS | RSS growth a shape | index a shape: features + signature + "
           "lists + shape record | prepared shape | load, file | query (median of %d; CPU, p90) | exact top %d kept / "
           "same first hit (%d queries) | the scan's top %d kept / same first hit | build shortlist (%d) a row: exact / "
           "quantizer, recall |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n", NQ_SCALE, TOP, NQ_EXACT, TOP,
           BUILD_M);
    for (int a = 2; a < argc; a++)
        part_scale(p, &s, (size_t)strtoul(argv[a], NULL, 10));
    if (argc == 2) /* the default sizes */
        for (size_t n = 1000; n <= 10000; n *= 10)
            part_scale(p, &s, n);
    amscr_params_free(p);
    shape_set_free(&s);
    return 0;
}
