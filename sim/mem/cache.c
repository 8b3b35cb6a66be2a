/* sim/mem/cache.c -- set-associative LRU write-back cache in front of a port (see cache.h).
 *
 * Owns: tags, LRU, dirty bits, fill times, counters. Must not: hold data or charge stalls.
 */
#include "cache.h"

#include <stdlib.h>
#include <string.h>

int cache_init(Cache *c, const CacheParams *p)
{
    memset(c, 0, sizeof *c);
    c->p = *p;
    int s = 0;
    while ((1 << s) < p->line_bytes)
        s++;
    c->line_shift = s;
    c->sets = p->bytes > 0 ? p->bytes / (p->line_bytes * p->ways) : 0;
    c->set_mask = c->sets > 1 && (c->sets & (c->sets - 1)) == 0 ? (uint64_t)c->sets - 1 : 0;
    return 0;
}

void cache_connect(Cache *c, MemPort below) { c->below = below; }

void cache_set_join(Cache *c, MemJoin join, void *ctx)
{
    c->join = join;
    c->jctx = ctx;
}

void cache_free(Cache *c)
{
    free(c->tag);
    free(c->ready);
    free(c->lru);
    free(c->dirty);
    free(c->from);
    c->tag = c->ready = c->lru = NULL;
    c->dirty = c->from = NULL;
    c->instantiated = 0;
}

void cache_reset(Cache *c)
{
    if (c->instantiated) {
        size_t n = (size_t)c->sets * (size_t)c->p.ways;
        memset(c->tag, 0, n * sizeof *c->tag);
        memset(c->ready, 0, n * sizeof *c->ready);
        memset(c->lru, 0, n * sizeof *c->lru);
        memset(c->dirty, 0, n);
        memset(c->from, 0, n);
    }
    c->stamp = 0;
    c->last_from = 0;
    c->last_way = 0;
}

static int instantiate(Cache *c)
{
    size_t n = (size_t)c->sets * (size_t)c->p.ways;
    c->tag = calloc(n, sizeof *c->tag);
    c->ready = calloc(n, sizeof *c->ready);
    c->lru = calloc(n, sizeof *c->lru);
    c->dirty = calloc(n, 1);
    c->from = calloc(n, 1);
    if (!c->tag || !c->ready || !c->lru || !c->dirty || !c->from) {
        cache_free(c);
        return -1;
    }
    c->instantiated = 1;
    return 0;
}

static inline size_t set_of(const Cache *c, uint64_t line)
{
    return (size_t)(c->set_mask ? line & c->set_mask : line % (uint64_t)c->sets);
}

/* A miss of line (in set) at cycle t: the least recently used way takes it. */
static uint64_t miss(Cache *c, uint64_t line, size_t set, uint64_t t, int write)
{
    const size_t w = (size_t)c->p.ways;
    uint64_t *tag = c->tag + set * w;
    c->st.misses++;
    size_t victim = 0;
    for (size_t i = 1; i < w; i++)
        if (c->lru[set * w + i] < c->lru[set * w + victim])
            victim = i;
    size_t k = set * w + victim;
    if (tag[victim] && c->dirty[k]) { /* write the victim back: nobody waits for it */
        c->st.writebacks++;
        (void)port_request(&c->below, (tag[victim] - 1) << c->line_shift, 1, t);
    }
    tag[victim] = line + 1;
    c->lru[k] = c->stamp;
    c->dirty[k] = (uint8_t)(write != 0);
    c->from[k] = 0;
    c->last_from = 0;
    c->ready[k] = port_request(&c->below, line << c->line_shift, 0, t);
    c->last_way = k;
    return c->ready[k];
}

uint64_t cache_access(Cache *c, uint64_t addr, uint64_t t, int write)
{
    c->st.accesses++;
    if (c->sets == 0) { /* no cache: every access is a request below */
        c->st.misses++;
        c->last_from = 0;
        return port_request(&c->below, addr & ~(((uint64_t)1 << c->line_shift) - 1), write, t);
    }
    if (!c->instantiated && instantiate(c))
        return UINT64_MAX;
    const uint64_t line = cache_line(c, addr);
    c->stamp++;
    /* The way the last hit or fill used first: a kernel reads a node's words one after another,
     * so it usually still holds this line (a line is in at most one way, so that is the hit the
     * search would find). */
    size_t k = c->last_way;
    if (c->tag[k] != line + 1) {
        const size_t set = set_of(c, line);
        const size_t w = (size_t)c->p.ways;
        const uint64_t *tag = c->tag + set * w;
        size_t i = 0;
        while (i < w && tag[i] != line + 1)
            i++;
        if (i == w)
            return miss(c, line, set, t, write);
        k = set * w + i;
        c->last_way = k;
    }
    c->st.hits++;
    c->lru[k] = c->stamp;
    if (write) /* a load leaves the line as it was */
        c->dirty[k] = 1;
    const uint64_t r = t + (uint64_t)c->p.hit_latency;
    c->last_from = c->ready[k] > r ? c->from[k] : 0; /* (a pending fill's: its answer says) */
    if (__builtin_expect(c->join != NULL, 0))
        return cache_join(c, r, c->ready[k]);
    return r > c->ready[k] ? r : c->ready[k];
}

void cache_fill_done(Cache *c, uint64_t addr, uint64_t pending, uint64_t x, int from)
{
    size_t k;
    if (cache_peek(c, addr, &k) && c->ready[k] == pending) {
        c->ready[k] = x;
        c->from[k] = (uint8_t)(from + 1);
    }
}

int cache_peek(const Cache *c, uint64_t addr, size_t *way)
{
    if (c->sets == 0 || !c->instantiated)
        return 0;
    const uint64_t line = cache_line(c, addr);
    if (c->tag[c->last_way] == line + 1) {
        *way = c->last_way;
        return 1;
    }
    const size_t set = set_of(c, line);
    const size_t w = (size_t)c->p.ways;
    for (size_t i = 0; i < w; i++)
        if (c->tag[set * w + i] == line + 1) {
            *way = set * w + i;
            return 1;
        }
    return 0;
}

void cache_hits(Cache *c, size_t way, uint64_t n)
{
    c->st.accesses += n;
    c->st.hits += n;
    c->stamp += n;
    c->lru[way] = c->stamp;
    c->last_way = way;
}

int cache_warm(Cache *c, uint64_t addr, int dirty)
{
    if (c->sets == 0)
        return 0;
    if (!c->instantiated && instantiate(c))
        return -1;
    const uint64_t line = cache_line(c, addr);
    const size_t set = set_of(c, line), w = (size_t)c->p.ways;
    size_t k = set * w, i = 0;
    while (i < w && c->tag[set * w + i] != line + 1)
        i++;
    if (i < w) {
        k = set * w + i;
    } else {
        for (i = 1; i < w; i++) /* the least recently used way, as a miss takes */
            if (c->lru[set * w + i] < c->lru[k])
                k = set * w + i;
        c->tag[k] = line + 1;
        c->dirty[k] = 0;
    }
    c->lru[k] = ++c->stamp;
    c->ready[k] = 0;
    c->from[k] = 0;
    if (dirty)
        c->dirty[k] = 1;
    c->last_way = k;
    return 0;
}
