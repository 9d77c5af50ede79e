/* out_path.h — where a file written whole goes (out_path.c). Shared by the library (file_io.c)
 * and the tool (tools/cli/util.c); never installed. */
#ifndef AMSCR_OUT_PATH_H
#define AMSCR_OUT_PATH_H

/* Resolves `path` for an output written whole. *stream = 1 when path names an existing file that
 * is not a regular file (a device such as /dev/null, a FIFO, a terminal, a socket) or names a
 * file through /proc (/dev/stdout, /dev/fd/N): write through it in place, appending (open with
 * O_APPEND: a shell's `>>` keeps its text), never replace it. Else *stream = 0 and *target (malloc'd,
 * the caller frees it) is the file to create or replace whole: path with its symbolic links
 * followed, so a link keeps pointing to the file written. 0, or -1 with errno set: EISDIR (a
 * directory), ELOOP (too many links), ENOMEM. */
int amscr__out_path(const char *path, int *stream, char **target);

#endif
