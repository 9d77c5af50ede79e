/* util.c — helpers of the amscr tool (see util.h). */
#define _GNU_SOURCE /* O_TMPFILE, where the system has it */
#include "util.h"
#include "out_path.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

static int g_error_printed;
static int g_muted; /* set only while no other thread runs (see util.h) */

int tool_error_printed(void) { return g_error_printed; }
void tool_errors_mute(int on) { g_muted = on; }
int tool_errors_muted(void) { return g_muted; }

static void print_line(const char *what, const char *msg)
{
    /* One line, whatever the message contains. */
    char line[2 * 8192 + 16]; /* two paths of PATH_MAX and more */
    if (what != NULL && what[0] != '\0')
        snprintf(line, sizeof line, "amscr: %s: %s", what, msg);
    else
        snprintf(line, sizeof line, "amscr: %s", msg);
    for (char *p = line; *p; p++)
        if (*p == '\n' || *p == '\r')
            *p = ' ';
    fprintf(stderr, "%s\n", line);
    fflush(stderr);
}

void tool_error(const char *what, const char *fmt, ...)
{
    if (g_muted || g_error_printed)
        return;
    g_error_printed = 1;
    char msg[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    print_line(what, msg);
}

int usage_error(const char *what, const char *fmt, ...)
{
    char msg[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    tool_error(what, "%s", msg);
    return TOOL_EXIT_USAGE;
}

const char *lib_detail(void)
{
    const char *d = amscr_last_error_detail();
    /* drop a leading "amscr_function_name: " */
    if (strncmp(d, "amscr_", 6) == 0) {
        const char *p = d;
        while ((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_')
            p++;
        if (p[0] == ':' && p[1] == ' ')
            return p + 2;
    }
    return d;
}

void tool_lib_error(const char *what, amscr_status st)
{
    const char *detail = lib_detail();
    if (g_muted || g_error_printed)
        return;
    if (detail != NULL && detail[0] != '\0') {
        size_t wl = what ? strlen(what) : 0;
        if (wl > 0 && strncmp(detail, what, wl) == 0 && detail[wl] == ':') {
            g_error_printed = 1;
            print_line(NULL, detail);
            return;
        }
        tool_error(what, "%s (%s)", detail, amscr_strerror(st));
    } else {
        tool_error(what, "%s", amscr_strerror(st));
    }
}

void *xmalloc_array(size_t n, size_t size)
{
    if (size != 0 && n > SIZE_MAX / size) {
        tool_error(NULL, "out of memory (%zu x %zu bytes)", n, size);
        return NULL;
    }
    void *p = malloc(n * size != 0 ? n * size : 1);
    if (p == NULL)
        tool_error(NULL, "out of memory (%zu bytes)", n * size);
    return p;
}

void *xcalloc_array(size_t n, size_t size)
{
    if (size != 0 && n > SIZE_MAX / size) {
        tool_error(NULL, "out of memory (%zu x %zu bytes)", n, size);
        return NULL;
    }
    void *p = calloc(n ? n : 1, size ? size : 1);
    if (p == NULL)
        tool_error(NULL, "out of memory (%zu bytes)", n * size);
    return p;
}

char *xstrdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *p = xmalloc_array(n, 1);
    if (p)
        memcpy(p, s, n);
    return p;
}

/* ----------------------------------------------------------- output files */
/* An unnamed file in dir (O_TMPFILE, where the system has it and /proc names its descriptors:
 * a write cut off leaves nothing behind), mode 0666 less the umask; -1 when there is none. */
static int open_unnamed(const char *dir)
{
#ifdef O_TMPFILE
    int fd = open(dir, O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    if (fd >= 0 && access(proc, F_OK) != 0) {
        close(fd);
        fd = -1;
    }
    return fd;
#else
    (void)dir;
    return -1;
#endif
}

/* Gives the unnamed file fd the name o->path: a link when the path is new, else a link under a
 * fresh temporary name (o->tmp) renamed over it. 0, or -1 with errno set. */
static int name_unnamed(tool_out *o, int fd)
{
    char proc[64];
    snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
    if (linkat(AT_FDCWD, proc, AT_FDCWD, o->path, AT_SYMLINK_FOLLOW) == 0)
        return 0;
    for (unsigned k = 0; errno == EEXIST && k < 64; k++) {
        snprintf(o->tmp, o->tmp_cap, "%s/.%s.%ld.%d.%u", o->dir, path_base(o->path), (long)getpid(), fd, k);
        if (linkat(AT_FDCWD, proc, AT_FDCWD, o->tmp, AT_SYMLINK_FOLLOW) != 0)
            continue;
        if (rename(o->tmp, o->path) == 0)
            return 0;
        int e = errno;
        unlink(o->tmp);
        errno = e;
        return -1;
    }
    return -1;
}

static void out_free(tool_out *o)
{
    free(o->tmp);
    free(o->path);
    free(o->dir);
    o->tmp = o->path = o->dir = NULL;
}

/* An existing file that is not replaced (out_path.h: a device, a FIFO, /dev/stdout), opened to
 * write through it. */
static int open_stream(tool_out *o, const char *path)
{
    int fd = open(path, O_WRONLY | O_APPEND | O_NOCTTY | O_CLOEXEC);
    o->fp = fd >= 0 ? fdopen(fd, "wb") : NULL;
    o->path = xstrdup(path);
    o->stream = 1;
    if (o->fp == NULL || o->path == NULL) {
        if (o->fp == NULL)
            tool_error(path, "cannot open output file: %s", strerror(errno));
        if (o->fp)
            fclose(o->fp);
        else if (fd >= 0)
            close(fd);
        o->fp = NULL;
        out_free(o);
        return -1;
    }
    return 0;
}

/* A file for `target` in its folder: unnamed, or under a temporary name (o->tmp); its mode is
 * the replaced file's, or 0666 less the umask for a new one. */
static int open_replacement(tool_out *o, const char *target)
{
    int fd = open_unnamed(o->dir);
    o->unnamed = fd >= 0;
    if (fd < 0) {
        snprintf(o->tmp, o->tmp_cap, "%s/.%s.XXXXXX", o->dir, path_base(target));
        fd = mkstemp(o->tmp);
        mode_t mask = umask(0); /* mkstemp makes 0600; give the usual 0666 & ~umask */
        umask(mask);
        if (fd >= 0)
            (void)fchmod(fd, 0666 & ~mask);
    }
    struct stat st;
    if (fd >= 0 && stat(target, &st) == 0 && S_ISREG(st.st_mode))
        (void)fchmod(fd, st.st_mode & 07777); /* a replaced file keeps its mode */
    return fd;
}

int tool_out_open(tool_out *o, const char *path)
{
    memset(o, 0, sizeof *o);
    if (strcmp(path, "-") == 0) {
        o->fp = stdout;
        return 0;
    }
    int stream = 0;
    char *target = NULL;
    if (amscr__out_path(path, &stream, &target) != 0) {
        if (errno == EISDIR)
            tool_error(path, "is a directory");
        else
            tool_error(path, "cannot write output file: %s", strerror(errno));
        return -1;
    }
    if (stream)
        return open_stream(o, path);
    o->path = target;
    o->dir = path_dir(target);
    o->tmp_cap = o->dir ? strlen(o->dir) + strlen(path_base(target)) + 64 : 0;
    o->tmp = o->dir ? xmalloc_array(o->tmp_cap, 1) : NULL;
    if (o->tmp == NULL) {
        out_free(o);
        return -1;
    }
    int fd = open_replacement(o, target);
    o->fp = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (o->fp == NULL) {
        tool_error(path, "cannot create output file: %s", strerror(errno));
        if (fd >= 0)
            close(fd);
        if (fd >= 0 && !o->unnamed)
            unlink(o->tmp);
        out_free(o);
        return -1;
    }
    return 0;
}

/* Flushes and closes a written-through file; -1 after the error line. */
static int commit_stream(tool_out *o)
{
    int bad = fflush(o->fp) != 0 || ferror(o->fp);
    int err = errno;
    if (fclose(o->fp) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    o->fp = NULL;
    if (bad)
        tool_error(o->path, "cannot write output file: %s", strerror(err));
    out_free(o);
    return bad ? -1 : 0;
}

/* Flushes o's file to the disk (named only once whole and on the disk); 0, or -1 with errno. */
static int flush_out(tool_out *o)
{
    if (fflush(o->fp) != 0 || ferror(o->fp))
        return -1;
    return fsync(fileno(o->fp)) == 0 || errno == EINVAL || errno == EROFS ? 0 : -1;
}

/* Names the flushed file o->path and closes it; -1 after the error line. */
static int name_out(tool_out *o)
{
    int bad = 0, err = 0;
    if (o->unnamed && name_unnamed(o, fileno(o->fp)) != 0) {
        bad = 1;
        err = errno;
    }
    if (fclose(o->fp) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    o->fp = NULL;
    if (!bad && !o->unnamed && rename(o->tmp, o->path) != 0) {
        bad = 1;
        err = errno;
    }
    if (bad) {
        tool_error(o->path, "cannot write output file: %s", strerror(err));
        if (!o->unnamed)
            unlink(o->tmp);
    }
    out_free(o);
    return bad ? -1 : 0;
}

/* The outputs whose names wait for tool_out_release (tool_out_hold); the tool writes its outputs
 * from its main thread only. */
enum { TOOL_OUT_HELD_MAX = 4 };
static tool_out g_held[TOOL_OUT_HELD_MAX];
static size_t g_nheld;
static int g_holding;

void tool_out_hold(void)
{
    g_holding = 1;
    g_nheld = 0;
}

int tool_out_release(int keep)
{
    int bad = 0;
    for (size_t i = 0; i < g_nheld; i++) {
        if (keep && !bad)
            bad = name_out(&g_held[i]) != 0;
        else
            tool_out_abort(&g_held[i]);
    }
    g_nheld = 0;
    g_holding = 0;
    return bad ? -1 : 0;
}

int tool_out_commit(tool_out *o)
{
    if (o->fp == NULL)
        return -1;
    if (o->path == NULL) { /* stdout */
        int bad = fflush(o->fp) != 0 || ferror(o->fp);
        o->fp = NULL;
        if (bad) {
            tool_error("<stdout>", "write error: %s", strerror(errno));
            return -1;
        }
        return 0;
    }
    if (o->stream)
        return commit_stream(o);
    if (flush_out(o) != 0) {
        tool_error(o->path, "cannot write output file: %s", strerror(errno));
        tool_out_abort(o);
        return -1;
    }
    if (g_holding && g_nheld < TOOL_OUT_HELD_MAX) {
        g_held[g_nheld++] = *o;
        memset(o, 0, sizeof *o);
        return 0;
    }
    return name_out(o);
}

void tool_out_abort(tool_out *o)
{
    if (o->fp != NULL && o->path != NULL)
        fclose(o->fp);
    if (o->path != NULL && !o->unnamed && !o->stream)
        unlink(o->tmp);
    out_free(o);
    o->fp = NULL;
}

int tool_out_probe(const char *path)
{
    int stream = 0;
    char *target = NULL;
    if (strcmp(path, "-") != 0 && amscr__out_path(path, &stream, &target) == 0 && stream) {
        /* not opened: a FIFO's reader would see its end before the output is written */
        if (access(path, W_OK) == 0)
            return 0;
        tool_error(path, "cannot open output file: %s", strerror(errno));
        return -1;
    }
    free(target);
    tool_out t;
    if (tool_out_open(&t, path) != 0)
        return -1;
    tool_out_abort(&t);
    return 0;
}

int tool_out_not_input(const char *opt, const char *path, const char *const *inputs, size_t n)
{
    struct stat so, si;
    if (path == NULL || strcmp(path, "-") == 0 || stat(path, &so) != 0)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (inputs[i] && stat(inputs[i], &si) == 0 && si.st_dev == so.st_dev && si.st_ino == so.st_ino) {
            tool_error(path, "%s would overwrite an input file: give another name", opt);
            return -1;
        }
    return 0;
}

/* ------------------------------------------------------------ strings */
void sb_init(sbuf *b)
{
    b->s = NULL;
    b->len = b->cap = 0;
    b->oom = 0;
}

void sb_free(sbuf *b)
{
    free(b->s);
    sb_init(b);
}

static int sb_reserve(sbuf *b, size_t extra)
{
    if (b->oom)
        return -1;
    if (b->len + extra + 1 <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 256;
    while (cap < b->len + extra + 1)
        cap *= 2;
    char *s = realloc(b->s, cap);
    if (s == NULL) {
        b->oom = 1;
        return -1;
    }
    b->s = s;
    b->cap = cap;
    return 0;
}

void sb_printf(sbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || sb_reserve(b, (size_t)n) != 0)
        return;
    va_start(ap, fmt);
    vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

void sb_puts(sbuf *b, const char *s)
{
    size_t n = strlen(s);
    if (sb_reserve(b, n) != 0)
        return;
    memcpy(b->s + b->len, s, n + 1);
    b->len += n;
}

int sb_write_stdout(const sbuf *b)
{
    if (b->oom) {
        tool_error(NULL, "out of memory");
        return -1;
    }
    fputs(b->s, stdout);
    if (fflush(stdout) != 0) {
        tool_error("<stdout>", "write error: %s", strerror(errno));
        return -1;
    }
    return 0;
}

const char *fmt_num(char buf[32], double v)
{
    if (isnan(v))
        snprintf(buf, 32, "nan");
    else if (isinf(v))
        snprintf(buf, 32, v > 0 ? "inf" : "-inf");
    else if (v == 0.0)
        snprintf(buf, 32, "0");
    else
        snprintf(buf, 32, "%.6g", v);
    return buf;
}

/* ------------------------------------------------------------ paths */
void path_ext(const char *path, char out[16])
{
    const char *base = path_base(path);
    const char *dot = strrchr(base, '.');
    out[0] = '\0';
    if (dot == NULL || dot == base || strlen(dot) >= 16)
        return;
    size_t i = 0;
    for (; dot[i]; i++) {
        char c = dot[i];
        out[i] = (c >= 'A' && c <= 'Z') ? (char)(c - 'A' + 'a') : c;
    }
    out[i] = '\0';
}

const char *path_base(const char *path)
{
    const char *s = strrchr(path, '/');
    return s ? s + 1 : path;
}

char *path_dir(const char *path)
{
    const char *s = strrchr(path, '/');
    if (s == NULL)
        return xstrdup(".");
    if (s == path)
        return xstrdup("/");
    size_t n = (size_t)(s - path);
    char *d = xmalloc_array(n + 1, 1);
    if (d) {
        memcpy(d, path, n);
        d[n] = '\0';
    }
    return d;
}

char *path_join(const char *dir, const char *rel)
{
    if (rel[0] == '/' || strcmp(dir, ".") == 0 || dir[0] == '\0')
        return xstrdup(rel);
    size_t n = strlen(dir) + strlen(rel) + 2;
    char *p = xmalloc_array(n, 1);
    if (p) {
        size_t dl = strlen(dir);
        snprintf(p, n, "%s%s%s", dir, (dl > 0 && dir[dl - 1] == '/') ? "" : "/", rel);
    }
    return p;
}

double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ------------------------------------------------------------ progress */
void progress_init(tool_progress *p, const char *label)
{
    const char *term = getenv("TERM");
    p->enabled = isatty(2) && !(term && strcmp(term, "dumb") == 0); /* a dumb terminal has no erase */
    p->label = label;
    p->start = now_seconds();
    p->last = 0.0;
    p->shown = 0;
}

/* "12s", "3m05s" or "1h02m" into out. */
static void format_duration(char out[32], double s)
{
    if (!(s >= 0.0) || s > 359999.0)
        s = 359999.0;
    unsigned long t = (unsigned long)(s + 0.5);
    if (t < 60)
        snprintf(out, 32, "%lus", t);
    else if (t < 3600)
        snprintf(out, 32, "%lum%02lus", t / 60, t % 60);
    else
        snprintf(out, 32, "%luh%02lum", t / 3600, t / 60 % 60);
}

void progress_update(tool_progress *p, size_t done, size_t total)
{
    if (!p->enabled || total == 0)
        return;
    double t = now_seconds();
    if (p->shown && t - p->last < 0.1 && done < total)
        return;
    p->last = t;
    p->shown = 1;
    double frac = (double)done / (double)total, el = t - p->start;
    int width = 30, fill = (int)(frac * width + 0.5);
    char bar[32], left[32];
    for (int i = 0; i < width; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[width] = '\0';
    double rate = el > 0.0 ? (double)done / el : 0.0;
    if (done > 0 && rate > 0.0)
        format_duration(left, (double)(total - done) / rate);
    else
        snprintf(left, sizeof left, "?");
    fprintf(stderr, "\r\033[Kamscr: %s [%s] %3d%% %zu/%zu  %.0f/s  %s left", p->label, bar,
            (int)(100.0 * frac + 0.5), done, total, rate, left);
    fflush(stderr);
}

void progress_note(tool_progress *p, const char *label)
{
    p->label = label;
    if (!p->enabled)
        return;
    fprintf(stderr, "\r\033[Kamscr: %s ...", label);
    fflush(stderr);
    p->shown = 1;
}

void progress_end(tool_progress *p)
{
    if (p->enabled && p->shown) {
        fprintf(stderr, "\r\033[K");
        fflush(stderr);
    }
    p->shown = 0;
}

int progress_cb(void *user, size_t done, size_t total)
{
    progress_update((tool_progress *)user, done, total);
    return 0;
}
