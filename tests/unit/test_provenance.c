/* tests/unit/test_provenance.c -- what made a run (sim/provenance.c): the command line quoted so
 * that a POSIX shell gives back every argument as it was, the date in ISO 8601 with its offset,
 * and report.json's "run" object.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../host/version.h"
#include "../../sim/provenance.h"

/* The shell's reading of line: its words, one per line, through printf '%s\n'. */
static char *shell_words(const char *line)
{
    char cmd[8192];
    snprintf(cmd, sizeof cmd, "set -- %s; printf '%%s\\n' \"$@\"", line);
    char *argv[] = {"sh", "-c", cmd, NULL};
    int fd[2];
    cr_assert_eq(pipe(fd), 0);
    pid_t pid = fork();
    cr_assert_geq(pid, 0);
    if (pid == 0) {
        dup2(fd[1], 1);
        close(fd[0]);
        execv("/bin/sh", argv);
        _exit(127);
    }
    close(fd[1]);
    static char out[8192];
    size_t n = 0;
    ssize_t got;
    while ((got = read(fd[0], out + n, sizeof out - 1 - n)) > 0)
        n += (size_t)got;
    out[n] = '\0';
    close(fd[0]);
    return out;
}

Test(provenance, command_line_pastes_back_into_a_shell)
{
    char *args[] = {"bin/sfsim", "run", "-s", "my scenes/box.ini", "--set", "render.seed=7", "it's", "",
                    "$HOME", "a\"b", "semi;colon", "*", "tab\there", "back\\slash", "é", "-o", "out/x_1@%+=:,.-"};
    int n = (int)(sizeof args / sizeof args[0]);
    prov_set_command(n, args);
    args[3] = "changed";   /* a copy is kept: option parsing may rewrite argv */
    cr_expect_eq(prov_argc(), n);
    cr_expect_str_eq(prov_argv(3), "my scenes/box.ini");
    cr_expect_str_eq(prov_argv(n), "");
    const char *line = prov_command();
    const char *head = "bin/sfsim run -s 'my scenes/box.ini' --set render.seed=7 'it'\\''s' '' '$HOME' ";
    cr_expect(!strncmp(line, head, strlen(head)), "%s", line);
    cr_expect(strstr(line, " -o out/x_1@%+=:,.-") != NULL, "safe characters are left unquoted: %s", line);
    char want[4096] = "";
    for (int i = 0; i < n; i++) {
        strcat(want, prov_argv(i));
        strcat(want, "\n");
    }
    cr_expect_str_eq(shell_words(line), want, "the shell does not read back the arguments of %s", line);
}

Test(provenance, quote_says_the_length_it_needs)
{
    char buf[8];
    cr_expect_eq(prov_quote("plain", buf, sizeof buf), 5);
    cr_expect_str_eq(buf, "plain");
    cr_expect_eq(prov_quote("a b c d e", buf, sizeof buf), 11);
    cr_expect_str_eq(buf, "'a b c ", "truncated, terminated");
    cr_expect_eq(prov_quote("", buf, sizeof buf), 2);
    cr_expect_str_eq(buf, "''");
    cr_expect_eq(prov_quote("x'y", NULL, 0), 8);
}

Test(provenance, date_is_iso_8601_with_the_offset)
{
    char *args[] = {"sfsim"};
    setenv("TZ", "NST+3:30", 1);   /* 3 h 30 west of UTC: a half-hour offset, no daylight time */
    prov_set_command(1, args);
    regex_t re;
    cr_assert_eq(regcomp(&re, "^[0-9]{4}-[01][0-9]-[0-3][0-9]T[0-2][0-9]:[0-5][0-9]:[0-6][0-9][+-][0-9]{2}:[0-9]{2}$",
                         REG_EXTENDED | REG_NOSUB), 0);
    cr_expect_eq(regexec(&re, prov_date(), 0, NULL, 0), 0, "%s", prov_date());
    regfree(&re);
    const char *z = prov_date() + strlen(prov_date()) - 6;
    cr_expect_str_eq(z, "-03:30");
    unsetenv("TZ");
}

Test(provenance, run_object_of_report_json)
{
    char *args[] = {"bin/sfsim", "run", "-o", "a b"};
    prov_set_command(4, args);
    cJSON *o = cJSON_CreateObject();
    cr_assert_eq(prov_json(o), 0);
    cr_expect_str_eq(cJSON_GetObjectItem(o, "version")->valuestring, version_string());
    cr_expect_str_eq(cJSON_GetObjectItem(o, "commit")->valuestring, version_commit());
    cr_expect_str_eq(cJSON_GetObjectItem(o, "command")->valuestring, "bin/sfsim run -o 'a b'");
    const cJSON *a = cJSON_GetObjectItem(o, "argv");
    cr_assert_eq(cJSON_GetArraySize(a), 4);
    cr_expect_str_eq(cJSON_GetArrayItem(a, 3)->valuestring, "a b");
    char cwd[4096], host[256];
    cr_assert_not_null(getcwd(cwd, sizeof cwd));
    cr_assert_eq(gethostname(host, sizeof host), 0);
    cr_expect_str_eq(cJSON_GetObjectItem(o, "cwd")->valuestring, cwd);
    cr_expect_str_eq(cJSON_GetObjectItem(o, "host")->valuestring, host);
    cr_expect_str_eq(cJSON_GetObjectItem(o, "date")->valuestring, prov_date());
    cJSON_Delete(o);
}
