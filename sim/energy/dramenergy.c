/* sim/energy/dramenergy.c -- the DRAM's energy from its counts (sim/energy/dramenergy.h, which
 * writes the closed forms; docs/energy.md, "DRAM").
 *
 * Owns: the closed forms. Must not: read the config, simulate, print.
 */
#include "dramenergy.h"

void dram_energy(const DramParams *p, const DramChanStats *s, double rank_cycles, DramEnergy *e)
{
    const DramPower *w = &p->power;
    const double io_pj_bit = w->io_pj_bit;
    const double tck = 1000.0 / p->clock_mhz, dev = (double)p->bus_bits / p->device_width;
    *e = (DramEnergy){0};
    e->bits = 8.0 * (double)s->bytes;
    e->io = e->bits * io_pj_bit * 1e-12;
    e->io_pj_per_bit = e->bits > 0 ? io_pj_bit : 0;
    e->known = w->vdd > 0 && w->idd0 > 0 && w->idd3n > 0;
    if (!e->known)
        return;
    e->act_pj = w->vdd * (w->idd0 * p->trc - (w->idd3n * p->tras + w->idd2n * (p->trc - p->tras))) * tck * dev;
    e->rd_pj = w->vdd * (w->idd4r - w->idd3n) * p->burst_cycles * tck * dev;
    e->wr_pj = w->vdd * (w->idd4w - w->idd3n) * p->burst_cycles * tck * dev;
    e->ref_pj = w->vdd * (w->idd5b - w->idd3n) * p->trfc * tck * dev;
    e->activate = (double)s->activates * e->act_pj * 1e-12;
    e->read = (double)s->reads * e->rd_pj * 1e-12;
    e->write = (double)s->writes * e->wr_pj * 1e-12;
    e->refresh = (double)s->refreshes * e->ref_pj * 1e-12;
    double active = (double)(s->active_cycles + s->refresh_cycles);
    if (active > rank_cycles)
        active = rank_cycles;
    e->background_active = w->vdd * w->idd3n * active * tck * dev * 1e-12;
    e->background_precharged = w->vdd * w->idd2n * (rank_cycles - active) * tck * dev * 1e-12;
    e->core = e->activate + e->read + e->write + e->refresh + e->background_active + e->background_precharged;
    e->pj_per_bit = e->bits > 0 ? e->core / e->bits * 1e12 : 0;
}
