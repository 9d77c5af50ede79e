/* bytes.h — little-endian writing into a growing buffer and bounds-checked reading, whatever
 * the host (bytes.c): the collection and index files. Never installed. */
#ifndef AMSCR_BYTES_H
#define AMSCR_BYTES_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    unsigned char *buf;
    size_t len, cap;
    int oom; /* an allocation failed: every later write is dropped */
} amscr__wbuf;

void amscr__w_bytes(amscr__wbuf *w, const void *p, size_t n);
void amscr__w_u32(amscr__wbuf *w, uint32_t v);
void amscr__w_u64(amscr__wbuf *w, uint64_t v);
void amscr__w_f64(amscr__wbuf *w, double d);
void amscr__w_f64s(amscr__wbuf *w, const double *d, size_t n);
/* n floats, 4 bytes each (IEEE single, little-endian). */
void amscr__w_f32s(amscr__wbuf *w, const float *d, size_t n);
/* A string: u32 length, then its bytes (NULL: length 0xffffffff, no bytes). */
void amscr__w_str(amscr__wbuf *w, const char *s);

typedef struct {
    const unsigned char *p;
    size_t len, pos;
    int bad; /* a read ran past the end or found a bad value: every later read gives 0 */
} amscr__rbuf;

uint32_t amscr__r_u32(amscr__rbuf *r);
uint64_t amscr__r_u64(amscr__rbuf *r);
double amscr__r_f64(amscr__rbuf *r);
/* n finite doubles into d; 0 (and r->bad) when short or one is not finite. */
int amscr__r_f64s(amscr__rbuf *r, double *d, size_t n);
/* n finite floats (4 bytes each) into d; 0 (and r->bad) when short or one is not finite. */
int amscr__r_f32s(amscr__rbuf *r, float *d, size_t n);
/* A string written by amscr__w_str into a new malloc'ed one (*out NULL for a NULL string);
 * 0 when short, not NUL-free or out of memory (*oom set). */
int amscr__r_str(amscr__rbuf *r, char **out, int *oom);

/* FNV-1a 64 of n bytes: the trailing checksum of collection files and of index files before
 * format version 4. Its offset basis is 1469598103934665603 (a digit short of FNV's published
 * 14695981039346656037): kept, since every file written so far carries it; a checksum made with
 * the published basis does not match. */
uint64_t amscr__fnv1a(const unsigned char *p, size_t n);
/* The trailing checksum of index files from format version 4: four lanes of 64-bit
 * little-endian words, each lane h = (h ^ word) * 0x9E3779B97F4A7C15, h ^= h >> 29 (one-to-one:
 * a changed word always changes its lane), the lanes folded into one value with the length,
 * the last n mod 32 bytes as FNV-1a. Several bytes a cycle where FNV-1a takes several cycles a
 * byte (a 50 MB index file: ~5 ms instead of ~70 ms). */
uint64_t amscr__sum64(const unsigned char *p, size_t n);

#endif
