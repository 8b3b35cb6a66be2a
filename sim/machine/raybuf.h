/* sim/machine/raybuf.h -- the ray buffers: banks, lines, bank conflicts and the alignment of ID
 * vectors (Gribble & Ramani 2008, Sec. 3.3: two 512 KB buffers of 32 banks, two-cycle pipelined
 * access; alignment overhead at N = 8 and 12 from the buffers' larger lines, minimal at N = 16).
 *
 * Owns: raybuf.banks, raybuf.line_bytes, raybuf.access_cycles and raybuf.align_cycles, the
 * per-bank line counts of one access, the cost of a gather or scatter and of an ID vector off a
 * line boundary, when a read's data are back, and its counters (RbStats). Must not: charge a stall (the timing core charges bank conflicts and
 * alignment) or hold data (the functional core does).
 *
 * Line L lives in bank L mod banks; an access takes one cycle per distinct line in its busiest
 * bank (docs/model.md, "Ray buffers").
 */
#ifndef SFSIM_MACHINE_RAYBUF_H
#define SFSIM_MACHINE_RAYBUF_H

#include <stdint.h>

#include "../config.h"
#include "interconnect.h"


typedef struct RbParams {
    int banks;                 /* banks per buffer */
    int line;                  /* line bytes (a power of two); a bank delivers one line per cycle */
    int access;                /* access latency, pipelined (also of ID-stream memory) */
    int align_cycles;          /* extra issue cycles to rotate an ID vector off a line boundary */
} RbParams;

void rb_params(const CfgMachine *c, RbParams *p);

/* Its counters (uint64_t only: timing_stats_add adds a TimingStats as an array). */
typedef struct RbStats {
    uint64_t accesses;         /* gathers and scatters with lanes */
    uint64_t lines;            /* lines they touched */
    uint64_t conflicted;       /* of them with a bank conflict (more than one cycle) */
} RbStats;

typedef struct RayBufs {
    RbParams p;
    int shift;                 /* byte address -> line */
    uint16_t *bank_cnt;        /* lines per bank in the current access, valid where stamped */
    int8_t *bank_head;         /* the bank's first line in the access's list, valid where stamped */
    uint32_t *bank_stamp, stamp;
    /* The last access (rb_access): its lanes' addresses and its counts. An access is a function of
     * its addresses alone, and one whose lanes are the last one's moved by the same whole number of
     * lines (the next field of the same rays: the fields are arrays of line-aligned size) names
     * lines that map one to one onto the last one's, in banks that map one to one too (a power-of-
     * two bank count), so it has the same counts. */
    _Alignas(64) uint32_t last_addr[ISA_MAX_LANES]; /* (compared and copied in vector pieces) */
    int last_n;                /* its lanes (0: none yet) */
    int last_cycles, last_lines;
    RbStats st;
} RayBufs;

/* 0, or -1 when out of memory (then rb_free). */
int rb_init(RayBufs *rb, const RbParams *p);
void rb_reset(RayBufs *rb);
void rb_free(RayBufs *rb);

/* A gather or scatter of naddr lanes (naddr >= 1): the cycles the banks need, the most distinct
 * lines any one bank serves. Counts the access, its lines and whether it had a conflict. addr
 * holds at least 16 words however small naddr is (a CoreRecord's addr does): the access is kept
 * for the next as 16 words in one copy, the words past naddr never compared. */
int rb_access(RayBufs *rb, const uint32_t *addr, int naddr);
/* rb_access in two steps: the cycles (the lines in last_lines), counting nothing; then the
 * counts of that access (a gather a replayed block takes in: the timing model's memo compares
 * the cycles first, and counts the access only when its replay goes on). */
int rb_cycles(RayBufs *rb, const uint32_t *addr, int naddr);
void rb_count(RayBufs *rb, uint64_t n);

/* Extra issue cycles of an ID vector read or appended at byte address base. */
static inline uint64_t rb_align_cycles(const RayBufs *rb, uint32_t base)
{
    return (base & (uint32_t)(rb->p.line - 1)) ? (uint64_t)rb->p.align_cycles : 0;
}

/* When a gather whose last issue cycle is `last` delivers: the pipelined bank access, then the
 * interconnect back to the lanes. */
static inline uint64_t rb_gather_ready(const RayBufs *rb, const Xbar *x, uint64_t last)
{
    return last + (uint64_t)rb->p.access + (uint64_t)x->p.latency;
}

/* When a scalar ID-stream read (sld) delivers: one access of the same banked memory, no
 * interconnect. */
static inline uint64_t rb_scalar_ready(const RayBufs *rb, uint64_t last)
{
    return last + (uint64_t)rb->p.access;
}

#endif
