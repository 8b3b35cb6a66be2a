/* tests/unit/test_tiles.c -- the tile launcher (sim/run/tiles.h): every tile runs exactly once on
 * any thread count, a failure stops every thread, a worker that cannot start stops the launch,
 * progress counts each finished tile, no tile at all still runs the calling thread, and a chained
 * launch (a frame's passes) runs each chain one tile at a time, in order. */
#include <criterion/criterion.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/run/tiles.h"

#define MAX_TILES 1000
#define MAX_THREADS 16

typedef struct Probe {
    atomic_int runs[MAX_TILES];
    atomic_int begun[MAX_THREADS], ended[MAX_THREADS];
    atomic_uint progress_calls, progress_last_total;
    atomic_int tiles_by_thread[MAX_THREADS];
    int fail_tile;          /* -1: none */
    uint32_t chain;         /* the launch's TileLaunch.chain */
    atomic_int finished[MAX_TILES];
    atomic_int running[MAX_TILES];  /* by chain */
    atomic_int order_errors;
    int fail_begin;         /* thread index whose begin fails, -1: none */
} Probe;

static int p_begin(void *ctx, int index)
{
    Probe *p = ctx;
    atomic_fetch_add(&p->begun[index], 1);
    return index == p->fail_begin ? -1 : 0;
}

static int p_tile(void *ctx, int index, uint32_t t)
{
    Probe *p = ctx;
    atomic_fetch_add(&p->runs[t], 1);
    atomic_fetch_add(&p->tiles_by_thread[index], 1);
    return (int)t == p->fail_tile ? -1 : 0;
}

/* A chained launch's tile: the one it continues has finished, and no other tile of its chain is
 * running. */
static int p_chain_tile(void *ctx, int index, uint32_t t)
{
    Probe *p = ctx;
    uint32_t c = t % p->chain;
    if (atomic_fetch_add(&p->running[c], 1) != 0)
        atomic_fetch_add(&p->order_errors, 1);
    if (t >= p->chain && !atomic_load(&p->finished[t - p->chain]))
        atomic_fetch_add(&p->order_errors, 1);
    for (volatile int spin = 0; spin < (int)(t * 7 % 500); spin++) /* tiles of unequal cost */
        ;
    int rc = p_tile(ctx, index, t);
    if (rc == 0)
        atomic_store(&p->finished[t], 1);
    atomic_fetch_sub(&p->running[c], 1);
    return rc;
}

static void p_end(void *ctx, int index)
{
    Probe *p = ctx;
    atomic_fetch_add(&p->ended[index], 1);
}

static void p_progress(void *ctx, uint32_t done, uint32_t total)
{
    Probe *p = ctx;
    atomic_fetch_add(&p->progress_calls, 1u);
    atomic_store(&p->progress_last_total, total);
    cr_expect_leq(done, total);
}

static Probe *probe_new(void)
{
    Probe *p = calloc(1, sizeof *p);
    cr_assert_not_null(p);
    p->fail_tile = -1;
    p->fail_begin = -1;
    return p;
}

Test(tiles, thread_count)
{
    cr_expect_eq(tiles_threads(0, 10), 1);
    cr_expect_eq(tiles_threads(-3, 10), 1);
    cr_expect_eq(tiles_threads(4, 10), 4);
    cr_expect_eq(tiles_threads(16, 3), 3, "no more threads than tiles");
    cr_expect_eq(tiles_threads(8, 0), 1, "the calling thread, even with no tile");
}

Test(tiles, every_tile_once_on_any_thread_count)
{
    for (int threads = 1; threads <= MAX_THREADS; threads++) {
        Probe *p = probe_new();
        uint32_t n = 997;
        TileLaunch l = {n, threads, p_begin, p_tile, p_end, p, p_progress, p, 0};
        cr_expect_eq(tiles_run(&l), n, "threads %d", threads);
        for (uint32_t t = 0; t < n; t++)
            cr_expect_eq(atomic_load(&p->runs[t]), 1, "tile %u ran %d times on %d threads", t,
                         atomic_load(&p->runs[t]), threads);
        int total = 0;
        for (int i = 0; i < MAX_THREADS; i++) {
            int expect = i < tiles_threads(threads, n) ? 1 : 0;
            cr_expect_eq(atomic_load(&p->begun[i]), expect, "thread %d of %d begun", i, threads);
            cr_expect_eq(atomic_load(&p->ended[i]), expect, "thread %d of %d ended", i, threads);
            total += atomic_load(&p->tiles_by_thread[i]);
        }
        cr_expect_eq(total, (int)n);
        cr_expect_eq(atomic_load(&p->progress_calls), n);
        cr_expect_eq(atomic_load(&p->progress_last_total), n);
        free(p);
    }
}

Test(tiles, a_failed_tile_stops_the_launch)
{
    Probe *p = probe_new();
    p->fail_tile = 5;
    TileLaunch l = {MAX_TILES, 1, p_begin, p_tile, p_end, p, NULL, NULL, 0};
    cr_expect_eq(tiles_run(&l), 5, "tiles 0..4 finished, 5 failed");
    cr_expect_eq(atomic_load(&p->runs[5]), 1);
    cr_expect_eq(atomic_load(&p->runs[6]), 0, "nothing after the failure on one thread");
    cr_expect_eq(atomic_load(&p->ended[0]), 1, "the worker is torn down after a failure");
    free(p);

    /* On several threads each stops after its current tile: far fewer than all tiles run. */
    p = probe_new();
    p->fail_tile = 0;
    TileLaunch l4 = {MAX_TILES, 4, p_begin, p_tile, p_end, p, NULL, NULL, 0};
    uint32_t done = tiles_run(&l4);
    cr_expect_lt(done, MAX_TILES);
    int ran = 0;
    for (int t = 0; t < MAX_TILES; t++)
        ran += atomic_load(&p->runs[t]);
    cr_expect_eq((uint32_t)ran, done + 1, "the finished tiles and the failed one");
    free(p);
}

Test(tiles, a_worker_that_cannot_start_stops_the_launch)
{
    Probe *p = probe_new();
    p->fail_begin = 0;
    TileLaunch l = {100, 1, p_begin, p_tile, p_end, p, NULL, NULL, 0};
    cr_expect_eq(tiles_run(&l), 0);
    cr_expect_eq(atomic_load(&p->runs[0]), 0);
    cr_expect_eq(atomic_load(&p->ended[0]), 1, "end is called for every begun worker");
    free(p);
}

Test(tiles, no_tiles_and_no_hooks)
{
    Probe *p = probe_new();
    TileLaunch l = {0, 4, p_begin, p_tile, p_end, p, p_progress, p, 0};
    cr_expect_eq(tiles_run(&l), 0);
    cr_expect_eq(atomic_load(&p->begun[0]), 1, "the calling thread still begins and ends");
    cr_expect_eq(atomic_load(&p->ended[0]), 1);
    cr_expect_eq(atomic_load(&p->progress_calls), 0);
    free(p);

    p = probe_new();
    TileLaunch bare = {10, 2, NULL, p_tile, NULL, p, NULL, NULL, 0};
    cr_expect_eq(tiles_run(&bare), 10);
    for (int t = 0; t < 10; t++)
        cr_expect_eq(atomic_load(&p->runs[t]), 1);
    free(p);
}

Test(tiles, a_chained_launch_runs_each_chain_in_order_one_tile_at_a_time)
{
    static const uint32_t chains[] = {1, 4, 13, 997, 2000};
    for (size_t i = 0; i < sizeof chains / sizeof chains[0]; i++)
        for (int threads = 1; threads <= MAX_THREADS; threads += 3) {
            Probe *p = probe_new();
            p->chain = chains[i];
            uint32_t n = 997;
            TileLaunch l = {n, threads, p_begin, p_chain_tile, p_end, p, p_progress, p, chains[i]};
            cr_expect_eq(tiles_run(&l), n, "chain %u, %d threads", chains[i], threads);
            for (uint32_t t = 0; t < n; t++)
                cr_expect_eq(atomic_load(&p->runs[t]), 1, "chain %u, %d threads: tile %u ran %d times", chains[i],
                             threads, t, atomic_load(&p->runs[t]));
            cr_expect_eq(atomic_load(&p->order_errors), 0,
                         "chain %u, %d threads: a tile ran before the one it continues, or beside another of its chain",
                         chains[i], threads);
            cr_expect_eq(atomic_load(&p->progress_calls), n);
            free(p);
        }
}

Test(tiles, a_failed_tile_stops_a_chained_launch_without_a_wait_left)
{
    for (int threads = 1; threads <= 8; threads++) {
        Probe *p = probe_new();
        p->chain = 5;
        p->fail_tile = 7; /* chain 2's second tile */
        TileLaunch l = {100, threads, p_begin, p_chain_tile, p_end, p, NULL, NULL, 5};
        uint32_t done = tiles_run(&l);
        cr_expect_lt(done, 100u, "%d threads", threads);
        for (uint32_t t = 12; t < 100; t += 5)
            cr_expect_eq(atomic_load(&p->runs[t]), 0, "%d threads: tile %u ran after the one it continues failed", threads,
                         t);
        int ran = 0;
        for (int t = 0; t < 100; t++)
            ran += atomic_load(&p->runs[t]);
        cr_expect_eq((uint32_t)ran, done + 1, "%d threads: the finished tiles and the failed one", threads);
        for (int i = 0; i < threads; i++)
            cr_expect_eq(atomic_load(&p->ended[i]), 1, "%d threads: worker %d torn down", threads, i);
        free(p);
    }
}
