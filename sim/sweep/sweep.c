/* sim/sweep/sweep.c -- the commands `sfsim sweep` and `sfsim merge` (sweep.h; docs/sweep.md is
 * the user's reference): their usage, arguments and exit codes, and the order of the steps the
 * other files of sim/sweep/ take.
 *
 * Owns: parsing the arguments, the sequence (manifest, folder, resume, run, CSV and plots),
 * what is printed at the end and how to resume, and the EXIT_* code. Must not: hold any step's
 * work itself (sweepfile.c, plan.c, folder.c, runner.c, csv.c, plot.c, emit.c), or simulate
 * (each point is an `sfsim run`).
 */
#include "sweep.h"

#include <errno.h>
#include <unistd.h>

#include "../cli/opts.h"
#include "../datadir.h"
#include "../exitcodes.h"
#include "../run/run.h"
#include "sweep_int.h"

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
            "  --sample F               sampled mode: the fraction of (tile, pass) units timed, for every run\n"
            "                           (default: as many as a +-1%% interval of the cycles needs)\n"
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
            "to resume)\n"
            "\n"
            "examples:\n"
            "  sfsim sweep --sweep configs/sweeps/width.ini -o width -j2\n"
            "  sfsim sweep --sweep configs/sweeps/width.ini -o width --mode sampled --set=render.spp=4\n"
            "  sfsim sweep --sweep configs/sweeps/kdtree.ini -o kd --emit slurm && sbatch kd/sweep.slurm\n");
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
            "(merge refuses, naming the pid that holds DIR's lock). docs/sweep.md.\n"
            "\n"
            "examples:\n"
            "  sfsim sweep --sweep configs/sweeps/width.ini -o width --emit parallel\n"
            "  parallel < width/sweep.parallel; sfsim merge width\n");
}

enum { W_SWEEP = CLI_LONG, W_MODE, W_SAMPLE, W_SET, W_TPP, W_RETRY, W_EMIT, W_POINT };
static const struct option sweep_longs[] = {
    {"config", required_argument, NULL, 'c'},  {"sweep", required_argument, NULL, W_SWEEP},
    {"scene", required_argument, NULL, 's'},   {"out", required_argument, NULL, 'o'},
    {"jobs", required_argument, NULL, 'j'},    {"mode", required_argument, NULL, W_MODE},
    {"sample", required_argument, NULL, W_SAMPLE}, {"set", required_argument, NULL, W_SET},
    {"threads-per-point", required_argument, NULL, W_TPP}, {"retry-failed", no_argument, NULL, W_RETRY},
    {"emit", required_argument, NULL, W_EMIT}, {"point", required_argument, NULL, W_POINT},
    {"help", no_argument, NULL, CLI_HELP},     {"version", no_argument, NULL, CLI_VERSION},
    {NULL, 0, NULL, 0}};

/* One option into a: 0, -1 usage error (said), -2 a bad value (said). */
static int args_option(const CliParse *p, SweepArgs *a, int code, const char *v)
{
    long long n;
    switch (code) {
    case 'c': a->config = v; break;
    case W_SWEEP: a->sweep = v; break;
    case 's': a->scene = v; break;
    case 'o': a->out = v; break;
    case 'j':
        if (cli_int(p, "-j", v, 1, SWEEP_MAX_JOBS, &n))
            return -2;
        a->jobs = (int)n;
        break;
    case W_MODE: a->mode = v; break;
    case W_SAMPLE: a->sample = v; break;
    case W_SET:
        a->sets = xrealloc(a->sets, (size_t)(a->nsets + 1) * sizeof *a->sets);
        a->sets[a->nsets++] = v;
        break;
    case W_TPP:
        if (cli_int(p, "--threads-per-point", v, 1, 1024, &n))
            return -2;
        a->threads = (int)n;
        break;
    case W_RETRY: a->retry = 1; break;
    case W_EMIT: a->emit = v; break;
    case W_POINT:
        if (cli_int(p, "--point", v, 0, SWEEP_MAX_POINTS - 1, &n))
            return -2;
        a->point = (int)n;
        break;
    default: return -1;
    }
    return 0;
}

/* 0 ok, 1 --help or --version printed, -1 usage error printed, -2 an option's value is bad (printed). */
static int args_parse(int argc, char **argv, SweepArgs *a)
{
    memset(a, 0, sizeof *a);
    a->scene = NULL; /* the shipped Cornell box in sfsim's data folder, below */
    a->mode = "detailed";
    a->threads = 1;
    a->point = -1;
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    a->jobs = ncpu > 0 ? (int)ncpu : 1;
    CliParse p = {"sfsim sweep", "sweep", sweep_longs, "c:s:o:j:h", argc, argv, 0};
    int code, rc;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, sweep_usage))
            return 1;
        if ((rc = args_option(&p, a, code, v)) != 0)
            return rc;
    }
    if (code < 0)
        return -1;
    if (cli_first_operand() < argc) {
        fprintf(stderr, "sfsim sweep: unexpected argument '%s' (sfsim help sweep)\n", argv[cli_first_operand()]);
        return -1;
    }
    if (!a->sweep || !a->out) {
        fprintf(stderr, "sfsim sweep: --sweep FILE and -o DIR are required (sfsim help sweep)\n");
        return -1;
    }
    RunMode mode;
    if (run_mode_parse(a->mode, &mode) != 0 || mode == RUN_REFERENCE) {
        fprintf(stderr, "sfsim sweep: --mode %s: expected detailed, functional or sampled\n", a->mode);
        return -2;
    }
    double f;
    if (a->sample && (!sweep_is_number(a->sample, &f) || !(f > 0 && f <= 1))) {
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

/* sweep.csv and the plots; prints what was written. -1 when the CSV or a plot could not be written
 * (a missing gnuplot is only a warning: the CSV holds every figure). */
static int outputs_write(const SweepPlan *pl, const char *dir, const char *cmd, int *ndone, int *nfailed,
                         int *nunfinished)
{
    char err[PATH_MAX + 256];
    SweepRow *rows = sweep_rows_collect(pl, dir, ndone, nfailed, nunfinished);
    char *csv = xasprintf("%s/sweep.csv", dir);
    int rc = sweep_csv_write(pl, rows, csv, err, sizeof err);
    if (rc) {
        fprintf(stderr, "sfsim %s: %s\n", cmd, err);
    } else {
        int pfail;
        int made = sweep_plots_make(pl, rows, dir, &pfail);
        fprintf(stderr, "%s: wrote %s and %d plot%s in %s/plots", cmd, csv, made, made == 1 ? "" : "s", dir);
        if (pfail)
            fprintf(stderr, "; %d plot%s could not be drawn", pfail, pfail == 1 ? "" : "s");
        fprintf(stderr, "\n");
        rc = pfail ? -1 : 0;
    }
    free(csv);
    sweep_rows_free(rows, pl->npoints);
    return rc;
}

/* How to resume: the command as given. */
static void print_resume(int argc, char **argv)
{
    UtilBuf b = {0};
    util_buf_puts(&b, "sfsim sweep");
    for (int i = 1; i < argc; i++) { /* argv[0] is "sweep" */
        util_buf_puts(&b, " ");
        sweep_shell_word(&b, argv[i], 0);
    }
    fprintf(stderr, "sweep: to resume (finished points are kept), run the same command again:\n  %s\n", sweep_buf_text(&b));
    util_buf_free(&b);
}

static int signal_exit(int sig)
{
    return EXIT_SIGNAL + sig;
}

static const char *signal_name(int sig)
{
    return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : strsignal(sig);
}

int sweep_main(int argc, char **argv)
{
    SweepArgs a;
    int prc = args_parse(argc, argv, &a);
    if (prc) {
        free(a.sets);
        return prc > 0 ? EXIT_OK : prc == -2 ? EXIT_INPUT : EXIT_USAGE;
    }
    int rc = EXIT_INPUT, lock_fd = -1;
    char *dir = NULL;
    int *todo = NULL;
    SweepRunner r;
    memset(&r, 0, sizeof r);
    SweepPlan pl;
    memset(&pl, 0, sizeof pl);
    char err[256];
    cJSON *m = sweep_manifest_build(&a);
    if (!m)
        goto out;
    if (sweep_plan_load(m, &pl, err, sizeof err)) {
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
        rc = sweep_emit_scripts(&pl, &a, r.exe, dir);
        goto out;
    }
    r.pl = &pl;
    r.dir = dir;
    r.jobs = a.point >= 0 ? 1 : a.jobs;
    r.threads = a.threads;
    r.total = pl.npoints;
    if (a.point >= 0) {
        double secs;
        int s = sweep_point_state(&pl, dir, a.point, &secs, NULL);
        char *label = sweep_point_label(&pl, a.point);
        if (s == SWEEP_DONE || (s == SWEEP_FAILED && !a.retry)) {
            fprintf(stderr, "sweep: %s %s already%s\n", label, s == SWEEP_DONE ? "is done" : "failed",
                    s == SWEEP_DONE ? "" : " (--retry-failed runs it again)");
            rc = s == SWEEP_DONE ? EXIT_OK : EXIT_POINTS;
            free(label);
            goto out;
        }
        todo = xrealloc(NULL, sizeof *todo);
        todo[0] = a.point;
        r.todo = todo;
        r.ntodo = 1;
        r.total = 1;
        int got = sweep_runner_run(&r);
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
    SweepTally before = {0};
    todo = xrealloc(NULL, (size_t)pl.npoints * sizeof *todo);
    int ntodo = sweep_plan_todo(&pl, dir, a.retry, todo, &before);
    r.done = before.done;
    r.failed = before.failed;
    r.secs_sum = before.secs_sum;
    r.secs_n = before.secs_n;
    r.todo = todo;
    r.ntodo = ntodo;
    r.progress = isatty(2);
    if (r.done + r.failed > 0)
        fprintf(stderr, "sweep: %s: %d of %d points finished before (%d done, %d failed); %d to run\n", a.out,
                r.done + r.failed, pl.npoints, r.done, r.failed, ntodo);
    int got = sweep_runner_run(&r);
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
    sweep_fmt_duration(util_now() - r.t0, d, sizeof d);
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
        sweep_plan_free(&pl);
    else
        cJSON_Delete(m);
    return rc;
}

static const struct option merge_longs[] = {
    {"help", no_argument, NULL, CLI_HELP}, {"version", no_argument, NULL, CLI_VERSION}, {NULL, 0, NULL, 0}};

int merge_main(int argc, char **argv)
{
    CliParse p = {"sfsim merge", "merge", merge_longs, "h", argc, argv, 0};
    int code;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0)
        if (cli_common(&p, code, merge_usage))
            return EXIT_OK;
    if (code < 0)
        return EXIT_USAGE;
    if (argc - cli_first_operand() != 1) {
        fprintf(stderr, "sfsim merge: expected one sweep folder, DIR (sfsim help merge)\n");
        return EXIT_USAGE;
    }
    argv += cli_first_operand();
    const char *dir = argv[0];
    char err[PATH_MAX + 256];
    char *manifest = xasprintf("%s/sweep.json", dir);
    size_t len;
    char *text = util_file_read(manifest, &len, err, sizeof err);
    int rc = EXIT_INPUT, lock_fd = -1;
    SweepPlan pl;
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
    if (sweep_plan_load(json, &pl, err, sizeof err)) {
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
        sweep_plan_free(&pl);
    free(text);
    free(manifest);
    return rc;
}
