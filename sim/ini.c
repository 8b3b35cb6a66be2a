/* sim/ini.c -- the one INI reader (sim/ini.h; the rules are docs/ini.md).
 *
 * Owns: the syntax of every INI file sfsim reads. inih (Debian's libinih) splits lines into
 * sections, keys and values; a reader callback sees each line first, from memory, to know line
 * numbers, to report every bad line (inih reports only the first one, and cuts long lines and long
 * section names silently), to strip inline comments and a UTF-8 BOM, and to decide what an
 * indented line is. The handler keeps each section and key once, with an index for lookups, so
 * that neither a repeated key nor a big file costs more than linear time. Must not: know keys.
 */
#include "ini.h"

#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <limits.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../host/infile.h"

/* ---- messages -------------------------------------------------------------------------------- */

static void add_message(IniFile *f, int line, char *text)
{
    f->nerrors++;
    if (!text) {
        f->oom = 1;
        return;
    }
    if (f->nmessages >= INIFILE_MAX_MESSAGES) {
        free(text);
        return;
    }
    if (!f->messages) {
        f->messages = malloc((INIFILE_MAX_MESSAGES + 1) * sizeof *f->messages);
        if (!f->messages) {
            f->oom = 1;
            free(text);
            return;
        }
    }
    f->messages[f->nmessages].line = line;
    f->messages[f->nmessages].text = text;
    f->nmessages++;
}

static void verror(IniFile *f, int line, const char *fmt, va_list ap)
{
    char *msg = NULL, *text = NULL;
    if (vasprintf(&msg, fmt, ap) < 0)
        msg = NULL;
    if (msg && (line > 0 ? asprintf(&text, "%s:%d: %s", f->name ? f->name : "?", line, msg)
                         : asprintf(&text, "%s: %s", f->name ? f->name : "?", msg)) < 0)
        text = NULL;
    free(msg);
    add_message(f, line, text);
}

void inifile_error(IniFile *f, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verror(f, line, fmt, ap);
    va_end(ap);
}

const IniMessage *inifile_messages(IniFile *f, int *n)
{
    if (!f->summarized) {
        f->summarized = 1;
        /* Stable, so that the messages of one line keep the order they were found in: an
         * insertion sort (at most INIFILE_MAX_MESSAGES, found nearly in line order). */
        for (int i = 1; i < f->nmessages; i++) {
            IniMessage x = f->messages[i];
            int j = i;
            for (; j > 0 && f->messages[j - 1].line > x.line; j--)
                f->messages[j] = f->messages[j - 1];
            f->messages[j] = x;
        }
        int hidden = f->nerrors - f->nmessages;
        if (hidden > 0 && f->messages) {
            char *text = NULL;
            if (asprintf(&text, "%s: ... and %d more error%s", f->name ? f->name : "?", hidden,
                         hidden == 1 ? "" : "s") >= 0) {
                f->messages[f->nmessages].line = INT_MAX;
                f->messages[f->nmessages].text = text;
                f->nmessages++; /* the array has room for this one */
            }
        }
    }
    *n = f->nmessages;
    return f->messages;
}

/* ---- the index: section names, and keys within a section ------------------------------------- */

typedef struct IniSlot {
    uint32_t hash;
    int sec; /* -1: a section name; else the section of a key */
    int idx; /* into sections or entries; -1 empty */
} IniSlot;

static uint32_t hash_of(int sec, const char *s)
{
    uint32_t h = 2166136261u ^ (uint32_t)(sec + 1);
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 16777619u;
    return h;
}

static const char *slot_name(const IniFile *f, const IniSlot *s)
{
    return s->sec < 0 ? f->sections[s->idx].name : f->entries[s->idx].key;
}

/* The slot of (sec, name): the one holding it, or the empty one where it would go. */
static IniSlot *slot_find(const IniFile *f, int sec, const char *name, uint32_t h)
{
    size_t mask = f->nslots - 1;
    for (size_t i = h & mask;; i = (i + 1) & mask) {
        IniSlot *s = &f->slots[i];
        if (s->idx < 0 || (s->hash == h && s->sec == sec && !strcmp(slot_name(f, s), name)))
            return s;
    }
}

static int slot_add(IniFile *f, int sec, const char *name, int idx)
{
    if (2 * (f->nused + 1) > f->nslots) {
        size_t n = f->nslots ? 2 * f->nslots : 64;
        IniSlot *old = f->slots, *s = malloc(n * sizeof *s);
        size_t oldn = f->nslots;
        if (!s)
            return -1;
        for (size_t i = 0; i < n; i++)
            s[i].idx = -1;
        f->slots = s;
        f->nslots = n;
        for (size_t i = 0; i < oldn; i++)
            if (old[i].idx >= 0)
                *slot_find(f, old[i].sec, slot_name(f, &old[i]), old[i].hash) = old[i];
        free(old);
    }
    uint32_t h = hash_of(sec, name);
    IniSlot *s = slot_find(f, sec, name, h);
    *s = (IniSlot){h, sec, idx};
    f->nused++;
    return 0;
}

static int lookup(const IniFile *f, int sec, const char *name)
{
    if (!f->nslots)
        return -1;
    IniSlot *s = slot_find(f, sec, name, hash_of(sec, name));
    return s->idx;
}

const IniSection *inifile_section(const IniFile *f, const char *name)
{
    int i = lookup(f, -1, name);
    return i < 0 ? NULL : &f->sections[i];
}

const IniEntry *inifile_get(const IniFile *f, const char *section, const char *key)
{
    int s = lookup(f, -1, section);
    int i = s < 0 ? -1 : lookup(f, s, key);
    return i < 0 ? NULL : &f->entries[i];
}

/* ---- reading lines ---------------------------------------------------------------------------- */

enum { LK_NONE, LK_KEY, LK_CONT };

typedef struct Rd {
    IniFile *f;
    const char *text;
    size_t len, pos;
    int line;
    int kind;  /* of the line handed to inih last */
    int sec;   /* the current section; -1 none yet; -2 a header that was reported: drop its keys */
    int entry; /* the key continuation lines extend; -1 none; -2 a key line that was reported */
} Rd;

/* inih's isspace(): what it strips around names and values and takes for indentation. */
static int blank(char c)
{
    return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r';
}

__attribute__((format(printf, 3, 4))) static void line_error(Rd *r, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verror(r->f, line, fmt, ap);
    va_end(ap);
    if (r->sec >= 0)
        r->f->sections[r->sec].nbad++;
}

static char *xstrndup(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = 0;
    }
    return d;
}

/* A [section] header, body[0..n) without blanks around it or a comment after it. */
static void header(Rd *r, const char *body, size_t n, char *str)
{
    IniFile *f = r->f;
    const char *close = memchr(body, ']', n);
    r->entry = -1;
    r->sec = -2; /* until the header proves good */
    if (!close || close != body + n - 1) {
        line_error(r, r->line, "syntax error: a section header is '[name]' alone on its line");
        return;
    }
    const char *a = body + 1, *b = close;
    while (a < b && blank(*a))
        a++;
    while (b > a && blank(b[-1]))
        b--;
    if (a == b) {
        line_error(r, r->line, "syntax error: empty section name");
        return;
    }
    if (b - a > INIFILE_MAX_SECTION) {
        line_error(r, r->line, "section name '%.20s...' longer than %d characters", a, INIFILE_MAX_SECTION);
        return;
    }
    char *name = xstrndup(a, (size_t)(b - a));
    if (!name) {
        f->oom = 1;
        return;
    }
    int prev = lookup(f, -1, name);
    if (prev >= 0 && f->opt.sections_repeat) {
        r->sec = prev; /* its keys join the section's first appearance */
        snprintf(str, INIFILE_MAX_SECTION + 4, "[%s]\n", name);
        free(name);
        return;
    }
    if (prev >= 0) {
        line_error(r, r->line, "section [%s] appears twice (first at line %d)", name, f->sections[prev].line);
        free(name);
        return;
    }
    IniSection *s = realloc(f->sections, (size_t)(f->nsections + 1) * sizeof *s);
    if (!s || (f->sections = s, slot_add(f, -1, name, f->nsections)) != 0) {
        free(name);
        f->oom = 1;
        return;
    }
    f->sections[f->nsections] = (IniSection){name, r->line, 0, 0};
    r->sec = f->nsections++;
    snprintf(str, INIFILE_MAX_SECTION + 4, "[%s]\n", name);
}

/* fgets for inih over the text in memory: one line per call. What inih gets is normalized (no
 * indentation on a key line, no inline comment, one blank before a continuation); a line that is
 * reported here reaches inih empty. */
static char *reader(char *str, int num, void *stream)
{
    Rd *r = stream;
    if (r->pos >= r->len)
        return NULL;
    const char *s = r->text + r->pos;
    size_t avail = r->len - r->pos;
    const char *nl = memchr(s, '\n', avail);
    size_t n = nl ? (size_t)(nl - s) : avail;
    r->pos += nl ? n + 1 : n;
    r->line++;
    r->kind = LK_NONE;
    strcpy(str, "\n");
    if (r->line == 1 && n >= 3 && !memcmp(s, "\xEF\xBB\xBF", 3)) {
        s += 3; /* a UTF-8 byte order mark, as Windows editors write */
        n -= 3;
    }
    if (n && s[n - 1] == '\r')
        n--;
    /* inih's buffer holds the line, its "\n" and a NUL. */
    size_t max = num - 2 < INIFILE_MAX_LINE ? (size_t)(num - 2) : INIFILE_MAX_LINE;
    if (n > max) {
        line_error(r, r->line, "line longer than %zu characters", max);
        r->entry = -2; /* it may have been a key: lines that continue it go with it */
        return str;
    }
    size_t indent = 0;
    while (indent < n && blank(s[indent]))
        indent++;
    const char *body = s + indent;
    size_t len = n - indent;
    for (size_t i = 0; i < len; i++) /* an inline comment: ; or # at the start or after a blank */
        if ((body[i] == ';' || body[i] == '#') && (i == 0 || blank(body[i - 1]))) {
            len = i;
            break;
        }
    while (len && blank(body[len - 1]))
        len--;
    if (!len)
        return str; /* blank, or a comment */
    if (body[0] == '[') {
        header(r, body, len, str);
        return str;
    }
    const char *eq = memchr(body, '=', len);
    if (!eq && indent) {
        /* An indented line without '=' continues the value of the key above it. */
        if (r->entry >= 0) {
            str[0] = ' ';
            memcpy(str + 1, body, len);
            memcpy(str + 1 + len, "\n", 2);
            r->kind = LK_CONT;
        } else if (r->entry == -1) {
            line_error(r, r->line, "syntax error: an indented line continues the value of a key, but no key comes "
                                   "before it");
        }
        return str;
    }
    r->entry = -2;
    if (!eq) {
        line_error(r, r->line, "syntax error: expected 'key = value' or '[section]', got '%.*s'",
                   (int)(len > 60 ? 60 : len), body);
        return str;
    }
    size_t kl = (size_t)(eq - body);
    while (kl && blank(body[kl - 1]))
        kl--;
    if (!kl) {
        line_error(r, r->line, "syntax error: no key before '='");
        return str;
    }
    if (memchr(body, ':', kl)) { /* inih would split "a: b = c" at the colon */
        line_error(r, r->line, "syntax error: ':' in key '%.*s' (a key and its value are separated by '=')",
                   (int)kl, body);
        return str;
    }
    if (r->sec == -1) {
        line_error(r, r->line, "key '%.*s': outside any section", (int)kl, body);
        return str;
    }
    if (r->sec == -2)
        return str; /* under a header that was reported */
    memcpy(str, body, len);
    memcpy(str + len, "\n", 2);
    r->kind = LK_KEY;
    return str;
}

static int repeatable(const IniFile *f, const char *section, const char *key)
{
    size_t sl = strlen(section);
    for (const char *const *p = f->opt.repeatable; p && *p; p++)
        if (!strncmp(*p, section, sl) && (*p)[sl] == '.' && !strcmp(*p + sl + 1, key))
            return 1;
    return 0;
}

static int handler(void *user, const char *section, const char *name, const char *value)
{
    (void)section; /* the reader follows the sections: it also sees those without keys */
    Rd *r = user;
    IniFile *f = r->f;
    if (r->kind == LK_CONT) {
        IniEntry *e = &f->entries[r->entry];
        size_t a = strlen(e->value), b = strlen(value);
        char *v = realloc((char *)e->value, a + b + 2);
        if (!v) {
            f->oom = 1;
            return 1;
        }
        v[a] = '\n';
        memcpy(v + a + 1, value, b + 1);
        e->value = v;
        return 1;
    }
    if (r->kind != LK_KEY)
        return 1; /* not reached: inih calls the handler only for lines the reader passed */
    const char *sec = f->sections[r->sec].name;
    int prev = lookup(f, r->sec, name);
    if (prev >= 0 && !repeatable(f, sec, name)) {
        if (f->opt.bare_keys)
            line_error(r, r->line, "key '%s': given twice (first at line %d)", name, f->entries[prev].line);
        else
            line_error(r, r->line, "key '%s.%s': given twice (first at line %d)", sec, name, f->entries[prev].line);
        r->entry = -2;
        return 1;
    }
    IniEntry *e = realloc(f->entries, (size_t)(f->nentries + 1) * sizeof *e);
    if (!e) {
        f->oom = 1;
        return 1;
    }
    f->entries = e;
    e = &f->entries[f->nentries];
    *e = (IniEntry){sec, strdup(name), strdup(value), r->line, r->sec};
    if (!e->key || !e->value || (prev < 0 && slot_add(f, r->sec, e->key, f->nentries) != 0)) {
        free((char *)e->key);
        free((char *)e->value);
        f->oom = 1;
        return 1;
    }
    f->sections[r->sec].nkeys++;
    r->entry = f->nentries++;
    return 1;
}

static void init(IniFile *f, const char *name, const IniOptions *opt)
{
    memset(f, 0, sizeof *f);
    f->name = strdup(name);
    if (!f->name)
        f->oom = 1;
    if (opt)
        f->opt = *opt;
}

int inifile_parse(IniFile *f, const char *name, const char *text, size_t len, const IniOptions *opt)
{
    init(f, name, opt);
    const char *nul = memchr(text, 0, len);
    if (nul) {
        int line = 1;
        for (const char *p = text; p < nul; p++)
            line += *p == '\n';
        inifile_error(f, line, "a NUL byte: not a text file");
        return f->nerrors;
    }
    Rd r = {f, text, len, 0, 0, LK_NONE, -1, -1};
    int rc = ini_parse_stream(reader, &r, handler, &r);
    if (rc > 0) {
        /* The reader passes only lines inih accepts: a safety net, for another inih build. */
        int said = 0;
        for (int i = 0; i < f->nmessages; i++)
            said |= f->messages[i].line == rc;
        if (!said)
            inifile_error(f, rc, "syntax error");
    } else if (rc < 0) {
        f->oom = 1;
    }
    if (f->oom)
        inifile_error(f, 0, "out of memory");
    return f->nerrors;
}

int inifile_read(const char *path, char **text, size_t *len, char *err, size_t errlen)
{
    return infile_read(path, INIFILE_MAX_BYTES, "an INI file", text, len, err, errlen);
}

int inifile_load(IniFile *f, const char *path, const IniOptions *opt)
{
    char *text, err[PATH_MAX + 128];
    size_t len;
    if (inifile_read(path, &text, &len, err, sizeof err) != 0) {
        init(f, path, opt);
        add_message(f, 0, strdup(err));
        return f->nerrors;
    }
    int n = inifile_parse(f, path, text, len, opt);
    free(text);
    return n;
}

int inifile_load_stream(IniFile *f, FILE *in, const char *name, const IniOptions *opt)
{
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + n, 1, cap - n, in);
        n += got;
        if (n > INIFILE_MAX_BYTES || got == 0)
            break;
        if (n == cap) {
            cap = cap * 2 > (size_t)INIFILE_MAX_BYTES + 1 ? (size_t)INIFILE_MAX_BYTES + 1 : cap * 2;
            char *b = realloc(buf, cap + 1);
            if (!b) {
                free(buf);
                buf = NULL;
            } else {
                buf = b;
            }
        }
    }
    if (!buf || ferror(in) || n > INIFILE_MAX_BYTES) {
        init(f, name, opt);
        if (!buf)
            inifile_error(f, 0, "out of memory");
        else if (n > INIFILE_MAX_BYTES)
            inifile_error(f, 0, "larger than %d MiB, the most an INI file may hold", INIFILE_MAX_BYTES >> 20);
        else
            inifile_error(f, 0, "cannot read: %s", strerror(errno));
        free(buf);
        return f->nerrors;
    }
    buf[n] = 0;
    int rc = inifile_parse(f, name, buf, n, opt);
    free(buf);
    return rc;
}

void inifile_free(IniFile *f)
{
    for (int i = 0; i < f->nsections; i++)
        free((char *)f->sections[i].name);
    for (int i = 0; i < f->nentries; i++) {
        free((char *)f->entries[i].key);
        free((char *)f->entries[i].value);
    }
    for (int i = 0; i < f->nmessages; i++)
        free(f->messages[i].text);
    free(f->sections);
    free(f->entries);
    free(f->messages);
    free(f->slots);
    free(f->name);
    memset(f, 0, sizeof *f);
}
