/* sim/machine/interconnect.h -- the multiplexer interconnect between the ray-buffer banks and
 * the units: its latency, its ports, and who holds them when (Gribble & Ramani 2008, Sec. 3.3).
 *
 * Owns: interconnect.latency and interconnect.ports, the port reservations of its three users
 * (the data path's last transfer, the AGUs' transfers in flight, the partition unit's run), the
 * counters (XbarStats). Must not: charge a stall (the timing core charges
 * a late transfer to `interconnect`) or decide when a unit wants a port (its caller does).
 *
 * A transfer of len cycles gets the first window, from the cycle asked for on, in which a port is
 * free in every cycle; reservations are first come, first served in simulated time (docs/model.md).
 */
#ifndef SFSIM_MACHINE_INTERCONNECT_H
#define SFSIM_MACHINE_INTERCONNECT_H

#include <stdint.h>

#include "../config.h"


typedef struct XbarParams {
    int latency;               /* cycles a transfer adds between banks and lanes */
    int ports;                 /* transfers per cycle */
} XbarParams;

void xbar_params(const CfgMachine *c, XbarParams *p);

/* Who asks for a port. */
typedef enum XbarUser { XBAR_DP, XBAR_AGU, XBAR_PART } XbarUser;

enum { XBAR_AGU_MAX = 128 };   /* AGU transfers in flight at once (far more than a queue holds) */

typedef struct XbarIvl { uint64_t s, e; } XbarIvl;   /* cycles [s, e) */

typedef struct XbarStats {     /* uint64_t only (timing_stats_add) */
    uint64_t transfers;        /* data-path transfers */
    uint64_t unit_delay;       /* cycles AGU and partition work waited for a port */
} XbarStats;

typedef struct Xbar {
    XbarParams p;
    XbarIvl dp;                /* the data path's last transfer */
    XbarIvl part;              /* the partition unit's run */
    XbarIvl agu[XBAR_AGU_MAX]; /* the AGUs' transfers that had not ended at the last reservation */
    int agu_n;
    int overflow;              /* set when more AGU transfers were in flight than XBAR_AGU_MAX */
    XbarStats st;
} Xbar;

int xbar_init(Xbar *x, const XbarParams *p);
void xbar_free(Xbar *x);
/* Idle ports for the next program run. */
void xbar_reset(Xbar *x);
/* A transfer for `user` of len cycles asked for at cycle `from` (now: the cycle the current
 * instruction may issue in; AGU transfers that ended before it are forgotten). Finds a window with
 * a free port (at least one cycle long), holds a port for [s, s + len) and returns s. Counts a
 * data-path transfer, or the cycles a unit (AGU, partition) waited for the port. */
uint64_t xbar_transfer(Xbar *x, XbarUser user, uint64_t from, uint64_t len, uint64_t now);
/* 1 when a data-path transfer asked for at any cycle from t on starts at once, as far as the
 * reservations made so far go: fewer of the other users' transfers not ended by t than ports
 * (fewer still at any later cycle, until another is made). */
int xbar_dp_free(const Xbar *x, uint64_t t);

#endif
