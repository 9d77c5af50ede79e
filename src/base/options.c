/* options.c — every number and flag of amscr_params, declared once (OPTIONS below): its key, its
 * field, its C type, its kind (integer or real) and the values it accepts. Both doors come from
 * that list and validate through the one check(): the named pairs amscr_params_set_<name> /
 * amscr_params_get_<name>, and the keyed calls amscr_params_set_int / _set_real / _get_int /
 * _get_real / _get_bounds. Options added from now on get a key here and no new pair. */
#include "internal.h"

#include <stdio.h>
#include <stdlib.h>

enum { KIND_INT, KIND_REAL };
/* Which values in [lo, hi] are accepted. */
enum {
    RULE_RANGE,   /* lo <= v <= hi */
    RULE_OPEN_LO, /* lo < v <= hi */
    RULE_OPEN_HI, /* lo <= v < hi */
    RULE_ZERO_OR  /* v == 0, or lo <= v <= hi */
};

/* X(KEY, name, C type, kind, lo, hi, rule): AMSCR_OPT_<KEY> sets the field `name` of amscr_params,
 * which the named pair amscr_params_set_<name> / amscr_params_get_<name> also sets and reads. */
#define OPTIONS(X)                                                                             \
    X(NUM_SAMPLES, num_samples, size_t, INT, 16, AMSCR_MAX_SAMPLES, RANGE)                     \
    X(CLOSED, closed, int, INT, 0, 1, RANGE)                                                   \
    X(PARAMETRIZATION, parametrization, amscr_parametrization, INT, 0, 2, RANGE)               \
    X(PRESMOOTH, presmooth, double, REAL, 0.0, 0.25, RANGE)                                    \
    X(ARCLENGTH_PASSES, arclength_passes, unsigned, INT, 1, 10, RANGE)                         \
    X(OVERSAMPLING, oversampling, unsigned, INT, 1, 64, RANGE)                                 \
    X(METHOD, method, amscr_method, INT, 0, 3, RANGE)                                          \
    X(KMAX, kmax, unsigned, INT, 1, AMSCR__KMAX, RANGE)                                        \
    X(REFLECTIONS, reflections, int, INT, 0, 1, RANGE)                                         \
    X(SYMMETRIC, symmetric, int, INT, 0, 1, RANGE)                                             \
    X(INVARIANCE, invariance, amscr_invariance, INT, 0, 2, RANGE)                              \
    X(PENALTY, penalty, double, REAL, 0.0, 1e6, RANGE)                                         \
    X(REFINE, refine, unsigned, INT, 0, 50, RANGE)                                             \
    X(PARTIAL, partial, int, INT, 0, 1, RANGE)                                                 \
    X(POLISH, polish, int, INT, 0, 1, RANGE)                                                   \
    X(NUM_THREADS, num_threads, unsigned, INT, 0, 1024, RANGE)                                 \
    X(CHANNEL_WEIGHT, channel_weight, double, REAL, 0.0, 1.0, RANGE)                           \
    X(CHANNEL_INVARIANCE, channel_invariance, amscr_invariance, INT, 0, 1, RANGE)              \
    X(CHANNEL_AFFINE_SHARE, channel_affine_share, double, REAL, 0.0, 1.0, RANGE)               \
    X(CHANNEL_BAND, channel_band, double, REAL, 0.0, 0.5, OPEN_LO)                             \
    X(CHANNEL_AFFINE_BAND, channel_affine_band, double, REAL, 0.0, 0.5, OPEN_LO)               \
    X(CHANNEL_SKIP, channel_skip, double, REAL, 0.0, 1e3, RANGE)                               \
    X(CHANNEL_LOCALITY, channel_locality, double, REAL, 0.0, 1e3, RANGE)                       \
    X(RERANK_K, rerank_k, unsigned, INT, 0, 1000, RANGE)                                       \
    X(RERANK_ITERATIONS, rerank_iterations, unsigned, INT, 1, 1000, RANGE)                     \
    X(RERANK_INNER_SHARE, rerank_inner_share, double, REAL, 0.0, 1.0, OPEN_HI)                 \
    X(INNER_CLOSING, inner_closing, double, REAL, 0.0, 1.0, RANGE)                             \
    X(CHANNEL_AFFINE_VIEW, channel_affine_view, double, REAL, 1.0, 100.0, ZERO_OR)

typedef struct {
    const char *name; /* NULL: no such key */
    int kind, rule;
    double lo, hi;
} option_t;

#define ROW(KEY, name, type, kind, lo, hi, rule) [AMSCR_OPT_##KEY] = {#name, KIND_##kind, RULE_##rule, lo, hi},
static const option_t TABLE[] = {OPTIONS(ROW)};
#define NUM_ROWS (sizeof TABLE / sizeof TABLE[0])

static const option_t *find(amscr_option key)
{
    size_t i = (size_t)(unsigned)key;
    return i < NUM_ROWS && TABLE[i].name ? &TABLE[i] : NULL;
}

/* v in the fewest digits that read back as v ("1.0000001", not %g's "1"). */
static const char *exact(double v, char buf[32])
{
    for (int prec = 6; prec <= 17; prec++) {
        snprintf(buf, 32, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    return buf;
}

/* AMSCR_OK when o accepts v (NaN never), else AMSCR_E_INVALID_ARG with a detail naming `who`.
 * wrapped: v came through an unsigned 32-bit type (an enum or unsigned field), so a value of
 * 2^31 or more is shown as the int the caller most likely passed (-1, not 4294967295). */
static amscr_status check(const option_t *o, double v, const char *who, int wrapped)
{
    int zero = o->rule == RULE_ZERO_OR && v == 0.0;
    int above = o->rule == RULE_OPEN_LO ? v > o->lo : v >= o->lo;
    int below = o->rule == RULE_OPEN_HI ? v < o->hi : v <= o->hi;
    if (zero || (above && below))
        return AMSCR_OK;
    if (o->kind == KIND_INT) {
        double shown = wrapped && v >= 2147483648.0 ? v - 4294967296.0 : v;
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s %.0f is not in %.0f..%.0f", who, o->name, shown, o->lo,
                           o->hi);
    }
    char b[32];
    return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s %s is not %sin %c%g, %g%c", who, o->name, exact(v, b),
                       o->rule == RULE_ZERO_OR ? "0 or " : "", o->rule == RULE_OPEN_LO ? '(' : '[', o->lo, o->hi,
                       o->rule == RULE_OPEN_HI ? ')' : ']');
}

/* ---- the named pairs: amscr_params_set_<name> and amscr_params_get_<name> ---- */
#define NAMED(KEY, name, type, kind, lo, hi, rule)                                                                  \
    AMSCR__SETTER(amscr_params_set_##name, amscr_params, p, type, name,                                             \
                  check(&TABLE[AMSCR_OPT_##KEY], (double)v, __func__, sizeof(type) == 4 && (type)-1 > 0))           \
    AMSCR__GETTER(amscr_params_get_##name, amscr_params, type, name)
OPTIONS(NAMED)

/* ---- the keyed calls ---- */
#define STORE(KEY, name, type, kind, lo, hi, rule)                                                                  \
    case AMSCR_OPT_##KEY:                                                                                          \
        p->name = (type)v;                                                                                         \
        break;
static void store(amscr_params *p, amscr_option key, double v)
{
    switch (key) {
        OPTIONS(STORE)
    default:
        break;
    }
}

#define LOAD(KEY, name, type, kind, lo, hi, rule)                                                                   \
    case AMSCR_OPT_##KEY:                                                                                          \
        return (double)p->name;
static double load(const amscr_params *p, amscr_option key)
{
    switch (key) {
        OPTIONS(LOAD)
    default:
        return 0.0;
    }
}

/* The row of key when it is of `kind`; otherwise AMSCR_E_INVALID_ARG with a detail naming `who`. */
static amscr_status find_kind(amscr_option key, int kind, const char *who, const option_t **out)
{
    const option_t *o = find(key);
    if (!o)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %d is not an option key", who, (int)key);
    if (o->kind != kind)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s is %s option (amscr_params_%s)", who, o->name,
                           o->kind == KIND_INT ? "an integer" : "a real",
                           o->kind == KIND_INT ? "set_int / get_int" : "set_real / get_real");
    *out = o;
    return AMSCR_OK;
}

/* Validates v for key (of `kind`) and stores it in p. */
static amscr_status set_keyed(amscr_params *p, amscr_option key, int kind, double v, const char *who)
{
    const option_t *o = NULL;
    amscr_status st = find_kind(key, kind, who, &o);
    if (st == AMSCR_OK)
        st = check(o, v, who, 0);
    if (st == AMSCR_OK)
        store(p, key, v);
    return st;
}

amscr_status amscr_params_set_int(amscr_params *p, amscr_option key, int v)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    return set_keyed(p, key, KIND_INT, (double)v, __func__);
}

amscr_status amscr_params_set_real(amscr_params *p, amscr_option key, double v)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    return set_keyed(p, key, KIND_REAL, v, __func__);
}

amscr_status amscr_params_get_int(const amscr_params *p, amscr_option key, int *out_v)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(out_v);
    const option_t *o = NULL;
    amscr_status st = find_kind(key, KIND_INT, __func__, &o);
    if (st == AMSCR_OK)
        *out_v = (int)load(p, key);
    return st;
}

amscr_status amscr_params_get_real(const amscr_params *p, amscr_option key, double *out_v)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(p);
    AMSCR_CHECK_NULL(out_v);
    const option_t *o = NULL;
    amscr_status st = find_kind(key, KIND_REAL, __func__, &o);
    if (st == AMSCR_OK)
        *out_v = load(p, key);
    return st;
}

amscr_status amscr_params_get_bounds(amscr_option key, double *out_lo, double *out_hi)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out_lo);
    AMSCR_CHECK_NULL(out_hi);
    const option_t *o = find(key);
    if (!o)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_params_get_bounds: %d is not an option key", (int)key);
    *out_lo = o->rule == RULE_ZERO_OR ? 0.0 : o->lo;
    *out_hi = o->hi;
    return AMSCR_OK;
}
