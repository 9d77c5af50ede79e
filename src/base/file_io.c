/* file_io.c — whole files: read into memory, mapped read-only (no copy, the page cache's
 * pages; read where a file cannot be mapped), and written atomically (a temporary name, then a
 * rename, with the mode of file_mode.c). The collection and index files use them (db_io.c,
 * index_io.c). */
#define _DEFAULT_SOURCE /* MAP_POPULATE, where the system has it */
#include "internal.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>

amscr_status amscr__file_write_atomic(const char *path, const void *buf, size_t len)
{
    size_t plen = strlen(path);
    char *tmp = malloc(plen + 16);
    if (!tmp)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    memcpy(tmp, path, plen);
    memcpy(tmp + plen, ".tmp.XXXXXX", 12);
    amscr_status st = AMSCR_OK;
    int fd = mkstemp(tmp);
    if (fd < 0) {
        st = amscr__fail(AMSCR_E_IO, "%s: cannot create a temporary file: %s", path, strerror(errno));
    } else {
        (void)fchmod(fd, (mode_t)amscr__file_mode(path)); /* mkstemp made it 0600 (best effort) */
        FILE *f = fdopen(fd, "wb");
        int ok = f && fwrite(buf, 1, len, f) == len;
        ok = ok && fflush(f) == 0 && fsync(fd) == 0; /* on the disk before it takes the name */
        if (f)
            ok = (fclose(f) == 0) && ok;
        else
            close(fd);
        if (!ok || rename(tmp, path) != 0) {
            st = amscr__fail(AMSCR_E_IO, "%s: cannot write: %s", path, strerror(errno));
            remove(tmp);
        }
    }
    free(tmp);
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

amscr_status amscr__file_read(const char *path, unsigned char **out, size_t *out_len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return amscr__fail(AMSCR_E_IO, "%s: %s", path, strerror(errno));
    size_t cap = file_size(f), len = 0;
    cap = cap ? cap + 1 : (size_t)1 << 16; /* one more byte: the end is seen without a second buffer */
    unsigned char *buf = malloc(cap);
    amscr_status st = AMSCR_OK;
    while (buf) {
        if (len == cap) {
            if (cap > ((size_t)1 << 40)) {
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
        if (got == 0)
            break;
    }
    int err = ferror(f);
    fclose(f);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    if (st == AMSCR_OK && err)
        st = amscr__fail(AMSCR_E_IO, "%s: read error", path);
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
    int fd = open(path, O_RDONLY);
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
