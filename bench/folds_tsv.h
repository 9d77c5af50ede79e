/* folds_tsv.h — mpeg7-dev's class folds (folds_tsv.c). */
#ifndef AMSCR_BENCH_FOLDS_TSV_H
#define AMSCR_BENCH_FOLDS_TSV_H
#include <stddef.h>
#include <stdint.h>

/* fold_of_class[k] (0 fold A, 1 fold B) for every class k of the manifest (in the manifest's
 * class order, k < cap), from folds.tsv beside it: 0, or -1 without it. */
int folds_tsv_read(const char *manifest, int32_t *fold_of_class, size_t cap);

#endif
