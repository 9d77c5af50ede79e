/* json.c — JSON printing for the tool (see json.h). */
#include "json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sb_json_num(sbuf *b, double v)
{
    if (!isfinite(v)) {
        sb_puts(b, "null");
        return;
    }
    if (v == 0.0) { /* also -0 */
        sb_puts(b, "0");
        return;
    }
    /* Shortest of %.15g..%.17g that reads back exactly. */
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    sb_puts(b, buf);
}

/* Length of the well-formed UTF-8 sequence at p (1..4), or 0 when the byte at p does not start
 * one (RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF). */
static int utf8_len(const unsigned char *p)
{
    unsigned c = p[0];
    if (c < 0x80)
        return 1;
    if (c >= 0xc2 && c <= 0xdf)
        return (p[1] & 0xc0) == 0x80 ? 2 : 0;
    if (c >= 0xe0 && c <= 0xef) {
        unsigned lo = c == 0xe0 ? 0xa0 : 0x80, hi = c == 0xed ? 0x9f : 0xbf;
        return p[1] >= lo && p[1] <= hi && (p[2] & 0xc0) == 0x80 ? 3 : 0;
    }
    if (c >= 0xf0 && c <= 0xf4) {
        unsigned lo = c == 0xf0 ? 0x90 : 0x80, hi = c == 0xf4 ? 0x8f : 0xbf;
        return p[1] >= lo && p[1] <= hi && (p[2] & 0xc0) == 0x80 && (p[3] & 0xc0) == 0x80 ? 4 : 0;
    }
    return 0;
}

size_t utf8_prefix(const char *s, size_t max_chars)
{
    const unsigned char *p = (const unsigned char *)s;
    size_t len = 0;
    for (size_t k = 0; k < max_chars && p[len]; k++) {
        int n = utf8_len(p + len);
        len += n > 0 ? (size_t)n : 1;
    }
    return len;
}

void sb_utf8_each(sbuf *b, const char *s, void (*byte)(sbuf *b, unsigned char c, int stray))
{
    for (const unsigned char *p = (const unsigned char *)s; p && *p;) {
        int n = utf8_len(p);
        if (n > 1) {
            char c[5] = {0};
            memcpy(c, p, (size_t)n);
            sb_puts(b, c);
            p += n;
        } else
            byte(b, *p++, n == 0);
    }
}

/* One byte of a JSON string. A stray byte (a name that is not UTF-8: a file name is bytes) is
 * the lone surrogate U+DC80+byte, Python's surrogateescape, so os.fsencode() gives the name back
 * and the output stays valid UTF-8. */
static void json_byte(sbuf *b, unsigned char c, int stray)
{
    if (stray) {
        sb_printf(b, "\\udc%02x", c);
        return;
    }
    switch (c) {
    case '"': sb_puts(b, "\\\""); break;
    case '\\': sb_puts(b, "\\\\"); break;
    case '\n': sb_puts(b, "\\n"); break;
    case '\r': sb_puts(b, "\\r"); break;
    case '\t': sb_puts(b, "\\t"); break;
    default:
        if (c < 0x20)
            sb_printf(b, "\\u%04x", c);
        else {
            char one[2] = {(char)c, 0};
            sb_puts(b, one);
        }
    }
}

void sb_json_str(sbuf *b, const char *s)
{
    sb_puts(b, "\"");
    sb_utf8_each(b, s, json_byte);
    sb_puts(b, "\"");
}

void sb_json_nums(sbuf *b, const double *v, const int *keep, size_t n)
{
    int first = 1;
    sb_puts(b, "[");
    for (size_t k = 0; k < n; k++)
        if (keep == NULL || keep[k]) {
            sb_puts(b, first ? "" : ", ");
            sb_json_num(b, v[k]);
            first = 0;
        }
    sb_puts(b, "]");
}

void sb_json_counts(sbuf *b, const size_t *c, size_t n)
{
    sb_puts(b, "[");
    for (size_t k = 0; k < n; k++)
        sb_printf(b, "%s%zu", k ? ", " : "", c[k]);
    sb_puts(b, "]");
}
