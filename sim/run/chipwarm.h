/* sim/run/chipwarm.h -- a sampled chip's functional warming (docs/sampling.md, "Sampling a chip",
 * design C step 5): the golden model's record of the scene-memory lines each (tile, pass) unit
 * reads, made on demand for the units a warming needs, and a timed unit's warming list.
 *
 * A unit's warming list is the lines of the units that start before it in a schedule (the
 * predicted one: sim/run/chipsampled.c), in the order they start, the last `cap` of them: what a
 * full run's L2 would hold when the unit starts, as far as the golden model tells it (it tells the
 * BVH nodes box-tested, the primitives of the leaves entered and the shading reads, not the
 * framebuffer's lines; docs/sampling.md measures what the record covers).
 *
 * Owns: the record (each recorded unit's distinct line addresses) and the golden-model runs that
 * make it (one a pass among the units asked for, only their tiles). Must not: time anything,
 * choose units, or know the schedule beyond the order it is given.
 */
#ifndef SFSIM_RUN_CHIPWARM_H
#define SFSIM_RUN_CHIPWARM_H

#include <stddef.h>
#include <stdint.h>

#include "../reference.h"

typedef struct ChipWarm ChipWarm;

/* A record for the frame of p rendered as rp says (tile, seed, workload; its units, unit_line,
 * passes and tiles are the record's own), of ntiles x spp units, lines of line_bytes, lists of at
 * most cap lines. NULL when out of memory. */
ChipWarm *chipwarm_new(const PackedScene *p, const RefParams *rp, uint32_t ntiles, uint32_t spp, uint32_t line_bytes,
                       size_t cap);
void chipwarm_free(ChipWarm *w);

/* The warming lists of n units: unit order[pos[i]] gets in lists[i] (malloc'd, the caller frees;
 * NULL when empty) and lens[i] the lines of order[0 .. pos[i]) from the latest back until cap lines
 * are reached, oldest first. order: the frame's N units in the order they start. The units whose
 * lines are needed are recorded first (golden-model runs on `threads` host threads). 0, or -1 with
 * err (the golden model's error, out of memory). */
int chipwarm_lists(ChipWarm *w, const uint32_t *order, const uint32_t *pos, uint32_t n, int threads,
                   uint64_t **lists, size_t *lens, char *err, size_t errlen);

/* Units recorded so far, and the golden model's host seconds spent on them. */
uint32_t chipwarm_recorded(const ChipWarm *w);
double chipwarm_seconds(const ChipWarm *w);

#endif
