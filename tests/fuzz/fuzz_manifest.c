/* fuzz_manifest.c — the tool's collection reader (tools/cli/collection.c: collection_open) on
 * arbitrary bytes, twice: as a manifest.tsv with the columns file, class and an optional group,
 * written to a temporary file first (the reader takes a path; the files it lists are not
 * opened); and as the .txt beside a point list in a folder, which the reader takes as a shape
 * when its first line is a point and skips otherwise (so the folder has one shape or two).
 * Properties on success: at least one shape; each shape's path and name non-empty, its class
 * an index into the classes, its group an index into the groups, or -1 for every shape exactly
 * when there is no group column; the class and group names non-empty and distinct; no file
 * listed twice (a repeated entry is refused). */
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "collection.h"
#include "fuzz_common.h"
#include "util.h"

/* Whether the n names are non-empty and distinct. */
static int names_ok(char **names, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (names[i] == NULL || names[i][0] == '\0')
            return 0;
        for (size_t j = 0; j < i; j++)
            if (strcmp(names[i], names[j]) == 0)
                return 0;
    }
    return 1;
}

/* Whether the shapes' names (the files as listed) are distinct. */
static int items_distinct(const collection *c)
{
    for (size_t i = 0; i < c->n; i++)
        for (size_t j = 0; j < i; j++)
            if (strcmp(c->items[i].name, c->items[j].name) == 0)
                return 0;
    return 1;
}

static void check(const collection *c)
{
    FUZZ_CHECK(c->n >= 1 && c->nclasses >= 1 && c->nclasses <= c->n && c->ngroups <= c->n);
    FUZZ_CHECK(names_ok(c->classes, c->nclasses) && names_ok(c->groups, c->ngroups) && items_distinct(c));
    for (size_t i = 0; i < c->n; i++) {
        const coll_item *it = &c->items[i];
        FUZZ_CHECK(it->path && it->path[0] && it->name && it->name[0]);
        FUZZ_CHECK(it->label >= 0 && (size_t)it->label < c->nclasses);
        FUZZ_CHECK(c->ngroups ? it->group >= 0 && (size_t)it->group < c->ngroups : it->group == -1);
    }
}

/* Writes the size bytes to the open fd and closes it; whether all were written. */
static int write_all(int fd, const uint8_t *data, size_t size)
{
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(fd, data + done, size - done);
        if (w <= 0)
            break;
        done += (size_t)w;
    }
    close(fd);
    return done == size;
}

/* The bytes as a manifest. */
static void as_manifest(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/amscr-fuzz-manifest-XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0)
        return;
    collection c;
    if (write_all(fd, data, size) && collection_open(path, &c) == 0) {
        check(&c);
        collection_free(&c);
    }
    unlink(path);
}

/* The bytes as b-1.txt in a folder beside the point list a-1.txt: one shape or both. */
static void as_folder_text(const uint8_t *data, size_t size)
{
    static const char square[] = "0 0\n1 0\n1 1\n0 1\n";
    char dir[] = "/tmp/amscr-fuzz-folder-XXXXXX";
    if (mkdtemp(dir) == NULL)
        return;
    char *a = path_join(dir, "a-1.txt"), *b = path_join(dir, "b-1.txt");
    int fa = a ? open(a, O_WRONLY | O_CREAT | O_EXCL, 0600) : -1;
    int fb = b && fa >= 0 ? open(b, O_WRONLY | O_CREAT | O_EXCL, 0600) : -1;
    int ok = fa >= 0 && write_all(fa, (const uint8_t *)square, sizeof square - 1);
    collection c;
    if (fb >= 0 && write_all(fb, data, size) && ok && collection_open(dir, &c) == 0) {
        check(&c);
        FUZZ_CHECK(c.n == 1 || c.n == 2);
        FUZZ_CHECK(strcmp(c.items[0].name, "a-1.txt") == 0);
        collection_free(&c);
    }
    if (fb < 0 && fa >= 0)
        close(fa);
    if (a)
        unlink(a);
    if (b)
        unlink(b);
    rmdir(dir);
    free(a);
    free(b);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    tool_errors_mute(1); /* a bad manifest is reported on stderr: not by the thousand here */
    as_manifest(data, size);
    as_folder_text(data, size);
    return 0;
}
