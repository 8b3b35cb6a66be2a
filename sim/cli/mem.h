/* sim/cli/mem.h -- `sfsim mem` (sim/cli/mem.c): replays a memory-access trace through the DRAM. */
#ifndef SFSIM_CLI_MEM_H
#define SFSIM_CLI_MEM_H

/* The command: argv[0] is "mem"; an EXIT_* code. */
int cmd_mem(int argc, char **argv);

#endif
