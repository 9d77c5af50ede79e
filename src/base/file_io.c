/* file_io.c — whole files: read into memory, mapped read-only (no copy, the page cache's
 * pages; read where a file cannot be mapped), and written atomically with the mode of
 * file_mode.c: into an unnamed file of the target's directory (O_TMPFILE, where the system has
 * it), named only once whole and on the disk, so a write cut off — the process killed, the disk
 * full — leaves nothing behind and never replaces the file; elsewhere through a temporary name
 * and a rename (a kill mid-write then leaves that temporary file). A path's symbolic links are
 * followed (the file they point to is replaced); a device, a FIFO or /dev/stdout is written
 * through (out_path.c). The collection, index and point-list files use them (db_io.c,
 * index_io.c, contour_text.c). */
#define _GNU_SOURCE /* O_TMPFILE, linkat; MAP_POPULATE, where the system has them */
#include "internal.h"
#include "out_path.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>

/* strerror_r in its GNU form (glibc under _GNU_SOURCE) or its XSI form. */
const char *amscr__errstr(int err, char *buf, size_t len)
{
#if defined(__GLIBC__)
    return strerror_r(err, buf, len);
#else
    if (strerror_r(err, buf, len) != 0)
        snprintf(buf, len, "error %d", err);
    return buf;
#endif
}

/* Writes all of buf to fd and flushes it to the disk; 0 with errno set when it cannot. */
static int write_all(int fd, const unsigned char *buf, size_t len)
{
    while (len > 0) {
        ssize_t w = write(fd, buf, len < ((size_t)1 << 30) ? len : ((size_t)1 << 30));
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return 0;
        buf += w;
        len -= (size_t)w;
    }
    return fsync(fd) == 0 || errno == EINVAL || errno == EROFS;
}

/* Gives the written unnamed file fd the name path: a link when path is new, else a link under a
 * fresh temporary name renamed over it (the name exists for the rename's instant). 1 on success;
 * 0 with errno set when it cannot link; -1 with errno set when the rename failed (a temporary
 * name would fail there too). */
static int name_unnamed(int fd, const char *path, char *tmp, size_t tmp_len)
{
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    if (linkat(AT_FDCWD, proc, AT_FDCWD, path, AT_SYMLINK_FOLLOW) == 0)
        return 1;
    if (errno != EEXIST)
        return 0;
    for (unsigned k = 0; k < 64; k++) { /* the pid and the descriptor make it unique; k skips strays */
        snprintf(tmp, tmp_len, "%s.tmp.%ld.%d.%u", path, (long)getpid(), fd, k);
        if (linkat(AT_FDCWD, proc, AT_FDCWD, tmp, AT_SYMLINK_FOLLOW) == 0) {
            if (rename(tmp, path) == 0)
                return 1;
            int e = errno;
            unlink(tmp);
            errno = e;
            return -1;
        }
        if (errno != EEXIST)
            return 0;
    }
    return 0;
}

/* The directory of path, into dir (size len): "." when path has none. */
static void dir_of(const char *path, char *dir, size_t len)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (slash == path ? 1 : (size_t)(slash - path)) : 0;
    snprintf(dir, len, "%.*s", n ? (int)n : 1, n ? path : ".");
}

/* The O_TMPFILE way: 1 when it wrote the file or failed where a temporary name would fail too
 * (*st says which), 0 when the system has no unnamed files here (nothing was written). */
static int write_unnamed(const char *path, const void *buf, size_t len, char *tmp, size_t tmp_len,
                         amscr_status *st)
{
#ifdef O_TMPFILE
    dir_of(path, tmp, tmp_len);
    mode_t mode = (mode_t)amscr__file_mode(path);
    int fd = open(tmp, O_TMPFILE | O_WRONLY | O_CLOEXEC, mode);
    if (fd < 0)
        return 0;
    (void)fchmod(fd, mode); /* the umask applied at open; a replaced file's mode is kept whole */
    char eb[128];
    if (!write_all(fd, buf, len)) {
        *st = amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, amscr__errstr(errno, eb, sizeof eb));
        close(fd);
        return 1;
    }
    int named = name_unnamed(fd, path, tmp, tmp_len), e = errno;
    close(fd);
    if (named == 0 && (e == ENOENT || e == EPERM || e == EOPNOTSUPP || e == EXDEV))
        return 0; /* no /proc, or no links here: the temporary name's way */
    *st = named == 1 ? AMSCR_OK
                     : amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, amscr__errstr(e, eb, sizeof eb));
    return 1;
#else
    (void)path, (void)buf, (void)len, (void)tmp, (void)tmp_len, (void)st;
    return 0;
#endif
}

/* The temporary name's way: path.tmp.XXXXXX written, then renamed over path. */
static amscr_status write_named(const char *path, const void *buf, size_t len, char *tmp, size_t tmp_len)
{
    char eb[128];
    snprintf(tmp, tmp_len, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0)
        return amscr__fail(AMSCR_E_IO, "%s: cannot create a temporary file: %s", path,
                           amscr__errstr(errno, eb, sizeof eb));
    (void)fchmod(fd, (mode_t)amscr__file_mode(path)); /* mkstemp made it 0600 (best effort) */
    int ok = write_all(fd, buf, len), e = errno;
    ok = close(fd) == 0 && ok;
    if (ok && rename(tmp, path) != 0)
        ok = 0, e = errno;
    if (ok)
        return AMSCR_OK;
    unlink(tmp);
    return amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, amscr__errstr(e, eb, sizeof eb));
}

/* A file that is not replaced (a device, a FIFO, /dev/stdout: out_path.h) written through. */
static amscr_status write_through(const char *path, const void *buf, size_t len)
{
    char eb[128];
    int fd = open(path, O_WRONLY | O_APPEND | O_NOCTTY | O_CLOEXEC);
    int ok = fd >= 0 && write_all(fd, buf, len), e = errno;
    if (fd >= 0 && close(fd) != 0 && ok)
        ok = 0, e = errno;
    return ok ? AMSCR_OK : amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, amscr__errstr(e, eb, sizeof eb));
}

amscr_status amscr__file_write_atomic(const char *path, const void *buf, size_t len)
{
    char eb[128], *target = NULL;
    int stream = 0;
    if (amscr__out_path(path, &stream, &target) != 0)
        return amscr__fail(errno == ENOMEM ? AMSCR_E_NOMEM : AMSCR_E_IO, "%s: cannot write: %s", path,
                           amscr__errstr(errno, eb, sizeof eb));
    if (stream)
        return write_through(path, buf, len);
    size_t tmp_len = strlen(target) + 64;
    char *tmp = malloc(tmp_len);
    amscr_status st = AMSCR_OK;
    if (!tmp)
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    else if (!write_unnamed(target, buf, len, tmp, tmp_len, &st))
        st = write_named(target, buf, len, tmp, tmp_len);
    free(tmp);
    free(target);
    return st;
}

/* The size of the open file f, or 0 when unknown (then read in growing chunks). */
static size_t file_size(FILE *f)
{
    struct stat sb;
    return fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0 && (uintmax_t)sb.st_size < SIZE_MAX / 2
               ? (size_t)sb.st_size
               : 0;
}

FILE *amscr__fopen_read(const char *path)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    FILE *f = fd >= 0 ? fdopen(fd, "rb") : NULL;
    if (fd >= 0 && !f) {
        int e = errno;
        close(fd);
        errno = e;
    }
    return f;
}

/* The largest buffer a read grows (by doubling, for a pipe) before a file is "too large": 1 TiB,
 * or half the address space where that is less (a 32-bit size_t: 1 << 40 did not fit, and every
 * pipe past 64 KiB was "too large"). */
static const uint64_t READ_MAX = SIZE_MAX / 2 < ((uint64_t)1 << 40) ? SIZE_MAX / 2 : ((uint64_t)1 << 40);

amscr_status amscr__file_read(const char *path, unsigned char **out, size_t *out_len)
{
    FILE *f = amscr__fopen_read(path);
    char eb[128];
    if (!f)
        return amscr__fail(AMSCR_E_IO, "%s: %s", path, amscr__errstr(errno, eb, sizeof eb));
    size_t cap = file_size(f), len = 0;
    cap = cap ? cap + 1 : (size_t)1 << 16; /* one more byte: the end is seen without a second buffer */
    unsigned char *buf = malloc(cap);
    amscr_status st = AMSCR_OK;
    int rerr = 0; /* errno of a failed read (EISDIR: a folder) */
    while (buf) {
        if (len == cap) {
            if ((uint64_t)cap > READ_MAX) {
                st = amscr__fail(AMSCR_E_LIMIT, "%s: file too large", path);
                break;
            }
            unsigned char *nb = realloc(buf, 2 * cap);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) {
            rerr = errno;
            break;
        }
    }
    int err = ferror(f);
    fclose(f);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    if (st == AMSCR_OK && err)
        st = amscr__fail(AMSCR_E_IO, "%s: read error: %s", path, amscr__errstr(rerr, eb, sizeof eb));
    if (st != AMSCR_OK) {
        free(buf);
        return st;
    }
    *out = buf;
    *out_len = len;
    return AMSCR_OK;
}

amscr_status amscr__file_map(const char *path, unsigned char **out, size_t *out_len, int *mapped)
{
    *mapped = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat sb;
    if (fd >= 0 && fstat(fd, &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0 &&
        (uintmax_t)sb.st_size < SIZE_MAX / 2) {
#ifdef MAP_POPULATE
        int flags = MAP_PRIVATE | MAP_POPULATE; /* every page mapped at once: the load reads them all */
#else
        int flags = MAP_PRIVATE;
#endif
        void *p = mmap(NULL, (size_t)sb.st_size, PROT_READ, flags, fd, 0);
        if (p != MAP_FAILED) {
            close(fd);
            *out = p;
            *out_len = (size_t)sb.st_size;
            *mapped = 1;
            return AMSCR_OK;
        }
    }
    if (fd >= 0)
        close(fd);
    return amscr__file_read(path, out, out_len); /* not mappable: read (and its errors) */
}

void amscr__file_unmap(unsigned char *buf, size_t len, int mapped)
{
    if (mapped)
        munmap(buf, len);
    else
        free(buf);
}
