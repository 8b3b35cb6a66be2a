/* sim/util.c -- the small shared helpers of sim/util.h: clock, integer parsing, mkdir -p, whole
 * files, a growable string buffer.
 *
 * Owns: these helpers. Must not: print, exit or abort (out of memory is a returned error, or a
 * buffer's `failed` flag), or know any sfsim format, key or command.
 */
#include "util.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../host/infile.h"

double util_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int util_parse_int(const char *s, long long lo, long long hi, long long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi)
        return -1;
    *out = v;
    return 0;
}

int util_mkdir_p(const char *path, char *err, size_t errlen)
{
    char *p = strdup(path);
    if (!p) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
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

char *util_file_read(const char *path, size_t *len, char *err, size_t errlen)
{
    char *text;
    if (infile_read(path, UTIL_FILE_MAX_BYTES, "a file sfsim reads back", &text, len, err, errlen) != 0)
        return NULL;
    return text;
}

/* ---- the string buffer ----------------------------------------------------------------------- */

int util_buf_add(UtilBuf *b, const char *s, size_t n)
{
    if (b->failed)
        return -1;
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 256;
        while (cap < b->len + n + 1)
            cap *= 2;
        char *t = realloc(b->s, cap);
        if (!t) {
            b->failed = 1;
            return -1;
        }
        b->s = t;
        b->cap = cap;
    }
    memcpy(b->s + b->len, s, n);
    b->len += n;
    b->s[b->len] = 0;
    return 0;
}

int util_buf_puts(UtilBuf *b, const char *s)
{
    return util_buf_add(b, s, strlen(s));
}

int util_buf_vprintf(UtilBuf *b, const char *fmt, va_list ap)
{
    if (b->failed)
        return -1;
    char *s = NULL;
    int n = vasprintf(&s, fmt, ap);
    if (n < 0) {
        b->failed = 1;
        return -1;
    }
    int rc = util_buf_add(b, s, (size_t)n);
    free(s);
    return rc;
}

int util_buf_printf(UtilBuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = util_buf_vprintf(b, fmt, ap);
    va_end(ap);
    return rc;
}

const char *util_buf_str(const UtilBuf *b)
{
    return b->s ? b->s : "";
}

void util_buf_free(UtilBuf *b)
{
    free(b->s);
    memset(b, 0, sizeof *b);
}
