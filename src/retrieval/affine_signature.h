/* affine_signature.h — a vector per prepared shape whose distance predicts the shape
 * channel's (docs/method.md §10.2), for shortlisting the candidates of an index query
 * (affine_signature.c). Never installed. */
#ifndef AMSCR_AFFINE_SIGNATURE_H
#define AMSCR_AFFINE_SIGNATURE_H

#include "internal.h"

/* Frequencies kept of every height-bin column (0 = the bin's mean along the curve): the first
 * N/8 at the default N = 128, as the channel's shift search (AMSCR__HF_FREQS). */
#define AMSCR__SIG_FREQS 16
/* Height bins (the channel's AMSCR__HF_BINS). */
#define AMSCR__SIG_BINS 16
/* Doubles in a signature: two frames (similarity, whitened) x two orientations (the shape and
 * its mirror image) x bins x frequencies. */
#define AMSCR__AFFINE_SIG_DIM (4 * AMSCR__SIG_BINS * AMSCR__SIG_FREQS)

/* The signature of a prepared closed shape into out (AMSCR__AFFINE_SIG_DIM doubles): in the
 * similarity frame and in the whitened frame, for the shape and its mirror image, the
 * magnitudes of the first AMSCR__SIG_FREQS DFT coefficients (divided by N) of every
 * height-bin column along the curve, each frame's
 * block scaled by its share in the channel (the descriptor's channel_invariance and
 * channel_affine_share). Invariant to the start point and, frame by frame, to the maps the
 * frame removes: the whitened block to affine maps, the similarity block to similarities.
 * Always finite (zeros for a frame that cannot be built). Allocates nothing; thread-safe. */
void amscr__affine_signature(const amscr_descriptor *d, double *out);

/* The same with the share of the whitened frame given (0..1; the similarity frame gets the
 * rest) rather than read from the descriptor's params. */
void amscr__affine_signature_share(const amscr_descriptor *d, double affine_share, double *out);

/* The distance of two signatures: per frame, the smaller Euclidean distance of the blocks of
 * the two shapes as they are (both orientations) and of either one against the other's mirror
 * image (as the channel tries both orientations; RMS over the two pairings: symmetric), summed
 * over the frames. */
double amscr__affine_signature_distance(const double *a, const double *b);

#endif
