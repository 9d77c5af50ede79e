/* fuzz_manifest.c — the tool's manifest reader (tools/cli/collection.c: collection_open on a
 * manifest.tsv with the columns file, class and an optional group) on arbitrary bytes, written
 * to a temporary file first (the reader takes a path; the files it lists are not opened).
 * Properties on success: at least one shape; each shape's path and name non-empty, its class
 * an index into the classes, its group an index into the groups, or -1 for every shape exactly
 * when there is no group column; the class and group names non-empty and distinct; no file
 * listed twice (a repeated entry is refused). */
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/amscr-fuzz-manifest-XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0)
        return 0;
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(fd, data + done, size - done);
        if (w <= 0)
            break;
        done += (size_t)w;
    }
    close(fd);
    collection c;
    tool_errors_mute(1); /* a bad manifest is reported on stderr: not by the thousand here */
    if (done == size && collection_open(path, &c) == 0) {
        check(&c);
        collection_free(&c);
    }
    unlink(path);
    return 0;
}
