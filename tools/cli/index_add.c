/* index_add.c — `amscr index COLLECTION -o FILE --add`: the new files' names, classes and
 * groups merged into the index's, their shapes prepared with the index's params and added by
 * the library (amscr_index_add: the old shapes are not prepared again; an index of fewer shapes
 * than twice its re-ranking K is built again on the old and new shapes, names kept). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "index_tool.h"
#include "shape_db.h"

/* The index's label of class `name` (a new one, named, when absent); -1 on error. A label the
 * index does not name is named by its number, as the index's classes are shown
 * (index_collection). */
static int32_t class_label(amscr_index *x, const char *name, int32_t *nlabels)
{
    for (int32_t l = 0; l < *nlabels; l++) {
        char num[24];
        const char *s = amscr_index_class_name(x, l);
        snprintf(num, sizeof num, "%d", (int)l);
        if (strcmp(s != NULL ? s : num, name) == 0)
            return l;
    }
    if (amscr_index_set_class_name(x, *nlabels, name) != AMSCR_OK) {
        tool_lib_error(NULL, AMSCR_E_NOMEM);
        return -1;
    }
    return (*nlabels)++;
}

/* Checks the new collection's names and group column against the index and maps its labels
 * to the index's. */
static int merge_names(const char *ipath, amscr_index *x, collection *c)
{
    size_t n = amscr_index_size(x);
    int groups = 0;
    int32_t nlabels = 0;
    for (size_t j = 0; j < n; j++) {
        groups |= amscr_index_group(x, j) != NULL;
        nlabels = amscr_index_label(x, j) + 1 > nlabels ? amscr_index_label(x, j) + 1 : nlabels;
    }
    if (n > 0 && groups != (c->ngroups > 0)) {
        tool_error(ipath, groups ? "the index has groups and the new shapes' manifest has no group column"
                                 : "the index has no groups and the new shapes' manifest has a group column");
        return TOOL_EXIT_FAIL;
    }
    for (size_t i = 0; i < c->n; i++)
        for (size_t j = 0; j < n; j++)
            if (amscr_index_name(x, j) != NULL && strcmp(c->items[i].name, amscr_index_name(x, j)) == 0) {
                tool_error(ipath, "'%s' is already in the index", c->items[i].name);
                return TOOL_EXIT_FAIL;
            }
    for (size_t i = 0; i < c->n; i++) {
        int32_t l = class_label(x, c->classes[c->items[i].label], &nlabels);
        if (l < 0)
            return TOOL_EXIT_FAIL;
        c->items[i].label = l; /* the new shapes are prepared with the index's labels */
    }
    return 0;
}

/* The error of amscr_index_add: a state error as the library's detail alone (it says what to
 * do), without the status's name. */
static void add_error(const char *ipath, amscr_status st)
{
    const char *d = lib_detail();
    if (st == AMSCR_E_STATE && d[0] != '\0')
        tool_error(ipath, "%s", d);
    else
        tool_lib_error(ipath, st);
}

int index_add(const opts *o, amscr_index *x, collection *c)
{
    const amscr_params *built = amscr_db_params(amscr_index_db(x));
    if (o->rerank_set && ((size_t)amscr_params_get_rerank_k(built) != o->rerank_k ||
                          (o->rerank_k > 0 && amscr_params_get_rerank_iterations(built) != o->rerank_iters)))
        return usage_error("--rerank", "the index '%s' was built with --rerank %u,%u; rebuild it (amscr index) to "
                           "change it, or drop --rerank", o->out, amscr_params_get_rerank_k(built),
                           amscr_params_get_rerank_iterations(built));
    amscr_params *p = NULL;
    int r = index_params(o, o->out, built, &p);
    if (r != 0)
        return r;
    size_t nold = amscr_index_size(x);
    amscr_db *dnew = NULL;
    r = merge_names(o->out, x, c);
    if (r == 0 && load_db(p, c, o->threshold, &dnew) != 0)
        r = TOOL_EXIT_FAIL;
    if (r == 0) {
        tool_progress pr;
        progress_init(&pr, "matching new shapes");
        amscr_status st = amscr_index_add(x, dnew, progress_cb, &pr);
        progress_end(&pr);
        if (st != AMSCR_OK) {
            add_error(o->out, st);
            r = TOOL_EXIT_FAIL;
        }
    }
    if (r == 0 && index_store_names(x, c, nold) != 0)
        r = TOOL_EXIT_FAIL;
    amscr_db_free(dnew);
    amscr_params_free(p);
    return r;
}
