/* sim/cli/runopts.h -- the one parse and check of the options of `sfsim run` and `sfsim trace`:
 * each option's value, how the options go together, the machine they build (-c, --set) and the
 * mode against that machine, and what a command line leaves to a default (the shipped scene, the
 * host threads of trace).
 *
 * Owns: the two commands' option tables, every message about them and its exit code (a value out
 * of range or a mode the machine cannot run is EXIT_INPUT; options that do not go together, an
 * unknown option or a missing one EXIT_USAGE; sim/exitcodes.def). Everything below it
 * (sim/render.c, sim/trace.c, sim/run/) takes the options as checked here and only asserts what
 * this check guarantees. Must not: open the scene or the ray file (their contents are their
 * loaders' to check), write files, or run anything.
 */
#ifndef SFSIM_CLI_RUNOPTS_H
#define SFSIM_CLI_RUNOPTS_H

#include "../config.h"
#include "../render.h"
#include "../trace.h"
#include "opts.h"

/* A checked `sfsim run`: o.cfg points at cfg and o.scene_path may point at scene, so it is used
 * where it was filled, never copied. */
typedef struct RunCmd {
    RenderOptions o;
    CfgMachine cfg;
    CliConfig ca;              /* -c and --set, as given (free with cli_config_free) */
    char scene[4096];          /* the shipped scene, when no -s was given */
} RunCmd;

/* `sfsim run`'s options (argv[0] is "run") parsed and checked into c: EXIT_OK; -1 when --help or
 * --version was printed (the command exits EXIT_OK); or the exit code after printing what was
 * wrong on stderr. Free c->ca with cli_config_free either way. */
int runopts_run(int argc, char **argv, RunCmd *c);

/* A checked `sfsim trace`: o.cfg points at cfg, as for RunCmd. */
typedef struct TraceCmd {
    TraceOptions o;
    CfgMachine cfg;
    CliConfig ca;
} TraceCmd;

/* `sfsim trace`'s options, as runopts_run. */
int runopts_trace(int argc, char **argv, TraceCmd *c);

#endif
