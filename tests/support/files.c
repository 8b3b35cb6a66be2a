/* tests/support/files.c -- file helpers the Criterion tests share (files.h). */
#include "files.h"

#include <criterion/criterion.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

char *tu_slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    cr_assert_not_null(f, "%s missing", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = calloc((size_t)n + 1, 1);
    cr_assert_not_null(buf);
    cr_assert_eq(fread(buf, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    return buf;
}

/* The generator: $env_var, $SFSIM_BUILD/name, <test binary's folder>/../name, or build/name. */
static void generator_path(const char *name, const char *env_var, char *buf, size_t len)
{
    const char *env = getenv(env_var);
    if (env) {
        snprintf(buf, len, "%s", env);
        return;
    }
    env = getenv("SFSIM_BUILD");
    if (env) {
        snprintf(buf, len, "%s/%s", env, name);
        return;
    }
    char exe[1024];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n > 0) {
        exe[n] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            slash = strrchr(exe, '/');
            if (slash) {
                *slash = '\0';
                snprintf(buf, len, "%s/%s", exe, name);
                if (access(buf, X_OK) == 0)
                    return;
            }
        }
    }
    snprintf(buf, len, "build/%s", name);
}

void tu_expect_generated(const char *name, const char *env_var, const char *doc)
{
    char gen[1200];
    generator_path(name, env_var, gen, sizeof gen);
    cr_assert_eq(access(gen, X_OK), 0, "%s not found: build it (make), or set %s", gen, env_var);
    FILE *g = popen(gen, "r");
    cr_assert_not_null(g, "cannot run %s", gen);
    FILE *f = fopen(doc, "r");
    cr_assert_not_null(f, "%s is missing: run make docs", doc);
    int a, b;
    long at = 0, lineno = 1;
    do {
        a = fgetc(g);
        b = fgetc(f);
        at++;
        if (a == b && a == '\n')
            lineno++;
    } while (a == b && a != EOF);
    int rc = pclose(g);
    fclose(f);
    cr_assert_eq(rc, 0, "%s failed", gen);
    cr_expect_eq(a, b, "%s is stale: run make docs (first difference at byte %ld, line %ld)", doc, at, lineno);
}

static int remove_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    remove(path);
    return 0;
}

void tu_remove_tree(const char *dir)
{
    nftw(dir, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
}

void tu_make_tmpdir(char *dir, size_t len, const char *tag)
{
    snprintf(dir, len, "/tmp/sfsim-%s-XXXXXX", tag);
    cr_assert_not_null(mkdtemp(dir), "cannot create a temporary folder from %s", dir);
}

void tu_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f, "cannot create %s", path);
    cr_assert_geq(fputs(text, f), 0, "cannot write %s", path);
    cr_assert_eq(fclose(f), 0, "cannot write %s", path);
}

static FILE *captured;
static int saved_stderr = -1;

void tu_stderr_begin(void)
{
    fflush(stderr);
    captured = tmpfile();
    cr_assert_not_null(captured, "no temporary file for stderr");
    saved_stderr = dup(2);
    cr_assert(saved_stderr >= 0 && dup2(fileno(captured), 2) >= 0, "cannot redirect stderr");
}

char *tu_stderr_end(void)
{
    cr_assert_not_null(captured, "tu_stderr_end without tu_stderr_begin");
    fflush(stderr);
    dup2(saved_stderr, 2);
    close(saved_stderr);
    saved_stderr = -1;
    long n = fseek(captured, 0, SEEK_END) == 0 ? ftell(captured) : -1; /* fd 2 wrote past the FILE's view */
    cr_assert(n >= 0 && fseek(captured, 0, SEEK_SET) == 0);
    char *buf = malloc((size_t)n + 1);
    cr_assert_not_null(buf);
    buf[fread(buf, 1, (size_t)n, captured)] = 0;
    fclose(captured);
    captured = NULL;
    return buf;
}
