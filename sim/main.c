/* sim/main.c -- the `sfsim` command line.
 *
 * Owns: argument parsing, exit codes and what is printed. Must not: simulate (it calls the
 * core, the config and the renderers). Exit codes: the EXIT_* of sim/exitcodes.def, nothing
 * else; an option value out of range is bad input (EXIT_INPUT), an unknown option or a missing
 * argument a usage error (EXIT_USAGE).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../asm/object.h"
#include "../host/version.h"
#include "config.h"
#include "core.h"
#include "datadir.h"
#include "exitcodes.h"
#include "exithelp.h"
#include "img.h"
#include "imglib.h"
#include "provenance.h"
#include "render.h"
#include "run/timedcore.h"
#include "stats.h"
#include "sweep/sweep.h"
#include "timing.h"
#include "trace.h"
#include "util.h"

static void usage(FILE *out)
{
    fprintf(out,
            "usage: sfsim <command> [options]\n"
            "\n"
            "sfsim simulates a stream-filtering ray tracing processor (Gribble & Ramani 2008).\n"
            "\n"
            "commands:\n"
            "  run      render a scene: --mode detailed (default: the kernel on the timed machine),\n"
            "           functional (the kernel, no timing) or reference (the golden model)\n"
            "  exec     run an assembled program (.sfo) on the functional core; print registers\n"
            "           and counters\n"
            "  config   list the machine-config keys (--dump) or write their reference (--markdown)\n"
            "  compare  compare two images: RMSE, PSNR, largest difference, NaN/Inf counts\n"
            "  trace    closest-hit / any-hit queries for a file of rays, through the kernel or the golden model\n"
            "  sweep    run a scene over many machine configs in parallel (sweep files, resumable; CSV, plots)\n"
            "  merge    build a sweep's CSV and plots from its point folders (after Slurm or GNU parallel)\n"
            "  help     help on a command (sfsim help exec), or on the exit codes (sfsim help exit-codes)\n"
            "\n"
            "options everywhere: --help, --version\n"
            "\n"
            "exit codes (every command; docs/exit-codes.md):\n");
    exithelp_print(out);
    fprintf(out, "\ndocumentation: docs/README.md\n");
}

static void usage_help(FILE *out)
{
    fprintf(out,
            "usage: sfsim help [COMMAND | exit-codes]\n"
            "\n"
            "Prints the help of COMMAND (run, exec, config, compare, trace, sweep, merge, help), the exit\n"
            "codes every command returns (exit-codes), or without an argument the list of commands.\n"
            "`sfsim COMMAND --help` prints the same as `sfsim help COMMAND`.\n");
}

static void usage_exit_codes(FILE *out)
{
    fprintf(out,
            "Exit codes of every sfsim and sfasm command (sim/exitcodes.def; docs/exit-codes.md):\n"
            "\n");
    exithelp_print(out);
}

static void usage_exec(FILE *out)
{
    fprintf(out,
            "usage: sfsim exec PROG.sfo [options]\n"
            "\n"
            "Runs an object produced by sfasm on the functional core until halt, a trap, or the\n"
            "instruction limit, then prints the scalar registers, the non-zero vector lanes, the\n"
            "masks and the counters per stage (instructions, operations by category, SIMD\n"
            "utilization = active lanes / (N x vector instructions)). With --timing the timing model\n"
            "runs beside it and the cycles are printed too: total, busy, stalls by cause, per stage,\n"
            "and the units' counters (docs/model.md).\n"
            "\n"
            "options:\n"
            "  -c, --config FILE        machine config (default: the built-in streamray machine)\n"
            "  --set SECTION.KEY=VALUE  override a config key (repeatable)\n"
            "  --width N                SIMD width, same as --set core.simd_width=N\n"
            "  --max-instructions N     instruction limit, same as --set sim.max_instructions=N\n"
            "  --dump-mem MEM:ADDR:WORDS  print WORDS words of MEM (rb0 rb1 idm spad scene fb) from\n"
            "                           byte address ADDR (a multiple of 4) after the run (repeatable)\n"
            "  -t, --timing             time the run on the machine of the config (detailed mode)\n"
            "  -q, --quiet              print only the summary line (and the timing, with --timing)\n"
            "  --no-progress            no progress line: a run still going after 2 s otherwise says on\n"
            "                           stderr, every 5 s, how many instructions it ran of the limit\n"
            "\n"
            "The --dump-mem specs are checked against the config's memory sizes before the program runs.\n"
            "Exit codes: 0 halted, 1 bad input (config, object, --dump-mem spec), 2 usage, 3 trap or the\n"
            "instruction limit (sfsim help exit-codes).\n");
}

static void usage_config(FILE *out)
{
    fprintf(out,
            "usage: sfsim config (--dump | --markdown) [-c FILE] [--set SECTION.KEY=VALUE]...\n"
            "\n"
            "  --dump       every key with its value, type, default, range and help\n"
            "  --markdown   the key reference as Markdown (docs/config.md is this output)\n");
}

static void usage_run(FILE *out)
{
    fprintf(out,
            "usage: sfsim run [-s SCENE] [-o DIR] [-c CONFIG] [--mode detailed|sampled|functional|reference] [options]\n"
            "\n"
            "Renders SCENE (a .gltf/.glb file or a scene.ini) and writes DIR/frame.exr (linear),\n"
            "DIR/frame.png (tone-mapped sRGB), DIR/report.json and DIR/report.txt, and in detailed\n"
            "mode DIR/cost.png (simulated cycles per pixel, per tile). docs/report.md lists the fields.\n"
            "\n"
            "modes:\n"
            "  detailed    (default) the path-tracing kernel (kernels/pathtrace.s) on the functional core\n"
            "              with the cycle-accurate timing model of the machine in CONFIG: cycles, fps,\n"
            "              stalls by cause, per stage, generation and tile, the units' counters\n"
            "              (docs/model.md); the same image bits as functional mode\n"
            "  sampled     the golden model renders the image (the same bits) and counts every (tile, pass)\n"
            "              unit's work; a seeded random sample of the units runs on the timed kernel and the\n"
            "              rest are skipped; cycles, instructions and fps estimated with 95%% confidence\n"
            "              intervals (docs/sampling.md): by default until the cycles are known to +-1%%\n"
            "  functional  the kernel executed instruction by instruction, no timing (fastest\n"
            "              simulation): operation mix, SIMD utilization and stream lengths per stage\n"
            "  reference   the golden model: a plain C path tracer over the packed scene memory\n"
            "\n"
            "options:\n"
            "  -s, --scene FILE         scene (default: the shipped Cornell box, scenes/cornell/scene.ini\n"
            "                           in sfsim's data folder, found beside the binary: docs/install.md)\n"
            "  -o, --out DIR            output folder (default: out): checked before any work, made when the\n"
            "                           outputs are written, each file whole or not at all (exit 4 if not;\n"
            "                           docs/report.md)\n"
            "  -c, --config FILE        machine config (stream.rays sets the tile: sqrt(M) pixels)\n"
            "  --set SECTION.KEY=VALUE  override a config key, or render.width, render.height,\n"
            "                           render.spp, render.max_depth, render.seed\n"
            "  -j, --threads N          host threads (default: all cores; results do not change)\n"
            "  --exposure X             scale before tone mapping frame.png (default 1)\n"
            "  --no-progress            no progress bar (it is shown only on a terminal anyway)\n"
            "  --target-error E         sampled mode: time units until the 95%% interval of the cycles is\n"
            "                           within +-E (a fraction: 0.01 = 1%%, the default), or every unit\n"
            "  --sample F               sampled mode: time a fixed fraction F of the units, (0, 1], instead\n"
            "  --sample-seed S          sampled mode: which units (default 1)\n"
            "  --no-image               sampled mode: no image; the golden model runs only a pilot pass per\n"
            "                           tile for the units' counts (the estimate alone, fastest)\n"
            "  --kernel FILE            kernel modes: the kernel source (default:\n"
            "                           kernels/pathtrace.s in the data folder, or $SFSIM_KERNEL)\n");
}

/* Config from -c/--set options, collected by the commands that take them. */
typedef struct ConfigArgs {
    const char *path;
    const char *sets[256];
    int nsets;
} ConfigArgs;

static int build_config(const ConfigArgs *a, CfgMachine *cfg)
{
    CfgErrors errs = {0};
    cfg_defaults(cfg);
    if (a->path)
        cfg_load(cfg, a->path, &errs);
    for (int i = 0; i < a->nsets; i++)
        cfg_set(cfg, a->sets[i], &errs);
    if (!errs.count)
        cfg_check(cfg, &errs);
    if (errs.count) {
        fprintf(stderr, "%s", errs.text);
        fprintf(stderr, "sfsim: %d configuration error%s\n", errs.count, errs.count == 1 ? "" : "s");
    }
    int n = errs.count;
    cfg_errors_free(&errs);
    return n ? -1 : 0;
}

static int add_set(ConfigArgs *a, const char *s)
{
    if (a->nsets >= (int)(sizeof a->sets / sizeof a->sets[0])) {
        fprintf(stderr, "sfsim: too many --set options (at most %zu)\n", sizeof a->sets / sizeof a->sets[0]);
        return -1;
    }
    a->sets[a->nsets++] = s;
    return 0;
}

static void print_float_of(uint32_t u, char *buf, size_t len)
{
    float f;
    memcpy(&f, &u, 4);
    snprintf(buf, len, "%.9g", (double)f);
}

/* One --dump-mem MEM:ADDR:WORDS, checked against the configured memory sizes before the program
 * runs (a typo must not cost a long run). */
typedef struct MemDump {
    const char *spec;
    CoreMem mem;
    uint32_t addr, words;
} MemDump;

/* A number of a --dump-mem spec: decimal, 0x hex or 0 octal, nothing else after it but `stop`. */
static int dump_number(const char *s, char stop, unsigned long long *out, const char **rest)
{
    char *end;
    errno = 0;
    if (*s == '-' || *s == '+' || *s == ' ')
        return -1;
    unsigned long long v = strtoull(s, &end, 0);
    if (end == s || errno || *end != stop)
        return -1;
    *out = v;
    *rest = end;
    return 0;
}

static int dump_parse(const char *spec, const CoreParams *cp, MemDump *d)
{
    const char *colon = strchr(spec, ':'), *rest;
    unsigned long long addr, words;
    if (!colon || dump_number(colon + 1, ':', &addr, &rest) || dump_number(rest + 1, '\0', &words, &rest)) {
        fprintf(stderr, "sfsim exec: --dump-mem %s: expected MEM:ADDR:WORDS, e.g. spad:0x40:8 (sfsim help exec)\n",
                spec);
        return -1;
    }
    int m = -1;
    for (int i = 0; i < CORE_MEM_COUNT; i++)
        if (strlen(core_mem_names[i]) == (size_t)(colon - spec) && !strncmp(spec, core_mem_names[i], (size_t)(colon - spec)))
            m = i;
    if (m < 0) {
        fprintf(stderr, "sfsim exec: --dump-mem %s: unknown memory '%.*s' (rb0 rb1 idm spad scene fb)\n", spec,
                (int)(colon - spec), spec);
        return -1;
    }
    uint64_t size = cp->mem_bytes[m];
    if (addr % 4) {
        fprintf(stderr, "sfsim exec: --dump-mem %s: address 0x%llx is not a multiple of 4 (words are 4 bytes)\n",
                spec, addr);
        return -1;
    }
    if (addr > size || words > (size - addr) / 4) {
        fprintf(stderr, "sfsim exec: --dump-mem %s: %llu word%s from 0x%llx end%s beyond %s (%llu bytes in this config)\n",
                spec, words, words == 1 ? "" : "s", addr, words == 1 ? "s" : "", core_mem_names[m],
                (unsigned long long)size);
        return -1;
    }
    *d = (MemDump){spec, (CoreMem)m, (uint32_t)addr, (uint32_t)words};
    return 0;
}

static void dump_print(Core *c, const MemDump *d)
{
    uint32_t size;
    uint8_t *mem = core_mem(c, d->mem, &size);
    printf("%s from 0x%08x:\n", core_mem_names[d->mem], d->addr);
    for (uint32_t i = 0; i < d->words && d->addr + 4ull * i + 4 <= size; i++) {
        uint32_t w;
        memcpy(&w, mem + d->addr + 4 * i, 4);
        char f[32];
        print_float_of(w, f, sizeof f);
        printf("  [0x%08x] 0x%08x %11d  %s\n", d->addr + 4 * i, w, (int32_t)w, f);
    }
}

/* Run to halt, trap or the instruction limit in slices, so that a long run can say how far it is:
 * after `after` seconds (SFSIM_PROGRESS_AFTER, default 2; 0 reports after every slice) and then
 * every 5 s, one line on stderr. stdout is the same with or without it. */
static CoreExit run_with_progress(Core *c, uint64_t limit, int progress)
{
    enum { SLICE = 1 << 20 };
    double after = 2.0;
    const char *env = getenv("SFSIM_PROGRESS_AFTER");
    if (env && *env) {
        char *end;
        double v = strtod(env, &end);
        if (!*end && v >= 0.0 && isfinite(v))
            after = v;
    }
    double t0 = util_now(), next = t0 + after;
    uint64_t done = 0;
    for (;;) {
        uint64_t slice = limit - done < SLICE ? limit - done : SLICE;
        CoreExit ex = core_run_slice(c, slice, limit);
        done += slice;
        if (ex != CORE_EXIT_LIMIT || done >= limit)
            return ex;
        double t = util_now();
        if (progress && t >= next) {
            uint64_t n = core_instructions(c);
            fprintf(stderr, "sfsim exec: still running after %.0f s: %llu instructions of the limit %llu "
                    "(sim.max_instructions; --max-instructions N sets it)\n", t - t0, (unsigned long long)n,
                    (unsigned long long)limit);
            next = t + (after > 0.0 ? 5.0 : 0.0);
        }
    }
}

static void print_state(Core *c)
{
    int n = core_lanes(c);
    printf("scalar registers:\n");
    for (int r = 0; r < ISA_NUM_SREGS; r++) {
        uint32_t v = core_sreg(c, r);
        if (!v)
            continue;
        char f[32];
        print_float_of(v, f, sizeof f);
        printf("  r%-2d = 0x%08x %11d  float %s\n", r, v, (int32_t)v, f);
    }
    printf("vector registers (lanes 0..%d; registers with every lane 0 left out):\n", n - 1);
    for (int v = 0; v < ISA_NUM_VREGS; v++) {
        int any = 0;
        for (int l = 0; l < n; l++)
            any |= core_vreg(c, v, l) != 0;
        if (!any)
            continue;
        printf("  v%-2d =", v);
        for (int l = 0; l < n; l++)
            printf("%s%x", l ? " " : " ", core_vreg(c, v, l));
        printf("\n");
    }
    printf("masks (lane 0 first):\n");
    for (int m = 0; m < ISA_NUM_MREGS; m++) {
        printf("  m%d = ", m);
        uint64_t x = core_mreg(c, m);
        for (int l = 0; l < n; l++)
            putchar((x >> l) & 1 ? '1' : '0');
        putchar('\n');
    }
    const CoreStats *st = core_stats(c);
    printf("counters per stage:\n  %-13s %12s %12s %6s", "stage", "instructions", "vector", "util");
    for (int k = 0; k < ISA_C_COUNT; k++)
        printf(" %14s", isa_category_keys[k]);
    printf("\n");
    for (int s = 0; s < ISA_STAGE_COUNT; s++) {
        if (!st->instructions[s])
            continue;
        double util = stats_utilization(st, n, s);
        printf("  %-13s %12llu %12llu %5.1f%%", isa_stage_keys[s], (unsigned long long)st->instructions[s],
               (unsigned long long)st->vec_instructions[s], 100.0 * util);
        for (int k = 0; k < ISA_C_COUNT; k++)
            printf(" %14llu", (unsigned long long)st->ops[s][k]);
        printf("\n");
    }
}

/* The timing of one `exec --timing` run (or a detailed trace) from the statistics registry
 * (sim/stats.def); non-zero when the model failed its own check. */
static int print_timing(const TimingStats *s, const CfgMachine *cfg, const char *model_err)
{
    StatsCtx sx = {.mode = STATS_M_EXEC, .cfg = cfg, .t = s};
    stats_print_exec(stdout, &sx);
    char err[256];
    if (model_err || timing_check(s, err, sizeof err)) {
        fprintf(stderr, "sfsim exec: %s\n", model_err ? model_err : err);
        return -1;
    }
    return 0;
}

static int cmd_exec(int argc, char **argv)
{
    ConfigArgs ca = {0};
    const char *prog = NULL, *dumps[64];
    int ndumps = 0, quiet = 0, timed = 0, progress = 1;
    char setbuf[2][64];
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int has_next = i + 1 < argc;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage_exec(stdout);
            return EXIT_OK;
        } else if ((!strcmp(a, "-c") || !strcmp(a, "--config")) && has_next) {
            ca.path = argv[++i];
        } else if (!strcmp(a, "--set") && has_next) {
            if (add_set(&ca, argv[++i]))
                return EXIT_USAGE;
        } else if (!strcmp(a, "--width") && has_next) {
            snprintf(setbuf[0], sizeof setbuf[0], "core.simd_width=%s", argv[++i]);
            if (add_set(&ca, setbuf[0]))
                return EXIT_USAGE;
        } else if (!strcmp(a, "--max-instructions") && has_next) {
            snprintf(setbuf[1], sizeof setbuf[1], "sim.max_instructions=%s", argv[++i]);
            if (add_set(&ca, setbuf[1]))
                return EXIT_USAGE;
        } else if (!strcmp(a, "--dump-mem") && has_next) {
            if (ndumps >= 64) {
                fprintf(stderr, "sfsim exec: at most 64 --dump-mem options\n");
                return EXIT_USAGE;
            }
            dumps[ndumps++] = argv[++i];
        } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet")) {
            quiet = 1;
        } else if (!strcmp(a, "-t") || !strcmp(a, "--timing")) {
            timed = 1;
        } else if (!strcmp(a, "--no-progress")) {
            progress = 0;
        } else if (a[0] == '-') {
            fprintf(stderr, "sfsim exec: unknown option or missing value: %s (sfsim help exec)\n", a);
            return EXIT_USAGE;
        } else if (!prog) {
            prog = a;
        } else {
            fprintf(stderr, "sfsim exec: more than one program: %s and %s\n", prog, a);
            return EXIT_USAGE;
        }
    }
    if (!prog) {
        fprintf(stderr, "sfsim exec: no program given (sfsim help exec)\n");
        return EXIT_USAGE;
    }
    CfgMachine cfg;
    if (build_config(&ca, &cfg))
        return EXIT_INPUT;
    CoreParams cp;
    cfg_core_params(&cfg, &cp);
    MemDump dd[64];
    for (int i = 0; i < ndumps; i++)
        if (dump_parse(dumps[i], &cp, &dd[i]))
            return EXIT_INPUT;
    AsmObject obj;
    char err[1024];
    if (asm_object_read(prog, &obj, err, sizeof err) != 0) {
        fprintf(stderr, "sfsim exec: %s\n", err);
        return EXIT_INPUT;
    }
    TimedCore tc;
    int orc = timedcore_open(&tc, &cfg, &obj, timed, err, sizeof err);
    if (orc != 0) {
        if (orc == -2)
            fprintf(stderr, "sfsim exec: %s\n", err);
        else
            fprintf(stderr, "sfsim exec: %s: %s\n", prog, err);
        asm_object_free(&obj);
        return EXIT_INPUT;
    }
    Core *c = tc.core;
    Timing *tm = tc.tm;
    double t0 = util_now();
    CoreExit ex = run_with_progress(c, (uint64_t)cfg.sim_max_instructions, progress);
    double secs = util_now() - t0;
    if (tm)
        timing_end(tm);
    uint64_t ni = core_instructions(c);
    printf("sfsim exec: %s on N = %d lanes: %s after %llu instructions (%.3f s, %.1f M instructions/s)\n", prog,
           core_lanes(c), ex == CORE_EXIT_HALT ? "halted" : ex == CORE_EXIT_TRAP ? "trapped" : "stopped at the limit",
           (unsigned long long)ni, secs, secs > 0 ? 1e-6 * (double)ni / secs : 0.0);
    int rc = EXIT_OK;
    if (!quiet)
        print_state(c);
    for (int i = 0; i < ndumps; i++)
        dump_print(c, &dd[i]);
    if (tm) {
        if (print_timing(timing_stats(tm), &cfg, timing_error(tm)))
            rc = EXIT_PROGRAM;
    }
    if (ex == CORE_EXIT_LIMIT) {
        fprintf(stderr, "sfsim exec: %s\n", core_trap_message(c));
        rc = EXIT_PROGRAM;
    } else if (ex != CORE_EXIT_HALT) {
        fprintf(stderr, "sfsim exec: %s\n", core_trap_message(c));
        rc = EXIT_PROGRAM;
    }
    timedcore_close(&tc);
    asm_object_free(&obj);
    return rc;
}

static int cmd_config(int argc, char **argv)
{
    ConfigArgs ca = {0};
    int dump = 0, markdown = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage_config(stdout);
            return EXIT_OK;
        } else if (!strcmp(a, "--dump")) {
            dump = 1;
        } else if (!strcmp(a, "--markdown")) {
            markdown = 1;
        } else if ((!strcmp(a, "-c") || !strcmp(a, "--config")) && i + 1 < argc) {
            ca.path = argv[++i];
        } else if (!strcmp(a, "--set") && i + 1 < argc) {
            if (add_set(&ca, argv[++i]))
                return EXIT_USAGE;
        } else {
            fprintf(stderr, "sfsim config: unknown option or missing value: %s (sfsim help config)\n", a);
            return EXIT_USAGE;
        }
    }
    if (dump == markdown) {
        usage_config(stderr);
        return EXIT_USAGE;
    }
    if (markdown) {
        cfg_markdown(stdout);
        return EXIT_OK;
    }
    CfgMachine cfg;
    if (build_config(&ca, &cfg))
        return EXIT_INPUT;
    cfg_dump(&cfg, stdout);
    return EXIT_OK;
}

static void usage_compare(FILE *out)
{
    fprintf(out,
            "usage: sfsim compare A B\n"
            "\n"
            "Compares two images of the same size (any format OpenImageIO reads; EXR compares linear\n"
            "radiance, PNG the stored 0..1 values) and prints RMSE, PSNR (peak 1), the largest channel\n"
            "difference, both means and the NaN/Inf counts. The values are compared as stored, never\n"
            "converted: a linear image (EXR, HDR, PFM) against a display image (PNG, JPEG) gets a warning\n"
            "on stderr, since PNG's values are sRGB-encoded, exposure-scaled and clamped. Exit 0 when it\n"
            "could compare, 1 when an image cannot be read or the sizes differ, 4 when sfsim's image library\n"
            "does not load.\n");
}

static int cmd_compare(int argc, char **argv)
{
    if (argc == 1 && (!strcmp(argv[0], "--help") || !strcmp(argv[0], "-h"))) {
        usage_compare(stdout);
        return EXIT_OK;
    }
    if (argc != 2 || argv[0][0] == '-' || argv[1][0] == '-') {
        usage_compare(stderr);
        return EXIT_USAGE;
    }
    float *a = NULL, *b = NULL;
    int wa, ha, wb, hb;
    char err[8192];
    /* A missing or broken image library is sfsim's fault, not the images': EXIT_IO as for run. */
    if (!imglib_get(err, sizeof err)) {
        fprintf(stderr, "sfsim compare: %s\n", err);
        return EXIT_IO;
    }
    int rc = EXIT_INPUT;
    if (img_read(argv[0], &a, &wa, &ha, err, sizeof err) != 0 || img_read(argv[1], &b, &wb, &hb, err, sizeof err) != 0) {
        fprintf(stderr, "sfsim compare: %s\n", err);
    } else if (wa != wb || ha != hb) {
        fprintf(stderr, "sfsim compare: sizes differ: %s is %d x %d, %s is %d x %d\n", argv[0], wa, ha, argv[1], wb, hb);
    } else {
        ImgEncoding ea = img_encoding(argv[0]), eb = img_encoding(argv[1]);
        if (ea != eb && ea != IMG_ENC_UNKNOWN && eb != IMG_ENC_UNKNOWN)
            fprintf(stderr,
                    "sfsim compare: warning: %s holds %s and %s %s: the figures below compare different encodings, "
                    "not the renders (compare frame.exr with frame.exr, or frame.png with frame.png)\n",
                    argv[0], ea == IMG_ENC_LINEAR ? "linear radiance" : "display values (sRGB-encoded, clamped to 0..1)",
                    argv[1], eb == IMG_ENC_LINEAR ? "linear radiance" : "display values (sRGB-encoded, clamped to 0..1)");
        ImgCompare c;
        img_compare(a, b, wa, ha, &c);
        printf("%s vs %s (%d x %d)\n", argv[0], argv[1], wa, ha);
        printf("  RMSE        %.6g\n  PSNR        %.2f dB\n  max diff    %.6g\n", c.rmse, c.psnr, c.max_abs);
        printf("  mean        %.6g vs %.6g\n  NaN/Inf     %ld vs %ld\n", c.mean_a, c.mean_b, c.nan_a, c.nan_b);
        rc = EXIT_OK;
    }
    free(a);
    free(b);
    return rc;
}

/* An integer option value in lo..hi; a bad value is bad input (EXIT_INPUT), said by the caller. */
static int parse_int(const char *cmd, const char *opt, const char *s, long lo, long hi, long *out)
{
    long long v;
    if (util_parse_int(s, lo, hi, &v)) {
        fprintf(stderr, "sfsim %s: %s %s: expected an integer in %ld..%ld\n", cmd, opt, s, lo, hi);
        return -1;
    }
    *out = (long)v;
    return 0;
}

static int cmd_run(int argc, char **argv)
{
    ConfigArgs ca = {0};
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = NULL; /* default: the shipped Cornell box, found beside the binary */
    o.out_dir = "out";
    o.progress = isatty(2);
    const char *mode = "detailed";
    int sample_given = 0, target_given = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int has_next = i + 1 < argc;
        long v;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage_run(stdout);
            return EXIT_OK;
        } else if ((!strcmp(a, "-s") || !strcmp(a, "--scene")) && has_next) {
            o.scene_path = argv[++i];
        } else if ((!strcmp(a, "-o") || !strcmp(a, "--out")) && has_next) {
            o.out_dir = argv[++i];
        } else if ((!strcmp(a, "-c") || !strcmp(a, "--config")) && has_next) {
            ca.path = argv[++i];
        } else if (!strcmp(a, "--mode") && has_next) {
            mode = argv[++i];
        } else if ((!strcmp(a, "-j") || !strcmp(a, "--threads")) && has_next) {
            if (parse_int("run", a, argv[++i], 1, 1024, &v))
                return EXIT_INPUT;
            o.threads = (int)v;
        } else if (!strcmp(a, "--exposure") && has_next) {
            char *end;
            o.exposure = strtof(argv[++i], &end);
            if (end == argv[i] || *end || !isfinite(o.exposure) || !(o.exposure > 0.0f)) {
                fprintf(stderr, "sfsim run: --exposure %s: expected a finite positive number (a float)\n", argv[i]);
                return EXIT_INPUT;
            }
        } else if (!strcmp(a, "--sample") && has_next) {
            char *end;
            o.sample = strtod(argv[++i], &end);
            if (*end || !(o.sample > 0.0 && o.sample <= 1.0)) {
                fprintf(stderr, "sfsim run: --sample %s: expected a fraction of the units in (0, 1], e.g. 0.05\n",
                        argv[i]);
                return EXIT_INPUT;
            }
            sample_given = 1;
        } else if (!strcmp(a, "--target-error") && has_next) {
            char *end;
            o.target_error = strtod(argv[++i], &end);
            if (end == argv[i] || *end || !(o.target_error > 0.0 && o.target_error < 1.0)) {
                fprintf(stderr, "sfsim run: --target-error %s: expected a fraction in (0, 1), e.g. 0.01 for +-1%%\n",
                        argv[i]);
                return EXIT_INPUT;
            }
            target_given = 1;
        } else if (!strcmp(a, "--no-image")) {
            o.no_image = 1;
        } else if (!strcmp(a, "--sample-seed") && has_next) {
            if (parse_int("run", a, argv[++i], 0, 4294967295L, &v))
                return EXIT_INPUT;
            o.sample_seed = (uint32_t)v;
        } else if (!strcmp(a, "--no-progress")) {
            o.progress = 0;
        } else if (!strcmp(a, "--kernel") && has_next) {
            o.kernel_path = argv[++i];
        } else if (!strcmp(a, "--set") && has_next) {
            const char *s = argv[++i];
            int handled = 0;
            for (int k = 0; k < RENDER_KEY_COUNT; k++) {
                size_t kl = strlen(render_keys[k].key);
                if (strncmp(s, render_keys[k].key, kl) != 0 || s[kl] != '=')
                    continue;
                char opt[64];
                snprintf(opt, sizeof opt, "--set %s =", render_keys[k].key);
                if (parse_int("run", opt, s + kl + 1, (long)render_keys[k].lo, (long)render_keys[k].hi, &v))
                    return EXIT_INPUT;
                if (k == RENDER_KEY_WIDTH) o.width = (int)v;
                if (k == RENDER_KEY_HEIGHT) o.height = (int)v;
                if (k == RENDER_KEY_SPP) o.spp = (int)v;
                if (k == RENDER_KEY_MAX_DEPTH) o.max_depth = (int)v;
                if (k == RENDER_KEY_SEED) o.seed = (uint32_t)v;
                handled = 1;
            }
            if (!handled && add_set(&ca, s))
                return EXIT_USAGE;
        } else {
            fprintf(stderr, "sfsim run: unknown option or missing value: %s (sfsim help run)\n", a);
            return EXIT_USAGE;
        }
    }
    if (strcmp(mode, "reference") != 0 && strcmp(mode, "functional") != 0 && strcmp(mode, "detailed") != 0 &&
        strcmp(mode, "sampled") != 0) {
        fprintf(stderr, "sfsim run: --mode %s: expected detailed, sampled, functional or reference (sfsim help run)\n",
                mode);
        return EXIT_INPUT;
    }
    if ((sample_given || target_given || o.no_image) && strcmp(mode, "sampled") != 0) {
        fprintf(stderr, "sfsim run: --sample, --target-error and --no-image apply to --mode sampled only "
                        "(sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (sample_given && target_given) {
        fprintf(stderr, "sfsim run: --sample F (a fixed fraction) and --target-error E (as many units as E needs) "
                        "exclude each other (sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (sample_given)
        o.target_error = 0.0; /* the fixed-size design */
    o.mode = mode;
    static char default_scene[4096];
    if (!o.scene_path) {
        char derr[8192];
        if (!datadir_path(DATADIR_DEFAULT_SCENE, default_scene, sizeof default_scene, derr, sizeof derr)) {
            fprintf(stderr, "sfsim run: no -s SCENE given and the default scene is missing: %s\n", derr);
            return EXIT_INPUT;
        }
        o.scene_path = default_scene;
    }
    CfgMachine cfg;
    if (build_config(&ca, &cfg))
        return EXIT_INPUT;
    o.cfg = &cfg;
    o.config_path = ca.path;
    static char err[65536];
    /* The images a run writes (frame.exr, frame.png, cost.png, frame.partial.exr) go through
     * OpenEXR, libpng and FreeType linked into this binary (sim/img_write.c, sim/heatmap.c): a run
     * never loads the image library, OpenImageIO's reader (docs/performance.md, "Start-up"). */
    int rrc = render_run(&o, err, sizeof err);
    if (rrc != 0) {
        fprintf(stderr, "sfsim run: %s\n", err);
        /* -3: an output could not be written (trace_run's convention, for render_run's writers) */
        return rrc == -2 ? EXIT_PROGRAM : rrc == -3 ? EXIT_IO : EXIT_INPUT;
    }
    printf("sfsim run: wrote %s/%sreport.txt, report.json%s\n", o.out_dir, o.no_image ? "" : "frame.png, frame.exr, ",
           !strcmp(mode, "detailed") || !strcmp(mode, "sampled") ? ", cost.png" : "");
    return EXIT_OK;
}

static void usage_trace(FILE *out)
{
    fprintf(out,
            "usage: sfsim trace -s SCENE --rays FILE -o HITS [options]\n"
            "\n"
            "Traces each ray of FILE (text or binary, docs/trace.md) against SCENE and writes its closest hit\n"
            "(distance, primitive, barycentrics) or miss, or for any-hit rays whether it is occluded, to HITS.\n"
            "\n"
            "options:\n"
            "  --mode functional|detailed|reference  the kernel's traversal and intersection on the\n"
            "                           functional core (default), the same timed on the machine of the\n"
            "                           config (prints cycles and stalls by cause), or the golden model's\n"
            "  -c, --config FILE        machine config; --set SECTION.KEY=VALUE overrides a key\n"
            "  --binary                 write HITS in the binary format (default: text)\n"
            "  -j, --threads N          host threads (default: all cores; results do not change)\n"
            "  --kernel FILE            the kernel source (default: kernels/pathtrace.s beside the binary)\n");
}

static int cmd_trace(int argc, char **argv)
{
    ConfigArgs ca = {0};
    TraceOptions o;
    memset(&o, 0, sizeof o);
    o.mode = "functional";
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int has_next = i + 1 < argc;
        long v;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage_trace(stdout);
            return EXIT_OK;
        } else if ((!strcmp(a, "-s") || !strcmp(a, "--scene")) && has_next) {
            o.scene_path = argv[++i];
        } else if (!strcmp(a, "--rays") && has_next) {
            o.rays_path = argv[++i];
        } else if ((!strcmp(a, "-o") || !strcmp(a, "--out")) && has_next) {
            o.out_path = argv[++i];
        } else if (!strcmp(a, "--mode") && has_next) {
            o.mode = argv[++i];
        } else if ((!strcmp(a, "-c") || !strcmp(a, "--config")) && has_next) {
            ca.path = argv[++i];
        } else if (!strcmp(a, "--set") && has_next) {
            if (add_set(&ca, argv[++i]))
                return EXIT_USAGE;
        } else if (!strcmp(a, "--binary")) {
            o.binary = 1;
        } else if ((!strcmp(a, "-j") || !strcmp(a, "--threads")) && has_next) {
            if (parse_int("trace", a, argv[++i], 1, 1024, &v))
                return EXIT_INPUT;
            o.threads = (int)v;
        } else if (!strcmp(a, "--kernel") && has_next) {
            o.kernel_path = argv[++i];
        } else {
            fprintf(stderr, "sfsim trace: unknown option or missing value: %s (sfsim help trace)\n", a);
            return EXIT_USAGE;
        }
    }
    if (!o.scene_path || !o.rays_path || !o.out_path) {
        fprintf(stderr, "sfsim trace: -s SCENE, --rays FILE and -o HITS are required (sfsim help trace)\n");
        return EXIT_USAGE;
    }
    if (strcmp(o.mode, "functional") != 0 && strcmp(o.mode, "reference") != 0 && strcmp(o.mode, "detailed") != 0) {
        fprintf(stderr, "sfsim trace: --mode %s: expected functional, detailed or reference\n", o.mode);
        return EXIT_INPUT;
    }
    if (o.threads == 0)
        o.threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    CfgMachine cfg;
    if (build_config(&ca, &cfg))
        return EXIT_INPUT;
    o.cfg = &cfg;
    static char err[65536];
    TraceSummary sum;
    int rc = trace_run(&o, &sum, err, sizeof err);
    if (rc != 0) {
        fprintf(stderr, "sfsim trace: %s\n", err);
        return rc == -2 ? EXIT_PROGRAM : rc == -3 ? EXIT_IO : EXIT_INPUT;
    }
    printf("sfsim trace: %u rays (%s): %u hits, %u misses, %u occluded, %u clear, %u invalid; %.3f s",
           sum.rays, o.mode, sum.hits, sum.misses, sum.occluded, sum.clear, sum.invalid, sum.seconds);
    if (sum.sim_instructions)
        printf(", %llu simulated instructions", (unsigned long long)sum.sim_instructions);
    printf("; wrote %s\n", o.out_path);
    if (sum.timed && print_timing(&sum.timing, &cfg, NULL))
        return EXIT_PROGRAM;
    return EXIT_OK;
}

static int dispatch(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
        usage(stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("sfsim %s (commit %s)\n", version_string(), version_commit());
        return EXIT_OK;
    }
    if (!strcmp(cmd, "help")) {
        if (argc > 3) {
            fprintf(stderr, "sfsim help: one topic at a time, not '%s %s' (sfsim help help)\n", argv[2], argv[3]);
            return EXIT_USAGE;
        }
        if (argc < 3)
            usage(stdout);
        else if (!strcmp(argv[2], "help") || !strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))
            usage_help(stdout);
        else if (!strcmp(argv[2], "exit-codes"))
            usage_exit_codes(stdout);
        else if (!strcmp(argv[2], "exec"))
            usage_exec(stdout);
        else if (!strcmp(argv[2], "config"))
            usage_config(stdout);
        else if (!strcmp(argv[2], "run"))
            usage_run(stdout);
        else if (!strcmp(argv[2], "compare"))
            usage_compare(stdout);
        else if (!strcmp(argv[2], "trace"))
            usage_trace(stdout);
        else if (!strcmp(argv[2], "sweep"))
            sweep_usage(stdout);
        else if (!strcmp(argv[2], "merge"))
            merge_usage(stdout);
        else {
            fprintf(stderr, "sfsim help: unknown command '%s' (sfsim help help)\n", argv[2]);
            return EXIT_USAGE;
        }
        return EXIT_OK;
    }
    if (!strcmp(cmd, "exec"))
        return cmd_exec(argc - 2, argv + 2);
    if (!strcmp(cmd, "config"))
        return cmd_config(argc - 2, argv + 2);
    if (!strcmp(cmd, "run"))
        return cmd_run(argc - 2, argv + 2);
    if (!strcmp(cmd, "compare"))
        return cmd_compare(argc - 2, argv + 2);
    if (!strcmp(cmd, "trace"))
        return cmd_trace(argc - 2, argv + 2);
    if (!strcmp(cmd, "sweep"))
        return sweep_main(argc - 2, argv + 2);
    if (!strcmp(cmd, "merge"))
        return merge_main(argc - 2, argv + 2);
    fprintf(stderr, "sfsim: unknown command '%s'\n\n", cmd);
    usage(stderr);
    return EXIT_USAGE;
}

int main(int argc, char **argv)
{
    prov_set_command(argc, argv);   /* what made the run, for its reports (sim/provenance.h) */
    int rc = dispatch(argc, argv);
    /* What went to stdout (a config dump, help, registers, the summary) is an output too: a full
     * disk or closed pipe must not pass for success. */
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "sfsim: cannot write to standard output: %s\n", strerror(errno ? errno : EIO));
        if (rc == EXIT_OK)
            rc = EXIT_IO;
    }
    /* With the image library loaded (`sfsim compare`: a run never loads it), end without exit's
     * clean-up: it would run the destructors of OpenImageIO's ~265 libraries (~8 ms of CPU:
     * docs/performance.md, "Start-up"). sfsim registers nothing to run at exit, its outputs are
     * written and closed by now, stdout is flushed above and stderr unbuffered. */
    if (imglib_dlopened()) {
        fflush(NULL);
        _exit(rc);
    }
    return rc;
}
