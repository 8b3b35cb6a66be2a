/* host/outfile.c -- output files written whole or not at all (host/outfile.h).
 *
 * Owns: temporary names, checked writes, the one close, the rename into place, the folders a run
 * creates, the checks before work, and the fault hook SFSIM_FAIL_WRITE. Must not: know file
 * formats, print, or exit.
 *
 * Why the temporary name: a file written in place and cut short by a full disk keeps its name and
 * looks complete (OpenImageIO's PNG writer does not even report the error); renamed only once it
 * is whole and synced, a file under its final name is always complete.
 */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>


enum { OUT_BUF = 1 << 16, OUT_PATH_MAX = 4096 };

/* ---- fault injection ------------------------------------------------------------------------ */

static atomic_long fault_ops, fault_at;
static pthread_once_t fault_once = PTHREAD_ONCE_INIT;
static atomic_int fault_overridden;
static void (*_Atomic op_hook)(long);

static void fault_init(void)
{
    const char *s = getenv("SFSIM_FAIL_WRITE");
    if (!s || atomic_load(&fault_overridden))
        return;
    /* A test hook: anything but a positive integer leaves it off. */
    char *end;
    errno = 0;
    long k = *s >= '0' && *s <= '9' ? strtol(s, &end, 10) : 0;
    atomic_store(&fault_at, k > 0 && !errno && !*end ? k : 0);
}

/* One operation that can fail on a full disk: -1 with errno = ENOSPC if it is the one to fail. */
static int fault_point(void)
{
    pthread_once(&fault_once, fault_init);
    long n = atomic_fetch_add(&fault_ops, 1) + 1;
    long at = atomic_load(&fault_at);
    void (*hook)(long) = atomic_load(&op_hook);
    if (hook)
        hook(n);
    if (at > 0 && n == at) {
        errno = ENOSPC;
        return -1;
    }
    return 0;
}

void outfile_fail_at(long k)
{
    pthread_once(&fault_once, fault_init);
    atomic_store(&fault_overridden, 1);
    atomic_store(&fault_at, k > 0 ? k : 0);
    atomic_store(&fault_ops, 0);
}

void outfile_set_hook(void (*hook)(long op))
{
    atomic_store(&op_hook, hook);
}

long outfile_ops(void)
{
    return atomic_load(&fault_ops);
}

/* ---- one file ------------------------------------------------------------------------------- */

static int fail(char *err, size_t errlen, const char *path, const char *what, int e)
{
    snprintf(err, errlen, "%s: %s: %s", path, what, strerror(e));
    return -1;
}

void outfile_process_init(void)
{
    signal(SIGXFSZ, SIG_IGN);
}

/* The name rename(2) must replace: a symbolic link is followed (as fopen would), so that the file
 * it points to is replaced and the link kept. */
static char *target_name(const char *path)
{
    struct stat st;
    if (lstat(path, &st) == 0 && S_ISLNK(st.st_mode)) {
        char *real = realpath(path, NULL);
        if (real)
            return real;
    }
    return strdup(path);
}

int outfile_open(OutFile *f, const char *path, char *err, size_t errlen)
{
    static atomic_uint seq;
    memset(f, 0, sizeof *f);
    f->fd = -1;
    if (strlen(path) >= OUT_PATH_MAX - 64) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    size_t pl = strlen(path);
    if (pl == 0 || path[pl - 1] == '/') {
        snprintf(err, errlen, "%s: a file name is needed, not a folder", path[0] ? path : "''");
        return -1;
    }
    f->path = strdup(path);
    f->buf = malloc(OUT_BUF);
    char *target = target_name(path);
    if (!f->path || !f->buf || !target) {
        free(target);
        outfile_discard(f);
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    struct stat st;
    if (stat(target, &st) == 0 && S_ISDIR(st.st_mode)) {
        free(target);
        outfile_discard(f);
        snprintf(err, errlen, "%s: is a folder", path);
        return -1;
    }
    if (stat(target, &st) == 0 && !S_ISREG(st.st_mode)) {
        /* A device or a FIFO (-o /dev/null, /dev/stdout): written as it is, nothing to rename. */
        free(target);
        if (fault_point() != 0 || (f->fd = open(path, O_WRONLY | O_CLOEXEC)) < 0) {
            int e = errno;
            outfile_discard(f);
            return fail(err, errlen, path, "cannot open", e);
        }
        return 0;
    }
    /* ".NAME.tmp-PID-N" beside the final name: the same file system, so rename(2) is atomic. */
    const char *slash = strrchr(target, '/');
    size_t dl = slash ? (size_t)(slash - target) + 1 : 0;
    size_t cap = strlen(target) + 64;
    f->tmp = malloc(cap);
    if (!f->tmp) {
        free(target);
        outfile_discard(f);
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    for (int tries = 0;; tries++) {
        snprintf(f->tmp, cap, "%.*s.%s.tmp-%ld-%u", (int)dl, target, target + dl, (long)getpid(),
                 atomic_fetch_add(&seq, 1));
        if (fault_point() == 0)
            f->fd = open(f->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (f->fd >= 0 || errno != EEXIST || tries >= 100)
            break;
    }
    if (f->fd >= 0) {
        f->target = target;
        return 0;
    }
    int e = errno;
    free(target);
    free(f->tmp);
    f->tmp = NULL; /* never created */
    outfile_discard(f);
    return fail(err, errlen, path, "cannot create", e);
}

/* write(2) all of data; each call is one operation. */
static int write_all(OutFile *f, const unsigned char *data, size_t n, char *err, size_t errlen)
{
    while (n > 0) {
        ssize_t w = fault_point() == 0 ? write(f->fd, data, n) : -1;
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            f->failed = 1;
            return fail(err, errlen, f->path, "cannot write", w < 0 ? errno : EIO);
        }
        data += w;
        n -= (size_t)w;
        f->written += (unsigned long long)w;
    }
    return 0;
}

static int flush(OutFile *f, char *err, size_t errlen)
{
    size_t n = f->len;
    f->len = 0;
    return write_all(f, f->buf, n, err, errlen);
}

int outfile_write(OutFile *f, const void *data, size_t n, char *err, size_t errlen)
{
    if (f->failed || f->fd < 0) {
        snprintf(err, errlen, "%s: write after a failure", f->path ? f->path : "?");
        return -1;
    }
    const unsigned char *p = data;
    if (f->len + n <= OUT_BUF) {
        memcpy(f->buf + f->len, p, n);
        f->len += n;
        return 0;
    }
    if (flush(f, err, errlen) != 0)
        return -1;
    if (n >= OUT_BUF)
        return write_all(f, p, n, err, errlen);
    memcpy(f->buf, p, n);
    f->len = n;
    return 0;
}

int outfile_printf(OutFile *f, char *err, size_t errlen, const char *fmt, ...)
{
    char small[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) {
        snprintf(err, errlen, "%s: cannot format output", f->path);
        return -1;
    }
    if ((size_t)n < sizeof small)
        return outfile_write(f, small, (size_t)n, err, errlen);
    char *big = malloc((size_t)n + 1);
    if (!big) {
        snprintf(err, errlen, "%s: out of memory", f->path);
        return -1;
    }
    va_start(ap, fmt);
    vsnprintf(big, (size_t)n + 1, fmt, ap);
    va_end(ap);
    int rc = outfile_write(f, big, (size_t)n, err, errlen);
    free(big);
    return rc;
}

static void forget(OutFile *f)
{
    free(f->path);
    free(f->target);
    free(f->tmp);
    free(f->buf);
    f->path = f->target = f->tmp = NULL;
    f->buf = NULL;
    f->len = 0;
}

void outfile_discard(OutFile *f)
{
    if (f->fd >= 0)
        close(f->fd);
    f->fd = -1;
    if (f->tmp)
        unlink(f->tmp);
    forget(f);
}

/* A staged file: its name as given, the name rename(2) replaces, its temporary name. */
typedef struct Staged {
    char *path, *target, *tmp;
} Staged;

struct OutSet {
    Staged *f;
    int n, cap;
};

static int set_add(OutSet *s, OutFile *f)
{
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 8;
        Staged *p = realloc(s->f, (size_t)cap * sizeof *p);
        if (!p)
            return -1;
        s->f = p;
        s->cap = cap;
    }
    s->f[s->n++] = (Staged){f->path, f->target, f->tmp};
    f->path = f->target = f->tmp = NULL; /* the set owns them now */
    return 0;
}

int outfile_close(OutFile *f, OutSet *set, char *err, size_t errlen)
{
    if (f->fd < 0 || f->failed) {
        snprintf(err, errlen, "%s: closed after a failure", f->path ? f->path : "?");
        outfile_discard(f);
        return -1;
    }
    if (flush(f, err, errlen) != 0)
        goto fail;
    if (f->tmp) {
        /* Synced before the rename: after a crash the final name holds the old file or the
         * whole new one, never an empty one. */
        if (fault_point() != 0 || fsync(f->fd) != 0) {
            fail(err, errlen, f->path, "cannot write (fsync)", errno);
            goto fail;
        }
        struct stat st;
        if (fstat(f->fd, &st) != 0 || (unsigned long long)st.st_size != f->written) {
            snprintf(err, errlen, "%s: cannot write: %llu bytes on disk, %llu written", f->path,
                     (unsigned long long)st.st_size, f->written);
            goto fail;
        }
    }
    /* Closed exactly once, whatever close returns (a second close could close another file). */
    int fd = f->fd;
    f->fd = -1;
    int injected = fault_point() != 0;
    int e = errno;
    if (close(fd) != 0 || injected) {
        fail(err, errlen, f->path, "cannot write (close)", injected ? e : errno);
        goto fail;
    }
    if (!f->tmp) {
        forget(f);
        return 0;
    }
    if (set) {
        if (set_add(set, f) != 0) {
            snprintf(err, errlen, "%s: out of memory", f->path);
            goto fail;
        }
        forget(f);
        return 0;
    }
    if (fault_point() != 0 || rename(f->tmp, f->target) != 0) {
        fail(err, errlen, f->path, "cannot write (rename into place)", errno);
        goto fail;
    }
    free(f->tmp);
    f->tmp = NULL;
    forget(f);
    return 0;
fail:
    outfile_discard(f);
    return -1;
}

int outfile_write_file(OutSet *set, const char *path, const void *data, size_t n, char *err, size_t errlen)
{
    OutFile f;
    if (outfile_open(&f, path, err, errlen) != 0)
        return -1;
    if (outfile_write(&f, data, n, err, errlen) != 0) {
        outfile_discard(&f);
        return -1;
    }
    return outfile_close(&f, set, err, errlen);
}

/* ---- sets ------------------------------------------------------------------------------------ */

OutSet *outset_new(void)
{
    return calloc(1, sizeof(OutSet));
}

int outset_count(const OutSet *s)
{
    return s ? s->n : 0;
}

/* A termination signal that arrives during the renames is held until they are done, so that ^C
 * cannot leave some files of a run beside older ones (SIGKILL aside). */
static volatile sig_atomic_t held_signal;
static void hold_signal(int sig)
{
    held_signal = sig;
}

static const int held_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
enum { NHELD = sizeof held_signals / sizeof held_signals[0] };

static int commit(OutSet *s, char *err, size_t errlen);

int outset_commit(OutSet *s, char *err, size_t errlen)
{
    struct sigaction sa, old[NHELD];
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = hold_signal;
    sigemptyset(&sa.sa_mask);
    held_signal = 0;
    for (int i = 0; i < NHELD; i++)
        sigaction(held_signals[i], &sa, &old[i]);
    int rc = commit(s, err, errlen);
    for (int i = 0; i < NHELD; i++)
        sigaction(held_signals[i], &old[i], NULL);
    if (held_signal)
        raise(held_signal); /* now with the disposition the program had */
    return rc;
}

static int commit(OutSet *s, char *err, size_t errlen)
{
    for (int i = 0; i < s->n; i++) {
        Staged *f = &s->f[i];
        if (fault_point() == 0 && rename(f->tmp, f->target) == 0) {
            free(f->tmp);
            f->tmp = NULL;
            continue;
        }
        int e = errno;
        /* No mix of this run's files and an older run's: the whole set goes. */
        for (int j = 0; j < s->n; j++) {
            if (s->f[j].tmp)
                unlink(s->f[j].tmp);
            unlink(s->f[j].target);
        }
        snprintf(err, errlen, "%s: cannot write (rename into place): %s; the files written with it were removed "
                 "too, so that none is left from a different run", f->path, strerror(e));
        return -1;
    }
    return 0;
}

void outset_free(OutSet *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->n; i++) {
        if (s->f[i].tmp)
            unlink(s->f[i].tmp);
        free(s->f[i].tmp);
        free(s->f[i].target);
        free(s->f[i].path);
    }
    free(s->f);
    free(s);
}

/* ---- folders --------------------------------------------------------------------------------- */

/* The deepest existing folder on the way to dir, in buf (dir's existing prefix); -1 with err
 * when a part of the path exists but is not a folder, or cannot be looked at. *whole = dir exists. */
static int existing_prefix(const char *dir, char *buf, size_t cap, int *whole, char *err, size_t errlen)
{
    char p[OUT_PATH_MAX];
    if (snprintf(p, sizeof p, "%s", dir) >= (int)sizeof p) {
        snprintf(err, errlen, "%s: path too long", dir);
        return -1;
    }
    snprintf(buf, cap, "%s", dir[0] == '/' ? "/" : ".");
    *whole = 0;
    size_t n = strlen(p);
    for (size_t i = 1; i <= n; i++) {
        if (p[i] != '/' && p[i] != 0)
            continue;
        if (p[i - 1] == '/')
            continue;
        char c = p[i];
        p[i] = 0;
        struct stat st;
        int r = stat(p, &st);
        int e = errno;
        if (r == 0 && !S_ISDIR(st.st_mode)) {
            if (c == 0)
                snprintf(err, errlen, "%s: exists and is not a folder", dir);
            else
                snprintf(err, errlen, "%s: %s exists and is not a folder", dir, p);
            return -1;
        }
        if (r != 0 && e == ENOENT)
            return 0;
        if (r != 0) {
            snprintf(err, errlen, "%s: cannot look at: %s", p, strerror(e));
            return -1;
        }
        snprintf(buf, cap, "%s", p);
        if (c == 0)
            *whole = 1;
        p[i] = c;
    }
    return 0;
}

int outfile_check_dir(const char *dir, char *err, size_t errlen)
{
    char have[OUT_PATH_MAX];
    int whole;
    if (!dir[0]) {
        snprintf(err, errlen, "'': an output folder name is needed");
        return -1;
    }
    if (existing_prefix(dir, have, sizeof have, &whole, err, errlen) != 0)
        return -1;
    if (access(have, W_OK | X_OK) != 0) {
        if (whole)
            snprintf(err, errlen, "%s: folder is not writable: %s", dir, strerror(errno));
        else
            snprintf(err, errlen, "%s: cannot create: %s is not writable: %s", dir, have, strerror(errno));
        return -1;
    }
    return 0;
}

int outfile_check_file(const char *path, char *err, size_t errlen)
{
    struct stat st;
    size_t n = strlen(path);
    if (n == 0 || path[n - 1] == '/' || (stat(path, &st) == 0 && S_ISDIR(st.st_mode))) {
        snprintf(err, errlen, "%s: is a folder; a file name is needed", n ? path : "''");
        return -1;
    }
    if (stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return access(path, W_OK) == 0 ? 0 : fail(err, errlen, path, "cannot write", errno);
    char dir[OUT_PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".") >= (int)sizeof dir) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    if (!dir[0])
        snprintf(dir, sizeof dir, "/");
    if (stat(dir, &st) != 0) {
        snprintf(err, errlen, "%s: cannot write into folder %s: %s", path, dir, strerror(errno));
        return -1;
    }
    if (!S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s: %s is not a folder", path, dir);
        return -1;
    }
    if (access(dir, W_OK | X_OK) != 0)
        return fail(err, errlen, path, "its folder is not writable", errno);
    return 0;
}

int outfile_make_dirs(const char *dir, OutDirs *d, char *err, size_t errlen)
{
    char p[OUT_PATH_MAX];
    if (snprintf(p, sizeof p, "%s", dir) >= (int)sizeof p) {
        snprintf(err, errlen, "%s: path too long", dir);
        return -1;
    }
    size_t n = strlen(p);
    for (size_t i = 1; i <= n; i++) {
        if ((p[i] != '/' && p[i] != 0) || p[i - 1] == '/')
            continue;
        char c = p[i];
        p[i] = 0;
        struct stat st;
        if (stat(p, &st) == 0) {
            if (!S_ISDIR(st.st_mode)) {
                snprintf(err, errlen, "%s: exists and is not a folder", p);
                return -1;
            }
        } else if (fault_point() != 0 || mkdir(p, 0777) != 0) {
            if (errno != EEXIST)
                return fail(err, errlen, p, "cannot create folder", errno);
        } else if (d->n < (int)(sizeof d->made / sizeof d->made[0])) {
            d->made[d->n] = strdup(p);
            if (d->made[d->n])
                d->n++;
        }
        p[i] = c;
    }
    return 0;
}

void outfile_remove_dirs(OutDirs *d)
{
    while (d->n > 0) {
        d->n--;
        rmdir(d->made[d->n]);
        free(d->made[d->n]);
    }
}

void outfile_keep_dirs(OutDirs *d)
{
    while (d->n > 0)
        free(d->made[--d->n]);
}
