/* index_add.c — `amscr index COLLECTION -o FILE --add`: new shapes prepared and appended;
 * the old ones are not prepared again and their distances among themselves not recomputed
 * (only old x new and new x new pairs are matched, under the index's base distance with the
 * medians of its build: index_dist.h). */
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "index_build.h"
#include "shape_db.h"

/* The index of name in names (appended when new); -1 on out of memory. */
static int32_t name_find_add(char ***names, size_t *n, const char *name)
{
    for (size_t i = 0; i < *n; i++)
        if (strcmp((*names)[i], name) == 0)
            return (int32_t)i;
    char **p = realloc(*names, (*n + 1) * sizeof *p);
    char *s = xstrdup(name);
    if (p == NULL || s == NULL) {
        if (p)
            *names = p;
        free(s);
        tool_error(NULL, "out of memory");
        return -1;
    }
    *names = p;
    p[*n] = s;
    return (int32_t)(*n)++;
}

/* Maps the new collection's labels and groups into the index's lists, appends its items, and
 * checks names and group columns. */
static int merge_names(const char *ipath, tool_index *x, collection *c)
{
    collection *ic = &x->coll;
    if ((ic->ngroups > 0) != (c->ngroups > 0)) {
        tool_error(ipath, "the index %s a group column and the new shapes' manifest %s", ic->ngroups ? "has" : "has no",
                   c->ngroups ? "has one" : "has none");
        return TOOL_EXIT_FAIL;
    }
    for (size_t i = 0; i < c->n; i++)
        for (size_t j = 0; j < ic->n; j++)
            if (strcmp(c->items[i].name, ic->items[j].name) == 0) {
                tool_error(ipath, "'%s' is already in the index", c->items[i].name);
                return TOOL_EXIT_FAIL;
            }
    coll_item *it = realloc(ic->items, (ic->n + c->n) * sizeof *it);
    if (it == NULL) {
        tool_error(NULL, "out of memory");
        return TOOL_EXIT_FAIL;
    }
    ic->items = it;
    for (size_t i = 0; i < c->n; i++) {
        coll_item *ni = &c->items[i];
        int32_t l = name_find_add(&ic->classes, &ic->nclasses, c->classes[ni->label]);
        int32_t g = ni->group >= 0 ? name_find_add(&ic->groups, &ic->ngroups, c->groups[ni->group]) : -1;
        char *name = xstrdup(ni->name);
        if (l < 0 || (ni->group >= 0 && g < 0) || name == NULL) {
            free(name);
            return TOOL_EXIT_FAIL;
        }
        ni->label = l; /* the new db is prepared with the index's labels */
        ic->items[ic->n++] = (coll_item){name, xstrdup(name), l, g};
    }
    return 0;
}

/* Neighbour lists of all N shapes from the old lists and the base distances a[in*N + j] of
 * new shape in and shape j (index_dist.h). An index smaller than its K (every shape in
 * every list, so nothing is unknown) grows its lists up to want_k. */
static int merge_knn(tool_index *x, size_t nold, size_t want_k, const double *a)
{
    size_t N = x->coll.n, nn = N - nold, kold = x->k;
    size_t k = kold == nold && want_k > kold ? (want_k < N ? want_k : N) : kold;
    uint32_t *idx = xmalloc_array(N * k > 0 ? N * k : 1, sizeof *idx);
    double *dist = xmalloc_array(N * k > 0 ? N * k : 1, sizeof *dist), *cd = xmalloc_array(N + kold, sizeof(double));
    size_t *cj = xmalloc_array(N + kold, sizeof(size_t));
    int ok = idx && dist && cd && cj;
    for (size_t i = 0; ok && i < N; i++) {
        size_t m = 0;
        if (i < nold) { /* its old list and the new shapes */
            for (size_t t = 0; t < kold; t++)
                cj[m] = x->nb_idx[i * kold + t], cd[m++] = x->nb_dist[i * kold + t];
            for (size_t jn = 0; jn < nn; jn++)
                cj[m] = nold + jn, cd[m++] = a[jn * N + i];
        } else {
            for (size_t j = 0; j < N; j++)
                cj[m] = j, cd[m++] = j == i ? 0.0 : a[(i - nold) * N + j];
        }
        for (size_t t = 0; t < m; t++)
            if (cd[t] > x->dmax)
                x->dmax = cd[t];
        if (k > 0)
            knn_select(i, cj, cd, m, k, idx + i * k, dist + i * k);
    }
    free(cd);
    free(cj);
    if (!ok) {
        free(idx);
        free(dist);
        return -1;
    }
    free(x->nb_idx);
    free(x->nb_dist);
    x->nb_idx = idx;
    x->nb_dist = dist;
    x->k = k;
    return 0;
}

/* The base distances a[in*N + j] of each new shape in (index nold + in) and every shape j
 * of the index (the new ones already appended to x->db), lower index first. */
static int cross(const tool_index *x, size_t nold, const amscr_params *p, double **a)
{
    size_t N = amscr_db_size(x->db), nn = N - nold;
    base_dist b = {p, amscr_params_get_channel_weight(p), x->med_a, x->med_h};
    amscr_workspace *ws = NULL;
    *a = xmalloc_array(nn * N > 0 ? nn * N : 1, sizeof(double));
    amscr_status st = *a ? amscr_workspace_new(&ws) : AMSCR_E_NOMEM;
    tool_progress pr;
    progress_init(&pr, "matching new shapes");
    for (size_t in = 0; st == AMSCR_OK && in < nn; in++) {
        size_t i = nold + in;
        const amscr_descriptor *di = amscr_db_descriptor(x->db, i);
        for (size_t j = 0; st == AMSCR_OK && j < N; j++) {
            const amscr_descriptor *dj = amscr_db_descriptor(x->db, j);
            (*a)[in * N + j] = 0.0;
            if (j < i)
                st = base_pair(&b, dj, di, ws, &(*a)[in * N + j]);
            else if (j > i)
                st = base_pair(&b, di, dj, ws, &(*a)[in * N + j]);
        }
        progress_update(&pr, in + 1, nn);
    }
    progress_end(&pr);
    amscr_workspace_free(ws);
    if (st != AMSCR_OK) {
        tool_lib_error("index", st);
        return -1;
    }
    return 0;
}

int index_add(const opts *o, tool_index *x, collection *c)
{
    amscr_params *p = NULL;
    int r = index_params(o, o->out, x, &p);
    if (r != 0)
        return r;
    if (o->threshold != TOOL_THRESHOLD_DEFAULT && o->threshold != x->threshold) {
        amscr_params_free(p);
        return usage_error("--threshold", "the index '%s' traced its images with another threshold", o->out);
    }
    size_t nold = x->coll.n;
    amscr_db *dnew = NULL;
    double *a = NULL;
    r = merge_names(o->out, x, c);
    if (r == 0 && load_db(p, c, x->threshold, &dnew) != 0)
        r = TOOL_EXIT_FAIL;
    for (size_t i = 0; r == 0 && i < amscr_db_size(dnew); i++)
        if (amscr_db_add_descriptor(x->db, amscr_db_descriptor(dnew, i), amscr_db_label(dnew, i), NULL) != AMSCR_OK) {
            tool_lib_error(o->out, AMSCR_E_NOMEM);
            r = TOOL_EXIT_FAIL;
        }
    size_t want_k = amscr_params_get_rerank_k(amscr_db_params(x->db)); /* as built */
    if (r == 0 && (index_signatures_from(x, nold) != 0 || cross(x, nold, p, &a) != 0 || merge_knn(x, nold, want_k, a) != 0))
        r = TOOL_EXIT_FAIL;
    free(a);
    amscr_db_free(dnew);
    amscr_params_free(p);
    return r;
}
