/* nearest.h — closest points on closed polylines of many points (never installed): a uniform
 * grid for a first, global search, a local search from a previous partner, the closest point of
 * a vertex's two edges, and smoothed edge normals. Used by the polish (polish.c). */
#ifndef AMSCR_NEAREST_H
#define AMSCR_NEAREST_H

#include <stddef.h>

/* A uniform grid over a point set: the points of every cell. */
typedef struct {
    double x0, y0, inv;
    long nx, ny;
    size_t *start, *item; /* nx*ny + 1 offsets, n point indices */
} amscr__grid;

/* (Re)builds g over the n points p (2n), cells about sqrt(area / n) wide. Returns 1; 0 when a
 * point is not finite; -1 when out of memory. amscr__grid_free releases; a zeroed grid is empty. */
int amscr__grid_build(amscr__grid *g, const double *p, size_t n);
void amscr__grid_free(amscr__grid *g);
/* Index of the point of g's set p nearest to (qx, qy) (finite); *d2 its squared distance. */
size_t amscr__grid_nearest(const amscr__grid *g, const double *p, double qx, double qy, double *d2);
/* The vertex of the closed polyline p (n) nearest to (qx, qy) near vertex i0: ±3 vertices, then
 * on along the polyline while closer. */
size_t amscr__local_nearest(const double *p, size_t n, size_t i0, double qx, double qy, double *d2);
/* The closest point to (qx, qy) on the two edges of the closed polyline p (n) at vertex i: the
 * edge's first vertex into *seg, the position along it (0..1) into *t; returns the squared
 * distance. */
double amscr__edge_foot(const double *p, size_t n, size_t i, double qx, double qy, size_t *seg, double *t);
/* Unit normals en (2n) of the edges a -> a+1 of the closed polyline p (n), each from the chord
 * one vertex beyond either end (a pixel chain's own edges point in 8 directions only); 0 for a
 * zero-length chord. */
void amscr__edge_normals(const double *p, size_t n, double *en);

#endif
