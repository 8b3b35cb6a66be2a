/* sim/cli/exec.h -- `sfsim exec` (sim/cli/exec.c), and the timing print-out it shares with trace. */
#ifndef SFSIM_CLI_EXEC_H
#define SFSIM_CLI_EXEC_H

#include "../config.h"
#include "../timing.h"

/* The command: argv[0] is "exec"; an EXIT_* code. */
int cmd_exec(int argc, char **argv);

/* The timing of one `exec --timing` run (or a detailed trace) from the statistics registry
 * (sim/stats.def); non-zero when the model failed its own check (said on stderr). */
int cli_print_timing(const TimingStats *s, const CfgMachine *cfg, const char *model_err);

#endif
