/* bench/speed_vs_error.c -- what sampled and functional modes save in host time, and what they
 * cost in accuracy, against the full detailed run, measured in one run.
 *
 * For each of three scenes (the Cornell box, sponza, the conference room) at 512 x 512, 1 spp,
 * M = 1024 (256 tiles of 32 x 32) on the default machine: one detailed run (the truth), one
 * functional run, and sampled runs at 1, 2, 5, 10, 25 and 100 % of the tiles (seed 1). Per run:
 * host seconds, speed-up over the detailed run, the error of the predicted fps and of the timed
 * utilization (largest over traversal / intersection / shading), and for sampled mode whether the
 * 95 % interval covered the detailed run's fps, and the interval's coverage over seeds 1..100
 * (estimated from the detailed run's per-tile cycles: a sampled tile's cycles equal its cycles in
 * the detailed run, tests/unit/test_sampling.c). Functional mode has no timing: its fps is the
 * no-stall rate (one cycle per instruction) and its utilization the per-instruction one, which
 * is what a user of functional mode would read off.
 *
 * usage: speed_vs_error [OUTDIR]   (default out/bench): writes OUTDIR/speed_vs_error.{md,dat,gp,png}
 * Not a test: numbers depend on the host. docs/validation.md quotes a run.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../sim/config.h"
#include "../sim/run/run.h"
#include "../sim/sampling.h"
#include "../sim/stats.h"
#include "bench_scenes.h"

static const double rates[] = {0.01, 0.02, 0.05, 0.10, 0.25, 1.00};
#define NRATES (sizeof rates / sizeof rates[0])

/* What every row of one scene needs: the machine, the truth (the detailed run) and the files. */
typedef struct SceneRun {
    const char *name;
    const RunScene *sc;
    const CfgMachine *cfg;
    int threads;
    RunFrame full;             /* the detailed run: the truth */
    double truth, fps_true, u_true[3];
    FILE *md, *dat;
} SceneRun;

/* sc's frame in mode (sample: RUN_SAMPLED's fraction of tiles, seed 1). 0, or -1 after printing
 * why; fr must be freed with run_frame_free either way. */
static int render(const SceneRun *r, RunMode mode, double sample, RunFrame *fr)
{
    static char err[65536];
    RunSpec spec = {.mode = mode, .cfg = r->cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1,
                    .threads = r->threads, .sample = sample, .sample_seed = 1};
    int rc = run_frame(r->sc, &spec, fr, err, sizeof err);
    if (rc != 0)
        fprintf(stderr, "%s\n", err);
    return rc;
}

/* Timed utilization of the three ray stages over the timed tiles (report.json's, sim/stats.h). */
static void util_timed(const FuncStats *f, int lanes, double u[3])
{
    for (int k = 1; k <= 3; k++)
        u[k - 1] = stats_utilization_timed(f, lanes, k);
}

static double max_abs_diff3(const double a[3], const double b[3])
{
    double m = 0.0;
    for (int k = 0; k < 3; k++)
        if (fabs(a[k] - b[k]) > m)
            m = fabs(a[k] - b[k]);
    return m;
}

/* The functional run's row: fps from instructions (no stalls), utilization per instruction. */
static int functional_row(const SceneRun *r)
{
    RunFrame fun;
    if (render(r, RUN_FUNCTIONAL, 0.0, &fun) != 0) {
        run_frame_free(&fun);
        return -1;
    }
    const double hz = r->cfg->core_clock_mhz * 1e6;
    double fps_f = hz / (double)fun.f.instructions, u_f[3];
    for (int k = 1; k <= 3; k++)
        u_f[k - 1] = stats_utilization(&fun.f.core, r->cfg->core_simd_width, k);
    fprintf(r->md, "| %s | functional | 0 | %.2f | %.1fx | %.3f | %+.1f %% | %.1f pts | - | - | - |\n", r->name,
            fun.seconds, r->full.seconds / fun.seconds, fps_f, 100.0 * (fps_f - r->fps_true) / r->fps_true,
            100.0 * max_abs_diff3(u_f, r->u_true));
    fprintf(r->dat, "%s 0 %.3f %.4f %.3f 0 0 0\n", r->name, r->full.seconds / fun.seconds,
            100.0 * fabs(fps_f - r->fps_true) / r->fps_true, 100.0 * max_abs_diff3(u_f, r->u_true));
    run_frame_free(&fun);
    return 0;
}

/* How many of seeds 1..100 give an interval covering the truth at this rate, from the detailed
 * run's per-tile cycles (y) and instructions (x). */
static int coverage100(const SceneRun *r, const double *y, const double *x, uint8_t *sel, double rate)
{
    uint32_t N = r->full.f.ntiles;
    int cov = 0;
    for (uint32_t seed = 1; seed <= 100; seed++) {
        SampleEstimate es;
        sample_select(N, rate, seed, sel);
        if (sample_ratio_estimate(y, x, sel, N, &es) == 0)
            cov += es.lo <= r->truth && r->truth <= es.hi;
    }
    return cov;
}

/* One sampled run's row. 0; 1 when sampling every tile misses the detailed cycles; -1 when the
 * run fails. */
static int sampled_row(const SceneRun *r, double rate, const double *y, const double *x, uint8_t *sel)
{
    RunFrame sr;
    if (render(r, RUN_SAMPLED, rate, &sr) != 0) {
        run_frame_free(&sr);
        return -1;
    }
    const SampleEstimate *e = &sr.est; /* the estimate report.json gives (its tiles' instructions are the full run's) */
    double fps_s = stats_frame(&sr.f.timing, sr.f.instructions, r->cfg->core_clock_mhz, e).fps, u_s[3];
    util_timed(&sr.f, r->cfg->core_simd_width, u_s);
    int covered = e->lo <= r->truth && r->truth <= e->hi;
    int cov100 = coverage100(r, y, x, sel, rate);
    double half = 100.0 * 0.5 * (e->hi - e->lo) / e->total;
    double speedup = r->full.seconds / sr.seconds, fps_err = 100.0 * (fps_s - r->fps_true) / r->fps_true;
    double util_err = 100.0 * max_abs_diff3(u_s, r->u_true);
    fprintf(r->md, "| %s | sampled %g %% | %u | %.2f | %.1fx | %.3f | %+.2f %% | %.2f pts | %s | %d %% | %.2f %% |\n",
            r->name, 100.0 * rate, e->n, sr.seconds, speedup, fps_s, fps_err, util_err, covered ? "yes" : "no",
            cov100, half);
    fprintf(r->dat, "%s %g %.3f %.4f %.3f %d %d %.4f\n", r->name, 100.0 * rate, speedup, fabs(fps_err), util_err,
            covered, cov100, half);
    int rc = 0;
    if (rate >= 1.0 && (e->total != r->truth || sr.f.timing.cycles != r->full.f.timing.cycles)) {
        fprintf(stderr, "%s: sampling every tile does not give the detailed cycles\n", r->name);
        rc = 1;
    }
    run_frame_free(&sr);
    fflush(r->md);
    return rc;
}

/* The sampled rows of one scene, against the detailed run's tiles. 0, 1 (a check failed) or -1. */
static int sampled_rows(const SceneRun *r)
{
    uint32_t N = r->full.f.ntiles;
    double *y = malloc(N * sizeof *y), *x = malloc(N * sizeof *x);
    uint8_t *sel = malloc(N);
    int rc = 0;
    if (!y || !x || !sel)
        rc = -1;
    for (uint32_t i = 0; rc == 0 && i < N; i++) {
        y[i] = (double)r->full.f.tiles[i].cycles;
        x[i] = (double)r->full.f.tiles[i].instructions;
    }
    for (size_t ri = 0; rc >= 0 && ri < NRATES; ri++) {
        int k = sampled_row(r, rates[ri], y, x, sel);
        rc = k < 0 ? -1 : k ? 1 : rc;
    }
    free(y);
    free(x);
    free(sel);
    return rc;
}

/* Every row of one scene at 512 x 512, 1 spp, M = 1024. 0, 1 (a check failed) or -1 (a run failed). */
static int scene_rows(const char *name, const char *path, int threads, FILE *md, FILE *dat)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    static char err[65536];
    RunScene sc;
    RunSize size = {512, 512, 1, -1};
    if (run_scene_open(&sc, path, &size, &cfg, RUN_DETAILED, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        run_scene_close(&sc);
        return -1;
    }
    SceneRun r = {.name = name, .sc = &sc, .cfg = &cfg, .threads = threads, .md = md, .dat = dat};
    int rc = render(&r, RUN_DETAILED, 0.0, &r.full);
    if (rc == 0) {
        r.truth = (double)r.full.f.timing.cycles;
        r.fps_true = cfg.core_clock_mhz * 1e6 / r.truth;
        util_timed(&r.full.f, cfg.core_simd_width, r.u_true);
        fprintf(md, "| %s | detailed | %u | %.2f | 1.0x | %.3f | - | - | - | - | - |\n", name, r.full.f.ntiles,
                r.full.seconds, r.fps_true);
        rc = functional_row(&r);
    }
    if (rc == 0)
        rc = sampled_rows(&r);
    fprintf(dat, "\n\n");
    run_frame_free(&r.full);
    run_scene_close(&sc);
    return rc;
}

/* The plot: speed-up against fps error, one line per scene, points by sampling rate. 0, or -1
 * when the script cannot be written (gnuplot's own failure is only said). */
static int write_plot(const char *outdir)
{
    char path[4200], cmd[4300];
    snprintf(path, sizeof path, "%s/speed_vs_error.gp", outdir);
    FILE *gp = fopen(path, "w");
    if (!gp) {
        fprintf(stderr, "speed_vs_error: cannot write %s\n", path);
        return -1;
    }
    fprintf(gp,
            "set terminal pngcairo size 900,600 font 'DejaVu Sans,11'\n"
            "set output '%s/speed_vs_error.png'\n"
            "set title 'sampled mode (labels: share of tiles timed) and functional mode: speed-up against fps error'\n"
            "set xlabel 'speed-up over the full detailed run (x)'\n"
            "set ylabel 'error of the predicted fps (%%, log; an exact 0 is drawn at 1e-4)'\n"
            "set logscale y\nset grid\nset key top left\n"
            "plot for [i=0:2] '%s/speed_vs_error.dat' index i using 3:($4 > 0 ? $4 : 1e-4) "
            "with points title word('cornell sponza conference', i+1) pt 7 ps 1.3, \\\n"
            "     for [i=0:2] '' index i using 3:($4 > 0 ? $4 : 1e-4):($2 == 0 ? 'functional' : sprintf('%%g%%%%', $2)) "
            "with labels offset 1.5,0.6 font ',8' notitle\n",
            outdir, outdir);
    fclose(gp);
    snprintf(cmd, sizeof cmd, "gnuplot '%s/speed_vs_error.gp'", outdir);
    if (system(cmd) != 0)
        fprintf(stderr, "speed_vs_error: gnuplot failed; the table and data are in %s\n", outdir);
    return 0;
}

/* OUTDIR/speed_vs_error.md and .dat, opened with their headings. 0, or -1 after saying why. */
static int open_outputs(const char *outdir, int threads, FILE **md, FILE **dat)
{
    char cmd[4200], path[4200];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", outdir);
    if (system(cmd) != 0) {
        fprintf(stderr, "speed_vs_error: cannot create %s\n", outdir);
        return -1;
    }
    snprintf(path, sizeof path, "%s/speed_vs_error.md", outdir);
    *md = fopen(path, "w");
    snprintf(path, sizeof path, "%s/speed_vs_error.dat", outdir);
    *dat = fopen(path, "w");
    if (!*md || !*dat) {
        fprintf(stderr, "speed_vs_error: cannot write into %s\n", outdir);
        return -1;
    }
    fprintf(*md, "512 x 512, 1 spp, N = 16, M = 1024 (256 tiles), %d host threads; sampled runs use seed 1.\n\n",
            threads);
    fprintf(*md, "| scene | mode | tiles timed | host s | speed-up | fps | fps error | util. error | covered | "
                 "coverage (100 seeds) | interval (+-) |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    fprintf(*dat, "# scene rate speedup fps_error_pct util_error_pts covered coverage100 halfwidth_pct\n");
    return 0;
}

/* The table, from the file (what a reader of OUTDIR gets). */
static void print_table(const char *outdir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/speed_vs_error.md", outdir);
    FILE *in = fopen(path, "r");
    if (!in)
        return;
    int ch;
    while ((ch = fgetc(in)) != EOF)
        putchar(ch);
    fclose(in);
}

int main(int argc, char **argv)
{
    const char *outdir = argc > 1 ? argv[1] : "out/bench";
    int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads < 1)
        threads = 1;
    FILE *md, *dat;
    if (open_outputs(outdir, threads, &md, &dat) != 0)
        return 1;
    static const char *const names[] = {"cornell", "sponza", "conference"};
    static const char *const paths[] = {"scenes/cornell/scene.ini", "scenes/sponza-dabrovic/scene.ini",
                                        "scenes/conference/scene.ini"};
    int rc = 0;
    int skipped = 0;
    for (int si = 0; si < 3; si++) {
        int ok = bench_scene_ok("speed_vs_error", paths[si], &skipped);
        if (ok < 0)
            return 1;
        if (!ok)
            continue;
        int k = scene_rows(names[si], paths[si], threads, md, dat);
        if (k < 0)
            return 1;
        rc |= k;
    }
    fclose(md);
    fclose(dat);
    if (write_plot(outdir) != 0)
        return 1;
    bench_scenes_summary("speed_vs_error", skipped, 3);
    print_table(outdir);
    return rc;
}
