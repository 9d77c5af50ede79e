/* polish_fit.h — the fit behind the polish (polish_fit.c; never installed): both input curves in
 * frames that keep their metric, their roughness and gaps, and the trimmed two-way point-to-line
 * Gauss-Newton fit of one start. The stage that ranks the starts and picks the winner is polish.c. */
#ifndef AMSCR_POLISH_FIT_H
#define AMSCR_POLISH_FIT_H

#include "match.h"
#include "nearest.h"

#include <stddef.h>

/* One input curve in its own frame and its partner bookkeeping. */
typedef struct {
    double *p;    /* 2n points */
    double *en;   /* 2n unit normals of its edges (the moved curve's: as moved) */
    size_t *part; /* n partners: the first vertex of the other curve's closest edge */
    size_t *gap;  /* n flags: edge i -> i+1 is a gap */
    double *ft;   /* n positions of the closest point along that edge, 0..1 */
    double *d2;   /* n squared distances to it */
    size_t n;
    double rough;            /* roughness (squared), in the curve's frame */
    double sim[6], unsim[6]; /* input -> the curve's frame, and back */
} curve_t;

typedef struct {
    curve_t src, tgt;
    curve_t *a, *b;  /* the curve the map moves (the smoother) and the other */
    double *moved;   /* 2 a->n: Y a */
    double *sorted;  /* scratch of the larger count */
    double wb, wa;   /* weights: b's points onto the moved a, and the moved a's points onto b */
    int partial;     /* a is an open fragment of the closed b: only its points are paired */
    amscr__grid gb, gm; /* grids over b and over the moved a */
    int nomem;          /* an allocation failed (the registration reports it) */
    double *block;
    size_t *iblock;
} polish_t;

/* Allocates the work arrays of w for a source of ns and a target of nt input points (w zeroed
 * first). AMSCR_OK, or AMSCR_E_NOMEM with w freed. */
amscr_status amscr__polish_alloc(size_t ns, size_t nt, polish_t *w);
void amscr__polish_free(polish_t *w);

/* Loads both curves (f, h), measures their noise, picks the moved curve (the smoother, in the
 * target's units under X) and the weights; builds the grid of the other. partial: f is an open
 * fragment of the closed h (always the moved curve, paired alone). Returns 1, 0 when it cannot,
 * -1 when out of memory. */
int amscr__polish_prepare(polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6],
                          int partial);

/* X (normalized frames f -> h) as Y (the curves' frames, a -> b), and back. */
void amscr__polish_to_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h, const double X[6],
                             double Y[6]);
void amscr__polish_from_frames(const polish_t *w, const amscr_descriptor *f, const amscr_descriptor *h,
                               const double Y[6], double X[6]);

/* Polishes Y (a -> b) in place with at most `iters` steps; returns its ranking cost (INFINITY
 * when it failed: Y is then as given). */
double amscr__polish_one(polish_t *w, double Y[6], int iters);

/* The two-way cost of map Y keeping `share` of each direction's pairs: the tie-break of starts
 * that rank alike (INFINITY when it cannot pair). */
double amscr__polish_tie_cost(polish_t *w, const double Y[6], double share);

/* Whether a curve has a gap edge. */
int amscr__polish_has_gap(const curve_t *c);

#endif
