/* folds_base.c — the base matrices of a collection under one raw_cfg: the shape channel in the
 * similarity and in the affine frame (as fuse.c computes them), the AMSCR distance
 * (amscr_db_distance_matrix) and the Fourier proportion channel; cached on disk. */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "channel.h"
#include "inner.h"

/* Low-order Fourier magnitudes |c_k|, |c_-k| (k = 1..FD_K) of the similarity-normalized curve. */
enum { FD_K = 8 };

static int cache_io(const char *key, double *M, size_t n, int write)
{
    char path[512];
    unsigned long long h = 1469598103934665603ull;
    for (const char *q = key; *q; q++)
        h = (h ^ (unsigned char)*q) * 1099511628211ull;
    if (write)
        (void)mkdir("/tmp/amscr-folds-cache", 0777); /* may exist */
    snprintf(path, sizeof path, "/tmp/amscr-folds-cache/%016llx.bin", h);
    FILE *f = fopen(path, write ? "wb" : "rb");
    if (!f)
        return -1;
    size_t got = write ? fwrite(M, sizeof *M, n * n, f) : fread(M, sizeof *M, n * n, f);
    fclose(f);
    return got == n * n ? 0 : -1;
}

static amscr_db *make_db(const coll_t *c, const raw_cfg *r)
{
    amscr_params *p = NULL;
    amscr_db *db = NULL;
    if (amscr_params_new_retrieval(&p) != AMSCR_OK || amscr_params_set_num_samples(p, r->N) != AMSCR_OK ||
        amscr_params_set_reflections(p, r->refl) != AMSCR_OK || amscr_params_set_num_threads(p, 2) != AMSCR_OK)
        return NULL;
    p->channel_band = r->band;
    p->channel_skip = r->skip;
    p->channel_locality = r->loc;
    if (amscr_db_new(p, &db) != AMSCR_OK)
        db = NULL;
    amscr_params_free(p);
    for (size_t i = 0; db && i < c->s.n; i++)
        if (amscr_db_add_contour(db, c->s.c[i], c->s.labels[i], NULL) != AMSCR_OK) {
            fprintf(stderr, "%s shape %zu: %s\n", c->name, i, amscr_last_error_detail());
            amscr_db_free(db);
            db = NULL;
        }
    return db;
}

static int channel_in_frame(const amscr_db *db, amscr_invariance frame, size_t stride, double *out)
{
    const amscr_params *p = amscr_db_params(db);
    size_t n = amscr_db_size(db);
    amscr__hf *hf = calloc(n, sizeof *hf);
    amscr_status st = hf ? AMSCR_OK : AMSCR_E_NOMEM;
    for (size_t i = 0; i < n && st == AMSCR_OK; i++)
        st = amscr__hf_of_descriptor(p, frame, amscr_db_descriptor(db, i), &hf[i]);
    if (st == AMSCR_OK) {
        amscr__hf_cfg cfg;
        amscr__hf_cfg_from(p, hf[0].n, 0, &cfg); /* the audit's band: the same in both frames */
        cfg.stride = stride;
        st = amscr__hf_matrix(hf, n, &cfg, 2, NULL, NULL, out);
    }
    for (size_t i = 0; hf && i < n; i++)
        amscr__hf_free(&hf[i]);
    free(hf);
    return st == AMSCR_OK ? 0 : -1;
}

/* Reflection-invariant Fourier magnitudes of the counter-clockwise, similarity-normalized samples. */
static void fourier_features(const amscr_descriptor *d, double *f)
{
    size_t n = d->n;
    const double *P = d->input;
    double cx = 0, cy = 0, area = 0, e = 0;
    for (size_t i = 0; i < n; i++) {
        cx += P[2 * i] / (double)n;
        cy += P[2 * i + 1] / (double)n;
        size_t j = (i + 1) % n;
        area += P[2 * i] * P[2 * j + 1] - P[2 * j] * P[2 * i + 1];
    }
    double sgn = area >= 0 ? 1.0 : -1.0; /* clockwise: traverse backwards (c_k <-> c_-k) */
    for (int k = 1; k <= FD_K; k++)
        for (int s = 0; s < 2; s++) {
            double kk = (s ? -k : k) * sgn, re = 0, im = 0;
            for (size_t i = 0; i < n; i++) {
                double x = P[2 * i] - cx, y = P[2 * i + 1] - cy, a = -6.283185307179586 * kk * (double)i / (double)n;
                re += x * cos(a) - y * sin(a);
                im += x * sin(a) + y * cos(a);
            }
            f[2 * (k - 1) + s] = hypot(re, im) / (double)n;
            e += f[2 * (k - 1) + s] * f[2 * (k - 1) + s];
        }
    for (int t = 0; t < 2 * FD_K; t++)
        f[t] /= sqrt(e);
}

/* Low-order moments of the samples (centroid at the origin, RMS radius 1; rotation-, reflection-
 * and start-invariant): the elongation |mu20 - mu02 + 2i mu11|, the two third-order magnitudes of
 * Hu's phi3 and phi4 (asymmetry: a pear against an apple), and the enclosed area over pi (how
 * round the outline is). */
enum { GM_K = 4 };
static void moment_features_of(const double *P, size_t n, double *f)
{
    double cx = 0, cy = 0, r2 = 0, area = 0;
    for (size_t i = 0; i < n; i++) {
        cx += P[2 * i] / (double)n;
        cy += P[2 * i + 1] / (double)n;
    }
    for (size_t i = 0; i < n; i++)
        r2 += ((P[2 * i] - cx) * (P[2 * i] - cx) + (P[2 * i + 1] - cy) * (P[2 * i + 1] - cy)) / (double)n;
    double s = 1.0 / sqrt(r2), m[4][4] = {{0}};
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        double x = s * (P[2 * i] - cx), y = s * (P[2 * i + 1] - cy);
        double x2 = s * (P[2 * j] - cx), y2 = s * (P[2 * j + 1] - cy);
        area += 0.5 * (x * y2 - x2 * y);
        for (int p = 0; p <= 3; p++)
            for (int q = 0; p + q <= 3; q++)
                m[p][q] += pow(x, p) * pow(y, q) / (double)n;
    }
    f[0] = hypot(m[2][0] - m[0][2], 2.0 * m[1][1]);
    f[1] = hypot(m[3][0] - 3.0 * m[1][2], 3.0 * m[2][1] - m[0][3]);
    f[2] = hypot(m[3][0] + m[1][2], m[2][1] + m[0][3]);
    f[3] = fabs(area) / 3.141592653589793;
}

/* The moments of the samples as they are (the similarity frame) or whitened (the affine frame:
 * the elongation is then 0 and the other three are affine invariants). */
static void moment_features(const amscr_descriptor *d, int affine, double *f)
{
    if (!affine) {
        moment_features_of(d->input, d->n, f);
        return;
    }
    double *w = malloc(2 * d->n * sizeof *w), fwd[6], inv[6];
    if (w && amscr__whiten(d->input, d->n, w, fwd, inv) == AMSCR_OK)
        moment_features_of(w, d->n, f);
    else
        f[0] = f[1] = f[2] = f[3] = 0.0;
    free(w);
}

static void moment_matrix(const amscr_db *db, int affine, double *out)
{
    size_t n = amscr_db_size(db);
    double *F = malloc(n * GM_K * sizeof *F);
    for (size_t i = 0; i < n; i++)
        moment_features(amscr_db_descriptor(db, i), affine, F + i * GM_K);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            double t = 0;
            for (int u = 0; u < GM_K; u++)
                t += (F[i * GM_K + u] - F[j * GM_K + u]) * (F[i * GM_K + u] - F[j * GM_K + u]);
            out[i * n + j] = sqrt(t);
        }
    free(F);
}

static void fourier_matrix(const amscr_db *db, double *out)
{
    size_t n = amscr_db_size(db);
    double *F = malloc(n * 2 * FD_K * sizeof *F);
    for (size_t i = 0; i < n; i++)
        fourier_features(amscr_db_descriptor(db, i), F + i * 2 * FD_K);
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            double s = 0;
            for (int t = 0; t < 2 * FD_K; t++)
                s += (F[i * 2 * FD_K + t] - F[j * 2 * FD_K + t]) * (F[i * 2 * FD_K + t] - F[j * 2 * FD_K + t]);
            out[i * n + j] = sqrt(s);
        }
    free(F);
}

/* One base matrix: from the cache or computed (what: 0 sim, 1 aff, 2 AMSCR, 3 Fourier, 4 moments, 5 moments
 * in the affine frame).
 * The key's "sp" marks contours traced at sub-pixel accuracy (the tool's tracer since 0.4). */
static double *one(const coll_t *c, const raw_cfg *r, int what, amscr_db **db)
{
    static const char *names[] = {"channel similarity", "channel affine", "AMSCR", "Fourier", "moments",
                                  "moments, affine frame", "inner distance"};
    size_t n = c->s.n;
    char key[300];
    char tag[32] = "";
    if (r->stride > 1)
        snprintf(tag, sizeof tag, " t%zu", r->stride);
    snprintf(key, sizeof key, "%s sp n%zu N%zu b%g s%g l%g r%d m%d%s", c->name, n, r->N, r->band, r->skip, r->loc,
             r->refl, what, tag);
    double *M = malloc(n * n * sizeof *M);
    if (!M || cache_io(key, M, n, 0) == 0)
        return M;
    double t0 = folds_now();
    if (!*db && !(*db = make_db(c, r))) {
        free(M);
        return NULL;
    }
    double tp = folds_now() - t0;
    t0 = folds_now();
    int st = 0;
    if (what < 2)
        st = channel_in_frame(*db, what ? AMSCR_INVARIANCE_AFFINE : AMSCR_INVARIANCE_SIMILARITY, r->stride, M);
    else if (what == 2)
        st = amscr_db_distance_matrix(*db, NULL, NULL, M) == AMSCR_OK ? 0 : -1;
    else if (what == 3)
        fourier_matrix(*db, M);
    else if (what == 6)
        st = amscr__inner_matrix(*db, 2, NULL, NULL, M) == AMSCR_OK ? 0 : -1;
    else
        moment_matrix(*db, what == 5, M);
    double t = folds_now() - t0, pairs = 0.5 * (double)n * (double)(n - 1);
    fprintf(stderr, "[%s: %s, %zu shapes (prepare %.1f s): %.1f s, %.0f pairs/s]\n", key, names[what], n, tp, t,
            pairs / t);
    if (st != 0) {
        free(M);
        return NULL;
    }
    cache_io(key, M, n, 1);
    return M;
}

/* CPU microseconds per pair of the similarity-frame channel matrix of c under r (not cached). */
double folds_channel_cpu(const coll_t *c, const raw_cfg *r)
{
    amscr_db *db = make_db(c, r);
    size_t n = c->s.n;
    double *M = malloc(n * n * sizeof *M);
    struct timespec t0, t1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
    int st = db && M ? channel_in_frame(db, AMSCR_INVARIANCE_SIMILARITY, r->stride, M) : -1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
    amscr_db_free(db);
    free(M);
    double cpu = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    return st == 0 ? 1e6 * cpu / (0.5 * (double)n * (double)(n - 1)) : -1.0;
}

int base_get(const coll_t *c, const raw_cfg *r, int amscr, int fourier, base_t *b)
{
    amscr_db *db = NULL;
    memset(b, 0, sizeof *b);
    b->n = c->s.n;
    b->hs = one(c, r, 0, &db);
    b->ha = one(c, r, 1, &db);
    b->in = one(c, r, 6, &db);
    if (amscr)
        b->am = one(c, r, 2, &db);
    if (fourier)
        b->fd = one(c, r, 3, &db);
    if (fourier > 1)
        b->gm = one(c, r, 4, &db);
    if (fourier > 1)
        b->ga = one(c, r, 5, &db);
    amscr_db_free(db);
    return b->hs && b->ha && b->in && (!amscr || b->am) && (!fourier || b->fd) && (fourier < 2 || (b->gm && b->ga)) ? 0 : -1;
}
