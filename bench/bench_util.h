/* bench_util.h — the benchmarks' error exit (with allocation and preparation), clocks, qsort comparison and
 * seeded random numbers (splitmix64; one generator per program: each benchmark is single-threaded where it draws). */
#ifndef AMSCR_BENCH_UTIL_H
#define AMSCR_BENCH_UTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "amscr.h"

#ifdef BENCH_PROGRAM
/* Prints "BENCH_PROGRAM: WHAT: the library's last error detail" and exits 1 (a program that
 * dies defines BENCH_PROGRAM, its name, before it includes this header). */
static inline void die(const char *what)
{
    fprintf(stderr, "%s: %s: %s\n", BENCH_PROGRAM, what, amscr_last_error_detail());
    exit(1);
}

/* malloc that dies when out of memory. */
static inline void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p)
        die("out of memory");
    return p;
}

/* c prepared with p; dies on failure. */
static inline amscr_descriptor *prepare(const amscr_params *p, const amscr_contour *c)
{
    amscr_descriptor *d = NULL;
    if (amscr_descriptor_new(p, c, &d) != AMSCR_OK)
        die("prepare");
    return d;
}
#endif

static inline double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Thread CPU seconds: every call timed runs on this thread (and the machine may be shared). */
static inline double cpu_now(void)
{
    struct timespec t;
    return clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) == 0 ? (double)t.tv_sec + 1e-9 * (double)t.tv_nsec : NAN;
}

/* qsort order of doubles. */
static inline int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static uint64_t rng_state;

/* Uniform in [0, 1). */
static inline double uni(void)
{
    uint64_t z = (rng_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

/* Standard normal (Box-Muller). */
static inline double gauss(void)
{
    double u = uni(), v = uni();
    return sqrt(-2.0 * log(u > 1e-300 ? u : 1e-300)) * cos(6.283185307179586 * v);
}

#endif
