/* The shape area (src/shape/): contours and the prepared shape (docs/method.md §2, §5):
 *   contour.c       the contour object, validation and orientation
 *   contour_text.c  text point lists: reading, parsing, writing
 *   trace.c         the outer boundary of the largest component of a mask
 *   trace_all.c     every contour of a mask with its hierarchy
 *   iso_level.c     the grey level a sub-pixel contour follows (and Otsu's split)
 *   march.c         marching squares along that level
 *   trace_image.c   sub-pixel contours of 8- and 16-bit images (amscr_contour(s)_from_image)
 *   join.c          AMSCR_TRACE_JOIN: a shape cut in pieces as one outline
 *   resample.c      Euclidean and affine arc-length resampling, whitening normalization
 *   despike.c       isolated stray points dropped from a point list
 *   descriptor.c    the prepared shape (this file), built from the others
 *
 * descriptor.c — a prepared shape (docs/method.md §2): validated, oriented, resampled, parametrized,
 * sampled at N points, normalized, smoothed at every scale. Immutable once built. */
#include "dense.h"
#include "fft.h"
#include "internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

amscr_status amscr__descriptor_alloc(size_t n, size_t p, amscr_descriptor **out)
{
    amscr_descriptor *d = calloc(1, sizeof *d);
    if (!d)
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    d->n = n;
    d->p = p;
    d->input = amscr__malloc_array(2 * n, sizeof(double));
    d->base = amscr__malloc_array(2 * n, sizeof(double));
    d->scaled = amscr__malloc_array(2 * n * p, sizeof(double));
    d->mom = amscr__malloc_array(6 * (p + 1), sizeof(double));
    d->minv = amscr__malloc_array(9 * (p + 1), sizeof(double));
    d->spec = amscr__malloc_array(4 * n, sizeof(double));
    d->gain = amscr__malloc_array((p + 1) * n, sizeof(double));
    if (!d->input || !d->base || !d->scaled || !d->mom || !d->minv || !d->spec || !d->gain) {
        amscr_descriptor_free(d);
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    }
    *out = d;
    return AMSCR_OK;
}

void amscr_descriptor_free(amscr_descriptor *d)
{
    if (!d)
        return;
    free(d->input);
    free(d->raw);
    free(d->base);
    free(d->scaled);
    free(d->mom);
    free(d->minv);
    free(d->spec);
    free(d->gain);
    free(d->outline);
    free(d);
}

int amscr__params_compatible(const amscr_params *a, const amscr_params *b, const char *what)
{
    if (a->num_samples != b->num_samples) {
        amscr__fail(AMSCR_E_INVALID_ARG, "%s: N differs (%zu vs %zu)", what, a->num_samples, b->num_samples);
        return 0;
    }
    if (a->num_scales != b->num_scales || memcmp(a->scales, b->scales, a->num_scales * sizeof(double)) != 0) {
        amscr__fail(AMSCR_E_INVALID_ARG, "%s: the scale lists differ", what);
        return 0;
    }
    if (a->closed != b->closed || a->parametrization != b->parametrization || a->invariance != b->invariance) {
        amscr__fail(AMSCR_E_INVALID_ARG, "%s: closed/parametrization/invariance differ", what);
        return 0;
    }
    return 1;
}

/* The moments of the base curve and of every smoothed one, and their inverted moment matrices. */
static amscr_status descriptor_moments(amscr_descriptor *d)
{
    size_t n = d->n;
    for (size_t k = 0; k <= d->p; k++) {
        const double *xy = k == 0 ? d->base : d->scaled + 2 * n * (k - 1);
        double M9[9];
        amscr__moments(xy, n, d->mom + 6 * k);
        amscr__moment_matrix(d->mom + 6 * k, M9);
        if (!amscr__inv3(M9, d->minv + 9 * k)) {
            if (k == 0)
                return amscr__fail(AMSCR_E_DEGENERATE, "descriptor: the sampled curve is degenerate");
            return amscr__fail(AMSCR_E_DEGENERATE,
                               "descriptor: scale %g smooths the %zu-sample curve to (almost) a point; use smaller "
                               "scales or more samples",
                               d->params.scales[k - 1], n);
        }
    }
    return AMSCR_OK;
}

/* The spectra of the base curve's x and y, and the energy of its Nyquist element. */
static void descriptor_spectra(amscr_descriptor *d, amscr__fft_plan *plan)
{
    size_t n = d->n;
    for (size_t c = 0; c < 2; c++) {
        double *z = d->spec + 2 * n * c;
        for (size_t a = 0; a < n; a++) {
            z[2 * a] = d->base[2 * a + c];
            z[2 * a + 1] = 0.0;
        }
        amscr__fft(plan, z, 0);
    }
    d->nyq2 = 0.0;
    if (n % 2 == 0) {
        const double *X = d->spec + n, *Y = d->spec + 2 * n + n; /* element N/2 (complex) */
        d->nyq2 = (X[0] * X[0] + X[1] * X[1] + Y[0] * Y[0] + Y[1] * Y[1]) / (double)n;
    }
}

/* w (n) = the Gaussian kernel of scale sigma wrapped onto a circle of n samples (sigma 0: the
 * identity); 0 when out of memory. */
static int circular_kernel(double sigma, size_t n, double *w)
{
    memset(w, 0, n * sizeof *w);
    if (sigma == 0.0) {
        w[0] = 1.0;
        return 1;
    }
    size_t r = amscr__kernel_radius(sigma);
    double *g = amscr__malloc_array(2 * r + 1, sizeof *g);
    if (!g)
        return 0;
    amscr__kernel_fill(sigma, r, g);
    for (size_t j = 0; j <= 2 * r; j++) {
        long long off = ((long long)j - (long long)r) % (long long)n;
        if (off < 0)
            off += (long long)n;
        w[off] += g[j];
    }
    free(g);
    return 1;
}

/* The gains |G_k|^2 of the circular kernels of every scale, and their sum. */
static amscr_status descriptor_gains(amscr_descriptor *d, amscr__fft_plan *plan)
{
    size_t n = d->n, p = d->p;
    double *tmp = amscr__malloc_array(2 * n + n, sizeof *tmp);
    if (!tmp)
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    double *sum = d->gain + p * n;
    memset(sum, 0, n * sizeof *sum);
    for (size_t k = 0; k < p; k++) {
        double *z = tmp, *w = tmp + 2 * n;
        if (!circular_kernel(d->params.scales[k], n, w)) {
            free(tmp);
            return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
        }
        for (size_t a = 0; a < n; a++) {
            z[2 * a] = w[a];
            z[2 * a + 1] = 0.0;
        }
        amscr__fft(plan, z, 0);
        for (size_t a = 0; a < n; a++) {
            double g2 = z[2 * a] * z[2 * a] + z[2 * a + 1] * z[2 * a + 1];
            d->gain[k * n + a] = g2;
            sum[a] += g2;
        }
    }
    free(tmp);
    return AMSCR_OK;
}

amscr_status amscr__descriptor_finish(amscr_descriptor *d)
{
    amscr_status st = descriptor_moments(d);
    if (st != AMSCR_OK)
        return st;
    d->norm2 = d->mom[0] + d->mom[2];
    d->finest = 0;
    for (size_t k = 1; k < d->p; k++)
        if (d->params.scales[k] < d->params.scales[d->finest])
            d->finest = k;
    amscr__fft_plan plan;
    if (amscr__fft_plan_init(&plan, d->n) != 0)
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    descriptor_spectra(d, &plan);
    st = descriptor_gains(d, &plan);
    amscr__fft_plan_free(&plan);
    return st;
}

/* Similarity normalization: centroid to the origin, RMS radius to 1 (no whitening). */
static amscr_status normalize_similarity(const double *xy, size_t n, double *out, double fwd[6], double inv[6])
{
    double cx, cy, s = 0;
    amscr__centroid(xy, n, &cx, &cy);
    for (size_t i = 0; i < n; i++) {
        double dx = xy[2 * i] - cx, dy = xy[2 * i + 1] - cy;
        s += dx * dx + dy * dy;
    }
    s = sqrt(s / (double)n);
    if (!(s > 0.0))
        return amscr__fail(AMSCR_E_DEGENERATE, "normalization: all samples coincide");
    /* scale so the covariance trace is 2, as with whitening (distances comparable) */
    double k = sqrt(2.0) / s;
    for (size_t i = 0; i < n; i++) {
        out[2 * i] = k * (xy[2 * i] - cx);
        out[2 * i + 1] = k * (xy[2 * i + 1] - cy);
    }
    double f[6] = {k, 0, -k * cx, 0, k, -k * cy};
    double v[6] = {1 / k, 0, cx, 0, 1 / k, cy};
    memcpy(fwd, f, sizeof f);
    memcpy(inv, v, sizeof v);
    return AMSCR_OK;
}

/* Hands the m input points pts (malloc'ed) to d for the polish, every k-th when many. */
static void keep_points(amscr_descriptor *d, double *pts, size_t m)
{
    size_t k = (m + AMSCR__POLISH_MAX_POINTS - 1) / AMSCR__POLISH_MAX_POINTS, n = 0;
    for (size_t i = 0; i < m; i += k, n++) {
        pts[2 * n] = pts[2 * i];
        pts[2 * n + 1] = pts[2 * i + 1];
    }
    d->raw = pts;
    d->nraw = n;
}

/* Adds (x, y) = shift to the n points xy. */
static void move_points(double *xy, size_t n, const double shift[2])
{
    for (size_t i = 0; i < n; i++) {
        xy[2 * i] += shift[0];
        xy[2 * i + 1] += shift[1];
    }
}

/* Points farther from the origin than this many times their extent are prepared moved by their
 * first point (and the results moved back): sums of their raw coordinates (the pre-smoothing's
 * running sums) would keep few of their digits (at 6.5e9 from the origin, a 100-unit shape's
 * samples moved by ~1e-4 of its size). Nearer ones are prepared as they are, bit for bit as
 * before (image coordinates never reach it). Set by the floating-point precision, not on data. */
#define FAR_FROM_ORIGIN 1048576.0

/* shift = the first of the m points when they lie far from the origin (FAR_FROM_ORIGIN), else 0. */
static void far_shift(const double *pts, size_t m, double shift[2])
{
    double lo[2], hi[2];
    amscr__bounds(pts, m, lo, hi);
    double ext = fmax(hi[0] - lo[0], hi[1] - lo[1]);
    double far = fmax(fabs(0.5 * lo[0] + 0.5 * hi[0]), fabs(0.5 * lo[1] + 0.5 * hi[1]));
    int moved = far > FAR_FROM_ORIGIN * ext;
    shift[0] = moved ? pts[0] : 0.0;
    shift[1] = moved ? pts[1] : 0.0;
}

/* d->outline from the m input points pts, moved by -shift (retrieval with the inner distance's
 * closing); the input samples' outline when pts bound no area. */
static amscr_status keep_outline(amscr_descriptor *d, const double *pts, size_t m, const double shift[2])
{
    d->outline = amscr__malloc_array(2 * AMSCR__OUTLINE_N, sizeof *d->outline);
    if (!d->outline)
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    amscr_status st = amscr__outline(pts, m, d->params.inner_closing, d->outline);
    if (st == AMSCR_OK)
        move_points(d->outline, AMSCR__OUTLINE_N, shift);
    if (st == AMSCR_E_DEGENERATE)
        st = amscr__resample_euclid(d->input, d->n, 1, AMSCR__OUTLINE_N, d->outline);
    return st == AMSCR_E_NOMEM ? amscr__fail(st, "descriptor: out of memory") : st;
}

amscr_status amscr__descriptor_rebuild(amscr_descriptor *d)
{
    const amscr_params *p = &d->params;
    size_t N = d->n;
    amscr_status st = p->invariance == AMSCR_INVARIANCE_AFFINE
                          ? amscr__whiten(d->input, N, d->base, d->fwd, d->inv)
                          : normalize_similarity(d->input, N, d->base, d->fwd, d->inv);
    for (size_t k = 0; st == AMSCR_OK && k < d->p; k++)
        st = amscr__smooth(d->base, N, p->closed, p->scales[k], d->scaled + 2 * N * k);
    return st == AMSCR_OK ? amscr__descriptor_finish(d) : st;
}

amscr_status amscr_descriptor_new(const amscr_params *p, const amscr_contour *c, amscr_descriptor **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(c);
    AMSCR_CHECK_NULL(out);
    amscr_params defaults;
    if (!p) {
        amscr__params_defaults(&defaults);
        p = &defaults;
    }
    size_t N = p->num_samples;
    for (size_t k = 0; k < p->num_scales; k++)
        if (p->scales[k] > (double)N)
            return amscr__fail(AMSCR_E_INVALID_ARG, "descriptor: scale %g exceeds N = %zu", p->scales[k], N);
    int closed = p->closed;
    amscr_status st = amscr__validate_points(c->xy, c->n, closed, "contour");
    if (st != AMSCR_OK)
        return st;
    size_t M = (size_t)p->oversampling * N;
    double *pts = amscr__malloc_array(2 * c->n, sizeof *pts);
    if (!pts)
        return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
    size_t m = amscr__dedupe_points(c->xy, c->n, closed, pts);
    if (p->polish && AMSCR__STAGE_ON(p, AMSCR__STAGE_DESPIKE)) { /* registration: stray points dropped (despike.c) */
        double *scratch = amscr__malloc_array(m, sizeof *scratch);
        if (!scratch) {
            free(pts);
            return amscr__fail(AMSCR_E_NOMEM, "descriptor: out of memory");
        }
        m = amscr__despike(pts, m, closed, scratch);
        free(scratch);
    }
    if (closed && amscr__signed_area(pts, m) < 0.0)
        amscr__reverse_points(pts, m);
    double shift[2], back[2];
    far_shift(pts, m, shift);
    back[0] = -shift[0];
    back[1] = -shift[1];
    move_points(pts, m, back);
    amscr_descriptor *d = NULL;
    st = amscr__descriptor_alloc(N, p->num_scales, &d);
    if (st == AMSCR_OK) {
        d->params = *p;
        st = amscr__parametrize(pts, m, closed, p->parametrization, p->presmooth, p->arclength_passes, M, N,
                                d->input);
        move_points(d->input, N, shift);
    }
    if (st == AMSCR_OK)
        st = amscr__descriptor_rebuild(d);
    if (st == AMSCR_OK && closed && p->inner_closing > 0.0)
        st = keep_outline(d, pts, m, shift);
    move_points(pts, m, shift);
    if (st == AMSCR_OK && p->invariance == AMSCR_INVARIANCE_AFFINE)
        keep_points(d, pts, m);
    else
        free(pts);
    if (st != AMSCR_OK) {
        amscr_descriptor_free(d);
        return st;
    }
    *out = d;
    return AMSCR_OK;
}

size_t amscr_descriptor_num_scales(const amscr_descriptor *d) { return d ? d->p : 0; }
size_t amscr_descriptor_num_samples(const amscr_descriptor *d) { return d ? d->n : 0; }
const double *amscr_descriptor_base_points(const amscr_descriptor *d) { return d ? d->base : NULL; }
const double *amscr_descriptor_input_points(const amscr_descriptor *d) { return d ? d->input : NULL; }
const amscr_params *amscr_descriptor_params(const amscr_descriptor *d) { return d ? &d->params : NULL; }

const double *amscr_descriptor_scale_points(const amscr_descriptor *d, size_t k)
{
    return (d && k < d->p) ? d->scaled + 2 * d->n * k : NULL;
}

amscr_status amscr_descriptor_normalization(const amscr_descriptor *d, double out_m6[6])
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(d);
    AMSCR_CHECK_NULL(out_m6);
    memcpy(out_m6, d->fwd, 6 * sizeof(double));
    return AMSCR_OK;
}
