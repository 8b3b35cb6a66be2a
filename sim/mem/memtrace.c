/* sim/mem/memtrace.c -- reading and writing memory-access traces (memtrace.h).
 *
 * Owns: the line syntax of both formats and messages naming file and line. Must not: hold a whole
 * trace in memory (it streams, so a trace of 10^7 lines costs a buffer), know the DRAM, print, or
 * exit.
 */
#include "memtrace.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../host/infile.h"
#include "../../host/outfile.h"

enum { MTR_BUF = 1 << 16, MTR_LINE_MAX = 4096 };
#define MTR_MAX_FILE (1ULL << 42) /* 4 TiB: a trace is streamed, so only a sanity cap */

struct MtrReader {
    int fd;
    char *path;
    MtrFormat fmt;
    uint64_t clock_khz, last_cycle;
    long line;
    char buf[MTR_BUF];
    size_t pos, len;
    int eof;
    char text[MTR_LINE_MAX + 2];
};

/* The next line into r->text without its newline: 1, 0 at the end, -1 on a read error or a line
 * longer than MTR_LINE_MAX. */
static int read_line(MtrReader *r, char *err, size_t errlen)
{
    size_t n = 0;
    for (;;) {
        if (r->pos == r->len) {
            if (r->eof)
                break;
            ssize_t got = read(r->fd, r->buf, sizeof r->buf);
            if (got < 0) {
                if (errno == EINTR)
                    continue;
                snprintf(err, errlen, "%s:%ld: cannot read: %s", r->path, r->line + 1, strerror(errno));
                return -1;
            }
            if (got == 0) {
                r->eof = 1;
                break;
            }
            r->pos = 0;
            r->len = (size_t)got;
        }
        char c = r->buf[r->pos++];
        if (c == '\n') {
            r->line++;
            r->text[n] = 0;
            return 1;
        }
        if (n >= MTR_LINE_MAX) {
            snprintf(err, errlen, "%s:%ld: line longer than %d bytes (not a trace?)", r->path, r->line + 1,
                     MTR_LINE_MAX);
            return -1;
        }
        r->text[n++] = c;
    }
    if (!n)
        return 0;
    r->line++;
    r->text[n] = 0;
    return 1;
}

static int blank_or_comment(const char *s)
{
    while (*s == ' ' || *s == '\t' || *s == '\r')
        s++;
    return !*s || *s == '#';
}

/* Splits s into at most max whitespace-separated words; the count, or max + 1 when there are more. */
static int words(char *s, char **w, int max)
{
    int n = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s)
            return n;
        if (n == max)
            return max + 1;
        w[n++] = s;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r')
            s++;
        if (*s)
            *s++ = 0;
    }
}

static int parse_u64(const char *s, int base, uint64_t *out)
{
    if (!*s || *s == '-' || *s == '+')
        return -1;
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, base);
    if (*end || errno)
        return -1;
    *out = v;
    return 0;
}

static int parse_addr(const char *s, uint64_t *out)
{
    if (s[0] != '0' || (s[1] != 'x' && s[1] != 'X') || !s[2])
        return -1;
    for (const char *p = s + 2; *p; p++)
        if (!strchr("0123456789abcdefABCDEF", *p))
            return -1;
    if (strlen(s + 2) > 16)
        return -1;
    return parse_u64(s + 2, 16, out);
}

/* "clock_mhz=F" into kHz, exactly (at most 3 decimals). */
static int parse_clock(const char *s, uint64_t *khz)
{
    if (strncmp(s, "clock_mhz=", 10))
        return -1;
    s += 10;
    uint64_t ip = 0, frac = 0;
    int digits = 0, fd = 0;
    for (; *s >= '0' && *s <= '9'; s++, digits++)
        ip = ip * 10 + (uint64_t)(*s - '0');
    if (*s == '.') {
        for (s++; *s >= '0' && *s <= '9'; s++, fd++) {
            if (fd == 3)
                return -1;
            frac = frac * 10 + (uint64_t)(*s - '0');
        }
    }
    while (fd < 3) {
        frac *= 10;
        fd++;
    }
    if (*s || !digits || digits > 9)
        return -1;
    *khz = ip * 1000 + frac;
    return *khz ? 0 : -1;
}

static int header(MtrReader *r, char *line, char *err, size_t errlen)
{
    char *w[4];
    int n = words(line, w, 3);
    if (n != 3 || strcmp(w[0], "sfsim-memtrace") || strcmp(w[1], "1") || parse_clock(w[2], &r->clock_khz)) {
        snprintf(err, errlen,
                 "%s:%ld: expected the header 'sfsim-memtrace 1 clock_mhz=F' (version 1, F > 0 with at most 3 "
                 "decimals)",
                 r->path, r->line);
        return -1;
    }
    return 0;
}

MtrReader *mtr_open(const char *path, MtrFormat fmt, char *err, size_t errlen)
{
    uint64_t size;
    MtrReader *r = calloc(1, sizeof *r);
    if (!r) {
        snprintf(err, errlen, "%s: out of memory", path);
        return NULL;
    }
    r->fd = infile_open(path, MTR_MAX_FILE, "a trace", &size, err, errlen);
    r->path = strdup(path);
    if (r->fd < 0 || !r->path) {
        if (r->path == NULL && r->fd >= 0)
            snprintf(err, errlen, "%s: out of memory", path);
        mtr_close(r);
        return NULL;
    }
    /* The format: the first line that is not blank or a comment. */
    int rc;
    while ((rc = read_line(r, err, errlen)) == 1 && blank_or_comment(r->text))
        ;
    if (rc < 0) {
        mtr_close(r);
        return NULL;
    }
    int is_header = rc == 1 && !strncmp(r->text + strspn(r->text, " \t"), "sfsim-memtrace", 14);
    r->fmt = fmt == MTR_AUTO ? (is_header ? MTR_SFSIM : MTR_DRAMSIM3) : fmt;
    if (r->fmt == MTR_SFSIM) {
        if (rc == 0) {
            snprintf(err, errlen, "%s:1: empty: expected the header 'sfsim-memtrace 1 clock_mhz=F'", path);
            mtr_close(r);
            return NULL;
        }
        if (header(r, r->text, err, errlen)) {
            mtr_close(r);
            return NULL;
        }
        r->text[0] = 0;
    } else if (is_header) {
        snprintf(err, errlen, "%s:%ld: this is an sfsim trace (the header says so), not DRAMsim3's format", path,
                 r->line);
        mtr_close(r);
        return NULL;
    }
    /* A DRAMsim3 first line stays in r->text for mtr_next. */
    return r;
}

static int parse_dramsim3(MtrReader *r, MtrRecord *rec, char *err, size_t errlen)
{
    char *w[4];
    int n = words(r->text, w, 3);
    if (n != 3) {
        snprintf(err, errlen, "%s:%ld: expected '0xADDR READ|WRITE CYCLE' (DRAMsim3's trace), got %d field%s",
                 r->path, r->line, n > 3 ? 4 : n, n == 1 ? "" : "s");
        return -1;
    }
    if (parse_addr(w[0], &rec->addr)) {
        snprintf(err, errlen, "%s:%ld: bad address '%.40s': expected 0x and 1 to 16 hex digits", r->path, r->line,
                 w[0]);
        return -1;
    }
    if (!strcmp(w[1], "READ") || !strcmp(w[1], "R"))
        rec->write = 0;
    else if (!strcmp(w[1], "WRITE") || !strcmp(w[1], "W"))
        rec->write = 1;
    else {
        snprintf(err, errlen, "%s:%ld: bad operation '%.40s': expected READ or WRITE", r->path, r->line, w[1]);
        return -1;
    }
    if (parse_u64(w[2], 10, &rec->cycle)) {
        snprintf(err, errlen, "%s:%ld: bad cycle '%.40s': expected a decimal integer >= 0", r->path, r->line, w[2]);
        return -1;
    }
    rec->source[0] = 0;
    return 0;
}

static int parse_sfsim(MtrReader *r, MtrRecord *rec, char *err, size_t errlen)
{
    char *w[5];
    int n = words(r->text, w, 4);
    if (n < 3 || n > 4) {
        snprintf(err, errlen, "%s:%ld: expected 'CYCLE R|W 0xADDR [SOURCE]', got %d field%s", r->path, r->line,
                 n > 4 ? 5 : n, n == 1 ? "" : "s");
        return -1;
    }
    if (parse_u64(w[0], 10, &rec->cycle)) {
        snprintf(err, errlen, "%s:%ld: bad cycle '%.40s': expected a decimal integer >= 0", r->path, r->line, w[0]);
        return -1;
    }
    if (strcmp(w[1], "R") && strcmp(w[1], "W")) {
        snprintf(err, errlen, "%s:%ld: bad operation '%.40s': expected R or W", r->path, r->line, w[1]);
        return -1;
    }
    rec->write = w[1][0] == 'W';
    if (parse_addr(w[2], &rec->addr)) {
        snprintf(err, errlen, "%s:%ld: bad address '%.40s': expected 0x and 1 to 16 hex digits", r->path, r->line,
                 w[2]);
        return -1;
    }
    rec->source[0] = 0;
    if (n == 4) {
        if (strlen(w[3]) >= sizeof rec->source) {
            snprintf(err, errlen, "%s:%ld: source '%.40s...' is longer than 31 characters", r->path, r->line, w[3]);
            return -1;
        }
        snprintf(rec->source, sizeof rec->source, "%s", w[3]);
    }
    return 0;
}

int mtr_next(MtrReader *r, MtrRecord *rec, char *err, size_t errlen)
{
    for (;;) {
        if (!r->text[0] || blank_or_comment(r->text)) {
            int rc = read_line(r, err, errlen);
            if (rc <= 0)
                return rc;
            if (blank_or_comment(r->text)) {
                r->text[0] = 0;
                continue;
            }
        }
        int bad = r->fmt == MTR_SFSIM ? parse_sfsim(r, rec, err, errlen) : parse_dramsim3(r, rec, err, errlen);
        r->text[0] = 0;
        if (bad)
            return -1;
        rec->line = r->line;
        if (rec->cycle < r->last_cycle) {
            snprintf(err, errlen, "%s:%ld: cycle %llu is before the previous request's %llu (a trace is in time order)",
                     r->path, r->line, (unsigned long long)rec->cycle, (unsigned long long)r->last_cycle);
            return -1;
        }
        r->last_cycle = rec->cycle;
        return 1;
    }
}

MtrFormat mtr_format(const MtrReader *r)
{
    return r->fmt;
}

uint64_t mtr_clock_khz(const MtrReader *r)
{
    return r->fmt == MTR_SFSIM ? r->clock_khz : 0;
}

void mtr_close(MtrReader *r)
{
    if (!r)
        return;
    if (r->fd >= 0)
        close(r->fd);
    free(r->path);
    free(r);
}

/* ---- the writer --------------------------------------------------------------------------------- */

struct MtrWriter {
    OutFile f;
    uint64_t last;
};

MtrWriter *mtr_create(const char *path, double clock_mhz, char *err, size_t errlen)
{
    if (!(clock_mhz > 0) || clock_mhz > 1e9) {
        snprintf(err, errlen, "%s: clock %g MHz is not a positive clock", path, clock_mhz);
        return NULL;
    }
    MtrWriter *w = calloc(1, sizeof *w);
    if (!w) {
        snprintf(err, errlen, "%s: out of memory", path);
        return NULL;
    }
    w->f.fd = -1;
    /* The clock with 3 decimals, trailing zeros dropped: what the reader takes exactly. */
    char clk[64];
    snprintf(clk, sizeof clk, "%.3f", clock_mhz);
    char *e = clk + strlen(clk) - 1;
    while (*e == '0')
        *e-- = 0;
    if (*e == '.')
        *e = 0;
    if (outfile_open(&w->f, path, err, errlen) || outfile_printf(&w->f, err, errlen, "sfsim-memtrace 1 clock_mhz=%s\n", clk)) {
        mtr_discard(w);
        return NULL;
    }
    return w;
}

int mtr_write(MtrWriter *w, uint64_t cycle, int write, uint64_t addr, const char *source, char *err, size_t errlen)
{
    if (cycle < w->last) {
        snprintf(err, errlen, "%s: cycle %llu written after %llu (a trace is in time order)", w->f.path,
                 (unsigned long long)cycle, (unsigned long long)w->last);
        return -1;
    }
    if (source && (!*source || strlen(source) > 31 || strpbrk(source, " \t\r\n#"))) {
        snprintf(err, errlen, "%s: source '%.40s' is not one word of 1 to 31 characters", w->f.path, source);
        return -1;
    }
    w->last = cycle;
    return outfile_printf(&w->f, err, errlen, "%llu %c 0x%llx%s%s\n", (unsigned long long)cycle, write ? 'W' : 'R',
                          (unsigned long long)addr, source ? " " : "", source ? source : "");
}

int mtr_finish(MtrWriter *w, char *err, size_t errlen)
{
    int rc = outfile_close(&w->f, NULL, err, errlen);
    free(w);
    return rc;
}

void mtr_discard(MtrWriter *w)
{
    if (!w)
        return;
    outfile_discard(&w->f);
    free(w);
}
