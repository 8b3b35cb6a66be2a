/* sim/run/chipwarm.h -- a sampled chip's functional warming (docs/sampling.md, "Sampling a chip",
 * design C step 5): what the shared L2 and a core's L1 hold when a unit starts in the full run, as
 * far as the golden model's record of the scene-memory lines each (tile, pass) unit reads tells it
 * (it tells the BVH nodes box-tested, the primitives of the leaves entered and the shading reads,
 * not the framebuffer's lines, which sim/run/engine.c warms itself).
 *
 * - The L2: every line first read by a unit that starts before this one in a schedule (the first
 *   predicted one: sim/run/chipsampled.c), as a full run's L2 holds them when they fit. One
 *   golden-model pass over the frame finds each line's first reader and how many units read it;
 *   when more lines than the L2 holds qualify, the most read ones are kept (they are the ones LRU
 *   keeps), and the list is ordered least read first.
 * - The L1: the lines of the unit that ran before this one on its core, in the order of their
 *   last use, the last L1-capacity of them. Those units' lines are recorded on demand (one
 *   golden-model run a pass, only their tiles).
 *
 * Owns: the first-reader table and the recorded units' lines. Must not: time anything, choose
 * units, or know the schedule beyond the positions and predecessors it is given.
 */
#ifndef SFSIM_RUN_CHIPWARM_H
#define SFSIM_RUN_CHIPWARM_H

#include <stddef.h>
#include <stdint.h>

#include "../reference.h"

typedef struct ChipWarm ChipWarm;

/* A record for the frame of p rendered as rp says (tile, seed, workload; its units, unit_line,
 * passes and tiles are the record's own), of ntiles x spp units, lines of line_bytes; L2 lists of
 * at most l2_lines lines, L1 lists of at most l1_lines. NULL when out of memory. */
ChipWarm *chipwarm_new(const PackedScene *p, const RefParams *rp, uint32_t ntiles, uint32_t spp, uint32_t line_bytes,
                       size_t l2_lines, size_t l1_lines);
void chipwarm_free(ChipWarm *w);

/* The first-reader table: pos[u] is unit u's position in the schedule's start order (N units).
 * One golden-model pass over the frame on `threads` host threads, of every pass_step-th pass of
 * each tile (0 or 1: all of them; a line that only the passes left out read is then not in the
 * table, and the first reader of one they read first is a later pass: docs/sampling.md, "The
 * warming's record"). 0, or -1 with err. */
int chipwarm_first_readers(ChipWarm *w, const uint32_t *pos, uint32_t pass_step, int threads, char *err,
                           size_t errlen);

/* Lines first read at each position (after chipwarm_first_readers): counts[pos] for pos < npos,
 * the lines of the record whose first reader is at pos (the full run's compulsory misses, as far
 * as the record tells them and the order is the run's). */
void chipwarm_first_counts(const ChipWarm *w, uint32_t npos, double *counts);

/* The L2 warming list of a unit at position `pos` of that order (after chipwarm_first_readers):
 * malloc'd into *list (NULL when empty), *len lines. 0, or -1 out of memory (err says). */
int chipwarm_l2(const ChipWarm *w, uint32_t pos, uint64_t **list, size_t *len, char *err, size_t errlen);

/* The L1 warming lists of n units whose predecessors on their cores are prev[0..n) (UINT32_MAX:
 * none, the list is empty): lists[i] malloc'd (NULL when empty), lens[i] lines, oldest first.
 * The predecessors not yet recorded are, first. 0, or -1 with err. */
int chipwarm_l1(ChipWarm *w, const uint32_t *prev, uint32_t n, int threads, uint64_t **lists, size_t *lens, char *err,
                size_t errlen);

/* Units recorded so far (the first-reader pass not counted), and the golden model's host seconds
 * spent on the record and the table. */
uint32_t chipwarm_recorded(const ChipWarm *w);
double chipwarm_seconds(const ChipWarm *w);

#endif
