/* matrix_file.c — .npy and .tsv writers of `amscr matrix` (see matrix_file.h). */
#include "matrix_file.h"

#include <stdint.h>
#include <string.h>

/* .npy v1.0: magic, version, little-endian u16 header length, a Python dict literal
 * padded with spaces and '\n' so the data starts at a multiple of 64 bytes. */
int write_npy(FILE *fp, const double *d, size_t n)
{
    char dict[128];
    snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, %zu), }", n, n);
    size_t dl = strlen(dict);
    size_t total = 10 + dl + 1;
    size_t pad = (64 - total % 64) % 64;
    size_t hlen = dl + pad + 1;
    if (hlen > 65535)
        return -1;
    unsigned char pre[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(hlen & 0xff),
                             (unsigned char)(hlen >> 8)};
    if (fwrite(pre, 1, 10, fp) != 10 || fwrite(dict, 1, dl, fp) != dl)
        return -1;
    for (size_t i = 0; i < pad; i++)
        if (fputc(' ', fp) == EOF)
            return -1;
    if (fputc('\n', fp) == EOF)
        return -1;
    const uint16_t one = 1;
    int little = *(const unsigned char *)&one == 1;
    for (size_t i = 0; i < n * n; i++) {
        unsigned char bytes[8];
        memcpy(bytes, &d[i], 8);
        if (!little)
            for (int k = 0; k < 4; k++) {
                unsigned char t = bytes[k];
                bytes[k] = bytes[7 - k];
                bytes[7 - k] = t;
            }
        if (fwrite(bytes, 1, 8, fp) != 8)
            return -1;
    }
    return 0;
}

int write_tsv(FILE *fp, const double *d, size_t n, const collection *c)
{
    if (fputs("#", fp) == EOF)
        return -1;
    for (size_t j = 0; j < n; j++) {
        /* names with tabs or newlines would break the comment line */
        fputc(j ? '\t' : ' ', fp);
        for (const char *s = c->items[j].name; *s; s++)
            fputc(*s == '\t' || *s == '\n' || *s == '\r' ? ' ' : *s, fp);
    }
    fputc('\n', fp);
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++)
            if (fprintf(fp, "%s%.17g", j ? "\t" : "", d[i * n + j]) < 0)
                return -1;
        if (fputc('\n', fp) == EOF)
            return -1;
    }
    return ferror(fp) ? -1 : 0;
}
