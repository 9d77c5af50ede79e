/* internal.h — shared internals of libamscr (never installed). */
#ifndef AMSCR_INTERNAL_H
#define AMSCR_INTERNAL_H

#include "amscr.h"

#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define AMSCR_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define AMSCR_PRINTF(a, b)
#endif

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

/* ---- small helpers -------------------------------------------------- */
/* Overflow-checked malloc of n*size bytes (NULL on overflow or failure; n == 0 gives a
 * valid 1-byte block). */
void *amscr__malloc_array(size_t n, size_t size);
void *amscr__calloc_array(size_t n, size_t size);
int amscr__all_finite(const double *v, size_t n);

/* ---- objects ---------------------------------------------------------- */
struct amscr_contour {
    size_t n;
    double *xy; /* 2n */
};

/* Makes a contour that takes ownership of xy (2n doubles from malloc). */
amscr_status amscr__contour_wrap(double *xy, size_t n, amscr_contour **out);

#define AMSCR__MAX_SCALES 64

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
};

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

/* Thread count helper: 0 -> online cores. */
unsigned amscr__resolve_threads(unsigned requested);

#endif
