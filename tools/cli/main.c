/* main.c — the amscr command-line tool (docs/method.md §6): dispatch through the command table.
 * Uses the public API only (STYLE.md rule 25): no src/ internals.
 *
 *   amscr contour IMG [-o FILE]
 *   amscr register SRC TGT [--json] [--overlay FILE] [--plot FILE] [shape options]
 *   amscr search QUERY COLLECTION [--top K] [--json]
 *   amscr matrix COLLECTION -o FILE.tsv|FILE.npy
 *   amscr eval COLLECTION [--protocol all|bullseye|topk|nn] [--ranks K] [--json]
 *
 * Layout: cli.h (options.c: the options; commands.c: the command table and help; cmd_*.c: one
 * handler per command), cmd_params.c (library params from the options), shape_db.c and load_db.c
 * (collection steps of search/matrix/eval), index_open.c and index_add.c (index files), names.c
 * (name/value tables), json.c, matrix_file.c, and the image, collection, drawing and utility
 * modules.
 *
 * Exit codes: 0 success, 1 bad input or failure (one line on stderr naming the file),
 * 2 usage error. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"

/* `code` once standard output is flushed and closed: output lost to a write error (a full disk,
 * a closed stdout, a pipe whose reader left while SIGPIPE is ignored) is a failure with its line,
 * never exit 0. A closed stdout that was never written to is not an error. */
static int finish(int code)
{
    int bad = fflush(stdout) != 0 || ferror(stdout);
    int e = errno;
    if (fclose(stdout) != 0 && !bad && errno != EBADF) {
        bad = 1;
        e = errno;
    }
    if (!bad)
        return code;
    tool_error("<stdout>", "write error: %s", strerror(e));
    return code == TOOL_EXIT_OK ? TOOL_EXIT_FAIL : code;
}

static int is_any(const char *s, const char *a, const char *b, const char *c)
{
    return strcmp(s, a) == 0 || strcmp(s, b) == 0 || strcmp(s, c) == 0;
}

/* The command's exit code, before standard output is closed. */
static int run(int argc, char **argv)
{
    char list[128];
    if (argc < 2)
        return usage_error(NULL, "missing command: %s (see 'amscr --help')", command_list(list, sizeof list));
    const char *name = argv[1];
    if (is_any(name, "--help", "-h", "help")) {
        if (strcmp(name, "help") == 0 && argc > 2) {
            const tool_command *c = command_find(argv[2]);
            if (c == NULL)
                return usage_error(NULL, "unknown command '%s' (see 'amscr --help')", argv[2]);
            return print_command_help(c);
        }
        print_main_help();
        return TOOL_EXIT_OK;
    }
    if (is_any(name, "--version", "-V", "version")) {
        printf("%s\n", amscr_version_string());
        return TOOL_EXIT_OK;
    }
    const tool_command *c = command_find(name);
    if (c == NULL)
        return usage_error(NULL, "unknown command '%s' (see 'amscr --help')", name);
    opts o;
    opts_init(&o, c);
    int r = parse_args(&o, c, argc, argv);
    if (r < 0)
        return print_command_help(c);
    if (r != 0)
        return r;
    return c->run(&o);
}

int main(int argc, char **argv)
{
#ifdef SIGXFSZ
    /* a file over the file-size limit (ulimit -f) is a write error with its line (EFBIG), as a
     * full disk is, rather than a death by signal with no message */
    signal(SIGXFSZ, SIG_IGN);
#endif
    return finish(run(argc, argv));
}
