/* check_contour_io.c — text point lists: parsing, reading, atomic writing. */
#include <check.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "amscr.h"
#include "internal.h" /* amscr__fopen_read */
#include "suites.h"
#include "testutil.h"

/* Parses a C string; returns the status and (on success) the contour. */
static amscr_status parse(const char *s, amscr_contour **c)
{
    *c = NULL;
    return amscr_contour_parse_text(s, strlen(s), c);
}

/* Asserts that contour c holds exactly the n points of xy. */
static void assert_points(const amscr_contour *c, const double *xy, size_t n)
{
    ck_assert_uint_eq(amscr_contour_size(c), n);
    const double *p = amscr_contour_xy(c);
    for (size_t i = 0; i < 2 * n; i++)
        ck_assert_msg(p[i] == xy[i], "coordinate %zu: %.17g != %.17g", i, p[i], xy[i]);
}

/* A fresh temporary folder (removed by rm_tree). */
static char *make_tmpdir(void)
{
    const char *base = getenv("TMPDIR");
    char *buf = malloc(4096);
    snprintf(buf, 4096, "%s/amscr_io_XXXXXX", base && *base ? base : "/tmp");
    ck_assert_ptr_nonnull(mkdtemp(buf));
    return buf;
}

/* Number of entries (other than . and ..) in a folder. */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    ck_assert_ptr_nonnull(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    closedir(d);
    return n;
}

/* Removes the files of a flat folder, then the folder. */
static void rm_tree(char *dir)
{
    DIR *d = opendir(dir);
    if (d) {
        struct dirent *e;
        char path[4200];
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
        closedir(d);
    }
    rmdir(dir);
    free(dir);
}

/* Writes a string to a file. */
static void write_file(const char *path, const char *s)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(s, 1, strlen(s), f), strlen(s));
    ck_assert_int_eq(fclose(f), 0);
}

START_TEST(parse_separators)
{
    amscr_contour *c;
    const char *text = "1 2\n3,4\n5, 6\n7\t8\n  9 \t 10  \n-1.5,+2.25\n11 ,12\n";
    const double xy[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, -1.5, 2.25, 11, 12};
    ck_assert_int_eq(parse(text, &c), AMSCR_OK);
    assert_points(c, xy, 7);
    ck_assert_str_eq(amscr_last_error_detail(), "");
    amscr_contour_free(c);
}
END_TEST

START_TEST(parse_comments_blank_crlf)
{
    amscr_contour *c;
    const char *text = "# header\r\n\r\n1 2 # trailing comment\r\n   \r\n\t\n3 4\r\n#5 6\n7 8#x y z\n# end";
    const double xy[] = {1, 2, 3, 4, 7, 8};
    ck_assert_int_eq(parse(text, &c), AMSCR_OK);
    assert_points(c, xy, 3);
    amscr_contour_free(c);
}
END_TEST

/* A UTF-8 byte order mark is skipped at the start only: anywhere else it is a bad line. */
START_TEST(parse_byte_order_mark)
{
    amscr_contour *c;
    const double xy[] = {1, 2, 3, 4, 5, 7};
    ck_assert_int_eq(parse("\xEF\xBB\xBF" "1 2\r\n3 4\r\n5 7\r\n", &c), AMSCR_OK);
    assert_points(c, xy, 3);
    amscr_contour_free(c);
    ck_assert_int_eq(parse("\xEF\xBB\xBF", &c), AMSCR_E_FORMAT); /* nothing but the mark: no points */
    ck_assert_int_eq(parse("1 2\n\xEF\xBB\xBF" "3 4\n", &c), AMSCR_E_FORMAT);
    ck_assert_str_eq(amscr_last_error_detail(), "line 2: expected 2 numbers");
}
END_TEST

START_TEST(parse_scientific_and_no_final_newline)
{
    amscr_contour *c;
    const char *text = "1e3 -2.5E-2\n.5 6.\n0x1p-2 1e-310\n-0 0.1";
    const double xy[] = {1000.0, -0.025, 0.5, 6.0, 0.25, 1e-310, -0.0, 0.1};
    ck_assert_int_eq(parse(text, &c), AMSCR_OK);
    assert_points(c, xy, 4);
    ck_assert(signbit(amscr_contour_xy(c)[6]));
    amscr_contour_free(c);
}
END_TEST

START_TEST(parse_not_nul_terminated)
{
    /* Only the first len bytes count: "1 2\n3 4" out of a longer buffer. */
    const char buf[] = "1 2\n3 4999 garbage";
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_parse_text(buf, 7, &c), AMSCR_OK);
    const double xy[] = {1, 2, 3, 4};
    assert_points(c, xy, 2);
    amscr_contour_free(c);
}
END_TEST

/* Bad inputs: each must fail with FORMAT naming the right line and what is wrong. */
#define NOT_TWO "expected 2 numbers"
#define NOT_FINITE "a coordinate is not a finite number"
static const struct {
    const char *text;
    int line;
    const char *what;
} bad_cases[] = {
    {"1 2\n3 4 5\n", 2, NOT_TWO},          /* three numbers */
    {"1 2\n\n7\n", 3, NOT_TWO},            /* one number */
    {"# c\nabc def\n", 2, NOT_TWO},        /* garbage */
    {"1 2\n3 nan\n", 2, NOT_FINITE},       /* NaN */
    {"inf 1\n", 1, NOT_FINITE},            /* infinity */
    {"1 2\n1e999 3\n", 2, NOT_FINITE},     /* overflow to infinity */
    {"1,,2\n", 1, NOT_TWO},                /* two commas */
    {"1, ,2\n", 1, NOT_TWO},               /* comma, blank, comma-less gap */
    {"1-2\n", 1, NOT_TWO},                 /* no separator */
    {"1 2,\n", 1, NOT_TWO},                /* trailing comma */
    {",1 2\n", 1, NOT_TWO},                /* leading comma */
    {"1 2\n3 4\n5 6x\n", 3, NOT_TWO},      /* trailing garbage */
    {"1 2\r\n3\r\n", 2, NOT_TWO},          /* CRLF and one number */
    {"1;2\n", 1, NOT_TWO},                 /* wrong separator */
};

START_TEST(parse_bad_line)
{
    amscr_contour *c = (amscr_contour *)&c; /* must stay untouched */
    amscr_contour *const sentinel = c;
    const char *text = bad_cases[_i].text;
    ck_assert_int_eq(amscr_contour_parse_text(text, strlen(text), &c), AMSCR_E_FORMAT);
    ck_assert_ptr_eq(c, sentinel);
    char want[64];
    snprintf(want, sizeof want, "line %d: %s", bad_cases[_i].line, bad_cases[_i].what);
    ck_assert_str_eq(amscr_last_error_detail(), want);
}
END_TEST

START_TEST(parse_empty)
{
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_parse_text("", 0, &c), AMSCR_E_FORMAT);
    ck_assert_ptr_null(c);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "no points"));
    ck_assert_int_eq(parse("# only a comment\n\n   \r\n", &c), AMSCR_E_FORMAT);
    ck_assert_ptr_null(c);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "no points"));
}
END_TEST

START_TEST(null_args)
{
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_parse_text(NULL, 3, &c), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    ck_assert_int_eq(amscr_contour_parse_text("1 2", 3, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_read_text(NULL, &c), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_read_text("x.txt", NULL), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    const double xy[] = {0, 0, 1, 0, 0, 1};
    ck_assert_int_eq(amscr_contour_new(xy, 3, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_write_text(NULL, "x.txt"), AMSCR_E_INVALID_ARG);
    ck_assert_int_eq(amscr_contour_write_text(c, NULL), AMSCR_E_INVALID_ARG);
    ck_assert_str_ne(amscr_last_error_detail(), "");
    amscr_contour_free(c);
}
END_TEST

START_TEST(read_file_and_errors)
{
    char *dir = make_tmpdir();
    char path[4200];
    snprintf(path, sizeof path, "%s/shape.txt", dir);
    write_file(path, "# a square\n0 0\n1,0\n1\t1\r\n0, 1\n");
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_read_text(path, &c), AMSCR_OK);
    const double xy[] = {0, 0, 1, 0, 1, 1, 0, 1};
    assert_points(c, xy, 4);
    amscr_contour_free(c);

    /* A bad line: "path:line: expected 2 numbers". */
    write_file(path, "0 0\n1 0\n\n1 1 1\n");
    c = NULL;
    ck_assert_int_eq(amscr_contour_read_text(path, &c), AMSCR_E_FORMAT);
    ck_assert_ptr_null(c);
    char want[4300];
    snprintf(want, sizeof want, "%s:4: expected 2 numbers", path);
    ck_assert_str_eq(amscr_last_error_detail(), want);

    /* Empty file. */
    write_file(path, "");
    ck_assert_int_eq(amscr_contour_read_text(path, &c), AMSCR_E_FORMAT);
    ck_assert_ptr_null(c);

    /* A folder: opens, but reading fails: IO. */
    ck_assert_int_eq(amscr_contour_read_text(dir, &c), AMSCR_E_IO);
    ck_assert_ptr_null(c);

    /* Missing file: IO, with the path and strerror in the detail. */
    snprintf(path, sizeof path, "%s/missing.txt", dir);
    ck_assert_int_eq(amscr_contour_read_text(path, &c), AMSCR_E_IO);
    ck_assert_ptr_null(c);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), path));
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), "No such file"));
    rm_tree(dir);
}
END_TEST

START_TEST(write_read_round_trip)
{
    char *dir = make_tmpdir();
    char path[4200];
    snprintf(path, sizeof path, "%s/out.txt", dir);
    amscr_test_rng r;
    amscr_test_rng_seed(&r, 42);
    enum { N = 500 };
    double xy[2 * N];
    for (int i = 0; i < 2 * N; i++)
        xy[i] = (amscr_test_uniform(&r) - 0.5) * pow(10.0, (double)(i % 41) - 20.0);
    xy[0] = 0.1;
    xy[1] = -0.0;
    xy[2] = 1e-310; /* subnormal */
    xy[3] = 1.7976931348623157e308;
    amscr_contour *c = NULL, *back = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, N, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_write_text(c, path), AMSCR_OK);
    ck_assert_int_eq(count_entries(dir), 1); /* no temporary left */
    ck_assert_int_eq(amscr_contour_read_text(path, &back), AMSCR_OK);
    assert_points(back, xy, N);
    amscr_contour_free(back);

    /* Overwriting an existing file works and is exact too. */
    double xy2[] = {1.0 / 3.0, 2.0 / 3.0, -5, 7};
    amscr_contour *c2 = NULL;
    ck_assert_int_eq(amscr_contour_new(xy2, 2, &c2), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_write_text(c2, path), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_read_text(path, &back), AMSCR_OK);
    assert_points(back, xy2, 2);
    ck_assert_int_eq(count_entries(dir), 1);

    /* The file format is "%.17g %.17g\n". */
    FILE *f = fopen(path, "rb");
    char text[256] = {0};
    ck_assert_ptr_nonnull(f);
    size_t got = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    ck_assert_uint_gt(got, 0);
    ck_assert_str_eq(text, "0.33333333333333331 0.66666666666666663\n-5 7\n");

    amscr_contour_free(back);
    amscr_contour_free(c);
    amscr_contour_free(c2);
    rm_tree(dir);
}
END_TEST

START_TEST(write_missing_dir)
{
    char *dir = make_tmpdir();
    char path[4200];
    snprintf(path, sizeof path, "%s/no/such/dir/out.txt", dir);
    const double xy[] = {0, 0, 1, 0, 0, 1};
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, 3, &c), AMSCR_OK);
    ck_assert_int_eq(amscr_contour_write_text(c, path), AMSCR_E_IO);
    ck_assert_ptr_nonnull(strstr(amscr_last_error_detail(), path));
    ck_assert_int_eq(access(path, F_OK), -1);
    ck_assert_int_eq(count_entries(dir), 0);

    /* The path is a folder: rename fails, the temporary is removed. */
    ck_assert_int_eq(amscr_contour_write_text(c, dir), AMSCR_E_IO);
    ck_assert_int_eq(count_entries(dir), 0);
    amscr_contour_free(c);
    rm_tree(dir);
}
END_TEST

/* Reads the whole small file at path into buf (NUL-terminated); the bytes read. */
static size_t slurp(const char *path, char *buf, size_t cap)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    size_t got = fread(buf, 1, cap - 1, f);
    buf[got] = '\0';
    fclose(f);
    return got;
}

/* A program that set a locale whose decimal point is ',' (setlocale(LC_ALL, "") in a German
 * session, as GUI toolkits do) still reads and writes point lists with '.', and keeps its
 * locale. The locale is compiled into the build folder (tests/meson.build, AMSCR_TEST_LOCPATH). */
START_TEST(text_in_a_comma_locale)
{
    const char *dir = getenv("AMSCR_TEST_LOCPATH");
    if (!dir || !*dir) {
        printf("SKIP: contour_io: no locale with a decimal comma was built (Debian: apt-get install locales)\n");
        return;
    }
    ck_assert_int_eq(setenv("LOCPATH", dir, 1), 0);
    ck_assert_ptr_nonnull(setlocale(LC_ALL, "de_DE.UTF-8"));
    char num[16];
    snprintf(num, sizeof num, "%.1f", 0.5);
    ck_assert_str_eq(num, "0,5"); /* the premise: this locale writes a comma */

    amscr_contour *c = NULL;
    ck_assert_int_eq(parse("0 0\n10.5 0\n10.5, 10.25\n-0.125 1e-3\n", &c), AMSCR_OK);
    const double xy[] = {0, 0, 10.5, 0, 10.5, 10.25, -0.125, 1e-3};
    assert_points(c, xy, 4);

    char *tmp = make_tmpdir();
    char path[4200];
    snprintf(path, sizeof path, "%s/pts.txt", tmp);
    ck_assert_int_eq(amscr_contour_write_text(c, path), AMSCR_OK);
    char text[256];
    ck_assert_uint_gt(slurp(path, text, sizeof text), 0);
    ck_assert_str_eq(text, "0 0\n10.5 0\n10.5 10.25\n-0.125 0.001\n");
    amscr_contour *back = NULL;
    ck_assert_int_eq(amscr_contour_read_text(path, &back), AMSCR_OK);
    assert_points(back, xy, 4);

    /* The program's locale is as it set it. */
    ck_assert_ptr_eq(uselocale((locale_t)0), LC_GLOBAL_LOCALE);
    snprintf(num, sizeof num, "%.1f", 0.5);
    ck_assert_str_eq(num, "0,5");
    setlocale(LC_ALL, "C");
    unsetenv("LOCPATH");
    amscr_contour_free(back);
    amscr_contour_free(c);
    rm_tree(tmp);
}
END_TEST

/* A symbolic link keeps pointing to the file written (its mode kept); a dangling one gets its
 * file made; a FIFO is written through (its reader gets the text) and stays a FIFO. */
START_TEST(write_through_links_and_fifos)
{
    char *dir = make_tmpdir();
    char target[4200], link[4200], dangling[4200], made[4200], fifo[4200], text[256];
    snprintf(target, sizeof target, "%s/target.txt", dir);
    snprintf(link, sizeof link, "%s/link.txt", dir);
    snprintf(dangling, sizeof dangling, "%s/dangling.txt", dir);
    snprintf(made, sizeof made, "%s/made.txt", dir);
    snprintf(fifo, sizeof fifo, "%s/fifo.txt", dir);
    const double xy[] = {0, 0, 1.5, 0, 0, 2};
    amscr_contour *c = NULL;
    ck_assert_int_eq(amscr_contour_new(xy, 3, &c), AMSCR_OK);

    FILE *f = fopen(target, "wb");
    ck_assert_ptr_nonnull(f);
    fclose(f);
    ck_assert_int_eq(chmod(target, 0600), 0);
    ck_assert_int_eq(symlink("target.txt", link), 0);
    ck_assert_int_eq(amscr_contour_write_text(c, link), AMSCR_OK);
    struct stat sb;
    ck_assert_int_eq(lstat(link, &sb), 0);
    ck_assert(S_ISLNK(sb.st_mode));
    ck_assert_int_eq(stat(target, &sb), 0);
    ck_assert_uint_eq(sb.st_mode & 0777, 0600);
    slurp(target, text, sizeof text);
    ck_assert_str_eq(text, "0 0\n1.5 0\n0 2\n");

    ck_assert_int_eq(symlink("made.txt", dangling), 0);
    ck_assert_int_eq(amscr_contour_write_text(c, dangling), AMSCR_OK);
    ck_assert_int_eq(lstat(dangling, &sb), 0);
    ck_assert(S_ISLNK(sb.st_mode));
    slurp(made, text, sizeof text);
    ck_assert_str_eq(text, "0 0\n1.5 0\n0 2\n");

    ck_assert_int_eq(mkfifo(fifo, 0600), 0);
    int rd = open(fifo, O_RDONLY | O_NONBLOCK); /* a reader, so the writer does not wait */
    ck_assert_int_ge(rd, 0);
    ck_assert_int_eq(amscr_contour_write_text(c, fifo), AMSCR_OK);
    ssize_t n = read(rd, text, sizeof text - 1);
    close(rd);
    ck_assert_int_gt(n, 0);
    text[n] = '\0';
    ck_assert_str_eq(text, "0 0\n1.5 0\n0 2\n");
    ck_assert_int_eq(lstat(fifo, &sb), 0);
    ck_assert(S_ISFIFO(sb.st_mode));
    amscr_contour_free(c);
    rm_tree(dir);
}
END_TEST

/* The library's reads are close-on-exec (a program spawning another on a second thread does not
 * hand it the library's files). */
START_TEST(reads_are_close_on_exec)
{
    char *dir = make_tmpdir();
    char path[4200];
    snprintf(path, sizeof path, "%s/p.txt", dir);
    write_file(path, "0 0\n1 0\n0 1\n");
    FILE *f = amscr__fopen_read(path);
    ck_assert_ptr_nonnull(f);
    ck_assert_int_ne(fcntl(fileno(f), F_GETFD) & FD_CLOEXEC, 0);
    fclose(f);
    ck_assert_ptr_null(amscr__fopen_read(dir + strlen(dir))); /* "": no such file, errno set */
    ck_assert_int_eq(errno, ENOENT);
    rm_tree(dir);
}
END_TEST

Suite *amscr_suite_contour_io(void)
{
    Suite *s = suite_create("contour_io");
    TCase *tc = tcase_create("parse");
    tcase_add_test(tc, parse_separators);
    tcase_add_test(tc, parse_comments_blank_crlf);
    tcase_add_test(tc, parse_byte_order_mark);
    tcase_add_test(tc, parse_scientific_and_no_final_newline);
    tcase_add_test(tc, parse_not_nul_terminated);
    tcase_add_loop_test(tc, parse_bad_line, 0, (int)(sizeof bad_cases / sizeof bad_cases[0]));
    tcase_add_test(tc, parse_empty);
    tcase_add_test(tc, null_args);
    suite_add_tcase(s, tc);
    TCase *tf = tcase_create("files");
    tcase_add_test(tf, read_file_and_errors);
    tcase_add_test(tf, write_read_round_trip);
    tcase_add_test(tf, write_missing_dir);
    tcase_add_test(tf, text_in_a_comma_locale);
    tcase_add_test(tf, write_through_links_and_fifos);
    tcase_add_test(tf, reads_are_close_on_exec);
    suite_add_tcase(s, tf);
    return s;
}
