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
#include <sys/stat.h>
#include <unistd.h>

#include "../scenes/pack.h"
#include "../scenes/scene.h"
#include "../sim/config.h"
#include "../sim/functional.h"
#include "../sim/sampling.h"
#include "../sim/stats.h"
#include "bench_scenes.h"
#include "../sim/util.h"

typedef struct Run {
    FuncStats st;
    double secs;
} Run;

static int render(const PackedScene *p, uint32_t needs, const CfgMachine *cfg, int timed, double sample, size_t n,
                  int threads, Run *r)
{
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = needs, .seed = 1, .threads = threads,
                     .timed = timed, .sample = sample, .sample_seed = 1};
    float *rgb = calloc(n, sizeof *rgb);
    double t0 = util_now();
    int rc = rgb ? func_render(p, &fp, rgb, &r->st, err, sizeof err) : -1;
    r->secs = util_now() - t0;
    free(rgb);
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

int main(int argc, char **argv)
{
    const char *outdir = argc > 1 ? argv[1] : "out/bench";
    char cmd[4200];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", outdir);
    if (system(cmd) != 0) {
        fprintf(stderr, "speed_vs_error: cannot create %s\n", outdir);
        return 1;
    }
    char path[4200];
    snprintf(path, sizeof path, "%s/speed_vs_error.md", outdir);
    FILE *md = fopen(path, "w");
    snprintf(path, sizeof path, "%s/speed_vs_error.dat", outdir);
    FILE *dat = fopen(path, "w");
    if (!md || !dat) {
        fprintf(stderr, "speed_vs_error: cannot write into %s\n", outdir);
        return 1;
    }
    int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (threads < 1)
        threads = 1;
    static const char *const names[] = {"cornell", "sponza", "conference"};
    static const char *const paths[] = {"scenes/cornell/scene.ini", "scenes/sponza-dabrovic/scene.ini",
                                        "scenes/conference/scene.ini"};
    static const double rates[] = {0.01, 0.02, 0.05, 0.10, 0.25, 1.00};
    const int w = 512, h = 512, spp = 1;
    fprintf(md, "512 x 512, 1 spp, N = 16, M = 1024 (256 tiles), %d host threads; sampled runs use seed 1.\n\n", threads);
    fprintf(md, "| scene | mode | tiles timed | host s | speed-up | fps | fps error | util. error | covered | "
                "coverage (100 seeds) | interval (+-) |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    fprintf(dat, "# scene rate speedup fps_error_pct util_error_pts covered coverage100 halfwidth_pct\n");
    int rc = 0;
    int skipped = 0;
    for (int si = 0; si < 3; si++) {
        int ok = bench_scene_ok("speed_vs_error", paths[si], &skipped);
        if (ok < 0)
            return 1;
        if (!ok)
            continue;
        char err[65536];
        Scene s;
        PackedScene p;
        if (pack_load_file(paths[si], w, h, spp, &s, &p, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        CfgMachine cfg;
        cfg_defaults(&cfg);
        cfg.stream_rays = 1024;
        const double hz = cfg.core_clock_mhz * 1e6;
        size_t n = 3 * (size_t)w * h;
        Run full, fun;
        if (render(&p, s.needs, &cfg, 1, 0.0, n, threads, &full) || render(&p, s.needs, &cfg, 0, 0.0, n, threads, &fun))
            return 1;
        const double truth = (double)full.st.timing.cycles, fps_true = hz / truth;
        double u_true[3];
        util_timed(&full.st, cfg.core_simd_width, u_true);
        fprintf(md, "| %s | detailed | %u | %.2f | 1.0x | %.3f | - | - | - | - | - |\n", names[si], full.st.ntiles,
                full.secs, fps_true);
        /* functional: fps from instructions (no stalls), utilization per instruction */
        double fps_f = hz / (double)fun.st.instructions, u_f[3];
        for (int k = 1; k <= 3; k++)
            u_f[k - 1] = stats_utilization(&fun.st.core, cfg.core_simd_width, k);
        fprintf(md, "| %s | functional | 0 | %.2f | %.1fx | %.3f | %+.1f %% | %.1f pts | - | - | - |\n", names[si],
                fun.secs, full.secs / fun.secs, fps_f, 100.0 * (fps_f - fps_true) / fps_true,
                100.0 * max_abs_diff3(u_f, u_true));
        fprintf(dat, "%s 0 %.3f %.4f %.3f 0 0 0\n", names[si], full.secs / fun.secs,
                100.0 * fabs(fps_f - fps_true) / fps_true, 100.0 * max_abs_diff3(u_f, u_true));
        /* the detailed run's tiles, for coverage over seeds */
        uint32_t N = full.st.ntiles;
        double *y = malloc(N * sizeof *y), *x = malloc(N * sizeof *x);
        uint8_t *sel = malloc(N);
        if (!y || !x || !sel)
            return 1;
        for (uint32_t i = 0; i < N; i++) {
            y[i] = (double)full.st.tiles[i].cycles;
            x[i] = (double)full.st.tiles[i].instructions;
        }
        for (size_t ri = 0; ri < sizeof rates / sizeof rates[0]; ri++) {
            Run sr;
            if (render(&p, s.needs, &cfg, 1, rates[ri], n, threads, &sr))
                return 1;
            SampleEstimate e;   /* the estimate report.json gives (its tiles' instructions are the full run's) */
            if (stats_sample_estimate(&sr.st, &e) != 0)
                return 1;
            double fps_s = stats_frame(&sr.st.timing, sr.st.instructions, cfg.core_clock_mhz, &e).fps, u_s[3];
            util_timed(&sr.st, cfg.core_simd_width, u_s);
            int covered = e.lo <= truth && truth <= e.hi;
            int cov100 = 0;
            for (uint32_t seed = 1; seed <= 100; seed++) {
                SampleEstimate es;
                sample_select(N, rates[ri], seed, sel);
                if (sample_ratio_estimate(y, x, sel, N, &es) == 0)
                    cov100 += es.lo <= truth && truth <= es.hi;
            }
            double half = 100.0 * 0.5 * (e.hi - e.lo) / e.total;
            fprintf(md, "| %s | sampled %g %% | %u | %.2f | %.1fx | %.3f | %+.2f %% | %.2f pts | %s | %d %% | %.2f %% |\n",
                    names[si], 100.0 * rates[ri], e.n, sr.secs, full.secs / sr.secs, fps_s,
                    100.0 * (fps_s - fps_true) / fps_true, 100.0 * max_abs_diff3(u_s, u_true), covered ? "yes" : "no",
                    cov100, half);
            fprintf(dat, "%s %g %.3f %.4f %.3f %d %d %.4f\n", names[si], 100.0 * rates[ri], full.secs / sr.secs,
                    100.0 * fabs(fps_s - fps_true) / fps_true, 100.0 * max_abs_diff3(u_s, u_true), covered, cov100,
                    half);
            if (rates[ri] >= 1.0 && (e.total != truth || sr.st.timing.cycles != full.st.timing.cycles)) {
                fprintf(stderr, "%s: sampling every tile does not give the detailed cycles\n", names[si]);
                rc = 1;
            }
            func_stats_free(&sr.st);
            fflush(md);
        }
        fprintf(dat, "\n\n");
        free(y);
        free(x);
        free(sel);
        func_stats_free(&full.st);
        func_stats_free(&fun.st);
        pack_free(&p);
        scene_free(&s);
    }
    fclose(md);
    fclose(dat);
    /* The plot: speed-up against fps error, one line per scene, points by sampling rate. */
    snprintf(path, sizeof path, "%s/speed_vs_error.gp", outdir);
    FILE *gp = fopen(path, "w");
    if (!gp)
        return 1;
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
    bench_scenes_summary("speed_vs_error", skipped, 3);
    snprintf(path, sizeof path, "%s/speed_vs_error.md", outdir);
    FILE *in = fopen(path, "r");
    if (in) {
        int ch;
        while ((ch = fgetc(in)) != EOF)
            putchar(ch);
        fclose(in);
    }
    return rc;
}
