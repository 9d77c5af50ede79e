/* oom_wrap.c — the link-time allocation wrappers and the loop of oom_wrap.h. */
#include "oom_wrap.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void *__real_calloc(size_t n, size_t s);
void *__real_realloc(void *p, size_t n);

static long counted, fail_at; /* allocations since arming; the one to fail (0: none) */
static int armed;

/* The blocks allocated while armed and not freed yet (an open-addressing set of pointers): a
 * block allocated before arming, or while paused, may be freed while armed. */
enum { SET_BITS = 20, SET_SIZE = 1 << SET_BITS };
static void *blocks[SET_SIZE];
static long live; /* blocks in the set */

static size_t slot_of(const void *p)
{
    size_t h = (size_t)((uint64_t)(uintptr_t)p * 11400714819323198485u >> (64 - SET_BITS)); /* Fibonacci hashing */
    while (blocks[h] != NULL && blocks[h] != p)
        h = (h + 1) & (SET_SIZE - 1);
    return h;
}
static void remember(void *p)
{
    if (p && live < SET_SIZE / 2) { /* half full at most (a scenario's blocks live at once are far fewer) */
        blocks[slot_of(p)] = p;
        live++;
    }
}
static void forget(void *p)
{
    size_t h = p ? slot_of(p) : 0;
    if (!p || blocks[h] == NULL)
        return;
    blocks[h] = NULL; /* the run after it moved up where its chain allows (backward-shift deletion) */
    for (size_t j = (h + 1) & (SET_SIZE - 1); blocks[j] != NULL; j = (j + 1) & (SET_SIZE - 1)) {
        void *q = blocks[j];
        blocks[j] = NULL;
        blocks[slot_of(q)] = q;
    }
    live--;
}

static int should_fail(void)
{
    if (!armed)
        return 0;
    return ++counted == fail_at;
}
void *__wrap_malloc(size_t n);
void *__wrap_calloc(size_t n, size_t s);
void *__wrap_realloc(void *q, size_t n);
void __wrap_free(void *p);

void *__wrap_malloc(size_t n)
{
    if (should_fail())
        return NULL;
    void *p = __real_malloc(n);
    if (armed)
        remember(p);
    return p;
}
void *__wrap_calloc(size_t n, size_t s)
{
    if (should_fail())
        return NULL;
    void *p = __real_calloc(n, s);
    if (armed)
        remember(p);
    return p;
}
void *__wrap_realloc(void *q, size_t n)
{
    if (should_fail())
        return NULL;
    void *p = __real_realloc(q, n);
    if (p) { /* a block of the set stays one under its new address; an older one stays out */
        size_t h = q ? slot_of(q) : 0;
        int known = q && blocks[h] != NULL;
        forget(q);
        if (known || (armed && !q))
            remember(p);
    }
    return p;
}
void __wrap_free(void *p)
{
    forget(p);
    __real_free(p);
}

int oom_pause(void)
{
    int was = armed;
    armed = 0;
    return was;
}

void oom_resume(int was)
{
    armed = was;
}

long oom_stride(void)
{
    const char *env = getenv("AMSCR_OOM_STRIDE");
    long stride = env ? strtol(env, NULL, 10) : 1;
    return stride > 0 ? stride : 1;
}

uint64_t oom_digest(uint64_t h, const void *bytes, size_t n)
{
    const unsigned char *b = bytes;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 1099511628211u;
    return h;
}

/* One run with allocation k failed (0: none): its status; *left the blocks it did not free,
 * *digest its results' digest (0: none). */
static amscr_status run_failing(oom_scenario_fn run, const void *ctx, long k, long *left, uint64_t *digest)
{
    counted = 0;
    fail_at = k;
    armed = 1;
    *digest = 0;
    amscr_status st = run(ctx, digest);
    armed = 0;
    *left = live;
    if (live != 0) { /* the blocks it left are forgotten: each run counts its own */
        memset(blocks, 0, sizeof blocks);
        live = 0;
    }
    return st;
}

int oom_check(const char *name, oom_scenario_fn run, const void *ctx, long stride)
{
    long left;
    uint64_t want, got;
    (void)run_failing(run, ctx, 0, &left, &want); /* a warm-up: what the fixtures keep once made */
    amscr_status st = run_failing(run, ctx, 0, &left, &want);
    long total = counted;
    if (st != AMSCR_OK || left != 0) {
        printf("FAIL %s: status %d (%s), %ld blocks left\n", name, (int)st, amscr_last_error_detail(), left);
        return 1;
    }
    int bad = 0, tried = 0, absorbed = 0;
    for (long k = 1; k <= total; k = k < total && k + stride > total ? total : k + stride, tried++) {
        st = run_failing(run, ctx, k, &left, &got);
        int same = st == AMSCR_OK && want != 0 && got == want;
        absorbed += same;
        if ((st != AMSCR_E_NOMEM && !same) || left != 0) {
            printf("FAIL %s: allocation %ld of %ld failed: status %d (%s), %s, %ld blocks left\n", name, k, total,
                   (int)st, amscr_last_error_detail(), st == AMSCR_OK ? "another result" : "", left);
            bad++;
        }
    }
    printf("%s: %ld allocations, %d failed in turn, each reported as out of memory%s", name, total, tried,
           bad ? " NOT" : "");
    if (absorbed)
        printf(" (%d absorbed by a fallback with the same result)", absorbed);
    printf("\n");
    return bad;
}
