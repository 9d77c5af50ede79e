/* collection.c — folders and manifests of shapes (see collection.h). */
#include "collection.h"

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image.h"
#include "util.h"

void class_from_name(const char *filename, char *out, size_t cap)
{
    const char *base = path_base(filename);
    size_t len = strlen(base);
    const char *dot = strrchr(base, '.');
    if (dot != NULL && dot != base)
        len = (size_t)(dot - base);
    size_t end = len;
    while (end > 0 && base[end - 1] >= '0' && base[end - 1] <= '9')
        end--;
    size_t cls = len;
    if (end < len && end > 0) {
        if ((base[end - 1] == '-' || base[end - 1] == '_') && end > 1)
            cls = end - 1; /* "bird-3" -> "bird" */
        else if (base[end - 1] != '-' && base[end - 1] != '_')
            cls = end; /* "Bone01" -> "Bone" */
    }
    if (cls >= cap)
        cls = cap - 1;
    memcpy(out, base, cls);
    out[cls] = '\0';
}

void collection_free(collection *c)
{
    if (c == NULL)
        return;
    for (size_t i = 0; i < c->n; i++) {
        free(c->items[i].path);
        free(c->items[i].name);
    }
    for (size_t i = 0; i < c->nclasses; i++)
        free(c->classes[i]);
    for (size_t i = 0; i < c->ngroups; i++)
        free(c->groups[i]);
    free(c->items);
    free(c->classes);
    free(c->groups);
    c->items = NULL;
    c->classes = NULL;
    c->groups = NULL;
    c->n = c->nclasses = c->ngroups = 0;
}

/* The index of `name` in the list (*names, *n), appended when new. */
int32_t coll_name_index(char ***names, size_t *n, const char *name, size_t *cap)
{
    for (size_t i = 0; i < *n; i++)
        if (strcmp((*names)[i], name) == 0)
            return (int32_t)i;
    if (*n == *cap) {
        size_t ncap = *cap ? *cap * 2 : 16;
        char **p = realloc(*names, ncap * sizeof *p);
        if (p == NULL) {
            tool_error(NULL, "out of memory");
            return -1;
        }
        *names = p;
        *cap = ncap;
    }
    char *s = xstrdup(name);
    if (s == NULL)
        return -1;
    (*names)[*n] = s;
    return (int32_t)(*n)++;
}

/* Appends the entry `entry` (a name in dir's listing or a manifest's file column) of class cls. */
static int add_item(collection *c, size_t *icap, size_t *ccap, const char *dir, const char *entry, const char *cls)
{
    char *path = path_join(dir, entry);
    char *name = xstrdup(entry);
    if (path == NULL || name == NULL) {
        free(path);
        free(name);
        return -1;
    }
    int32_t label = coll_name_index(&c->classes, &c->nclasses, cls, ccap);
    if (label < 0) {
        free(path);
        free(name);
        return -1;
    }
    if (c->n == *icap) {
        size_t ncap = *icap ? *icap * 2 : 64;
        coll_item *p = realloc(c->items, ncap * sizeof *p);
        if (p == NULL) {
            free(path);
            free(name);
            tool_error(NULL, "out of memory");
            return -1;
        }
        c->items = p;
        *icap = ncap;
    }
    c->items[c->n].path = path;
    c->items[c->n].name = name;
    c->items[c->n].label = label;
    c->items[c->n].group = -1;
    c->n++;
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

static int open_folder(const char *dir, collection *c)
{
    DIR *d = opendir(dir);
    if (d == NULL) {
        tool_error(dir, "cannot open folder: %s", strerror(errno));
        return -1;
    }
    char **names = NULL;
    size_t n = 0, cap = 0;
    struct dirent *e;
    int ok = 1;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char *path = path_join(dir, e->d_name);
        if (path == NULL) {
            ok = 0;
            break;
        }
        struct stat st;
        char ext[16];
        path_ext(e->d_name, ext);
        int take = stat(path, &st) == 0 && S_ISREG(st.st_mode) &&
                   (strcmp(ext, ".txt") == 0 || strcmp(ext, ".csv") == 0 || file_is_image(path));
        free(path);
        if (!take)
            continue;
        if (n == cap) {
            cap = cap ? cap * 2 : 64;
            char **p = realloc(names, cap * sizeof *p);
            if (p == NULL) {
                tool_error(NULL, "out of memory");
                ok = 0;
                break;
            }
            names = p;
        }
        names[n] = xstrdup(e->d_name);
        if (names[n] == NULL) {
            ok = 0;
            break;
        }
        n++;
    }
    closedir(d);
    if (ok && n == 0) {
        tool_error(dir, "no shapes in this folder (PNG or PGM images, .txt or .csv point lists)");
        ok = 0;
    }
    if (ok)
        qsort(names, n, sizeof *names, cmp_str);
    size_t icap = 0, ccap = 0;
    for (size_t i = 0; ok && i < n; i++) {
        char cls[256];
        class_from_name(names[i], cls, sizeof cls);
        if (add_item(c, &icap, &ccap, dir, names[i], cls) != 0)
            ok = 0;
    }
    for (size_t i = 0; i < n; i++)
        free(names[i]);
    free(names);
    return ok ? 0 : -1;
}

/* Splits a line on tabs in place; returns the number of fields (at most max). */
static size_t split_tabs(char *line, char **fields, size_t max)
{
    size_t n = 0;
    char *p = line;
    while (n < max) {
        fields[n++] = p;
        char *t = strchr(p, '\t');
        if (t == NULL)
            break;
        *t = '\0';
        p = t + 1;
    }
    return n;
}

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    size_t i = 0;
    while (s[i] == ' ')
        i++;
    if (i)
        memmove(s, s + i, n - i + 1);
}

/* The group of the last item added (a manifest's `group` column). */
static int set_group(collection *c, char *g, size_t *gcap, const char *mpath, size_t lineno)
{
    trim(g);
    if (g[0] == '\0') {
        tool_error(mpath, "line %zu: empty group", lineno);
        return -1;
    }
    int32_t gi = coll_name_index(&c->groups, &c->ngroups, g, gcap);
    if (gi < 0)
        return -1;
    c->items[c->n - 1].group = gi;
    return 0;
}

/* Reads one line of any length into *line (grown as needed; NUL-terminated, without its '\n').
 * Returns 1 for a line (its length in *out_len), 0 at the end of the file, -1 out of memory
 * (reported). */
static int read_line(FILE *fp, char **line, size_t *lcap, size_t *out_len)
{
    size_t len = 0;
    int ch;
    while ((ch = getc(fp)) != EOF && ch != '\n') {
        if (len + 2 > *lcap) {
            char *p = realloc(*line, *lcap * 2);
            if (p == NULL) {
                tool_error(NULL, "out of memory");
                return -1;
            }
            *line = p;
            *lcap *= 2;
        }
        (*line)[len++] = (char)ch;
    }
    if (ch == EOF && len == 0)
        return 0;
    (*line)[len] = '\0';
    *out_len = len;
    return 1;
}

/* A manifest being read: where it is, its columns (from the header line) and the capacities of
 * the collection's growing arrays. */
typedef struct {
    const char *path;
    const char *dir;             /* the manifest's folder: file names are relative to it */
    int header;                  /* 1 until the header line is read */
    long fcol, ccol, gcol;       /* the columns file, class and (optional, else -1) group */
    size_t lineno, icap, ccap, gcap;
} manifest_reader;

/* The header line: finds the columns named file, class and group. */
static int manifest_header(manifest_reader *r, char **f, size_t nf)
{
    for (size_t i = 0; i < nf; i++) {
        trim(f[i]);
        if (strcmp(f[i], "file") == 0)
            r->fcol = (long)i;
        else if (strcmp(f[i], "class") == 0)
            r->ccol = (long)i;
        else if (strcmp(f[i], "group") == 0)
            r->gcol = (long)i;
    }
    if (r->fcol < 0 || r->ccol < 0) {
        tool_error(r->path, "line %zu: the header must name the columns 'file' and 'class' (tab-separated)",
                   r->lineno);
        return -1;
    }
    r->header = 0;
    return 0;
}

/* A shape line: its file, class and group added to the collection. */
static int manifest_row(manifest_reader *r, char **f, size_t nf, collection *c)
{
    long need = r->fcol > r->ccol ? r->fcol : r->ccol;
    if (r->gcol > need)
        need = r->gcol;
    if ((size_t)need >= nf) {
        tool_error(r->path, "line %zu: expected %ld tab-separated columns, found %zu", r->lineno, need + 1, nf);
        return -1;
    }
    char *file = f[r->fcol], *cls = f[r->ccol];
    trim(file);
    trim(cls);
    if (file[0] == '\0' || cls[0] == '\0') {
        tool_error(r->path, "line %zu: empty file or class", r->lineno);
        return -1;
    }
    if (add_item(c, &r->icap, &r->ccap, r->dir, file, cls) != 0)
        return -1;
    if (r->gcol >= 0 && set_group(c, f[r->gcol], &r->gcap, r->path, r->lineno) != 0)
        return -1;
    return 0;
}

/* Every line of the manifest: blank lines and '#' comments skipped, the header, then the shapes. */
static int manifest_lines(manifest_reader *r, FILE *fp, collection *c)
{
    size_t lcap = 4096, len = 0;
    char *line = malloc(lcap);
    if (line == NULL) {
        tool_error(NULL, "out of memory");
        return -1;
    }
    int ok = 1, got;
    while ((got = read_line(fp, &line, &lcap, &len)) > 0) {
        r->lineno++;
        if (memchr(line, '\0', len) != NULL) {
            tool_error(r->path, "line %zu: not a text manifest", r->lineno);
            ok = 0;
            break;
        }
        trim(line);
        if (line[0] == '\0' || line[0] == '#')
            continue;
        char *f[64];
        size_t nf = split_tabs(line, f, 64);
        if ((r->header ? manifest_header(r, f, nf) : manifest_row(r, f, nf, c)) != 0) {
            ok = 0;
            break;
        }
    }
    free(line);
    return ok && got >= 0 ? 0 : -1;
}

static int open_manifest(const char *mpath, collection *c)
{
    FILE *fp = fopen(mpath, "rb");
    if (fp == NULL) {
        tool_error(mpath, "cannot open: %s", strerror(errno));
        return -1;
    }
    char *dir = path_dir(mpath);
    if (dir == NULL) {
        fclose(fp);
        return -1;
    }
    manifest_reader r = {mpath, dir, 1, -1, -1, -1, 0, 0, 0, 0};
    int ok = manifest_lines(&r, fp, c) == 0;
    if (ok && ferror(fp)) {
        tool_error(mpath, "read error");
        ok = 0;
    }
    if (ok && r.header) {
        tool_error(mpath, r.lineno == 0 ? "empty file" : "no header line with 'file' and 'class' columns");
        ok = 0;
    }
    if (ok && c->n == 0) {
        tool_error(mpath, "the manifest lists no shapes");
        ok = 0;
    }
    free(dir);
    fclose(fp);
    return ok ? 0 : -1;
}

int collection_open(const char *path, collection *out)
{
    memset(out, 0, sizeof *out);
    struct stat st;
    if (stat(path, &st) != 0) {
        tool_error(path, "cannot open: %s", strerror(errno));
        return -1;
    }
    int r = S_ISDIR(st.st_mode) ? open_folder(path, out) : open_manifest(path, out);
    if (r != 0)
        collection_free(out);
    return r;
}
