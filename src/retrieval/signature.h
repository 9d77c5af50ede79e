/* signature.h — the shortlist signature of a prepared shape (signature.c): a short vector
 * whose Euclidean distance orders the shapes a large index matches first. Never installed. */
#ifndef AMSCR_SIGNATURE_H
#define AMSCR_SIGNATURE_H

#include "internal.h"

/* Dimension of amscr__shape_signature's output (stored in the index file as sig_dim). */
#define AMSCR__SIG_DIM 24

/* The signature of d into out[AMSCR__SIG_DIM]. */
void amscr__shape_signature(const amscr_descriptor *d, double *out);

#endif
