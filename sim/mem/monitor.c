/* sim/mem/monitor.c -- a watch on the traffic between two shared levels (see monitor.h). */
#include "monitor.h"

#include <stdlib.h>

struct MemMonitor {
    MemLevel below;
    int level;
    MemWatch w;
    MemAnswer up;              /* the run in progress: the answer of the level above */
    void *up_ctx;
};

static void mon_push(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    MemMonitor *m = self;
    m->w.pushed(m->w.ctx, m->level, id, addr, write, cycle);
    m->below.push(m->below.self, addr, write, cycle, id);
}

static uint64_t mon_next(const void *self)
{
    const MemMonitor *m = self;
    return m->below.next(m->below.self);
}

static void mon_answer(void *ctx, uint64_t id, uint64_t cycle)
{
    MemMonitor *m = ctx;
    m->w.answered(m->w.ctx, m->level, id, cycle);
    m->up(m->up_ctx, id, cycle);
}

static void mon_run(void *self, uint64_t until, MemAnswer answer, void *ctx)
{
    MemMonitor *m = self;
    MemAnswer up = m->up;
    void *up_ctx = m->up_ctx;
    m->up = answer;
    m->up_ctx = ctx;
    m->below.run(m->below.self, until, mon_answer, m);
    m->up = up; /* (a run inside a run, should a level nest them) */
    m->up_ctx = up_ctx;
}

MemMonitor *monitor_new(MemLevel below, int level, const MemWatch *w)
{
    MemMonitor *m = calloc(1, sizeof *m);
    if (m) {
        m->below = below;
        m->level = level;
        m->w = *w;
    }
    return m;
}

void monitor_free(MemMonitor *m) { free(m); }

MemLevel monitor_level(MemMonitor *m) { return (MemLevel){m, mon_push, mon_next, mon_run}; }
