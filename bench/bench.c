/* amscr-bench — speed of preparation and many-vs-many matching on a synthetic collection of
 * MPEG-7 size (1400 shapes, 70 classes of perturbed, affine-distorted random shapes).
 * Prints shapes/s, pairs/s, seconds for all threads and for one thread, per-stage timings,
 * and checks that both matrices are bit-identical.
 *
 *   amscr-bench [--shapes N] [--classes C]
 *
 * Not a test: it prints numbers. Run through `meson compile -C build bench`. */
#include <amscr.h>

#define BENCH_PROGRAM "amscr-bench"
#include "bench_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

void amscr__workspace_stage_times(const amscr_workspace *ws, double out[4]);

#define H 8
/* Class prototype: radius harmonics; instance: prototype + small perturbation, affine map,
 * noise, random start and point count. */
static void make_shape(const double *a, const double *b, size_t n, double *xy)
{
    double pa[H], pb[H];
    for (int k = 0; k < H; k++) {
        pa[k] = a[k] + 0.03 * gauss() / (1 + k);
        pb[k] = b[k] + 0.03 * gauss() / (1 + k);
    }
    double th = 6.283185307179586 * uni(), s1 = 1 + 0.6 * uni(), s2 = 1 / (1 + 0.6 * uni()), sh = 0.4 * (2 * uni() - 1);
    double c = cos(th), s = sin(th), start = 6.283185307179586 * uni();
    for (size_t i = 0; i < n; i++) {
        double t = start + 6.283185307179586 * (double)i / (double)n, r = 1;
        for (int k = 0; k < H; k++)
            r += pa[k] * cos((k + 2) * t) + pb[k] * sin((k + 2) * t);
        if (r < 0.2)
            r = 0.2;
        double x = r * cos(t), y = r * sin(t);
        double u = s1 * (x + sh * y), v = s2 * y;
        xy[2 * i] = 100 * (c * u - s * v) + 3 * gauss() * 0.2;
        xy[2 * i + 1] = 100 * (s * u + c * v) + 3 * gauss() * 0.2;
    }
}

int main(int argc, char **argv)
{
    size_t nshapes = 1400, nclasses = 70;
    const int reflections = 1;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--shapes"))
            nshapes = (size_t)atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--classes"))
            nclasses = (size_t)atol(argv[i + 1]);
        else {
            fprintf(stderr, "usage: amscr-bench [--shapes N] [--classes C]\n");
            return 2;
        }
    }
    if (nshapes < 2 || nclasses < 1 || nclasses > nshapes) {
        fprintf(stderr, "amscr-bench: bad sizes\n");
        return 2;
    }
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    amscr_params *p = NULL;
    amscr_db *db = NULL, *db1 = NULL;
    if (amscr_params_new(&p) || amscr_params_set_reflections(p, reflections) || amscr_db_new(p, &db) ||
        amscr_params_set_num_threads(p, 1) || amscr_db_new(p, &db1))
        die("params");
    /* the collection */
    double *protos = malloc(nclasses * 2 * H * sizeof(double));
    rng_state = 12345;
    for (size_t c = 0; c < nclasses; c++)
        for (int k = 0; k < 2 * H; k++)
            protos[c * 2 * H + k] = 0.3 * (2 * uni() - 1) / (1 + 0.5 * k);
    amscr_contour **contours = malloc(nshapes * sizeof *contours);
    size_t total_points = 0;
    for (size_t i = 0; i < nshapes; i++) {
        size_t c = i % nclasses, n = 250 + (size_t)(350 * uni());
        double *xy = malloc(2 * n * sizeof(double));
        make_shape(protos + c * 2 * H, protos + c * 2 * H + H, n, xy);
        if (amscr_contour_new(xy, n, &contours[i]))
            die("contour");
        total_points += n;
        free(xy);
    }
    double t0 = now();
    for (size_t i = 0; i < nshapes; i++)
        if (amscr_db_add_contour(db, contours[i], (int32_t)(i % nclasses), NULL))
            die("prepare");
    double t_prep = now() - t0;
    for (size_t i = 0; i < nshapes; i++)
        if (amscr_db_add_descriptor(db1, amscr_db_descriptor(db, i), amscr_db_label(db, i), NULL))
            return 1;
    double *D = malloc(nshapes * nshapes * sizeof(double)), *D1 = malloc(nshapes * nshapes * sizeof(double));
    double pairs = (double)nshapes * (double)(nshapes - 1);
    printf("amscr %s benchmark: %zu shapes in %zu classes (%.0f points each on average), N = %zu, %zu scales, "
           "reflections %s, method multiclass-em\n",
           amscr_version_string(), nshapes, nclasses, (double)total_points / (double)nshapes,
           amscr_params_get_num_samples(p), amscr_descriptor_num_scales(amscr_db_descriptor(db, 0)),
           reflections ? "on" : "off");
    printf("machine: %ld cores\n", cores);
    printf("prepare:            %8.3f s   %10.0f shapes/s (1 thread)\n", t_prep, (double)nshapes / t_prep);
    double t_mat[2]; /* the matrix on every core (db), then on one thread (db1) */
    for (int k = 0; k < 2; k++) {
        fflush(stdout);
        t0 = now();
        if (amscr_db_distance_matrix(k ? db1 : db, NULL, NULL, k ? D1 : D))
            die("distance matrix");
        t_mat[k] = now() - t0;
        printf("matrix, %2ld thread%s %8.3f s   %10.0f pairs/s   %.2f us/pair\n", k ? 1L : cores, k ? ": " : "s:",
               t_mat[k], pairs / t_mat[k], 1e6 * t_mat[k] / pairs);
    }
    printf("speed-up %.2fx on %ld cores; matrices bit-identical: %s\n", t_mat[1] / t_mat[0], cores,
           memcmp(D, D1, nshapes * nshapes * sizeof(double)) == 0 ? "yes" : "NO");
    /* per-stage timings on a sample of pairs (1 thread, one workspace) */
    amscr_workspace *ws = NULL;
    if (amscr_workspace_new(&ws))
        return 1;
    size_t sample = nshapes < 200 ? nshapes : 200;
    double d;
    t0 = now();
    for (size_t i = 0; i < sample; i++)
        for (size_t j = 0; j < sample; j++)
            if (i != j && amscr_distance(p, amscr_db_descriptor(db, i), amscr_db_descriptor(db, j), ws, &d))
                return 1;
    double t_s = now() - t0, st[4];
    amscr__workspace_stage_times(ws, st);
    double np = (double)sample * (double)(sample - 1);
    printf("per pair (%zu x %zu sample, 1 thread): total %.2f us = shift search %.2f + per-scale solves %.2f + "
           "selection %.2f + final solve %.2f (+ %.2f other)\n",
           sample, sample, 1e6 * t_s / np, 1e6 * st[0] / np, 1e6 * st[1] / np, 1e6 * st[2] / np, 1e6 * st[3] / np,
           1e6 * (t_s - st[0] - st[1] - st[2] - st[3]) / np);
    /* retrieval on the synthetic classes (a sanity check of the matrix) */
    int32_t *labels = malloc(nshapes * sizeof *labels);
    for (size_t i = 0; i < nshapes; i++)
        labels[i] = (int32_t)(i % nclasses);
    double be = 0, nn = 0;
    if (amscr_score_bullseye(D, nshapes, labels, 0, &be) || amscr_score_nn_accuracy(D, nshapes, labels, &nn))
        return 1;
    printf("synthetic retrieval: bull's eye %.2f %%, 1-NN %.2f %%\n", 100 * be, 100 * nn);
    amscr_workspace_free(ws);
    for (size_t i = 0; i < nshapes; i++)
        amscr_contour_free(contours[i]);
    free(contours);
    free(protos);
    free(D);
    free(D1);
    free(labels);
    amscr_db_free(db);
    amscr_db_free(db1);
    amscr_params_free(p);
    return 0;
}
