/* fuzz_index.c — the index loader of `amscr index` (tools/cli/index_file.c: index_parse) on
 * arbitrary bytes, as given and with the file length and the meta section's checksum made
 * right (so the sections behind them are reached). Properties on success: at least one shape, as many prepared shapes as names,
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
    if (size >= 40) { /* the file length and the meta section's checksum made right */
        uint8_t *fixed = malloc(size);
        if (fixed == NULL)
            return 0;
        memcpy(fixed, data, size);
        uint64_t mlen = 0;
        for (int i = 7; i >= 0; i--)
            mlen = mlen << 8 | fixed[24 + i];
        for (int i = 0; i < 8; i++)
            fixed[16 + i] = (uint8_t)((uint64_t)size >> (8 * i));
        if (mlen <= size - 40) {
            uint64_t h = index_checksum(fixed + 32, (size_t)mlen);
            for (int i = 0; i < 8; i++)
                fixed[32 + mlen + (size_t)i] = (uint8_t)(h >> (8 * i));
        }
        one(fixed, size);
        free(fixed);
    }
    return 0;
}
