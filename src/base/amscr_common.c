/* The base area (src/base/): what every other area builds on:
 *   amscr_common.c  errors (status strings, the thread-local detail), version, features, allocation
 *   params.c        the options object: documented defaults, presets, the scales, the stage switches
 *   options.c       its numbers and flags, each declared once: the named and the keyed setters
 *   stage_names.c   the names of amscr_register's stages and which ones are switchable
 *   internal.h      the shared internals of libamscr (never installed)
 *
 * amscr_common.c — errors, version, features, allocation helpers. */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT (Linux) */
#include "internal.h"

#if defined(__linux__)
#include <sched.h>
#endif

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define AMSCR__STR2(x) #x
#define AMSCR__STR(x) AMSCR__STR2(x)

/* Thread-local error detail: GCC/Clang's __thread in C99 mode, C11's _Thread_local elsewhere. */
#if defined(__GNUC__)
#define AMSCR_TLS __thread
#elif defined(AMSCR_HAVE_THREAD_LOCAL_KEYWORD)
#define AMSCR_TLS _Thread_local
#else
#error "amscr needs thread-local storage (__thread or _Thread_local)"
#endif

static AMSCR_TLS char amscr__detail[512];

int amscr_version_number(void) { return AMSCR_VERSION_NUMBER; }

const char *amscr_version_string(void)
{
    return AMSCR__STR(AMSCR_VERSION_MAJOR) "." AMSCR__STR(AMSCR_VERSION_MINOR) "." AMSCR__STR(
        AMSCR_VERSION_PATCH);
}

int amscr_has_feature(amscr_feature feature)
{
    switch (feature) {
    case AMSCR_FEATURE_THREADS:
        return 1;
    }
    return 0;
}

const char *amscr_strerror(amscr_status status)
{
    switch (status) {
    case AMSCR_OK: return "success";
    case AMSCR_E_INVALID_ARG: return "invalid argument";
    case AMSCR_E_NOMEM: return "out of memory";
    case AMSCR_E_IO: return "input/output error";
    case AMSCR_E_FORMAT: return "malformed or unsupported data";
    case AMSCR_E_UNSUPPORTED: return "feature not supported by this build";
    case AMSCR_E_DEGENERATE: return "degenerate input";
    case AMSCR_E_NUMERIC: return "numerical failure";
    case AMSCR_E_NOT_CONVERGED: return "did not converge";
    case AMSCR_E_NOT_FOUND: return "not found";
    case AMSCR_E_STATE: return "object in the wrong state";
    case AMSCR_E_INTERNAL: return "internal error";
    case AMSCR_E_CANCELLED: return "cancelled";
    case AMSCR_E_LIMIT: return "input exceeds a size limit";
    }
    return "unknown status code";
}

const char *amscr_last_error_detail(void) { return amscr__detail; }

void amscr__clear_error(void) { amscr__detail[0] = '\0'; }

amscr_status amscr__fail(amscr_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(amscr__detail, sizeof amscr__detail, fmt, ap);
    va_end(ap);
    return st;
}

void amscr_free(void *ptr) { free(ptr); }

void *amscr__malloc_array(size_t n, size_t size)
{
    if (size != 0 && n > SIZE_MAX / size)
        return NULL;
    return malloc((n != 0 && size != 0) ? n * size : 1);
}

void *amscr__calloc_array(size_t n, size_t size)
{
    if (n == 0 || size == 0)
        return calloc(1, 1);
    return calloc(n, size);
}

amscr_status amscr__nan_on_failure(amscr_status st, double *out, size_t rows, size_t cols)
{
    if (st != AMSCR_OK && out && (cols == 0 || rows <= SIZE_MAX / cols))
        for (size_t i = 0; i < rows * cols; i++)
            out[i] = NAN;
    return st;
}

int amscr__all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

unsigned amscr__resolve_threads(unsigned requested)
{
    if (requested > 0)
        return requested;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
#if defined(__linux__) && defined(CPU_COUNT)
    cpu_set_t set; /* the cores this process may run on (taskset, a container's cpuset) */
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        n = CPU_COUNT(&set);
#endif
    if (n < 1)
        n = 1;
    if (n > 1024)
        n = 1024;
    return (unsigned)n;
}
