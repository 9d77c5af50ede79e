/* testutil.h — helpers shared by the Check suites: a seeded PRNG, synthetic shapes,
 * random affine maps, noise/occlusion, and dataset access (skipped when absent). */
#ifndef AMSCR_TESTUTIL_H
#define AMSCR_TESTUTIL_H

#include <stddef.h>
#include <stdint.h>

typedef struct { uint64_t s; } amscr_test_rng;

void amscr_test_rng_seed(amscr_test_rng *r, uint64_t seed);
uint64_t amscr_test_rng_next(amscr_test_rng *r);
double amscr_test_uniform(amscr_test_rng *r);            /* [0, 1) */
double amscr_test_normal(amscr_test_rng *r);             /* N(0, 1) */

/* A random smooth star-shaped closed curve, n points, counter-clockwise, radius ~1.
 * xy: 2n doubles. `complexity` = number of Fourier harmonics (e.g. 4..8). */
void amscr_test_random_shape(amscr_test_rng *r, size_t n, int complexity, double *xy);
/* An ellipse with semi-axes a, b, n points starting at angle phase. */
void amscr_test_ellipse(size_t n, double a, double b, double phase, double *xy);
/* A random affine map: any rotation, anisotropic scale in [1/smax, smax]... exact:
 * A = R(theta) * diag(s1, s2) * shear(h) * R(phi) with s in [0.5, smax]^-ish, |h| <= shear;
 * det > 0 unless `reflect`, translation in [-tmax, tmax]^2. */
void amscr_test_random_affine(amscr_test_rng *r, double smax, double shear, double tmax, int reflect,
                              double m6[6]);
void amscr_test_apply_affine(const double m6[6], const double *xy, size_t n, double *out);
/* A closed polygon through v (nv vertices), each edge split into m points; returns nv * m. */
size_t amscr_test_polygon(const double *v, size_t nv, size_t m, double *out);
/* Signed (shoelace) area of the n points as given (positive counter-clockwise in a y-up frame). */
double amscr_test_shoelace(const double *xy, size_t n);
/* The 10 vertices (20 doubles) of a regular 5-pointed star (outer radius 1, inner 0.4). */
void amscr_test_star5(double *v);
/* out[i] = xy[(i + shift) % n] */
void amscr_test_cyclic_shift(const double *xy, size_t n, size_t shift, double *out);
/* Adds Gaussian noise of standard deviation `sigma` to every coordinate. */
void amscr_test_add_noise(amscr_test_rng *r, double *xy, size_t n, double sigma);
/* Size of a shape: sqrt of the largest eigenvalue of the covariance * 2 (≈ a radius measure);
 * precisely the RMS distance to the centroid. */
double amscr_test_shape_size(const double *xy, size_t n);
/* max over points of |m6(xy_i) - truth(xy_i)| */
double amscr_test_max_map_error(const double m6[6], const double truth[6], const double *xy, size_t n);

/* Folder of the shared datasets, or NULL when absent (tests then skip with a message). */
const char *amscr_test_datasets_dir(void);
/* The datasets folder, or NULL after printing "SKIP: <suite>: datasets not found" (a test
 * that needs them then returns; run_one.c turns the suite's exit into meson's SKIP). */
const char *amscr_test_datasets_or_skip(const char *suite);
/* Whether the suite of that name (accuracy, robust, trace) reads the datasets. */
int amscr_test_suite_reads_datasets(const char *suite);
/* Reads an 8-bit grayscale (or any PNG libpng can expand) into a malloc'ed luminance
 * buffer; returns 0 on success. */
int amscr_test_read_png_gray(const char *path, unsigned char **out_pixels, size_t *out_w, size_t *out_h);

/* The n bytes of the host value at v written at b in the files' byte order (little-endian,
 * whatever the host), and a double read back from it: for tests that craft collection and index
 * files (a host-order memcpy reads differently on a big-endian host). */
void amscr_test_put_le(unsigned char *b, const void *v, size_t n);
double amscr_test_get_f64le(const unsigned char *b);

#endif
