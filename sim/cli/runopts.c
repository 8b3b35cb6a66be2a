/* sim/cli/runopts.c -- the one parse and check of `sfsim run`'s and `sfsim trace`'s options
 * (runopts.h): each option's value as it is read, then how they go together, then the machine they
 * build and the mode against it, in that order, before any work.
 */
#include "runopts.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../datadir.h"
#include "../exitcodes.h"
#include "../run/spec.h"
#include "../timeline.h"
#include "help.h"

/* ---- run --------------------------------------------------------------------------------------- */

enum { R_MODE = CLI_LONG, R_SET, R_EXPOSURE, R_SAMPLE, R_TARGET, R_NO_IMAGE, R_SEED, R_NOPROG, R_KERNEL, R_MEMTRACE, R_TIMELINE, R_TLWIN };
static const struct option run_longs[] = {
    {"scene", required_argument, NULL, 's'},         {"out", required_argument, NULL, 'o'},
    {"config", required_argument, NULL, 'c'},        {"mode", required_argument, NULL, R_MODE},
    {"threads", required_argument, NULL, 'j'},       {"set", required_argument, NULL, R_SET},
    {"exposure", required_argument, NULL, R_EXPOSURE}, {"sample", required_argument, NULL, R_SAMPLE},
    {"target-error", required_argument, NULL, R_TARGET}, {"no-image", no_argument, NULL, R_NO_IMAGE},
    {"sample-seed", required_argument, NULL, R_SEED}, {"no-progress", no_argument, NULL, R_NOPROG},
    {"kernel", required_argument, NULL, R_KERNEL},   {"mem-trace", required_argument, NULL, R_MEMTRACE},
    {"timeline", required_argument, NULL, R_TIMELINE}, {"timeline-window", required_argument, NULL, R_TLWIN},
    {"help", no_argument, NULL, CLI_HELP},
    {"version", no_argument, NULL, CLI_VERSION},     {NULL, 0, NULL, 0}};

/* Which of the sampled mode's sizes the command line gave (their values alone do not say). */
typedef struct RunGiven {
    int sample, target, window;
} RunGiven;

/* A render key (render.width=..., sim/render.h's table) into o: 1 taken, 0 not a render key, -1 a
 * bad value (said). */
static int run_render_key(const CliParse *p, RenderOptions *o, const char *s)
{
    for (int k = 0; k < RENDER_KEY_COUNT; k++) {
        size_t kl = strlen(render_keys[k].key);
        if (strncmp(s, render_keys[k].key, kl) != 0 || s[kl] != '=')
            continue;
        char opt[64];
        long long v;
        snprintf(opt, sizeof opt, "--set %s =", render_keys[k].key);
        if (cli_int(p, opt, s + kl + 1, render_keys[k].lo, render_keys[k].hi, &v))
            return -1;
        int *field[] = {&o->width, &o->height, &o->spp, &o->max_depth, NULL};
        if (k == RENDER_KEY_SEED)
            o->seed = (uint32_t)v;
        else
            *field[k] = (int)v;
        return 1;
    }
    return 0;
}

/* A fraction in (lo, hi) or (lo, hi] for --sample / --target-error / --exposure: 0 or -1 (said). */
static int run_fraction(const char *opt, const char *s, double lo, double hi, int hi_in, const char *what, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (end == s || *end || errno || !isfinite(v) || !(v > lo) || (hi_in ? v > hi : v >= hi)) {
        fprintf(stderr, "sfsim run: %s %s: expected %s\n", opt, s, what);
        return -1;
    }
    *out = v;
    return 0;
}

/* One option of run into c: EXIT_OK, or the exit code after saying what was wrong. */
static int run_option(const CliParse *p, RunCmd *c, RunGiven *g, int code, const char *v)
{
    RenderOptions *o = &c->o;
    long long n;
    double x;
    switch (code) {
    case 's': o->scene_path = v; break;
    case 'o': o->out_dir = v; break;
    case 'c': c->ca.path = v; break;
    case R_MODE:
        if (run_mode_parse(v, &o->mode) != 0) {
            fprintf(stderr, "sfsim run: --mode %s: expected detailed, sampled, functional or reference (sfsim help run)\n", v);
            return EXIT_INPUT;
        }
        break;
    case 'j':
        if (cli_int(p, "-j", v, 1, 1024, &n))
            return EXIT_INPUT;
        o->threads = (int)n;
        break;
    case R_EXPOSURE:
        if (run_fraction("--exposure", v, 0.0, 3.0e38, 1, "a finite positive number (a float)", &x))
            return EXIT_INPUT;
        o->exposure = (float)x;
        break;
    case R_SAMPLE:
        if (run_fraction("--sample", v, 0.0, 1.0, 1, "a fraction of the units in (0, 1], e.g. 0.05", &o->sample))
            return EXIT_INPUT;
        g->sample = 1;
        break;
    case R_TARGET:
        if (run_fraction("--target-error", v, 0.0, 1.0, 0, "a fraction in (0, 1), e.g. 0.01 for +-1%", &o->target_error))
            return EXIT_INPUT;
        g->target = 1;
        break;
    case R_NO_IMAGE: o->no_image = 1; break;
    case R_SEED:
        if (cli_int(p, "--sample-seed", v, 0, 4294967295LL, &n))
            return EXIT_INPUT;
        o->sample_seed = (uint32_t)n;
        break;
    case R_NOPROG: o->progress = 0; break;
    case R_KERNEL: o->kernel_path = v; break;
    case R_MEMTRACE: o->mem_trace = v; break;
    case R_TIMELINE: o->timeline = v; break;
    case R_TLWIN: {
        char why[300];
        if (timeline_parse_window(v, &o->timeline_from, &o->timeline_to, why, sizeof why)) {
            fprintf(stderr, "sfsim run: %s\n", why);
            return EXIT_INPUT;
        }
        g->window = 1;
        break;
    }
    case R_SET: {
        int r = run_render_key(p, o, v);
        if (r < 0)
            return EXIT_INPUT;
        if (r == 0 && cli_config_set(&c->ca, v))
            return EXIT_USAGE;
        break;
    }
    default: return EXIT_USAGE;
    }
    return EXIT_OK;
}

/* How run's options go together, after all of them were read. */
static int run_together(RenderOptions *o, const RunGiven *g)
{
    if ((g->sample || g->target || o->no_image) && o->mode != RUN_SAMPLED) {
        fprintf(stderr, "sfsim run: --sample, --target-error and --no-image apply to --mode sampled only "
                        "(sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (o->mem_trace && o->mode != RUN_DETAILED) {
        fprintf(stderr, "sfsim run: --mem-trace FILE writes the timed requests of --mode detailed only (sfsim help run)\n");
        return EXIT_USAGE;
    }
    if ((o->timeline || g->window) && o->mode != RUN_DETAILED) {
        fprintf(stderr, "sfsim run: --timeline FILE shows the cycles of --mode detailed only (sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (g->window && !o->timeline) {
        fprintf(stderr, "sfsim run: --timeline-window chooses the cycles of --timeline FILE, which is not given "
                        "(sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (g->sample && g->target) {
        fprintf(stderr, "sfsim run: --sample F (a fixed fraction) and --target-error E (as many units as E needs) "
                        "exclude each other (sfsim help run)\n");
        return EXIT_USAGE;
    }
    if (g->sample)
        o->target_error = 0.0; /* the fixed-size design */
    return EXIT_OK;
}

/* The mode against the machine the options built: the golden model renders the reference mode's
 * frame and gives the sampled mode its units' auxiliary counts, and it has only the path tracer and
 * the Phong workload (spec.h, run_workload_golden). */
static int run_machine(const RenderOptions *o, const CfgMachine *cfg)
{
    const char *kind = cfg_enum_name("workload", "kind", cfg->workload_kind);
    if (o->mode == RUN_REFERENCE && !run_workload_golden(cfg)) {
        fprintf(stderr, "sfsim run: --mode reference: workload.kind = %s has no golden model (path and phong do)\n", kind);
        return EXIT_INPUT;
    }
    if (o->mode == RUN_SAMPLED && !run_workload_golden(cfg)) {
        fprintf(stderr, "sfsim run: --mode sampled: workload.kind = %s has no golden model to draw the units' "
                        "auxiliary counts from (path and phong do); use --mode detailed\n", kind);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

int runopts_run(int argc, char **argv, RunCmd *c)
{
    memset(c, 0, sizeof *c);
    CliParse p = {"sfsim run", "run", run_longs, "s:o:c:j:h", argc, argv, 0};
    RenderOptions *o = &c->o;
    render_default_options(o);
    o->scene_path = NULL; /* default: the shipped Cornell box, found beside the binary */
    o->out_dir = "out";
    o->progress = isatty(2);
    o->mode = RUN_DETAILED;
    RunGiven given = {0};
    int code, rc;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_run))
            return -1;
        if ((rc = run_option(&p, c, &given, code, v)) != EXIT_OK)
            return rc;
    }
    if (code < 0)
        return EXIT_USAGE;
    if (cli_first_operand() < argc) {
        fprintf(stderr, "sfsim run: unexpected argument '%s': the scene is given with -s (sfsim help run)\n",
                argv[cli_first_operand()]);
        return EXIT_USAGE;
    }
    if ((rc = run_together(o, &given)) != EXIT_OK)
        return rc;
    if (!o->scene_path) {
        char derr[8192];
        if (!datadir_path(DATADIR_DEFAULT_SCENE, c->scene, sizeof c->scene, derr, sizeof derr)) {
            fprintf(stderr, "sfsim run: no -s SCENE given and the default scene is missing: %s\n", derr);
            return EXIT_INPUT;
        }
        o->scene_path = c->scene;
    }
    if (cli_config_build(&c->ca, &c->cfg))
        return EXIT_INPUT;
    o->cfg = &c->cfg;
    o->config_path = c->ca.path;
    return run_machine(o, &c->cfg);
}

/* ---- trace ------------------------------------------------------------------------------------- */

enum { T_RAYS = CLI_LONG, T_MODE, T_SET, T_BINARY, T_KERNEL };
static const struct option trace_longs[] = {
    {"scene", required_argument, NULL, 's'},   {"rays", required_argument, NULL, T_RAYS},
    {"out", required_argument, NULL, 'o'},     {"mode", required_argument, NULL, T_MODE},
    {"config", required_argument, NULL, 'c'},  {"set", required_argument, NULL, T_SET},
    {"binary", no_argument, NULL, T_BINARY},   {"threads", required_argument, NULL, 'j'},
    {"kernel", required_argument, NULL, T_KERNEL}, {"help", no_argument, NULL, CLI_HELP},
    {"version", no_argument, NULL, CLI_VERSION}, {NULL, 0, NULL, 0}};

/* One option of trace into c: EXIT_OK, or the exit code after saying what was wrong. */
static int trace_option(const CliParse *p, TraceCmd *c, int code, const char *v)
{
    TraceOptions *o = &c->o;
    long long n;
    switch (code) {
    case 's': o->scene_path = v; break;
    case T_RAYS: o->rays_path = v; break;
    case 'o': o->out_path = v; break;
    case 'c': c->ca.path = v; break;
    case T_MODE: /* a ray batch has no (tile, pass) units to sample */
        if (run_mode_parse(v, &o->mode) != 0 || o->mode == RUN_SAMPLED) {
            fprintf(stderr, "sfsim trace: --mode %s: expected functional, detailed or reference\n", v);
            return EXIT_INPUT;
        }
        break;
    case T_SET:
        if (cli_config_set(&c->ca, v))
            return EXIT_USAGE;
        break;
    case T_BINARY: o->binary = 1; break;
    case 'j':
        if (cli_int(p, "-j", v, 1, 1024, &n))
            return EXIT_INPUT;
        o->threads = (int)n;
        break;
    case T_KERNEL: o->kernel_path = v; break;
    default: return EXIT_USAGE;
    }
    return EXIT_OK;
}

int runopts_trace(int argc, char **argv, TraceCmd *c)
{
    memset(c, 0, sizeof *c);
    CliParse p = {"sfsim trace", "trace", trace_longs, "s:o:c:j:h", argc, argv, 0};
    TraceOptions *o = &c->o;
    o->mode = RUN_FUNCTIONAL;
    int code, rc;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_trace))
            return -1;
        if ((rc = trace_option(&p, c, code, v)) != EXIT_OK)
            return rc;
    }
    if (code < 0)
        return EXIT_USAGE;
    if (cli_first_operand() < argc) {
        fprintf(stderr, "sfsim trace: unexpected argument '%s' (sfsim help trace)\n", argv[cli_first_operand()]);
        return EXIT_USAGE;
    }
    if (!o->scene_path || !o->rays_path || !o->out_path) {
        fprintf(stderr, "sfsim trace: -s SCENE, --rays FILE and -o HITS are required (sfsim help trace)\n");
        return EXIT_USAGE;
    }
    if (o->threads == 0)
        o->threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (cli_config_build(&c->ca, &c->cfg))
        return EXIT_INPUT;
    o->cfg = &c->cfg;
    return EXIT_OK;
}
