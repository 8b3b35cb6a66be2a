/* host/infile.c -- the check every input file passes, and reading one whole (host/infile.h).
 *
 * Why one module: each reader used to open its file its own way (fopen and fread to the end), and
 * four of them read /dev/zero until memory ran out. Every path that opens a user's file now comes
 * here first; a library that opens by name is handed the name only after infile_check.
 */
#include "infile.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind_of(mode_t m)
{
    return S_ISCHR(m) ? "a character device" : S_ISBLK(m) ? "a block device" : S_ISFIFO(m) ? "a FIFO"
         : S_ISSOCK(m) ? "a socket" : "not a file";
}

static void say_size(const char *path, uint64_t max_bytes, const char *what, char *err, size_t errlen)
{
    if (max_bytes >= (1u << 20) && max_bytes % (1u << 20) == 0)
        snprintf(err, errlen, "%s: larger than %llu MiB, the most %s may hold", path,
                 (unsigned long long)(max_bytes >> 20), what);
    else
        snprintf(err, errlen, "%s: larger than %llu bytes, the most %s may hold", path, (unsigned long long)max_bytes,
                 what);
}

/* The verdict on what st describes: 0, or -1 with the reason. */
static int judge(const char *path, const struct stat *st, uint64_t max_bytes, const char *what, char *err,
                 size_t errlen)
{
    if (S_ISDIR(st->st_mode)) {
        snprintf(err, errlen, "%s: is a directory, not a regular file", path);
        return -1;
    }
    if (!S_ISREG(st->st_mode)) {
        snprintf(err, errlen, "%s: not a regular file (%s)", path, kind_of(st->st_mode));
        return -1;
    }
    if (max_bytes && (uint64_t)st->st_size > max_bytes) {
        say_size(path, max_bytes, what, err, errlen);
        return -1;
    }
    return 0;
}

int infile_check(const char *path, uint64_t max_bytes, const char *what, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    return judge(path, &st, max_bytes, what, err, errlen);
}

int infile_open(const char *path, uint64_t max_bytes, const char *what, uint64_t *size, char *err, size_t errlen)
{
    /* O_NONBLOCK: opening a FIFO must not wait for a writer; fstat then refuses it. */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        snprintf(err, errlen, "%s: cannot read: %s", path, strerror(errno));
        close(fd);
        return -1;
    }
    if (judge(path, &st, max_bytes, what, err, errlen) != 0) {
        close(fd);
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl >= 0)
        (void)fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    if (size)
        *size = (uint64_t)st.st_size;
    return fd;
}

int infile_read(const char *path, uint64_t max_bytes, const char *what, char **text, size_t *len, char *err,
                size_t errlen)
{
    *text = NULL;
    *len = 0;
    uint64_t size;
    int fd = infile_open(path, max_bytes, what, &size, err, errlen);
    if (fd < 0)
        return -1;
    /* Read to the end, not st_size bytes: the file may grow, and /proc files say 0. One byte more
     * than the cap tells a file that grew past it. */
    size_t cap = size + 1 < 4096 ? 4096 : (size_t)size + 1, n = 0;
    char *buf = malloc(cap + 1);
    if (!buf)
        goto oom;
    for (;;) {
        if (n == cap) {
            if (max_bytes && n > max_bytes) {
                say_size(path, max_bytes, what, err, errlen);
                goto fail;
            }
            size_t more = cap > SIZE_MAX / 4 ? SIZE_MAX / 2 : 2 * cap;
            if (max_bytes && more > max_bytes + 1)
                more = (size_t)max_bytes + 1;
            char *b = more > cap ? realloc(buf, more + 1) : NULL;
            if (!b)
                goto oom;
            buf = b;
            cap = more;
        }
        ssize_t got = read(fd, buf + n, cap - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            snprintf(err, errlen, "%s: cannot read: %s", path, strerror(errno));
            goto fail;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    if (max_bytes && n > max_bytes) {
        say_size(path, max_bytes, what, err, errlen);
        goto fail;
    }
    close(fd);
    buf[n] = 0;
    *text = buf;
    *len = n;
    return 0;
oom:
    snprintf(err, errlen, "%s: out of memory", path);
fail:
    free(buf);
    close(fd);
    return -1;
}

size_t infile_bom(const void *text, size_t len)
{
    const unsigned char *p = text;
    return len >= 3 && p[0] == 0xEF && p[1] == 0xBB && p[2] == 0xBF ? 3 : 0;
}

const char *infile_reason(const char *err, const char *path)
{
    size_t n = strlen(path);
    if (!strncmp(err, path, n) && err[n] == ':' && err[n + 1] == ' ')
        err += n + 2;
    return !strncmp(err, "cannot open: ", 13) ? err + 13 : err;
}
