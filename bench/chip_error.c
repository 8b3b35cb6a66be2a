/* bench/chip_error.c -- sampled mode on a chip against the chip's full detailed run of the same frame,
 * over many sample seeds: error, coverage of the 95 % interval, speed-up (issue 41, deliverable 4;
 * docs/sampling.md, "Built: sampled mode on a chip"; docs/validation.md quotes a run).
 *
 * On a chip a unit's cycles depend on what its core ran before and on what the other cores do, so
 * bench/speed_vs_error's replay of seeds on a population of units does not apply: every seed here is
 * a whole sampled run (run_frame, RUN_SAMPLED, sample_seed = s).
 *
 * Rows (stream.rays = 1024: 32 x 32 tiles; max depth the scene's, 3 for the conference room):
 *   a. K = 16, DDR4  (configs/chip16-ddr4.ini),                  conference, 256 x 256 x 16 (64 tiles, 4 a core)
 *   b. K = 64, GDDR6 (configs/chip64-gddr6.ini),                 conference, 512 x 512 x 4 (256 tiles, 4 a core)
 *   c. K = 16, GDDR6 (configs/chip64-gddr6.ini, chip.cores = 16), row a's frame      (--all)
 *   d. K = 64, DDR4  (configs/chip16-ddr4.ini, chip.cores = 64),  row b's frame      (--all)
 * --small: every row on the Cornell box at 128 x 128 x 4 (16 tiles: at K = 64, 16 of the cores get a tile),
 * to check the bench in seconds, not to quote.
 * Per row: one detailed run on one host thread (the truth: the chip's makespan, and the host seconds
 * every speed-up divides), then seeds 1..S of --target-error 0.01 (with the image, or --no-image's
 * pilot), one host thread each. The error is the cycles': estimate / makespan - 1. Host seconds are
 * run_frame's wall time (scene loading and the BVH build, shared by both modes, left out).
 *
 * usage: chip_error [--seeds S] [--all] [--rows a,b,c,d] [--small] [--no-image] [OUTDIR]
 *   S 1..10000 (default 100); --rows picks rows (default a,b; --all: a,b,c,d); OUTDIR default out/bench.
 * Writes OUTDIR/chip_error.md (the table) and OUTDIR/chip_error-<row>.tsv (one line per seed), all
 * together and only when every row ran (host/outfile.h); progress per seed goes to stderr and each
 * row's table line to stdout as it ends. Scenes needing ../shared are skipped when it is absent.
 * Exit: 0; 1 a run failed (a config, a scene, a frame, or the output files); 2 bad usage.
 * Not a test: host seconds depend on the host; the full default run takes hours on 2 cores.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../host/outfile.h"
#include "../sim/chip/chip.h"
#include "../sim/config.h"
#include "../sim/run/run.h"
#include "../sim/util.h"
#include "bench_scenes.h"

#define TARGET 0.01            /* the --target-error of every sampled run */
#define ME "chip_error"

/* The memory figures the sampled chip estimates (docs/sampling.md, step 8). */
enum { MEM_LATENCY, MEM_L2_HIT, MEM_DRAM_GBS, MEM_COUNT };
static const char *const mem_name[MEM_COUNT] = {"memory latency", "L2 hit rate", "DRAM GB/s"};

/* One row: a chip and a frame. */
typedef struct Row {
    char id;
    int cores;
    const char *config, *dram;
    const char *scene, *frame;  /* the scene file, its short name */
    int width, height, spp;
} Row;

static const Row rows_full[] = {
    {'a', 16, "configs/chip16-ddr4.ini", "DDR4", "scenes/conference/scene.ini", "conference", 256, 256, 16},
    {'b', 64, "configs/chip64-gddr6.ini", "GDDR6", "scenes/conference/scene.ini", "conference", 512, 512, 4},
    {'c', 16, "configs/chip64-gddr6.ini", "GDDR6", "scenes/conference/scene.ini", "conference", 256, 256, 16},
    {'d', 64, "configs/chip16-ddr4.ini", "DDR4", "scenes/conference/scene.ini", "conference", 512, 512, 4},
};
enum { NROWS = sizeof rows_full / sizeof rows_full[0] };

/* Text grown in memory, written whole at the end. */
typedef struct Buf {
    char *p;
    size_t len, cap;
    int oom;
} Buf;

static void buf_printf(Buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void buf_printf(Buf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0 || b->oom)
        return;
    if (b->len + (size_t)n + 1 > b->cap) {
        size_t cap = (b->cap ? 2 * b->cap : 4096) + (size_t)n;
        char *p = realloc(b->p, cap);
        if (!p) {
            b->oom = 1;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    va_start(ap, fmt);
    vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

/* The options. */
typedef struct Opts {
    const char *outdir;
    int seeds, small, no_image;
    int pick[NROWS];
} Opts;

/* A row's figures over its seeds. */
typedef struct Result {
    double det_makespan, det_seconds;
    int seeds, covered;
    double mean_abs, mean_signed, max_abs, mean_units, mean_seconds;
    /* the memory figures (MEM_*): the detailed run's, and over the seeds that estimated them */
    double det_mem[MEM_COUNT];
    int mem_seeds[MEM_COUNT], mem_covered[MEM_COUNT];
    double mem_abs[MEM_COUNT], mem_signed[MEM_COUNT];
} Result;

/* A frame's memory figure m (MEM_*) from a detailed run's counters (the report's: chip_mem_figures). */
static double det_mem(const RunFrame *fr, const CfgMachine *cfg, int m)
{
    if (!fr->f.chip_mem)
        return -1.0;
    double f[CHIP_FIG_COUNT];
    chip_mem_figures(fr->f.chip_mem, (double)fr->f.makespan / (cfg->core_clock_mhz * 1e6), f);
    return f[m == MEM_LATENCY ? CHIP_FIG_LATENCY : m == MEM_L2_HIT ? CHIP_FIG_L2_HIT_RATE : CHIP_FIG_DRAM_GBS];
}

/* A sampled frame's estimate of m with its interval (f[3]); 0 when it has none. */
static int samp_mem(const RunFrame *fr, int m, const double **f)
{
    const StatsChipSample *c = &fr->chip;
    *f = m == MEM_LATENCY ? c->latency : m == MEM_L2_HIT ? c->l2_hit_rate : c->dram_gbs;
    return m == MEM_L2_HIT ? c->has_l2 : c->has_mem;
}

/* cfg for row r: its config file, chip.cores, stream.rays = 1024. 0, or -1 after printing why. */
static int row_machine(const Row *r, CfgMachine *cfg)
{
    CfgErrors errs = {0};
    cfg_defaults(cfg);
    int rc = 0;
    if (cfg_load(cfg, r->config, &errs) != 0) {
        rc = -1;
    } else {
        cfg->chip_cores = r->cores;
        cfg->stream_rays = 1024;
        if (cfg_check(cfg, &errs) != 0)
            rc = -1;
    }
    if (rc != 0)
        fprintf(stderr, ME ": row %c: %s", r->id, errs.text ? errs.text : r->config);
    cfg_errors_free(&errs);
    return rc;
}

/* One frame of sc; host seconds in *s. 0, or -1 after printing why (fr freed by the caller). */
static int frame(const Row *r, const RunScene *sc, const RunSpec *spec, RunFrame *fr, double *s)
{
    static char err[65536];
    double t0 = util_now();
    int rc = run_frame(sc, spec, fr, err, sizeof err);
    *s = util_now() - t0;
    if (rc != 0)
        fprintf(stderr, ME ": row %c: %s\n", r->id, err);
    return rc != 0 ? -1 : 0;
}

/* The detailed run, then the seeds, each seed a line of tsv. 0, or -1 after printing why. */
static int row_runs(const Row *r, const Opts *o, const RunScene *sc, const CfgMachine *cfg, Result *res, Buf *tsv)
{
    RunSpec spec = {.mode = RUN_DETAILED, .cfg = cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = 1};
    RunFrame fr;
    double s;
    int rc = frame(r, sc, &spec, &fr, &s);
    if (rc == 0 && (!fr.f.chip_cores || !fr.f.makespan)) {
        fprintf(stderr, ME ": row %c: the detailed run has no chip makespan\n", r->id);
        rc = -1;
    }
    res->det_makespan = rc == 0 ? (double)fr.f.makespan : 0.0;
    res->det_seconds = s;
    for (int m = 0; m < MEM_COUNT; m++)
        res->det_mem[m] = rc == 0 ? det_mem(&fr, cfg, m) : -1.0;
    run_frame_free(&fr);
    if (rc != 0)
        return -1;
    fprintf(stderr, ME ": row %c: detailed makespan %.0f cycles, %.1f s\n", r->id, res->det_makespan, s);
    buf_printf(tsv, "# row %c: K = %d, %s, %s %d x %d x %d; detailed makespan %.0f cycles, %.3f host s; "
                    "--target-error %.2f%s\n", r->id, r->cores, r->dram, r->frame, r->width, r->height, r->spp,
               res->det_makespan, s, TARGET, o->no_image ? ", --no-image" : "");
    buf_printf(tsv, "# memory figures of the detailed run: latency %.6g cycles, L2 hit rate %.6g, DRAM %.6g GB/s "
                    "(-1: none)\n", res->det_mem[MEM_LATENCY], res->det_mem[MEM_L2_HIT], res->det_mem[MEM_DRAM_GBS]);
    buf_printf(tsv, "# seed\testimate\tlo\thi\terror_pct\tcovered\tunits\tr\tr_lo\tr_hi\thost_s"
                    "\tlatency\tlatency_lo\tlatency_hi\tl2_hit\tl2_hit_lo\tl2_hit_hi\tdram_gbs\tdram_gbs_lo\tdram_gbs_hi\n");
    const double M = res->det_makespan;
    for (int seed = 1; seed <= o->seeds; seed++) {
        RunSpec ss = {.mode = RUN_SAMPLED, .cfg = cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = 1,
                      .sample_seed = (uint32_t)seed, .target_error = TARGET, .no_image = o->no_image};
        int bad = frame(r, sc, &ss, &fr, &s) != 0;
        if (!bad && (!fr.has_est || !fr.chip.on)) {
            fprintf(stderr, ME ": row %c: seed %d: no chip estimate\n", r->id, seed);
            bad = 1;
        }
        if (bad) {
            run_frame_free(&fr);
            return -1;
        }
        double e = fr.est.total / M - 1.0;
        int in = fr.est.lo <= M && M <= fr.est.hi;
        res->seeds++;
        res->covered += in;
        res->mean_abs += fabs(e);
        res->mean_signed += e;
        res->max_abs = fabs(e) > res->max_abs ? fabs(e) : res->max_abs;
        res->mean_units += fr.units_sampled;
        res->mean_seconds += s;
        buf_printf(tsv, "%d\t%.0f\t%.0f\t%.0f\t%+.4f\t%d\t%u\t%.5f\t%.5f\t%.5f\t%.3f", seed, fr.est.total, fr.est.lo,
                   fr.est.hi, 100.0 * e, in, fr.units_sampled, fr.chip.r, fr.chip.r_lo, fr.chip.r_hi, s);
        for (int m = 0; m < MEM_COUNT; m++) {
            const double *f;
            if (!samp_mem(&fr, m, &f) || res->det_mem[m] <= 0.0) {
                buf_printf(tsv, "\t-\t-\t-");
                continue;
            }
            const double em = f[0] / res->det_mem[m] - 1.0;
            res->mem_seeds[m]++;
            res->mem_covered[m] += f[1] <= res->det_mem[m] && res->det_mem[m] <= f[2];
            res->mem_abs[m] += fabs(em);
            res->mem_signed[m] += em;
            buf_printf(tsv, "\t%.6g\t%.6g\t%.6g", f[0], f[1], f[2]);
        }
        buf_printf(tsv, "\n");
        fprintf(stderr, ME ": row %c: seed %d: %+.3f %%, %s, %u units, %.1f s\n", r->id, seed, 100.0 * e,
                in ? "covered" : "NOT covered", fr.units_sampled, s);
        run_frame_free(&fr);
    }
    const double n = res->seeds;
    res->mean_abs /= n;
    res->mean_signed /= n;
    res->mean_units /= n;
    res->mean_seconds /= n;
    return 0;
}

/* One row: its table line in md, its memory figures' lines in mem_md, its seeds in tsv. 0, 1 (skipped: ../shared absent) or -1. */
static int row(const Row *r, const Opts *o, Buf *md, Buf *mem_md, Buf *tsv, int *skipped)
{
    int ok = bench_scene_ok(ME, r->scene, skipped);
    if (ok <= 0)
        return ok < 0 ? -1 : 1;
    CfgMachine cfg;
    if (row_machine(r, &cfg) != 0)
        return -1;
    static char err[65536];
    RunSize size = {r->width, r->height, r->spp, -1};
    RunScene sc;
    int rc = run_scene_open(&sc, r->scene, &size, &cfg, RUN_SAMPLED, NULL, err, sizeof err);
    if (rc != 0)
        fprintf(stderr, ME ": row %c: %s\n", r->id, err);
    Result res = {0};
    if (rc == 0)
        rc = row_runs(r, o, &sc, &cfg, &res, tsv);
    run_scene_close(&sc);
    if (rc != 0)
        return -1;
    char line[1024];
    snprintf(line, sizeof line,
             "| %c | %s %d x %d x %d | %d | %s | %.0f | %.1f | %d | %d (%.0f %%) | %.3f %% | %+.3f %% | %.3f %% | %.0f | "
             "%.1f | %.1fx |\n",
             r->id, r->frame, r->width, r->height, r->spp, r->cores, r->dram, res.det_makespan, res.det_seconds,
             res.seeds, res.covered, 100.0 * res.covered / res.seeds, 100.0 * res.mean_abs, 100.0 * res.mean_signed,
             100.0 * res.max_abs, res.mean_units, res.mean_seconds, res.det_seconds / res.mean_seconds);
    buf_printf(md, "%s", line);
    fputs(line, stdout);
    fflush(stdout);
    for (int m = 0; m < MEM_COUNT; m++) {
        const int n = res.mem_seeds[m];
        if (n)
            snprintf(line, sizeof line, "| %c | %s | %.6g | %d | %d (%.0f %%) | %.3f %% | %+.3f %% |\n", r->id,
                     mem_name[m], res.det_mem[m], n, res.mem_covered[m], 100.0 * res.mem_covered[m] / n,
                     100.0 * res.mem_abs[m] / n, 100.0 * res.mem_signed[m] / n);
        else
            snprintf(line, sizeof line, "| %c | %s | %.6g | 0 | - | - | - |\n", r->id, mem_name[m], res.det_mem[m]);
        buf_printf(mem_md, "%s", line);
        fputs(line, stdout);
    }
    fflush(stdout);
    return 0;
}

/* --rows a,b,...: 0, or -1 for a letter that names no row. */
static int parse_rows(const char *s, int pick[NROWS])
{
    memset(pick, 0, NROWS * sizeof pick[0]);
    int any = 0;
    for (const char *p = s; *p; p++) {
        if (*p == ',')
            continue;
        if (*p < 'a' || *p >= 'a' + NROWS)
            return -1;
        pick[*p - 'a'] = 1;
        any = 1;
    }
    return any ? 0 : -1;
}

static int usage(void)
{
    fprintf(stderr, "usage: " ME " [--seeds S] [--all] [--rows a,b,c,d] [--small] [--no-image] [OUTDIR]\n");
    return 2;
}

/* 0, or 2 after printing the usage. */
static int parse_args(int argc, char **argv, Opts *o)
{
    *o = (Opts){.outdir = "out/bench", .seeds = 100, .pick = {1, 1, 0, 0}};
    int all = 0, rows = 0;
    for (int i = 1; i < argc; i++) {
        char *end;
        if (!strcmp(argv[i], "--seeds") && i + 1 < argc) {
            long v = strtol(argv[++i], &end, 10);
            if (*end || v < 1 || v > 10000)
                return usage();
            o->seeds = (int)v;
        } else if (!strcmp(argv[i], "--rows") && i + 1 < argc) {
            if (parse_rows(argv[++i], o->pick) != 0)
                return usage();
            rows = 1;
        } else if (!strcmp(argv[i], "--all")) {
            all = 1;
        } else if (!strcmp(argv[i], "--small")) {
            o->small = 1;
        } else if (!strcmp(argv[i], "--no-image")) {
            o->no_image = 1;
        } else if (argv[i][0] == '-' || argv[i][0] == '\0') {
            return usage();
        } else {
            o->outdir = argv[i];
        }
    }
    if (all && !rows)
        for (int k = 0; k < NROWS; k++)
            o->pick[k] = 1;
    return 0;
}

/* Every file staged in one set, renamed into place together. 0, or -1 after printing why. */
static int write_outputs(const Opts *o, const Buf *md, Buf tsv[NROWS])
{
    char err[4200], path[4200];
    OutDirs dirs = {0};
    if (outfile_make_dirs(o->outdir, &dirs, err, sizeof err) != 0) {
        fprintf(stderr, ME ": %s\n", err);
        return -1;
    }
    OutSet *set = outset_new();
    int rc = set ? 0 : -1;
    snprintf(path, sizeof path, "%s/chip_error.md", o->outdir);
    if (rc == 0)
        rc = outfile_write_file(set, path, md->p, md->len, err, sizeof err);
    for (int k = 0; k < NROWS && rc == 0; k++) {
        if (!tsv[k].len)
            continue;
        snprintf(path, sizeof path, "%s/chip_error-%c.tsv", o->outdir, rows_full[k].id);
        rc = outfile_write_file(set, path, tsv[k].p, tsv[k].len, err, sizeof err);
    }
    if (rc == 0)
        rc = outset_commit(set, err, sizeof err);
    outset_free(set);
    if (rc != 0) {
        fprintf(stderr, ME ": %s\n", set ? err : "out of memory");
        outfile_remove_dirs(&dirs);
        return -1;
    }
    outfile_keep_dirs(&dirs);
    printf(ME ": wrote %s/chip_error.md\n", o->outdir);
    return 0;
}

int main(int argc, char **argv)
{
    Opts o;
    if (parse_args(argc, argv, &o) != 0)
        return 2;
    outfile_process_init();
    Buf md = {0}, mem_md = {0}, tsv[NROWS] = {{0}};
    buf_printf(&mem_md, "\nThe memory figures (a chip with shared memory; docs/sampling.md, step 8): each seed's "
                        "estimate against the detailed run's; covered: its 95 %% interval contains it.\n\n"
                        "| row | figure | detailed | seeds | covered | mean abs. error | signed mean error |\n"
                        "|---|---|---|---|---|---|---|\n");
    buf_printf(&md, "Sampled mode on a chip (`--target-error %.2f`%s, one host thread) against the chip's detailed "
                    "run of the same frame (one host thread), over sample seeds 1..%d%s. Error: the estimated "
                    "makespan over the detailed one, minus 1; covered: the 95 %% interval contains the detailed "
                    "makespan; speed-up: detailed host s over the mean sampled host s. stream.rays = 1024.\n\n",
               TARGET, o.no_image ? ", `--no-image`" : ", with the image", o.seeds,
               o.small ? " (--small: the Cornell box at 128 x 128 x 4)" : "");
    buf_printf(&md, "| row | frame | K | DRAM | detailed makespan | detailed host s | seeds | covered | mean abs. error | "
                    "signed mean error | largest abs. error | mean units timed | mean sampled host s | speed-up |\n"
                    "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    int skipped = 0, total = 0, rc = 0;
    for (int k = 0; k < NROWS && rc == 0; k++) {
        if (!o.pick[k])
            continue;
        Row r = rows_full[k];
        if (o.small) {
            r.scene = "scenes/cornell/scene.ini";
            r.frame = "cornell";
            r.width = r.height = 128;
            r.spp = 4;
        }
        total++;
        if (row(&r, &o, &md, &mem_md, &tsv[k], &skipped) < 0)
            rc = 1;
    }
    buf_printf(&md, "%s", mem_md.p ? mem_md.p : "");
    if (rc == 0 && (md.oom || mem_md.oom || tsv[0].oom || tsv[1].oom || tsv[2].oom || tsv[3].oom)) {
        fprintf(stderr, ME ": out of memory\n");
        rc = 1;
    }
    if (rc == 0 && write_outputs(&o, &md, tsv) != 0)
        rc = 1;
    bench_scenes_summary(ME, skipped, total);
    free(md.p);
    free(mem_md.p);
    for (int k = 0; k < NROWS; k++)
        free(tsv[k].p);
    return rc;
}
