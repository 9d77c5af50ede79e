/* cmd_search.c — `amscr search QUERY COLLECTION`: the closest shapes of a collection. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "amscr.h"
#include "cli.h"
#include "components.h"
#include "collection.h"
#include "image.h"
#include "index_build.h"
#include "index_query.h"
#include "json.h"
#include "cmd_params.h"
#include "shape_db.h"
#include "sheet.h"

/* The channel distances from dq to every shape of db (n of them) into dist: the retrieval
 * matrix's entries when the channel is used alone without re-ranking. */
static int channel_distances(const amscr_db *db, const amscr_descriptor *dq, const char *qpath, double *dist)
{
    size_t n = amscr_db_size(db);
    tool_progress pr;
    progress_init(&pr, "matching");
    for (size_t j = 0; j < n; j++) {
        amscr_status st = amscr_channel_distance(NULL, amscr_db_descriptor(db, j), dq, &dist[j]);
        if (st != AMSCR_OK) {
            progress_end(&pr);
            tool_lib_error(qpath, st);
            return -1;
        }
        progress_update(&pr, j + 1, n);
    }
    progress_end(&pr);
    return 0;
}

/* The index of the collection's item that is the query's file (same device and inode), or
 * SIZE_MAX: a member query is ranked by its own row, so its score against itself is 0. */
static size_t member_index(const collection *c, const char *qpath)
{
    struct stat q, m;
    if (stat(qpath, &q) != 0)
        return SIZE_MAX;
    for (size_t i = 0; i < c->n; i++)
        if (stat(c->items[i].path, &m) == 0 && m.st_dev == q.st_dev && m.st_ino == q.st_ino)
            return i;
    return SIZE_MAX;
}

/* The distances from the query dq to every shape of db (n of them) into dist: the plain AMSCR
 * distance (query -> shape), the channel alone, or read from the retrieval matrix (fusion and
 * re-ranking need the whole matrix): row `member` of the collection's when the query is one of
 * its shapes, else the last row of the collection's plus the query (dq is added to db). */
static int query_distances(amscr_db *db, const amscr_descriptor *dq, size_t member, const char *qpath,
                           const char *cpath, double *dist)
{
    size_t n = amscr_db_size(db);
    const amscr_params *p = amscr_db_params(db);
    if (retrieval_is_plain(p)) {
        tool_progress pr;
        progress_init(&pr, "matching");
        amscr_status st = amscr_db_query(db, dq, progress_cb, &pr, dist);
        progress_end(&pr);
        if (st != AMSCR_OK) {
            tool_lib_error(qpath, st);
            return -1;
        }
        return 0;
    }
    if (amscr_params_get_channel_weight(p) >= 1.0 && amscr_params_get_rerank_k(p) == 0)
        return channel_distances(db, dq, qpath, dist);
    double *full = NULL;
    if (member == SIZE_MAX && amscr_db_add_descriptor(db, dq, -1, NULL) != AMSCR_OK) {
        tool_lib_error(qpath, AMSCR_E_NOMEM);
        return -1;
    }
    if (compute_matrix(db, cpath, &full) != 0)
        return -1;
    size_t cols = amscr_db_size(db), row = member == SIZE_MAX ? n : member;
    for (size_t j = 0; j < n; j++)
        dist[j] = full[row * cols + j]; /* collection columns */
    free(full);
    return 0;
}

/* The k results idx[] of n (distances dist) as text or JSON. */
static void format_results(sbuf *b, const opts *o, const collection *c, const double *dist, const size_t *idx,
                           size_t k, size_t n, double secs)
{
    const char *qpath = o->pos[0], *cpath = o->pos[1];
    if (o->json) {
        sb_puts(b, "{\"query\": ");
        sb_json_str(b, qpath);
        sb_puts(b, ", \"collection\": ");
        sb_json_str(b, cpath);
        sb_printf(b, ", \"n\": %zu, \"results\": [", n);
        for (size_t i = 0; i < k; i++) {
            const coll_item *it = &c->items[idx[i]];
            sb_printf(b, "%s{\"rank\": %zu, \"index\": %zu, \"file\": ", i ? ", " : "", i + 1, idx[i]);
            sb_json_str(b, it->name);
            sb_puts(b, ", \"class\": ");
            sb_json_str(b, c->classes[it->label]);
            sb_puts(b, ", \"distance\": ");
            sb_json_num(b, dist[idx[i]]);
            sb_puts(b, "}");
        }
        sb_puts(b, "], \"seconds\": ");
        sb_json_num(b, secs);
        sb_puts(b, "}\n");
        return;
    }
    sb_printf(b, "query %s against %s (%zu shapes, %.2f s)\n", qpath, cpath, n, secs);
    sb_printf(b, "%4s  %-12s  %-16s  %s\n", "rank", "distance", "class", "file");
    char d1[32];
    for (size_t i = 0; i < k; i++) {
        const coll_item *it = &c->items[idx[i]];
        sb_printf(b, "%4zu  %-12s  %-16s  %s\n", i + 1, fmt_num(d1, dist[idx[i]]), c->classes[it->label], it->name);
    }
}

/* One hit's tile: its sampled points registered onto the query (the retrieval params: the
 * registration that the distance measured). */
static int hit_tile(const amscr_db *db, const amscr_descriptor *dq, size_t j, double *after, sheet_tile *t)
{
    const amscr_descriptor *h = amscr_db_descriptor(db, j);
    size_t n = amscr_descriptor_num_samples(h);
    amscr_result *res = NULL;
    double m[6];
    amscr_status st = amscr_register(amscr_db_params(db), h, dq, NULL, &res);
    if (st == AMSCR_OK)
        st = amscr_result_affine(res, m);
    if (st == AMSCR_OK)
        st = amscr_affine_apply(m, amscr_descriptor_input_points(h), n, after);
    amscr_result_free(res);
    if (st != AMSCR_OK) {
        tool_lib_error("--sheet", st);
        return -1;
    }
    t->over = after;
    t->no = n;
    return 0;
}

/* --sheet: the query and its k hits (shape pos[i] of db is hit i). */
static int draw_search_sheet(const opts *o, const amscr_db *db, const size_t *pos, const amscr_contour *q,
                             const amscr_descriptor *dq, const collection *c, const double *dist, const size_t *idx,
                             size_t k)
{
    size_t ns = amscr_descriptor_num_samples(dq);
    sheet_tile *t = xcalloc_array(k + 1, sizeof *t);
    double *pts = xmalloc_array(k ? k : 1, 2 * ns * sizeof(double));
    int ret = -1;
    if (t == NULL || pts == NULL)
        goto done;
    for (size_t i = 0; i <= k; i++) {
        t[i].base = amscr_contour_xy(q);
        t[i].nb = amscr_contour_size(q);
    }
    snprintf(t[0].title, sizeof t[0].title, "query");
    snprintf(t[0].name, sizeof t[0].name, "%s", path_base(o->pos[0]));
    for (size_t i = 0; i < k; i++) {
        const coll_item *it = &c->items[idx[i]];
        if (hit_tile(db, dq, pos[i], pts + i * 2 * ns, &t[i + 1]) != 0)
            goto done;
        snprintf(t[i + 1].title, sizeof t[i + 1].title, "%zu %.9s %.3g", i + 1, c->classes[it->label],
                 dist[idx[i]]);
        snprintf(t[i + 1].name, sizeof t[i + 1].name, "%s", path_base(it->name));
    }
    ret = draw_sheet(o->sheet, t, k + 1, amscr_params_get_closed(amscr_db_params(db)));
done:
    free(t);
    free(pts);
    return ret;
}

/* --sheet: the hits from the folder's db, or read from the index (x non-NULL). */
static int sheet_of(const opts *o, const tool_index *x, const amscr_db *db, const amscr_contour *q,
                    const amscr_descriptor *dq, const collection *c, const double *dist, const size_t *idx, size_t k)
{
    size_t *pos = xmalloc_array(k ? k : 1, sizeof(size_t));
    amscr_db *hits = NULL;
    int r = -1;
    if (pos == NULL || (x && index_fetch(x, NULL, idx, k, &hits) != 0)) {
        free(pos);
        return -1;
    }
    for (size_t i = 0; i < k; i++)
        pos[i] = x ? i : idx[i];
    r = draw_search_sheet(o, x ? hits : db, pos, q, dq, c, dist, idx, k);
    amscr_db_free(hits);
    free(pos);
    return r;
}

/* The collection to search: an index (x, is_index set; c and db point into it) or a folder /
 * manifest prepared now (c and db owned by the caller). Returns 0 or an exit code. */
static int open_target(const opts *o, tool_index *x, int *is_index, amscr_params **p, collection **c,
                       amscr_db **db, collection *own)
{
    const char *cpath = o->pos[1];
    int r = 0;
    *is_index = index_file_is(cpath);
    if (*is_index && index_open_lazy(cpath, x) != 0)
        return TOOL_EXIT_FAIL;
    if (!*is_index) {
        *c = own;
        if ((r = make_params(o, 0, p)) != 0)
            return r;
        return collection_open(cpath, own) == 0 && load_db(*p, own, o->threshold, db) == 0 ? 0 : TOOL_EXIT_FAIL;
    }
    *c = &x->coll;
    *db = x->db;
    if ((r = index_params(o, cpath, x, p)) != 0)
        return r;
    size_t n = x->coll.n, want = amscr_params_get_rerank_k(*p), need = want < n ? want : n;
    if (x->k < need)
        return usage_error("--rerank", "the index '%s' holds %zu neighbours a shape (built with %s); use --rerank K "
                           "with K <= %zu, --no-rerank, or rebuild the index with --rerank %zu", cpath, x->k,
                           x->k ? "a smaller --rerank" : "--no-rerank", x->k, want);
    return 0;
}

int cmd_search(opts *o)
{
    const char *qpath = o->pos[0], *cpath = o->pos[1];
    amscr_params *p = NULL;
    collection own, *c = &own;
    tool_index x;
    int is_index = 0;
    amscr_db *db = NULL;
    amscr_contour *q = NULL;
    amscr_descriptor *dq = NULL;
    double *dist = NULL;
    size_t *idx = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&own, 0, sizeof own);
    memset(&x, 0, sizeof x);
    double t0 = now_seconds();

    int r = open_target(o, &x, &is_index, &p, &c, &db, &own);
    if (r != 0) {
        ret = r;
        goto done;
    }
    if (shape_load_opts(o, qpath, &q) != 0 || prepare(is_index ? p : amscr_db_params(db), qpath, q, &dq) != 0)
        goto done;
    size_t n = c->n;
    dist = xmalloc_array(n, sizeof(double));
    size_t k = o->top < n ? o->top : n;
    idx = xmalloc_array(k ? k : 1, sizeof(size_t));
    if (dist == NULL || idx == NULL)
        goto done;
    if (is_index ? index_search(&x, p, dq, o->candidates && o->candidates < k ? k : o->candidates, dist) != 0
                 : query_distances(db, dq, member_index(c, qpath), qpath, cpath, dist) != 0)
        goto done;
    amscr_status st = amscr_topk(dist, n, k, SIZE_MAX, idx);
    if (st != AMSCR_OK) {
        tool_lib_error(qpath, st);
        goto done;
    }
    if (o->sheet && sheet_of(o, is_index ? &x : NULL, db, q, dq, c, dist, idx, k) != 0)
        goto done;
    format_results(&b, o, c, dist, idx, k, n, now_seconds() - t0);
    if (sb_write_stdout(&b) == 0)
        ret = TOOL_EXIT_OK;
done:
    sb_free(&b);
    free(dist);
    free(idx);
    amscr_descriptor_free(dq);
    amscr_contour_free(q);
    if (!is_index)
        amscr_db_free(db);
    collection_free(&own);
    index_free(&x);
    amscr_params_free(p);
    return ret;
}
