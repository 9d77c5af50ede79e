/* folds_tsv.c — mpeg7-dev's class folds (folds.tsv beside its manifest), for the ablation,
 * which scores fold A and fold B as collections of their own. */
#include <stdio.h>
#include <string.h>

#include "folds_tsv.h"
#include "collection.h"

/* Fold (0 A, 1 B) of every class of the manifest from folds.tsv beside it; -1 without it. */
int folds_tsv_read(const char *manifest, int32_t *fold_of_class, size_t cap)
{
    char path[4096], line[256];
    collection col;
    snprintf(path, sizeof path, "%.*s/folds.tsv", (int)(strrchr(manifest, '/') - manifest), manifest);
    FILE *f = fopen(path, "r");
    if (!f || collection_open(manifest, &col) != 0) {
        if (f)
            fclose(f);
        return -1;
    }
    for (size_t k = 0; k < cap; k++)
        fold_of_class[k] = 0;
    while (fgets(line, sizeof line, f)) {
        char *tab = strchr(line, '\t');
        if (!tab)
            continue;
        *tab = '\0';
        for (size_t k = 0; k < col.nclasses && k < cap; k++)
            if (strcmp(col.classes[k], line) == 0)
                fold_of_class[k] = tab[1] == 'B';
    }
    fclose(f);
    collection_free(&col);
    return 0;
}
