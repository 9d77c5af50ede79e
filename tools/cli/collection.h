/* collection.h — shape collections for `amscr search|matrix|eval`: a folder of images and
 * point lists, or a manifest.tsv (columns `file` and `class`).
 *
 * Folder: the regular, non-hidden files whose magic bytes say PNG or PGM, or whose name
 * ends in .txt or .csv (other files, e.g. manifest.tsv or stats.json, are skipped), sorted
 * by name (byte order, strcmp). Images of formats the tool cannot read (JPEG, GIF, TIFF,
 * WebP, BMP, other Netpbm: by their magic bytes) are skipped with one warning line on stderr
 * naming how many and the first by name. The class of a file is its name without the
 * extension, cut before a final '-' or '_' followed by digits ("bird-3.png" -> "bird",
 * "leaf_12.txt" -> "leaf"); failing that, trailing digits are dropped ("Bone01" -> "Bone");
 * failing that, the whole name is the class. Trailing blanks are dropped, and with the digits
 * the separators ' ', '-', '_' before them ("star 3" -> "star"), unless nothing is left.
 *
 * Manifest: a tab-separated file with a header line naming (at least) the columns `file`
 * and `class`, in any order; paths are relative to the manifest's folder (absolute paths
 * are kept); a UTF-8 byte order mark before the header is dropped; blank lines and lines
 * starting with '#' are skipped. Rows keep their order; a file listed twice (the same
 * entry) is an error naming both lines. An optional column `group` names the object or
 * source each shape belongs to (eval --protocol groups leaves one group out at a time).
 * An image, a point list or an amscr file given as a manifest is an error saying so. */
#ifndef AMSCR_TOOL_COLLECTION_H
#define AMSCR_TOOL_COLLECTION_H

#include <stddef.h>
#include <stdint.h>

typedef struct coll_item {
    char *path;    /* path to open */
    char *name;    /* as listed (file name or manifest entry) */
    int32_t label; /* index into classes */
    int32_t group; /* index into groups; -1 without a group column */
} coll_item;

typedef struct collection {
    coll_item *items;
    size_t n;
    char **classes; /* class names, in order of first appearance */
    size_t nclasses;
    char **groups; /* group names (manifest column `group`), in order of first appearance */
    size_t ngroups; /* 0: no group column */
} collection;

/* Reads a folder or a manifest. Returns 0, or -1 after printing one error line. */
int collection_open(const char *path, collection *out);
void collection_free(collection *c);

/* -1 after an error line when the output `path` (given with option `opt`) is a file the command
 * reads: one of the n `inputs` (the collection file or folder, a query, ...) or, c not NULL (a
 * folder or a manifest, not an index), one of c's shape files; else 0. */
int collection_out_not_input(const char *opt, const char *path, const collection *c, const char *const *inputs,
                             size_t n);

/* The index of `name` in the list (*names, *n; capacity *cap), appended when new; -1 when out
 * of memory (printed). */
int32_t coll_name_index(char ***names, size_t *n, const char *name, size_t *cap);

/* Class of a file name (see above) into out (capacity cap). */
void class_from_name(const char *filename, char *out, size_t cap);

#endif
