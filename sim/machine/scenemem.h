/* sim/machine/scenemem.h -- the core's side of scene memory (BVH, primitives, materials,
 * textures, lights, and the framebuffer): the line ports a scene-memory or framebuffer
 * instruction goes through to the core's scene cache, its L1 (sim/mem/cache.h), whose misses
 * leave through a port (sim/mem/port.h) to what lies below: the paper's bus (sim/mem/bus.h) on
 * the default machine. Gribble & Ramani 2008 give no figures for any of it; every number is an
 * assumption (docs/model.md, "Scene memory").
 *
 * Owns: the scene.ports key, the port cycles of one instruction, the L1's parameters from the
 * scene.* keys (mem_l1_params), the count of scene-memory instructions. Must not: hold data (the
 * functional core does), hold cache state (the L1 does) or charge stalls (sim/timing.c charges
 * the extra port cycles and waits for loaded data to `scene_memory`).
 */
#ifndef SFSIM_MACHINE_SCENEMEM_H
#define SFSIM_MACHINE_SCENEMEM_H

#include <stdint.h>

#include "../config.h"
#include "../mem/cache.h"

typedef struct SceneMemParams {
    int ports;                    /* lines per cycle an instruction's accesses go through (mem_issue) */
} SceneMemParams;

void mem_params(const CfgMachine *c, SceneMemParams *p);
/* The L1 scene cache's parameters from the scene.* keys. */
void mem_l1_params(const CfgMachine *c, CacheParams *p);

typedef struct SceneMemStats {    /* uint64_t only (timing_stats_add) */
    uint64_t instructions;        /* scene-memory and framebuffer instructions */
} SceneMemStats;

typedef struct SceneMem {
    SceneMemParams p;
    uint64_t fb_base;          /* where the core's framebuffer starts in the framebuffer space (a
                                  chip: its tile's place in the frame's; else 0) */
    int last_from;             /* mem_issue's: where its latest line's fill came from (Cache.from),
                                  when the access waited for it; else 0 */
    SceneMemStats st;
} SceneMem;

int mem_init(SceneMem *m, const SceneMemParams *p);
void mem_reset(SceneMem *m);
void mem_free(SceneMem *m);

/* The physical address (sim/mem/port.h) of byte addr of an instruction with ISA flags `flags`:
 * ISA_FL_FB picks the framebuffer's space. */
static inline uint64_t mem_phys(const SceneMem *m, uint32_t flags, uint32_t addr)
{
    return (flags & ISA_FL_FB) ? ((uint64_t)1 << MEM_SPACE_SHIFT) + m->fb_base + addr : addr;
}

/* One scene-memory or framebuffer instruction (flags: its ISA flags; ISA_FL_FB picks the
 * framebuffer, ISA_FL_WRITE marks its lines dirty) of naddr lanes (naddr >= 1) whose first port
 * cycle is `at`, through the L1 l1: each distinct line is one access, `ports` lines per cycle.
 * Returns its port cycles, ceil(lines / ports); *ready = when the last line's data are there
 * (UINT64_MAX: out of memory for the tag array). Counts the instruction. */
uint64_t mem_issue(SceneMem *m, Cache *l1, uint32_t flags, const uint32_t *addr, int naddr, uint64_t at,
                   uint64_t *ready);

#endif
