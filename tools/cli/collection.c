/* collection.c — folders and manifests of shapes (see collection.h). */
#include "collection.h"

#include <dirent.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image.h"
#include "util.h"

/* A separator a derived class name does not end with: "star 3" -> "star", "bird--3" -> "bird". */
static int is_name_sep(char ch) { return ch == ' ' || ch == '\t' || ch == '-' || ch == '_'; }

/* The length of base[0..len) without trailing blanks (and, when digits were dropped, trailing
 * separators); len itself when nothing would be left. */
static size_t trim_class(const char *base, size_t len, int digits_dropped)
{
    size_t n = len;
    while (n > 0 && (digits_dropped ? is_name_sep(base[n - 1]) : base[n - 1] == ' ' || base[n - 1] == '\t'))
        n--;
    return n > 0 ? n : len;
}

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
    cls = cls < len ? trim_class(base, cls, 1) : trim_class(base, len, 0);
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

/* Appends a copy of name to the list (names, *n; capacity *cap); -1 out of memory (printed). */
static int push_name(char ***names, size_t *n, size_t *cap, const char *name)
{
    if (*n == *cap) {
        size_t ncap = *cap ? *cap * 2 : 64;
        char **p = realloc(*names, ncap * sizeof *p);
        if (p == NULL) {
            tool_error(NULL, "out of memory");
            return -1;
        }
        *names = p;
        *cap = ncap;
    }
    if (((*names)[*n] = xstrdup(name)) == NULL)
        return -1;
    (*n)++;
    return 0;
}

/* The index of `name` in the list (*names, *n), appended when new. */
int32_t coll_name_index(char ***names, size_t *n, const char *name, size_t *cap)
{
    for (size_t i = 0; i < *n; i++)
        if (strcmp((*names)[i], name) == 0)
            return (int32_t)i;
    return push_name(names, n, cap, name) == 0 ? (int32_t)(*n - 1) : -1;
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

/* The files of a folder the tool does not read although they are images: how many, and the
 * first by name. */
typedef struct {
    size_t n;
    char example[256];
} skipped_files;

static int is_point_line(const char *s);

/* Whether the file at path reads as a point list: 1 when its first line with content (after a
 * UTF-8 byte order mark, blank lines and '#' comments) is a point, 0 when it is something else
 * or there is none (a README.txt, a table of classes.csv, an empty file), -1 when the file cannot
 * be opened (errno set). */
static int text_is_points(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (fp == NULL)
        return -1;
    char line[512];
    int r = 0, first = 1, rest = 0; /* rest: the chunk continues a line longer than the buffer */
    while (fgets(line, sizeof line, fp) != NULL) {
        char *s = line;
        int skip = rest;
        rest = strchr(line, '\n') == NULL;
        if (skip) /* the tail of a comment or blank line: a line with content ended the loop */
            continue;
        if (first && strncmp(s, "\xEF\xBB\xBF", 3) == 0)
            s += 3;
        first = 0;
        s[strcspn(s, "#\r\n")] = '\0';
        s += strspn(s, " \t");
        size_t n = strlen(s);
        while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
            s[--n] = '\0';
        if (n > 0) {
            r = is_point_line(s);
            break;
        }
    }
    fclose(fp);
    return r;
}

/* 1 when the folder entry `name` is a shape file (a regular file: PNG or PGM magic bytes, or a
 * .txt / .csv name whose first line is a point); 0 when not (counted in sk when it looks meant as
 * a shape: an image of a format the tool cannot read, a file named as an image that is none —
 * empty, damaged, a dangling link — or a .txt / .csv that is no point list); -1 out of memory.
 * A file named as a shape that cannot be opened (no permission) is taken: its load names why. */
static int take_entry(const char *dir, const char *name, skipped_files *sk)
{
    char *path = path_join(dir, name);
    if (path == NULL)
        return -1;
    struct stat st;
    char ext[16];
    path_ext(name, ext);
    int reg = stat(path, &st) == 0 && S_ISREG(st.st_mode);
    int text = strcmp(ext, ".txt") == 0 || strcmp(ext, ".csv") == 0;
    int named = strcmp(ext, ".png") == 0 || strcmp(ext, ".pgm") == 0 || strcmp(ext, ".pnm") == 0;
    int points = reg && text ? text_is_points(path) : 0;
    int take = reg && (points != 0 || file_is_image(path) || (named && access(path, R_OK) != 0));
    if (!take && (named || text || (reg && file_image_other(path) != NULL))) {
        if (sk->n++ == 0 || strcmp(name, sk->example) < 0)
            snprintf(sk->example, sizeof sk->example, "%s", name);
    }
    free(path);
    return take;
}

/* The names of the shape files of a folder (unsorted); 0, or -1 after printing the error. */
static int folder_names(const char *dir, char ***names, size_t *n, skipped_files *sk)
{
    DIR *d = opendir(dir);
    if (d == NULL) {
        tool_error(dir, "cannot open folder: %s", strerror(errno));
        return -1;
    }
    size_t cap = 0;
    struct dirent *e;
    int ok = 1;
    while (ok && (e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        int take = take_entry(dir, e->d_name, sk);
        ok = take >= 0 && (take == 0 || push_name(names, n, &cap, e->d_name) == 0);
    }
    closedir(d);
    return ok ? 0 : -1;
}

/* The error of a folder without shapes; a manifest.tsv in it is what the user meant. */
static void no_shapes_error(const char *dir)
{
    char *m = path_join(dir, "manifest.tsv");
    struct stat st;
    if (m != NULL && stat(m, &st) == 0 && S_ISREG(st.st_mode))
        tool_error(dir, "no shapes in this folder (PNG or PGM images, .txt or .csv point lists); it holds a "
                        "manifest: pass %s", m);
    else
        tool_error(dir, "no shapes in this folder (PNG or PGM images, .txt or .csv point lists)");
    free(m);
}

static int open_folder(const char *dir, collection *c)
{
    char **names = NULL;
    size_t n = 0;
    skipped_files sk = {0, ""};
    int ok = folder_names(dir, &names, &n, &sk) == 0;
    if (sk.n > 0 && !tool_errors_muted()) /* a warning, not an error: the folder's shapes are read */
        fprintf(stderr, "amscr: %s: %zu file%s skipped: not PNG, PGM or a point list (e.g. %s)\n", dir, sk.n,
                sk.n == 1 ? "" : "s", sk.example);
    if (ok && n == 0) {
        no_shapes_error(dir);
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

/* Splits a line on tabs in place; returns the number of fields, of which the first max are
 * stored. */
static size_t split_tabs(char *line, char **fields, size_t max)
{
    size_t n = 0;
    char *p = line;
    for (;;) {
        if (n < max)
            fields[n] = p;
        n++;
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

/* A manifest being read: where it is, its columns (from the header line), the capacities of
 * the collection's growing arrays and the line of each shape. */
typedef struct {
    const char *path;
    const char *dir;       /* the manifest's folder: file names are relative to it */
    int header;            /* 1 until the header line is read */
    long fcol, ccol, gcol; /* the columns file, class and (optional, else -1) group */
    size_t ncol;           /* the header's columns: a row may have fewer (trailing ones empty), not more */
    size_t lineno, icap, ccap, gcap;
    size_t *lines, lines_cap; /* lines[i]: the line of shape i */
} manifest_reader;

/* What a file given as a collection is when it is not one (a folder, a manifest, an index). */
#define NOT_COLLECTION                                                                                       \
    "not a collection (a folder of shapes, a manifest .tsv with the columns file and class, or an index)"

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
    r->ncol = nf;
    r->header = 0;
    return 0;
}

/* Notes the line of the shape just added (shape c->n - 1). */
static int note_line(manifest_reader *r, const collection *c)
{
    if (c->n > r->lines_cap) {
        size_t ncap = r->lines_cap ? r->lines_cap * 2 : 64;
        size_t *p = realloc(r->lines, ncap * sizeof *p);
        if (p == NULL) {
            tool_error(NULL, "out of memory");
            return -1;
        }
        r->lines = p;
        r->lines_cap = ncap;
    }
    r->lines[c->n - 1] = r->lineno;
    return 0;
}

/* A shape line: its file, class and group added to the collection. */
static int manifest_row(manifest_reader *r, char **f, size_t nf, collection *c)
{
    long need = r->fcol > r->ccol ? r->fcol : r->ccol;
    if (r->gcol > need)
        need = r->gcol;
    if ((size_t)need >= nf || nf > r->ncol) {
        tool_error(r->path, "line %zu: expected %s %zu tab-separated columns (the header's), found %zu", r->lineno,
                   nf > r->ncol ? "at most" : "at least", nf > r->ncol ? r->ncol : (size_t)need + 1, nf);
        return -1;
    }
    char *file = f[r->fcol], *cls = f[r->ccol];
    trim(file);
    trim(cls);
    if (file[0] == '\0' || cls[0] == '\0') {
        tool_error(r->path, "line %zu: empty file or class", r->lineno);
        return -1;
    }
    if (add_item(c, &r->icap, &r->ccap, r->dir, file, cls) != 0 || note_line(r, c) != 0)
        return -1;
    if (r->gcol >= 0 && set_group(c, f[r->gcol], &r->gcap, r->path, r->lineno) != 0)
        return -1;
    return 0;
}

/* 1 when s (a trimmed line) is a point of a point list: two numbers, "x y" or "x,y", then
 * nothing but a comment. */
static int is_point_line(const char *s)
{
    char *end;
    (void)strtod(s, &end);
    if (end == s)
        return 0;
    while (*end == ' ' || *end == '\t' || *end == ',')
        end++;
    const char *y = end;
    (void)strtod(y, &end);
    if (end == y)
        return 0;
    while (*end == ' ' || *end == '\t')
        end++;
    return *end == '\0' || *end == '#';
}

/* The most columns a manifest line may have (file, class, group and whatever else it carries). */
enum { MANIFEST_COLUMNS = 64 };

/* One line with content (trimmed, not a comment): the header or a shape. */
static int manifest_line(manifest_reader *r, char *line, collection *c)
{
    if (r->header && is_point_line(line)) {
        tool_error(r->path, "a point list, " NOT_COLLECTION);
        return -1;
    }
    char *f[MANIFEST_COLUMNS];
    size_t nf = split_tabs(line, f, MANIFEST_COLUMNS);
    if (nf > MANIFEST_COLUMNS) {
        tool_error(r->path, "line %zu: %zu tab-separated columns, more than the %d a manifest may have", r->lineno,
                   nf, MANIFEST_COLUMNS);
        return -1;
    }
    return r->header ? manifest_header(r, f, nf) : manifest_row(r, f, nf, c);
}

/* Every line of the manifest: a UTF-8 byte order mark (an export of Excel or Notepad) before the
 * first dropped, blank lines and '#' comments skipped, the header, then the shapes. */
static int manifest_lines(manifest_reader *r, FILE *fp, collection *c)
{
    size_t lcap = 4096, len = 0;
    char *line = malloc(lcap);
    if (line == NULL) {
        tool_error(NULL, "out of memory");
        return -1;
    }
    int ok = 1, got = 0;
    while (ok && (got = read_line(fp, &line, &lcap, &len)) > 0) {
        if (r->lineno++ == 0 && len >= 3 && memcmp(line, "\xEF\xBB\xBF", 3) == 0) {
            memmove(line, line + 3, len - 2); /* the rest and its '\0' */
            len -= 3;
        }
        if (memchr(line, '\0', len) != NULL) {
            tool_error(r->path, "line %zu: not a text manifest", r->lineno);
            ok = 0;
            break;
        }
        trim(line);
        if (line[0] != '\0' && line[0] != '#')
            ok = manifest_line(r, line, c) == 0;
    }
    free(line);
    return ok && got >= 0 ? 0 : -1;
}

/* A shape's file name and its position, sorted to find a file listed twice. */
typedef struct {
    const char *name;
    size_t i;
} listed_file;

static int cmp_listed(const void *a, const void *b)
{
    const listed_file *x = a, *y = b;
    int d = strcmp(x->name, y->name);
    return d ? d : (x->i > y->i) - (x->i < y->i);
}

/* 0 when every file is listed once; else the error naming the first repeat's two lines. */
static int check_repeats(const manifest_reader *r, const collection *c)
{
    listed_file *v = xmalloc_array(c->n ? c->n : 1, sizeof *v);
    if (v == NULL)
        return -1;
    for (size_t i = 0; i < c->n; i++)
        v[i] = (listed_file){c->items[i].name, i};
    qsort(v, c->n, sizeof *v, cmp_listed);
    size_t first = 0, again = SIZE_MAX; /* the repeat on the earliest line, and its first listing */
    for (size_t k = 1; k < c->n; k++)
        if (strcmp(v[k].name, v[k - 1].name) == 0 && (again == SIZE_MAX || v[k].i < again)) {
            again = v[k].i;
            first = v[k - 1].i;
        }
    free(v);
    if (again == SIZE_MAX)
        return 0;
    tool_error(r->path, "line %zu: '%s' is already listed on line %zu (list each file once)", r->lines[again],
               c->items[again].name, r->lines[first]);
    return -1;
}

/* What is wrong with a manifest read to its end: no header, no shapes, a file listed twice. */
static int manifest_complete(const manifest_reader *r, const collection *c)
{
    if (r->header) {
        tool_error(r->path, r->lineno == 0 ? "empty file" : "no header line with 'file' and 'class' columns");
        return -1;
    }
    if (c->n == 0) {
        tool_error(r->path, "the manifest lists no shapes");
        return -1;
    }
    return check_repeats(r, c);
}

/* -1 after the error when the file's first bytes say it is an image or an amscr file, which
 * the manifest reader would misread as a manifest without a header. */
static int manifest_is_other(const char *mpath)
{
    unsigned char m[8];
    FILE *fp = fopen(mpath, "rb");
    size_t n = fp ? fread(m, 1, sizeof m, fp) : 0;
    if (fp)
        fclose(fp);
    const char *kind = file_image_other(mpath);
    if (file_is_image(mpath))
        tool_error(mpath, "a PNG or PGM image, " NOT_COLLECTION);
    else if (kind != NULL)
        tool_error(mpath, "a %s image, " NOT_COLLECTION, kind);
    else if (n >= 5 && memcmp(m, "AMSCR", 5) == 0) /* AMSCRDB, AMSCRIDX, or a file of them cut short */
        tool_error(mpath, "an amscr index or collection file, not a folder of shapes or a manifest .tsv, which "
                          "`amscr index` builds from (--add adds shapes to an index; an index of a collection file "
                          "of Python's Collection.save: amscr.Index(amscr.Collection.load(FILE)).save(OUT))");
    else
        return 0;
    return -1;
}

static int open_manifest(const char *mpath, collection *c)
{
    if (manifest_is_other(mpath) != 0)
        return -1;
    FILE *fp = fopen(mpath, "rb");
    if (fp == NULL) {
        tool_error(mpath, "cannot open: %s", strerror(errno));
        return -1;
    }
    char *dir = path_dir(mpath);
    manifest_reader r = {mpath, dir, 1, -1, -1, -1, 0, 0, 0, 0, 0, NULL, 0};
    int ok = dir != NULL && manifest_lines(&r, fp, c) == 0;
    if (ok && ferror(fp)) {
        tool_error(mpath, "read error");
        ok = 0;
    }
    ok = ok && manifest_complete(&r, c) == 0;
    free(r.lines);
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
    if (!S_ISDIR(st.st_mode) && !S_ISREG(st.st_mode)) { /* its shapes' paths need a folder */
        tool_error(path, "a pipe or a device: a collection is a folder, a manifest file or an index file");
        return -1;
    }
    int r = S_ISDIR(st.st_mode) ? open_folder(path, out) : open_manifest(path, out);
    if (r != 0)
        collection_free(out);
    return r;
}

int collection_out_not_input(const char *opt, const char *path, const collection *c, const char *const *inputs,
                             size_t n)
{
    if (tool_out_not_input(opt, path, inputs, n) != 0)
        return -1;
    for (size_t i = 0; c != NULL && i < c->n; i++) {
        const char *item = c->items[i].path;
        if (tool_out_not_input(opt, path, &item, 1) != 0)
            return -1;
    }
    return 0;
}
