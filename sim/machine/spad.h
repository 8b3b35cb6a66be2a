/* sim/machine/spad.h -- the scratchpad's ports (Gribble & Ramani 2008, Sec. 3.3: a dual-ported
 * scratchpad holds the traversal stack and intermediates).
 *
 * Owns: spad.ports, spad.latency and spad.line_bytes, the cost of one access, when a load's data
 * are back, and its counters (SpadStats). Must not: charge a stall (the timing
 * core charges the extra port cycles to `scratchpad`) or hold data (the functional core does).
 *
 * An access touching k distinct lines takes ceil(k / ports) issue cycles; a load's data are
 * ready spad.latency cycles after its last issue cycle (docs/model.md, "Scratchpad").
 */
#ifndef SFSIM_MACHINE_SPAD_H
#define SFSIM_MACHINE_SPAD_H

#include <stdint.h>

#include "../config.h"


typedef struct SpadParams {
    int ports;                 /* lines per cycle */
    int latency;               /* load latency */
    int line;                  /* port width in bytes (a power of two) */
} SpadParams;

void spad_params(const CfgMachine *c, SpadParams *p);

typedef struct SpadStats {     /* uint64_t only (timing_stats_add) */
    uint64_t accesses;         /* scratchpad accesses */
    uint64_t lines;            /* lines they touched */
} SpadStats;

typedef struct Spad {
    SpadParams p;
    int shift;                 /* byte address -> line */
    SpadStats st;
} Spad;

int spad_init(Spad *s, const SpadParams *p);
void spad_reset(Spad *s);
void spad_free(Spad *s);

/* An access of naddr lanes (naddr >= 1): its issue cycles, ceil(distinct lines / ports).
 * Counts the access and its lines. */
uint64_t spad_access(Spad *s, const uint32_t *addr, int naddr);

/* When a load whose last issue cycle is `last` delivers. */
static inline uint64_t spad_load_ready(const Spad *s, uint64_t last)
{
    return last + (uint64_t)s->p.latency;
}

/* n scalar accesses (spld, spst: one word each) counted. One word is one line, so such an access
 * takes one issue cycle at any port count and a load's data are ready spad.latency after it,
 * whatever its address: the timing core times it as a plain instruction and counts it here. */
static inline void spad_count_scalar(Spad *s, uint64_t n)
{
    s->st.accesses += n;
    s->st.lines += n;
}

#endif
