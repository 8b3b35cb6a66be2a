/* sim/run/engine_int.h -- the kernel engine's inside (sim/run/engine.c), shared with the chip's
 * run of it (sim/run/chiprun.c): the job of a launch, its workers (one core each), and the steps
 * of a (tile, pass) unit that both take.
 *
 * Owns: nothing of its own (engine.c's types and steps). Must not: be included outside sim/run/.
 */
#ifndef SFSIM_RUN_ENGINE_INT_H
#define SFSIM_RUN_ENGINE_INT_H

#include <pthread.h>
#include <stdatomic.h>

#include "engine.h"
#include "chipunit.h"
#include "timedcore.h"

typedef struct Job {
    const PackedScene *p;
    const FuncParams *fp;
    const Kernel *k;
    float *rgb;
    uint32_t width, height, tiles_x, ntiles;
    FuncTile *tiles;
    uint32_t spp;
    const uint32_t *units;     /* sampled mode: the round's (tile, pass) units, NULL for whole tiles */
    uint32_t *passes_done;     /* func_render, when not NULL: the launch's items are (tile, pass)
                                  units in pass order, each pass after the tile's one before
                                  (run_tile_pass); each tile's passes finished */
    atomic_uint tiles_done;    /* ... and the tiles with every pass finished */
    FuncUnit *unit_out;        /* ... and their figures */
    struct Worker *workers;    /* one per host thread (sim/run/tiles.h) */
    int nworkers;
    atomic_int failed;
    int trapped;               /* the failure was the kernel's (trap, limit, error code) */
    pthread_mutex_t lock;
    char err[1024];
    /* a chip's run (sim/run/chiprun.c): its cores' figures, the makespan, the shared memory's */
    FuncCore *cores;
    uint32_t ncores;
    uint64_t makespan;
    uint64_t *pass_cycles;     /* a chip's frame: tile t's pass p took pass_cycles[t * spp + p] */
    struct ChipCoreStats *pass_mem; /* a wave's: each unit's share of the shared memory's work */
    struct ChipMemStats *chip_mem;
    FuncMemRec *trace;
    size_t ntrace;
} Job;

typedef struct Worker {
    Job *job;
    TimedCore tc;              /* the core; its timing model in the timed modes */
    ChipUnit cu;               /* FuncParams.chip_unit: the chip's shared memory, tc as its core 0 */
    FuncStats st;
} Worker;

/* The job's failure: the first message is kept (trapped: the kernel's own failure). */
void eng_fail(Job *j, const char *msg, int trapped);
/* Tile t placed, its counts zeroed (before its first pass). */
FuncTile *eng_tile_start(Job *j, uint32_t t);
/* A pass's launch block on a restarted core (the framebuffer zeroed for a tile's first pass), and
 * the pass's number in it. */
void eng_pass_launch(Job *j, Core *c, const FuncTile *ft, int zero_fb);
void eng_pass_set(Job *j, Core *c, uint32_t pass);
/* After the pass's run stopped with ex: 0 if it halted without an error code, else -1 after
 * eng_fail() with the tile, the pass and the reason. */
int eng_pass_end(Job *j, Core *c, const FuncTile *ft, uint32_t pass, CoreExit ex);
/* The kernel's counters of the pass just run added to st; its rays returned. */
uint64_t eng_counters_add(Job *j, Core *c, FuncStats *st);
/* `sfsim trace`'s batch t (its rays into a restarted core's RB0; its FuncTile placed), and after
 * the run stopped with ex its hits out and its rays counted into st: 0, or -1 after eng_fail. */
void eng_batch_launch(Job *j, Core *c, uint32_t t);
int eng_batch_end(Job *j, Core *c, uint32_t t, CoreExit ex, FuncStats *st);
/* The tile's pixels between the core's framebuffer and the frame (to_fb: into the framebuffer). */
void eng_tile_pixels(Job *j, Core *c, const FuncTile *ft, int to_fb);
/* A sampled chip's unit (FuncParams.unit_warm_l1): timing model t's L1 warmed for unit `unit`
 * (tile * spp + pass) after its reset. 0, or -1 after eng_fail. */
int eng_warm_l1(Job *j, Timing *t, uint32_t unit);
/* ... and past its tile's first pass, the tile's framebuffer lines (at base in the framebuffer's
 * space) into the chip's shared levels as written (chip_warm_written): its earlier passes left
 * them there. Where in the L2's recency (docs/sampling.md, step 4): pass 1 finds them as pass 0
 * fetched them, at the tile's start (the L1 kept them; the L2 saw them no more), so they go in
 * before the scene's lines (early = 1: only for pass 1); a later pass finds them as the L1 wrote
 * them back during the passes before, so they go in after (early = 0: only for passes >= 2). */
void eng_warm_fb_shared(Job *j, Chip *chip, uint64_t base, uint32_t unit, int early);
/* The framebuffer lines of tiles [lo, hi) but tile `skip`, the last L2-capacity of them, into the
 * chip's shared levels as written, oldest first (FuncParams.unit_warm_tiles). */
void eng_warm_fb_tiles(Job *j, Chip *chip, uint32_t lo, uint32_t hi, uint32_t skip);
/* A tile's framebuffer bytes in the chip's framebuffer space, in whole lines (tile t at t times it). */
uint64_t eng_fb_tile_bytes(const Job *j);
/* Worker `index`'s core opened and the scene loaded (sim/run/tiles.h's begin). */
int eng_worker_begin(void *ctx, int index);
/* The workers' counters into st, in worker order. */
void eng_stats_sum(FuncStats *st, const Worker *ws, int nworkers);

#endif
