/* sim/main.c -- the `sfsim` command line: which command runs, and the commands run, trace,
 * config and compare (exec is sim/cli/exec.c; sweep and merge sim/sweep/sweep.c).
 *
 * Owns: the options of config and compare (a getopt_long table each, parsed by sim/cli/opts.c),
 * what each command prints, and the exit code; run's and trace's options are parsed and checked
 * once, in sim/cli/runopts.c. Must not: simulate (it calls the config, the renderers and trace).
 * Exit codes: the EXIT_* of sim/exitcodes.def, nothing else; an option value out of range is bad
 * input (EXIT_INPUT), an unknown option, a missing argument or options that do not go together a
 * usage error (EXIT_USAGE).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../host/outfile.h"
#include "../host/version.h"
#include "cli/exec.h"
#include "cli/help.h"
#include "cli/mem.h"
#include "cli/opts.h"
#include "cli/runopts.h"
#include "config.h"
#include "exitcodes.h"
#include "img.h"
#include "imglib.h"
#include "provenance.h"
#include "render.h"
#include "run/run.h"
#include "sweep/sweep.h"
#include "trace.h"
#include "util.h"

/* ---- config ------------------------------------------------------------------------------------ */

enum { C_DUMP = CLI_LONG, C_MARKDOWN, C_SET };
static const struct option config_longs[] = {
    {"dump", no_argument, NULL, C_DUMP},        {"markdown", no_argument, NULL, C_MARKDOWN},
    {"config", required_argument, NULL, 'c'},   {"set", required_argument, NULL, C_SET},
    {"help", no_argument, NULL, CLI_HELP},      {"version", no_argument, NULL, CLI_VERSION},
    {NULL, 0, NULL, 0}};

static int cmd_config(int argc, char **argv)
{
    CliParse p = {"sfsim config", "config", config_longs, "c:h", argc, argv, 0};
    CliConfig ca = {0};
    int dump = 0, markdown = 0, code, rc = EXIT_USAGE;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_config)) {
            rc = EXIT_OK;
            goto out;
        }
        if (code == C_DUMP)
            dump = 1;
        else if (code == C_MARKDOWN)
            markdown = 1;
        else if (code == 'c')
            ca.path = v;
        else if (code == C_SET && cli_config_set(&ca, v))
            goto out;
    }
    if (code < 0)
        goto out;
    if (cli_first_operand() < argc) {
        fprintf(stderr, "sfsim config: unexpected argument '%s' (sfsim help config)\n", argv[cli_first_operand()]);
        goto out;
    }
    if (dump == markdown) {
        fprintf(stderr, "sfsim config: give one of --dump and --markdown (sfsim help config)\n");
        goto out;
    }
    rc = EXIT_OK;
    if (markdown) {
        cfg_markdown(stdout);
    } else {
        CfgMachine cfg;
        if (cli_config_build(&ca, &cfg))
            rc = EXIT_INPUT;
        else
            cfg_dump(&cfg, stdout);
    }
out:
    cli_config_free(&ca);
    return rc;
}

/* ---- compare ----------------------------------------------------------------------------------- */

enum { K_MAX_RMSE = CLI_LONG, K_MIN_PSNR, K_MAX_DIFF };
static const struct option compare_longs[] = {
    {"max-rmse", required_argument, NULL, K_MAX_RMSE}, {"min-psnr", required_argument, NULL, K_MIN_PSNR},
    {"max-diff", required_argument, NULL, K_MAX_DIFF}, {"help", no_argument, NULL, CLI_HELP},
    {"version", no_argument, NULL, CLI_VERSION},       {NULL, 0, NULL, 0}};

/* A threshold's value: a finite number (a PSNR may be negative; the others are >= 0). */
static int threshold(const char *opt, const char *s, int signed_ok, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || (!signed_ok && v < 0)) {
        fprintf(stderr, "sfsim compare: %s %s: expected a finite number%s\n", opt, s, signed_ok ? "" : " >= 0");
        return -1;
    }
    *out = v;
    return 0;
}

/* Prints the figures; EXIT_OK, or EXIT_DIFFER when a threshold given was exceeded (said). */
static int compare_report(const char *na, const char *nb, int w, int h, const ImgCompare *c, const double lim[3],
                          const int given[3])
{
    printf("%s vs %s (%d x %d)\n", na, nb, w, h);
    printf("  RMSE        %.6g\n  PSNR        %.2f dB\n  max diff    %.6g\n", c->rmse, c->psnr, c->max_abs);
    printf("  mean        %.6g vs %.6g\n  NaN/Inf     %ld vs %ld\n", c->mean_a, c->mean_b, c->nan_a, c->nan_b);
    static const char *const names[3] = {"--max-rmse", "--min-psnr", "--max-diff"};
    const double got[3] = {c->rmse, c->psnr, c->max_abs};
    int rc = EXIT_OK;
    for (int k = 0; k < 3; k++) {
        if (!given[k])
            continue;
        int bad = c->nan_a != c->nan_b || isnan(got[k]) || (k == 1 ? got[k] < lim[k] : got[k] > lim[k]);
        if (bad) {
            fprintf(stderr, "sfsim compare: %s %g exceeded: %s %.6g%s\n", names[k], lim[k],
                    k == 0 ? "RMSE" : k == 1 ? "PSNR" : "largest difference", got[k],
                    c->nan_a != c->nan_b ? " (and the NaN/Inf counts differ)" : "");
            rc = EXIT_DIFFER;
        }
    }
    return rc;
}

static int cmd_compare(int argc, char **argv)
{
    CliParse p = {"sfsim compare", "compare", compare_longs, "h", argc, argv, 0};
    double lim[3] = {0};
    int given[3] = {0}, code;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_compare))
            return EXIT_OK;
        int k = code - K_MAX_RMSE;
        if (k >= 0 && k < 3) {
            if (threshold(k == 0 ? "--max-rmse" : k == 1 ? "--min-psnr" : "--max-diff", v, k == 1, &lim[k]))
                return EXIT_INPUT;
            given[k] = 1;
        }
    }
    if (code < 0)
        return EXIT_USAGE;
    int first = cli_first_operand();
    if (argc - first != 2) {
        fprintf(stderr, "sfsim compare: expected two images, A and B (sfsim help compare)\n");
        return EXIT_USAGE;
    }
    const char *na = argv[first], *nb = argv[first + 1];
    float *a = NULL, *b = NULL;
    int wa, ha, wb, hb;
    char err[8192];
    /* A missing or broken image library is sfsim's fault, not the images': EXIT_IO as for run. */
    if (!imglib_get(err, sizeof err)) {
        fprintf(stderr, "sfsim compare: %s\n", err);
        return EXIT_IO;
    }
    int rc = EXIT_INPUT;
    if (img_read(na, &a, &wa, &ha, err, sizeof err) != 0 || img_read(nb, &b, &wb, &hb, err, sizeof err) != 0) {
        fprintf(stderr, "sfsim compare: %s\n", err);
    } else if (wa != wb || ha != hb) {
        fprintf(stderr, "sfsim compare: sizes differ: %s is %d x %d, %s is %d x %d\n", na, wa, ha, nb, wb, hb);
    } else {
        ImgEncoding ea = img_encoding(na), eb = img_encoding(nb);
        if (ea != eb && ea != IMG_ENC_UNKNOWN && eb != IMG_ENC_UNKNOWN)
            fprintf(stderr,
                    "sfsim compare: warning: %s holds %s and %s %s: the figures below compare different encodings, "
                    "not the renders (compare frame.exr with frame.exr, or frame.png with frame.png)\n",
                    na, ea == IMG_ENC_LINEAR ? "linear radiance" : "display values (sRGB-encoded, clamped to 0..1)",
                    nb, eb == IMG_ENC_LINEAR ? "linear radiance" : "display values (sRGB-encoded, clamped to 0..1)");
        ImgCompare c;
        img_compare(a, b, wa, ha, &c);
        rc = compare_report(na, nb, wa, ha, &c, lim, given);
    }
    free(a);
    free(b);
    return rc;
}

/* ---- run and trace (their options: sim/cli/runopts.c) ------------------------------------------ */

static int cmd_run(int argc, char **argv)
{
    RunCmd c;
    int rc = runopts_run(argc, argv, &c);
    if (rc != EXIT_OK) {
        cli_config_free(&c.ca);
        return rc < 0 ? EXIT_OK : rc;
    }
    RenderOptions *o = &c.o;
    static char err[65536];
    /* The images a run writes (frame.exr, frame.png, cost.png, frame.partial.exr) go through
     * OpenEXR, libpng and FreeType linked into this binary (sim/img_write.c, sim/heatmap.c): a run
     * never loads the image library, OpenImageIO's reader (docs/performance.md, "Start-up"). */
    int rrc = render_run(o, err, sizeof err);
    if (rrc != 0) {
        fprintf(stderr, "sfsim run: %s\n", err);
        /* -3: an output could not be written (trace_run's convention, for render_run's writers) */
        rc = rrc == -2 ? EXIT_PROGRAM : rrc == -3 ? EXIT_IO : EXIT_INPUT;
        goto out;
    }
    size_t n = strlen(o->out_dir);
    const char *sep = n && o->out_dir[n - 1] == '/' ? "" : "/";
    printf("sfsim run: wrote %s%s%sreport.txt, report.json, stats.txt%s%s%s%s%s\n", o->out_dir, sep,
           o->no_image ? "" : "frame.png, frame.exr, ", run_mode_timed(o->mode) ? ", cost.png" : "",
           o->mem_trace ? "; " : "", o->mem_trace ? o->mem_trace : "", o->timeline ? "; " : "",
           o->timeline ? o->timeline : "");
    if (o->timeline)
        printf("sfsim run: the timeline holds cycles %llu to %llu (--timeline-window FROM:TO chooses them)\n",
               (unsigned long long)o->timeline_from, (unsigned long long)o->timeline_to);
    rc = EXIT_OK;
out:
    cli_config_free(&c.ca);
    return rc;
}

static int cmd_trace(int argc, char **argv)
{
    TraceCmd c;
    int rc = runopts_trace(argc, argv, &c);
    if (rc != EXIT_OK) {
        cli_config_free(&c.ca);
        return rc < 0 ? EXIT_OK : rc;
    }
    TraceOptions o = c.o;
    static char err[65536];
    TraceSummary sum;
    rc = trace_run(&o, &sum, err, sizeof err);
    cli_config_free(&c.ca);
    if (rc != 0) {
        fprintf(stderr, "sfsim trace: %s\n", err);
        return rc == -2 ? EXIT_PROGRAM : rc == -3 ? EXIT_IO : EXIT_INPUT;
    }
    printf("sfsim trace: %u rays (%s): %u hits, %u misses, %u occluded, %u clear, %u invalid; %.3f s",
           sum.rays, run_mode_names[o.mode], sum.hits, sum.misses, sum.occluded, sum.clear, sum.invalid, sum.seconds);
    if (sum.sim_instructions)
        printf(", %llu simulated instructions", (unsigned long long)sum.sim_instructions);
    printf("; wrote %s\n", o.out_path);
    if (sum.cores)
        printf("sfsim trace: chip: %u cores, %u with a batch, makespan %llu cycles (the cycles below: the batches' "
               "summed)\n", sum.cores, sum.cores_used, (unsigned long long)sum.makespan);
    if (sum.timed && cli_print_timing(&sum.timing, &c.cfg, NULL))
        return EXIT_PROGRAM;
    return EXIT_OK;
}

/* ---- the commands ------------------------------------------------------------------------------ */

static const struct {
    const char *name;
    int (*run)(int argc, char **argv); /* argv[0] is the command's name */
    void (*help)(FILE *out);
} commands[] = {
    {"run", cmd_run, help_run},         {"exec", cmd_exec, help_exec},       {"config", cmd_config, help_config},
    {"compare", cmd_compare, help_compare}, {"trace", cmd_trace, help_trace}, {"sweep", sweep_main, sweep_usage},
    {"merge", merge_main, merge_usage}, {"mem", cmd_mem, help_mem}};
enum { NCOMMANDS = sizeof commands / sizeof commands[0] };

static int cmd_help(int argc, char **argv)
{
    if (argc > 2) {
        fprintf(stderr, "sfsim help: one topic at a time, not '%s %s' (sfsim help help)\n", argv[1], argv[2]);
        return EXIT_USAGE;
    }
    const char *t = argc > 1 ? argv[1] : NULL;
    if (!t) {
        help_commands(stdout);
    } else if (!strcmp(t, "help") || !strcmp(t, "--help") || !strcmp(t, "-h")) {
        help_help(stdout);
    } else if (!strcmp(t, "--version")) {
        printf("sfsim %s (commit %s)\n", version_string(), version_commit());
    } else if (!strcmp(t, "exit-codes")) {
        help_exit_codes(stdout);
    } else {
        for (int i = 0; i < NCOMMANDS; i++)
            if (!strcmp(t, commands[i].name)) {
                commands[i].help(stdout);
                return EXIT_OK;
            }
        fprintf(stderr, "sfsim help: unknown command '%s' (sfsim help help)\n", t);
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

static int dispatch(int argc, char **argv)
{
    if (argc < 2) {
        help_commands(stderr);
        return EXIT_USAGE;
    }
    const char *cmd = argv[1];
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h")) {
        help_commands(stdout);
        return EXIT_OK;
    }
    if (!strcmp(cmd, "--version")) {
        printf("sfsim %s (commit %s)\n", version_string(), version_commit());
        return EXIT_OK;
    }
    if (!strcmp(cmd, "help"))
        return cmd_help(argc - 1, argv + 1);
    for (int i = 0; i < NCOMMANDS; i++)
        if (!strcmp(cmd, commands[i].name))
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "sfsim: unknown command '%s'\n\n", cmd);
    help_commands(stderr);
    return EXIT_USAGE;
}

int main(int argc, char **argv)
{
    outfile_process_init();
    prov_set_command(argc, argv); /* what made the run, for its reports (sim/provenance.h) */
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
