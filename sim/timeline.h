/* sim/timeline.h -- what a run's cores, units and memory levels did over simulated time, for a
 * window of cycles, written in the Chrome trace event format (Perfetto, chrome://tracing):
 * `sfsim run --timeline FILE` and `sfsim exec --timeline FILE` (docs/timeline.md).
 *
 * Owns: the events of the window as the timing model (TimingWatch), the run (the passes of tiles)
 * and the shared memory (MemWatch) tell them, their merging into spans, a core's idle time, and
 * the file. Must not: change a result (it only watches; the run it watches turns the memo of
 * blocks off, which changes no result), or write a file part-way (written whole or not at all).
 *
 * The time axis: 1 unit of the format's ts ("us" to a viewer) is 1 cycle of the core clock.
 * Per core (a process "core K"): thread "issue" has every cycle of the core in the window as
 * "busy" (an instruction issued), "stall: CAUSE" (charged to CAUSE; scene_memory split into
 * "scene_memory", "scene_memory (l2)" and "scene_memory (dram)" by where the data came from) or
 * "idle" (no work: before its first tile, between tiles, after its last), so that over a window
 * covering the run the spans add up to the report's counts; thread "work" the passes of tiles;
 * one thread per unit (timing.h TIMING_UNITS) with the spans the unit was busy (merged where they
 * touch or overlap); requests below the L1 of a core's own bus as async slices. The shared memory
 * (a process "memory"): each request into each level (network, L2, DRAM) as an async slice from
 * the cycle it entered to its answer, and a counter of the requests in flight per level.
 * The pipeline trace (exec): each instruction as an async slice from issue to its results' cycle,
 * with its pc and its stall cycles.
 */
#ifndef SFSIM_TIMELINE_H
#define SFSIM_TIMELINE_H

#include <stddef.h>
#include <stdint.h>

#include "mem/monitor.h"
#include "timing.h"

typedef struct Timeline Timeline;

/* The default window: the first this many cycles (docs/timeline.md). */
#define TIMELINE_DEFAULT_CYCLES 1000000ull

/* A timeline of cycles [from, to) of a run of `cores` cores (1 for one core); pipeline: each
 * instruction too (exec). NULL on out of memory. */
Timeline *timeline_new(uint64_t from, uint64_t to, int cores, double clock_mhz, int pipeline);
void timeline_free(Timeline *tl);
/* Parses "FROM:TO" (cycles, TO > FROM; either may be left out: 0, and FROM + the default length).
 * 0, or -1 with the reason in err. */
int timeline_parse_window(const char *s, uint64_t *from, uint64_t *to, char *err, size_t errlen);
/* Core k's watch (timing_watch). */
TimingWatch timeline_core_watch(Timeline *tl, int k);
/* The shared memory's watch (chip_new), levels named by chip_level_keys. */
MemWatch timeline_mem_watch(Timeline *tl);
/* Core k ran pass `pass` of tile `tile` over [from, to). */
void timeline_pass(Timeline *tl, int k, uint32_t tile, uint32_t pass, uint64_t from, uint64_t to);
/* Whether nothing from cycle `now` on is in the window (a core past it may stop being watched). */
int timeline_past(const Timeline *tl, uint64_t now);
/* The run ended at makespan: each core's cycles without an instruction's busy or stall span up to
 * there are idle. */
void timeline_end(Timeline *tl, uint64_t makespan);
/* Written whole or not at all. 0, or -1 with err naming the file (or saying memory ran out while
 * recording). */
int timeline_write(const Timeline *tl, const char *path, char *err, size_t errlen);
/* The window, for messages. */
void timeline_window(const Timeline *tl, uint64_t *from, uint64_t *to);

#endif
