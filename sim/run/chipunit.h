/* sim/run/chipunit.h -- one (tile, pass) unit on one core of a chip's shared memory: the unit of
 * a sampled chip (docs/sampling.md, "Sampling a chip", design C step 2; issue 41).
 *
 * The core's L1 misses go to the chip's network, L2 and DRAM (sim/chip) as core 0 of the chip's K,
 * with no other core sending: the unit's cycles with the hierarchy and without the other cores.
 * Every unit starts from a cold machine: the core's units and L1 (timing_reset) and the shared
 * levels (chip_reset: an empty L2, closed DRAM rows, nothing in flight), so that a unit's cycles
 * do not depend on which units a host thread ran before it. (The functional warming of the L2 and
 * the DRAM rows, design C's step 5, is to come.)
 *
 * Owns: the one-core form of the chip's step rule (docs/chip.md): the core runs until it waits
 * for an answer, then the shared memory steps until the answer is in. Must not: hand out units,
 * or time anything itself.
 */
#ifndef SFSIM_RUN_CHIPUNIT_H
#define SFSIM_RUN_CHIPUNIT_H

#include <stddef.h>
#include <stdint.h>

#include "../chip/chip.h"
#include "../config.h"
#include "../core.h"
#include "../timing.h"

typedef struct ChipUnit {
    Chip *chip;                /* cfg's shared memory for chip.cores cores; core 0 attached */
    Timing *t;
} ChipUnit;

/* cfg's shared memory, with the timing model t (hooked to its core) as its core 0. 0, or -1 with
 * err (a bad config, out of memory). */
int chipunit_open(ChipUnit *u, const CfgMachine *cfg, Timing *t, char *err, size_t errlen);
void chipunit_close(ChipUnit *u);
/* The shared levels cold and idle, before a unit (after timing_reset of the core's model). */
void chipunit_reset(ChipUnit *u);
/* Then the n lines (oldest first) read into them as if by the units before (chip_warm). */
void chipunit_warm(ChipUnit *u, const uint64_t *lines, size_t n);
/* Core c (whose model is u's) runs the launched pass until it halts, traps or reaches `limit`
 * instructions (sim.max_instructions; 0: none), the shared memory stepped whenever the core waits
 * for it. *ex: how it ended; CORE_EXIT_LIMIT may come without a trap message (the limit fell on a
 * yield), for the caller to say. 0, or -1 on an internal error of the chip (err says what). */
int chipunit_run(ChipUnit *u, Core *c, uint64_t limit, CoreExit *ex, char *err, size_t errlen);

#endif
