/* sim/mem/dram_level.h -- the DRAM (sim/mem/dram.h) as a level of the chip's memory (level.h):
 * requests and answers in the cores' clock, a line split into the DRAM's bursts.
 *
 * Owns: the crossing between the two clock domains and the splitting of a line into bursts.
 * Must not: change what the DRAM does, or use floating point for a cycle.
 *
 * Crossing is exact integer arithmetic on the two clocks in kHz (docs/chip.md): a request at core
 * cycle c reaches the DRAM at its first cycle at or after c, ceil(c x dram / core); a burst done
 * at DRAM cycle d is at the core's first cycle at or after d, ceil(d x core / dram). A line of L
 * bytes is ceil(L / burst) bursts at consecutive addresses, all pushed at the line's cycle; the
 * line is done when its last burst is.
 */
#ifndef SFSIM_MEM_DRAM_LEVEL_H
#define SFSIM_MEM_DRAM_LEVEL_H

#include <stddef.h>
#include <stdint.h>

#include "dram.h"
#include "level.h"

typedef struct DramLevel DramLevel;

/* d stays the caller's. core_khz: the cores' clock in kHz (>= 1). 0 on out of memory. */
DramLevel *dram_level_new(Dram *d, uint64_t core_khz, int line_bytes);
void dram_level_free(DramLevel *l);
/* Nothing in flight (after dram_reset of its DRAM). */
void dram_level_reset(DramLevel *l);
MemLevel dram_level(DramLevel *l);
/* The crossings, exposed for their tests. */
uint64_t dram_level_to_dram(const DramLevel *l, uint64_t core_cycle);
uint64_t dram_level_to_core(const DramLevel *l, uint64_t dram_cycle);

#endif
