/* sim/sweep/sweep_int.h -- what the files of `sfsim sweep` and `sfsim merge` share (private: only
 * the files of sim/sweep/ and the unit tests include it; sim/sweep/sweep.h is the public API).
 *
 * The files, one job each: common.c (out-of-memory policy, string lists, messages, small string
 * and folder helpers), sweepfile.c (reading and checking a sweep file, expanding its points),
 * plan.c (sweep.json: building it, taking it apart, comparing two, which points still run),
 * folder.c (the sweep folder, its lock, point folders and their markers), runner.c (running
 * points as child processes), csv.c (sweep.csv; its figure columns are the statistics registry's,
 * sim/stats.def, read back through stats_csv_*), plot.c (gnuplot), emit.c (Slurm / GNU parallel
 * scripts), sweep.c (the two commands).
 * Must not: simulate (a point is an `sfsim run`), or know what a machine key means (cfg_set
 * checks values). Like sim/main.c these are a command's parts: they print their messages, and
 * running out of memory ends the process (the x* helpers below, sweep_buf_text): nothing useful is
 * left to do then.
 */
#ifndef SFSIM_SWEEP_INT_H
#define SFSIM_SWEEP_INT_H

#include <cjson/cJSON.h>
#include <limits.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "../../isa/isa.h"
#include "../run/engine.h"
#include "../stats.h"
#include "../timing.h"
#include "../util.h"

/* The one limit: more points than this is an error that says so. */
#define SWEEP_MAX_POINTS 100000
/* The most points a sweep runs at once (-j). */
#define SWEEP_MAX_JOBS 4096
#define SWEEP_MANIFEST_FORMAT "sfsim sweep 1"
/* Lines of a failed point's log kept in its `failed` marker. */
#define SWEEP_TAIL_LINES 12

/* ---- common.c: memory, strings, messages --------------------------------------------------- */

/* Says "sfsim: out of memory" and aborts. */
__attribute__((noreturn)) void sweep_oom(void);

static inline void *xrealloc(void *p, size_t n)
{
    void *q = realloc(p, n ? n : 1);
    if (!q)
        sweep_oom();
    return q;
}

static inline char *xstrndup(const char *s, size_t n)
{
    char *d = xrealloc(NULL, n + 1);
    memcpy(d, s, n);
    d[n] = 0;
    return d;
}

static inline char *xstrdup(const char *s)
{
    return xstrndup(s, strlen(s));
}

__attribute__((format(printf, 1, 2))) static inline char *xasprintf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    char *s = NULL;
    int n = vasprintf(&s, fmt, ap);
    va_end(ap);
    if (n < 0)
        sweep_oom();
    return s;
}

/* A buffer's text; a buffer that ran out of memory ends the process (sweep_oom). */
const char *sweep_buf_text(const UtilBuf *b);

/* Messages for the user, one a line; all of them are printed before giving up. */
typedef struct SweepErrs {
    UtilBuf text;
    int count;
} SweepErrs;

__attribute__((format(printf, 2, 3))) void sweep_err_add(SweepErrs *e, const char *fmt, ...);

/* A growable list of malloc'ed strings (NULL items allowed). */
typedef struct SweepStrs {
    char **v;
    int n, cap;
} SweepStrs;

void sweep_strs_push(SweepStrs *l, char *s);
void sweep_strs_free(SweepStrs *l);

/* Blanks (and a line end) off both ends, in place. */
char *sweep_trim(char *s);
/* A number written in full ("12", "0.5", "1e3"); *is_int when it is a decimal integer. 0 / -1. */
int sweep_parse_number(const char *s, double *v, int *is_int, long long *iv);
/* 1 when s (may be NULL) is a number, in *v. */
int sweep_is_number(const char *s, double *v);
/* Two strings, either may be NULL, are the same. */
int sweep_str_eq(const char *a, const char *b);
int sweep_file_exists(const char *path);
/* Remove everything inside a folder, keeping the folder. 0, or -1 with the reason in err. */
int sweep_dir_clear(const char *path, char *err, size_t errlen);
/* Shell words: "..." with \ " $ ` escaped (for the scripts, always_quote), or bare when nothing
 * needs quoting (for messages). */
void sweep_shell_word(UtilBuf *b, const char *s, int always_quote);

/* ---- sweepfile.c: sweep files -------------------------------------------------------------- */

/* 0 when VALUE is a valid value of KEY (a render key `sfsim run --set` takes, or a machine key:
 * cfg_set on a scratch config); else -1 with the reason in msg, *unknown set when KEY is no key. */
int sweep_value_check(const char *key, const char *value, int *unknown, char *msg, size_t len);

/* The points of a sweep file (its text, read once; path names it in messages) as the manifest's
 * "points" array -- a cross product with the first key varying slowest, or the [point.NAME]
 * sections in order -- or NULL after adding every problem to errs. The number of points is known,
 * and refused beyond SWEEP_MAX_POINTS, before any value is made. */
cJSON *sweep_file_points(const char *path, const char *text, size_t len, SweepErrs *errs, int *explicit_points);

/* ---- plan.c: sweep.json -------------------------------------------------------------------- */

/* The defining arguments of `sfsim sweep` (sweep.c parses them). */
typedef struct SweepArgs {
    const char *config, *sweep, *scene, *out, *mode, *sample, *emit;
    const char **sets;
    int nsets;
    int jobs, threads, retry, point;
} SweepArgs;

typedef struct SweepPoint {
    const char *name; /* [point.NAME]; NULL in a cross product */
    int n;
    const char **key, **val;
} SweepPoint;

typedef struct SweepPlan {
    cJSON *json; /* the manifest; the strings below point into it */
    int explicit_points;
    const char *config, *config_text, *sweep, *sweep_text, *scene, *mode, *sample;
    const char **sets;
    int nsets;
    SweepPoint *points;
    int npoints;
    const char **keys; /* every key a point sets, in order of appearance: the CSV's key columns */
    int nkeys;
    int digits; /* of the point folders' names */
} SweepPlan;

/* Read and check everything the arguments name, and build the manifest; NULL after printing
 * every problem. */
cJSON *sweep_manifest_build(const SweepArgs *a);
/* Take the manifest (owned from here on) apart; -1 with err when it is not one. */
int sweep_plan_load(cJSON *json, SweepPlan *pl, char *err, size_t errlen);
void sweep_plan_free(SweepPlan *pl);
/* The value point p gives key, or NULL. */
const char *sweep_plan_value(const SweepPlan *pl, int p, const char *key);
/* What differs between the sweep in a folder (old) and the one the arguments define (cur), a
 * line each; nothing when they are the same sweep. */
void sweep_plan_diff(const SweepPlan *old, const SweepPlan *cur, UtilBuf *out);

/* What resuming in a folder finds: the points finished before, and the host seconds their markers
 * hold (for the progress line's estimate). */
typedef struct SweepTally {
    int done, failed;
    double secs_sum;
    int secs_n;
} SweepTally;

/* The progress line's estimate of the seconds left: nrunning points that ran elapsed[i] seconds
 * and queued points not started, on jobs slots, every point taking mean seconds. The runner's
 * schedule, simulated (the queued points go to the slot free first), so that with points of one
 * length the estimate falls by the time that passes, second for second. */
double sweep_eta(double mean, const double *elapsed, int nrunning, int queued, int jobs);

/* Resuming: the points of pl still to run in dir, in order, into todo (pl->npoints long):
 * unfinished ones, and failed ones when retry; the others are counted in *t. Returns how many. */
int sweep_plan_todo(const SweepPlan *pl, const char *dir, int retry, int *todo, SweepTally *t);

/* ---- folder.c: the sweep folder, point folders and markers --------------------------------- */

/* A point's state, from the markers in its folder. */
enum { SWEEP_UNFINISHED, SWEEP_DONE, SWEEP_FAILED };

/* The folder's lock, DIR/.sweep.lock (exclusive for a whole sweep and merge, shared for --point
 * tasks); cmd ("sweep", "merge") names the refusal. EXIT_OK with the lock in *fd, or an exit code
 * after saying why. */
int sweep_lock(const char *dir, int exclusive, const char *cmd, int *fd);
/* Open the sweep folder for the sweep in cur: create it and write sweep.json, or check the one
 * there is the same sweep; take its lock. EXIT_OK with *dir_abs its absolute path (malloc'ed)
 * and the lock held in *lock_fd, or an exit code after saying why. */
int sweep_dir_open(const char *dir, const SweepPlan *cur, int exclusive, int *lock_fd, char **dir_abs);
/* DIR/points/NNN (malloc'ed). */
char *sweep_point_dir(const SweepPlan *pl, const char *dir, int k);
/* "point 7" or "point 2 (small-buffer)" (malloc'ed). */
char *sweep_point_label(const SweepPlan *pl, int k);
/* The state of point k; *secs the host seconds its marker holds (0 when none). The `error` line
 * of a failed marker in *error when error is not NULL (malloc'ed). */
int sweep_point_state(const SweepPlan *pl, const char *dir, int k, double *secs, char **error);
/* The point's own settings as a [point.NAME] section, in pdir/point.ini; argv is its command. */
int sweep_point_ini_write(const SweepPlan *pl, const char *pdir, int k, char *const *argv, char *err, size_t errlen);
/* The last SWEEP_TAIL_LINES lines of a log (its last 64 KiB), malloc'ed. */
char *sweep_log_tail(const char *path);

/* ---- runner.c: running points -------------------------------------------------------------- */

typedef struct SweepChild {
    pid_t pid;
    int point;
    double t0;
} SweepChild;

typedef struct SweepRunner {
    const SweepPlan *pl;
    const char *dir; /* absolute */
    char exe[PATH_MAX];
    int jobs, threads, progress;
    const int *todo;
    int ntodo, next;
    SweepChild *kids;
    int nkids;
    int done, failed, total, started;
    double secs_sum;
    int secs_n;
    int shown; /* a progress line is on the terminal */
    int fatal;
    sigset_t child_mask;
    double t0;
} SweepRunner;

/* Run the points of r->todo, r->jobs at once. Returns 0, the signal that stopped it, or -1 when
 * a point folder or marker could not be written. */
int sweep_runner_run(SweepRunner *r);
/* "42s", "3m07s", "2h05m". */
void sweep_fmt_duration(double s, char *buf, size_t len);

/* ---- csv.c: sweep.csv ---------------------------------------------------------------------- */

/* A point's row: its state, a failed point's error, the figures it has. m[] and has[] hold one
 * entry per figure column, stats_csv_count() of them (the rows of sim/stats.def with a CSV name,
 * in the CSV's order; sweep_row_init allocates them). */
typedef struct SweepRow {
    int state;
    char *error;
    double *m;
    unsigned char *has;
} SweepRow;

/* An empty row (no error, no figures), its arrays allocated; sweep_row_clear frees them. */
void sweep_row_init(SweepRow *row);
void sweep_row_clear(SweepRow *row);
/* The index of the figure column called name, or -1 with an error naming it in err. */
int sweep_col(const char *name, char *err, size_t errlen);
/* The STATS_M_* bit of a manifest's mode ("detailed", "functional", "sampled"; NULL: detailed). */
unsigned sweep_stats_mode(const char *mode);
/* The figures of a point's report.json into row (those it holds; the others empty). -1 with err
 * ("PATH: missing", "PATH: not valid JSON at byte N of M", "PATH: key 'K' is not a number (a
 * string)", "PATH: key 'K' missing"; several keys joined by "; ") when it cannot be read, or,
 * when mode (STATS_M_*) is not 0, lacks or holds wrong a figure a run of that mode writes
 * (stats_csv_check; a figure the mode does not have may be absent or null). */
int sweep_row_read_report(SweepRow *row, const char *path, unsigned mode, char *err, size_t errlen);
/* Every point's state and figures. A done point whose report.json fails sweep_row_read_report
 * for the manifest's mode is failed (named on stderr, the reason in its error, the figures read
 * kept) and counted in *nfailed, not *ndone. */
SweepRow *sweep_rows_collect(const SweepPlan *pl, const char *dir, int *ndone, int *nfailed, int *nunfinished);
void sweep_rows_free(SweepRow *rows, int n);
/* sweep.csv into path. 0, or -1 with the reason in err. */
int sweep_csv_write(const SweepPlan *pl, const SweepRow *rows, const char *path, char *err, size_t errlen);
/* Integers as integers (cycles), the rest to 10 significant digits. */
void sweep_fmt_num(double v, char *buf, size_t len);

/* ---- plot.c, emit.c ------------------------------------------------------------------------ */

/* The figure columns the plots draw, found by name (sweep_col) once. The groups' columns follow
 * their first in the registry's order: utilization_traversal, _intersection, _shading; a
 * stall_share_<cause> per cause and an ops_share_<category> per category, in tm_cause_keys and
 * isa_category_keys order. */
typedef struct SweepPlotCols {
    int fps, fps_lo, fps_hi;
    int util;          /* utilization_traversal, then _intersection and _shading */
    int kd, kd_camera; /* kd_nodes_per_ray, kd_camera_nodes_per_ray */
    int stall, ops;    /* stall_share_<first cause>, ops_share_<first category> */
    int chip, chip_n;  /* load_imbalance, then memory_latency, l2_hit_rate, dram_gbs, dram_bandwidth_share */
    int energy;        /* energy_<level>_j, a column per level of sim/energy/energy.h, in order */
    int power, area;   /* power_w, area_chip_mm2 (the Pareto plots' x axes) */
} SweepPlotCols;
/* 0, or -1 with the column that is missing or out of its group's order in err. */
int sweep_plot_cols(SweepPlotCols *cols, char *err, size_t errlen);
/* Every plot of the sweep into DIR/plots, each PNG whole or not at all; returns how many were
 * drawn, and in *failed how many gnuplot could not draw whole (each said on stderr; a missing
 * gnuplot is a warning and counts none). */
int sweep_plots_make(const SweepPlan *pl, const SweepRow *rows, const char *dir, int *failed);
/* DIR/sweep.slurm or DIR/sweep.parallel (a->emit), and what to run next on stdout. EXIT_OK or
 * EXIT_IO (said). */
int sweep_emit_scripts(const SweepPlan *pl, const SweepArgs *a, const char *exe, const char *dir);

#endif
