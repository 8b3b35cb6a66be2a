/* sim/run/tiles.h -- the tile launcher: one thread pool that hands a frame's tiles (or a trace's
 * ray batches) to host threads, used by every mode -- the golden model, functional, detailed,
 * sampled and trace.
 *
 * Owns: the threads, the order tiles are handed out (a shared counter: the next free tile goes to
 * the next idle thread), the waits of a tile on the one it continues (TileLaunch.chain), stopping
 * every thread after a failure, progress calls. Must not: know
 * what a tile is or hold results: per-thread state lives in the caller's workers, and results
 * never depend on which thread ran which tile or on the thread count (each tile is computed
 * from its own inputs alone; the caller sums per-thread counters in worker order).
 */
#ifndef SFSIM_RUN_TILES_H
#define SFSIM_RUN_TILES_H

#include <stdint.h>

typedef struct TileLaunch {
    uint32_t ntiles;
    int threads;               /* host threads wanted; tiles_threads() says how many run */
    /* Set up thread `index`'s worker (0 .. threads-1; index 0 runs on the calling thread): 0, or
     * -1 to stop the launch (the caller keeps its own message). May be NULL. */
    int (*begin)(void *ctx, int index);
    /* Run tile t on thread `index`: 0, or -1 to stop every thread after its current tile. */
    int (*tile)(void *ctx, int index, uint32_t t);
    /* Tear down thread `index`'s worker, after its last tile or a failure; called for every
     * thread whose begin was called. May be NULL. */
    void (*end)(void *ctx, int index);
    void *ctx;
    /* After each finished tile, from the thread that finished it (may be NULL). */
    void (*progress)(void *ctx, uint32_t tiles_done, uint32_t tiles_total);
    void *progress_ctx;
    /* 0: the tiles are independent. k > 0: tile t >= k continues tile t - k (a frame's passes,
     * tile t being pass t / k of tile t % k): each chain t % k runs one tile at a time in order,
     * a tile starting only after the one it continues finished, on whichever thread takes it
     * (the caller hands state over from one to the next); an idle thread takes the first tile,
     * in index order, of a chain with no tile running, and waits while there is none. */
    uint32_t chain;
} TileLaunch;

/* The threads a launch runs: threads clamped to 1 .. ntiles, and at least 1 (the calling
 * thread, which finds no work when there is no tile). Size the caller's workers by it. */
int tiles_threads(int threads, uint32_t ntiles);

/* Run every tile. Returns the number of tiles finished; it is ntiles unless some call failed
 * (then the caller's message says why). A thread that cannot be started leaves its share of
 * the tiles to the others. */
uint32_t tiles_run(const TileLaunch *l);

#endif
