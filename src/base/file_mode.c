/* file_mode.c — the permissions a file the library writes gets: a file it replaces keeps its
 * mode; a new one gets 0666 less the process's umask, as open(2) would give it. The umask is
 * read from /proc/self/status (umask(2) would have to change it to read it, which is not safe
 * beside other threads); where that is unavailable, 0644. */
#define _DEFAULT_SOURCE
#include "internal.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

/* The process's umask, or -1 when it cannot be read without changing it. */
static int read_umask(void)
{
    FILE *f = amscr__fopen_read("/proc/self/status");
    if (!f)
        return -1;
    char line[256];
    unsigned mask = 0;
    int found = 0;
    while (!found && fgets(line, sizeof line, f))
        found = strncmp(line, "Umask:", 6) == 0 && sscanf(line + 6, "%o", &mask) == 1;
    fclose(f);
    return found ? (int)(mask & 0777) : -1;
}

unsigned amscr__file_mode(const char *path)
{
    struct stat sb;
    if (stat(path, &sb) == 0 && S_ISREG(sb.st_mode))
        return (unsigned)(sb.st_mode & 07777);
    int mask = read_umask();
    return mask < 0 ? 0644u : 0666u & ~(unsigned)mask;
}
