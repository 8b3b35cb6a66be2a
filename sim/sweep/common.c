/* sim/sweep/common.c -- the small helpers the sweep's files share (sweep_int.h): the
 * out-of-memory policy, messages, string lists, numbers as a sweep file writes them, shell
 * quoting, emptying a point's folder.
 *
 * Owns: these helpers. Must not: know sweep files, manifests, points or the CSV (their own files
 * do), or hold helpers sfsim's other parts need too (sim/util.c has those).
 */
#include "sweep_int.h"

#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <sys/stat.h>

void sweep_oom(void)
{
    fputs("sfsim: out of memory\n", stderr);
    abort();
}

const char *sweep_buf_text(const UtilBuf *b)
{
    if (b->failed)
        sweep_oom();
    return util_buf_str(b);
}

void sweep_err_add(SweepErrs *e, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    util_buf_vprintf(&e->text, fmt, ap);
    va_end(ap);
    util_buf_puts(&e->text, "\n");
    e->count++;
}

void sweep_strs_push(SweepStrs *l, char *s)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 8;
        l->v = xrealloc(l->v, (size_t)l->cap * sizeof *l->v);
    }
    l->v[l->n++] = s;
}

void sweep_strs_free(SweepStrs *l)
{
    for (int i = 0; i < l->n; i++)
        free(l->v[i]);
    free(l->v);
    memset(l, 0, sizeof *l);
}

char *sweep_trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = 0;
    return s;
}

int sweep_parse_number(const char *s, double *v, int *is_int, long long *iv)
{
    char *end;
    errno = 0;
    long long i = strtoll(s, &end, 10);
    if (end != s && !*end && !errno) {
        *is_int = 1;
        *iv = i;
        *v = (double)i;
        return 0;
    }
    errno = 0;
    double d = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(d))
        return -1;
    *is_int = 0;
    *iv = 0;
    *v = d;
    return 0;
}

int sweep_is_number(const char *s, double *v)
{
    int is_int;
    long long iv;
    return s && sweep_parse_number(s, v, &is_int, &iv) == 0;
}

int sweep_str_eq(const char *a, const char *b)
{
    return (!a && !b) || (a && b && !strcmp(a, b));
}

int sweep_file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static const char *rm_root;
static int rm_errno;
static char rm_failed[PATH_MAX];

static int rm_entry(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
    (void)st;
    (void)type;
    if (ftw->level == 0)
        return 0;
    if (remove(path) != 0) {
        rm_errno = errno;
        snprintf(rm_failed, sizeof rm_failed, "%s", path);
        return 1;
    }
    return 0;
}

int sweep_dir_clear(const char *path, char *err, size_t errlen)
{
    rm_root = path;
    rm_errno = 0;
    int rc = nftw(path, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
    if (rc != 0) {
        if (rm_errno)
            snprintf(err, errlen, "%s: cannot remove: %s", rm_failed, strerror(rm_errno));
        else
            snprintf(err, errlen, "%s: cannot empty the folder: %s", rm_root, strerror(errno));
        return -1;
    }
    return 0;
}

void sweep_shell_word(UtilBuf *b, const char *s, int always_quote)
{
    int plain = *s != 0 && !always_quote;
    for (const char *c = s; *c && plain; c++)
        plain = strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./=:,+@%-", *c) != NULL;
    if (plain) {
        util_buf_puts(b, s);
        return;
    }
    util_buf_puts(b, "\"");
    for (const char *c = s; *c; c++) {
        if (strchr("\"\\$`", *c))
            util_buf_puts(b, "\\");
        util_buf_add(b, c, 1);
    }
    util_buf_puts(b, "\"");
}
