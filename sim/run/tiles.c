/* sim/run/tiles.c -- the tile launcher (see tiles.h). */
#include "tiles.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>

typedef struct Pool {
    const TileLaunch *l;
    atomic_uint next, done;
    atomic_int failed;
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

static void *thread_main(void *arg)
{
    Thread *th = arg;
    Pool *pool = th->pool;
    const TileLaunch *l = pool->l;
    if (l->begin && l->begin(l->ctx, th->index) != 0) {
        atomic_store(&pool->failed, 1);
        if (l->end)
            l->end(l->ctx, th->index);
        return NULL;
    }
    while (!atomic_load(&pool->failed)) {
        uint32_t t = atomic_fetch_add(&pool->next, 1u);
        if (t >= l->ntiles)
            break;
        if (l->tile(l->ctx, th->index, t) != 0) {
            atomic_store(&pool->failed, 1);
            break;
        }
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
    int n = tiles_threads(l->threads, l->ntiles);
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
    return atomic_load(&pool.done);
}
