/* retrieval_folds.c — the generalization audit of the retrieval default (docs/results-retrieval.md,
 * "Generalization audit (class-split folds)"): every setting of the retrieval preset swept one at a
 * time around its default, each value scored on the two class folds of mpeg7-dev (folds.tsv; each
 * fold is its own collection: bull's eye within the fold), on the whole of mpeg7-dev and on
 * Kimia-99 / Kimia-216 (top-k sums).
 *
 * A fold's matrix is the sub-matrix of mpeg7-dev's: the channel and AMSCR distances of a pair do
 * not depend on the rest of the collection; what does (the medians of the fusion, the kNN graph of
 * the re-ranking) is recomputed on the fold, so every number is what `amscr eval` gives on a
 * manifest of that fold alone. Base matrices are computed through the library's internals exactly
 * as amscr_db_retrieval_matrix computes them and cached in /tmp/amscr-folds-cache (the key names
 * every setting they depend on).
 *
 *   amscr-retrieval-folds DATASETS post    share, re-ranking k / iterations, AMSCR fusion weight
 *   amscr-retrieval-folds DATASETS raw     N samples, band, skip, locality, reflections
 *   amscr-retrieval-folds DATASETS scale   re-ranking k at 350 / 700 / 916 / 1400 shapes
 *   amscr-retrieval-folds DATASETS fd      the global proportion channel (Fourier magnitudes)
 *   amscr-retrieval-folds DATASETS fuse    a proportion channel (Fourier / moments) fused over medians or
 *                                          local scales (folds_fuse.c)
 *   amscr-retrieval-folds DATASETS local   the channel rescaled before re-ranking: local scaling, NICDM,
 *                                          mutual proximity (folds_fuse.c; LOCAL_K=k the re-ranking's k)
 *   amscr-retrieval-folds DATASETS halves  candidates on 24 random class halves of mpeg7-dev (folds_fuse.c)
 *   amscr-retrieval-folds DATASETS band    the channel's band on random class subsets of mpeg7-dev and on
 *                                          the 916- and 1400-shape collections (folds_band.c)
 *   amscr-retrieval-folds DATASETS inner   the inner-distance graph's share in the re-ranking on the same
 *                                          subsets, the folds and the whole collections (folds_inner.c)
 *   amscr-retrieval-folds DATASETS classes 1-NN, the 916-shape collection's parts, mpeg7-dev per class
 *   amscr-retrieval-folds DATASETS mcd     the MCD-style affine views by band and affine share
 *   amscr-retrieval-folds DATASETS row N BAND SKIP LOC SHARE K ITERS [STRIDE]   one combination, all splits
 *                                          and the MCD-style views
 *   amscr-retrieval-folds DATASETS cost    the channel's CPU time per pair by N and band */
#include "folds.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATASETS post|raw|scale|fd|fuse|mcd|cost|row ...\n", argv[0]);
        return 2;
    }
    if (strcmp(argv[2], "mcd") == 0)
        return folds_mcd(argv[1]);
    folds_data fd;
    if (folds_load(argv[1], &fd) != 0)
        return 1;
    const char *what = argv[2];
    int r = 2;
    if (strcmp(what, "post") == 0)
        r = folds_sweep_post(&fd);
    else if (strcmp(what, "raw") == 0)
        r = folds_sweep_raw(&fd);
    else if (strcmp(what, "scale") == 0)
        r = folds_scale(&fd);
    else if (strcmp(what, "row") == 0 && (argc == 10 || argc == 11))
        r = folds_row(&fd, argv[1], argv + 3);
    else if (strcmp(what, "cost") == 0)
        r = folds_cost(&fd);
    else if (strcmp(what, "fd") == 0)
        r = folds_fourier(&fd);
    else if (strcmp(what, "fuse") == 0)
        r = folds_fuse(&fd, argv[1]);
    else if (strcmp(what, "local") == 0)
        r = folds_local(&fd, argv[1]);
    else if (strcmp(what, "halves") == 0)
        r = folds_halves(&fd);
    else if (strcmp(what, "band") == 0)
        r = folds_band(&fd);
    else if (strcmp(what, "inner") == 0)
        r = folds_inner(&fd);
    else if (strcmp(what, "classes") == 0)
        r = folds_classes(&fd, argv[1]);
    else
        fprintf(stderr, "unknown sweep %s\n", what);
    folds_free(&fd);
    return r;
}
