/* load_db.c — a collection's shapes decoded, traced and prepared on threads (see load_db.h).
 *
 * Shapes are handed out in order, one at a time; every thread (the calling one too) decodes
 * and traces its shape and prepares it with amscr_descriptor_new, muted. The calling thread
 * adds the prepared shapes to the db in the collection's order as they are ready, so the db
 * is the one a loop over the shapes builds. After a failure no new shape is handed out; the
 * first failing shape in order is loaded again on the calling thread, which prints its error
 * as a single-threaded load would: the message does not depend on the thread count. */
#include "load_db.h"

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#include "image.h"
#include "util.h"

typedef struct {
    const amscr_params *p;
    const collection *c;
    int threshold;
    amscr_descriptor **d; /* prepared shapes, by index; NULL until ready or once added */
    char *ready;          /* 1 when d[i] is done (prepared, or failed) */
    pthread_mutex_t lock;
    size_t next;   /* the next shape to hand out */
    size_t failed; /* the first failing shape, c->n when none */
} load_job;

static int prepare_one(const load_job *j, size_t i, amscr_descriptor **out)
{
    amscr_contour *ct = NULL;
    *out = NULL;
    if (shape_load(j->c->items[i].path, j->threshold, &ct) != 0)
        return -1;
    amscr_status st = amscr_descriptor_new(j->p, ct, out);
    amscr_contour_free(ct);
    return st == AMSCR_OK ? 0 : -1;
}

/* Hands out the next shape into *i; 0 when none is left or a shape failed. */
static int take(load_job *j, size_t *i)
{
    pthread_mutex_lock(&j->lock);
    *i = j->next;
    int go = *i < j->c->n && j->failed == j->c->n;
    if (go)
        j->next++;
    pthread_mutex_unlock(&j->lock);
    return go;
}

static void do_one(load_job *j, size_t i)
{
    amscr_descriptor *d = NULL;
    int bad = prepare_one(j, i, &d) != 0;
    pthread_mutex_lock(&j->lock);
    j->d[i] = d;
    j->ready[i] = 1;
    if (bad && i < j->failed)
        j->failed = i;
    pthread_mutex_unlock(&j->lock);
}

static void *worker(void *arg)
{
    size_t i;
    while (take(arg, &i))
        do_one(arg, i);
    return NULL;
}

/* Adds the ready shapes from *added on, in order; the failing status of an add, else OK. */
static amscr_status add_ready(load_job *j, amscr_db *db, size_t *added)
{
    for (;;) {
        pthread_mutex_lock(&j->lock);
        size_t i = *added;
        amscr_descriptor *d = i < j->failed && j->ready[i] ? j->d[i] : NULL;
        if (d)
            j->d[i] = NULL;
        pthread_mutex_unlock(&j->lock);
        if (!d)
            return AMSCR_OK;
        amscr_status st = amscr_db_add_descriptor(db, d, j->c->items[i].label, NULL);
        amscr_descriptor_free(d);
        if (st != AMSCR_OK) { /* no new shape for the other threads either */
            pthread_mutex_lock(&j->lock);
            j->failed = i;
            pthread_mutex_unlock(&j->lock);
            return st;
        }
        (*added)++;
    }
}

static unsigned thread_count(const amscr_params *p, size_t n)
{
    unsigned t = amscr_params_get_num_threads(p);
    if (t == 0) {
        long c = sysconf(_SC_NPROCESSORS_ONLN);
        t = c > 0 ? (unsigned)c : 1u;
    }
    if (t > 64)
        t = 64;
    return n < t ? (n > 0 ? (unsigned)n : 1u) : t;
}

/* Every shape prepared and added in order (muted); *added = how many were added. */
static amscr_status run(load_job *j, amscr_db *db, unsigned nt, size_t *added)
{
    pthread_t tid[64];
    unsigned started = 0;
    for (unsigned t = 1; t < nt; t++)
        if (pthread_create(&tid[started], NULL, worker, j) == 0)
            started++;
    tool_progress pr;
    progress_init(&pr, "preparing shapes");
    amscr_status st = AMSCR_OK;
    size_t i;
    while (st == AMSCR_OK && take(j, &i)) {
        do_one(j, i);
        st = add_ready(j, db, added);
        progress_update(&pr, *added, j->c->n);
    }
    for (unsigned t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    if (st == AMSCR_OK)
        st = add_ready(j, db, added);
    progress_update(&pr, *added, j->c->n); /* the bar's end, when every shape is in */
    progress_end(&pr);
    return st;
}

/* The error of shape i, printed as a load on one thread prints it: loaded again. */
static void report(const load_job *j, size_t i, amscr_status add_st)
{
    const char *path = j->c->items[i].path;
    if (add_st != AMSCR_OK) {
        tool_lib_error(path, add_st);
        return;
    }
    amscr_contour *ct = NULL;
    if (shape_load(path, j->threshold, &ct) != 0)
        return; /* printed */
    amscr_descriptor *d = NULL;
    amscr_status st = amscr_descriptor_new(j->p, ct, &d);
    amscr_contour_free(ct);
    amscr_descriptor_free(d);
    const char *detail = lib_detail();
    if (st == AMSCR_E_DEGENERATE)
        tool_error(path, "cannot use this shape: %s", detail[0] ? detail : "degenerate");
    else if (st != AMSCR_OK)
        tool_lib_error(path, st);
    else
        tool_error(path, "cannot prepare this shape (out of memory?)");
}

int load_db(const amscr_params *p, const collection *c, int threshold, amscr_db **out)
{
    amscr_db *db = NULL;
    amscr_status st = amscr_db_new(p, &db);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return -1;
    }
    load_job j = {p, c, threshold, xcalloc_array(c->n + 1, sizeof *j.d), xcalloc_array(c->n + 1, 1),
                  PTHREAD_MUTEX_INITIALIZER, 0, c->n};
    size_t added = 0;
    if (!j.d || !j.ready) {
        free(j.d);
        free(j.ready);
        amscr_db_free(db);
        return -1;
    }
    tool_errors_mute(1);
    st = run(&j, db, thread_count(p, c->n), &added);
    tool_errors_mute(0);
    int ok = st == AMSCR_OK && added == c->n;
    if (!ok)
        report(&j, added, st);
    for (size_t i = 0; i < c->n; i++)
        amscr_descriptor_free(j.d[i]);
    free(j.d);
    free(j.ready);
    pthread_mutex_destroy(&j.lock);
    if (!ok) {
        amscr_db_free(db);
        return -1;
    }
    *out = db;
    return 0;
}
