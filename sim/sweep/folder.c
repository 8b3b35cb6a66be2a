/* sim/sweep/folder.c -- the sweep folder: sweep.json in it, its lock, and the point folders
 * points/NNN with their done / failed markers, point.ini and log.txt.
 *
 * Owns: the folder's layout and what makes a folder foreign, the lock (DIR/.sweep.lock: who may
 * run beside whom), reading a point's state from its markers, and the text of point.ini and of a
 * failed marker's log tail. Must not: decide which points run (plan.c), start processes
 * (runner.c), or read reports (csv.c).
 */
#include "../../host/outfile.h"
#include "sweep_int.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../exitcodes.h"

/* ---- the sweep folder and its lock ----------------------------------------------------------- */

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
int sweep_lock(const char *dir, int exclusive, const char *cmd, int *fd)
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
int sweep_dir_open(const char *dir, const SweepPlan *cur, int exclusive, int *lock_fd, char **dir_abs)
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
        if (!sweep_file_exists(manifest) && dir_foreign(dir)) {
            fprintf(stderr, "sfsim sweep: %s is not empty and holds no sweep.json: not a sweep folder "
                            "(choose another -o DIR)\n", dir);
            rc = EXIT_INPUT;
            goto out;
        }
    }
    if (util_mkdir_p(dir, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        goto out;
    }
    if ((rc = sweep_lock(dir, exclusive, "sweep", lock_fd)) != EXIT_OK)
        goto out;
    rc = EXIT_INPUT; /* a manifest that is not this sweep's is the arguments' fault */
    if (sweep_file_exists(manifest)) {
        size_t len;
        char *text = util_file_read(manifest, &len, err, sizeof err);
        if (!text) {
            fprintf(stderr, "sfsim sweep: %s\n", err);
            goto out;
        }
        cJSON *json = cJSON_Parse(text);
        free(text);
        SweepPlan old;
        if (!json || sweep_plan_load(json, &old, err, sizeof err)) {
            if (!json)
                snprintf(err, sizeof err, "not JSON");
            else
                sweep_plan_free(&old);
            fprintf(stderr, "sfsim sweep: %s: %s\n", manifest, err);
            goto out;
        }
        UtilBuf diff = {0};
        sweep_plan_diff(&old, cur, &diff);
        sweep_plan_free(&old);
        if (diff.len) {
            fprintf(stderr, "sfsim sweep: %s holds another sweep (%s); what differs:\n%s"
                            "To resume it, give the arguments it was made with; for a new sweep, choose another -o DIR.\n",
                    dir, manifest, sweep_buf_text(&diff));
            util_buf_free(&diff);
            goto out;
        }
    } else {
        char *text = cJSON_Print(cur->json);
        if (!text)
            sweep_oom();
        size_t len = strlen(text);
        text[len] = 0;
        UtilBuf b = {0};
        util_buf_printf(&b, "%s\n", text);
        cJSON_free(text);
        int w = outfile_write_file(NULL, manifest, sweep_buf_text(&b), b.len, err, sizeof err);
        util_buf_free(&b);
        if (w) {
            fprintf(stderr, "sfsim sweep: %s\n", err);
            rc = EXIT_IO;
            goto out;
        }
    }
    rc = EXIT_IO;
    if (util_mkdir_p(points, err, sizeof err)) {
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

char *sweep_point_dir(const SweepPlan *pl, const char *dir, int k)
{
    return xasprintf("%s/points/%0*d", dir, pl->digits, k);
}

char *sweep_point_label(const SweepPlan *pl, int k)
{
    return pl->points[k].name ? xasprintf("point %d (%s)", k, pl->points[k].name) : xasprintf("point %d", k);
}

/* The state of point k; *secs the host seconds its marker holds (0 when none). The `error`
 * line of a failed marker in *error when error is not NULL (malloc'ed). */
int sweep_point_state(const SweepPlan *pl, const char *dir, int k, double *secs, char **error)
{
    char *pdir = sweep_point_dir(pl, dir, k);
    char *done = xasprintf("%s/done", pdir), *failed = xasprintf("%s/failed", pdir);
    int state = sweep_file_exists(done) ? SWEEP_DONE : sweep_file_exists(failed) ? SWEEP_FAILED : SWEEP_UNFINISHED;
    *secs = 0;
    if (error)
        *error = NULL;
    if (state != SWEEP_UNFINISHED) {
        char err[PATH_MAX + 64];
        size_t len;
        char *text = util_file_read(state == SWEEP_DONE ? done : failed, &len, err, sizeof err);
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
        if (error && state == SWEEP_FAILED && !*error)
            *error = xstrdup("(no error line in the failed marker)");
    }
    free(done);
    free(failed);
    free(pdir);
    return state;
}

/* The point's own settings, as a [point.NAME] section of a sweep file: concatenated, the
 * point.ini files of a sweep make an explicit-point sweep file. */
int sweep_point_ini_write(const SweepPlan *pl, const char *pdir, int k, char *const *argv, char *err, size_t errlen)
{
    UtilBuf b = {0};
    util_buf_printf(&b, "; sfsim sweep: point %d of %d of the sweep %s\n", k, pl->npoints, pl->sweep);
    if (pl->nsets) {
        util_buf_puts(&b, "; every point also has:");
        for (int i = 0; i < pl->nsets; i++)
            util_buf_printf(&b, " --set %s", pl->sets[i]);
        util_buf_puts(&b, "\n");
    }
    util_buf_puts(&b, "; command:");
    for (int i = 0; argv[i]; i++) {
        util_buf_puts(&b, " ");
        sweep_shell_word(&b, argv[i], 0);
    }
    util_buf_puts(&b, "\n");
    if (pl->points[k].name)
        util_buf_printf(&b, "[point.%s]\n", pl->points[k].name);
    else
        util_buf_printf(&b, "[point.%0*d]\n", pl->digits, k);
    for (int i = 0; i < pl->points[k].n; i++)
        util_buf_printf(&b, "%s = %s\n", pl->points[k].key[i], pl->points[k].val[i]);
    char *path = xasprintf("%s/point.ini", pdir);
    int rc = outfile_write_file(NULL, path, sweep_buf_text(&b), b.len, err, errlen);
    free(path);
    util_buf_free(&b);
    return rc;
}

/* The last SWEEP_TAIL_LINES lines of a log (its last 64 KiB). */
char *sweep_log_tail(const char *path)
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
        if (buf[start - 1] == '\n' && ++lines == SWEEP_TAIL_LINES)
            break;
    return xstrdup(buf + start);
}
