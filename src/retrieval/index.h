/* index.h — internals of the retrieval index (index*.c): a collection with what one-vs-many
 * retrieval needs, so that a query never recomputes the collection's matrix (docs/method.md
 * §10). Never installed. */
#ifndef AMSCR_INDEX_H
#define AMSCR_INDEX_H

#include "channel.h"
#include "inner.h"
#include "internal.h"
#include "rank.h"
#include "rows.h"
#include "signature.h"

/* The shortlist a build seeks each shape's neighbours in (index_build.c tells why 192). */
#define AMSCR__INDEX_BUILD_SHORTLIST 192
/* From this many shapes a shortlist build finds the shortlists among the lists of a coarse
 * quantizer (signature.h) instead of scanning every shape's lower bound, and keeps it for the
 * queries (index.c: amscr__index_shortlist). */
#define AMSCR__INDEX_IVF_MIN 20000

struct amscr_index {
    amscr_db *db;         /* the collection (owned, unless db_borrowed) */
    int db_borrowed;      /* db is the caller's (a collection's kept index: retrieval_query.c) */
    size_t k;             /* neighbours a shape: amscr__rerank_k (a 0.5 file: min(rerank_k, n)) */
    size_t candidates;    /* the build's shortlist M (0: every shape, exact lists) */
    double dmax;          /* largest base distance of the collection */
    double med_a, med_h;  /* the fusion's medians (0 < channel weight < 1; else 0) */
    size_t sig_dim;       /* AMSCR__SIG_DIM */
    amscr__sig_ivf ivf;   /* the coarse quantizer of the lower-bound vectors a shortlist is sought in
                           * (a shortlist build of at least AMSCR__INDEX_IVF_MIN shapes; nc 0: none, every
                           * bound scanned) */
    uint16_t *sigq;       /* n x sig_dim: the signatures in 16 bits (signature.h) */
    int32_t *sige;        /* n: their exponents */
    float *sig_lb;        /* n x AMSCR__SIG_LB_DIM: their lower-bound vectors */
    int nf;               /* channel frames whose features are kept (0: no channel) */
    amscr__hf *hf;        /* n x nf: each shape's channel features, ready for matching (an entry
                           * with no sequences, after a lazy load: built where a pair needs it) */
    int lazy;             /* loaded with AMSCR_INDEX_LAZY: features of loaded shapes not built */
    int failed;           /* a failed amscr_index_add left its new shapes without their lists */
    unsigned char *mirror_pool; /* the mirrored orientation of the features of shapes whose rows are
                                 * being built (a build, an add), in one block (index_features.c)
                                 * freed whole once the rows are; NULL otherwise */
    size_t pool_first;    /* the first shape whose mirrored features the pool holds */
    unsigned char *map;   /* the index file, mapped, while loaded shapes' heights point into it and
                           * db decodes its prepared shapes from it (a lazy load of a file;
                           * index_io.c, db.c), else NULL */
    size_t map_len;
    uint32_t *nb_idx;     /* n x k: itself first, then by (base distance, index) */
    double *nb_dist;      /* n x k */
    size_t k2;            /* the inner distance's graph (index_inner.c): k when the params give it a share of
                           * the re-ranking, else 0 (and the three below NULL) */
    double dmax2;         /* largest inner distance of the collection */
    amscr__inner *inner;  /* n inner features */
    uint32_t *in_idx;     /* n x k2: itself first, then by (inner distance, index) */
    double *in_dist;      /* n x k2 */
    char **names;         /* n entries (NULL: unnamed) */
    char **groups;        /* n entries (NULL: no group) */
    char **classes;       /* class name of label L (0 <= L < nclasses; NULL: unnamed) */
    size_t nclasses;
    size_t cap;           /* allocated rows of sig, nb_*, names */
    size_t *rev_start;    /* n + 1 offsets into rev (NULL: not built; a query builds its own) */
    uint32_t *rev;        /* rows i holding shape j in their lists (either graph's; a row twice when both):
                           * rev[rev_start[j]..rev_start[j+1]) */
    double *w_fixed;      /* n rows of w_kk affinities: each stored row's as a query that enters neither
                           * it nor its neighbours' rows sees them (index_graph.c; NULL: none) */
    size_t w_k, w_kk;     /* the graph's k they were computed for (amscr__rerank_k of n + 1), and k + k2 */
    double w_tiny, w_tiny2; /* and its distance floors */
};

/* How the base distance of the retrieval matrix (fuse.c) is computed pair by pair. */
typedef struct {
    const amscr_params *p;
    double w, sa, sh;            /* channel weight and the fusion's weights */
    int nf;                      /* frames of the channel (0: no channel) */
    amscr_invariance frames[2];
    double share[2];
    unsigned threads;
} amscr__base;

/* Per-thread scratch of the pair distance. */
typedef struct {
    amscr_workspace *ws;
    amscr__hf_cfg cfg[2]; /* per frame of amscr__channel_frames */
    amscr__hf_ws hws;
    int have_hws;
} amscr__pair_ws;

/* ------------------------------------------------------------ the object (index.c) */

/* An empty index of a copy of db (no lists yet). */
amscr_status amscr__index_alloc(const amscr_db *db, amscr_index **out);
amscr_status amscr__index_alloc_on(const amscr_db *db, amscr_index **out); /* on db itself */
/* x's collection replaced by a copy of it held as compact records (amscr__db_compact_copy: its
 * shapes decoded when read); x owns it. */
amscr_status amscr__index_compact_db(amscr_index *x);
/* An index on db itself (not a copy; db must outlive it), its lists exact (candidates 0). */
amscr_status amscr__index_build_on(const amscr_db *db, amscr_progress_fn progress, void *user, amscr_index **out);
/* Shapes n0..n-1 of x->db, already in it, into x: features, lists, the lists they enter. */
amscr_status amscr__index_extend(amscr_index *x, size_t n0, amscr_progress_fn progress, void *user);
/* Grows the per-shape arrays to hold n rows. */
amscr_status amscr__index_reserve(amscr_index *x, size_t n);
/* Refined lists (*nidx, *ndist) replace (*idx, *dist), their first `keep` entries (the rows
 * not refined) copied over; the old freed, *nidx and *ndist NULL. */
void amscr__index_take_lists(uint32_t **idx, double **dist, uint32_t **nidx, double **ndist, size_t keep);
/* The channel frames whose features an index with params p keeps (0: no channel). */
int amscr__index_frames(const amscr_params *p);
/* The inner graph's neighbours a shape of an index of k neighbours with params p: k when p gives
 * the inner distance a share of the re-ranking, else 0. */
size_t amscr__index_k2(const amscr_params *p, size_t k);
/* db can be indexed (closed curves for the channel, at most 2^32 - 1 shapes). */
amscr_status amscr__index_check_db(const amscr_db *db, const char *what);
/* The member rule of the search calls (index_query.c): whether p's scores depend on the
 * collection (re-ranking or fusion) or on the pair's order (the channel), so a member's copy is
 * scored as the member; and
 * amscr_index_search_scores (member 1) or amscr_index_query_scores (member 0) with candidates 0,
 * without their checks, progress (may be NULL) counting the base distances. */
int amscr__member_rule_applies(const amscr_params *p);
amscr_status amscr__index_row(const amscr_index *x, const amscr_descriptor *q, int member,
                              amscr_progress_fn progress, void *user, double *out);
/* Shape i's signature (dequantized) into out[AMSCR__SIG_DIM]. */
void amscr__index_sig(const amscr_index *x, size_t i, float *out);
/* Shape i's signature from the floats sig (computed, or read from a file: rounded to 16 bits),
 * and its lower-bound vector from what is kept. */
void amscr__index_set_sig(amscr_index *x, size_t i, const float *sig);

/* The candidates of shape-like q: every shape (m = 0 or >= n) or the m whose signatures are
 * nearest sig / lb (exclude: an index to leave out or SIZE_MAX), ascending, sought in the lists
 * of x's quantizer nearest lb when x has one (x->ivf); 0 when out of memory. */
size_t amscr__index_shortlist(const amscr_index *x, const float *sig, const float *lb, size_t m, size_t exclude,
                              size_t *cand);
/* Frees the lists' reverse and the stored rows' affinities (index_reverse.c builds them). */
void amscr__index_reverse_free(amscr_index *x);
/* Drops x's hold on its mapped file: the heights that point into it forgotten, x->map NULL. */
void amscr__index_detach_map(amscr_index *x);

/* ------------------------------------------ the base distance pair by pair (index_pairs.c) */

void amscr__base_init(amscr__base *b, const amscr_params *p, double med_a, double med_h);
amscr_status amscr__pair_ws_init(const amscr__base *b, amscr__pair_ws *pw);
void amscr__pair_ws_free(amscr__pair_ws *pw);
/* A workspace on the heap (*out, for the threads' scratch of rows.c) and its release. */
amscr_status amscr__pair_ws_new(const amscr__base *b, void **out);
void amscr__pair_ws_delete(void *pw);
/* The channel sequences of d in b's frames (hf[0..nf-1]); free with amscr__base_hf_free. */
amscr_status amscr__base_hf(const amscr__base *b, const amscr_descriptor *d, amscr__hf hf[2]);
void amscr__base_hf_free(const amscr__base *b, amscr__hf hf[2]);
/* out[t] = base distance of shape cand[t] of db and q (sequences hq), on this thread; hfs (n x
 * b->nf, or NULL: built per pair) the shapes' channel features. */
amscr_status amscr__base_pairs(const amscr__base *b, const amscr_db *db, const amscr__hf *hfs,
                               const amscr_descriptor *q, const amscr__hf hq[2], size_t qpos, const size_t *cand,
                               size_t m, amscr__pair_ws *pw, double *out);

/* out[t] = base distance of shape cand[t] of db and q, computed as the matrix cell of the two
 * (the lower index first; q counts as index qpos, SIZE_MAX = after every shape), on b->threads
 * threads. progress (may be NULL) counts pairs. */
amscr_status amscr__base_row(const amscr__base *b, const amscr_db *db, const amscr__hf *hfs,
                             const amscr_descriptor *q, size_t qpos, const size_t *cand, size_t m,
                             amscr_progress_fn progress, void *user, double *out);

/* --------------------------------------------- each shape's kept features (index_features.c) */

/* Signatures, lower-bound vectors (unless have_sig: then the signatures are there) and channel
 * features of shapes first..n-1, on the params' threads; drops the lists' reverse, and rebuilds
 * it when have_sig and first == 0 (a load: the lists are in place). */
/* AMSCR_E_STATE from the calling public function `fn` when x was left incomplete by a failed
 * amscr_index_add (cancelled or out of memory, its new shapes without their lists): the header
 * says to free it, and every call but amscr_index_free refuses it rather than read the lists. */
#define AMSCR__CHECK_INDEX_WHOLE(fn, x)                                                                      \
    do {                                                                                                   \
        if ((x)->failed)                                                                                   \
            return amscr__fail(AMSCR_E_STATE, "%s: the index was left incomplete by a failed "              \
                                              "amscr_index_add (cancelled or out of memory): free it", (fn)); \
    } while (0)

/* The features of shapes first..n-1 (have_sig: a load's, which read their signatures and inner
 * features from the file); progress (may be NULL) over the shapes, in two stages when the inner
 * features are computed too. */
amscr_status amscr__index_features(amscr_index *x, size_t first, int have_sig, amscr_progress_fn progress,
                                    void *user);

/* ------------------------------------------ the mirrored features' pool (index_mirror.c) */

/* Bytes of one frame's mirrored orientation in the pool at N samples (its heights, then its
 * spectra, each rounded up to 16 bytes). */
size_t amscr__index_pool_frame(size_t N);
/* The mirrored orientation of a shape's features (nf frames) freed; what points into pool
 * (pool_len bytes; NULL, 0: none) only forgotten. */
void amscr__index_mirror_free(amscr__hf *hf, int nf, const unsigned char *pool, size_t pool_len);
/* Shape i's mirrored features moved into x's pool (their own blocks freed). */
void amscr__index_mirror_to_pool(amscr_index *x, size_t i);
/* The mirrored orientation of the channel features of shapes first..n-1 freed, once their rows
 * are built (the pairs that read it make it), and the mirror pool with it. */
void amscr__index_drop_mirrors(amscr_index *x, size_t first);

/* ------------------------------------------------------------------- the neighbour lists */

/* Rows first..n-1 from their M signature-nearest shapes (index_build.c); x->dmax grows. */
amscr_status amscr__index_rows(amscr_index *x, size_t first, size_t m, amscr_progress_fn progress, void *user);
/* Rows first..n-1's lists (their K nearest among their shortlists S, m each, ascending) refined
 * from the neighbours' lists (index_refine.c); x->dmax grows. */
amscr_status amscr__index_refine(amscr_index *x, const amscr__base *b, size_t first, const uint32_t *S, size_t m);
/* The inner distance of shapes i and j of x, computed as the matrix cell of the two (the lower
 * index first; index_inner.c). */
double amscr__index_inner_pair(const amscr_index *x, size_t i, size_t j, amscr__inner_ws *ws);
/* Lists from the full inner matrix: x->in_*, x->dmax2. */
amscr_status amscr__index_inner_full(amscr_index *x, amscr_progress_fn progress, void *user);
/* Rows first..n-1's inner lists among their shortlists S (m each) and their base lists (a
 * shortlist build); x->dmax2 grows. */
amscr_status amscr__index_inner_rows(amscr_index *x, size_t first, const uint32_t *S, size_t m);

/* -------------------------------------------------------- what a query reads of the lists */

/* The lists' reverse (x->rev_start, x->rev) and the stored rows' affinities (x->w_fixed) from
 * x's lists (index_reverse.c); frees the old. */
amscr_status amscr__index_reverse(amscr_index *x);
/* The stored lists' reverse of x (n shapes, k + k2 entries each: both graphs') into rs (n + 1
 * offsets) and rv. */
void amscr__index_reverse_lists(const amscr_index *x, size_t n, size_t *rs, uint32_t *rv);
/* The scores (n entries) of row `self` (n: a query; < n: that shape of the index) against every
 * shape from its base distances dq[t] to the m candidates cand[t] (ascending) and, for a query
 * of an index with the inner graph, its inner distances dq2[t] (else NULL): the row of the
 * retrieval matrix of the collection plus the query, or of the collection (index_diffuse.c). */
amscr_status amscr__index_scores(const amscr_index *x, size_t self, const size_t *cand, const double *dq,
                                 const double *dq2, size_t m, double *out);

/* -------------------------------------------------------------------- loading (index_io.c) */

/* x as an index file of `version` (13: the format of 0.11 to 0.13, full shape records and the
 * inner features; 14: amscr_index_save_memory's) into *out_buf (caller frees with free). */
amscr_status amscr__index_write(const amscr_index *x, uint32_t version, void **out_buf, size_t *out_len);
/* An index file's bytes buf (len) mapped with mmap: loaded as amscr_index_load_with loads a
 * file (AMSCR_INDEX_LAZY: the index keeps the mapping, its shapes decoded from it when needed);
 * the mapping is the callee's either way (unmapped when not kept). */
amscr_status amscr__index_load_mapped(unsigned char *buf, size_t len, unsigned flags, amscr_index **out);

#endif
