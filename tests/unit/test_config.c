/* tests/unit/test_config.c -- the machine configuration (sim/config.h) against sim/config.def.
 *
 * Defaults, ranges and help are written out here by hand from sim/config.def; error messages
 * follow the formats promised by sim/config.h ("FILE:LINE: key 'sec.key': message", "FILE:LINE:
 * message" for syntax, "--set ASSIGNMENT: message"). Also: docs/config.md must be what
 * cfg_markdown prints today, and configs/streamray.ini must load cleanly.
 *
 * Suites: config_defaults, config_load, config_set, config_check, config_params, config_files.
 */
#include <criterion/criterion.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../sim/config.h"

/* ---- helpers ------------------------------------------------------------------------------------ */

/* Write text to a fresh temporary .ini file; the caller unlinks path. */
static void write_temp(char *path, size_t len, const char *text)
{
    snprintf(path, len, "/tmp/sfsim-cfgtest-XXXXXX.ini");
    int fd = mkstemps(path, 4);
    cr_assert(fd >= 0, "mkstemps failed");
    FILE *f = fdopen(fd, "w");
    cr_assert_not_null(f);
    fputs(text, f);
    fclose(f);
}

/* Load text as a config file over the defaults; returns the count, fills errs. */
static int load_text(const char *text, CfgMachine *cfg, CfgErrors *errs, char *path, size_t pathlen)
{
    write_temp(path, pathlen, text);
    cfg_defaults(cfg);
    memset(errs, 0, sizeof *errs);
    int n = cfg_load(cfg, path, errs);
    unlink(path);
    return n;
}

/* The file must give exactly one error, with exactly this text after "PATH:". */
static void expect_one_error(const char *text, const char *after_path)
{
    char path[64], want[512];
    CfgMachine cfg;
    CfgErrors e;
    int n = load_text(text, &cfg, &e, path, sizeof path);
    snprintf(want, sizeof want, "%s:%s\n", path, after_path);
    cr_expect_eq(n, 1, "%d errors for:\n%s\ngot:\n%s", n, text, e.text ? e.text : "(none)");
    cr_expect_eq(e.count, 1);
    cr_expect_str_eq(e.text ? e.text : "", want);
    cfg_errors_free(&e);
}

static void expect_clean(const char *text, CfgMachine *cfg)
{
    char path[64];
    CfgErrors e;
    int n = load_text(text, cfg, &e, path, sizeof path);
    cr_expect_eq(n, 0, "errors for:\n%s\ngot:\n%s", text, e.text ? e.text : "");
    cr_expect_null(e.text);
    cfg_errors_free(&e);
}

/* ==== config_defaults ============================================================================== */

Test(config_defaults, values_from_config_def)
{
    CfgMachine c;
    memset(&c, 0x5A, sizeof c);
    cfg_defaults(&c);
    cr_expect_eq(c.core_simd_width, 16);
    cr_expect_eq(c.core_clock_mhz, 500.0);
    cr_expect_eq(c.stream_rays, 4096);
    cr_expect_eq(c.raybuf_size_kb, 512);
    cr_expect_eq(c.raybuf_banks, 32);
    cr_expect_eq(c.idm_size_kb, 32);
    cr_expect_eq(c.spad_size_kb, 64);
    cr_expect_eq(c.scene_size_mb, 256);
    cr_expect_eq(c.fb_size_kb, 256);
    cr_expect_eq(c.sim_max_instructions, INT64_C(10000000000));
}

Test(config_defaults, pass_the_cross_checks)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_check(&c, &e), 0, "%s", e.text ? e.text : "");
    cfg_errors_free(&e);
}

/* ==== config_load ================================================================================== */

Test(config_load, every_key)
{
    CfgMachine c;
    expect_clean("; the paper's machine, resized\n"
                 "[core]\n"
                 "simd_width = 12\n"
                 "clock_mhz = 750.5\n"
                 "\n"
                 "[stream]\n"
                 "rays = 1024\n"
                 "[raybuf]\n"
                 "size_kb=256\n"
                 "banks   =   16\n"
                 "[idm]\n"
                 "size_kb = 16 ; inline comment\n"
                 "[spad]\n"
                 "size_kb = 32\n"
                 "[scene]\n"
                 "size_mb = 8\n"
                 "[fb]\n"
                 "size_kb = 128\n"
                 "[sim]\n"
                 "max_instructions = 123456789012\n",
                 &c);
    cr_expect_eq(c.core_simd_width, 12);
    cr_expect_eq(c.core_clock_mhz, 750.5);
    cr_expect_eq(c.stream_rays, 1024);
    cr_expect_eq(c.raybuf_size_kb, 256);
    cr_expect_eq(c.raybuf_banks, 16);
    cr_expect_eq(c.idm_size_kb, 16);
    cr_expect_eq(c.spad_size_kb, 32);
    cr_expect_eq(c.scene_size_mb, 8);
    cr_expect_eq(c.fb_size_kb, 128);
    cr_expect_eq(c.sim_max_instructions, INT64_C(123456789012));
}

Test(config_load, keys_left_out_keep_their_defaults)
{
    CfgMachine c;
    expect_clean("[core]\nsimd_width = 8\n", &c);
    cr_expect_eq(c.core_simd_width, 8);
    cr_expect_eq(c.core_clock_mhz, 500.0);
    cr_expect_eq(c.stream_rays, 4096);
    cr_expect_eq(c.raybuf_size_kb, 512);
    cr_expect_eq(c.sim_max_instructions, INT64_C(10000000000));
    /* an empty file is a valid config */
    expect_clean("", &c);
    cr_expect_eq(c.core_simd_width, 16);
}

Test(config_load, range_limits_are_inclusive)
{
    CfgMachine c;
    expect_clean("[core]\nsimd_width = 1\nclock_mhz = 1\n[raybuf]\nsize_kb = 4\nbanks = 1\n", &c);
    cr_expect_eq(c.core_simd_width, 1);
    cr_expect_eq(c.raybuf_size_kb, 4);
    expect_clean("[core]\nsimd_width = 64\nclock_mhz = 100000\n[scene]\nsize_mb = 2047\n[fb]\nsize_kb = 2097151\n", &c);
    cr_expect_eq(c.core_simd_width, 64);
    cr_expect_eq(c.core_clock_mhz, 100000.0);
    cr_expect_eq(c.scene_size_mb, 2047);
    cr_expect_eq(c.fb_size_kb, 2097151);
    expect_clean("[sim]\nmax_instructions = 1\n", &c);
    cr_expect_eq(c.sim_max_instructions, 1);
    expect_clean("[sim]\nmax_instructions = 4000000000000000000\n", &c);
    cr_expect_eq(c.sim_max_instructions, INT64_C(4000000000000000000));
}

Test(config_load, unknown_section)
{
    expect_one_error("[core]\nsimd_width = 8\n[cache]\nsize_kb = 4\n", "4: key 'cache.size_kb': unknown section [cache]");
}

Test(config_load, unknown_key)
{
    expect_one_error("[core]\nwidth = 8\n", "2: key 'core.width': unknown key");
    /* a known key in the wrong (known) section */
    expect_one_error("[core]\nrays = 1024\n", "2: key 'core.rays': unknown key");
}

Test(config_load, not_a_number)
{
    expect_one_error("[core]\nsimd_width = abc\n", "2: key 'core.simd_width': expected an integer, got 'abc'");
    expect_one_error("[core]\nclock_mhz = fast\n", "2: key 'core.clock_mhz': expected a number, got 'fast'");
    /* an integer key does not take a fraction */
    expect_one_error("[core]\nsimd_width = 8.5\n", "2: key 'core.simd_width': expected an integer, got '8.5'");
    expect_one_error("[sim]\nmax_instructions = lots\n", "2: key 'sim.max_instructions': expected an integer, got 'lots'");
}

Test(config_load, trailing_junk)
{
    expect_one_error("[core]\nsimd_width = 12abc\n", "2: key 'core.simd_width': expected an integer, got '12abc'");
    expect_one_error("[core]\nclock_mhz = 500MHz\n", "2: key 'core.clock_mhz': expected a number, got '500MHz'");
    expect_one_error("[stream]\nrays = 4096 4096\n", "2: key 'stream.rays': expected an integer, got '4096 4096'");
}

Test(config_load, missing_value)
{
    expect_one_error("[core]\nsimd_width =\n", "2: key 'core.simd_width': missing value");
}

Test(config_load, out_of_range)
{
    expect_one_error("[core]\nsimd_width = 65\n", "2: key 'core.simd_width': value 65 out of range 1..64");
    expect_one_error("[core]\nsimd_width = 0\n", "2: key 'core.simd_width': value 0 out of range 1..64");
    expect_one_error("[core]\nsimd_width = -4\n", "2: key 'core.simd_width': value -4 out of range 1..64");
    expect_one_error("[core]\nclock_mhz = 0.5\n", "2: key 'core.clock_mhz': value 0.5 out of range 1..100000");
    expect_one_error("[raybuf]\nsize_kb = 65537\n", "2: key 'raybuf.size_kb': value 65537 out of range 4..65536");
    expect_one_error("[sim]\nmax_instructions = 0\n",
                     "2: key 'sim.max_instructions': value 0 out of range 1..4000000000000000000");
    /* beyond int64 itself */
    expect_one_error("[sim]\nmax_instructions = 99999999999999999999\n",
                     "2: key 'sim.max_instructions': value 99999999999999999999 out of range 1..4000000000000000000");
}

Test(config_load, int64_values_are_exact)
{
    /* sim.max_instructions is a 64-bit integer key: a value above 2^53 must arrive unchanged,
     * and one just above the maximum must be out of range. */
    CfgMachine c;
    expect_clean("[sim]\nmax_instructions = 9007199254740993\n", &c);
    cr_expect_eq(c.sim_max_instructions, INT64_C(9007199254740993), "max_instructions = %lld, expected 9007199254740993",
                 (long long)c.sim_max_instructions);
    expect_one_error("[sim]\nmax_instructions = 4000000000000000001\n",
                     "2: key 'sim.max_instructions': value 4000000000000000001 out of range 1..4000000000000000000");
}

Test(config_load, stream_rays_is_1024_or_4096)
{
    expect_one_error("[stream]\nrays = 2048\n", "2: key 'stream.rays': value 2048: must be 1024 or 4096");
    expect_one_error("[stream]\nrays = 1025\n", "2: key 'stream.rays': value 1025: must be 1024 or 4096");
    expect_one_error("[stream]\nrays = 512\n", "2: key 'stream.rays': value 512 out of range 1024..4096");
    CfgMachine c;
    expect_clean("[stream]\nrays = 1024\n", &c);
    cr_expect_eq(c.stream_rays, 1024);
    expect_clean("[stream]\nrays = 4096\n", &c);
    cr_expect_eq(c.stream_rays, 4096);
}

Test(config_load, syntax_error)
{
    expect_one_error("[core]\nsimd_width = 8\nclock_mhz 500\n",
                     "3: syntax error: expected 'key = value' or '[section]', got 'clock_mhz 500'");
    expect_one_error("[core]\nsimd_width = 8\n[stream\n", "3: syntax error: a section header is '[name]' alone on its line");
}

/* Every expected line must be in the text, and the count must match. */
static void expect_errors(const char *text, const char *const *after_path, int n)
{
    char path[64];
    CfgMachine cfg;
    CfgErrors e;
    int got = load_text(text, &cfg, &e, path, sizeof path);
    cr_expect_eq(got, n, "%d errors, expected %d; got:\n%s", got, n, e.text ? e.text : "");
    cr_expect_eq(e.count, n);
    for (int i = 0; i < n; i++) {
        char want[512];
        snprintf(want, sizeof want, "%s:%s\n", path, after_path[i]);
        cr_expect(e.text && strstr(e.text, want), "missing error '%s' in:\n%s", want, e.text ? e.text : "");
    }
    /* one line per error */
    int lines = 0;
    for (const char *p = e.text; p && *p; p++)
        lines += *p == '\n';
    cr_expect_eq(lines, n, "%d lines for %d errors", lines, n);
    cfg_errors_free(&e);
}

Test(config_load, all_errors_of_a_file_at_once)
{
    const char *text = "[core]\n"              /* 1 */
                       "simd_width = 99\n"     /* 2 out of range */
                       "clock_mhz = 500\n"     /* 3 fine */
                       "colour = red\n"        /* 4 unknown key */
                       "[stream]\n"            /* 5 */
                       "rays = 2000\n"         /* 6 not 1024/4096 */
                       "[gpu]\n"               /* 7 */
                       "cores = 4\n"           /* 8 unknown section */
                       "[idm]\n"               /* 9 */
                       "size_kb = 1x\n"        /* 10 junk */
                       "this is not ini\n";    /* 11 syntax */
    const char *want[] = {
        "2: key 'core.simd_width': value 99 out of range 1..64",
        "4: key 'core.colour': unknown key",
        "6: key 'stream.rays': value 2000: must be 1024 or 4096",
        "8: key 'gpu.cores': unknown section [gpu]",
        "10: key 'idm.size_kb': expected an integer, got '1x'",
        "11: syntax error: expected 'key = value' or '[section]', got 'this is not ini'",
    };
    expect_errors(text, want, 6);
}

Test(config_load, every_syntax_error_is_reported)
{
    /* config.h: every problem is reported, all of them -- syntax errors included */
    const char *text = "[core]\n"
                       "simd_width 8\n"        /* 2 */
                       "clock_mhz = 500\n"
                       "clock_mhz 500\n"       /* 4 */
                       "[stream]\n"
                       "rays = 1024\n";
    const char *want[] = {
        "2: syntax error: expected 'key = value' or '[section]', got 'simd_width 8'",
        "4: syntax error: expected 'key = value' or '[section]', got 'clock_mhz 500'",
    };
    expect_errors(text, want, 2);
}

/* The rules of every INI file (sim/ini.c, docs/ini.md), as the machine config meets them. Before
 * the one reader, the machine INI took a repeated key's last value silently and called a BOM a
 * syntax error; scene.ini and sweep files did neither. */
Test(config_load, a_key_given_twice_is_an_error_naming_both_lines)
{
    expect_one_error("[core]\nsimd_width = 8\nclock_mhz = 400\nsimd_width = 4\n",
                     "4: key 'core.simd_width': given twice (first at line 2)");
    /* also across a repeated section, which a machine config may have (config --dump writes one) */
    expect_one_error("[core]\nsimd_width = 8\n[stream]\nrays = 1024\n[core]\nsimd_width = 4\n",
                     "6: key 'core.simd_width': given twice (first at line 2)");
    CfgMachine c;
    expect_clean("[core]\nsimd_width = 8\n[stream]\nrays = 1024\n[core]\nclock_mhz = 400\n", &c);
    cr_expect_eq(c.core_simd_width, 8);
    cr_expect_eq(c.core_clock_mhz, 400.0);
}

Test(config_load, a_utf8_bom_and_crlf_are_fine)
{
    CfgMachine c;
    expect_clean("\xEF\xBB\xBF; saved by a Windows editor\r\n[core]\r\nsimd_width = 12\r\n", &c);
    cr_expect_eq(c.core_simd_width, 12);
    expect_clean("\xEF\xBB\xBF[stream]\nrays = 1024\n", &c);
    cr_expect_eq(c.stream_rays, 1024);
}

Test(config_load, a_value_continued_on_an_indented_line_is_an_error)
{
    /* inih would hand the handler the key again with "4": the last value won, silently */
    expect_one_error("[core]\nsimd_width = 8\n    4\n",
                     "2: key 'core.simd_width': continued on an indented line: the value must be on one line");
}

Test(config_load, key_outside_any_section_and_long_lines)
{
    expect_one_error("simd_width = 8\n[core]\n", "1: key 'simd_width': outside any section");
    char text[512];
    snprintf(text, sizeof text, "[core]\n; %0200d\nsimd_width = 8\n", 0);
    expect_one_error(text, "2: line longer than 198 characters");
}

static void expect_load_error(const char *path, const char *want)
{
    CfgMachine c, before;
    cfg_defaults(&c);
    before = c;
    CfgErrors e = {0};
    cr_expect_eq(cfg_load(&c, path, &e), 1, "%s was loaded", path);
    cr_expect_str_eq(e.text ? e.text : "", want);
    cr_expect_eq(memcmp(&c, &before, sizeof c), 0, "a failed load changed the config");
    cfg_errors_free(&e);
}

Test(config_load, a_directory_device_or_fifo_is_refused)
{
    /* a directory was read as an empty file: -c DIR silently ran the built-in machine */
    char dir[] = "/tmp/sfsim-cfgdir-XXXXXX", want[256];
    cr_assert_not_null(mkdtemp(dir));
    snprintf(want, sizeof want, "%s: is a directory, not a regular file\n", dir);
    expect_load_error(dir, want);
    /* /dev/zero was read forever */
    expect_load_error("/dev/zero", "/dev/zero: not a regular file (a character device)\n");
    char fifo[64];
    snprintf(fifo, sizeof fifo, "%s/fifo.ini", dir);
    cr_assert_eq(mkfifo(fifo, 0600), 0);
    snprintf(want, sizeof want, "%s: not a regular file (a FIFO)\n", fifo);
    expect_load_error(fifo, want);
    unlink(fifo);
    rmdir(dir);
}

Test(config_load, from_text_in_memory)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    const char *text = "[core]\nsimd_width = 4\nbogus = 1\n";
    cr_expect_eq(cfg_load_text(&c, text, strlen(text), "mem.ini", &e), 1);
    cr_expect_str_eq(e.text ? e.text : "", "mem.ini:3: key 'core.bogus': unknown key\n");
    cr_expect_eq(c.core_simd_width, 4);
    cfg_errors_free(&e);
}

Test(config_load, missing_file)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    const char *path = "/nonexistent/sfsim/machine.ini";
    cr_expect_eq(cfg_load(&c, path, &e), 1);
    cr_expect_str_eq(e.text ? e.text : "", "/nonexistent/sfsim/machine.ini: cannot open: No such file or directory\n");
    cfg_errors_free(&e);
}

Test(config_load, errors_accumulate_across_calls)
{
    /* cfg_* return the number of errors of the call; the buffer collects all of them */
    char path[64];
    write_temp(path, sizeof path, "[core]\nsimd_width = 0\nbogus = 1\n");
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_load(&c, path, &e), 2);
    cr_expect_eq(cfg_set(&c, "core.simd_width=100", &e), 1);
    cr_expect_eq(cfg_set(&c, "core.simd_width=8", &e), 0);
    cr_expect_eq(e.count, 3);
    char want[512];
    snprintf(want, sizeof want,
             "%s:2: key 'core.simd_width': value 0 out of range 1..64\n"
             "%s:3: key 'core.bogus': unknown key\n"
             "--set core.simd_width=100: value 100 out of range 1..64\n",
             path, path);
    cr_expect_str_eq(e.text ? e.text : "", want);
    cr_expect_eq(c.core_simd_width, 8);
    unlink(path);
    cfg_errors_free(&e);
}

/* ==== config_set ==================================================================================== */

Test(config_set, valid_assignments)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_set(&c, "core.simd_width=12", &e), 0);
    cr_expect_eq(cfg_set(&c, "core.clock_mhz=1250.25", &e), 0);
    cr_expect_eq(cfg_set(&c, "stream.rays=1024", &e), 0);
    cr_expect_eq(cfg_set(&c, "sim.max_instructions=5000000000", &e), 0);
    cr_expect_eq(cfg_set(&c, "fb.size_kb=1024", &e), 0);
    cr_expect_eq(e.count, 0, "%s", e.text ? e.text : "");
    cr_expect_eq(c.core_simd_width, 12);
    cr_expect_eq(c.core_clock_mhz, 1250.25);
    cr_expect_eq(c.stream_rays, 1024);
    cr_expect_eq(c.sim_max_instructions, INT64_C(5000000000));
    cr_expect_eq(c.fb_size_kb, 1024);
    /* the last assignment wins */
    cr_expect_eq(cfg_set(&c, "core.simd_width=4", &e), 0);
    cr_expect_eq(c.core_simd_width, 4);
    /* integers are decimal: a leading zero does not make octal */
    cr_expect_eq(cfg_set(&c, "core.simd_width=010", &e), 0);
    cr_expect_eq(c.core_simd_width, 10);
    cfg_errors_free(&e);
}

static void expect_set_error(const char *assignment, const char *want_line)
{
    CfgMachine c, before;
    cfg_defaults(&c);
    before = c;
    CfgErrors e = {0};
    cr_expect_eq(cfg_set(&c, assignment, &e), 1, "--set %s was accepted", assignment);
    char want[512];
    snprintf(want, sizeof want, "%s\n", want_line);
    cr_expect_str_eq(e.text ? e.text : "", want);
    cr_expect_eq(memcmp(&c, &before, sizeof c), 0, "--set %s changed the config", assignment);
    cfg_errors_free(&e);
}

Test(config_set, errors)
{
    expect_set_error("core.simd_width", "--set core.simd_width: expected section.key=value");
    expect_set_error("simd_width=8", "--set simd_width=8: expected section.key=value");
    expect_set_error(".simd_width=8", "--set .simd_width=8: expected section.key=value");
    expect_set_error("core.=8", "--set core.=8: expected section.key=value");
    expect_set_error("core.nokey=1", "--set core.nokey=1: unknown key 'core.nokey' (sfsim config --dump lists them)");
    expect_set_error("gpu.cores=4", "--set gpu.cores=4: unknown key 'gpu.cores' (sfsim config --dump lists them)");
    expect_set_error("core.simd_width=999", "--set core.simd_width=999: value 999 out of range 1..64");
    expect_set_error("core.simd_width=abc", "--set core.simd_width=abc: expected an integer, got 'abc'");
    expect_set_error("core.simd_width=8x", "--set core.simd_width=8x: expected an integer, got '8x'");
    expect_set_error("core.clock_mhz=fast", "--set core.clock_mhz=fast: expected a number, got 'fast'");
    expect_set_error("core.simd_width=", "--set core.simd_width=: missing value");
    expect_set_error("stream.rays=2048", "--set stream.rays=2048: value 2048: must be 1024 or 4096");
}

Test(config_set, int64_values_are_exact)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_set(&c, "sim.max_instructions=9007199254740993", &e), 0);
    cr_expect_eq(c.sim_max_instructions, INT64_C(9007199254740993), "max_instructions = %lld, expected 9007199254740993",
                 (long long)c.sim_max_instructions);
    cfg_errors_free(&e);
}

/* ==== config_check ================================================================================== */

static void expect_check(const char *const *sets, int nsets, const char *want)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    for (int i = 0; i < nsets; i++)
        cr_assert_eq(cfg_set(&c, sets[i], &e), 0, "%s", e.text);
    int n = cfg_check(&c, &e);
    int lines = 0;
    for (const char *p = want; *p; p++)
        lines += *p == '\n';
    cr_expect_eq(n, lines, "cfg_check gave %d errors, expected %d:\n%s", n, lines, e.text ? e.text : "");
    cr_expect_str_eq(e.text ? e.text : "", want);
    cfg_errors_free(&e);
}

Test(config_check, cross_key_errors)
{
    /* ray-buffer size must divide into banks */
    const char *a[] = {"raybuf.size_kb=1000", "raybuf.banks=3"};
    expect_check(a, 2, "config: raybuf.size_kb = 1000 is not divisible by raybuf.banks = 3\n");
    /* M rays of 128 bytes must fit one ray buffer: 4096 x 128 B = 512 KiB */
    const char *b[] = {"raybuf.size_kb=256", "raybuf.banks=32"};
    expect_check(b, 2, "config: stream.rays = 4096 needs 512 KiB of ray buffer at 128 bytes per ray, raybuf.size_kb = 256\n");
    /* two streams of M IDs: 2 x 4096 x 4 B = 32 KiB of IDM */
    const char *c[] = {"idm.size_kb=16"};
    expect_check(c, 1, "config: stream.rays = 4096 needs 32 KiB of ID-stream memory (two streams), idm.size_kb = 16\n");
    /* all three at once */
    const char *d[] = {"raybuf.size_kb=100", "idm.size_kb=31"};
    expect_check(d, 2,
                 "config: raybuf.size_kb = 100 is not divisible by raybuf.banks = 32\n"
                 "config: stream.rays = 4096 needs 512 KiB of ray buffer at 128 bytes per ray, raybuf.size_kb = 100\n"
                 "config: stream.rays = 4096 needs 32 KiB of ID-stream memory (two streams), idm.size_kb = 31\n");
    /* the forced specular workload bounces at least once; phong may have no bounce at all, and
     * the bounce count of another workload is not checked */
    const char *e[] = {"workload.kind=specular", "workload.bounces=0"};
    expect_check(e, 2, "config: workload.bounces = 0: workload.kind = specular needs at least 1 bounce\n");
    const char *f[] = {"workload.kind=phong", "workload.bounces=0"};
    expect_check(f, 2, "");
    const char *g[] = {"workload.bounces=0"};
    expect_check(g, 1, "");
}

Test(config_check, boundaries_pass)
{
    /* exactly full is fine: 1024 rays need 128 KiB of ray buffer and 8 KiB of IDM */
    const char *a[] = {"stream.rays=1024", "raybuf.size_kb=128", "raybuf.banks=32", "idm.size_kb=8"};
    expect_check(a, 4, "");
    const char *b[] = {"stream.rays=1024", "raybuf.size_kb=127", "raybuf.banks=1"};
    expect_check(b, 3, "config: stream.rays = 1024 needs 128 KiB of ray buffer at 128 bytes per ray, raybuf.size_kb = 127\n");
    const char *c[] = {"stream.rays=1024", "idm.size_kb=7"};
    expect_check(c, 2, "config: stream.rays = 1024 needs 8 KiB of ID-stream memory (two streams), idm.size_kb = 7\n");
}

/* ==== config_params ================================================================================= */

Test(config_params, core_params_from_keys)
{
    CfgMachine c;
    cfg_defaults(&c);
    CoreParams p;
    memset(&p, 0xA5, sizeof p);
    cfg_core_params(&c, &p);
    cr_expect_eq(p.lanes, 16);
    cr_expect_eq(p.mem_bytes[CORE_MEM_RB0], 512u * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_RB1], 512u * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_IDM], 32u * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_SPAD], 64u * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_SCENE], 256u * 1024 * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_FB], 256u * 1024);

    CfgErrors e = {0};
    cfg_set(&c, "core.simd_width=12", &e);
    cfg_set(&c, "scene.size_mb=2047", &e);
    cfg_set(&c, "fb.size_kb=2097151", &e);
    cfg_set(&c, "raybuf.size_kb=65536", &e);
    cr_assert_eq(e.count, 0, "%s", e.text);
    cfg_core_params(&c, &p);
    cr_expect_eq(p.lanes, 12);
    cr_expect_eq(p.mem_bytes[CORE_MEM_SCENE], 2047u * 1024 * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_FB], 2097151u * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_RB0], 64u * 1024 * 1024);
    cr_expect_eq(p.mem_bytes[CORE_MEM_RB1], 64u * 1024 * 1024);
    cfg_errors_free(&e);
}

Test(config_params, dump_lists_every_key_with_its_value)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cfg_set(&c, "core.simd_width=12", &e);
    cfg_set(&c, "sim.max_instructions=777", &e);
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    cr_assert_not_null(f);
    cfg_dump(&c, f);
    fclose(f);
    const char *must[] = {"[core]\n", "simd_width = 12\n", "clock_mhz = 500\n", "[stream]\n", "rays = 4096\n",
                          "[raybuf]\n", "size_kb = 512\n", "banks = 32\n", "[idm]\n", "[spad]\n", "[scene]\n",
                          "size_mb = 256\n", "[fb]\n", "size_kb = 256\n", "[sim]\n", "max_instructions = 777\n"};
    for (size_t i = 0; i < sizeof must / sizeof must[0]; i++)
        cr_expect(strstr(buf, must[i]) != NULL, "dump lacks '%s':\n%s", must[i], buf);
    free(buf);
    cfg_errors_free(&e);
}

/* ==== config_files ================================================================================== */

static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = NULL;
    size_t cap = 0, n = 0;
    for (;;) {
        if (n + 4096 > cap) {
            cap = 2 * cap + 4096;
            char *t = realloc(buf, cap);
            if (!t) {
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = t;
        }
        size_t got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0)
            break;
    }
    fclose(f);
    *len = n;
    return buf;
}

Test(config_files, docs_config_md_is_current)
{
    char *want = NULL;
    size_t wantlen = 0;
    FILE *f = open_memstream(&want, &wantlen);
    cr_assert_not_null(f);
    cfg_markdown(f);
    fclose(f);
    size_t havelen = 0;
    char *have = read_all("docs/config.md", &havelen);
    int same = have && havelen == wantlen && memcmp(have, want, wantlen) == 0;
    cr_expect(same, "docs/config.md is stale: run bin/sfsim config --markdown > docs/config.md");
    free(have);
    free(want);
}

Test(config_files, streamray_ini_loads_cleanly)
{
    const char *path = "configs/streamray.ini";
    cr_assert(access(path, R_OK) == 0, "%s is missing (it is the paper's machine and the default -c)", path);
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_load(&c, path, &e), 0, "%s", e.text ? e.text : "");
    cr_expect_eq(cfg_check(&c, &e), 0, "%s", e.text ? e.text : "");
    cfg_errors_free(&e);
}

Test(config_files, streamray_ini_is_the_default_machine)
{
    /* config.def: the defaults are the machine of Gribble & Ramani 2008, Sec. 3.3, which is what
     * configs/streamray.ini describes. */
    const char *path = "configs/streamray.ini";
    cr_assert(access(path, R_OK) == 0, "%s is missing", path);
    CfgMachine def, c;
    cfg_defaults(&def);
    memset(&c, 0, sizeof c);
    cfg_defaults(&c);
    CfgErrors e = {0};
    cfg_load(&c, path, &e);
    cfg_errors_free(&e);
    cr_expect_eq(c.core_simd_width, def.core_simd_width);
    cr_expect_eq(c.core_clock_mhz, def.core_clock_mhz);
    cr_expect_eq(c.stream_rays, def.stream_rays);
    cr_expect_eq(c.raybuf_size_kb, def.raybuf_size_kb);
    cr_expect_eq(c.raybuf_banks, def.raybuf_banks);
    cr_expect_eq(c.idm_size_kb, def.idm_size_kb);
    cr_expect_eq(c.spad_size_kb, def.spad_size_kb);
    cr_expect_eq(c.scene_size_mb, def.scene_size_mb);
    cr_expect_eq(c.fb_size_kb, def.fb_size_kb);
    cr_expect_eq(c.sim_max_instructions, def.sim_max_instructions);
}

Test(config_params, enum_keys_take_names_and_reject_others)
{
    CfgMachine c;
    cfg_defaults(&c);
    cr_expect_eq(c.stream_mode, CFG_STREAM_MODE_STREAM);
    cr_expect_eq(c.workload_kind, CFG_WORKLOAD_PATH);
    CfgErrors e = {0};
    cr_expect_eq(cfg_set(&c, "stream.mode=packet", &e), 0);
    cr_expect_eq(c.stream_mode, CFG_STREAM_MODE_PACKET);
    cr_expect_eq(cfg_set(&c, "workload.kind=diffuse", &e), 0);
    cr_expect_eq(c.workload_kind, CFG_WORKLOAD_DIFFUSE);
    cr_expect_eq(cfg_set(&c, "workload.kind=2", &e), 1);
    cr_expect_eq(cfg_set(&c, "workload.kind=specularity", &e), 1);
    cr_expect(e.text && strstr(e.text, "expected one of path, specular, diffuse, phong, got 'specularity'"), "%s",
              e.text ? e.text : "");
    cr_expect_eq(c.workload_kind, CFG_WORKLOAD_DIFFUSE);
    cr_expect_eq(cfg_set(&c, "workload.kind=phong", &e), 0);
    cr_expect_eq(c.workload_kind, CFG_WORKLOAD_PHONG);
    cr_expect_eq(cfg_set(&c, "workload.bounces=0", &e), 0);
    cr_expect_eq(cfg_set(&c, "workload.bounces=-1", &e), 1);
    cr_expect_str_eq(cfg_enum_name("stream", "mode", 1), "packet");
    cr_expect_null(cfg_enum_name("core", "simd_width", 0));
    cfg_errors_free(&e);
}

/* ==== kd-tree keys (accel.structure, kd.*) ============================================================ */

Test(config_params, kd_keys_defaults)
{
    CfgMachine c;
    cfg_defaults(&c);
    cr_expect_eq(c.accel_structure, CFG_ACCEL_BVH);
    cr_expect_eq(c.kd_traversal, CFG_KD_STACK);
    cr_expect_eq(c.kd_stack_depth, 3);
    cr_expect_eq(c.kd_cost_traversal, 1.0);
    cr_expect_eq(c.kd_cost_intersect, 1.0);
    cr_expect_eq(c.kd_empty_bonus, 0.8);
    cr_expect_eq(c.kd_max_depth, 0);
    cr_expect_eq(c.kd_leaf_size, 1);
}

Test(config_load, kd_keys)
{
    CfgMachine c;
    expect_clean("[accel]\nstructure = kd\n[kd]\ntraversal = shortstack\nstack_depth = 64\ncost_traversal = 0.5\n"
                 "cost_intersect = 2\nempty_bonus = 1\nmax_depth = 60\nleaf_size = 8\n",
                 &c);
    cr_expect_eq(c.accel_structure, CFG_ACCEL_KD);
    cr_expect_eq(c.kd_traversal, CFG_KD_SHORTSTACK);
    cr_expect_eq(c.kd_stack_depth, 64);
    cr_expect_eq(c.kd_cost_traversal, 0.5);
    cr_expect_eq(c.kd_cost_intersect, 2.0);
    cr_expect_eq(c.kd_empty_bonus, 1.0);
    cr_expect_eq(c.kd_max_depth, 60);
    cr_expect_eq(c.kd_leaf_size, 8);
    /* every traversal name, in KD_VARIANT order (kernels/lib/kconst.inc is generated from these names) */
    const char *names[] = {"stack", "restart", "pushdown", "shortstack", "packet", "stream"};
    CfgErrors e = {0};
    for (int i = 0; i < 6; i++) {
        char set[64];
        snprintf(set, sizeof set, "kd.traversal=%s", names[i]);
        cr_expect_eq(cfg_set(&c, set, &e), 0, "%s", e.text ? e.text : "");
        cr_expect_eq(c.kd_traversal, i, "%s", names[i]);
        cr_expect_str_eq(cfg_enum_name("kd", "traversal", i), names[i]);
    }
    cr_expect_eq(c.kd_traversal, CFG_KD_STREAM);
    cr_expect_null(cfg_enum_name("kd", "traversal", 6));
    cr_expect_str_eq(cfg_enum_name("accel", "structure", CFG_ACCEL_KD), "kd");
    cfg_errors_free(&e);
}

Test(config_load, kd_bad_values_name_the_key)
{
    expect_one_error("[accel]\nstructure = octree\n", "2: key 'accel.structure': expected one of bvh, kd, got 'octree'");
    expect_one_error("[kd]\ntraversal = shortstak\n",
                     "2: key 'kd.traversal': expected one of stack, restart, pushdown, shortstack, packet, stream, got "
                     "'shortstak'");
    expect_one_error("[kd]\nstack_depth = 0\n", "2: key 'kd.stack_depth': value 0 out of range 1..64");
    expect_one_error("[kd]\nstack_depth = 65\n", "2: key 'kd.stack_depth': value 65 out of range 1..64");
    expect_one_error("[kd]\nmax_depth = 61\n", "2: key 'kd.max_depth': value 61 out of range 0..60");
    expect_one_error("[kd]\nleaf_size = 0\n", "2: key 'kd.leaf_size': value 0 out of range 1..64");
    expect_one_error("[kd]\nempty_bonus = 1.5\n", "2: key 'kd.empty_bonus': value 1.5 out of range 0..1");
    /* the builder takes costs > 0 and a bonus in (0, 1]: 0 (or what rounds to 0 in binary32) is refused */
    expect_one_error("[kd]\nempty_bonus = 0\n", "2: key 'kd.empty_bonus': value 0: must be greater than 0");
    expect_one_error("[kd]\ncost_traversal = 0\n", "2: key 'kd.cost_traversal': value 0: must be greater than 0");
    expect_one_error("[kd]\ncost_intersect = 1e-60\n",
                     "2: key 'kd.cost_intersect': value 1e-60: must be greater than 0");
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_expect_eq(cfg_set(&c, "kd.traversal=bogus", &e), 1);
    cr_expect(e.text && strstr(e.text, "--set kd.traversal=bogus: expected one of stack,"), "%s", e.text ? e.text : "");
    cr_expect_eq(c.kd_traversal, CFG_KD_STACK);
    cfg_errors_free(&e);
}
