/* check_version.c — runtime version and feature queries agree with the header macros. */
#include <amscr.h>
#include <check.h>
#include <stdio.h>
#include <string.h>

#include "suites.h"

START_TEST(test_version_number_matches_macros)
{
    ck_assert_int_eq(amscr_version_number(), AMSCR_VERSION_NUMBER);
    /* The packing formula itself, recomputed independently of AMSCR_VERSION_NUMBER. */
    ck_assert_int_eq(amscr_version_number(),
                     AMSCR_VERSION_MAJOR * 10000 + AMSCR_VERSION_MINOR * 100 + AMSCR_VERSION_PATCH);
    ck_assert_int_ge(AMSCR_VERSION_MINOR, 0);
    ck_assert_int_lt(AMSCR_VERSION_MINOR, 100);
    ck_assert_int_ge(AMSCR_VERSION_PATCH, 0);
    ck_assert_int_lt(AMSCR_VERSION_PATCH, 100);
}
END_TEST

START_TEST(test_version_string_matches_macros)
{
    char expect[64];
    snprintf(expect, sizeof expect, "%d.%d.%d", AMSCR_VERSION_MAJOR, AMSCR_VERSION_MINOR, AMSCR_VERSION_PATCH);
    const char *s = amscr_version_string();
    ck_assert_ptr_nonnull(s);
    ck_assert_str_eq(s, expect);
}
END_TEST

START_TEST(test_version_string_consistent_with_number)
{
    /* Parse the string back and repack it: it must give the runtime number. */
    int maj = -1, min = -1, pat = -1;
    char tail = 0;
    const char *s = amscr_version_string();
    ck_assert_ptr_nonnull(s);
    ck_assert_int_eq(sscanf(s, "%d.%d.%d%c", &maj, &min, &pat, &tail), 3);
    ck_assert_int_eq(maj * 10000 + min * 100 + pat, amscr_version_number());
}
END_TEST

START_TEST(test_version_string_is_static)
{
    const char *a = amscr_version_string();
    const char *b = amscr_version_string();
    ck_assert_ptr_eq(a, b);
}
END_TEST

START_TEST(test_has_feature)
{
    ck_assert_int_eq(amscr_has_feature(AMSCR_FEATURE_THREADS), 1);
    ck_assert_int_eq(amscr_has_feature((amscr_feature)0), 0);
    ck_assert_int_eq(amscr_has_feature((amscr_feature)2), 0);
    ck_assert_int_eq(amscr_has_feature((amscr_feature)12345), 0);
    ck_assert_int_eq(amscr_has_feature((amscr_feature)-1), 0);
}
END_TEST

Suite *amscr_suite_version(void)
{
    Suite *s = suite_create("version");
    TCase *tc = tcase_create("version");
    tcase_add_test(tc, test_version_number_matches_macros);
    tcase_add_test(tc, test_version_string_matches_macros);
    tcase_add_test(tc, test_version_string_consistent_with_number);
    tcase_add_test(tc, test_version_string_is_static);
    tcase_add_test(tc, test_has_feature);
    suite_add_tcase(s, tc);
    return s;
}
