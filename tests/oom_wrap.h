/* oom_wrap.h — allocation failures injected at link time, for the oom_* tests.
 *
 * A test linked with -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free against the
 * static library has every allocation the library makes pass through oom_wrap.c's wrappers.
 * oom_check runs a scenario once to count its allocations, then fails each of them in turn
 * (every stride-th and the last: AMSCR_OOM_STRIDE, which the valgrind setup sets) and checks
 * that the scenario returns AMSCR_E_NOMEM and frees everything it allocated (no leak on any
 * error path). Nothing is swallowed: a scenario that returns AMSCR_OK though an allocation
 * failed must have given the very result of the run without failures (a digest of it), i.e. only
 * a pure optimization (a pooled block) may fall back; a scenario without a digest allows no
 * fallback. The allocations of the shared libraries (LAPACK, BLAS) are not wrapped. Not
 * thread-safe: scenarios run on one thread. */
#ifndef AMSCR_OOM_WRAP_H
#define AMSCR_OOM_WRAP_H

#include <stddef.h>
#include <stdint.h>

#include "amscr.h"

void *__real_malloc(size_t n);
void __real_free(void *p);

/* A scenario: does its work, frees everything it made, returns the first failure (or a failure
 * of its own, e.g. AMSCR_E_STATE, when its counting run did not reach what it exists for). On
 * AMSCR_OK it may set *digest to a hash of its results (oom_digest; left 0: no fallback allowed). */
typedef amscr_status (*oom_scenario_fn)(const void *ctx, uint64_t *digest);

/* FNV-1a of n bytes continued from h (start with OOM_DIGEST_START). */
#define OOM_DIGEST_START 14695981039346656037u
uint64_t oom_digest(uint64_t h, const void *bytes, size_t n);

/* Counting off (for set-up a scenario does not test) and back: returns the previous state. */
int oom_pause(void);
void oom_resume(int was);

/* The scenario's allocations failed in turn, as above; prints one line; returns the failures. */
int oom_check(const char *name, oom_scenario_fn run, const void *ctx, long stride);

/* The stride from AMSCR_OOM_STRIDE (1 when unset). */
long oom_stride(void);

#endif
