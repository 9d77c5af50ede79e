/* testutil.c — see testutil.h. */
#include "testutil.h"

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void amscr_test_rng_seed(amscr_test_rng *r, uint64_t seed) { r->s = seed * 0x9E3779B97F4A7C15ull + 1; }

uint64_t amscr_test_rng_next(amscr_test_rng *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double amscr_test_uniform(amscr_test_rng *r) { return (double)(amscr_test_rng_next(r) >> 11) * 0x1.0p-53; }

double amscr_test_normal(amscr_test_rng *r)
{
    double u1 = amscr_test_uniform(r), u2 = amscr_test_uniform(r);
    if (u1 < 1e-300)
        u1 = 1e-300;
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

void amscr_test_random_shape(amscr_test_rng *r, size_t n, int complexity, double *xy)
{
    double a[16], b[16];
    if (complexity > 16)
        complexity = 16;
    for (int k = 0; k < complexity; k++) {
        double amp = 0.35 / (1.0 + 0.6 * k);
        a[k] = amp * (2.0 * amscr_test_uniform(r) - 1.0);
        b[k] = amp * (2.0 * amscr_test_uniform(r) - 1.0);
    }
    for (size_t i = 0; i < n; i++) {
        double t = 2.0 * M_PI * (double)i / (double)n;
        double rad = 1.0;
        for (int k = 0; k < complexity; k++)
            rad += a[k] * cos((k + 2) * t) + b[k] * sin((k + 2) * t);
        if (rad < 0.15)
            rad = 0.15;
        xy[2 * i] = rad * cos(t);
        xy[2 * i + 1] = rad * sin(t);
    }
}

void amscr_test_ellipse(size_t n, double a, double b, double phase, double *xy)
{
    for (size_t i = 0; i < n; i++) {
        double t = phase + 2.0 * M_PI * (double)i / (double)n;
        xy[2 * i] = a * cos(t);
        xy[2 * i + 1] = b * sin(t);
    }
}

void amscr_test_random_affine(amscr_test_rng *r, double smax, double shear, double tmax, int reflect,
                              double m6[6])
{
    double th = 2.0 * M_PI * amscr_test_uniform(r), ph = 2.0 * M_PI * amscr_test_uniform(r);
    double s1 = 1.0 + (smax - 1.0) * amscr_test_uniform(r);
    double s2 = 1.0 / (1.0 + (smax - 1.0) * amscr_test_uniform(r));
    double h = shear * (2.0 * amscr_test_uniform(r) - 1.0);
    double scale = 0.5 + 2.0 * amscr_test_uniform(r);
    /* M = R(th) * diag(s1, s2) * [[1, h], [0, 1]] * R(ph) * scale */
    double R1[4] = {cos(th), -sin(th), sin(th), cos(th)};
    double R2[4] = {cos(ph), -sin(ph), sin(ph), cos(ph)};
    double D[4] = {s1, s1 * h, 0, s2};
    double T[4], M[4];
    T[0] = D[0] * R2[0] + D[1] * R2[2];
    T[1] = D[0] * R2[1] + D[1] * R2[3];
    T[2] = D[2] * R2[0] + D[3] * R2[2];
    T[3] = D[2] * R2[1] + D[3] * R2[3];
    M[0] = R1[0] * T[0] + R1[1] * T[2];
    M[1] = R1[0] * T[1] + R1[1] * T[3];
    M[2] = R1[2] * T[0] + R1[3] * T[2];
    M[3] = R1[2] * T[1] + R1[3] * T[3];
    if (reflect) {
        M[1] = -M[1];
        M[3] = -M[3];
    }
    m6[0] = scale * M[0];
    m6[1] = scale * M[1];
    m6[3] = scale * M[2];
    m6[4] = scale * M[3];
    m6[2] = tmax * (2.0 * amscr_test_uniform(r) - 1.0);
    m6[5] = tmax * (2.0 * amscr_test_uniform(r) - 1.0);
}

void amscr_test_apply_affine(const double m[6], const double *xy, size_t n, double *out)
{
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        out[2 * i] = m[0] * x + m[1] * y + m[2];
        out[2 * i + 1] = m[3] * x + m[4] * y + m[5];
    }
}

void amscr_test_cyclic_shift(const double *xy, size_t n, size_t shift, double *out)
{
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + shift) % n;
        out[2 * i] = xy[2 * j];
        out[2 * i + 1] = xy[2 * j + 1];
    }
}

void amscr_test_add_noise(amscr_test_rng *r, double *xy, size_t n, double sigma)
{
    for (size_t i = 0; i < 2 * n; i++)
        xy[i] += sigma * amscr_test_normal(r);
}

double amscr_test_shape_size(const double *xy, size_t n)
{
    double cx = 0, cy = 0, s = 0;
    for (size_t i = 0; i < n; i++) {
        cx += xy[2 * i];
        cy += xy[2 * i + 1];
    }
    cx /= (double)n;
    cy /= (double)n;
    for (size_t i = 0; i < n; i++) {
        double dx = xy[2 * i] - cx, dy = xy[2 * i + 1] - cy;
        s += dx * dx + dy * dy;
    }
    return sqrt(s / (double)n);
}

double amscr_test_max_map_error(const double m[6], const double t[6], const double *xy, size_t n)
{
    double worst = 0;
    for (size_t i = 0; i < n; i++) {
        double x = xy[2 * i], y = xy[2 * i + 1];
        double dx = (m[0] - t[0]) * x + (m[1] - t[1]) * y + (m[2] - t[2]);
        double dy = (m[3] - t[3]) * x + (m[4] - t[4]) * y + (m[5] - t[5]);
        double e = sqrt(dx * dx + dy * dy);
        if (e > worst)
            worst = e;
    }
    return worst;
}

const char *amscr_test_datasets_dir(void)
{
    static char buf[4096];
    const char *env = getenv("AMSCR_DATASETS");
    const char *cands[3] = {env, "../shared/datasets", "../../shared/datasets"};
    for (int i = 0; i < 3; i++) {
        struct stat st;
        if (!cands[i])
            continue;
        snprintf(buf, sizeof buf, "%s/kimia99", cands[i]);
        if (stat(buf, &st) == 0 && S_ISDIR(st.st_mode)) {
            snprintf(buf, sizeof buf, "%s", cands[i]);
            return buf;
        }
    }
    return NULL;
}

const char *amscr_test_datasets_or_skip(const char *suite)
{
    const char *root = amscr_test_datasets_dir();
    if (!root) {
        printf("SKIP: %s: datasets not found (set AMSCR_DATASETS)\n", suite);
        fflush(stdout);
    }
    return root;
}

int amscr_test_suite_reads_datasets(const char *suite)
{
    static const char *const readers[] = {"accuracy", "robust", "trace"};
    for (size_t i = 0; i < sizeof readers / sizeof readers[0]; i++)
        if (strcmp(suite, readers[i]) == 0)
            return 1;
    return 0;
}

int amscr_test_read_png_gray(const char *path, unsigned char **out_pixels, size_t *out_w, size_t *out_h)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path))
        return -1;
    img.format = PNG_FORMAT_GRAY;
    unsigned char *buf = malloc(PNG_IMAGE_SIZE(img));
    if (!buf) {
        png_image_free(&img);
        return -1;
    }
    if (!png_image_finish_read(&img, NULL, buf, 0, NULL)) {
        free(buf);
        png_image_free(&img);
        return -1;
    }
    *out_pixels = buf;
    *out_w = img.width;
    *out_h = img.height;
    return 0;
}

double amscr_test_shoelace(const double *xy, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        size_t j = (i + 1) % n;
        s += xy[2 * i] * xy[2 * j + 1] - xy[2 * j] * xy[2 * i + 1];
    }
    return 0.5 * s;
}

size_t amscr_test_polygon(const double *v, size_t nv, size_t m, double *out)
{
    size_t k = 0;
    for (size_t i = 0; i < nv; i++)
        for (size_t j = 0; j < m; j++, k++) {
            double s = (double)j / (double)m;
            size_t b = (i + 1) % nv;
            out[2 * k] = (1 - s) * v[2 * i] + s * v[2 * b];
            out[2 * k + 1] = (1 - s) * v[2 * i + 1] + s * v[2 * b + 1];
        }
    return k;
}

void amscr_test_star5(double *v)
{
    for (int k = 0; k < 10; k++) {
        double r = k % 2 ? 0.4 : 1.0, ang = 1.5707963267948966 + k * 0.6283185307179586;
        v[2 * k] = r * cos(ang);
        v[2 * k + 1] = r * sin(ang);
    }
}

void amscr_test_put_le(unsigned char *b, const void *v, size_t n)
{
    const uint16_t one = 1;
    const unsigned char *p = v;
    int little = *(const unsigned char *)&one == 1;
    for (size_t i = 0; i < n; i++)
        b[i] = little ? p[i] : p[n - 1 - i];
}

double amscr_test_get_f64le(const unsigned char *b)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)b[i] << (8 * i);
    double d;
    memcpy(&d, &v, sizeof d);
    return d;
}
