/* bench/functional_speed.c -- host speed of the functional mode: the path-tracing kernel
 * (kernels/pathtrace.s) on the functional core, against the golden model on the same scene.
 *
 * For each of three scenes (the Cornell box, sponza, the conference room) at a fixed size,
 * renders once with the golden model and once through the kernel on the default machine
 * (N = 16, M = 4096), both on one host thread, and reports simulated instructions per host
 * second, traced rays per host second, and the slow-down of the functional mode against the
 * golden model measured in the same run. Both renders must agree pixel for pixel (the bench
 * says so, or fails). Scene loading and BVH building are not timed.
 *
 * usage: functional_speed [WIDTH HEIGHT SPP]   (default 128 96 4)
 * Not a test: numbers depend on the host. The closing notes and docs/kernel.md quote runs.
 */
#include <stdio.h>
#include <string.h>

#include "../sim/run/run.h"
#include "../sim/stats.h"
#include "bench_args.h"
#include "bench_scenes.h"

int main(int argc, char **argv)
{
    int w, h, spp;
    if (bench_size_args(argc, argv, "functional_speed", &w, &h, &spp))
        return 2;
    static const char *const scenes[] = {"scenes/cornell/scene.ini", "scenes/sponza-dabrovic/scene.ini",
                                         "scenes/conference/scene.ini"};
    printf("functional mode vs golden model, %d x %d, %d spp, 1 host thread, N = 16, M = 4096\n", w, h, spp);
    printf("%-34s %12s %10s %9s %9s %10s %10s %9s\n", "scene", "sim instr", "rays", "ref s", "func s", "M instr/s",
           "M rays/s", "slowdown");
    int rc = 0;
    int skipped = 0;
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        int ok = bench_scene_ok("functional_speed", scenes[i], &skipped);
        if (ok < 0)
            return 1;
        if (!ok)
            continue;
        char err[65536];
        RunScene sc;
        RunSize size = {w, h, spp, -1};
        if (run_scene_open(&sc, scenes[i], &size, NULL, RUN_FUNCTIONAL, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        /* The default machine: the golden model's tile is sqrt(stream.rays) = 64. */
        RunSpec golden = {.mode = RUN_REFERENCE, .seed = 1, .threads = 1};
        RunSpec kernel = {.mode = RUN_FUNCTIONAL, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = 1};
        RunFrame ref, fun;
        if (run_frame(&sc, &golden, &ref, err, sizeof err) != 0 || run_frame(&sc, &kernel, &fun, err, sizeof err) != 0) {
            fprintf(stderr, "%s: %s\n", scenes[i], err);
            return 1;
        }
        uint64_t instr = fun.f.instructions, rays = stats_rays_total(&fun.f);
        int same = memcmp(ref.rgb, fun.rgb, 3 * (size_t)w * h * sizeof(float)) == 0;
        printf("%-34s %12llu %10llu %9.3f %9.3f %10.2f %10.3f %8.1fx%s\n", scenes[i], (unsigned long long)instr,
               (unsigned long long)rays, ref.seconds, fun.seconds, 1e-6 * (double)instr / fun.seconds,
               1e-6 * (double)rays / fun.seconds, fun.seconds / ref.seconds, same ? "" : "  IMAGES DIFFER");
        if (!same)
            rc = 1;
        run_frame_free(&ref);
        run_frame_free(&fun);
        run_scene_close(&sc);
    }
    bench_scenes_summary("functional_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
