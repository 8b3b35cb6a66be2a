/* bench/detailed_speed.c -- host speed of detailed mode (the timing model) against functional
 * mode, on the same scenes, and of 1 host thread against all of them, measured in one run.
 *
 * For each of three scenes (the Cornell box, sponza, the conference room) at a fixed size,
 * renders through the kernel on the default machine (N = 16, M = 4096) in functional mode and in
 * detailed mode, on one host thread and on all host threads. The four renders take turns, REPS
 * rounds of them, and each keeps its best time, so a host whose speed drifts during the run (a
 * shared machine) slows all four alike instead of whichever ran in the slow minute. Reports
 * simulated instructions and traced rays per host second, the slow-down of detailed against
 * functional mode at the same thread count, and the speed-up of all threads against one in each
 * mode. Beside each best time, the process's CPU time in that render and the share of the threads'
 * wall time it fills ("busy": 100 % when no thread ever waits for work), which tells a shortfall in
 * the scaling that comes from the program (threads idle) from one that comes from the host (each
 * thread slower when both run, at the same busy share); and the share of the host's CPU time that
 * the hypervisor gave to other guests during that render ("steal", from /proc/stat, all CPUs; "-"
 * where it cannot be read), which says when such a slow-down was the host's. "busy scaling" is the
 * speed-up all threads would give if each ran as fast as one thread alone (threads x their busy
 * share / one thread's): the program's part of the scaling, which a host whose speed changes from
 * one render to the next cannot move. Both modes must give
 * the same image bits, and detailed mode the same cycles on every
 * thread count and round (the bench says so, or fails). Scene loading and BVH building are not timed.
 *
 * usage: detailed_speed [WIDTH HEIGHT SPP [REPS]]   (default 128 96 4, REPS 3)
 * Not a test: numbers depend on the host. The closing notes and docs/performance.md quote runs.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../sim/run/run.h"
#include "../sim/stats.h"
#include "bench_args.h"
#include "bench_scenes.h"

/* sc's frame through the kernel on the default machine, in mode (functional or detailed). 0, or -1
 * after printing why; fr must be freed with run_frame_free either way. */
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The host's steal time so far, in seconds summed over its CPUs (the eighth figure of /proc/stat's
 * "cpu" line, in clock ticks), or -1 where it cannot be read. */
static double steal_now(void)
{
    FILE *f = fopen("/proc/stat", "r");
    if (!f)
        return -1.0;
    unsigned long long v[8];
    int n = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                   &v[7]);
    fclose(f);
    long tck = sysconf(_SC_CLK_TCK);
    return n == 8 && tck > 0 ? (double)v[7] / (double)tck : -1.0;
}

/* What one render took beside its wall time. */
typedef struct Cost {
    double cpu;    /* the process's CPU seconds (every thread's) */
    double steal;  /* the host's steal seconds over all its CPUs, or -1 */
} Cost;

/* ... and *c: what it took. */
static int render(const RunScene *sc, RunMode mode, int threads, RunFrame *fr, Cost *c)
{
    static char err[65536];
    RunSpec spec = {.mode = mode, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = threads};
    double c0 = cpu_now(), s0 = steal_now();
    if (run_frame(sc, &spec, fr, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    double s1 = steal_now();
    c->cpu = cpu_now() - c0;
    c->steal = s0 >= 0.0 && s1 >= 0.0 ? s1 - s0 : -1.0;
    return 0;
}

/* One scene's best times: [threads index][0 functional, 1 detailed]. */
typedef struct Best {
    double seconds[2][2];
    Cost cost[2][2];               /* what the render that gave the best time took */
    uint64_t instructions, rays, cycles;
} Best;

/* REPS rounds of the four renders of sc; 0, or 1 after printing what differed. */
static int measure(const RunScene *sc, const char *name, int all, int reps, size_t n, Best *b)
{
    int rc = 0;
    float *image = NULL;
    for (int r = 0; r < reps && rc == 0; r++)
        for (int ti = 0; ti < 2 && rc == 0; ti++) {
            int threads = ti ? all : 1;
            RunFrame f, d;
            Cost fc, dc;
            if (render(sc, RUN_FUNCTIONAL, threads, &f, &fc) || render(sc, RUN_DETAILED, threads, &d, &dc))
                return 1;
            if (!image) {
                image = malloc(n * sizeof(float));
                if (!image) {
                    fprintf(stderr, "detailed_speed: out of memory\n");
                    return 1;
                }
                memcpy(image, f.rgb, n * sizeof(float));
                b->instructions = f.f.instructions;
                b->rays = stats_rays_total(&f.f);
                b->cycles = d.f.timing.cycles;
                for (int k = 0; k < 4; k++)
                    b->seconds[k / 2][k % 2] = INFINITY;
            }
            if (memcmp(image, f.rgb, n * sizeof(float)) != 0 || memcmp(image, d.rgb, n * sizeof(float)) != 0) {
                fprintf(stderr, "detailed_speed: %s: IMAGES DIFFER (round %d, %d threads)\n", name, r + 1, threads);
                rc = 1;
            }
            if (d.f.timing.cycles != b->cycles || d.f.instructions != b->instructions ||
                f.f.instructions != b->instructions) {
                fprintf(stderr, "detailed_speed: %s: CYCLES OR INSTRUCTIONS DIFFER (round %d, %d threads)\n", name,
                        r + 1, threads);
                rc = 1;
            }
            if (f.seconds < b->seconds[ti][0]) {
                b->seconds[ti][0] = f.seconds;
                b->cost[ti][0] = fc;
            }
            if (d.seconds < b->seconds[ti][1]) {
                b->seconds[ti][1] = d.seconds;
                b->cost[ti][1] = dc;
            }
            run_frame_free(&f);
            run_frame_free(&d);
        }
    free(image);
    return rc;
}

int main(int argc, char **argv)
{
    int w, h, spp, reps = 3;
    if (argc == 5) {
        reps = atoi(argv[4]);
        argc = 4;
        if (reps < 1 || reps > 100) {
            fprintf(stderr, "usage: detailed_speed [WIDTH HEIGHT SPP [REPS]]   (REPS 1..100; default 3)\n");
            return 2;
        }
    }
    if (bench_size_args(argc, argv, "detailed_speed", &w, &h, &spp))
        return 2;
    int all = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (all < 1)
        all = 1;
    static const char *const scenes[] = {"scenes/cornell/scene.ini", "scenes/sponza-dabrovic/scene.ini",
                                         "scenes/conference/scene.ini"};
    printf("detailed vs functional mode, %d x %d, %d spp, N = 16, M = 4096; 1 and %d host threads; "
           "best of %d rounds taking turns\n",
           w, h, spp, all, reps);
    printf("%-34s %7s %11s %12s %9s %9s %6s %6s %9s %10s %9s %9s %13s %10s\n", "scene", "threads", "mode",
           "sim instr", "seconds", "cpu s", "busy", "steal", "M instr/s", "M rays/s", "slowdown", "scaling",
           "busy scaling", "cycles");
    int rc = 0;
    int skipped = 0;
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        int ok = bench_scene_ok("detailed_speed", scenes[i], &skipped);
        if (ok < 0)
            return 1;
        if (!ok)
            continue;
        char err[65536];
        RunScene sc;
        RunSize size = {w, h, spp, -1};
        if (run_scene_open(&sc, scenes[i], &size, NULL, RUN_DETAILED, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        Best b;
        if (measure(&sc, scenes[i], all, reps, 3 * (size_t)w * h, &b) != 0)
            rc = 1;
        else
            for (int ti = 0; ti < 2; ti++)
                for (int m = 0; m < 2; m++) {
                    double t = b.seconds[ti][m];
                    char slow[16] = "", scale[16] = "", bscale[16] = "", cyc[24] = "";
                    if (m)
                        snprintf(slow, sizeof slow, "%.2fx", t / b.seconds[ti][0]);
                    if (ti) {
                        snprintf(scale, sizeof scale, "%.2fx", b.seconds[0][m] / t);
                        double busy1 = b.cost[0][m].cpu / b.seconds[0][m], busy = b.cost[1][m].cpu / (all * t);
                        snprintf(bscale, sizeof bscale, "%.2fx", all * busy / busy1);
                    }
                    if (m)
                        snprintf(cyc, sizeof cyc, "%llu", (unsigned long long)b.cycles);
                    const int threads = ti ? all : 1;
                    const Cost *c = &b.cost[ti][m];
                    char steal[16] = "-";
                    if (c->steal >= 0.0)
                        snprintf(steal, sizeof steal, "%.0f%%", 100.0 * c->steal / (all * t));
                    printf("%-34s %7d %11s %12llu %9.3f %9.3f %5.0f%% %6s %9.2f %10.3f %9s %9s %13s %10s\n",
                           scenes[i], threads, m ? "detailed" : "functional", (unsigned long long)b.instructions, t,
                           c->cpu, 100.0 * c->cpu / (threads * t), steal, 1e-6 * (double)b.instructions / t,
                           1e-6 * (double)b.rays / t, slow, scale, bscale, cyc);
                }
        run_scene_close(&sc);
    }
    bench_scenes_summary("detailed_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
