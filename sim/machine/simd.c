/* sim/machine/simd.c -- the SIMD execution unit's parameters and operand table (see simd.h; the
 * model and its sources: docs/model.md, "SIMD execution unit").
 *
 * Owns: the per-class latencies and issue intervals from the config, and the registers each
 * opcode reads and writes from the ISA table. Must not: charge stalls or push events.
 */
#include "simd.h"

#include <string.h>

void simd_params(const CfgMachine *c, SimdParams *p)
{
    /* Assumption (docs/model.md; Gribble & Ramani 2008 give no latencies): the usual proportions
     * of a short-pipeline float unit at 500 MHz; classes without a key take 1 cycle. */
    for (int u = 0; u < ISA_U_COUNT; u++)
        p->lat[u] = p->issue[u] = 1;
    p->lat[ISA_U_SALU] = c->latency_salu;
    p->lat[ISA_U_SFPU] = c->latency_sfpu;
    p->lat[ISA_U_SSPEC] = c->latency_sspec;
    p->lat[ISA_U_VADD] = c->latency_vadd;
    p->lat[ISA_U_VMUL] = c->latency_vmul;
    p->lat[ISA_U_VFMA] = c->latency_vfma;
    p->lat[ISA_U_VSPEC] = c->latency_vspec;
    p->lat[ISA_U_VCMP] = c->latency_vcmp;
    p->lat[ISA_U_VLOGIC] = c->latency_vlogic;
    p->lat[ISA_U_VSEL] = c->latency_vsel;
    p->lat[ISA_U_MASK] = c->latency_mask;
    p->lat[ISA_U_AGU] = c->latency_agu; /* ralloc; the AGUs' fetch takes the same key (agu.c) */
    p->issue[ISA_U_SSPEC] = c->issue_sspec;
    p->issue[ISA_U_VSPEC] = c->issue_vspec;
    p->issue[ISA_U_VMUL] = c->issue_vmul;
    p->issue[ISA_U_VFMA] = c->issue_vfma;
    p->taken_penalty = c->branch_taken_penalty;
}

/* Which registers each opcode reads and writes: its format's register operands and the ACC
 * column (r, w, x), plus the exec mask of masked formats. */
static void build_op_regs(SimdOpRegs *ops)
{
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaOpInfo *oi = &isa_ops[op];
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        SimdOpRegs *r = &ops[op];
        memset(r, 0, sizeof *r);
        int ri = 0;
        for (int i = 0; i < fi->nops; i++) {
            IsaOperandKind k = fi->ops[i].kind;
            if (k != ISA_K_R && k != ISA_K_V && k != ISA_K_M)
                continue;
            char acc = oi->access[ri++];
            if (acc == 'r' || acc == 'x') {
                r->src_kind[r->nsrc] = (uint8_t)k;
                r->src_field[r->nsrc++] = (uint8_t)fi->ops[i].field;
            }
            if (acc == 'w' || acc == 'x') {
                r->dst_kind[r->ndst] = (uint8_t)k;
                r->dst_field[r->ndst++] = (uint8_t)fi->ops[i].field;
            }
        }
        r->mask_src = (uint8_t)fi->masked;
    }
}

int simd_init(SimdUnit *u, const SimdParams *p)
{
    memset(u, 0, sizeof *u);
    u->p = *p;
    build_op_regs(u->ops);
    return 0;
}

void simd_free(SimdUnit *u) { (void)u; }

void simd_reset(SimdUnit *u)
{
    memset(u->ready, 0, sizeof u->ready);
    u->horizon = 0;
    memset(u->unit_pending, 0, sizeof u->unit_pending);
    u->fetch_pending = 0;
}
