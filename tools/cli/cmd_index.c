/* cmd_index.c — `amscr index COLLECTION -o FILE [--add]`: the library's retrieval index of a
 * collection (amscr_index_build / amscr_index_add) with the files' names, classes and groups,
 * written in the library's index file format. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amscr.h"
#include "cli.h"
#include "cmd_params.h"
#include "collection.h"
#include "index_tool.h"
#include "shape_db.h"

/* A new index of collection c: every pair, or each shape's --candidates M (default: the library's
 * for the collection's size). */
static int build(const opts *o, const collection *c, amscr_index **x)
{
    amscr_params *p = NULL;
    amscr_db *db = NULL;
    int r = make_params(o, 0, &p);
    if (r != 0)
        return r;
    r = TOOL_EXIT_FAIL;
    if (load_db(p, c, o->threshold, &db) == 0) {
        tool_progress pr;
        progress_init(&pr, "matching");
        size_t m = o->candidates_set ? o->candidates : amscr_index_default_candidates(amscr_db_size(db));
        amscr_status st = amscr_index_build(db, m, progress_cb, &pr, x);
        progress_end(&pr);
        if (st != AMSCR_OK)
            tool_lib_error(o->pos[0], st);
        else
            r = 0;
    }
    for (size_t l = 0; r == 0 && l < c->nclasses; l++)
        if (amscr_index_set_class_name(*x, (int32_t)l, c->classes[l]) != AMSCR_OK) {
            tool_lib_error(NULL, AMSCR_E_NOMEM);
            r = TOOL_EXIT_FAIL;
        }
    if (r == 0 && index_store_names(*x, c, 0) != 0)
        r = TOOL_EXIT_FAIL;
    amscr_db_free(db);
    amscr_params_free(p);
    return r;
}

/* 1 when path is the file standard output writes to (-o /dev/stdout, /proc/self/fd/1): the
 * summary line then goes to stderr, never into the index it describes. */
static int is_stdout(const char *path)
{
    struct stat a, b;
    return stat(path, &a) == 0 && fstat(STDOUT_FILENO, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino;
}

int cmd_index(opts *o)
{
    if (o->out == NULL || strcmp(o->out, "-") == 0)
        return usage_error("index", "missing -o FILE (the index file)");
    amscr_index *x = NULL;
    collection c;
    memset(&c, 0, sizeof c);
    retrieval_tracing();
    int r = TOOL_EXIT_FAIL;
    if (o->add && index_open(o->out, 0, &x) != 0)
        return TOOL_EXIT_FAIL;
    if (collection_open(o->pos[0], &c) == 0 && collection_out_not_input("-o", o->out, &c, o->pos, 1) == 0 &&
        tool_out_probe(o->out) == 0) /* a file that cannot be written fails before the work */
        r = o->add ? index_add(o, x, &c) : build(o, &c, &x);
    if (r == 0) {
        amscr_status st = amscr_index_save(x, o->out);
        if (st != AMSCR_OK) {
            tool_lib_error(o->out, st);
            r = TOOL_EXIT_FAIL;
        }
    }
    if (r == 0) {
        FILE *fp = is_stdout(o->out) ? stderr : stdout;
        size_t nclasses = index_num_classes(x);
        const amscr_params *ip = amscr_db_params(amscr_index_db(x));
        double share = amscr_params_get_rerank_inner_share(ip), closing = amscr_params_get_inner_closing(ip);
        size_t n = amscr_index_size(x), k = amscr_index_neighbours(x);
        fprintf(fp, "index %s: %zu shape%s, %zu class%s, %zu neighbour%s per shape", o->out, n, n == 1 ? "" : "s",
                nclasses, nclasses == 1 ? "" : "es", k, k == 1 ? "" : "s");
        if (amscr_index_neighbours(x) > 0 && share > 0.0)
            fprintf(fp, " (re-ranking on two graphs, the inner distance's at share %g, closing %g)\n", share, closing);
        else
            fprintf(fp, amscr_index_neighbours(x) > 0 ? " (re-ranking on one graph)\n" : "\n");
    }
    collection_free(&c);
    amscr_index_free(x);
    return r;
}
