/* db_batch.c — many contours prepared on a collection's threads and added in order
 * (amscr_db_add_contours in amscr.h). Each contour is prepared by the same code whatever thread
 * takes it; the first failing contour in order is prepared again on the calling thread, so its
 * error detail does not depend on the thread count. */
#include "db_io.h"
#include "rows.h"

#include <stdio.h>
#include <stdlib.h>

typedef struct {
    const amscr_params *p;
    const amscr_contour *const *c;
    amscr_descriptor **d;
    amscr_status *st; /* each contour's status (AMSCR_OK until it fails) */
} batch_job;

static amscr_status prepare_row(void *ctx, size_t i, void *scratch)
{
    (void)scratch;
    const batch_job *j = ctx;
    amscr_status st = j->c[i] ? amscr__db_prepare(j->p, j->c[i], &j->d[i])
                              : amscr__fail(AMSCR_E_INVALID_ARG, "a NULL contour");
    j->st[i] = st;
    return st;
}

/* The first failing contour in order (rows are handed out in order and a failure stops the
 * hand-out, so every contour before it was prepared), its detail made again on this thread. */
static amscr_status first_failure(const batch_job *j, size_t n, amscr_status st, size_t *failed)
{
    size_t i = 0;
    while (i < n && j->st[i] == AMSCR_OK)
        i++;
    *failed = i;
    if (i == n)
        return st; /* not one contour's: out of memory, cancelled */
    amscr_descriptor *d = NULL;
    amscr_status again = j->c[i] ? amscr_descriptor_new(j->p, j->c[i], &d) : AMSCR_E_INVALID_ARG;
    amscr_descriptor_free(d);
    if (again == AMSCR_OK)
        return amscr__fail(j->st[i], "contour %zu: %s", i, amscr_strerror(j->st[i]));
    if (!j->c[i])
        return amscr__fail(AMSCR_E_INVALID_ARG, "contour %zu: NULL", i);
    char detail[256];
    snprintf(detail, sizeof detail, "%s", amscr_last_error_detail());
    return amscr__fail(again, "contour %zu: %s", i, detail);
}

amscr_status amscr_db_add_contours(amscr_db *db, const amscr_contour *const *contours, const int32_t *labels,
                                   size_t n, amscr_progress_fn progress, void *user, size_t *out_failed)
{
    amscr__clear_error();
    if (out_failed)
        *out_failed = n;
    AMSCR_CHECK_NULL(db);
    if (n == 0)
        return AMSCR_OK;
    AMSCR_CHECK_NULL(contours);
    const amscr_params *p = amscr_db_params(db);
    batch_job j = {p, contours, amscr__calloc_array(n, sizeof *j.d), amscr__calloc_array(n, sizeof *j.st)};
    amscr_status st = j.d && j.st ? amscr__db_reserve(db, n) : amscr__fail(AMSCR_E_NOMEM, "db: out of memory");
    if (st == AMSCR_OK) {
        amscr__rows_fn rows = {NULL, NULL, prepare_row, &j, "amscr_db_add_contours"};
        st = amscr__run_rows(&rows, 0, n, amscr__resolve_threads(p->num_threads), progress, user);
    }
    size_t failed = n;
    if (st != AMSCR_OK && j.st)
        st = first_failure(&j, n, st, &failed);
    for (size_t i = 0; i < n && j.d; i++) {
        if (st == AMSCR_OK) /* cannot fail: reserved */
            (void)amscr__db_push(db, j.d[i], labels ? labels[i] : 0, NULL);
        else
            amscr_descriptor_free(j.d[i]);
    }
    if (out_failed)
        *out_failed = failed;
    free(j.d);
    free(j.st);
    return st;
}
