/* tests/unit/test_infile.c -- the one check every input file passes (host/infile.h): a regular
 * file is read whole; a folder, a character device, a FIFO and a missing file are refused with the
 * reason before a byte is read; the cap holds for a file and for a file that grows past it.
 *
 * Suite: infile.
 */
#include <criterion/criterion.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../host/infile.h"
#include "../support/files.h"

static void expect_refused(const char *path, uint64_t cap, const char *why)
{
    char *buf = (char *)1, err[512] = "";
    size_t len = 7;
    cr_expect_eq(infile_read(path, cap, "a test file", &buf, &len, err, sizeof err), -1, "%s was read", path);
    cr_expect_null(buf);
    cr_expect_eq(len, 0);
    char want[600];
    snprintf(want, sizeof want, "%s: %s", path, why);
    cr_expect_str_eq(err, want);
    cr_expect_eq(infile_check(path, cap, "a test file", err, sizeof err), -1);
    cr_expect_str_eq(err, want, "infile_check says the same");
}

Test(infile, a_regular_file_is_read_whole_and_terminated)
{
    char dir[64], path[128], err[256];
    tu_make_tmpdir(dir, sizeof dir, "infile");
    snprintf(path, sizeof path, "%s/a.txt", dir);
    tu_write_file(path, "hello\n");
    char *buf;
    size_t len;
    cr_assert_eq(infile_read(path, 6, "a test file", &buf, &len, err, sizeof err), 0, "%s", err);
    cr_expect_eq(len, 6);
    cr_expect_str_eq(buf, "hello\n");
    free(buf);
    cr_expect_eq(infile_check(path, 0, "a test file", err, sizeof err), 0);
    uint64_t size = 0;
    int fd = infile_open(path, 0, "a test file", &size, err, sizeof err);
    cr_assert_geq(fd, 0, "%s", err);
    cr_expect_eq(size, 6);
    cr_expect_eq(fcntl(fd, F_GETFL) & O_NONBLOCK, 0, "the fd is left blocking");
    close(fd);
    tu_remove_tree(dir);
}

Test(infile, folders_devices_fifos_and_missing_files_are_refused_by_name)
{
    char dir[64], fifo[128];
    tu_make_tmpdir(dir, sizeof dir, "infile");
    expect_refused(dir, 0, "is a directory, not a regular file");
    expect_refused("/dev/zero", 0, "not a regular file (a character device)");
    expect_refused("/dev/null", 0, "not a regular file (a character device)");
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    cr_assert_eq(mkfifo(fifo, 0600), 0);
    expect_refused(fifo, 0, "not a regular file (a FIFO)"); /* and it did not wait for a writer */
    char missing[128];
    snprintf(missing, sizeof missing, "%s/none", dir);
    expect_refused(missing, 0, "cannot open: No such file or directory");
    tu_remove_tree(dir);
}

Test(infile, the_cap_is_said_in_mib_or_bytes)
{
    char dir[64], path[128];
    tu_make_tmpdir(dir, sizeof dir, "infile");
    snprintf(path, sizeof path, "%s/b.txt", dir);
    tu_write_file(path, "0123456789");
    expect_refused(path, 9, "larger than 9 bytes, the most a test file may hold");
    char *buf;
    size_t len;
    char err[256];
    cr_expect_eq(infile_read(path, 10, "a test file", &buf, &len, err, sizeof err), 0, "exactly the cap is taken");
    free(buf);
    int fd = open(path, O_WRONLY | O_TRUNC);
    cr_assert_geq(fd, 0);
    cr_assert_eq(ftruncate(fd, (2 << 20) + 1), 0);
    close(fd);
    expect_refused(path, 2 << 20, "larger than 2 MiB, the most a test file may hold");
    tu_remove_tree(dir);
}

Test(infile, the_reason_and_the_byte_order_mark)
{
    cr_expect_str_eq(infile_reason("/x/a.s: is a directory, not a regular file", "/x/a.s"),
                     "is a directory, not a regular file");
    cr_expect_str_eq(infile_reason("/x/a.s: cannot open: No such file or directory", "/x/a.s"),
                     "No such file or directory");
    cr_expect_str_eq(infile_reason("other: message", "/x/a.s"), "other: message");
    cr_expect_eq(infile_bom("\xef\xbb\xbfx", 4), 3);
    cr_expect_eq(infile_bom("\xef\xbb", 2), 0);
    cr_expect_eq(infile_bom("abc", 3), 0);
}
