/* sim/run/chiprun.h -- the detailed mode's frame on a chip of chip.cores cores (docs/chip.md):
 * the kernel engine's job (sim/run/engine_int.h) run on one worker per core, the tiles handed
 * out in simulated time, the cores' scene caches over the shared memory of sim/chip/chip.h.
 *
 * Owns: the chip's run of a frame. Must not: be reached but through the kernel engine.
 */
#ifndef SFSIM_RUN_CHIPRUN_H
#define SFSIM_RUN_CHIPRUN_H

#include "engine_int.h"

/* Whether fp's run is a chip's: a detailed frame with chip.cores > 1 or chip.memory = shared. */
int chip_run_wanted(const FuncParams *fp);
/* The frame on j->workers (chip.cores of them, unopened): its tiles into j->rgb and j->tiles,
 * the per-core figures into j->cores, the makespan and the shared memory's counters into the
 * job. Returns the tiles finished; a failure is the job's (eng_fail). */
uint32_t chip_run_frame(Job *j);

#endif
