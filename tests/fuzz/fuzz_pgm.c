/* fuzz_pgm.c — the tool's PGM decoder (P2/P5, 8/16-bit, comments): see fuzz_image.h. */
#include "fuzz_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_image_one(data, size, 0); }
