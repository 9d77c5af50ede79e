/* matrix_file.h — the two file formats of `amscr matrix`: NumPy .npy and tab-separated text.
 * Tool-internal. */
#ifndef AMSCR_TOOL_MATRIX_FILE_H
#define AMSCR_TOOL_MATRIX_FILE_H

#include <stddef.h>
#include <stdio.h>

#include "collection.h"

/* The n x n row-major matrix d as NumPy .npy v1.0: little-endian float64, C order. 0 or -1
 * on a write error. */
int write_npy(FILE *fp, const double *d, size_t n);
/* The matrix as text: a '#' comment line listing the names of c's items (tab-separated; a
 * tab or line break inside a name becomes a space), then one row per line, %.17g numbers
 * separated by tabs. 0 or -1 on a write error. */
int write_tsv(FILE *fp, const double *d, size_t n, const collection *c);

#endif
