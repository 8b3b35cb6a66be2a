/* sim/sweep.c -- `sfsim sweep` and `sfsim merge` (sim/sweep.h; docs/sweep.md is the user's reference).
 *
 * Owns: reading sweep files, the sweep folder (sweep.json, points/NNN with their done / failed
 * markers), running points as child `sfsim run` processes of this same binary, resuming,
 * sweep.csv, the gnuplot plots, and the Slurm / GNU parallel scripts.
 * Must not: simulate (a point is an `sfsim run`), or know what a key means: values are checked by
 * cfg_set (sim/config.c) and the render keys by the ranges `sfsim run --set` takes.
 * Like sim/main.c this is a command: it prints its messages and returns exit codes. Running out
 * of memory ends the process (x* helpers): nothing useful is left to do then.
 */
#include "sweep.h"

#include <cjson/cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <limits.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "config.h"
#include "datadir.h"
#include "exitcodes.h"
#include "functional.h"
#include "ini.h"
#include "render.h"
#include "timing.h"

/* The one limit: more points than this is an error that says so. */
#define SW_MAX_POINTS 100000
#define SW_MANIFEST_FORMAT "sfsim sweep 1"
/* Lines of a failed point's log kept in its `failed` marker. */
#define SW_TAIL_LINES 12

/* ---- memory, strings ------------------------------------------------------------------------ */

static void *xrealloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q) {
        fputs("sfsim: out of memory\n", stderr);
        abort();
    }
    return q;
}

static char *xstrndup(const char *s, size_t n)
{
    char *d = xrealloc(NULL, n + 1);
    memcpy(d, s, n);
    d[n] = 0;
    return d;
}

static char *xstrdup(const char *s)
{
    return xstrndup(s, strlen(s));
}

__attribute__((format(printf, 1, 2))) static char *xasprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *s = NULL;
    int n = vasprintf(&s, fmt, ap);
    va_end(ap);
    if (n < 0) {
        fputs("sfsim: out of memory\n", stderr);
        abort();
    }
    return s;
}

typedef struct Buf {
    char *s;
    size_t len, cap;
} Buf;

static void buf_add(Buf *b, const char *s, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        while (cap < b->len + n + 1)
            cap *= 2;
        b->s = xrealloc(b->s, cap);
        b->cap = cap;
    }
    memcpy(b->s + b->len, s, n);
    b->len += n;
    b->s[b->len] = 0;
}

static void buf_puts(Buf *b, const char *s)
{
    buf_add(b, s, strlen(s));
}

static void buf_vprintf(Buf *b, const char *fmt, va_list ap)
{
    char *s = NULL;
    int n = vasprintf(&s, fmt, ap);
    if (n < 0) {
        fputs("sfsim: out of memory\n", stderr);
        abort();
    }
    buf_add(b, s, (size_t)n);
    free(s);
}

__attribute__((format(printf, 2, 3))) static void buf_printf(Buf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    buf_vprintf(b, fmt, ap);
    va_end(ap);
}

static const char *buf_str(const Buf *b)
{
    return b->s ? b->s : "";
}

static void buf_free(Buf *b)
{
    free(b->s);
    memset(b, 0, sizeof *b);
}

/* Messages for the user, one a line; all of them are printed before giving up. */
typedef struct Errs {
    Buf text;
    int count;
} Errs;

__attribute__((format(printf, 2, 3))) static void err_add(Errs *e, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    buf_vprintf(&e->text, fmt, ap);
    va_end(ap);
    buf_puts(&e->text, "\n");
    e->count++;
}

typedef struct StrList {
    char **v;
    int n, cap;
} StrList;

static void sl_push(StrList *l, char *s)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 8;
        l->v = xrealloc(l->v, (size_t)l->cap * sizeof *l->v);
    }
    l->v[l->n++] = s;
}

static void sl_free(StrList *l)
{
    for (int i = 0; i < l->n; i++)
        free(l->v[i]);
    free(l->v);
    memset(l, 0, sizeof *l);
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = 0;
    return s;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A number written in full ("12", "0.5", "1e3"); *is_int when it is a decimal integer. */
static int parse_number(const char *s, double *v, int *is_int, long long *iv)
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

static int is_number(const char *s, double *v)
{
    int is_int;
    long long iv;
    return s && parse_number(s, v, &is_int, &iv) == 0;
}

/* ---- files and folders ---------------------------------------------------------------------- */

/* A whole file, NUL-terminated; NULL with the reason in err. */
static char *file_read(const char *path, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rbe");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    Buf b = {0};
    char chunk[65536];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
        buf_add(&b, chunk, n);
    int bad = ferror(f);
    fclose(f);
    if (bad) {
        snprintf(err, errlen, "%s: cannot read: %s", path, strerror(errno));
        buf_free(&b);
        return NULL;
    }
    if (!b.s)
        buf_add(&b, "", 0);
    *len = b.len;
    return b.s;
}

/* Write through a temporary file and rename, so readers see the old file or the whole new one. */
static int file_write_atomic(const char *path, const char *data, size_t len, char *err, size_t errlen)
{
    const char *slash = strrchr(path, '/');
    char *tmp = slash ? xasprintf("%.*s/.%s.tmp.%ld", (int)(slash - path), path, slash + 1, (long)getpid())
                      : xasprintf(".%s.tmp.%ld", path, (long)getpid());
    int rc = -1;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot create: %s", tmp, strerror(errno));
        goto out;
    }
    size_t off = 0;
    while (off < len) {
        ssize_t w = write(fd, data + off, len - off);
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0) {
            snprintf(err, errlen, "%s: cannot write: %s", tmp, strerror(errno));
            close(fd);
            unlink(tmp);
            goto out;
        }
        off += (size_t)w;
    }
    if (fsync(fd) != 0 || close(fd) != 0) {
        snprintf(err, errlen, "%s: cannot write: %s", tmp, strerror(errno));
        unlink(tmp);
        goto out;
    }
    if (rename(tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot rename to %s: %s", tmp, path, strerror(errno));
        unlink(tmp);
        goto out;
    }
    rc = 0;
out:
    free(tmp);
    return rc;
}

static int mkdir_p(const char *path, char *err, size_t errlen)
{
    char *p = xstrdup(path);
    int rc = 0;
    for (char *s = p + 1;; s++) {
        if (*s != '/' && *s)
            continue;
        char c = *s;
        *s = 0;
        if (mkdir(p, 0755) != 0 && errno != EEXIST) {
            snprintf(err, errlen, "%s: cannot create the folder: %s", p, strerror(errno));
            rc = -1;
            break;
        }
        *s = c;
        if (!c)
            break;
    }
    if (!rc) {
        struct stat st;
        if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) {
            snprintf(err, errlen, "%s: exists and is not a folder", path);
            rc = -1;
        }
    }
    free(p);
    return rc;
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

/* Remove everything inside a folder, keeping the folder. */
static int dir_clear(const char *path, char *err, size_t errlen)
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

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Shell words: "..." with \ " $ ` escaped (for the scripts), or bare when nothing needs quoting
 * (for messages). */
static void buf_shell_word(Buf *b, const char *s, int always_quote)
{
    int plain = *s != 0 && !always_quote;
    for (const char *c = s; *c && plain; c++)
        plain = strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./=:,+@%-", *c) != NULL;
    if (plain) {
        buf_puts(b, s);
        return;
    }
    buf_puts(b, "\"");
    for (const char *c = s; *c; c++) {
        if (strchr("\"\\$`", *c))
            buf_puts(b, "\\");
        buf_add(b, c, 1);
    }
    buf_puts(b, "\"");
}

/* ---- keys and values ------------------------------------------------------------------------ */

/* The render keys `sfsim run --set` takes beside the machine keys: render_keys (sim/render.h). */
#define N_RENDER_KEYS RENDER_KEY_COUNT

/* 0 when VALUE is a valid value of KEY; else -1 with the reason in msg, *unknown set when KEY
 * is no key at all. Machine keys go through cfg_set on a scratch config. */
static int value_check(const char *key, const char *value, int *unknown, char *msg, size_t len)
{
    *unknown = 0;
    for (int i = 0; i < N_RENDER_KEYS; i++) {
        if (strcmp(key, render_keys[i].key) != 0)
            continue;
        char *end;
        errno = 0;
        long long v = strtoll(value, &end, 10);
        if (end == value || *end || errno || v < render_keys[i].lo || v > render_keys[i].hi) {
            snprintf(msg, len, "expected an integer in %lld..%lld, got '%s'", render_keys[i].lo, render_keys[i].hi,
                     value);
            return -1;
        }
        return 0;
    }
    CfgMachine scratch;
    cfg_defaults(&scratch);
    CfgErrors ce = {0};
    char *assign = xasprintf("%s=%s", key, value);
    int rc = 0;
    if (cfg_set(&scratch, assign, &ce)) {
        const char *t = ce.text ? ce.text : "invalid value";
        size_t al = strlen(assign);
        if (!strncmp(t, "--set ", 6) && !strncmp(t + 6, assign, al) && !strncmp(t + 6 + al, ": ", 2))
            t += 8 + al;
        if (!strncmp(t, "unknown key", 11) || !strncmp(t, "expected section.key=value", 26)) {
            *unknown = 1;
            snprintf(msg, len, "unknown key (sfsim config --dump lists the machine keys; the render keys are "
                               "render.width, render.height, render.spp, render.max_depth, render.seed)");
        } else {
            snprintf(msg, len, "%.*s", (int)strcspn(t, "\n"), t);
        }
        rc = -1;
    }
    cfg_errors_free(&ce);
    free(assign);
    return rc;
}

static int key_known(const char *key)
{
    int unknown;
    char msg[512];
    value_check(key, "0", &unknown, msg, sizeof msg);
    return !unknown;
}

/* A range "A..B" or "A..B step S" (inclusive; S defaults to 1): integers exactly, floats with a
 * little slack so that 0..1 step 0.1 ends at 1. */
typedef struct Range {
    int ints;
    long long a, s;  /* integers */
    double af, sf;   /* floats */
    double count;    /* values it gives; may be huge, never computed by making them */
} Range;

/* -1 with msg when item is no good range. Overflow-safe: the count of a range of integers is
 * computed in unsigned arithmetic, of floats in double (inf is "too many"). */
static int range_parse(const char *item, Range *r, char *msg, size_t len)
{
    const char *dots = strstr(item, "..");
    char *a = xstrndup(item, (size_t)(dots - item));
    char *rest = xstrdup(dots + 2);
    char *step = strstr(rest, "step");
    char *b;
    const char *s;
    if (step) {
        *step = 0;
        b = trim(rest);
        s = trim(step + 4);
    } else {
        b = trim(rest);
        s = "1";
    }
    double av, bv, sv;
    int ai, bi, si, rc = -1;
    long long aii, bii, sii;
    memset(r, 0, sizeof *r);
    if (parse_number(trim(a), &av, &ai, &aii) || parse_number(b, &bv, &bi, &bii) || parse_number(s, &sv, &si, &sii)) {
        snprintf(msg, len, "bad range '%s': expected A..B or A..B step S, with numbers", item);
    } else if (!(sv > 0)) {
        snprintf(msg, len, "bad range '%s': the step must be > 0", item);
    } else if (ai && bi && si ? bii < aii : bv < av) {
        snprintf(msg, len, "bad range '%s': its end is below its start", item);
    } else {
        r->ints = ai && bi && si;
        if (r->ints) {
            r->a = aii;
            r->s = sii;
            r->count = (double)(((unsigned long long)bii - (unsigned long long)aii) / (unsigned long long)sii) + 1;
        } else {
            r->af = av;
            r->sf = sv;
            r->count = floor((bv - av) / sv * (1 + 1e-12) + 1e-9) + 1;
        }
        if (!(r->count <= SW_MAX_POINTS)) {
            if (r->count < 1e15)
                snprintf(msg, len, "range '%s' gives %.0f values, more than %d", item, r->count, SW_MAX_POINTS);
            else
                snprintf(msg, len, "range '%s' gives more than %d values", item, SW_MAX_POINTS);
        } else {
            rc = 0;
        }
    }
    free(a);
    free(rest);
    return rc;
}

/* Value i of a range (i < r->count). a + i s stays within [A, B]: no overflow. */
static char *range_value(const Range *r, long long i)
{
    if (r->ints)
        return xasprintf("%lld", (long long)((unsigned long long)r->a + (unsigned long long)i * (unsigned long long)r->s));
    return xasprintf("%.10g", r->af + (double)i * r->sf);
}

/* ---- the sweep file ------------------------------------------------------------------------- */

/* The syntax is sim/ini.c's (docs/ini.md); this part knows [sweep] and [point.NAME] and their keys. */

typedef struct SfKey {
    const IniEntry *e;
    StrList items;  /* a [sweep] key: its list's items (values or ranges) */
    double count;   /* the values they give */
    int bad;        /* reported */
    StrList vals;   /* the values, once checked */
} SfKey;

static int point_name_ok(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') || *s == '-' ||
              *s == '_'))
            return 0;
    return 1;
}

/* Split a [sweep] key's list into items and count its values (without making them). A list
 * continues on indented lines: a line break is a comma, and a comma may end the line before. */
static void sf_list_count(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    Buf joined = {0};
    for (const char *p = e->value; *p;) {
        size_t n = strcspn(p, "\n");
        char *line = xstrndup(p, n);
        char *t = trim(line);
        size_t tl = strlen(t);
        if (tl && t[tl - 1] == ',')
            t[--tl] = 0;
        if (tl) {
            if (joined.len)
                buf_puts(&joined, ",");
            buf_puts(&joined, t);
        }
        free(line);
        p += n + (p[n] == '\n');
    }
    int empty = 0;
    for (const char *p = buf_str(&joined);;) {
        size_t n = strcspn(p, ",");
        char *item = xstrndup(p, n);
        char *t = trim(item);
        memmove(item, t, strlen(t) + 1);
        empty += !*item;
        sl_push(&k->items, item);
        if (!p[n])
            break;
        p += n + 1;
    }
    buf_free(&joined);
    if (empty) {
        inifile_error(f, e->line, "key '%s': %s", e->key, empty == k->items.n ? "empty list" : "an empty item in the list");
        k->bad = 1;
        return;
    }
    char msg[512];
    k->count = 0;
    for (int i = 0; i < k->items.n; i++) {
        Range r;
        if (!strstr(k->items.v[i], "..")) {
            k->count += 1;
        } else if (range_parse(k->items.v[i], &r, msg, sizeof msg) == 0) {
            k->count += r.count;
        } else {
            inifile_error(f, e->line, "key '%s': %s", e->key, msg);
            k->bad = 1;
        }
    }
}

/* For the duplicate check: a value as a number (8 and 8.0 are one value) or as text. */
typedef struct SfVal {
    int is_num;
    double num;
    const char *text;
    int pos;
} SfVal;

static int sfval_cmp(const void *a, const void *b)
{
    const SfVal *x = a, *y = b;
    if (x->is_num != y->is_num)
        return x->is_num ? -1 : 1;
    int c = x->is_num ? (x->num < y->num ? -1 : x->num > y->num) : strcmp(x->text, y->text);
    return c ? c : (x->pos > y->pos) - (x->pos < y->pos);
}

/* Make and check the values of a [sweep] key whose items are good: each value as `--set`
 * checks it, and no value twice (sorted, so a long list costs n log n). */
static void sf_list_values(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    char msg[512];
    for (int i = 0; i < k->items.n; i++) {
        const char *item = k->items.v[i];
        Range r;
        int is_range = strstr(item, "..") != NULL;
        long long n = 1;
        if (is_range) {
            range_parse(item, &r, msg, sizeof msg); /* good: sf_list_count said so */
            n = (long long)r.count;
        }
        for (long long j = 0; j < n; j++) {
            char *v = is_range ? range_value(&r, j) : xstrdup(item);
            int unknown;
            if (value_check(e->key, v, &unknown, msg, sizeof msg)) {
                if (is_range)
                    inifile_error(f, e->line, "key '%s': in %s: %s", e->key, item, msg);
                else
                    inifile_error(f, e->line, "key '%s': %s", e->key, msg);
                k->bad = 1;
                free(v);
                break;
            }
            sl_push(&k->vals, v);
        }
    }
    if (k->vals.n < 2)
        return;
    SfVal *sv = xrealloc(NULL, (size_t)k->vals.n * sizeof *sv);
    for (int i = 0; i < k->vals.n; i++) {
        sv[i].text = k->vals.v[i];
        sv[i].pos = i;
        sv[i].is_num = is_number(k->vals.v[i], &sv[i].num);
    }
    qsort(sv, (size_t)k->vals.n, sizeof *sv, sfval_cmp);
    /* Each value given more than once; say the one repeated first, and how many others are. */
    int first = -1, repeated = 0;
    for (int i = 1; i < k->vals.n; i++) {
        const SfVal *x = &sv[i - 1], *y = &sv[i];
        int same = x->is_num == y->is_num && (x->is_num ? x->num == y->num : !strcmp(x->text, y->text));
        int group_start = i < 2 || !(sv[i - 2].is_num == x->is_num &&
                                     (x->is_num ? sv[i - 2].num == x->num : !strcmp(sv[i - 2].text, x->text)));
        if (same && group_start) { /* y is the group's second occurrence */
            repeated++;
            if (first < 0 || y->pos < sv[first].pos)
                first = i;
        }
    }
    if (repeated) {
        inifile_error(f, e->line, "key '%s': value %s appears twice in the list%s", e->key, sv[first].text,
                      repeated > 1 ? " (and other values too)" : "");
        k->bad = 1;
    }
    free(sv);
}

/* A [point.NAME] key: one value. */
static void sf_point_value(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    const char *v = e->value;
    char msg[512];
    int unknown;
    msg[0] = 0;
    if (!*v)
        snprintf(msg, sizeof msg, "empty value");
    else if (strchr(v, ',') || strchr(v, '\n'))
        snprintf(msg, sizeof msg, "a point takes one value, not a list ('%.*s')", (int)strcspn(v, "\n"), v);
    else if (strstr(v, ".."))
        snprintf(msg, sizeof msg, "a point takes one value, not a range ('%s')", v);
    else if (value_check(e->key, v, &unknown, msg, sizeof msg) == 0)
        sl_push(&k->vals, xstrdup(v));
    if (msg[0]) {
        inifile_error(f, e->line, "key '%s': %s", e->key, msg);
        k->bad = 1;
    }
}

/* The points of a sweep file (its text, read once) as the manifest's "points" array, or NULL
 * after adding every problem to errs. The number of points is known, and refused beyond
 * SW_MAX_POINTS, before any value is made. */
static cJSON *sweep_points(const char *path, const char *text, size_t len, Errs *errs, int *explicit_points)
{
    IniFile f;
    const IniOptions opt = {0, 1, NULL};
    inifile_parse(&f, path, text, len, &opt);
    cJSON *points = NULL;
    int nsec = f.nsections, sweep_line = 0, point_line = 0, npoints = 0;
    char *sec_ok = xrealloc(NULL, (size_t)nsec + 1);
    for (int i = 0; i < nsec; i++) {
        const IniSection *s = &f.sections[i];
        int is_sweep = !strcmp(s->name, "sweep"), is_point = !strncmp(s->name, "point.", 6);
        sec_ok[i] = 0;
        if (!is_sweep && !is_point) {
            inifile_error(&f, s->line, "unknown section [%s] (a sweep file has a [sweep] section or [point.NAME] "
                                       "sections)", s->name);
            continue;
        }
        if (is_point && !point_name_ok(s->name + 6)) {
            inifile_error(&f, s->line, "section [%s]: a point's name is letters, digits, '-' and '_'", s->name);
            continue;
        }
        if ((is_sweep && point_line) || (is_point && sweep_line && !point_line))
            inifile_error(&f, s->line, "[%s] in a file with %s (line %d): a sweep file has a [sweep] section or "
                          "[point.NAME] sections, not both", s->name, is_sweep ? "[point.NAME] sections" : "[sweep]",
                          is_sweep ? point_line : sweep_line);
        if (is_sweep)
            sweep_line = s->line;
        else if (!point_line)
            point_line = s->line;
        npoints += is_point;
        sec_ok[i] = 1;
        if (!s->nkeys && !s->nbad)
            inifile_error(&f, s->line, "[%s] has no keys", s->name);
    }
    if (!sweep_line && !point_line && (f.nsections || !f.nerrors)) /* (not for a binary file) */
        inifile_error(&f, 0, "no [sweep] section and no [point.NAME] section");
    if (npoints > SW_MAX_POINTS)
        inifile_error(&f, 0, "%d points, more than %d (split the sweep)", npoints, SW_MAX_POINTS);

    /* The keys: known ones, then a [sweep] key's list counted, a point's value checked. */
    SfKey *keys = xrealloc(NULL, ((size_t)f.nentries + 1) * sizeof *keys);
    memset(keys, 0, ((size_t)f.nentries + 1) * sizeof *keys);
    double total = 1;
    int nlists = 0;
    char factors[256] = "";
    for (int i = 0; i < f.nentries; i++) {
        SfKey *k = &keys[i];
        k->e = &f.entries[i];
        k->bad = 1;
        if (!sec_ok[k->e->sec])
            continue; /* its section is reported */
        char msg[512];
        int unknown;
        if (!key_known(k->e->key)) {
            value_check(k->e->key, "0", &unknown, msg, sizeof msg);
            inifile_error(&f, k->e->line, "key '%s': %s", k->e->key, msg);
            continue;
        }
        k->bad = 0;
        if (!strcmp(k->e->section, "sweep")) {
            sf_list_count(&f, k);
            if (!k->bad) {
                total *= k->count;
                size_t fl = strlen(factors);
                if (fl + 40 < sizeof factors)
                    snprintf(factors + fl, sizeof factors - fl, "%s%.0f", nlists ? " x " : "", k->count);
                else if (!strstr(factors, "..."))
                    strcat(factors, " x ...");
                nlists++;
            }
        } else if (npoints <= SW_MAX_POINTS) {
            sf_point_value(&f, k);
        }
    }
    if (sweep_line && !point_line && total > SW_MAX_POINTS) {
        if (total < 1e15)
            inifile_error(&f, sweep_line, "[sweep]: %.0f points (%s values), more than %d (split the sweep)", total,
                          factors, SW_MAX_POINTS);
        else
            inifile_error(&f, sweep_line, "[sweep]: more than %d points (%s values; split the sweep)", SW_MAX_POINTS,
                          factors);
    } else {
        for (int i = 0; i < f.nentries; i++)
            if (!keys[i].bad && !strcmp(keys[i].e->section, "sweep"))
                sf_list_values(&f, &keys[i]);
    }
    int n;
    const IniMessage *m = inifile_messages(&f, &n);
    for (int i = 0; i < n; i++)
        err_add(errs, "%s", m[i].text);
    errs->count += f.nerrors - n; /* a last "... and N more errors" line stands for N */
    if (f.nerrors)
        goto out;

    *explicit_points = point_line != 0;
    points = cJSON_CreateArray();
    if (*explicit_points) {
        int e = 0;
        for (int i = 0; i < nsec; i++) {
            cJSON *p = cJSON_CreateObject(), *set = cJSON_CreateObject();
            cJSON_AddStringToObject(p, "name", f.sections[i].name + 6);
            for (; e < f.nentries && keys[e].e->sec == i; e++)
                cJSON_AddStringToObject(set, keys[e].e->key, keys[e].vals.v[0]);
            cJSON_AddItemToObject(p, "settings", set);
            cJSON_AddItemToArray(points, p);
        }
        goto out;
    }
    /* The cross product, the first key varying slowest. */
    long long ntotal = (long long)total;
    for (long long p = 0; p < ntotal; p++) {
        cJSON *pt = cJSON_CreateObject(), *set = cJSON_CreateObject();
        long long rest = p, stride = ntotal;
        for (int j = 0; j < f.nentries; j++) {
            stride /= keys[j].vals.n;
            cJSON_AddStringToObject(set, keys[j].e->key, keys[j].vals.v[rest / stride]);
            rest %= stride;
        }
        cJSON_AddItemToObject(pt, "settings", set);
        cJSON_AddItemToArray(points, pt);
    }
out:
    for (int i = 0; i < f.nentries; i++) {
        sl_free(&keys[i].items);
        sl_free(&keys[i].vals);
    }
    free(keys);
    free(sec_ok);
    inifile_free(&f);
    return points;
}

/* ---- the plan: what sweep.json says --------------------------------------------------------- */

typedef struct Point {
    const char *name; /* [point.NAME]; NULL in a cross product */
    int n;
    const char **key, **val;
} Point;

typedef struct Plan {
    cJSON *json; /* the manifest; the strings below point into it */
    int explicit_points;
    const char *config, *config_text, *sweep, *sweep_text, *scene, *mode, *sample;
    const char **sets;
    int nsets;
    Point *points;
    int npoints;
    const char **keys; /* every key a point sets, in order of appearance: the CSV's key columns */
    int nkeys;
    int digits; /* of the point folders' names */
} Plan;

static void plan_free(Plan *pl)
{
    for (int i = 0; i < pl->npoints; i++) {
        free(pl->points[i].key);
        free(pl->points[i].val);
    }
    free(pl->points);
    free(pl->keys);
    free(pl->sets);
    cJSON_Delete(pl->json);
    memset(pl, 0, sizeof *pl);
}

static const char *json_str(const cJSON *o, const char *name, int nullable, int *bad)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, name);
    if (cJSON_IsString(it))
        return it->valuestring;
    if (!(nullable && (!it || cJSON_IsNull(it))))
        *bad = 1;
    return NULL;
}

/* Take the manifest (owned from here on) apart; -1 with err when it is not one. */
static int plan_load(cJSON *json, Plan *pl, char *err, size_t errlen)
{
    memset(pl, 0, sizeof *pl);
    pl->json = json;
    int bad = 0;
    const char *format = json_str(json, "format", 0, &bad);
    if (bad || strcmp(format, SW_MANIFEST_FORMAT) != 0) {
        snprintf(err, errlen, "not a sweep manifest of this sfsim (its \"format\" is not \"%s\")", SW_MANIFEST_FORMAT);
        return -1;
    }
    pl->config = json_str(json, "config", 1, &bad);
    pl->config_text = json_str(json, "config_contents", 1, &bad);
    pl->sweep = json_str(json, "sweep_file", 0, &bad);
    pl->sweep_text = json_str(json, "sweep_contents", 0, &bad);
    pl->scene = json_str(json, "scene", 0, &bad);
    pl->mode = json_str(json, "mode", 0, &bad);
    pl->sample = json_str(json, "sample", 1, &bad);
    const char *kind = json_str(json, "kind", 0, &bad);
    const cJSON *sets = cJSON_GetObjectItemCaseSensitive(json, "sets");
    const cJSON *points = cJSON_GetObjectItemCaseSensitive(json, "points");
    if (bad || !cJSON_IsArray(sets) || !cJSON_IsArray(points) || cJSON_GetArraySize(points) < 1 ||
        cJSON_GetArraySize(points) > SW_MAX_POINTS || (strcmp(kind, "cross") && strcmp(kind, "points"))) {
        snprintf(err, errlen, "a field is missing or has the wrong type");
        return -1;
    }
    pl->explicit_points = !strcmp(kind, "points");
    pl->sets = xrealloc(NULL, (size_t)cJSON_GetArraySize(sets) * sizeof *pl->sets);
    const cJSON *it;
    cJSON_ArrayForEach(it, sets)
    {
        if (!cJSON_IsString(it)) {
            snprintf(err, errlen, "\"sets\" holds a non-string");
            return -1;
        }
        pl->sets[pl->nsets++] = it->valuestring;
    }
    int np = cJSON_GetArraySize(points);
    pl->points = xrealloc(NULL, (size_t)np * sizeof *pl->points);
    memset(pl->points, 0, (size_t)np * sizeof *pl->points);
    int kcap = 0;
    cJSON_ArrayForEach(it, points)
    {
        Point *p = &pl->points[pl->npoints++];
        const cJSON *set = cJSON_GetObjectItemCaseSensitive(it, "settings");
        p->name = json_str(it, "name", 1, &bad);
        if (bad || !cJSON_IsObject(set) || (pl->explicit_points && !p->name)) {
            snprintf(err, errlen, "point %d is malformed", pl->npoints - 1);
            return -1;
        }
        int n = cJSON_GetArraySize(set);
        p->key = xrealloc(NULL, (size_t)n * sizeof *p->key);
        p->val = xrealloc(NULL, (size_t)n * sizeof *p->val);
        const cJSON *kv;
        cJSON_ArrayForEach(kv, set)
        {
            if (!cJSON_IsString(kv) || !kv->string) {
                snprintf(err, errlen, "point %d: a setting is not a string", pl->npoints - 1);
                return -1;
            }
            p->key[p->n] = kv->string;
            p->val[p->n++] = kv->valuestring;
            int known = 0;
            for (int k = 0; k < pl->nkeys && !known; k++)
                known = !strcmp(pl->keys[k], kv->string);
            if (!known) {
                if (pl->nkeys == kcap) {
                    kcap = kcap ? 2 * kcap : 8;
                    pl->keys = xrealloc(pl->keys, (size_t)kcap * sizeof *pl->keys);
                }
                pl->keys[pl->nkeys++] = kv->string;
            }
        }
    }
    pl->digits = 3;
    for (int m = 1000; m <= pl->npoints - 1; m *= 10)
        pl->digits++;
    return 0;
}

/* The value point p gives key k, or NULL. */
static const char *plan_value(const Plan *pl, int p, const char *key)
{
    for (int i = 0; i < pl->points[p].n; i++)
        if (!strcmp(pl->points[p].key[i], key))
            return pl->points[p].val[i];
    return NULL;
}

static char *point_dir(const Plan *pl, const char *dir, int k)
{
    return xasprintf("%s/points/%0*d", dir, pl->digits, k);
}

/* "point 7" or "point 2 (small-buffer)". */
static char *point_label(const Plan *pl, int k)
{
    return pl->points[k].name ? xasprintf("point %d (%s)", k, pl->points[k].name) : xasprintf("point %d", k);
}

/* ---- the manifest and the sweep folder ------------------------------------------------------ */

typedef struct Args {
    const char *config, *sweep, *scene, *out, *mode, *sample, *emit;
    const char **sets;
    int nsets;
    int jobs, threads, retry, point;
} Args;

/* Read and check everything the arguments name, and build the manifest; NULL after printing
 * every problem. */
static cJSON *manifest_build(const Args *a)
{
    Errs errs = {0};
    char err[PATH_MAX + 256];
    char *config = NULL, *config_text = NULL, *sweep = NULL, *sweep_text = NULL, *scene = NULL;
    size_t config_len = 0, sweep_len = 0;
    cJSON *points = NULL, *m = NULL;
    int explicit_points = 0;

    /* The config and the sweep file are INI files: read as sim/ini.c reads every one (a regular
     * file of at most 16 MiB), and their text kept in the manifest. */
    if (a->config) {
        if (inifile_read(a->config, &config_text, &config_len, err, sizeof err))
            err_add(&errs, "%s", err);
        else if (!(config = realpath(a->config, NULL)))
            err_add(&errs, "%s: cannot open: %s", a->config, strerror(errno));
        else {
            CfgMachine cfg;
            CfgErrors ce = {0};
            cfg_defaults(&cfg);
            cfg_load_text(&cfg, config_text, config_len, a->config, &ce);
            if (ce.count)
                buf_puts(&errs.text, ce.text);
            errs.count += ce.count;
            cfg_errors_free(&ce);
        }
    }
    for (int i = 0; i < a->nsets; i++) {
        const char *eq = strchr(a->sets[i], '=');
        int unknown;
        char msg[512];
        if (!eq || eq == a->sets[i]) {
            err_add(&errs, "--set %s: expected section.key=value", a->sets[i]);
            continue;
        }
        char *key = xstrndup(a->sets[i], (size_t)(eq - a->sets[i]));
        if (value_check(key, eq + 1, &unknown, msg, sizeof msg))
            err_add(&errs, "--set %s: %s", a->sets[i], msg);
        free(key);
    }
    scene = realpath(a->scene, NULL);
    if (!scene)
        err_add(&errs, "scene %s: cannot open: %s", a->scene, strerror(errno));
    if (inifile_read(a->sweep, &sweep_text, &sweep_len, err, sizeof err))
        err_add(&errs, "%s", err);
    else if (!(sweep = realpath(a->sweep, NULL)))
        err_add(&errs, "%s: cannot open: %s", a->sweep, strerror(errno));
    else
        points = sweep_points(a->sweep, sweep_text, sweep_len, &errs, &explicit_points);
    if (errs.count) {
        fputs(buf_str(&errs.text), stderr);
        fprintf(stderr, "sfsim sweep: %d error%s; nothing was run\n", errs.count, errs.count == 1 ? "" : "s");
        cJSON_Delete(points);
        goto out;
    }
    /* A --set of a key the sweep also sets is overridden by each point: say so. */
    for (int i = 0; i < a->nsets; i++) {
        size_t kl = strcspn(a->sets[i], "=");
        const cJSON *p;
        int hit = 0;
        cJSON_ArrayForEach(p, points)
        {
            const cJSON *kv;
            cJSON_ArrayForEach(kv, cJSON_GetObjectItemCaseSensitive(p, "settings"))
                hit |= strlen(kv->string) == kl && !strncmp(kv->string, a->sets[i], kl);
        }
        if (hit)
            fprintf(stderr, "sfsim sweep: note: --set %s: the sweep file sets %.*s too; its value wins\n", a->sets[i],
                    (int)kl, a->sets[i]);
    }
    m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "format", SW_MANIFEST_FORMAT);
    if (config) {
        cJSON_AddStringToObject(m, "config", config);
        cJSON_AddStringToObject(m, "config_contents", config_text);
    } else {
        cJSON_AddNullToObject(m, "config");
        cJSON_AddNullToObject(m, "config_contents");
    }
    cJSON_AddStringToObject(m, "sweep_file", sweep);
    cJSON_AddStringToObject(m, "sweep_contents", sweep_text);
    cJSON_AddStringToObject(m, "scene", scene);
    cJSON_AddStringToObject(m, "mode", a->mode);
    if (a->sample)
        cJSON_AddStringToObject(m, "sample", a->sample);
    else
        cJSON_AddNullToObject(m, "sample");
    cJSON *sets = cJSON_AddArrayToObject(m, "sets");
    for (int i = 0; i < a->nsets; i++)
        cJSON_AddItemToArray(sets, cJSON_CreateString(a->sets[i]));
    cJSON_AddStringToObject(m, "kind", explicit_points ? "points" : "cross");
    cJSON_AddItemToObject(m, "points", points);
out:
    buf_free(&errs.text);
    free(config);
    free(config_text);
    free(sweep);
    free(sweep_text);
    free(scene);
    return m;
}

static const char *or_none(const char *s, const char *none)
{
    return s ? s : none;
}

static int str_eq(const char *a, const char *b)
{
    return (!a && !b) || (a && b && !strcmp(a, b));
}

/* What differs between the sweep in a folder (old) and the one the arguments define, a line each. */
static void plan_diff(const Plan *old, const Plan *cur, Buf *out)
{
    if (!str_eq(old->config, cur->config))
        buf_printf(out, "  -c: %s there, %s here\n", or_none(old->config, "none (the built-in machine)"),
                   or_none(cur->config, "none (the built-in machine)"));
    else if (!str_eq(old->config_text, cur->config_text))
        buf_printf(out, "  the config file %s: its contents changed since the sweep began\n", cur->config);
    if (!str_eq(old->sweep, cur->sweep))
        buf_printf(out, "  --sweep: %s there, %s here\n", old->sweep, cur->sweep);
    else if (!str_eq(old->sweep_text, cur->sweep_text))
        buf_printf(out, "  the sweep file %s: its contents changed since the sweep began\n", cur->sweep);
    if (!str_eq(old->scene, cur->scene))
        buf_printf(out, "  -s: %s there, %s here\n", old->scene, cur->scene);
    if (!str_eq(old->mode, cur->mode))
        buf_printf(out, "  --mode: %s there, %s here\n", old->mode, cur->mode);
    if (!str_eq(old->sample, cur->sample))
        buf_printf(out, "  --sample: %s there, %s here\n", or_none(old->sample, "none"), or_none(cur->sample, "none"));
    int same_sets = old->nsets == cur->nsets;
    for (int i = 0; same_sets && i < old->nsets; i++)
        same_sets = !strcmp(old->sets[i], cur->sets[i]);
    if (!same_sets) {
        buf_puts(out, "  --set:");
        for (int i = 0; i < old->nsets; i++)
            buf_printf(out, " %s", old->sets[i]);
        buf_printf(out, "%s there;", old->nsets ? "" : " none");
        for (int i = 0; i < cur->nsets; i++)
            buf_printf(out, " %s", cur->sets[i]);
        buf_printf(out, "%s here\n", cur->nsets ? "" : " none");
    }
    if (!out->len && !cJSON_Compare(cJSON_GetObjectItemCaseSensitive(old->json, "points"),
                                    cJSON_GetObjectItemCaseSensitive(cur->json, "points"), 1))
        buf_puts(out, "  the points (the sweep was begun by another version of sfsim)\n");
}

/* A folder without sweep.json holds something else than these (another task may be writing the
 * manifest: its lock and temporary file). A points/ folder without a manifest is foreign too:
 * its markers may belong to another sweep. */
static int dir_foreign(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    struct dirent *e;
    int foreign = 0;
    while ((e = readdir(d)) && !foreign)
        foreign = strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strcmp(e->d_name, ".sweep.lock") &&
                  strncmp(e->d_name, ".sweep.json.tmp.", 16);
    closedir(d);
    return foreign;
}

/* The folder's lock, DIR/.sweep.lock: a whole sweep and merge hold it exclusively, --point tasks
 * shared, so that merge never writes sweep.csv under a running sweep, and a sweep never starts
 * under another. A POSIX record lock (fcntl) rather than flock: a refusal can then name the
 * holder's pid (F_GETLK), and it also works on NFS. The lock belongs to this process (not to the
 * points it forks) until *fd is closed. EXIT_OK, or an exit code after saying why. */
static int sweep_lock(const char *dir, int exclusive, const char *cmd, int *fd)
{
    char *path = xasprintf("%s/.sweep.lock", dir);
    int rc = EXIT_IO;
    *fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (*fd < 0) {
        fprintf(stderr, "sfsim %s: %s: cannot create: %s\n", cmd, path, strerror(errno));
        goto out;
    }
    struct flock fl;
    memset(&fl, 0, sizeof fl);
    fl.l_type = exclusive ? F_WRLCK : F_RDLCK;
    fl.l_whence = SEEK_SET; /* l_start = l_len = 0: the whole file */
    if (fcntl(*fd, F_SETLK, &fl) == 0) {
        rc = EXIT_OK;
        goto out;
    }
    if (errno == EACCES || errno == EAGAIN) {
        struct flock q = fl;
        char holder[128] = "another sfsim sweep";
        if (fcntl(*fd, F_GETLK, &q) == 0 && q.l_type == F_RDLCK)
            snprintf(holder, sizeof holder, "sfsim sweep --point tasks (pid %ld, perhaps others)", (long)q.l_pid);
        else if (q.l_type == F_WRLCK)
            snprintf(holder, sizeof holder, "another sfsim sweep or merge (pid %ld)", (long)q.l_pid);
        if (!strcmp(cmd, "merge"))
            fprintf(stderr, "sfsim merge: %s is in use by %s: merge when it has ended\n", dir, holder);
        else
            fprintf(stderr, "sfsim sweep: %s is in use by %s (wait for it or stop it)\n", dir, holder);
        close(*fd);
        *fd = -1;
        goto out;
    }
    fprintf(stderr, "sfsim %s: warning: %s: cannot lock (%s); make sure no other sweep runs in %s\n", cmd, path,
            strerror(errno), dir);
    rc = EXIT_OK;
out:
    free(path);
    return rc;
}

/* Open the sweep folder `dir` for the sweep in cur: create it and write sweep.json, or check
 * the one there is the same sweep. Takes the folder's lock (exclusive for a whole sweep, shared
 * for one point). EXIT_OK with *dir_abs the folder's absolute path and the lock held in
 * *lock_fd, or an exit code after saying why. */
static int sweep_dir_open(const char *dir, const Plan *cur, int exclusive, int *lock_fd, char **dir_abs)
{
    char err[PATH_MAX + 256];
    *lock_fd = -1;
    *dir_abs = NULL;
    char *manifest = xasprintf("%s/sweep.json", dir);
    char *points = xasprintf("%s/points", dir);
    int rc = EXIT_IO;
    struct stat st;
    if (stat(dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode)) {
            fprintf(stderr, "sfsim sweep: %s exists and is not a folder\n", dir);
            goto out;
        }
        if (!file_exists(manifest) && dir_foreign(dir)) {
            fprintf(stderr, "sfsim sweep: %s is not empty and holds no sweep.json: not a sweep folder "
                            "(choose another -o DIR)\n", dir);
            rc = EXIT_INPUT;
            goto out;
        }
    }
    if (mkdir_p(dir, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        goto out;
    }
    if ((rc = sweep_lock(dir, exclusive, "sweep", lock_fd)) != EXIT_OK)
        goto out;
    rc = EXIT_INPUT; /* a manifest that is not this sweep's is the arguments' fault */
    if (file_exists(manifest)) {
        size_t len;
        char *text = file_read(manifest, &len, err, sizeof err);
        if (!text) {
            fprintf(stderr, "sfsim sweep: %s\n", err);
            goto out;
        }
        cJSON *json = cJSON_Parse(text);
        free(text);
        Plan old;
        if (!json || plan_load(json, &old, err, sizeof err)) {
            if (!json)
                snprintf(err, sizeof err, "not JSON");
            else
                plan_free(&old);
            fprintf(stderr, "sfsim sweep: %s: %s\n", manifest, err);
            goto out;
        }
        Buf diff = {0};
        plan_diff(&old, cur, &diff);
        plan_free(&old);
        if (diff.len) {
            fprintf(stderr, "sfsim sweep: %s holds another sweep (%s); what differs:\n%s"
                            "To resume it, give the arguments it was made with; for a new sweep, choose another -o DIR.\n",
                    dir, manifest, buf_str(&diff));
            buf_free(&diff);
            goto out;
        }
    } else {
        char *text = cJSON_Print(cur->json);
        if (!text) {
            fputs("sfsim: out of memory\n", stderr);
            abort();
        }
        size_t len = strlen(text);
        text[len] = 0;
        Buf b = {0};
        buf_printf(&b, "%s\n", text);
        cJSON_free(text);
        int w = file_write_atomic(manifest, b.s, b.len, err, sizeof err);
        buf_free(&b);
        if (w) {
            fprintf(stderr, "sfsim sweep: %s\n", err);
            rc = EXIT_IO;
            goto out;
        }
    }
    rc = EXIT_IO;
    if (mkdir_p(points, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        goto out;
    }
    *dir_abs = realpath(dir, NULL);
    if (!*dir_abs) {
        fprintf(stderr, "sfsim sweep: %s: %s\n", dir, strerror(errno));
        goto out;
    }
    rc = EXIT_OK;
out:
    if (rc && *lock_fd >= 0) {
        close(*lock_fd);
        *lock_fd = -1;
    }
    free(manifest);
    free(points);
    return rc;
}

/* ---- point folders and markers -------------------------------------------------------------- */

enum { PS_UNFINISHED, PS_DONE, PS_FAILED };

/* The state of point k; *secs the host seconds its marker holds (0 when none). The `error`
 * line of a failed marker in *error when error is not NULL (malloc'ed). */
static int point_state(const Plan *pl, const char *dir, int k, double *secs, char **error)
{
    char *pdir = point_dir(pl, dir, k);
    char *done = xasprintf("%s/done", pdir), *failed = xasprintf("%s/failed", pdir);
    int state = file_exists(done) ? PS_DONE : file_exists(failed) ? PS_FAILED : PS_UNFINISHED;
    *secs = 0;
    if (error)
        *error = NULL;
    if (state != PS_UNFINISHED) {
        char err[PATH_MAX + 64];
        size_t len;
        char *text = file_read(state == PS_DONE ? done : failed, &len, err, sizeof err);
        for (char *line = text; line && *line;) {
            char *nl = strchr(line, '\n');
            if (nl)
                *nl = 0;
            if (!strncmp(line, "host_seconds ", 13))
                *secs = strtod(line + 13, NULL);
            if (!strncmp(line, "error ", 6) && error && !*error)
                *error = xstrdup(line + 6);
            if (!strncmp(line, "--- ", 4) || !nl)
                break;
            line = nl + 1;
        }
        free(text);
        if (error && state == PS_FAILED && !*error)
            *error = xstrdup("(no error line in the failed marker)");
    }
    free(done);
    free(failed);
    free(pdir);
    return state;
}

/* The point's own settings, as a [point.NAME] section of a sweep file: concatenated, the
 * point.ini files of a sweep make an explicit-point sweep file. */
static int point_ini_write(const Plan *pl, const char *pdir, int k, char *const *argv, char *err, size_t errlen)
{
    Buf b = {0};
    buf_printf(&b, "; sfsim sweep: point %d of %d of the sweep %s\n", k, pl->npoints, pl->sweep);
    if (pl->nsets) {
        buf_puts(&b, "; every point also has:");
        for (int i = 0; i < pl->nsets; i++)
            buf_printf(&b, " --set %s", pl->sets[i]);
        buf_puts(&b, "\n");
    }
    buf_puts(&b, "; command:");
    for (int i = 0; argv[i]; i++) {
        buf_puts(&b, " ");
        buf_shell_word(&b, argv[i], 0);
    }
    buf_puts(&b, "\n");
    if (pl->points[k].name)
        buf_printf(&b, "[point.%s]\n", pl->points[k].name);
    else
        buf_printf(&b, "[point.%0*d]\n", pl->digits, k);
    for (int i = 0; i < pl->points[k].n; i++)
        buf_printf(&b, "%s = %s\n", pl->points[k].key[i], pl->points[k].val[i]);
    char *path = xasprintf("%s/point.ini", pdir);
    int rc = file_write_atomic(path, b.s, b.len, err, errlen);
    free(path);
    buf_free(&b);
    return rc;
}

/* The last SW_TAIL_LINES lines of a log (its last 64 KiB). */
static char *log_tail(const char *path)
{
    FILE *f = fopen(path, "rbe");
    if (!f)
        return xstrdup("");
    char buf[65536];
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : 0;
    if (size > (long)sizeof buf - 1)
        fseek(f, size - (long)sizeof buf + 1, SEEK_SET);
    else
        fseek(f, 0, SEEK_SET);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = 0;
    for (size_t i = 0; i < n; i++)
        if (buf[i] == 0 || buf[i] == '\r')
            buf[i] = ' ';
    while (n && buf[n - 1] == '\n')
        buf[--n] = 0;
    size_t start = n;
    for (int lines = 0; start > 0; start--)
        if (buf[start - 1] == '\n' && ++lines == SW_TAIL_LINES)
            break;
    return xstrdup(buf + start);
}

/* ---- running points ------------------------------------------------------------------------- */

static volatile sig_atomic_t sw_stop_signal; /* SIGINT/SIGTERM/SIGHUP received; 0 none */

static void on_stop(int sig)
{
    if (!sw_stop_signal)
        sw_stop_signal = sig;
}

static void on_child(int sig)
{
    (void)sig; /* only to interrupt ppoll */
}

typedef struct Child {
    pid_t pid;
    int point;
    double t0;
} Child;

typedef struct Runner {
    const Plan *pl;
    const char *dir; /* absolute */
    char exe[PATH_MAX];
    int jobs, threads, progress;
    const int *todo;
    int ntodo, next;
    Child *kids;
    int nkids;
    int done, failed, total, started;
    double secs_sum;
    int secs_n;
    int shown; /* a progress line is on the terminal */
    int fatal;
    sigset_t child_mask;
    double t0;
} Runner;

static void progress_clear(Runner *r)
{
    if (r->shown) {
        fputs("\r\033[K", stderr);
        r->shown = 0;
    }
}

static void fmt_duration(double s, char *buf, size_t len)
{
    long t = (long)(s + 0.5);
    if (t < 60)
        snprintf(buf, len, "%lds", t);
    else if (t < 3600)
        snprintf(buf, len, "%ldm%02lds", t / 60, t % 60);
    else
        snprintf(buf, len, "%ldh%02ldm", t / 3600, t % 3600 / 60);
}

static void progress_line(const Runner *r, Buf *b)
{
    buf_printf(b, "sweep: %d/%d done, %d running, %d failed", r->done, r->total, r->nkids, r->failed);
    int remaining = r->total - r->done - r->failed;
    if (remaining > 0 && r->secs_n > 0) {
        double mean = r->secs_sum / r->secs_n, t = now(), running = 0;
        for (int i = 0; i < r->nkids; i++)
            running += fmin(t - r->kids[i].t0, mean);
        int par = remaining < r->jobs ? remaining : r->jobs;
        char d[32];
        fmt_duration(fmax(0, (remaining * mean - running) / par), d, sizeof d);
        buf_printf(b, ", ~%s left", d);
    }
}

static void progress_show(Runner *r)
{
    if (!r->progress)
        return;
    Buf b = {0};
    progress_line(r, &b);
    fprintf(stderr, "\r\033[K%s", buf_str(&b));
    fflush(stderr);
    r->shown = 1;
    buf_free(&b);
}

/* The `sfsim run` command of point k, NULL-terminated (free with argv_free). */
static char **point_argv(const Runner *r, int k, const char *pdir)
{
    const Plan *pl = r->pl;
    StrList a = {0};
    sl_push(&a, xstrdup(r->exe));
    sl_push(&a, xstrdup("run"));
    if (pl->config) {
        sl_push(&a, xstrdup("-c"));
        sl_push(&a, xstrdup(pl->config));
    }
    sl_push(&a, xstrdup("-s"));
    sl_push(&a, xstrdup(pl->scene));
    sl_push(&a, xstrdup("-o"));
    sl_push(&a, xstrdup(pdir));
    sl_push(&a, xstrdup("--mode"));
    sl_push(&a, xstrdup(pl->mode));
    if (pl->sample) {
        sl_push(&a, xstrdup("--sample"));
        sl_push(&a, xstrdup(pl->sample));
    }
    for (int i = 0; i < pl->nsets; i++) {
        sl_push(&a, xstrdup("--set"));
        sl_push(&a, xstrdup(pl->sets[i]));
    }
    for (int i = 0; i < pl->points[k].n; i++) {
        sl_push(&a, xstrdup("--set"));
        sl_push(&a, xasprintf("%s=%s", pl->points[k].key[i], pl->points[k].val[i]));
    }
    sl_push(&a, xstrdup("-j"));
    sl_push(&a, xasprintf("%d", r->threads));
    sl_push(&a, xstrdup("--no-progress"));
    sl_push(&a, NULL);
    return a.v;
}

static void argv_free(char **argv)
{
    for (int i = 0; argv && argv[i]; i++)
        free(argv[i]);
    free(argv);
}

/* Empty point k's folder, write its point.ini and start its run; -1 (r->fatal) when the folder
 * or the process cannot be made. */
static int runner_start(Runner *r, int k)
{
    char err[PATH_MAX + 256];
    char *pdir = point_dir(r->pl, r->dir, k);
    char *log = xasprintf("%s/log.txt", pdir);
    char **argv = point_argv(r, k, pdir);
    int rc = -1, logfd = -1, nullfd = -1;
    if (mkdir_p(pdir, err, sizeof err) || dir_clear(pdir, err, sizeof err) ||
        point_ini_write(r->pl, pdir, k, argv, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        goto out;
    }
    logfd = open(log, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    nullfd = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (logfd < 0 || nullfd < 0) {
        fprintf(stderr, "sfsim sweep: %s: cannot create: %s\n", logfd < 0 ? log : "/dev/null", strerror(errno));
        goto out;
    }
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) {
        /* Its own process group: a terminal's ^C reaches the sweep, which stops its points; and
         * a sweep killed outright takes its points with it. */
        setpgid(0, 0);
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent)
            _exit(127);
        if (dup2(nullfd, 0) < 0 || dup2(logfd, 1) < 0 || dup2(logfd, 2) < 0)
            _exit(127);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGHUP, SIG_DFL);
        signal(SIGCHLD, SIG_DFL);
        sigprocmask(SIG_SETMASK, &r->child_mask, NULL);
        execv("/proc/self/exe", argv);
        dprintf(2, "sfsim sweep: cannot run %s: %s\n", r->exe, strerror(errno));
        _exit(127);
    }
    if (pid < 0) {
        fprintf(stderr, "sfsim sweep: cannot start a process: %s\n", strerror(errno));
        goto out;
    }
    setpgid(pid, pid); /* also here: whichever runs first */
    r->kids = xrealloc(r->kids, (size_t)(r->nkids + 1) * sizeof *r->kids);
    r->kids[r->nkids++] = (Child){pid, k, now()};
    r->started++;
    rc = 0;
out:
    if (logfd >= 0)
        close(logfd);
    if (nullfd >= 0)
        close(nullfd);
    if (rc)
        r->fatal = 1;
    argv_free(argv);
    free(log);
    free(pdir);
    return rc;
}

/* Write a point's marker (done or failed); a marker that cannot be written stops the sweep. */
static int marker_write(Runner *r, const char *pdir, const char *name, const Buf *text)
{
    char err[PATH_MAX + 256];
    char *path = xasprintf("%s/%s", pdir, name);
    int rc = file_write_atomic(path, buf_str(text), text->len, err, sizeof err);
    if (rc) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        r->fatal = 1;
    }
    free(path);
    return rc;
}

/* A child ended: mark its point done or failed. */
static void runner_finish(Runner *r, pid_t pid, int status)
{
    int i = 0;
    while (i < r->nkids && r->kids[i].pid != pid)
        i++;
    if (i == r->nkids)
        return;
    Child c = r->kids[i];
    r->kids[i] = r->kids[--r->nkids];
    double secs = now() - c.t0;
    char *pdir = point_dir(r->pl, r->dir, c.point);
    char *report = xasprintf("%s/report.json", pdir);
    char *log = xasprintf("%s/log.txt", pdir);
    Buf m = {0}, why = {0};
    int ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && file_exists(report);
    if (ok) {
        buf_printf(&m, "exit_status 0\nhost_seconds %.3f\n", secs);
        if (marker_write(r, pdir, "done", &m) == 0)
            r->done++;
    } else {
        char *tail = log_tail(log);
        const char *first = tail;
        while (*first == '\n')
            first++;
        size_t fl = strcspn(first, "\n");
        if (WIFEXITED(status)) {
            buf_printf(&m, "exit_status %d\n", WEXITSTATUS(status));
            if (WEXITSTATUS(status) == 0)
                buf_puts(&why, "exit 0 but no report.json");
            else if (fl)
                buf_printf(&why, "exit %d: %.*s", WEXITSTATUS(status), (int)fl, first);
            else
                buf_printf(&why, "exit %d, no output", WEXITSTATUS(status));
        } else {
            int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
            buf_printf(&m, "exit_status signal %d\n", sig);
            buf_printf(&why, "killed by signal %d (%s)", sig, strsignal(sig));
        }
        buf_printf(&m, "host_seconds %.3f\nerror %s\n--- the last lines of log.txt ---\n%s\n", secs, buf_str(&why),
                   tail);
        free(tail);
        if (marker_write(r, pdir, "failed", &m) == 0) {
            r->failed++;
            char *label = point_label(r->pl, c.point);
            progress_clear(r);
            fprintf(stderr, "sweep: %s failed, %s (%s)\n", label, buf_str(&why), log);
            free(label);
        }
    }
    r->secs_sum += secs;
    r->secs_n++;
    buf_free(&m);
    buf_free(&why);
    free(report);
    free(log);
    free(pdir);
}

/* Stop the running points: TERM to each point's process group, KILL after ten seconds. Their
 * folders stay unmarked (unfinished). */
static void runner_stop_all(Runner *r)
{
    for (int i = 0; i < r->nkids; i++)
        if (kill(-r->kids[i].pid, SIGTERM) != 0)
            kill(r->kids[i].pid, SIGTERM);
    double deadline = now() + 10;
    while (r->nkids) {
        for (int i = 0; i < r->nkids;) {
            int st;
            pid_t w = waitpid(r->kids[i].pid, &st, WNOHANG);
            if (w == r->kids[i].pid || (w < 0 && errno == ECHILD))
                r->kids[i] = r->kids[--r->nkids];
            else
                i++;
        }
        if (!r->nkids)
            break;
        if (now() > deadline) {
            for (int i = 0; i < r->nkids; i++) {
                kill(-r->kids[i].pid, SIGKILL);
                kill(r->kids[i].pid, SIGKILL);
                waitpid(r->kids[i].pid, NULL, 0);
            }
            r->nkids = 0;
            break;
        }
        struct timespec ts = {0, 20 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
}

/* Run the points of r->todo, r->jobs at once. Returns 0, the signal that stopped it, or -1
 * when a point folder or marker could not be written. */
static int runner_run(Runner *r)
{
    sigset_t block, wait_mask;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    sigaddset(&block, SIGCHLD);
    if (sigprocmask(SIG_BLOCK, &block, &r->child_mask) != 0) {
        fprintf(stderr, "sfsim sweep: sigprocmask: %s\n", strerror(errno));
        return -1;
    }
    wait_mask = r->child_mask;
    sigdelset(&wait_mask, SIGINT);
    sigdelset(&wait_mask, SIGTERM);
    sigdelset(&wait_mask, SIGHUP);
    sigdelset(&wait_mask, SIGCHLD);
    struct sigaction sa, old_int, old_term, old_hup, old_chld;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = on_stop;
    sw_stop_signal = 0;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    sigaction(SIGHUP, &sa, &old_hup);
    sa.sa_handler = on_child;
    sa.sa_flags = SA_NOCLDSTOP;
    sigaction(SIGCHLD, &sa, &old_chld);

    r->t0 = now();
    while (!sw_stop_signal && !r->fatal && (r->next < r->ntodo || r->nkids)) {
        while (!r->fatal && r->nkids < r->jobs && r->next < r->ntodo)
            runner_start(r, r->todo[r->next++]);
        int reaped = 0, st;
        pid_t pid;
        while (!r->fatal && (pid = waitpid(-1, &st, WNOHANG)) > 0) {
            runner_finish(r, pid, st);
            reaped = 1;
        }
        if (reaped || r->fatal || !r->nkids)
            continue; /* start the next points first */
        progress_show(r);
        struct timespec ts = {1, 0};
        ppoll(NULL, 0, &ts, &wait_mask); /* wakes on SIGCHLD, a stop signal, or each second */
    }
    int rc = sw_stop_signal ? (int)sw_stop_signal : r->fatal ? -1 : 0;
    if (rc)
        runner_stop_all(r);
    progress_clear(r);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    sigaction(SIGHUP, &old_hup, NULL);
    sigaction(SIGCHLD, &old_chld, NULL);
    sigprocmask(SIG_SETMASK, &r->child_mask, NULL);
    return rc;
}

/* ---- sweep.csv ------------------------------------------------------------------------------ */

enum {
    M_CYCLES,
    M_BUSY,
    M_FPS,
    M_FPS_NO_STALL,
    M_FPS_LO,
    M_FPS_HI,
    M_UTIL,                         /* 4 stages, in the order of util_stages */
    M_UTIL_TIMED = M_UTIL + 4,      /* the same */
    M_STALL = M_UTIL_TIMED + 4,     /* TM_CAUSE_COUNT causes */
    M_OPS = M_STALL + TM_CAUSE_COUNT, /* ISA_C_COUNT categories */
    M_RAYS = M_OPS + ISA_C_COUNT,
    M_HOST,
    M_KD,                           /* kd_<counter>_per_ray over all rays, FUNC_KD_COUNTERS of them */
    M_KD_KIND = M_KD + FUNC_KD_COUNTERS, /* kd_<kind>_<counter>_per_ray: per ray kind, kind-major */
    M_KD_CAMERA_NODES = M_KD_KIND + FUNC_KD_CAMERA * FUNC_KD_COUNTERS + FUNC_KD_NODES,
    M_COUNT = M_KD_KIND + FUNC_KD_KINDS * FUNC_KD_COUNTERS
};

/* The report's stages, in the CSV's order. */
static const int util_stages[4] = {ISA_STAGE_TRAVERSAL, ISA_STAGE_INTERSECTION, ISA_STAGE_SHADING, ISA_STAGE_OTHER};

static void metric_name(int m, char *buf, size_t len)
{
    static const char *const fixed[] = {"cycles", "busy_cycles", "fps", "fps_no_stall", "fps_lo", "fps_hi"};
    if (m < M_UTIL)
        snprintf(buf, len, "%s", fixed[m]);
    else if (m < M_UTIL_TIMED)
        snprintf(buf, len, "utilization_%s", isa_stage_keys[util_stages[m - M_UTIL]]);
    else if (m < M_STALL)
        snprintf(buf, len, "utilization_timed_%s", isa_stage_keys[util_stages[m - M_UTIL_TIMED]]);
    else if (m < M_OPS)
        snprintf(buf, len, "stall_share_%s", tm_cause_keys[m - M_STALL]);
    else if (m < M_RAYS)
        snprintf(buf, len, "ops_share_%s", isa_category_keys[m - M_OPS]);
    else if (m < M_KD)
        snprintf(buf, len, "%s", m == M_RAYS ? "rays_total" : "host_seconds");
    else if (m < M_KD_KIND)
        snprintf(buf, len, "kd_%s_per_ray", func_kd_counter_keys[m - M_KD]);
    else
        snprintf(buf, len, "kd_%s_%s_per_ray", func_kd_kind_keys[(m - M_KD_KIND) / FUNC_KD_COUNTERS],
                 func_kd_counter_keys[(m - M_KD_KIND) % FUNC_KD_COUNTERS]);
}

typedef struct Row {
    int state;
    char *error;
    double m[M_COUNT];
    unsigned char has[M_COUNT];
} Row;

static void row_num(Row *row, int m, const cJSON *it)
{
    if (cJSON_IsNumber(it) && isfinite(it->valuedouble)) {
        row->m[m] = it->valuedouble;
        row->has[m] = 1;
    }
}

static const cJSON *jget(const cJSON *o, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(o, name);
}

/* The figures of a point's report.json; -1 when it cannot be read. */
static int row_read_report(Row *row, const char *path, char *err, size_t errlen)
{
    size_t len;
    char *text = file_read(path, &len, err, errlen);
    if (!text)
        return -1;
    cJSON *j = cJSON_Parse(text);
    free(text);
    if (!cJSON_IsObject(j)) {
        snprintf(err, errlen, "%s: not a JSON object", path);
        cJSON_Delete(j);
        return -1;
    }
    row_num(row, M_CYCLES, jget(j, "cycles"));
    row_num(row, M_BUSY, jget(j, "busy_cycles"));
    row_num(row, M_FPS, jget(j, "fps"));
    row_num(row, M_FPS_NO_STALL, jget(j, "fps_no_stall"));
    const cJSON *ci = jget(j, "fps_ci95");
    if (cJSON_IsArray(ci) && cJSON_GetArraySize(ci) == 2) {
        row_num(row, M_FPS_LO, cJSON_GetArrayItem(ci, 0));
        row_num(row, M_FPS_HI, cJSON_GetArrayItem(ci, 1));
    }
    for (int s = 0; s < 4; s++) {
        row_num(row, M_UTIL + s, jget(jget(j, "utilization"), isa_stage_keys[util_stages[s]]));
        row_num(row, M_UTIL_TIMED + s, jget(jget(j, "utilization_timed"), isa_stage_keys[util_stages[s]]));
    }
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        row_num(row, M_STALL + c, jget(jget(j, "stall_shares"), tm_cause_keys[c]));
    double sum = 0;
    for (int c = 0; c < ISA_C_COUNT; c++) {
        row_num(row, M_OPS + c, jget(jget(j, "ops"), isa_category_keys[c]));
        sum += row->has[M_OPS + c] ? row->m[M_OPS + c] : 0;
    }
    for (int c = 0; c < ISA_C_COUNT; c++) {
        if (sum > 0)
            row->m[M_OPS + c] /= sum;
        else
            row->has[M_OPS + c] = 0;
    }
    row_num(row, M_RAYS, jget(jget(j, "rays"), "total"));
    row_num(row, M_HOST, jget(jget(j, "host"), "seconds"));
    const cJSON *kd = jget(j, "kd");
    for (int c = 0; c < FUNC_KD_COUNTERS; c++) {
        char key[64];
        snprintf(key, sizeof key, "%s_per_ray", func_kd_counter_keys[c]);
        row_num(row, M_KD + c, jget(jget(kd, "total"), key));
    }
    for (int k = 0; k < FUNC_KD_KINDS; k++)
        for (int c = 0; c < FUNC_KD_COUNTERS; c++) {
            char key[64];
            snprintf(key, sizeof key, "%s_per_ray", func_kd_counter_keys[c]);
            row_num(row, M_KD_KIND + k * FUNC_KD_COUNTERS + c, jget(jget(kd, func_kd_kind_keys[k]), key));
        }
    cJSON_Delete(j);
    return 0;
}

/* Every point's state and figures. */
static Row *rows_collect(const Plan *pl, const char *dir, int *ndone, int *nfailed, int *nunfinished)
{
    Row *rows = xrealloc(NULL, (size_t)pl->npoints * sizeof *rows);
    memset(rows, 0, (size_t)pl->npoints * sizeof *rows);
    *ndone = *nfailed = *nunfinished = 0;
    for (int k = 0; k < pl->npoints; k++) {
        double secs;
        rows[k].state = point_state(pl, dir, k, &secs, &rows[k].error);
        if (rows[k].state == PS_DONE) {
            (*ndone)++;
            char *pdir = point_dir(pl, dir, k);
            char *report = xasprintf("%s/report.json", pdir);
            char err[PATH_MAX + 64];
            if (row_read_report(&rows[k], report, err, sizeof err))
                fprintf(stderr, "sfsim sweep: warning: %s; its row has no figures\n", err);
            free(report);
            free(pdir);
        } else if (rows[k].state == PS_FAILED) {
            (*nfailed)++;
        } else {
            (*nunfinished)++;
        }
    }
    return rows;
}

static void rows_free(Row *rows, int n)
{
    for (int i = 0; rows && i < n; i++)
        free(rows[i].error);
    free(rows);
}

static void csv_field(Buf *b, const char *s, int quote)
{
    quote |= strpbrk(s, ",\"\n\r") != NULL;
    if (!quote) {
        buf_puts(b, s);
        return;
    }
    buf_puts(b, "\"");
    for (const char *c = s; *c; c++)
        buf_add(b, *c == '"' ? "\"\"" : c, *c == '"' ? 2 : 1);
    buf_puts(b, "\"");
}

/* Integers as integers (cycles), the rest to 10 significant digits. */
static void fmt_num(double v, char *buf, size_t len)
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, len, "%.0f", v);
    else
        snprintf(buf, len, "%.10g", v);
}

static const char *state_name(int s)
{
    return s == PS_DONE ? "ok" : s == PS_FAILED ? "failed" : "unfinished";
}

static int csv_write(const Plan *pl, const Row *rows, const char *path, char *err, size_t errlen)
{
    Buf b = {0};
    char name[64];
    buf_puts(&b, "point");
    for (int k = 0; k < pl->nkeys; k++) {
        buf_puts(&b, ",");
        csv_field(&b, pl->keys[k], 0);
    }
    buf_puts(&b, ",status,error");
    for (int m = 0; m < M_COUNT; m++) {
        metric_name(m, name, sizeof name);
        buf_printf(&b, ",%s", name);
    }
    buf_puts(&b, "\n");
    for (int p = 0; p < pl->npoints; p++) {
        if (pl->points[p].name)
            csv_field(&b, pl->points[p].name, 0);
        else
            buf_printf(&b, "%d", p);
        for (int k = 0; k < pl->nkeys; k++) {
            const char *v = plan_value(pl, p, pl->keys[k]);
            buf_puts(&b, ",");
            csv_field(&b, v ? v : "", 0);
        }
        buf_printf(&b, ",%s,", state_name(rows[p].state));
        if (rows[p].error)
            csv_field(&b, rows[p].error, 1);
        for (int m = 0; m < M_COUNT; m++) {
            buf_puts(&b, ",");
            if (rows[p].has[m]) {
                fmt_num(rows[p].m[m], name, sizeof name);
                buf_puts(&b, name);
            }
        }
        buf_puts(&b, "\n");
    }
    int rc = file_write_atomic(path, b.s, b.len, err, errlen);
    buf_free(&b);
    return rc;
}

/* ---- plots ---------------------------------------------------------------------------------- */

typedef struct Plotter {
    const Plan *pl;
    const Row *rows;
    const char *dir; /* DIR/plots */
    char *subtitle;  /* scene, mode and fixed keys, gnuplot-escaped, lines joined by \n */
    int made;
    int gnuplot_missing, gnuplot_failed;
} Plotter;

/* A string in gnuplot double quotes. */
static void gp_str(Buf *b, const char *s)
{
    buf_puts(b, "\"");
    for (const char *c = s; *c; c++) {
        if (*c == '"' || *c == '\\')
            buf_puts(b, "\\");
        buf_add(b, c, 1);
    }
    buf_puts(b, "\"");
}

/* Units of a key for its axis label. */
static const char *key_unit(const char *key)
{
    static const struct { const char *suffix, *unit; } units[] = {
        {"core.simd_width", "lanes"}, {"stream.rays", "rays per stream"}, {"render.width", "pixels"},
        {"render.height", "pixels"}, {"render.spp", "samples per pixel"}, {"render.max_depth", "bounces"},
        {"kd.max_depth", "levels"},
        {"_per_cycle", "per cycle"}, {"_kb", "KiB"}, {"_mb", "MiB"}, {"_mhz", "MHz"}, {"_bytes", "bytes"},
        {"_cycles", "cycles"}, {"_penalty", "cycles"}, {"latency", "cycles"}, {"banks", "banks"}, {"ports", "ports"},
        {"_ways", "ways"}, {"_depth", "entries"}, {"bins", "bins"}, {"leaf_size", "primitives"},
        {"bounces", "bounces"}};
    size_t kl = strlen(key);
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
        size_t sl = strlen(units[i].suffix);
        if (kl >= sl && !strcmp(key + kl - sl, units[i].suffix))
            return units[i].unit;
    }
    if (!strncmp(key, "latency.", 8))
        return "cycles";
    if (!strncmp(key, "issue.", 6))
        return "cycles between issues";
    return NULL;
}

static void axis_label(Buf *b, const char *key)
{
    const char *u = key_unit(key);
    Buf t = {0};
    buf_printf(&t, u ? "%s (%s)" : "%s", key, u);
    gp_str(b, buf_str(&t));
    buf_free(&t);
}

/* Distinct values of a key over all points; *numeric when every point sets it to a number. */
static int key_values(const Plan *pl, const char *key, int *numeric)
{
    StrList seen = {0};
    *numeric = 1;
    for (int p = 0; p < pl->npoints; p++) {
        const char *v = plan_value(pl, p, key);
        double d;
        if (!v || !is_number(v, &d))
            *numeric = 0;
        int dup = 0;
        for (int i = 0; i < seen.n && !dup; i++)
            dup = str_eq(seen.v[i], v);
        if (!dup)
            sl_push(&seen, v ? xstrdup(v) : NULL);
    }
    int n = seen.n;
    sl_free(&seen);
    return n;
}

static int key_swept(const Plan *pl, const char *key)
{
    int numeric;
    return key_values(pl, key, &numeric) > 1;
}

static int row_usable(const Plotter *p, int r, int m0, int n)
{
    if (p->rows[r].state != PS_DONE)
        return 0;
    for (int m = m0; m < m0 + n; m++)
        if (p->rows[r].has[m])
            return 1;
    return 0;
}

static void dat_num(Buf *b, const Row *row, int m)
{
    char v[64];
    if (row->has[m])
        fmt_num(row->m[m], v, sizeof v);
    else
        snprintf(v, sizeof v, "NaN");
    buf_printf(b, " %s", v);
}

/* A group of rows: the points that share the values of the swept keys other than x. */
typedef struct Group {
    char *label;
    int *rows;
    int n;
} Group;

static void groups_free(Group *g, int n)
{
    for (int i = 0; i < n; i++) {
        free(g[i].label);
        free(g[i].rows);
    }
    free(g);
}

/* Usable rows (metrics m0..m0+n-1) grouped by the other swept keys, each sorted by x. */
static int groups_make(const Plotter *p, const char *xkey, int m0, int nm, Group **out)
{
    const Plan *pl = p->pl;
    Group *g = NULL;
    int ng = 0;
    for (int r = 0; r < pl->npoints; r++) {
        if (!row_usable(p, r, m0, nm))
            continue;
        Buf label = {0};
        for (int k = 0; k < pl->nkeys; k++) {
            if (!strcmp(pl->keys[k], xkey) || !key_swept(pl, pl->keys[k]))
                continue;
            const char *v = plan_value(pl, r, pl->keys[k]);
            buf_printf(&label, "%s%s=%s", label.len ? ", " : "", pl->keys[k], v ? v : "(unset)");
        }
        int i = 0;
        while (i < ng && strcmp(g[i].label, buf_str(&label)))
            i++;
        if (i == ng) {
            g = xrealloc(g, (size_t)(ng + 1) * sizeof *g);
            g[ng].label = xstrdup(buf_str(&label));
            g[ng].rows = NULL;
            g[ng].n = 0;
            ng++;
        }
        buf_free(&label);
        g[i].rows = xrealloc(g[i].rows, (size_t)(g[i].n + 1) * sizeof *g[i].rows);
        double x, y;
        is_number(plan_value(pl, r, xkey), &x);
        int j = g[i].n++;
        while (j > 0 && is_number(plan_value(pl, g[i].rows[j - 1], xkey), &y) && y > x) {
            g[i].rows[j] = g[i].rows[j - 1];
            j--;
        }
        g[i].rows[j] = r;
    }
    *out = g;
    return ng;
}

/* Run gnuplot on base.gp in the plots folder; its messages go to gnuplot.log. */
static void gp_run(Plotter *p, const char *base)
{
    if (p->gnuplot_missing)
        return;
    char *script = xasprintf("%s.gp", base);
    char *logpath = xasprintf("%s/gnuplot.log", p->dir);
    int logfd = open(logpath, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (logfd < 0) {
        fprintf(stderr, "sfsim sweep: warning: %s: cannot create: %s; no plots\n", logpath, strerror(errno));
        p->gnuplot_missing = 1;
        goto out;
    }
    dprintf(logfd, "== gnuplot %s\n", script);
    pid_t pid = fork();
    if (pid == 0) {
        if (chdir(p->dir) != 0 || dup2(logfd, 1) < 0 || dup2(logfd, 2) < 0)
            _exit(126);
        execlp("gnuplot", "gnuplot", script, (char *)NULL);
        _exit(127);
    }
    close(logfd);
    int st = 0;
    if (pid < 0) {
        fprintf(stderr, "sfsim sweep: warning: cannot start gnuplot: %s; no plots\n", strerror(errno));
        p->gnuplot_missing = 1;
        goto out;
    }
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 127) {
        fprintf(stderr, "sfsim sweep: warning: gnuplot is not installed (Debian: gnuplot-nox); no plots, the CSV is "
                        "written\n");
        p->gnuplot_missing = 1;
    } else if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "sfsim sweep: warning: gnuplot failed on %s/%s (see %s)\n", p->dir, script, logpath);
        p->gnuplot_failed++;
    } else {
        p->made++;
    }
out:
    free(script);
    free(logpath);
}

/* Write base.gp and base.dat, then draw base.png. */
static void plot_write(Plotter *p, const char *base, const Buf *gp, const Buf *dat)
{
    char err[PATH_MAX + 256];
    char *gpath = xasprintf("%s/%s.gp", p->dir, base), *dpath = xasprintf("%s/%s.dat", p->dir, base);
    if (file_write_atomic(dpath, buf_str(dat), dat->len, err, sizeof err) ||
        file_write_atomic(gpath, buf_str(gp), gp->len, err, sizeof err))
        fprintf(stderr, "sfsim sweep: warning: %s\n", err);
    else
        gp_run(p, base);
    free(gpath);
    free(dpath);
}

/* End the script (closing a multiplot), write both files, draw, and free the buffers. */
static void plot_finish(Plotter *p, const char *base, Buf *gp, Buf *dat, int multiplot)
{
    if (multiplot)
        buf_puts(gp, "unset multiplot\n");
    plot_write(p, base, gp, dat);
    buf_free(gp);
    buf_free(dat);
}

static void gp_head(const Plotter *p, Buf *g, const char *base, int w, int h, const char *what, const char *against)
{
    buf_printf(g, "# Written by sfsim sweep / sfsim merge from the points of this sweep; the data is in %s.dat.\n"
                  "# Restyle and redraw: cd into this folder, then gnuplot %s.gp\n", base, base);
    buf_printf(g, "set terminal pngcairo size %d,%d noenhanced font \"sans,11\"\nset output \"%s.png\"\n", w, h, base);
    buf_puts(g, "set datafile missing \"NaN\"\nset grid\n");
    Buf t = {0};
    buf_printf(&t, "%s against %s", what, against);
    buf_puts(g, "set title ");
    gp_str(g, buf_str(&t));
    buf_printf(g, " . \"\\n\" . %s\n", p->subtitle);
    buf_free(&t);
}

/* Colours of stacked bars (matplotlib's tab10). */
static const char *const palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                      "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
#define N_PALETTE (int)(sizeof palette / sizeof palette[0])

static void gp_palette(Buf *g, int n)
{
    for (int i = 0; i < n; i++)
        buf_printf(g, "set linetype %d lc rgb \"%s\"\n", i + 1, palette[i % N_PALETTE]);
}

/* Series of a stacked plot: stall causes or operation categories. */
typedef struct Series {
    int m0, n;
    const char *const *names;
    const char *what, *ylabel, *base;
    int unit_range;
} Series;

static const Series stall_series = {M_STALL, TM_CAUSE_COUNT, tm_cause_keys, "stall cycles by cause",
                                    "share of all cycles", "stalls", 0};
static const Series ops_series = {M_OPS, ISA_C_COUNT, isa_category_keys, "operation mix",
                                  "share of executed instructions", "ops", 1};

/* fps (lines, with the confidence interval as error bars when every point has one), SIMD
 * utilization (three panels) or, for kd-tree runs, nodes visited per ray against a numeric key.
 * what: 0 fps, 1 utilization, 2 kd-tree nodes. */
static void plot_lines(Plotter *p, const char *xkey, int what)
{
    const int util = what == 1, kd = what == 2;
    int m0 = util ? M_UTIL : kd ? M_KD : M_FPS, nm = util ? 3 : 1;
    Group *g;
    int ng = groups_make(p, xkey, m0, nm, &g);
    if (!ng) {
        groups_free(g, ng);
        return;
    }
    int ci = !util && !kd;
    for (int i = 0; i < ng && ci; i++)
        for (int j = 0; j < g[i].n && ci; j++)
            ci = p->rows[g[i].rows[j]].has[M_FPS_LO] && p->rows[g[i].rows[j]].has[M_FPS_HI];
    char *base = xasprintf("%s_%s", util ? "utilization" : kd ? "kd_nodes" : "fps", xkey);
    Buf gp = {0}, dat = {0};
    for (int i = 0; i < ng; i++) {
        buf_printf(&dat, "%s# %s\n# %s %s\n", i ? "\n\n" : "", g[i].label[0] ? g[i].label : "all points", xkey,
                   util ? "utilization_traversal utilization_intersection utilization_shading"
                   : kd ? "kd_camera_nodes_per_ray kd_nodes_per_ray" : "fps fps_lo fps_hi");
        for (int j = 0; j < g[i].n; j++) {
            const Row *row = &p->rows[g[i].rows[j]];
            buf_printf(&dat, "%s", plan_value(p->pl, g[i].rows[j], xkey));
            if (util) {
                for (int s = 0; s < 3; s++)
                    dat_num(&dat, row, M_UTIL + s);
            } else if (kd) {
                dat_num(&dat, row, M_KD_CAMERA_NODES);
                dat_num(&dat, row, M_KD);
            } else {
                dat_num(&dat, row, M_FPS);
                dat_num(&dat, row, M_FPS_LO);
                dat_num(&dat, row, M_FPS_HI);
            }
            buf_puts(&dat, "\n");
        }
    }
    gp_head(p, &gp, base, util ? 1500 : 960, util ? 560 : 620,
            util ? "SIMD utilization per stage" : kd ? "kd-tree nodes visited per ray" : "frames per second", xkey);
    buf_puts(&gp, "set xlabel ");
    axis_label(&gp, xkey);
    buf_puts(&gp, "\n");
    int numeric, nv = key_values(p->pl, xkey, &numeric);
    double lo = INFINITY, hi = -INFINITY;
    for (int r = 0; r < p->pl->npoints; r++) {
        double x;
        if (is_number(plan_value(p->pl, r, xkey), &x))
            lo = fmin(lo, x), hi = fmax(hi, x);
    }
    if (lo > 0 && hi / lo >= 100)
        buf_puts(&gp, "set logscale x\n");
    if (nv <= 16) {
        buf_puts(&gp, "set xtics (");
        StrList seen = {0};
        for (int r = 0; r < p->pl->npoints; r++) {
            const char *v = plan_value(p->pl, r, xkey);
            int dup = 0;
            for (int i = 0; i < seen.n && !dup; i++)
                dup = !strcmp(seen.v[i], v);
            if (!dup) {
                buf_printf(&gp, "%s%s", seen.n ? ", " : "", v);
                sl_push(&seen, xstrdup(v));
            }
        }
        sl_free(&seen);
        buf_puts(&gp, ")\n");
    }
    buf_puts(&gp, "set offsets graph 0.03, graph 0.03, 0, 0\n");
    buf_puts(&gp, ng > 1 || kd ? "set key outside below center horizontal\n" : "unset key\n");
    if (util) {
        buf_puts(&gp, "set yrange [0:1]\nset ylabel \"SIMD utilization (active lanes / N)\"\n");
        buf_puts(&gp, "set multiplot layout 1,3 title ");
        Buf t = {0};
        buf_printf(&t, "SIMD utilization per stage against %s", xkey);
        gp_str(&gp, buf_str(&t));
        buf_free(&t);
        buf_printf(&gp, " . \"\\n\" . %s\nunset title\n", p->subtitle);
    } else if (kd) {
        buf_puts(&gp, "set yrange [0:*]\nset ylabel \"nodes visited per ray (inner nodes and leaves)\"\n");
    } else {
        buf_printf(&gp, "set yrange [0:*]\nset ylabel \"frames per second (at core.clock_mhz)%s\"\n",
                   ci ? "; bars: 95% confidence interval" : "");
    }
    for (int s = 0; s < (util ? 3 : 1); s++) {
        if (util)
            buf_printf(&gp, "set title \"%s\"\n", isa_stage_keys[util_stages[s]]);
        buf_puts(&gp, "plot ");
        for (int i = 0; i < ng && kd; i++)
            for (int c = 0; c < 2; c++) {
                Buf t = {0};
                buf_printf(&t, "%s%s%s", c ? "all rays" : "camera rays", g[i].label[0] ? ", " : "", g[i].label);
                buf_printf(&gp, "%s\"%s.dat\" index %d using 1:%d with linespoints lw 2 pt 7 ps 1.2 title ",
                           i || c ? ", \\\n     " : "", base, i, 2 + c);
                gp_str(&gp, buf_str(&t));
                buf_free(&t);
            }
        for (int i = 0; i < ng && !kd; i++) {
            buf_printf(&gp, "%s\"%s.dat\" index %d using 1:%d%s with %s lw 2 pt 7 ps 1.2 title ", i ? ", \\\n     " : "",
                       base, i, 2 + s, ci ? ":3:4" : "", ci ? "yerrorlines" : "linespoints");
            gp_str(&gp, g[i].label[0] ? g[i].label : (ci ? "fps, 95% confidence interval" : "all points"));
        }
        buf_puts(&gp, "\n");
    }
    plot_finish(p, base, &gp, &dat, util);
    free(base);
    groups_free(g, ng);
}

/* Stall shares or the operation mix as stacked bars against a numeric key, one panel per
 * combination of the other swept keys. */
static void plot_stacked(Plotter *p, const char *xkey, const Series *se)
{
    Group *g;
    int ng = groups_make(p, xkey, se->m0, se->n, &g);
    if (!ng) {
        groups_free(g, ng);
        return;
    }
    int cols = ng == 1 ? 1 : ng <= 4 ? 2 : 3, rws = (ng + cols - 1) / cols;
    char *base = xasprintf("%s_%s", se->base, xkey);
    Buf gp = {0}, dat = {0};
    for (int i = 0; i < ng; i++) {
        buf_printf(&dat, "%s# %s\n# %s", i ? "\n\n" : "", g[i].label[0] ? g[i].label : "all points", xkey);
        for (int c = 0; c < se->n; c++)
            buf_printf(&dat, " %s", se->names[c]);
        buf_puts(&dat, "\n");
        for (int j = 0; j < g[i].n; j++) {
            buf_printf(&dat, "\"%s\"", plan_value(p->pl, g[i].rows[j], xkey));
            for (int c = 0; c < se->n; c++)
                dat_num(&dat, &p->rows[g[i].rows[j]], se->m0 + c);
            buf_puts(&dat, "\n");
        }
    }
    gp_head(p, &gp, base, 820 * cols, 480 * rws + 60, se->what, xkey);
    buf_puts(&gp, "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.85 border -1\n"
                  "set boxwidth 0.7 relative\nset key outside right top\n");
    buf_printf(&gp, "set yrange [0:%s]\nset ylabel \"%s\"\nset xlabel ", se->unit_range ? "1" : "*", se->ylabel);
    axis_label(&gp, xkey);
    buf_puts(&gp, "\n");
    gp_palette(&gp, se->n);
    if (ng > 1) {
        buf_printf(&gp, "set multiplot layout %d,%d title ", rws, cols);
        Buf t = {0};
        buf_printf(&t, "%s against %s (a panel per combination of the other keys)", se->what, xkey);
        gp_str(&gp, buf_str(&t));
        buf_free(&t);
        buf_printf(&gp, " . \"\\n\" . %s\n", p->subtitle);
    }
    for (int i = 0; i < ng; i++) {
        if (ng > 1) {
            buf_puts(&gp, "set title ");
            gp_str(&gp, g[i].label);
            buf_puts(&gp, "\n");
        }
        buf_puts(&gp, "plot ");
        for (int c = 0; c < se->n; c++)
            buf_printf(&gp, "%s\"%s.dat\" index %d using %d%s title \"%s\"", c ? ", \\\n     " : "", base, i, c + 2,
                       c ? "" : ":xtic(1)", se->names[c]);
        buf_puts(&gp, "\n");
    }
    plot_finish(p, base, &gp, &dat, ng > 1);
    free(base);
    groups_free(g, ng);
}

/* Bar charts against the point (explicit points, or no numeric key swept). kind: 0 fps,
 * 1 utilization, 2 stalls, 3 ops. */
static void plot_bars(Plotter *p, int kind)
{
    const Plan *pl = p->pl;
    const Series *se = kind == 2 ? &stall_series : kind == 3 ? &ops_series : NULL;
    int m0 = se ? se->m0 : kind == 1 ? M_UTIL : kind == 4 ? M_KD : M_FPS, nm = se ? se->n : kind == 1 ? 3 : 1;
    static const char *const bases[] = {"fps_point", "utilization_point", "stalls_point", "ops_point", "kd_nodes_point"};
    static const char *const whats[] = {"frames per second", "SIMD utilization per stage", "stall cycles by cause",
                                        "operation mix", "kd-tree nodes visited per ray"};
    Buf gp = {0}, dat = {0};
    int n = 0, ci = kind == 0, longest = 0;
    for (int r = 0; r < pl->npoints; r++) {
        if (!row_usable(p, r, m0, nm))
            continue;
        Buf label = {0};
        if (pl->points[r].name)
            buf_puts(&label, pl->points[r].name);
        for (int k = 0; k < pl->nkeys && !pl->points[r].name; k++)
            if (key_swept(pl, pl->keys[k])) {
                const char *v = plan_value(pl, r, pl->keys[k]);
                buf_printf(&label, "%s%s=%s", label.len ? ", " : "", pl->keys[k], v ? v : "(unset)");
            }
        if (!label.len)
            buf_printf(&label, "%d", r);
        longest = (int)label.len > longest ? (int)label.len : longest;
        gp_str(&dat, buf_str(&label));
        buf_free(&label);
        if (kind == 0) {
            dat_num(&dat, &p->rows[r], M_FPS);
            dat_num(&dat, &p->rows[r], M_FPS_LO);
            dat_num(&dat, &p->rows[r], M_FPS_HI);
            ci = ci && p->rows[r].has[M_FPS_LO] && p->rows[r].has[M_FPS_HI];
        } else if (kind == 4) {
            dat_num(&dat, &p->rows[r], M_KD_CAMERA_NODES);
            dat_num(&dat, &p->rows[r], M_KD);
        } else {
            for (int m = m0; m < m0 + nm; m++)
                dat_num(&dat, &p->rows[r], m);
        }
        buf_puts(&dat, "\n");
        n++;
    }
    if (!n) {
        buf_free(&dat);
        return;
    }
    int w = 300 + 70 * n * (kind == 1 || kind == 4 ? 2 : 1);
    int wmin = kind == 0 ? 900 : 1100;
    gp_head(p, &gp, bases[kind], w < wmin ? wmin : w, 600 + 6 * (longest > 12 ? longest : 0), whats[kind], "the point");
    buf_puts(&gp, "set style fill solid 0.85 border -1\nset xlabel \"point\"\n");
    if (n > 6 || longest > 10)
        buf_puts(&gp, "set xtics rotate by 30 right\n");
    if (kind == 0) {
        buf_printf(&gp, "set boxwidth 0.6\nset xrange [-0.6:%g]\nset yrange [0:*]\n"
                        "set ylabel \"frames per second (at core.clock_mhz)\"\n", n - 0.4);
        buf_printf(&gp, "plot \"%s.dat\" using 0:2:xtic(1) with boxes lc rgb \"%s\" %s", bases[kind], palette[0],
                   ci ? "title \"fps\"" : "notitle");
        if (ci)
            buf_printf(&gp, ", \\\n     \"%s.dat\" using 0:2:3:4 with yerrorbars lc rgb \"black\" pt -1 "
                            "title \"95%% confidence interval\"", bases[kind]);
        buf_puts(&gp, "\n");
    } else if (kind == 4) {
        buf_puts(&gp, "set style data histograms\nset style histogram clustered gap 1\nset yrange [0:*]\n"
                      "set ylabel \"nodes visited per ray (inner nodes and leaves)\"\nset key outside right top\n");
        gp_palette(&gp, 2);
        buf_printf(&gp, "plot \"%s.dat\" using 2:xtic(1) title \"camera rays\", \\\n     \"%s.dat\" using 3 "
                        "title \"all rays\"\n", bases[kind], bases[kind]);
    } else if (kind == 1) {
        buf_puts(&gp, "set style data histograms\nset style histogram clustered gap 1\nset yrange [0:1]\n"
                      "set ylabel \"SIMD utilization (active lanes / N)\"\nset key outside right top\n");
        gp_palette(&gp, 3);
        for (int s = 0; s < 3; s++)
            buf_printf(&gp, "%s\"%s.dat\" using %d%s title \"%s\"", s ? ", \\\n     " : "plot ", bases[kind], s + 2,
                       s ? "" : ":xtic(1)", isa_stage_keys[util_stages[s]]);
        buf_puts(&gp, "\n");
    } else {
        buf_printf(&gp, "set style data histograms\nset style histogram rowstacked\nset boxwidth 0.7 relative\n"
                        "set yrange [0:%s]\nset ylabel \"%s\"\nset key outside right top\n",
                   se->unit_range ? "1" : "*", se->ylabel);
        gp_palette(&gp, se->n);
        for (int c = 0; c < se->n; c++)
            buf_printf(&gp, "%s\"%s.dat\" using %d%s title \"%s\"", c ? ", \\\n     " : "plot ", bases[kind], c + 2,
                       c ? "" : ":xtic(1)", se->names[c]);
        buf_puts(&gp, "\n");
    }
    plot_finish(p, bases[kind], &gp, &dat, 0);
}

/* "cornell/scene.ini": the scene's file and its folder. */
static const char *short_path(const char *path)
{
    const char *last = strrchr(path, '/');
    if (!last)
        return path;
    const char *prev = last;
    while (prev > path && prev[-1] != '/')
        prev--;
    return prev > path ? prev : last + 1;
}

/* The second title line(s): scene, mode, config and the keys every point shares. */
static char *plot_subtitle(const Plan *pl)
{
    Buf s = {0}, line = {0};
    StrList parts = {0};
    sl_push(&parts, xasprintf("scene %s", short_path(pl->scene)));
    sl_push(&parts, pl->sample ? xasprintf("%s mode (sample %s)", pl->mode, pl->sample) : xasprintf("%s mode", pl->mode));
    sl_push(&parts, xasprintf("config %s", pl->config ? short_path(pl->config) : "built-in"));
    for (int i = 0; i < pl->nsets; i++)
        sl_push(&parts, xstrdup(pl->sets[i]));
    for (int k = 0; k < pl->nkeys && !pl->explicit_points; k++)
        if (!key_swept(pl, pl->keys[k]))
            sl_push(&parts, xasprintf("%s=%s", pl->keys[k], plan_value(pl, 0, pl->keys[k])));
    /* Lines of at most ~110 characters. */
    for (int i = 0; i < parts.n; i++) {
        if (line.len && line.len + strlen(parts.v[i]) > 110) {
            if (s.len)
                buf_puts(&s, " . \"\\n\" . ");
            gp_str(&s, buf_str(&line));
            line.len = 0;
            line.s[0] = 0;
        }
        buf_printf(&line, "%s%s", line.len ? ", " : "", parts.v[i]);
    }
    if (s.len)
        buf_puts(&s, " . \"\\n\" . ");
    gp_str(&s, buf_str(&line));
    buf_free(&line);
    sl_free(&parts);
    return s.s;
}

/* Every plot of the sweep into DIR/plots; returns how many were drawn. */
static int plots_make(const Plan *pl, const Row *rows, const char *dir, int *failed)
{
    char err[PATH_MAX + 256];
    Plotter p = {0};
    p.pl = pl;
    p.rows = rows;
    char *pdir = xasprintf("%s/plots", dir);
    p.dir = pdir;
    *failed = 0;
    if (mkdir_p(pdir, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: warning: %s; no plots\n", err);
        free(pdir);
        return 0;
    }
    char *logpath = xasprintf("%s/gnuplot.log", pdir);
    unlink(logpath);
    free(logpath);
    p.subtitle = plot_subtitle(pl);
    int lines = 0;
    for (int k = 0; k < pl->nkeys && !pl->explicit_points; k++) {
        int numeric, nv = key_values(pl, pl->keys[k], &numeric);
        if (nv < 2 || !numeric)
            continue;
        lines++;
        plot_lines(&p, pl->keys[k], 0);
        plot_lines(&p, pl->keys[k], 1);
        plot_lines(&p, pl->keys[k], 2); /* only when some point ran on a kd-tree */
        plot_stacked(&p, pl->keys[k], &stall_series);
        plot_stacked(&p, pl->keys[k], &ops_series);
    }
    if (!lines)
        for (int kind = 0; kind < 5; kind++)
            plot_bars(&p, kind); /* (kd_nodes_point: only when some point ran on a kd-tree) */
    free(p.subtitle);
    free(pdir);
    *failed = p.gnuplot_failed || p.gnuplot_missing;
    return p.made;
}

/* sweep.csv and the plots; prints what was written. -1 when the CSV could not be written. */
static int outputs_write(const Plan *pl, const char *dir, const char *cmd, int *ndone, int *nfailed, int *nunfinished)
{
    char err[PATH_MAX + 256];
    Row *rows = rows_collect(pl, dir, ndone, nfailed, nunfinished);
    char *csv = xasprintf("%s/sweep.csv", dir);
    int rc = csv_write(pl, rows, csv, err, sizeof err);
    if (rc) {
        fprintf(stderr, "sfsim %s: %s\n", cmd, err);
    } else {
        int pfail;
        int made = plots_make(pl, rows, dir, &pfail);
        fprintf(stderr, "%s: wrote %s and %d plot%s in %s/plots\n", cmd, csv, made, made == 1 ? "" : "s", dir);
    }
    free(csv);
    rows_free(rows, pl->npoints);
    return rc;
}

/* ---- emitting Slurm and GNU parallel scripts ------------------------------------------------ */

/* `"sfsim" sweep <defining arguments> -o "DIR"`, paths absolute. */
static void task_command(Buf *b, const char *exe, const Plan *pl, const Args *a, const char *dir)
{
    buf_shell_word(b, exe, 1);
    buf_puts(b, " sweep");
    if (pl->config) {
        buf_puts(b, " -c ");
        buf_shell_word(b, pl->config, 1);
    }
    buf_puts(b, " --sweep ");
    buf_shell_word(b, pl->sweep, 1);
    buf_puts(b, " -s ");
    buf_shell_word(b, pl->scene, 1);
    buf_printf(b, " --mode %s", pl->mode);
    if (pl->sample) {
        buf_puts(b, " --sample ");
        buf_shell_word(b, pl->sample, 1);
    }
    for (int i = 0; i < pl->nsets; i++) {
        buf_puts(b, " --set ");
        buf_shell_word(b, pl->sets[i], 1);
    }
    buf_printf(b, " --threads-per-point %d%s -o ", a->threads, a->retry ? " --retry-failed" : "");
    buf_shell_word(b, dir, 1);
}

static int emit_scripts(const Plan *pl, const Args *a, const char *exe, const char *dir)
{
    char err[PATH_MAX + 256];
    Buf b = {0};
    int slurm = !strcmp(a->emit, "slurm");
    char *path = xasprintf("%s/sweep.%s", dir, slurm ? "slurm" : "parallel");
    if (slurm) {
        buf_printf(&b, "#!/bin/bash\n#SBATCH --job-name=sfsim-sweep\n#SBATCH --array=0-%d\n#SBATCH --cpus-per-task=%d\n",
                   pl->npoints - 1, a->threads);
        buf_puts(&b, "#SBATCH --output=");
        buf_shell_word(&b, dir, 0);
        buf_puts(&b, "/points/slurm-%A_%a.out\n");
        buf_printf(&b, "# Written by sfsim sweep --emit slurm: one array task per point of the sweep in %s.\n"
                       "# A task whose point is done already exits at once; after the tasks: sfsim merge %s\n",
                   dir, dir);
        task_command(&b, exe, pl, a, dir);
        buf_puts(&b, " --point \"$SLURM_ARRAY_TASK_ID\"\n");
    } else {
        for (int k = 0; k < pl->npoints; k++) {
            task_command(&b, exe, pl, a, dir);
            buf_printf(&b, " --point %d\n", k);
        }
    }
    int rc = file_write_atomic(path, b.s, b.len, err, sizeof err);
    buf_free(&b);
    if (rc) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        free(path);
        return EXIT_IO;
    }
    if (slurm)
        printf("sweep: wrote %s, a Slurm array job of %d tasks, one per point (the folder must be on storage the "
               "nodes share). Next:\n  sbatch %s\n  sfsim merge %s      # when the tasks have ended: sweep.csv and "
               "plots\n", path, pl->npoints, path, dir);
    else
        printf("sweep: wrote %s, %d commands, one per point. Next:\n  parallel -j %d < %s\n"
               "      (or parallel -S host1,host2 ... with %s on storage the hosts share)\n"
               "  sfsim merge %s      # then: sweep.csv and plots\n", path, pl->npoints, a->jobs, path, dir, dir);
    free(path);
    return EXIT_OK;
}

/* ---- the commands --------------------------------------------------------------------------- */

void sweep_usage(FILE *out)
{
    fprintf(out,
            "usage: sfsim sweep --sweep FILE -o DIR [-c CONFIG] [-s SCENE] [options]\n"
            "\n"
            "Runs SCENE once per point of the sweep FILE (lists and ranges of machine-config and render\n"
            "keys crossed, or explicit [point.NAME] sections: configs/sweeps/*.ini), each point an\n"
            "`sfsim run` of its own in DIR/points/NNN, several at once. Writes DIR/sweep.json (what\n"
            "defines the sweep), DIR/sweep.csv (a row per point) and DIR/plots/*.png. Started again\n"
            "with the same arguments it resumes: finished points are kept, unfinished ones run again.\n"
            "docs/sweep.md is the reference.\n"
            "\n"
            "options:\n"
            "  --sweep FILE             the sweep file (required)\n"
            "  -o, --out DIR            the sweep folder (required)\n"
            "  -c, --config FILE        machine config every point starts from (default: the built-in one)\n"
            "  -s, --scene FILE         scene (default: the shipped Cornell box, scenes/cornell/scene.ini in\n"
            "                           sfsim's data folder beside the binary: docs/install.md)\n"
            "  -j, --jobs N             points run at once (default: the number of cores)\n"
            "  --mode MODE              detailed (default), functional or sampled, for every run\n"
            "  --sample F               sampled mode: the fraction of tiles timed, for every run\n"
            "  --set SECTION.KEY=VALUE  applied to every point before its own keys (repeatable); also\n"
            "                           render.width, render.height, render.spp, render.max_depth, render.seed\n"
            "  --threads-per-point T    host threads of each run (default 1)\n"
            "  --retry-failed           run the points that failed before again\n"
            "  --emit slurm|parallel    write DIR/sweep.slurm (a Slurm array job) or DIR/sweep.parallel (a\n"
            "                           command per point for GNU parallel); run nothing\n"
            "  --point K                run point K alone (0-based), as those tasks do; no CSV\n"
            "\n"
            "exit: 0 every point done, 1 an input error (nothing is run), 2 usage, 4 an output could\n"
            "not be written or DIR is in use by another sweep or merge, 5 a point failed (the others\n"
            "still run), 128 + signal: 130/143 stopped by SIGINT/SIGTERM (run the same command again\n"
            "to resume)\n");
}

void merge_usage(FILE *out)
{
    fprintf(out,
            "usage: sfsim merge DIR\n"
            "\n"
            "Builds DIR/sweep.csv and DIR/plots/ from DIR/sweep.json and the point folders, after the\n"
            "points ran as Slurm or GNU parallel tasks (sfsim sweep --emit), and says how many points\n"
            "are done, failed and unfinished. Exit 0 when every point is done, 5 otherwise (the CSV is\n"
            "written all the same, with rows of status failed or unfinished); 1 when DIR holds no\n"
            "sweep; 4 when the CSV cannot be written, or while a sweep or its --point tasks run in DIR\n"
            "(merge refuses, naming the pid that holds DIR's lock). docs/sweep.md.\n");
}

static int parse_int_opt(const char *opt, const char *s, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi) {
        fprintf(stderr, "sfsim sweep: %s %s: expected an integer in %ld..%ld\n", opt, s, lo, hi);
        return -1;
    }
    *out = (int)v;
    return 0;
}

/* 0 ok, 1 --help printed, -1 usage error printed, -2 an option's value is bad (printed). */
static int args_parse(int argc, char **argv, Args *a)
{
    memset(a, 0, sizeof *a);
    a->scene = NULL; /* the shipped Cornell box in sfsim's data folder, below */
    a->mode = "detailed";
    a->threads = 1;
    a->point = -1;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    a->jobs = ncpu > 0 ? (int)ncpu : 1;
    for (int i = 0; i < argc; i++) {
        const char *o = argv[i];
        int has = i + 1 < argc;
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            sweep_usage(stdout);
            return 1;
        } else if ((!strcmp(o, "-c") || !strcmp(o, "--config")) && has) {
            a->config = argv[++i];
        } else if (!strcmp(o, "--sweep") && has) {
            a->sweep = argv[++i];
        } else if ((!strcmp(o, "-s") || !strcmp(o, "--scene")) && has) {
            a->scene = argv[++i];
        } else if ((!strcmp(o, "-o") || !strcmp(o, "--out")) && has) {
            a->out = argv[++i];
        } else if ((!strcmp(o, "-j") || !strcmp(o, "--jobs")) && has) {
            if (parse_int_opt(o, argv[++i], 1, 4096, &a->jobs))
                return -2;
        } else if (!strcmp(o, "--mode") && has) {
            a->mode = argv[++i];
        } else if (!strcmp(o, "--sample") && has) {
            a->sample = argv[++i];
        } else if (!strcmp(o, "--set") && has) {
            a->sets = xrealloc(a->sets, (size_t)(a->nsets + 1) * sizeof *a->sets);
            a->sets[a->nsets++] = argv[++i];
        } else if (!strcmp(o, "--threads-per-point") && has) {
            if (parse_int_opt(o, argv[++i], 1, 1024, &a->threads))
                return -2;
        } else if (!strcmp(o, "--retry-failed")) {
            a->retry = 1;
        } else if (!strcmp(o, "--emit") && has) {
            a->emit = argv[++i];
        } else if (!strcmp(o, "--point") && has) {
            if (parse_int_opt(o, argv[++i], 0, SW_MAX_POINTS - 1, &a->point))
                return -2;
        } else {
            fprintf(stderr, "sfsim sweep: unknown option or missing value: %s (sfsim help sweep)\n", o);
            return -1;
        }
    }
    if (!a->sweep || !a->out) {
        fprintf(stderr, "sfsim sweep: --sweep FILE and -o DIR are required (sfsim help sweep)\n");
        return -1;
    }
    if (strcmp(a->mode, "detailed") && strcmp(a->mode, "functional") && strcmp(a->mode, "sampled")) {
        fprintf(stderr, "sfsim sweep: --mode %s: expected detailed, functional or sampled\n", a->mode);
        return -2;
    }
    double f;
    if (a->sample && (!is_number(a->sample, &f) || !(f > 0 && f <= 1))) {
        fprintf(stderr, "sfsim sweep: --sample %s: expected a fraction in (0, 1]\n", a->sample);
        return -2;
    }
    if (a->emit && strcmp(a->emit, "slurm") && strcmp(a->emit, "parallel")) {
        fprintf(stderr, "sfsim sweep: --emit %s: expected slurm or parallel\n", a->emit);
        return -2;
    }
    if (a->emit && a->point >= 0) {
        fprintf(stderr, "sfsim sweep: --emit and --point do not go together\n");
        return -1;
    }
    if (!a->scene) {
        static char scene[4096];
        char err[8192];
        if (!datadir_path(DATADIR_DEFAULT_SCENE, scene, sizeof scene, err, sizeof err)) {
            fprintf(stderr, "sfsim sweep: no -s SCENE given and the default scene is missing: %s\n", err);
            return -2;
        }
        a->scene = scene;
    }
    return 0;
}

/* How to resume: the command as given. */
static void print_resume(int argc, char **argv)
{
    Buf b = {0};
    buf_puts(&b, "sfsim sweep");
    for (int i = 0; i < argc; i++) {
        buf_puts(&b, " ");
        buf_shell_word(&b, argv[i], 0);
    }
    fprintf(stderr, "sweep: to resume (finished points are kept), run the same command again:\n  %s\n", buf_str(&b));
    buf_free(&b);
}

static int signal_exit(int sig)
{
    return EXIT_SIGNAL + sig;
}

static const char *signal_name(int sig)
{
    return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : strsignal(sig);
}

/* The points still to run: unfinished ones, and failed ones with --retry-failed. */
static int *todo_list(const Plan *pl, const char *dir, int retry, Runner *r, int *ntodo)
{
    int *todo = xrealloc(NULL, (size_t)pl->npoints * sizeof *todo);
    *ntodo = 0;
    for (int k = 0; k < pl->npoints; k++) {
        double secs;
        int s = point_state(pl, dir, k, &secs, NULL);
        if (s == PS_DONE || (s == PS_FAILED && !retry)) {
            r->done += s == PS_DONE;
            r->failed += s == PS_FAILED;
            if (secs > 0) {
                r->secs_sum += secs;
                r->secs_n++;
            }
        } else {
            todo[(*ntodo)++] = k;
        }
    }
    return todo;
}

int sweep_main(int argc, char **argv)
{
    Args a;
    int prc = args_parse(argc, argv, &a);
    if (prc) {
        free(a.sets);
        return prc > 0 ? EXIT_OK : prc == -2 ? EXIT_INPUT : EXIT_USAGE;
    }
    int rc = EXIT_INPUT, lock_fd = -1;
    char *dir = NULL;
    int *todo = NULL;
    Runner r;
    memset(&r, 0, sizeof r);
    Plan pl;
    memset(&pl, 0, sizeof pl);
    char err[256];
    cJSON *m = manifest_build(&a);
    if (!m)
        goto out;
    if (plan_load(m, &pl, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: internal error: %s\n", err);
        goto out;
    }
    if (a.point >= pl.npoints) {
        fprintf(stderr, "sfsim sweep: --point %d: the sweep has points 0..%d\n", a.point, pl.npoints - 1);
        goto out;
    }
    if ((rc = sweep_dir_open(a.out, &pl, a.point < 0, &lock_fd, &dir)) != EXIT_OK)
        goto out;
    rc = EXIT_INPUT;
    ssize_t n = readlink("/proc/self/exe", r.exe, sizeof r.exe - 1);
    if (n <= 0) {
        fprintf(stderr, "sfsim sweep: cannot find this program (/proc/self/exe): %s\n", strerror(errno));
        goto out;
    }
    r.exe[n] = 0;
    if (a.emit) {
        rc = emit_scripts(&pl, &a, r.exe, dir);
        goto out;
    }
    r.pl = &pl;
    r.dir = dir;
    r.jobs = a.point >= 0 ? 1 : a.jobs;
    r.threads = a.threads;
    r.total = pl.npoints;
    if (a.point >= 0) {
        double secs;
        int s = point_state(&pl, dir, a.point, &secs, NULL);
        char *label = point_label(&pl, a.point);
        if (s == PS_DONE || (s == PS_FAILED && !a.retry)) {
            fprintf(stderr, "sweep: %s %s already%s\n", label, s == PS_DONE ? "is done" : "failed",
                    s == PS_DONE ? "" : " (--retry-failed runs it again)");
            rc = s == PS_DONE ? EXIT_OK : EXIT_POINTS;
            free(label);
            goto out;
        }
        todo = xrealloc(NULL, sizeof *todo);
        todo[0] = a.point;
        r.todo = todo;
        r.ntodo = 1;
        r.total = 1;
        int got = runner_run(&r);
        if (got > 0) {
            fprintf(stderr, "sweep: %s stopped by %s; it is unfinished\n", label, signal_name(got));
            rc = signal_exit(got);
        } else if (got == 0) {
            fprintf(stderr, "sweep: %s %s\n", label, r.done ? "done" : "failed");
            rc = r.done ? EXIT_OK : EXIT_POINTS;
        } else {
            rc = EXIT_IO; /* its folder or marker could not be written (said) */
        }
        free(label);
        goto out;
    }
    int ntodo;
    todo = todo_list(&pl, dir, a.retry, &r, &ntodo);
    r.todo = todo;
    r.ntodo = ntodo;
    r.progress = isatty(2);
    if (r.done + r.failed > 0)
        fprintf(stderr, "sweep: %s: %d of %d points finished before (%d done, %d failed); %d to run\n", a.out,
                r.done + r.failed, pl.npoints, r.done, r.failed, ntodo);
    int got = runner_run(&r);
    if (got != 0) {
        if (got > 0) {
            int left = pl.npoints - r.done - r.failed;
            fprintf(stderr, "sweep: stopped by %s: %d/%d done, %d failed, %d unfinished (the running points were "
                            "stopped and left unmarked); nothing finished is lost\n",
                    signal_name(got), r.done, pl.npoints, r.failed, left);
            print_resume(argc, argv);
            rc = signal_exit(got);
        } else {
            rc = EXIT_IO; /* a point folder or marker could not be written (said) */
        }
        goto out;
    }
    int nd, nf, nu;
    int csv_bad = outputs_write(&pl, dir, "sweep", &nd, &nf, &nu);
    char d[32];
    fmt_duration(now() - r.t0, d, sizeof d);
    fprintf(stderr, "sweep: %d/%d done, %d failed, %d unfinished (%d run now in %s, -j %d)\n", nd, pl.npoints, nf, nu,
            r.started, d, r.jobs);
    rc = csv_bad ? EXIT_IO : nd == pl.npoints ? EXIT_OK : EXIT_POINTS;
out:
    if (lock_fd >= 0)
        close(lock_fd);
    free(r.kids);
    free(todo);
    free(dir);
    free(a.sets);
    if (pl.json)
        plan_free(&pl);
    else
        cJSON_Delete(m);
    return rc;
}

int merge_main(int argc, char **argv)
{
    if (argc == 1 && (!strcmp(argv[0], "--help") || !strcmp(argv[0], "-h"))) {
        merge_usage(stdout);
        return EXIT_OK;
    }
    if (argc != 1 || argv[0][0] == '-') {
        merge_usage(stderr);
        return EXIT_USAGE;
    }
    const char *dir = argv[0];
    char err[PATH_MAX + 256];
    char *manifest = xasprintf("%s/sweep.json", dir);
    size_t len;
    char *text = file_read(manifest, &len, err, sizeof err);
    int rc = EXIT_INPUT, lock_fd = -1;
    Plan pl;
    memset(&pl, 0, sizeof pl);
    if (!text) {
        fprintf(stderr, "sfsim merge: %s (is %s a sweep folder?)\n", err, dir);
        goto out;
    }
    cJSON *json = cJSON_Parse(text);
    if (!json) {
        fprintf(stderr, "sfsim merge: %s: not JSON\n", manifest);
        goto out;
    }
    if (plan_load(json, &pl, err, sizeof err)) {
        fprintf(stderr, "sfsim merge: %s: %s\n", manifest, err);
        goto out;
    }
    /* Not under a running sweep or its tasks: they write the markers this reads and a whole
     * sweep writes sweep.csv itself at its end. */
    if ((rc = sweep_lock(dir, 1, "merge", &lock_fd)) != EXIT_OK)
        goto out;
    int nd, nf, nu;
    int csv_bad = outputs_write(&pl, dir, "merge", &nd, &nf, &nu);
    printf("merge: %s: %d points: %d done, %d failed, %d unfinished\n", dir, pl.npoints, nd, nf, nu);
    rc = csv_bad ? EXIT_IO : nd == pl.npoints ? EXIT_OK : EXIT_POINTS;
out:
    if (lock_fd >= 0)
        close(lock_fd);
    if (pl.json)
        plan_free(&pl);
    free(text);
    free(manifest);
    return rc;
}
