/* sim/machine/interconnect.c -- the multiplexer interconnect: ports and their reservations (see
 * interconnect.h; the model and its sources: docs/model.md, "Interconnect").
 *
 * Owns: the port search and the reservations. Must not: charge stalls or know what a transfer
 * carries.
 */
#include "interconnect.h"

#include <string.h>

void xbar_params(const CfgMachine *c, XbarParams *p)
{
    /* Gribble & Ramani 2008, Sec. 3.3: the multiplexers are "sized to allow for single-cycle
     * operation"; two ports (assumption) carry "the bandwidth requirements of the address fetch
     * and execution units". */
    p->latency = c->interconnect_latency;
    p->ports = c->interconnect_ports;
}

int xbar_init(Xbar *x, const XbarParams *p)
{
    memset(x, 0, sizeof *x);
    x->p = *p;
    return 0;
}

void xbar_free(Xbar *x) { (void)x; }

void xbar_reset(Xbar *x)
{
    x->agu_n = 0;
    x->dp.s = x->dp.e = 0;
    x->part.s = x->part.e = 0;
}

/* The other users' transfers still running at or after from. */
static inline int running(const Xbar *x, uint64_t from, XbarUser user)
{
    int n = user != XBAR_PART && x->part.e > from;
    if (user != XBAR_AGU)
        for (int i = 0; i < x->agu_n; i++)
            n += x->agu[i].e > from;
    return n + (user != XBAR_DP && x->dp.e > from);
}

/* The first cycle s >= from at which a transfer of len cycles finds a free port in each of its
 * cycles, given the other users' transfers; called when running() finds every port taken at from
 * (xbar_transfer tests that first, without building a list). */
static uint64_t earliest(const Xbar *x, uint64_t from, uint64_t len, XbarUser user)
{
    XbarIvl iv[XBAR_AGU_MAX + 2];
    int n = 0;
    if (user != XBAR_PART && x->part.e > from)
        iv[n++] = x->part;
    if (user != XBAR_AGU)
        for (int i = 0; i < x->agu_n; i++)
            if (x->agu[i].e > from)
                iv[n++] = x->agu[i];
    if (user != XBAR_DP && x->dp.e > from)
        iv[n++] = x->dp;
    uint64_t s = from;
    for (;;) {
        /* The most ports taken at any cycle of [s, s + len): check s and every start inside. */
        int worst = 0;
        for (int a = -1; a < n; a++) {
            uint64_t pt = a < 0 ? s : iv[a].s;
            if (pt < s || pt >= s + len)
                continue;
            int used = 0;
            for (int b = 0; b < n; b++)
                used += iv[b].s <= pt && pt < iv[b].e;
            if (used > worst)
                worst = used;
        }
        if (worst < x->p.ports)
            return s;
        uint64_t next = UINT64_MAX;
        for (int b = 0; b < n; b++)
            if (iv[b].e > s && iv[b].s < s + len && iv[b].e < next)
                next = iv[b].e;
        s = next;
    }
}

static void hold_agu(Xbar *x, uint64_t s, uint64_t e, uint64_t now)
{
    /* Drop transfers that ended before the present. */
    int k = 0;
    for (int i = 0; i < x->agu_n; i++)
        if (x->agu[i].e > now)
            x->agu[k++] = x->agu[i];
    x->agu_n = k;
    if (k == XBAR_AGU_MAX) {
        x->overflow = 1;
        return;
    }
    x->agu[x->agu_n++] = (XbarIvl){s, e};
}

int xbar_dp_free(const Xbar *x, uint64_t t)
{
    return running(x, t, XBAR_DP) < x->p.ports;
}

uint64_t xbar_transfer(Xbar *x, XbarUser user, uint64_t from, uint64_t len, uint64_t now)
{
    /* fewer transfers running than ports (nearly always): a port is free at from */
    const uint64_t s = running(x, from, user) < x->p.ports ? from : earliest(x, from, len ? len : 1, user);
    switch (user) {
    case XBAR_DP:
        x->dp = (XbarIvl){s, s + len};
        x->st.transfers++;
        break;
    case XBAR_AGU:
        x->st.unit_delay += s - from;
        hold_agu(x, s, s + len, now);
        break;
    case XBAR_PART:
        x->st.unit_delay += s - from;
        x->part = (XbarIvl){s, s + len};
        break;
    }
    return s;
}
