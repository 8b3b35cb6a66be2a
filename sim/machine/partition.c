/* sim/machine/partition.c -- the partition unit's cost and hazards (see partition.h; the model
 * and its sources: docs/model.md, "Partition unit").
 *
 * Owns: what one partition costs and whom it holds back. Must not: charge stalls or push events.
 */
#include "partition.h"

#include <string.h>

void part_params(const CfgMachine *c, PartParams *p)
{
    p->setup = c->partition_setup_cycles;
    /* Gribble & Ramani 2008, Sec. 3.3: the unit is built from SIMD comparator units, so by
     * default it moves N IDs per cycle. */
    p->ids_per_cycle = c->partition_ids_per_cycle ? c->partition_ids_per_cycle : c->core_simd_width;
}

int part_init(PartUnit *u, const PartParams *p)
{
    memset(u, 0, sizeof *u);
    u->p = *p;
    return 0;
}

void part_free(PartUnit *u) { (void)u; }

void part_reset(PartUnit *u)
{
    u->busy = 0;
    u->e = 0;
}

int part_blocks(const PartUnit *u, const IsaOpInfo *oi, const CoreRecord *rec)
{
    if (!u->busy)
        return 0;
    if (oi->unit == ISA_U_PART) /* pmask, part, pclr */
        return 1;
    if ((oi->flags & ISA_FL_IDM) && !isa_id_fetch(oi->flags) && rec->naddr > 0) {
        uint32_t lo = rec->addr[0], hi = rec->addr[rec->naddr - 1] + 4;
        return part_overlaps(u, lo, hi);
    }
    return 0;
}

uint64_t part_start(PartUnit *u, Xbar *x, uint32_t base, uint32_t n, uint64_t at, uint64_t now)
{
    /* Assumption (docs/model.md): a stable partition by a mask is one pass over the stream. */
    const uint64_t cost = (uint64_t)u->p.setup + (n + (uint64_t)u->p.ids_per_cycle - 1) / (uint64_t)u->p.ids_per_cycle;
    const uint64_t s = xbar_transfer(x, XBAR_PART, at, cost, now);
    u->e = s + cost;
    u->lo = base;
    u->hi = base + 4 * n;
    u->st.runs++;
    u->st.ids += n;
    u->st.cycles += cost;
    return u->e;
}
