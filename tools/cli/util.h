/* util.h — small helpers of the amscr command-line tool: one-line error reporting,
 * atomic output files, growable strings, progress lines (JSON printing: json.h).
 * Tool-internal: uses the public amscr.h only. */
#ifndef AMSCR_TOOL_UTIL_H
#define AMSCR_TOOL_UTIL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include "amscr.h"

#if defined(__GNUC__)
#define TOOL_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define TOOL_PRINTF(a, b)
#endif

/* Exit codes (docs/method.md §6). */
enum { TOOL_EXIT_OK = 0, TOOL_EXIT_FAIL = 1, TOOL_EXIT_USAGE = 2 };

/* Prints "amscr: WHAT: message" on stderr, once per process run: the first error wins,
 * later ones are dropped, so the user always sees exactly one line. `what` is a file
 * name, a subcommand or an option (may be NULL: "amscr: message"). */
void tool_error(const char *what, const char *fmt, ...) TOOL_PRINTF(2, 3);
/* tool_error, then returns TOOL_EXIT_USAGE (a wrong command line). */
int usage_error(const char *what, const char *fmt, ...) TOOL_PRINTF(2, 3);
/* tool_error for a failed library call: "amscr: WHAT: <detail or strerror>". When the
 * library detail already starts with "WHAT:" it is printed as is after "amscr: ". */
void tool_lib_error(const char *what, amscr_status st);
/* amscr_last_error_detail() without a leading "amscr_function: " prefix. */
const char *lib_detail(void);
/* Non-zero once an error has been printed. */
int tool_error_printed(void);
/* While muted (on != 0) errors are not printed, and do not count as printed: work on several
 * threads is muted and the main thread prints the first failure again after it. Set only while
 * no other thread of the tool runs. */
void tool_errors_mute(int on);
/* Whether errors (and the warnings that go with them) are muted now. */
int tool_errors_muted(void);

/* Overflow-checked allocation; prints "amscr: out of memory" and returns NULL on failure. */
void *xmalloc_array(size_t n, size_t size);
void *xcalloc_array(size_t n, size_t size);
char *xstrdup(const char *s);

/* ----------------------------------------------------------- output files */
/* An output written to an unnamed file in the destination's folder (O_TMPFILE), named on
 * commit — where the system has none, to a temporary file renamed over the destination — so a
 * failure never leaves a partial file, and a kill mid-write none at all. A replaced file keeps
 * its mode; a symbolic link is followed (its target is replaced). Path "-" means stdout (no
 * temporary); so does an existing device, FIFO or /dev/stdout, written through in place. */
typedef struct tool_out {
    FILE *fp;
    char *tmp;      /* temporary path (or room for one), NULL for stdout */
    size_t tmp_cap; /* its size */
    char *path;     /* final path, NULL for stdout */
    char *dir;      /* its folder */
    int unnamed;    /* fp is an unnamed file */
    int stream;     /* fp writes through path (a device, a FIFO, /dev/stdout: out_path.h) */
} tool_out;

/* Opens; on failure prints the error (naming `path`) and returns -1. */
int tool_out_open(tool_out *o, const char *path);
/* Flushes, closes and renames; on failure prints the error, removes the temporary, -1. */
int tool_out_commit(tool_out *o);
/* Closes and removes the temporary (no-op when not open). */
void tool_out_abort(tool_out *o);
/* Outputs committed from now on are written whole and flushed but named only by
 * tool_out_release: all of them when `keep` (0, or -1 after the error line of the first that
 * cannot be named), else none (their files removed) — a command's outputs, all or nothing. */
void tool_out_hold(void);
int tool_out_release(int keep);
/* 0 when an output file can be made at `path` (opened, then abandoned: nothing is left); else
 * -1 after the error line. Checks every output of a command before the first is written. */
int tool_out_probe(const char *path);
/* -1 after an error line when the output `path`, given with option `opt`, is the same file as
 * one of the n inputs (device and inode); else 0. */
int tool_out_not_input(const char *opt, const char *path, const char *const *inputs, size_t n);

/* ------------------------------------------------------------ strings */
typedef struct sbuf {
    char *s;
    size_t len, cap;
    int oom;
} sbuf;
void sb_init(sbuf *b);
void sb_free(sbuf *b);
void sb_printf(sbuf *b, const char *fmt, ...) TOOL_PRINTF(2, 3);
void sb_puts(sbuf *b, const char *s);
/* Prints b on stdout and flushes: 0, or -1 after printing "out of memory" (b ran out) or
 * "<stdout>: write error: ..." (a command's whole output is built first, then written once). */
int sb_write_stdout(const sbuf *b);

/* Formats a number compactly for humans ("%.6g"). */
const char *fmt_num(char buf[32], double v);

/* ------------------------------------------------------------ misc */
/* Lower-case extension of a path including the dot (".png"), or "" when none. */
void path_ext(const char *path, char out[16]);
/* Base name (pointer into path). */
const char *path_base(const char *path);
/* Folder part of path ("." when none); malloc'ed. */
char *path_dir(const char *path);
/* Joins a folder and a relative path (absolute `rel` is returned as is); malloc'ed. */
char *path_join(const char *dir, const char *rel);

/* Seconds from a monotonic clock. */
double now_seconds(void);

/* Progress line on stderr when it is a terminal (isatty(2)), quiet otherwise: a bar, the
 * count, the rate (items per second since progress_init) and the time left at that rate. */
typedef struct tool_progress {
    int enabled;
    const char *label;
    double start, last;
    int shown;
} tool_progress;
void progress_init(tool_progress *p, const char *label);
void progress_update(tool_progress *p, size_t done, size_t total);
void progress_end(tool_progress *p);
/* A step without a count ("re-ranking ..."), shown until the next update or progress_end. */
void progress_note(tool_progress *p, const char *label);
/* amscr_progress_fn adaptor: user = tool_progress*. Never cancels. */
int progress_cb(void *user, size_t done, size_t total);

#endif
