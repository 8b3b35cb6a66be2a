/* sim/mem/cache.h -- a set-associative cache with LRU replacement and write-back, in front of a
 * port to the level below (port.h): the scene cache of a core (its L1).
 *
 * Owns: the tags, the LRU stamps, the dirty bits and the fill time of each line, and the hit /
 * miss / write-back counters. Must not: hold data (the functional core does), know what is
 * below its port, or charge stalls. The tag array is allocated on the first access: a run that
 * never touches it never instantiates it.
 *
 * One access to a line at cycle t (docs/model.md, "Scene memory"):
 *   hit:  ready = max(t + hit_latency, the line's fill time if it is still in flight)
 *   miss: the least recently used way takes the line; a dirty victim is written back first (a
 *         write request below, nothing waits for it), then the line is read: ready = the read's
 *         completion as the port answers it
 *   no cache (size 0): every access is a request below, its completion the ready cycle.
 */
#ifndef SFSIM_MEM_CACHE_H
#define SFSIM_MEM_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include "port.h"

typedef struct CacheParams {
    int bytes;                    /* 0: no cache */
    int ways, line_bytes, hit_latency;
} CacheParams;

typedef struct CacheStats {       /* uint64_t only (timing_stats_add) */
    uint64_t accesses, hits, misses, writebacks;
} CacheStats;

typedef struct Cache {
    CacheParams p;
    int sets, line_shift;
    uint64_t set_mask;            /* sets - 1 when sets is a power of two (a mask, not a
                                     division, per access), else 0 */
    uint64_t *tag;                /* sets x ways; line address + 1, 0 = empty */
    uint64_t *ready;              /* fill completion time per way */
    uint64_t *lru;                /* last-use stamp per way */
    uint8_t *dirty;
    uint8_t *from;                /* per way: where a chip's fill came from (cache_fill_done's
                                     from + 1), 0 for a line of the level's own (the bus's) */
    int last_from;                /* the last access's: its line's from when the access waited
                                     for the fill beyond its hit latency, else 0 */
    uint64_t stamp;
    size_t last_way;              /* the way of the last hit or fill (tag index), tried first */
    int instantiated;
    MemPort below;
    MemJoin join;                 /* NULL unless the port answers later (port.h, MEM_PENDING) */
    void *jctx;
    CacheStats st;
} Cache;

int cache_init(Cache *c, const CacheParams *p);
void cache_free(Cache *c);
/* Cold: empty, nothing in flight; counters kept. */
void cache_reset(Cache *c);
/* The level below (before the first access). */
void cache_connect(Cache *c, MemPort below);
/* A port that may answer later (port.h, MEM_PENDING): a hit on a line whose fill is pending is
 * ready at join(its hit cycle, the fill's pending value). */
void cache_set_join(Cache *c, MemJoin join, void *ctx);
/* The fill of the line holding addr, pending as `pending`, came at cycle x from `from` (a chip's
 * TIMING_FROM_L2 or TIMING_FROM_DRAM): the line, if it is still there waiting for that fill, is
 * ready at x, and an access that waits for it past its hit latency says where the fill came from
 * (last_from: from + 1). */
void cache_fill_done(Cache *c, uint64_t addr, uint64_t pending, uint64_t x, int from);
/* The later of two ready cycles, either maybe pending (MemJoin; the plain maximum without one). */
static inline uint64_t cache_join(const Cache *c, uint64_t a, uint64_t b)
{
    if (__builtin_expect(c->join != NULL, 0) && (mem_pending(a) || mem_pending(b)))
        return c->join(c->jctx, a, b);
    return a > b ? a : b;
}
/* The line of a physical byte address (port.h). */
static inline uint64_t cache_line(const Cache *c, uint64_t addr)
{
    return addr >> c->line_shift;
}
/* One access to the line holding physical byte address addr at cycle t; write marks it dirty.
 * Returns the cycle its data are ready, UINT64_MAX only if the tag array cannot be allocated. */
uint64_t cache_access(Cache *c, uint64_t addr, uint64_t t, int write);
/* Whether the line holding addr is in the cache, without touching anything (its way in *way):
 * 0 on a miss, with no cache, or before the first access. */
int cache_peek(const Cache *c, uint64_t addr, size_t *way);
/* n loads that hit the line in `way`, one after another, with nothing between them: their counts
 * and the line's use (cache_access's hit path n times, but for the cycles it returns). */
void cache_hits(Cache *c, size_t way, uint64_t n);
/* Functional warming (docs/sampling.md, "Sampling a chip"): the line holding addr brought in as an
 * access at no time would bring it, most recently used, ready at once, dirty if `dirty`; a victim
 * is dropped (no write-back) and nothing is counted. 0, or -1 if the tag array cannot be
 * allocated (nothing with no cache). */
int cache_warm(Cache *c, uint64_t addr, int dirty);

#endif
