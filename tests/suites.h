/* suites.h — every Check suite of the project. */
#ifndef AMSCR_TEST_SUITES_H
#define AMSCR_TEST_SUITES_H
#include <check.h>

Suite *amscr_suite_version(void);
Suite *amscr_suite_errors(void);
Suite *amscr_suite_contour_io(void);
Suite *amscr_suite_trace(void);
Suite *amscr_suite_smooth(void);
Suite *amscr_suite_arclength(void);
Suite *amscr_suite_lstsq(void);
Suite *amscr_suite_affine(void);
Suite *amscr_suite_kmeans(void);
Suite *amscr_suite_gmm1d(void);
Suite *amscr_suite_params(void);
Suite *amscr_suite_register(void);
Suite *amscr_suite_accuracy(void);
Suite *amscr_suite_db(void);
Suite *amscr_suite_retrieval(void);
Suite *amscr_suite_threads(void);
Suite *amscr_suite_rerank(void);
Suite *amscr_suite_invariance(void);
/* robust registration */
Suite *amscr_suite_robust(void);
Suite *amscr_suite_channel(void);
Suite *amscr_suite_trace_all(void);
Suite *amscr_suite_polish(void);
Suite *amscr_suite_ordered(void);
Suite *amscr_suite_despike(void);
Suite *amscr_suite_even(void);
Suite *amscr_suite_index(void);
Suite *amscr_suite_shards(void);
Suite *amscr_suite_signature(void);
Suite *amscr_suite_protocols(void);
Suite *amscr_suite_subpixel(void);
Suite *amscr_suite_stages(void);
Suite *amscr_suite_inner(void);
Suite *amscr_suite_pixel_grid(void);
Suite *amscr_suite_fenv(void);

#endif
