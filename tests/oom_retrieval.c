/* oom_retrieval.c — every allocation failure in retrieval reaches the caller.
 *
 * For each scenario (a collection's shapes prepared; an index built from every pair, with its
 * base and inner-distance lists; an index built from signature shortlists; shapes added to a
 * small index, which is built again, and to a larger one, which extends its lists; a query of a
 * collection, which builds its kept index; an index's queries and member search; an index saved
 * to memory and loaded back) each allocation of the scenario's calls is failed in turn and must
 * come back as AMSCR_E_NOMEM with nothing leaked, or, where a pooled block falls back to blocks of
 * its own, with the very result of the run without failures (oom_wrap.h: a digest of the saved
 * index or collection, or of the scores). One C thread: the wrappers count on one. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "amscr.h"
#include "oom_wrap.h"

/* SHAPES the most a fixture holds: an index of 16 (twice the preset's re-ranking k) extends its
 * lists on an add, a smaller one is built again; a scenario's cost grows as its shapes cubed. */
enum { SHAPES = 16, FEW = 10, POINTS = 90, SAMPLES = 32 };

/* Closed curve s of a family: r(t) = 1 + a cos(k t) + b sin(3 t), its lobes and depth by s. */
static amscr_status make_curve(int s, amscr_contour **out)
{
    double xy[2 * POINTS];
    double a = 0.1 + 0.02 * (s % 7), b = 0.05 * (s % 3), k = 3 + s % 4;
    for (int i = 0; i < POINTS; i++) {
        double t = 2.0 * 3.141592653589793 * i / POINTS, r = 1.0 + a * cos(k * t) + b * sin(3.0 * t);
        xy[2 * i] = (1.0 + 0.1 * (s % 5)) * r * cos(t);
        xy[2 * i + 1] = r * sin(t) + 0.2 * r * cos(t) * (s % 2);
    }
    return amscr_contour_new(xy, POINTS, out);
}

/* The retrieval preset on one thread at SAMPLES samples. */
static amscr_status make_params(amscr_params **out)
{
    amscr_status st = amscr_params_new_retrieval(out);
    if (st == AMSCR_OK)
        st = amscr_params_set_num_threads(*out, 1);
    if (st == AMSCR_OK)
        st = amscr_params_set_num_samples(*out, SAMPLES);
    return st;
}

/* A collection of shapes first..first+n-1 (labels s % 4). */
static amscr_status make_db(int first, int n, amscr_db **out)
{
    amscr_params *p = NULL;
    amscr_contour *c[SHAPES] = {0};
    int32_t labels[SHAPES];
    amscr_status st = make_params(&p);
    if (st == AMSCR_OK)
        st = amscr_db_new(p, out);
    for (int i = 0; i < n && st == AMSCR_OK; i++) {
        labels[i] = (first + i) % 4;
        st = make_curve(first + i, &c[i]);
    }
    if (st == AMSCR_OK)
        st = amscr_db_add_contours(*out, (const amscr_contour *const *)c, labels, (size_t)n, NULL, NULL, NULL);
    for (int i = 0; i < n; i++)
        amscr_contour_free(c[i]);
    amscr_params_free(p);
    if (st != AMSCR_OK) {
        amscr_db_free(*out);
        *out = NULL;
    }
    return st;
}

/* The digest of bytes the library serializes (made uncounted); 0 when they cannot be made. */
static uint64_t digest_of(amscr_status (*save)(const void *, void **, size_t *), const void *obj)
{
    void *buf = NULL;
    size_t len = 0;
    int was = oom_pause();
    uint64_t h = save(obj, &buf, &len) == AMSCR_OK ? oom_digest(OOM_DIGEST_START, buf, len) : 0;
    amscr_free(buf);
    oom_resume(was);
    return h;
}
static amscr_status save_index(const void *x, void **buf, size_t *len) { return amscr_index_save_memory(x, buf, len); }
static amscr_status save_db(const void *db, void **buf, size_t *len) { return amscr_db_save_memory(db, buf, len); }

/* What a scenario does, on fixtures made outside the counting (its own calls are counted). */
typedef struct {
    const char *name;
    amscr_status (*run)(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest);
    int n, more;    /* shapes in db, in more */
    int candidates; /* of the fixture index (-1: no index) */
} scenario;

static amscr_status prepare(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)db, (void)more, (void)x;
    amscr_db *d = NULL;
    amscr_status st = make_db(0, FEW, &d);
    if (st == AMSCR_OK)
        *digest = digest_of(save_db, d);
    amscr_db_free(d);
    return st;
}

/* An index of db built with `candidates`, its digest the saved index's. */
static amscr_status build(const amscr_db *db, size_t candidates, uint64_t *digest)
{
    amscr_index *y = NULL;
    amscr_status st = amscr_index_build(db, candidates, NULL, NULL, &y);
    if (st == AMSCR_OK)
        *digest = digest_of(save_index, y);
    amscr_index_free(y);
    return st;
}

static amscr_status build_every_pair(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)more, (void)x;
    return build(db, 0, digest);
}

static amscr_status build_shortlists(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)more, (void)x;
    return build(db, 6, digest);
}

/* A copy of x (its bytes loaded: an index is not copied otherwise), made uncounted: a fresh index
 * whose shapes are decoded when first read, as a loaded or built one's are. */
static amscr_status copy_of(const amscr_index *x, amscr_index **out)
{
    void *buf = NULL;
    size_t len = 0;
    int was = oom_pause();
    amscr_status st = amscr_index_save_memory(x, &buf, &len);
    if (st == AMSCR_OK)
        st = amscr_index_load_memory(buf, len, out);
    amscr_free(buf);
    oom_resume(was);
    return st;
}

static amscr_status add(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)db;
    amscr_index *y = NULL;
    amscr_status st = copy_of(x, &y);
    if (st == AMSCR_OK)
        st = amscr_index_add(y, more, NULL, NULL);
    if (st == AMSCR_OK)
        *digest = digest_of(save_index, y);
    amscr_index_free(y);
    return st;
}

static amscr_status query_collection(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)x;
    amscr_db *d = NULL; /* a fresh collection: its kept index is built by the first query */
    double scores[SHAPES];
    int was = oom_pause();
    amscr_status st = make_db(0, amscr_db_size(db) > SHAPES ? SHAPES : (int)amscr_db_size(db), &d);
    oom_resume(was);
    if (st == AMSCR_OK)
        st = amscr_db_query_retrieval(d, amscr_db_descriptor(more, 0), NULL, NULL, scores, amscr_db_size(d));
    if (st == AMSCR_OK)
        *digest = oom_digest(OOM_DIGEST_START, scores, amscr_db_size(d) * sizeof *scores);
    amscr_db_free(d);
    return st;
}

static amscr_status query_index(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    double scores[4 * SHAPES];
    size_t n = amscr_index_size(x), idx[5], count;
    amscr_index *y = NULL;
    amscr_status st = copy_of(x, &y);
    if (st == AMSCR_OK)
        st = amscr_index_query_scores(y, amscr_db_descriptor(more, 0), 0, scores, n);
    if (st == AMSCR_OK)
        st = amscr_index_query(y, amscr_db_descriptor(more, 1), 6, 5, idx, scores + n, &count);
    if (st == AMSCR_OK) /* a member: the member rule */
        st = amscr_index_search_scores(y, amscr_db_descriptor(db, 3), 0, scores + 2 * n, n);
    if (st == AMSCR_OK)
        st = amscr_index_member_scores(y, 2, 0, scores + 3 * n, n);
    if (st == AMSCR_OK)
        *digest = oom_digest(oom_digest(OOM_DIGEST_START, scores, 4 * n * sizeof *scores), idx, count * sizeof *idx);
    amscr_index_free(y);
    return st;
}

static amscr_status save_load(const amscr_db *db, const amscr_db *more, const amscr_index *x, uint64_t *digest)
{
    (void)db, (void)more;
    void *buf = NULL;
    size_t len = 0;
    amscr_index *y = NULL;
    amscr_status st = amscr_index_save_memory(x, &buf, &len);
    if (st == AMSCR_OK)
        st = amscr_index_load_memory(buf, len, &y);
    if (st == AMSCR_OK)
        *digest = digest_of(save_index, y);
    amscr_index_free(y);
    amscr_free(buf);
    return st;
}

typedef struct {
    const scenario *s;
    const amscr_db *db, *more;
    const amscr_index *x;
} fixture;

static amscr_status run_fixture(const void *ctx, uint64_t *digest)
{
    const fixture *f = ctx;
    return f->s->run(f->db, f->more, f->x, digest);
}

/* The scenario's fixtures made (uncounted), its allocations failed in turn. */
static int check(const scenario *s, long stride)
{
    amscr_db *db = NULL, *more = NULL;
    amscr_index *x = NULL;
    amscr_status st = make_db(0, s->n, &db);
    if (st == AMSCR_OK)
        st = make_db(SHAPES, s->more, &more);
    if (st == AMSCR_OK && s->candidates >= 0)
        st = amscr_index_build(db, (size_t)s->candidates, NULL, NULL, &x);
    int bad = 1;
    if (st == AMSCR_OK) {
        fixture f = {s, db, more, x};
        bad = oom_check(s->name, run_fixture, &f, stride);
    } else {
        printf("FAIL %s: fixtures: %s\n", s->name, amscr_last_error_detail());
    }
    amscr_index_free(x);
    amscr_db_free(more);
    amscr_db_free(db);
    return bad;
}

int main(void)
{
    static const scenario scenarios[] = {
        {"collection prepared (add contours)", prepare, 2, 2, -1},
        {"index from every pair (base and inner lists)", build_every_pair, FEW, 2, -1},
        {"index from signature shortlists", build_shortlists, FEW, 2, -1},
        {"shapes added to a small index (built again)", add, 6, 3, 0},
        {"shapes added to an index (lists extended)", add, SHAPES, 2, 0},
        {"shapes added to a shortlist index", add, SHAPES, 2, 6},
        {"collection queried (its kept index built)", query_collection, FEW, 2, -1},
        {"index queried, a member searched", query_index, FEW, 2, 0},
        {"shortlist index queried, a member searched", query_index, FEW, 2, 6},
        {"index saved to memory and loaded", save_load, FEW, 2, 6},
    };
    int bad = 0;
    setvbuf(stdout, NULL, _IOLBF, 0); /* each scenario's line out before a crash */
    for (size_t i = 0; i < sizeof scenarios / sizeof scenarios[0]; i++)
        bad += check(&scenarios[i], oom_stride());
    return bad ? 1 : 0;
}
