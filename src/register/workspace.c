/* workspace.c — the caller-owned scratch of a registration (amscr_workspace): sized on first
 * use for N samples and p scales, grown on demand, never shrunk until freed. */
#include "match.h"

#include <stdlib.h>
#include <string.h>

#ifdef AMSCR_STAGE_TIMING
#include <time.h>
double amscr__stage_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void amscr__workspace_stage_times(const amscr_workspace *ws, double out[4]);
void amscr__workspace_stage_times(const amscr_workspace *ws, double out[4])
{
    memcpy(out, ws->stage, sizeof ws->stage);
}
#endif

amscr_status amscr_workspace_new(amscr_workspace **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    amscr_workspace *ws = calloc(1, sizeof *ws);
    if (!ws)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_workspace_new: out of memory");
    *out = ws;
    return AMSCR_OK;
}

void amscr__ws_release(amscr_workspace *ws)
{
    amscr__fft_plan_free(&ws->plan);
    free(ws->z);
    free(ws->scratch);
    free(ws->qa);
    free(ws->qi);
    free(ws->rbuf);
    ws->rbuf = NULL;
    ws->rcap = 0;
    ws->z = ws->scratch = ws->qa = NULL;
    ws->qi = NULL;
    ws->n = ws->p = ws->qcap = ws->scratch_cap = 0;
}

void amscr_workspace_free(amscr_workspace *ws)
{
    if (!ws)
        return;
    amscr__ws_release(ws);
    free(ws);
}

amscr_status amscr__ws_reserve(amscr_workspace *ws, size_t n, size_t p)
{
    if (ws->n == n && ws->p >= p && ws->z)
        return AMSCR_OK;
    amscr__ws_release(ws);
    size_t half = n / 2 + 1;
    /* z 4N, crit N, P 8 (N/2+1), q 4 (N/2+1), curve 2N */
    ws->z = amscr__malloc_array(5 * n + 12 * half + 2 * n, sizeof(double));
    ws->scratch_cap = amscr__select_scratch(p);
    ws->scratch = amscr__malloc_array(ws->scratch_cap, sizeof(double));
    if (!ws->z || !ws->scratch || amscr__fft_plan_init(&ws->plan, n) != 0) {
        amscr__ws_release(ws);
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->crit = ws->z + 4 * n;
    ws->P = ws->z + 5 * n;
    ws->q = ws->P + 8 * half;
    ws->curve = ws->q + 4 * half;
    ws->n = n;
    ws->p = p;
    return AMSCR_OK;
}

amscr_status amscr__ws_reserve_qr(amscr_workspace *ws, size_t rows)
{
    if (ws->qcap >= rows)
        return AMSCR_OK;
    free(ws->qa);
    free(ws->qi);
    /* A (rows x 3) and B (rows x 2) column-major, then LAPACK's work; iwork: 3 ints (dtrcon) */
    ws->qa = amscr__malloc_array(5 * rows + amscr__lstsq_work_size(rows, 3, 2), sizeof(double));
    ws->qi = amscr__malloc_array(3, sizeof(int));
    if (!ws->qa || !ws->qi) {
        free(ws->qa);
        free(ws->qi);
        ws->qa = NULL;
        ws->qi = NULL;
        ws->qcap = 0;
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->qb = ws->qa + 3 * rows;
    ws->qw = ws->qb + 2 * rows;
    ws->qcap = rows;
    return AMSCR_OK;
}

amscr_status amscr__ws_reserve_refine(amscr_workspace *ws, size_t n)
{
    if (ws->rcap >= n && ws->rbuf)
        return AMSCR_OK;
    free(ws->rbuf);
    /* q 2n, r2 n, sorted n, q2 2n, hints n, hints2 n, dense target: at most AMSCR__DENSE n points */
    ws->rbuf = amscr__malloc_array((8 + 2 * AMSCR__DENSE) * n, sizeof(double));
    if (!ws->rbuf) {
        ws->rcap = 0;
        return amscr__fail(AMSCR_E_NOMEM, "workspace: out of memory");
    }
    ws->rcap = n;
    return AMSCR_OK;
}
