/* check_all.c — runs every suite; its closing line ("100%: Checks: N, Failures: 0, Errors: 0")
 * is what CI reads. */
#include <check.h>
#include <stdlib.h>

#include "suites.h"

int main(void)
{
    SRunner *sr = srunner_create(suite_create("amscr"));
#define X(area) srunner_add_suite(sr, amscr_suite_##area());
    AMSCR_SUITES
#undef X
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
