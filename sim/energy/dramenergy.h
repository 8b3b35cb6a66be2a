/* sim/energy/dramenergy.h -- the DRAM's energy from its command counts and its time in the two
 * standby states, by the method of Micron's TN-41-01 ("Calculating Memory System Power for DDR3")
 * and DRAMPower (Chandrasekar et al.): each command's energy is its current above the background
 * it would otherwise draw, over the time it takes (docs/energy.md, "DRAM").
 *
 * Owns: the closed forms below. Must not: simulate (sim/mem/dram_sched.c counts), or read the
 * config (the caller gives DramParams, whose power columns the [dram] keys have overridden).
 *
 * Per device, VDD in V, currents in mA, tCK in ns (mA x V x ns = pJ); a rank has bus / width devices:
 *   ACT (and its PRE)  VDD (IDD0 tRC - (IDD3N tRAS + IDD2N (tRC - tRAS))) tCK   per ACT
 *   RD burst           VDD (IDD4R - IDD3N) burst_cycles tCK                     per read burst
 *   WR burst           VDD (IDD4W - IDD3N) burst_cycles tCK                     per write burst
 *   REF                VDD (IDD5B - IDD3N) tRFC tCK                             per all-bank REF
 *   background         VDD (IDD3N (active + refresh) + IDD2N (rest)) tCK       over rank-cycles
 * I/O (the interface and its termination, on the controller's side too) is apart: p->power.io_pj_bit
 * per bit transferred (the preset's, or the key energy.dram_io_pj_bit's: sim/mem/dram.c).
 */
#ifndef SFSIM_ENERGY_DRAMENERGY_H
#define SFSIM_ENERGY_DRAMENERGY_H

#include <stdint.h>

#include "../mem/dram.h"

typedef struct DramEnergy {
    int known;                      /* the preset (or the keys) gave VDD and the currents */
    double act_pj, rd_pj, wr_pj, ref_pj;     /* one command's energy, the whole rank */
    /* The totals, J: */
    double activate, read, write, refresh, background_active, background_precharged, io;
    double core;                    /* all but io */
    double bits;                    /* bits transferred */
    double pj_per_bit;              /* core / bits (0 when none) */
    double io_pj_per_bit;           /* io / bits */
} DramEnergy;

/* The energy of counts s over rank_cycles = channels x ranks x the DRAM cycles of the span
 * (s->active_cycles and s->refresh_cycles of them in active standby). */
void dram_energy(const DramParams *p, const DramChanStats *s, double rank_cycles, DramEnergy *e);

#endif
