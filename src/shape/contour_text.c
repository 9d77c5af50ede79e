/* contour_text.c — text point lists: reading, parsing from memory, atomic writing.
 *
 * Written through amscr__file_write_atomic (file_io.c): the whole list or nothing.
 *
 * Format: one point per line, "x y", "x,y", "x, y" or tab-separated; '#' starts a
 * comment anywhere on a line; blank lines are ignored; CRLF line ends are accepted; a UTF-8
 * byte order mark before the first line (Excel's and Notepad's text exports) is skipped.
 * Numbers are read with strtod and written with "%.17g" in the "C" locale whatever locale the
 * program set (c_numeric.c: the decimal point is always '.'), and must be finite. */
#include "internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Horizontal white space inside a line ('\r' included so CRLF and stray CRs pass). */
static int ct_is_space(char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\v' || ch == '\f'; }

/* Parses one line [s, e) (NUL at *e is guaranteed by the caller).
 * Returns 1 when it holds a point (written to p), 0 when it is blank or a comment,
 * -1 when it is malformed, -2 when it holds two numbers of which one is not finite (NaN,
 * infinity, or beyond the range of a double). */
static int ct_parse_line(char *s, char *e, double p[2])
{
    for (char *q = s; q < e; q++)
        if (*q == '#') {
            e = q;
            break;
        }
    while (s < e && ct_is_space(*s))
        s++;
    while (e > s && ct_is_space(e[-1]))
        e--;
    if (s == e)
        return 0;
    char saved = *e;
    *e = '\0'; /* strtod must not run past the line (the comment or trailing blanks) */
    int ok = 0;
    char *end = NULL;
    double x = strtod(s, &end);
    if (end != s && end < e) {
        char *q = end;
        int sep = 0;
        while (q < e && ct_is_space(*q)) {
            q++;
            sep = 1;
        }
        if (q < e && *q == ',') {
            q++;
            sep = 1;
            while (q < e && ct_is_space(*q))
                q++;
        }
        /* A separator (blanks and/or one comma) is required, and the second number must
         * follow it: "1-2", "1,,2" and "1, ,2" are rejected. */
        if (sep && q < e && !ct_is_space(*q) && *q != ',') {
            char *end2 = NULL;
            double y = strtod(q, &end2);
            if (end2 != q && end2 == e) {
                p[0] = x;
                p[1] = y;
                ok = isfinite(x) && isfinite(y) ? 1 : -2;
            }
        }
    }
    *e = saved;
    return ok ? ok : -1;
}

/* Parses a NUL-terminated, writable buffer of len bytes (the NUL at buf[len] is extra) in the
 * calling thread's locale. `path` names the source in details ("path:line"); NULL gives "line N". */
static amscr_status ct_parse_points(char *buf, size_t len, const char *path, amscr_contour **out)
{
    double *xy = NULL;
    size_t n = 0, cap = 0;
    size_t line = 0;
    char *p = buf, *end = buf + len;
    if (len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0)
        p += 3;
    while (p < end) {
        char *nl = memchr(p, '\n', (size_t)(end - p));
        char *le = nl ? nl : end;
        line++;
        double pt[2];
        int r = ct_parse_line(p, le, pt);
        if (r < 0) {
            const char *what = r == -1 ? "expected 2 numbers" : "a coordinate is not a finite number";
            free(xy);
            if (path)
                return amscr__fail(AMSCR_E_FORMAT, "%s:%zu: %s", path, line, what);
            return amscr__fail(AMSCR_E_FORMAT, "line %zu: %s", line, what);
        }
        if (r > 0) {
            if (n >= AMSCR_MAX_POINTS) {
                free(xy);
                if (path)
                    return amscr__fail(AMSCR_E_LIMIT, "%s:%zu: more than %u points", path, line,
                                       (unsigned)AMSCR_MAX_POINTS);
                return amscr__fail(AMSCR_E_LIMIT, "line %zu: more than %u points", line,
                                   (unsigned)AMSCR_MAX_POINTS);
            }
            if (n == cap) {
                size_t ncap = cap ? 2 * cap : 256;
                if (ncap > AMSCR_MAX_POINTS)
                    ncap = AMSCR_MAX_POINTS;
                double *nxy = realloc(xy, ncap * 2 * sizeof *nxy);
                if (!nxy) {
                    free(xy);
                    return amscr__fail(AMSCR_E_NOMEM, "contour text: out of memory (%zu points)", ncap);
                }
                xy = nxy;
                cap = ncap;
            }
            xy[2 * n] = pt[0];
            xy[2 * n + 1] = pt[1];
            n++;
        }
        if (!nl)
            break;
        p = nl + 1;
    }
    if (n == 0) {
        free(xy);
        if (path)
            return amscr__fail(AMSCR_E_FORMAT, "%s: no points", path);
        return amscr__fail(AMSCR_E_FORMAT, "no points");
    }
    if (n < cap) { /* give back the slack; failure to shrink is harmless */
        double *nxy = realloc(xy, n * 2 * sizeof *nxy);
        if (nxy)
            xy = nxy;
    }
    /* amscr__contour_wrap takes ownership of xy (also on failure). */
    return amscr__contour_wrap(xy, n, out);
}

/* As ct_parse_points, its numbers read in the "C" locale. */
static amscr_status ct_parse_buffer(char *buf, size_t len, const char *path, amscr_contour **out)
{
    amscr__c_numeric loc;
    amscr_status st = amscr__c_numeric_enter(&loc);
    if (st != AMSCR_OK)
        return st;
    st = ct_parse_points(buf, len, path, out);
    amscr__c_numeric_leave(&loc);
    return st;
}

amscr_status amscr_contour_parse_text(const char *text, size_t len, amscr_contour **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(out);
    AMSCR_CHECK_NULL(text);
    if (len == SIZE_MAX)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_parse_text: len too large");
    char *buf = malloc(len + 1);
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_parse_text: out of memory (%zu bytes)", len);
    if (len)
        memcpy(buf, text, len);
    buf[len] = '\0';
    amscr_status st = ct_parse_buffer(buf, len, NULL, out);
    free(buf);
    return st;
}

amscr_status amscr_contour_read_text(const char *path, amscr_contour **out)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(path);
    AMSCR_CHECK_NULL(out);
    char eb[128];
    FILE *f = amscr__fopen_read(path);
    if (!f)
        return amscr__fail(AMSCR_E_IO, "%s: %s", path, amscr__errstr(errno, eb, sizeof eb));
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory", path);
    }
    for (;;) {
        if (cap - len < 2) {
            if (cap > SIZE_MAX / 2) {
                free(buf);
                fclose(f);
                return amscr__fail(AMSCR_E_LIMIT, "%s: file too large", path);
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                fclose(f);
                return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (%zu bytes)", path, cap * 2);
            }
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len - 1, f);
        len += got;
        if (got == 0) {
            if (ferror(f)) {
                int e = errno;
                free(buf);
                fclose(f);
                return amscr__fail(AMSCR_E_IO, "%s: read error: %s", path, amscr__errstr(e, eb, sizeof eb));
            }
            break;
        }
    }
    fclose(f);
    buf[len] = '\0';
    amscr_status st = ct_parse_buffer(buf, len, path, out);
    free(buf);
    return st;
}

amscr_status amscr_contour_write_text(const amscr_contour *c, const char *path)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(c);
    AMSCR_CHECK_NULL(path);
    if (c->n == 0 || c->xy == NULL)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_write_text: empty contour");
    if (!amscr__all_finite(c->xy, 2 * c->n))
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_contour_write_text: non-finite coordinate");
    enum { LINE_MAX_CHARS = 2 * 24 + 2 }; /* two %.17g numbers (at most 24 characters each), ' ', '\n' */
    char *buf = amscr__malloc_array(c->n + 1, LINE_MAX_CHARS); /* room for the last NUL */
    if (!buf)
        return amscr__fail(AMSCR_E_NOMEM, "amscr_contour_write_text: out of memory");
    amscr__c_numeric loc;
    amscr_status st = amscr__c_numeric_enter(&loc);
    if (st != AMSCR_OK) {
        free(buf);
        return st;
    }
    size_t len = 0;
    for (size_t i = 0; i < c->n; i++)
        len += (size_t)snprintf(buf + len, LINE_MAX_CHARS + 1, "%.17g %.17g\n", c->xy[2 * i], c->xy[2 * i + 1]);
    amscr__c_numeric_leave(&loc);
    st = amscr__file_write_atomic(path, buf, len); /* the file's whole text, or nothing */
    free(buf);
    return st;
}
