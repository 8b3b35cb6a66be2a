/* sim/run/schedmodel.h -- the machine model the assembler's scheduling pass schedules the kernel for,
 * from the machine config.
 *
 * Owns: filling an AsmSchedModel (asm/sched.h) from a CfgMachine. Must not: map a config key to a
 * unit class itself (the units' params functions in sim/machine/ do, as for the timing model), or
 * time anything.
 */
#ifndef SFSIM_RUN_SCHEDMODEL_H
#define SFSIM_RUN_SCHEDMODEL_H

#include "../../asm/sched.h"
#include "../config.h"

/* The latencies and issue intervals the timing model takes from cfg (sim/timing.c's timing_params):
 * per class from simd_params; a ray-buffer gather's, a scalar ID-stream read's, a scratchpad
 * load's and a scene-memory load's result times from the units' own functions, for an access
 * without conflicts (and a scene-cache hit, or the memory's latency without a cache). */
void schedmodel_fill(const CfgMachine *cfg, AsmSchedModel *m);

#endif
