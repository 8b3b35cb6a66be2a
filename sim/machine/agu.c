/* sim/machine/agu.c -- the address-generation units: fetch, run-ahead queue (see agu.h; the
 * model and its sources: docs/model.md, "Address-generation units").
 *
 * Owns: the queue of ID vectors fetched ahead and what a fetch costs. Must not: charge stalls.
 */
#include "agu.h"

#include <string.h>

void agu_params(const CfgMachine *c, AguParams *p)
{
    p->lanes = c->core_simd_width;
    /* Assumption (docs/model.md): 8 IDs per cycle, so wider SIMD needs longer to fetch a
     * vector, the trend Gribble & Ramani 2008 report. */
    p->ids_per_cycle = c->agu_ids_per_cycle;
    p->depth = c->agu_queue_depth;
    p->latency = c->latency_agu;
}

int agu_init(Agus *a, const AguParams *p)
{
    memset(a, 0, sizeof *a);
    a->p = *p;
    return 0;
}

void agu_free(Agus *a) { (void)a; }

void agu_reset(Agus *a)
{
    a->head = a->n = 0;
    a->free = 0;
}

/* Schedule the fetch of n IDs at addr, starting no earlier than `from`. */
static AguEntry fetch(Agus *a, const PartUnit *pu, Xbar *x, uint32_t addr, uint32_t n, uint64_t from, uint64_t now)
{
    AguEntry e = {addr, n, 0, 0, 0};
    uint64_t s = from > a->free ? from : a->free;
    if (part_overlaps(pu, addr, addr + 4 * n) && pu->e > s) { /* the IDs are being reordered */
        s = pu->e;
        e.part_end = s;
    }
    uint64_t len = (n + (uint32_t)a->p.ids_per_cycle - 1) / (uint32_t)a->p.ids_per_cycle;
    uint64_t g = xbar_transfer(x, XBAR_AGU, s, len, now);
    e.icn_delay = g - s;
    a->free = g + len;
    e.ready = g + len + (uint64_t)a->p.latency;
    a->st.fetches++;
    return e;
}

uint64_t agu_serve(Agus *a, const PartUnit *pu, Xbar *x, uint32_t addr, uint32_t k, uint32_t avail, uint64_t at,
                   uint64_t now, AguWait *w)
{
    AguEntry e;
    memset(w, 0, sizeof *w);
    if (a->n > 0 && a->q[a->head].addr == addr && a->q[a->head].n == k) {
        e = a->q[a->head];
        a->head = (a->head + 1) % AGU_MAX;
        a->n--;
        a->st.ahead++;
    } else {
        a->n = 0; /* another stream: what was fetched ahead is dropped */
        e = fetch(a, pu, x, addr, k, at, now);
    }
    if (e.ready > at) { /* the wait, in segments: partition, then interconnect, then the fetch */
        uint64_t wait = e.ready - at, c;
        c = e.part_end > at ? e.part_end - at : 0;
        c = c < wait ? c : wait;
        w->partition = c;
        wait -= c;
        c = e.icn_delay < wait ? e.icn_delay : wait;
        w->interconnect = c;
        wait -= c;
        w->fetch = wait;
        at = e.ready;
    }
    /* Run ahead: fetch the stream's next vectors, up to the queue depth. */
    uint32_t next = addr + 4 * k, left = avail > k ? avail - k : 0;
    for (int i = 0; i < a->n; i++) {
        const AguEntry *q = &a->q[(a->head + i) % AGU_MAX];
        if (q->addr != next || q->n > left) { /* the stream changed under the queue: keep what still fits */
            a->n = i;
            break;
        }
        next = q->addr + 4 * q->n;
        left -= q->n;
    }
    while (a->n < a->p.depth && left > 0) {
        uint32_t n = left < (uint32_t)a->p.lanes ? left : (uint32_t)a->p.lanes;
        a->q[(a->head + a->n) % AGU_MAX] = fetch(a, pu, x, next, n, at, now);
        a->n++;
        next += 4 * n;
        left -= n;
    }
    return at;
}

void agu_drop_range(Agus *a, uint32_t lo, uint32_t hi)
{
    for (int i = 0; i < a->n; i++) {
        const AguEntry *q = &a->q[(a->head + i) % AGU_MAX];
        if (q->addr < hi && lo < q->addr + 4 * q->n) {
            a->n = 0;
            break;
        }
    }
}
