/* longshape.h — long noisy test shapes for the stages that use the order and the spacing of a
 * noisy curve's points (check_ordered.c, check_even.c): a smooth random shape stretched 5:1,
 * sampled evenly or unevenly along a dense version, and a start map stretched along the long
 * axis (where a closest-point fit cannot pin a long shape down). */
#ifndef AMSCR_TEST_LONGSHAPE_H
#define AMSCR_TEST_LONGSHAPE_H

#include <stddef.h>

#include "testutil.h"

/* Points of the dense curves. */
enum { AMSCR_TEST_DENSE = 4096 };

/* A smooth random shape (complexity 4) stretched 5:1 along x: AMSCR_TEST_DENSE points into d. */
void amscr_test_long_dense(amscr_test_rng *rng, double *d);

/* n points along the closed dense curve d (AMSCR_TEST_DENSE points), `density` times denser on
 * the first and third quarters of its length than on the others, and 1 + wave sin(6 pi s) times
 * denser at the share s of it (density 1, wave 0: evenly spaced in arc length). */
void amscr_test_resample_uneven(const double *d, size_t n, double density, double wave, double *out);

/* Z = a stretch by 1 + k along the long axis of the points b (n; through their centroid) after
 * the map Y. */
void amscr_test_long_axis_stretch(const double *b, size_t n, const double Y[6], double k, double Z[6]);

/* A refining stage's signature (ordered.h, even.h): Y (a -> b) refined in place; 1 when it was. */
typedef int (*amscr_test_stage)(const double *a, size_t na, const double *b, size_t nb, double rough_b,
                                double Y[6]);

/* Asserts what every such stage must do on degenerate input, with a (n points) a clean curve, b
 * (n points) scratch, s2 a noise variance and Z a map: a zero or non-finite map and a one-point
 * curve are refused with Z left exactly as given; on a random cloud of points (size wide) Z
 * stays finite, and exactly as given when refused. */
void amscr_test_stage_degenerate(amscr_test_stage stage, const double *a, double *b, size_t n, double s2, double size,
                                 double Z[6]);

/* Reverses the order of n points in place. */
void amscr_test_reverse(double *p, size_t n);

#endif
