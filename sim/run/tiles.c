/* sim/run/tiles.c -- the tile launcher (see tiles.h). */
#include "tiles.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

typedef struct Pool {
    const TileLaunch *l;
    atomic_uint next, done;
    atomic_int failed;
    /* chained launches (TileLaunch.chain), under lock: the next tile of each chain with no tile
     * running, in a binary min-heap (at most chain entries), and the tiles running; a thread that
     * finds the heap empty while tiles run sleeps on cond, woken by each finished tile and by a
     * failure */
    uint32_t *heap;
    uint32_t nheap, running;
    pthread_mutex_t lock;
    pthread_cond_t cond;
} Pool;

typedef struct Thread {
    Pool *pool;
    int index;
} Thread;

int tiles_threads(int threads, uint32_t ntiles)
{
    int n = threads < 1 ? 1 : threads;
    if ((uint32_t)n > ntiles)
        n = ntiles ? (int)ntiles : 1;
    return n;
}

/* A failure: every thread stops after its current tile, and none waits on a tile that will not
 * run. */
static void pool_fail(Pool *pool)
{
    atomic_store(&pool->failed, 1);
    if (pool->heap) {
        pthread_mutex_lock(&pool->lock);
        pthread_cond_broadcast(&pool->cond);
        pthread_mutex_unlock(&pool->lock);
    }
}

/* Chained: the next tile to run into *t: of the chains with no tile running, the one whose next
 * tile comes first (so passes go out in pass order while the tiles before them are free), after a
 * wait while the heap is empty and tiles run. 0; 1 when every tile is handed out; -1 after a
 * failure. */
static int pool_take(Pool *pool, uint32_t *t)
{
    int rc;
    pthread_mutex_lock(&pool->lock);
    for (;;) {
        if (atomic_load(&pool->failed)) {
            rc = -1;
            break;
        }
        if (pool->nheap) { /* the root out, the last entry sifted down from the root */
            uint32_t *h = pool->heap, n = --pool->nheap, last = h[n], i = 0;
            *t = h[0];
            for (uint32_t c; (c = 2 * i + 1) < n; i = c) {
                if (c + 1 < n && h[c + 1] < h[c])
                    c++;
                if (last <= h[c])
                    break;
                h[i] = h[c];
            }
            h[i] = last;
            pool->running++;
            rc = 0;
            break;
        }
        if (!pool->running) { /* nothing queued and nothing that could queue more */
            rc = 1;
            break;
        }
        pthread_cond_wait(&pool->cond, &pool->lock);
    }
    pthread_mutex_unlock(&pool->lock);
    return rc;
}

/* Chained: tile t finished; the tile that continues it, if any, joins the heap. */
static void pool_finished(Pool *pool, uint32_t t)
{
    const uint32_t k = pool->l->chain;
    pthread_mutex_lock(&pool->lock);
    pool->running--;
    if ((uint64_t)t + k < pool->l->ntiles) { /* sifted up from the end */
        uint32_t *h = pool->heap, i = pool->nheap++, v = t + k;
        for (; i && h[(i - 1) / 2] > v; i = (i - 1) / 2)
            h[i] = h[(i - 1) / 2];
        h[i] = v;
    }
    pthread_cond_broadcast(&pool->cond);
    pthread_mutex_unlock(&pool->lock);
}

static void *thread_main(void *arg)
{
    Thread *th = arg;
    Pool *pool = th->pool;
    const TileLaunch *l = pool->l;
    if (l->begin && l->begin(l->ctx, th->index) != 0) {
        pool_fail(pool);
        if (l->end)
            l->end(l->ctx, th->index);
        return NULL;
    }
    while (!atomic_load(&pool->failed)) {
        uint32_t t;
        if (pool->heap) {
            if (pool_take(pool, &t) != 0)
                break;
        } else {
            t = atomic_fetch_add(&pool->next, 1u);
            if (t >= l->ntiles)
                break;
        }
        if (l->tile(l->ctx, th->index, t) != 0) {
            pool_fail(pool);
            break;
        }
        if (pool->heap)
            pool_finished(pool, t);
        uint32_t done = atomic_fetch_add(&pool->done, 1u) + 1u;
        if (l->progress)
            l->progress(l->progress_ctx, done, l->ntiles);
    }
    if (l->end)
        l->end(l->ctx, th->index);
    return NULL;
}

uint32_t tiles_run(const TileLaunch *l)
{
    Pool pool;
    pool.l = l;
    atomic_init(&pool.next, 0u);
    atomic_init(&pool.done, 0u);
    atomic_init(&pool.failed, 0);
    pool.heap = NULL;
    int n = tiles_threads(l->threads, l->ntiles);
    if (l->chain && n > 1) { /* (one thread alone takes the tiles in order: each after the one it continues) */
        pool.nheap = l->chain < l->ntiles ? l->chain : l->ntiles;
        pool.running = 0;
        pool.heap = malloc((size_t)pool.nheap * sizeof *pool.heap);
        int locked = pool.heap && pthread_mutex_init(&pool.lock, NULL) == 0;
        if (locked && pthread_cond_init(&pool.cond, NULL) != 0) {
            pthread_mutex_destroy(&pool.lock);
            locked = 0;
        }
        if (!locked) { /* no memory: the calling thread runs every tile */
            free(pool.heap);
            pool.heap = NULL;
            n = 1;
        } else {
            for (uint32_t i = 0; i < pool.nheap; i++) /* each chain's first tile: ascending, a heap */
                pool.heap[i] = i;
        }
    }
    Thread local[8], *ths = n <= 8 ? local : malloc((size_t)n * sizeof *ths);
    pthread_t *ids = n > 1 ? malloc((size_t)n * sizeof *ids) : NULL;
    if (!ths || (n > 1 && !ids))
        n = 1; /* no memory for more threads: the calling thread runs every tile */
    if (!ths)
        ths = local;
    int started = 0;
    for (int i = 0; i < n; i++)
        ths[i] = (Thread){&pool, i};
    for (int i = 1; i < n; i++, started++)
        if (pthread_create(&ids[i], NULL, thread_main, &ths[i]) != 0)
            break;
    thread_main(&ths[0]);
    for (int i = 1; i <= started; i++)
        pthread_join(ids[i], NULL);
    free(ids);
    if (ths != local)
        free(ths);
    if (pool.heap) {
        pthread_cond_destroy(&pool.cond);
        pthread_mutex_destroy(&pool.lock);
        free(pool.heap);
    }
    return atomic_load(&pool.done);
}
