/* sim/run/engine.h -- the kernel engine: the path-tracing kernel (kernels/pathtrace.s), built for
 * the scene and the machine by sim/run/kernel.c, run on functional cores (and, in the detailed and
 * sampled modes, a timing model hooked to each) over a frame's tiles, a sample's (tile, pass)
 * units or a ray batch. The functional, detailed and sampled modes and `sfsim trace` run through it.
 *
 * Owns: the kernel's runs: the launch block of each (tile, pass) unit or batch, copying the tile
 * in and out of the framebuffer, the ray batch in and the hits out, the kernel's counters read
 * back from the scratchpad, the workers (one timed core per host thread, sim/run/timedcore.h)
 * that sim/run/tiles.c hands the work to, and the figures (FuncStats, FuncTile, FuncUnit) that
 * sim/stats.def reads. Its prefix stays func_ (the kernel on functional cores), the names the
 * statistics registry and the tests know it by.
 * Must not: choose the kernel's symbols or assemble it (sim/run/kernel.c), build acceleration
 * structures (sim/run/accel.c), choose the mode or its defaults (sim/run/run.c calls it), compute
 * any pixel itself, or model time (sim/timing.c does). It calls only down: kernel, tiles,
 * timedcore, the core and the timing model; nothing in sim/run/run.h.
 */
#ifndef SFSIM_RUN_ENGINE_H
#define SFSIM_RUN_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "../../scenes/pack.h"
#include "../config.h"
#include "../core.h"
#include "../raybatch.h"
#include "../timing.h"
#include "kernel.h"

#define FUNC_STAGES 3          /* stream counters: traversal, intersection, shading */

typedef struct FuncParams {
    const CfgMachine *cfg;     /* SIMD width, stream size, memories, instruction limit */
    const char *kernel_path;   /* kernels/pathtrace.s */
    /* p's bytes as a shared image (the opened scene's, RunScene.image: sim/run/run.h), which each
     * core maps copy-on-write; NULL: each core copies p's bytes. It must hold p's bytes unchanged. */
    const CoreImage *image;
    uint32_t needs;            /* SCENE_NEED_* of the scene */
    uint32_t seed;
    int threads;
    void (*progress)(void *ctx, uint32_t tiles_done, uint32_t tiles_total);
    void *progress_ctx;
    /* Trace mode (`sfsim trace`): when batch is set, the kernel is built with TRACE_ONLY and runs
     * traversal and intersection on the batch, M rays per run; hits[i] receives ray i's result
     * and rgb is not touched (may be NULL). */
    const RayBatch *batch;
    BatchHit *hits;
    /* Detailed mode: time every instruction on the machine of cfg (sim/timing.h). Each tile (or
     * trace batch) starts on a cold machine, so the cycles do not depend on the host threads. */
    int timed;
    /* Detailed mode: keep every request the L1s send below (FuncStats.trace; the frame then runs
     * on the chip's run, sim/run/chiprun.c, in one continuous time per core). */
    int mem_trace;
    /* Detailed mode: record the run's timeline here (sim/timeline.h; the frame then runs on the
     * chip's run too), or NULL. */
    struct Timeline *timeline;
    /* Timed, on a chip with shared memory (chip.memory = shared): each tile or unit runs alone on
     * one core of the chip's network, L2 and DRAM, every level cold at its start (sim/run/
     * chipunit.h: a sampled chip's units), instead of the chip's frame. */
    int chip_unit;
    /* With chip_unit: the lines to warm the chip's levels with before unit u (chip_warm: oldest
     * first), or NULL for none; called from the host thread that runs u, several at once. */
    const uint64_t *(*unit_warm)(void *ctx, uint32_t unit, size_t *n);
    void *unit_warm_ctx;
    /* ... and before those, the framebuffer lines of tiles [*lo, *hi) (frame order: the tiles
     * that started before u), as written (chip_warm_written), oldest first, the last L2-capacity
     * of them; u's own tile is left out. NULL: none. Same ctx, same threads. */
    void (*unit_warm_tiles)(void *ctx, uint32_t unit, uint32_t *lo, uint32_t *hi);
    /* With chip_unit or wave: the scene lines to warm unit u's L1 with before it runs (oldest
     * first), or NULL for none; past the tile's first pass its framebuffer's lines are warmed too
     * (before them, dirty: the tile's earlier passes wrote them). Same ctx, same threads. */
    const uint64_t *(*unit_warm_l1)(void *ctx, uint32_t unit, size_t *n);
    /* Detailed, on a chip: the frame only until pass 0 of each of its first K tiles (the chip's
     * first wave, a sampled chip's opening: docs/sampling.md) has ended. Every (tile, pass) unit
     * that ended by then has its exact cycles in FuncStats.pass_cycles (the others 0); the chip's
     * figures are those of that moment (the timing sums hold the busy and stall cycles of the units
     * cut off, not their cycles, so they are not checked), and the picture holds the tiles that
     * ended. */
    int opening;
    /* Detailed, on a chip with shared memory: instead of the frame, one wave (a sampled chip's,
     * docs/sampling.md): unit wave[i] (tile * spp + pass; nwave <= chip.cores) starts on core i
     * at cycle 0, from a cleared launch block as a sampled unit does, after the shared levels are
     * warmed with wave_warm[0..nwave_warm) (oldest first; chip_warm); each core then stops.
     * FuncStats.pass_cycles has the wave's units' cycles (the others 0), FuncStats.pass_mem each
     * one's share of the shared memory's work (chip_core_stats: what its core's requests did from
     * the unit's start to the next's on the core, a core's last unit's to the run's end). With wave_passes = 2 a core whose
     * unit is not its tile's last pass runs the tile's next pass after it, from the state the first
     * left (its L1, the shared levels under the other cores' traffic), and one whose unit is its
     * tile's last pass runs pass 0 of tile wave_next[i] (UINT32_MAX, or wave_next NULL: none);
     * 0 or 1: one unit a core. */
    const uint32_t *wave;
    uint32_t nwave;
    uint32_t wave_passes;
    const uint32_t *wave_next;
    const uint64_t *wave_warm;
    size_t nwave_warm;
    uint32_t wave_fb_lo, wave_fb_hi; /* ... after the framebuffer lines of tiles [lo, hi) as unit_warm_tiles's */
} FuncParams;

typedef struct FuncTile {
    uint32_t x0, y0, w, h;
    uint64_t instructions;
    uint64_t rays;             /* traced, all kinds */
    uint64_t cycles, busy;     /* detailed mode (sampled mode: the tile's sampled units) */
    uint64_t stalls[TM_CAUSE_COUNT];
    uint8_t sampled;           /* timed: every tile in detailed mode; sampled mode: a unit of it was sampled */
    uint32_t units_timed;      /* sampled mode: the tile's units timed */
    uint64_t active_lanes[ISA_STAGE_COUNT]; /* per stage (for sampled mode's utilization) */
    uint32_t core;             /* a chip's run: the core that rendered it */
} FuncTile;

/* Sampled mode's unit: one pass of one tile (unit = tile * spp + pass), run alone from a cleared
 * launch block on a cold machine -- exactly as that pass runs inside detailed mode's frame. */
typedef struct FuncUnit {
    uint32_t unit;
    uint64_t instructions;
    uint64_t rays;             /* traced, all kinds */
    uint64_t cycles, busy;     /* when timed */
    uint64_t stalls[TM_CAUSE_COUNT];
    uint64_t active_lanes[ISA_STAGE_COUNT];
    /* A chip's unit (FuncParams.chip_unit), from its shared levels' counters (ChipMemStats): the
     * requests its L1 sent below, the sum of their read latencies, the L2's accesses (reads and
     * writes) and hits, and DRAM's bytes. */
    uint64_t mem_requests, mem_read_latency, l2_accesses, l2_hits, dram_bytes;
} FuncUnit;

/* A chip's core over the frame (docs/chip.md): busy + stall + idle = the makespan. */
typedef struct FuncCore {
    uint64_t tiles, instructions;
    uint64_t busy, stall, idle;
    uint64_t finish;            /* the cycle its last tile ended (0: it got none) */
    uint64_t stalls[TM_CAUSE_COUNT];
} FuncCore;

/* A request an L1 sent below (FuncParams.mem_trace): in (cycle, core, order sent) order. */
typedef struct FuncMemRec {
    uint64_t cycle, addr;       /* the cycle it left the core; a physical line address (port.h) */
    uint32_t core;
    uint8_t write;
    uint64_t seq;               /* the core's requests so far */
} FuncMemRec;

struct ChipMemStats;

typedef struct FuncStats {
    CoreStats core;                                 /* summed over all tiles */
    uint64_t instructions;
    uint64_t rays_camera, rays_indirect, rays_shadow, dropped;
    uint64_t rays_per_generation[FUNC_MAX_GENERATIONS];
    uint64_t generations;
    /* stream filters run per stage and the rays entering them (average stream length): per
     * generation, and summed */
    uint64_t gen_streams[FUNC_MAX_GENERATIONS][FUNC_STAGES], gen_rays[FUNC_MAX_GENERATIONS][FUNC_STAGES];
    uint64_t trav_streams, trav_rays, isect_streams, isect_rays, shade_streams, shade_rays;
    FuncTile *tiles;                                /* ntiles entries, raster order */
    uint32_t ntiles, tiles_done;                    /* after a failure: the tiles that finished */
    uint32_t kernel_instructions;                   /* program size */
    uint32_t tile_w, tile_h;                        /* pixels (= rays) of a stream's tile */
    char defines[512];                              /* the -D symbols the kernel was built with */
    int unroll_box;                                 /* the box-test loop as built: 1 or 2 (auto resolved) */
    int timed;                                      /* detailed mode: timing holds the sums */
    TimingStats timing;                             /* (sampled mode: of the sampled units) */
    uint32_t tiles_timed;                           /* detailed mode: every tile; sampled: tiles with a unit */
    uint32_t units_timed;                           /* sampled mode: the units run */
    /* accel.structure = kd: the kernel's KD_STACK_DEPTH, and its counters summed over lanes,
     * tiles and threads */
    int kd;
    uint32_t kd_stack_depth;
    uint64_t kd_counts[FUNC_KD_KINDS][FUNC_KD_COUNTERS];
    /* A chip run (chip.cores > 1 or chip.memory = shared, detailed mode): its cores, the frame's
     * cycles (the makespan) and the shared memory's counters (NULL without one). */
    uint32_t chip_cores;                            /* 0: not a chip run */
    FuncCore *cores;
    uint64_t makespan;
    /* a chip's frame (not a ray batch): each (tile, pass) unit's cycles on its core, from its
     * start to its end, tile * pass_spp + pass; NULL otherwise */
    uint64_t *pass_cycles;
    uint32_t pass_spp;
    struct ChipCoreStats *pass_mem;                 /* a wave's (FuncParams.wave), the same layout; else NULL */
    struct ChipMemStats *chip_mem;
    FuncMemRec *trace;                              /* FuncParams.mem_trace */
    size_t ntrace;
} FuncStats;

/* Render the whole image through the kernel: rgb (width * height * 3 floats, zeroed by the
 * caller) receives the mean radiance. 0; -1 with a message for bad input (assembly errors, a
 * scene the kernel cannot render, memories too small); -2 when the kernel itself failed in a
 * tile (a trap, the instruction limit, an error code it set). Free st with func_stats_free. */
int func_render(const PackedScene *p, const FuncParams *fp, float *rgb, FuncStats *st, char *err,
                size_t errlen);
void func_stats_free(FuncStats *st);

/* Sampled mode's units: open a session (the kernel built once, one core per host thread kept
 * across calls), run lists of (tile, pass) units in it (out[i] receives units[i]'s figures; the
 * image is not made), and close it: st then holds the counters of every unit run (st->tiles: the
 * frame's tiles, with the sums of their units). Returns as func_render; a session that failed
 * must still be closed (its st is then partial). */
typedef struct FuncSession FuncSession;
int func_open(const PackedScene *p, const FuncParams *fp, FuncSession **out, char *err, size_t errlen);
int func_units(FuncSession *s, const uint32_t *units, uint32_t n, FuncUnit *out, char *err, size_t errlen);
/* The frame's units: tiles x spp. */
uint64_t func_units_total(const FuncSession *s);
int func_close(FuncSession *s, FuncStats *st, char *err, size_t errlen);

/* `sfsim trace` through the kernel: fp->batch and fp->hits must be set. Same returns. */
int func_trace(const PackedScene *p, const FuncParams *fp, FuncStats *st, char *err, size_t errlen);

#endif
