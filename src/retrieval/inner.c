/* inner.c — the inner-distance graph of the re-ranking (docs/method.md §10.4): the inner
 * distance of Ling and Jacobs ("Shape classification using the inner-distance", IEEE PAMI
 * 2007), the length of the shortest path between two boundary points that stays inside the
 * shape. Bending a part at a joint leaves it almost unchanged, so it sees articulated shapes
 * alike where the height functions of the shape channel see them differ.
 *
 * Per shape (once): the closed curve resampled to AMSCR__INNER_N points evenly along its
 * length; the visibility graph of that polygon (a chord joins two vertices when it crosses
 * no edge and its midpoint lies inside) and its shortest paths (Floyd-Warshall); the matrix
 * divided by its mean (scale-free; chords that no path joins, possible only on a degenerate
 * polygon, keep their straight length). Per pair: the matrices, low-passed along the curve,
 * compared at every cyclic shift of the vertices and both orientations at once, by one inverse
 * FFT over the columns of the offset form (i -> ID(i, i + k)); N/2 x (N/4 + 1) complex products
 * a pair and orientation. */
#include "inner.h"

#include "dense.h" /* AMSCR__PI */

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define N AMSCR__INNER_N

amscr_status amscr__inner_ws_init(amscr__inner_ws *ws)
{
    if (amscr__fft_plan_init(&ws->plan, N) != 0)
        return amscr__fail(AMSCR_E_NOMEM, "inner distance: out of memory");
    ws->have_tw = 0;
    for (size_t m = 0; m < N; m++) {
        double a = -2.0 * AMSCR__PI * (double)m / (double)N;
        ws->cs[2 * m] = cos(a);
        ws->cs[2 * m + 1] = sin(a);
    }
    return AMSCR_OK;
}

void amscr__inner_ws_free(amscr__inner_ws *ws) { amscr__fft_plan_free(&ws->plan); }

static double cross(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

/* Whether the point (x, y) lies inside the polygon V (even-odd rule). */
static int inside(const double *V, double x, double y)
{
    int in = 0;
    for (size_t e = 0; e < N; e++) {
        const double *a = V + 2 * e, *b = V + 2 * ((e + 1) % N);
        if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0])
            in = !in;
    }
    return in;
}

/* Whether the chord from vertex i to vertex j stays inside the polygon V. Each vertex's side of
 * the chord's line is computed once and carried to the next edge. */
static int visible(const double *V, size_t i, size_t j)
{
    const double *p = V + 2 * i, *q = V + 2 * j;
    double ce = cross(p, q, V);
    for (size_t e = 0; e < N; e++) {
        size_t f = (e + 1) % N;
        const double *a = V + 2 * e, *b = V + 2 * f;
        double cf = cross(p, q, b);
        if (!(e == i || e == j || f == i || f == j) && ce * cf < 0.0 && cross(a, b, p) * cross(a, b, q) < 0.0)
            return 0;
        ce = cf;
    }
    return inside(V, 0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]));
}

/* D (N x N): the inner distances of the polygon V, divided by their mean. 0 if degenerate. */
static int inner_matrix_of(const double *V, double *D)
{
    for (size_t i = 0; i < N; i++) {
        D[i * N + i] = 0.0;
        for (size_t j = i + 1; j < N; j++) {
            int adjacent = j == i + 1 || (i == 0 && j == N - 1);
            double l = hypot(V[2 * j] - V[2 * i], V[2 * j + 1] - V[2 * i + 1]);
            D[i * N + j] = D[j * N + i] = adjacent || visible(V, i, j) ? l : INFINITY;
        }
    }
    double row[N];
    for (size_t k = 0; k < N; k++) { /* row k and column k do not change in step k (D[k][k] = 0) */
        memcpy(row, D + k * N, sizeof row);
        for (size_t i = 0; i < N; i++) {
            double dik = D[i * N + k], *Di = D + i * N;
            for (size_t j = 0; j < N; j++) { /* a minimum: vector instructions */
                double v = dik + row[j];
                Di[j] = v < Di[j] ? v : Di[j];
            }
        }
    }
    double sum = 0.0;
    for (size_t i = 0; i < N; i++)
        for (size_t j = 0; j < N; j++) {
            if (!isfinite(D[i * N + j]))
                D[i * N + j] = hypot(V[2 * j] - V[2 * i], V[2 * j + 1] - V[2 * i + 1]);
            sum += D[i * N + j];
        }
    if (!(sum > 0.0) || !isfinite(sum))
        return 0;
    double s = (double)(N * N) / sum;
    for (size_t i = 0; i < N * N; i++)
        D[i] *= s;
    return 1;
}

/* The reversed orientation's twist of b's column k, in b's units, into ws->tw (unless it holds
 * b's already): tw[0] + i tw[1] = (re + i im) e^{-2 pi i f (k + 1) / N}. */
static void twist(const amscr__inner *b, amscr__inner_ws *ws)
{
    if (ws->have_tw && memcmp(ws->tw_of[0], b->re, sizeof b->re) == 0 &&
        memcmp(ws->tw_of[1], b->im, sizeof b->im) == 0)
        return;
    for (size_t q = 0; q < AMSCR__INNER_F; q++)
        for (size_t k = 0; k < AMSCR__INNER_K; k++) {
            const double *c = ws->cs + 2 * ((q * (k + 1)) % N);
            double br = b->re[q][k], bi = b->im[q][k];
            ws->tw[0][q][k] = br * c[0] - bi * c[1];
            ws->tw[1][q][k] = br * c[1] + bi * c[0];
        }
    memcpy(ws->tw_of[0], b->re, sizeof b->re);
    memcpy(ws->tw_of[1], b->im, sizeof b->im);
    ws->have_tw = 1;
}

int amscr__inner_quantize(amscr__inner *f, const double *v)
{
    const double *x = v;
    const size_t fk = AMSCR__INNER_F * AMSCR__INNER_K;
    double top = 0.0, sum = 0.0;
    for (size_t t = 0; t < 2 * fk; t++) {
        if (!isfinite(x[t]))
            return 0;
        top = fabs(x[t]) > top ? fabs(x[t]) : top;
    }
    f->scale = top / AMSCR__INNER_Q;
    for (size_t q = 0; q < AMSCR__INNER_F; q++)
        for (size_t k = 0; k < AMSCR__INNER_K; k++) {
            int16_t r[2];
            for (int c = 0; c < 2; c++) {
                double u = top > 0.0 ? x[(size_t)c * fk + q * AMSCR__INNER_K + k] / f->scale : 0.0;
                r[c] = (int16_t)(u > AMSCR__INNER_Q ? AMSCR__INNER_Q : u < -AMSCR__INNER_Q ? -AMSCR__INNER_Q : lround(u));
            }
            f->re[q][k] = r[0];
            f->im[q][k] = r[1];
            /* exact: integers below 2^53 */
            sum += (q == 0 || 2 * q == N ? 1.0 : 2.0) * ((double)r[0] * r[0] + (double)r[1] * r[1]);
        }
    f->norm2 = sum * f->scale * f->scale / (double)N;
    return 1;
}

/* The features of the N vertices in ws->xy. */
static amscr_status from_vertices(amscr__inner *out, amscr__inner_ws *ws)
{
    if (!inner_matrix_of(ws->xy, ws->id))
        return amscr__fail(AMSCR_E_DEGENERATE, "inner distance: the curve has no extent");
    for (size_t k = 0; k < AMSCR__INNER_K; k++) {
        size_t off = k + 1;
        double w = sqrt(off < N / 2 ? 2.0 : 1.0);
        for (size_t i = 0; i < N; i++) {
            ws->z[2 * i] = w * ws->id[i * N + (i + off) % N];
            ws->z[2 * i + 1] = 0.0;
        }
        amscr__fft(&ws->plan, ws->z, 0);
        for (size_t f = 0; f < AMSCR__INNER_F; f++) {
            ws->fz[0][f][k] = ws->z[2 * f];
            ws->fz[1][f][k] = ws->z[2 * f + 1];
        }
    }
    if (!amscr__inner_quantize(out, &ws->fz[0][0][0]))
        return amscr__fail(AMSCR_E_DEGENERATE, "inner distance: the curve has no extent");
    return AMSCR_OK;
}

amscr_status amscr__inner_build(const double *xy, size_t n, amscr__inner *out, amscr__inner_ws *ws)
{
    amscr_status st = n < 3 ? AMSCR_E_DEGENERATE : amscr__resample_euclid(xy, n, 1, N, ws->xy);
    if (st == AMSCR_E_NOMEM)
        return st;
    if (st != AMSCR_OK)
        return amscr__fail(AMSCR_E_DEGENERATE, "inner distance: the curve has no extent");
    return from_vertices(out, ws);
}

amscr_status amscr__inner_vertices(const amscr_descriptor *d, double closing, double *V)
{
    if (closing > 0.0 && d->outline && d->params.inner_closing == closing) {
        memcpy(V, d->outline, 2 * N * sizeof *V);
        return AMSCR_OK;
    }
    amscr_status st = closing > 0.0 ? amscr__outline(d->input, d->n, closing, V) : AMSCR_E_DEGENERATE;
    if (st == AMSCR_E_DEGENERATE) { /* no closing, or no area to close: the samples themselves */
        amscr__clear_error();
        st = amscr__resample_euclid(d->input, d->n, 1, N, V);
    }
    return st;
}

amscr_status amscr__inner_build_shape(const amscr_descriptor *d, double closing, amscr__inner *out,
                                      amscr__inner_ws *ws)
{
    amscr_status st = amscr__inner_vertices(d, closing, ws->xy);
    if (st == AMSCR_E_NOMEM)
        return st;
    if (st != AMSCR_OK)
        return amscr__fail(AMSCR_E_DEGENERATE, "inner distance: the curve has no extent");
    return from_vertices(out, ws);
}

/* The four sums over the columns k of frequencies f0 .. f0 + g - 1 into s[f][0..3] (X's real and
 * imaginary part, Y's; Y 0 without `refl`), in the units of a and b: the g frequencies side by
 * side, each summed over k in order (the chain of one sum no longer waits on itself alone). X's
 * sums of integer products are exact; Y reads b's twist tw. */
static inline void column_sums(const amscr__inner *a, const amscr__inner *b, const amscr__inner_ws *ws, int refl,
                               size_t f0, size_t g, double (*s)[4])
{
    double xr[4] = {0.0}, xi[4] = {0.0}, yr[4] = {0.0}, yi[4] = {0.0};
    for (size_t k = 0; k < AMSCR__INNER_K; k++)
        for (size_t t = 0; t < g; t++) {
            double ar = a->re[f0 + t][k], ai = a->im[f0 + t][k], br = b->re[f0 + t][k], bi = b->im[f0 + t][k];
            xr[t] += ar * br + ai * bi;
            xi[t] += ar * bi - ai * br;
        }
    for (size_t k = 0; refl && k < AMSCR__INNER_K; k++)
        for (size_t t = 0; t < g; t++) {
            double ar = a->re[f0 + t][k], ai = a->im[f0 + t][k], tr = ws->tw[0][f0 + t][k], ti = ws->tw[1][f0 + t][k];
            yr[t] += ar * tr - ai * ti;
            yi[t] += ar * ti + ai * tr;
        }
    for (size_t t = 0; t < g; t++) {
        s[f0 + t][0] = xr[t];
        s[f0 + t][1] = xi[t];
        s[f0 + t][2] = yr[t];
        s[f0 + t][3] = yi[t];
    }
}

/* Z(f), f = 0..N/2, into ws->z with its Hermitian rest: the correlation of a and b over the
 * shifts (real part: sum_k conj(A) B, sum_i a[i] b[i + s]) and, when `refl`, of a and b
 * reversed (imaginary part: sum_k A B e^{-2 pi i f (k + 1) / N}, sum_i a[i] b[-i - s - k - 1]). */
static void spectrum(const amscr__inner *a, const amscr__inner *b, int refl, amscr__inner_ws *ws)
{
    double *z = ws->z, s[AMSCR__INNER_F][4], u = a->scale * b->scale;
    size_t f0 = 0;
    if (refl)
        twist(b, ws);
    for (; f0 + 4 <= AMSCR__INNER_F; f0 += 4)
        column_sums(a, b, ws, refl, f0, 4, s);
    for (; f0 < AMSCR__INNER_F; f0++)
        column_sums(a, b, ws, refl, f0, 1, s);
    for (size_t f = 0; f < AMSCR__INNER_F; f++) {
        double xr = u * s[f][0], xi = u * s[f][1], yr = u * s[f][2], yi = u * s[f][3];
        z[2 * f] = xr - yi; /* X + i Y */
        z[2 * f + 1] = xi + yr;
        if (f > 0 && f < N / 2) { /* conj(X) + i conj(Y) at N - f */
            z[2 * (N - f)] = xr + yi;
            z[2 * (N - f) + 1] = -xi + yr;
        }
    }
    for (size_t f = AMSCR__INNER_F; f + AMSCR__INNER_F <= N; f++) /* the frequencies left out */
        z[2 * f] = z[2 * f + 1] = 0.0;
}

double amscr__inner_distance(const amscr__inner *a, const amscr__inner *b, int reflections, amscr__inner_ws *ws)
{
    spectrum(a, b, reflections, ws);
    amscr__fft(&ws->plan, ws->z, 1);
    double best = -INFINITY;
    for (size_t s = 0; s < N; s++) {
        if (ws->z[2 * s] > best)
            best = ws->z[2 * s];
        if (reflections && ws->z[2 * s + 1] > best)
            best = ws->z[2 * s + 1];
    }
    double d2 = a->norm2 + b->norm2 - 2.0 * best / (double)N;
    /* below the sums' rounding (a shape against itself): 0 */
    return d2 > 1e-12 * (a->norm2 + b->norm2) ? sqrt(d2 / (double)(N * N)) : 0.0;
}

/* ------------------------------------------------- a workspace on the heap (rows.c) */

amscr_status amscr__inner_ws_new(void **out)
{
    amscr__inner_ws *w = malloc(sizeof *w);
    if (!w || amscr__inner_ws_init(w) != AMSCR_OK) {
        free(w);
        return AMSCR_E_NOMEM;
    }
    *out = w;
    return AMSCR_OK;
}

void amscr__inner_ws_delete(void *ws)
{
    if (ws)
        amscr__inner_ws_free(ws);
    free(ws);
}
