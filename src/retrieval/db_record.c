/* db_record.c — one shape's record in a collection file (db_record.h): the compact record a save
 * writes (the input samples and, when the params close the inner distance's silhouette, its
 * outline), and a record decoded into a prepared shape with the checks a load makes (finite
 * values, levels with extent, a full record's input that rebuilds). db.c decodes a lazily loaded
 * shape here; db_io.c every shape of a file. */
#include "db_record.h"
#include "dense.h"
#include "inner.h" /* amscr__inner_vertices */

#include <stdlib.h>
#include <string.h>

int amscr__db_write_compact(const amscr_descriptor *d, int32_t label, const amscr_params *prm, amscr__wbuf *w)
{
    amscr__w_u32(w, (uint32_t)label);
    amscr__w_f64s(w, d->input, 2 * prm->num_samples);
    if (!amscr__db_has_outline(AMSCR__DB_VERSION_INDEX_COMPACT, prm))
        return 1;
    double V[2 * AMSCR__OUTLINE_N];
    if (amscr__inner_vertices(d, prm->inner_closing, V) != AMSCR_OK)
        return 0; /* only out of memory: a prepared shape's samples always resample */
    amscr__w_f64s(w, V, 2 * AMSCR__OUTLINE_N);
    return 1;
}

/* Whether shape records of `per` bytes (params prm) end with an outline: longer than a record
 * without one. */
int amscr__db_outline_kept(size_t per, int compact, const amscr_params *prm)
{
    return per > amscr__db_shape_bytes(compact ? AMSCR__DB_VERSION_INDEX_COMPACT : AMSCR__DB_VERSION_PLAIN,
                                       &(amscr_params){.num_samples = prm->num_samples,
                                                       .num_scales = prm->num_scales});
}

/* Whether the curve xy (n points) has an invertible moment matrix (amscr__descriptor_finish's
 * test). */
int amscr__db_level_ok(const double *xy, size_t n)
{
    double mom[6], M9[9], inv[9];
    amscr__moments(xy, n, mom);
    amscr__moment_matrix(mom, M9);
    return amscr__inv3(M9, inv);
}

/* Whether a full record's input (d's) rebuilds into a prepared shape, as it must: a save keeps only
 * the input (a compact record) and a load rebuilds from it. AMSCR_OK, AMSCR_E_DEGENERATE, or
 * AMSCR_E_NOMEM. */
static amscr_status input_rebuilds(const amscr_descriptor *d)
{
    amscr_descriptor *t = NULL;
    if (amscr__descriptor_alloc(d->n, d->p, &t) != AMSCR_OK)
        return AMSCR_E_NOMEM;
    t->params = d->params;
    memcpy(t->input, d->input, 2 * d->n * sizeof *t->input);
    amscr_status st = amscr__descriptor_rebuild(t);
    amscr_descriptor_free(t);
    return st;
}

/* Shape bytes at `at` decoded: 0, or 1 truncated / not finite, 2 degenerate, 3 out of memory. A
 * full record's input must have extent, and with rebuild_check rebuild (an index's: its save keeps
 * only the input; a plain collection's stored levels are trusted, its load twice as fast). */
int amscr__db_decode_shape(const unsigned char *p, size_t at, size_t per, int compact, int rebuild_check,
                           const amscr_params *prm, int32_t *label, amscr_descriptor **out)
{
    size_t N = prm->num_samples, np = prm->num_scales;
    int outline = amscr__db_outline_kept(per, compact, prm);
    amscr__rbuf r = {p, at + per, at, 0};
    *label = (int32_t)amscr__r_u32(&r);
    amscr_descriptor *d = NULL;
    if (amscr__descriptor_alloc(N, np, &d) != AMSCR_OK)
        return 3;
    d->params = *prm;
    int bad = 0;
    if (compact ? !amscr__r_f64s(&r, d->input, 2 * N)
                : (!amscr__r_f64s(&r, d->fwd, 6) || !amscr__r_f64s(&r, d->inv, 6) ||
                   !amscr__r_f64s(&r, d->input, 2 * N) || !amscr__r_f64s(&r, d->base, 2 * N) ||
                   !amscr__r_f64s(&r, d->scaled, 2 * N * np)))
        bad = 1;
    else if (outline && !(d->outline = amscr__malloc_array(2 * AMSCR__OUTLINE_N, sizeof *d->outline)))
        bad = 3;
    else if (outline && !amscr__r_f64s(&r, d->outline, 2 * AMSCR__OUTLINE_N))
        bad = 1;
    else {
        amscr_status st = compact ? amscr__descriptor_rebuild(d) : amscr__descriptor_finish(d);
        if (st == AMSCR_OK && !compact)
            st = !amscr__db_level_ok(d->input, N) ? AMSCR_E_DEGENERATE : rebuild_check ? input_rebuilds(d) : AMSCR_OK;
        bad = st == AMSCR_OK ? 0 : st == AMSCR_E_DEGENERATE ? 2 : 3;
    }
    if (bad) {
        amscr_descriptor_free(d);
        return bad;
    }
    *out = d;
    return 0;
}

amscr_status amscr__db_decode(const unsigned char *p, size_t at, size_t per, int compact, const amscr_params *prm,
                              int32_t *label, amscr_descriptor **out)
{
    int32_t lab = 0;
    int bad = amscr__db_decode_shape(p, at, per, compact, 0, prm, &lab, out);
    if (bad == 1)
        return amscr__fail(AMSCR_E_FORMAT, "collection: a shape is truncated or has non-finite values");
    if (bad == 2)
        return amscr__fail(AMSCR_E_FORMAT, "collection: a shape is degenerate");
    if (bad == 3)
        return amscr__fail(AMSCR_E_NOMEM, "collection: out of memory");
    if (label)
        *label = lab;
    return AMSCR_OK;
}
