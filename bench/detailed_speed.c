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
 * mode. Both modes must give the same image bits, and detailed mode the same cycles on every
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
#include <unistd.h>

#include "../sim/run/run.h"
#include "../sim/stats.h"
#include "bench_args.h"
#include "bench_scenes.h"

/* sc's frame through the kernel on the default machine, in mode (functional or detailed). 0, or -1
 * after printing why; fr must be freed with run_frame_free either way. */
static int render(const RunScene *sc, RunMode mode, int threads, RunFrame *fr)
{
    static char err[65536];
    RunSpec spec = {.mode = mode, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = threads};
    if (run_frame(sc, &spec, fr, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    return 0;
}

/* One scene's best times: [threads index][0 functional, 1 detailed]. */
typedef struct Best {
    double seconds[2][2];
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
            if (render(sc, RUN_FUNCTIONAL, threads, &f) || render(sc, RUN_DETAILED, threads, &d))
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
            b->seconds[ti][0] = fmin(b->seconds[ti][0], f.seconds);
            b->seconds[ti][1] = fmin(b->seconds[ti][1], d.seconds);
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
    printf("%-34s %7s %11s %12s %9s %9s %10s %9s %9s %10s\n", "scene", "threads", "mode", "sim instr", "seconds",
           "M instr/s", "M rays/s", "slowdown", "scaling", "cycles");
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
                    char slow[16] = "", scale[16] = "", cyc[24] = "";
                    if (m)
                        snprintf(slow, sizeof slow, "%.2fx", t / b.seconds[ti][0]);
                    if (ti)
                        snprintf(scale, sizeof scale, "%.2fx", b.seconds[0][m] / t);
                    if (m)
                        snprintf(cyc, sizeof cyc, "%llu", (unsigned long long)b.cycles);
                    printf("%-34s %7d %11s %12llu %9.3f %9.2f %10.3f %9s %9s %10s\n", scenes[i], ti ? all : 1,
                           m ? "detailed" : "functional", (unsigned long long)b.instructions, t,
                           1e-6 * (double)b.instructions / t, 1e-6 * (double)b.rays / t, slow, scale, cyc);
                }
        run_scene_close(&sc);
    }
    bench_scenes_summary("detailed_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
