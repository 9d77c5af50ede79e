/* signature.h — the shortlist signature of a prepared shape (signature.c): the affine
 * signature (affine_signature.h) as floats, frequency-major, with a short lower-bound vector,
 * so an index finds the M shapes whose signatures are nearest a query's without computing
 * every full distance. Never installed. */
#ifndef AMSCR_SIGNATURE_H
#define AMSCR_SIGNATURE_H

#include "affine_signature.h"
#include "internal.h"

/* Floats of a signature (stored in the index file as sig_dim). */
#define AMSCR__SIG_DIM AMSCR__AFFINE_SIG_DIM
/* Frequencies of the lower-bound vector (the first ones: most of the energy; 8 prunes most full
 * distances of a search, measured in docs/measurements.md). */
#define AMSCR__SIG_LB_FREQS 8
/* Floats of the lower-bound vector: frames x bins x AMSCR__SIG_LB_FREQS. */
#define AMSCR__SIG_LB_DIM (2 * AMSCR__SIG_BINS * AMSCR__SIG_LB_FREQS)

/* The signature of d into out[AMSCR__SIG_DIM]: amscr__affine_signature's values, reordered by
 * frequency, then frame, orientation and bin. */
void amscr__shape_signature(const amscr_descriptor *d, float *out);
/* A signature held in 16 bits (an index's rows, 2 KB a shape rather than 4): value t is
 * q[t] * 2^e, e the row's exponent (its largest value takes 16 bits), the values rounded to the
 * nearest. Exact in float both ways: the dequantized row quantizes back to the same q and e (an
 * index file keeps the dequantized floats). The values are >= 0 (magnitudes). */
void amscr__sig_quantize(const float *sig, uint16_t *q, int32_t *e);
void amscr__sig_dequantize(const uint16_t *q, int32_t e, float *out);

/* Rows of signatures: n x AMSCR__SIG_DIM floats f, or (f NULL) quantized rows q with their
 * exponents e; a search reads a quantized row as its dequantized floats (the same distances). */
typedef struct {
    const float *f;
    const uint16_t *q;
    const int32_t *e;
} amscr__sig_rows;
/* The lower-bound vector of a signature into lb[AMSCR__SIG_LB_DIM]. */
void amscr__sig_bound_vector(const float *sig, float *lb);
/* A lower bound of the signature distance (amscr__affine_signature_distance of two signatures,
 * in float: the search's) from the two lower-bound vectors. */
double amscr__sig_bound(const float *la, const float *lb);

/* The m signatures nearest sig (lower-bound vector lb) among the n of sigs / lbs (rows of
 * AMSCR__SIG_DIM values and AMSCR__SIG_LB_DIM floats), by (distance, index), leaving out `exclude`
 * (or SIZE_MAX), into cand in ascending index order; exactly those of the full distances.
 * Returns m, 0 when out of memory. */
size_t amscr__sig_nearest(const amscr__sig_rows *sigs, const float *lbs, size_t n, const float *sig, const float *lb,
                          size_t m, size_t exclude, size_t *cand);

/* A coarse quantizer of the lower-bound vectors (a large build's shortlists, and a large
 * index's queries: index.c): ceil(sqrt(n)) K-means lists, each holding its shapes in ascending
 * order. */
typedef struct {
    size_t nc;     /* lists (0: no quantizer) */
    size_t n;      /* shapes */
    float *cent;   /* nc x AMSCR__SIG_LB_DIM centroids */
    uint32_t *cell; /* n: each shape's list */
    size_t *start; /* nc + 1 offsets into ids */
    size_t *ids;   /* the n shapes, list by list */
} amscr__sig_ivf;

amscr_status amscr__sig_ivf_build(const float *lbs, size_t n, amscr__sig_ivf *v);
void amscr__sig_ivf_free(amscr__sig_ivf *v);
/* v's lists (start, ids) from its cells (v->n shapes, each < v->nc); 0 when out of memory. */
int amscr__sig_ivf_lists(amscr__sig_ivf *v);
/* Shapes v->n..n-1 (lower-bound vectors lbs) into the lists of their nearest centroids (the
 * centroids unchanged). */
amscr_status amscr__sig_ivf_add(amscr__sig_ivf *v, const float *lbs, size_t n);
/* amscr__sig_nearest among the shapes of the lists nearest lb (at least 8 lists and 16 m + 1
 * shapes): the m nearest of those, not necessarily the m nearest of all. */
size_t amscr__sig_ivf_nearest(const amscr__sig_ivf *v, const amscr__sig_rows *sigs, const float *lbs, size_t n,
                              const float *sig, const float *lb, size_t m, size_t exclude, size_t *cand);

#endif
