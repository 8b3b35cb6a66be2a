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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../scenes/pack.h"
#include "bench_args.h"
#include "bench_scenes.h"
#include "../scenes/scene.h"
#include "../sim/config.h"
#include "../sim/functional.h"
#include "../sim/stats.h"
#include "../sim/reference.h"
#include "../sim/util.h"

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
        Scene s;
        PackedScene p;
        if (pack_load_file(scenes[i], w, h, spp, &s, &p, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        size_t n = 3 * (size_t)w * h;
        float *ref = calloc(n, sizeof(float)), *fun = calloc(n, sizeof(float));
        RefParams rp = {.tile = 64, .seed = 1, .threads = 1};
        double t0 = util_now();
        if (!ref || !fun || ref_render(&p, &rp, ref, NULL, err, sizeof err) != 0) {
            fprintf(stderr, "%s: %s\n", scenes[i], err);
            return 1;
        }
        double t1 = util_now();
        CfgMachine cfg;
        cfg_defaults(&cfg);
        FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s.needs, .seed = 1, .threads = 1};
        FuncStats st;
        if (func_render(&p, &fp, fun, &st, err, sizeof err) != 0) {
            fprintf(stderr, "%s: %s\n", scenes[i], err);
            return 1;
        }
        double t2 = util_now();
        uint64_t rays = stats_rays_total(&st);
        int same = memcmp(ref, fun, n * sizeof(float)) == 0;
        printf("%-34s %12llu %10llu %9.3f %9.3f %10.2f %10.3f %8.1fx%s\n", scenes[i],
               (unsigned long long)st.instructions, (unsigned long long)rays, t1 - t0, t2 - t1,
               1e-6 * (double)st.instructions / (t2 - t1), 1e-6 * (double)rays / (t2 - t1), (t2 - t1) / (t1 - t0),
               same ? "" : "  IMAGES DIFFER");
        if (!same)
            rc = 1;
        free(ref);
        free(fun);
        func_stats_free(&st);
        pack_free(&p);
        scene_free(&s);
    }
    bench_scenes_summary("functional_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
