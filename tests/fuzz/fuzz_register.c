/* fuzz_register.c — registration of two fuzzed point lists (small N for speed).
 * Input: byte 0 and byte 1 = option bits (below), then two text point lists separated by
 * the first '|' (no '|': the target is the source itself).
 *   byte 0: bit 0 N = 16/32; bits 1-2 method; bits 3-4 parametrization (3 -> affine);
 *           bit 5 reflections; bits 6-7 invariance (3 -> affine)
 *   byte 1: bit 0 open curves; bit 1 symmetric; bits 2-3 refine 0/1/3/10;
 *           bits 4-5 oversampling 1/2/4/8; bits 6-7 arc-length passes 1..4
 * Scales {0, 1, 2, 3}. Properties on success: finite distance >= 0, equal (to rounding) to
 * amscr_distance on the same descriptors, finite maps, shift < N, kept <= scales. Curves under
 * affine invariance are registered again with the polish and every optional stage on (stray
 * points dropped, the fit on the input points, the order and even spacing of noisy points): a
 * finite map or a clean error; finite alternatives, the chosen map first. And the source as a
 * fragment of the target (partial matching): a finite map and its part of the target's boundary
 * in [0, 1), or a clean error. */
#include <math.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

static void set_ok(amscr_status st) { FUZZ_CHECK(st == AMSCR_OK); }

/* The same registration with the polish on: a finite map or a clean error. */
static void polished(const amscr_params *p, const amscr_contour *a, const amscr_contour *tgt)
{
    amscr_params *q = NULL;
    amscr_result *r = NULL;
    set_ok(amscr_params_copy(p, &q));
    set_ok(amscr_params_set_polish(q, 1));
    set_ok(amscr_params_set_stage(q, "despike", 1)); /* the opt-in stages too */
    set_ok(amscr_params_set_stage(q, "order", 1));
    set_ok(amscr_params_set_stage(q, "even_spacing", 1));
    amscr_status st = amscr_register_contours(q, a, tgt, &r);
    if (st == AMSCR_OK) {
        double m[6], c = 0.0;
        FUZZ_CHECK(amscr_result_affine(r, m) == AMSCR_OK);
        for (int i = 0; i < 6; i++)
            FUZZ_CHECK(isfinite(m[i]));
        size_t na = amscr_result_num_alternatives(r); /* the chosen map first, finite maps */
        FUZZ_CHECK(na >= 1);
        for (size_t k = 0; k < na; k++) {
            double ak[6];
            FUZZ_CHECK(amscr_result_alternative(r, k, ak, &c) == AMSCR_OK);
            for (int i = 0; i < 6; i++)
                FUZZ_CHECK(isfinite(ak[i]) && (k > 0 || ak[i] == m[i]));
        }
        amscr_result_free(r);
    } else {
        FUZZ_CHECK(r == NULL);
        FUZZ_CHECK(st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG || st == AMSCR_E_NUMERIC);
    }
    amscr_params_free(q);
}

/* The source placed on the target as a fragment: a finite map, the part within [0, 1), or a
 * clean error. */
static void partial(const amscr_params *p, const amscr_contour *a, const amscr_contour *tgt)
{
    amscr_params *q = NULL;
    amscr_result *r = NULL;
    set_ok(amscr_params_copy(p, &q));
    set_ok(amscr_params_set_partial(q, 1));
    amscr_status st = amscr_register_contours(q, a, tgt, &r);
    if (st == AMSCR_OK) {
        double m[6], s = -1.0, e = -1.0;
        FUZZ_CHECK(amscr_result_affine(r, m) == AMSCR_OK);
        for (int i = 0; i < 6; i++)
            FUZZ_CHECK(isfinite(m[i]));
        FUZZ_CHECK(amscr_result_part(r, &s, &e) == AMSCR_OK);
        FUZZ_CHECK(s >= 0.0 && s < 1.0 && e >= 0.0 && e < 1.0);
        amscr_result_free(r);
    } else {
        FUZZ_CHECK(r == NULL);
        FUZZ_CHECK(st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG || st == AMSCR_E_NUMERIC);
    }
    amscr_params_free(q);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 3)
        return 0;
    unsigned b0 = data[0], b1 = data[1];
    const char *text = (const char *)data + 2;
    size_t len = size - 2;
    const char *bar = memchr(text, '|', len);
    size_t la = bar ? (size_t)(bar - text) : len;
    amscr_contour *a = NULL, *b = NULL;
    if (amscr_contour_parse_text(text, la, &a) != AMSCR_OK)
        return 0;
    if (bar) {
        if (amscr_contour_parse_text(bar + 1, len - la - 1, &b) != AMSCR_OK) {
            amscr_contour_free(a);
            return 0;
        }
    }
    const amscr_contour *tgt = b ? b : a;

    amscr_params *p = NULL;
    set_ok(amscr_params_new(&p));
    size_t N = (b0 & 1) ? 32 : 16;
    static const double scales[] = {0.0, 1.0, 2.0, 3.0};
    static const unsigned refine[] = {0, 1, 3, 10};
    static const unsigned over[] = {1, 2, 4, 8};
    set_ok(amscr_params_set_num_samples(p, N));
    set_ok(amscr_params_set_scales(p, scales, 4));
    set_ok(amscr_params_set_method(p, (amscr_method)((b0 >> 1) & 3)));
    set_ok(amscr_params_set_parametrization(p, (amscr_parametrization)(((b0 >> 3) & 3) % 3)));
    set_ok(amscr_params_set_reflections(p, (b0 >> 5) & 1));
    set_ok(amscr_params_set_invariance(p, (amscr_invariance)(((b0 >> 6) & 3) % 3)));
    set_ok(amscr_params_set_closed(p, !(b1 & 1)));
    set_ok(amscr_params_set_symmetric(p, (b1 >> 1) & 1));
    set_ok(amscr_params_set_refine(p, refine[(b1 >> 2) & 3]));
    set_ok(amscr_params_set_oversampling(p, over[(b1 >> 4) & 3]));
    set_ok(amscr_params_set_arclength_passes(p, 1 + ((b1 >> 6) & 3)));
    set_ok(amscr_params_set_num_threads(p, 1));

    amscr_result *r = NULL;
    amscr_status st = amscr_register_contours(p, a, tgt, &r);
    if (st == AMSCR_OK) {
        FUZZ_CHECK(r != NULL);
        double d = amscr_result_distance(r);
        FUZZ_CHECK(isfinite(d) && d >= 0.0);
        double m[6], mn[6];
        FUZZ_CHECK(amscr_result_affine(r, m) == AMSCR_OK);
        FUZZ_CHECK(amscr_result_affine_normalized(r, mn) == AMSCR_OK);
        for (int i = 0; i < 6; i++)
            FUZZ_CHECK(isfinite(m[i]) && isfinite(mn[i]));
        FUZZ_CHECK(amscr_result_shift(r) < N);
        FUZZ_CHECK(amscr_result_num_scales(r) == 4);
        FUZZ_CHECK(amscr_result_num_kept(r) <= 4);
        double res[4];
        size_t nres = 4;
        FUZZ_CHECK(amscr_result_residuals(r, res, &nres) == AMSCR_OK && nres == 4);

        /* The batch path must agree with the result object. */
        amscr_descriptor *da = NULL, *db = NULL;
        set_ok(amscr_descriptor_new(p, a, &da));
        set_ok(amscr_descriptor_new(p, tgt, &db));
        double d2 = -1.0;
        set_ok(amscr_distance(p, da, db, NULL, &d2));
        FUZZ_CHECK(fabs(d2 - d) <= 1e-6 * (1.0 + d));
        amscr_descriptor_free(da);
        amscr_descriptor_free(db);
        amscr_result_free(r);
    } else {
        FUZZ_CHECK(r == NULL);
        FUZZ_CHECK(st == AMSCR_E_DEGENERATE || st == AMSCR_E_INVALID_ARG || st == AMSCR_E_NUMERIC);
    }
    if (((b0 >> 6) & 3) % 3 == 0) { /* affine */
        polished(p, a, tgt);
        partial(p, a, tgt);
    }
    amscr_params_free(p);
    amscr_contour_free(a);
    amscr_contour_free(b);
    return 0;
}
