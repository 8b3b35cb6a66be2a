/* tests/unit/test_ini.c -- the one INI reader (sim/ini.h) against docs/ini.md: comments, sections,
 * key = value, blanks, continuation lines, a UTF-8 BOM and CRLF, a section or key given twice,
 * line and size limits, files that are no regular files, the order and cap of the messages, and
 * lookups. Machine configs, scene.ini and sweep files are each tested through their own loader
 * (test_config.c, test_scene_ini.c, tests/cli/sweep.sh); this is the syntax they share.
 *
 * Suites: ini_syntax, ini_errors, ini_files.
 */
#include <criterion/criterion.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../../sim/ini.h"

/* ---- helpers ------------------------------------------------------------------------------------ */

static int parse(IniFile *f, const char *text, const IniOptions *opt)
{
    return inifile_parse(f, "t.ini", text, strlen(text), opt);
}

/* All messages, one a line. */
static char *messages(IniFile *f)
{
    static char buf[1 << 16];
    int n;
    const IniMessage *m = inifile_messages(f, &n);
    buf[0] = 0;
    for (int i = 0; i < n; i++) {
        strncat(buf, m[i].text, sizeof buf - strlen(buf) - 2);
        strcat(buf, "\n");
    }
    return buf;
}

/* text must give exactly these messages (after "t.ini:"), in this order. */
static void expect_messages(const char *text, const IniOptions *opt, const char *want)
{
    IniFile f;
    parse(&f, text, opt);
    char expect[4096] = "";
    for (const char *p = want; *p;) {
        const char *nl = strchr(p, '\n');
        size_t n = nl ? (size_t)(nl - p + 1) : strlen(p);
        strcat(expect, "t.ini:");
        strncat(expect, p, n);
        p += n;
    }
    cr_expect_str_eq(messages(&f), expect, "for:\n%s", text);
    inifile_free(&f);
}

static const IniEntry *entry(const IniFile *f, int i)
{
    cr_assert_lt(i, f->nentries, "only %d entries", f->nentries);
    return &f->entries[i];
}

/* ==== ini_syntax ================================================================================= */

Test(ini_syntax, sections_keys_values_comments_and_blanks)
{
    IniFile f;
    int n = parse(&f,
                  "; a comment\n"
                  "# another\n"
                  "\n"
                  "[core]\n"
                  "simd_width = 8\n"
                  "clock_mhz=500 ; inline comment after a blank\n"
                  "  \t indented_key  =   spaced value  \n"
                  "url = a;b#c\n"        /* ; and # without a blank before them are the value's */
                  "eq = x = y\n"         /* the first '=' separates */
                  "colon = c:/d\n"
                  "empty =\n"
                  "[ stream ]  # a comment after a header\n"
                  "rays = 1024\n",
                  NULL);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_assert_eq(f.nsections, 2);
    cr_expect_str_eq(f.sections[0].name, "core");
    cr_expect_eq(f.sections[0].line, 4);
    cr_expect_eq(f.sections[0].nkeys, 7);
    cr_expect_str_eq(f.sections[1].name, "stream");
    cr_expect_eq(f.sections[1].line, 12);
    cr_assert_eq(f.nentries, 8);
    const char *want[][3] = {{"core", "simd_width", "8"},  {"core", "clock_mhz", "500"},
                             {"core", "indented_key", "spaced value"}, {"core", "url", "a;b#c"},
                             {"core", "eq", "x = y"},      {"core", "colon", "c:/d"},
                             {"core", "empty", ""},        {"stream", "rays", "1024"}};
    const int lines[] = {5, 6, 7, 8, 9, 10, 11, 13};
    for (int i = 0; i < 8; i++) {
        cr_expect_str_eq(entry(&f, i)->section, want[i][0]);
        cr_expect_str_eq(entry(&f, i)->key, want[i][1]);
        cr_expect_str_eq(entry(&f, i)->value, want[i][2], "key %s", want[i][1]);
        cr_expect_eq(entry(&f, i)->line, lines[i], "key %s", want[i][1]);
        cr_expect_eq(entry(&f, i)->sec, i < 7 ? 0 : 1);
    }
    inifile_free(&f);
}

Test(ini_syntax, a_bom_and_crlf_line_ends_are_accepted)
{
    IniFile f;
    int n = parse(&f, "\xEF\xBB\xBF[core]\r\nsimd_width = 8\r\n; c\r\n[stream]\r\nrays = 1024", NULL);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_expect_str_eq(inifile_get(&f, "core", "simd_width")->value, "8");
    cr_expect_str_eq(inifile_get(&f, "stream", "rays")->value, "1024"); /* no final line end */
    cr_expect_eq(inifile_get(&f, "stream", "rays")->line, 5);
    inifile_free(&f);
    /* a BOM anywhere but at the start of the file is text: here, part of a key's name */
    n = parse(&f, "[core]\n\xEF\xBB\xBF" "a = 1\n", NULL);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_expect_null(inifile_get(&f, "core", "a"));
    cr_expect_str_eq(entry(&f, 0)->key, "\xEF\xBB\xBF" "a");
    inifile_free(&f);
}

Test(ini_syntax, continuation_lines_join_with_a_newline)
{
    IniFile f;
    int n = parse(&f,
                  "[sweep]\n"
                  "list = 4, 8,\n"
                  "    12, 16\n"
                  "; a comment between\n"
                  "\n"
                  "\t32 ; and a comment after\n"
                  "other = 1\n"
                  "  key2 = 2\n" /* indented with '=': a key of its own */
                  "    3\n",
                  NULL);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_expect_str_eq(inifile_get(&f, "sweep", "list")->value, "4, 8,\n12, 16\n32");
    cr_expect_eq(inifile_get(&f, "sweep", "list")->line, 2);
    cr_expect_str_eq(inifile_get(&f, "sweep", "other")->value, "1");
    cr_expect_str_eq(inifile_get(&f, "sweep", "key2")->value, "2\n3");
    cr_expect_eq(f.nentries, 3);
    inifile_free(&f);
}

Test(ini_syntax, repeatable_keys_and_repeated_sections_when_allowed)
{
    static const char *const rep[] = {"scene.gltf", NULL};
    const IniOptions opt = {0, 0, rep};
    IniFile f;
    int n = parse(&f, "[scene]\ngltf = a.glb\ngltf = b.glb\n[render]\nwidth = 1\n", &opt);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_assert_eq(f.nentries, 3);
    cr_expect_str_eq(f.entries[1].value, "b.glb");
    cr_expect_str_eq(inifile_get(&f, "scene", "gltf")->value, "a.glb"); /* the first */
    inifile_free(&f);

    const IniOptions join = {1, 0, NULL};
    n = parse(&f, "[core]\na = 1\n[stream]\nb = 2\n[core]\nc = 3\n", &join);
    cr_expect_eq(n, 0, "%s", messages(&f));
    cr_expect_eq(f.nsections, 2);
    cr_expect_eq(inifile_get(&f, "core", "c")->sec, 0);
    cr_expect_eq(inifile_section(&f, "core")->nkeys, 2);
    cr_expect_eq(inifile_section(&f, "core")->line, 1);
    inifile_free(&f);
    /* ... but a key is still given once */
    expect_messages("[core]\na = 1\n[stream]\nb = 2\n[core]\na = 3\n", &join,
                    "6: key 'core.a': given twice (first at line 2)\n");
}

/* ==== ini_errors ================================================================================= */

Test(ini_errors, a_key_given_twice_names_both_lines)
{
    expect_messages("[core]\nsimd_width = 8\nclock_mhz = 1\n\nsimd_width = 4\n", NULL,
                    "5: key 'core.simd_width': given twice (first at line 2)\n");
    /* the first value stays */
    IniFile f;
    parse(&f, "[core]\nsimd_width = 8\nsimd_width = 4\n", NULL);
    cr_expect_str_eq(inifile_get(&f, "core", "simd_width")->value, "8");
    cr_expect_eq(f.nentries, 1);
    inifile_free(&f);
    /* bare keys, as sweep files name them */
    const IniOptions bare = {0, 1, NULL};
    expect_messages("[point.a]\ncore.simd_width = 8\ncore.simd_width = 16\n", &bare,
                    "3: key 'core.simd_width': given twice (first at line 2)\n");
    /* a key of the same name in another section is another key */
    expect_messages("[a]\nx = 1\n[b]\nx = 2\n", NULL, "");
}

Test(ini_errors, a_section_given_twice_names_both_lines_and_its_keys_are_dropped)
{
    expect_messages("[render]\nspp = 4\n[camera]\nfov_y = 30\n[render]\nspp = 8\nwidth = 2\n", NULL,
                    "5: section [render] appears twice (first at line 1)\n");
    IniFile f;
    parse(&f, "[render]\nspp = 4\n[render]\nspp = 8\n", NULL);
    cr_expect_eq(f.nentries, 1);
    cr_expect_str_eq(inifile_get(&f, "render", "spp")->value, "4");
    inifile_free(&f);
}

Test(ini_errors, every_syntax_error_with_its_line)
{
    expect_messages("x = 1\n"                 /* 1 */
                    "[core]\n"                /* 2 */
                    "just words\n"            /* 3 */
                    "[stream\n"               /* 4 */
                    "[a] b\n"                 /* 5 */
                    "[ ]\n"                   /* 6 */
                    "= 5\n"                   /* 7 */
                    "a: b = c\n"              /* 8 */
                    "[core2]\n"               /* 9 */
                    "    orphan\n"            /* 10: no key above it in this section */
                    "ok = 1\n",               /* 11 */
                    NULL,
                    "1: key 'x': outside any section\n"
                    "3: syntax error: expected 'key = value' or '[section]', got 'just words'\n"
                    "4: syntax error: a section header is '[name]' alone on its line\n"
                    "5: syntax error: a section header is '[name]' alone on its line\n"
                    "6: syntax error: empty section name\n"
                    "7: syntax error: no key before '='\n"
                    "8: syntax error: ':' in key 'a: b' (a key and its value are separated by '=')\n"
                    "10: syntax error: an indented line continues the value of a key, but no key comes before "
                    "it\n");
}

Test(ini_errors, lines_after_a_reported_line_do_not_cascade)
{
    /* keys under a bad header, continuation lines of a refused key: one message each cause */
    expect_messages("[bad\na = 1\nb = 2\n[ok]\nk = 1\nk = 2\n    more\n", NULL,
                    "1: syntax error: a section header is '[name]' alone on its line\n"
                    "6: key 'ok.k': given twice (first at line 5)\n");
}

Test(ini_errors, line_length_limit)
{
    char text[600];
    /* exactly INIFILE_MAX_LINE characters (and a CR) is fine */
    int head = snprintf(text, sizeof text, "[s]\nk = ");
    memset(text + head, 'v', INIFILE_MAX_LINE - 4);
    strcpy(text + head + INIFILE_MAX_LINE - 4, "\r\nz = 1\n");
    IniFile f;
    cr_expect_eq(parse(&f, text, NULL), 0, "%s", messages(&f));
    cr_expect_eq(strlen(inifile_get(&f, "s", "k")->value), (size_t)INIFILE_MAX_LINE - 4);
    cr_expect_str_eq(inifile_get(&f, "s", "z")->value, "1");
    inifile_free(&f);
    /* one more is refused, not cut in two (inih would take its rest for another line) */
    memset(text + head, 'v', INIFILE_MAX_LINE - 3);
    strcpy(text + head + INIFILE_MAX_LINE - 3, "\nz = 1\n");
    char want[128];
    snprintf(want, sizeof want, "2: line longer than %d characters\n", INIFILE_MAX_LINE);
    expect_messages(text, NULL, want);
    parse(&f, text, NULL);
    cr_expect_null(inifile_get(&f, "s", "k"));
    cr_expect_str_eq(inifile_get(&f, "s", "z")->value, "1");
    inifile_free(&f);
}

Test(ini_errors, section_name_limit)
{
    /* inih cuts names at 49 characters: 49 are fine, 50 are refused instead of cut */
    char text[256];
    snprintf(text, sizeof text, "[%.*s]\nk = 1\n", INIFILE_MAX_SECTION, "abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyz");
    IniFile f;
    cr_expect_eq(parse(&f, text, NULL), 0, "%s", messages(&f));
    cr_expect_eq(strlen(f.sections[0].name), (size_t)INIFILE_MAX_SECTION);
    inifile_free(&f);
    snprintf(text, sizeof text, "[%.*s]\nk = 1\n", INIFILE_MAX_SECTION + 1,
             "abcdefghijklmnopqrstuvwxyzabcdefghijklmnopqrstuvwxyz");
    parse(&f, text, NULL);
    cr_expect_eq(f.nerrors, 1);
    cr_expect(strstr(messages(&f), "t.ini:1: section name 'abcdefghijklmnopqrst...' longer than 49 characters"),
              "%s", messages(&f));
    cr_expect_eq(f.nentries, 0);
    inifile_free(&f);
}

Test(ini_errors, a_nul_byte_is_not_text)
{
    IniFile f;
    inifile_parse(&f, "t.ini", "[a]\nk = 1\nx\0y\n", 13, NULL);
    cr_expect_str_eq(messages(&f), "t.ini:3: a NUL byte: not a text file\n");
    cr_expect_eq(f.nerrors, 1);
    inifile_free(&f);
}

Test(ini_errors, messages_in_line_order_and_capped)
{
    IniFile f;
    parse(&f, "[a]\nk = 1\n", NULL);
    inifile_error(&f, 2, "second");
    inifile_error(&f, 0, "whole file");
    inifile_error(&f, 1, "first");
    inifile_error(&f, 2, "second again");
    cr_expect_str_eq(messages(&f), "t.ini: whole file\nt.ini:1: first\nt.ini:2: second\nt.ini:2: second again\n");
    cr_expect_eq(f.nerrors, 4);
    inifile_free(&f);

    /* a binary file must not give millions of lines: the first ones, then a count */
    size_t n = 100000;
    char *text = malloc(3 * n + 1);
    for (size_t i = 0; i < n; i++)
        memcpy(text + 3 * i, "x!\n", 3);
    text[3 * n] = 0;
    parse(&f, text, NULL);
    cr_expect_eq(f.nerrors, (int)n);
    int m;
    const IniMessage *msg = inifile_messages(&f, &m);
    cr_expect_eq(m, INIFILE_MAX_MESSAGES + 1);
    cr_expect_str_eq(msg[0].text, "t.ini:1: syntax error: expected 'key = value' or '[section]', got 'x!'");
    char want[128];
    snprintf(want, sizeof want, "t.ini: ... and %zu more errors", n - INIFILE_MAX_MESSAGES);
    cr_expect_str_eq(msg[m - 1].text, want);
    inifile_free(&f);
    free(text);
}

/* ==== ini_files ================================================================================== */

static char g_dir[64];

static void make_dir(void)
{
    snprintf(g_dir, sizeof g_dir, "/tmp/sfsim-initest-XXXXXX");
    cr_assert_not_null(mkdtemp(g_dir));
}

static void remove_dir(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", g_dir);
    cr_expect_eq(system(cmd), 0);
}

TestSuite(ini_files, .init = make_dir, .fini = remove_dir);

static void expect_read_error(const char *path, const char *want_after_path)
{
    char *text = (char *)"untouched", err[512], want[512];
    size_t len = 7;
    cr_expect_eq(inifile_read(path, &text, &len, err, sizeof err), -1, "%s was read", path);
    cr_expect_null(text);
    snprintf(want, sizeof want, "%s: %s", path, want_after_path);
    cr_expect_str_eq(err, want);
    /* the loader gives the same as its one message */
    IniFile f;
    cr_expect_eq(inifile_load(&f, path, NULL), 1);
    snprintf(want, sizeof want, "%s: %s\n", path, want_after_path);
    cr_expect_str_eq(messages(&f), want);
    inifile_free(&f);
}

Test(ini_files, a_directory_is_refused)
{
    expect_read_error(g_dir, "is a directory, not a regular file");
}

Test(ini_files, devices_and_fifos_are_refused_at_once)
{
    expect_read_error("/dev/zero", "not a regular file (a character device)");
    expect_read_error("/dev/null", "not a regular file (a character device)");
    char fifo[128];
    snprintf(fifo, sizeof fifo, "%s/pipe.ini", g_dir);
    cr_assert_eq(mkfifo(fifo, 0600), 0);
    expect_read_error(fifo, "not a regular file (a FIFO)"); /* no writer: an open without O_NONBLOCK would wait */
}

Test(ini_files, missing_file)
{
    expect_read_error("/nonexistent/sfsim/x.ini", "cannot open: No such file or directory");
}

Test(ini_files, size_limit)
{
    char path[128];
    snprintf(path, sizeof path, "%s/big.ini", g_dir);
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    cr_assert_geq(fd, 0);
    cr_assert_eq(ftruncate(fd, INIFILE_MAX_BYTES), 0); /* sparse: zeros */
    close(fd);
    char *text, err[512];
    size_t len;
    cr_expect_eq(inifile_read(path, &text, &len, err, sizeof err), 0, "%s", err);
    cr_expect_eq(len, (size_t)INIFILE_MAX_BYTES);
    free(text);
    cr_assert_eq(truncate(path, INIFILE_MAX_BYTES + 1), 0);
    expect_read_error(path, "larger than 16 MiB, the most an INI file may hold");
    /* a stream with no end is read up to the limit only */
    FILE *z = fopen("/dev/zero", "r");
    cr_assert_not_null(z);
    IniFile f;
    cr_expect_eq(inifile_load_stream(&f, z, "zero", NULL), 1);
    fclose(z);
    cr_expect_str_eq(messages(&f), "zero: larger than 16 MiB, the most an INI file may hold\n");
    inifile_free(&f);
}

Test(ini_files, a_regular_file_loads)
{
    char path[128];
    snprintf(path, sizeof path, "%s/ok.ini", g_dir);
    FILE *out = fopen(path, "w");
    cr_assert_not_null(out);
    fputs("[core]\nsimd_width = 12\n", out);
    fclose(out);
    IniFile f;
    cr_expect_eq(inifile_load(&f, path, NULL), 0, "%s", messages(&f));
    cr_expect_str_eq(f.name, path);
    cr_expect_str_eq(inifile_get(&f, "core", "simd_width")->value, "12");
    cr_expect_null(inifile_get(&f, "core", "clock_mhz"));
    cr_expect_null(inifile_get(&f, "gpu", "simd_width"));
    cr_expect_null(inifile_section(&f, "gpu"));
    inifile_free(&f);
}

/* Sections and keys are indexed: 100,000 sections with a key each, and a section of 100,000 keys,
 * are read in linear time (about 0.1 s each here; comparing each with all others took minutes). */
Test(ini_files, many_sections_and_keys)
{
    size_t n = 100000;
    char *text = malloc(n * 40 + 64), *p = text;
    for (size_t i = 0; i < n; i++)
        p += sprintf(p, "[point.p%zu]\nk = %zu\n", i, i);
    p += sprintf(p, "[point.p77]\n");
    IniFile f;
    parse(&f, text, NULL);
    cr_expect_eq(f.nsections, (int)n);
    cr_expect_eq(f.nentries, (int)n);
    cr_expect_str_eq(messages(&f), "t.ini:200001: section [point.p77] appears twice (first at line 155)\n");
    cr_expect_str_eq(inifile_get(&f, "point.p99999", "k")->value, "99999");
    inifile_free(&f);

    p = text + sprintf(text, "[big]\n");
    for (size_t i = 0; i < n; i++)
        p += sprintf(p, "k%zu = %zu\n", i, i);
    sprintf(p, "k4242 = again\n");
    parse(&f, text, NULL);
    cr_expect_eq(f.nentries, (int)n);
    cr_expect_str_eq(messages(&f), "t.ini:100002: key 'big.k4242': given twice (first at line 4244)\n");
    cr_expect_str_eq(inifile_get(&f, "big", "k12345")->value, "12345");
    inifile_free(&f);
    free(text);
}
