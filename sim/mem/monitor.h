/* sim/mem/monitor.h -- a watch on the traffic between two shared levels (gem5's CommMonitor,
 * reduced to what a timeline needs): it stands in for the level below, passes every request and
 * answer through unchanged, and tells a watcher of each.
 *
 * Owns: nothing of the traffic (it changes no cycle, id or order). Must not: be put in unless
 * something watches (it costs a call per request and per run).
 */
#ifndef SFSIM_MEM_MONITOR_H
#define SFSIM_MEM_MONITOR_H

#include <stdint.h>

#include "level.h"

typedef struct MemWatch {
    /* a request pushed into level `level` (the watcher's number for it), and its answer */
    void (*pushed)(void *ctx, int level, uint64_t id, uint64_t addr, int write, uint64_t cycle);
    void (*answered)(void *ctx, int level, uint64_t id, uint64_t cycle);
    void *ctx;
} MemWatch;

typedef struct MemMonitor MemMonitor;

/* A monitor of `below`, reporting as level `level` to w (copied); NULL on out of memory. */
MemMonitor *monitor_new(MemLevel below, int level, const MemWatch *w);
void monitor_free(MemMonitor *m);
/* The level to connect above in place of `below`. */
MemLevel monitor_level(MemMonitor *m);

#endif
