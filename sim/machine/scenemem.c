/* sim/machine/scenemem.c -- the ports of scene-memory instructions (see scenemem.h).
 *
 * Owns: what a scene or framebuffer instruction costs at the core's side. Must not: charge
 * stalls, hold data or cache state.
 */
#include "scenemem.h"

#include <string.h>

#include "lines.h"

void mem_params(const CfgMachine *c, SceneMemParams *p)
{
    p->ports = c->scene_ports;
}

void mem_l1_params(const CfgMachine *c, CacheParams *p)
{
    /* Assumption (docs/model.md): a 64 KB 4-way cache of 64-byte lines suffices because a node
     * load serves a whole stream. */
    p->bytes = c->scene_cache_kb * 1024;
    p->ways = c->scene_cache_ways;
    p->line_bytes = c->scene_line_bytes;
    p->hit_latency = c->scene_hit_latency;
}

int mem_init(SceneMem *m, const SceneMemParams *p)
{
    memset(m, 0, sizeof *m);
    m->p = *p;
    return 0;
}

void mem_reset(SceneMem *m) { (void)m; }

void mem_free(SceneMem *m) { (void)m; }

/* mem_issue of more than one lane: each distinct line is one access. */
static __attribute__((noinline)) uint64_t mem_issue_lanes(SceneMem *m, Cache *l1, uint32_t flags, int write,
                                                          const uint32_t *addr, int naddr, uint64_t at,
                                                          uint64_t *ready)
{
    uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
    for (int i = 0; i < naddr; i++)
        lines[i] = cache_line(l1, mem_phys(m, flags, addr[i]));
    int k = lines_distinct(lines, naddr, d);
    *ready = 0;
    m->last_from = 0;
    uint64_t slot = at;
    for (int i = 0, in_slot = 0; i < k; i++) { /* one line per port-slot: slot = at + i / ports */
        if (in_slot == m->p.ports) {
            slot++;
            in_slot = 0;
        }
        in_slot++;
        const uint64_t r = cache_access(l1, d[i] << l1->line_shift, slot, write);
        if (r > *ready) /* (the first line of the latest ready cycle, in lane order, says where from) */
            m->last_from = l1->last_from;
        *ready = cache_join(l1, *ready, r);
    }
    m->st.instructions++;
    return ((uint64_t)k + (uint64_t)m->p.ports - 1) / (uint64_t)m->p.ports;
}

uint64_t mem_issue(SceneMem *m, Cache *l1, uint32_t flags, const uint32_t *addr, int naddr, uint64_t at,
                   uint64_t *ready)
{
    const int write = (flags & ISA_FL_WRITE) != 0;
    if (naddr != 1)
        return mem_issue_lanes(m, l1, flags, write, addr, naddr, at, ready);
    /* a scalar access: one line, no search for distinct lines */
    *ready = cache_access(l1, mem_phys(m, flags, addr[0]), at, write);
    m->last_from = l1->last_from;
    m->st.instructions++;
    return 1;
}
