/* sim/mem/bus.h -- the paper's memory behind the scene cache: a fixed latency and a bus of a fixed
 * bandwidth that moves one line at a time (Gribble & Ramani 2008 give no figures; every number is
 * an assumption: docs/model.md, "Scene memory").
 *
 * Owns: the scene.latency and scene.bytes_per_cycle keys, the bus's next free cycle, its
 * counters. Must not: hold data or know what asks (it is a MemPort's far end: port.h).
 *
 * A line request at cycle t, read or write alike: it goes over the bus when the bus is free,
 * s = max(t, free); the bus is busy for xfer = ceil(line / bytes_per_cycle) cycles; it is done
 * (a read's data there) at s + latency + xfer. Nothing waits for a write-back but the bus.
 */
#ifndef SFSIM_MEM_BUS_H
#define SFSIM_MEM_BUS_H

#include <stdint.h>

#include "../config.h"
#include "port.h"

typedef struct BusParams {
    int latency, bytes_per_cycle, line_bytes;
} BusParams;

void bus_params(const CfgMachine *c, BusParams *p);

typedef struct BusStats {       /* uint64_t only (timing_stats_add) */
    uint64_t requests;          /* lines moved */
    uint64_t bytes;             /* bytes moved */
} BusStats;

typedef struct Bus {
    BusParams p;
    uint64_t xfer;              /* bus cycles per line */
    uint64_t next;              /* the first cycle the bus is free */
    BusStats st;
} Bus;

int bus_init(Bus *b, const BusParams *p);
/* Idle (counters kept). */
void bus_reset(Bus *b);
void bus_free(Bus *b);
/* One line over the bus at cycle at: the cycle it is done (see above). */
uint64_t bus_line(Bus *b, uint64_t at);
/* b as the port a level above connects to. */
MemPort bus_port(Bus *b);

#endif
