/* sim/util.h -- small helpers every part of sfsim shares, written once: a monotonic clock, strict
 * integer parsing, mkdir -p, reading whole files (outputs are written by host/outfile.c), and a growable string buffer.
 *
 * Owns: these helpers and nothing else. Must not: print, exit or abort (each returns 0 / -1 or
 * NULL with a message in err, or records a failure the caller checks), or know about any sfsim
 * file format, config key or command.
 */
#ifndef SFSIM_UTIL_H
#define SFSIM_UTIL_H

#include <stdarg.h>
#include <stddef.h>

/* Seconds on the monotonic clock (for durations only: its zero is arbitrary). */
double util_now(void);

/* A decimal integer that is the whole of s (strtoll's leading blanks and sign allowed, nothing
 * after it), in lo..hi: 0 with *out set, or -1 (out unchanged) when s is not one. */
int util_parse_int(const char *s, long long lo, long long hi, long long *out);

/* mkdir -p: path and every missing folder above it (mode 0755). 0, or -1 with the reason in err
 * ("P: cannot create the folder: ...", "PATH: exists and is not a folder"). */
int util_mkdir_p(const char *path, char *err, size_t errlen);

/* The whole file, NUL-terminated (malloc'ed), its length in *len; NULL with the reason in err. A
 * regular file of at most UTIL_FILE_MAX_BYTES only (host/infile.h): the reports and records a
 * sweep reads back. */
#define UTIL_FILE_MAX_BYTES (256u << 20)
char *util_file_read(const char *path, size_t *len, char *err, size_t errlen);

/* A growable NUL-terminated string; {0} is empty. When memory runs out the buffer keeps what it
 * held, `failed` is set and every later append is dropped: check it once, before using the text. */
typedef struct UtilBuf {
    char *s;
    size_t len, cap;
    int failed;
} UtilBuf;

/* Appends; 0, or -1 when the buffer has failed (now or before). */
int util_buf_add(UtilBuf *b, const char *s, size_t n);
int util_buf_puts(UtilBuf *b, const char *s);
int util_buf_vprintf(UtilBuf *b, const char *fmt, va_list ap);
__attribute__((format(printf, 2, 3))) int util_buf_printf(UtilBuf *b, const char *fmt, ...);
/* The text so far ("" for an empty buffer). */
const char *util_buf_str(const UtilBuf *b);
/* Frees the text; the buffer is {0} again. */
void util_buf_free(UtilBuf *b);

#endif
