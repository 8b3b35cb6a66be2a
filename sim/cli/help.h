/* sim/cli/help.h -- the help texts of sfsim's commands (sim/cli/help.c). */
#ifndef SFSIM_CLI_HELP_H
#define SFSIM_CLI_HELP_H

#include <stdio.h>

void help_commands(FILE *out);
void help_help(FILE *out);
void help_exit_codes(FILE *out);
void help_exec(FILE *out);
void help_config(FILE *out);
void help_run(FILE *out);
void help_compare(FILE *out);
void help_trace(FILE *out);
void help_mem(FILE *out);

#endif
