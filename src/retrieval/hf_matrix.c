/* hf_matrix.c — the shape channel over a whole collection: the height functions of every
 * shape (once), then the upper triangle of the pair distances a few rows at a time on threads
 * (rows.c: every cell computed by the same code, so the result does not depend on the thread
 * count), mirrored into a symmetric matrix with a zero diagonal. */
#include "channel.h"
#include "rows.h"

#include <math.h>
#include <stdlib.h>

typedef struct {
    const amscr__hf *hf;
    size_t n;
    const amscr__hf_cfg *cfg;
    double *out;
} hfm_t;

static amscr_status hfm_init(void *ctx, void **ws)
{
    const hfm_t *m = ctx;
    amscr__hf_ws *w = malloc(sizeof *w);
    if (!w || amscr__hf_ws_init(w, m->hf[0].n, m->cfg->band) != AMSCR_OK) {
        free(w);
        return AMSCR_E_NOMEM;
    }
    *ws = w;
    return AMSCR_OK;
}

static void hfm_fini(void *ws)
{
    amscr__hf_ws_free(ws);
    free(ws);
}

/* Rows a task takes: the columns of a group of AMSCR__HF_GROUP are read for each of its rows
 * while they are still in the processor's cache (a shape's spectra are ~10 KB a frame). */
#define HFM_ROWS 4

/* Task t: rows HFM_ROWS t .. HFM_ROWS t + HFM_ROWS - 1, their upper-triangle cells taken column
 * group by column group, each group's pairs side by side (the same values as one by one). */
static amscr_status hfm_row(void *ctx, size_t t, void *ws)
{
    const hfm_t *m = ctx;
    size_t i0 = t * HFM_ROWS, i1 = i0 + HFM_ROWS < m->n ? i0 + HFM_ROWS : m->n;
    for (size_t c = i0 + 1; c < m->n; c += AMSCR__HF_GROUP) {
        size_t c1 = c + AMSCR__HF_GROUP < m->n ? c + AMSCR__HF_GROUP : m->n;
        for (size_t i = i0; i < i1; i++) {
            size_t j0 = c > i + 1 ? c : i + 1;
            if (j0 >= c1)
                continue;
            const amscr__hf *a[AMSCR__HF_GROUP], *b[AMSCR__HF_GROUP];
            for (size_t j = j0; j < c1; j++) {
                a[j - j0] = &m->hf[i];
                b[j - j0] = &m->hf[j];
            }
            amscr__hf_distances(a, b, c1 - j0, m->cfg, ws, m->out + i * m->n + j0);
        }
    }
    return AMSCR_OK;
}

void amscr__mirror_upper(double *out, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        out[i * n + i] = 0.0;
        for (size_t j = i + 1; j < n; j++)
            out[j * n + i] = out[i * n + j];
    }
}

amscr_status amscr__hf_matrix(const amscr__hf *hf, size_t n, const amscr__hf_cfg *cfg, unsigned threads,
                              amscr_progress_fn progress, void *user, double *out)
{
    if (n == 0)
        return AMSCR_OK;
    hfm_t m = {hf, n, cfg, out};
    amscr__rows_fn f = {hfm_init, hfm_fini, hfm_row, &m, "shape channel"};
    amscr_status st = amscr__run_rows(&f, 0, (n + HFM_ROWS - 1) / HFM_ROWS, threads, progress, user);
    if (st != AMSCR_OK) {
        for (size_t i = 0; i < n * n; i++)
            out[i] = NAN;
        return st;
    }
    amscr__mirror_upper(out, n);
    return AMSCR_OK;
}
