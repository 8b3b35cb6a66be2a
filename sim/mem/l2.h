/* sim/mem/l2.h -- the chip's shared L2 (docs/chip.md): banked, set-associative, LRU, with
 * miss-status registers that merge misses to one line, a number of tag ports per bank, and a
 * write-back or write-through policy; its misses and write-backs go to the level below it
 * (level.h), and it is itself a level (l2_level) that the network or the chip pushes into.
 *
 * Owns: the l2.* keys' model, tags, LRU, dirty and pending lines, the miss-status registers, each
 * bank's queue of requests, and the counters (L2Stats). Must not: hold data, know what is below
 * it, or know which core asked (the answer carries the asker's id).
 *
 * Timing (all in core cycles; docs/model.md, "L2"):
 *  - lines are interleaved over the banks (bank = line mod banks); each bank takes its requests in
 *    arrival order, up to `ports` tag accesses a cycle: a request arriving at cycle a starts at the
 *    first cycle s >= a with a port free (the wait is counted as port_wait);
 *  - a read that hits is answered at s + hit_latency; one whose line is being filled is merged
 *    into that line's miss-status register and answered when the fill comes (merged);
 *  - a read that misses takes a free miss-status register and the least recently used way that is
 *    not being filled, writes that way's line below if it is dirty, and reads its line from below
 *    at s + hit_latency (the tag check first); the fill comes at the cycle the level below answers
 *    it, and answers every read merged into it at that cycle. A bank with no free register (or a
 *    set whose every way is being filled) stops taking requests until a fill frees one (the wait
 *    is mshr_wait);
 *  - a write is a whole line (an L1's write-back or a framebuffer line): write-back: a hit marks
 *    the line dirty, a miss allocates it dirty without reading it from below (the whole line is
 *    written), a write to a line being filled marks it dirty when it comes; write-through: the
 *    line (if present) stays clean and the write goes below at s + hit_latency. A write is answered
 *    at s + hit_latency.
 */
#ifndef SFSIM_MEM_L2_H
#define SFSIM_MEM_L2_H

#include <stddef.h>
#include <stdint.h>

#include "level.h"

typedef struct L2Params {
    int bytes;                  /* total size, over all banks */
    int ways, line_bytes, banks;
    int hit_latency;            /* tag and data access, pipelined */
    int ports;                  /* tag accesses per bank per cycle */
    int mshrs;                  /* miss-status registers per bank */
    int write_back;             /* 1: write-back, write-allocate; 0: write-through, no allocate */
} L2Params;

typedef struct L2Stats {        /* uint64_t only */
    uint64_t reads, writes;     /* requests taken */
    uint64_t hits, misses;      /* of them: found (valid), not found */
    uint64_t merged;            /* requests to a line being filled, merged into its register */
    uint64_t fills;             /* lines read from below */
    uint64_t writebacks;        /* dirty lines written below (evicted, or written through) */
    uint64_t port_wait;         /* cycles requests waited for a tag port */
    uint64_t mshr_wait;         /* cycles a bank's next request waited for a miss-status register */
    uint64_t read_latency;      /* sum over reads of answer - arrival */
    uint64_t mshr_max;          /* most registers of one bank busy at once */
} L2Stats;

/* One core's share of the L2's work (l2_count_cores): the requests whose ids name core k
 * (MEM_ID_CORE), those that hit, and the lines sent below for them (a miss's fill, the dirty line
 * it evicted, a write written through). Summed over the cores: reads + writes, hits, and fills +
 * writebacks of L2Stats. */
typedef struct L2CoreStats {    /* uint64_t only */
    uint64_t accesses, hits, below;
} L2CoreStats;

typedef struct L2 L2;

/* 0, or -1 with the reason in err (a geometry that does not divide: sizes, ways, banks). */
int l2_check(const L2Params *p, char *err, size_t errlen);
L2 *l2_new(const L2Params *p, MemLevel below, char *err, size_t errlen);
void l2_free(L2 *l);
/* Cold: empty, nothing queued or in flight (the level below is reset by its owner); counters kept. */
void l2_reset(L2 *l);
/* Functional warming (a sampled chip's unit: docs/sampling.md): the line of addr brought into its
 * set as a read would bring it, most recently used and clean, the set's least recently used line
 * leaving; no time passes, nothing is counted or sent below. Only on an idle L2 (after l2_reset,
 * before the first push). 1 when the line was not there (a read would have gone below), else 0. */
int l2_warm(L2 *l, uint64_t addr);
/* ... and as a write would leave it: dirty when the L2 writes back (a write-through L2 does not
 * allocate on a write: then nothing changes and 0 is returned). */
int l2_warm_written(L2 *l, uint64_t addr);
const L2Stats *l2_stats(const L2 *l);
/* Count each of `cores` cores' share too (a sampled chip's waves: docs/sampling.md), from zero;
 * 0, or -1 when out of memory (nothing counted). Requests of a core >= cores are not counted. */
int l2_count_cores(L2 *l, int cores);
/* Core k's share, or NULL when not counted. */
const L2CoreStats *l2_core_stats(const L2 *l, int k);
/* The level interface (level.h). */
void l2_push(L2 *l, uint64_t addr, int write, uint64_t cycle, uint64_t id);
uint64_t l2_next(const L2 *l);
void l2_run(L2 *l, uint64_t until, MemAnswer answer, void *ctx);
MemLevel l2_level(L2 *l);

#endif
