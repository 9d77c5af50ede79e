/* out_path.c — where a file written whole goes: the file its path names once symbolic links are
 * followed (replacing it keeps the links), or, for an existing file that is not a regular file (a
 * device such as /dev/null, a FIFO, a terminal) or one reached through /proc (/dev/stdout,
 * /dev/fd/N), that file itself, written through: replacing /dev/null with a regular file (as
 * root) or a FIFO nobody then reads would be the wrong thing done quietly. */
#include "out_path.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Links followed before ELOOP, as the kernel's limit. */
#define OUT_PATH_HOPS 40

static int via_proc(const char *p) { return strncmp(p, "/proc/", 6) == 0 || strncmp(p, "/dev/fd/", 8) == 0; }

static char *copy(const char *s, size_t n)
{
    char *c = malloc(n + 1);
    if (c) {
        memcpy(c, s, n);
        c[n] = '\0';
    }
    return c;
}

/* The file the symbolic link p points to (link text `l`): l itself when absolute, else l in p's
 * folder. */
static char *link_target(const char *p, const char *l)
{
    const char *slash = strrchr(p, '/');
    if (l[0] == '/' || !slash)
        return copy(l, strlen(l));
    size_t d = (size_t)(slash - p) + 1, n = strlen(l);
    char *t = malloc(d + n + 1);
    if (t) {
        memcpy(t, p, d);
        memcpy(t + d, l, n + 1);
    }
    return t;
}

/* The text of the symbolic link p (size from lstat's st_size, or grown while it fills). */
static char *read_link(const char *p, size_t hint)
{
    for (size_t cap = hint + 2 > 256 ? hint + 2 : 256; cap <= (1u << 20); cap *= 2) {
        char *buf = malloc(cap);
        if (!buf)
            return NULL;
        ssize_t n = readlink(p, buf, cap);
        if (n >= 0 && (size_t)n < cap) {
            buf[n] = '\0';
            return buf;
        }
        free(buf);
        if (n < 0)
            return NULL;
    }
    errno = ENAMETOOLONG;
    return NULL;
}

int amscr__out_path(const char *path, int *stream, char **target)
{
    struct stat sb;
    *stream = 0;
    *target = NULL;
    int exists = stat(path, &sb) == 0;
    if (exists && S_ISDIR(sb.st_mode)) {
        errno = EISDIR;
        return -1;
    }
    if ((exists && !S_ISREG(sb.st_mode)) || via_proc(path)) {
        *stream = 1;
        return 0;
    }
    char *p = copy(path, strlen(path));
    for (int hops = 0; p; hops++) {
        struct stat lb;
        if (via_proc(p)) { /* /dev/stdout -> /proc/self/fd/1 */
            free(p);
            *stream = 1;
            return 0;
        }
        if (lstat(p, &lb) != 0 || !S_ISLNK(lb.st_mode)) {
            *target = p;
            return 0;
        }
        char *l = hops < OUT_PATH_HOPS ? read_link(p, (size_t)lb.st_size) : NULL;
        char *next = l ? link_target(p, l) : NULL;
        int e = hops < OUT_PATH_HOPS ? errno : ELOOP;
        free(l);
        free(p);
        p = next;
        if (!p) {
            errno = e == 0 ? ENOMEM : e;
            return -1;
        }
    }
    errno = ENOMEM;
    return -1;
}
