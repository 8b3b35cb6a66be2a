/* sim/scenemem.h -- timing of scene memory (BVH, primitives, materials, textures, lights, and
 * the framebuffer): an optional set-associative LRU cache in front of a memory with a latency
 * and a bandwidth.
 *
 * Owns: cache tags, the memory bus's next free cycle, hit/miss/traffic counters.
 * Must not: hold data (the functional core does) or charge stalls (sim/timing.c decides what
 * a late line costs). The cache's tag array is allocated on the first access: a run whose
 * kernel never touches scene memory never instantiates it.
 *
 * Timing of one line access at cycle t (docs/model.md):
 *   cached hit:  ready = max(t + hit_latency, the line's fill time if it is still in flight)
 *   miss or no cache: the line moves over the bus when it is free, s = max(t, bus_free);
 *                bus_free = s + ceil(line / bytes_per_cycle); ready = s + latency + that transfer
 *   a dirty victim is written back over the bus (bandwidth only; nothing waits for it).
 */
#ifndef SFSIM_SCENEMEM_H
#define SFSIM_SCENEMEM_H

#include <stdint.h>

typedef struct SceneMemParams {
    int latency, bytes_per_cycle, line_bytes, hit_latency;
    int cache_bytes, ways;        /* cache_bytes = 0: no cache */
} SceneMemParams;

typedef struct SceneMemStats {
    uint64_t accesses, hits, misses, writebacks, bus_bytes;
} SceneMemStats;

typedef struct SceneMem {
    SceneMemParams p;
    int sets, line_shift, xfer;   /* xfer: bus cycles per line */
    uint64_t *tag;                /* sets x ways; line address + 1, 0 = empty */
    uint64_t *ready;              /* fill completion time per way */
    uint64_t *lru;                /* last-use stamp per way */
    uint8_t *dirty;
    uint64_t stamp, bus_free;
    int instantiated;
    SceneMemStats st;
} SceneMem;

void smem_init(SceneMem *m, const SceneMemParams *p);
void smem_free(SceneMem *m);
/* Back to a cold state (empty cache, idle bus); counters are kept. */
void smem_reset(SceneMem *m);
/* One access to the line holding byte address addr in address space `space` (0 = scene memory,
 * 1 = framebuffer) at cycle t; write marks the line dirty. Returns the cycle its data are ready.
 * Returns UINT64_MAX only if the tag array cannot be allocated. */
uint64_t smem_access(SceneMem *m, int space, uint32_t addr, uint64_t t, int write);
/* The line number of an address (for counting distinct lines of a gather). */
static inline uint64_t smem_line(const SceneMem *m, int space, uint32_t addr)
{
    return ((uint64_t)space << 32 | addr) >> m->line_shift;
}

#endif
