/* fuzz_png.c — the tool's PNG decoder (libpng, every colour type and depth, interlace,
 * palette, tRNS, the alpha policy): see fuzz_image.h. */
#include "fuzz_image.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { return fuzz_image_one(data, size, 0); }
