/* protocols.c — the evaluation protocols on a distance matrix (docs/method.md §4 and
 * docs/collections.md): the class list, per-class leave-one-out scores, the seeded per-class
 * random split, leave one group out and the precision-recall curve. Ranking as in scores.c:
 * distance ascending, ties to the lower index; +inf is allowed, NaN and -inf are refused.
 * Classes (and groups) are the distinct label values in ascending order; every per-class
 * output is indexed by that order. */
#include "rank.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The distinct values of n labels, ascending, their counts, and each item's dense id. */
typedef struct pt_classes {
    int32_t *values; /* nclasses distinct labels, ascending */
    size_t *sizes;   /* nclasses counts */
    size_t *id;      /* n ids in 0..nclasses-1 */
    size_t nclasses;
} pt_classes;

static void pt_classes_free(pt_classes *c)
{
    free(c->values);
    free(c->sizes);
    free(c->id);
    memset(c, 0, sizeof *c);
}

static int pt_cmp_i32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

/* Fills c from labels[0..n-1] (n >= 1). AMSCR_E_NOMEM with a detail naming fn. */
static amscr_status pt_classes_build(const char *fn, const int32_t *labels, size_t n, pt_classes *c)
{
    memset(c, 0, sizeof *c);
    c->values = amscr__malloc_array(n, sizeof *c->values);
    c->sizes = amscr__calloc_array(n, sizeof *c->sizes);
    c->id = amscr__malloc_array(n, sizeof *c->id);
    if (!c->values || !c->sizes || !c->id) {
        pt_classes_free(c);
        return amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (n = %zu)", fn, n);
    }
    memcpy(c->values, labels, n * sizeof *labels);
    qsort(c->values, n, sizeof *c->values, pt_cmp_i32);
    size_t m = 0;
    for (size_t i = 0; i < n; i++)
        if (m == 0 || c->values[i] != c->values[m - 1])
            c->values[m++] = c->values[i];
    c->nclasses = m;
    for (size_t i = 0; i < n; i++) {
        const int32_t *hit = bsearch(&labels[i], c->values, m, sizeof *c->values, pt_cmp_i32);
        c->id[i] = (size_t)(hit - c->values);
        c->sizes[c->id[i]]++;
    }
    return AMSCR_OK;
}

/* Checks an n x n matrix: its size, and no NaN or -inf. */
static amscr_status pt_check_matrix(const char *fn, const double *dist, size_t n)
{
    if (n > SIZE_MAX / sizeof(double) / n)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: matrix %zu x %zu too large", fn, n, n);
    for (size_t i = 0; i < n * n; i++)
        if (isnan(dist[i]) || dist[i] == -INFINITY)
            return amscr__fail(AMSCR_E_INVALID_ARG, "%s: distance [%zu][%zu] is %s (NaN and -inf are refused)", fn,
                               i / n, i % n, isnan(dist[i]) ? "NaN" : "-inf");
    return AMSCR_OK;
}

/* The checks every protocol shares: n >= 2, the matrix, and the class list into c. */
static amscr_status pt_begin(const char *fn, const double *dist, size_t n, const int32_t *labels, pt_classes *c)
{
    if (n < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: n = %zu < 2", fn, n);
    amscr_status st = pt_check_matrix(fn, dist, n);
    return st != AMSCR_OK ? st : pt_classes_build(fn, labels, n, c);
}

/* AMSCR_E_INVALID_ARG unless a per-class output's length equals the number of classes. */
static amscr_status pt_check_count(const char *fn, const char *what, size_t given, size_t have)
{
    if (given != have)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: %s = %zu, but the labels have %zu distinct values", fn, what,
                           given, have);
    return AMSCR_OK;
}

amscr_status amscr_score_classes(const int32_t *labels, size_t n, int32_t *out_classes, size_t *out_sizes,
                                 size_t *inout_nclasses)
{
    amscr__clear_error();
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(inout_nclasses);
    if (n == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_classes: n = 0");
    pt_classes c;
    amscr_status st = pt_classes_build("amscr_score_classes", labels, n, &c);
    if (st != AMSCR_OK)
        return st;
    if ((out_classes || out_sizes) && *inout_nclasses < c.nclasses) {
        st = amscr__fail(AMSCR_E_INVALID_ARG, "amscr_score_classes: capacity %zu < %zu classes", *inout_nclasses,
                         c.nclasses);
    } else {
        if (out_classes)
            memcpy(out_classes, c.values, c.nclasses * sizeof *out_classes);
        if (out_sizes)
            memcpy(out_sizes, c.sizes, c.nclasses * sizeof *out_sizes);
        *inout_nclasses = c.nclasses;
    }
    pt_classes_free(&c);
    return st;
}

amscr_status amscr_score_per_class(const double *dist, size_t n, const int32_t *labels, size_t nclasses,
                                   double *out_bullseye, double *out_nn_accuracy)
{
    static const char fn[] = "amscr_score_per_class";
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    if (!out_bullseye && !out_nn_accuracy)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: out_bullseye and out_nn_accuracy are both NULL", fn);
    pt_classes c;
    amscr_status st = pt_begin(fn, dist, n, labels, &c);
    if (st != AMSCR_OK)
        return st;
    size_t *idx = amscr__malloc_array(n, sizeof *idx), *nn = amscr__calloc_array(c.nclasses, sizeof *nn);
    double *be = amscr__calloc_array(c.nclasses, sizeof *be);
    if ((st = pt_check_count(fn, "nclasses", nclasses, c.nclasses)) != AMSCR_OK)
        goto done;
    if (!idx || !nn || !be) {
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (n = %zu)", fn, n);
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        size_t k = c.id[i], w = 2 * c.sizes[k] < n ? 2 * c.sizes[k] : n, hits = 0;
        nn[k] += labels[amscr__rank_argmin(dist + i * n, n, i)] == labels[i];
        if (!out_bullseye)
            continue;
        amscr__rank_select(dist + i * n, NULL, n, w, SIZE_MAX, idx);
        for (size_t t = 0; t < w; t++)
            hits += labels[idx[t]] == labels[i];
        be[k] += (double)hits;
    }
    for (size_t k = 0; k < c.nclasses; k++) {
        if (out_nn_accuracy)
            out_nn_accuracy[k] = (double)nn[k] / (double)c.sizes[k];
        if (out_bullseye)
            out_bullseye[k] = be[k] / ((double)c.sizes[k] * (double)c.sizes[k]);
    }
done:
    free(idx);
    free(nn);
    free(be);
    pt_classes_free(&c);
    return st;
}

/* splitmix64 (Steele, Lea and Flood, OOPSLA 2014): the seeded generator of the random split,
 * the same sequence on every platform. */
static uint64_t pt_next_random(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* One split: class by class (ascending label), `train` of the class's members (in index
 * order) drawn by a partial Fisher-Yates shuffle get is_test 0, every other item 1. */
static void pt_draw_split(const pt_classes *c, size_t n, size_t train, uint64_t *rng, size_t *members,
                          unsigned char *is_test)
{
    memset(is_test, 1, n);
    for (size_t k = 0; k < c->nclasses; k++) {
        size_t m = 0;
        for (size_t i = 0; i < n; i++)
            if (c->id[i] == k)
                members[m++] = i;
        for (size_t t = 0; t < train && t < m; t++) {
            size_t r = t + (size_t)(pt_next_random(rng) % (uint64_t)(m - t)); /* modulo bias < m / 2^64 */
            size_t tmp = members[t];
            members[t] = members[r];
            members[r] = tmp;
            is_test[members[t]] = 0;
        }
    }
}

/* 1-NN of every item with is_test 1 against those with is_test 0 (ties to the lower index):
 * per class, tested[k] and correct[k] grow; returns the number of correct items. `train` is
 * scratch for n indices. */
static size_t pt_nn_subset(const double *dist, size_t n, const pt_classes *c, const unsigned char *is_test,
                           size_t *train, size_t *tested, size_t *correct)
{
    size_t ntr = 0, right = 0;
    for (size_t j = 0; j < n; j++)
        if (!is_test[j])
            train[ntr++] = j;
    for (size_t i = 0; i < n; i++) {
        if (!is_test[i] || ntr == 0)
            continue;
        const double *row = dist + i * n;
        size_t best = train[0];
        for (size_t b = 1; b < ntr; b++)
            if (row[train[b]] < row[best])
                best = train[b];
        size_t k = c->id[i], ok = c->id[best] == k;
        tested[k]++;
        correct[k] += ok;
        right += ok;
    }
    return right;
}

/* The split protocol's arguments beyond the matrix (checked by the caller). */
typedef struct pt_split_args {
    size_t train, splits;
    uint64_t seed;
} pt_split_args;

/* The splits: acc[r] each split's accuracy, cls[k] each class's accuracy averaged over them. */
static amscr_status pt_run_splits(const double *dist, size_t n, const pt_classes *c, const pt_split_args *a,
                                  double *acc, double *cls)
{
    size_t nc = c->nclasses, *members = amscr__malloc_array(n, sizeof *members);
    size_t *train = amscr__malloc_array(n, sizeof *train), *tested = amscr__malloc_array(nc, sizeof *tested);
    size_t *correct = amscr__malloc_array(nc, sizeof *correct);
    unsigned char *is_test = amscr__malloc_array(n, 1);
    amscr_status st = AMSCR_OK;
    uint64_t rng = a->seed;
    if (!members || !train || !tested || !correct || !is_test) {
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_score_nn_random_split: out of memory (n = %zu)", n);
        goto done;
    }
    for (size_t k = 0; k < nc; k++)
        cls[k] = 0.0;
    for (size_t r = 0; r < a->splits; r++) {
        memset(tested, 0, nc * sizeof *tested);
        memset(correct, 0, nc * sizeof *correct);
        pt_draw_split(c, n, a->train, &rng, members, is_test);
        size_t right = pt_nn_subset(dist, n, c, is_test, train, tested, correct), ntest = 0;
        for (size_t k = 0; k < nc; k++) {
            cls[k] += (double)correct[k] / (double)tested[k] / (double)a->splits;
            ntest += tested[k];
        }
        acc[r] = (double)right / (double)ntest;
    }
done:
    free(members);
    free(train);
    free(tested);
    free(correct);
    free(is_test);
    return st;
}

/* AMSCR_E_INVALID_ARG unless 1 <= train < every class's size and splits >= 1. */
static amscr_status pt_check_split(const pt_classes *c, const pt_split_args *a)
{
    static const char fn[] = "amscr_score_nn_random_split";
    if (a->train == 0 || a->splits == 0)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: train = %zu and splits = %zu must be >= 1", fn, a->train,
                           a->splits);
    size_t worst = 0;
    for (size_t k = 1; k < c->nclasses; k++)
        if (c->sizes[k] < c->sizes[worst])
            worst = k;
    if (a->train >= c->sizes[worst])
        return amscr__fail(AMSCR_E_INVALID_ARG,
                           "%s: train = %zu leaves no shape to test in class %ld (%zu shapes); use train <= %zu", fn,
                           a->train, (long)c->values[worst], c->sizes[worst], c->sizes[worst] - 1);
    return AMSCR_OK;
}

amscr_status amscr_score_nn_random_split(const double *dist, size_t n, const int32_t *labels, size_t train,
                                         size_t splits, uint64_t seed, size_t nclasses, double *out_mean,
                                         double *out_std, double *out_accuracies, double *out_class_accuracy)
{
    static const char fn[] = "amscr_score_nn_random_split";
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(out_mean);
    pt_split_args a = {train, splits, seed};
    pt_classes c;
    amscr_status st = pt_begin(fn, dist, n, labels, &c);
    if (st != AMSCR_OK)
        return st;
    double *acc = amscr__malloc_array(splits, sizeof *acc), *cls = amscr__malloc_array(c.nclasses, sizeof *cls);
    if ((st = pt_check_split(&c, &a)) != AMSCR_OK)
        goto done;
    if (out_class_accuracy && (st = pt_check_count(fn, "nclasses", nclasses, c.nclasses)) != AMSCR_OK)
        goto done;
    if (!acc || !cls) {
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (splits = %zu)", fn, splits);
        goto done;
    }
    if ((st = pt_run_splits(dist, n, &c, &a, acc, cls)) != AMSCR_OK)
        goto done;
    double sum = 0.0, sq = 0.0;
    for (size_t r = 0; r < splits; r++)
        sum += acc[r];
    double mean = sum / (double)splits;
    for (size_t r = 0; r < splits; r++)
        sq += (acc[r] - mean) * (acc[r] - mean);
    *out_mean = mean;
    if (out_std)
        *out_std = splits > 1 ? sqrt(sq / (double)(splits - 1)) : 0.0;
    if (out_accuracies)
        memcpy(out_accuracies, acc, splits * sizeof *acc);
    if (out_class_accuracy)
        memcpy(out_class_accuracy, cls, c.nclasses * sizeof *cls);
done:
    free(acc);
    free(cls);
    pt_classes_free(&c);
    return st;
}

/* Leave one group out over the dense group ids of gr: correct[k] the correct items of class k,
 * group_correct[g] those of group g. */
static amscr_status pt_run_groups(const double *dist, size_t n, const pt_classes *c, const pt_classes *gr,
                                  size_t *correct, size_t *group_correct)
{
    size_t *train = amscr__malloc_array(n, sizeof *train), *tested = amscr__calloc_array(c->nclasses, sizeof *tested);
    unsigned char *is_test = amscr__malloc_array(n, 1);
    amscr_status st = AMSCR_OK;
    if (!train || !tested || !is_test) {
        st = amscr__fail(AMSCR_E_NOMEM, "amscr_score_nn_groups: out of memory (n = %zu)", n);
        goto done;
    }
    for (size_t g = 0; g < gr->nclasses; g++) {
        for (size_t i = 0; i < n; i++)
            is_test[i] = gr->id[i] == g;
        group_correct[g] = pt_nn_subset(dist, n, c, is_test, train, tested, correct);
    }
done:
    free(train);
    free(tested);
    free(is_test);
    return st;
}

amscr_status amscr_score_nn_groups(const double *dist, size_t n, const int32_t *labels, const int32_t *groups,
                                   size_t ngroups, size_t nclasses, double *out_accuracy, double *out_group_accuracy,
                                   double *out_class_accuracy)
{
    static const char fn[] = "amscr_score_nn_groups";
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(groups);
    AMSCR_CHECK_NULL(out_accuracy);
    pt_classes c, gr;
    memset(&gr, 0, sizeof gr);
    amscr_status st = pt_begin(fn, dist, n, labels, &c);
    if (st != AMSCR_OK)
        return st;
    if ((st = pt_classes_build(fn, groups, n, &gr)) != AMSCR_OK)
        goto done;
    if (gr.nclasses < 2) {
        st = amscr__fail(AMSCR_E_INVALID_ARG, "%s: needs at least 2 groups, found 1 (%ld)", fn, (long)gr.values[0]);
        goto done;
    }
    if (out_group_accuracy && (st = pt_check_count(fn, "ngroups", ngroups, gr.nclasses)) != AMSCR_OK)
        goto done;
    if (out_class_accuracy && (st = pt_check_count(fn, "nclasses", nclasses, c.nclasses)) != AMSCR_OK)
        goto done;
    size_t *correct = amscr__calloc_array(c.nclasses, sizeof *correct);
    size_t *gcorrect = amscr__calloc_array(gr.nclasses, sizeof *gcorrect);
    if (!correct || !gcorrect)
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (n = %zu)", fn, n);
    else
        st = pt_run_groups(dist, n, &c, &gr, correct, gcorrect);
    if (st == AMSCR_OK) {
        size_t total = 0;
        for (size_t k = 0; k < c.nclasses; k++) {
            total += correct[k];
            if (out_class_accuracy)
                out_class_accuracy[k] = (double)correct[k] / (double)c.sizes[k];
        }
        for (size_t g = 0; out_group_accuracy && g < gr.nclasses; g++)
            out_group_accuracy[g] = (double)gcorrect[g] / (double)gr.sizes[g];
        *out_accuracy = (double)total / (double)n;
    }
    free(correct);
    free(gcorrect);
done:
    pt_classes_free(&c);
    pt_classes_free(&gr);
    return st;
}

/* One query's interpolated precision (the best precision at any recall >= the level) at the
 * recall levels l / (nlevels - 1), added to acc[]; best[] is scratch for nlevels values. */
static void pt_query_pr(const int32_t *labels, size_t i, const size_t *order, size_t m, size_t relevant,
                        size_t nlevels, double *best, double *acc)
{
    for (size_t l = 0; l < nlevels; l++)
        best[l] = 0.0;
    size_t hits = 0;
    for (size_t r = 0; r < m && hits < relevant; r++) {
        if (labels[order[r]] != labels[i])
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

amscr_status amscr_score_precision_recall(const double *dist, size_t n, const int32_t *labels, size_t nlevels,
                                          double *out_precision)
{
    static const char fn[] = "amscr_score_precision_recall";
    amscr__clear_error();
    AMSCR_CHECK_NULL(dist);
    AMSCR_CHECK_NULL(labels);
    AMSCR_CHECK_NULL(out_precision);
    if (nlevels < 2)
        return amscr__fail(AMSCR_E_INVALID_ARG, "%s: nlevels = %zu < 2", fn, nlevels);
    pt_classes c;
    amscr_status st = pt_begin(fn, dist, n, labels, &c);
    if (st != AMSCR_OK)
        return st;
    size_t *order = amscr__malloc_array(n, sizeof *order), queries = 0;
    double *acc = amscr__calloc_array(nlevels, 2 * sizeof *acc);
    if (!order || !acc) {
        st = amscr__fail(AMSCR_E_NOMEM, "%s: out of memory (n = %zu, nlevels = %zu)", fn, n, nlevels);
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        size_t relevant = c.sizes[c.id[i]] - 1;
        if (relevant == 0)
            continue;
        amscr__rank_select(dist + i * n, NULL, n, n - 1, i, order);
        pt_query_pr(labels, i, order, n - 1, relevant, nlevels, acc + nlevels, acc);
        queries++;
    }
    for (size_t l = 0; l < nlevels; l++)
        out_precision[l] = queries ? acc[l] / (double)queries : NAN;
done:
    free(order);
    free(acc);
    pt_classes_free(&c);
    return st;
}
