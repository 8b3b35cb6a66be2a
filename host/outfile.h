/* host/outfile.h -- output files written whole or not at all, and failures that name the file.
 *
 * Owns: how every output of `sfsim run` and `sfsim trace` reaches the disk: a temporary name in
 * the final file's folder (".NAME.tmp-PID-N"), every write(2) checked, fsync, one checked close,
 * then rename over the final name; the temporary is removed on any failure. A set of files
 * (OutSet) is renamed into place together after all of them were written, so a run that fails
 * half-way leaves no new file under a final name. Also the checks made before any work (the
 * output folder can be created or is a writable folder; the output file is not a folder), the
 * folders a run creates (removed again if it writes nothing), and the test-only fault hook.
 * Must not: know any file format (callers hand it bytes), print, or exit.
 *
 * Errors: -1 with "PATH: what failed: strerror" in err, PATH the final name the user asked for.
 *
 * Fault injection (a test hook, always compiled in, docs/report.md): every operation that can
 * fail on a full disk is one numbered operation: creating a folder, creating a temporary file,
 * each write(2), fsync, close and rename. With SFSIM_FAIL_WRITE=k in the environment (read once)
 * or after outfile_fail_at(k), operation k of the process fails with ENOSPC instead of running.
 */
#ifndef SFSIM_OUTFILE_H
#define SFSIM_OUTFILE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One file being written under its temporary name. Fields are private. */
typedef struct OutFile {
    int fd;                 /* -1 when closed */
    char *path;             /* the final name as given (messages name it) */
    char *target, *tmp;     /* what rename(2) replaces (a symbolic link resolved), the temporary
                             * name; tmp NULL when there is none (a device, or renamed) */
    unsigned char *buf;     /* write buffer */
    size_t len;             /* bytes in buf */
    unsigned long long written;
    int failed;             /* a write failed: only outfile_discard is allowed */
} OutFile;

/* Files written under temporary names, to be renamed into place together. */
typedef struct OutSet OutSet;

/* Create PATH's temporary file (PATH's folder must exist). */
/* Once, at the start of every program that writes files (sfsim, sfasm): SIGXFSZ ignored, so that a
 * write past a file-size limit (ulimit -f) fails with EFBIG, is reported naming the file, and its
 * temporary is removed, instead of the signal killing the process and leaving the temporary
 * behind. Programs it starts (gnuplot, the points of a sweep) inherit the setting. */
void outfile_process_init(void);

int outfile_open(OutFile *f, const char *path, char *err, size_t errlen);
/* Append bytes (buffered; the buffer is written when full). */
int outfile_write(OutFile *f, const void *data, size_t n, char *err, size_t errlen);
int outfile_printf(OutFile *f, char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Write the buffer, fsync, check the size on disk, close: the temporary file is complete. Then
 * set NULL: rename it over PATH now; set not NULL: hand it to the set (renamed by
 * outset_commit). On failure the temporary file is removed. f is finished either way. */
int outfile_close(OutFile *f, OutSet *set, char *err, size_t errlen);
/* Abandon f: close it and remove its temporary file. Harmless on a finished or zeroed OutFile. */
void outfile_discard(OutFile *f);

/* PATH whole from memory: open, write, close (into set, or into place when set is NULL). */
int outfile_write_file(OutSet *set, const char *path, const void *data, size_t n, char *err, size_t errlen);

OutSet *outset_new(void);
/* Rename every staged file into place, in the order they were closed. If a rename fails, every
 * file of the set is removed, those renamed already and the older files of the same names not yet
 * replaced, so that the folder holds no mix of two runs' files; err names the file. SIGINT,
 * SIGTERM, SIGHUP and SIGQUIT arriving meanwhile are held and raised again once it is done. */
int outset_commit(OutSet *s, char *err, size_t errlen);
/* Remove the temporary files not committed, and free. NULL is harmless. */
void outset_free(OutSet *s);
/* The number of files staged. */
int outset_count(const OutSet *s);

/* Before any work: DIR is a writable folder, or can be created (every existing part of the path
 * is a folder, the deepest one writable). */
int outfile_check_dir(const char *dir, char *err, size_t errlen);
/* Before any work: PATH can be written: not a folder, in a writable existing folder. */
int outfile_check_file(const char *path, char *err, size_t errlen);

/* The folders made by outfile_make_dirs, to remove them again when nothing was written. */
typedef struct OutDirs {
    char *made[32];         /* outermost first */
    int n;
} OutDirs;
/* mkdir -p DIR, recording the folders it created in d (zero it first). */
int outfile_make_dirs(const char *dir, OutDirs *d, char *err, size_t errlen);
/* Remove the folders d recorded, innermost first, if they are empty; forget them. */
void outfile_remove_dirs(OutDirs *d);
/* Forget the recorded folders (they hold outputs now). */
void outfile_keep_dirs(OutDirs *d);

/* Test hook: make operation k (1-based, counted from now) fail with ENOSPC; 0 turns it off.
 * Overrides SFSIM_FAIL_WRITE. */
void outfile_fail_at(long k);
/* Operations counted since the start or the last outfile_fail_at. */
long outfile_ops(void);
/* Test hook: call hook(n) before operation n runs (a signal sent there, say); NULL: none. */
void outfile_set_hook(void (*hook)(long op));

#ifdef __cplusplus
}
#endif

#endif
