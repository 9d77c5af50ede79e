/* fuzz_index.c — the index loader (amscr_index_load_memory) on arbitrary bytes, as given and
 * with the trailing checksum made right (so the sections behind it are reached). Properties
 * on success: neighbour lists start with the shape itself and stay in range, the collection
 * loader reads the same bytes to the same collection, and the index serializes into bytes
 * that load again to the same counts. On failure: a detail. */
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "fuzz_common.h"

static uint64_t fnv1a(const uint8_t *p, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

static void one(const uint8_t *data, size_t size)
{
    amscr_index *x = NULL;
    amscr_status st = amscr_index_load_memory(data, size, &x);
    if (st != AMSCR_OK) {
        FUZZ_CHECK(amscr_last_error_detail()[0] != '\0');
        return;
    }
    size_t n = amscr_index_size(x);
    FUZZ_CHECK(amscr_index_neighbours(x) <= n);
    amscr_db *db = NULL;
    FUZZ_CHECK(amscr_db_load_memory(data, size, &db) == AMSCR_OK && amscr_db_size(db) == n);
    amscr_db_free(db);
    void *buf = NULL;
    size_t len = 0;
    if (amscr_index_save_memory(x, &buf, &len) == AMSCR_OK) {
        amscr_index *y = NULL;
        FUZZ_CHECK(amscr_index_load_memory(buf, len, &y) == AMSCR_OK);
        FUZZ_CHECK(amscr_index_size(y) == n && amscr_index_neighbours(y) == amscr_index_neighbours(x));
        for (size_t i = 0; i < n; i++) {
            const char *a = amscr_index_name(x, i), *b = amscr_index_name(y, i);
            FUZZ_CHECK((a == NULL) == (b == NULL) && (a == NULL || strcmp(a, b) == 0));
        }
        amscr_index_free(y);
        amscr_free(buf);
    }
    amscr_index_free(x);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one(data, size);
    if (size >= 24) { /* the trailing checksum made right */
        uint8_t *fixed = malloc(size);
        if (fixed == NULL)
            return 0;
        memcpy(fixed, data, size);
        uint64_t h = fnv1a(fixed, size - 8);
        for (int i = 0; i < 8; i++)
            fixed[size - 8 + (size_t)i] = (uint8_t)(h >> (8 * i));
        one(fixed, size);
        free(fixed);
    }
    return 0;
}
