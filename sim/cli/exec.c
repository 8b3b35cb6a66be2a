/* sim/cli/exec.c -- the command `sfsim exec`: run an assembled program on the functional core (and
 * the timing model with --timing), then print its registers, memory words and counters.
 *
 * Owns: exec's options, the --dump-mem specs (checked against the config's memory sizes before the
 * program runs), the progress line of a long run, and the print-outs. Must not: simulate (the
 * core and the timing model do) or decide exit codes other than sim/exitcodes.def's.
 */
#include "exec.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/object.h"
#include "../core.h"
#include "../exitcodes.h"
#include "../run/timedcore.h"
#include "../stats.h"
#include "../timeline.h"
#include "../timing.h"
#include "../../host/outfile.h"
#include "../util.h"
#include "help.h"
#include "opts.h"

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
int cli_print_timing(const TimingStats *s, const CfgMachine *cfg, const char *model_err)
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

/* exec's options: its getopt_long table. */
enum { X_SET = CLI_LONG, X_WIDTH, X_MAXI, X_DUMP, X_NOPROG, X_TIMELINE, X_TLWIN };
static const struct option exec_longs[] = {
    {"config", required_argument, NULL, 'c'},      {"set", required_argument, NULL, X_SET},
    {"width", required_argument, NULL, X_WIDTH},    {"max-instructions", required_argument, NULL, X_MAXI},
    {"dump-mem", required_argument, NULL, X_DUMP},  {"timing", no_argument, NULL, 't'},
    {"quiet", no_argument, NULL, 'q'},              {"no-progress", no_argument, NULL, X_NOPROG},
    {"timeline", required_argument, NULL, X_TIMELINE}, {"timeline-window", required_argument, NULL, X_TLWIN},
    {"help", no_argument, NULL, CLI_HELP},          {"version", no_argument, NULL, CLI_VERSION},
    {NULL, 0, NULL, 0}};

typedef struct ExecArgs {
    CliConfig ca;
    const char *prog, *dumps[64];
    int ndumps, quiet, timed, progress;
    char setbuf[2][96];
    const char *timeline;      /* --timeline FILE: the pipeline trace of cycles [tl_from, tl_to) */
    uint64_t tl_from, tl_to;
    int tl_window;
} ExecArgs;

/* EXIT_OK to go on, or the exit code (after printing what was wrong, or the help). -1: help done. */
static int exec_parse(int argc, char **argv, ExecArgs *a)
{
    CliParse p = {"sfsim exec", "exec", exec_longs, "c:tqh", argc, argv, 0};
    const char *v;
    int code;
    a->progress = 1;
    a->tl_to = TIMELINE_DEFAULT_CYCLES;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_exec))
            return -1;
        switch (code) {
        case 'c': a->ca.path = v; break;
        case X_SET:
            if (cli_config_set(&a->ca, v))
                return EXIT_USAGE;
            break;
        case X_WIDTH:
        case X_MAXI: {
            char *buf = a->setbuf[code == X_MAXI];
            snprintf(buf, sizeof a->setbuf[0], "%s=%s", code == X_WIDTH ? "core.simd_width" : "sim.max_instructions", v);
            if (cli_config_set(&a->ca, buf))
                return EXIT_USAGE;
            break;
        }
        case X_DUMP:
            if (a->ndumps >= 64) {
                fprintf(stderr, "sfsim exec: at most 64 --dump-mem options\n");
                return EXIT_USAGE;
            }
            a->dumps[a->ndumps++] = v;
            break;
        case 'q': a->quiet = 1; break;
        case 't': a->timed = 1; break;
        case X_NOPROG: a->progress = 0; break;
        case X_TIMELINE: a->timeline = v; a->timed = 1; break;
        case X_TLWIN: {
            char why[300];
            if (timeline_parse_window(v, &a->tl_from, &a->tl_to, why, sizeof why)) {
                fprintf(stderr, "sfsim exec: %s\n", why);
                return EXIT_INPUT;
            }
            a->tl_window = 1;
            break;
        }
        default: return EXIT_USAGE;
        }
    }
    if (code < 0)
        return EXIT_USAGE;
    if (a->tl_window && !a->timeline) {
        fprintf(stderr, "sfsim exec: --timeline-window chooses the cycles of --timeline FILE, which is not given "
                        "(sfsim help exec)\n");
        return EXIT_USAGE;
    }
    int first = cli_first_operand();
    if (first >= argc) {
        fprintf(stderr, "sfsim exec: no program given (sfsim help exec)\n");
        return EXIT_USAGE;
    }
    if (argc - first > 1) {
        fprintf(stderr, "sfsim exec: more than one program: %s and %s\n", argv[first], argv[first + 1]);
        return EXIT_USAGE;
    }
    a->prog = argv[first];
    return EXIT_OK;
}

/* The rest of the command, once the program and the config are known. */
static int exec_run(const ExecArgs *a, const CfgMachine *cfg, const MemDump *dd)
{
    AsmObject obj;
    char err[1024];
    if (asm_object_read(a->prog, &obj, err, sizeof err) != 0) {
        fprintf(stderr, "sfsim exec: %s\n", err);
        return EXIT_INPUT;
    }
    TimedCore tc;
    int orc = timedcore_open(&tc, cfg, &obj, a->timed, err, sizeof err);
    if (orc != 0) {
        if (orc == -2)
            fprintf(stderr, "sfsim exec: %s\n", err);
        else
            fprintf(stderr, "sfsim exec: %s: %s\n", a->prog, err);
        asm_object_free(&obj);
        return EXIT_INPUT;
    }
    Core *c = tc.core;
    Timing *tm = tc.tm;
    Timeline *tl = NULL;
    if (a->timeline) {
        const int bad = outfile_check_file(a->timeline, err, sizeof err) != 0;
        if (bad || !(tl = timeline_new(a->tl_from, a->tl_to, 1, cfg->core_clock_mhz, 1))) {
            fprintf(stderr, "sfsim exec: %s\n", bad ? err : "out of memory for the timeline");
            timedcore_close(&tc);
            asm_object_free(&obj);
            return EXIT_IO;
        }
        const TimingWatch w = timeline_core_watch(tl, 0);
        timing_watch(tm, &w);
    }
    double t0 = util_now();
    CoreExit ex = run_with_progress(c, (uint64_t)cfg->sim_max_instructions, a->progress);
    double secs = util_now() - t0;
    if (tm)
        timing_end(tm);
    uint64_t ni = core_instructions(c);
    printf("sfsim exec: %s on N = %d lanes: %s after %llu instructions (%.3f s, %.1f M instructions/s)\n", a->prog,
           core_lanes(c), ex == CORE_EXIT_HALT ? "halted" : ex == CORE_EXIT_TRAP ? "trapped" : "stopped at the limit",
           (unsigned long long)ni, secs, secs > 0 ? 1e-6 * (double)ni / secs : 0.0);
    int rc = EXIT_OK;
    if (!a->quiet)
        print_state(c);
    for (int i = 0; i < a->ndumps; i++)
        dump_print(c, &dd[i]);
    if (tm && cli_print_timing(timing_stats(tm), cfg, timing_error(tm)))
        rc = EXIT_PROGRAM;
    if (tl) { /* the pipeline trace, also of a run that trapped (what led up to it) */
        timeline_end(tl, timing_stats(tm)->cycles);
        if (timeline_write(tl, a->timeline, err, sizeof err) != 0) {
            fprintf(stderr, "sfsim exec: %s\n", err);
            rc = EXIT_IO;
        } else {
            printf("sfsim exec: wrote %s (cycles %llu to %llu)\n", a->timeline, (unsigned long long)a->tl_from,
                   (unsigned long long)a->tl_to);
        }
        timeline_free(tl);
    }
    if (ex != CORE_EXIT_HALT) {
        fprintf(stderr, "sfsim exec: %s\n", core_trap_message(c));
        rc = EXIT_PROGRAM;
    }
    timedcore_close(&tc);
    asm_object_free(&obj);
    return rc;
}

int cmd_exec(int argc, char **argv)
{
    ExecArgs a = {0};
    int rc = exec_parse(argc, argv, &a);
    if (rc != EXIT_OK) {
        cli_config_free(&a.ca);
        return rc < 0 ? EXIT_OK : rc;
    }
    CfgMachine cfg;
    MemDump dd[64];
    CoreParams cp;
    rc = EXIT_INPUT;
    if (cli_config_build(&a.ca, &cfg) == 0) {
        cfg_core_params(&cfg, &cp);
        int ok = 1;
        for (int i = 0; i < a.ndumps && ok; i++)
            ok = dump_parse(a.dumps[i], &cp, &dd[i]) == 0;
        if (ok)
            rc = exec_run(&a, &cfg, dd);
    }
    cli_config_free(&a.ca);
    return rc;
}
