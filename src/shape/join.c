/* join.c — AMSCR_TRACE_JOIN of amscr_contour_from_image: one outline for a shape cut in
 * pieces (docs/method.md §5).
 *
 * An occluder across a thin part (a bite through a guitar's neck or a bone's shaft) leaves the
 * shape as two components, and the largest alone lacks the other's boundary: registered
 * against the whole source it fits nothing (the bench's bite failures, maps 80-330 % off).
 * With the flag, every other component outside the largest's holes that has at least
 * JOIN_SHARE of its pixels and lies within JOIN_REACH of its RMS radius (about the outline's
 * vertex centroid) is joined, largest first, to the outline built so far by a bridge between
 * their closest vertices: the outline walks to the piece, around it (counter-clockwise, as
 * itself) and back along the same bridge. The bridge is a zero-width slit, so the area is the
 * pieces' sum; the registration sees the gap as it sees a bite (method.md §11.3). */
#include "dense.h"
#include "internal.h"
#include "iso_level.h"
#include "nearest.h"
#include "trace_all.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A piece is joined when it has at least this share of the largest component's pixels (specks
 * of segmentation noise stay out) ... */
#define JOIN_SHARE 0.05
/* ... and comes within this many RMS radii of the largest's outline. */
#define JOIN_REACH 1.0
/* At most this many pieces are joined (the largest first). */
#define JOIN_MAX 8

/* RMS distance of the n vertices xy from their centroid. */
static double join_radius(const double *xy, size_t n)
{
    double cx, cy, cov[3];
    amscr__centroid(xy, n, &cx, &cy);
    amscr__scatter(xy, n, cx, cy, 1.0, cov);
    return sqrt((cov[0] + cov[2]) / (double)n);
}

/* The pieces to join: foreground labels other than `largest`, outside any hole (the pixel left
 * of the first one belongs to the outside, label 1), of JOIN_SHARE of its size; by size, at
 * most JOIN_MAX. Returns their count. */
static size_t join_candidates(const amscr__regions *R, const size_t *count, size_t largest, size_t out[JOIN_MAX])
{
    size_t k = 0;
    for (size_t r = 2; r <= R->n; r++) {
        if (r == largest || !R->fg[r] || R->lab[R->first[r] - 1] != 1 ||
            (double)count[r] < JOIN_SHARE * (double)count[largest])
            continue;
        size_t pos = k < JOIN_MAX ? k++ : JOIN_MAX;
        while (pos > 0 && count[out[pos - 1]] < count[r]) {
            if (pos < JOIN_MAX)
                out[pos] = out[pos - 1];
            pos--;
        }
        if (pos < JOIN_MAX)
            out[pos] = r;
    }
    return k;
}

/* Splices the closed outline P (m) into J (*n) between J's vertex i and P's vertex j:
 * J[0..i], P[j..m-1], P[0..j], J[i..n-1]. */
static amscr_status join_splice(double **J, size_t *n, const double *P, size_t m, size_t i, size_t j)
{
    size_t total = *n + m + 2;
    if (total > AMSCR_MAX_POINTS)
        return amscr__fail(AMSCR_E_LIMIT, "amscr_contour_from_image: the joined outline exceeds %u points",
                           (unsigned)AMSCR_MAX_POINTS);
    double *out = amscr__malloc_array(2 * total, sizeof *out), *o = out;
    if (!out)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_image: out of memory (%zu points)", total);
    memcpy(o, *J, 2 * (i + 1) * sizeof *o);
    o += 2 * (i + 1);
    memcpy(o, P + 2 * j, 2 * (m - j) * sizeof *o);
    o += 2 * (m - j);
    memcpy(o, P, 2 * (j + 1) * sizeof *o);
    o += 2 * (j + 1);
    memcpy(o, *J + 2 * i, 2 * (*n - i) * sizeof *o);
    free(*J);
    *J = out;
    *n = total;
    return AMSCR_OK;
}

/* Joins piece r's outline to J when within reach (outline from march.c, counter-clockwise). */
static amscr_status join_piece(const amscr__iso *f, const amscr__regions *R, size_t r, double reach, double **J,
                               size_t *n)
{
    const size_t W = f->w + 2, p = R->first[r];
    double *P = NULL;
    size_t m = 0;
    amscr_status st = amscr__march(f, p % W - 1, p / W - 1, 2, "amscr_contour_from_image", &P, &m);
    if (st != AMSCR_OK)
        return st;
    double a = m >= 3 ? amscr__signed_area(P, m) : 0.0;
    if (a == 0.0) {
        free(P);
        return AMSCR_OK;
    }
    if (a < 0.0)
        amscr__reverse_points(P, m);
    amscr__grid g = {0};
    if (amscr__grid_build(&g, *J, *n) != 1) {
        free(P);
        amscr__grid_free(&g);
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_from_image: out of memory (joining)");
    }
    size_t bi = 0, bj = 0;
    double best = INFINITY;
    for (size_t j = 0; j < m; j++) {
        double d2;
        size_t i = amscr__grid_nearest(&g, *J, P[2 * j], P[2 * j + 1], &d2);
        if (d2 < best) {
            best = d2;
            bi = i;
            bj = j;
        }
    }
    amscr__grid_free(&g);
    /* a piece touching the outline at a vertex (a saddle of the iso-line) is left out: its
     * bridge would repeat that vertex */
    if (best > 0.0 && sqrt(best) <= reach)
        st = join_splice(J, n, P, m, bi, bj);
    free(P);
    return st;
}

amscr_status amscr__join_pieces(const amscr__iso *f, const amscr__regions *R, const size_t *count, size_t largest,
                                double **xy, size_t *n)
{
    size_t pieces[JOIN_MAX], k = join_candidates(R, count, largest, pieces);
    double reach = JOIN_REACH * join_radius(*xy, *n);
    for (size_t c = 0; c < k; c++) {
        amscr_status st = join_piece(f, R, pieces[c], reach, xy, n);
        if (st != AMSCR_OK)
            return st;
    }
    return AMSCR_OK;
}
