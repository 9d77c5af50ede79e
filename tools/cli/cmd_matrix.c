/* cmd_matrix.c — `amscr matrix COLLECTION -o FILE`: the all-pairs distance matrix. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amscr.h"
#include "cli.h"
#include "collection.h"
#include "matrix_file.h"
#include "cmd_params.h"
#include "index_tool.h"
#include "shape_db.h"

/* 1 when the outputs a and b ("-": standard output) are one file that is not a character device
 * (-o - --names /dev/stdout into a file or a pipe): written through two descriptors, the second
 * would overwrite or interleave with the first. */
static int same_output(const char *a, const char *b)
{
    struct stat sa, sb;
    if (strcmp(a, b) == 0)
        return 1;
    int ra = strcmp(a, "-") == 0 ? fstat(STDOUT_FILENO, &sa) : stat(a, &sa);
    int rb = strcmp(b, "-") == 0 ? fstat(STDOUT_FILENO, &sb) : stat(b, &sb);
    return ra == 0 && rb == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino && !S_ISCHR(sa.st_mode);
}

/* -o and --names: neither a file the command reads (the collection, its shapes) nor one file. */
static int outputs_checked(const opts *o, const collection *c)
{
    const char *in = o->pos[0];
    const collection *shapes = index_file_is(in) ? NULL : c;
    if (collection_out_not_input("-o", o->out, shapes, &in, 1) != 0 ||
        collection_out_not_input("--names", o->names, shapes, &in, 1) != 0)
        return TOOL_EXIT_FAIL;
    if (o->names && same_output(o->names, o->out)) {
        tool_error(o->names, "-o and --names name the same file");
        return TOOL_EXIT_FAIL;
    }
    if ((strcmp(o->out, "-") != 0 && tool_out_probe(o->out) != 0) || (o->names && tool_out_probe(o->names) != 0))
        return TOOL_EXIT_FAIL; /* before any shape is prepared */
    for (size_t i = 0; o->names && i < c->n; i++) /* a names file is TSV: one line a shape */
        if (strpbrk(c->items[i].name, "\t\n\r") || strpbrk(c->classes[c->items[i].label], "\t\n\r")) {
            tool_error(o->names, "shape %zu's file or class name holds a tab or a line break, which a TSV names "
                                 "file cannot: rename it", i + 1);
            return TOOL_EXIT_FAIL;
        }
    return 0;
}

int cmd_matrix(opts *o)
{
    const char *cpath = o->pos[0];
    if (o->out == NULL)
        return usage_error("matrix", "missing -o FILE (.tsv, .npy, or - for stdout)");
    char ext[16];
    path_ext(o->out, ext);
    int npy = strcmp(ext, ".npy") == 0, device = strncmp(o->out, "/dev/", 5) == 0; /* /dev/stdout: TSV */
    if (!npy && !device && strcmp(ext, ".tsv") != 0 && strcmp(ext, ".txt") != 0 && strcmp(o->out, "-") != 0)
        return usage_error("-o", "'%s': the matrix file must end in .tsv, .txt or .npy (or be - or a device "
                                 "such as /dev/stdout)", o->out);
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    retrieval_tracing();
    double *d = NULL;
    int ret = TOOL_EXIT_FAIL;
    memset(&c, 0, sizeof c);
    int r = open_collection_db(o, cpath, outputs_checked, &p, &c, &db);
    if (r != 0) {
        ret = r;
        goto done;
    }
    if (compute_matrix(db, cpath, &d) != 0)
        goto done;
    size_t n = c.n;
    tool_out out;
    tool_out_hold(); /* the matrix and --names named together, or neither */
    if (tool_out_open(&out, o->out) != 0)
        goto done;
    if ((npy ? write_npy(out.fp, d, n) : write_tsv(out.fp, d, n, &c)) != 0) {
        tool_error(o->out, "write error: %s", strerror(errno));
        tool_out_abort(&out);
        goto done;
    }
    if (o->names) {
        tool_out nf;
        if (tool_out_open(&nf, o->names) != 0) {
            tool_out_abort(&out);
            goto done;
        }
        fputs("file\tclass\n", nf.fp);
        for (size_t i = 0; i < n; i++)
            fprintf(nf.fp, "%s\t%s\n", c.items[i].name, c.classes[c.items[i].label]);
        if (tool_out_commit(&nf) != 0) {
            tool_out_abort(&out);
            goto done;
        }
    }
    if (tool_out_commit(&out) != 0 || tool_out_release(1) != 0)
        goto done;
    if (isatty(2) && strcmp(o->out, "-") != 0)
        fprintf(stderr, "amscr: wrote %s (%zu x %zu)\n", o->out, n, n);
    ret = TOOL_EXIT_OK;
done:
    tool_out_release(0); /* after a failure: nothing named */
    free(d);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}

