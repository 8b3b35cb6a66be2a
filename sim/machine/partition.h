/* sim/machine/partition.h -- the partition unit: an in-place partition of an ID stream by the mask
 * bits `pmask` queued, running beside the data path (Gribble & Ramani 2008, Sec. 3.3: built from
 * SIMD comparator units, clocked at 500 MHz).
 *
 * Owns: partition.setup_cycles and partition.ids_per_cycle, the unit's state (busy, the end of
 * its run, the byte range of IDM it reorders), its cost, which instructions it holds back, and the
 * counters (PartStats). Must not: charge a stall (the timing core
 * charges what it holds back to `partition`), push events (the timing core does, at part_hold's
 * time), or move an ID (the functional core does).
 *
 * Cost of `part` over a stream of n IDs: setup + ceil(n / ids_per_cycle) cycles, holding one
 * interconnect port for the whole run (docs/model.md, "Partition unit").
 */
#ifndef SFSIM_MACHINE_PARTITION_H
#define SFSIM_MACHINE_PARTITION_H

#include <stdint.h>

#include "../config.h"
#include "../core.h"
#include "interconnect.h"


typedef struct PartParams {
    int setup;                 /* fixed cycles of one partition */
    int ids_per_cycle;         /* IDs moved per cycle (the config's 0 means N) */
} PartParams;

void part_params(const CfgMachine *c, PartParams *p);

typedef struct PartStats {     /* uint64_t only (timing_stats_add) */
    uint64_t runs;             /* partitions */
    uint64_t ids;              /* ray IDs they moved */
    uint64_t cycles;           /* cycles the unit ran */
} PartStats;

typedef struct PartUnit {
    PartParams p;
    int busy;                  /* still running at the data path's next issue slot */
    uint64_t e;                /* the cycle the last run ends (its port: interconnect.h) */
    uint32_t lo, hi;           /* the IDM byte range it reorders */
    PartStats st;
} PartUnit;

int part_init(PartUnit *u, const PartParams *p);
void part_free(PartUnit *u);
/* Idle for the next program run. */
void part_reset(PartUnit *u);

/* Whether a running partition reorders any byte of [lo, hi). */
static inline int part_overlaps(const PartUnit *u, uint32_t lo, uint32_t hi)
{
    return u->busy && lo < u->hi && u->lo < hi;
}

/* Whether the running partition holds back this instruction: the unit's own instructions wait for
 * it, and so does an ID-stream access into the range it reorders (an ID fetch meets it in the
 * AGUs instead, agu.c). */
int part_blocks(const PartUnit *u, const IsaOpInfo *oi, const CoreRecord *rec);

/* `part` issues at cycle at over n IDs from byte address base: the run starts when an interconnect
 * port is free for it. Returns the cycle the run ends (its result is ready then). */
uint64_t part_start(PartUnit *u, Xbar *x, uint32_t base, uint32_t n, uint64_t at, uint64_t now);

/* After `part` issued: whether the run outlasts the next issue slot `end` (then the unit is busy
 * until u->e, and the timing core schedules part_done for then). */
static inline int part_hold(PartUnit *u, uint64_t end)
{
    if (u->e <= end)
        return 0;
    u->busy = 1;
    return 1;
}

static inline void part_done(PartUnit *u)
{
    u->busy = 0;
}

#endif
