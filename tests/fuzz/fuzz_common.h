/* fuzz_common.h — shared bits of the libFuzzer targets in tests/fuzz/ (hardening, docs/hardening.md).
 *
 * Every target defines LLVMFuzzerTestOneInput. Built two ways:
 *   - with clang -fsanitize=fuzzer,address,undefined by tests/fuzz/build.sh (real fuzzing);
 *   - with any C compiler plus tests/fuzz/standalone.c (a main() that replays files), which
 *     tests/meson.build uses to rerun the committed corpora (regressions included) in every
 *     normal and sanitizer test run.
 * FUZZ_CHECK is a property check that must hold for every input: a failure aborts, so both
 * libFuzzer and the replay driver report it as a crash with the input that caused it. */
#ifndef AMSCR_FUZZ_COMMON_H
#define AMSCR_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#define FUZZ_CHECK(cond)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: property violated: %s\n", __FILE__, __LINE__, #cond);          \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif
