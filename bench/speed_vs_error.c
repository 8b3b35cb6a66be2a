/* bench/speed_vs_error.c -- what sampled mode saves in host time, and what it costs in accuracy,
 * against the full detailed run of the same frame, measured in one run.
 *
 * For each scene (the Cornell box, the conference room; sponza with --all) at W x H x S (default
 * 512 x 512 x 16 spp), M = 1024, on the default machine:
 *   - one detailed run: the truth (cycles, fps) and the host time every speed-up divides;
 *   - every (tile, pass) unit timed once (sim/run/sampled.h sampled_population; its total must be
 *     the detailed cycles, checked), which gives the coverage of the 95 % interval over seeds
 *     1..100 without 100 more runs: a sampled unit's cycles are exactly its cycles in the detailed
 *     run (tests/unit/test_units.c), so seed s's estimate is computed from them as a run would;
 *   - sampled runs (seed 1): --target-error 1 % with the image, the same with --no-image, and a
 *     fixed --sample of 1 % of the units.
 * Per row: units timed, host seconds of the frame (scene loading and the BVH build are the same
 * for every mode and left out), speed-up over detailed, the fps and its error, the interval's
 * half-width, whether it covered the detailed fps; and over seeds 1..100: coverage, mean and
 * largest fps error, estimates within 1 %, mean units timed.
 *
 * usage: speed_vs_error [--size WxHxS] [--all] [OUTDIR]   (default out/bench): OUTDIR/speed_vs_error.md,
 * and OUTDIR/units-<scene>.tsv with every unit's figures
 * Not a test: numbers depend on the host. docs/validation.md quotes a run.
 * The chip's rows (K = 16 and 64, DDR4 and GDDR6; every seed a whole sampled run, since a chip's
 * units depend on each other) are bench/chip_error.c's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../sim/config.h"
#include "../sim/run/run.h"
#include "../sim/run/sampled.h"
#include "../sim/sampling.h"
#include "../sim/stats.h"
#include "bench_scenes.h"

#define TARGET 0.01            /* the --target-error of the sampled rows */

/* One scene's frame, its truth and the table. */
typedef struct SceneRun {
    const char *name;
    const RunScene *sc;
    const CfgMachine *cfg;
    int threads;
    double det_seconds, truth, fps_true;
    SampledPopulation pop;
    FILE *md;
} SceneRun;

/* A sampled row's set-up. */
typedef struct Variant {
    const char *label;
    double target, sample;
    int no_image;
} Variant;

/* The sequential rule (or the fixed sample) of v, replayed on the population for one seed. */
typedef struct Replay {
    const double *y;
} Replay;

static int replay_measure(void *ctx, const uint32_t *units, uint32_t count, double *ys)
{
    const Replay *r = ctx;
    for (uint32_t i = 0; i < count; i++)
        ys[i] = r->y[units[i]];
    return 0;
}

/* Seeds 1..100 of v replayed on the population (and 1..1000 for the coverage alone: a count over
 * 100 seeds varies by about +-2 around its mean). */
typedef struct Seeds {
    int covered;               /* intervals that contain the detailed cycles */
    int covered1000;           /* ... over seeds 1..1000 */
    int within;                /* estimates within TARGET of the detailed fps */
    double mean_err, max_err;  /* |fps error| */
    double mean_units;
} Seeds;

static Seeds seeds100(const SceneRun *r, const Variant *v)
{
    const SampledPopulation *p = &r->pop;
    uint32_t *order = malloc(p->N * sizeof *order);
    double *ys = malloc(p->N * sizeof *ys);
    Seeds sd = {0};
    for (uint32_t seed = 1; order && ys && seed <= 1000; seed++) {
        sample_order(p->N, seed, order);
        Replay rp = {p->cycles};
        uint32_t n0 = v->target > 0.0 ? (p->N < SAMPLED_FIRST_UNITS ? p->N : SAMPLED_FIRST_UNITS)
                                       : sample_count(p->N, v->sample);
        SampleEstimate e;
        if (sample_sequential(v->no_image ? p->x_pilot : p->x, SAMPLED_AUX_K, order, p->N, n0, v->target,
                              replay_measure, &rp, ys, &e, NULL) != 0)
            continue;
        int in = e.lo <= r->truth && r->truth <= e.hi;
        sd.covered1000 += in;
        if (seed > 100)
            continue;
        double err = fabs(r->truth / e.total - 1.0); /* fps = clock / cycles */
        sd.covered += in;
        sd.within += err <= TARGET;
        sd.mean_err += err / 100.0;
        sd.max_err = err > sd.max_err ? err : sd.max_err;
        sd.mean_units += e.n / 100.0;
    }
    free(order);
    free(ys);
    return sd;
}

static int frame(const SceneRun *r, RunMode mode, const Variant *v, RunFrame *fr)
{
    static char err[65536];
    RunSpec spec = {.mode = mode, .cfg = r->cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1,
                    .threads = r->threads, .sample_seed = 1};
    if (v) {
        spec.target_error = v->target;
        spec.sample = v->sample;
        spec.no_image = v->no_image;
    }
    int rc = run_frame(r->sc, &spec, fr, err, sizeof err);
    if (rc != 0)
        fprintf(stderr, "speed_vs_error: %s: %s\n", r->name, err);
    return rc;
}

/* One sampled row. 0, or -1 when the run fails. */
static int sampled_row(const SceneRun *r, const Variant *v)
{
    RunFrame fr;
    if (frame(r, RUN_SAMPLED, v, &fr) != 0) {
        run_frame_free(&fr);
        return -1;
    }
    const double hz = r->cfg->core_clock_mhz * 1e6;
    double fps = hz / fr.est.total, half = fr.est.t * fr.est.std_error / fr.est.total;
    int covered = fr.est.lo <= r->truth && r->truth <= fr.est.hi;
    Seeds sd = seeds100(r, v);
    fprintf(r->md, "| %s | %s | %u of %u | %.2f | %.1fx | %.4f | %+.2f %% | %.2f %% | %s | %d | %.1f %% | %.2f %% | %.2f %% | %d | %.0f |\n",
            r->name, v->label, fr.est.n, fr.est.N, fr.seconds, r->det_seconds / fr.seconds, fps,
            100.0 * (fps / r->fps_true - 1.0), 100.0 * half, covered ? "yes" : "no", sd.covered,
            sd.covered1000 / 10.0, 100.0 * sd.mean_err,
            100.0 * sd.max_err, sd.within, sd.mean_units);
    fflush(r->md);
    run_frame_free(&fr);
    return 0;
}

/* OUTDIR/units-<scene>.tsv: every unit's detailed cycles and instructions and its auxiliaries
 * (from every pass, then from the --no-image pilot), for studying other estimators offline. */
static void dump_units(const SceneRun *r, const char *outdir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/units-%s.tsv", outdir, r->name);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "speed_vs_error: cannot write %s (the table goes on)\n", path);
        return;
    }
    const SampledPopulation *p = &r->pop;
    fprintf(f, "# unit = tile * %u + pass; cycles; instructions; node_steps leaf_steps ray_steps; the same from "
               "the pilot\n", p->spp);
    for (uint32_t u = 0; u < p->N; u++) {
        fprintf(f, "%u\t%.0f\t%.0f", u, p->cycles[u], p->instructions[u]);
        for (int j = 0; j < SAMPLED_AUX_K; j++)
            fprintf(f, "\t%.0f", p->x[(size_t)u * SAMPLED_AUX_K + j]);
        for (int j = 0; j < SAMPLED_AUX_K; j++)
            fprintf(f, "\t%.3f", p->x_pilot[(size_t)u * SAMPLED_AUX_K + j]);
        fputc('\n', f);
    }
    if (fclose(f) != 0)
        fprintf(stderr, "speed_vs_error: %s was not written whole\n", path);
}

/* Every row of one scene. 0, 1 (the population does not add up to the detailed run) or -1. */
static int scene_rows(SceneRun *r, const char *outdir)
{
    static char err[65536];
    RunFrame det;
    if (frame(r, RUN_DETAILED, NULL, &det) != 0) {
        run_frame_free(&det);
        return -1;
    }
    r->det_seconds = det.seconds;
    r->truth = (double)det.f.timing.cycles;
    r->fps_true = r->cfg->core_clock_mhz * 1e6 / r->truth;
    fprintf(r->md, "| %s | detailed | all %u | %.2f | 1.0x | %.4f | - | - | - | - | - | - | - | - | - |\n", r->name,
            det.f.ntiles * (uint32_t)r->sc->s.render.spp, det.seconds, r->fps_true);
    run_frame_free(&det);
    RunSpec spec = {.mode = RUN_SAMPLED, .cfg = r->cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1,
                    .threads = r->threads};
    if (sampled_population(r->sc, &spec, &r->pop, err, sizeof err) != 0) {
        fprintf(stderr, "speed_vs_error: %s: %s\n", r->name, err);
        return -1;
    }
    if (r->pop.total_cycles != r->truth) {
        fprintf(stderr, "speed_vs_error: %s: the units add up to %.0f cycles, the detailed run took %.0f\n", r->name,
                r->pop.total_cycles, r->truth);
        return 1;
    }
    dump_units(r, outdir);
    static const Variant variants[] = {{"sampled, --target-error 1 %", TARGET, 0.0, 0},
                                       {"sampled, --target-error 1 %, --no-image", TARGET, 0.0, 1},
                                       {"sampled, --sample 0.01", 0.0, 0.01, 0}};
    for (size_t i = 0; i < sizeof variants / sizeof variants[0]; i++)
        if (sampled_row(r, &variants[i]) != 0)
            return -1;
    return 0;
}

static int scene(const char *name, const char *path, const RunSize *size, int threads, FILE *md, const char *outdir)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    static char err[65536];
    RunScene sc;
    if (run_scene_open(&sc, path, size, &cfg, RUN_SAMPLED, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "speed_vs_error: %s\n", err);
        run_scene_close(&sc);
        return -1;
    }
    SceneRun r = {.name = name, .sc = &sc, .cfg = &cfg, .threads = threads, .md = md};
    int rc = scene_rows(&r, outdir);
    sampled_population_free(&r.pop);
    run_scene_close(&sc);
    return rc;
}

/* The table, from the file (what a reader of OUTDIR gets). */
static void print_table(const char *path)
{
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
    const char *outdir = "out/bench";
    RunSize size = {512, 512, 16, -1};
    int all = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (sscanf(argv[++i], "%dx%dx%d", &size.width, &size.height, &size.spp) != 3 || size.width < 1 ||
                size.height < 1 || size.spp < 1) {
                fprintf(stderr, "speed_vs_error: --size %s: expected WxHxS, e.g. 512x512x16\n", argv[i]);
                return 2;
            }
        } else if (!strcmp(argv[i], "--all")) {
            all = 1;
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "usage: speed_vs_error [--size WxHxS] [--all] [OUTDIR]\n");
            return 2;
        } else {
            outdir = argv[i];
        }
    }
    int threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    threads = threads < 1 ? 1 : threads;
    char cmd[4200], path[4200];
    snprintf(cmd, sizeof cmd, "mkdir -p '%s'", outdir);
    snprintf(path, sizeof path, "%s/speed_vs_error.md", outdir);
    FILE *md = system(cmd) == 0 ? fopen(path, "w") : NULL;
    if (!md) {
        fprintf(stderr, "speed_vs_error: cannot write %s\n", path);
        return 1;
    }
    fprintf(md, "%d x %d x %d spp, N = 16, M = 1024, %d host threads. The run's columns are seed 1's; the last five "
                "replay seeds 1-100 on every unit's detailed cycles: how many intervals cover the detailed cycles "
                "(and the share over seeds 1-1000), the mean and largest fps error, how many estimates are within "
                "%.0f %%, and the mean units timed.\n\n",
            size.width, size.height, size.spp, threads, 100.0 * TARGET);
    fprintf(md, "| scene | mode | units timed | host s | speed-up | fps | fps error | interval (+-) | covered | "
                "covered (100 seeds) | covered (1000 seeds) | mean error | largest error | within 1 %% | mean units |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    static const char *const names[] = {"cornell", "conference", "sponza"};
    static const char *const paths[] = {"scenes/cornell/scene.ini", "scenes/conference/scene.ini",
                                        "scenes/sponza-dabrovic/scene.ini"};
    int nscenes = all ? 3 : 2, rc = 0, skipped = 0;
    for (int si = 0; si < nscenes; si++) {
        int ok = bench_scene_ok("speed_vs_error", paths[si], &skipped);
        if (ok < 0)
            return 1;
        if (!ok)
            continue;
        int k = scene(names[si], paths[si], &size, threads, md, outdir);
        if (k < 0)
            return 1;
        rc |= k;
    }
    fclose(md);
    bench_scenes_summary("speed_vs_error", skipped, nscenes);
    print_table(path);
    return rc;
}
