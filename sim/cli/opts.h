/* sim/cli/opts.h -- the command line's conventions, once: options parsed with glibc's getopt_long,
 * so that `--set=key=value`, `--set key=value`, `-j2`, `-j 2`, `--threads=2` and unambiguous
 * prefixes (`--thr 2`) work as users type them, and options and operands may come in any order
 * (`sfsim exec prog.sfo --timing`); `--` ends the options. Also the machine config every command
 * builds from -c and --set, and the numbers options take.
 *
 * Owns: the parse loop, its messages (unknown option, missing value, bad number) and their exit
 * codes: a usage error is EXIT_USAGE, a value out of range EXIT_INPUT (sim/exitcodes.def). Must
 * not: know any command's options (each command has its table) or run anything.
 */
#ifndef SFSIM_CLI_OPTS_H
#define SFSIM_CLI_OPTS_H

#include <getopt.h>
#include <stdio.h>

#include "../config.h"

/* Codes of the long options that have no short form start here (above any character). */
enum { CLI_LONG = 0x100, CLI_HELP = 'h', CLI_VERSION = 0xff };

/* One command's parse. */
typedef struct CliParse {
    const char *cmd;              /* "sfsim run": every message starts with it */
    const char *topic;            /* "run": the message points at `sfsim help run` */
    const struct option *longs;   /* getopt_long's table, ended by {0} */
    const char *shorts;           /* getopt's short options ("s:o:c:j:h") */
    int argc;
    char **argv;                  /* argv[0] is the command's name */
    int started;
} CliParse;

/* The next option's code (a short option's character or a long option's val) with its value in
 * *arg; 0 when the options are done, the operands then argv[cli_first_operand()..argc); -1 after a
 * usage error was printed (an unknown option, a missing value: return EXIT_USAGE). */
int cli_next(CliParse *p, const char **arg);
int cli_first_operand(void);

/* --help and --version, which every command takes: prints and returns 1 when code is one of them
 * (the command then exits EXIT_OK), 0 otherwise. usage prints the command's help. */
int cli_common(const CliParse *p, int code, void (*usage)(FILE *));

/* An integer value in lo..hi, or a finite number in (lo, hi]: 0, or -1 after printing
 * "CMD: OPT VALUE: expected ..." (the command returns EXIT_INPUT). */
int cli_int(const CliParse *p, const char *opt, const char *s, long long lo, long long hi, long long *out);

/* The machine config of -c FILE and the --set SECTION.KEY=VALUE options, in order. */
typedef struct CliConfig {
    const char *path;
    const char **sets;
    int nsets, cap;
} CliConfig;

/* Appends one --set (0, or -1 out of memory, printed). */
int cli_config_set(CliConfig *c, const char *set);
/* Defaults, the file, the sets in order, then the whole config checked: 0, or -1 with every error
 * printed on stderr (the command returns EXIT_INPUT). */
int cli_config_build(const CliConfig *c, CfgMachine *cfg);
void cli_config_free(CliConfig *c);

#endif
