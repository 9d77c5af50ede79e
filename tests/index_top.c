/* index_top.c — the C face of an index search, for the cross-face test
 * (bindings/python/tests/test_index_faces.py): loads an index file (amscr_index_load), prepares
 * the query (a text file of "x y" lines) with the index's params and prints its TOP best shapes
 * (amscr_index_search: a member's copy scored as the member) as JSON:
 * {"n": N, "results": [{"index": I, "file": NAME, "distance": D}]}.
 *   index_top INDEX QUERY.txt [CANDIDATES (default 0: every shape)] [TOP (default 10)] */
#include <stdio.h>
#include <stdlib.h>

#include "amscr.h"

/* The points of a text file ("x y" a line, '#' comments), malloc'ed; NULL on error. */
static double *read_points(const char *path, size_t *n)
{
    FILE *f = fopen(path, "r");
    char line[256];
    size_t cap = 0;
    double *xy = NULL;
    *n = 0;
    while (f && fgets(line, sizeof line, f)) {
        double x, y;
        if (line[0] == '#' || sscanf(line, "%lf %lf", &x, &y) != 2)
            continue;
        if (*n == cap) {
            cap = cap ? 2 * cap : 256;
            double *p = realloc(xy, 2 * cap * sizeof *p);
            if (!p)
                break;
            xy = p;
        }
        xy[2 * *n] = x;
        xy[2 * *n + 1] = y;
        (*n)++;
    }
    if (f)
        fclose(f);
    return xy;
}

static void print_str(const char *s)
{
    putchar('"');
    for (; s && *s; s++) {
        if (*s == '"' || *s == '\\')
            printf("\\%c", *s);
        else if ((unsigned char)*s < 0x20)
            printf("\\u%04x", (unsigned)(unsigned char)*s);
        else
            putchar(*s);
    }
    putchar('"');
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: index_top INDEX QUERY.txt [CANDIDATES] [TOP]\n");
        return 2;
    }
    size_t cand = argc > 3 ? strtoul(argv[3], NULL, 10) : 0, top = argc > 4 ? strtoul(argv[4], NULL, 10) : 10;
    size_t np = 0, count = 0, *idx = malloc((top ? top : 1) * sizeof *idx);
    double *xy = read_points(argv[2], &np), *scores = malloc((top ? top : 1) * sizeof *scores);
    amscr_index *x = NULL;
    amscr_contour *c = NULL;
    amscr_descriptor *q = NULL;
    amscr_status st = idx && scores && xy ? amscr_index_load(argv[1], &x) : AMSCR_E_NOMEM;
    if (st == AMSCR_OK)
        st = amscr_contour_new(xy, np, &c);
    if (st == AMSCR_OK)
        st = amscr_descriptor_new(amscr_db_params(amscr_index_db(x)), c, &q);
    if (st == AMSCR_OK)
        st = amscr_index_search(x, q, cand, top, idx, scores, &count);
    if (st == AMSCR_OK) {
        printf("{\"n\": %zu, \"results\": [", amscr_index_size(x));
        for (size_t t = 0; t < count; t++) {
            printf("%s{\"index\": %zu, \"file\": ", t ? ", " : "", idx[t]);
            print_str(amscr_index_name(x, idx[t]));
            printf(", \"distance\": %.17g}", scores[t]);
        }
        printf("]}\n");
    } else {
        fprintf(stderr, "index_top: %s: %s\n", amscr_strerror(st), amscr_last_error_detail());
    }
    amscr_descriptor_free(q);
    amscr_contour_free(c);
    amscr_index_free(x);
    free(xy);
    free(idx);
    free(scores);
    return st == AMSCR_OK ? 0 : 1;
}
