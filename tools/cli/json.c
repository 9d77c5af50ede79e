/* json.c — JSON printing for the tool (see json.h). */
#include "json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

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

void sb_json_str(sbuf *b, const char *s)
{
    sb_puts(b, "\"");
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        switch (*p) {
        case '"': sb_puts(b, "\\\""); break;
        case '\\': sb_puts(b, "\\\\"); break;
        case '\n': sb_puts(b, "\\n"); break;
        case '\r': sb_puts(b, "\\r"); break;
        case '\t': sb_puts(b, "\\t"); break;
        default:
            if (*p < 0x20)
                sb_printf(b, "\\u%04x", *p);
            else {
                char c[2] = {(char)*p, 0};
                sb_puts(b, c);
            }
        }
    }
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
