/* json.h — JSON printing into an sbuf for the tool's --json outputs: numbers, strings and
 * arrays of numbers. Tool-internal. */
#ifndef AMSCR_TOOL_JSON_H
#define AMSCR_TOOL_JSON_H

#include <stddef.h>

#include "util.h"

/* A finite number as the shortest of %.15g, %.16g, %.17g that reads back exactly (C99 has
 * no shortest round-trip format); 0 and -0 as "0"; non-finite as null. */
void sb_json_num(sbuf *b, double v);
/* Bytes of the first max_chars characters of s (a sequence that is not UTF-8 counts a
 * character a byte): a cut there splits no character. */
size_t utf8_prefix(const char *s, size_t max_chars);
/* Appends s to b: each well-formed multi-byte UTF-8 character as it is, each other byte through
 * byte(b, c, stray) (stray: c starts no UTF-8 sequence). s may be NULL (nothing). */
void sb_utf8_each(sbuf *b, const char *s, void (*byte)(sbuf *b, unsigned char c, int stray));
/* A string, quoted and escaped. */
void sb_json_str(sbuf *b, const char *s);
/* "[v0, v1, ...]" of the n numbers v[k] (sb_json_num) whose keep[k] is non-zero; keep NULL
 * keeps every number. */
void sb_json_nums(sbuf *b, const double *v, const int *keep, size_t n);
/* "[c0, c1, ...]" of n counts. */
void sb_json_counts(sbuf *b, const size_t *c, size_t n);

#endif
