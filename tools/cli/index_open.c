/* index_open.c — an index where a folder or manifest is accepted: the params it was built
 * with against the options the user set (index_build.h, shape_db.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "index_build.h"
#include "names.h"
#include "cmd_params.h"
#include "shape_db.h"

/* "--points: the index 'x' was built with 128; rebuild it to use 256, or drop --points". */
static int conflict(const char *opt, const char *path, const char *built, const char *asked)
{
    return usage_error(opt, "the index '%s' was built with %s; rebuild it (amscr index) to use %s, or drop %s", path,
                       built, asked, opt);
}

static int check_scales(const opts *o, const char *path, const amscr_params *p)
{
    size_t n = 0;
    double *s = params_scales(p, &n);
    int same = s != NULL && n == o->nscales;
    for (size_t i = 0; same && i < n; i++)
        same = s[i] == o->scales[i];
    free(s);
    return same ? 0 : conflict("--scales", path, "other scales", "these");
}

static int check_options(const opts *o, const char *path, const amscr_params *p)
{
    char b[64], a[64];
#define NUM(flag, opt, have, want)                                                                           \
    if ((flag) && (double)(have) != (double)(want)) {                                                        \
        snprintf(b, sizeof b, "%s %g", opt, (double)(have));                                                 \
        snprintf(a, sizeof a, "%s %g", opt, (double)(want));                                                 \
        return conflict(opt, path, b, a);                                                                    \
    }
#define NAME(flag, opt, table, have, want)                                                                   \
    if ((flag) && (int)(have) != (int)(want)) {                                                              \
        snprintf(b, sizeof b, "%s %s", opt, name_of(&table, (int)(have)));                                   \
        snprintf(a, sizeof a, "%s %s", opt, name_of(&table, (int)(want)));                                   \
        return conflict(opt, path, b, a);                                                                    \
    }
    NUM(o->points_set, "--points", amscr_params_get_num_samples(p), o->points)
    NUM(o->refine_set, "--refine", amscr_params_get_refine(p), o->refine)
    NUM(o->kmax_set, "--kmax", amscr_params_get_kmax(p), o->kmax)
    NAME(o->method_set, "--method", METHOD_NAMES, amscr_params_get_method(p), o->method)
    NAME(o->param_set, "--parametrization", PARAM_NAMES, amscr_params_get_parametrization(p), o->param)
    NAME(o->inv_set, "--invariance", INVARIANCE_NAMES, amscr_params_get_invariance(p), o->inv)
    /* the neighbour lists are of the base distance these two define (index_dist.h) */
    NUM(o->channel_weight_set, "--channel-weight", amscr_params_get_channel_weight(p), o->channel_weight)
    NUM(o->affine_share_set, "--affine-share", amscr_params_get_channel_affine_share(p), o->affine_share)
#undef NUM
#undef NAME
    if (o->reflections >= 0 && o->reflections != amscr_params_get_reflections(p))
        return conflict(o->reflections ? "--reflections" : "--no-reflections", path,
                        amscr_params_get_reflections(p) ? "reflections" : "no reflections",
                        o->reflections ? "reflections" : "none");
    if (o->open && amscr_params_get_closed(p))
        return conflict("--open", path, "closed curves", "open ones");
    if (o->symmetric && !amscr_params_get_symmetric(p))
        return conflict("--symmetric", path, "one-way distances", "symmetric ones");
    if (o->scales_set)
        return check_scales(o, path, p);
    return 0;
}

int index_params(const opts *o, const char *path, const tool_index *x, amscr_params **out)
{
    const amscr_params *p = amscr_db_params(x->db);
    int r = check_options(o, path, p);
    if (r != 0)
        return r;
    amscr_status st = amscr_params_copy(p, out);
    if (st == AMSCR_OK && o->threads_set)
        st = amscr_params_set_num_threads(*out, o->threads);
    /* --rerank / --no-rerank: a query-time setting (search needs the index to hold K
     * neighbours a shape: cmd_search.c checks) */
    if (st == AMSCR_OK && o->rerank_set)
        st = amscr_params_set_rerank_k(*out, (unsigned)o->rerank_k);
    if (st == AMSCR_OK && o->rerank_set && o->rerank_k > 0)
        st = amscr_params_set_rerank_iterations(*out, o->rerank_iters);
    if (st != AMSCR_OK) {
        amscr_params_free(*out);
        *out = NULL;
        tool_lib_error(o->threads_set ? "--threads" : path, st);
        return TOOL_EXIT_FAIL;
    }
    return 0;
}

int open_shapes(const opts *o, const char *path, tool_index *x, int *is_index)
{
    memset(x, 0, sizeof *x);
    *is_index = index_file_is(path);
    if (!*is_index)
        return 0;
    return index_load(path, x) == 0 ? 0 : TOOL_EXIT_FAIL;
}

int open_collection_db(const opts *o, const char *path, int (*check)(const opts *, const collection *),
                       amscr_params **p, collection *c, amscr_db **db)
{
    tool_index x;
    int is_index, r = open_shapes(o, path, &x, &is_index);
    if (r != 0)
        return r;
    if (is_index) {
        r = index_params(o, path, &x, p);
        if (r == 0 && check)
            r = check(o, &x.coll);
        if (r == 0 && o->threads_set) { /* the db's copy of the params gets the threads */
            amscr_db *d2 = NULL;
            amscr_status st = amscr_db_new(*p, &d2);
            for (size_t i = 0; st == AMSCR_OK && i < amscr_db_size(x.db); i++)
                st = amscr_db_add_descriptor(d2, amscr_db_descriptor(x.db, i), amscr_db_label(x.db, i), NULL);
            if (st != AMSCR_OK) {
                amscr_db_free(d2);
                tool_lib_error(path, st);
                r = TOOL_EXIT_FAIL;
            } else {
                amscr_db_free(x.db);
                x.db = d2;
            }
        }
        if (r == 0) {
            *c = x.coll;
            *db = x.db;
            memset(&x.coll, 0, sizeof x.coll);
            x.db = NULL;
        }
        index_free(&x);
        return r;
    }
    if ((r = make_params(o, 0, p)) != 0)
        return r;
    if (collection_open(path, c) != 0)
        return TOOL_EXIT_FAIL;
    if (check && (r = check(o, c)) != 0)
        return r;
    return load_db(*p, c, o->threshold, db) == 0 ? 0 : TOOL_EXIT_FAIL;
}
