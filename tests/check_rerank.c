/* check_rerank.c — contextual re-ranking (amscr_rerank_diffusion) on hand-made matrices whose
 * correct answer is known, and its argument checks; the re-ranking on several graphs
 * (amscr__rerank_graphs) against the one- and two-graph entries. */
#include <amscr.h>
#include <check.h>
#include <math.h>
#include <stdlib.h>

#include "internal.h"
#include "suites.h"

/* Two classes: A = {0, 1, 2, 3}, B = {4, 5, 6, 7}. Item 3 is a loose member of A (0.30 from
 * 0, 1, 2, which are 0.20 apart), and its single nearest item is 4 (0.25), a member of the tight
 * class B (0.10 apart). Everything else is 1.0 apart. The pairwise distance puts 4 first for 3;
 * the context says A: 4 lives in a much tighter neighbourhood (self-tuning scale 0.10 against
 * 0.20 for A), so the affinity 3-4 is weaker than 3-0 (worked out by hand:
 * exp(-0.25 / sqrt(0.30 * 0.10)) = 0.236 < exp(-0.30 / sqrt(0.30 * 0.20)) = 0.294), and the
 * diffusion ranks class A first for item 3. */
static void two_classes(double *D)
{
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 8; j++) {
            double d = 1.0;
            if (i == j)
                d = 0.0;
            else if (i < 3 && j < 3)
                d = 0.20;
            else if ((i == 3 && j < 3) || (j == 3 && i < 3))
                d = 0.30;
            else if (i >= 4 && j >= 4)
                d = 0.10;
            else if ((i == 3 && j == 4) || (i == 4 && j == 3))
                d = 0.25;
            D[i * 8 + j] = d;
        }
}

static int nearest(const double *D, int n, int i)
{
    int best = -1;
    for (int j = 0; j < n; j++)
        if (j != i && (best < 0 || D[i * n + j] < D[i * n + best]))
            best = j;
    return best;
}

START_TEST(test_known_answer)
{
    double D[64], R[64];
    two_classes(D);
    ck_assert_int_eq(nearest(D, 8, 3), 4); /* the pairwise distance is wrong for item 3 */
    ck_assert_int_eq(amscr_rerank_diffusion(D, 8, 3, 20, R), AMSCR_OK);
    for (int i = 0; i < 8; i++) {
        int j = nearest(R, 8, i);
        ck_assert_msg((i < 4) == (j < 4), "item %d: nearest after re-ranking is %d", i, j);
        ck_assert_double_le(R[i * 8 + i], 1e-12); /* itself first */
        for (int t = 0; t < 8; t++)
            ck_assert(isfinite(R[i * 8 + t]) && R[i * 8 + t] >= 0.0);
    }
}
END_TEST

START_TEST(test_blocks_and_unreached)
{
    /* three well-separated classes of 4: with k = 2 the diffusion stays inside a class, so every
     * same-class item ranks before every other (reached < 1 <= unreached) */
    enum { N = 12 };
    double D[N * N], R[N * N];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            D[i * N + j] = i == j ? 0.0 : (i / 4 == j / 4 ? 0.1 + 0.01 * abs(i - j) : 5.0 + 0.1 * abs(i - j));
    ck_assert_int_eq(amscr_rerank_diffusion(D, N, 2, 10, R), AMSCR_OK);
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            if (i / 4 == j / 4)
                ck_assert_double_lt(R[i * N + j], 1.0);
            else
                ck_assert_double_ge(R[i * N + j], 1.0);
        }
    /* in place gives the same answer, and it is deterministic */
    double R2[N * N];
    for (int i = 0; i < N * N; i++)
        R2[i] = D[i];
    ck_assert_int_eq(amscr_rerank_diffusion(R2, N, 2, 10, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert(R2[i] == R[i]);
}
END_TEST

START_TEST(test_invalid)
{
    double D[4] = {0, 1, 1, 0}, R[4];
    ck_assert_int_eq(amscr_rerank_diffusion(NULL, 2, 1, 1, R), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 1, 1, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 0, 1, 1, R), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 0, 1, R), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 3, 1, R), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 1, 0, R), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 1, 1001, R), AMSCR_E_INVALID_ARG);
    D[1] = NAN;
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 1, 1, R), AMSCR_E_INVALID_ARG);
    D[1] = -1.0;
    ck_assert_int_eq(amscr_rerank_diffusion(D, 2, 1, 1, R), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
}
END_TEST

/* A symmetric random distance matrix (zero diagonal) from a seeded generator. */
static void random_matrix(double *D, int n, unsigned seed)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            seed = seed * 1103515245u + 12345u;
            D[i * n + j] = D[j * n + i] = i == j ? 0.0 : 0.1 + (double)(seed >> 8 & 0xffff) / 65536.0;
        }
}

START_TEST(test_graphs)
{
    enum { N = 14 };
    double A[N * N], B[N * N], C[N * N], R1[N * N], R2[N * N];
    random_matrix(A, N, 1);
    random_matrix(B, N, 2);
    random_matrix(C, N, 3);
    /* one graph and two graphs: exactly the entries the library used before */
    const double *one[1] = {A}, *two[2] = {A, B}, *halves[3] = {A, B, B}, *unused[3] = {A, B, C};
    double s1[1] = {0.0}, s2[2] = {0.0, 0.3}, sh[3] = {0.0, 0.15, 0.15}, s0[3] = {0.0, 0.3, 0.0};
    ck_assert_int_eq(amscr__rerank_normalized(A, N, 4, 10, 1, R1), AMSCR_OK);
    ck_assert_int_eq(amscr__rerank_graphs(one, s1, 1, N, 4, 10, 2, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert(R1[i] == R2[i]);
    ck_assert_int_eq(amscr__rerank_normalized2(A, B, 0.3, N, 4, 10, 1, R1), AMSCR_OK);
    ck_assert_int_eq(amscr__rerank_graphs(two, s2, 2, N, 4, 10, 2, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert(R1[i] == R2[i]);
    /* a graph split in two halves is the same graph; a graph of share 0 changes nothing */
    ck_assert_int_eq(amscr__rerank_graphs(halves, sh, 3, N, 4, 10, 1, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert_double_eq_tol(R1[i], R2[i], 1e-12);
    ck_assert_int_eq(amscr__rerank_graphs(unused, s0, 3, N, 4, 10, 1, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert_double_eq_tol(R1[i], R2[i], 1e-12);
    /* a third graph with a share moves the ranking */
    double s3[3] = {0.0, 0.3, 0.3};
    ck_assert_int_eq(amscr__rerank_graphs(unused, s3, 3, N, 4, 10, 1, R2), AMSCR_OK);
    int differ = 0;
    for (int i = 0; i < N * N; i++)
        differ |= fabs(R1[i] - R2[i]) > 1e-9;
    ck_assert(differ);
    ck_assert_int_eq(amscr__rerank_graphs(unused, s3, 0, N, 4, 10, 1, R2), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr__rerank_graphs(unused, s3, AMSCR__RERANK_GRAPHS + 1, N, 4, 10, 1, R2),
                     AMSCR_E_INVALID_ARG);
    C[5] = NAN;
    ck_assert_int_eq(amscr__rerank_graphs(unused, s3, 3, N, 4, 10, 1, R2), AMSCR_E_INVALID_ARG);
}
END_TEST

/* 1 when row a of A (na wide) and row b of B (nb wide) order m shapes alike: columns cols[t]
 * of A, bcols[t] of B. */
static int same_order(const double *A, int na, int a, const double *B, int nb, int b, const int *cols, const int *bcols,
                      int m)
{
    for (int s = 0; s < m; s++)
        for (int t = 0; t < m; t++)
            if ((A[a * na + cols[s]] < A[a * na + cols[t]]) != (B[b * nb + bcols[s]] < B[b * nb + bcols[t]]))
                return 0;
    return 1;
}

/* Held-out shapes: with none it is the plain re-ranking; the others' rows order the others as
 * the re-ranking of the others alone; a held-out row orders the others the same whatever the
 * other held-out shapes are (here: with shape 3 dropped from the matrix). */
START_TEST(test_held)
{
    enum { N = 14 };
    double A[N * N], B[N * N], R1[N * N], R2[N * N], S[N * N], T[N * N];
    random_matrix(A, N, 4);
    random_matrix(B, N, 5);
    unsigned char none[N] = {0}, held[N] = {0}, held2[N - 1] = {0};
    const double *two[2] = {A, B};
    double sh[2] = {0.0, 0.2};
    ck_assert_int_eq(amscr__rerank_graphs(two, sh, 2, N, 4, 10, 1, R1), AMSCR_OK);
    ck_assert_int_eq(amscr__rerank_held(two, sh, 2, N, 4, 10, 2, none, R2), AMSCR_OK);
    for (int i = 0; i < N * N; i++)
        ck_assert(R1[i] == R2[i]);
    int others[N], m = 0, others2[N];
    for (int i = 0; i < N; i++) {
        held[i] = i % 3 == 0; /* 0, 3, 6, 9, 12 */
        if (!held[i])
            others[m++] = i;
    }
    ck_assert_int_eq(amscr__rerank_held(two, sh, 2, N, 4, 10, 1, held, R2), AMSCR_OK);
    /* the others alone: their submatrices */
    double SA[N * N], SB[N * N];
    for (int s = 0; s < m; s++)
        for (int t = 0; t < m; t++) {
            SA[s * m + t] = A[others[s] * N + others[t]];
            SB[s * m + t] = B[others[s] * N + others[t]];
        }
    const double *sub[2] = {SA, SB};
    ck_assert_int_eq(amscr__rerank_graphs(sub, sh, 2, (size_t)m, 4, 10, 1, S), AMSCR_OK);
    for (int s = 0; s < m; s++)
        others2[s] = s;
    for (int s = 0; s < m; s++)
        ck_assert(same_order(R2, N, others[s], S, m, s, others, others2, m));
    /* shape 3 dropped: the matrix without row and column 3 */
    double DA[(N - 1) * (N - 1)], DB[(N - 1) * (N - 1)];
    for (int i = 0, u = 0; i < N; i++) {
        if (i == 3)
            continue;
        held2[u] = held[i];
        for (int j = 0, v = 0; j < N; j++)
            if (j != 3) {
                DA[u * (N - 1) + v] = A[i * N + j];
                DB[u * (N - 1) + v++] = B[i * N + j];
            }
        u++;
    }
    const double *drop[2] = {DA, DB};
    ck_assert_int_eq(amscr__rerank_held(drop, sh, 2, N - 1, 4, 10, 1, held2, T), AMSCR_OK);
    for (int s = 0; s < m; s++)
        others2[s] = others[s] - (others[s] > 3);
    ck_assert(same_order(R2, N, 0, T, N - 1, 0, others, others2, m));
    ck_assert(same_order(R2, N, 12, T, N - 1, 11, others, others2, m));
    ck_assert_int_eq(amscr__rerank_held(two, sh, 2, N, 4, 10, 1, NULL, R2), AMSCR_E_INVALID_ARG);
}
END_TEST

Suite *amscr_suite_rerank(void)
{
    Suite *s = suite_create("rerank");
    TCase *tc = tcase_create("diffusion");
    tcase_add_test(tc, test_known_answer);
    tcase_add_test(tc, test_blocks_and_unreached);
    tcase_add_test(tc, test_invalid);
    tcase_add_test(tc, test_graphs);
    tcase_add_test(tc, test_held);
    suite_add_tcase(s, tc);
    return s;
}
