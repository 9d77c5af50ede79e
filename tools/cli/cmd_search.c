/* cmd_search.c — `amscr search QUERY COLLECTION`: the closest shapes of a collection (a folder,
 * a manifest or an index), ranked by the library's retrieval scores. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "components.h"
#include "collection.h"
#include "image.h"
#include "index_tool.h"
#include "json.h"
#include "cmd_params.h"
#include "shape_db.h"
#include "sheet.h"

/* The query's scores against every shape of db (n of them) into dist, as the db's params say:
 * the plain AMSCR distance (query -> shape), or its retrieval scores with the library's member
 * rule (amscr_db_search_retrieval: a member's copy gets the member's row of the collection's
 * retrieval matrix). */
static int query_distances(const amscr_db *db, const amscr_descriptor *dq, const char *qpath, double *dist)
{
    size_t n = amscr_db_size(db);
    const amscr_params *p = amscr_db_params(db);
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = retrieval_is_plain(p) ? amscr_db_query(db, dq, progress_cb, &pr, dist)
                                            : amscr_db_search_retrieval(db, dq, progress_cb, &pr, dist, n);
    progress_end(&pr);
    if (st != AMSCR_OK) {
        tool_lib_error(qpath, st);
        return -1;
    }
    return 0;
}

/* The query's scores against an index: its stored lists with the library's member rule
 * (amscr_index_search_scores) when the user's params are the index's; the collection's
 * scores (as a folder) when --rerank/--no-rerank/--inner-share/--inner-closing differs from the
 * build's (an index holds the build's graphs); the plain distance without the channel. */
static int index_distances(const amscr_index *x, const amscr_params *p, const amscr_descriptor *dq, size_t cand,
                           const char *qpath, const char *cpath, double *dist)
{
    const amscr_db *idb = amscr_index_db(x);
    const amscr_params *b = amscr_db_params(idb);
    size_t n = amscr_index_size(x);
    if (retrieval_is_plain(p))
        return query_distances(idb, dq, qpath, dist);
    double c = amscr_params_get_inner_closing(p), cb = amscr_params_get_inner_closing(b);
    if (c > 0.0 && c != cb && amscr_params_get_rerank_k(p) > 0 && amscr_params_get_rerank_inner_share(p) > 0.0) {
        /* the outlines come from the shapes' contours, which an index does not keep */
        tool_error(cpath, "built with --inner-closing %g; searching with --inner-closing %g needs its shapes' "
                          "outlines closed at %g: rebuild the index with it, or search the folder",
                   cb, c, c);
        return -1;
    }
    if (amscr_params_get_rerank_k(p) != amscr_params_get_rerank_k(b) ||
        amscr_params_get_rerank_iterations(p) != amscr_params_get_rerank_iterations(b) ||
        amscr_params_get_rerank_inner_share(p) != amscr_params_get_rerank_inner_share(b) ||
        amscr_params_get_inner_closing(p) != amscr_params_get_inner_closing(b)) {
        amscr_db *db = NULL;
        int r = index_db_with_params(x, p, cpath, &db) == 0 ? query_distances(db, dq, qpath, dist) : -1;
        amscr_db_free(db);
        return r;
    }
    amscr_status st = amscr_index_search_scores(x, dq, cand, dist, n);
    if (st != AMSCR_OK) {
        tool_lib_error(qpath, st);
        return -1;
    }
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
    t[0].name = path_base(o->pos[0]);
    for (size_t i = 0; i < k; i++) {
        const coll_item *it = &c->items[idx[i]];
        if (hit_tile(db, dq, pos[i], pts + i * 2 * ns, &t[i + 1]) != 0)
            goto done;
        const char *cls = c->classes[it->label];
        snprintf(t[i + 1].title, sizeof t[i + 1].title, "%zu %.*s %.3g", i + 1, (int)utf8_prefix(cls, 9), cls,
                 dist[idx[i]]);
        t[i + 1].name = path_base(it->name);
    }
    ret = draw_sheet(o->sheet, t, k + 1, amscr_params_get_closed(amscr_db_params(db)));
done:
    free(t);
    free(pts);
    return ret;
}

/* The collection to search: an index (*x) or a folder / manifest prepared now (*db). The
 * params: the index's with the user's query-time settings, or the options'. 0 or an exit code. */
static int open_target(const opts *o, amscr_index **x, amscr_params **p, collection *c, amscr_db **db)
{
    const char *cpath = o->pos[1];
    int r;
    if (!index_file_is(cpath)) {
        if ((r = make_params(o, 0, p)) != 0)
            return r;
        return collection_open(cpath, c) == 0 && collection_out_not_input("--sheet", o->sheet, c, o->pos, 2) == 0 &&
                       load_db(*p, c, o->threshold, db) == 0
                   ? 0
                   : TOOL_EXIT_FAIL;
    }
    if (collection_out_not_input("--sheet", o->sheet, NULL, o->pos, 2) != 0 || index_open(cpath, 1, x) != 0)
        return TOOL_EXIT_FAIL;
    if ((r = index_params(o, cpath, amscr_db_params(amscr_index_db(*x)), p)) != 0)
        return r;
    return index_collection(*x, c) == 0 ? 0 : TOOL_EXIT_FAIL;
}

int cmd_search(opts *o)
{
    const char *qpath = o->pos[0], *cpath = o->pos[1];
    amscr_params *p = NULL;
    collection c;
    amscr_index *x = NULL;
    amscr_db *db = NULL;
    amscr_contour *q = NULL;
    amscr_descriptor *dq = NULL;
    double *dist = NULL;
    size_t *idx = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&c, 0, sizeof c);
    double t0 = now_seconds();

    retrieval_tracing();
    int r = open_target(o, &x, &p, &c, &db);
    if (r != 0) {
        ret = r;
        goto done;
    }
    const amscr_db *sdb = x ? amscr_index_db(x) : db;
    if (shape_load_opts(o, qpath, &q) != 0 || prepare(x ? p : amscr_db_params(db), qpath, q, &dq) != 0)
        goto done;
    size_t n = c.n;
    dist = xmalloc_array(n, sizeof(double));
    size_t k = o->top < n ? o->top : n;
    idx = xmalloc_array(k ? k : 1, sizeof(size_t));
    if (dist == NULL || idx == NULL)
        goto done;
    size_t cand = o->candidates && o->candidates < k ? k : o->candidates;
    if (x ? index_distances(x, p, dq, cand, qpath, cpath, dist) != 0
          : query_distances(db, dq, qpath, dist) != 0)
        goto done;
    amscr_status st = amscr_topk(dist, n, k, SIZE_MAX, idx);
    if (st != AMSCR_OK) {
        tool_lib_error(qpath, st);
        goto done;
    }
    if (o->sheet && draw_search_sheet(o, sdb, idx, q, dq, &c, dist, idx, k) != 0)
        goto done;
    format_results(&b, o, &c, dist, idx, k, n, now_seconds() - t0);
    if (sb_write_stdout(&b) == 0)
        ret = TOOL_EXIT_OK;
done:
    sb_free(&b);
    free(dist);
    free(idx);
    amscr_descriptor_free(dq);
    amscr_contour_free(q);
    amscr_db_free(db);
    collection_free(&c);
    amscr_index_free(x);
    amscr_params_free(p);
    return ret;
}
