/* json.h — JSON printing into an sbuf for the tool's --json outputs: numbers, strings and
 * arrays of numbers. Tool-internal. */
#ifndef AMSCR_TOOL_JSON_H
#define AMSCR_TOOL_JSON_H

#include <stddef.h>

#include "util.h"

/* A finite number as the shortest of %.15g, %.16g, %.17g that reads back exactly (C99 has
 * no shortest round-trip format); 0 and -0 as "0"; non-finite as null. */
void sb_json_num(sbuf *b, double v);
/* Length of the well-formed UTF-8 sequence at p (1..4), or 0 when the byte at p does not start
 * one (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF). */
int utf8_len(const unsigned char *p);
/* Bytes of the first max_chars characters of s (a sequence that is not UTF-8 counts a
 * character a byte): a cut there splits no character. */
size_t utf8_prefix(const char *s, size_t max_chars);
/* A string, quoted and escaped. */
void sb_json_str(sbuf *b, const char *s);
/* "[v0, v1, ...]" of the n numbers v[k] (sb_json_num) whose keep[k] is non-zero; keep NULL
 * keeps every number. */
void sb_json_nums(sbuf *b, const double *v, const int *keep, size_t n);
/* "[c0, c1, ...]" of n counts. */
void sb_json_counts(sbuf *b, const size_t *c, size_t n);

#endif
