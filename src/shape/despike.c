/* despike.c — isolated spikes removed from a point list before registration (robust registration).
 *
 * A few stray points in a contour (a detector's glitch, a mis-clicked vertex) wreck everything
 * that follows: each adds two long edges, so the arc-length parametrization, the affine
 * normalization and the start-point search all see another curve (measured: 0.5 % of a clean
 * contour's points moved to random places left 67.9 % of the held-out pairs within 2 %, 1 %
 * left 37.9 %; bench/registration_uneven.py --outliers). A spike is a run of at most SPIKE_RUN
 * points that the curve leaves and re-enters by edges longer than SPIKE_RATIO times its median
 * edge, while the points before and after the run lie within SPIKE_CHORD times the median edge
 * per step skipped: the curve itself did not go there. Real thin parts of a densely sampled
 * contour have many points and short edges (a pixel chain's edges are at most 1.41 times its
 * median; noise-dominated edges rarely reach 4 times it), so they stay. An open curve (a
 * fragment) also loses an end that jumps away in one step while the curve goes on evenly from
 * the next point (measured: 1 % stray points in 70 % fragments left 4.3 % of them within 2 %).
 * Lists of fewer than
 * SPIKE_MIN_POINTS points (polygons) are left alone. Never removes more than 1/SPIKE_MAX_SHARE
 * of the points (more would not be isolated spikes). */
#include "dense.h"
#include "internal.h"

#include <math.h>
#include <string.h>

#define SPIKE_RATIO 8.0
#define SPIKE_RUN 3
#define SPIKE_CHORD 2.0
#define SPIKE_MIN_POINTS 32
#define SPIKE_MAX_SHARE 8
#define SPIKE_PASSES 3

static double dist(const double *p, size_t i, size_t j)
{
    return hypot(p[2 * j] - p[2 * i], p[2 * j + 1] - p[2 * i + 1]);
}

double amscr__median_edge(const double *p, size_t n, int closed, double *scratch)
{
    size_t ne = closed ? n : n - 1;
    for (size_t i = 0; i < ne; i++)
        scratch[i] = dist(p, i, (i + 1) % n);
    amscr__select_kth(scratch, ne, ne / 2);
    return scratch[ne / 2];
}

/* Marks (1 in mark) the run i .. i + r - 1 of p (n points); returns how many were new. */
static size_t mark_run(size_t i, size_t r, size_t n, double *mark)
{
    size_t count = 0;
    for (size_t k = 0; k < r; k++)
        count += mark[(i + k) % n] == 0.0, mark[(i + k) % n] = 1.0;
    return count;
}

/* Marks the points of every spike run of p (closed, or open: runs inside it, and an end that
 * jumps away in one step from a curve that goes on evenly); returns how many. */
static size_t mark_spikes(const double *p, size_t n, int closed, double med, double *mark)
{
    size_t count = 0;
    double longest = SPIKE_RATIO * med;
    memset(mark, 0, n * sizeof *mark);
    for (size_t i = closed ? 0 : 1; i < n; i++) {
        size_t before = (i + n - 1) % n;
        if (mark[i] != 0.0 || !(dist(p, before, i) > longest))
            continue;
        for (size_t r = 1; r <= SPIKE_RUN && (closed || i + r < n); r++) { /* the run i .. i + r - 1, back at j */
            size_t j = (i + r) % n;
            if (dist(p, (j + n - 1) % n, j) > longest && dist(p, before, j) <= SPIKE_CHORD * (double)(r + 1) * med) {
                count += mark_run(i, r, n, mark);
                break;
            }
        }
    }
    if (!closed && dist(p, 0, 1) > longest && dist(p, 1, 2) <= SPIKE_CHORD * med)
        count += mark_run(0, 1, n, mark);
    if (!closed && dist(p, n - 2, n - 1) > longest && dist(p, n - 3, n - 2) <= SPIKE_CHORD * med)
        count += mark_run(n - 1, 1, n, mark);
    return count;
}

size_t amscr__despike(double *p, size_t n, int closed, double *scratch)
{
    size_t removed = 0;
    for (int pass = 0; pass < SPIKE_PASSES && n >= SPIKE_MIN_POINTS; pass++) {
        double med = amscr__median_edge(p, n, closed, scratch);
        if (!(med > 0.0))
            break;
        size_t count = mark_spikes(p, n, closed, med, scratch);
        if (count == 0 || (removed + count) * SPIKE_MAX_SHARE > n + removed)
            break;
        size_t m = 0;
        for (size_t i = 0; i < n; i++)
            if (scratch[i] == 0.0) {
                p[2 * m] = p[2 * i];
                p[2 * m + 1] = p[2 * i + 1];
                m++;
            }
        removed += count;
        n = m;
    }
    return n;
}
