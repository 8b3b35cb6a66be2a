/* sim/mem/port.h -- how a memory level meets the one below it: a request goes in, the cycle it is
 * done comes out (gem5's request and response ports, reduced to what a level needs of the next).
 *
 * Owns: the shape of a request and of a port. Must not: know what is behind a port. A level
 * holds the MemPort of the level below it and nothing else of it, so a level is put in or taken
 * out by connecting ports (timing_new, the chip), never by changing the level's code.
 *
 * Addresses are byte addresses in one physical space: scene memory at [0, 2^32), the framebuffer
 * at [2^32, 2^33) (MEM_SPACE_FB), so that two spaces never share a line below the core.
 */
#ifndef SFSIM_MEM_PORT_H
#define SFSIM_MEM_PORT_H

#include <stdint.h>

enum { MEM_SPACE_SHIFT = 32 };  /* the framebuffer's addresses: 1 << MEM_SPACE_SHIFT | addr */

typedef struct MemReq {
    uint64_t addr;              /* byte address of the line (physical space above) */
    uint64_t at;                /* the cycle it leaves the level above */
    uint8_t write;              /* 1: a write (a write-back, a framebuffer line), 0: a read */
} MemReq;

typedef struct MemPort {
    /* The cycle the request is done: a read's data are at the level above, a write is taken.
     * UINT64_MAX: the level could not take it (out of memory; an internal error upstream). */
    uint64_t (*request)(void *below, const MemReq *r);
    void *below;
} MemPort;

/* A ready cycle not known yet (a chip's core: the answer of a shared level below its L1 comes
 * later, docs/chip.md): bit 63 set and bit 62 clear, the low 32 bits naming what it waits for, an
 * outstanding line fill or (MEM_PENDING_GROUP) a group of them (sim/timing/pend.c). Such a value
 * compares above every cycle, so a wait on it is seen as a wait; it never ends up in a statistic.
 * UINT64_MAX (a level out of memory) is not one. */
#define MEM_PENDING ((uint64_t)1 << 63)
#define MEM_PENDING_GROUP ((uint64_t)1 << 61)
static inline int mem_pending(uint64_t v) { return (v >> 62) == 2; }
/* The later of two ready cycles when one may be pending: the maximum of two known cycles, or a
 * pending value standing for both (the joiner's). */
typedef uint64_t (*MemJoin)(void *ctx, uint64_t a, uint64_t b);

static inline uint64_t port_request(const MemPort *p, uint64_t addr, int write, uint64_t at)
{
    const MemReq r = {addr, at, (uint8_t)(write != 0)};
    return p->request(p->below, &r);
}

#endif
