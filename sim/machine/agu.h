/* sim/machine/agu.h -- the address-generation units: ID-vector fetches decoupled from the data
 * path (Gribble & Ramani 2008, Sec. 3.3: address computation and ID-stream fetch are isolated
 * from data computation and run in parallel with it; the data path stalls when addresses are
 * late, more so at larger N).
 *
 * Owns: agu.ids_per_cycle, agu.queue_depth and latency.agu for a fetch, the queue of ID vectors
 * fetched ahead of the data path and the AGUs' next free cycle, the cost of a fetch, and the
 * counters (AguStats). Must not: charge a stall (agu_serve says how the wait
 * splits; the timing core charges it), or read an ID (the functional core does).
 *
 * A fetch of n IDs: ceil(n / ids_per_cycle) cycles on an interconnect port, then latency.agu of
 * address computation; after each sfetch the AGUs fetch the same stream's next vectors, up to
 * queue_depth of them (docs/model.md, "Address-generation units").
 */
#ifndef SFSIM_MACHINE_AGU_H
#define SFSIM_MACHINE_AGU_H

#include <stdint.h>

#include "../config.h"
#include "interconnect.h"
#include "partition.h"


typedef struct AguParams {
    int lanes;                 /* N: the IDs of one vector */
    int ids_per_cycle;         /* IDs a fetch moves per cycle */
    int depth;                 /* vectors fetched ahead (0: none) */
    int latency;               /* address computation after a fetch (latency.agu) */
} AguParams;

void agu_params(const CfgMachine *c, AguParams *p);

enum { AGU_MAX = 65 };         /* queue slots: agu.queue_depth is at most 64, plus one */

typedef struct AguEntry {      /* an ID vector the AGUs fetch */
    uint32_t addr, n;
    uint64_t ready;            /* the data path may take it from this cycle on */
    uint64_t part_end;         /* it waited for the partition unit until here */
    uint64_t icn_delay;        /* cycles it waited for an interconnect port */
} AguEntry;

typedef struct AguStats {      /* uint64_t only (timing_stats_add) */
    uint64_t fetches;          /* ID vectors fetched */
    uint64_t ahead;            /* of them fetched ahead of the data path's ask */
} AguStats;

typedef struct Agus {
    AguParams p;
    AguEntry q[AGU_MAX];       /* fetched ahead, oldest first, from q[head] */
    int head, n;
    uint64_t free;             /* the first cycle the AGUs can start another fetch */
    AguStats st;
} Agus;

/* How an sfetch's wait for its vector splits: the part spent behind the partition unit, behind
 * a busy interconnect port, and the rest fetching. */
typedef struct AguWait {
    uint64_t partition, interconnect, fetch;
} AguWait;

int agu_init(Agus *a, const AguParams *p);
void agu_free(Agus *a);
/* Empty queue, idle units for the next program run. */
void agu_reset(Agus *a);

/* sfetch of k IDs at byte address addr, with `avail` IDs left in the stream, ready to issue at
 * cycle at (now: the cycle the instruction could first issue in): takes the vector from the
 * queue or fetches it, then fetches the stream's next vectors ahead. Returns the cycle it issues
 * in; *w says how the wait until then splits. */
uint64_t agu_serve(Agus *a, const PartUnit *pu, Xbar *x, uint32_t addr, uint32_t k, uint32_t avail, uint64_t at,
                   uint64_t now, AguWait *w);

/* A partition starts reordering IDM bytes [lo, hi): IDs fetched ahead from there are stale. */
void agu_drop_range(Agus *a, uint32_t lo, uint32_t hi);

#endif
