/* ordered.h — a polished map refined by the ORDER of a noisy curve's points (ordered.c; never
 * installed). Used by the polish (polish.c). */
#ifndef AMSCR_ORDERED_H
#define AMSCR_ORDERED_H

#include <stddef.h>

/* Refines Y (2x3, a -> b) in place: a (na points, closed) is a clean model of the curve, b (nb
 * points, closed, in order along it) noisy observations of Y a with noise variance rough_b per
 * coordinate. Runs only where it helps: the points scatter across the curve by at least
 * ORDER_MIN_SCATTER of their spacing (else their closest points already say where along the
 * curve each was taken). Returns 1 when Y was refined, 0 when it was left as given (outside that
 * regime, or a result that moved too far to trust), -1 when out of memory (Y as given). */
int amscr__ordered_fit(const double *a, size_t na, const double *b, size_t nb, double rough_b, double Y[6]);

#endif
