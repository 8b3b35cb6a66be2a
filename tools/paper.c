/* tools/paper.c -- seed 001 Table 6 at the paper's scale, in sampled mode (`make paper`).
 *
 * The conference room with its 72 lights (scenes/conference/scene.ini) at 1024 x 1024, 64 spp,
 * max depth 3, on the default machine at 500 MHz with N = 8, 12, 16 and streams of M = 1024 and
 * 4096 rays: each point in sampled mode (docs/sampling.md) with --target-error 0.01 and no image
 * (the estimate alone), then the N = 16, M = 4096 point again with its image, as a user would run
 * it. With --check, also one full detailed run of N = 16, M = 4096 (about 75 minutes on 2 cores):
 * its cycles against the estimate's interval, and the host times side by side.
 *
 * Prints a markdown section between the markers docs/validation-data.md keeps (Makefile `paper`).
 * Host times are the frame's (run_frame) plus the scene's load and acceleration build.
 *
 * usage: paper [--check] [--size WxHxS]     (--size: a smaller frame to try the tool)
 * Exit 0, or 1 when a run fails or the detailed run falls outside the estimate's interval.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../sim/config.h"
#include "../sim/run/run.h"
#include "../sim/util.h"

#define SCENE "scenes/conference/scene.ini"
#define TARGET 0.01

/* seed 001 Table 6, the conference room (conf): fps at 500 MHz, [M = 1024 (32x32), 4096 (64x64)]
 * [N = 8, 12, 16]. */
static const double paper_fps[2][3] = {{8.15, 12.56, 14.35}, {12.78, 18.32, 20.32}};
static const int widths[3] = {8, 12, 16}, streams[2] = {1024, 4096};

typedef struct Point {
    int n, m;
    double fps, lo, hi, half, seconds, scene_seconds;
    uint32_t units, units_sampled, rounds;
    double cycles, cycles_lo, cycles_hi;
} Point;

static int point(const RunSize *size, int n, int m, int image, int detailed, Point *pt)
{
    static char err[65536];
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.core_simd_width = n;
    cfg.stream_rays = m;
    RunScene sc;
    double t0 = util_now();
    RunMode mode = detailed ? RUN_DETAILED : RUN_SAMPLED;
    if (run_scene_open(&sc, SCENE, size, &cfg, mode, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "paper: %s\n", err);
        run_scene_close(&sc);
        return -1;
    }
    memset(pt, 0, sizeof *pt);
    pt->n = n;
    pt->m = m;
    pt->scene_seconds = util_now() - t0;
    RunSpec spec = {.mode = mode, .cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1,
                    .target_error = detailed ? 0.0 : TARGET, .sample_seed = 1, .no_image = !image && !detailed};
    RunFrame fr;
    int rc = run_frame(&sc, &spec, &fr, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "paper: N = %d, M = %d: %s\n", n, m, err);
    } else {
        double hz = cfg.core_clock_mhz * 1e6;
        pt->seconds = fr.seconds;
        if (detailed) {
            pt->cycles = pt->cycles_lo = pt->cycles_hi = (double)fr.f.timing.cycles;
        } else {
            pt->cycles = fr.est.total;
            pt->cycles_lo = fr.est.lo;
            pt->cycles_hi = fr.est.hi;
            pt->units = fr.est.N;
            pt->units_sampled = fr.est.n;
            pt->rounds = fr.rounds;
            pt->half = fr.est.t * fr.est.std_error / fr.est.total;
        }
        pt->fps = hz / pt->cycles;
        pt->lo = hz / pt->cycles_hi;
        pt->hi = hz / pt->cycles_lo;
    }
    run_frame_free(&fr);
    run_scene_close(&sc);
    return rc;
}

static void print_head(const RunSize *size, int threads)
{
    printf("<!-- make paper: begin -->\n"
           "## Table 6 at the paper's scale, sampled (`make paper`)\n\n"
           "`build/paper` (tools/paper.c): the conference room with its 72 lights at %d x %d, %d spp, max\n"
           "depth 3 (seed 001's frame), the default machine at 500 MHz, each point in sampled mode with\n"
           "`--target-error 0.01 --no-image` (seed 1; docs/sampling.md), %d host threads. *host s* is the\n"
           "frame's host time, *+ scene s* the scene's load and BVH build before it. The paper's fps are\n"
           "beside ours; absolute fps are not comparable (docs/validation.md explains why), the shape is.\n\n"
           "| M | N | fps | 95 %% interval | +- | units timed | rounds | host s | + scene s | paper fps | rel | paper rel |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
           size->width, size->height, size->spp, threads);
}

static void print_point(const Point *p, double fps16, int mi, int ni)
{
    printf("| %s | %d | %.5f | %.5f .. %.5f | %.2f %% | %u of %u | %u | %.1f | %.1f | %.2f | %.2f | %.2f |\n",
           p->m == 1024 ? "32x32" : "64x64", p->n, p->fps, p->lo, p->hi, 100.0 * p->half, p->units_sampled, p->units,
           p->rounds, p->seconds, p->scene_seconds, paper_fps[mi][ni], p->fps / fps16,
           paper_fps[mi][ni] / paper_fps[mi][2]);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    RunSize size = {1024, 1024, 64, 3};
    int check = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--check")) {
            check = 1;
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc &&
                   sscanf(argv[i + 1], "%dx%dx%d", &size.width, &size.height, &size.spp) == 3) {
            i++;
        } else {
            fprintf(stderr, "usage: paper [--check] [--size WxHxS]\n");
            return 2;
        }
    }
    int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    print_head(&size, threads);
    Point pts[2][3], img, det;
    double all = util_now();
    for (int mi = 0; mi < 2; mi++) {
        for (int ni = 2; ni >= 0; ni--) /* N = 16 first: the others are relative to it */
            if (point(&size, widths[ni], streams[mi], 0, 0, &pts[mi][ni]) != 0)
                return 1;
        for (int ni = 0; ni < 3; ni++)
            print_point(&pts[mi][ni], pts[mi][2].fps, mi, ni);
    }
    double six = util_now() - all;
    if (point(&size, 16, 4096, 1, 0, &img) != 0)
        return 1;
    printf("\nAll six points: %.1f s of host time, loading included. With the image (the golden model renders\n"
           "the whole frame), N = 16, M = 64x64: %.5f fps (95 %%: %.5f .. %.5f), %u of %u units, %.1f s + %.1f s.\n",
           six, img.fps, img.lo, img.hi, img.units_sampled, img.units, img.seconds, img.scene_seconds);
    int rc = 0;
    if (check) {
        if (point(&size, 16, 4096, 1, 1, &det) != 0)
            return 1;
        const Point *e = &pts[1][2];
        int inside = e->cycles_lo <= det.cycles && det.cycles <= e->cycles_hi;
        printf("\nThe full detailed run of N = 16, M = 64x64: %.0f cycles, %.5f fps, %.1f s of host time (+ %.1f s).\n"
               "The sampled estimate without the image: %.0f cycles (95 %%: %.0f .. %.0f), error %+.2f %%, %s; host\n"
               "time %.1f s: %.0fx faster. With the image: %.1f s, %.0fx faster.\n",
               det.cycles, det.fps, det.seconds, det.scene_seconds, e->cycles, e->cycles_lo, e->cycles_hi,
               100.0 * (e->cycles / det.cycles - 1.0), inside ? "inside the interval" : "OUTSIDE the interval",
               e->seconds, det.seconds / e->seconds, img.seconds, det.seconds / img.seconds);
        rc = !inside;
    } else {
        printf("\n(`build/paper --check` adds one full detailed run of N = 16, M = 64x64 to check the estimate.)\n");
    }
    printf("<!-- make paper: end -->\n");
    return rc;
}
