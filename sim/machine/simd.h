/* sim/machine/simd.h -- the SIMD execution unit: in-order single issue, a latency and an issue
 * interval per functional-unit class, the register scoreboard, and the bubble after a taken
 * branch (Gribble & Ramani 2008, Sec. 3.3: one N-wide execution subsystem fed by the
 * address-generation units; the units are synthesised for 1 GHz and clocked at 500 MHz).
 *
 * Owns: the latency.*, issue.* and branch.taken_penalty keys, the registers each opcode reads
 * and writes (from the ISA table's FMT and ACC columns), which registers wait for a result and
 * the cause its producer charges, which classes are inside their issue interval, and whether
 * fetch is redirecting. Must not: charge a stall, order hazards or push events (the timing core
 * does all three, sim/timing.c), or compute a value (the functional core does).
 *
 * A result is ready latency[class] cycles after issue; a class with issue interval k accepts
 * its next instruction k cycles after the last (docs/model.md, "SIMD execution unit").
 */
#ifndef SFSIM_MACHINE_SIMD_H
#define SFSIM_MACHINE_SIMD_H

#include <stdint.h>

#include "../config.h"
#include "../../isa/isa.h"

typedef struct SimdParams {
    int lat[ISA_U_COUNT];      /* result latency per unit class (compute classes, AGU, branch) */
    int issue[ISA_U_COUNT];    /* cycles between issues per unit class */
    int taken_penalty;         /* bubble cycles after a taken branch */
} SimdParams;

void simd_params(const CfgMachine *c, SimdParams *p);

enum { SIMD_NREGS = ISA_NUM_SREGS + ISA_NUM_VREGS + ISA_NUM_MREGS }; /* r, then v, then m */

typedef struct SimdOpRegs {    /* registers an opcode reads and writes, from the ISA table */
    uint8_t nsrc, ndst;
    uint8_t src_kind[ISA_MAX_OPERANDS + 1], src_field[ISA_MAX_OPERANDS + 1];
    uint8_t dst_kind[ISA_MAX_OPERANDS], dst_field[ISA_MAX_OPERANDS];
    uint8_t mask_src;          /* reads the exec mask register */
} SimdOpRegs;

typedef struct SimdStats {     /* uint64_t only (timing_stats_add) */
    uint64_t uses[ISA_U_COUNT]; /* instructions issued per unit class */
} SimdStats;

typedef struct SimdUnit {
    SimdParams p;
    SimdOpRegs ops[ISA_OP_COUNT];
    uint64_t ready[SIMD_NREGS];        /* the cycle the register's latest write lands: an
                                          instruction needing it waits while ready > its cycle */
    uint8_t rcause[SIMD_NREGS];        /* what a wait for it is charged to (its producer's cause) */
    uint64_t horizon;                  /* the latest ready cycle of any register: at or after it,
                                          nothing waits (the common case needs no loop) */
    uint8_t unit_pending[ISA_U_COUNT]; /* the class is inside its issue interval */
    uint8_t fetch_pending;             /* the bubble after a taken branch */
    SimdStats st;
} SimdUnit;

int simd_init(SimdUnit *u, const SimdParams *p);
void simd_free(SimdUnit *u);
/* Nothing in flight for the next program run. */
void simd_reset(SimdUnit *u);

/* Register numbers of the scoreboard (r, v, m in one space). */
static inline int simd_reg(int kind, int num)
{
    return kind == ISA_K_R ? num : kind == ISA_K_V ? ISA_NUM_SREGS + num : ISA_NUM_SREGS + ISA_NUM_VREGS + num;
}

static inline int simd_field(const IsaInstr *in, int f)
{
    return f == ISA_FIELD_A ? in->a : f == ISA_FIELD_B ? in->b : f == ISA_FIELD_C ? in->c : in->d;
}

/* The registers an instruction must find ready: its sources, the exec mask, and its destinations
 * (no write after a pending write). Writes them to regs (returns how many) and the destinations
 * alone to dsts (*ndst). The timing core calls it once per program instruction and keeps the
 * lists (sim/timing.c). */
static inline int simd_operands(const SimdUnit *u, const IsaInstr *in, uint8_t *regs, uint8_t *dsts, int *ndst)
{
    const SimdOpRegs *orr = &u->ops[in->op];
    int n = 0;
    for (int i = 0; i < orr->nsrc; i++)
        regs[n++] = (uint8_t)simd_reg(orr->src_kind[i], simd_field(in, orr->src_field[i]));
    if (orr->mask_src)
        regs[n++] = (uint8_t)simd_reg(ISA_K_M, in->mask);
    *ndst = 0;
    for (int i = 0; i < orr->ndst; i++)
        regs[n++] = dsts[(*ndst)++] = (uint8_t)simd_reg(orr->dst_kind[i], simd_field(in, orr->dst_field[i]));
    return n;
}

/* The cause of the first of regs[0..n) still waiting for a result at cycle at, or -1. */
static inline int simd_waiting_operand(const SimdUnit *u, const uint8_t *regs, int n, uint64_t at)
{
    if (u->horizon <= at)
        return -1;
    for (int i = 0; i < n; i++)
        if (u->ready[regs[i]] > at)
            return u->rcause[regs[i]];
    return -1;
}

/* The cause of the first register still waiting for a result at cycle at, or -1 (a program ends
 * when every result in flight has landed). */
static inline int simd_any_waiting(const SimdUnit *u, uint64_t at)
{
    if (u->horizon <= at)
        return -1;
    for (int r = 0; r < SIMD_NREGS; r++)
        if (u->ready[r] > at)
            return u->rcause[r];
    return -1;
}

/* The first cycle after at when one of regs[0..n) (all registers when n < 0) gets its result,
 * or UINT64_MAX: the next change of the register hazards. */
static inline uint64_t simd_next_landing(const SimdUnit *u, const uint8_t *regs, int n, uint64_t at)
{
    uint64_t next = UINT64_MAX;
    if (n < 0) {
        for (int r = 0; r < SIMD_NREGS; r++)
            if (u->ready[r] > at && u->ready[r] < next)
                next = u->ready[r];
        return next;
    }
    for (int i = 0; i < n; i++)
        if (u->ready[regs[i]] > at && u->ready[regs[i]] < next)
            next = u->ready[regs[i]];
    return next;
}

/* Result of a class issued at cycle at, by its latency. */
static inline uint64_t simd_result_ready(const SimdUnit *u, int unit, uint64_t at)
{
    return at + (uint64_t)u->p.lat[unit];
}

/* Register reg gets its value at cycle ready; a wait for it is charged to cause. (The result's
 * landing is this table entry, not an event on the queue: the common case costs no heap work.) */
static inline void simd_result(SimdUnit *u, int reg, uint64_t ready, int cause)
{
    u->ready[reg] = ready;
    u->rcause[reg] = (uint8_t)cause;
    if (ready > u->horizon)
        u->horizon = ready;
}

/* After an instruction of class unit issued at cycle at (next issue slot end): 1 when the class
 * is still inside its issue interval then, busy until *until. */
static inline int simd_hold_unit(SimdUnit *u, int unit, uint64_t at, uint64_t end, uint64_t *until)
{
    if (u->p.issue[unit] > 1 && at + (uint64_t)u->p.issue[unit] > end) {
        u->unit_pending[unit] = 1;
        *until = at + (uint64_t)u->p.issue[unit];
        return 1;
    }
    return 0;
}

static inline void simd_unit_free(SimdUnit *u, int unit)
{
    u->unit_pending[unit] = 0;
}

/* A branch was taken (next issue slot end): 1 when fetch redirects until *until. Not-taken
 * branches are free (predict not taken). */
static inline int simd_redirect(SimdUnit *u, uint64_t end, uint64_t *until)
{
    if (u->p.taken_penalty <= 0)
        return 0;
    u->fetch_pending = 1;
    *until = end + (uint64_t)u->p.taken_penalty;
    return 1;
}

static inline void simd_fetch_resumed(SimdUnit *u)
{
    u->fetch_pending = 0;
}

#endif
