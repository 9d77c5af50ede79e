/* fuzz_index.c — the index loader of `amscr index` (tools/index_file.c: index_parse) on
 * arbitrary bytes, as given and with the checksum made right (so the sections behind it are
 * reached). Properties on success: at least one shape, as many prepared shapes as names,
 * classes in range, neighbour lists starting with the shape itself, and the index serializes
 * into bytes that parse again to the same counts. On failure: a message. */
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"
#include "index_file.h"

static void one(const uint8_t *data, size_t size)
{
    tool_index x;
    char msg[300];
    msg[0] = '\0';
    if (index_parse(data, size, &x, msg, sizeof msg) != 0) {
        FUZZ_CHECK(msg[0] != '\0');
        index_free(&x);
        return;
    }
    size_t n = x.coll.n;
    FUZZ_CHECK(n >= 1 && amscr_db_size(x.db) == n && x.k <= n);
    for (size_t i = 0; i < n; i++) {
        FUZZ_CHECK(x.coll.items[i].label >= 0 && (size_t)x.coll.items[i].label < x.coll.nclasses);
        FUZZ_CHECK(x.k == 0 || x.nb_idx[i * x.k] == i);
    }
    unsigned char *buf = NULL;
    size_t len = 0;
    if (index_serialize(&x, &buf, &len) == 0) {
        tool_index y;
        FUZZ_CHECK(index_parse(buf, len, &y, msg, sizeof msg) == 0);
        FUZZ_CHECK(y.coll.n == n && y.k == x.k && y.coll.nclasses == x.coll.nclasses);
        index_free(&y);
        free(buf);
    }
    index_free(&x);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one(data, size);
    if (size >= 24) {
        uint8_t *fixed = malloc(size);
        if (fixed == NULL)
            return 0;
        memcpy(fixed, data, size);
        uint64_t h = index_checksum(fixed, size - 8);
        for (int i = 0; i < 8; i++)
            fixed[size - 8 + (size_t)i] = (uint8_t)(h >> (8 * i));
        one(fixed, size);
        free(fixed);
    }
    return 0;
}
