/* sim/mem/noc.c -- the on-chip network between cores and L2 banks (see noc.h; docs/chip.md).
 *
 * Owns: the messages in flight, ordered by (cycle, the order they were made), and the ports' free
 * cycles. Must not: reorder the messages at a port (first come, first served) or answer a read
 * before the level behind it has.
 */
#include "noc.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Where a message is: at its sender's port, at its receiver's port, delivered. */
enum { AT_CORE_OUT, AT_BANK_IN, TO_BEHIND, AT_BANK_OUT, AT_CORE_IN, TO_CORE };

typedef struct Msg {
    uint64_t cycle, seq;
    uint64_t addr, id;          /* id: the core's request id; for an answer, the slot's */
    uint32_t core, bank, len;
    uint8_t stage, write;
} Msg;

typedef struct Slot {           /* a read delivered behind, waiting for its answer */
    uint64_t id, addr;
    uint32_t core, bank;
    uint32_t next_free;
} Slot;

/* A write's id behind (its answer needs nothing); a read's is its slot. Both carry the sender's core
 * (MEM_ID), which the level behind may count by (the L2's per-core shares). */
#define NOC_WRITE ((uint64_t)1 << 47)

struct Noc {
    NocParams p;
    MemLevel behind;
    int shift;
    uint32_t xfer;              /* cycles a line takes on a port */
    uint64_t *core_out, *core_in, *bank_in, *bank_out; /* each port's first free cycle */
    Msg *h;                     /* the messages, a binary heap on (cycle, seq) */
    size_t n, cap;
    uint64_t seq;
    Slot *slot;
    uint32_t nslot, capslot, free_slot; /* free list through next_free; UINT32_MAX: empty */
    MemAnswer answer;           /* during noc_run */
    void *actx;
    NocStats st;
};

int noc_check(const NocParams *p, char *err, size_t errlen)
{
    if (p->cores < 1 || p->banks < 1 || p->latency < 0 || p->bytes_per_cycle < 1 || p->line_bytes < 4 ||
        (p->line_bytes & (p->line_bytes - 1))) {
        snprintf(err, errlen, "noc: cores, banks and bytes_per_cycle must be at least 1, latency at least 0, "
                              "and the line a power of two of at least 4 bytes");
        return -1;
    }
    return 0;
}

Noc *noc_new(const NocParams *p, MemLevel behind, char *err, size_t errlen)
{
    if (noc_check(p, err, errlen))
        return NULL;
    Noc *n = calloc(1, sizeof *n);
    if (!n) {
        snprintf(err, errlen, "out of memory for the network");
        return NULL;
    }
    n->p = *p;
    n->behind = behind;
    while ((1 << n->shift) < p->line_bytes)
        n->shift++;
    n->xfer = (uint32_t)((p->line_bytes + p->bytes_per_cycle - 1) / p->bytes_per_cycle);
    n->core_out = calloc((size_t)p->cores, sizeof *n->core_out);
    n->core_in = calloc((size_t)p->cores, sizeof *n->core_in);
    n->bank_in = calloc((size_t)p->banks, sizeof *n->bank_in);
    n->bank_out = calloc((size_t)p->banks, sizeof *n->bank_out);
    n->free_slot = UINT32_MAX;
    if (!n->core_out || !n->core_in || !n->bank_in || !n->bank_out) {
        noc_free(n);
        snprintf(err, errlen, "out of memory for the network's ports");
        return NULL;
    }
    return n;
}

void noc_free(Noc *n)
{
    if (!n)
        return;
    free(n->core_out);
    free(n->core_in);
    free(n->bank_in);
    free(n->bank_out);
    free(n->h);
    free(n->slot);
    free(n);
}

void noc_reset(Noc *n)
{
    memset(n->core_out, 0, sizeof *n->core_out * (size_t)n->p.cores);
    memset(n->core_in, 0, sizeof *n->core_in * (size_t)n->p.cores);
    memset(n->bank_in, 0, sizeof *n->bank_in * (size_t)n->p.banks);
    memset(n->bank_out, 0, sizeof *n->bank_out * (size_t)n->p.banks);
    n->n = 0;
    n->seq = 0;
    n->nslot = 0;
    n->free_slot = UINT32_MAX;
}

const NocStats *noc_stats(const Noc *n) { return &n->st; }

static int before(const Msg *a, const Msg *b) { return a->cycle < b->cycle || (a->cycle == b->cycle && a->seq < b->seq); }

/* A message to the heap, at its cycle; made now, so after every message made before it. */
static void put(Noc *n, Msg m)
{
    if (n->n == n->cap) {
        size_t cap = n->cap ? 2 * n->cap : 64;
        Msg *h = realloc(n->h, sizeof *h * cap);
        if (!h)
            abort(); /* messages in flight: a few per core; out of memory here is the host's end */
        n->h = h;
        n->cap = cap;
    }
    m.seq = n->seq++;
    size_t i = n->n++;
    while (i > 0 && before(&m, &n->h[(i - 1) / 2])) {
        n->h[i] = n->h[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    n->h[i] = m;
}

static Msg take(Noc *n)
{
    Msg top = n->h[0], last = n->h[--n->n];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n->n)
            break;
        if (c + 1 < n->n && before(&n->h[c + 1], &n->h[c]))
            c++;
        if (!before(&n->h[c], &last))
            break;
        n->h[i] = n->h[c];
        i = c;
    }
    if (n->n)
        n->h[i] = last;
    return top;
}

void noc_push(Noc *n, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    const uint32_t core = MEM_ID_CORE(id) < (uint32_t)n->p.cores ? MEM_ID_CORE(id) : 0;
    const uint32_t bank = (uint32_t)((addr >> n->shift) % (uint64_t)n->p.banks);
    if (write)
        n->st.writes++;
    else
        n->st.requests++;
    put(n, (Msg){cycle, 0, addr, id, core, bank, write ? n->xfer : 1u, AT_CORE_OUT, (uint8_t)(write != 0)});
}

/* The message crosses the port whose first free cycle is *port: it starts at its cycle or when
 * the port is free; returns the cycle it starts. */
static uint64_t cross(Noc *n, uint64_t *port, const Msg *m)
{
    const uint64_t s = m->cycle > *port ? m->cycle : *port;
    n->st.port_wait += s - m->cycle;
    *port = s + m->len;
    return s;
}

static uint32_t slot_new(Noc *n, const Msg *m)
{
    uint32_t i = n->free_slot;
    if (i != UINT32_MAX) {
        n->free_slot = n->slot[i].next_free;
    } else {
        if (n->nslot == n->capslot) {
            uint32_t cap = n->capslot ? 2 * n->capslot : 64;
            Slot *s = realloc(n->slot, sizeof *s * cap);
            if (!s)
                abort();
            n->slot = s;
            n->capslot = cap;
        }
        i = n->nslot++;
    }
    n->slot[i] = (Slot){m->id, m->addr, m->core, m->bank, UINT32_MAX};
    return i;
}

/* The message leaves over the sender's port (*port): its head reaches the receiver's port
 * `latency` cycles after it starts. */
static void send(Noc *n, uint64_t *port, Msg m, int next)
{
    m.cycle = cross(n, port, &m) + (uint64_t)n->p.latency;
    m.stage = (uint8_t)next;
    put(n, m);
}

/* The message crosses the receiver's port (*port): it is there when its last cycle has. */
static void arrive(Noc *n, uint64_t *port, Msg m, int next)
{
    m.cycle = cross(n, port, &m) + m.len;
    m.stage = (uint8_t)next;
    put(n, m);
}

/* One message at its cycle: on to its next stage. */
static void step(Noc *n, Msg m)
{
    switch (m.stage) {
    case AT_CORE_OUT:
        n->st.bytes += m.write ? (uint64_t)n->p.line_bytes : 0;
        send(n, &n->core_out[m.core], m, AT_BANK_IN);
        break;
    case AT_BANK_IN: arrive(n, &n->bank_in[m.bank], m, TO_BEHIND); break;
    case TO_BEHIND:
        if (m.write) {
            n->behind.push(n->behind.self, m.addr, 1, m.cycle, MEM_ID(m.core, NOC_WRITE));
            n->answer(n->actx, m.id, m.cycle);
        } else {
            n->behind.push(n->behind.self, m.addr, 0, m.cycle, MEM_ID(m.core, slot_new(n, &m)));
        }
        break;
    case AT_BANK_OUT:
        n->st.bytes += (uint64_t)n->p.line_bytes;
        send(n, &n->bank_out[m.bank], m, AT_CORE_IN);
        break;
    case AT_CORE_IN: arrive(n, &n->core_in[m.core], m, TO_CORE); break;
    case TO_CORE:
        n->st.answers++;
        n->answer(n->actx, m.id, m.cycle);
        break;
    }
}

/* The level behind answered the read in slot id at cycle x: its line starts back. */
static void from_behind(void *ctx, uint64_t id, uint64_t x)
{
    Noc *n = ctx;
    if (id & NOC_WRITE)
        return;
    const uint64_t below = id & MEM_FROM_BELOW;
    const uint32_t slot = (uint32_t)id; /* (below the core's bits and MEM_FROM_BELOW) */
    Slot *s = &n->slot[slot];
    put(n, (Msg){x, 0, s->addr, s->id | below, s->core, s->bank, n->xfer, AT_BANK_OUT, 0});
    s->next_free = n->free_slot;
    n->free_slot = slot;
}

uint64_t noc_next(const Noc *n)
{
    const uint64_t tb = n->behind.next(n->behind.self);
    return n->n && n->h[0].cycle < tb ? n->h[0].cycle : tb;
}

void noc_run(Noc *n, uint64_t until, MemAnswer answer, void *ctx)
{
    n->answer = answer;
    n->actx = ctx;
    for (;;) {
        const uint64_t th = n->n ? n->h[0].cycle : UINT64_MAX, tb = n->behind.next(n->behind.self);
        const uint64_t t = th < tb ? th : tb;
        if (t >= until)
            break;
        if (th == t) { /* the network's messages of cycle t first: they may deliver behind at t */
            while (n->n && n->h[0].cycle == t)
                step(n, take(n));
        } else {
            n->behind.run(n->behind.self, t + 1, from_behind, n);
        }
    }
}

static void lv_push(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    noc_push(self, addr, write, cycle, id);
}
static uint64_t lv_next(const void *self) { return noc_next(self); }
static void lv_run(void *self, uint64_t until, MemAnswer a, void *ctx) { noc_run(self, until, a, ctx); }

MemLevel noc_level(Noc *n) { return (MemLevel){n, lv_push, lv_next, lv_run}; }
