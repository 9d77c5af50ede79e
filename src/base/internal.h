/* internal.h — shared internals of libamscr (never installed). */
#ifndef AMSCR_INTERNAL_H
#define AMSCR_INTERNAL_H

#include "amscr.h"

#include <locale.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#if defined(__GNUC__)
#define AMSCR_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define AMSCR_PRINTF(a, b)
#endif

/* ---- numbers in the "C" locale (c_numeric.c) ------------------------ */
/* The calling thread reads and writes numbers with '.' between enter and leave, whatever
 * setlocale the program made (uselocale: the thread's only). */
typedef struct {
    locale_t c, prev;
} amscr__c_numeric;
/* AMSCR_OK, or AMSCR_E_NOMEM with its detail (then no leave). */
amscr_status amscr__c_numeric_enter(amscr__c_numeric *s);
void amscr__c_numeric_leave(amscr__c_numeric *s);

/* ---- progress of a call in stages (progress.c) ------------------------ */
/* Stage `stage` of `stages` (equal shares) of a call reporting to fn(user, ...). */
typedef struct {
    amscr_progress_fn fn;
    void *user;
    size_t stage, stages;
} amscr__stages;
/* A stage's (done, total) reported to sp->fn as its share of the whole; user is an amscr__stages. */
int amscr__stage_cb(void *user, size_t done, size_t total);

/* ---- errors (errors.c) ------------------------------------------------ */
/* Sets the calling thread's detail and returns `st`. */
amscr_status amscr__fail(amscr_status st, const char *fmt, ...) AMSCR_PRINTF(2, 3);
/* Clears the calling thread's detail (call at the start of public entry points). */
void amscr__clear_error(void);

#define AMSCR_CHECK_NULL(ptr)                                                                  \
    do {                                                                                       \
        if ((ptr) == NULL)                                                                     \
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s is NULL", __func__, #ptr);         \
    } while (0)

/* Returns AMSCR_E_INVALID_ARG from the calling public function when the flag v is not 0 or 1
 * (flags are int 0 or 1: amscr.h, Conventions). */
#define AMSCR_CHECK_FLAG(v)                                                                    \
    do {                                                                                       \
        if ((v) != 0 && (v) != 1)                                                              \
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s = %d is not 0 or 1", __func__, #v,   \
                               (int)(v));                                                      \
    } while (0)

/* As AMSCR_CHECK_NULL in a helper of the public function named by the string fn. */
#define AMSCR_CHECK_NULL_IN(fn, ptr)                                                           \
    do {                                                                                       \
        if ((ptr) == NULL)                                                                     \
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s is NULL", (fn), #ptr);             \
    } while (0)

/* AMSCR_OK when cond holds, else AMSCR_E_INVALID_ARG with the printf-style detail given. */
#define AMSCR__REQUIRE(cond, ...) ((cond) ? AMSCR_OK : amscr__fail(AMSCR_E_INVALID_ARG, __VA_ARGS__))
/* Defines the validating setter `amscr_status fn(obj_t *obj, vtype v)` of obj->field: it clears
 * the calling thread's detail, refuses a NULL obj and stores v when `check`, an amscr_status
 * expression of v (AMSCR__REQUIRE), is AMSCR_OK; it returns that status (obj unchanged otherwise). */
#define AMSCR__SETTER(fn, obj_t, obj, vtype, field, check)                                     \
    amscr_status fn(obj_t *obj, vtype v)                                                       \
    {                                                                                          \
        amscr__clear_error();                                                                  \
        AMSCR_CHECK_NULL(obj);                                                                 \
        amscr_status check_ = (check);                                                         \
        if (check_ == AMSCR_OK)                                                                \
            obj->field = v;                                                                    \
        return check_;                                                                         \
    }
/* Defines the getter `vtype fn(const obj_t *obj)` of obj->field: 0 for a NULL obj. */
#define AMSCR__GETTER(fn, obj_t, vtype, field)                                                 \
    vtype fn(const obj_t *obj) { return obj ? obj->field : (vtype)0; }

/* ---- small helpers -------------------------------------------------- */
/* Overflow-checked malloc of n*size bytes (NULL on overflow or failure; n == 0 gives a
 * valid 1-byte block). */
void *amscr__malloc_array(size_t n, size_t size);
void *amscr__calloc_array(size_t n, size_t size);
int amscr__all_finite(const double *v, size_t n);
/* st, after setting every element of the rows x cols output out to NaN when st is a failure (a
 * batch call's contract: never a stale or partial output); out NULL: nothing set. */
amscr_status amscr__nan_on_failure(amscr_status st, double *out, size_t rows, size_t cols);

/* ---- objects ---------------------------------------------------------- */
struct amscr_contour {
    size_t n;
    double *xy; /* 2n */
};

/* Makes a contour that takes ownership of xy (2n doubles from malloc). */
amscr_status amscr__contour_wrap(double *xy, size_t n, amscr_contour **out);

#define AMSCR__MAX_SCALES 64
/* Largest mixture class count of the scale selection (amscr_params_set_kmax's bound): the
 * per-scale residuals of at most 64 scales never support more classes than this. */
#define AMSCR__KMAX 16

struct amscr_params {
    size_t num_samples;
    size_t num_scales;
    double scales[AMSCR__MAX_SCALES];
    amscr_method method;
    int closed;
    int reflections;
    amscr_parametrization parametrization;
    double presmooth;
    unsigned arclength_passes;
    unsigned oversampling;
    unsigned kmax;
    int symmetric;
    unsigned refine;
    unsigned num_threads;
    amscr_invariance invariance;
    double penalty;
    /* partial matching: the source is an open fragment of the target's closed boundary */
    int partial;
    /* polish the reported map on the input points (polish.c) */
    int polish;
    /* switchable stages of amscr_register turned off (AMSCR__STAGE_BIT; register/stages.c) */
    unsigned stages_off;
    /* retrieval (0.2, channel.c / fuse.c) */
    double channel_weight;             /* share of the shape channel in the fused distance, 0..1 */
    amscr_invariance channel_invariance; /* frame of the shape channel (affine or similarity) */
    double channel_affine_share;       /* similarity frame: share of the whitened frame's channel */
    double channel_band;               /* DP band half-width, fraction of N */
    double channel_affine_band;        /* the same in the whitened second frame (0.6) */
    double channel_skip;               /* DP cost of a sample matched twice */
    double channel_locality;           /* height bins weighted 1 / (1 + locality * distance along the curve) */
    unsigned rerank_k;                 /* re-ranking neighbours, 0 = no re-ranking */
    unsigned rerank_iterations;
    double rerank_inner_share;         /* share of the inner-distance graph in the re-ranking (0.7) */
    double inner_closing;              /* closing radius of the inner distance's silhouette / sqrt(area) (0.9) */
    double channel_affine_view;        /* > 0: a pair's channel = min(the mix, this x d_affine) (0.11) */
};

/* The stages of amscr_register in pipeline order: their names in base/stage_names.c, their
 * functions and conditions in register/stages.c. */
enum {
    AMSCR__STAGE_DESPIKE,
    AMSCR__STAGE_SEARCH,
    AMSCR__STAGE_METHOD,
    AMSCR__STAGE_RECOVERY,
    AMSCR__STAGE_FINAL_SOLVE,
    AMSCR__STAGE_SYMMETRIC,
    AMSCR__STAGE_POLISH,
    AMSCR__STAGE_ORDER,
    AMSCR__STAGE_EVEN,
    AMSCR__STAGE_ALTERNATIVES,
    AMSCR__STAGE_CORRESPOND,
    AMSCR__STAGE_PIXEL_GRID,
    AMSCR__NUM_STAGES
};
/* The bit of stage i in params->stages_off. */
#define AMSCR__STAGE_BIT(i) (1u << (unsigned)(i))
/* Whether params p leave switchable stage i on. */
#define AMSCR__STAGE_ON(p, i) (!((p)->stages_off & AMSCR__STAGE_BIT(i)))
/* Name of stage i (NULL past the last). */
const char *amscr__stage_name(size_t i);
/* Index of the switchable stage called name, or -1. */
int amscr__stage_switch(const char *name);

/* ---- geometry internals (contour.c, smooth.c, resample.c, affine.c) ---- */
double amscr__signed_area(const double *xy, size_t n);
void amscr__reverse_points(double *xy, size_t n);
/* lo and hi widened to hold the n points p (per coordinate). */
void amscr__points_extent(const double *p, size_t n, double lo[2], double hi[2]);
/* Copies xy dropping repeated consecutive points (and, closed, a repeated closing point);
 * returns the count. out: room for 2n doubles. */
size_t amscr__dedupe_points(const double *xy, size_t n, int closed, double *out);
/* despike.c: drops isolated spikes (runs of <= 3 points the list p leaves and re-enters by edges
 * 8x its median; open: also a stray end) in place; returns the new count. scratch: n doubles. */
size_t amscr__despike(double *p, size_t n, int closed, double *scratch);
/* The median edge length of the list p (n >= 2 points; scratch: n doubles, reordered). */
double amscr__median_edge(const double *p, size_t n, int closed, double *scratch);
/* The extent (the larger side of the bounding box) a shape may have: the moments of the
 * normalization multiply four coordinates, and beyond about 1e75 (below 1e-75) they overflow
 * (underflow); every face works at 1e70 and 1e-70. Set by the floating-point range, not on data. */
#define AMSCR__EXTENT_MIN 1e-60
#define AMSCR__EXTENT_MAX 1e60
/* How far from the origin, in extents, a shape may lie: 2^44, where the spacing of doubles is
 * 1/256 of the extent, so coordinates hold the shape to less than that and a map in their frame
 * (its B) cannot be written more finely (a 100-unit shape at 1e16 registered 3.5 % off, yet
 * confident). Set by the floating-point precision, not on data. */
#define AMSCR__OFFSET_MAX 17592186044416.0
/* Finite, at least 8 distinct points, an extent within the range above, not collinear, and
 * (closed) a non-zero area; else AMSCR_E_INVALID_ARG or AMSCR_E_DEGENERATE with a detail. */
amscr_status amscr__validate_points(const double *xy, size_t n, int closed, const char *what);
size_t amscr__kernel_radius(double sigma);
void amscr__kernel_fill(double sigma, size_t r, double *taps);
void amscr__smooth_with_kernel(const double *xy, size_t n, int closed, const double *g, size_t r, double *wrapped,
                               double *out);
amscr_status amscr__smooth(const double *xy, size_t n, int closed, double sigma, double *out);
amscr_status amscr__smooth_box3(const double *xy, size_t n, int closed, double sigma, double *out, double *scratch);
amscr_status amscr__resample_euclid(const double *xy, size_t n, int closed, size_t m, double *out);
amscr_status amscr__affine_cum(const double *xy, size_t n, int closed, double sigma0, double *cum, double *out_total);
int amscr__sym2_invsqrt(const double cov[3], double W[4], double Winv[4]);
amscr_status amscr__parametrize(const double *P, size_t np, int closed, amscr_parametrization kind, double sigma0_frac,
                                unsigned passes, size_t M, size_t m, double *out);
amscr_status amscr__whiten(const double *xy, size_t n, double *out_xy, double fwd[6], double inv[6]);
/* closing.c: the outline of the region the closed curve xy (n points) bounds, closed by a disk of
 * radius c sqrt(|area|) (c > 0): *out (2 *out_n doubles, caller frees), counter-clockwise.
 * AMSCR_E_DEGENERATE when the curve bounds no area; AMSCR_E_NOMEM. */
amscr_status amscr__close_curve(const double *xy, size_t n, double c, double **out, size_t *out_n);
/* Vertices of a prepared shape's outline (the inner distance's polygon, retrieval/inner.h). */
#define AMSCR__OUTLINE_N 64
/* That outline closed at c (amscr__close_curve) resampled to AMSCR__OUTLINE_N points evenly along
 * its length into V (2 AMSCR__OUTLINE_N doubles); at most 4096 points of xy are read (every
 * k-th: the grid's pixels are coarser). AMSCR_E_DEGENERATE when the curve bounds no area; AMSCR_E_NOMEM. */
amscr_status amscr__outline(const double *xy, size_t n, double c, double *V);
void amscr__affine_compose(const double a[6], const double b[6], double out[6]);
/* The inverse of the affine map m into out (may be m); 0 when it is singular or not finite (out
 * unchanged, no error set: amscr_affine_invert is the public call, with its own test). */
int amscr__affine_inverse(const double m[6], double out[6]);
/* rasterize.c: a closed polygon P (n vertices) on the w x h pixel grid whose pixel (i, j) is
 * centred at (x0 + i, y0 + j), even-odd rule, out[j w + i] 255 or 0. */
/* The horizontal line y's crossings of P, sorted into xs (room for n); returns an even count. */
size_t amscr__crossings(const double *P, size_t n, double y, double *xs);
/* The pixels P covers by at least half their area (a camera and a threshold at half level). */
amscr_status amscr__raster_cover(const double *P, size_t n, long x0, long y0, size_t w, size_t h, uint8_t *out);
/* The pixels whose centre P contains. */
amscr_status amscr__raster_centres(const double *P, size_t n, long x0, long y0, size_t w, size_t h, uint8_t *out);
void amscr__params_defaults(amscr_params *p);
void amscr__params_registration(amscr_params *p);
void amscr__params_retrieval(amscr_params *p);

/* ---- least squares (lstsq.c) ---- */
size_t amscr__lstsq_work_size(size_t m, size_t n, size_t nrhs);
amscr_status amscr__lstsq_colmajor(double *A, size_t m, size_t n, double *B, size_t nrhs, double *work, int *iwork,
                                   double *x, double *resid);


/* ---- 1-D mixture, small hot-path fit (gmm1d.c): no allocation, caller scratch ---- */
size_t amscr__gmm1d_small_scratch(size_t n, size_t k);
amscr_status amscr__gmm1d_fit_small(const double *x, size_t n, size_t k, unsigned max_iter, double tol, double var_floor_rel,
                           double *w, double *mu, double *var, double *scratch, unsigned *out_iter,
                           int *out_converged, double *out_loglik);
/* The same fit of data already ascending (sorted may be scratch itself: no copy, no sort). */
amscr_status amscr__gmm1d_fit_sorted(const double *sorted, size_t n, size_t k, unsigned max_iter, double tol,
                                     double var_floor_rel, double *w, double *mu, double *var, double *scratch,
                                     unsigned *out_iter, int *out_converged, double *out_loglik);

/* ---- prepared shapes (descriptor.c) ---- */
struct amscr_descriptor {
    amscr_params params; /* as built */
    size_t n;            /* N samples */
    size_t p;            /* scales */
    double *input;       /* 2N: samples in input coordinates */
    double *base;        /* 2N: normalized, unsmoothed */
    double *scaled;      /* p * 2N: normalized, smoothed at each scale */
    double fwd[6], inv[6];
    /* derived from the above (recomputed on load) */
    double *mom;   /* (p+1) * 6: per level (0 = base, k+1 = scale k) sums sxx, sxy, syy, sx, sy, n */
    double *minv;  /* (p+1) * 9: inverse of each level's 3x3 normal matrix */
    double *spec;  /* 4N: DFT of base x then base y (complex interleaved), closed curves only */
    double *gain;  /* (p+1) * N: |G_k(w)|^2 per scale (index k), and their sum (index p) */
    double norm2;  /* sum |base|^2 */
    double nyq2;   /* even N: (|X(N/2)|^2 + |Y(N/2)|^2) / N, the Nyquist term's energy */
    size_t finest; /* index of the smallest scale */
    /* the input points (deduplicated, counter-clockwise, every k-th when over
     * AMSCR__POLISH_MAX_POINTS) kept for the polish (polish.c): closed curves under affine
     * invariance; NULL in collections (amscr_db) and after a load. */
    double *raw;
    size_t nraw;
    /* closed curves prepared with params.inner_closing > 0: the outline of the silhouette closed
     * at that radius, from the input points (amscr__outline), AMSCR__OUTLINE_N points; kept in
     * collection files of version 10 and 11. NULL otherwise. */
    double *outline;
};

/* Most input points a descriptor keeps for the polish: a fit on more is not measurably better. */
#define AMSCR__POLISH_MAX_POINTS 4096

/* Builds the derived arrays of a descriptor whose params, n, p, input, base, scaled, fwd,
 * inv are set (used by amscr_descriptor_new and by db load). */
amscr_status amscr__descriptor_finish(amscr_descriptor *d);
/* The normalized and smoothed samples of a descriptor whose params, n, p and input are set
 * (base, scaled, fwd, inv), then its derived arrays: bit for bit what amscr_descriptor_new
 * computed from the same input (a compact record keeps only the input: db_io.c). */
amscr_status amscr__descriptor_rebuild(amscr_descriptor *d);
/* Allocates an empty descriptor for n samples and p scales (arrays uninitialized). */
amscr_status amscr__descriptor_alloc(size_t n, size_t p, amscr_descriptor **out);
/* Non-zero when two params describe compatible prepared shapes (N, scales, closed,
 * parametrization, invariance); fills a detail otherwise. */
int amscr__params_compatible(const amscr_params *a, const amscr_params *b, const char *what);

/* ---- matching (register.c; the engine's own internals are in match.h) ---- */
/* The distance with a caller workspace (batch path; symmetric honoured). p must be
 * compatible with both descriptors (not checked here). */
amscr_status amscr__distance_ws(const amscr_params *p, const amscr_descriptor *src, const amscr_descriptor *tgt,
                                amscr_workspace *ws, double *out);

/* ---- numerical internals ---------------------------------------------- */
/* Exact 1-D K-means by dynamic programming on sorted data.
 * sorted: n ascending values; sse_out[k-1] = optimal SSE with k clusters for k = 1..kmax
 * (kmax <= n). If centers/bounds wanted: centers_out (kmax values for k = kmax clusters),
 * may be NULL. scratch: at least amscr__kmeans1d_scratch(n, kmax) doubles. */
size_t amscr__kmeans1d_scratch(size_t n, size_t kmax);
void amscr__kmeans1d_dp(const double *sorted, size_t n, size_t kmax, double *scratch, double *sse_out,
                        size_t *split_out /* kmax*kmax or NULL */);

/* Elbow choice on sse[0..m-1] for K = k_min..k_min+m-1; returns chosen K. */
size_t amscr__elbow_choose(const double *sse, size_t m, size_t k_min);

/* Re-ranking as amscr_rerank_diffusion with the output halved into [0, 1] (< 0.5: reached by
 * the diffusion) and a zero diagonal (rerank.c); the diffusion's rows on `threads` threads
 * (the result does not depend on their number). */
amscr_status amscr__rerank_normalized(const double *dist, size_t n, size_t k, unsigned iterations, unsigned threads,
                                      double *out_dist);
/* The same on two graphs: the kNN graphs of dist and of dist2 (n x n, symmetric) mixed as
 * (1 - share) P + share P2 before the diffusion; unreached pairs ordered by dist. */
amscr_status amscr__rerank_normalized2(const double *dist, const double *dist2, double share, size_t n, size_t k,
                                       unsigned iterations, unsigned threads, double *out_dist);
/* The same on 1..AMSCR__RERANK_GRAPHS graphs: graph g > 0 takes share[g] of every row's mass,
 * graph 0 the rest (share[0] not read); unreached pairs ordered by dist[0]. */
enum { AMSCR__RERANK_GRAPHS = 4 };
amscr_status amscr__rerank_graphs(const double *const *dist, const double *share, int graphs, size_t n, size_t k,
                                  unsigned iterations, unsigned threads, double *out_dist);
/* The same with the shapes held[i] != 0 held out of the graph: no list holds them but their own,
 * and their own lists are themselves then their nearest among the others (not held out). The
 * others' rows are then the re-ranking of the others alone, and a held-out row's entries of the
 * others are its diffusion as a query into their graph (the other held-out shapes change them
 * only by the row's scale, never their order). */
amscr_status amscr__rerank_held(const double *const *dist, const double *share, int graphs, size_t n, size_t k,
                                unsigned iterations, unsigned threads, const unsigned char *held, double *out_dist);

/* The retrieval settings in the saved collection (format versions 2 and up, retrieval_io.c):
 * little-endian f64 channel_weight, u32 channel_invariance, f64 channel_affine_share,
 * f64 channel_band, f64 channel_skip, f64 channel_locality, u32 rerank_k,
 * u32 rerank_iterations; versions 5 and 6 (0.6) then f64 channel_affine_band (_V2); versions 7
 * and 8 (0.7) then f64 rerank_inner_share (_V3); versions 10 and 11 (0.9) then f64
 * inner_closing (_V4); versions 12 and 13 (0.11) then f64 channel_affine_view (_V5). A shorter
 * block reads with channel_affine_band = channel_band (one band for both frames before 0.6),
 * rerank_inner_share = 0 (one graph before 0.7), inner_closing = 0 (the inner distance on the
 * curve itself before 0.9) and channel_affine_view = 0 (the frames' mix for every pair before
 * 0.11).
 * read validates through the setters' rules (AMSCR_E_FORMAT). */
#define AMSCR__RETRIEVAL_BLOCK 52
#define AMSCR__RETRIEVAL_BLOCK_V2 60
#define AMSCR__RETRIEVAL_BLOCK_V3 68
#define AMSCR__RETRIEVAL_BLOCK_V4 76
#define AMSCR__RETRIEVAL_BLOCK_V5 84
/* size: AMSCR__RETRIEVAL_BLOCK, _V2, _V3, _V4 or _V5. */
void amscr__retrieval_block_write(const amscr_params *p, unsigned char *out, size_t size);
amscr_status amscr__retrieval_block_read(const unsigned char *in, size_t size, amscr_params *p);

/* The re-ranking's neighbours in a collection of n shapes (n >= 1): rerank_k, but at most half
 * the collection and at least 1; 0 without re-ranking. Neighbourhoods that cover the collection
 * carry no context: the diffusion then flattens every score, and a 9-shape folder ranked by
 * noise (0.6; min(rerank_k, n) before, which index files of 0.5 hold). */
static inline size_t amscr__rerank_k(const amscr_params *p, size_t n)
{
    size_t half = n / 2 > 0 ? n / 2 : 1;
    return p->rerank_k < half ? p->rerank_k : half;
}

/* Thread count helper: 0 -> online cores. */
unsigned amscr__resolve_threads(unsigned requested);

/* The mode of a file written to path (file_mode.c): the replaced file's, else 0666 & ~umask. */
unsigned amscr__file_mode(const char *path);
/* strerror, thread-safe: the message of errno value err, in buf (size len) or static (file_io.c). */
const char *amscr__errstr(int err, char *buf, size_t len);
/* fopen(path, "rb") with close-on-exec: a program that starts another one while the library
 * reads (posix_spawn on another thread) does not hand it the file. NULL with errno set. */
FILE *amscr__fopen_read(const char *path);
/* Whole files (file_io.c). buf written to path whole before it takes its name (an unnamed
 * O_TMPFILE file linked in, else a temporary name renamed). */
amscr_status amscr__file_write_atomic(const char *path, const void *buf, size_t len);
/* The whole file at path (caller frees *out). */
amscr_status amscr__file_read(const char *path, unsigned char **out, size_t *out_len);
/* The whole file at path mapped read-only (*mapped = 1; no copy, the page cache's pages), or
 * read as amscr__file_read where it cannot be mapped; release with amscr__file_unmap. */
amscr_status amscr__file_map(const char *path, unsigned char **out, size_t *out_len, int *mapped);
void amscr__file_unmap(unsigned char *buf, size_t len, int mapped);

#endif
