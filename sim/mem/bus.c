/* sim/mem/bus.c -- the fixed-latency, fixed-bandwidth memory bus (see bus.h).
 *
 * Owns: what a line over the bus costs. Must not: hold data.
 */
#include "bus.h"

#include <string.h>

void bus_params(const CfgMachine *c, BusParams *p)
{
    /* Assumption (docs/model.md): DRAM at 500 MHz is 50 cycles away. */
    p->latency = c->scene_latency;
    p->bytes_per_cycle = c->scene_bytes_per_cycle;
    p->line_bytes = c->scene_line_bytes;
}

int bus_init(Bus *b, const BusParams *p)
{
    memset(b, 0, sizeof *b);
    b->p = *p;
    b->xfer = (uint64_t)((p->line_bytes + p->bytes_per_cycle - 1) / p->bytes_per_cycle);
    return 0;
}

void bus_reset(Bus *b) { b->next = 0; }

void bus_free(Bus *b) { (void)b; }

uint64_t bus_line(Bus *b, uint64_t at)
{
    const uint64_t s = at > b->next ? at : b->next;
    b->next = s + b->xfer;
    b->st.requests++;
    b->st.bytes += (uint64_t)b->p.line_bytes;
    return s + (uint64_t)b->p.latency + b->xfer;
}

static uint64_t bus_request(void *below, const MemReq *r)
{
    return bus_line(below, r->at);
}

MemPort bus_port(Bus *b)
{
    return (MemPort){bus_request, b};
}
