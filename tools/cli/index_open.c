/* index_open.c — an index where a folder or manifest is accepted: the library's index file
 * opened, its names as a collection, the params it was built with against the options the
 * user set (index_tool.h, shape_db.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cmd_params.h"
#include "index_tool.h"
#include "names.h"
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
    /* the neighbour lists are of the base distance these two define (the retrieval matrix's base distance) */
    NUM(o->channel_weight_set, "--channel-weight", amscr_params_get_channel_weight(p), o->channel_weight)
    NUM(o->affine_share_set, "--affine-share", amscr_params_get_channel_affine_share(p), o->affine_share)
    NUM(o->affine_view_set, "--affine-view", amscr_params_get_channel_affine_view(p), o->affine_view)
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

int index_params(const opts *o, const char *path, const amscr_params *built, amscr_params **out)
{
    int r = check_options(o, path, built);
    if (r != 0)
        return r;
    amscr_status st = amscr_params_copy(built, out);
    if (st == AMSCR_OK && o->threads_set)
        st = amscr_params_set_num_threads(*out, o->threads);
    /* --rerank / --no-rerank: a query-time setting (cmd_search.c ranks by the collection's
     * matrix when it differs from the index's) */
    if (st == AMSCR_OK && o->rerank_set)
        st = amscr_params_set_rerank_k(*out, (unsigned)o->rerank_k);
    if (st == AMSCR_OK && o->rerank_set && o->rerank_k > 0)
        st = amscr_params_set_rerank_iterations(*out, o->rerank_iters);
    /* --inner-share, --inner-closing: the same (an index holds the graphs of its build's settings) */
    if (st == AMSCR_OK && o->inner_share_set)
        st = amscr_params_set_rerank_inner_share(*out, o->inner_share);
    if (st == AMSCR_OK && o->inner_closing_set)
        st = amscr_params_set_inner_closing(*out, o->inner_closing);
    if (st != AMSCR_OK) {
        amscr_params_free(*out);
        *out = NULL;
        tool_lib_error(o->threads_set ? "--threads" : path, st);
        return TOOL_EXIT_FAIL;
    }
    return 0;
}

int index_file_is(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return 0; /* a pipe's first bytes would be gone: collection_open refuses it */
    FILE *f = fopen(path, "rb");
    char m[8] = {0};
    if (f == NULL)
        return 0;
    size_t got = fread(m, 1, sizeof m, f);
    fclose(f);
    /* the magic AMSCRDB or AMSCRIDX, or its start (a file cut short: the loader names it) */
    return got >= 5 && memcmp(m, "AMSCR", 5) == 0;
}

int index_open(const char *path, int lazy, amscr_index **out)
{
    amscr_status st = amscr_index_load_with(path, lazy ? AMSCR_INDEX_LAZY : 0u, out);
    if (st != AMSCR_OK) {
        tool_lib_error(path, st);
        return -1;
    }
    return 0;
}

static int cmp_label(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* The index's distinct labels, ascending (malloc'ed, *k of them); NULL when out of memory
 * (printed). */
static int32_t *label_set(const amscr_index *x, size_t *k)
{
    size_t n = amscr_index_size(x), m = 0;
    int32_t *l = xmalloc_array(n ? n : 1, sizeof *l);
    if (l == NULL)
        return NULL;
    for (size_t i = 0; i < n; i++)
        l[i] = amscr_index_label(x, i);
    qsort(l, n, sizeof *l, cmp_label);
    for (size_t i = 0; i < n; i++)
        if (m == 0 || l[i] != l[m - 1])
            l[m++] = l[i];
    *k = m;
    return l;
}

size_t index_num_classes(const amscr_index *x)
{
    size_t k = 0;
    free(label_set(x, &k));
    return k;
}

/* The classes of the index: its distinct labels in ascending order, label L named by the index
 * or "L"; set[*k] are the labels (malloc'ed), class c of the collection is label set[c]. */
static int32_t *index_classes(const amscr_index *x, collection *c, size_t *k)
{
    int32_t *set = label_set(x, k);
    if (set == NULL)
        return NULL;
    if (*k > 0 && set[0] < 0) {
        tool_error(NULL, "a shape of the index has no class (label %d)", (int)set[0]);
        free(set);
        return NULL;
    }
    c->classes = xcalloc_array(*k ? *k : 1, sizeof *c->classes);
    for (size_t j = 0; c->classes != NULL && j < *k; j++) {
        char num[24];
        const char *name = amscr_index_class_name(x, set[j]);
        snprintf(num, sizeof num, "%d", (int)set[j]);
        if ((c->classes[j] = xstrdup(name ? name : num)) == NULL)
            break;
        c->nclasses = j + 1;
    }
    if (c->nclasses != *k) {
        free(set);
        return NULL;
    }
    return set;
}

/* The class of label l: its position in the ascending set of k labels. */
static int32_t dense_label(const int32_t *set, size_t k, int32_t l)
{
    const int32_t *p = bsearch(&l, set, k, sizeof *set, cmp_label);
    return p ? (int32_t)(p - set) : -1;
}

int index_collection(const amscr_index *x, collection *c)
{
    size_t n = amscr_index_size(x), gcap = 0, k = 0;
    memset(c, 0, sizeof *c);
    c->items = xcalloc_array(n ? n : 1, sizeof *c->items);
    int32_t *set = c->items != NULL ? index_classes(x, c, &k) : NULL;
    int ok = set != NULL, groups = 0;
    for (size_t i = 0; ok && i < n; i++)
        groups |= amscr_index_group(x, i) != NULL;
    for (size_t i = 0; ok && i < n; i++) {
        char num[32];
        const char *name = amscr_index_name(x, i), *g = amscr_index_group(x, i);
        snprintf(num, sizeof num, "#%zu", i); /* an unnamed shape: its index */
        coll_item *it = &c->items[i];
        it->name = xstrdup(name ? name : num);
        it->path = xstrdup(name ? name : num);
        it->label = dense_label(set, k, amscr_index_label(x, i)); /* eval's classes are 0..k-1 */
        it->group = groups ? coll_name_index(&c->groups, &c->ngroups, g ? g : "", &gcap) : -1;
        c->n = i + 1;
        ok = it->name && it->path && (!groups || it->group >= 0);
    }
    free(set);
    if (!ok) {
        collection_free(c);
        return -1;
    }
    return 0;
}

int index_store_names(amscr_index *x, const collection *c, size_t from)
{
    amscr_status st = AMSCR_OK;
    for (size_t i = 0; st == AMSCR_OK && i < c->n; i++) {
        const coll_item *it = &c->items[i];
        st = amscr_index_set_name(x, from + i, it->name);
        if (st == AMSCR_OK && it->group >= 0)
            st = amscr_index_set_group(x, from + i, c->groups[it->group]);
    }
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return -1;
    }
    return 0;
}

int index_db_with_params(const amscr_index *x, const amscr_params *p, const char *path, amscr_db **out)
{
    const amscr_db *src = amscr_index_db(x);
    amscr_status st = amscr_db_new(p, out);
    int lost = 0; /* a shape that does not decode (amscr_db_descriptor's NULL): its detail says why */
    for (size_t i = 0; st == AMSCR_OK && !lost && i < amscr_db_size(src); i++) {
        const amscr_descriptor *d = amscr_db_descriptor(src, i);
        if (d)
            st = amscr_db_add_descriptor(*out, d, amscr_db_label(src, i), NULL);
        else
            lost = 1;
    }
    if (st != AMSCR_OK || lost) {
        if (lost)
            tool_error(path, "%s", amscr_last_error_detail());
        else
            tool_lib_error(path, st);
        amscr_db_free(*out);
        *out = NULL;
        return -1;
    }
    return 0;
}

int open_collection_db(const opts *o, const char *path, int (*check)(const opts *, const collection *),
                       amscr_params **p, collection *c, amscr_db **db)
{
    int r;
    if (index_file_is(path)) {
        amscr_index *x = NULL;
        if (index_open(path, 1, &x) != 0)
            return TOOL_EXIT_FAIL;
        r = index_params(o, path, amscr_db_params(amscr_index_db(x)), p);
        if (r == 0 && index_collection(x, c) != 0)
            r = TOOL_EXIT_FAIL;
        if (r == 0 && check)
            r = check(o, c);
        if (r == 0 && index_db_with_params(x, *p, path, db) != 0)
            r = TOOL_EXIT_FAIL;
        amscr_index_free(x);
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
