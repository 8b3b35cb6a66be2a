/* tests/unit/test_memtrace.c -- memory traces (sim/mem/memtrace.h): what the writer writes the
 * reader reads back, both formats parse, and bad lines are refused naming file and line.
 *
 * Suites: memtrace.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/mem/memtrace.h"

static char *tmp_path(const char *name)
{
    static char p[256];
    snprintf(p, sizeof p, "/tmp/sfsim-mtr-%d-%s", (int)getpid(), name);
    return p;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs(text, f);
    fclose(f);
}

Test(memtrace, writer_round_trip)
{
    char err[512];
    const char *path = tmp_path("rt.mtr");
    MtrWriter *w = mtr_create(path, 500.25, err, sizeof err);
    cr_assert_not_null(w, "%s", err);
    cr_assert_eq(mtr_write(w, 3, 0, 0x1000, "core0", err, sizeof err), 0, "%s", err);
    cr_assert_eq(mtr_write(w, 3, 1, 0xffffffffffffffc0ULL, NULL, err, sizeof err), 0, "%s", err);
    cr_expect_eq(mtr_write(w, 2, 0, 0, NULL, err, sizeof err), -1); /* back in time */
    cr_expect_eq(mtr_write(w, 9, 0, 0, "two words", err, sizeof err), -1);
    cr_assert_eq(mtr_finish(w, err, sizeof err), 0, "%s", err);
    MtrReader *r = mtr_open(path, MTR_AUTO, err, sizeof err);
    cr_assert_not_null(r, "%s", err);
    cr_expect_eq(mtr_format(r), MTR_SFSIM);
    cr_expect_eq(mtr_clock_khz(r), 500250);
    MtrRecord rec;
    cr_assert_eq(mtr_next(r, &rec, err, sizeof err), 1, "%s", err);
    cr_expect(rec.cycle == 3 && !rec.write && rec.addr == 0x1000 && !strcmp(rec.source, "core0") && rec.line == 2);
    cr_assert_eq(mtr_next(r, &rec, err, sizeof err), 1, "%s", err);
    cr_expect(rec.write && rec.addr == 0xffffffffffffffc0ULL && !rec.source[0]);
    cr_expect_eq(mtr_next(r, &rec, err, sizeof err), 0);
    mtr_close(r);
    unlink(path);
}

Test(memtrace, dramsim3_format)
{
    char err[512];
    const char *path = tmp_path("d3.trc");
    put(path, "# DRAMsim3\n0x7ff0 READ 0\r\n\n0x40 WRITE 12\n0x80 R 12");
    MtrReader *r = mtr_open(path, MTR_AUTO, err, sizeof err);
    cr_assert_not_null(r, "%s", err);
    cr_expect_eq(mtr_format(r), MTR_DRAMSIM3);
    cr_expect_eq(mtr_clock_khz(r), 0);
    MtrRecord rec;
    cr_assert_eq(mtr_next(r, &rec, err, sizeof err), 1, "%s", err);
    cr_expect(rec.addr == 0x7ff0 && !rec.write && rec.cycle == 0 && rec.line == 2);
    cr_assert_eq(mtr_next(r, &rec, err, sizeof err), 1, "%s", err);
    cr_expect(rec.addr == 0x40 && rec.write && rec.cycle == 12 && rec.line == 4);
    cr_assert_eq(mtr_next(r, &rec, err, sizeof err), 1, "%s", err); /* no newline at the end */
    cr_expect(rec.addr == 0x80 && !rec.write && rec.line == 5);
    cr_expect_eq(mtr_next(r, &rec, err, sizeof err), 0);
    mtr_close(r);
    unlink(path);
}

Test(memtrace, bad_lines_name_file_and_line)
{
    static const char *const cases[][2] = {
        {"0x0 READ 5\n0x0 READ 4\n", ":2: cycle 4 is before"},
        {"0x0 READ 5\n0xg READ 6\n", ":2: bad address"},
        {"0x0 LOAD 5\n", ":1: bad operation 'LOAD'"},
        {"0x0 READ 5x\n", ":1: bad cycle '5x'"},
        {"0x0 READ 99999999999999999999\n", ":1: bad cycle"},
        {"READ 0x0 5\n", ":1: bad address 'READ'"},
        {"sfsim-memtrace 1 clock_mhz=0\n", ":1: expected the header"},
        {"sfsim-memtrace 1 clock_mhz=1.0001\n", ":1: expected the header"},
        {"sfsim-memtrace 1 clock_mhz=800\n5 R 0x0 a-source-name-longer-than-31-chars\n", ":2: source"},
        {"sfsim-memtrace 1 clock_mhz=800\n5 r 0x0\n", ":2: bad operation 'r'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char err[512] = "";
        const char *path = tmp_path("bad.trc");
        put(path, cases[i][0]);
        MtrReader *r = mtr_open(path, MTR_AUTO, err, sizeof err);
        int rc = -1;
        if (r) {
            MtrRecord rec;
            while ((rc = mtr_next(r, &rec, err, sizeof err)) == 1)
                ;
            mtr_close(r);
        }
        cr_expect_eq(rc, -1, "case %zu", i);
        cr_expect(strstr(err, path) && strstr(err, cases[i][1]), "case %zu: %s", i, err);
        unlink(path);
    }
}
