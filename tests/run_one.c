/* run_one.c — main() of a one-area test executable (AMSCR_SUITE names the suite).
 *
 * A suite that reads the shared datasets prints "SKIP: <suite>: datasets not found" from the
 * test that needs them when they are absent (amscr_test_datasets_or_skip); its executable then
 * exits 77 after the rest of the suite passed, so meson reports it as SKIP, not OK. check_all
 * prints the same line and still passes. */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "suites.h"
#include "testutil.h"

#define RUN_ONE_STR2(x) #x
#define RUN_ONE_STR(x) RUN_ONE_STR2(x)

int main(void)
{
    SRunner *sr = srunner_create(AMSCR_SUITE());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    if (failed != 0)
        return EXIT_FAILURE;
    /* "amscr_suite_accuracy" -> "accuracy" */
    const char *name = RUN_ONE_STR(AMSCR_SUITE) + strlen("amscr_suite_");
    if (amscr_test_suite_reads_datasets(name) && amscr_test_datasets_dir() == NULL)
        return 77;
    return EXIT_SUCCESS;
}
