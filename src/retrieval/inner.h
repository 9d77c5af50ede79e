/* inner.h — the inner-distance graph of the re-ranking: one pair (inner.c) and a whole
 * collection (inner_matrix.c). Never installed. */
#ifndef AMSCR_INNER_H
#define AMSCR_INNER_H

#include "fft.h"
#include "internal.h"

/* Vertices of the polygon whose inner distances are taken, the offsets kept (the others
 * repeat them: ID(i, i + N - k) = ID(i - k, i)), and the frequencies kept along the contour
 * (0..N/4: the matrices are compared smoothed along the curve; the full spectrum scores the
 * same, at twice the cost: docs/decisions.md). */
#define AMSCR__INNER_N AMSCR__OUTLINE_N
#define AMSCR__INNER_K (AMSCR__INNER_N / 2)
#define AMSCR__INNER_F (AMSCR__INNER_N / 4 + 1)

/* A shape's inner distances in offset form, column k (offset k + 1) the sequence
 * i -> ID(i, i + k + 1) over the N vertices, scaled by the square root of its share of the
 * whole matrix (2 for offsets below N/2, 1 for N/2): the DFT of every column at the kept
 * frequencies, as re[f][k] + i im[f][k] (columns contiguous: the pair loop runs along k), in
 * units of `scale` (the largest magnitude / AMSCR__INNER_Q, rounded to the nearest: 2.2 KB a
 * shape), and the sum of squares of the columns so low-passed (of the values as stored). The
 * reversed orientation's twist of the columns is computed where a pair needs it (the pair's
 * second shape; a workspace keeps the last one's). */
#define AMSCR__INNER_Q 32767.0
typedef struct {
    int16_t re[AMSCR__INNER_F][AMSCR__INNER_K], im[AMSCR__INNER_F][AMSCR__INNER_K];
    double scale;
    double norm2;
} amscr__inner;

/* Per-thread scratch of the features and the pair distance. */
typedef struct {
    amscr__fft_plan plan;
    double z[2 * AMSCR__INNER_N];
    double cs[2 * AMSCR__INNER_N]; /* e^{-2 pi i m / N}, m = 0..N-1 */
    double xy[2 * AMSCR__INNER_N];
    double id[AMSCR__INNER_N * AMSCR__INNER_N];
    double fz[2][AMSCR__INNER_F][AMSCR__INNER_K]; /* a shape's values before their rounding */
    int16_t tw_of[2][AMSCR__INNER_F][AMSCR__INNER_K]; /* the shape whose twist tw holds (have_tw) */
    double tw[2][AMSCR__INNER_F][AMSCR__INNER_K];
    int have_tw;
} amscr__inner_ws;

amscr_status amscr__inner_ws_init(amscr__inner_ws *ws);
void amscr__inner_ws_free(amscr__inner_ws *ws);
/* A workspace on the heap (*out: the threads' scratch of rows.c) and its release (NULL: none). */
amscr_status amscr__inner_ws_new(void **out);
void amscr__inner_ws_delete(void *ws);
/* The features of the closed curve of n points xy, resampled to N vertices. */
amscr_status amscr__inner_build(const double *xy, size_t n, amscr__inner *out, amscr__inner_ws *ws);
/* The N vertices (2N doubles) whose inner distances are a prepared shape's features under a
 * closing c (amscr_params_set_inner_closing): c = 0, its input samples resampled (as before
 * 0.9); c > 0, its outline (d->outline) when d was prepared with c, else the outline of its input
 * samples closed (amscr__outline; the samples themselves when they bound no area). */
amscr_status amscr__inner_vertices(const amscr_descriptor *d, double closing, double *V);
/* The features of the prepared shape d under the closing c (amscr__inner_vertices). */
amscr_status amscr__inner_build_shape(const amscr_descriptor *d, double closing, amscr__inner *out,
                                      amscr__inner_ws *ws);
/* The distance of two shapes: the RMS difference of their inner-distance matrices (each
 * divided by its mean) at the best cyclic shift, and orientation when `reflections`; 0 for
 * a shape against itself, symmetric. */
double amscr__inner_distance(const amscr__inner *a, const amscr__inner *b, int reflections, amscr__inner_ws *ws);
/* f's values re, im and scale from the values v (F K real parts, then F K imaginary) as computed
 * (a file before version 16: its float32 or double values), its norm2 from the rounded values;
 * 0 when a value is not finite. */
int amscr__inner_quantize(amscr__inner *f, const double *v);

/* ------------------------------------------------ over a collection (inner_matrix.c) */

/* The features of shapes first..n-1 of db into f[first..n-1], on `threads` threads; progress
 * (may be NULL) in shapes. */
amscr_status amscr__inner_features(const amscr_db *db, size_t first, unsigned threads, amscr__inner *f,
                                   amscr_progress_fn progress, void *user);
/* The symmetric n x n matrix of the inner distances of features f (zero diagonal; cell (i, j),
 * i < j, is amscr__inner_distance(f + i, f + j)), on `threads` threads. */
amscr_status amscr__inner_matrix_from(const amscr__inner *f, size_t n, int reflections, unsigned threads,
                                      amscr_progress_fn progress, void *user, double *out);
/* The symmetric n x n matrix of the collection's inner distances (zero diagonal), on
 * `threads` threads; independent of the thread count. */
amscr_status amscr__inner_matrix(const amscr_db *db, unsigned threads, amscr_progress_fn progress, void *user,
                                 double *out);

#endif
