/* fuzz_index.c — the index loader (amscr_index_load_memory) on arbitrary bytes, as given and
 * with the trailing checksum made right (so the sections behind it are reached: the channel
 * features of a version 4 file too). Properties
 * on success: neighbour lists start with the shape itself and stay in range, the collection
 * loader reads the same bytes to the same collection, and the index serializes into bytes
 * that load again to the same counts. On failure: a detail. */
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "db_io.h"
#include "fuzz_common.h"

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
        uint32_t version = (uint32_t)fixed[8] | (uint32_t)fixed[9] << 8 | (uint32_t)fixed[10] << 16 |
                           (uint32_t)fixed[11] << 24;
        uint64_t h = amscr__db_checksum(version, fixed, size - 8); /* FNV-1a, or from version 4 sum64 */
        for (int i = 0; i < 8; i++)
            fixed[size - 8 + (size_t)i] = (uint8_t)(h >> (8 * i));
        one(fixed, size);
        free(fixed);
    }
    return 0;
}
