/* fuzz_index.c — the index loader (amscr_index_load_memory) on arbitrary bytes, as given and
 * with the trailing checksum made right (so the sections behind it are reached: the channel
 * features of a version 4 file too). Properties
 * on success: neighbour lists start with the shape itself and stay in range, the collection
 * loader reads the same bytes to the same collection (or calls a shape damaged that the index's
 * calls, which decode it when they read it, call damaged too), and the index serializes into bytes
 * that load again to the same counts, a quantizer's lists hold every shape once; a lazy load of the bytes mapped (as a file's: the shapes
 * checked, decoded when needed) succeeds or fails with a lazy load of the bytes as given (the
 * shapes decoded at load), to the same collection bytes. On failure: a detail. */
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS */
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "amscr.h"
#include "db_io.h"
#include "fuzz_common.h"
#include "index.h"

/* The collection file bytes of index x's collection (*len; caller frees), NULL when not saved. */
static void *collection_bytes(const amscr_index *x, size_t *len)
{
    void *buf = NULL;
    return amscr_db_save_memory(amscr_index_db(x), &buf, len) == AMSCR_OK ? buf : NULL;
}

/* data loaded lazily from a private mapping: as a lazy load of data itself. */
static void lazy_mapped(const uint8_t *data, size_t size)
{
    amscr_index *x = NULL;
    if (size == 0 || amscr_index_load_memory_with(data, size, AMSCR_INDEX_LAZY, &x) == AMSCR_E_NOMEM)
        return;
    unsigned char *m = mmap(NULL, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) {
        amscr_index_free(x);
        return;
    }
    memcpy(m, data, size);
    amscr_index *y = NULL;
    amscr_status st = amscr__index_load_mapped(m, size, AMSCR_INDEX_LAZY, &y); /* the mapping is its */
    FUZZ_CHECK((st == AMSCR_OK) == (x != NULL) || st == AMSCR_E_NOMEM);
    if (st != AMSCR_OK || !x) {
        amscr_index_free(x);
        amscr_index_free(y);
        return;
    }
    size_t la = 0, lb = 0;
    void *a = collection_bytes(x, &la), *b = collection_bytes(y, &lb);
    FUZZ_CHECK((a == NULL) == (b == NULL) && la == lb && (a == NULL || memcmp(a, b, la) == 0));
    amscr_free(a);
    amscr_free(b);
    amscr_index_free(x);
    amscr_index_free(y);
}

/* An index loaded whose collection file does not load (a shape's record passes the load's check
 * of its samples, but its smoothed levels fail, in a file whose checksum was made again): some
 * shape does not decode, and the calls that read it say the file is damaged, not out of memory. */
static void damaged_shape(const amscr_index *x, size_t n)
{
    size_t bad = n;
    for (size_t i = 0; i < n && bad == n; i++)
        if (amscr_db_descriptor(amscr_index_db(x), i) == NULL && strstr(amscr_last_error_detail(), "damaged"))
            bad = i;
    FUZZ_CHECK(bad < n);
    double *row = malloc(n * sizeof *row);
    void *buf = NULL;
    size_t len = 0;
    if (row) {
        amscr_status st = amscr_index_member_scores(x, bad, 0, row, n);
        FUZZ_CHECK(st == AMSCR_E_FORMAT || st == AMSCR_E_NOMEM);
    }
    amscr_status st = amscr_db_save_memory(amscr_index_db(x), &buf, &len);
    FUZZ_CHECK(st == AMSCR_E_FORMAT || st == AMSCR_E_NOMEM);
    free(row);
}

static void one(const uint8_t *data, size_t size)
{
    amscr_index *x = NULL;
    amscr_status st = amscr_index_load_memory(data, size, &x);
    if (st != AMSCR_OK) {
        FUZZ_CHECK(amscr_last_error_detail()[0] != '\0');
        lazy_mapped(data, size);
        return;
    }
    lazy_mapped(data, size);
    size_t n = amscr_index_size(x);
    FUZZ_CHECK(amscr_index_neighbours(x) <= n);
    /* a quantizer (version 16): every shape in one list, the lists ascending and within range */
    FUZZ_CHECK(x->ivf.nc == 0 || (x->ivf.nc <= n && x->ivf.n == n && x->ivf.start[x->ivf.nc] == n));
    for (size_t c = 0; c < x->ivf.nc; c++)
        for (size_t t = x->ivf.start[c]; t < x->ivf.start[c + 1]; t++)
            FUZZ_CHECK(x->ivf.ids[t] < n && x->ivf.cell[x->ivf.ids[t]] == c &&
                       (t == x->ivf.start[c] || x->ivf.ids[t] > x->ivf.ids[t - 1]));
    amscr_db *db = NULL;
    amscr_status dst = amscr_db_load_memory(data, size, &db);
    FUZZ_CHECK(dst == AMSCR_OK ? amscr_db_size(db) == n : dst == AMSCR_E_FORMAT || dst == AMSCR_E_NOMEM);
    amscr_db_free(db);
    if (dst == AMSCR_E_FORMAT) /* a record whose samples pass the load's check but do not decode */
        damaged_shape(x, n);
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
