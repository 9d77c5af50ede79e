/*
 * amscr.h — Affine Multi-Scale Curve Registration: the one public header.
 *
 * SPDX-License-Identifier: MIT
 */
#ifndef AMSCR_H
#define AMSCR_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/*
 * ============================================================================
 * Conventions (read once; every declaration below follows them)
 * ============================================================================
 *
 * Points.      A point set is a `double` array with x and y interleaved
 *              (x0, y0, x1, y1, ...) and a count `n` of POINTS (not 2n doubles).
 * Contours.    Closed implicitly: no repeated end point. Traced contours are
 *              counter-clockwise in a y-up frame (mathematical orientation:
 *              positive signed area). For image coordinates (y pointing down)
 *              this is clockwise on screen.
 * Matrices.    Row-major, always (LAPACK and most C vision libraries are
 *              column-major: we are not).
 * Affine maps. `double m[6] = {a11, a12, tx, a21, a22, ty}`: p' = A p + t.
 * Sizes.       Counts and indices are `size_t`, labels `int32_t`, seeds `uint64_t`.
 * Arguments.   Handle first, then inputs, then outputs. A buffer is a
 *              (pointer, count) pair; out-parameters come last and start with
 *              `out_`. Outputs are written only when AMSCR_OK is returned.
 * Errors.      Every fallible function returns `amscr_status`. On failure
 *              amscr_last_error_detail() says what went wrong, for the
 *              calling thread. The library never prints and never aborts.
 * Ownership.   Functions whose names contain _new, _copy, _read, _parse or
 *              _load, and amscr_register, amscr_register_contours,
 *              amscr_contour_from_mask and amscr_db_save_memory, hand the
 *              caller something to free: an object with its own
 *              amscr_<obj>_free() (each accepts NULL), or for
 *              amscr_db_save_memory a buffer for amscr_free(). Every other pointer
 *              returned is borrowed: valid until its owner is freed or
 *              modified.
 *
 * Thread-safety (three laws):
 *   1. Every function is reentrant; the library has no global mutable state
 *      (the only global is the thread-local error detail).
 *   2. A non-const object is used by one thread at a time.
 *   3. Objects passed as `const` (amscr_params, amscr_descriptor, a finished
 *      amscr_db, fitted amscr_kmeans/amscr_gmm1d, amscr_result) may be shared
 *      by any number of threads. Adding to a db while another thread queries
 *      it is not allowed. Python's cffi releases the GIL during calls, so
 *      Python threads do call in concurrently: this contract is tested.
 */

/* ---------------------------------------------------------------- macros */
#if defined(_WIN32) && !defined(AMSCR_STATIC)
#  if defined(AMSCR_BUILDING)
#    define AMSCR_API __declspec(dllexport)
#  else
#    define AMSCR_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#  define AMSCR_API __attribute__((visibility("default")))
#else
#  define AMSCR_API
#endif

#if defined(__GNUC__) && (__GNUC__ > 3 || (__GNUC__ == 3 && __GNUC_MINOR__ >= 4))
#  define AMSCR_NODISCARD __attribute__((warn_unused_result))
#else
#  define AMSCR_NODISCARD
#endif

#define AMSCR_VERSION_MAJOR 0
#define AMSCR_VERSION_MINOR 3
#define AMSCR_VERSION_PATCH 2
#define AMSCR_VERSION_NUMBER \
    (AMSCR_VERSION_MAJOR * 10000 + AMSCR_VERSION_MINOR * 100 + AMSCR_VERSION_PATCH)

/* ------------------------------------------------------- limits (0.1) */
/** Largest image side accepted by amscr_contour_from_mask (pixels). */
#define AMSCR_MAX_IMAGE_SIDE 32768
/** Largest number of pixels accepted by amscr_contour_from_mask. */
#define AMSCR_MAX_IMAGE_PIXELS 268435456u /* 2^28 */
/** Largest number of points in a contour. */
#define AMSCR_MAX_POINTS 16777216u /* 2^24 */
/** Largest number of samples N per scale. */
#define AMSCR_MAX_SAMPLES 65536u
/** Largest number of scales. */
#define AMSCR_MAX_SCALES 64u
/** Automatic threshold (Otsu) for amscr_contour_from_mask. */
#define AMSCR_THRESHOLD_AUTO (-1)

/* ---------------------------------------------------------- status codes */
/** Status codes. The values are pinned forever: never renumbered, never reused. */
typedef enum amscr_status {
    AMSCR_OK = 0,                /**< success */
    AMSCR_E_INVALID_ARG = 1,     /**< NULL pointer, out-of-range value, bad option */
    AMSCR_E_NOMEM = 2,           /**< allocation failed */
    AMSCR_E_IO = 3,              /**< a file could not be opened, read or written */
    AMSCR_E_FORMAT = 4,          /**< malformed or unsupported file content */
    AMSCR_E_UNSUPPORTED = 5,     /**< feature not compiled in */
    AMSCR_E_DEGENERATE = 6,      /**< too few points, zero area, collinear, singular */
    AMSCR_E_NUMERIC = 7,         /**< rank-deficient system, LAPACK failure, non-finite result */
    AMSCR_E_NOT_CONVERGED = 8,   /**< an iteration cap was reached without convergence */
    AMSCR_E_NOT_FOUND = 9,       /**< nothing found: empty mask, no Bayes crossing */
    AMSCR_E_STATE = 10,          /**< object used in the wrong state (e.g. not fitted) */
    AMSCR_E_INTERNAL = 11,       /**< a bug: please report */
    AMSCR_E_CANCELLED = 12,      /**< a progress callback asked to stop */
    AMSCR_E_LIMIT = 13           /**< input exceeds a documented size limit */
} amscr_status;

/** Optional features. */
typedef enum amscr_feature {
    AMSCR_FEATURE_THREADS = 1    /**< batch calls can use POSIX threads */
} amscr_feature;

/* ------------------------------------------------------------ opaque types */
typedef struct amscr_params amscr_params;
typedef struct amscr_contour amscr_contour;
typedef struct amscr_descriptor amscr_descriptor;
typedef struct amscr_result amscr_result;
typedef struct amscr_workspace amscr_workspace;
typedef struct amscr_db amscr_db;
typedef struct amscr_kmeans amscr_kmeans;
typedef struct amscr_gmm1d amscr_gmm1d;

/**
 * @brief Progress callback for long batch calls.
 * @param user  the pointer given with the callback.
 * @param done  work items finished so far.
 * @param total work items in the call.
 * @return 0 to continue, non-zero to cancel (the call then returns AMSCR_E_CANCELLED).
 * Thread-safety: called from the thread that made the batch call, never concurrently.
 */
typedef int (*amscr_progress_fn)(void *user, size_t done, size_t total);

/* ======================================================================
 * Library information and errors
 * ====================================================================== */

/** @brief Runtime version as M*10000 + m*100 + p.
 *  Thread-safety: safe. @since 0.1 */
AMSCR_API int amscr_version_number(void);

/** @brief Runtime version as a static string "M.m.p". Never NULL.
 *  Ownership: static. Thread-safety: safe. @since 0.1 */
AMSCR_API const char *amscr_version_string(void);

/** @brief Non-zero when `feature` was compiled in. Thread-safety: safe. @since 0.1 */
AMSCR_API int amscr_has_feature(amscr_feature feature);

/** @brief Static, never-NULL English description of a status code (unknown codes too).
 *  Ownership: static. Thread-safety: safe. @since 0.1 */
AMSCR_API const char *amscr_strerror(amscr_status status);

/** @brief Detail of the calling thread's last failure, e.g. "shape.txt:17: expected 2 numbers".
 *  Empty string when there is none. Never NULL.
 *  Ownership: thread-local buffer, valid until the next amscr call on this thread.
 *  Thread-safety: per thread. @since 0.1 */
AMSCR_API const char *amscr_last_error_detail(void);

/** @brief Releases a raw buffer allocated by the library. Accepts NULL.
 *  Thread-safety: safe. @since 0.1 */
AMSCR_API void amscr_free(void *ptr);

/* ======================================================================
 * Contours
 * ====================================================================== */

/**
 * @brief Makes a contour by copying `n` interleaved points.
 * @param[in]  xy   2n doubles (may contain anything; validation happens when used).
 * @param[in]  n    number of points, 1..AMSCR_MAX_POINTS.
 * @param[out] out  new contour.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_LIMIT, AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free. Thread-safety: reentrant. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_new(const double *xy, size_t n, amscr_contour **out);

/** @brief Releases a contour; accepts NULL. @since 0.1 */
AMSCR_API void amscr_contour_free(amscr_contour *c);

/** @brief Number of points (0 for NULL). Thread-safety: const. @since 0.1 */
AMSCR_API size_t amscr_contour_size(const amscr_contour *c);

/** @brief Borrowed pointer to the 2n interleaved coordinates (NULL for NULL).
 *  Ownership: borrowed from c. @since 0.1 */
AMSCR_API const double *amscr_contour_xy(const amscr_contour *c);

/**
 * @brief Checks that a contour can be registered: finite coordinates, at least 8
 *        distinct points after dropping repeated consecutive points, and (closed)
 *        non-zero area / (open) not all collinear.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (NULL, non-finite), AMSCR_E_DEGENERATE.
 * Thread-safety: const. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_validate(const amscr_contour *c, int closed);

/** @brief Signed area of the closed polygon (positive = counter-clockwise, y up).
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_signed_area(const amscr_contour *c, double *out_area);

/** @brief Reverses the point order in place when the signed area is negative.
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG. Thread-safety: modifies c. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_orient_ccw(amscr_contour *c);

/**
 * @brief Reads a text point list: one "x y" or "x,y" per line (tabs/spaces/one comma),
 *        '#' starts a comment, blank lines ignored.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_IO (cannot open/read),
 *         AMSCR_E_FORMAT (bad line; the detail names "path:line"), AMSCR_E_LIMIT, AMSCR_E_NOMEM.
 *         An empty list is AMSCR_E_FORMAT.
 * Ownership: caller frees *out. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_read_text(const char *path, amscr_contour **out);

/** @brief The same as amscr_contour_read_text from a memory buffer of `len` bytes
 *         (need not be NUL-terminated). Error details name "line N".
 *  Ownership: caller frees *out. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_parse_text(const char *text, size_t len, amscr_contour **out);

/** @brief Writes a contour as a text point list ("%.17g %.17g" per line). The file is
 *         written to a temporary name in the same folder and renamed, so a failure
 *         never leaves a partial file.
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_IO. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_write_text(const amscr_contour *c, const char *path);

/**
 * @brief Traces the outer boundary of the largest 8-connected foreground component
 *        of an 8-bit image.
 *
 * A pixel is "on" when its value is > threshold (threshold 0..254, or
 * AMSCR_THRESHOLD_AUTO for Otsu's threshold). Polarity is automatic: if most of
 * the image border is "on", on/off are swapped, so the border is background.
 * Holes are ignored; specks and smaller components are dropped; shapes touching
 * the border are handled (the image is treated as padded with background).
 * The result is the sequence of boundary pixel centres (x = column, y = row),
 * with positive signed area as computed by amscr_contour_signed_area on these
 * (x, y) values (counter-clockwise in a y-up frame), no repeated point.
 *
 * @param[in] pixels  width*height bytes, rows `stride` bytes apart.
 * @param[in] width, height  1..AMSCR_MAX_IMAGE_SIDE, width*height <= AMSCR_MAX_IMAGE_PIXELS.
 * @param[in] stride  >= width.
 * @param[in] threshold  0..254 or AMSCR_THRESHOLD_AUTO.
 * @param[out] out  new contour.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_LIMIT, AMSCR_E_NOT_FOUND (no foreground,
 *         or foreground everywhere), AMSCR_E_DEGENERATE (component too small to trace: < 3
 *         boundary points), AMSCR_E_NOMEM.
 * Ownership: caller frees *out. Thread-safety: reentrant. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_from_mask(const uint8_t *pixels, size_t width,
                                                               size_t height, size_t stride, int threshold,
                                                               amscr_contour **out);

/* ======================================================================
 * Smoothing, resampling, normalization (stateless; caller allocates outputs)
 * ====================================================================== */

/**
 * @brief FIR Gaussian taps: radius r = ceil(4*sigma), 2r+1 taps, normalized to sum 1.
 * @param[in]     sigma  > 0, finite, <= 1e6.
 * @param[out]    taps   room for *inout_ntaps doubles, or NULL to query the count.
 * @param[in,out] inout_ntaps  capacity in, count out.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (also when the capacity is too small). @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gaussian_kernel(double sigma, double *taps, size_t *inout_ntaps);

/**
 * @brief Gaussian smoothing of a polyline, x and y separately: circular for closed
 *        curves (exact even when the kernel is longer than the curve: the curve is
 *        wrapped as often as needed), mirrored at the ends (half-sample symmetric,
 *        "reflect") for open curves. sigma == 0 copies.
 * @param[in]  xy, n  input points (n >= 1).
 * @param[out] out_xy 2n doubles; must not overlap xy.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_smooth_gaussian(const double *xy, size_t n, int closed, double sigma,
                                                             double *out_xy);

/**
 * @brief m points equally spaced in Euclidean arc length along the polygon
 *        (linear interpolation; periodic when closed; the first output is the first
 *        input point; for open curves the last output is the last input point).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_DEGENERATE (zero length), AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_resample_euclidean(const double *xy, size_t n, int closed, size_t m,
                                                                double *out_xy);

/**
 * @brief Cumulative affine arc length (paper eq. 2) at each vertex of a uniformly
 *        sampled curve: the curve is smoothed with a Gaussian of `sigma0` samples
 *        (0 = none), derivatives are central differences (periodic when closed,
 *        one-sided at open ends), speed v = |x'y'' - x''y'|^(1/3), trapezoid sums.
 *        out_cumulative[0] = 0; out_total is the whole length (closed: including the
 *        closing segment). Not normalized.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (n < 5, non-finite), AMSCR_E_DEGENERATE (total
 *         numerically zero: a straight curve), AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_arclength(const double *xy, size_t n, int closed, double sigma0,
                                                              double *out_cumulative, double *out_total);

/**
 * @brief m points equally spaced in affine arc length. The polygon is first
 *        resampled uniformly (Euclidean) to max(8m, n) points, then `passes`
 *        (>= 1) affine arc-length passes are made, each pass taking derivatives
 *        over the previous pass's parameter (DESIGN.md §2.3); sigma0 is the
 *        pre-smoothing as a FRACTION of the curve length (e.g. 0.02).
 * @return as amscr_affine_arclength, plus AMSCR_E_INVALID_ARG for m < 4. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_resample_affine(const double *xy, size_t n, int closed, double sigma0,
                                                             unsigned passes, size_t m, double *out_xy);

/**
 * @brief Whitening normalization: moves the centroid of the points to the origin and
 *        multiplies by Sigma^(-1/2) (Sigma the 2x2 covariance, 1/n), so the output has
 *        identity covariance. n == 0 is AMSCR_E_INVALID_ARG, 1 or 2 points AMSCR_E_DEGENERATE.
 * @param[out] out_xy       2n doubles (may be NULL).
 * @param[out] out_forward  affine map input -> normalized (may be NULL).
 * @param[out] out_inverse  affine map normalized -> input (may be NULL).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_DEGENERATE (collinear / singular covariance). @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_normalize_whiten(const double *xy, size_t n, double *out_xy,
                                                              double out_forward[6], double out_inverse[6]);

/* ======================================================================
 * Least squares and affine utilities
 * ====================================================================== */

/**
 * @brief Least squares min ||a x - b|| by Householder QR (LAPACKE), several right-hand
 *        sides in one call.
 * @param[in]  a     m x n, row-major, m >= n >= 1.
 * @param[in]  b     m x nrhs, row-major.
 * @param[out] out_x n x nrhs, row-major.
 * @param[out] out_residual_norms nrhs residual 2-norms (may be NULL).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NUMERIC (rank-deficient or ill-conditioned:
 *         reciprocal condition estimate of R below 1e-12; the detail gives it), AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_lstsq_qr(const double *a, size_t m, size_t n, const double *b,
                                                      size_t nrhs, double *out_x, double *out_residual_norms);

/** @brief Least-squares affine map taking src[i] to dst[i] (n >= 3, not collinear).
 *  @param[out] out_rms RMS residual distance (may be NULL).
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NUMERIC (collinear src), AMSCR_E_NOMEM. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_fit(const double *src_xy, const double *dst_xy, size_t n,
                                                        double out_m6[6], double *out_rms);

/** @brief Applies an affine map to n points; out_xy may equal xy (in place).
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_apply(const double m6[6], const double *xy, size_t n,
                                                          double *out_xy);

/** @brief Inverts an affine map. @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_DEGENERATE (singular). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_invert(const double m6[6], double out_m6[6]);

/* ======================================================================
 * K-means (deterministic) and elbow
 * ====================================================================== */

/** @brief A K-means object for k >= 1 clusters. Defaults: seed 0, 100 iterations, 1e-10
 *         tolerance, 4 restarts. @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM.
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_new(size_t k, amscr_kmeans **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_kmeans_free(amscr_kmeans *km);
/** @brief Seed of the k-means++ start (dim > 1). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_seed(amscr_kmeans *km, uint64_t seed);
/** @brief Lloyd iteration cap, >= 1. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_max_iterations(amscr_kmeans *km, unsigned n);
/** @brief Relative SSE change that counts as converged, >= 0. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_tolerance(amscr_kmeans *km, double tol);
/** @brief Seeded restarts (dim > 1), >= 1; the best SSE is kept. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_restarts(amscr_kmeans *km, unsigned r);
/** @brief Getters mirroring the setters (NULL-safe: return 0). @since 0.1 */
AMSCR_API uint64_t amscr_kmeans_get_seed(const amscr_kmeans *km);
AMSCR_API unsigned amscr_kmeans_get_max_iterations(const amscr_kmeans *km);
AMSCR_API double amscr_kmeans_get_tolerance(const amscr_kmeans *km);
AMSCR_API unsigned amscr_kmeans_get_restarts(const amscr_kmeans *km);
AMSCR_API size_t amscr_kmeans_num_clusters(const amscr_kmeans *km);
/** @brief Dimension of the last fit (0 before a fit). @since 0.1 */
AMSCR_API size_t amscr_kmeans_dim(const amscr_kmeans *km);

/**
 * @brief Clusters n x dim row-major data (n >= k). For dim == 1 the result is the exact
 *        optimum (dynamic programming over sorted data), otherwise Lloyd iterations from a
 *        seeded k-means++ start with restarts. Deterministic for a given seed.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (NULL, n < k, dim 0, non-finite), AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_fit(amscr_kmeans *km, const double *data, size_t n, size_t dim);
/** @brief Borrowed k x dim centres of the last fit (sorted ascending when dim == 1), NULL before. @since 0.1 */
AMSCR_API const double *amscr_kmeans_centers(const amscr_kmeans *km);
/** @brief Within-cluster sum of squares (SSE) of the last fit; NaN before a fit. @since 0.1 */
AMSCR_API double amscr_kmeans_inertia(const amscr_kmeans *km);
/** @brief Nearest-centre labels (and squared distances, may be NULL) for n points of the fitted dim.
 *  Thread-safety: const. @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_STATE (not fitted). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_assign(const amscr_kmeans *km, const double *data, size_t n,
                                                           size_t *out_labels, double *out_sq_dist);

/**
 * @brief SSE for every k in [k_min, k_max] (out_inertia has k_max - k_min + 1 entries) and
 *        the elbow: with k and SSE both scaled to [0, 1], the k farthest below the chord
 *        from k_min to k_max; k_min when SSE(k_min) is negligible or there is no bend.
 *        1 <= k_min <= k_max <= n.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_elbow(const double *data, size_t n, size_t dim, size_t k_min,
                                                          size_t k_max, uint64_t seed, double *out_inertia,
                                                          size_t *out_k_best);

/* ======================================================================
 * 1-D Gaussian mixture (EM) and the Bayes threshold
 * ====================================================================== */

/** @brief A 1-D GMM with k >= 1 components. Defaults: 200 iterations, tolerance 1e-10
 *         (relative log-likelihood gain), variance floor 1e-6 (relative to the data
 *         variance; absolute floor 1e-300). Initialized from exact 1-D K-means.
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_new(size_t k, amscr_gmm1d **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_gmm1d_free(amscr_gmm1d *g);
/** @brief EM iteration cap, >= 1. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_max_iterations(amscr_gmm1d *g, unsigned n);
/** @brief Convergence tolerance on the relative log-likelihood gain, >= 0. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_tolerance(amscr_gmm1d *g, double tol);
/** @brief Variance floor relative to the data variance, in [0, 1]. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_variance_floor(amscr_gmm1d *g, double v);
AMSCR_API unsigned amscr_gmm1d_get_max_iterations(const amscr_gmm1d *g);
AMSCR_API double amscr_gmm1d_get_tolerance(const amscr_gmm1d *g);
AMSCR_API double amscr_gmm1d_get_variance_floor(const amscr_gmm1d *g);
AMSCR_API size_t amscr_gmm1d_num_components(const amscr_gmm1d *g);

/** @brief Fits by EM (n >= k finite values).
 *  @return AMSCR_OK (also when the cap is reached: see amscr_gmm1d_converged),
 *          AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_fit(amscr_gmm1d *g, const double *x, size_t n);
/** @brief Borrowed arrays of k values, components sorted by mean; NULL before a fit. @since 0.1 */
AMSCR_API const double *amscr_gmm1d_weights(const amscr_gmm1d *g);
AMSCR_API const double *amscr_gmm1d_means(const amscr_gmm1d *g);
AMSCR_API const double *amscr_gmm1d_variances(const amscr_gmm1d *g);
/** @brief Log-likelihood of the last fit (NaN before). @since 0.1 */
AMSCR_API double amscr_gmm1d_loglik(const amscr_gmm1d *g);
/** @brief EM iterations used by the last fit. @since 0.1 */
AMSCR_API unsigned amscr_gmm1d_iterations(const amscr_gmm1d *g);
/** @brief Non-zero when the last fit converged within the cap. @since 0.1 */
AMSCR_API int amscr_gmm1d_converged(const amscr_gmm1d *g);
/** @brief Responsibilities (k values) of the components at x. Thread-safety: const.
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_STATE. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_posterior(const amscr_gmm1d *g, double x, double *out_post);
/** @brief Bayes threshold between components i and j of a fitted mixture (see
 *         amscr_bayes_threshold). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_bayes_threshold(const amscr_gmm1d *g, size_t i, size_t j,
                                                                   double *out_threshold);
/**
 * @brief The point s between mu1 and mu2 where w1*N(s; mu1, var1) = w2*N(s; mu2, var2)
 *        (the root of a quadratic, or of a line when var1 == var2).
 * @return AMSCR_OK; AMSCR_E_NOT_FOUND when no root lies strictly between the means (then
 *         *out_threshold is still set to the midpoint (mu1+mu2)/2, as DESIGN.md §3.4d
 *         prescribes); AMSCR_E_INVALID_ARG (weights <= 0, variances <= 0, non-finite).
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_bayes_threshold(double w1, double mu1, double var1, double w2,
                                                             double mu2, double var2, double *out_threshold);

/* ======================================================================
 * Registration parameters
 * ====================================================================== */

/** Registration methods (the paper's table rows). */
typedef enum amscr_method {
    AMSCR_METHOD_ACMA = 0,          /**< one scale (the finest), no selection */
    AMSCR_METHOD_AMSCR = 1,         /**< all scales stacked, no selection */
    AMSCR_METHOD_BINARY_EM = 2,     /**< selection with a 2-component mixture */
    AMSCR_METHOD_MULTICLASS_EM = 3  /**< K by K-means + elbow, K-component mixture (default) */
} amscr_method;

/** Parametrizations of a curve before sampling N points. */
typedef enum amscr_parametrization {
    AMSCR_PARAM_AFFINE = 0,     /**< affine arc length (paper eq. 2), iterated */
    AMSCR_PARAM_EUCLIDEAN = 1,  /**< Euclidean arc length (not affine-invariant) */
    AMSCR_PARAM_WHITENED = 2    /**< Euclidean arc length after whitening by region moments */
} amscr_parametrization;

/** Invariance group of the distance. */
typedef enum amscr_invariance {
    AMSCR_INVARIANCE_AFFINE = 0,      /**< full affine (the paper) */
    AMSCR_INVARIANCE_SIMILARITY = 1,  /**< rotation + uniform scale + translation */
    AMSCR_INVARIANCE_PENALIZED = 2    /**< affine fit + penalty on A's distance from a similarity */
} amscr_invariance;

/** @brief A params object with documented defaults (see each setter).
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new(amscr_params **out);
/** @brief A params object tuned for registering single pairs rather than building collections:
 *         the defaults with N = 256 samples, 20 refinement iterations (trimmed closest-point
 *         refinement in the aligned frame) and the polish on the input points (0.3). Measured in
 *         the README: on Kimia pixel contours under random affine maps it keeps 100 % / 99.8 % /
 *         100 % of pairs within 2 % of the shape size (clean / 1 % noise / 5 % occlusion; 0.1:
 *         100 / 98.6 / 97.6 %), against 99.2 % / 81 % / 66 % for the collection defaults; about
 *         1.8 ms per registration of two 760-point contours (0.1: about 1 ms on smaller ones).
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new_registration(amscr_params **out);
/** @brief Deep copy. Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_copy(const amscr_params *p, amscr_params **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_params_free(amscr_params *p);

/* Every setter validates and returns AMSCR_OK or AMSCR_E_INVALID_ARG (with a detail);
 * every getter returns the value (0 / NULL-safe on a NULL params). @since 0.1 */

/** N, samples per scale: 16..AMSCR_MAX_SAMPLES (default 128). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_num_samples(amscr_params *p, size_t n);
AMSCR_API size_t amscr_params_get_num_samples(const amscr_params *p);
/** Scale list sigma_k in samples of the N-point curve: 1..AMSCR_MAX_SCALES values,
 *  each finite, >= 0 (0 = unsmoothed) and <= N; stored as given. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_scales(amscr_params *p, const double *sigmas, size_t n);
/** Copies the scales into out_sigmas (capacity *inout_n); NULL out_sigmas queries the count. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_get_scales(const amscr_params *p, double *out_sigmas,
                                                               size_t *inout_n);
/** Method (default AMSCR_METHOD_MULTICLASS_EM). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_method(amscr_params *p, amscr_method m);
AMSCR_API amscr_method amscr_params_get_method(const amscr_params *p);
/** Closed (1, default) or open (0) curves. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_closed(amscr_params *p, int closed);
AMSCR_API int amscr_params_get_closed(const amscr_params *p);
/** Also try the reversed target (mirror matches); default 0. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_reflections(amscr_params *p, int on);
AMSCR_API int amscr_params_get_reflections(const amscr_params *p);
/** Parametrization (default AMSCR_PARAM_WHITENED: chosen by measurement, see the README;
 *  AMSCR_PARAM_AFFINE is the paper's affine arc length). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_parametrization(amscr_params *p, amscr_parametrization v);
AMSCR_API amscr_parametrization amscr_params_get_parametrization(const amscr_params *p);
/** Pre-smoothing sigma0 of the parametrization (the parameter is measured on a copy smoothed
 *  over the sample index, a linear hence affine-covariant filter), as a fraction of the curve
 *  length, 0..0.25
 *  (default 0.01). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_presmooth(amscr_params *p, double fraction);
AMSCR_API double amscr_params_get_presmooth(const amscr_params *p);
/** Parametrization passes, 1..10 (default 3): each pass measures the parameter over the
 *  previous pass's parameter (DESIGN.md §2.3). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_arclength_passes(amscr_params *p, unsigned passes);
AMSCR_API unsigned amscr_params_get_arclength_passes(const amscr_params *p);
/** Dense resampling factor: the curve is first resampled to factor*N points, 1..64 (default 8). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_oversampling(amscr_params *p, unsigned factor);
AMSCR_API unsigned amscr_params_get_oversampling(const amscr_params *p);
/** Kmax of the elbow, 1..16 (default 5; clamped to the number of scales at use). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_kmax(amscr_params *p, unsigned kmax);
AMSCR_API unsigned amscr_params_get_kmax(const amscr_params *p);
/** Symmetric distance (average of both directions); default 0. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_symmetric(amscr_params *p, int on);
AMSCR_API int amscr_params_get_symmetric(const amscr_params *p);
/** Refinement iterations in the aligned frame (DESIGN.md §3.8), 0..50 (default 0 = the paper's
 *  method, fastest for collections). Each iteration pairs every source sample with the closest
 *  point of the target polygon, trims the worst 10 % of pairs and re-solves (trimmed ICP from
 *  AMSCR's global estimate); the distance is then the mean squared closest-point residual.
 *  10 is recommended for registering occluded or noisy contours (README: measurements). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_refine(amscr_params *p, unsigned iterations);
AMSCR_API unsigned amscr_params_get_refine(const amscr_params *p);
/** Threads for batch calls: 0 = all cores (default), else 1..1024. */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_num_threads(amscr_params *p, unsigned n);
AMSCR_API unsigned amscr_params_get_num_threads(const amscr_params *p);
/** Invariance of the distance (default AMSCR_INVARIANCE_AFFINE). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_invariance(amscr_params *p, amscr_invariance v);
AMSCR_API amscr_invariance amscr_params_get_invariance(const amscr_params *p);
/** Weight of the penalty of AMSCR_INVARIANCE_PENALIZED, >= 0 (default 0.5). */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_penalty(amscr_params *p, double weight);
AMSCR_API double amscr_params_get_penalty(const amscr_params *p);

/* ======================================================================
 * Prepared shapes (descriptors) and registration
 * ====================================================================== */

/**
 * @brief Prepares a shape once (DESIGN.md §2: validate, orient, resample, parametrize,
 *        sample N points, whiten, smooth at every scale). Immutable afterwards, shareable
 *        by any number of threads. It keeps a copy of the params it was built with.
 *        Memory: about 784 + 8 * (9N + 3Np + 15p + 15) bytes (N samples, p scales): 35.8 KB at
 *        the defaults (N = 128, p = 8); a collection (amscr_db) holds one per shape plus ~16
 *        bytes; a saved collection takes 4 + 8 * (12 + 4N + 2Np) bytes per shape (20.6 KB).
 * @param[in] p  params (NULL = defaults).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_DEGENERATE, AMSCR_E_NOMEM.
 * Ownership: caller frees *out. Thread-safety: reentrant. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_descriptor_new(const amscr_params *p, const amscr_contour *c,
                                                            amscr_descriptor **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_descriptor_free(amscr_descriptor *d);
/** @brief Number of scales p. @since 0.1 */
AMSCR_API size_t amscr_descriptor_num_scales(const amscr_descriptor *d);
/** @brief Samples N per scale. @since 0.1 */
AMSCR_API size_t amscr_descriptor_num_samples(const amscr_descriptor *d);
/** @brief Borrowed N normalized, unsmoothed points. @since 0.1 */
AMSCR_API const double *amscr_descriptor_base_points(const amscr_descriptor *d);
/** @brief Borrowed N normalized points smoothed at scale k (0 <= k < p); NULL if out of range. @since 0.1 */
AMSCR_API const double *amscr_descriptor_scale_points(const amscr_descriptor *d, size_t k);
/** @brief N sampled points in input coordinates (before normalization), borrowed. @since 0.1 */
AMSCR_API const double *amscr_descriptor_input_points(const amscr_descriptor *d);
/** @brief Normalization map input -> normalized frame. @return AMSCR_OK, AMSCR_E_INVALID_ARG. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_descriptor_normalization(const amscr_descriptor *d, double out_m6[6]);
/** @brief Borrowed params the descriptor was built with. @since 0.1 */
AMSCR_API const amscr_params *amscr_descriptor_params(const amscr_descriptor *d);

/** @brief Per-thread scratch memory for registration and queries (optional: NULL where a
 *         workspace is accepted means "allocate internally").
 *  Ownership: caller frees. Thread-safety: one thread at a time. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_workspace_new(amscr_workspace **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_workspace_free(amscr_workspace *ws);

/**
 * @brief Registers prepared source `src` onto target `tgt`: h ≈ A f + B.
 * @param[in] p    matching options (method, reflections, kmax, symmetric, refine,
 *                 invariance); NULL = the source descriptor's params. Its N, scales,
 *                 closed flag and parametrization must equal both descriptors' (else
 *                 AMSCR_E_INVALID_ARG).
 * @param[in,out] ws  workspace or NULL.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NUMERIC, AMSCR_E_NOMEM.
 * Ownership: caller frees *out_result. Thread-safety: reentrant (ws per thread). @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_register(const amscr_params *p, const amscr_descriptor *src,
                                                      const amscr_descriptor *tgt, amscr_workspace *ws,
                                                      amscr_result **out_result);
/** @brief Convenience: builds both descriptors with p and registers. NULL p means the
 *         registration preset (amscr_params_new_registration), not the collection defaults.
 *  Ownership: caller frees *out_result. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_register_contours(const amscr_params *p, const amscr_contour *src,
                                                               const amscr_contour *tgt, amscr_result **out_result);
/** @brief The distance only (batch path: closed-form 2x2 solves, no result object).
 *  Agrees with amscr_result_distance to rounding. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_distance(const amscr_params *p, const amscr_descriptor *src,
                                                      const amscr_descriptor *tgt, amscr_workspace *ws,
                                                      double *out_distance);

/** @brief Releases a result; accepts NULL. @since 0.1 */
AMSCR_API void amscr_result_free(amscr_result *r);
/** @brief Affine-invariant distance (target's normalized frame); NaN for NULL. @since 0.1 */
AMSCR_API double amscr_result_distance(const amscr_result *r);
/** @brief The map taking the source onto the target in INPUT coordinates. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_affine(const amscr_result *r, double out_m6[6]);
/** @brief The same map between the normalized frames. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_affine_normalized(const amscr_result *r, double out_m6[6]);
/** @brief Start shift: source sample a corresponds to target sample (a + shift) mod N
 *         (of the reversed target when reflected). @since 0.1 */
AMSCR_API size_t amscr_result_shift(const amscr_result *r);
/** @brief Non-zero when the match used the reversed target (a mirror match). @since 0.1 */
AMSCR_API int amscr_result_reflected(const amscr_result *r);
/** @brief The method used; (amscr_method)-1, which is no method, for a NULL result. @since 0.1 */
AMSCR_API amscr_method amscr_result_method(const amscr_result *r);
/** @brief Number of scales p. @since 0.1 */
AMSCR_API size_t amscr_result_num_scales(const amscr_result *r);
/** @brief Per-scale residuals L2_k (eq. 13), p values; size query with NULL out. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_residuals(const amscr_result *r, double *out, size_t *inout_n);
/** @brief Kept flags (1/0) per scale, p values; size query with NULL out. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_kept(const amscr_result *r, int *out, size_t *inout_n);
/** @brief Number of kept scales. @since 0.1 */
AMSCR_API size_t amscr_result_num_kept(const amscr_result *r);
/** @brief K chosen by the elbow (2 for binary-em, 0 for acma/amscr). @since 0.1 */
AMSCR_API size_t amscr_result_k(const amscr_result *r);
/** @brief SSE(K) for K = 1..Kmax of the elbow (size query with NULL out; 0 values for acma/amscr). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_sse(const amscr_result *r, double *out, size_t *inout_n);
/** @brief Mixture found by EM: K weights, means, variances (sorted by mean; any out may be NULL;
 *         *inout_n capacity in, K out). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_mixture(const amscr_result *r, double *out_weights,
                                                            double *out_means, double *out_variances,
                                                            size_t *inout_n);
/** @brief Bayes threshold s0 (+inf when every scale is kept without a threshold). @since 0.1 */
AMSCR_API double amscr_result_threshold(const amscr_result *r);

/* ======================================================================
 * Collections (many shapes) and batch matching
 * ====================================================================== */

/** @brief An empty collection; copies p (NULL = defaults).
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_new(const amscr_params *p, amscr_db **out);
/** @brief Releases; accepts NULL. @since 0.1 */
AMSCR_API void amscr_db_free(amscr_db *db);
/** @brief Prepares a contour with the db's params and stores it with a label.
 *  @param[out] out_index  index of the new shape (may be NULL). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_add_contour(amscr_db *db, const amscr_contour *c, int32_t label,
                                                            size_t *out_index);
/** @brief Stores a copy of a prepared shape (its N/scales/closed/parametrization must match
 *         the db's). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_add_descriptor(amscr_db *db, const amscr_descriptor *d,
                                                               int32_t label, size_t *out_index);
/** @brief Number of shapes. @since 0.1 */
AMSCR_API size_t amscr_db_size(const amscr_db *db);
/** @brief Label of shape i (0 if out of range). @since 0.1 */
AMSCR_API int32_t amscr_db_label(const amscr_db *db, size_t i);
/** @brief Borrowed descriptor of shape i (NULL if out of range). @since 0.1 */
AMSCR_API const amscr_descriptor *amscr_db_descriptor(const amscr_db *db, size_t i);
/** @brief Borrowed params of the db. @since 0.1 */
AMSCR_API const amscr_params *amscr_db_params(const amscr_db *db);

/**
 * @brief 1-vs-many: out_dist[i] = distance(q -> shape i), amscr_db_size values.
 *        Uses the db's threads; results are bit-identical for any thread count.
 *        Batch outputs (this and the two calls below) are the one exception to "outputs are
 *        written only on AMSCR_OK": they are computed in place, so on failure or cancellation
 *        every element is set to NaN (never a silently partial result).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_CANCELLED, AMSCR_E_NOMEM. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_query(const amscr_db *db, const amscr_descriptor *q,
                                                      amscr_progress_fn progress, void *user, double *out_dist);
/**
 * @brief Many-vs-many: out_dist (n x n, row-major) [i*n + j] = distance(shape i -> shape j);
 *        the diagonal is 0. Threads, determinism and cancellation as amscr_db_query.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_distance_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                                void *user, double *out_dist);
/** @brief Cross matrix nq x nt: [i*nt + j] = distance(query i -> target j); the params
 *         (threads, method, ...) are those of `queries`. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_cross_distances(const amscr_db *queries, const amscr_db *targets,
                                                                amscr_progress_fn progress, void *user,
                                                                double *out_dist);
/** @brief Writes the prepared collection (versioned little-endian binary format with a
 *         checksum) to a temporary name and renames it. @return AMSCR_OK, AMSCR_E_INVALID_ARG,
 *         AMSCR_E_IO. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_save(const amscr_db *db, const char *path);
/** @brief Reads a saved collection. @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_IO,
 *         AMSCR_E_FORMAT (wrong magic, newer version, bad checksum, truncated), AMSCR_E_NOMEM.
 *  Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_load(const char *path, amscr_db **out);
/** @brief Serializes into a library-allocated buffer (free with amscr_free). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_save_memory(const amscr_db *db, void **out_buf, size_t *out_len);
/** @brief Deserializes a buffer from amscr_db_save_memory. Ownership: caller frees. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_load_memory(const void *buf, size_t len, amscr_db **out);

/* ======================================================================
 * Retrieval scores (pure functions on a distance matrix and labels)
 * ====================================================================== */

/** @brief Indices of the k smallest of n distances, ascending, ties broken by lower index;
 *         `exclude` (an index, or SIZE_MAX for none) is skipped. k <= n (minus one if excluded).
 *  @return AMSCR_OK, AMSCR_E_INVALID_ARG. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_topk(const double *dist, size_t n, size_t k, size_t exclude,
                                                  size_t *out_indices);
/**
 * @brief Bull's eye score (MPEG-7): for each query i, count shapes of its class among its
 *        `window` nearest (itself included; ties by lower index); the total is divided by
 *        the sum over queries of their class size Nc (= n * Nc when every class has Nc
 *        members). window 0 means twice the query's class size.
 * @param[in] dist n x n row-major (row i = distances from query i).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_bullseye(const double *dist, size_t n, const int32_t *labels,
                                                            size_t window, double *out_score);
/** @brief Top-k table (Kimia): out_counts[r] (r = 0..kmax-1) = number of queries whose
 *         (r+1)-th nearest neighbour (query excluded, ties by index) has the query's label.
 *  @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_topk_table(const double *dist, size_t n, const int32_t *labels,
                                                              size_t kmax, size_t *out_counts);
/** @brief Leave-one-out 1-NN accuracy (query excluded, ties by index). @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_accuracy(const double *dist, size_t n,
                                                               const int32_t *labels, double *out_accuracy);
/** @brief Train/test 1-NN accuracy: dist is ntest x ntrain row-major. @since 0.1 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_split(const double *dist, size_t ntest, size_t ntrain,
                                                            const int32_t *test_labels,
                                                            const int32_t *train_labels, double *out_accuracy);

/* ======================================================================
 * Contextual re-ranking (pure function on a distance matrix)
 * ====================================================================== */

/**
 * @brief Re-ranks a whole distance matrix with what the rest of the collection says: affinity
 *        diffusion on a k-nearest-neighbour tensor-product graph (Yang, Prasad, Latecki,
 *        "Affinity learning with diffusion on tensor product graph", CVPR 2012).
 *
 * Steps: D is symmetrized ((D + D^T) / 2); affinities W_ij = exp(-D_ij / sqrt(s_i s_j)) with
 * s_i the distance of i to its k-th nearest neighbour (self-tuning scale); W is kept only on
 * each row's k nearest neighbours (itself included) and row-normalized into P; then
 * Q <- P Q P^T + I is iterated `iterations` times from Q = P. The output is a dissimilarity
 * for ranking: out_ij = 1 - Q_ij / max_j Q_ij where Q_ij > 0 (so in [0, 1)), and
 * 1 + D_ij / max D for pairs the diffusion does not reach (so they keep their original order
 * after every reached one). Deterministic; O(iterations * n^2 * k) time, 3 n^2 doubles of
 * memory. The output is symmetric up to the row normalization by max_j Q_ij.
 * @param[in]  dist n x n row-major distances (finite, >= 0).
 * @param[in]  k    neighbours, 1..n (typical 10; README: measured choice).
 * @param[in]  iterations 1..1000 (typical 20).
 * @param[out] out_dist n x n; may equal dist (in place).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM. Thread-safety: reentrant. @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_rerank_diffusion(const double *dist, size_t n, size_t k,
                                                              unsigned iterations, double *out_dist);

/* ======================================================================
 * Robust and partial registration, confidence, dense correspondences (0.2)
 * ====================================================================== */

/**
 * @brief Partial matching (default 0): the source is an open fragment of the target's closed
 *        boundary. amscr_register then searches where on the target the fragment lies (its start
 *        and its length, in affine arc length, which an affine map preserves up to one factor),
 *        refines the map by trimmed closest points, and reports the place
 *        (amscr_result_part). amscr_register_contours (and the tool's --partial, Python's
 *        partial=True) prepare the source open and the target closed whatever `closed` says;
 *        with amscr_register the descriptors must have been prepared that way. Fragments of at
 *        least half the boundary register reliably; shorter ones are often ambiguous, which
 *        amscr_result_confidence reports. A partial match has no per-scale systems: its
 *        residuals are 0, no scale is kept, the threshold is +inf. @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_partial(amscr_params *p, int on);
/** @brief The partial flag (0 for NULL). @since 0.2 */
AMSCR_API int amscr_params_get_partial(const amscr_params *p);

/**
 * @brief Polish the reported map on the input points (default 0; 1 in the registration preset,
 *        so amscr_register_contours(NULL, ...), the tool's register and Python's register() use
 *        it). After the method and its refinement on the N samples, the map is re-fitted on the
 *        input points themselves by point-to-line steps. The smoother of the two curves is the
 *        one moved (noisy points as regressors would shrink the map); the points of each curve
 *        are paired with the closest point of the other, each direction weighted by its curve's
 *        measured roughness, so a noisy curve is fitted onto the clean one (the closest point ON
 *        a noisy curve is biased); pairs beyond 5x the median distance, and pairs on the chord
 *        across a missing run, are left out. When the start-point search was ambiguous its other
 *        distinct candidates are polished alike; the lowest two-way trimmed cost wins and sets
 *        the ambiguity. When one curve is markedly the noisier (4x the other's noise variance)
 *        and its noise is as large as its point spacing, the map is then refined by the ORDER of
 *        its points (0.3.1: each point a little further along the curve than the one before; a
 *        hidden Markov model fitted by EM), which pins where long and thin parts end, and then by
 *        their EVEN SPACING where the points bear it out (0.3.2: point i at the share off +- i/n
 *        of the moved clean curve; kept only when the residuals are white along the curve and
 *        at most 3x the distances from it, so unevenly sampled points are left to the order
 *        stage). Partial
 *        matching: the fragment's points alone. With the polish on, a contour of 32 or more
 *        points also loses its isolated stray points first (0.3.1: runs of at most 3 points the
 *        curve leaves and re-enters by edges 8x its median edge, and an open curve's end that
 *        jumps away so; a few stray points wrecked the arc-length parametrization). Needs the
 *        input points:
 *        amscr_descriptor_new keeps up to 4096 of them (64 KiB) under affine invariance;
 *        descriptors in a collection (amscr_db) or loaded from a file have none and are then
 *        registered unpolished. A closed target, affine invariance; the distance stays the batch
 *        path's. Measured in the README (held-out 1 % / 2 % noise: 95.7 / 88.6 % -> 100 / 100 %;
 *        over 280 pairs at 2 % noise the order stage takes 96.8 to 98.2 %, the even spacing to
 *        99.6 %; 50 % fragments 90.0 -> 95.7 %). @since 0.3
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_polish(amscr_params *p, int on);
/** @brief The polish flag (0 for NULL). @since 0.3 */
AMSCR_API int amscr_params_get_polish(const amscr_params *p);

/**
 * @brief How sure the registration is, in [0, 1]: (1 - ambiguity) x inlier fraction.
 *        Near 0: reject the map — either another, clearly different map explains the target
 *        almost as well (a symmetric shape: circle, square, regular star, or a fragment too short
 *        to place), or most source samples found no target boundary near them. Measured on the
 *        held-out benchmark (bench/registration_heldout.py, 560 maps, all conditions): of the
 *        maps with confidence >= 0.25, 99.8 % were within 10 % of the shape size (no wrong
 *        rotation or placement) and 97.4 % within 2 %. It flags wrong maps, not small biases:
 *        a slightly inaccurate map of a noisy contour still reads near 1. NaN for NULL. @since 0.2
 */
AMSCR_API double amscr_result_confidence(const amscr_result *r);
/**
 * @brief Ambiguity in [0, 1]: the trimmed closest-point cost of the chosen map divided by that
 *        of the best clearly different candidate map (a map moving the source samples by more
 *        than 10 % of the shape's RMS radius on average). 1 = two different maps fit equally
 *        well (symmetry); near 0 = the runner-up is far worse. 0 when no different candidate
 *        was evaluated (the batch path without refinement). NaN for NULL. @since 0.2
 */
AMSCR_API double amscr_result_ambiguity(const amscr_result *r);
/**
 * @brief Fraction of the source samples whose closest target boundary point lies within
 *        3 times the median closest-point distance (at least 1 % of the target's RMS radius) of
 *        their image under the map: 1 for a complete, clean match; about 1 - missing share
 *        when part of the target's boundary is missing. NaN for NULL. @since 0.2
 */
AMSCR_API double amscr_result_inlier_fraction(const amscr_result *r);
/**
 * @brief Where the source lies on the target: the boundary parameters, as fractions in [0, 1)
 *        of the target's boundary, of the targets points matched to the source's first and last
 *        samples. The parameter runs along the target's samples (its parametrization,
 *        whitened arc length by default) from the target's first input point in its input
 *        direction. For a partial match: where the fragment starts and ends (end < start when
 *        it wraps over the target's first point). @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_part(const amscr_result *r, double *out_start,
                                                         double *out_end);
/**
 * @brief Dense correspondences: for each of the N source samples (in input coordinates,
 *        out_src_xy, 2N values), the matched target boundary parameter (out_param, N values,
 *        fractions as in amscr_result_part) and the matched target point (out_tgt_xy, 2N values,
 *        input coordinates): the closest point of the target's boundary to the sample's image
 *        under the map. Any out may be NULL; *inout_n: capacity in samples in, N out (size
 *        query with all outs NULL). @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_correspondences(const amscr_result *r, double *out_src_xy,
                                                                    double *out_param, double *out_tgt_xy,
                                                                    size_t *inout_n);

/* ======================================================================
 * Retrieval beyond one aligned distance (0.2): the shape channel, fusion, re-ranking
 * ====================================================================== */

/**
 * @brief The retrieval preset: the defaults plus mirror images, the shape channel alone
 *        (channel weight 1: on articulated collections the AMSCR distance lowered the fused
 *        result at every weight measured) and context re-ranking with k = 8, 10 iterations
 *        (README /
 *        bench/RESULTS-retrieval.md: measured on mpeg7-dev, Kimia-99/216 and the MCD-style
 *        affine set). Use it with amscr_db_retrieval_matrix. Ownership: caller frees. @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new_retrieval(amscr_params **out);
/** Share of the shape channel in amscr_db_retrieval_matrix, 0..1: fused = (1 - w) AMSCR + w
 *  channel (each divided by its median); 0 = the AMSCR distance alone (default), 1 = the
 *  channel alone, and the AMSCR matrix is then not computed (the retrieval preset). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_weight(amscr_params *p, double w);
AMSCR_API double amscr_params_get_channel_weight(const amscr_params *p);
/** Frame of the shape channel: AMSCR_INVARIANCE_SIMILARITY (default) or _AFFINE (whitened);
 *  the channel distance is invariant to that group. @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_invariance(amscr_params *p, amscr_invariance v);
AMSCR_API amscr_invariance amscr_params_get_channel_invariance(const amscr_params *p);
/** With the similarity frame: the share, 0..1, of the same channel computed in the whitened
 *  (affine-normalized) frame, mixed in as (1 - s) d_similarity + s d_affine (default 0.2:
 *  keeps affine-distorted views retrievable while articulation is judged in the similarity
 *  frame). Ignored when the channel's frame is affine. @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_affine_share(amscr_params *p, double share);
AMSCR_API double amscr_params_get_channel_affine_share(const amscr_params *p);
/** Half width of the channel's dynamic-programming band, a fraction of N in (0, 0.5]
 *  (default 0.08: 10 samples at N = 128). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_band(amscr_params *p, double fraction);
AMSCR_API double amscr_params_get_channel_band(const amscr_params *p);
/** Cost of a sample matched twice (a skipped stretch on the other curve), in height units of
 *  the normalized frame, 0..1000 (default 1). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_skip(amscr_params *p, double cost);
AMSCR_API double amscr_params_get_channel_skip(const amscr_params *p);
/** Locality of the height functions: the bin at distance t (fraction of the curve, 0..0.5)
 *  from the sample is weighted 1 / (1 + locality * t); 0..1000 (default 4). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_locality(amscr_params *p, double locality);
AMSCR_API double amscr_params_get_channel_locality(const amscr_params *p);
/** Neighbours of the context re-ranking in amscr_db_retrieval_matrix, 0..1000; 0 = none
 *  (default 0; 8 in the retrieval preset). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_rerank_k(amscr_params *p, unsigned k);
AMSCR_API unsigned amscr_params_get_rerank_k(const amscr_params *p);
/** Diffusion iterations of the re-ranking, 1..1000 (default 10). @since 0.2 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_rerank_iterations(amscr_params *p, unsigned iterations);
AMSCR_API unsigned amscr_params_get_rerank_iterations(const amscr_params *p);

/**
 * @brief The shape channel's distance of two prepared closed shapes: height functions (the
 *        signed distances of all samples to the tangent at each sample, binned and weighted
 *        by locality; Wang et al., Pattern Recognition Letters 2012) in the channel's frame,
 *        compared by an order-preserving dynamic-programming correspondence in a band around
 *        the best cyclic shift (and mirror image when reflections are on). >= 0, 0 for a
 *        shape against itself, invariant to the channel's group, tolerant of articulation
 *        and local stretch. d(a, b) and d(b, a) differ only when the shift/mirror search
 *        of the two orders picks different candidates (rare); amscr_db_channel_matrix uses
 *        d(i, j) for i < j in both cells. The channel settings come from `p` (NULL = a's).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (NULL, open curves, different N), AMSCR_E_NOMEM.
 * Thread-safety: reentrant. @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_channel_distance(const amscr_params *p, const amscr_descriptor *a,
                                                              const amscr_descriptor *b, double *out_dist);
/**
 * @brief The n x n matrix of shape-channel distances of a collection (symmetric, zero
 *        diagonal), on the collection's threads; result independent of the thread count.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_NOMEM, AMSCR_E_CANCELLED (matrix all NaN).
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_channel_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                               void *user, double *out_dist);
/**
 * @brief The retrieval distance of a collection: the AMSCR matrix (symmetrized) and the shape
 *        channel, each divided by its median off-diagonal value and mixed by the channel
 *        weight, then (rerank_k > 0) diffusion re-ranking exactly as amscr_rerank_diffusion
 *        with its output halved: a dissimilarity in [0, 1] where row i ranks i's neighbours,
 *        0 for i itself, below 0.5 for the shapes the diffusion reaches from i and 0.5 + half
 *        the normalized fused distance for the others. Without re-ranking the fused distance
 *        itself (symmetric, 0 on the diagonal).
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG (open curves with a channel weight), AMSCR_E_NOMEM,
 *         AMSCR_E_CANCELLED (matrix all NaN). @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_retrieval_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                                 void *user, double *out_dist);

/* ======================================================================
 * Every contour of an image, with its hierarchy (0.2)
 * ====================================================================== */

/** A list of contours with their hierarchy (amscr_contours_from_mask). Opaque. */
typedef struct amscr_contour_set amscr_contour_set;

/** Parent index of a top-level contour (amscr_contour_set_parent). */
#define AMSCR_NO_PARENT SIZE_MAX

/**
 * @brief Traces every 8-connected foreground component of an 8-bit image and every hole
 *        (4-connected background region not connected to the border), each with its parent:
 *        the hierarchy of OpenCV's findContours with RETR_TREE.
 *
 * Threshold and polarity as amscr_contour_from_mask. Outer contours go through the boundary
 * pixel centres of their component, counter-clockwise (positive signed area); a hole's
 * contour goes through the centres of its own boundary (background) pixels, clockwise
 * (negative signed area). The parent of a hole is the component around it; the parent of a
 * component is the hole it lies in, or AMSCR_NO_PARENT. Contours are listed in raster order
 * of their first pixel, so a parent comes before its children.
 * A contour is kept when it has at least 3 points, its polygon area (pixels^2, |signed area|)
 * is >= min_area and its parent is kept; contours of no area (single pixels, lines) are
 * always dropped.
 *
 * @param[in] pixels, width, height, stride, threshold  as amscr_contour_from_mask.
 * @param[in] min_area  >= 0 and finite (0 keeps every contour with an area).
 * @param[out] out  new set with at least one contour.
 * @return AMSCR_OK, AMSCR_E_INVALID_ARG, AMSCR_E_LIMIT, AMSCR_E_NOT_FOUND (no foreground,
 *         foreground everywhere, or no contour of min_area), AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_set_free. Thread-safety: reentrant.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contours_from_mask(const uint8_t *pixels, size_t width,
                                                                size_t height, size_t stride, int threshold,
                                                                double min_area, amscr_contour_set **out);
/** @brief Releases a set and its contours; accepts NULL. @since 0.2 */
AMSCR_API void amscr_contour_set_free(amscr_contour_set *s);
/** @brief Number of contours (0 for NULL). @since 0.2 */
AMSCR_API size_t amscr_contour_set_size(const amscr_contour_set *s);
/** @brief Contour i, borrowed: valid until the set is freed (NULL if out of range). @since 0.2 */
AMSCR_API const amscr_contour *amscr_contour_set_contour(const amscr_contour_set *s, size_t i);
/** @brief Index of the parent of contour i (< i), or AMSCR_NO_PARENT (also if out of range).
 *  @since 0.2 */
AMSCR_API size_t amscr_contour_set_parent(const amscr_contour_set *s, size_t i);
/** @brief 1 when contour i is a hole, else 0. @since 0.2 */
AMSCR_API int amscr_contour_set_is_hole(const amscr_contour_set *s, size_t i);
/** @brief Polygon area of contour i (pixels^2, >= 0; 0 if out of range). @since 0.2 */
AMSCR_API double amscr_contour_set_area(const amscr_contour_set *s, size_t i);

#ifdef __cplusplus
}
#endif

#endif /* AMSCR_H */
