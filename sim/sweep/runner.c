/* sim/sweep/runner.c -- running a sweep's points: each an `sfsim run` child process of this same
 * binary, several at once, with a progress line, and stopped cleanly on SIGINT / SIGTERM / SIGHUP.
 *
 * Owns: the child processes (their command line, process groups, log.txt), writing a finished
 * point's done / failed marker, the progress line and its time estimate, and the signal handling
 * while points run. Must not: decide which points run (plan.c gives the list), or read the
 * points' reports (csv.c).
 */
#include "../../host/outfile.h"
#include "sweep_int.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

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

static void progress_clear(SweepRunner *r)
{
    if (r->shown) {
        fputs("\r\033[K", stderr);
        r->shown = 0;
    }
}

void sweep_fmt_duration(double s, char *buf, size_t len)
{
    long t = (long)(s + 0.5);
    if (t < 60)
        snprintf(buf, len, "%lds", t);
    else if (t < 3600)
        snprintf(buf, len, "%ldm%02lds", t / 60, t % 60);
    else
        snprintf(buf, len, "%ldh%02ldm", t / 3600, t % 3600 / 60);
}

/* A min-heap of slot times, for sweep_eta. */
static void heap_down(double *h, int n, int i)
{
    for (;;) {
        int l = 2 * i + 1, m = i;
        if (l < n && h[l] < h[m])
            m = l;
        if (l + 1 < n && h[l + 1] < h[m])
            m = l + 1;
        if (m == i)
            return;
        double t = h[i];
        h[i] = h[m];
        h[m] = t;
        i = m;
    }
}

double sweep_eta(double mean, const double *elapsed, int nrunning, int queued, int jobs)
{
    if (jobs < 1 || !(mean > 0.0))
        return 0.0;
    if (jobs > SWEEP_MAX_JOBS)
        jobs = SWEEP_MAX_JOBS;
    /* Each of the jobs slots is free at a time from now: a running point's at the mean less what
     * it ran (0 once it ran longer), an idle slot's at once. The queued points, each of the mean
     * length, go to the slot free first (as the runner starts them); the last to end is the
     * estimate. Points are not divisible: near the end fewer slots work, and a fluid estimate
     * ((work left) / jobs) rose as the last points finished. */
    double h[SWEEP_MAX_JOBS];
    for (int i = 0; i < jobs; i++)
        h[i] = i < nrunning ? fmax(0.0, mean - elapsed[i]) : 0.0;
    for (int i = jobs / 2 - 1; i >= 0; i--)
        heap_down(h, jobs, i);
    for (int q = 0; q < queued; q++) {
        h[0] += mean;
        heap_down(h, jobs, 0);
    }
    double end = 0.0;
    for (int i = 0; i < jobs; i++)
        end = fmax(end, h[i]);
    return end;
}

static void progress_line(const SweepRunner *r, UtilBuf *b)
{
    util_buf_printf(b, "sweep: %d/%d done, %d running, %d failed", r->done, r->total, r->nkids, r->failed);
    int remaining = r->total - r->done - r->failed;
    if (remaining > 0 && r->secs_n > 0) {
        double mean = r->secs_sum / r->secs_n, t = util_now(), elapsed[SWEEP_MAX_JOBS];
        int n = r->nkids < SWEEP_MAX_JOBS ? r->nkids : SWEEP_MAX_JOBS;
        for (int i = 0; i < n; i++)
            elapsed[i] = t - r->kids[i].t0;
        char d[32];
        sweep_fmt_duration(sweep_eta(mean, elapsed, n, remaining - r->nkids, r->jobs), d, sizeof d);
        util_buf_printf(b, ", ~%s left", d);
    }
}

static void progress_show(SweepRunner *r)
{
    if (!r->progress)
        return;
    UtilBuf b = {0};
    progress_line(r, &b);
    fprintf(stderr, "\r\033[K%s", sweep_buf_text(&b));
    fflush(stderr);
    r->shown = 1;
    util_buf_free(&b);
}

/* The `sfsim run` command of point k, NULL-terminated (free with argv_free). */
static char **point_argv(const SweepRunner *r, int k, const char *pdir)
{
    const SweepPlan *pl = r->pl;
    SweepStrs a = {0};
    sweep_strs_push(&a, xstrdup(r->exe));
    sweep_strs_push(&a, xstrdup("run"));
    if (pl->config) {
        sweep_strs_push(&a, xstrdup("-c"));
        sweep_strs_push(&a, xstrdup(pl->config));
    }
    sweep_strs_push(&a, xstrdup("-s"));
    sweep_strs_push(&a, xstrdup(pl->scene));
    sweep_strs_push(&a, xstrdup("-o"));
    sweep_strs_push(&a, xstrdup(pdir));
    sweep_strs_push(&a, xstrdup("--mode"));
    sweep_strs_push(&a, xstrdup(pl->mode));
    if (pl->sample) {
        sweep_strs_push(&a, xstrdup("--sample"));
        sweep_strs_push(&a, xstrdup(pl->sample));
    }
    for (int i = 0; i < pl->nsets; i++) {
        sweep_strs_push(&a, xstrdup("--set"));
        sweep_strs_push(&a, xstrdup(pl->sets[i]));
    }
    for (int i = 0; i < pl->points[k].n; i++) {
        sweep_strs_push(&a, xstrdup("--set"));
        sweep_strs_push(&a, xasprintf("%s=%s", pl->points[k].key[i], pl->points[k].val[i]));
    }
    sweep_strs_push(&a, xstrdup("-j"));
    sweep_strs_push(&a, xasprintf("%d", r->threads));
    sweep_strs_push(&a, xstrdup("--no-progress"));
    sweep_strs_push(&a, NULL);
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
static int runner_start(SweepRunner *r, int k)
{
    char err[PATH_MAX + 256];
    char *pdir = sweep_point_dir(r->pl, r->dir, k);
    char *log = xasprintf("%s/log.txt", pdir);
    char **argv = point_argv(r, k, pdir);
    int rc = -1, logfd = -1, nullfd = -1;
    if (util_mkdir_p(pdir, err, sizeof err) || sweep_dir_clear(pdir, err, sizeof err) ||
        sweep_point_ini_write(r->pl, pdir, k, argv, err, sizeof err)) {
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
    r->kids[r->nkids++] = (SweepChild){pid, k, util_now()};
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
static int marker_write(SweepRunner *r, const char *pdir, const char *name, const UtilBuf *text)
{
    char err[PATH_MAX + 256];
    char *path = xasprintf("%s/%s", pdir, name);
    int rc = outfile_write_file(NULL, path, sweep_buf_text(text), text->len, err, sizeof err);
    if (rc) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        r->fatal = 1;
    }
    free(path);
    return rc;
}

/* A child ended: mark its point done or failed. */
static void runner_finish(SweepRunner *r, pid_t pid, int status)
{
    int i = 0;
    while (i < r->nkids && r->kids[i].pid != pid)
        i++;
    if (i == r->nkids)
        return;
    SweepChild c = r->kids[i];
    r->kids[i] = r->kids[--r->nkids];
    double secs = util_now() - c.t0;
    char *pdir = sweep_point_dir(r->pl, r->dir, c.point);
    char *report = xasprintf("%s/report.json", pdir);
    char *log = xasprintf("%s/log.txt", pdir);
    UtilBuf m = {0}, why = {0};
    int ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && sweep_file_exists(report);
    if (ok) {
        util_buf_printf(&m, "exit_status 0\nhost_seconds %.3f\n", secs);
        if (marker_write(r, pdir, "done", &m) == 0)
            r->done++;
    } else {
        char *tail = sweep_log_tail(log);
        const char *first = tail;
        while (*first == '\n')
            first++;
        size_t fl = strcspn(first, "\n");
        if (WIFEXITED(status)) {
            util_buf_printf(&m, "exit_status %d\n", WEXITSTATUS(status));
            if (WEXITSTATUS(status) == 0)
                util_buf_puts(&why, "exit 0 but no report.json");
            else if (fl)
                util_buf_printf(&why, "exit %d: %.*s", WEXITSTATUS(status), (int)fl, first);
            else
                util_buf_printf(&why, "exit %d, no output", WEXITSTATUS(status));
        } else {
            int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
            util_buf_printf(&m, "exit_status signal %d\n", sig);
            util_buf_printf(&why, "killed by signal %d (%s)", sig, strsignal(sig));
        }
        util_buf_printf(&m, "host_seconds %.3f\nerror %s\n--- the last lines of log.txt ---\n%s\n", secs,
                        sweep_buf_text(&why), tail);
        free(tail);
        if (marker_write(r, pdir, "failed", &m) == 0) {
            r->failed++;
            char *label = sweep_point_label(r->pl, c.point);
            progress_clear(r);
            fprintf(stderr, "sweep: %s failed, %s (%s)\n", label, sweep_buf_text(&why), log);
            free(label);
        }
    }
    r->secs_sum += secs;
    r->secs_n++;
    util_buf_free(&m);
    util_buf_free(&why);
    free(report);
    free(log);
    free(pdir);
}

/* Stop the running points: TERM to each point's process group, KILL after ten seconds. Their
 * folders stay unmarked (unfinished). */
static void runner_stop_all(SweepRunner *r)
{
    for (int i = 0; i < r->nkids; i++)
        if (kill(-r->kids[i].pid, SIGTERM) != 0)
            kill(r->kids[i].pid, SIGTERM);
    double deadline = util_now() + 10;
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
        if (util_now() > deadline) {
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
int sweep_runner_run(SweepRunner *r)
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

    r->t0 = util_now();
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
