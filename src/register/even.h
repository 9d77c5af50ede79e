/* even.h — a map refined on the evidence that a noisy curve's points were taken evenly along it
 * (even.c; never installed). Used by the polish (polish.c), after the order stage (ordered.h). */
#ifndef AMSCR_EVEN_H
#define AMSCR_EVEN_H

#include <stddef.h>

/* Refines Y (2x3, a -> b) in place: a (na points, closed) is a clean model of the curve, b (nb
 * points, closed, in order along it) noisy observations of Y a with noise variance rough_b per
 * coordinate. Point i of b is taken to lie at the share off +- i / nb of the moved curve's length
 * (the sign: b's running direction), and Y and off are fitted by least squares. Runs only on
 * points that scatter across the curve (EVEN_MIN_SCATTER of their spacing) and that Y already
 * explains within their noise; the result is kept only when the points bear the model out:
 * their mean squared residual at most EVEN_MAX_RATIO times their mean squared distance from the
 * curve (even sampling leaves twice that: the noise's along-curve half joins its across-curve
 * half; uneven sampling many times more), and their residuals along the curve white (Kuiper's
 * test). Returns 1 when Y was refined, 0 when it was left as given (outside that regime, too few
 * points, a degenerate or area-changing result), -1 when out of memory (Y as given). */
int amscr__even_fit(const double *a, size_t na, const double *b, size_t nb, double rough_b, double Y[6]);

#endif
