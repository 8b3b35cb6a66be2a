/* sim/mem/noc.h -- the chip's on-chip network between the cores and the L2's banks (docs/chip.md):
 * a latency, and ports that move bytes_per_cycle bytes a cycle, each taken first come, first
 * served. It is a level (level.h) in front of the level it carries requests to (the L2), so the
 * cores push into it as they would into the L2.
 *
 * Owns: the noc.* keys' model, its ports' next free cycles, its messages in flight, its counters
 * (NocStats). Must not: know what the level behind it does with a request.
 *
 * A request's id carries the core that sent it in its top bits (MEM_ID_CORE). Each core has an
 * injection port (to the network) and an ejection port (from it); each bank of the level behind
 * it has one of each too (bank = line mod banks). A message is a read request (one cycle on a
 * port: an address), a write (the line: ceil(line / bytes_per_cycle) cycles) or a read's answer
 * (the line). A message crosses its sender's port when the port is free, reaches the receiver's
 * port `latency` cycles after it started, crosses that port when it is free, and is delivered when
 * its last cycle has crossed:
 *   core k sends at t:  s = max(t, inject[k] free);   inject[k] busy [s, s + len)
 *   bank b takes it:    r = max(s + latency, eject[b] free); eject[b] busy [r, r + len); delivered
 *                       to the level behind at r + len
 * and a read's answer at cycle x comes back the same way from bank b's injection port to core k's
 * ejection port; the core has it when the last cycle has crossed. A write is answered when it is
 * delivered (the cores wait for no write). Each port serves messages in the order they reach it
 * (cycle, then the order they were sent).
 */
#ifndef SFSIM_MEM_NOC_H
#define SFSIM_MEM_NOC_H

#include <stddef.h>
#include <stdint.h>

#include "level.h"

typedef struct NocParams {
    int cores, banks;           /* the ports at each side */
    int latency;                /* cycles from the start of a message on one port to its head at the other */
    int bytes_per_cycle;        /* of every port */
    int line_bytes;
} NocParams;

typedef struct NocStats {       /* uint64_t only */
    uint64_t requests, writes;  /* messages from the cores: reads, writes */
    uint64_t answers;           /* read answers carried back */
    uint64_t port_wait;         /* cycles messages waited for a busy port (contention), all ports */
    uint64_t bytes;             /* bytes carried (both ways) */
} NocStats;

typedef struct Noc Noc;

int noc_check(const NocParams *p, char *err, size_t errlen);
Noc *noc_new(const NocParams *p, MemLevel behind, char *err, size_t errlen);
void noc_free(Noc *n);
void noc_reset(Noc *n);
const NocStats *noc_stats(const Noc *n);
void noc_push(Noc *n, uint64_t addr, int write, uint64_t cycle, uint64_t id);
uint64_t noc_next(const Noc *n);
void noc_run(Noc *n, uint64_t until, MemAnswer answer, void *ctx);
MemLevel noc_level(Noc *n);

#endif
