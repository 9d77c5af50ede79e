/* folds.h — the generalization audit's data and sweeps (retrieval_folds.c). */
#ifndef AMSCR_BENCH_FOLDS_H
#define AMSCR_BENCH_FOLDS_H
#include <stddef.h>
#include <stdint.h>

#include "folds_tsv.h"
#include "mcd_set.h"

/* Settings a base matrix depends on. */
typedef struct {
    size_t N;       /* samples */
    double band;    /* channel band, fraction of N */
    double skip;    /* channel skip cost */
    double loc;     /* channel locality */
    int refl;       /* mirror images */
    size_t stride;  /* the channel's DP on every stride-th sample (1 as the library) */
} raw_cfg;

/* Settings applied on a collection's base matrices. */
typedef struct {
    double share;   /* affine share of the channel */
    double weight;  /* channel weight of the fusion with AMSCR (1: the channel alone) */
    size_t k;       /* re-ranking k (0: none); see kmode */
    unsigned iters; /* re-ranking iterations */
    double wfd;     /* weight of the Fourier proportion channel (0: none) */
    int kmode;      /* 0: k as is; 1: k = round(kfrac * sqrt(n)); 2: mutual-kNN k among kfrac nearest */
    double kfrac;
    int prop;       /* the proportion channel of wfd: 0 Fourier magnitudes, 1 low-order moments, 2 the
                       moments in the affine frame, 3 the moments of both frames mixed by the share */
    int fmode;      /* fusion of the proportion channel: 0 medians, 1 local scales, 2 local scales with
                       per-query confidence */
    int scale;      /* the channel before re-ranking: 0 as is; 1 local scaling d / sqrt(s_i s_j), s = the
                       distance to the lsk-th neighbour; 2 the same with s = the mean distance to the lsk
                       nearest; 3 mutual proximity (empirical, no parameter); 4 mutual proximity (Gaussian) */
    size_t lsk;
    double inner;   /* share of the inner-distance graph in the re-ranking (0: one graph) */
} post_cfg;

/* A labelled collection. */
typedef struct {
    const char *name;
    shape_set s;
    int kind; /* 0 bull's eye, 1 top-k sum */
} coll_t;

/* Base matrices of one collection under one raw_cfg (NULL until needed). */
typedef struct {
    size_t n;
    double *hs, *ha, *am, *fd, *gm, *ga; /* channel similarity / affine frame, AMSCR, Fourier, moments
                                         (similarity / affine frame) */
    double *in;                          /* the inner distance (the re-ranking's second graph) */
} base_t;

typedef struct {
    coll_t dev, k99, k216, devwarp, devk216;
    int *fold; /* per mpeg7-dev shape: 0 fold A, 1 fold B */
} folds_data;

extern const raw_cfg RAW_DEFAULT;
extern const post_cfg POST_DEFAULT;

int folds_load(const char *datasets, folds_data *fd);
void folds_free(folds_data *fd);

/* Base matrices of c under r: the channel always, AMSCR when amscr, Fourier when fourier (1) or
 * Fourier and moments (2). */
int base_get(const coll_t *c, const raw_cfg *r, int amscr, int fourier, base_t *b);
void base_free(base_t *b);

/* Score of the sub-collection idx (m shapes; NULL = all) under pc. */
extern size_t last_k; /* the k of the last eval_sub */
double eval_sub(const base_t *b, const coll_t *c, const size_t *idx, size_t m, const post_cfg *pc);
/* The sub-collection's final matrix (m x m, caller frees; NULL on failure) under pc. */
double *eval_matrix(const base_t *b, const size_t *idx, size_t m, const post_cfg *pc);

/* One row: fold A, fold B, mpeg7-dev, Kimia-99, Kimia-216 under (r, pc). */
typedef struct {
    double a, b, dev, k99, k216;
} row_scores;
int score_row(const folds_data *fd, const raw_cfg *r, const post_cfg *pc, row_scores *out);

int folds_sweep_post(const folds_data *fd);
int folds_sweep_raw(const folds_data *fd);
int folds_scale(const folds_data *fd);
int folds_fourier(const folds_data *fd);
int folds_fuse(const folds_data *fd, const char *datasets);
int folds_local(const folds_data *fd, const char *datasets);
int folds_halves(const folds_data *fd);
/* The next seeded random subset of C of mpeg7-dev's L classes: its shapes' indices into idx
 * (returns their count); perm and in are L-entry scratch. */
size_t folds_subset(const folds_data *fd, int C, int L, unsigned long long *seed, int *perm, int *in, size_t *idx);
/* The channel's band on random class subsets of mpeg7-dev and on the larger collections. */
int folds_band(const folds_data *fd);
/* The inner-distance graph's share in the re-ranking, the same way (folds_inner.c). */
int folds_inner(const folds_data *fd);
int folds_classes(const folds_data *fd, const char *datasets);
/* Local scale of each row of the m x m matrix M: its k-th smallest off-diagonal entry. */
void folds_local_scale(const double *M, size_t m, size_t k, double *sigma);
int folds_mcd(const char *datasets);
double folds_channel_cpu(const coll_t *c, const raw_cfg *r);
int folds_cost(const folds_data *fd);
int folds_row(const folds_data *fd, const char *datasets, char **v);

double folds_now(void);
#endif
