/* sim/machine/scenemem.h -- timing of scene memory (BVH, primitives, materials, textures, lights,
 * and the framebuffer): an optional set-associative LRU cache in front of a memory with a latency
 * and a bandwidth, reached through scene.ports line ports. Gribble & Ramani 2008 give no figures
 * for it; every number is an assumption (docs/model.md, "Scene memory").
 *
 * Owns: the scene.* timing keys, cache tags, the memory bus's next free cycle, the port cycles
 * of one scene-memory or framebuffer instruction, hit/miss/traffic counters and scene_instr.
 * Must not: hold data (the functional core does) or charge stalls (sim/timing.c charges the
 * extra port cycles and waits for loaded data to `scene_memory`). The cache's tag array is
 * allocated on the first access: a run whose kernel never touches scene memory never
 * instantiates it.
 *
 * Timing of one line access at cycle t (docs/model.md):
 *   cached hit:  ready = max(t + hit_latency, the line's fill time if it is still in flight)
 *   miss or no cache: the line moves over the bus when it is free, s = max(t, bus_free);
 *                bus_free = s + ceil(line / bytes_per_cycle); ready = s + latency + that transfer
 *   a dirty victim is written back over the bus (bandwidth only; nothing waits for it).
 */
#ifndef SFSIM_MACHINE_SCENEMEM_H
#define SFSIM_MACHINE_SCENEMEM_H

#include <stddef.h>
#include <stdint.h>

#include "../config.h"

struct TimingStats;

typedef struct SceneMemParams {
    int latency, bytes_per_cycle, line_bytes, hit_latency;
    int cache_bytes, ways;        /* cache_bytes = 0: no cache */
    int ports;                    /* lines per cycle an instruction's accesses go through (mem_issue) */
} SceneMemParams;

void mem_params(const CfgMachine *c, SceneMemParams *p);

typedef struct SceneMemStats {
    uint64_t accesses, hits, misses, writebacks, bus_bytes;
} SceneMemStats;

typedef struct SceneMem {
    SceneMemParams p;
    int sets, line_shift, xfer;   /* xfer: bus cycles per line */
    uint64_t set_mask;            /* sets - 1 when sets is a power of two (a mask, not a
                                     division, per access), else 0 */
    uint64_t *tag;                /* sets x ways; line address + 1, 0 = empty */
    uint64_t *ready;              /* fill completion time per way */
    uint64_t *lru;                /* last-use stamp per way */
    uint8_t *dirty;
    uint64_t stamp, bus_free;
    size_t last_way;              /* the way of the last hit or fill (tag index), tried first */
    int instantiated;
    SceneMemStats st;
} SceneMem;

void mem_init(SceneMem *m, const SceneMemParams *p);
void mem_free(SceneMem *m);
/* Back to a cold state (empty cache, idle bus); counters are kept. */
void mem_reset(SceneMem *m);
/* One access to the line holding byte address addr in address space `space` (0 = scene memory,
 * 1 = framebuffer) at cycle t; write marks the line dirty. Returns the cycle its data are ready.
 * Returns UINT64_MAX only if the tag array cannot be allocated. */
uint64_t mem_access(SceneMem *m, int space, uint32_t addr, uint64_t t, int write);
/* Whether the line holding addr is in the cache, without touching anything (a lookup as
 * mem_access's, its way in *way): 0 on a miss, with no cache, or before the first access. */
int mem_peek(const SceneMem *m, int space, uint32_t addr, size_t *way);
/* n loads that hit the line in `way`, one after another, with nothing between them: their counts
 * and the line's use (mem_access's hit path n times, but for the cycles it returns). */
void mem_hits(SceneMem *m, size_t way, uint64_t n);
/* The line number of an address (for counting distinct lines of a gather). */
static inline uint64_t mem_line(const SceneMem *m, int space, uint32_t addr)
{
    return ((uint64_t)space << 32 | addr) >> m->line_shift;
}

/* One scene-memory or framebuffer instruction (flags: its ISA flags; ISA_FL_FB picks the
 * framebuffer, ISA_FL_WRITE marks its lines dirty) of naddr lanes (naddr >= 1) whose first port
 * cycle is `at`: each distinct line is one access, `ports` lines per cycle. Returns its port
 * cycles, ceil(lines / ports); *ready = when the last line's data are there (UINT64_MAX: out of
 * memory for the tag array). Counts the instruction. */
uint64_t mem_issue(SceneMem *m, uint32_t flags, const uint32_t *addr, int naddr, uint64_t at, uint64_t *ready,
                   struct TimingStats *st);

#endif
