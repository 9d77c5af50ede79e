/* oom_register.c — every allocation failure in a registration reaches the caller.
 *
 * For each scenario (a noisy target, which runs the polish with its order and even-spacing steps;
 * a target with a missing run, which runs the recovery; a partial match; a symmetric match; a
 * target traced from a small binary image, which runs the pixel_grid stage, the same image's pixel
 * chain onto itself, which traces both again first, and the small image as the source onto a large
 * image's trace, which runs the stage on the source's side) each allocation of one
 * amscr_register_contours call is failed in turn and must come back as AMSCR_E_NOMEM with nothing
 * leaked (oom_wrap.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "oom_wrap.h"

/* A closed star-like curve of n points: r(t) = 1 + a cos(k t) + b sin(3 t), mapped by M and
 * with Gaussian noise sigma (a fixed LCG), starting at point `start`. */
static double *curve(size_t n, double sigma, const double M[6], size_t start, unsigned *seed)
{
    double *xy = __real_malloc(2 * n * sizeof *xy);
    for (size_t i = 0; i < n; i++) {
        double t = 2.0 * 3.141592653589793 * (double)((i + start) % n) / (double)n;
        double r = 1.0 + 0.3 * cos(5.0 * t) + 0.1 * sin(3.0 * t), x = r * cos(t), y = r * sin(t);
        double g[2];
        for (int k = 0; k < 2; k++) { /* Box-Muller from two LCG draws */
            *seed = *seed * 1103515245u + 12345u;
            double u1 = ((*seed >> 8) + 1.0) / 16777217.0;
            *seed = *seed * 1103515245u + 12345u;
            double u2 = (*seed >> 8) / 16777216.0;
            g[k] = sqrt(-2.0 * log(u1)) * cos(2.0 * 3.141592653589793 * u2);
        }
        xy[2 * i] = M[0] * x + M[1] * y + M[2] + sigma * g[0];
        xy[2 * i + 1] = M[3] * x + M[4] * y + M[5] + sigma * g[1];
    }
    return xy;
}

typedef struct {
    const char *name;
    size_t ns, nt, drop; /* source points, target points, target points dropped (a missing run) */
    double sigma;
    int partial, symmetric;
    const char *must_run; /* a stage the scenario exists for */
    int traced;           /* the target traced from its binary image (LATTICE_SIDE px square): 1 at
                           * sub-pixel accuracy, 2 as a pixel chain; 3: the source so traced, the
                           * target a large image's trace */
} scenario;

enum { LATTICE_SIDE = 40 };

/* The binary image of the closed polygon b (n points) scaled by 8 about the image's centre (the
 * pixels whose centre it contains), traced with `flags`: at sub-pixel accuracy (0), points on the
 * pixel lattice, or as a pixel chain (AMSCR_TRACE_PIXEL_CHAIN). */
static amscr_status traced_at(const double *b, size_t n, int side, double scale, int flags, amscr_contour **out);
static amscr_status traced_target(const double *b, size_t n, int flags, amscr_contour **out)
{
    return traced_at(b, n, LATTICE_SIDE, 8.0, flags, out);
}

/* The same on a side x side grid at `scale` pixels a unit. */
static amscr_status traced_at(const double *b, size_t n, int side, double scale, int flags, amscr_contour **out)
{
    unsigned char *img = __real_malloc((size_t)side * (size_t)side);
    if (!img)
        return AMSCR_E_NOMEM;
    for (int j = 0; j < side; j++)
        for (int i = 0; i < side; i++) {
            double x = (i - side / 2) / scale, y = (j - side / 2) / scale;
            int in = 0;
            for (size_t k = 0, l = n - 1; k < n; l = k++)
                if ((b[2 * k + 1] > y) != (b[2 * l + 1] > y) &&
                    x < b[2 * k] + (y - b[2 * k + 1]) * (b[2 * l] - b[2 * k]) / (b[2 * l + 1] - b[2 * k + 1]))
                    in = !in;
            img[j * side + i] = in ? 255 : 0;
        }
    amscr_status st = amscr_contour_from_image(img, (size_t)side, (size_t)side, (size_t)side, 8, 127.5, flags, out);
    __real_free(img);
    return st;
}

/* A large image's trace (the curve b, n points, at 40 px a unit: an RMS radius over the
 * pixel_grid stage's 40 px) as a new contour: traced once, outside the counted allocations (the
 * tracing is not this scenario's concern), copied on each call. */
static amscr_status large_trace(const double *b, size_t n, amscr_contour **out)
{
    static double *xy;
    static size_t m;
    if (!xy) {
        int was = oom_pause();
        amscr_contour *c = NULL;
        if (traced_at(b, n, 400, 40.0, 0, &c) == AMSCR_OK) {
            m = amscr_contour_size(c);
            xy = __real_malloc(2 * m * sizeof *xy);
            if (xy)
                memcpy(xy, amscr_contour_xy(c), 2 * m * sizeof *xy);
        }
        amscr_contour_free(c);
        oom_resume(was);
        if (!xy)
            return AMSCR_E_NOMEM;
    }
    return amscr_contour_new(xy, m, out);
}

static amscr_status run(const scenario *s, amscr_result **out)
{
    static const double I[6] = {1, 0, 0, 0, 1, 0}, M[6] = {1.4, 0.3, 2.0, -0.2, 0.8, -1.0};
    unsigned seed = 7;
    size_t ns = s->partial ? s->ns * 6 / 10 : s->ns, nt = s->nt - s->drop;
    double *a = curve(s->ns, 0.0, I, 0, &seed), *b = curve(s->nt, s->sigma, M, 0, &seed);
    amscr_contour *src = NULL, *tgt = NULL;
    amscr_params *p = NULL;
    amscr_status st = amscr_params_new_registration(&p);
    if (st == AMSCR_OK)
        st = amscr_params_set_num_samples(p, 128);
    if (st == AMSCR_OK && s->partial)
        st = amscr_params_set_partial(p, 1);
    if (st == AMSCR_OK && s->symmetric)
        st = amscr_params_set_symmetric(p, 1);
    const char *opt_in[] = {"despike", "order", "even_spacing"}; /* every stage on */
    for (size_t i = 0; i < 3 && st == AMSCR_OK; i++)
        st = amscr_params_set_stage(p, opt_in[i], 1);
    if (st == AMSCR_OK && s->traced == 3) /* the small image the source, onto a large image's trace */
        st = large_trace(b, nt, &tgt);
    else if (st == AMSCR_OK)
        st = s->traced ? traced_target(b, nt, s->traced == 2 ? AMSCR_TRACE_PIXEL_CHAIN : 0, &tgt)
                       : amscr_contour_new(b + 2 * s->drop, nt, &tgt);
    if (st == AMSCR_OK && s->traced == 2) /* the chain onto itself: both traced again */
        st = amscr_contour_new(amscr_contour_xy(tgt), amscr_contour_size(tgt), &src);
    else if (st == AMSCR_OK && s->traced == 3)
        st = traced_target(a, ns, 0, &src);
    else if (st == AMSCR_OK)
        st = amscr_contour_new(a, ns, &src);
    if (st == AMSCR_OK)
        st = amscr_register_contours(p, src, tgt, out);
    amscr_contour_free(src);
    amscr_contour_free(tgt);
    amscr_params_free(p);
    __real_free(a);
    __real_free(b);
    return st;
}

static int stage_ran(const amscr_result *r, const char *name)
{
    for (size_t i = 0; i < amscr_result_num_stages(r); i++) {
        const char *n;
        int ran;
        if (amscr_result_stage(r, i, &n, &ran) == AMSCR_OK && strcmp(n, name) == 0)
            return ran;
    }
    return 0;
}

/* One registration of scenario ctx; AMSCR_E_STATE when the stage it exists for did not run. */
static amscr_status run_scenario(const void *ctx, uint64_t *digest)
{
    (void)digest; /* no fallback allowed */
    const scenario *s = ctx;
    amscr_result *r = NULL;
    amscr_status st = run(s, &r);
    if (st == AMSCR_OK && !stage_ran(r, s->must_run)) {
        printf("%s: stage %s did not run\n", s->name, s->must_run);
        st = AMSCR_E_STATE;
    }
    amscr_result_free(r);
    return st;
}

int main(void)
{
    static const scenario scenarios[] = {
        {"noisy target (polish, order, even spacing)", 400, 1600, 0, 0.01, 0, 0, "even_spacing", 0},
        {"missing run (recovery)", 300, 300, 75, 0.0, 0, 0, "recovery", 0},
        {"partial fragment", 300, 300, 0, 0.0, 1, 0, "polish", 0},
        {"symmetric distance", 300, 300, 0, 0.0, 0, 1, "symmetric", 0},
        {"small binary image (pixel grid)", 300, 300, 0, 0.0, 0, 0, "pixel_grid", 1},
        {"small binary image's pixel chain onto itself (both traced again)", 300, 300, 0, 0.0, 0, 0, "pixel_grid", 2},
        {"small binary image as the source, onto a large image's trace (pixel grid)", 300, 300, 0, 0.0, 0, 0,
         "pixel_grid", 3},
    };
    int bad = 0;
    setvbuf(stdout, NULL, _IOLBF, 0); /* each scenario's line out before a crash */
    for (size_t i = 0; i < sizeof scenarios / sizeof scenarios[0]; i++)
        bad += oom_check(scenarios[i].name, run_scenario, &scenarios[i], oom_stride());
    return bad ? 1 : 0;
}
