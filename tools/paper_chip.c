/* tools/paper_chip.c -- the paper's frame on chips, in sampled mode (`make paper-chip`; issue 41).
 *
 * The conference room with its 72 lights (scenes/conference/scene.ini) at 1024 x 1024, 64 spp,
 * max depth 3 (seed 001's Table 6 frame), streams of M = 4096 rays (256 tiles), on chips of
 * K = 1, 4, 16, 64 and 256 of the paper's cores with two memories: configs/chip16-ddr4.ini (a 4 MB
 * L2 and two DDR4-2400 channels) and configs/chip64-gddr6.ini (an 8 MB L2 and sixteen GDDR6
 * channels), chip.cores set to K. Each point in sampled mode (docs/sampling.md, "Sampling a
 * chip") with --target-error 0.01 and no image (the estimate alone), seed 1. With --check, also
 * one full detailed run of K = 16 with DDR4 (about 95 minutes on one host thread: a chip with
 * shared memory runs on one): its cycles against the estimate's interval, and the host times.
 *
 * Prints a markdown section between the markers docs/validation-data.md keeps (Makefile
 * `paper-chip`), and writes the points to DATFILE (K, fps, lo, hi per memory) for the plot of fps
 * against K (docs/img/paper-chip-fps.png). Host times are the frame's (run_frame) plus the scene's
 * load and acceleration build.
 *
 * usage: paper_chip [--check] [--size WxHxS] [--cores K,K,...] DATFILE
 *   --size: a smaller frame to try the tool; --cores: other chip sizes.
 * Exit 0; 1 when a run fails or the detailed run falls outside the estimate's interval; 2 on bad
 * usage.
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
#define MAX_CORES_LIST 16

static const char *const mem_config[2] = {"configs/chip16-ddr4.ini", "configs/chip64-gddr6.ini"};
static const char *const mem_name[2] = {"DDR4-2400 x 2, 4 MB L2", "GDDR6 x 16, 8 MB L2"};

typedef struct Point {
    int k, mem;
    double fps, lo, hi, seconds, scene_seconds, r;
    uint32_t units, units_sampled, opening, wave_units;
    double cycles, cycles_lo, cycles_hi;
} Point;

static int machine(int mem, int k, CfgMachine *cfg)
{
    cfg_defaults(cfg);
    CfgErrors errs = {0};
    if (cfg_load(cfg, mem_config[mem], &errs) != 0) {
        fprintf(stderr, "paper_chip: %s\n", errs.text ? errs.text : mem_config[mem]);
        cfg_errors_free(&errs);
        return -1;
    }
    cfg_errors_free(&errs);
    cfg->chip_cores = k;
    cfg->stream_rays = 4096;
    return 0;
}

static int point(const RunSize *size, int mem, int k, int detailed, Point *pt)
{
    static char err[65536];
    CfgMachine cfg;
    if (machine(mem, k, &cfg) != 0)
        return -1;
    RunScene sc;
    const double t0 = util_now();
    const RunMode mode = detailed ? RUN_DETAILED : RUN_SAMPLED;
    if (run_scene_open(&sc, SCENE, size, &cfg, mode, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "paper_chip: %s\n", err);
        run_scene_close(&sc);
        return -1;
    }
    memset(pt, 0, sizeof *pt);
    pt->k = k;
    pt->mem = mem;
    pt->scene_seconds = util_now() - t0;
    RunSpec spec = {.mode = mode, .cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1,
                    .target_error = detailed ? 0.0 : TARGET, .sample_seed = 1, .no_image = !detailed};
    RunFrame fr;
    const int rc = run_frame(&sc, &spec, &fr, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "paper_chip: K = %d, %s: %s\n", k, mem_config[mem], err);
    } else {
        const double hz = cfg.core_clock_mhz * 1e6;
        pt->seconds = fr.seconds;
        if (detailed) {
            pt->cycles = pt->cycles_lo = pt->cycles_hi =
                (double)(fr.f.chip_cores ? fr.f.makespan : fr.f.timing.cycles);
        } else {
            pt->cycles = fr.est.total;
            pt->cycles_lo = fr.est.lo;
            pt->cycles_hi = fr.est.hi;
            pt->units = fr.est.N;
            pt->units_sampled = fr.units_sampled;
            pt->opening = fr.chip.opening_units;
            pt->wave_units = fr.chip.wave_units;
            pt->r = fr.chip.on ? fr.chip.r : 1.0;
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
    printf("<!-- make paper-chip: begin -->\n"
           "## The paper's frame on chips, sampled (`make paper-chip`)\n\n"
           "`build/paper_chip` (tools/paper_chip.c): the conference room with its 72 lights at %d x %d, %d spp,\n"
           "max depth 3 (seed 001's frame), streams of 64 x 64 rays, on K of the paper's cores (N = 16,\n"
           "500 MHz) sharing the memory of configs/chip16-ddr4.ini or configs/chip64-gddr6.ini (chip.cores\n"
           "set to K); each point in sampled mode with `--target-error 0.01 --no-image` (seed 1;\n"
           "docs/sampling.md, \"Sampling a chip\"), %d host threads. *units* are those timed alone (the\n"
           "opening's and the waves' apart); *host s* is the frame's host time, *+ scene s* the scene's\n"
           "load and BVH build.\n\n"
           "| memory | K | fps | 95 %% interval | +- | units timed | opening | wave units | r | host s | + scene s |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|\n",
           size->width, size->height, size->spp, threads);
}

static void print_point(const Point *p)
{
    printf("| %s | %d | %.4f | %.4f .. %.4f | %.2f %% | %u of %u | %u | %u | %.4f | %.1f | %.1f |\n",
           mem_name[p->mem], p->k, p->fps, p->lo, p->hi, 100.0 * (p->cycles_hi - p->cycles_lo) / 2.0 / p->cycles,
           p->units_sampled, p->units, p->opening, p->wave_units, p->r, p->seconds, p->scene_seconds);
    fflush(stdout);
}

static int parse_cores(const char *s, int *cores, int *n)
{
    *n = 0;
    for (const char *p = s; *p && *n < MAX_CORES_LIST;) {
        char *end;
        const long k = strtol(p, &end, 10);
        if (end == p || k < 1 || k > 1024 || (*end && *end != ','))
            return -1;
        cores[(*n)++] = (int)k;
        p = *end ? end + 1 : end;
    }
    return *n > 0 ? 0 : -1;
}

static void check_line(const Point *det, const Point *e)
{
    const int inside = e->cycles_lo <= det->cycles && det->cycles <= e->cycles_hi;
    printf("\nThe full detailed run of K = 16 with DDR4: %.0f cycles, %.4f fps, %.1f s of host time (+ %.1f s).\n"
           "The sampled estimate: %.0f cycles (95 %%: %.0f .. %.0f), error %+.2f %%, %s; host time %.1f s:\n"
           "%.0fx faster.\n",
           det->cycles, det->fps, det->seconds, det->scene_seconds, e->cycles, e->cycles_lo, e->cycles_hi,
           100.0 * (e->cycles / det->cycles - 1.0), inside ? "inside the interval" : "OUTSIDE the interval",
           e->seconds, det->seconds / e->seconds);
}

int main(int argc, char **argv)
{
    RunSize size = {1024, 1024, 64, 3};
    int check = 0, cores[MAX_CORES_LIST] = {1, 4, 16, 64, 256}, ncores = 5;
    const char *dat = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--check")) {
            check = 1;
        } else if (!strcmp(argv[i], "--size") && i + 1 < argc &&
                   sscanf(argv[i + 1], "%dx%dx%d", &size.width, &size.height, &size.spp) == 3) {
            i++;
        } else if (!strcmp(argv[i], "--cores") && i + 1 < argc && parse_cores(argv[i + 1], cores, &ncores) == 0) {
            i++;
        } else if (argv[i][0] != '-' && !dat) {
            dat = argv[i];
        } else {
            fprintf(stderr, "usage: paper_chip [--check] [--size WxHxS] [--cores K,K,...] DATFILE\n");
            return 2;
        }
    }
    if (!dat) {
        fprintf(stderr, "usage: paper_chip [--check] [--size WxHxS] [--cores K,K,...] DATFILE\n");
        return 2;
    }
    const int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    print_head(&size, threads);
    Point pts[2][MAX_CORES_LIST];
    const double all = util_now();
    for (int m = 0; m < 2; m++)
        for (int i = 0; i < ncores; i++) {
            if (point(&size, m, cores[i], 0, &pts[m][i]) != 0)
                return 1;
            print_point(&pts[m][i]);
        }
    printf("\nAll %d points: %.1f s of host time, loading included.\n", 2 * ncores, util_now() - all);
    /* the plot's data, written whole (a temporary file renamed) */
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp", dat);
    FILE *f = fopen(tmp, "w");
    int ok = f != NULL;
    for (int i = 0; ok && i < ncores; i++)
        ok = fprintf(f, "%d %.6f %.6f %.6f %.6f %.6f %.6f\n", cores[i], pts[0][i].fps, pts[0][i].lo, pts[0][i].hi,
                     pts[1][i].fps, pts[1][i].lo, pts[1][i].hi) > 0;
    if (f && fclose(f) != 0)
        ok = 0;
    if (!ok || rename(tmp, dat) != 0) {
        fprintf(stderr, "paper_chip: cannot write %s\n", dat);
        remove(tmp);
        return 1;
    }
    int rc = 0;
    int i16 = -1;
    for (int i = 0; i < ncores; i++)
        if (cores[i] == 16)
            i16 = i;
    if (check && i16 >= 0) {
        Point det;
        if (point(&size, 0, 16, 1, &det) != 0)
            return 1;
        check_line(&det, &pts[0][i16]);
        rc = !(pts[0][i16].cycles_lo <= det.cycles && det.cycles <= pts[0][i16].cycles_hi);
    } else {
        printf("\n(`build/paper_chip --check` adds one full detailed run of K = 16 with DDR4 to check the estimate.)\n");
    }
    printf("\n![fps against K](img/paper-chip-fps.png)\n<!-- make paper-chip: end -->\n");
    return rc;
}
