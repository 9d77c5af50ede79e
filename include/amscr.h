/*
 * amscr.h — Affine Multi-Scale Curve Registration: the one public header.
 *
 * The method is that of the paper "Optimized multi-scale affine shape registration based on an
 * unsupervised Bayesian classification"; docs/method.md describes the algorithms. This header
 * is the contract: what each call does, its units, ownership, thread-safety, errors and the
 * release that introduced it.
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
 * Units.       Coordinates are the caller's (pixels for traced contours). Registration
 *              distances are dimensionless: expressed in the target's normalized frame.
 *              "Fraction" means a value in [0, 1] of the stated whole.
 * Sizes.       Counts and indices are `size_t`, labels `int32_t`, seeds `uint64_t`.
 *              Flags are `int` 0 or 1.
 * Arguments.   Handle first, then inputs, then outputs. A buffer is a
 *              (pointer, count) pair; out-parameters come last and start with
 *              `out_`; `inout_n` is a capacity in and a count out (a NULL output
 *              buffer queries the count). Outputs are written only when AMSCR_OK is
 *              returned; the exceptions are stated where they apply (the batch calls
 *              fill their output with NaN on failure; amscr_bayes_threshold writes
 *              a fallback with AMSCR_E_NOT_FOUND).
 * Floating point. The calls run under the caller's floating-point environment: a
 *              rounding mode other than to-nearest or flush-to-zero moves results by
 *              rounding only; traps on invalid or divide-by-zero (feenableexcept) are
 *              not set off by registration, retrieval or tracing (a NaN that marks
 *              "not computed" is compared quietly). The status flags
 *              (fetestexcept) are left as the computation raised them.
 * errno.       Not part of the interface: any call may change it, also on success.
 * Errors.      Every fallible function returns `amscr_status`. On failure
 *              amscr_last_error_detail() says what went wrong, for the
 *              calling thread. The library never prints and never aborts.
 *              A NULL required pointer is AMSCR_E_INVALID_ARG. Getters that cannot
 *              fail return 0, NULL or NaN (as stated) for a NULL object.
 * Ownership.   Functions whose names contain _new, _copy, _read, _parse or
 *              _load, and amscr_register, amscr_register_contours,
 *              amscr_contour_from_mask, amscr_contours_from_mask,
 *              amscr_contour_from_image, amscr_contours_from_image,
 *              amscr_index_build, amscr_db_save_memory and amscr_index_save_memory,
 *              hand the caller something to free: an object with its own
 *              amscr_<obj>_free() (each accepts NULL), or for the two _save_memory
 *              calls a buffer for amscr_free(). Every other pointer
 *              returned is borrowed: valid until its owner is freed or
 *              modified. Inputs are copied when kept; the caller keeps its buffers.
 *
 * Thread-safety (three laws):
 *   1. Every function is reentrant; the library has no global mutable state
 *      (the only global is the thread-local error detail).
 *   2. A non-const object is used by one thread at a time.
 *   3. Objects passed as `const` (amscr_params, amscr_contour, amscr_contour_set,
 *      amscr_descriptor, a finished amscr_db or amscr_index, fitted
 *      amscr_kmeans/amscr_gmm1d, amscr_result) may be shared by any number of threads.
 *      Adding to a db or an index while another thread queries it is not allowed.
 *      Bindings that release their interpreter lock during calls (Python's cffi)
 *      rely on these laws.
 *   fork(): a child process inherits the locks of the calls other threads were
 *   making (a db builds its kept retrieval index under one); it may use only the
 *   objects no call was using at the fork. The Python package waits for such
 *   calls before a fork.
 *   Each call below says which applies: "safe" (no object, or a static one),
 *   "const" (reads its objects: law 3), "exclusive on X" (modifies X: law 2),
 *   "reentrant" (creates a new object from shared inputs).
 */

/* ============================================================================
 * Export macros, version, limits, special values
 * ============================================================================ */
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

/* A status must be looked at (warn_unused_result). GCC warns even when it is cast to void: a
 * caller that discards statuses on purpose defines AMSCR_NODISCARD empty before including this
 * header (-DAMSCR_NODISCARD=). */
#if !defined(AMSCR_NODISCARD)
#  if defined(__GNUC__) && (__GNUC__ > 3 || (__GNUC__ == 3 && __GNUC_MINOR__ >= 4))
#    define AMSCR_NODISCARD __attribute__((warn_unused_result))
#  else
#    define AMSCR_NODISCARD
#  endif
#endif

/** Compile-time version; amscr_version_number() gives the runtime one. */
#define AMSCR_VERSION_MAJOR 0
#define AMSCR_VERSION_MINOR 22
#define AMSCR_VERSION_PATCH 8
#define AMSCR_VERSION_NUMBER \
    (AMSCR_VERSION_MAJOR * 10000 + AMSCR_VERSION_MINOR * 100 + AMSCR_VERSION_PATCH)

/** Largest image side accepted by the tracing calls (pixels). @since 0.1 */
#define AMSCR_MAX_IMAGE_SIDE 32768
/** Largest number of pixels accepted by the tracing calls. @since 0.1 */
#define AMSCR_MAX_IMAGE_PIXELS 268435456u /* 2^28 */
/** Largest number of points in a contour. @since 0.1 */
#define AMSCR_MAX_POINTS 16777216u /* 2^24 */
/** Largest number of samples N per scale. @since 0.1 */
#define AMSCR_MAX_SAMPLES 65536u
/** Largest number of scales. @since 0.1 */
#define AMSCR_MAX_SCALES 64u
/** Automatic threshold (Otsu) for amscr_contour_from_mask. @since 0.1 */
#define AMSCR_THRESHOLD_AUTO (-1)
/** Parent index of a top-level contour (amscr_contour_set_parent). @since 0.2 */
#define AMSCR_NO_PARENT SIZE_MAX

/* ============================================================================
 * Status codes and features
 * ============================================================================ */

/** Status codes. The values are pinned forever: never renumbered, never reused. @since 0.1 */
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

/** Optional features (amscr_has_feature). @since 0.1 */
typedef enum amscr_feature {
    AMSCR_FEATURE_THREADS = 1    /**< batch calls can use POSIX threads */
} amscr_feature;

/* ============================================================================
 * Opaque types and callbacks
 * ============================================================================ */

/** Registration options (amscr_params_new). @since 0.1 */
typedef struct amscr_params amscr_params;
/** A list of points (amscr_contour_new). @since 0.1 */
typedef struct amscr_contour amscr_contour;
/** A prepared, immutable shape (amscr_descriptor_new). @since 0.1 */
typedef struct amscr_descriptor amscr_descriptor;
/** The outcome of one registration (amscr_register). @since 0.1 */
typedef struct amscr_result amscr_result;
/** Per-thread scratch memory (amscr_workspace_new). @since 0.1 */
typedef struct amscr_workspace amscr_workspace;
/** A collection of prepared, labelled shapes (amscr_db_new). @since 0.1 */
typedef struct amscr_db amscr_db;
/** A K-means clustering (amscr_kmeans_new). @since 0.1 */
typedef struct amscr_kmeans amscr_kmeans;
/** A 1-D Gaussian mixture (amscr_gmm1d_new). @since 0.1 */
typedef struct amscr_gmm1d amscr_gmm1d;
/** A list of contours with their hierarchy (amscr_contours_from_image). @since 0.2 */
typedef struct amscr_contour_set amscr_contour_set;

/**
 * @brief Progress callback for long batch calls.
 * @param user  the pointer given with the callback.
 * @param done  work items finished so far.
 * @param total work items in the call (> 0: a call with no work does not report). A call
 *              that runs in stages may report each stage in its own items: done / total is
 *              the fraction, monotone over the call.
 * @return 0 to continue, non-zero to cancel (the call then returns AMSCR_E_CANCELLED).
 * The callback must return normally: no C++ exception, longjmp or thread cancellation may
 * leave it (the call would keep its locks and memory; catch, and return non-zero). It may call
 * the library on other objects and query the objects the call only reads, except the
 * collection of an amscr_db_query_retrieval or amscr_db_search_retrieval reporting to it
 * (AMSCR_E_STATE: that call holds the collection's lock); it must not change or free the
 * objects the call uses.
 * Thread-safety: called from the thread that made the batch call, never concurrently.
 * @since 0.1
 */
typedef int (*amscr_progress_fn)(void *user, size_t done, size_t total);

/* ============================================================================
 * Version and errors
 * ============================================================================ */

/**
 * @brief Runtime version as M*10000 + m*100 + p (compare with AMSCR_VERSION_NUMBER).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API int amscr_version_number(void);

/**
 * @brief Runtime version as the string "M.m.p". Never NULL.
 * Ownership: static storage; do not free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API const char *amscr_version_string(void);

/**
 * @brief Whether an optional feature was compiled in.
 * @param[in] feature  an amscr_feature value.
 * @return non-zero when compiled in, 0 otherwise (also for unknown values).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API int amscr_has_feature(amscr_feature feature);

/**
 * @brief English description of a status code (unknown codes too). Never NULL.
 * Ownership: static storage; do not free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API const char *amscr_strerror(amscr_status status);

/**
 * @brief Detail of the calling thread's last failure, e.g. "shape.txt:17: expected 2 numbers".
 *        Every call that returns an amscr_status clears it first: after AMSCR_OK it is the
 *        empty string. Never NULL.
 * Ownership: thread-local buffer, valid until the next amscr call on this thread.
 * Thread-safety: per thread.
 * @since 0.1
 */
AMSCR_API const char *amscr_last_error_detail(void);

/**
 * @brief Releases a raw buffer allocated by the library (amscr_db_save_memory). Accepts NULL.
 * Ownership: takes ptr.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API void amscr_free(void *ptr);

/* ============================================================================
 * Contour: points, validation, text I/O, tracing from masks
 * ============================================================================ */

/**
 * @brief Makes a contour by copying `n` interleaved points.
 * @param[in]  xy   2n doubles (may contain anything; validation happens when used).
 * @param[in]  n    number of points, 1..AMSCR_MAX_POINTS.
 * @param[out] out  new contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n == 0); AMSCR_E_LIMIT; AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_new(const double *xy, size_t n, amscr_contour **out);

/**
 * @brief Releases a contour. Accepts NULL.
 * Ownership: takes c.
 * Thread-safety: exclusive on c.
 * @since 0.1
 */
AMSCR_API void amscr_contour_free(amscr_contour *c);

/**
 * @brief Number of points.
 * @return the count; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_contour_size(const amscr_contour *c);

/**
 * @brief The 2n interleaved coordinates.
 * @return the array; NULL for NULL.
 * Ownership: borrowed from c.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_contour_xy(const amscr_contour *c);

/**
 * @brief Checks that a contour can be registered: finite coordinates, at least 8 distinct
 *        points after dropping repeated consecutive points, an extent (the larger side of the
 *        bounding box) from 1e-60 to 1e60, a distance from the origin (of the bounding box's
 *        centre) at most 2^44 (1.76e13) times the extent (beyond, doubles hold the shape to less
 *        than 1/256 of its size: subtract an offset), and (closed) non-zero area or (open) not
 *        all collinear. Shapes far from the origin (over 2^20 times their extent) are prepared
 *        moved by their first point, so they lose no more than their coordinates' own rounding.
 * @param[in] c       the contour.
 * @param[in] closed  1 to check as a closed curve, 0 as an open one.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite); AMSCR_E_DEGENERATE.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_validate(const amscr_contour *c, int closed);

/**
 * @brief Signed area of the closed polygon (positive = counter-clockwise, y up), in
 *        squared coordinate units.
 * @param[out] out_area  the area.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite coordinates).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_signed_area(const amscr_contour *c, double *out_area);

/**
 * @brief Reverses the point order in place when the signed area is negative.
 * @param[in,out] c  the contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite coordinates).
 * Ownership: none.
 * Thread-safety: exclusive on c.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_orient_ccw(amscr_contour *c);

/**
 * @brief Reads a text point list: one "x y" or "x,y" per line (tabs/spaces/one comma),
 *        '#' starts a comment, blank lines are ignored. An empty list is AMSCR_E_FORMAT.
 *        A UTF-8 byte order mark at the start is skipped. The decimal point is '.' whatever
 *        locale the program set with setlocale; the program's locale is left as it is.
 * @param[in]  path  file name.
 * @param[out] out   new contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_IO (cannot open/read); AMSCR_E_FORMAT (bad
 *         line, the detail names "path:line"; empty list); AMSCR_E_LIMIT; AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_read_text(const char *path, amscr_contour **out);

/**
 * @brief As amscr_contour_read_text, from a memory buffer. Error details name "line N".
 * @param[in]  text  `len` bytes (need not be NUL-terminated).
 * @param[out] out   new contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_FORMAT; AMSCR_E_LIMIT; AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_parse_text(const char *text, size_t len, amscr_contour **out);

/**
 * @brief Writes a contour as a text point list ("%.17g %.17g" per line, with '.' as the
 *        decimal point whatever locale the program set). The file is
 *        written whole before it takes its name (an unnamed file of the folder, O_TMPFILE,
 *        linked in; where the system has none, a temporary name renamed), so a failure never
 *        leaves a partial file (and, with unnamed files, a killed process leaves none at all).
 *        A replaced file keeps its mode; a symbolic link's target is replaced, not the link;
 *        an existing file that is not a regular file (a device such as /dev/null, a FIFO,
 *        /dev/stdout or /dev/fd/N) is written through, appending, never replaced.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite coordinates); AMSCR_E_IO; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_write_text(const amscr_contour *c, const char *path);

/**
 * @brief Traces the outer boundary of the largest 8-connected foreground component of an
 *        8-bit image.
 *
 * A pixel is "on" when its value is > threshold. Polarity is automatic: if most of the image
 * border is "on", on/off are swapped, so the border is background. Holes are ignored; smaller
 * components are dropped; shapes touching the border are handled (the image is treated as
 * padded with background). The result is the sequence of boundary pixel centres (x = column,
 * y = row) with positive signed area (counter-clockwise in a y-up frame), no repeated point.
 * Prefer amscr_contour_from_image (8/16 bits, sub-pixel; AMSCR_TRACE_PIXEL_CHAIN at level T + 0.5 is this call).
 *
 * @param[in] pixels  width*height bytes, rows `stride` bytes apart.
 * @param[in] width   1..AMSCR_MAX_IMAGE_SIDE, width*height <= AMSCR_MAX_IMAGE_PIXELS.
 * @param[in] height  1..AMSCR_MAX_IMAGE_SIDE.
 * @param[in] stride  >= width.
 * @param[in] threshold  0..254 or AMSCR_THRESHOLD_AUTO (Otsu).
 * @param[out] out  new contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_LIMIT; AMSCR_E_NOT_FOUND (no foreground, or
 *         foreground everywhere); AMSCR_E_DEGENERATE (component too small to trace: < 3
 *         boundary points); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_from_mask(const uint8_t *pixels, size_t width,
                                                               size_t height, size_t stride, int threshold,
                                                               amscr_contour **out);

/* ---------------------------------------- contour set: every contour of an image */

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
 * of their first pixel, so a parent comes before its children. A contour is kept when it has
 * at least 3 points, its polygon area (pixels^2) is >= min_area and its parent is kept;
 * contours of no area (single pixels, lines) are always dropped.
 * Prefer amscr_contours_from_image (8/16 bits, sub-pixel; AMSCR_TRACE_PIXEL_CHAIN at level T + 0.5 is this call).
 *
 * @param[in] pixels     as amscr_contour_from_mask.
 * @param[in] width      as amscr_contour_from_mask.
 * @param[in] height     as amscr_contour_from_mask.
 * @param[in] stride     as amscr_contour_from_mask.
 * @param[in] threshold  as amscr_contour_from_mask.
 * @param[in] min_area  pixels^2, >= 0 and finite (0 keeps every contour with an area).
 * @param[out] out  new set with at least one contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_LIMIT; AMSCR_E_NOT_FOUND (no foreground,
 *         foreground everywhere, or no contour of min_area); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_set_free.
 * Thread-safety: reentrant.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contours_from_mask(const uint8_t *pixels, size_t width,
                                                                size_t height, size_t stride, int threshold,
                                                                double min_area, amscr_contour_set **out);

/**
 * @brief Releases a set and its contours. Accepts NULL.
 * Ownership: takes s; contours borrowed from it become invalid.
 * Thread-safety: exclusive on s.
 * @since 0.2
 */
AMSCR_API void amscr_contour_set_free(amscr_contour_set *s);

/**
 * @brief Number of contours.
 * @return the count; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API size_t amscr_contour_set_size(const amscr_contour_set *s);

/**
 * @brief Contour i.
 * @return the contour; NULL for NULL or i out of range.
 * Ownership: borrowed from s (valid until the set is freed).
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API const amscr_contour *amscr_contour_set_contour(const amscr_contour_set *s, size_t i);

/**
 * @brief Index of the parent of contour i (always < i).
 * @return the index; AMSCR_NO_PARENT for a top-level contour, NULL or i out of range.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API size_t amscr_contour_set_parent(const amscr_contour_set *s, size_t i);

/**
 * @brief Whether contour i is a hole.
 * @return 1 for a hole, else 0 (also for NULL or i out of range).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API int amscr_contour_set_is_hole(const amscr_contour_set *s, size_t i);

/**
 * @brief Polygon area of contour i, pixels^2.
 * @return the area, >= 0; 0 for NULL or i out of range.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_contour_set_area(const amscr_contour_set *s, size_t i);

/* ---------------------------------------- sub-pixel contours of grey images */

/** Automatic level for amscr_contour_from_image (any negative level). @since 0.4 */
#define AMSCR_LEVEL_AUTO (-1.0)
/** Flag of amscr_contour_from_image: the pixel-centre chain of amscr_contour_from_mask. @since 0.4 */
#define AMSCR_TRACE_PIXEL_CHAIN 1
/** Flag of amscr_contour_from_image (sub-pixel tracing; no effect with AMSCR_TRACE_PIXEL_CHAIN):
 *  the other large components near the largest (at least 5 % of its pixels, within its RMS
 *  radius, not inside its holes; up to 8) joined to its outline by zero-width bridges between
 *  closest vertices — a shape an occluder cut in pieces keeps all its boundary for registration
 *  (docs/method.md §5). @since 0.5 */
#define AMSCR_TRACE_JOIN 2

/**
 * @brief Traces the outer boundary of the largest foreground component of an 8- or 16-bit
 *        grey image at sub-pixel accuracy: the iso-line at `level`.
 *
 * A pixel is foreground when its value is > level. Polarity is automatic, components and
 * shapes touching the border as amscr_contour_from_mask (foreground 8-connected; the image is
 * treated as padded with its background level). The result is the iso-line of the image at
 * `level` through the component's boundary, found by marching squares with linear
 * interpolation between pixel centres (x = column, y = row; a binary image's boundary runs
 * halfway between foreground and background pixel centres, an antialiased image's where the
 * coverage is one half), with positive signed area (counter-clockwise in a y-up frame), no
 * repeated point. Saddle cells join foreground corners. With AMSCR_TRACE_PIXEL_CHAIN the
 * pixels are classified the same way and the result is amscr_contour_from_mask's chain of
 * boundary pixel centres. With AMSCR_TRACE_JOIN (sub-pixel only) the outline also takes in the
 * other large pieces near the largest component (see the flag).
 *
 * @param[in] pixels  height rows of width samples (uint8_t for bits 8, native-endian uint16_t
 *                    for bits 16), rows `stride` samples apart.
 * @param[in] width   1..AMSCR_MAX_IMAGE_SIDE, width*height <= AMSCR_MAX_IMAGE_PIXELS.
 * @param[in] height  1..AMSCR_MAX_IMAGE_SIDE.
 * @param[in] stride  samples between row starts, >= width.
 * @param[in] bits  8 or 16.
 * @param[in] level  the iso-level in sample units, 0 <= level < 2^bits - 1 (T + 0.5 classifies
 *                   pixels as amscr_contour_from_mask's threshold T); negative
 *                   (AMSCR_LEVEL_AUTO): halfway between the medians of the two classes
 *                   of Otsu's split.
 * @param[in] flags  0 (sub-pixel), AMSCR_TRACE_PIXEL_CHAIN, and/or AMSCR_TRACE_JOIN.
 * @param[out] out  new contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, empty image, bad stride, bits, level or
 *         flags); AMSCR_E_LIMIT; AMSCR_E_NOT_FOUND (no foreground, or foreground
 *         everywhere); AMSCR_E_DEGENERATE (no area); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_free.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contour_from_image(const void *pixels, size_t width, size_t height,
                                                                size_t stride, int bits, double level, int flags,
                                                                amscr_contour **out);

/**
 * @brief Every contour of an 8- or 16-bit grey image at sub-pixel accuracy, with the
 *        hierarchy of amscr_contours_from_mask.
 *
 * Level, polarity and flags as amscr_contour_from_image; components, holes, parents, order
 * and min_area as amscr_contours_from_mask. Each contour is the iso-line at `level` between
 * its region and the region around it: outer contours counter-clockwise, holes clockwise.
 * Areas are those of the sub-pixel polygons (a single binary pixel has area 0.5).
 *
 * @param[in] pixels  as amscr_contour_from_image.
 * @param[in] width   as amscr_contour_from_image.
 * @param[in] height  as amscr_contour_from_image.
 * @param[in] stride  as amscr_contour_from_image.
 * @param[in] bits    as amscr_contour_from_image.
 * @param[in] level   as amscr_contour_from_image.
 * @param[in] flags  0 or AMSCR_TRACE_PIXEL_CHAIN (AMSCR_TRACE_JOIN: AMSCR_E_INVALID_ARG).
 * @param[in] min_area  pixels^2, >= 0 and finite.
 * @param[out] out  new set with at least one contour.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_LIMIT; AMSCR_E_NOT_FOUND (no foreground,
 *         foreground everywhere, or no contour of min_area); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_contour_set_free.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_contours_from_image(const void *pixels, size_t width, size_t height,
                                                                 size_t stride, int bits, double level, int flags,
                                                                 double min_area, amscr_contour_set **out);

/* ============================================================================
 * Curve processing: smoothing, resampling, normalization
 * (stateless; the caller allocates every output)
 * ============================================================================ */

/**
 * @brief FIR Gaussian taps: radius r = ceil(4*sigma), 2r+1 taps, normalized to sum 1.
 * @param[in]     sigma  in samples, > 0, finite, <= 1e6.
 * @param[out]    taps   room for *inout_ntaps doubles, or NULL to query the count.
 * @param[in,out] inout_ntaps  capacity in, count out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (also when the capacity is too small).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gaussian_kernel(double sigma, double *taps, size_t *inout_ntaps);

/**
 * @brief Gaussian smoothing of a polyline, x and y separately: circular for closed curves
 *        (exact for kernels longer than the curve), mirrored at the ends (half-sample
 *        symmetric, "reflect") for open curves. sigma == 0 copies.
 * @param[in] xy  n input points (n >= 1).
 * @param[in] n   the number of points.
 * @param[in]  closed  1 closed, 0 open.
 * @param[in]  sigma   in samples, 0 to 1e6 (as amscr_gaussian_kernel).
 * @param[out] out_xy  2n doubles; must not overlap xy.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (also out_xy overlapping xy); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_smooth_gaussian(const double *xy, size_t n, int closed, double sigma,
                                                             double *out_xy);

/**
 * @brief m points equally spaced in Euclidean arc length along the polygon (linear
 *        interpolation; periodic when closed). The first output is the first input point;
 *        for open curves the last output is the last input point.
 * @param[in] xy      the polygon (n >= 2).
 * @param[in] n       the number of points.
 * @param[in] closed  1 closed, 0 open.
 * @param[in]  m  the points wanted (m >= 2).
 * @param[out] out_xy  2m doubles.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n or m below 2, non-finite); AMSCR_E_DEGENERATE
 *         (zero length); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_resample_euclidean(const double *xy, size_t n, int closed, size_t m,
                                                                double *out_xy);

/**
 * @brief Cumulative affine arc length (the paper's eq. 2) at each vertex of a uniformly
 *        sampled curve, after Gaussian smoothing over the sample index; central differences
 *        (one-sided at open ends), speed |x'y'' - x''y'|^(1/3), trapezoid sums. Not normalized.
 * @param[in] xy      the curve, n >= 5.
 * @param[in] n       the number of points.
 * @param[in] closed  1 closed, 0 open.
 * @param[in]  sigma0  smoothing in samples (0 = none).
 * @param[out] out_cumulative  n values, out_cumulative[0] = 0.
 * @param[out] out_total  the whole length (closed: including the closing segment).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (n < 5, non-finite); AMSCR_E_DEGENERATE (total
 *         numerically zero: a straight curve); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_arclength(const double *xy, size_t n, int closed, double sigma0,
                                                              double *out_cumulative, double *out_total);

/**
 * @brief m points equally spaced in affine arc length. The polygon is first resampled
 *        uniformly (Euclidean) to max(8m, n) points; each of the `passes` affine arc-length
 *        passes takes derivatives over the previous pass's parameter.
 * @param[in]  sigma0  pre-smoothing as a FRACTION of the curve length (e.g. 0.02).
 * @param[in]  passes  >= 1.
 * @param[in]  m       >= 4.
 * @param[out] out_xy  2m doubles.
 * @return as amscr_affine_arclength, plus AMSCR_E_INVALID_ARG for m < 4.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_resample_affine(const double *xy, size_t n, int closed, double sigma0,
                                                             unsigned passes, size_t m, double *out_xy);

/**
 * @brief Whitening normalization: moves the centroid to the origin and multiplies by
 *        Sigma^(-1/2) (Sigma the 2x2 covariance, 1/n), so the output has identity covariance.
 * @param[out] out_xy       2n doubles (may be NULL).
 * @param[out] out_forward  affine map input -> normalized (may be NULL).
 * @param[out] out_inverse  affine map normalized -> input (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (n == 0, non-finite); AMSCR_E_DEGENERATE (1 or 2
 *         points, collinear, singular covariance).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_normalize_whiten(const double *xy, size_t n, double *out_xy,
                                                              double out_forward[6], double out_inverse[6]);

/* ============================================================================
 * Least squares and affine maps
 * ============================================================================ */

/**
 * @brief Least squares min ||a x - b|| by Householder QR (LAPACKE), several right-hand sides
 *        in one call.
 * @param[in]  a     m x n, row-major, m >= n >= 1.
 * @param[in]  b     m x nrhs, row-major, nrhs >= 1.
 * @param[out] out_x n x nrhs, row-major.
 * @param[out] out_residual_norms nrhs residual 2-norms (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_LIMIT (problem too large); AMSCR_E_NUMERIC
 *         (rank-deficient or ill-conditioned: reciprocal condition estimate of R below 1e-12;
 *         the detail gives it); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_lstsq_qr(const double *a, size_t m, size_t n, const double *b,
                                                      size_t nrhs, double *out_x, double *out_residual_norms);

/**
 * @brief Least-squares affine map taking src[i] to dst[i].
 * @param[in] src_xy  n points, not collinear (n >= 3).
 * @param[in] dst_xy  n points, dst_xy[i] the image of src_xy[i].
 * @param[in] n       the number of pairs.
 * @param[out] out_m6   the map.
 * @param[out] out_rms  RMS residual distance, in coordinate units (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NUMERIC (collinear src); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_fit(const double *src_xy, const double *dst_xy, size_t n,
                                                        double out_m6[6], double *out_rms);

/**
 * @brief Applies an affine map to n points.
 * @param[out] out_xy  2n doubles; may equal xy (in place).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_apply(const double m6[6], const double *xy, size_t n,
                                                          double *out_xy);

/**
 * @brief Inverts an affine map.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite); AMSCR_E_DEGENERATE (singular
 *         relative to the map's scale, or an inverse a double cannot hold).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_affine_invert(const double m6[6], double out_m6[6]);

/* ============================================================================
 * K-means (deterministic) and the elbow
 * ============================================================================ */

/**
 * @brief A K-means object for k clusters. Defaults: seed 0, 100 iterations, tolerance 1e-10,
 *        4 restarts.
 * @param[in]  k    clusters, >= 1.
 * @param[out] out  new object.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (k == 0, NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_kmeans_free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_new(size_t k, amscr_kmeans **out);

/**
 * @brief Releases a K-means object. Accepts NULL.
 * Ownership: takes km.
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API void amscr_kmeans_free(amscr_kmeans *km);

/**
 * @brief Sets the seed of the k-means++ start (used when dim > 1); default 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_seed(amscr_kmeans *km, uint64_t seed);

/**
 * @brief The seed.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API uint64_t amscr_kmeans_get_seed(const amscr_kmeans *km);

/**
 * @brief Sets the Lloyd iteration cap, >= 1 (default 100).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_max_iterations(amscr_kmeans *km, unsigned n);

/**
 * @brief The Lloyd iteration cap.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_kmeans_get_max_iterations(const amscr_kmeans *km);

/**
 * @brief Sets the relative SSE change that counts as converged, >= 0 (default 1e-10).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_tolerance(amscr_kmeans *km, double tol);

/**
 * @brief The convergence tolerance.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_kmeans_get_tolerance(const amscr_kmeans *km);

/**
 * @brief Sets the number of seeded restarts (used when dim > 1), >= 1 (default 4); the
 *        best SSE is kept.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_set_restarts(amscr_kmeans *km, unsigned r);

/**
 * @brief The number of restarts.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_kmeans_get_restarts(const amscr_kmeans *km);

/**
 * @brief The number of clusters k.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_kmeans_num_clusters(const amscr_kmeans *km);

/**
 * @brief Dimension of the last fit.
 * @return the value; 0 before a fit and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_kmeans_dim(const amscr_kmeans *km);

/**
 * @brief Clusters n x dim row-major data (n >= k). For dim == 1 the result is the exact
 *        optimum (dynamic programming over sorted data), otherwise Lloyd iterations from a
 *        seeded k-means++ start with restarts. Deterministic for a given seed.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n < k, dim 0, non-finite); AMSCR_E_NOMEM.
 * Ownership: none (data is copied as needed).
 * Thread-safety: exclusive on km.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_fit(amscr_kmeans *km, const double *data, size_t n, size_t dim);

/**
 * @brief The k x dim centres of the last fit (sorted ascending when dim == 1).
 * @return the array; NULL before a fit and for NULL.
 * Ownership: borrowed from km (valid until the next fit or free).
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_kmeans_centers(const amscr_kmeans *km);

/**
 * @brief Within-cluster sum of squares (SSE) of the last fit.
 * @return the value; NaN before a fit and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_kmeans_inertia(const amscr_kmeans *km);

/**
 * @brief Nearest-centre labels for n points of the fitted dimension.
 * @param[out] out_labels   n labels in 0..k-1.
 * @param[out] out_sq_dist  n squared distances to the centre (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite); AMSCR_E_STATE (not fitted).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_assign(const amscr_kmeans *km, const double *data, size_t n,
                                                           size_t *out_labels, double *out_sq_dist);

/**
 * @brief SSE for every k in [k_min, k_max] and the elbow: with k and SSE both scaled to
 *        [0, 1], the k farthest below the chord from k_min to k_max; k_min when SSE(k_min) is
 *        negligible or there is no bend.
 * @param[in] data  n x dim row-major data.
 * @param[in] n     the number of rows.
 * @param[in] dim   the number of columns.
 * @param[in] k_min  1 <= k_min <= k_max.
 * @param[in] k_max  k_min <= k_max <= n.
 * @param[in]  seed          seed of the k-means++ starts.
 * @param[out] out_inertia   k_max - k_min + 1 SSE values.
 * @param[out] out_k_best    the elbow k.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_kmeans_elbow(const double *data, size_t n, size_t dim, size_t k_min,
                                                          size_t k_max, uint64_t seed, double *out_inertia,
                                                          size_t *out_k_best);

/* ============================================================================
 * 1-D Gaussian mixture (EM) and the Bayes threshold
 * ============================================================================ */

/**
 * @brief A 1-D Gaussian mixture with k components, initialized from exact 1-D K-means.
 *        Defaults: 200 iterations, tolerance 1e-10, variance floor 1e-6.
 * @param[in]  k    components, >= 1.
 * @param[out] out  new object.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (k == 0, NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_gmm1d_free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_new(size_t k, amscr_gmm1d **out);

/**
 * @brief Releases a mixture. Accepts NULL.
 * Ownership: takes g.
 * Thread-safety: exclusive on g.
 * @since 0.1
 */
AMSCR_API void amscr_gmm1d_free(amscr_gmm1d *g);

/**
 * @brief Sets the EM iteration cap, >= 1 (default 200).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on g.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_max_iterations(amscr_gmm1d *g, unsigned n);

/**
 * @brief The EM iteration cap.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_gmm1d_get_max_iterations(const amscr_gmm1d *g);

/**
 * @brief Sets the convergence tolerance on the relative log-likelihood gain, >= 0
 *        (default 1e-10).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on g.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_tolerance(amscr_gmm1d *g, double tol);

/**
 * @brief The convergence tolerance.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_gmm1d_get_tolerance(const amscr_gmm1d *g);

/**
 * @brief Sets the variance floor as a fraction of the data variance, in [0, 1] (default
 *        1e-6; an absolute floor of 1e-300 always applies).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, out of range).
 * Ownership: none.
 * Thread-safety: exclusive on g.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_set_variance_floor(amscr_gmm1d *g, double v);

/**
 * @brief The relative variance floor.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_gmm1d_get_variance_floor(const amscr_gmm1d *g);

/**
 * @brief The number of components k.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_gmm1d_num_components(const amscr_gmm1d *g);

/**
 * @brief Fits the mixture by EM to n >= k finite values.
 * @return AMSCR_OK (also when the cap is reached: see amscr_gmm1d_converged);
 *         AMSCR_E_INVALID_ARG (NULL, n < k, non-finite); AMSCR_E_NUMERIC (the likelihood
 *         overflows a double: values too spread, e.g. +-1e200; g keeps its last fit);
 *         AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: exclusive on g.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_fit(amscr_gmm1d *g, const double *x, size_t n);

/**
 * @brief The k component weights of the last fit, components sorted by mean.
 * @return the array; NULL before a fit and for NULL.
 * Ownership: borrowed from g (valid until the next fit or free).
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_gmm1d_weights(const amscr_gmm1d *g);

/**
 * @brief The k component means of the last fit, ascending.
 * @return the array; NULL before a fit and for NULL.
 * Ownership: borrowed from g (valid until the next fit or free).
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_gmm1d_means(const amscr_gmm1d *g);

/**
 * @brief The k component variances of the last fit, components sorted by mean.
 * @return the array; NULL before a fit and for NULL.
 * Ownership: borrowed from g (valid until the next fit or free).
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_gmm1d_variances(const amscr_gmm1d *g);

/**
 * @brief Log-likelihood of the last fit.
 * @return the value; NaN before a fit and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_gmm1d_loglik(const amscr_gmm1d *g);

/**
 * @brief EM iterations used by the last fit.
 * @return the count; 0 before a fit and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_gmm1d_iterations(const amscr_gmm1d *g);

/**
 * @brief Whether the last fit converged within the iteration cap.
 * @return non-zero when it did; 0 otherwise, before a fit and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int amscr_gmm1d_converged(const amscr_gmm1d *g);

/**
 * @brief Responsibilities of the components at x.
 * @param[out] out_post  k values summing to 1.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_STATE (not fitted); AMSCR_E_NUMERIC.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_posterior(const amscr_gmm1d *g, double x, double *out_post);

/**
 * @brief Bayes threshold between components i and j of a fitted mixture, as
 *        amscr_bayes_threshold.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, i or j out of range); AMSCR_E_STATE (not
 *         fitted); AMSCR_E_NOT_FOUND (as amscr_bayes_threshold, the midpoint is written).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_gmm1d_bayes_threshold(const amscr_gmm1d *g, size_t i, size_t j,
                                                                   double *out_threshold);

/**
 * @brief The point s between mu1 and mu2 where w1*N(s; mu1, var1) = w2*N(s; mu2, var2)
 *        (the root of a quadratic, or of a line when var1 == var2).
 * @return AMSCR_OK; AMSCR_E_NOT_FOUND when no root lies strictly between the means (then
 *         *out_threshold is still set, to the midpoint (mu1+mu2)/2); AMSCR_E_INVALID_ARG
 *         (weights <= 0, variances <= 0, non-finite).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_bayes_threshold(double w1, double mu1, double var1, double w2,
                                                             double mu2, double var2, double *out_threshold);

/* ============================================================================
 * Params: the registration and retrieval options
 * ============================================================================ */

/** Registration methods (the paper's table rows). @since 0.1 */
typedef enum amscr_method {
    AMSCR_METHOD_ACMA = 0,          /**< one scale (the finest), no selection */
    AMSCR_METHOD_AMSCR = 1,         /**< all scales stacked, no selection */
    AMSCR_METHOD_BINARY_EM = 2,     /**< selection with a 2-component mixture */
    AMSCR_METHOD_MULTICLASS_EM = 3  /**< K by K-means + elbow, K-component mixture (default) */
} amscr_method;

/** Parametrizations of a curve before sampling N points. @since 0.1 */
typedef enum amscr_parametrization {
    AMSCR_PARAM_AFFINE = 0,     /**< affine arc length (paper eq. 2), iterated */
    AMSCR_PARAM_EUCLIDEAN = 1,  /**< Euclidean arc length (not affine-invariant) */
    AMSCR_PARAM_WHITENED = 2    /**< Euclidean arc length after whitening by region moments */
} amscr_parametrization;

/** Invariance group of the distance. @since 0.1 */
typedef enum amscr_invariance {
    AMSCR_INVARIANCE_AFFINE = 0,      /**< full affine (the paper) */
    AMSCR_INVARIANCE_SIMILARITY = 1,  /**< rotation + uniform scale + translation */
    AMSCR_INVARIANCE_PENALIZED = 2    /**< affine fit + penalty on A's distance from a similarity */
} amscr_invariance;

/*
 * Every amscr_params_set_* below returns AMSCR_OK, or AMSCR_E_INVALID_ARG (NULL p or a value
 * out of the stated range, with a detail) leaving p unchanged; it is exclusive on p. Every
 * amscr_params_get_* returns the stored value (0 for a NULL p) and is const.
 */

/**
 * @brief A params object with the defaults stated at each setter (the collection defaults).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_params_free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new(amscr_params **out);

/**
 * @brief The registration preset, for registering single pairs rather than building
 *        collections: the defaults with N = 256 samples, 20 refinement iterations and the
 *        polish on. amscr_register_contours uses it when given NULL params.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_params_free.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new_registration(amscr_params **out);

/**
 * @brief The retrieval preset, for amscr_db_retrieval_matrix and amscr_index_build: the
 *        defaults with reflections on, channel weight 1 (the shape channel alone), affine-view
 *        factor 2, and re-ranking with k = 8 neighbours (10 iterations) on the retrieval
 *        distance's graph and the inner distance's (share 0.1, closing 0.04).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_params_free.
 * Thread-safety: safe.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_new_retrieval(amscr_params **out);

/**
 * @brief Deep copy.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_params_free.
 * Thread-safety: const on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_copy(const amscr_params *p, amscr_params **out);

/**
 * @brief Releases a params object. Accepts NULL.
 * Ownership: takes p.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API void amscr_params_free(amscr_params *p);

/* ---------------------------------------------- sampling and parametrization */

/**
 * @brief Sets N, the samples per scale: 16..AMSCR_MAX_SAMPLES (default 128).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_num_samples(amscr_params *p, size_t n);

/**
 * @brief N, the samples per scale.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_params_get_num_samples(const amscr_params *p);

/**
 * @brief Sets the scale list sigma_k, in samples of the N-point curve: 1..AMSCR_MAX_SCALES
 *        values, each finite, >= 0 (0 = unsmoothed) and <= the current N; stored as given
 *        (default 1, 2, 3, 4, 6, 8, 11, 16). amscr_descriptor_new rejects scales above N.
 * @param[in] sigmas  n sigmas, the list (copied).
 * @param[in] n       the number of sigmas.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_scales(amscr_params *p, const double *sigmas, size_t n);

/**
 * @brief Copies the scale list.
 * @param[out]    out_sigmas  room for *inout_n values, or NULL to query the count.
 * @param[in,out] inout_n     capacity in, count out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL p or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_get_scales(const amscr_params *p, double *out_sigmas,
                                                               size_t *inout_n);

/**
 * @brief Sets closed (1, default) or open (0) curves.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_closed(amscr_params *p, int closed);

/**
 * @brief The closed flag.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int amscr_params_get_closed(const amscr_params *p);

/**
 * @brief Sets the parametrization (default AMSCR_PARAM_WHITENED; AMSCR_PARAM_AFFINE is the
 *        paper's affine arc length).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_parametrization(amscr_params *p, amscr_parametrization v);

/**
 * @brief The parametrization.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API amscr_parametrization amscr_params_get_parametrization(const amscr_params *p);

/**
 * @brief Sets the pre-smoothing sigma0 of the parametrization (the parameter is computed on a
 *        copy smoothed over the sample index), as a fraction of the curve length, 0..0.25
 *        (default 0.01).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_presmooth(amscr_params *p, double fraction);

/**
 * @brief The pre-smoothing fraction.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_params_get_presmooth(const amscr_params *p);

/**
 * @brief Sets the parametrization passes, 1..10 (default 3): each pass computes the
 *        parameter over the previous pass's parameter.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_arclength_passes(amscr_params *p, unsigned passes);

/**
 * @brief The parametrization passes.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_params_get_arclength_passes(const amscr_params *p);

/**
 * @brief Sets the dense resampling factor: the curve is first resampled to factor*N points,
 *        1..64 (default 8).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_oversampling(amscr_params *p, unsigned factor);

/**
 * @brief The dense resampling factor.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_params_get_oversampling(const amscr_params *p);

/* ----------------------------------------------------------------- matching */

/**
 * @brief Sets the method (default AMSCR_METHOD_MULTICLASS_EM).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_method(amscr_params *p, amscr_method m);

/**
 * @brief The method.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API amscr_method amscr_params_get_method(const amscr_params *p);

/**
 * @brief Sets Kmax of the elbow, 1..16 (default 5; clamped to the number of scales at use).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_kmax(amscr_params *p, unsigned kmax);

/**
 * @brief Kmax of the elbow.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_params_get_kmax(const amscr_params *p);

/**
 * @brief Sets whether the reversed target is also tried (mirror matches); default 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_reflections(amscr_params *p, int on);

/**
 * @brief The reflections flag.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int amscr_params_get_reflections(const amscr_params *p);

/**
 * @brief Sets the symmetric distance (the average of both directions); default 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_symmetric(amscr_params *p, int on);

/**
 * @brief The symmetric flag.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int amscr_params_get_symmetric(const amscr_params *p);

/**
 * @brief Sets the invariance group of the distance (default AMSCR_INVARIANCE_AFFINE).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_invariance(amscr_params *p, amscr_invariance v);

/**
 * @brief The invariance group.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API amscr_invariance amscr_params_get_invariance(const amscr_params *p);

/**
 * @brief Sets the weight of the penalty of AMSCR_INVARIANCE_PENALIZED, 0..1e6 (default 0.5).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_penalty(amscr_params *p, double weight);

/**
 * @brief The penalty weight.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_params_get_penalty(const amscr_params *p);

/**
 * @brief Sets the refinement iterations in the aligned frame, 0..50 (default 0: the paper's
 *        method; 20 in the registration preset). Each iteration pairs every source sample
 *        with the closest point of the target polygon, trims the worst 10 % of pairs and
 *        re-solves; the distance is then the mean squared closest-point residual.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_refine(amscr_params *p, unsigned iterations);

/**
 * @brief The refinement iterations.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_params_get_refine(const amscr_params *p);

/**
 * @brief Sets partial matching (default 0): the source is an open fragment of the target's
 *        closed boundary. amscr_register then finds where on the target the fragment lies
 *        (amscr_result_part) and refines the map on it. amscr_register_contours prepares the
 *        source open and the target closed whatever `closed` says; with amscr_register the
 *        descriptors must have been prepared so. A partial result has no per-scale systems:
 *        residuals 0, no kept scale, threshold +inf. Short fragments may be ambiguous
 *        (amscr_result_confidence). The fragment's points may run either way
 *        along the target (both are searched; without reflections only maps that keep the
 *        orientation, determinant > 0, are placed).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_partial(amscr_params *p, int on);

/**
 * @brief The partial flag.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API int amscr_params_get_partial(const amscr_params *p);

/**
 * @brief Sets the polish of the reported map on the input points (default 0; 1 in the
 *        registration preset). After the method and its refinement on the N samples,
 *        amscr_register re-fits the map on the input points of both curves (docs/method.md).
 *        It applies when both descriptors keep their input points (amscr_descriptor_new keeps
 *        up to 4096 of them, 64 KiB, under affine invariance; descriptors in or loaded from a
 *        collection keep none), the target is closed and the invariance is affine. With the
 *        polish and the "despike" stage on (amscr_params_set_stage; off by default),
 *        amscr_descriptor_new also drops isolated stray points of contours of 32 or more
 *        points. The distance is not changed by the polish.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.3
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_polish(amscr_params *p, int on);

/**
 * @brief The polish flag.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.3
 */
AMSCR_API int amscr_params_get_polish(const amscr_params *p);

/**
 * @brief Switches an optional stage of amscr_register on or off by name: "despike" (stray
 *        points dropped when a shape is prepared with the polish on), "recovery" (fragments
 *        placed as further starts when part of the target is missing), "polish" (both this
 *        switch and amscr_params_set_polish must be on; prefer amscr_params_set_polish, as
 *        this one is on by default), "order" and "even_spacing" (the polish's steps on
 *        markedly noisy points), "pixel_grid" (a target traced from a small binary image, its
 *        points on the pixel lattice, is registered onto again with its tracing's bias
 *        simulated and removed; the map whose rendering differs from the target image in fewer
 *        pixels is kept; likewise a source traced from a small binary image when the target,
 *        too large for that, was traced from an image too; a target given as such an image's
 *        pixel chain is first traced again at sub-pixel, and the result is read against that
 *        trace; so is a source given as a small image's pixel chain when the target was traced
 *        from an image too; which targets and sources: docs/method.md §11.7). Default in every
 *        preset:
 *        recovery, polish and pixel_grid on; despike, order and even_spacing off (switch them
 *        on for point lists with stray points or synthetic noise; docs/method.md §11). A stage
 *        switched on still runs only when its condition holds (amscr_result_stage).
 * @param on  1 on, 0 off.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, unknown or mandatory stage, on not 0 or 1).
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.5
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_stage(amscr_params *p, const char *name, int on);

/**
 * @brief Whether the optional stage `name` is on (see amscr_params_set_stage).
 * @return 1 on, 0 off; -1 for NULL or a name that is not a switchable stage.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.5
 */
AMSCR_API int amscr_params_get_stage(const amscr_params *p, const char *name);

/* ------------------------------------------------------------- batch calls */

/**
 * @brief Sets the threads of batch calls: 0 = all cores (default), else 1..1024. Results do
 *        not depend on the thread count. "All cores" are those the process may run on (its
 *        CPU affinity on Linux: taskset, a container's cpuset).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_num_threads(amscr_params *p, unsigned n);

/**
 * @brief The thread count of batch calls.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API unsigned amscr_params_get_num_threads(const amscr_params *p);

/* ------------------------------------ retrieval: shape channel and re-ranking */

/**
 * @brief Sets the share of the shape channel in amscr_db_retrieval_matrix, 0..1:
 *        fused = (1 - w) AMSCR + w channel (each divided by its median); 0 = the AMSCR
 *        distance alone (default), 1 = the channel alone (the AMSCR matrix is then not
 *        computed; the retrieval preset).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_weight(amscr_params *p, double w);

/**
 * @brief The channel weight.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_params_get_channel_weight(const amscr_params *p);

/**
 * @brief Sets the frame of the shape channel: AMSCR_INVARIANCE_SIMILARITY (default) or
 *        AMSCR_INVARIANCE_AFFINE (whitened); the channel distance is invariant to that group.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (also AMSCR_INVARIANCE_PENALIZED).
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_invariance(amscr_params *p, amscr_invariance v);

/**
 * @brief The channel's frame.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API amscr_invariance amscr_params_get_channel_invariance(const amscr_params *p);

/**
 * @brief With the similarity frame: sets the share s, 0..1, of the same channel computed in
 *        the whitened (affine-normalized) frame, mixed in as (1 - s) d_similarity +
 *        s d_affine (default 0.2). Ignored when the channel's frame is affine.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_affine_share(amscr_params *p, double share);

/**
 * @brief The channel's affine share.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_params_get_channel_affine_share(const amscr_params *p);

/**
 * @brief Sets the half width of the channel's dynamic-programming band, as a fraction of N
 *        in (0, 0.5] (default 0.15: 19 samples at N = 128): how far the correspondence may
 *        stray from the best cyclic shift, i.e. how much articulation (a part bent or
 *        stretched along the curve) the channel forgives. With the similarity frame and an
 *        affine share, the whitened frame has its own band
 *        (amscr_params_set_channel_affine_band).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_band(amscr_params *p, double fraction);

/**
 * @brief The channel's band fraction.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_params_get_channel_band(const amscr_params *p);

/**
 * @brief Sets the band of the channel's whitened frame when it is the second frame (the
 *        similarity frame with an affine share > 0), as a fraction of N in (0, 0.5]
 *        (default 0.08). A file that
 *        holds one band for both frames loads with this one equal to
 *        amscr_params_set_channel_band's.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.6
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_affine_band(amscr_params *p, double fraction);

/**
 * @brief The band of the channel's whitened second frame.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.6
 */
AMSCR_API double amscr_params_get_channel_affine_band(const amscr_params *p);

/**
 * @brief Sets the cost of a sample matched twice (a skipped stretch on the other curve), in
 *        height units of the normalized frame, 0..1000 (default 1).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_skip(amscr_params *p, double cost);

/**
 * @brief The channel's skip cost.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_params_get_channel_skip(const amscr_params *p);

/**
 * @brief Sets the locality of the height functions: the bin at distance t (a fraction of the
 *        curve, 0..0.5) from the sample is weighted 1 / (1 + locality * t); 0..1000
 *        (default 4).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_locality(amscr_params *p, double locality);

/**
 * @brief The channel's locality.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_params_get_channel_locality(const amscr_params *p);

/**
 * @brief Sets the neighbours of the context re-ranking in amscr_db_retrieval_matrix,
 *        0..1000; 0 = no re-ranking (default 0; 8 in the retrieval preset). A collection of
 *        n shapes uses K = min(k, max(1, n / 2)): neighbourhoods that cover the collection
 *        carry no context and flatten every score.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_rerank_k(amscr_params *p, unsigned k);

/**
 * @brief The re-ranking neighbours.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API unsigned amscr_params_get_rerank_k(const amscr_params *p);

/**
 * @brief Sets the diffusion iterations of the re-ranking, 1..1000 (default 10).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_rerank_iterations(amscr_params *p, unsigned iterations);

/**
 * @brief The re-ranking iterations.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API unsigned amscr_params_get_rerank_iterations(const amscr_params *p);

/**
 * @brief Sets the share of the inner-distance graph in the re-ranking, in [0, 1) (default 0;
 *        0.1 in the retrieval preset). The re-ranking diffuses over the kNN graph of the
 *        retrieval distance; with a share s > 0 it diffuses over (1 - s) times that graph
 *        plus s times the kNN graph of the inner distance (the shortest path inside the
 *        shape between two boundary points, which a part bent at a joint hardly changes),
 *        so neighbours both distances agree on reinforce each other. It adds one inner
 *        distance per pair the channel compares (a small part of the channel's time) and
 *        changes nothing without re-ranking. An index holds both graphs; an index file that
 *        holds one graph loads with share 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (outside [0, 1), NaN).
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.7
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_rerank_inner_share(amscr_params *p, double share);

/**
 * @brief The share of the inner-distance graph in the re-ranking.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.7
 */
AMSCR_API double amscr_params_get_rerank_inner_share(const amscr_params *p);

/**
 * @brief Sets the closing of the silhouette the inner distance is taken in, as a radius in
 *        units of the square root of the area the curve bounds, in [0, 1] (default 0; 0.04 in
 *        the retrieval preset). With c > 0 the inner distance's paths run inside the region
 *        the curve bounds closed morphologically by a disk of radius c sqrt(area): cracks,
 *        slots and gaps narrower than the disk do not force a path around them, while
 *        parts and wider inlets stay. A cut that reaches the outline then changes the inner
 *        distance as little as it changes the shape. Only the inner-distance graph uses it
 *        (amscr_params_set_rerank_inner_share); a curve that bounds no area is taken as it
 *        is. The outline (64 points, 1 KB) is made from the whole contour when a shape is
 *        prepared with c > 0 and kept with it; a shape prepared with another value is closed
 *        from its N samples instead, which on a long slotted outline approximates it poorly.
 *        Collection and index files keep the value and the outlines; a file without them
 *        loads with 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (outside [0, 1], NaN).
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.9
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_inner_closing(amscr_params *p, double radius);

/**
 * @brief The closing radius of the inner distance's silhouette (amscr_params_set_inner_closing).
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.9
 */
AMSCR_API double amscr_params_get_inner_closing(const amscr_params *p);

/**
 * @brief Sets the factor f by which the whitened (affine) frame alone must find a pair nearer
 *        than the two frames' mix for the pair to be ranked by it: with the similarity frame
 *        and an affine share s strictly between 0 and 1 (amscr_params_set_channel_affine_share),
 *        a pair's channel distance is m = (1 - s) d_similarity + s d_affine, and with f > 0 it is
 *        min(m, f d_affine). An affine view of a shape (a photograph at an angle, a sheared or
 *        stretched copy) is far nearer in the whitened frame than in the similarity frame and
 *        is then ranked by the whitened frame; any other pair keeps the mix. 0 (the default)
 *        keeps the mix for every pair; 2 in the retrieval preset. With one frame (share 0 or
 *        1, or the affine frame) it changes nothing. Collection and index files keep the
 *        value; a file without it loads with 0.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (not 0 and outside [1, 100], NaN).
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.11
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_channel_affine_view(amscr_params *p, double factor);

/**
 * @brief The channel's affine-view factor (amscr_params_set_channel_affine_view).
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.11
 */
AMSCR_API double amscr_params_get_channel_affine_view(const amscr_params *p);

/* ------------------------------------------------- which scores the params rank by */

/** The scores a collection ranks its shapes by under given params (amscr_params_ranking).
 *  @since 0.13 */
typedef enum amscr_ranking {
    AMSCR_RANKING_DISTANCE = 0,  /**< the AMSCR distance: amscr_db_query, amscr_db_distance_matrix */
    AMSCR_RANKING_RETRIEVAL = 1  /**< the retrieval scores: amscr_db_query_retrieval,
                                      amscr_db_retrieval_matrix, an amscr_index */
} amscr_ranking;

/**
 * @brief Which scores params p rank a collection by: the retrieval scores when p asks for the
 *        shape channel (channel weight > 0) or for re-ranking (rerank_k > 0), else the AMSCR
 *        distance (with neither, amscr_db_retrieval_matrix is the symmetrized AMSCR distance,
 *        not the one-way distance of amscr_db_query).
 * @param[in]  p            the params.
 * @param[out] out_ranking  AMSCR_RANKING_DISTANCE or AMSCR_RANKING_RETRIEVAL.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_ranking(const amscr_params *p, amscr_ranking *out_ranking);

/* ----------------------------------------------------------- every option by key */

/**
 * Option keys of the keyed calls amscr_params_set_int / _set_real / _get_int / _get_real /
 * _get_bounds: one key per number or flag of amscr_params. Each key sets the same value, with the
 * same validation, as its named pair (AMSCR_OPT_NUM_SAMPLES and amscr_params_set_num_samples);
 * the ranges, units and defaults below are those of the pair. The values are pinned forever:
 * new keys are only appended, and a key may have no named pair.
 * Integer keys (flags are 0 or 1; enumerations take their enum's values) go through the _int
 * calls, real keys through the _real calls.
 * @since 0.13
 */
typedef enum amscr_option {
    AMSCR_OPT_NUM_SAMPLES = 1,           /**< int: N, samples per scale, 16..AMSCR_MAX_SAMPLES */
    AMSCR_OPT_CLOSED = 2,                /**< int: closed (1) or open (0) curves */
    AMSCR_OPT_PARAMETRIZATION = 3,       /**< int: an amscr_parametrization */
    AMSCR_OPT_PRESMOOTH = 4,             /**< real: pre-smoothing, fraction of the curve length, 0..0.25 */
    AMSCR_OPT_ARCLENGTH_PASSES = 5,      /**< int: parametrization passes, 1..10 */
    AMSCR_OPT_OVERSAMPLING = 6,          /**< int: dense resampling factor, 1..64 */
    AMSCR_OPT_METHOD = 7,                /**< int: an amscr_method */
    AMSCR_OPT_KMAX = 8,                  /**< int: Kmax of the elbow, 1..16 */
    AMSCR_OPT_REFLECTIONS = 9,           /**< int: flag, mirror matches tried */
    AMSCR_OPT_SYMMETRIC = 10,            /**< int: flag, distance averaged over both directions */
    AMSCR_OPT_INVARIANCE = 11,           /**< int: an amscr_invariance */
    AMSCR_OPT_PENALTY = 12,              /**< real: penalty weight of AMSCR_INVARIANCE_PENALIZED, 0..1e6 */
    AMSCR_OPT_REFINE = 13,               /**< int: refinement iterations, 0..50 */
    AMSCR_OPT_PARTIAL = 14,              /**< int: flag, partial matching */
    AMSCR_OPT_POLISH = 15,               /**< int: flag, polish on the input points */
    AMSCR_OPT_NUM_THREADS = 16,          /**< int: threads of batch calls, 0 (all cores)..1024 */
    AMSCR_OPT_CHANNEL_WEIGHT = 17,       /**< real: share of the shape channel, 0..1 */
    AMSCR_OPT_CHANNEL_INVARIANCE = 18,   /**< int: the channel's frame, AMSCR_INVARIANCE_AFFINE or _SIMILARITY */
    AMSCR_OPT_CHANNEL_AFFINE_SHARE = 19, /**< real: share of the whitened frame's channel, 0..1 */
    AMSCR_OPT_CHANNEL_BAND = 20,         /**< real: DP band half width, fraction of N, (0, 0.5] */
    AMSCR_OPT_CHANNEL_AFFINE_BAND = 21,  /**< real: the whitened second frame's band, fraction of N, (0, 0.5] */
    AMSCR_OPT_CHANNEL_SKIP = 22,         /**< real: cost of a sample matched twice, height units, 0..1000 */
    AMSCR_OPT_CHANNEL_LOCALITY = 23,     /**< real: locality of the height functions, 0..1000 */
    AMSCR_OPT_RERANK_K = 24,             /**< int: re-ranking neighbours, 0 (none)..1000 */
    AMSCR_OPT_RERANK_ITERATIONS = 25,    /**< int: diffusion iterations, 1..1000 */
    AMSCR_OPT_RERANK_INNER_SHARE = 26,   /**< real: share of the inner-distance graph, [0, 1) */
    AMSCR_OPT_INNER_CLOSING = 27,        /**< real: closing radius, units of sqrt(area), 0..1 */
    AMSCR_OPT_CHANNEL_AFFINE_VIEW = 28   /**< real: affine-view factor, 0 or 1..100 */
} amscr_option;

/**
 * @brief Sets the integer option `key` to v, validated as by its named pair.
 * @param[in,out] p    the params.
 * @param[in]     key  an integer option key (amscr_option).
 * @param[in]     v    the value, in the key's range (amscr_params_get_bounds).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL p, an unknown key, a real key, v out of range),
 *         leaving p unchanged.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_int(amscr_params *p, amscr_option key, int v);

/**
 * @brief Sets the real option `key` to v, validated as by its named pair.
 * @param[in,out] p    the params.
 * @param[in]     key  a real option key (amscr_option).
 * @param[in]     v    the value, in the key's range (amscr_params_get_bounds); never NaN.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL p, an unknown key, an integer key, v out of range
 *         or NaN), leaving p unchanged.
 * Ownership: none.
 * Thread-safety: exclusive on p.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_set_real(amscr_params *p, amscr_option key, double v);

/**
 * @brief The value of the integer option `key`.
 * @param[in]  p      the params.
 * @param[in]  key    an integer option key (amscr_option).
 * @param[out] out_v  the value.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL p or out_v, an unknown key, a real key).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_get_int(const amscr_params *p, amscr_option key, int *out_v);

/**
 * @brief The value of the real option `key`.
 * @param[in]  p      the params.
 * @param[in]  key    a real option key (amscr_option).
 * @param[out] out_v  the value.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL p or out_v, an unknown key, an integer key).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_get_real(const amscr_params *p, amscr_option key,
                                                             double *out_v);

/**
 * @brief The range of option `key`, integer or real: every accepted value v has
 *        lo <= v <= hi, in the key's units. Three keys also refuse values inside it:
 *        AMSCR_OPT_CHANNEL_BAND and AMSCR_OPT_CHANNEL_AFFINE_BAND refuse 0,
 *        AMSCR_OPT_RERANK_INNER_SHARE refuses 1, and AMSCR_OPT_CHANNEL_AFFINE_VIEW accepts 0
 *        and [1, 100] only.
 * @param[in]  key     an option key (amscr_option).
 * @param[out] out_lo  the least value.
 * @param[out] out_hi  the greatest value.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out_lo or out_hi, an unknown key).
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.13
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_params_get_bounds(amscr_option key, double *out_lo, double *out_hi);

/* ============================================================================
 * Workspace
 * ============================================================================ */

/**
 * @brief Per-thread scratch memory for registration and queries (optional: NULL where a
 *        workspace is accepted means "allocate internally").
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_workspace_free.
 * Thread-safety: safe; the workspace is then used by one thread at a time.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_workspace_new(amscr_workspace **out);

/**
 * @brief Releases a workspace. Accepts NULL.
 * Ownership: takes ws.
 * Thread-safety: exclusive on ws.
 * @since 0.1
 */
AMSCR_API void amscr_workspace_free(amscr_workspace *ws);

/* ============================================================================
 * Descriptor: a prepared shape
 * ============================================================================ */

/**
 * @brief Prepares a shape once: validates, orients, resamples, parametrizes, samples N points,
 *        normalizes and smooths at every scale (docs/method.md). Immutable afterwards; keeps
 *        a copy of the params. Memory: about 784 + 8 * (9N + 3Np + 15p + 15) bytes (N samples,
 *        p scales), plus up to 64 KiB of input points under affine invariance.
 * @param[in]  p    params (NULL = the defaults of amscr_params_new).
 * @param[in]  c    the contour (copied).
 * @param[out] out  new descriptor.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, non-finite, a scale above N);
 *         AMSCR_E_DEGENERATE (see amscr_contour_validate); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_descriptor_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_descriptor_new(const amscr_params *p, const amscr_contour *c,
                                                            amscr_descriptor **out);

/**
 * @brief Releases a descriptor. Accepts NULL.
 * Ownership: takes d.
 * Thread-safety: exclusive on d.
 * @since 0.1
 */
AMSCR_API void amscr_descriptor_free(amscr_descriptor *d);

/**
 * @brief Number of scales p.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_descriptor_num_scales(const amscr_descriptor *d);

/**
 * @brief Samples N per scale.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_descriptor_num_samples(const amscr_descriptor *d);

/**
 * @brief The N normalized, unsmoothed sample points.
 * @return 2N doubles; NULL for NULL.
 * Ownership: borrowed from d.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_descriptor_base_points(const amscr_descriptor *d);

/**
 * @brief The N normalized sample points smoothed at scale k (0 <= k < p).
 * @return 2N doubles; NULL for NULL or k out of range.
 * Ownership: borrowed from d.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_descriptor_scale_points(const amscr_descriptor *d, size_t k);

/**
 * @brief The N sample points in input coordinates (before normalization).
 * @return 2N doubles; NULL for NULL.
 * Ownership: borrowed from d.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const double *amscr_descriptor_input_points(const amscr_descriptor *d);

/**
 * @brief The normalization map, input -> normalized frame.
 * @param[out] out_m6  the map.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_descriptor_normalization(const amscr_descriptor *d, double out_m6[6]);

/**
 * @brief The params the descriptor was built with.
 * @return the params; NULL for NULL.
 * Ownership: borrowed from d.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const amscr_params *amscr_descriptor_params(const amscr_descriptor *d);

/* ============================================================================
 * Result of a registration
 * ============================================================================ */

/**
 * @brief Releases a result. Accepts NULL.
 * Ownership: takes r.
 * Thread-safety: exclusive on r.
 * @since 0.1
 */
AMSCR_API void amscr_result_free(amscr_result *r);

/**
 * @brief The distance, invariant to the chosen group, expressed in the target's normalized
 *        frame (dimensionless, >= 0).
 * @return the value; NaN for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_result_distance(const amscr_result *r);

/**
 * @brief The map taking the source onto the target in INPUT coordinates.
 * @param[out] out_m6  the map.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_affine(const amscr_result *r, double out_m6[6]);

/**
 * @brief The same map between the normalized frames.
 * @param[out] out_m6  the map.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_affine_normalized(const amscr_result *r, double out_m6[6]);

/**
 * @brief Start shift: source sample a corresponds to target sample (a + shift) mod N (of the
 *        reversed target when reflected).
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_result_shift(const amscr_result *r);

/**
 * @brief Whether the match used the reversed target (a mirror match).
 * @return non-zero when it did; 0 otherwise and for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int amscr_result_reflected(const amscr_result *r);

/**
 * @brief The method used.
 * @return the method; (amscr_method)-1, which is no method, for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API amscr_method amscr_result_method(const amscr_result *r);

/**
 * @brief Number of scales p.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_result_num_scales(const amscr_result *r);

/**
 * @brief Per-scale residuals L2_k (the paper's eq. 13), p values.
 * @param[out]    out      room for *inout_n values, or NULL to query the count.
 * @param[in,out] inout_n  capacity in, p out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_residuals(const amscr_result *r, double *out, size_t *inout_n);

/**
 * @brief Kept flags (1/0) per scale, p values.
 * @param[out]    out      room for *inout_n values, or NULL to query the count.
 * @param[in,out] inout_n  capacity in, p out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_kept(const amscr_result *r, int *out, size_t *inout_n);

/**
 * @brief Number of kept scales.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_result_num_kept(const amscr_result *r);

/**
 * @brief K chosen by the elbow (2 for binary-em, 0 for acma and amscr).
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_result_k(const amscr_result *r);

/**
 * @brief SSE(K) for K = 1..Kmax of the elbow (no values for acma and amscr).
 * @param[out]    out      room for *inout_n values, or NULL to query the count.
 * @param[in,out] inout_n  capacity in, count out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_sse(const amscr_result *r, double *out, size_t *inout_n);

/**
 * @brief The mixture found by EM: K weights, means and variances, sorted by mean.
 * @param[out] out_weights    K values; may be NULL.
 * @param[out] out_means      K values; may be NULL.
 * @param[out] out_variances  K values; may be NULL.
 * @param[in,out] inout_n  capacity in, K out.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_mixture(const amscr_result *r, double *out_weights,
                                                            double *out_means, double *out_variances,
                                                            size_t *inout_n);

/**
 * @brief The Bayes threshold s0 on the residuals.
 * @return the value; +inf when every scale is kept without a threshold; NaN for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API double amscr_result_threshold(const amscr_result *r);

/**
 * @brief How sure the registration is, in [0, 1]: (1 - a) x min(inlier fraction, overlap) /
 *        (1 + (e / 0.01)^2) / (1 + (s / 0.01)^2), a the larger of amscr_result_ambiguity and
 *        amscr_result_symmetry_ambiguity (when computed), e the forward-backward error (0 when
 *        the check did not run; amscr_result_backward_error), s the map's standard error (0
 *        when not computed; amscr_result_standard_error). Near 0: reject the map, because
 *        another, clearly different map explains the target almost as well (a symmetric shape,
 *        a symmetric shape with a part missing, a fragment too short to place), most source
 *        samples found no target boundary near them, the registered regions overlap little,
 *        the target registered back onto the source on its own does not undo the map, or the
 *        map rests on a few parts of the boundary that disagree with the rest. Reject maps
 *        below 0.25. It flags wrong and imprecise maps, not a bias the whole boundary shares
 *        (such a map can still read high). A partial match (no
 *        region, no way back) reads (1 - ambiguity) x inlier fraction / (1 + (s / 0.01)^2).
 * @return the value; NaN for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_result_confidence(const amscr_result *r);

/**
 * @brief The overlap of the registered shapes as regions, in [0, 1]: the intersection over
 *        union of the areas the two closed contours enclose (even-odd rule), the source's
 *        under the map and the target's, computed from the sampled contours without images.
 *        1 for a perfect match; about 1 - the damaged share of the area when part of the
 *        target is missing or an object touches it; low for a wrong map.
 * @return the value; NaN for NULL, a partial match or open curves (closed 0: an open curve
 *         encloses no region).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API double amscr_result_overlap(const amscr_result *r);

/**
 * @brief The forward-backward error: when the map is confident but less than 85 % of the
 *        shape agrees (the smaller of the inlier fraction and the overlap), the target is
 *        registered onto the source on its own, as amscr_register would with the same
 *        params; the two maps should compose to the identity. The value is the RMS
 *        displacement of the source's samples under the composition, in units of the
 *        source's RMS radius (in the affine-normalized frame): about 0 when the two agree,
 *        0.01 halves the confidence. The map itself does not change.
 * @return the value; NaN when the check did not run (a clean match, an unconfident map, a
 *         partial match, the way back failing) or for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API double amscr_result_backward_error(const amscr_result *r);

/**
 * @brief The map's standard error, from the data: the source's samples fall into floor(sqrt(N))
 *        blocks of consecutive samples along the curve; each block in turn is left out and the
 *        map solved again (one point-to-line step from the reported map, on the other blocks'
 *        samples within 5 % of the target's size of its boundary and within 5 times the median
 *        closest-point distance, the pairs the final fit keeps); the value is the block
 *        jackknife's RMS displacement of the source's samples, in units of the target's RMS
 *        radius (in the affine-normalized frame). A map every part of the boundary agrees on
 *        reads near 0; 0.01 halves the confidence (a map resting on one part that pulls
 *        it, as a thin part traced at low resolution or a touching object does). It measures
 *        how firmly the data fix the map, not its distance from the truth: a bias the whole
 *        boundary shares is not seen. The map itself does not change.
 * @return the value; NaN when not computed (an invariance other than affine, fewer than 9
 *         samples, too few inliers to solve without one block) or for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.18
 */
AMSCR_API double amscr_result_standard_error(const amscr_result *r);

/**
 * @brief The ambiguity near a symmetry of the source, in [0, 1]: when the map is confident but
 *        less than 95 % of the shape agrees (the smaller of the inlier fraction and the
 *        overlap), the source is registered onto itself; each of its own distinct maps that
 *        maps it onto itself as well as the identity does (within the ambiguity's 0.5 % floor: a
 *        symmetry S) gives the alternative map (chosen map) o S, refined on the target; the
 *        value is the largest ratio of the chosen map's cost to such an alternative's, as in
 *        amscr_result_ambiguity (both refined to convergence, the two-way trimmed
 *        closest-point cost). 1: a symmetric turn of the source explains the damaged target
 *        exactly as well (a 4-armed cross with one arm cut), or any other of the
 *        source's own turns, composed and refined alike, fits the target clearly better than
 *        the chosen map (below 0.9 times its cost: the map is not the best fit of a
 *        near-symmetric source); 0: the source has no symmetry, or none fits. The confidence
 *        uses the larger of the two ambiguities.
 * @return the value; NaN when it was not computed (a clean match, an unconfident map, a partial
 *         match) or for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API double amscr_result_symmetry_ambiguity(const amscr_result *r);

/**
 * @brief Ambiguity in [0, 1]: the trimmed closest-point cost of the chosen map divided by that
 *        of the best clearly different candidate map (one moving the source samples by more
 *        than 10 % of the shape's RMS radius on average). 1 = two different maps fit equally
 *        well (symmetry); near 0 = the runner-up is far worse; 0 when no different candidate
 *        was evaluated. Where the "pixel_grid" stage replaced the map by a clearly different
 *        one, at least the ratio of the pixels in which each differs from the small image,
 *        the chosen map's over the first map's (the image decided between them).
 * @return the value; NaN for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_result_ambiguity(const amscr_result *r);

/**
 * @brief Fraction of the source samples whose closest target boundary point lies within
 *        5 % of the target's RMS radius (in the affine-normalized frame) of their image under
 *        the map: 1 for a complete, clean match; about 1 - the missing share when part of the
 *        target's boundary is missing.
 * @return the value; NaN for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API double amscr_result_inlier_fraction(const amscr_result *r);

/**
 * @brief Where the source lies on the target: the boundary parameters, as fractions in
 *        [0, 1) of the target's boundary, of the target points matched to the source's first
 *        and last samples. The parameter runs along the target's samples (its
 *        parametrization) from the target's first input point in its input direction; a
 *        closed target is prepared counter-clockwise (y up), so one given clockwise runs from
 *        its last input point against its input direction. For a
 *        partial match: where the fragment starts and ends (end < start when it wraps; for
 *        a fragment whose points run against the target's direction the fragment covers the
 *        boundary from end to start).
 * @param[out] out_start  where the fragment starts, a fraction.
 * @param[out] out_end    where it ends, a fraction.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_part(const amscr_result *r, double *out_start,
                                                         double *out_end);

/**
 * @brief Dense correspondences: for each of the N source samples, the matched target point,
 *        the closest point of the target's boundary to the sample's image under the map. The
 *        boundary is the target's N samples joined by straight edges: its points lie on the
 *        target's input polygon at the samples, and between them cut its corners by up to
 *        about a sample spacing at a sharp corner (most visible in a partial match, whose
 *        fragment is sampled more densely than the target).
 * @param[out]    out_src_xy  2N values: the source samples, input coordinates (may be NULL).
 * @param[out]    out_param   N values: the target boundary parameters, fractions as in
 *                            amscr_result_part (may be NULL).
 * @param[out]    out_tgt_xy  2N values: the matched target points, input coordinates (may be NULL).
 * @param[in,out] inout_n     capacity in samples in, N out (all outputs NULL: a size query).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r or inout_n, capacity too small).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_correspondences(const amscr_result *r, double *out_src_xy,
                                                                    double *out_param, double *out_tgt_xy,
                                                                    size_t *inout_n);

/**
 * @brief The number of stages of amscr_register's pipeline (the same for every result): in
 *        order despike, search, method, recovery, final_solve, symmetric, polish, order,
 *        even_spacing, alternatives, correspondences, pixel_grid (docs/method.md §12). New
 *        stages may be added in later versions; read them by index with amscr_result_stage.
 * @return the count; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.5
 */
AMSCR_API size_t amscr_result_num_stages(const amscr_result *r);

/**
 * @brief Stage i of the pipeline (0 .. amscr_result_num_stages - 1, in pipeline order): its
 *        name and whether it ran for this result (its condition held: e.g. the recovery only
 *        when many source samples found no target boundary near them, the order and
 *        even-spacing steps only on markedly noisy points, a switched-off stage never;
 *        amscr_params_set_stage). despike ran when either shape was prepared with it.
 * @param[out] out_name  the stage's name, a static string owned by the library (may be NULL).
 * @param[out] out_ran   1 when it ran, else 0 (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r, i out of range).
 * Ownership: *out_name is the library's, valid for the process's lifetime.
 * Thread-safety: const.
 * @since 0.5
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_stage(const amscr_result *r, size_t i, const char **out_name,
                                                          int *out_ran);

/**
 * @brief How many distinct maps fit about as well as the chosen one, the chosen one included
 *        (at least 1). Symmetric shapes have several, each listed once: a square or a 4-armed
 *        cross 4 (its quarter turns), an equilateral triangle 3, a regular 5-pointed star 5; with
 *        reflections on, their mirror maps too (8, 6, 10); an n-fold shape n (2n with
 *        reflections on when it is also mirror-symmetric); an asymmetric shape 1. The
 *        start-point search ranks the lowest three minima of its criterion per orientation (the
 *        reported map is the best of them) and, when those are distinct maps that score alike
 *        (in the search's ranking or the polish's), every further local minimum, up to 12 per
 *        orientation: a shape with more symmetries than that (a circle, an ellipse) lists 12
 *        (24 with reflections).
 *        Alternative 0 is always the reported map (amscr_result_affine). Another map
 *        is listed when it moves the source samples by more than 10 % of the shape's RMS
 *        radius (RMS) from the chosen one and from every map listed before, and its ranking
 *        cost c satisfies (c0 + f) / (c + f) >= 0.75 (c0 the chosen map's cost, f the
 *        ambiguity's floor): then amscr_result_ambiguity >= 0.75 and the confidence is at
 *        most 0.25. The maps come from the registration's ranking of its start points (with
 *        refinement; the polish's re-ranking when it re-ranked): without refinement, for a
 *        partial match, or when the recovery replaced the ranked winner, only the chosen map
 *        is listed.
 * @return the count; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.5
 */
AMSCR_API size_t amscr_result_num_alternatives(const amscr_result *r);

/**
 * @brief Alternative i (0 .. amscr_result_num_alternatives - 1, by ascending cost after the
 *        chosen map): the map in input coordinates, like amscr_result_affine, and its ranking
 *        cost (the trimmed closest-point cost in the normalized frames after a few refinement
 *        or polish steps; costs compare within one result only; NaN for alternative 0 when
 *        no ranking describes the reported map).
 * @param[out] out_m6    {a11, a12, b1, a21, a22, b2} (may be NULL).
 * @param[out] out_cost  the ranking cost (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL r, i out of range).
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.5
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_result_alternative(const amscr_result *r, size_t i, double out_m6[6],
                                                                double *out_cost);

/* ============================================================================
 * Registration
 * ============================================================================ */

/**
 * @brief Registers prepared source `src` onto target `tgt`: h ≈ A f + B.
 * @param[in] p    matching options (method, reflections, kmax, symmetric, refine, invariance,
 *                 partial, polish); NULL = the source descriptor's params. Its N, scales,
 *                 closed flag and parametrization must equal both descriptors'.
 * @param[in] src  prepared source shape.
 * @param[in] tgt  prepared target shape.
 * @param[in,out] ws  workspace or NULL.
 * @param[out] out_result  new result.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, incompatible params or descriptors);
 *         AMSCR_E_DEGENERATE (partial: no placement fits); AMSCR_E_NUMERIC; AMSCR_E_NOMEM.
 * Ownership: caller frees *out_result with amscr_result_free.
 * Thread-safety: reentrant (one workspace per thread).
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_register(const amscr_params *p, const amscr_descriptor *src,
                                                      const amscr_descriptor *tgt, amscr_workspace *ws,
                                                      amscr_result **out_result);

/**
 * @brief Convenience: builds both descriptors with p and registers. NULL p means the
 *        registration preset (amscr_params_new_registration), not the collection defaults.
 * @return as amscr_descriptor_new and amscr_register.
 * Ownership: caller frees *out_result with amscr_result_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_register_contours(const amscr_params *p, const amscr_contour *src,
                                                               const amscr_contour *tgt, amscr_result **out_result);

/**
 * @brief The distance only (the batch path: closed-form 2x2 solves, no result object).
 *        Agrees with amscr_result_distance to rounding.
 * @param[out] out_distance  the distance.
 * @return as amscr_register.
 * Ownership: none.
 * Thread-safety: reentrant (one workspace per thread).
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_distance(const amscr_params *p, const amscr_descriptor *src,
                                                      const amscr_descriptor *tgt, amscr_workspace *ws,
                                                      double *out_distance);

/* ============================================================================
 * Collection (db): many prepared shapes, batch matching, files
 * ============================================================================ */

/**
 * @brief An empty collection.
 * @param[in] p  params (copied; NULL = the defaults of amscr_params_new).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL out); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_db_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_new(const amscr_params *p, amscr_db **out);

/**
 * @brief Releases a collection and its descriptors. Accepts NULL.
 * Ownership: takes db.
 * Thread-safety: exclusive on db.
 * @since 0.1
 */
AMSCR_API void amscr_db_free(amscr_db *db);

/**
 * @brief Prepares a contour with the db's params and stores it with a label.
 * Prefer amscr_db_add_contours (many at once on the db's threads, all or nothing; n = 1 is this call).
 * @param[out] out_index  index of the new shape (may be NULL).
 * @return AMSCR_OK; as amscr_descriptor_new.
 * Ownership: none (the contour is not kept).
 * Thread-safety: exclusive on db.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_add_contour(amscr_db *db, const amscr_contour *c, int32_t label,
                                                            size_t *out_index);

/**
 * @brief Prepares n contours with the db's params on the db's threads and stores them, in
 *        order, after the shapes it has (as n calls of amscr_db_add_contour would).
 * @param contours  n contours (none NULL).
 * @param labels    n labels, or NULL for 0 each.
 * @param n         number of contours (0: nothing to do).
 * @param progress  called with (contours prepared, n) from the calling thread; non-zero
 *                  cancels (may be NULL).
 * @param[out] out_failed  on failure, the index of the first contour, in order, that could not
 *                  be prepared (n when the failure was not one contour's: out of memory,
 *                  cancelled); n on success; may be NULL.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL); as amscr_descriptor_new for the contour
 *         *out_failed names (the error detail starts "contour I: "); AMSCR_E_CANCELLED;
 *         AMSCR_E_NOMEM. All or nothing: on failure no shape is added.
 * Threads: amscr_params_set_num_threads of the db's params (0 = all cores); the shapes are the
 *          same for any thread count.
 * Ownership: none (the contours are not kept).
 * Thread-safety: exclusive on db; the contours are only read.
 * @since 0.10
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_add_contours(amscr_db *db, const amscr_contour *const *contours,
                                                             const int32_t *labels, size_t n,
                                                             amscr_progress_fn progress, void *user,
                                                             size_t *out_failed);

/**
 * @brief Stores a copy of a prepared shape with a label.
 * @param[out] out_index  index of the new shape (may be NULL).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL; N, scales, closed flag or parametrization
 *         differ from the db's); AMSCR_E_NOMEM.
 * Ownership: none (d is copied).
 * Thread-safety: exclusive on db.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_add_descriptor(amscr_db *db, const amscr_descriptor *d,
                                                               int32_t label, size_t *out_index);

/**
 * @brief Number of shapes.
 * @return the value; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API size_t amscr_db_size(const amscr_db *db);

/**
 * @brief Label of shape i.
 * @return the label; 0 for NULL or i out of range.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API int32_t amscr_db_label(const amscr_db *db, size_t i);

/**
 * @brief Descriptor of shape i.
 * @return the descriptor; NULL for NULL or i out of range, or (the collection of an index,
 *         amscr_index_db, whose shapes are decoded when first read) when decoding it failed:
 *         out of memory, or a damaged file (a load checks each shape's samples, not every
 *         level they smooth to), amscr_last_error_detail() saying which.
 * Ownership: borrowed from db.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const amscr_descriptor *amscr_db_descriptor(const amscr_db *db, size_t i);

/**
 * @brief The db's params.
 * @return the params; NULL for NULL.
 * Ownership: borrowed from db.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API const amscr_params *amscr_db_params(const amscr_db *db);

/**
 * @brief 1-vs-many: out_dist[i] = distance(q -> shape i), amscr_db_size values, on the db's
 *        threads; results are bit-identical for any thread count. Batch outputs (this call and
 *        every amscr_db_*_matrix / amscr_db_cross_distances) are computed in place: on failure
 *        or cancellation every element is set to NaN (never a silently partial result); a
 *        call refused before any work (a NULL argument, a size that is not the collection's)
 *        leaves the output untouched.
 * @param[in] progress  optional progress callback (NULL = none).
 * @param[in] user      passed to progress.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, q incompatible with the db); AMSCR_E_CANCELLED;
 *         AMSCR_E_NUMERIC; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_query(const amscr_db *db, const amscr_descriptor *q,
                                                      amscr_progress_fn progress, void *user, double *out_dist);

/**
 * @brief Many-vs-many: out_dist (n x n, row-major) [i*n + j] = distance(shape i -> shape j);
 *        the diagonal is 0. Threads, determinism and NaN on failure as amscr_db_query.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_CANCELLED; AMSCR_E_NUMERIC; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_distance_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                                void *user, double *out_dist);

/**
 * @brief Cross matrix nq x nt: [i*nt + j] = distance(query i -> target j); the params
 *        (threads, method, ...) are those of `queries`. NaN on failure as amscr_db_query.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, incompatible collections); AMSCR_E_CANCELLED;
 *         AMSCR_E_NUMERIC; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_cross_distances(const amscr_db *queries, const amscr_db *targets,
                                                                amscr_progress_fn progress, void *user,
                                                                double *out_dist);

/**
 * @brief The n x n matrix of shape-channel distances (amscr_channel_distance; symmetric, zero
 *        diagonal, d(i, j) for i < j in both cells), on the db's threads; the result does not
 *        depend on the thread count. NaN on failure as amscr_db_query.
 * Prefer amscr_db_retrieval_matrix (channel weight 1, rerank_k 0: this matrix over its median, the same ranking).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, open curves); AMSCR_E_CANCELLED; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_channel_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                               void *user, double *out_dist);

/**
 * @brief The retrieval dissimilarity, n x n: the AMSCR matrix (symmetrized) and the shape
 *        channel, each divided by its median off-diagonal value and mixed by the channel
 *        weight; then, when rerank_k > 0, re-ranked as amscr_rerank_diffusion with its output
 *        halved: values in [0, 1] where row i ranks i's neighbours, 0 for i itself, below 0.5
 *        for the shapes the diffusion reaches from i and 0.5 + half the normalized fused
 *        distance for the others. Without re-ranking: the fused distance (symmetric, zero
 *        diagonal). NaN on failure as amscr_db_query.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, open curves with a channel weight);
 *         AMSCR_E_CANCELLED; AMSCR_E_NUMERIC; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_retrieval_matrix(const amscr_db *db, amscr_progress_fn progress,
                                                                 void *user, double *out_dist);

/**
 * @brief The retrieval matrix with each group held out in turn (leave one group out, e.g. one
 *        ETH-80 object): row i holds shape i's scores as a new query against the collection
 *        without i's group. For each group, the fusion's medians and the re-ranking's kNN graph
 *        are those of the other groups alone (the group's shapes are in no neighbour list but
 *        their own, which holds the shape itself then its nearest among the other groups); the
 *        pair distances are computed once. Row i then ranks the other groups' shapes as
 *        amscr_db_retrieval_matrix does (values in [0, 1] with re-ranking, the fused distance
 *        without), its own group's entries are +infinity and its diagonal 0; amscr_score_nn_groups
 *        on it is the leave-one-group-out accuracy of a collection that never saw the group.
 *        A query does not enter the other shapes' lists here (amscr_index_query_scores lets it
 *        enter those it is nearer to than their K-th neighbour). Cost: the pair matrices once,
 *        then one re-ranking of the n shapes per group (n x n doubles, a few times over).
 * @param[in]  groups  n group ids (at least 2 distinct values; any int32 values).
 * @param[in]  n       the collection's size (amscr_db_size).
 * @param[out] out_dist  n x n, row-major.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n not the size, one group, open curves with a
 *         channel weight); AMSCR_E_LIMIT (n > 65536); AMSCR_E_CANCELLED; AMSCR_E_NUMERIC;
 *         AMSCR_E_NOMEM. NaN on failure as amscr_db_query.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_retrieval_matrix_heldout(const amscr_db *db, const int32_t *groups,
                                                                         size_t n, amscr_progress_fn progress,
                                                                         void *user, double *out_dist);

/**
 * @brief Writes the prepared collection (versioned little-endian binary format with a
 *        checksum, 4 + 8 * (12 + 4N + 2Np) bytes per shape, 1 KB more when the params close
 *        the inner distance's silhouette), whole before it takes its name (as
 *        amscr_contour_write_text); amscr_db_load reads it and every earlier format version.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_IO; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_save(const amscr_db *db, const char *path);

/**
 * @brief Reads a saved collection file of any format version (of an index file: its collection).
 * Prefer amscr_index_load_with for an index file (this call reads only its collection).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_IO; AMSCR_E_LIMIT (file too large);
 *         AMSCR_E_FORMAT (wrong magic, newer version, bad checksum, truncated); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_db_free.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_load(const char *path, amscr_db **out);

/**
 * @brief Serializes the collection (the amscr_db_save format) into a new buffer.
 * @param[out] out_buf  the buffer.
 * @param[out] out_len  its size in bytes.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: caller frees *out_buf with amscr_free.
 * Thread-safety: const.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_save_memory(const amscr_db *db, void **out_buf, size_t *out_len);

/**
 * @brief Deserializes a buffer made by amscr_db_save_memory (or a file's bytes).
 * Prefer amscr_index_load_memory_with for an index's bytes (this call reads only its collection).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_FORMAT (as amscr_db_load); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_db_free; buf is not kept.
 * Thread-safety: reentrant.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_load_memory(const void *buf, size_t len, amscr_db **out);

/**
 * @brief One query's retrieval scores against a collection: the query's row of
 *        amscr_db_retrieval_matrix computed on the collection plus the query (the query last;
 *        its collection columns; to rounding, ~1e-12). With a channel weight strictly between
 *        0 and 1 the fusion uses the collection's medians (those of the kept index's build),
 *        not medians moved by the query.
 * Cost: without re-ranking and fusion, n pair distances. Otherwise the collection keeps an
 *       exact index for its queries: the first such call builds it (n^2 pair distances, as
 *       amscr_index_build with candidates 0), the first call after shapes were added enters
 *       them (n pair distances a new shape), and each call then costs n pair distances and
 *       the re-ranking of one row, as amscr_index_query_scores with candidates 0. A build or
 *       update that was cancelled or failed leaves no kept index: the next call builds it on
 *       every shape (so its medians are the whole collection's).
 * Memory: the kept index (channel and inner features, signature, lists; not a copy of the
 *       shapes), until amscr_db_free.
 * Prefer an amscr_index to save the preparation in a file or to query with a shortlist.
 * The query is scored as a new shape even when it is a member's copy (no member rule:
 * amscr_db_search_retrieval applies it).
 * @param[in]  q  a shape prepared with params compatible with the collection's.
 * @param[in] progress  optional progress callback (may be NULL): the query's pair
 *                      distances; a call that builds the kept index or enters added shapes reports
 *                      that first, as the first of two stages (fractions, see amscr_progress_fn).
 * @param[in] user      passed to progress.
 * @param[out] out_scores  n scores, lower is better (see amscr_db_retrieval_matrix).
 * @param[in]  n  must equal amscr_db_size(db).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n, incompatible params, open curves with a
 *         channel weight); AMSCR_E_STATE (called from the progress callback of a query of the
 *         same collection); AMSCR_E_CANCELLED; AMSCR_E_NOMEM. NaN on failure as amscr_db_query
 *         (never a partial row).
 * Ownership: none.
 * Thread-safety: const: concurrent queries are safe (the kept index is built or extended by
 *       one of them under the collection's lock); runs on the db's threads.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_query_retrieval(const amscr_db *db, const amscr_descriptor *q,
                                                                amscr_progress_fn progress, void *user,
                                                                double *out_scores, size_t n);

/**
 * @brief amscr_db_query_retrieval with the member rule (see amscr_index_search_scores): a
 *        query whose prepared samples equal a shape's of the collection, bit for bit (a member
 *        traced and prepared again), gets that shape's row of amscr_db_retrieval_matrix on the
 *        collection itself (0 against itself; to rounding, ~1e-12), as `amscr search` shows it;
 *        any other query gets amscr_db_query_retrieval's scores. The rule applies when the scores
 *        depend on the collection (rerank_k > 0, or a channel weight strictly between 0 and 1) or
 *        on the pair's order (a channel weight above 0: the channel's distance runs from the lower
 *        index to the higher, so a copy scored as a new shape would get d(j, i) where the
 *        member's row has d(i, j)); without re-ranking the member's row is found by comparing the
 *        query with every shape, no index built. With the AMSCR distance alone (channel weight 0,
 *        no re-ranking) the base distances are the same for a member's copy.
 * Cost, memory, params as amscr_db_query_retrieval; the rule adds the query's signature and
 *       a comparison with its 32 signature-nearest shapes.
 * @param[out] out_scores  n scores, lower is better.
 * @param[in]  n  must equal amscr_db_size(db).
 * @return as amscr_db_query_retrieval.
 * Ownership: none.
 * Thread-safety: as amscr_db_query_retrieval.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_db_search_retrieval(const amscr_db *db, const amscr_descriptor *q,
                                                                 amscr_progress_fn progress, void *user,
                                                                 double *out_scores, size_t n);

/* ============================================================================
 * Retrieval index: a collection with what one-vs-many retrieval needs
 * ============================================================================ */

/** The recommended shortlist size M of an index query and of a large collection's build
 *  (amscr_index_build, amscr_index_query): the M signature-nearest shapes are matched.
 *  @since 0.4 */
#define AMSCR_INDEX_CANDIDATES 256

/** A retrieval index: a collection, each shape's nearest shapes under the retrieval matrix's
 *  base distance (and under the inner distance, when the params give its graph a share of the
 *  re-ranking), shape signatures, optional names (amscr_index_build). @since 0.4 */
typedef struct amscr_index amscr_index;

/**
 * @brief Builds the retrieval index of a collection for the retrieval its params say
 *        (channel weight, re-ranking k and iterations, inner-distance share): a copy of the
 *        shapes with their channel features and signatures, and each shape's K nearest shapes
 *        (K as amscr_params_set_rerank_k) under the base distance of amscr_db_retrieval_matrix
 *        (the fused distance before re-ranking), with the fusion's medians and the largest
 *        distance; when the inner distance's graph has a share
 *        (amscr_params_set_rerank_inner_share), also each shape's inner features and its K
 *        nearest shapes under the inner distance.
 *        candidates 0: every pair is matched and the lists are exact (a query with
 *        candidates 0 then gives exactly amscr_db_query_retrieval's scores).
 *        candidates M > 0, for large collections: each shape's lists are sought among a
 *        shortlist of at most M (at least K - 1) signature-nearest shapes and then among its
 *        neighbours' neighbours, so they may miss a few of the exact nearest; with a channel
 *        weight strictly between 0 and 1 the fusion's medians come from a sample of the
 *        shapes (docs/collections.md, "The index file").
 * Cost: candidates 0: n^2 pair distances; M > 0: O(n (M + K^2)) pair distances.
 * Memory: the index holds a compact copy of the shapes (each shape's input samples
 *         and outline; a prepared shape is recomputed from them, bit for bit, when first
 *         read, e.g. through amscr_index_db, and then kept), the channel features and
 *         signature, the listed neighbours and, with the inner graph, the inner features;
 *         the build's scratch is n^2 doubles with candidates 0, at most 12 n M bytes with M.
 * Threads: amscr_params_set_num_threads of the db's params; the index is the same for any
 *          thread count.
 * @param[in]  db  the collection (copied; may be freed afterwards).
 * @param[in]  candidates  0, or the shortlist size M (AMSCR_INDEX_CANDIDATES is the
 *                         recommended one).
 * @param[in] progress  optional progress callback (may be NULL): two stages, the
 *                      shapes' features, then their lists (fractions, see amscr_progress_fn), from
 *                      the start of the build, so a cancel stops it at any stage (since 0.22.6).
 * @param[in] user      passed to progress.
 * @param[out] out  the new index.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, open curves with a channel weight);
 *         AMSCR_E_LIMIT (2^32 shapes or more); AMSCR_E_CANCELLED; AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_index_free.
 * Thread-safety: const on db.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_build(const amscr_db *db, size_t candidates,
                                                         amscr_progress_fn progress, void *user, amscr_index **out);

/** The largest collection whose index amscr_index_default_candidates builds from every pair:
 *  the exact build's cost grows as n^2, a shortlist build's as n. @since 0.13 */
#define AMSCR_INDEX_EXACT_MAX 2000

/**
 * @brief The candidates argument an index of n shapes is built with by default (the tool's
 *        `amscr index`, Python's amscr.Index): 0 (every pair: exact neighbour lists) for n up to
 *        AMSCR_INDEX_EXACT_MAX shapes, AMSCR_INDEX_CANDIDATES above (O(n M) distances).
 * @param[in] n  the collection's size.
 * @return 0 or AMSCR_INDEX_CANDIDATES; never fails.
 * Ownership: none.
 * Thread-safety: pure.
 * @since 0.13
 */
AMSCR_API size_t amscr_index_default_candidates(size_t n);

/**
 * @brief Adds the shapes of a collection (labels kept, unnamed) to the index: each new shape's
 *        list from its base distances to every shape (or to its M signature-nearest, for an
 *        index built with candidates), and the older lists it enters; runs on the threads of
 *        the index's params. With candidates 0 and a channel weight of 0 or 1 the result
 *        equals a rebuild's; with a channel weight strictly between 0 and 1 the fusion keeps
 *        the medians of the build. An index of fewer shapes than twice its re-ranking k,
 *        whose lists' length K grows with its size, is built again on its shapes and the new
 *        ones instead (the same index as amscr_index_build of them all, its names, groups and
 *        class names kept); on failure it
 *        is left as it was.
 * @param[in] shapes  prepared with exactly the index's params (threads aside).
 * @param[in] progress  optional progress callback (may be NULL): two stages, the new
 *                      shapes' features, then their lists (since 0.22.6; fractions, see
 *                      amscr_progress_fn).
 * @param[in] user      passed to progress.
 * @return AMSCR_OK (also for no shapes: no work, no report); AMSCR_E_INVALID_ARG (NULL;
 *         params that differ: the detail names the option); AMSCR_E_LIMIT; AMSCR_E_CANCELLED;
 *         AMSCR_E_NOMEM. After AMSCR_E_CANCELLED or AMSCR_E_NOMEM the index holds the shapes
 *         but not all their lists: free it; every other call on it returns AMSCR_E_STATE.
 * Ownership: none (shapes is copied).
 * Thread-safety: exclusive on x.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_add(amscr_index *x, const amscr_db *shapes,
                                                       amscr_progress_fn progress, void *user);

/**
 * @brief The query's retrieval scores against every shape of the index: the query's row of
 *        amscr_db_retrieval_matrix on the collection plus the query, from the stored lists (the
 *        query's K nearest entering them). candidates 0 (or >= n) matches the query with every
 *        shape: with an index built with candidates 0 and a channel weight of 0 or 1 the scores
 *        equal amscr_db_query_retrieval's (to rounding, ~1e-12); with a channel weight strictly
 *        between 0 and 1 the fusion uses the build's medians. candidates M matches the query
 *        with its M signature-nearest shapes only (at least K - 1); the others get +inf unless
 *        the re-ranking reaches them. An index built with candidates from 20,000 shapes keeps
 *        its build's coarse quantizer of the signatures (kept in its file): its
 *        queries with candidates M take the M nearest among the shapes of the quantizer's
 *        clusters nearest the query (a few of the M signature-nearest may be missed) and drop
 *        the re-ranking diffusion's entries below 1e-3 of the largest at every step
 *        (docs/collections.md, "Queries at scale"). The query is scored as a new shape even when it is a
 *        member's copy (no member rule: amscr_index_search_scores applies it).
 * @param[in]  q  a shape prepared with params compatible with the index's.
 * @param[out] out_scores  n scores, lower is better.
 * @param[in]  n  must equal amscr_index_size(x).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n, incompatible params); AMSCR_E_STATE (an
 *         index a failed amscr_index_add left incomplete, as for every index call);
 *         AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const; runs on the params' threads.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_query_scores(const amscr_index *x, const amscr_descriptor *q,
                                                                size_t candidates, double *out_scores, size_t n);

/**
 * @brief The `top` best shapes of amscr_index_query_scores, best first (ties by index).
 * @param[out] out_idx     room for `top` entries.
 * @param[out] out_scores  room for `top` entries.
 * @param[out] out_count  min(top, n) entries written.
 * @return as amscr_index_query_scores.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_query(const amscr_index *x, const amscr_descriptor *q,
                                                         size_t candidates, size_t top, size_t *out_idx,
                                                         double *out_scores, size_t *out_count);

/**
 * @brief Row i of the collection's own retrieval matrix (amscr_db_retrieval_matrix of the
 *        indexed collection; 0 for shape i itself): what a search with a member of the
 *        collection as the query shows. candidates as amscr_index_query_scores.
 * @param[out] out_scores  n scores.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, i >= n, n); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_member_scores(const amscr_index *x, size_t i, size_t candidates,
                                                                 double *out_scores, size_t n);

/**
 * @brief The member rule: the shape of the index whose prepared samples are the query's, bit
 *        for bit (the same number of samples and the same sample points in input coordinates,
 *        amscr_descriptor_input_points), e.g. a file of the collection traced and prepared
 *        again with the index's params; the lowest index when the collection holds copies.
 *        The search calls (amscr_index_search_scores, amscr_index_search,
 *        amscr_db_search_retrieval; the tool's `amscr search`) score such a query as that
 *        shape: its row of the collection's retrieval matrix (amscr_index_member_scores).
 *        The query calls (amscr_index_query_scores, amscr_index_query,
 *        amscr_db_query_retrieval) never apply it: they score every query as a new shape.
 * Cost: the query's signature and a comparison with its 32 signature-nearest shapes (a lazy
 *       load decodes at most those); no pair distance.
 * @param[in]  q  a shape prepared with params compatible with the index's.
 * @param[out] out_i  the shape's index, or SIZE_MAX when no shape has the query's samples.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, incompatible params); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_find_member(const amscr_index *x, const amscr_descriptor *q,
                                                               size_t *out_i);

/**
 * @brief The query's scores as a search shows them: amscr_index_member_scores of the shape
 *        amscr_index_find_member finds (the member rule), else amscr_index_query_scores. The rule
 *        applies when the scores depend on the collection (rerank_k > 0, or a channel weight
 *        strictly between 0 and 1) or on the pair's order (a channel weight above 0: the
 *        channel's distance runs from the lower index to the higher); the AMSCR distance alone
 *        (channel weight 0 without re-ranking) is amscr_index_query_scores' for every query. So a
 *        member's copy ranks
 *        the member first at 0 and the others as the member's own row, with every face (C, the
 *        tool, Python's Index.query and Collection.query) giving the same scores.
 * @param[in]  q  a shape prepared with params compatible with the index's.
 * @param[in]  candidates  as amscr_index_query_scores.
 * @param[out] out_scores  n scores, lower is better.
 * @param[in]  n  must equal amscr_index_size(x).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n, incompatible params); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const; runs on the params' threads.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_search_scores(const amscr_index *x, const amscr_descriptor *q,
                                                                 size_t candidates, double *out_scores, size_t n);

/**
 * @brief The `top` best shapes of amscr_index_search_scores, best first (ties by index).
 * @param[out] out_idx     room for `top` entries.
 * @param[out] out_scores  room for `top` entries.
 * @param[out] out_count  min(top, n) entries written.
 * @return as amscr_index_search_scores.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_search(const amscr_index *x, const amscr_descriptor *q,
                                                          size_t candidates, size_t top, size_t *out_idx,
                                                          double *out_scores, size_t *out_count);

/**
 * @brief Shapes in the index (0 for NULL).
 * Ownership: none. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API size_t amscr_index_size(const amscr_index *x);

/**
 * @brief The index's collection (its shapes, labels and params).
 * @return borrowed; NULL for NULL. Valid until the index changes or is freed.
 * Ownership: the index. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API const amscr_db *amscr_index_db(const amscr_index *x);

/**
 * @brief Label of shape i (0 for NULL or i out of range).
 * Ownership: none. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API int32_t amscr_index_label(const amscr_index *x, size_t i);

/**
 * @brief Neighbours stored a shape: K at the build (amscr_index_build; 0 for NULL).
 * Ownership: none. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API size_t amscr_index_neighbours(const amscr_index *x);

/**
 * @brief Sets (NULL: clears) the name of shape i, e.g. its file name; saved with the index.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL x, i out of range); AMSCR_E_NOMEM.
 * Ownership: name is copied. Thread-safety: exclusive on x.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_set_name(amscr_index *x, size_t i, const char *name);

/**
 * @brief The name of shape i, or NULL (unnamed, NULL x, i out of range).
 * Ownership: the index; valid until the name changes or the index is freed.
 * Thread-safety: const.
 * @since 0.4
 */
AMSCR_API const char *amscr_index_name(const amscr_index *x, size_t i);

/**
 * @brief Sets (NULL: clears) the name of class `label` (0..1000000); saved with the index.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: name is copied. Thread-safety: exclusive on x.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_set_class_name(amscr_index *x, int32_t label, const char *name);

/**
 * @brief The name of class `label`, or NULL (unnamed, NULL x).
 * Ownership: the index; valid until the name changes or the index is freed.
 * Thread-safety: const.
 * @since 0.4
 */
AMSCR_API const char *amscr_index_class_name(const amscr_index *x, int32_t label);

/**
 * @brief Sets (NULL: clears) the group of shape i: the object or source it shows (e.g. the
 *        object of a set of views), for protocols that leave one group out; saved with the
 *        index. Shapes added later have none.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL x, i out of range); AMSCR_E_NOMEM.
 * Ownership: group is copied. Thread-safety: exclusive on x.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_set_group(amscr_index *x, size_t i, const char *group);

/**
 * @brief The group of shape i, or NULL (none, NULL x, i out of range).
 * Ownership: the index; valid until the group changes or the index is freed.
 * Thread-safety: const.
 * @since 0.4
 */
AMSCR_API const char *amscr_index_group(const amscr_index *x, size_t i);

/**
 * @brief Writes the index, whole before it takes its name (as amscr_contour_write_text): the
 *        collection file format (amscr_db_load of it gives the collection) with an index
 *        section holding the lists, each shape's channel features (so a load does not rebuild
 *        them) and, with the inner graph, each shape's inner features and its lists;
 *        amscr_index_load_with reads it and every earlier format version (docs/collections.md).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_IO; AMSCR_E_NOMEM.
 * Ownership: none. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_save(const amscr_index *x, const char *path);

/**
 * @brief Serializes the index (the amscr_index_save format) into a new buffer.
 * @param[out] out_buf  the buffer.
 * @param[out] out_len  its size in bytes.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: caller frees *out_buf with amscr_free. Thread-safety: const.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_save_memory(const amscr_index *x, void **out_buf,
                                                               size_t *out_len);

/**
 * @brief Reads an index file: amscr_index_load_with with flags 0.
 * Prefer amscr_index_load_with (the same with flags 0; AMSCR_INDEX_LAZY for a few queries).
 * @return as amscr_index_load_with.
 * Ownership: caller frees *out with amscr_index_free.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_load(const char *path, amscr_index **out);

/**
 * @brief Deserializes an index from memory: amscr_index_load_memory_with with flags 0.
 * Prefer amscr_index_load_memory_with (the same with flags 0).
 * @return as amscr_index_load_memory_with.
 * Ownership: caller frees *out with amscr_index_free; buf is not kept.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_load_memory(const void *buf, size_t len, amscr_index **out);

/** Load flag: the shapes' channel features are not made ready at load; each query computes
 *  those of the candidates it matches (for one or a few queries a load, e.g. a command-line
 *  search); without it a load makes every shape's ready once, on the params' threads (for many
 *  queries: it costs an FFT a shape, or the features of a file without them). A lazy load
 *  of a file (amscr_index_load_with) also maps the file and decodes each prepared shape when it
 *  is first read (every shape is still checked at load, so the same files are refused). Scores
 *  are the same either way. @since 0.4 */
#define AMSCR_INDEX_LAZY 1u

/**
 * @brief Reads an index file (amscr_index_save) with flags 0 or AMSCR_INDEX_LAZY. The file is
 *        mapped read-only where the system can map it, while it is read (for the index's
 *        lifetime with AMSCR_INDEX_LAZY): replace an index file by renaming, as
 *        amscr_index_save does, not by rewriting it in place. Every earlier format version
 *        loads; a file that lacks the channel features has them built from its shapes. A
 *        collection file without an index (amscr_db_save) and index files of an older,
 *        separate format are AMSCR_E_FORMAT with a detail saying to build the index again.
 * Memory: about 16.5 KB a shape once loaded (20.5 KB with AMSCR_INDEX_LAZY; the retrieval
 *         preset at N = 128, mpeg7-dev's 700 shapes). With the shape channel alone (channel
 *         weight 1, the retrieval preset) queries and searches, of members' copies too, read
 *         the shapes without keeping them: a long-running search service stays at that size.
 *         A shape whose prepared form is read (each candidate of a query with a channel weight
 *         below 1, where the AMSCR distance needs it; amscr_db_descriptor of amscr_index_db) is
 *         decoded and kept until amscr_index_free, about 36 KB more a shape.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, an unknown flag); AMSCR_E_IO; AMSCR_E_LIMIT;
 *         AMSCR_E_FORMAT (wrong magic, version, checksum, truncated or inconsistent
 *         content); AMSCR_E_NOMEM.
 * Ownership: caller frees *out with amscr_index_free.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_load_with(const char *path, unsigned flags, amscr_index **out);

/**
 * @brief Deserializes a buffer made by amscr_index_save_memory (or an index file's bytes) with
 *        flags 0 or AMSCR_INDEX_LAZY; formats as amscr_index_load_with.
 * @return as amscr_index_load_with, without AMSCR_E_IO.
 * Ownership: caller frees *out with amscr_index_free; buf is not kept.
 * Thread-safety: reentrant.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_load_memory_with(const void *buf, size_t len, unsigned flags,
                                                                    amscr_index **out);

/**
 * @brief Frees an index. Accepts NULL.
 * Ownership: x. Thread-safety: exclusive on x.
 * @since 0.4
 */
AMSCR_API void amscr_index_free(amscr_index *x);

/* ============================================================================
 * Retrieval: shape channel, scores, re-ranking
 * (pure functions on descriptors, distance matrices and labels)
 * ============================================================================ */

/**
 * @brief The shape channel's distance of two prepared closed shapes: height functions (Wang
 *        et al., Pattern Recognition Letters 2012) in the channel's frame, compared by an
 *        order-preserving dynamic-programming correspondence in a band around the best cyclic
 *        shift (and mirror image when reflections are on). >= 0, 0 for a shape against
 *        itself, invariant to the channel's group. d(a, b) and d(b, a) may differ slightly.
 * @param[in] p  channel settings (NULL = a's params).
 * @param[out] out_dist  the distance.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, open curves, different N); AMSCR_E_DEGENERATE;
 *         AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: reentrant.
 * @since 0.2
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_channel_distance(const amscr_params *p, const amscr_descriptor *a,
                                                              const amscr_descriptor *b, double *out_dist);

/**
 * @brief Indices of the k smallest of n distances, ascending, ties broken by lower index.
 * @param[in]  exclude  an index to skip, or SIZE_MAX for none.
 * @param[in]  k        <= n (minus one if an index is excluded).
 * @param[out] out_indices  k indices.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_topk(const double *dist, size_t n, size_t k, size_t exclude,
                                                  size_t *out_indices);

/**
 * @brief Bull's eye score (MPEG-7): for each query i, count shapes of its class among its
 *        `window` nearest (itself included; ties by lower index); the total is divided by
 *        the sum over queries of their class size Nc. window 0 means twice the query's
 *        class size.
 * @param[in]  dist    n x n row-major (row i = distances from query i).
 * @param[in]  labels  n labels.
 * @param[out] out_score  fraction in [0, 1].
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_bullseye(const double *dist, size_t n, const int32_t *labels,
                                                            size_t window, double *out_score);

/**
 * @brief Top-k table (Kimia): out_counts[r] (r = 0..kmax-1) = number of queries whose
 *        (r+1)-th nearest neighbour (query excluded, ties by index) has the query's label.
 * @param[in] dist    as amscr_score_bullseye.
 * @param[in] n       as amscr_score_bullseye.
 * @param[in] labels  as amscr_score_bullseye.
 * @param[out] out_counts  kmax counts.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_topk_table(const double *dist, size_t n, const int32_t *labels,
                                                              size_t kmax, size_t *out_counts);

/**
 * @brief Leave-one-out 1-NN accuracy (query excluded, ties by index).
 * @param[in] dist    as amscr_score_bullseye.
 * @param[in] n       as amscr_score_bullseye.
 * @param[in] labels  as amscr_score_bullseye.
 * @param[out] out_accuracy  fraction in [0, 1].
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_accuracy(const double *dist, size_t n,
                                                               const int32_t *labels, double *out_accuracy);

/**
 * @brief Train/test 1-NN accuracy.
 * @param[in]  dist  ntest x ntrain row-major.
 * @param[in] test_labels   ntest labels.
 * @param[in] train_labels  ntrain labels.
 * @param[out] out_accuracy  fraction in [0, 1].
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_split(const double *dist, size_t ntest, size_t ntrain,
                                                            const int32_t *test_labels,
                                                            const int32_t *train_labels, double *out_accuracy);

/*
 * Evaluation protocols (docs/collections.md). Classes are the distinct label values in
 * ascending order (amscr_score_classes lists them); every per-class output below has one
 * entry per class in that order, and its length `nclasses` is checked against the labels.
 * Ranking as above: distance ascending, ties to the lower index; +inf is allowed, NaN and
 * -inf are AMSCR_E_INVALID_ARG.
 */

/**
 * @brief The distinct labels of n items, ascending, and how many items carry each: the class
 *        order of the per-class outputs of the protocols (also the group order of
 *        amscr_score_nn_groups when given the groups).
 * @param[in]  labels  n labels, n >= 1.
 * @param[out] out_classes  room for *inout_nclasses labels, or NULL.
 * @param[out] out_sizes    room for *inout_nclasses counts, or NULL.
 * @param[in,out] inout_nclasses  capacity in, number of classes out (both outputs NULL: a
 *        size query).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL labels or inout_nclasses, n = 0, capacity too
 *         small); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_classes(const int32_t *labels, size_t n, int32_t *out_classes,
                                                           size_t *out_sizes, size_t *inout_nclasses);

/**
 * @brief Per-class leave-one-out scores. For class c of size Nc: out_bullseye[c] = the shapes
 *        of class c among the min(2 Nc, n) nearest of each of its queries (itself included),
 *        summed over its queries and divided by Nc^2 (amscr_score_bullseye restricted to the
 *        class); out_nn_accuracy[c] = the fraction of its queries whose nearest other shape
 *        is of class c.
 * @param[in]  dist      n x n row-major (row i = distances from query i), n >= 2.
 * @param[in]  labels    n labels.
 * @param[in]  nclasses  the number of distinct labels (amscr_score_classes).
 * @param[out] out_bullseye     nclasses fractions; may be NULL if out_nn_accuracy is not.
 * @param[out] out_nn_accuracy  nclasses fractions; may be NULL if out_bullseye is not.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n < 2, wrong nclasses, NaN or -inf);
 *         AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_per_class(const double *dist, size_t n, const int32_t *labels,
                                                             size_t nclasses, double *out_bullseye,
                                                             double *out_nn_accuracy);

/**
 * @brief Seeded per-class random split: in each of `splits` splits, `train` shapes of every
 *        class are the training set and the others are classified by 1-NN against it; the
 *        mean accuracy over the splits and its sample standard deviation. The draw: a
 *        splitmix64 generator seeded with `seed` runs on over the splits; in each split,
 *        class by class (ascending label), a partial Fisher-Yates shuffle of the class's
 *        members (in index order) takes `train` of them, each step swapping position t with
 *        t + (next value mod (Nc - t)). The same seed gives the same splits on every platform.
 * @param[in]  dist      n x n row-major, n >= 2.
 * @param[in]  labels    n labels.
 * @param[in]  train     training shapes per class: 1 <= train < the smallest class size.
 * @param[in]  splits    >= 1.
 * @param[in]  seed      the generator's seed.
 * @param[in]  nclasses  the number of distinct labels; read only with out_class_accuracy.
 * @param[out] out_mean  mean accuracy over the splits, a fraction in [0, 1].
 * @param[out] out_std   sample standard deviation of the splits' accuracies (0 for one
 *             split), or NULL.
 * @param[out] out_accuracies  `splits` accuracies, one per split, or NULL.
 * @param[out] out_class_accuracy  nclasses values: each class's accuracy averaged over the
 *             splits, or NULL.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n < 2, train or splits 0, train >= a class's
 *         size, wrong nclasses, NaN or -inf); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_random_split(const double *dist, size_t n,
                                                                   const int32_t *labels, size_t train,
                                                                   size_t splits, uint64_t seed, size_t nclasses,
                                                                   double *out_mean, double *out_std,
                                                                   double *out_accuracies,
                                                                   double *out_class_accuracy);

/**
 * @brief Leave one group out: the shapes of each group are classified by 1-NN against every
 *        shape of the other groups (a query never matches a shape of its own group).
 * @param[in]  dist      n x n row-major, n >= 2.
 * @param[in]  labels    n class labels.
 * @param[in]  groups    n group ids (at least 2 distinct); groups are ordered like classes
 *             (amscr_score_classes on the groups).
 * @param[in]  ngroups   the number of distinct groups; read only with out_group_accuracy.
 * @param[in]  nclasses  the number of distinct labels; read only with out_class_accuracy.
 * @param[out] out_accuracy  the fraction of all n shapes classified right.
 * @param[out] out_group_accuracy  ngroups fractions (each group's shapes), or NULL.
 * @param[out] out_class_accuracy  nclasses fractions (each class's shapes), or NULL.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n < 2, one group, wrong ngroups or nclasses,
 *         NaN or -inf); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_nn_groups(const double *dist, size_t n, const int32_t *labels,
                                                             const int32_t *groups, size_t ngroups,
                                                             size_t nclasses, double *out_accuracy,
                                                             double *out_group_accuracy,
                                                             double *out_class_accuracy);

/**
 * @brief Mean interpolated precision at recall levels l / (nlevels - 1), l = 0..nlevels-1:
 *        each shape queries the others (itself excluded), the other shapes of its class are
 *        the relevant ones, and its precision at a level is the best precision reached at any
 *        recall >= the level; averaged over the queries whose class has another shape (NaN
 *        at every level when there is none).
 * @param[in]  dist     n x n row-major, n >= 2.
 * @param[in]  labels   n labels.
 * @param[in]  nlevels  >= 2 (21: recall 0, 0.05, ..., 1).
 * @param[out] out_precision  nlevels fractions.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n < 2, nlevels < 2, NaN or -inf);
 *         AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.4
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_score_precision_recall(const double *dist, size_t n,
                                                                    const int32_t *labels, size_t nlevels,
                                                                    double *out_precision);

/* ============================================================================
 * An index split in shards: what amscr.distributed builds on (docs/collections.md,
 * "An index in shards"). A collection of n shapes is cut into contiguous blocks; each block is an
 * ordinary index (a shard, whose shapes carry their features); the whole collection's neighbour
 * lists are computed from amscr_index_pair_distances over every pair of blocks (or, for a
 * shortlist build, from amscr_index_pair_distances_at over the pairs of the global signature
 * shortlists, amscr_signature_shortlists) and held, without any shape, by an amscr_index_graph.
 * A query's distances to every shard's shapes (amscr_index_pair_distances with qpos SIZE_MAX),
 * given to amscr_index_graph_scores, are the scores of the single index of the whole collection
 * built with candidates 0 and queried with candidates 0 (to rounding), for a channel weight of 0
 * or 1; the same holds with a shortlist M for build and query alike.
 * ============================================================================ */

/** The neighbour lists of a whole collection without its shapes, and its largest distances:
 *  turns a query's distances into its retrieval scores. @since 0.14 */
typedef struct amscr_index_graph amscr_index_graph;

/**
 * @brief The base distance (the retrieval matrix's distance before re-ranking, as an index
 *        lists it) and the inner distance of q to shapes first.. of x, each pair computed as the
 *        cell of the two in the matrix of one collection (the lower index first): shapes of x
 *        below qpos come before q, the others after it. qpos SIZE_MAX: q is a query (after
 *        every shape, as amscr_index_query_scores with candidates 0 matches it); 0: q comes
 *        before every shape of x (x's block lies after q's in the whole collection); i: q is
 *        shape i of x itself (its own distance is 0; first i + 1 gives the pairs of a block
 *        with itself once).
 * @param[in]  x  an index (a shard), with a channel weight of 0 or 1 (a weight strictly between
 *                uses x's own medians: the whole collection's differ).
 * @param[in]  q  a shape prepared with params compatible with x's.
 * @param[in]  first  the first shape of x matched (0: all).
 * @param[out] out_base  n base distances (of shapes first..first+n-1).
 * @param[out] out_inner  n inner distances, or NULL; zeros when the params give the inner graph
 *                        no share.
 * @param[in]  n  must equal amscr_index_size(x) - first.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, first or n, incompatible params); AMSCR_E_NOMEM.
 * Cost: n pair distances on the params' threads.
 * Ownership: none.
 * Thread-safety: const on x.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_pair_distances(const amscr_index *x, const amscr_descriptor *q,
                                                                  size_t qpos, size_t first, double *out_base,
                                                                  double *out_inner, size_t n);

/**
 * @brief The widths of a collection's neighbour lists: *out_k neighbours a shape under the base
 *        distance (the re-ranking's k for n shapes, at most n / 2; 0 without re-ranking) and
 *        *out_k2 under the inner distance (*out_k when the params give the inner graph a share,
 *        else 0). Either pointer may be NULL; p NULL gives 0 and 0.
 * @param[in]  p  the collection's params.
 * @param[in]  n  the collection's size.
 * Ownership: none.
 * Thread-safety: pure.
 * @since 0.14
 */
AMSCR_API void amscr_index_graph_widths(const amscr_params *p, size_t n, size_t *out_k, size_t *out_k2);

/**
 * @brief A graph of n shapes from lists computed elsewhere (amscr_index_pair_distances over
 *        every pair of blocks): row i of each list is shape i itself at distance 0, then its
 *        k - 1 nearest other shapes by (distance, index), as amscr_index_build with candidates 0
 *        lists them; dmax and dmax2 the largest base and inner distance of the collection.
 * @param[in] p  the collection's params (copied).
 * @param[in] nb_idx   n x k (amscr_index_graph_widths), row-major.
 * @param[in] nb_dist  n x k, row-major.
 * @param[in] in_idx   n x k2, or NULL when k2 is 0.
 * @param[in] in_dist  n x k2, or NULL when k2 is 0.
 * @param[out] out  the new graph.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL; a row not itself first, an index >= n, a distance
 *         negative or not finite: the detail names the row); AMSCR_E_LIMIT (2^32 shapes or
 *         more); AMSCR_E_NOMEM.
 * Memory: about (k + k2) * 28 bytes a shape.
 * Ownership: caller frees *out with amscr_index_graph_free; the lists are copied.
 * Thread-safety: pure.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_graph_new(const amscr_params *p, size_t n, const uint32_t *nb_idx,
                                                             const double *nb_dist, const uint32_t *in_idx,
                                                             const double *in_dist, double dmax, double dmax2,
                                                             amscr_index_graph **out);

/**
 * @brief A query's retrieval scores against the graph's n shapes from its distances to the
 *        candidates cand[0..m-1] (strictly ascending; the others score +inf unless the
 *        re-ranking reaches them): the computation of amscr_index_query_scores after its
 *        matching. With every shape a candidate and the distances of amscr_index_pair_distances
 *        (qpos SIZE_MAX), the scores of the single index (see above).
 * @param[in] dq   m base distances (finite, >= 0).
 * @param[in] dq2  m inner distances, or NULL when the graph's k2 is 0.
 * @param[out] out_scores  n scores, lower is better.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n, candidates not ascending or out of range, a
 *         distance not finite or negative); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const on g; runs on the calling thread.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_graph_scores(const amscr_index_graph *g, const size_t *cand,
                                                                const double *dq, const double *dq2, size_t m,
                                                                double *out_scores, size_t n);

/**
 * @brief The scores of shape i of the graph's collection as the query (the member rule:
 *        amscr_index_member_scores of the single index): its base distances dq to candidates
 *        cand[0..m-1] (strictly ascending, i left out; every other shape, or its M
 *        signature-nearest for candidates M), each computed as the pair's cell
 *        (amscr_index_pair_distances_at with qpos i relative to each shard: SIZE_MAX for a shard
 *        before i's, 0 after, i's own index in its shard).
 * @param[out] out_scores  n scores (its own 0).
 * @param[in]  n  must equal the graph's size.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, i or n, candidates not ascending, out of range or
 *         i, a distance not finite and >= 0); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_graph_member_scores(const amscr_index_graph *g, size_t i,
                                                                       const size_t *cand, const double *dq, size_t m,
                                                                       double *out_scores, size_t n);

/**
 * @brief The graph's number of shapes.
 * @return n; 0 for NULL.
 * Ownership: none.
 * Thread-safety: const.
 * @since 0.14
 */
AMSCR_API size_t amscr_index_graph_size(const amscr_index_graph *g);

/**
 * @brief Frees a graph.
 * @param[in] g  the graph, or NULL (a no-op).
 * Ownership: takes g.
 * Thread-safety: exclusive on g.
 * @since 0.14
 */
AMSCR_API void amscr_index_graph_free(amscr_index_graph *g);

/**
 * @brief The base and inner distances of q to the chosen shapes cand[0..m-1] of x (a shard),
 *        each pair computed as amscr_index_pair_distances computes it (qpos as there): the
 *        pairs of a shortlist build in shards.
 * @param[in]  cand  m shape indices of x, strictly ascending.
 * @param[out] out_base   m distances; may be NULL (not computed), not with out_inner too
 *                        when m > 0.
 * @param[out] out_inner  m distances; may be NULL (not computed), not with out_base too when
 *                        m > 0; zeros when the params give the inner graph no share.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, cand not ascending or out of range, incompatible
 *         params); AMSCR_E_NOMEM.
 * Cost: m pair distances on the params' threads.
 * Ownership: none.
 * Thread-safety: const on x.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_pair_distances_at(const amscr_index *x, const amscr_descriptor *q,
                                                                     size_t qpos, const size_t *cand, size_t m,
                                                                     double *out_base, double *out_inner);

/**
 * @brief The floats of one shape signature (the compact summary whose distances choose an
 *        index's shortlists; amscr_index_signatures, amscr_shape_signature).
 * @return the count (fixed for a library version).
 * Ownership: none.
 * Thread-safety: pure.
 * @since 0.14
 */
AMSCR_API size_t amscr_signature_size(void);

/**
 * @brief The stored signatures of x's shapes, in order (amscr_signature_size() floats each): each
 *        shape's amscr_shape_signature held in 16 bits (its values rounded to steps of at most
 *        1/32768 of its largest), the values its shortlists are sought by.
 * @param[out] out  n floats.
 * @param[in]  n  must equal amscr_index_size(x) * amscr_signature_size().
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n).
 * Ownership: none.
 * Thread-safety: const on x.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_signatures(const amscr_index *x, float *out, size_t n);

/** Smallest exponent of a packed signature (amscr_index_signatures_packed). @since 0.22 */
#define AMSCR_SIGNATURE_EXP_MIN (-126)
/** Largest exponent of a packed signature: q * 2^e stays finite in float for every 16-bit q.
 *  @since 0.22 */
#define AMSCR_SIGNATURE_EXP_MAX 112

/**
 * @brief The stored signatures of x's shapes as the index holds them: each shape's
 *        amscr_signature_size() 16-bit values q and one exponent e, value t being q[t] * 2^e
 *        (exactly amscr_index_signatures' float). The shortlists of packed signatures:
 *        amscr_signature_shortlists_packed.
 * @param[out] out_q  n * amscr_signature_size() values.
 * @param[out] out_e  n exponents, each from AMSCR_SIGNATURE_EXP_MIN to AMSCR_SIGNATURE_EXP_MAX.
 * @param[in]  n  must equal amscr_index_size(x) (the shapes).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n).
 * Ownership: none.
 * Thread-safety: const on x.
 * @since 0.22
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_index_signatures_packed(const amscr_index *x, uint16_t *out_q,
                                                                     int32_t *out_e, size_t n);

/**
 * @brief A prepared shape's signature, as an index computes a new query's (a member's is the one
 *        it stores: amscr_index_signatures).
 * @param[out] out  n floats.
 * @param[in]  n  must equal amscr_signature_size().
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, n).
 * Ownership: none.
 * Thread-safety: const on q.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_shape_signature(const amscr_descriptor *q, float *out, size_t n);

/**
 * @brief The shortlist width M' an index of n shapes built with `candidates` (amscr_index_build)
 *        seeks each shape's neighbours in: 0 when that build matches every pair (candidates 0
 *        or >= n - 1), else at most the build's cap (192) and at least K - 1.
 * @param[in] p  the collection's params (NULL gives 0).
 * @return M' or 0; never fails.
 * Ownership: none.
 * Thread-safety: pure.
 * @since 0.14
 */
AMSCR_API size_t amscr_index_build_shortlist(const amscr_params *p, size_t n, size_t candidates);

/**
 * @brief Shortlists by signature: for each query r (signature qsigs + r * amscr_signature_size()),
 *        the m shapes of sigs (n signatures) whose signatures are nearest, by (distance, index),
 *        ascending by index, leaving out shape first + r (first SIZE_MAX: none left out, e.g. a
 *        new query); exactly the shortlists of amscr_index_build and amscr_index_query_scores
 *        (below the 20,000 shapes from which a build and its queries find them through a coarse
 *        quantizer).
 * @param[in]  sigs  n signatures (amscr_index_signatures of the shards, concatenated).
 * @param[in]  qsigs  nq signatures (a block of sigs for a build's rows, first its first shape).
 * @param[in]  m  1 .. n (n - 1 when first is not SIZE_MAX).
 * @param[in]  threads  as amscr_params_set_num_threads (0: every core).
 * @param[out] out  nq x m shape indices.
 * @param[in]  out_len  must equal nq * m.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, m, first, out_len, a signature not finite);
 *         AMSCR_E_NOMEM.
 * Cost: O(nq n) signature bounds, then a few full signature distances a query.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.14
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_signature_shortlists(const float *sigs, size_t n, const float *qsigs,
                                                                  size_t nq, size_t first, size_t m, unsigned threads,
                                                                  size_t *out, size_t out_len);

/**
 * @brief amscr_signature_shortlists over packed signatures (amscr_index_signatures_packed of the
 *        shards, concatenated: n shapes' q, n * amscr_signature_size() values, and their n
 *        exponents e): exactly the shortlists of their floats.
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG (NULL, m, first, out_len, an exponent out of range, a
 *         query not finite); AMSCR_E_NOMEM.
 * Cost: as amscr_signature_shortlists.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.22
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_signature_shortlists_packed(const uint16_t *q, const int32_t *e,
                                                                         size_t n, const float *qsigs, size_t nq,
                                                                         size_t first, size_t m, unsigned threads,
                                                                         size_t *out, size_t out_len);

/**
 * @brief Re-ranks a whole distance matrix by affinity diffusion on a k-nearest-neighbour
 *        tensor-product graph (Yang, Prasad, Latecki, CVPR 2012; docs/method.md). The output
 *        is a dissimilarity for ranking: out_ij = 1 - Q_ij / max_j Q_ij in [0, 1) for the
 *        pairs the diffusion reaches, 1 + D_ij / max D for the others (so they keep their
 *        order after every reached one). Deterministic; O(iterations * n^2 * k) time, 3 n^2
 *        doubles of memory.
 * @param[in]  dist  n x n row-major distances (finite, >= 0).
 * @param[in]  k     neighbours, 1..n (typical 10).
 * @param[in]  iterations  1..1000 (typical 20).
 * @param[out] out_dist  n x n; may equal dist (in place).
 * @return AMSCR_OK; AMSCR_E_INVALID_ARG; AMSCR_E_LIMIT (n above 65536); AMSCR_E_NOMEM.
 * Ownership: none.
 * Thread-safety: safe.
 * @since 0.1
 */
AMSCR_API AMSCR_NODISCARD amscr_status amscr_rerank_diffusion(const double *dist, size_t n, size_t k,
                                                              unsigned iterations, double *out_dist);

#ifdef __cplusplus
}
#endif

#endif /* AMSCR_H */
