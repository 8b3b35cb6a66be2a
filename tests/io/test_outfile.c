/* tests/io/test_outfile.c -- output files written whole or not at all (host/outfile.h): every
 * operation that can fail on a full disk made to fail in turn (the fault hook, as SQLite tests
 * its I/O), for plain files, staged sets and images; the checks before work; the folders a run
 * makes and removes again. After each failure: the error names the file and says why, the final
 * name holds the old file or nothing, and no temporary file is left.
 */
#include <criterion/criterion.h>
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../../sim/heatmap.h"
#include "../../sim/img.h"
#include "../../host/outfile.h"

static char dir[64];

static void mkdir_tmp(void)
{
    strcpy(dir, "/tmp/sfsim-outfile-XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
}

static void rm_tree(const char *path)
{
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", path);
    cr_assert_eq(system(cmd), 0);
}

static void cleanup(void)
{
    rm_tree(dir);
}

/* Entries of folder d that are temporary files of host/outfile.c. */
static int temporaries(const char *d)
{
    DIR *h = opendir(d);
    cr_assert_not_null(h, "%s", d);
    int n = 0;
    for (struct dirent *e; (e = readdir(h));)
        n += strstr(e->d_name, ".tmp-") != NULL;
    closedir(h);
    return n;
}

/* The file's bytes (malloc'ed, *n its size), or NULL when it does not exist. */
static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)len + 1);
    cr_assert_not_null(buf);
    cr_assert_eq(fread(buf, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    *n = (size_t)len;
    return buf;
}

static int holds(const char *path, const void *data, size_t n)
{
    size_t m;
    char *got = slurp(path, &m);
    int same = got && m == n && memcmp(got, data, n) == 0;
    free(got);
    return same;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f);
    cr_assert_eq(fputs(text, f) >= 0, 1);
    cr_assert_eq(fclose(f), 0);
}

/* A file of 200,000 bytes written 1,000 at a time: the buffer is written in several pieces. */
static int write_big(const char *path, const char *data, char *err, size_t errlen)
{
    OutFile f;
    if (outfile_open(&f, path, err, errlen) != 0)
        return -1;
    for (int i = 0; i < 200; i++)
        if (outfile_write(&f, data + 1000 * i, 1000, err, errlen) != 0) {
            outfile_discard(&f);
            return -1;
        }
    return outfile_close(&f, NULL, err, errlen);
}

Test(outfile, a_file_is_written_whole_under_its_name, .init = mkdir_tmp, .fini = cleanup)
{
    char path[128], err[512];
    snprintf(path, sizeof path, "%s/a.txt", dir);
    cr_assert_eq(outfile_write_file(NULL, path, "hello\n", 6, err, sizeof err), 0, "%s", err);
    cr_expect(holds(path, "hello\n", 6));
    cr_expect_eq(temporaries(dir), 0);
    struct stat st;
    cr_assert_eq(stat(path, &st), 0);
    mode_t um = umask(0);
    umask(um);
    cr_expect_eq(st.st_mode & 0777, 0666 & ~um, "mode %o: not 0666 less the umask, as fopen makes it",
                 (unsigned)(st.st_mode & 0777));
    /* printf, large and small, across the buffer's end */
    OutFile f;
    cr_assert_eq(outfile_open(&f, path, err, sizeof err), 0, "%s", err);
    char big[100000];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = 0;
    cr_assert_eq(outfile_printf(&f, err, sizeof err, "%d %s|", 42, big), 0, "%s", err);
    cr_assert_eq(outfile_printf(&f, err, sizeof err, "end\n"), 0, "%s", err);
    cr_assert_eq(outfile_close(&f, NULL, err, sizeof err), 0, "%s", err);
    size_t n;
    char *got = slurp(path, &n);
    cr_assert_not_null(got);
    cr_expect_eq(n, 3 + sizeof big - 1 + 1 + 4);
    cr_expect(memcmp(got, "42 xxx", 6) == 0 && memcmp(got + n - 5, "|end\n", 5) == 0);
    free(got);
}

Test(outfile, every_operation_of_a_file_fails_in_turn, .init = mkdir_tmp, .fini = cleanup)
{
    static char data[200000], old[] = "the previous file\n";
    for (size_t i = 0; i < sizeof data; i++)
        data[i] = (char)('a' + i % 26);
    char path[128], err[512];
    snprintf(path, sizeof path, "%s/big.txt", dir);
    outfile_fail_at(0);
    cr_assert_eq(write_big(path, data, err, sizeof err), 0, "%s", err);
    long ops = outfile_ops();
    /* create, 4 writes of the 64 KiB buffer, fsync, close, rename */
    cr_expect_eq(ops, 8, "%ld operations", ops);
    for (int fresh = 0; fresh <= 1; fresh++) {
        for (long k = 1; k <= ops + 1; k++) {
            if (fresh)
                unlink(path);
            else
                put(path, old);
            outfile_fail_at(k);
            int rc = write_big(path, data, err, sizeof err);
            if (k == ops + 1) {
                cr_expect_eq(rc, 0, "k = %ld: %s", k, err);
                cr_expect(holds(path, data, sizeof data), "k = %ld: not whole", k);
                continue;
            }
            cr_expect_eq(rc, -1, "operation %ld of %ld did not fail", k, ops);
            cr_expect(strncmp(err, path, strlen(path)) == 0 && strstr(err, ": No space left on device"),
                      "k = %ld: %s", k, err);
            if (fresh)
                cr_expect_eq(access(path, F_OK), -1, "k = %ld: a file is left under the final name", k);
            else
                cr_expect(holds(path, old, strlen(old)), "k = %ld: the previous file was touched", k);
            cr_expect_eq(temporaries(dir), 0, "k = %ld: a temporary file is left", k);
        }
    }
    outfile_fail_at(0);
}

Test(outfile, a_set_goes_into_place_whole_or_leaves_no_mix, .init = mkdir_tmp, .fini = cleanup)
{
    static const char *const names[] = {"one.txt", "two.txt", "three.txt"};
    char path[3][128], err[512];
    for (int i = 0; i < 3; i++)
        snprintf(path[i], sizeof path[i], "%s/%s", dir, names[i]);
    long ops = -1;
    for (long k = 0; ops < 0 || k <= ops + 1; k++) {
        for (int i = 0; i < 3; i++)
            put(path[i], "old\n");
        outfile_fail_at(k);
        OutSet *set = outset_new();
        int rc = 0;
        for (int i = 0; i < 3 && rc == 0; i++)
            rc = outfile_write_file(set, path[i], "new\n", 4, err, sizeof err);
        /* staged, not yet in place */
        for (int i = 0; i < 3 && rc == 0; i++)
            cr_expect(holds(path[i], "old\n", 4), "k = %ld: %s replaced before the commit", k, names[i]);
        if (rc == 0)
            rc = outset_commit(set, err, sizeof err);
        outset_free(set);
        if (k == 0) {
            cr_assert_eq(rc, 0, "%s", err);
            ops = outfile_ops(); /* 3 x (create, write, fsync, close) + 3 renames */
            cr_expect_eq(ops, 15, "%ld operations", ops);
        }
        if (k == 0 || k == ops + 1) {
            cr_expect_eq(rc, 0, "k = %ld: %s", k, err);
            for (int i = 0; i < 3; i++)
                cr_expect(holds(path[i], "new\n", 4), "k = %ld: %s", k, names[i]);
            continue;
        }
        cr_expect_eq(rc, -1, "operation %ld of %ld did not fail", k, ops);
        cr_expect(strstr(err, dir) == err && strstr(err, "No space left on device"), "k = %ld: %s", k, err);
        int olds = 0, gone = 0;
        for (int i = 0; i < 3; i++) {
            cr_expect(!holds(path[i], "new\n", 4), "k = %ld: %s is new in a failed set", k, names[i]);
            olds += holds(path[i], "old\n", 4);
            gone += access(path[i], F_OK) != 0;
        }
        cr_expect(olds == 3 || gone == 3, "k = %ld: %d old files beside %d removed ones", k, olds, gone);
        cr_expect_eq(olds, k <= 12 ? 3 : 0, "k = %ld: the old files stay unless a rename failed", k);
        cr_expect_eq(temporaries(dir), 0, "k = %ld: a temporary file is left", k);
    }
    outfile_fail_at(0);
}

static long term_at;
static void term_hook(long op)
{
    if (op == term_at)
        raise(SIGTERM);
}

Test(outfile, a_signal_during_the_renames_waits_for_them, .init = mkdir_tmp, .fini = cleanup)
{
    char path[3][128], err[512];
    for (int i = 0; i < 3; i++) {
        snprintf(path[i], sizeof path[i], "%s/f%d.txt", dir, i);
        put(path[i], "old\n");
    }
    pid_t pid = fork();
    cr_assert_geq(pid, 0);
    if (pid == 0) {
        signal(SIGTERM, SIG_DFL);
        OutSet *set = outset_new();
        for (int i = 0; i < 3; i++)
            if (outfile_write_file(set, path[i], "new\n", 4, err, sizeof err) != 0)
                _exit(2);
        term_at = outfile_ops() + 2; /* SIGTERM just before the second rename */
        outfile_set_hook(term_hook);
        outset_commit(set, err, sizeof err);
        _exit(0); /* not reached: the held SIGTERM is raised again after the renames */
    }
    int st;
    cr_assert_eq(waitpid(pid, &st, 0), pid);
    cr_expect(WIFSIGNALED(st) && WTERMSIG(st) == SIGTERM, "the child was not ended by its SIGTERM (status %#x)", st);
    for (int i = 0; i < 3; i++)
        cr_expect(holds(path[i], "new\n", 4), "f%d.txt: the signal cut the renames short", i);
    cr_expect_eq(temporaries(dir), 0);
}

Test(outfile, images_and_heat_maps_fail_whole, .init = mkdir_tmp, .fini = cleanup)
{
    float px[4 * 2 * 3];
    double v[8];
    for (int i = 0; i < 24; i++)
        px[i] = 0.04f * (float)i;
    for (int i = 0; i < 8; i++)
        v[i] = i;
    static const char *const names[] = {"a.exr", "a.png", "cost.png"};
    for (int w = 0; w < 3; w++) {
        char path[128], err[512];
        snprintf(path, sizeof path, "%s/%s", dir, names[w]);
        for (long k = 1; k <= 6; k++) {
            unlink(path);
            outfile_fail_at(k);
            int rc = w == 0   ? img_write_linear(NULL, path, px, 4, 2, err, sizeof err)
                     : w == 1 ? img_write_display(NULL, path, px, 4, 2, 1.0f, err, sizeof err)
                              : heatmap_write(NULL, path, v, 4, 2, "t", "u", err, sizeof err);
            if (k == 6) { /* create, write, fsync, close, rename */
                cr_expect_eq(rc, 0, "%s: %s", names[w], err);
                float *back;
                int bw, bh;
                cr_expect_eq(img_read(path, &back, &bw, &bh, err, sizeof err), 0, "%s", err);
                free(back);
                continue;
            }
            cr_expect_eq(rc, -1, "%s: operation %ld did not fail", names[w], k);
            cr_expect(strncmp(err, path, strlen(path)) == 0 && strstr(err, "No space left on device"), "%s", err);
            cr_expect_eq(access(path, F_OK), -1, "%s, k = %ld: a file is left", names[w], k);
            cr_expect_eq(temporaries(dir), 0, "%s, k = %ld: a temporary file is left", names[w], k);
        }
    }
    outfile_fail_at(0);
}

Test(outfile, the_environment_hook_is_read_once)
{
    char path[] = "/tmp/sfsim-outfile-env-XXXXXX", err[512];
    int fd = mkstemp(path);
    cr_assert_geq(fd, 0);
    close(fd);
    /* Criterion runs each test in a fresh process: the hook is not yet read. */
    setenv("SFSIM_FAIL_WRITE", "2", 1);
    cr_expect_eq(outfile_write_file(NULL, path, "x", 1, err, sizeof err), -1, "operation 2 did not fail");
    cr_expect(strstr(err, ": cannot write: No space left on device"), "%s", err);
    setenv("SFSIM_FAIL_WRITE", "3", 1); /* read once: no effect now */
    cr_expect_eq(outfile_write_file(NULL, path, "x", 1, err, sizeof err), 0, "%s", err);
    unlink(path);
}

Test(outfile, the_hook_ignores_what_is_not_a_positive_number)
{
    char path[] = "/tmp/sfsim-outfile-env-XXXXXX", err[512];
    int fd = mkstemp(path);
    cr_assert_geq(fd, 0);
    close(fd);
    setenv("SFSIM_FAIL_WRITE", "2x", 1);
    cr_expect_eq(outfile_write_file(NULL, path, "x", 1, err, sizeof err), 0, "%s", err);
    unlink(path);
}

Test(outfile, links_devices_and_folders, .init = mkdir_tmp, .fini = cleanup)
{
    char path[192], link[128], sub[128], err[512];
    /* a symbolic link: the file it points to is replaced, the link stays */
    snprintf(sub, sizeof sub, "%s/sub", dir);
    cr_assert_eq(mkdir(sub, 0700), 0);
    snprintf(path, sizeof path, "%s/real.txt", sub);
    put(path, "old\n");
    snprintf(link, sizeof link, "%s/link.txt", dir);
    cr_assert_eq(symlink(path, link), 0);
    cr_assert_eq(outfile_write_file(NULL, link, "new\n", 4, err, sizeof err), 0, "%s", err);
    struct stat st;
    cr_assert_eq(lstat(link, &st), 0);
    cr_expect(S_ISLNK(st.st_mode), "the link was replaced by a file");
    cr_expect(holds(path, "new\n", 4));
    cr_expect_eq(temporaries(dir) + temporaries(sub), 0);
    /* a device is written as it is, not replaced */
    cr_assert_eq(outfile_write_file(NULL, "/dev/null", "x", 1, err, sizeof err), 0, "%s", err);
    cr_assert_eq(stat("/dev/null", &st), 0);
    cr_expect(S_ISCHR(st.st_mode), "/dev/null was replaced");
    /* a folder is not a file */
    cr_expect_eq(outfile_write_file(NULL, sub, "x", 1, err, sizeof err), -1);
    cr_expect(strstr(err, sub) == err && strstr(err, "is a folder"), "%s", err);
    cr_expect_eq(outfile_write_file(NULL, "/tmp/", "x", 1, err, sizeof err), -1);
    cr_expect_eq(outfile_write_file(NULL, "/nonexistent-dir/x.txt", "x", 1, err, sizeof err), -1);
    cr_expect(strstr(err, "/nonexistent-dir/x.txt: cannot create: No such file or directory") == err, "%s", err);
}

Test(outfile, checks_before_work, .init = mkdir_tmp, .fini = cleanup)
{
    char file[128], p[192], err[512];
    snprintf(file, sizeof file, "%s/file", dir);
    put(file, "x");
    /* folders */
    cr_expect_eq(outfile_check_dir(dir, err, sizeof err), 0, "%s", err);
    snprintf(p, sizeof p, "%s/new/deeper", dir);
    cr_expect_eq(outfile_check_dir(p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(access(p, F_OK), -1, "the check created the folder");
    snprintf(p, sizeof p, "%s/new", dir);
    cr_expect_eq(access(p, F_OK), -1, "the check created a folder");
    cr_expect_eq(outfile_check_dir(file, err, sizeof err), -1);
    cr_expect(strstr(err, file) == err && strstr(err, "exists and is not a folder"), "%s", err);
    snprintf(p, sizeof p, "%s/file/sub", dir);
    cr_expect_eq(outfile_check_dir(p, err, sizeof err), -1);
    cr_expect(strstr(err, p) == err && strstr(err, "file exists and is not a folder"), "%s", err);
    cr_expect_eq(outfile_check_dir("", err, sizeof err), -1);
    /* files */
    cr_expect_eq(outfile_check_file(file, err, sizeof err), 0, "%s", err);
    snprintf(p, sizeof p, "%s/hits.txt", dir);
    cr_expect_eq(outfile_check_file(p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(outfile_check_file(dir, err, sizeof err), -1);
    cr_expect(strstr(err, dir) == err && strstr(err, "is a folder"), "%s", err);
    snprintf(p, sizeof p, "%s/nodir/hits.txt", dir);
    cr_expect_eq(outfile_check_file(p, err, sizeof err), -1);
    cr_expect(strstr(err, p) == err && strstr(err, "No such file or directory"), "%s", err);
    snprintf(p, sizeof p, "%s/file/hits.txt", dir);
    cr_expect_eq(outfile_check_file(p, err, sizeof err), -1);
    cr_expect(strstr(err, p) == err, "%s", err);
    cr_expect_eq(outfile_check_file("/dev/null", err, sizeof err), 0, "%s", err);
}

Test(outfile, folders_made_are_removed_when_empty, .init = mkdir_tmp, .fini = cleanup)
{
    char p[192], q[192], f[256], err[512];
    snprintf(p, sizeof p, "%s/a/b/c", dir);
    OutDirs d = {0};
    cr_assert_eq(outfile_make_dirs(p, &d, err, sizeof err), 0, "%s", err);
    cr_expect_eq(d.n, 3);
    struct stat st;
    cr_expect(stat(p, &st) == 0 && S_ISDIR(st.st_mode));
    outfile_remove_dirs(&d);
    snprintf(q, sizeof q, "%s/a", dir);
    cr_expect_eq(access(q, F_OK), -1, "the folders made were not removed");
    cr_expect_eq(access(dir, F_OK), 0, "a folder that existed was removed");
    /* a folder that holds a file stays, and so do the ones around it */
    cr_assert_eq(outfile_make_dirs(p, &d, err, sizeof err), 0, "%s", err);
    snprintf(f, sizeof f, "%s/x", p);
    put(f, "x");
    outfile_remove_dirs(&d);
    cr_expect_eq(access(f, F_OK), 0);
    /* kept: nothing removed later */
    snprintf(q, sizeof q, "%s/k/l", dir);
    cr_assert_eq(outfile_make_dirs(q, &d, err, sizeof err), 0, "%s", err);
    outfile_keep_dirs(&d);
    outfile_remove_dirs(&d);
    cr_expect_eq(access(q, F_OK), 0);
    /* a fault while making the folders, and a file in the way */
    snprintf(q, sizeof q, "%s/m/n", dir);
    outfile_fail_at(2);
    OutDirs e = {0};
    cr_expect_eq(outfile_make_dirs(q, &e, err, sizeof err), -1);
    cr_expect(strstr(err, q) == err && strstr(err, "No space left on device"), "%s", err);
    outfile_fail_at(0);
    outfile_remove_dirs(&e);
    snprintf(q, sizeof q, "%s/m", dir);
    cr_expect_eq(access(q, F_OK), -1);
    snprintf(q, sizeof q, "%s/a/b/c/x/y", dir);
    cr_expect_eq(outfile_make_dirs(q, &e, err, sizeof err), -1);
    cr_expect(strstr(err, "exists and is not a folder"), "%s", err);
}
