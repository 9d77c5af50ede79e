/* protocols.c — per-class scores, the split and groups protocols of `amscr eval` (see
 * protocols.h). */
#include "protocols.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"

size_t *class_sizes(const collection *c)
{
    size_t *sz = xcalloc_array(c->nclasses ? c->nclasses : 1, sizeof(size_t));
    if (sz != NULL)
        for (size_t i = 0; i < c->n; i++)
            sz[c->items[i].label]++;
    return sz;
}

int per_class_loo(const double *d, const collection *c, double *nn, double *be)
{
    size_t n = c->n, *sz = class_sizes(c), *idx = xmalloc_array(n, sizeof(size_t));
    int ret = -1;
    if (sz == NULL || idx == NULL)
        goto done;
    for (size_t k = 0; k < c->nclasses; k++) {
        if (nn)
            nn[k] = 0.0;
        if (be)
            be[k] = 0.0;
    }
    for (size_t i = 0; i < n; i++) {
        int32_t l = c->items[i].label;
        size_t nc = sz[l], w = 2 * nc < n ? 2 * nc : n;
        if (nn && amscr_topk(d + i * n, n, 1, i, idx) == AMSCR_OK && c->items[idx[0]].label == l)
            nn[l] += 1.0;
        if (be && amscr_topk(d + i * n, n, w, SIZE_MAX, idx) == AMSCR_OK) {
            size_t hits = 0;
            for (size_t t = 0; t < w; t++)
                hits += c->items[idx[t]].label == l;
            be[l] += (double)hits;
        }
    }
    for (size_t k = 0; k < c->nclasses; k++) { /* counts to fractions */
        if (nn)
            nn[k] /= (double)sz[k];
        if (be)
            be[k] /= (double)sz[k] * (double)sz[k];
    }
    ret = 0;
done:
    free(sz);
    free(idx);
    return ret;
}

/* The shapes whose flag equals `want`, ordered by class (collection order within a class). */
static size_t order_by_class(const collection *c, const unsigned char *flag, int want, size_t *out)
{
    size_t m = 0;
    for (size_t k = 0; k < c->nclasses; k++)
        for (size_t i = 0; i < c->n; i++)
            if ((flag[i] != 0) == (want != 0) && c->items[i].label == (int32_t)k)
                out[m++] = i;
    return m;
}

/* 1-NN of the shapes with flag 1 (tested) against those with flag 0 (training), with
 * amscr_score_nn_split: the overall accuracy into *acc, each class's into cls[k] and its
 * number of tested shapes into tested[k] (classes without tested shapes are left alone). */
static int nn_subset(const double *d, const collection *c, const unsigned char *is_test, double *acc, double *cls,
                     size_t *tested)
{
    size_t n = c->n, *test = xmalloc_array(n, sizeof(size_t)), *train = xmalloc_array(n, sizeof(size_t));
    int32_t *tl = xmalloc_array(n, sizeof(int32_t)), *rl = xmalloc_array(n, sizeof(int32_t));
    double *sub = NULL;
    int ret = -1;
    if (!test || !train || !tl || !rl)
        goto done;
    size_t nt = order_by_class(c, is_test, 1, test), ntr = 0;
    for (size_t i = 0; i < n; i++)
        if (!is_test[i])
            train[ntr++] = i;
    if ((sub = xmalloc_array(nt * ntr > 0 ? nt * ntr : 1, sizeof(double))) == NULL)
        goto done;
    for (size_t a = 0; a < nt; a++) {
        tl[a] = c->items[test[a]].label;
        for (size_t b = 0; b < ntr; b++)
            sub[a * ntr + b] = d[test[a] * n + train[b]];
    }
    for (size_t b = 0; b < ntr; b++)
        rl[b] = c->items[train[b]].label;
    amscr_status st = amscr_score_nn_split(sub, nt, ntr, tl, rl, acc);
    for (size_t off = 0, end; st == AMSCR_OK && off < nt; off = end) {
        for (end = off; end < nt && tl[end] == tl[off]; end++)
            ;
        st = amscr_score_nn_split(sub + off * ntr, end - off, ntr, tl + off, rl, &cls[tl[off]]);
        tested[tl[off]] = end - off;
    }
    if (st != AMSCR_OK)
        tool_lib_error("eval", st);
    else
        ret = 0;
done:
    free(test);
    free(train);
    free(tl);
    free(rl);
    free(sub);
    return ret;
}

int split_check(const collection *c, size_t train)
{
    size_t *sz = class_sizes(c), worst = 0;
    if (sz == NULL)
        return TOOL_EXIT_FAIL;
    for (size_t k = 1; k < c->nclasses; k++)
        if (sz[k] < sz[worst])
            worst = k;
    int r = 0;
    if (train >= sz[worst])
        r = usage_error("--train", "%zu training shapes per class leave none to test in class '%s' (%zu shapes); "
                        "use --train %zu or less",
                        train, c->classes[worst], sz[worst], sz[worst] - 1);
    free(sz);
    return r;
}

/* splitmix64 (Steele, Lea, Flood 2014): a small seeded generator, the same on every platform. */
static uint64_t next_random(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* One split: `train` members of every class drawn at random (partial Fisher-Yates on the
 * class's members in collection order) get flag 0, the others flag 1. */
static void draw_split(const collection *c, size_t train, uint64_t *rng, size_t *members, unsigned char *is_test)
{
    memset(is_test, 1, c->n);
    for (size_t k = 0; k < c->nclasses; k++) {
        size_t m = 0;
        for (size_t i = 0; i < c->n; i++)
            if (c->items[i].label == (int32_t)k)
                members[m++] = i;
        for (size_t t = 0; t < train && t < m; t++) {
            size_t r = t + (size_t)(next_random(rng) % (uint64_t)(m - t)); /* modulo bias < m / 2^64 */
            size_t tmp = members[t];
            members[t] = members[r];
            members[r] = tmp;
            is_test[members[t]] = 0;
        }
    }
}

int protocol_split(const double *d, const collection *c, size_t train, size_t splits, unsigned long long seed,
                   split_result *out)
{
    memset(out, 0, sizeof *out);
    out->train = train;
    out->splits = splits;
    out->seed = seed;
    size_t nc = c->nclasses, *members = xmalloc_array(c->n, sizeof(size_t)), *tested = xcalloc_array(nc, sizeof(size_t));
    unsigned char *is_test = xmalloc_array(c->n, 1);
    double *cls = xmalloc_array(nc, sizeof(double));
    out->acc = xmalloc_array(splits, sizeof(double));
    out->cls = xcalloc_array(nc, sizeof(double));
    int ret = -1;
    uint64_t rng = (uint64_t)seed;
    if (!members || !tested || !is_test || !cls || !out->acc || !out->cls)
        goto done;
    double sum = 0.0, sq = 0.0;
    for (size_t r = 0; r < splits; r++) {
        draw_split(c, train, &rng, members, is_test);
        if (nn_subset(d, c, is_test, &out->acc[r], cls, tested) != 0)
            goto done;
        for (size_t k = 0; k < nc; k++)
            out->cls[k] += cls[k] / (double)splits;
        sum += out->acc[r];
    }
    out->mean = sum / (double)splits;
    for (size_t r = 0; r < splits; r++)
        sq += (out->acc[r] - out->mean) * (out->acc[r] - out->mean);
    out->std = splits > 1 ? sqrt(sq / (double)(splits - 1)) : 0.0;
    ret = 0;
done:
    free(members);
    free(tested);
    free(is_test);
    free(cls);
    return ret;
}

void split_result_free(split_result *r)
{
    free(r->acc);
    free(r->cls);
    r->acc = r->cls = NULL;
}

int protocol_groups(const double *d, const collection *c, groups_result *out)
{
    memset(out, 0, sizeof *out);
    size_t nc = c->nclasses, *tested = xcalloc_array(nc, sizeof(size_t)), *tested_all = xcalloc_array(nc, sizeof(size_t));
    unsigned char *is_test = xmalloc_array(c->n, 1);
    double *cls = xmalloc_array(nc, sizeof(double)), *correct = xcalloc_array(nc, sizeof(double));
    out->grp = xmalloc_array(c->ngroups, sizeof(double));
    out->cls = xmalloc_array(nc, sizeof(double));
    int ret = -1;
    if (!tested || !tested_all || !is_test || !cls || !correct || !out->grp || !out->cls)
        goto done;
    double total = 0.0;
    for (size_t g = 0; g < c->ngroups; g++) {
        for (size_t i = 0; i < c->n; i++)
            is_test[i] = c->items[i].group == (int32_t)g;
        memset(tested, 0, nc * sizeof *tested);
        if (nn_subset(d, c, is_test, &out->grp[g], cls, tested) != 0)
            goto done;
        for (size_t k = 0; k < nc; k++) {
            correct[k] += tested[k] ? floor(cls[k] * (double)tested[k] + 0.5) : 0.0;
            tested_all[k] += tested[k];
        }
    }
    for (size_t k = 0; k < nc; k++) {
        out->cls[k] = tested_all[k] ? correct[k] / (double)tested_all[k] : NAN;
        total += correct[k];
    }
    out->acc = total / (double)c->n;
    ret = 0;
done:
    free(tested);
    free(tested_all);
    free(is_test);
    free(cls);
    free(correct);
    return ret;
}

void groups_result_free(groups_result *r)
{
    free(r->grp);
    free(r->cls);
    r->grp = r->cls = NULL;
}

/* One query's precision at the recall levels into acc[] (interpolated: the best precision at
 * any recall >= the level). */
static void query_pr(const collection *c, size_t i, const size_t *order, size_t m, size_t relevant, double *acc,
                     size_t nlevels)
{
    double *best = acc + nlevels; /* scratch: nlevels entries */
    for (size_t l = 0; l < nlevels; l++)
        best[l] = 0.0;
    size_t hits = 0;
    for (size_t r = 0; r < m && hits < relevant; r++) {
        if (c->items[order[r]].label != c->items[i].label)
            continue;
        hits++;
        double rec = (double)hits / (double)relevant, prec = (double)hits / (double)(r + 1);
        for (size_t l = 0; l < nlevels; l++)
            if ((double)l / (double)(nlevels - 1) <= rec + 1e-12 && prec > best[l])
                best[l] = prec;
    }
    for (size_t l = 0; l < nlevels; l++)
        acc[l] += best[l];
}

int pr_curve(const double *d, const collection *c, size_t nlevels, double *precision)
{
    size_t n = c->n, *sz = class_sizes(c), *order = xmalloc_array(n, sizeof(size_t)), queries = 0;
    double *acc = xcalloc_array(2 * nlevels, sizeof(double));
    int ret = -1;
    if (sz == NULL || order == NULL || acc == NULL || n < 2)
        goto done;
    for (size_t i = 0; i < n; i++) {
        size_t relevant = sz[c->items[i].label] - 1;
        if (relevant == 0 || amscr_topk(d + i * n, n, n - 1, i, order) != AMSCR_OK)
            continue;
        query_pr(c, i, order, n - 1, relevant, acc, nlevels);
        queries++;
    }
    for (size_t l = 0; l < nlevels; l++)
        precision[l] = queries ? acc[l] / (double)queries : NAN;
    ret = 0;
done:
    free(sz);
    free(order);
    free(acc);
    return ret;
}
