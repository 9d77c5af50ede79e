/* check_index.c — the retrieval index (amscr_index_*) and the one-vs-many retrieval query
 * (amscr_db_query_retrieval): the exact query equals the query's row of the retrieval matrix
 * of the collection plus the query; an index query with every shape a candidate equals it;
 * member rows; file and memory round trips; damaged files; add; thread-count independence. */
#define _GNU_SOURCE /* O_TMPFILE: whether the killed save could leave nothing behind */
#include <amscr.h>
#include <check.h>
#include <fcntl.h>
#include <dirent.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>

#include "db_io.h"
#include "index.h"
#include "suites.h"
#include "testutil.h"

#define NPTS 200
#define NSHAPES 24

/* Params: the retrieval preset with N = 64 (fast), channel weight w, re-ranking k. */
static amscr_params *params_of(double w, unsigned k, unsigned threads)
{
    amscr_params *p = NULL;
    ck_assert_int_eq(amscr_params_new_retrieval(&p), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_samples(p, 64), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_weight(p, w), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_rerank_k(p, k), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_num_threads(p, threads), AMSCR_OK);
    return p;
}

/* Shape `i`: one of 6 random base shapes (classes), affinely warped. */
static amscr_descriptor *shape(const amscr_params *p, unsigned i)
{
    amscr_test_rng r;
    double xy[2 * NPTS], w[2 * NPTS], m[6];
    amscr_test_rng_seed(&r, 1000 + i % 6);
    amscr_test_random_shape(&r, NPTS, 5, xy);
    amscr_test_rng_seed(&r, 77 + i);
    amscr_test_random_affine(&r, 2.0, 0.5, 3.0, 0, m);
    amscr_test_apply_affine(m, xy, NPTS, w);
    amscr_test_add_noise(&r, w, NPTS, 0.01);
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_contour_new(w, NPTS, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_OK);
    amscr_contour_free(c);
    return d;
}

static amscr_db *db_of(const amscr_params *p, unsigned n)
{
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (unsigned i = 0; i < n; i++) {
        amscr_descriptor *d = shape(p, i);
        ck_assert_int_eq(amscr_db_add_descriptor(db, d, (int32_t)(i % 6), NULL), AMSCR_OK);
        amscr_descriptor_free(d);
    }
    return db;
}

/* The query's row (its collection columns) of the retrieval matrix of db plus q. */
static void reference_row(const amscr_db *db, const amscr_descriptor *q, double *out)
{
    size_t n = amscr_db_size(db);
    amscr_db *all = NULL;
    ck_assert_int_eq(amscr_db_new(amscr_db_params(db), &all), AMSCR_OK);
    for (size_t i = 0; i < n; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(all, amscr_db_descriptor(db, i), 0, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_db_add_descriptor(all, q, 0, NULL), AMSCR_OK);
    double *M = malloc((n + 1) * (n + 1) * sizeof *M);
    ck_assert_int_eq(amscr_db_retrieval_matrix(all, NULL, NULL, M), AMSCR_OK);
    memcpy(out, M + n * (n + 1), n * sizeof *out);
    free(M);
    amscr_db_free(all);
}

static void assert_close(const double *a, const double *b, size_t n, double tol)
{
    for (size_t j = 0; j < n; j++)
        ck_assert_msg(fabs(a[j] - b[j]) <= tol, "score %zu: %.17g vs %.17g", j, a[j], b[j]);
}

/* amscr_db_query_retrieval and the index query (every shape a candidate) against the matrix,
 * the inner distance's graph at `share` of the re-ranking (0: one graph). */
static void exact_case_share(double w, unsigned k, double share)
{
    amscr_params *p = params_of(w, k, 2);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, share), AMSCR_OK);
    amscr_db *db = db_of(p, NSHAPES);
    amscr_descriptor *q = shape(p, 1000);
    double ref[NSHAPES], got[NSHAPES], viax[NSHAPES];
    reference_row(db, q, ref);
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, got, NSHAPES), AMSCR_OK);
    /* fused weights: the collection's medians (its kept index), not moved by the query */
    assert_close(ref, got, NSHAPES, w > 0.0 && w < 1.0 ? 1e-3 : 1e-12);
    if (w > 0.0 && w < 1.0) {
        amscr_index *x = NULL;
        ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
        ck_assert_int_eq(amscr_index_query_scores(x, q, 0, viax, NSHAPES), AMSCR_OK);
        assert_close(viax, got, NSHAPES, 1e-12);
        amscr_index_free(x);
    }
    if (w <= 0.0 || w >= 1.0) { /* an index: the collection's graphs */
        amscr_index *x = NULL;
        ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
        ck_assert(amscr_params_get_rerank_inner_share(amscr_db_params(amscr_index_db(x))) == share);
        ck_assert_uint_eq(x->k2, k > 0 && share > 0.0 ? x->k : 0);
        ck_assert_int_eq(amscr_index_query_scores(x, q, 0, viax, NSHAPES), AMSCR_OK);
        assert_close(ref, viax, NSHAPES, 1e-12);
        amscr_index_free(x);
    }
    amscr_descriptor_free(q);
    amscr_db_free(db);
    amscr_params_free(p);
}

static void exact_case(double w, unsigned k) { exact_case_share(w, k, 0.05); }

/* A collection's queries keep its index: after an add, the same scores as a new collection's. */
static void kept_case(double w, unsigned k)
{
    amscr_params *p = params_of(w, k, 2);
    amscr_db *db = db_of(p, NSHAPES - 5), *fresh = db_of(p, NSHAPES);
    amscr_descriptor *q = shape(p, 1000);
    double got[NSHAPES], ref[NSHAPES];
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, got, NSHAPES - 5), AMSCR_OK);
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, ref, NSHAPES - 5), AMSCR_OK);
    assert_close(ref, got, NSHAPES - 5, 0.0); /* the kept index: the same scores again */
    for (unsigned i = NSHAPES - 5; i < NSHAPES; i++) {
        amscr_descriptor *d = shape(p, i);
        ck_assert_int_eq(amscr_db_add_descriptor(db, d, (int32_t)(i % 6), NULL), AMSCR_OK);
        amscr_descriptor_free(d);
        if (i == NSHAPES - 3) /* a query between adds: the index follows each */
            ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, got, i + 1), AMSCR_OK);
    }
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, got, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_db_query_retrieval(fresh, q, NULL, NULL, ref, NSHAPES), AMSCR_OK);
    assert_close(ref, got, NSHAPES, 1e-12);
    amscr_descriptor_free(q);
    amscr_db_free(db);
    amscr_db_free(fresh);
    amscr_params_free(p);
}

START_TEST(kept_after_add) { kept_case(1.0, 8); }
END_TEST

START_TEST(kept_after_add_amscr) { kept_case(0.0, 5); }
END_TEST

/* Threads querying a collection at once: one builds its kept index, all get the serial scores. */
typedef struct {
    const amscr_db *db;
    const amscr_descriptor *q;
    double out[NSHAPES];
    amscr_status st;
} kept_job;

static void *kept_worker(void *arg)
{
    kept_job *j = arg;
    j->st = amscr_db_query_retrieval(j->db, j->q, NULL, NULL, j->out, NSHAPES);
    return NULL;
}

START_TEST(kept_concurrent)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of(p, NSHAPES), *serial = db_of(p, NSHAPES);
    amscr_descriptor *q = shape(p, 1000);
    double ref[NSHAPES];
    ck_assert_int_eq(amscr_db_query_retrieval(serial, q, NULL, NULL, ref, NSHAPES), AMSCR_OK);
    enum { T = 4 };
    kept_job jobs[T];
    pthread_t tid[T];
    for (int t = 0; t < T; t++) {
        jobs[t].db = db;
        jobs[t].q = q;
        ck_assert_int_eq(pthread_create(&tid[t], NULL, kept_worker, &jobs[t]), 0);
    }
    for (int t = 0; t < T; t++) {
        ck_assert_int_eq(pthread_join(tid[t], NULL), 0);
        ck_assert_int_eq(jobs[t].st, AMSCR_OK);
        assert_close(ref, jobs[t].out, NSHAPES, 0.0);
    }
    amscr_descriptor_free(q);
    amscr_db_free(db);
    amscr_db_free(serial);
    amscr_params_free(p);
}
END_TEST

/* A query on the same collection from the progress callback of a query that builds its kept
 * index (the lock held by this thread): AMSCR_E_STATE, not a deadlock; the outer query goes on. */
typedef struct {
    const amscr_db *db;
    const amscr_descriptor *q;
    amscr_status inner;
    int calls;
} reentry;

static int query_again(void *user, size_t done, size_t total)
{
    reentry *r = user;
    double out[NSHAPES];
    (void)done, (void)total;
    if (r->calls++ == 0)
        r->inner = amscr_db_query_retrieval(r->db, r->q, NULL, NULL, out, NSHAPES);
    return 0;
}

START_TEST(kept_query_from_its_own_callback)
{
    amscr_params *p = params_of(1.0, 8, 1);
    amscr_db *db = db_of(p, NSHAPES), *serial = db_of(p, NSHAPES);
    amscr_descriptor *q = shape(p, 1000);
    double ref[NSHAPES], out[NSHAPES];
    ck_assert_int_eq(amscr_db_query_retrieval(serial, q, NULL, NULL, ref, NSHAPES), AMSCR_OK);
    reentry r = {db, q, AMSCR_OK, 0};
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, query_again, &r, out, NSHAPES), AMSCR_OK);
    ck_assert_int_gt(r.calls, 0);
    ck_assert_int_eq(r.inner, AMSCR_E_STATE);
    assert_close(ref, out, NSHAPES, 0.0);
    ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, out, NSHAPES), AMSCR_OK); /* usable after */
    assert_close(ref, out, NSHAPES, 0.0);
    amscr_descriptor_free(q);
    amscr_db_free(db);
    amscr_db_free(serial);
    amscr_params_free(p);
}
END_TEST

/* Progress of the retrieval queries: the query that builds (or brings up to date) the kept
 * index reports that and then the query's own pairs, as fractions that only grow and end at 1;
 * a query of a kept index reports its pairs, and can be cancelled (NaN, then usable). */
typedef struct {
    double last;
    int calls, cancel_at, monotone, ended;
} fractions;

static int record_fraction(void *user, size_t done, size_t total)
{
    fractions *f = user;
    ck_assert_uint_gt(total, 0);
    double x = (double)done / (double)total;
    f->monotone &= x >= f->last && x <= 1.0;
    f->ended = done == total;
    f->last = x;
    return ++f->calls == f->cancel_at;
}

static void query_fractions(const amscr_db *db, const amscr_descriptor *q, int member, int cancel_at,
                            amscr_status want, double *out)
{
    fractions f = {0.0, 0, cancel_at, 1, 0};
    amscr_status st = member ? amscr_db_search_retrieval(db, q, record_fraction, &f, out, amscr_db_size(db))
                             : amscr_db_query_retrieval(db, q, record_fraction, &f, out, amscr_db_size(db));
    ck_assert_int_eq(st, want);
    ck_assert_int_gt(f.calls, 0);
    ck_assert(f.monotone);
    if (want == AMSCR_OK)
        ck_assert(f.ended);
    else
        ck_assert_int_eq(f.calls, cancel_at); /* none after the cancel */
}

START_TEST(kept_query_reports_progress)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of(p, NSHAPES - 4), *ref_db = db_of(p, NSHAPES - 4);
    amscr_descriptor *q = shape(p, 1000);
    double ref[NSHAPES], out[NSHAPES];
    for (int member = 0; member < 2; member++) {
        query_fractions(db, q, member, 0, AMSCR_OK, out); /* builds the kept index (once) */
        query_fractions(db, q, member, 0, AMSCR_OK, out); /* the kept index's query */
        query_fractions(db, q, member, 1, AMSCR_E_CANCELLED, out);
        ck_assert(isnan(out[0]) && isnan(out[NSHAPES - 5]));
        query_fractions(db, q, member, 0, AMSCR_OK, out);
        ck_assert_int_eq(amscr_db_query_retrieval(ref_db, q, NULL, NULL, ref, NSHAPES - 4), AMSCR_OK);
        if (!member)
            assert_close(ref, out, NSHAPES - 4, 0.0);
    }
    for (unsigned i = NSHAPES - 4; i < NSHAPES; i++) { /* the kept index brought up to date: two stages */
        amscr_descriptor *d = shape(p, i);
        ck_assert_int_eq(amscr_db_add_descriptor(db, d, (int32_t)(i % 6), NULL), AMSCR_OK);
        amscr_descriptor_free(d);
    }
    query_fractions(db, q, 0, 0, AMSCR_OK, out);
    amscr_descriptor_free(q);
    amscr_db_free(db);
    amscr_db_free(ref_db);
    amscr_params_free(p);
}
END_TEST

/* A build reports from its start: each shape's features (the first half, once a shape at
 * least), then its lists, fractions growing to 1, the exact build and a shortlist build alike;
 * a cancel at the first report stops it; an add reports its new shapes' features likewise.
 * Before, the features, a third of a build, reported nothing, so no cancel (Python's Ctrl-C)
 * could stop them. */
typedef struct {
    fractions f;
    int below_half;
} halves;

static int record_halves(void *user, size_t done, size_t total)
{
    halves *h = user;
    h->below_half += 2 * done < total;
    return record_fraction(&h->f, done, total);
}

START_TEST(build_reports_its_features)
{
    /* one thread: only the calling thread reports, once for each row it takes, so with two a
     * worker that takes rows while the caller computes one leaves fewer reports (under load) */
    amscr_params *p = params_of(1.0, 8, 1);
    amscr_db *db = db_of(p, NSHAPES), *more = db_of(p, NSHAPES);
    for (size_t m = 0; m <= 8; m += 8) {
        halves h = {{0.0, 0, 0, 1, 0}, 0};
        amscr_index *x = NULL;
        ck_assert_int_eq(amscr_index_build(db, m, record_halves, &h, &x), AMSCR_OK);
        ck_assert(h.f.monotone && h.f.ended);
        ck_assert_int_ge(h.below_half, NSHAPES - 1); /* each shape but the last, whose report is the half */
        halves a = {{0.0, 0, 0, 1, 0}, 0};
        ck_assert_int_eq(amscr_index_add(x, more, record_halves, &a), AMSCR_OK);
        ck_assert(a.f.monotone && a.f.ended);
        ck_assert_int_ge(a.below_half, NSHAPES - 1);
        amscr_index_free(x);
        fractions first = {0.0, 0, 1, 1, 0};
        x = NULL;
        ck_assert_int_eq(amscr_index_build(db, m, record_fraction, &first, &x), AMSCR_E_CANCELLED);
        ck_assert_ptr_null(x);
        ck_assert_int_eq(first.calls, 1);
    }
    amscr_db_free(more);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* The build's default: every pair up to AMSCR_INDEX_EXACT_MAX shapes, the shortlist above. */
START_TEST(default_candidates)
{
    ck_assert_uint_eq(amscr_index_default_candidates(0), 0);
    ck_assert_uint_eq(amscr_index_default_candidates(AMSCR_INDEX_EXACT_MAX), 0);
    ck_assert_uint_eq(amscr_index_default_candidates(AMSCR_INDEX_EXACT_MAX + 1), AMSCR_INDEX_CANDIDATES);
    ck_assert_uint_eq(amscr_index_default_candidates(SIZE_MAX), AMSCR_INDEX_CANDIDATES);
}
END_TEST

START_TEST(exact_channel_rerank) { exact_case(1.0, 8); }
END_TEST
START_TEST(exact_amscr_rerank) { exact_case(0.0, 5); }
END_TEST
START_TEST(exact_fused_rerank) { exact_case(0.5, 8); }
END_TEST
START_TEST(exact_channel_plain) { exact_case(1.0, 0); }
END_TEST
START_TEST(exact_large_k) { exact_case(1.0, 40); }
END_TEST
START_TEST(exact_one_graph) { exact_case_share(1.0, 8, 0.0); }
END_TEST
START_TEST(exact_inner_heavy) { exact_case_share(1.0, 5, 0.6); }
END_TEST
START_TEST(exact_inner_amscr) { exact_case_share(0.0, 8, 0.3); }
END_TEST

/* Row i of the collection's own retrieval matrix. */
START_TEST(member_rows)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of(p, NSHAPES);
    double *M = malloc(NSHAPES * NSHAPES * sizeof *M), got[NSHAPES];
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_db_retrieval_matrix(amscr_index_db(x), NULL, NULL, M), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i += 5) {
        ck_assert_int_eq(amscr_index_member_scores(x, i, 0, got, NSHAPES), AMSCR_OK);
        assert_close(M + i * NSHAPES, got, NSHAPES, 1e-12);
    }
    ck_assert_int_eq(amscr_index_member_scores(x, NSHAPES, 0, got, NSHAPES), AMSCR_E_INVALID_ARG);
    amscr_index_free(x);
    free(M);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* The member rule (amscr_index_find_member and the search calls): a query prepared again from
 * a member's points is that member (the lowest index of copies), and the search calls score it
 * by the member's row of the collection's retrieval matrix (amscr_index_member_scores; the db's
 * search its row of amscr_db_retrieval_matrix) when the scores re-rank or fuse or take the
 * channel, whose pairs run from the lower index to the higher (the channel alone too: a copy
 * scored as a new shape would get d(j, i) where the member's row has d(i, j)); any other query
 * gets the query calls' scores; the query calls never apply the rule; a lazy load finds the same
 * member. */
static void member_rule_case(double w, unsigned k, int applies)
{
    amscr_params *p = params_of(w, k, 2);
    amscr_db *db = db_of(p, NSHAPES);
    amscr_descriptor *dup = shape(p, 7), *q = NULL, *other = shape(p, 2000);
    ck_assert_int_eq(amscr_db_add_descriptor(db, dup, 1, NULL), AMSCR_OK); /* shape NSHAPES: a copy of 7 */
    const size_t n = NSHAPES + 1;
    double *M = malloc(n * n * sizeof *M), got[NSHAPES + 1], want[NSHAPES + 1], mem[NSHAPES + 1];
    amscr_index *x = NULL, *y = NULL;
    void *buf = NULL;
    size_t len = 0, i = 0, idx[5], cnt = 0;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_memory_with(buf, len, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    ck_assert_int_eq(amscr_db_retrieval_matrix(db, NULL, NULL, M), AMSCR_OK);
    for (unsigned s = 3; s < NSHAPES; s += 4) {
        q = shape(p, s); /* the member's points prepared again: its samples, bit for bit */
        ck_assert_int_eq(amscr_index_find_member(x, q, &i), AMSCR_OK);
        ck_assert_uint_eq(i, s);
        ck_assert_int_eq(amscr_index_find_member(y, q, &i), AMSCR_OK);
        ck_assert_uint_eq(i, s);
        ck_assert_int_eq(amscr_index_query_scores(x, q, 0, want, n), AMSCR_OK);
        ck_assert_int_eq(amscr_index_member_scores(x, s, 0, mem, n), AMSCR_OK);
        if (applies)
            memcpy(want, mem, sizeof want);
        ck_assert_int_eq(amscr_index_search_scores(x, q, 0, got, n), AMSCR_OK);
        ck_assert_mem_eq(got, want, sizeof got);
        ck_assert_int_eq(amscr_index_search_scores(y, q, 0, got, n), AMSCR_OK);
        assert_close(got, want, n, 1e-12);
        ck_assert_int_eq(amscr_index_search(x, q, 0, 5, idx, got, &cnt), AMSCR_OK);
        ck_assert_uint_eq(cnt, 5);
        ck_assert_uint_eq(idx[0], s); /* first, at its own score */
        ck_assert(got[0] == want[s]);
        ck_assert_int_eq(amscr_db_search_retrieval(db, q, NULL, NULL, got, n), AMSCR_OK);
        if (applies) {
            assert_close(got, M + s * n, n, 1e-12); /* its row of the collection's matrix */
            ck_assert(got[s] == 0.0);
            ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, want, n), AMSCR_OK);
            double diff = 0.0; /* the query call scores it as a new shape: other scores */
            for (size_t j = 0; j < n; j++)
                diff = fmax(diff, fabs(want[j] - got[j]));
            ck_assert_msg(diff > 1e-6, "the query call should not apply the member rule (%g)", diff);
        } else {
            ck_assert_int_eq(amscr_db_query_retrieval(db, q, NULL, NULL, want, n), AMSCR_OK);
            ck_assert_mem_eq(got, want, sizeof got);
        }
        amscr_descriptor_free(q);
    }
    /* copies: the lowest index */
    ck_assert_int_eq(amscr_index_find_member(x, dup, &i), AMSCR_OK);
    ck_assert_uint_eq(i, 7);
    /* not a member: the query calls' scores */
    ck_assert_int_eq(amscr_index_find_member(x, other, &i), AMSCR_OK);
    ck_assert_uint_eq(i, SIZE_MAX);
    ck_assert_int_eq(amscr_index_query_scores(x, other, 0, want, n), AMSCR_OK);
    ck_assert_int_eq(amscr_index_search_scores(x, other, 0, got, n), AMSCR_OK);
    ck_assert_mem_eq(got, want, sizeof got);
    ck_assert_int_eq(amscr_db_query_retrieval(db, other, NULL, NULL, want, n), AMSCR_OK);
    ck_assert_int_eq(amscr_db_search_retrieval(db, other, NULL, NULL, got, n), AMSCR_OK);
    ck_assert_mem_eq(got, want, sizeof got);
    /* errors */
    ck_assert_int_eq(amscr_index_find_member(NULL, other, &i), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_find_member(x, NULL, &i), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_find_member(x, other, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_search_scores(x, other, 0, got, n - 1), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_search(x, other, 0, 5, NULL, got, &cnt), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_search_retrieval(db, other, NULL, NULL, got, n + 1), AMSCR_E_INVALID_ARG);
    amscr_params *p32 = params_of(w, k, 2);
    ck_assert_int_eq(amscr_params_set_num_samples(p32, 32), AMSCR_OK);
    amscr_descriptor *q32 = shape(p32, 3);
    i = 77;
    ck_assert_int_eq(amscr_index_find_member(x, q32, &i), AMSCR_E_INVALID_ARG);
    ck_assert_uint_eq(i, 77); /* outputs are written only on AMSCR_OK */
    ck_assert_int_eq(amscr_index_search_scores(x, q32, 0, got, n), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_db_search_retrieval(db, q32, NULL, NULL, got, n), AMSCR_E_INVALID_ARG);
    amscr_descriptor_free(q32);
    amscr_params_free(p32);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_index_free(y);
    free(M);
    amscr_descriptor_free(dup);
    amscr_descriptor_free(other);
    amscr_db_free(db);
    amscr_params_free(p);
}

START_TEST(member_rule_rerank) { member_rule_case(1.0, 8, 1); }
END_TEST

START_TEST(member_rule_fused) { member_rule_case(0.5, 0, 1); }
END_TEST

START_TEST(member_rule_channel_alone) { member_rule_case(1.0, 0, 1); }
END_TEST

static amscr_index *named_index(const amscr_params *p, size_t candidates)
{
    amscr_db *db = db_of(p, NSHAPES);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, candidates, NULL, NULL, &x), AMSCR_OK);
    amscr_db_free(db);
    ck_assert_int_eq(amscr_index_set_name(x, 3, "three.png"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_class_name(x, 2, "bird"), AMSCR_OK);
    return x;
}

static void same_query(const amscr_index *a, const amscr_index *b, const amscr_descriptor *q, size_t cand)
{
    double sa[NSHAPES], sb[NSHAPES];
    ck_assert_int_eq(amscr_index_query_scores(a, q, cand, sa, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_index_query_scores(b, q, cand, sb, NSHAPES), AMSCR_OK);
    for (size_t j = 0; j < NSHAPES; j++)
        ck_assert(sa[j] == sb[j] || (isinf(sa[j]) && isinf(sb[j])));
}

/* A lazy load (AMSCR_INDEX_LAZY: channel features built per query) gives the same scores as an
 * eager one, for every shape a candidate and for a shortlist; an add on it matches the old
 * shapes too; an unknown flag is refused. */
START_TEST(lazy_load)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 0), *y = NULL, *z = NULL;
    amscr_descriptor *q = shape(p, 2000);
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_memory_with(buf, len, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    same_query(x, y, q, 0);
    same_query(x, y, q, 6);
    ck_assert_int_eq(amscr_index_load_memory_with(buf, len, 2u, &z), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(z);
    ck_assert_int_eq(amscr_index_load_with("check_index_no_such.idx", 8u, &z), AMSCR_E_INVALID_ARG);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_index_free(y);
    amscr_descriptor_free(q);
    amscr_params_free(p);
}
END_TEST

/* A thread's member rows of a lazily loaded index: rows 0..NSHAPES-1 into out (NSHAPES^2). */
typedef struct {
    const amscr_index *x;
    double *out;
    int ok;
} rows_arg;

static void *member_rows_thread(void *arg)
{
    rows_arg *a = arg;
    a->ok = 1;
    for (size_t i = 0; i < NSHAPES; i++)
        a->ok &= amscr_index_member_scores(a->x, i, 6, a->out + i * NSHAPES, NSHAPES) == AMSCR_OK;
    return NULL;
}

/* Two threads reading the same lazily loaded index at once (each decoding shapes as it goes)
 * get the eager load's rows. */
static void concurrent_rows(const char *path, const amscr_index *e)
{
    amscr_index *y = NULL;
    ck_assert_int_eq(amscr_index_load_with(path, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    static double want[NSHAPES * NSHAPES], got[2][NSHAPES * NSHAPES];
    for (size_t i = 0; i < NSHAPES; i++)
        ck_assert_int_eq(amscr_index_member_scores(e, i, 6, want + i * NSHAPES, NSHAPES), AMSCR_OK);
    rows_arg a[2] = {{y, got[0], 0}, {y, got[1], 0}};
    pthread_t t;
    ck_assert_int_eq(pthread_create(&t, NULL, member_rows_thread, &a[1]), 0);
    member_rows_thread(&a[0]);
    pthread_join(t, NULL);
    ck_assert(a[0].ok && a[1].ok);
    ck_assert(memcmp(got[0], want, sizeof want) == 0 && memcmp(got[1], want, sizeof want) == 0);
    amscr_index_free(y);
}

/* A lazy load of a file decodes each prepared shape when first needed: with a fused weight
 * (the AMSCR distance read for the candidates) the scores, member rows (two threads at once
 * too), the collection's shapes and batch calls, a save (the same bytes) and an add are an
 * eager load's. */
START_TEST(lazy_file_shapes)
{
    amscr_params *p = params_of(0.5, 8, 2);
    amscr_index *x = named_index(p, 6), *y = NULL, *e = NULL;
    amscr_descriptor *q = shape(p, 2000);
    const char *path = "check_index_lazy_shapes.idx";
    ck_assert_int_eq(amscr_index_save(x, path), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_with(path, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_with(path, 0u, &e), AMSCR_OK);
    concurrent_rows(path, e);
    same_query(e, y, q, 0);
    same_query(e, y, q, 6);
    double a[NSHAPES], b[NSHAPES];
    ck_assert_int_eq(amscr_index_member_scores(e, 5, 6, a, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_index_member_scores(y, 5, 6, b, NSHAPES), AMSCR_OK);
    for (size_t j = 0; j < NSHAPES; j++)
        ck_assert(a[j] == b[j] || (isinf(a[j]) && isinf(b[j])));
    const amscr_db *dy = amscr_index_db(y), *de = amscr_index_db(e);
    ck_assert_int_eq(amscr_db_query(dy, q, NULL, NULL, a), AMSCR_OK);
    ck_assert_int_eq(amscr_db_query(de, q, NULL, NULL, b), AMSCR_OK);
    ck_assert(memcmp(a, b, sizeof a) == 0);
    const amscr_descriptor *s = amscr_db_descriptor(dy, 7), *t = amscr_db_descriptor(de, 7);
    ck_assert_ptr_nonnull(s);
    ck_assert(memcmp(amscr_descriptor_input_points(s), amscr_descriptor_input_points(t), 2 * 64 * sizeof(double)) == 0);
    void *b1 = NULL, *b2 = NULL;
    size_t l1 = 0, l2 = 0;
    ck_assert_int_eq(amscr_index_save_memory(e, &b1, &l1), AMSCR_OK);
    ck_assert_int_eq(amscr_index_save_memory(y, &b2, &l2), AMSCR_OK);
    ck_assert_uint_eq(l1, l2);
    ck_assert(memcmp(b1, b2, l1) == 0);
    amscr_db *more = db_of(p, 2);
    ck_assert_int_eq(amscr_index_add(y, more, NULL, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_index_add(e, more, NULL, NULL), AMSCR_OK);
    double c[NSHAPES + 2], d[NSHAPES + 2];
    ck_assert_int_eq(amscr_index_query_scores(e, q, 0, c, NSHAPES + 2), AMSCR_OK);
    ck_assert_int_eq(amscr_index_query_scores(y, q, 0, d, NSHAPES + 2), AMSCR_OK);
    ck_assert(memcmp(c, d, sizeof c) == 0);
    amscr_db_free(more);
    amscr_free(b1);
    amscr_free(b2);
    remove(path);
    amscr_index_free(x);
    amscr_index_free(y);
    amscr_index_free(e);
    amscr_descriptor_free(q);
    amscr_params_free(p);
}
END_TEST

/* Index x's bytes b (len; version 13, its params' closing 0, so no shape keeps an outline) as
 * version 9 (0.8): the closing's and the affine-view factor's 16 bytes of the retrieval block
 * left out. *out_len set; *at: the
 * offset of the index section's length. */
static unsigned char *as_version9(const amscr_index *x, const unsigned char *b, size_t len, size_t *out_len,
                                  size_t *at)
{
    ck_assert(amscr_params_get_inner_closing(amscr_db_params(amscr_index_db(x))) == 0.0);
    ck_assert(amscr_params_get_channel_affine_view(amscr_db_params(amscr_index_db(x))) == 0.0);
    void *dbuf = NULL;
    size_t dlen = 0, ns = 0;
    ck_assert_int_eq(amscr_db_save_memory(amscr_index_db(x), &dbuf, &dlen), AMSCR_OK);
    amscr_free(dbuf);
    ck_assert_int_eq(amscr_params_get_scales(amscr_db_params(amscr_index_db(x)), NULL, &ns), AMSCR_OK);
    size_t cut = 32 + 8 * ns + 60 + 68; /* magic .. scales, the params, the version 7 block */
    unsigned char *o = malloc(len - 16);
    memcpy(o, b, cut);
    memcpy(o + cut, b + cut + 16, len - cut - 16);
    o[8] = 9;
    *out_len = len - 16;
    *at = dlen - 8 - 16;
    uint64_t h = amscr__db_checksum(9, o, *out_len - 8);
    for (int i = 0; i < 8; i++)
        o[*out_len - 8 + (size_t)i] = (unsigned char)(h >> (8 * i));
    return o;
}

/* The version 3 file of index x (no stored channel features, FNV-1a checksum, the 52-byte
 * retrieval block) from its version 9 bytes b (len; one graph): the groups flag (no groups),
 * the features, the inner graph's count, the whitened frame's band and the inner share
 * dropped. *out_len set. */
static unsigned char *as_version3(const amscr_index *x, const unsigned char *b13, size_t len13, size_t *out_len)
{
    size_t len = 0, at = 0, n = amscr_index_size(x);
    unsigned char *b = as_version9(x, b13, len13, &len, &at);
    size_t feat = 12 + n * (size_t)x->nf * 2 * 64 * AMSCR__HF_BINS + 4, keep = len - 8 - feat - 4;
    unsigned char *o = malloc(keep + 8);
    memcpy(o, b, keep);
    free(b);
    o[8] = 3;
    uint64_t sec = 0;
    for (int i = 0; i < 8; i++)
        sec |= (uint64_t)o[at + (size_t)i] << (8 * i);
    sec -= feat + 4;
    for (int i = 0; i < 8; i++)
        o[at + (size_t)i] = (unsigned char)(sec >> (8 * i));
    size_t ns = 0;
    ck_assert_int_eq(amscr_params_get_scales(amscr_db_params(amscr_index_db(x)), NULL, &ns), AMSCR_OK);
    size_t band_at = 32 + 8 * ns + 60 + 52; /* magic .. scales, the params, the version 2 block */
    memmove(o + band_at, o + band_at + 16, keep - band_at - 16); /* the band and the inner share */
    keep -= 16;
    uint64_t h = amscr__db_checksum(3, o, keep);
    for (int i = 0; i < 8; i++)
        o[keep + (size_t)i] = (unsigned char)(h >> (8 * i));
    *out_len = keep + 8;
    return o;
}

/* Format 4 stores the channel features' heights; a version 3 file (without them, rebuilt at
 * load) still loads, eagerly and lazily, to the same scores; features of other dimensions are
 * refused with a detail. */
START_TEST(stored_features)
{
    amscr_params *p = params_of(1.0, 8, 2);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.0), AMSCR_OK); /* all a version 3 file holds */
    ck_assert_int_eq(amscr_params_set_inner_closing(p, 0.0), AMSCR_OK);
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 0.0), AMSCR_OK); /* the mix: all before 0.11 */
    /* one band for both frames: all a version 3 file can hold (it loads with the two equal) */
    ck_assert_int_eq(amscr_params_set_channel_affine_band(p, amscr_params_get_channel_band(p)), AMSCR_OK);
    amscr_index *x = named_index(p, 0), *y = NULL;
    amscr_descriptor *q = shape(p, 2000);
    void *buf = NULL;
    size_t len = 0, l3 = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(((unsigned char *)buf)[8], AMSCR__DB_VERSION_NEWEST);
    ck_assert_int_eq(x->nf, 2);
    void *b13 = NULL; /* the format of 0.11 to 0.13, which older files are made from */
    size_t l13 = 0;
    ck_assert_int_eq(amscr__index_write(x, 13, &b13, &l13), AMSCR_OK);
    ck_assert_int_eq(((unsigned char *)b13)[8], 13);
    ck_assert_uint_gt(l13, len);
    unsigned char *v3 = as_version3(x, b13, l13, &l3);
    free(b13);
    for (unsigned lazy = 0; lazy < 2; lazy++) {
        ck_assert_int_eq(amscr_index_load_memory_with(v3, l3, lazy ? AMSCR_INDEX_LAZY : 0u, &y), AMSCR_OK);
        same_query(x, y, q, 0);
        same_query(x, y, q, 6);
        ck_assert_str_eq(amscr_index_name(y, 3), "three.png");
        amscr_index_free(y);
        y = NULL;
        ck_assert_int_eq(amscr_index_load_memory_with(buf, len, lazy ? AMSCR_INDEX_LAZY : 0u, &y), AMSCR_OK);
        ck_assert_ptr_nonnull(y->hf[0].seq[0]);
        ck_assert(lazy ? y->hf[0].spec[0] == NULL : y->hf[0].spec[0] != NULL);
        /* an index keeps the forward orientation only (the mirrored one is made by a pair that
         * reads it), loaded eagerly or lazily, as it was built */
        ck_assert(y->hf[0].seq[1] == NULL && y->hf[0].spec[1] == NULL);
        ck_assert(x->hf[0].seq[1] == NULL && x->hf[0].spec[1] == NULL);
        same_query(x, y, q, 0);
        same_query(x, y, q, 6);
        amscr_index_free(y);
        y = NULL;
    }
    /* a lazily loaded index saves the heights it did not build: the same bytes */
    void *b2 = NULL;
    size_t len2 = 0;
    ck_assert_int_eq(amscr_index_load_memory_with(v3, l3, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    ck_assert_int_eq(amscr_index_save_memory(y, &b2, &len2), AMSCR_OK);
    ck_assert_uint_eq(len2, len);
    ck_assert(memcmp(b2, buf, len) == 0);
    amscr_index_free(y);
    y = NULL;
    /* a lazy load of a file reads the heights in place from the mapped file: the same scores,
     * the same bytes saved */
    const char *path = "check_index_features.idx";
    ck_assert_int_eq(amscr_index_save(x, path), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_with(path, AMSCR_INDEX_LAZY, &y), AMSCR_OK);
    same_query(x, y, q, 0);
    same_query(x, y, q, 6);
    /* a member's row reads its candidates' mirrored heights, which format 16 does not store:
     * made from their input samples in the mapped file, the same scores */
    for (size_t i = 0; i < NSHAPES; i += 7) {
        double ma[NSHAPES], mb[NSHAPES];
        ck_assert_int_eq(amscr_index_member_scores(x, i, 0, ma, NSHAPES), AMSCR_OK);
        ck_assert_int_eq(amscr_index_member_scores(y, i, 0, mb, NSHAPES), AMSCR_OK);
        ck_assert(memcmp(ma, mb, sizeof ma) == 0);
    }
    amscr_free(b2);
    ck_assert_int_eq(amscr_index_save_memory(y, &b2, &len2), AMSCR_OK);
    ck_assert_uint_eq(len2, len);
    ck_assert(memcmp(b2, buf, len) == 0);
    amscr_index_free(y);
    y = NULL;
    remove(path);
    /* two frames announced as one: refused (from format 16 the forward heights only) */
    unsigned char *b = buf;
    size_t at = len - 8 - (12 + NSHAPES * 2 * 64 * AMSCR__HF_BINS + 4 + 4); /* + inner count, quantizer's */
    ck_assert_int_eq(b[at], 2);
    b[at] = 1;
    uint64_t h = amscr__db_checksum(4, b, len - 8);
    for (int i = 0; i < 8; i++)
        b[len - 8 + (size_t)i] = (unsigned char)(h >> (8 * i));
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "channel features") != NULL);
    ck_assert_ptr_null(y);
    free(v3);
    amscr_free(b2);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_descriptor_free(q);
    amscr_params_free(p);
}
END_TEST

/* The trailing checksum of b (len bytes, version v) rewritten after an edit. */
static void reseal(unsigned char *b, size_t len, uint32_t v)
{
    uint64_t h = amscr__db_checksum(v, b, len - 8);
    for (int i = 0; i < 8; i++)
        b[len - 8 + (size_t)i] = (unsigned char)(h >> (8 * i));
}

/* Index x's version 13 bytes b13 (len13) as version 8 (0.7): as version 9, then the inner graph's
 * section, `drop` bytes before the checksum, left out. *out_len set. */
static unsigned char *as_version8(const amscr_index *x, const unsigned char *b13, size_t len13, size_t drop,
                                  size_t *out_len)
{
    size_t len = 0, at = 0;
    unsigned char *b = as_version9(x, b13, len13, &len, &at);
    unsigned char *o = malloc(len - drop);
    memcpy(o, b, len - 8 - drop);
    free(b);
    o[8] = 8;
    uint64_t sec = 0;
    for (int i = 0; i < 8; i++)
        sec |= (uint64_t)o[at + (size_t)i] << (8 * i);
    sec -= drop;
    for (int i = 0; i < 8; i++)
        o[at + (size_t)i] = (unsigned char)(sec >> (8 * i));
    *out_len = len - drop;
    reseal(o, *out_len, 8);
    return o;
}

/* The inner graph's lists: itself first, by (distance, index), each distance the pair's; a
 * full build's hold each shape's K nearest, a shortlist build's the nearest it saw. */
START_TEST(inner_lists)
{
    amscr_params *p = params_of(1.0, 6, 2);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.3), AMSCR_OK);
    amscr__inner_ws ws;
    ck_assert_int_eq(amscr__inner_ws_init(&ws), AMSCR_OK);
    for (size_t cand = 0; cand <= 10; cand += 10) {
        amscr_index *x = named_index(p, cand);
        size_t k2 = x->k2;
        ck_assert_uint_eq(k2, x->k);
        ck_assert_uint_eq(k2, 6);
        for (size_t i = 0; i < NSHAPES; i++) {
            const uint32_t *j = x->in_idx + i * k2;
            const double *d = x->in_dist + i * k2;
            ck_assert_uint_eq(j[0], i);
            ck_assert(d[0] == 0.0);
            for (size_t t = 1; t < k2; t++) {
                ck_assert(j[t] != i && d[t] >= d[t - 1]);
                ck_assert(d[t] == amscr__index_inner_pair(x, i, j[t], &ws));
                ck_assert(d[t] <= x->dmax2);
            }
            for (size_t o = 0; cand == 0 && o < NSHAPES; o++) { /* nothing nearer outside the list */
                size_t t = 0;
                while (t < k2 && j[t] != o)
                    t++;
                if (t == k2)
                    ck_assert(amscr__index_inner_pair(x, i, o, &ws) >= d[k2 - 1]);
            }
        }
        amscr_index_free(x);
    }
    amscr__inner_ws_free(&ws);
    amscr_params_free(p);
}
END_TEST

/* Inner features read from a file before version 16: the values of a (rounded from them) are b's,
 * the scale and norm to float32's precision. */
static void same_inner(const amscr__inner *a, const amscr__inner *b)
{
    ck_assert(memcmp(a->re, b->re, sizeof a->re) == 0 && memcmp(a->im, b->im, sizeof a->im) == 0);
    ck_assert(fabs(a->scale - b->scale) <= 1e-6 * b->scale);
    ck_assert(fabs(a->norm2 - b->norm2) <= 1e-5 * b->norm2);
}

/* The inner graph's section of a file: a count that is not the params', a bad list entry or a
 * feature that is not finite are refused with a detail; a version 8 file (0.7: one graph)
 * loads to the same scores, but not one whose params give the inner graph a share. */
START_TEST(inner_section)
{
    amscr_params *p = params_of(1.0, 8, 2);
    ck_assert_int_eq(amscr_params_set_inner_closing(p, 0.0), AMSCR_OK); /* no outlines: all version 8 holds */
    ck_assert_int_eq(amscr_params_set_channel_affine_view(p, 0.0), AMSCR_OK); /* the mix: all it holds too */
    amscr_index *x = named_index(p, 0), *y = NULL;
    size_t k2 = x->k2, fk = AMSCR__INNER_F * AMSCR__INNER_K, len = 0;
    void *buf = NULL;
    ck_assert_uint_gt(k2, 0);
    /* version 16 (compact shapes, the inner features as int16 and a scale; then the quantizer's
     * count, 0 in a small index) */
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    size_t sec = 4 + 8 + NSHAPES * k2 * 12 + NSHAPES * (8 + 2 * 2 * fk), at = len - 8 - 4 - sec;
    unsigned char *b = malloc(len);
    memcpy(b, buf, len);
    ck_assert_uint_eq(b[8], 16);
    ck_assert_uint_eq(b[at], k2);
    b[at] = 0; /* no inner graph, the params give one */
    reseal(b, len, 16);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner graph") != NULL);
    memcpy(b, buf, len);
    b[at + 12] = 1; /* shape 0's inner list not starting with itself */
    reseal(b, len, 16);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner neighbour") != NULL);
    memcpy(b, buf, len);
    double dnan = NAN;
    amscr_test_put_le(b + at + 12 + NSHAPES * k2 * 12, &dnan, 8); /* shape 0's scale */
    reseal(b, len, 16);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner features") != NULL);
    ck_assert_ptr_null(y);
    ck_assert_int_eq(amscr_index_load_memory(buf, len, &y), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i++) /* the features: the build's, bit for bit */
        ck_assert(memcmp(&y->inner[i], &x->inner[i], sizeof x->inner[i]) == 0);
    amscr_index_free(y);
    y = NULL;
    free(b);
    amscr_free(buf);
    /* version 15 (the inner features in float32): the same values, the scale to float32's
     * precision; a value that is not finite refused */
    ck_assert_int_eq(amscr__index_write(x, 15, &buf, &len), AMSCR_OK);
    sec = 4 + 8 + NSHAPES * k2 * 12 + NSHAPES * (4 * 2 * fk + 8), at = len - 8 - sec;
    ck_assert_int_eq(amscr_index_load_memory(buf, len, &y), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i++)
        same_inner(&y->inner[i], &x->inner[i]);
    amscr_index_free(y);
    y = NULL;
    b = malloc(len);
    memcpy(b, buf, len);
    float fnan = NAN;
    amscr_test_put_le(b + at + 12 + NSHAPES * k2 * 12 + 4 * 3, &fnan, 4); /* shape 0's fourth real part */
    reseal(b, len, 15);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner features") != NULL);
    ck_assert_ptr_null(y);
    free(b);
    amscr_free(buf);
    /* version 14 (0.14's first builds: the inner features in f64): the same features, and a
     * value beyond float32's range refused */
    ck_assert_int_eq(amscr__index_write(x, 14, &buf, &len), AMSCR_OK);
    sec = 4 + 8 + NSHAPES * k2 * 12 + NSHAPES * 8 * (2 * fk + 1), at = len - 8 - sec;
    ck_assert_int_eq(amscr_index_load_memory(buf, len, &y), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i++)
        same_inner(&y->inner[i], &x->inner[i]);
    amscr_index_free(y);
    y = NULL;
    b = malloc(len);
    memcpy(b, buf, len);
    double huge = 1e300;
    amscr_test_put_le(b + at + 12 + NSHAPES * k2 * 12, &huge, 8); /* shape 0's first real part */
    reseal(b, len, 14);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner features") != NULL);
    ck_assert_ptr_null(y);
    free(b);
    amscr_free(buf);
    /* version 13 (0.11 to 0.13): the features stored */
    ck_assert_int_eq(amscr__index_write(x, 13, &buf, &len), AMSCR_OK);
    sec = 4 + 8 + NSHAPES * k2 * 12 + NSHAPES * 8 * (2 * fk + 1), at = len - 8 - sec;
    b = malloc(len);
    memcpy(b, buf, len);
    ck_assert_uint_eq(b[at], k2);
    b[at] = 0; /* no inner graph, the params give one */
    reseal(b, len, 13);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner graph") != NULL);
    memcpy(b, buf, len);
    b[at + 12] = 1; /* shape 0's inner list not starting with itself */
    reseal(b, len, 13);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner neighbour") != NULL);
    memcpy(b, buf, len);
    double nan = NAN;
    amscr_test_put_le(b + at + 12 + NSHAPES * k2 * 12 + 8 * 2 * fk, &nan, 8); /* shape 0's norm */
    reseal(b, len, 13);
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "inner features") != NULL);
    ck_assert_ptr_null(y);
    size_t l8 = 0;
    unsigned char *v8 = as_version8(x, buf, len, sec, &l8);
    ck_assert_int_eq(amscr_index_load_memory(v8, l8, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "no inner graph") != NULL);
    free(v8);
    free(b);
    amscr_free(buf);
    amscr_index_free(x);
    /* one graph: a version 8 file is the version 9 file without its inner count */
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, 0.0), AMSCR_OK);
    x = named_index(p, 0);
    ck_assert_uint_eq(x->k2, 0);
    ck_assert_int_eq(amscr__index_write(x, 13, &buf, &len), AMSCR_OK);
    v8 = as_version8(x, buf, len, 4, &l8);
    ck_assert_int_eq(amscr_index_load_memory(v8, l8, &y), AMSCR_OK);
    amscr_descriptor *q = shape(p, 2000);
    same_query(x, y, q, 0);
    same_query(x, y, q, 6);
    amscr_descriptor_free(q);
    free(v8);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_index_free(y);
    amscr_params_free(p);
}
END_TEST

/* An index holds its shapes as compact records (their input samples and outline): each decodes
 * to the prepared shape it was built from, bit for bit; a version 13 file (0.11 to 0.13, full
 * records and the inner features) loads, eagerly and lazily, to the same scores and saves as the
 * build's version 15 bytes; every cut of a version 15 file is refused. */
START_TEST(compact_shapes)
{
    amscr_params *p = params_of(0.5, 8, 2); /* fused: a query reads the candidates' prepared shapes */
    amscr_db *db = db_of(p, NSHAPES);
    amscr_index *x = NULL, *y = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    size_t N = amscr_params_get_num_samples(p), np = amscr_db_params(amscr_index_db(x))->num_scales;
    for (size_t i = 0; i < NSHAPES; i++) {
        const amscr_descriptor *a = amscr_db_descriptor(db, i), *b = amscr_db_descriptor(amscr_index_db(x), i);
        ck_assert_ptr_nonnull(b);
        ck_assert(a != b);
        ck_assert(memcmp(a->input, b->input, 2 * N * sizeof(double)) == 0);
        ck_assert(memcmp(a->base, b->base, 2 * N * sizeof(double)) == 0);
        ck_assert(memcmp(a->scaled, b->scaled, 2 * N * np * sizeof(double)) == 0);
        ck_assert(memcmp(a->fwd, b->fwd, sizeof a->fwd) == 0 && memcmp(a->inv, b->inv, sizeof a->inv) == 0);
        ck_assert(a->outline && b->outline && memcmp(a->outline, b->outline, 2 * AMSCR__OUTLINE_N * 8) == 0);
        ck_assert_int_eq(amscr_db_label(amscr_index_db(x), i), amscr_db_label(db, i));
    }
    /* shapes added: kept as compact records too, the same index as one built on all of them */
    amscr_db *half = NULL, *rest = NULL;
    ck_assert_int_eq(amscr_db_new(p, &half), AMSCR_OK);
    ck_assert_int_eq(amscr_db_new(p, &rest), AMSCR_OK);
    for (size_t i = 0; i < NSHAPES; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(i < NSHAPES - 4 ? half : rest, amscr_db_descriptor(db, i),
                                                 amscr_db_label(db, i), NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_index_build(half, 0, NULL, NULL, &y), AMSCR_OK);
    ck_assert_int_eq(amscr_index_add(y, rest, NULL, NULL), AMSCR_OK);
    ck_assert_ptr_nonnull(amscr__db_record(amscr_index_db(y), NSHAPES - 1));
    for (size_t i = 0; i < NSHAPES; i++) {
        const amscr_descriptor *a = amscr_db_descriptor(db, i), *b = amscr_db_descriptor(amscr_index_db(y), i);
        ck_assert(memcmp(a->scaled, b->scaled, 2 * N * np * sizeof(double)) == 0);
        ck_assert_int_eq(amscr_db_label(amscr_index_db(y), i), amscr_db_label(db, i));
    }
    amscr_index_free(y);
    y = NULL;
    amscr_db_free(half);
    amscr_db_free(rest);
    amscr_db_free(db);
    amscr_descriptor *q = shape(p, 2000);
    void *buf = NULL, *b13 = NULL, *b2 = NULL;
    size_t len = 0, l13 = 0, len2 = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr__index_write(x, 13, &b13, &l13), AMSCR_OK);
    ck_assert_uint_lt(len, l13);
    for (unsigned lazy = 0; lazy < 2; lazy++) {
        ck_assert_int_eq(amscr_index_load_memory_with(b13, l13, lazy ? AMSCR_INDEX_LAZY : 0u, &y), AMSCR_OK);
        same_query(x, y, q, 0);
        same_query(x, y, q, 6);
        ck_assert_int_eq(amscr_index_save_memory(y, &b2, &len2), AMSCR_OK);
        ck_assert_uint_eq(len2, len);
        ck_assert(memcmp(b2, buf, len) == 0);
        amscr_free(b2);
        amscr_index_free(y);
        ck_assert_int_eq(amscr_index_load_memory_with(buf, len, lazy ? AMSCR_INDEX_LAZY : 0u, &y), AMSCR_OK);
        same_query(x, y, q, 0);
        same_query(x, y, q, 6);
        amscr_index_free(y);
        y = NULL;
    }
    for (size_t cut = 0; cut < len; cut += cut < 256 ? 1 : 997) { /* a file cut short anywhere */
        ck_assert_int_ne(amscr_index_load_memory(buf, cut, &y), AMSCR_OK);
        ck_assert_ptr_null(y);
        ck_assert(strlen(amscr_last_error_detail()) > 0);
    }
    amscr_descriptor_free(q);
    free(b13);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

/* The file's bytes at path (*len; caller frees). */
static unsigned char *file_bytes(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    unsigned char *b = malloc(1 << 22);
    *len = fread(b, 1, 1 << 22, f);
    fclose(f);
    return b;
}

/* A save cut off, by a full disk (the file-size limit: writes fail) or by the process killed
 * mid-write (SIGXFSZ's default), never replaces the good file, whose mode stays, and leaves no
 * temporary file where the directory takes unnamed ones; the failed save reports an I/O error. */
START_TEST(cut_off_save)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 0);
    char path[] = "/tmp/amscr_cut_XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    close(fd);
    ck_assert_int_eq(amscr_index_save(x, path), AMSCR_OK);
    ck_assert_int_eq(chmod(path, 0644), 0);
    size_t l0 = 0, l1 = 0;
    unsigned char *b0 = file_bytes(path, &l0);
    ck_assert_uint_gt(l0, 8192);
    for (int killed = 0; killed < 2; killed++) {
        pid_t pid = fork();
        ck_assert_int_ge(pid, 0);
        if (pid == 0) { /* the child: writes beyond 4 KB fail, or kill it */
            signal(SIGXFSZ, killed ? SIG_DFL : SIG_IGN);
            struct rlimit rl = {4096, 4096};
            setrlimit(RLIMIT_FSIZE, &rl);
            amscr_status st = amscr_index_save(x, path);
            _exit(st == AMSCR_E_IO ? 3 : 4);
        }
        int ws = 0;
        ck_assert_int_eq(waitpid(pid, &ws, 0), pid);
        if (killed)
            ck_assert(WIFSIGNALED(ws) && WTERMSIG(ws) == SIGXFSZ);
        else
            ck_assert(WIFEXITED(ws) && WEXITSTATUS(ws) == 3);
        unsigned char *b1 = file_bytes(path, &l1);
        ck_assert_uint_eq(l1, l0);
        ck_assert(memcmp(b0, b1, l0) == 0);
        free(b1);
        struct stat sb;
        ck_assert_int_eq(stat(path, &sb), 0);
        ck_assert_uint_eq(sb.st_mode & 0777, 0644);
        amscr_index *y = NULL;
        ck_assert_int_eq(amscr_index_load(path, &y), AMSCR_OK);
        amscr_index_free(y);
    }
    free(b0);
    remove(path);
    char tmpl[64];
    snprintf(tmpl, sizeof tmpl, "%s.tmp.", path + 5);
    int left = 0, unnamed = 0; /* the killed save's temporary file: none where the directory takes */
#ifdef O_TMPFILE                  /* unnamed files (O_TMPFILE); elsewhere it is cleaned up here */
    int probe = open("/tmp", O_TMPFILE | O_WRONLY, 0600);
    unnamed = probe >= 0;
    if (probe >= 0)
        close(probe);
#endif
    DIR *dir = opendir("/tmp");
    for (struct dirent *e = dir ? readdir(dir) : NULL; e; e = readdir(dir))
        if (strncmp(e->d_name, tmpl, strlen(tmpl)) == 0) {
            char t[300];
            snprintf(t, sizeof t, "/tmp/%s", e->d_name);
            remove(t);
            left++;
        }
    if (dir)
        closedir(dir);
    if (unnamed)
        ck_assert_int_eq(left, 0);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

START_TEST(round_trips)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 0), *y = NULL, *z = NULL;
    amscr_descriptor *q = shape(p, 2000);
    const char *path = "check_index_tmp.idx";
    ck_assert_int_eq(amscr_index_save(x, path), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load(path, &y), AMSCR_OK);
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_memory(buf, len, &z), AMSCR_OK);
    same_query(x, y, q, 0);
    same_query(x, z, q, 0);
    same_query(x, y, q, 6);
    /* the inner graph: its lists and features as built */
    ck_assert_uint_gt(x->k2, 0);
    ck_assert(memcmp(x->in_idx, y->in_idx, NSHAPES * x->k2 * sizeof *x->in_idx) == 0);
    ck_assert(memcmp(x->in_dist, z->in_dist, NSHAPES * x->k2 * sizeof *x->in_dist) == 0);
    ck_assert(memcmp(x->inner, y->inner, NSHAPES * sizeof *x->inner) == 0 && x->dmax2 == y->dmax2);
    ck_assert_str_eq(amscr_index_name(y, 3), "three.png");
    ck_assert_ptr_null(amscr_index_name(y, 4));
    ck_assert_str_eq(amscr_index_class_name(z, 2), "bird");
    ck_assert_ptr_null(amscr_index_class_name(z, 1));
    ck_assert_int_eq(amscr_index_label(y, 7), 1);
    /* an index file is a collection file: amscr_db_load gives its collection */
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_load(path, &db), AMSCR_OK);
    ck_assert_uint_eq(amscr_db_size(db), NSHAPES);
    ck_assert_int_eq(amscr_db_label(db, 7), 1);
    /* a collection file without an index is refused by the index loader, clearly */
    ck_assert_int_eq(amscr_db_save(db, path), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load(path, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "amscr_index_build") != NULL);
    remove(path);
    amscr_db_free(db);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_index_free(y);
    amscr_index_free(z);
    amscr_descriptor_free(q);
    amscr_params_free(p);
}
END_TEST

START_TEST(bad_files)
{
    amscr_params *p = params_of(1.0, 8, 1);
    amscr_index *x = named_index(p, 0), *y = NULL;
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    unsigned char *b = malloc(len);
    for (size_t cut = 0; cut < len; cut += 1 + cut / 3) { /* truncated */
        memcpy(b, buf, cut);
        ck_assert_int_eq(amscr_index_load_memory(b, cut, &y), AMSCR_E_FORMAT);
    }
    for (size_t at = 0; at < len; at += 97) { /* damaged */
        memcpy(b, buf, len);
        b[at] ^= 0x5a;
        ck_assert_int_ne(amscr_index_load_memory(b, len, &y), AMSCR_OK);
    }
    memcpy(b, buf, len);
    b[8] = AMSCR__DB_VERSION_NEWEST + 1; /* a newer version */
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "newer") != NULL);
    memcpy(b, "AMSCRIDX", 8); /* the tool's index before 0.4 */
    ck_assert_int_eq(amscr_index_load_memory(b, len, &y), AMSCR_E_FORMAT);
    ck_assert(strstr(amscr_last_error_detail(), "rebuild") != NULL);
    ck_assert_int_eq(amscr_index_load_memory(NULL, len, &y), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_load("/nonexistent/x.idx", &y), AMSCR_E_IO);
    free(b);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

/* add: refused with other params (the detail names the option); with the same, a full index
 * gives the scores of a rebuild. */
START_TEST(add_shapes)
{
    amscr_params *p = params_of(1.0, 8, 2), *other = params_of(1.0, 6, 2);
    amscr_db *first = db_of(p, NSHAPES - 4), *all = db_of(p, NSHAPES), *more = NULL, *wrong = db_of(other, 2);
    ck_assert_int_eq(amscr_db_new(p, &more), AMSCR_OK);
    for (size_t i = NSHAPES - 4; i < NSHAPES; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(more, amscr_db_descriptor(all, i), amscr_db_label(all, i), NULL),
                         AMSCR_OK);
    amscr_index *x = NULL, *ref = NULL;
    ck_assert_int_eq(amscr_index_build(first, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_index_add(x, wrong, NULL, NULL), AMSCR_E_INVALID_ARG);
    ck_assert(strstr(amscr_last_error_detail(), "rerank_k") != NULL);
    ck_assert_uint_eq(amscr_index_size(x), NSHAPES - 4);
    ck_assert_int_eq(amscr_index_add(x, more, NULL, NULL), AMSCR_OK);
    ck_assert_int_eq(amscr_index_build(all, 0, NULL, NULL, &ref), AMSCR_OK);
    amscr_descriptor *q = shape(p, 3000);
    double a[NSHAPES], b[NSHAPES];
    ck_assert_int_eq(amscr_index_query_scores(x, q, 0, a, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_index_query_scores(ref, q, 0, b, NSHAPES), AMSCR_OK);
    assert_close(a, b, NSHAPES, 1e-12);
    amscr_descriptor_free(q);
    amscr_index_free(x);
    amscr_index_free(ref);
    amscr_db_free(first);
    amscr_db_free(all);
    amscr_db_free(more);
    amscr_db_free(wrong);
    amscr_params_free(p);
    amscr_params_free(other);
}
END_TEST

static int reports_seen;
static int cancel_at_first(void *user, size_t done, size_t total)
{
    (void)user, (void)done, (void)total;
    reports_seen++;
    return 1;
}

/* An add cancelled (or out of memory) after it took its shapes in leaves an index whose new
 * shapes lack their lists: the header says to free it, and every call but free refuses it with
 * AMSCR_E_STATE (a query read the missing lists: SIGSEGV). An add of no shapes is no work: no
 * report (it reported 0 of 0), AMSCR_OK. */
START_TEST(add_cancelled_leaves_an_index_to_free)
{
    amscr_params *p = params_of(1.0, 8, 1);
    amscr_db *first = db_of(p, NSHAPES - 4), *all = db_of(p, NSHAPES), *more = NULL, *none = NULL;
    ck_assert_int_eq(amscr_db_new(p, &more), AMSCR_OK);
    ck_assert_int_eq(amscr_db_new(p, &none), AMSCR_OK);
    for (size_t i = NSHAPES - 4; i < NSHAPES; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(more, amscr_db_descriptor(all, i), amscr_db_label(all, i), NULL),
                         AMSCR_OK);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(first, 0, NULL, NULL, &x), AMSCR_OK);
    reports_seen = 0;
    ck_assert_int_eq(amscr_index_add(x, none, cancel_at_first, NULL), AMSCR_OK);
    ck_assert_int_eq(reports_seen, 0);
    ck_assert_int_eq(amscr_index_add(x, more, cancel_at_first, NULL), AMSCR_E_CANCELLED);
    amscr_descriptor *q = shape(p, 3000);
    double a[NSHAPES];
    size_t idx[5], cnt, i = 77;
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_index_query_scores(x, q, 0, a, amscr_index_size(x)), AMSCR_E_STATE);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "free it"));
    ck_assert_int_eq(amscr_index_search(x, q, 0, 5, idx, a, &cnt), AMSCR_E_STATE);
    ck_assert_int_eq(amscr_index_member_scores(x, 0, 0, a, amscr_index_size(x)), AMSCR_E_STATE);
    ck_assert_int_eq(amscr_index_find_member(x, q, &i), AMSCR_E_STATE);
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_E_STATE);
    ck_assert_ptr_null(buf);
    ck_assert_int_eq(amscr_index_add(x, more, NULL, NULL), AMSCR_E_STATE);
    amscr_index_free(x);
    amscr_descriptor_free(q);
    amscr_db_free(first);
    amscr_db_free(all);
    amscr_db_free(more);
    amscr_db_free(none);
    amscr_params_free(p);
}
END_TEST

/* A query of an empty collection is no work: no report (it reported 0 of 0, twice), AMSCR_OK. */
START_TEST(empty_collection_query_reports_nothing)
{
    for (int ranked = 0; ranked < 2; ranked++) {
        amscr_params *p = params_of(ranked ? 1.0 : 0.0, ranked ? 8 : 0, 2);
        amscr_db *db = NULL;
        ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
        amscr_descriptor *q = shape(p, 5);
        double out[1] = {7.0};
        reports_seen = 0;
        ck_assert_int_eq(amscr_db_query_retrieval(db, q, cancel_at_first, NULL, out, 0), AMSCR_OK);
        ck_assert_int_eq(amscr_db_search_retrieval(db, q, cancel_at_first, NULL, out, 0), AMSCR_OK);
        ck_assert_int_eq(amscr_db_query(db, q, cancel_at_first, NULL, out), AMSCR_OK);
        ck_assert_int_eq(reports_seen, 0);
        ck_assert(out[0] == 7.0);
        amscr_descriptor_free(q);
        amscr_db_free(db);
        amscr_params_free(p);
    }
}
END_TEST

/* Queries, searches (of members' copies too) and member rows of a loaded index read its shapes
 * without keeping them decoded: its memory does not grow with its queries (a search decoded its
 * 32 signature-nearest shapes for the member rule and kept them, ~36 KB a shape). Only
 * amscr_db_descriptor of amscr_index_db keeps the shape it decodes. */
START_TEST(queries_keep_no_decoded_shape)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of(p, NSHAPES);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    void *buf = NULL;
    size_t len = 0, idx[5], cnt, member = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    for (unsigned flags = 0; flags <= AMSCR_INDEX_LAZY; flags++) {
        amscr_index *y = NULL;
        ck_assert_int_eq(amscr_index_load_memory_with(buf, len, flags, &y), AMSCR_OK);
        double a[NSHAPES], b[NSHAPES], top[5];
        for (size_t i = 0; i < NSHAPES; i++) {
            amscr_descriptor *copy = shape(p, (unsigned)i), *other = shape(p, 2000 + (unsigned)i);
            ck_assert_int_eq(amscr_index_search_scores(y, copy, 0, a, NSHAPES), AMSCR_OK);
            ck_assert_int_eq(amscr_index_member_scores(y, i, 0, b, NSHAPES), AMSCR_OK);
            assert_close(a, b, NSHAPES, 0.0); /* the copy scored as the member */
            ck_assert_int_eq(amscr_index_find_member(y, copy, &member), AMSCR_OK);
            ck_assert_uint_eq(member, i);
            ck_assert_int_eq(amscr_index_search(y, other, 0, 5, idx, top, &cnt), AMSCR_OK);
            ck_assert_int_eq(amscr_index_query(y, other, 0, 5, idx, top, &cnt), AMSCR_OK);
            amscr_descriptor_free(copy);
            amscr_descriptor_free(other);
        }
        ck_assert_uint_eq(amscr__db_decoded(amscr_index_db(y)), 0);
        ck_assert_ptr_nonnull(amscr_db_descriptor(amscr_index_db(y), 3)); /* decoded, and kept */
        ck_assert_uint_eq(amscr__db_decoded(amscr_index_db(y)), 1);
        amscr_index_free(y);
    }
    free(buf);
    amscr_index_free(x);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* Shapes added to an index of fewer than twice its re-ranking k, whose lists grow with its size:
 * the index is built again on its shapes and the new ones (the queries a build's), its names,
 * groups and class names kept; one shape at a time from an empty index too. */
START_TEST(add_grows_the_lists)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *first = db_of(p, 3), *all = db_of(p, 12), *more = NULL;
    ck_assert_int_eq(amscr_db_new(p, &more), AMSCR_OK);
    for (size_t i = 3; i < 12; i++)
        ck_assert_int_eq(amscr_db_add_descriptor(more, amscr_db_descriptor(all, i), amscr_db_label(all, i), NULL),
                         AMSCR_OK);
    amscr_index *x = NULL, *ref = NULL, *one = NULL;
    ck_assert_int_eq(amscr_index_build(first, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_name(x, 1, "one.png"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_group(x, 2, "object-2"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_class_name(x, 0, "bone"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_add(x, more, NULL, NULL), AMSCR_OK);
    ck_assert_uint_eq(amscr_index_size(x), 12);
    ck_assert_str_eq(amscr_index_name(x, 1), "one.png");
    ck_assert_str_eq(amscr_index_group(x, 2), "object-2");
    ck_assert_str_eq(amscr_index_class_name(x, 0), "bone");
    ck_assert_ptr_null(amscr_index_name(x, 5));
    ck_assert_int_eq(amscr_index_build(all, 0, NULL, NULL, &ref), AMSCR_OK);
    amscr_db *empty = db_of(p, 0), *single = NULL;
    ck_assert_int_eq(amscr_index_build(empty, 0, NULL, NULL, &one), AMSCR_OK);
    for (size_t i = 0; i < 12; i++) { /* one at a time: K = 1, 1, 1, 2, ... */
        ck_assert_int_eq(amscr_db_new(p, &single), AMSCR_OK);
        ck_assert_int_eq(amscr_db_add_descriptor(single, amscr_db_descriptor(all, i), amscr_db_label(all, i), NULL),
                         AMSCR_OK);
        ck_assert_int_eq(amscr_index_add(one, single, NULL, NULL), AMSCR_OK);
        amscr_db_free(single);
    }
    amscr_descriptor *q = shape(p, 3000);
    double a[12], b[12], c[12];
    ck_assert_int_eq(amscr_index_query_scores(x, q, 0, a, 12), AMSCR_OK);
    ck_assert_int_eq(amscr_index_query_scores(ref, q, 0, b, 12), AMSCR_OK);
    ck_assert_int_eq(amscr_index_query_scores(one, q, 0, c, 12), AMSCR_OK);
    assert_close(a, b, 12, 1e-12);
    assert_close(c, b, 12, 1e-12);
    amscr_descriptor_free(q);
    amscr_index_free(x);
    amscr_index_free(ref);
    amscr_index_free(one);
    amscr_db_free(first);
    amscr_db_free(all);
    amscr_db_free(more);
    amscr_db_free(empty);
    amscr_params_free(p);
}
END_TEST

/* The saved bytes do not depend on the thread count (full and shortlist builds). */
START_TEST(thread_independence)
{
    for (size_t cand = 0; cand <= 10; cand += 10) {
        void *buf[2] = {NULL, NULL};
        size_t len[2] = {0, 0};
        for (unsigned t = 0; t < 2; t++) {
            amscr_params *p = params_of(1.0, 8, t == 0 ? 1 : 3);
            amscr_index *x = named_index(p, cand);
            ck_assert_int_eq(amscr_params_set_num_threads(p, 1), AMSCR_OK);
            ck_assert_int_eq(amscr_index_save_memory(x, &buf[t], &len[t]), AMSCR_OK);
            amscr_index_free(x);
            amscr_params_free(p);
        }
        ck_assert_uint_eq(len[0], len[1]);
        /* the params (their thread count) differ; everything after them is the same */
        ck_assert(memcmp((char *)buf[0] + len[0] / 4, (char *)buf[1] + len[1] / 4, len[0] - len[0] / 4 - 8) == 0);
        amscr_free(buf[0]);
        amscr_free(buf[1]);
    }
}
END_TEST

/* A shortlist query returns finite scores for its best shapes; top-k agrees with the scores. */
START_TEST(groups)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 0), *y = NULL;
    void *b0 = NULL, *b1 = NULL;
    size_t l0 = 0, l1 = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &b0, &l0), AMSCR_OK);
    ck_assert_ptr_null(amscr_index_group(x, 0));
    ck_assert_int_eq(amscr_index_set_group(x, NSHAPES, "a"), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_set_group(NULL, 0, "a"), AMSCR_E_INVALID_ARG);
    ck_assert_ptr_null(amscr_index_group(NULL, 0));
    ck_assert_int_eq(amscr_index_set_group(x, 0, "cup-a"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_group(x, 5, "cup-b"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_set_group(x, 5, "cup-c"), AMSCR_OK);
    ck_assert_int_eq(amscr_index_save_memory(x, &b1, &l1), AMSCR_OK);
    ck_assert_uint_gt(l1, l0); /* an index without groups keeps the format without them */
    ck_assert_int_eq(amscr_index_load_memory(b1, l1, &y), AMSCR_OK);
    ck_assert_str_eq(amscr_index_group(y, 0), "cup-a");
    ck_assert_str_eq(amscr_index_group(y, 5), "cup-c");
    ck_assert_ptr_null(amscr_index_group(y, 1));
    ck_assert_str_eq(amscr_index_name(y, 3), "three.png");
    amscr_index_free(y);
    y = NULL;
    ck_assert_int_eq(amscr_index_load_memory(b0, l0, &y), AMSCR_OK);
    ck_assert_ptr_null(amscr_index_group(y, 0));
    amscr_index_free(y);
    y = NULL;
    ck_assert_int_eq(amscr_index_set_group(x, 0, NULL), AMSCR_OK);
    ck_assert_ptr_null(amscr_index_group(x, 0));
    amscr_free(b0);
    amscr_free(b1);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

START_TEST(top_and_shortlist)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 10);
    amscr_descriptor *q = shape(p, 6); /* class 0 */
    size_t idx[5], cnt = 0;
    double sc[5], all[NSHAPES];
    ck_assert_int_eq(amscr_index_query(x, q, 12, 5, idx, sc, &cnt), AMSCR_OK);
    ck_assert_uint_eq(cnt, 5);
    ck_assert_int_eq(amscr_index_query_scores(x, q, 12, all, NSHAPES), AMSCR_OK);
    for (size_t t = 0; t < cnt; t++) {
        ck_assert(isfinite(sc[t]) && sc[t] == all[idx[t]]);
        ck_assert(t == 0 || sc[t] >= sc[t - 1]);
    }
    ck_assert_int_eq(amscr_index_label(x, idx[0]), 0);
    ck_assert_int_eq(amscr_index_query(x, NULL, 0, 5, idx, sc, &cnt), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_index_query_scores(x, q, 0, all, NSHAPES - 1), AMSCR_E_INVALID_ARG);
    amscr_descriptor_free(q);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

/* Shape i of a larger collection: one of `classes` random base shapes, affinely warped. */
static amscr_descriptor *shape_of(const amscr_params *p, unsigned i, unsigned classes)
{
    amscr_test_rng r;
    double xy[2 * NPTS], w[2 * NPTS], m[6];
    amscr_test_rng_seed(&r, 5000 + i % classes);
    amscr_test_random_shape(&r, NPTS, 5, xy);
    amscr_test_rng_seed(&r, 9000 + i);
    amscr_test_random_affine(&r, 2.0, 0.5, 3.0, 0, m);
    amscr_test_apply_affine(m, xy, NPTS, w);
    amscr_test_add_noise(&r, w, NPTS, 0.01);
    amscr_contour *c = NULL;
    amscr_descriptor *d = NULL;
    ck_assert_int_eq(amscr_contour_new(w, NPTS, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_descriptor_new(p, c, &d), AMSCR_OK);
    amscr_contour_free(c);
    return d;
}

/* n shapes of shape_of, labelled by class. */
static amscr_db *db_of_classes(const amscr_params *p, unsigned n, unsigned classes)
{
    amscr_db *db = NULL;
    ck_assert_int_eq(amscr_db_new(p, &db), AMSCR_OK);
    for (unsigned i = 0; i < n; i++) {
        amscr_descriptor *d = shape_of(p, i, classes);
        ck_assert_int_eq(amscr_db_add_descriptor(db, d, (int32_t)(i % classes), NULL), AMSCR_OK);
        amscr_descriptor_free(d);
    }
    return db;
}

/* In a collection of many small classes a query enters few rows' lists: the rows it leaves
 * alone keep the affinities stored at build time (x->w_fixed), the others are recomputed. The
 * query row still equals the matrix row of the collection plus the query, at either graph's
 * share, for queries near and far from the collection's shapes. */
static void left_alone_case(double share)
{
    enum { N = 72, CLASSES = 24 };
    amscr_params *p = params_of(1.0, 4, 2);
    ck_assert_int_eq(amscr_params_set_rerank_inner_share(p, share), AMSCR_OK);
    amscr_db *db = db_of_classes(p, N, CLASSES);
    amscr_index *x = NULL;
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &x), AMSCR_OK);
    ck_assert_ptr_nonnull(x->w_fixed);
    double ref[N], got[N];
    for (unsigned t = 0; t < 4; t++) {
        amscr_descriptor *q = shape_of(p, t < 2 ? 5 + 24 * t : 500 + t, CLASSES);
        reference_row(db, q, ref);
        ck_assert_int_eq(amscr_index_query_scores(x, q, 0, got, N), AMSCR_OK);
        assert_close(ref, got, N, 1e-12);
        amscr_descriptor_free(q);
    }
    amscr_index_free(x);
    amscr_db_free(db);
    amscr_params_free(p);
}

START_TEST(rows_left_alone)
{
    left_alone_case(0.0);
    left_alone_case(0.3);
}
END_TEST

/* The default shortlist (AMSCR_INDEX_CANDIDATES, build and query) finds the exact first hit of
 * affine-warped queries in a collection larger than the shortlist. */
START_TEST(default_shortlist_first_hit)
{
    enum { N = 320, CLASSES = 40 };
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of_classes(p, N, CLASSES);
    amscr_index *x = NULL, *full = NULL;
    ck_assert_int_eq(amscr_index_build(db, AMSCR_INDEX_CANDIDATES, NULL, NULL, &x), AMSCR_OK);
    ck_assert_int_eq(amscr_index_build(db, 0, NULL, NULL, &full), AMSCR_OK);
    for (unsigned q = 0; q < 6; q++) {
        amscr_descriptor *d = shape_of(p, 100000 + q * 7, CLASSES);
        size_t a[1], b[1], ca = 0, cb = 0;
        double sa[1], sb[1];
        ck_assert_int_eq(amscr_index_query(x, d, AMSCR_INDEX_CANDIDATES, 1, a, sa, &ca), AMSCR_OK);
        ck_assert_int_eq(amscr_index_query(full, d, 0, 1, b, sb, &cb), AMSCR_OK);
        ck_assert_uint_eq(a[0], b[0]);
        amscr_descriptor_free(d);
    }
    amscr_index_free(x);
    amscr_index_free(full);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* A query reads the lists' reverse kept by the build, or builds its own (after an add): the
 * same scores. */
START_TEST(kept_and_own_reverse)
{
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_index *x = named_index(p, 10);
    amscr_descriptor *q = shape(p, 3000);
    double a[NSHAPES], b[NSHAPES], ma[NSHAPES], mb[NSHAPES];
    ck_assert_ptr_nonnull(x->rev);
    ck_assert_int_eq(amscr_index_query_scores(x, q, 12, a, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_index_member_scores(x, 5, 12, ma, NSHAPES), AMSCR_OK);
    amscr__index_reverse_free(x);
    ck_assert_int_eq(amscr_index_query_scores(x, q, 12, b, NSHAPES), AMSCR_OK);
    ck_assert_int_eq(amscr_index_member_scores(x, 5, 12, mb, NSHAPES), AMSCR_OK);
    for (size_t j = 0; j < NSHAPES; j++) {
        ck_assert(a[j] == b[j] || (isinf(a[j]) && isinf(b[j])));
        ck_assert(ma[j] == mb[j] || (isinf(ma[j]) && isinf(mb[j])));
    }
    amscr_descriptor_free(q);
    amscr_index_free(x);
    amscr_params_free(p);
}
END_TEST

/* The coarse quantizer's shortlist: m distinct shapes, ascending, without the excluded one, and
 * most of the exact shortlist. Rows in 16 bits give the shortlists of their dequantized floats,
 * and quantize back from them to the same bits. */
START_TEST(quantizer_shortlist)
{
    enum { N = 3000, M = 32, ROWS = 20, CLUSTERS = 60 };
    float *sig = malloc((size_t)N * AMSCR__SIG_DIM * sizeof *sig);
    float *lb = malloc((size_t)N * AMSCR__SIG_LB_DIM * sizeof *lb);
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 77);
    for (size_t i = 0; i < N; i++)
        for (size_t t = 0; t < AMSCR__SIG_DIM; t++) /* clustered: a centre per class plus noise */
            sig[i * AMSCR__SIG_DIM + t] = (float)(fabs(sin((double)((i % CLUSTERS) * 131 + t))) +
                                                  0.2 * amscr_test_uniform(&r));
    uint16_t *q16 = malloc((size_t)N * AMSCR__SIG_DIM * sizeof *q16), back[AMSCR__SIG_DIM];
    int32_t *e = malloc(N * sizeof *e), e2 = 0;
    for (size_t i = 0; i < N; i++) { /* the rows as an index keeps them */
        amscr__sig_quantize(sig + i * AMSCR__SIG_DIM, q16 + i * AMSCR__SIG_DIM, &e[i]);
        amscr__sig_dequantize(q16 + i * AMSCR__SIG_DIM, e[i], sig + i * AMSCR__SIG_DIM);
        amscr__sig_quantize(sig + i * AMSCR__SIG_DIM, back, &e2);
        ck_assert(e2 == e[i] && memcmp(back, q16 + i * AMSCR__SIG_DIM, sizeof back) == 0);
        amscr__sig_bound_vector(sig + i * AMSCR__SIG_DIM, lb + i * AMSCR__SIG_LB_DIM);
    }
    amscr__sig_rows rows = {sig, NULL, NULL}, rows16 = {NULL, q16, e};
    amscr__sig_ivf v;
    ck_assert_int_eq(amscr__sig_ivf_build(lb, N, &v), AMSCR_OK);
    size_t a[M], b[M], same = 0;
    for (size_t q = 0; q < ROWS; q++) {
        size_t i = q * 149;
        const float *s = sig + i * AMSCR__SIG_DIM, *l = lb + i * AMSCR__SIG_LB_DIM;
        size_t c[M];
        ck_assert_uint_eq(amscr__sig_nearest(&rows, lb, N, s, l, M, i, a), M);
        ck_assert_uint_eq(amscr__sig_nearest(&rows16, lb, N, s, l, M, i, c), M);
        ck_assert_mem_eq(a, c, sizeof a);
        ck_assert_uint_eq(amscr__sig_ivf_nearest(&v, &rows16, lb, N, s, l, M, i, b), M);
        for (size_t u = 0; u < M; u++) {
            ck_assert(b[u] != i && b[u] < N && (u == 0 || b[u] > b[u - 1]));
            for (size_t w = 0; w < M; w++)
                same += a[w] == b[u];
        }
    }
    ck_assert_msg(same >= 9 * M * ROWS / 10, "%zu of %d", same, M * ROWS);
    amscr__sig_ivf_free(&v);
    free(sig);
    free(q16);
    free(e);
    free(lb);
}
END_TEST

/* The sublinear query of a large index (the quantizer's shortlist and the pruned diffusion; a
 * build keeps its quantizer from AMSCR__INDEX_IVF_MIN shapes, attached here to a collection
 * small enough to build in seconds) finds the top 10 and first hit of the query that scans every
 * signature (the same index without its quantizer), its first hit of the exhaustive query's class
 * (every shape matched), while probing only some of the lists; a file keeps the quantizer (the
 * same scores after a load) and an add puts the new shapes in its lists. */
START_TEST(quantizer_query)
{
    enum { N = 1200, CLASSES = 120, M = 32, TOP = 10, QUERIES = 6 };
    amscr_params *p = params_of(1.0, 8, 2);
    amscr_db *db = db_of_classes(p, N, CLASSES);
    amscr_index *x = NULL, *y = NULL;
    ck_assert_int_eq(amscr_index_build(db, M, NULL, NULL, &x), AMSCR_OK);
    ck_assert_uint_eq(x->ivf.nc, 0); /* below AMSCR__INDEX_IVF_MIN: every bound scanned */
    ck_assert_int_eq(amscr__sig_ivf_build(x->sig_lb, N, &x->ivf), AMSCR_OK);
    amscr__sig_ivf ivf = x->ivf, none;
    memset(&none, 0, sizeof none);
    ck_assert_uint_lt(16 * M + 1 + N / x->ivf.nc * 2, N); /* the probed lists hold some of the shapes */
    void *buf = NULL;
    size_t len = 0;
    ck_assert_int_eq(amscr_index_save_memory(x, &buf, &len), AMSCR_OK);
    ck_assert_int_eq(amscr_index_load_memory(buf, len, &y), AMSCR_OK);
    ck_assert_uint_eq(y->ivf.nc, x->ivf.nc);
    ck_assert(memcmp(y->ivf.cell, x->ivf.cell, N * sizeof *x->ivf.cell) == 0);
    ck_assert(memcmp(y->ivf.cent, x->ivf.cent, x->ivf.nc * AMSCR__SIG_LB_DIM * sizeof(float)) == 0);
    static double sx[N], sy[N];
    for (unsigned q = 0; q < QUERIES; q++) {
        amscr_descriptor *d = shape_of(p, 300000 + q * 13, CLASSES);
        size_t a[TOP], b[TOP], c[TOP], ca = 0, cb = 0, cc = 0, kept = 0;
        double va[TOP], vb[TOP], vc[TOP];
        ck_assert_int_eq(amscr_index_query(x, d, M, TOP, a, va, &ca), AMSCR_OK);
        x->ivf = none; /* every signature scanned, the exact diffusion */
        ck_assert_int_eq(amscr_index_query(x, d, M, TOP, c, vc, &cc), AMSCR_OK);
        ck_assert_int_eq(amscr_index_query(x, d, 0, TOP, b, vb, &cb), AMSCR_OK);
        x->ivf = ivf;
        ck_assert_uint_eq(ca, TOP);
        for (size_t u = 0; u < TOP; u++)
            for (size_t v = 0; v < TOP; v++)
                kept += a[u] == c[v];
        ck_assert_uint_eq(kept, TOP);
        ck_assert_uint_eq(a[0], c[0]);
        ck_assert_int_eq(amscr_index_label(x, a[0]), amscr_index_label(x, b[0]));
        ck_assert_int_eq(amscr_index_query_scores(x, d, M, sx, N), AMSCR_OK);
        ck_assert_int_eq(amscr_index_query_scores(y, d, M, sy, N), AMSCR_OK);
        for (size_t j = 0; j < N; j++)
            ck_assert(sx[j] == sy[j] || (isinf(sx[j]) && isinf(sy[j])));
        amscr_descriptor_free(d);
    }
    amscr_db *more = NULL; /* shapes N..N+7 */
    ck_assert_int_eq(amscr_db_new(p, &more), AMSCR_OK);
    for (unsigned i = 0; i < 8; i++) {
        amscr_descriptor *d = shape_of(p, N + i, CLASSES);
        ck_assert_int_eq(amscr_db_add_descriptor(more, d, (int32_t)((N + i) % CLASSES), NULL), AMSCR_OK);
        amscr_descriptor_free(d);
    }
    ck_assert_int_eq(amscr_index_add(y, more, NULL, NULL), AMSCR_OK);
    ck_assert_uint_eq(y->ivf.n, N + 8);
    ck_assert_uint_eq(y->ivf.start[y->ivf.nc], N + 8);
    size_t a[1], ca = 0;
    double va[1];
    amscr_descriptor *d = shape_of(p, N + 3, CLASSES); /* an added shape's own samples: the member rule */
    ck_assert_int_eq(amscr_index_search(y, d, M, 1, a, va, &ca), AMSCR_OK);
    ck_assert_uint_eq(a[0], N + 3);
    amscr_descriptor_free(d);
    amscr_db_free(more);
    amscr_free(buf);
    amscr_index_free(x);
    amscr_index_free(y);
    amscr_db_free(db);
    amscr_params_free(p);
}
END_TEST

/* The reference order of amscr__knn_select: itself first, then by distance, ties by index. */
typedef struct {
    double d;
    size_t j;
} ref_nb;

static int ref_cmp(const void *a, const void *b)
{
    const ref_nb *x = a, *y = b;
    if (x->d != y->d)
        return x->d < y->d ? -1 : 1;
    return x->j < y->j ? -1 : (x->j > y->j);
}

/* The k nearest kept by insertion equal the first k of the whole candidate list sorted: with
 * many ties, the shape itself among the candidates or not, fewer candidates than k (the last
 * repeated) and k = 1. */
START_TEST(knn_select_is_the_sorted_prefix)
{
    unsigned long long s = 12345;
    for (int trial = 0; trial < 300; trial++) {
        size_t m = (size_t)(trial % 37), k = 1 + (size_t)(trial % 11), self = (size_t)(trial % 5);
        size_t cj[40];
        double cd[40];
        ref_nb ref[41];
        size_t r = 0;
        ref[r++] = (ref_nb){-1.0, self};
        for (size_t t = 0; t < m; t++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            cj[t] = (size_t)(s >> 33) % 50;   /* repeats, and now and then itself */
            cd[t] = (double)((s >> 20) % 4); /* many ties */
            if (cj[t] != self)
                ref[r++] = (ref_nb){cd[t], cj[t]};
        }
        qsort(ref, r, sizeof *ref, ref_cmp);
        uint32_t idx[16];
        double dist[16];
        ck_assert_int_eq(amscr__knn_select(self, cj, cd, m, k, idx, dist), AMSCR_OK);
        for (size_t t = 0; t < k; t++) {
            const ref_nb *e = &ref[t < r ? t : r - 1];
            ck_assert_uint_eq(idx[t], e->j);
            ck_assert(dist[t] == (t == 0 ? 0.0 : e->d));
        }
    }
}
END_TEST

Suite *amscr_suite_index(void)
{
    Suite *s = suite_create("index");
    TCase *tc = tcase_create("index");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, knn_select_is_the_sorted_prefix);
    tcase_add_test(tc, default_candidates);
    tcase_add_test(tc, kept_after_add);
    tcase_add_test(tc, kept_after_add_amscr);
    tcase_add_test(tc, kept_concurrent);
    tcase_add_test(tc, exact_channel_rerank);
    tcase_add_test(tc, exact_amscr_rerank);
    tcase_add_test(tc, exact_fused_rerank);
    tcase_add_test(tc, exact_channel_plain);
    tcase_add_test(tc, exact_large_k);
    tcase_add_test(tc, exact_one_graph);
    tcase_add_test(tc, exact_inner_heavy);
    tcase_add_test(tc, exact_inner_amscr);
    tcase_add_test(tc, inner_lists);
    tcase_add_test(tc, inner_section);
    tcase_add_test(tc, member_rows);
    tcase_add_test(tc, member_rule_rerank);
    tcase_add_test(tc, member_rule_fused);
    tcase_add_test(tc, member_rule_channel_alone);
    tcase_add_test(tc, round_trips);
    tcase_add_test(tc, compact_shapes);
    tcase_add_test(tc, cut_off_save);
    tcase_add_test(tc, lazy_load);
    tcase_add_test(tc, lazy_file_shapes);
    tcase_add_test(tc, stored_features);
    tcase_add_test(tc, bad_files);
    tcase_add_test(tc, add_shapes);
    tcase_add_test(tc, kept_query_from_its_own_callback);
    tcase_add_test(tc, kept_query_reports_progress);
    tcase_add_test(tc, build_reports_its_features);
    tcase_add_test(tc, empty_collection_query_reports_nothing);
    tcase_add_test(tc, queries_keep_no_decoded_shape);
    tcase_add_test(tc, add_cancelled_leaves_an_index_to_free);
    tcase_add_test(tc, add_grows_the_lists);
    tcase_add_test(tc, thread_independence);
    tcase_add_test(tc, top_and_shortlist);
    tcase_add_test(tc, default_shortlist_first_hit);
    tcase_add_test(tc, groups);
    tcase_add_test(tc, kept_and_own_reverse);
    tcase_add_test(tc, rows_left_alone);
    tcase_add_test(tc, quantizer_shortlist);
    tcase_add_test(tc, quantizer_query);
    suite_add_tcase(s, tc);
    return s;
}
