/* sim/timeline_int.h -- the timeline's inside (sim/timeline.c records, sim/timeline_write.c
 * writes): its events, lists and per-core state.
 *
 * Owns: nothing of its own. Must not: be included outside sim/timeline*.c.
 */
#ifndef SFSIM_TIMELINE_INT_H
#define SFSIM_TIMELINE_INT_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "chip/chip.h"
#include "timeline.h"

/* What an event is called: the issue track's kinds, a unit, a pass, a request, an instruction. */
enum {
    N_BUSY, N_IDLE, N_STALL,                        /* N_STALL + TmCause */
    N_FROM = N_STALL + TM_CAUSE_COUNT,              /* N_FROM + TIMING_FROM_L2 / _DRAM */
    N_UNIT = N_FROM + 2,                            /* N_UNIT + TIMING_UNIT_* */
    N_PASS = N_UNIT + TIMING_UNIT_COUNT,
    N_READ, N_WRITE, N_INSTR
};
/* A core's threads (the format's tid), and the memory's (one per level, from T_LEVEL). */
enum { T_ISSUE, T_WORK, T_UNIT, T_BUS = T_UNIT + TIMING_UNIT_COUNT, T_PIPE, T_COUNT };
enum { T_LEVEL = 0 };

typedef struct TlEv {
    uint64_t from, to;
    uint32_t name;
    uint32_t c;                /* N_INSTR: the cause charged most before it (N_STALL + cause), or 0 */
    uint64_t a, b;             /* N_PASS: tile, pass; requests: address, id; N_INSTR: pc | op << 32,
                                  stall cycles */
} TlEv;

typedef struct TlList {
    TlEv *v;
    size_t n, cap;
} TlList;

typedef struct TlCharge {
    uint32_t name;
    uint64_t n;
} TlCharge;

typedef struct TlCore {
    struct Timeline *tl;
    int k;
    TlList t[T_COUNT];
    TlCharge *ch;              /* the charges of the instruction being timed */
    size_t nch, capch;
    uint64_t nreq;             /* requests of its bus: their ids */
    uint64_t mismatch;         /* instructions whose charges did not fill their cycles (a model error) */
    int oom;
} TlCore;

typedef struct TlOpen {        /* a request in a shared level, not answered yet */
    uint64_t key;              /* 0: a free slot; 1: a removed one */
    uint64_t at, addr;
    int write;
} TlOpen;

struct Timeline {
    uint64_t from, to;
    int cores, pipeline;
    double clock_mhz;
    TlCore *core;
    TlList level[CHIP_LEVELS];
    TlOpen *open;              /* open addressing by key (level, id) */
    size_t nopen, capopen, used;
    int oom;
};

#endif
