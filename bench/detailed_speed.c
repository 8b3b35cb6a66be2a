/* bench/detailed_speed.c -- host speed of detailed mode (the timing model) against functional
 * mode, on the same scenes, measured in one run.
 *
 * For each of three scenes (the Cornell box, sponza, the conference room) at a fixed size,
 * renders through the kernel on the default machine (N = 16, M = 4096) in functional mode and in
 * detailed mode, on one host thread and on all host threads, and reports simulated instructions
 * and traced rays per host second, and the slow-down of detailed against functional mode at the
 * same thread count. Both modes must give the same image bits, and detailed mode the same cycles
 * on every thread count (the bench says so, or fails). Scene loading and BVH building are not timed.
 *
 * usage: detailed_speed [WIDTH HEIGHT SPP]   (default 128 96 4)
 * Not a test: numbers depend on the host. The closing notes and docs/model.md quote runs.
 */
#include <stdio.h>
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

int main(int argc, char **argv)
{
    int w, h, spp;
    if (bench_size_args(argc, argv, "detailed_speed", &w, &h, &spp))
        return 2;
    int all = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (all < 1)
        all = 1;
    static const char *const scenes[] = {"scenes/cornell/scene.ini", "scenes/sponza-dabrovic/scene.ini",
                                         "scenes/conference/scene.ini"};
    printf("detailed vs functional mode, %d x %d, %d spp, N = 16, M = 4096; 1 and %d host threads\n", w, h, spp, all);
    printf("%-34s %7s %11s %12s %9s %9s %10s %9s %9s\n", "scene", "threads", "mode", "sim instr", "seconds",
           "M instr/s", "M rays/s", "slowdown", "cycles");
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
        size_t n = 3 * (size_t)w * h;
        uint64_t cycles1 = 0;
        for (int ti = 0; ti < 2; ti++) {
            int threads = ti ? all : 1;
            RunFrame f, d;
            if (render(&sc, RUN_FUNCTIONAL, threads, &f) || render(&sc, RUN_DETAILED, threads, &d))
                return 1;
            int same = memcmp(f.rgb, d.rgb, n * sizeof(float)) == 0;
            uint64_t cycles = d.f.timing.cycles;
            if (ti == 0)
                cycles1 = cycles;
            int same_cycles = cycles == cycles1;
            printf("%-34s %7d %11s %12llu %9.3f %9.2f %10.3f %9s %9s\n", scenes[i], threads, "functional",
                   (unsigned long long)f.f.instructions, f.seconds, 1e-6 * (double)f.f.instructions / f.seconds,
                   1e-6 * (double)stats_rays_total(&f.f) / f.seconds, "", "");
            printf("%-34s %7d %11s %12llu %9.3f %9.2f %10.3f %8.2fx %9llu%s%s\n", scenes[i], threads, "detailed",
                   (unsigned long long)d.f.instructions, d.seconds, 1e-6 * (double)d.f.instructions / d.seconds,
                   1e-6 * (double)stats_rays_total(&d.f) / d.seconds, d.seconds / f.seconds,
                   (unsigned long long)cycles, same ? "" : "  IMAGES DIFFER",
                   same_cycles ? "" : "  CYCLES DIFFER FROM 1 THREAD");
            if (!same || !same_cycles)
                rc = 1;
            run_frame_free(&f);
            run_frame_free(&d);
        }
        run_scene_close(&sc);
    }
    bench_scenes_summary("detailed_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
