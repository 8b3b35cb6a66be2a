/* tests/unit/test_cache.c -- the scene cache (sim/mem/cache.c), the paper's bus behind it
 * (sim/mem/bus.c) and the scene-memory ports in front of it (sim/machine/scenemem.c): hand-derived
 * cycles, and the cache against a plain LRU cache written from docs/model.md ("Scene memory").
 */
#include <criterion/criterion.h>
#include <string.h>

#include "../../sim/machine/scenemem.h"
#include "../../sim/mem/bus.h"
#include "../../sim/mem/cache.h"
#include "../support/rng.h"

/* An L1 joined to a bus through its port, as timing_new joins them. */
typedef struct L1 {
    Cache c;
    Bus b;
} L1;

static void l1_open(L1 *f, BusParams bp, CacheParams cp)
{
    cr_assert_eq(bus_init(&f->b, &bp), 0);
    cr_assert_eq(cache_init(&f->c, &cp), 0);
    cache_connect(&f->c, bus_port(&f->b));
}

static void l1_close(L1 *f)
{
    cache_free(&f->c);
    bus_free(&f->b);
}

/* An access to byte addr of scene memory (space 0) or the framebuffer (space 1). */
static uint64_t l1_access(L1 *f, int space, uint32_t addr, uint64_t t, int write)
{
    return cache_access(&f->c, space ? (uint64_t)1 << MEM_SPACE_SHIFT | addr : addr, t, write);
}

/* The reference's parameters: bus latency and bytes per cycle, line, hit latency. */
typedef struct RefParams {
    int latency, bytes_per_cycle, line_bytes, hit_latency;
} RefParams;

Test(cache, scene_ports_serve_lines_in_slots)
{
    /* 64 sets x 4 ways (a power of two: the set is a mask) and 3 sets x 4 ways (a division); 3
     * ports; hit latency 2. Seven lines are filled, then one gather of the same seven hits them:
     * line i goes through slot at + i / 3, so the last is served at 100 + 2, ready 104, and the
     * gather needs ceil(7 / 3) = 3 issue cycles. */
    static const int cache_bytes[2] = {64 * 4 * 64, 3 * 4 * 64};
    for (int c = 0; c < 2; c++) {
        L1 f;
        l1_open(&f, (BusParams){10, 16, 64}, (CacheParams){cache_bytes[c], 4, 64, 2});
        SceneMem m;
        mem_init(&m, &(SceneMemParams){3});
        uint32_t addr[7];
        for (int i = 0; i < 7; i++) {
            addr[i] = 64u * (uint32_t)i + 4u;
            l1_access(&f, 0, addr[i], 0, 0);
        }
        const uint64_t hits0 = f.c.st.hits;
        uint64_t ready = 0;
        cr_expect_eq(mem_issue(&m, &f.c, 0, addr, 7, 100, &ready), 3, "cache of %d bytes", cache_bytes[c]);
        cr_expect_eq(ready, 104, "cache of %d bytes: ready %llu", cache_bytes[c], (unsigned long long)ready);
        cr_expect_eq(f.c.st.hits - hits0, 7, "cache of %d bytes", cache_bytes[c]);
        cr_expect_eq(m.st.instructions, 1);
        mem_free(&m);
        l1_close(&f);
    }
}

Test(cache, scene_cache_lru_and_bus)
{
    /* 2 sets x 2 ways of 64-byte lines; latency 10, 16 bytes per cycle (4 cycles a line); one port. */
    L1 f;
    l1_open(&f, (BusParams){10, 16, 64}, (CacheParams){256, 2, 64, 1});
    cr_assert_eq(f.c.instantiated, 0, "the tag array exists before the first access");
    cr_expect_eq(l1_access(&f, 0, 0, 0, 0), 14);       /* miss: bus 0..3, ready 0 + 10 + 4 */
    cr_expect_eq(f.c.instantiated, 1);
    cr_expect_eq(l1_access(&f, 0, 128, 0, 0), 18);     /* same set, other way: bus 4..7 */
    cr_expect_eq(l1_access(&f, 0, 4, 20, 0), 21);      /* hit on line 0 (now most recent) */
    cr_expect_eq(l1_access(&f, 0, 256, 30, 1), 44);    /* miss evicts line 128 (LRU), dirty */
    cr_expect_eq(l1_access(&f, 0, 0, 50, 0), 51);      /* line 0 still there */
    cr_expect_eq(l1_access(&f, 0, 128, 60, 0), 78);    /* 128 again: evicts dirty 256: write-back 60..63, fill 64..67 */
    cr_expect_eq(f.c.st.writebacks, 1);
    cr_expect_eq(f.c.st.hits, 2);
    cr_expect_eq(f.c.st.misses, 4);
    cr_expect_eq(f.b.st.requests, 5, "four fills and a write-back over the bus");
    cr_expect_eq(l1_access(&f, 1, 0, 100, 0), 114);    /* framebuffer address 0 is another line */
    cache_reset(&f.c);
    bus_reset(&f.b);
    cr_expect_eq(l1_access(&f, 0, 0, 0, 0), 14, "reset leaves a cold cache");
    l1_close(&f);
}

Test(cache, warming_brings_lines_in_as_reads_would_at_no_time)
{
    /* 2 sets x 2 ways of 64-byte lines; latency 10, 16 bytes per cycle (4 cycles a line). Lines 0,
     * 128 and 256 share set 0: warming 0, 128, 256 in that order leaves 128 and 256 (0 was least
     * recently used); 256 warmed dirty. Nothing is counted and the bus stays idle, so the first
     * read that misses starts at once: line 0 at cycle 0 evicts 128 (the least recent, clean: no
     * write-back), bus 0..3, ready 14; 256 hits (ready 21 at 20); 128 at 30 evicts 0 (now the
     * least recent, clean), bus 30..33, ready 44; 0 at 50 evicts the dirty 256: its write-back on
     * the bus 50..53, the fill 54..57, ready 68. */
    L1 f;
    l1_open(&f, (BusParams){10, 16, 64}, (CacheParams){256, 2, 64, 1});
    cr_assert_eq(cache_warm(&f.c, 0, 0), 0);
    cr_assert_eq(cache_warm(&f.c, 128, 0), 0);
    cr_assert_eq(cache_warm(&f.c, 256, 1), 0);
    cr_expect_eq(f.c.st.accesses + f.c.st.hits + f.c.st.misses + f.c.st.writebacks, 0, "warming counts nothing");
    cr_expect_eq(f.b.st.requests, 0, "warming sends nothing below");
    cr_expect_eq(l1_access(&f, 0, 0, 0, 0), 14);
    cr_expect_eq(l1_access(&f, 0, 256, 20, 0), 21);
    cr_expect_eq(l1_access(&f, 0, 128, 30, 0), 44);
    cr_expect_eq(f.c.st.writebacks, 0, "the warmed clean lines leave without a write-back");
    cr_expect_eq(l1_access(&f, 0, 0, 50, 0), 68);
    cr_expect_eq(f.c.st.writebacks, 1, "the line warmed dirty is written back");
    cr_expect_eq(f.c.st.hits, 1);
    cr_expect_eq(f.c.st.misses, 3);
    l1_close(&f);
    /* no cache: nothing to warm */
    l1_open(&f, (BusParams){10, 16, 64}, (CacheParams){0, 2, 64, 1});
    cr_expect_eq(cache_warm(&f.c, 0, 1), 0);
    cr_expect_eq(f.c.instantiated, 0);
    l1_close(&f);
}

/* A plain set-associative LRU cache with the same bus and latencies as docs/model.md gives them
 * ("Scene memory"): the reference for the cache's shortcuts (the way of the last hit tried first). */
typedef struct RefCache {
    int sets, ways;
    uint64_t tag[64][8], ready[64][8], used[64][8], clock, bus_free;
    uint8_t dirty[64][8];
    uint64_t hits, misses, writebacks;
} RefCache;

static uint64_t ref_cache_access(RefCache *c, const RefParams *p, int space, uint32_t addr, uint64_t t,
                                 int write)
{
    const uint64_t line = ((uint64_t)space << 32 | addr) / (uint64_t)p->line_bytes;
    const int set = (int)(line % (uint64_t)c->sets), xfer = (p->line_bytes + p->bytes_per_cycle - 1) / p->bytes_per_cycle;
    c->clock++;
    for (int w = 0; w < c->ways; w++)
        if (c->tag[set][w] == line + 1) {
            c->hits++;
            c->used[set][w] = c->clock;
            c->dirty[set][w] |= (uint8_t)(write != 0);
            const uint64_t r = t + (uint64_t)p->hit_latency;
            return r > c->ready[set][w] ? r : c->ready[set][w];
        }
    c->misses++;
    int v = 0;
    for (int w = 1; w < c->ways; w++)
        if (c->used[set][w] < c->used[set][v])
            v = w;
    if (c->tag[set][v] && c->dirty[set][v]) {
        c->writebacks++;
        c->bus_free = (t > c->bus_free ? t : c->bus_free) + (uint64_t)xfer;
    }
    const uint64_t s = t > c->bus_free ? t : c->bus_free;
    c->bus_free = s + (uint64_t)xfer;
    c->tag[set][v] = line + 1;
    c->used[set][v] = c->clock;
    c->dirty[set][v] = (uint8_t)(write != 0);
    c->ready[set][v] = s + (uint64_t)p->latency + (uint64_t)xfer;
    return c->ready[set][v];
}

Test(cache, scene_cache_matches_a_plain_lru_cache_on_random_accesses)
{
    /* Runs of words of one line (a node read word by word), lines of one set in turn, other lines,
     * the framebuffer and writes, at 1, 2 and 4 ways and power-of-two and other set counts. */
    static const int shapes[][2] = {{16, 4}, {3, 4}, {8, 2}, {5, 1}, {64, 1}};
    uint64_t seed = TEST_RNG_SEED;
    for (size_t k = 0; k < sizeof shapes / sizeof *shapes; k++) {
        const int sets = shapes[k][0], ways = shapes[k][1];
        const RefParams p = {10, 16, 64, 2};
        L1 f;
        l1_open(&f, (BusParams){10, 16, 64}, (CacheParams){sets * ways * 64, ways, 64, 2});
        static RefCache ref;
        memset(&ref, 0, sizeof ref);
        ref.sets = sets;
        ref.ways = ways;
        uint32_t addr = 0;
        uint64_t t = 0;
        for (int i = 0; i < 40000; i++) {
            const uint32_t r = test_rng_u32(&seed) % 16u;
            if (r < 8) /* the next word of the same line */
                addr = (addr & ~63u) | ((addr + 4u) & 63u);
            else if (r < 12) /* another line of the same set */
                addr += 64u * (uint32_t)sets * (1u + test_rng_u32(&seed) % (uint32_t)(ways + 1));
            else /* anywhere in 64 KB */
                addr = 4u * (test_rng_u32(&seed) % 16384u);
            const int space = test_rng_u32(&seed) % 16u == 0, write = test_rng_u32(&seed) % 8u == 0;
            t += test_rng_u32(&seed) % 6u;
            const uint64_t got = l1_access(&f, space, addr, t, write);
            const uint64_t want = ref_cache_access(&ref, &p, space, addr, t, write);
            cr_assert_eq(got, want, "%d sets x %d ways, access %d (address %u, space %d): ready %llu, want %llu", sets,
                         ways, i, addr, space, (unsigned long long)got, (unsigned long long)want);
            if (i == 20000) { /* a reset leaves both cold */
                cache_reset(&f.c);
                bus_reset(&f.b);
                memset(ref.tag, 0, sizeof ref.tag);
                memset(ref.used, 0, sizeof ref.used);
                memset(ref.ready, 0, sizeof ref.ready);
                memset(ref.dirty, 0, sizeof ref.dirty);
                ref.clock = ref.bus_free = 0;
            }
        }
        cr_expect_eq(f.c.st.hits, ref.hits, "%d sets x %d ways", sets, ways);
        cr_expect_eq(f.c.st.misses, ref.misses, "%d sets x %d ways", sets, ways);
        cr_expect_eq(f.c.st.writebacks, ref.writebacks, "%d sets x %d ways", sets, ways);
        cr_expect(ref.hits > 10000 && ref.misses > 1000, "%d sets x %d ways: %llu hits, %llu misses", sets, ways,
                  (unsigned long long)ref.hits, (unsigned long long)ref.misses);
        l1_close(&f);
    }
}


/* A level below that answers later (a chip's, sim/mem/port.h): every read gets a pending value. */
static uint64_t later_request(void *below, const MemReq *r)
{
    uint32_t *n = below;
    return r->write ? r->at : MEM_PENDING | (*n)++;
}

Test(cache, a_fill_says_where_it_came_from)
{
    /* Line A misses at 0 (pending); its answer comes from DRAM at 100 (cache_fill_done, from 1 =
     * TIMING_FROM_DRAM). A hit on A at 10 waits for the fill (hit latency 2: 12 < 100): the access
     * says DRAM (from + 1 = 2). A hit at 200 waits for nothing of the fill: 0. A miss: 0. Through
     * the scene-memory ports: a two-line access whose latest line is A's (ready 300, from the L2)
     * says the L2 (1); the other line, B, is the bus's own. */
    Cache c;
    cr_assert_eq(cache_init(&c, &(CacheParams){64 * 4 * 64, 4, 64, 2}), 0);
    uint32_t fills = 0;
    cache_connect(&c, (MemPort){later_request, &fills});
    const uint64_t p = cache_access(&c, 0x40, 0, 0);
    cr_assert(mem_pending(p));
    cr_assert_eq(c.last_from, 0);
    cache_fill_done(&c, 0x40, p, 100, 1);
    cr_assert_eq(cache_access(&c, 0x44, 10, 0), 100);
    cr_assert_eq(c.last_from, 2, "a hit waiting for a fill DRAM answered");
    cr_assert_eq(cache_access(&c, 0x48, 200, 0), 202);
    cr_assert_eq(c.last_from, 0, "a hit after the fill waits for its hit latency only");
    const uint64_t q = cache_access(&c, 0x1000, 210, 0);
    cr_assert(mem_pending(q));
    cr_assert_eq(c.last_from, 0);
    cache_fill_done(&c, 0x1000, q, 250, -1); /* (-1: a fill of the level's own: from 0) */
    const uint64_t p2 = cache_access(&c, 0x2040, 260, 0); /* a third line, then A's again in flight */
    cache_fill_done(&c, 0x2040, p2, 300, 0);
    SceneMem m;
    mem_init(&m, &(SceneMemParams){2});
    uint64_t ready;
    const uint32_t two[2] = {0x1000, 0x2040};
    cr_assert_eq(mem_issue(&m, &c, 0, two, 2, 270, &ready), 1);
    cr_assert_eq(ready, 300);
    cr_assert_eq(m.last_from, 1, "the latest line's fill came from the L2");
    const uint32_t own[1] = {0x1000};
    mem_issue(&m, &c, 0, own, 1, 280, &ready);
    cr_assert_eq(ready, 282);
    cr_assert_eq(m.last_from, 0);
    mem_free(&m);
    cache_free(&c);
}
