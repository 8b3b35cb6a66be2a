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
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../scenes/pack.h"
#include "bench_args.h"
#include "bench_scenes.h"
#include "../scenes/scene.h"
#include "../sim/config.h"
#include "../sim/functional.h"
#include "../sim/util.h"
#include "../sim/stats.h"

typedef struct Result {
    double secs;
    uint64_t instructions, rays, cycles;
    float *rgb;
} Result;

static int render(const PackedScene *p, uint32_t needs, int timed, int threads, size_t n, Result *r)
{
    static char err[65536];
    CfgMachine cfg;
    cfg_defaults(&cfg);
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = needs, .seed = 1, .threads = threads, .timed = timed};
    FuncStats st;
    r->rgb = calloc(n, sizeof(float));
    double t0 = util_now();
    if (!r->rgb || func_render(p, &fp, r->rgb, &st, err, sizeof err) != 0) {
        fprintf(stderr, "%s\n", err);
        return -1;
    }
    r->secs = util_now() - t0;
    r->instructions = st.instructions;
    r->rays = stats_rays_total(&st);
    r->cycles = st.timing.cycles;
    func_stats_free(&st);
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
        Scene s;
        PackedScene p;
        if (pack_load_file(scenes[i], w, h, spp, &s, &p, err, sizeof err) != 0) {
            fprintf(stderr, "%s\n", err);
            return 1;
        }
        size_t n = 3 * (size_t)w * h;
        uint64_t cycles1 = 0;
        for (int ti = 0; ti < 2; ti++) {
            int threads = ti ? all : 1;
            Result f, d;
            if (render(&p, s.needs, 0, threads, n, &f) || render(&p, s.needs, 1, threads, n, &d))
                return 1;
            int same = memcmp(f.rgb, d.rgb, n * sizeof(float)) == 0;
            if (ti == 0)
                cycles1 = d.cycles;
            int same_cycles = d.cycles == cycles1;
            printf("%-34s %7d %11s %12llu %9.3f %9.2f %10.3f %9s %9s\n", scenes[i], threads, "functional",
                   (unsigned long long)f.instructions, f.secs, 1e-6 * (double)f.instructions / f.secs,
                   1e-6 * (double)f.rays / f.secs, "", "");
            printf("%-34s %7d %11s %12llu %9.3f %9.2f %10.3f %8.2fx %9llu%s%s\n", scenes[i], threads, "detailed",
                   (unsigned long long)d.instructions, d.secs, 1e-6 * (double)d.instructions / d.secs,
                   1e-6 * (double)d.rays / d.secs, d.secs / f.secs, (unsigned long long)d.cycles,
                   same ? "" : "  IMAGES DIFFER", same_cycles ? "" : "  CYCLES DIFFER FROM 1 THREAD");
            if (!same || !same_cycles)
                rc = 1;
            free(f.rgb);
            free(d.rgb);
        }
        pack_free(&p);
        scene_free(&s);
    }
    bench_scenes_summary("detailed_speed", skipped, (int)(sizeof scenes / sizeof scenes[0]));
    return rc;
}
