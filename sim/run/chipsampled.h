/* sim/run/chipsampled.h -- sampled mode on a chip (chip.cores > 1 or chip.memory = shared;
 * docs/sampling.md, "Sampling a chip", design C; issue 41).
 *
 * 1. The golden model renders the frame (or the --no-image pilot) and counts every (tile, pass)
 *    unit's work, as sampled mode does on one core (sim/run/sampled.c).
 * 2. The opening, exact: the chip's frame in full detail until pass 0 of its first K tiles has
 *    ended (FuncParams.opening); those units' cycles are known exactly.
 * 3. A predicted schedule: every unit's cycles predicted from its golden counts (a fit on the
 *    opening's units first, the sample's fit later) and the distributor's list schedule of the
 *    tiles (chip_list_schedule); a unit starts after its tile's earlier passes.
 * 4. Phase 1: today's sample and sequential rule (sim/sampling.h) over the units, each timed alone
 *    on one core of the chip's memory (FuncParams.chip_unit), its L2 and DRAM rows warmed with the
 *    golden model's lines of the units that start before it in the predicted schedule
 *    (sim/run/chipwarm.h), after the framebuffer lines of the tiles that started before it (as
 *    written: dirty in the L2; its own tile's, for pass 1, before the scene's lines, for later
 *    passes after them); the regression of their cycles on the golden counts.
 * 5. Phase 2, the other cores: waves at evenly spaced instants of the predicted schedule (a seeded
 *    offset): the K units running then timed together on the whole chip (FuncParams.wave), and up
 *    to CHIPSAMPLED_WAVE_ALONE of them alone; their ratio r, with a jackknife over waves. Where the
 *    memory figures are estimated, each core also runs the unit that follows its own in the
 *    schedule (its tile's next pass, or its next tile's first), from the state the first left;
 *    those second units, also timed alone, give step 8 its correction.
 * 6. The makespan: every tile's estimate (exact, sampled or predicted units, times r, with the
 *    tile-effect correction) list-scheduled, with its 95 % interval (sim/chipsampling.h).
 * 7. The tail (with --target-error): a first round, then more while that interval is wider than the
 *    target: units of the tiles the latest cores end with are timed alone too and join the fit
 *    (CHIPSAMPLED_TAIL_*).
 * 8. The memory figures (chip.memory = shared): the opening's traffic exactly, the tiles' first
 *    passes (at least CHIPSAMPLED_FIRST_UNITS of them timed alone) and the rest from phase 1's
 *    units alone, with each unit's first-read lines (the warming's table) as an auxiliary, each
 *    stratum corrected by the waves' second units' together less alone (sim/chipmemest.h): the
 *    average read latency, the L2's hit rate and DRAM's bandwidth, each with a 95 % interval.
 * A chip whose cores have buses of their own (chip.memory = bus) has no shared level to warm or
 * contend for: its units are timed as sampled mode's (a cold core on its bus) and r = 1.
 *
 * Owns: the order of those steps, the predicted schedule, the waves' instants and r. Must not:
 * estimate the makespan itself (sim/chipsampling.c), time anything itself, or write files.
 */
#ifndef SFSIM_RUN_CHIPSAMPLED_H
#define SFSIM_RUN_CHIPSAMPLED_H

#include <stddef.h>

#include "run.h"

/* The units of a wave also timed alone (evenly spread over its cores) for the ratio r. */
#define CHIPSAMPLED_WAVE_ALONE 16u

/* The tail (with --target-error, while the makespan's interval is wider): a round times, on each
 * of this many of the cores that end last in the estimate, up to this many units of the tile with
 * the most cycles still predicted; all rounds at most twice phase 1's units. */
#define CHIPSAMPLED_TAIL_CORES 4u
#define CHIPSAMPLED_TAIL_UNITS 4u
/* ... and the rounds after the first stop once CHIPSAMPLED_TAIL_STILL in a row each moved the
 * makespan's estimate by at most CHIPSAMPLED_TAIL_MOVE of its standard errors (the late tiles are
 * then known as well as the tail can tell). */
#define CHIPSAMPLED_TAIL_MOVE 0.2
#define CHIPSAMPLED_TAIL_STILL 2u

/* With --no-image, the warming's first-reader record renders this many passes of each tile (every
 * ceil(spp / this)-th); with the image, or at this many samples or fewer, all of them. A partial
 * record leaves the memory figures unestimated (docs/sampling.md, step 4). */
#define CHIPSAMPLED_RECORD_PASSES 8u

/* The memory figures' stratum of the tiles' first passes outside the opening (sim/chipmemest.h):
 * at least this many of them timed, phase 1's sample's and extra ones drawn at random. */
#define CHIPSAMPLED_FIRST_UNITS 8u

/* Waves timed on a chip of K cores: 4, or 2 above 64 cores (a wave costs K units); at most this many. */
#define CHIPSAMPLED_MAX_WAVES 8u
uint32_t chipsampled_waves(uint32_t cores);

/* Whether a run on cfg is a chip's (sampled mode goes here rather than to sampled_frame). */
int chipsampled_wanted(const CfgMachine *cfg);

/* As sampled_frame (sim/run/sampled.h), on a chip. */
int chipsampled_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, const FuncParams *fp,
                      RunFrame *fr, char *err, size_t errlen);

#endif
