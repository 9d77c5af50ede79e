/* inner_matrix.c — the inner distance (inner.c) over a whole collection: every shape's
 * features (once), then the upper triangle of the pair distances a few rows at a time on
 * threads (rows.c: every cell computed by the same code, so the result does not depend on the
 * thread count), mirrored into a symmetric matrix with a zero diagonal. */
#include "channel.h" /* amscr__mirror_upper */
#include "db_io.h"   /* amscr__db_peek */
#include "inner.h"
#include "rows.h"

#include <math.h>
#include <stdlib.h>

typedef struct {
    const amscr_db *db;
    amscr__inner *f;        /* the features built */
    const amscr__inner *cf; /* the features compared */
    size_t n;
    int reflections;
    double *out;
} inner_job;

static amscr_status job_init(void *ctx, void **ws)
{
    (void)ctx;
    return amscr__inner_ws_new(ws);
}

static amscr_status feature_row(void *ctx, size_t i, void *ws)
{
    const inner_job *m = ctx;
    size_t N = amscr_db_params(m->db)->num_samples;
    double *in = amscr__malloc_array(2 * N + 2 * AMSCR__OUTLINE_N, sizeof *in);
    if (!in)
        return amscr__fail(AMSCR_E_NOMEM, "inner distance: out of memory");
    /* a compact record's samples and outline read as they are, else a lazy collection's shape
     * decoded for this row only */
    amscr_descriptor sd, *tmp = NULL;
    const amscr_descriptor *d = &sd;
    amscr_status st = amscr__db_shallow(m->db, i, &sd, in, in + 2 * N) ? AMSCR_OK : amscr__db_peek(m->db, i, &d, &tmp);
    if (st == AMSCR_OK)
        st = amscr__inner_build_shape(d, amscr_db_params(m->db)->inner_closing, &m->f[i], ws);
    amscr_descriptor_free(tmp);
    free(in);
    return st;
}

/* Rows a task takes, and the columns each row takes at a time: a column group's features
 * (~17 KB a shape) are read for the task's rows while they are in the processor's cache. */
enum { PAIR_ROWS = 4, PAIR_COLS = 8 };

static amscr_status pair_row(void *ctx, size_t t, void *ws)
{
    const inner_job *m = ctx;
    size_t i0 = t * PAIR_ROWS, i1 = i0 + PAIR_ROWS < m->n ? i0 + PAIR_ROWS : m->n;
    for (size_t c = i0 + 1; c < m->n; c += PAIR_COLS)
        for (size_t i = i0; i < i1; i++)
            for (size_t j = c > i + 1 ? c : i + 1; j < c + PAIR_COLS && j < m->n; j++)
                m->out[i * m->n + j] = amscr__inner_distance(&m->cf[i], &m->cf[j], m->reflections, ws);
    return AMSCR_OK;
}

amscr_status amscr__inner_features(const amscr_db *db, size_t first, unsigned threads, amscr__inner *f,
                                   amscr_progress_fn progress, void *user)
{
    inner_job m = {db, f, NULL, amscr_db_size(db), 0, NULL};
    amscr__rows_fn features = {job_init, amscr__inner_ws_delete, feature_row, &m, "inner distance"};
    return amscr__run_rows(&features, first, m.n, threads, progress, user);
}

amscr_status amscr__inner_matrix_from(const amscr__inner *f, size_t n, int reflections, unsigned threads,
                                      amscr_progress_fn progress, void *user, double *out)
{
    inner_job m = {NULL, NULL, f, n, reflections, out};
    amscr__rows_fn pairs = {job_init, amscr__inner_ws_delete, pair_row, &m, "inner distance"};
    amscr_status st = amscr__run_rows(&pairs, 0, (n + PAIR_ROWS - 1) / PAIR_ROWS, threads, progress, user);
    if (st == AMSCR_OK)
        amscr__mirror_upper(out, n);
    return st;
}

amscr_status amscr__inner_matrix(const amscr_db *db, unsigned threads, amscr_progress_fn progress, void *user,
                                 double *out)
{
    size_t n = amscr_db_size(db);
    amscr__inner *f = amscr__malloc_array(n, sizeof *f);
    amscr_status st = f ? AMSCR_OK : amscr__fail(AMSCR_E_NOMEM, "inner distance: out of memory");
    if (st == AMSCR_OK)
        st = amscr__inner_features(db, 0, threads, f, NULL, NULL);
    if (st == AMSCR_OK)
        st = amscr__inner_matrix_from(f, n, amscr_db_params(db)->reflections, threads, progress, user, out);
    if (st != AMSCR_OK)
        for (size_t i = 0; i < n * n; i++)
            out[i] = NAN;
    free(f);
    return st;
}
