/* protocols.h — the evaluation protocols of `amscr eval` beyond the library's whole-matrix
 * scores: per-class leave-one-out scores, the per-class random train/test split (Swedish
 * leaf) and leave-one-group-out (ETH-80), each a 1-NN classifier read from the full distance
 * matrix with amscr_score_nn_split. Tool-internal. */
#ifndef AMSCR_TOOL_PROTOCOLS_H
#define AMSCR_TOOL_PROTOCOLS_H

#include <stddef.h>

#include "collection.h"

/* The class sizes of c (nclasses entries, malloc'ed), or NULL after printing an error. */
size_t *class_sizes(const collection *c);

/* Per-class leave-one-out scores of the n x n matrix d: nn[c] the 1-NN accuracy of class c's
 * queries, be[c] their bull's eye (same class among the 2*Nc nearest, query included, divided
 * by Nc^2). Either may be NULL. Ties by lower index (amscr_topk). Returns 0 or -1. */
int per_class_loo(const double *d, const collection *c, double *nn, double *be);

typedef struct split_result {
    size_t train, splits;
    unsigned long long seed;
    double *acc;       /* splits entries: the accuracy of each split */
    double mean, std;  /* over the splits (std: sample standard deviation, 0 for one split) */
    double *cls;       /* nclasses entries: each class's accuracy, mean over the splits */
} split_result;

/* Per-class random split: in each of `splits` splits, `train` shapes of every class (drawn
 * with a seeded generator) are the training set, the rest are tested by 1-NN. Every class
 * needs more than `train` shapes (the caller checks: split_check). Returns 0 or -1. */
int protocol_split(const double *d, const collection *c, size_t train, size_t splits, unsigned long long seed,
                   split_result *out);
/* 0 when every class has more than `train` shapes; otherwise prints the error naming the
 * smallest such class and returns TOOL_EXIT_USAGE. */
int split_check(const collection *c, size_t train);
void split_result_free(split_result *r);

typedef struct groups_result {
    double acc;   /* all shapes, each tested with its own group left out */
    double *grp;  /* ngroups entries: each group's accuracy */
    double *cls;  /* nclasses entries */
} groups_result;

/* Leave one group out: the shapes of each group are tested by 1-NN against every shape of the
 * other groups. Needs a group column and at least two groups (the caller checks). */
int protocol_groups(const double *d, const collection *c, groups_result *out);
void groups_result_free(groups_result *r);

/* The precision-recall curve of the whole collection: each shape queries the others (its own
 * class are the relevant ones), precision interpolated at the recall levels l / (nlevels - 1),
 * l = 0..nlevels-1, averaged over the queries whose class has another shape. Returns 0 or -1. */
int pr_curve(const double *d, const collection *c, size_t nlevels, double *precision);

#endif
