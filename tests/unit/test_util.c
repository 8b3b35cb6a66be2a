/* tests/unit/test_util.c -- the shared helpers of sim/util.h: the monotonic clock, strict integer
 * parsing, mkdir -p, reading and atomically writing whole files, and the growable string buffer.
 *
 * Suites: util_clock, util_parse, util_files, util_buf.
 */
#include <criterion/criterion.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../../sim/util.h"
#include "../support/files.h"

/* ---- helpers ------------------------------------------------------------------------------------ */

static void make_tmpdir(char *dir, size_t len)
{
    snprintf(dir, len, "/tmp/sfsim-util-XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
}

static void write_file(const char *path, const char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f, "cannot create %s", path);
    cr_assert_eq(fwrite(data, 1, len, f), len);
    fclose(f);
}

static int is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* ---- the clock ---------------------------------------------------------------------------------- */

Test(util_clock, is_monotonic_and_counts_seconds)
{
    double a = util_now();
    struct timespec ts = {0, 30 * 1000 * 1000};
    nanosleep(&ts, NULL);
    double b = util_now();
    cr_expect_gt(a, 0.0);
    cr_expect_geq(b - a, 0.025, "30 ms of sleep measured as %g s", b - a);
    cr_expect_lt(b - a, 5.0, "30 ms of sleep measured as %g s", b - a);
}

/* ---- integers ----------------------------------------------------------------------------------- */

Test(util_parse, accepts_whole_decimal_integers_in_range)
{
    long long v = -1;
    cr_expect_eq(util_parse_int("12", 0, 100, &v), 0);
    cr_expect_eq(v, 12);
    cr_expect_eq(util_parse_int("-7", -10, 10, &v), 0);
    cr_expect_eq(v, -7);
    cr_expect_eq(util_parse_int("010", 0, 100, &v), 0);
    cr_expect_eq(v, 10, "decimal, not octal: got %lld", v);
    cr_expect_eq(util_parse_int("+3", 0, 100, &v), 0);
    cr_expect_eq(v, 3);
    /* the bounds are inclusive */
    cr_expect_eq(util_parse_int("1", 1, 4096, &v), 0);
    cr_expect_eq(util_parse_int("4096", 1, 4096, &v), 0);
    cr_expect_eq(v, 4096);
    cr_expect_eq(util_parse_int("9223372036854775807", 0, 9223372036854775807LL, &v), 0);
    cr_expect_eq(v, 9223372036854775807LL);
}

Test(util_parse, refuses_anything_else_and_leaves_the_output_alone)
{
    static const char *const bad[] = {"", "x", "12x", "1.5", "1e3", "0x10", "12 ", "--1", "-"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        long long v = 42;
        cr_expect_eq(util_parse_int(bad[i], -1000, 1000, &v), -1, "'%s' was taken", bad[i]);
        cr_expect_eq(v, 42, "'%s' changed the output", bad[i]);
    }
    long long v = 42;
    cr_expect_eq(util_parse_int("0", 1, 10, &v), -1, "below the range");
    cr_expect_eq(util_parse_int("11", 1, 10, &v), -1, "above the range");
    cr_expect_eq(util_parse_int("99999999999999999999", 0, 9223372036854775807LL, &v), -1, "overflow");
    cr_expect_eq(util_parse_int("-99999999999999999999", -9223372036854775807LL, 0, &v), -1, "underflow");
    cr_expect_eq(v, 42);
}

/* ---- folders and files -------------------------------------------------------------------------- */

Test(util_files, mkdir_p_makes_every_missing_folder)
{
    char dir[64], path[256], err[512] = "";
    make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/a/b/c", dir);
    cr_assert_eq(util_mkdir_p(path, err, sizeof err), 0, "%s", err);
    cr_expect(is_dir(path));
    /* again: it exists, which is fine; a trailing slash too */
    cr_expect_eq(util_mkdir_p(path, err, sizeof err), 0, "%s", err);
    snprintf(path, sizeof path, "%s/a/b/d/", dir);
    cr_expect_eq(util_mkdir_p(path, err, sizeof err), 0, "%s", err);
    snprintf(path, sizeof path, "%s/a/b/d", dir);
    cr_expect(is_dir(path));
    tu_remove_tree(dir);
}

Test(util_files, mkdir_p_says_what_is_in_the_way)
{
    char dir[64], file[128], path[256], err[512] = "", want[512];
    make_tmpdir(dir, sizeof dir);
    snprintf(file, sizeof file, "%s/f", dir);
    write_file(file, "x", 1);
    cr_expect_eq(util_mkdir_p(file, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: exists and is not a folder", file);
    cr_expect_str_eq(err, want);
    snprintf(path, sizeof path, "%s/f/sub", dir);
    cr_expect_eq(util_mkdir_p(path, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: cannot create the folder: ", path);
    cr_expect_eq(strncmp(err, want, strlen(want)), 0, "got: %s", err);
    tu_remove_tree(dir);
}

Test(util_files, file_read_returns_every_byte)
{
    char dir[64], path[128], err[512] = "";
    make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/data", dir);
    /* bigger than the 64 KiB read chunk, with NUL bytes inside */
    size_t n = 200000;
    char *data = malloc(n);
    cr_assert_not_null(data);
    for (size_t i = 0; i < n; i++)
        data[i] = (char)(i * 7 % 251);
    write_file(path, data, n);
    size_t len = 0;
    char *got = util_file_read(path, &len, err, sizeof err);
    cr_assert_not_null(got, "%s", err);
    cr_expect_eq(len, n);
    cr_expect_eq(memcmp(got, data, n), 0);
    cr_expect_eq(got[len], 0, "not NUL-terminated");
    free(got);
    free(data);
    /* an empty file is "" */
    write_file(path, "", 0);
    got = util_file_read(path, &len, err, sizeof err);
    cr_assert_not_null(got, "%s", err);
    cr_expect_eq(len, 0);
    cr_expect_str_eq(got, "");
    free(got);
    tu_remove_tree(dir);
}

Test(util_files, file_read_of_a_missing_file_says_so)
{
    char err[512] = "";
    size_t len = 99;
    cr_expect_null(util_file_read("/nonexistent/sfsim-util-test", &len, err, sizeof err));
    cr_expect_str_eq(err, "/nonexistent/sfsim-util-test: cannot open: No such file or directory");
}

/* ---- the string buffer -------------------------------------------------------------------------- */

Test(util_buf, appends_and_formats)
{
    UtilBuf b = {0};
    cr_expect_str_eq(util_buf_str(&b), "", "an empty buffer is \"\"");
    cr_expect_eq(util_buf_puts(&b, "point"), 0);
    cr_expect_eq(util_buf_printf(&b, ",%s=%d", "core.simd_width", 16), 0);
    cr_expect_eq(util_buf_add(&b, ",xyz", 2), 0);
    cr_expect_str_eq(util_buf_str(&b), "point,core.simd_width=16,x");
    cr_expect_eq(b.len, strlen("point,core.simd_width=16,x"));
    cr_expect_eq(b.failed, 0);
    util_buf_free(&b);
    cr_expect_null(b.s);
    cr_expect_eq(b.len, 0);
    cr_expect_str_eq(util_buf_str(&b), "");
}

Test(util_buf, grows_past_its_first_capacity)
{
    UtilBuf b = {0};
    for (int i = 0; i < 20000; i++)
        util_buf_printf(&b, "%05d", i);
    cr_assert_eq(b.len, 100000);
    cr_expect_eq(strlen(util_buf_str(&b)), 100000);
    cr_expect_eq(strncmp(b.s + 5 * 12345, "12345", 5), 0);
    cr_expect_str_eq(b.s + 5 * 19999, "19999");
    util_buf_free(&b);
}

Test(util_buf, a_failed_buffer_takes_nothing_more)
{
    UtilBuf b = {0};
    util_buf_puts(&b, "kept");
    b.failed = 1; /* as after a failed allocation */
    cr_expect_eq(util_buf_puts(&b, " dropped"), -1);
    cr_expect_eq(util_buf_printf(&b, "%d", 5), -1);
    cr_expect_str_eq(util_buf_str(&b), "kept");
    util_buf_free(&b);
    cr_expect_eq(b.failed, 0);
}
