/* tests/unit/test_core_run.c -- the functional core (sim/core.h) as the rest of the simulator
 * sees it: its counters (core_stats), the record it hands the timing model (core_hook), and runs
 * with limits, repeated, with and without a hook (core_run).
 *
 * As in test_core.c, every expected value is written by hand from the DESC column of
 * isa/opcodes.def, from docs/isa.md and from the comments of sim/core.h; none is obtained by
 * running the core. Programs are built with tests/support/core_prog.h.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/object.h"
#include "../../isa/isa.h"
#include "../../sim/core.h"
#include "../support/core_prog.h"

/* ==== core_stats ===================================================================================== */

static const IsaInstr stats_prog[] = {
    I_AI(LI, 1, 3),                    /*  0 other: integer */
    V_AI(VLI, 1, 5, 0),                /*  1 other: compute, vector, E = all */
    I_AB(MTAIL, 2, 1),                 /*  2 other: compute (mask logic, not vector) */
    I_I(STAGE, 1),                     /*  3 other: control */
    V_ABC(VADD, 2, 1, 1, 2),           /*  4 traversal: compute, vector, 3 lanes */
    V_ABC(VFADD, 3, 1, 1, 0),          /*  5 traversal: compute, vector, N lanes */
    I_ABI(SPST, 1, 0, 0),              /*  6 traversal: store */
    I_ABI(SPLD, 2, 0, 0),              /*  7 traversal: load */
    I_I(STAGE, 2),                     /*  8 traversal: control */
    V_ABCI(RGAT, 4, 0, 0, 0, 2),       /*  9 intersection: scatter_gather, vector, 3 lanes */
    I_A(PMASK, 2),                     /* 10 intersection: partition */
    I_0(PCLR),                         /* 11 intersection: partition */
    V_ABI(LDB, 5, 0, 0, 7),            /* 12 intersection: load, vector, 0 lanes (m7 empty) */
    I_I(STAGE, 3),                     /* 13 intersection: control */
    I_ABI(ADDI, 3, 3, 1),              /* 14 shading: integer (x3) */
    I_ABI(BLT, 3, 1, 14),              /* 15 shading: control (x3) */
    I_0(HALT),                         /* 16 shading: control */
};

Test(core_stats, per_stage_and_category)
{
    const int ws[] = {4, 12, 64};
    for (size_t w = 0; w < sizeof ws / sizeof ws[0]; w++) {
        int n = ws[w];
        TcCore t;
        tc_init(&t, stats_prog, sizeof stats_prog / sizeof stats_prog[0], n);
        tc_run_halt(&t);
        const CoreStats *st = core_stats(t.c);
        const uint64_t instr[ISA_STAGE_COUNT] = {4, 5, 5, 7};
        const uint64_t vec[ISA_STAGE_COUNT] = {1, 2, 2, 0};
        const uint64_t lanes[ISA_STAGE_COUNT] = {(uint64_t)n, 3 + (uint64_t)n, 3, 0};
        /* ops[stage][category]: LOAD STORE COMPUTE SCATGATH PARTITION INTEGER CONTROL */
        const uint64_t ops[ISA_STAGE_COUNT][ISA_C_COUNT] = {
            {0, 0, 2, 0, 0, 1, 1},
            {1, 1, 2, 0, 0, 0, 1},
            {1, 0, 0, 1, 2, 0, 1},
            {0, 0, 0, 0, 0, 3, 4},
        };
        for (int s = 0; s < ISA_STAGE_COUNT; s++) {
            cr_expect_eq(st->instructions[s], instr[s], "N=%d %s instructions %llu, expected %llu", n, isa_stage_keys[s],
                         (unsigned long long)st->instructions[s], (unsigned long long)instr[s]);
            cr_expect_eq(st->vec_instructions[s], vec[s], "N=%d %s vector instructions %llu, expected %llu", n,
                         isa_stage_keys[s], (unsigned long long)st->vec_instructions[s], (unsigned long long)vec[s]);
            cr_expect_eq(st->active_lanes[s], lanes[s], "N=%d %s active lanes %llu, expected %llu", n, isa_stage_keys[s],
                         (unsigned long long)st->active_lanes[s], (unsigned long long)lanes[s]);
            for (int k = 0; k < ISA_C_COUNT; k++)
                cr_expect_eq(st->ops[s][k], ops[s][k], "N=%d %s %s: %llu, expected %llu", n, isa_stage_keys[s],
                             isa_category_keys[k], (unsigned long long)st->ops[s][k], (unsigned long long)ops[s][k]);
        }
        uint64_t by_op[ISA_OP_COUNT] = {0};
        by_op[ISA_OP_LI] = 1;
        by_op[ISA_OP_VLI] = 1;
        by_op[ISA_OP_MTAIL] = 1;
        by_op[ISA_OP_STAGE] = 3;
        by_op[ISA_OP_VADD] = 1;
        by_op[ISA_OP_VFADD] = 1;
        by_op[ISA_OP_SPST] = 1;
        by_op[ISA_OP_SPLD] = 1;
        by_op[ISA_OP_RGAT] = 1;
        by_op[ISA_OP_PMASK] = 1;
        by_op[ISA_OP_PCLR] = 1;
        by_op[ISA_OP_LDB] = 1;
        by_op[ISA_OP_ADDI] = 3;
        by_op[ISA_OP_BLT] = 3;
        by_op[ISA_OP_HALT] = 1;
        for (int op = 0; op < ISA_OP_COUNT; op++)
            cr_expect_eq(st->by_op[op], by_op[op], "N=%d by_op[%s] = %llu, expected %llu", n, isa_ops[op].mnemonic,
                         (unsigned long long)st->by_op[op], (unsigned long long)by_op[op]);
        cr_expect_eq(core_instructions(t.c), 21u, "N=%d total", n);
        tc_free(&t);
    }
}

Test(core_stats, sfetch_counts_the_lanes_it_fills)
{
    /* core.h: for sfetch the active lanes are the n lanes that received an ID, and its record's
     * exec is that tail mask: a stream's last, partial vector is the under-utilization Gribble &
     * Ramani 2008 (Sec. 4.1) attribute to stream lengths that are not multiples of N. */
    TcCore t;
    tc_init(&t, PROG(I_ABCD(SFETCH, 1, 1, 2, 3), I_0(HALT)), 4);
    core_set_sreg(t.c, 2, 0);
    core_set_sreg(t.c, 3, 12);
    tc_run_halt(&t);
    cr_expect_eq(core_mreg(t.c, 1), 0x7u);
    cr_expect_eq(core_stats(t.c)->vec_instructions[0], 1u);
    cr_expect_eq(core_stats(t.c)->active_lanes[0], 3u, "sfetch counted %llu active lanes, expected the 3 it filled",
                 (unsigned long long)core_stats(t.c)->active_lanes[0]);
    tc_free(&t);
}

Test(core_stats, stage_instruction_belongs_to_the_previous_stage)
{
    /* "stage imm attributes the instructions that follow": the marker itself is not one of them */
    TcCore t;
    tc_init(&t, PROG(I_I(STAGE, 3), I_I(STAGE, 0), I_I(STAGE, 2), I_0(HALT)), 4);
    tc_run_halt(&t);
    const CoreStats *st = core_stats(t.c);
    cr_expect_eq(st->instructions[ISA_STAGE_OTHER], 2u);
    cr_expect_eq(st->instructions[ISA_STAGE_SHADING], 1u);
    cr_expect_eq(st->instructions[ISA_STAGE_INTERSECTION], 1u);
    cr_expect_eq(st->instructions[ISA_STAGE_TRAVERSAL], 0u);
    tc_free(&t);
}

/* ==== core_hook ====================================================================================== */

typedef struct HookLog {
    CoreRecord rec[64];
    int n;
} HookLog;

static void log_hook(void *ctx, const CoreRecord *r)
{
    HookLog *h = ctx;
    if (h->n < 64)
        h->rec[h->n] = *r;
    h->n++;
}

enum { NO_MEM = CORE_MEM_COUNT, ANY = -1 };

typedef struct WantRec {
    uint32_t pc, next_pc;
    int taken;              /* 0/1, or ANY */
    int mem;                /* CoreMem, NO_MEM, or ANY */
    int naddr;              /* or ANY */
    uint32_t addr[4];
    long long count;        /* or ANY */
    long long exec;         /* or ANY */
} WantRec;

Test(core_hook, records)
{
    static const IsaInstr prog[] = {
        I_AI(LI, 2, 3),                  /*  0 */
        V_A(VIOTA, 1, 0),                /*  1 v1 = 0 1 2 3 */
        I_AB(MTAIL, 2, 2),               /*  2 m2 = lanes 0..2 */
        V_ABCI(RGAT, 3, 1, 0, 16, 2),    /*  3 RB0 16 20 24 */
        I_0(RSWAP),                      /*  4 */
        V_ABCI(RSCT, 3, 1, 0, 32, 2),    /*  5 RBc is RB1 now: 32 36 40 */
        V_ABCI(RGATN, 4, 1, 0, 0, 0),    /*  6 RBn is RB0: 0 4 8 12 */
        I_A(PMASK, 2),                   /*  7 count 4 */
        I_A(PMASK, 2),                   /*  8 count 8 */
        I_AI(LI, 5, 64),                 /*  9 */
        I_AI(LI, 6, 88),                 /* 10 L = 6 */
        I_ABC(PART, 7, 5, 6),            /* 11 IDM, count 6 */
        I_ABI(BEQ, 0, 0, 14),            /* 12 taken */
        I_0(HALT),                       /* 13 skipped */
        I_ABI(BNE, 0, 0, 13),            /* 14 not taken */
        I_AI(JAL, 10, 18),               /* 15 r10 = 16 */
        I_0(HALT),                       /* 16 */
        I_0(HALT),                       /* 17 */
        V_ABI(VSPLD, 5, 0, 8, 2),        /* 18 SP 8 12 16 */
        I_ABCD(SFETCH, 6, 3, 5, 6),      /* 19 IDM 64 68 72 76; r5 = 80 */
        V_ABI(LDB, 7, 0, 4, 7),          /* 20 empty mask: no access */
        V_AI(VLI, 10, 3, 0),             /* 21 */
        V_ABC(VSUB, 9, 10, 1, 0),        /* 22 3 2 1 0 */
        V_ABI(VSHLI, 9, 9, 2, 0),        /* 23 12 8 4 0 */
        V_ABI(LDG, 8, 9, 256, 0),        /* 24 SM 268 264 260 256 */
        V_AB(SAPP, 5, 1, 2),             /* 25 IDM 80 84 88 */
        V_ABI(FBADD, 1, 9, 0, 2),        /* 26 FB 12 8 4 */
        V_ABI(LDB, 7, 0, 4, 0),          /* 27 SM 4 */
        I_A(JR, 10),                     /* 28 -> 16 */
    };
    const WantRec want[] = {
        {0, 1, 0, NO_MEM, 0, {0}, 0, ANY},
        {1, 2, 0, NO_MEM, 0, {0}, 0, 0xF},
        {2, 3, 0, NO_MEM, 0, {0}, 0, ANY},
        {3, 4, 0, CORE_MEM_RB0, 3, {16, 20, 24}, 0, 0x7},
        {4, 5, 0, NO_MEM, 0, {0}, 0, ANY},
        {5, 6, 0, CORE_MEM_RB1, 3, {32, 36, 40}, 0, 0x7},
        {6, 7, 0, CORE_MEM_RB0, 4, {0, 4, 8, 12}, 0, 0xF},
        {7, 8, 0, NO_MEM, 0, {0}, 4, ANY},
        {8, 9, 0, NO_MEM, 0, {0}, 8, ANY},
        {9, 10, 0, NO_MEM, 0, {0}, 0, ANY},
        {10, 11, 0, NO_MEM, 0, {0}, 0, ANY},
        {11, 12, 0, CORE_MEM_IDM, ANY, {0}, 6, ANY},
        {12, 14, 1, NO_MEM, 0, {0}, 0, ANY},
        {14, 15, 0, NO_MEM, 0, {0}, 0, ANY},
        {15, 18, 1, NO_MEM, 0, {0}, 0, ANY},
        {18, 19, 0, CORE_MEM_SPAD, 3, {8, 12, 16}, 0, 0x7},
        {19, 20, 0, CORE_MEM_IDM, 4, {64, 68, 72, 76}, 6, 0xF}, /* count: IDs left, (88 - 64) / 4 */
        {20, 21, 0, NO_MEM, 0, {0}, 0, 0x0},
        {21, 22, 0, NO_MEM, 0, {0}, 0, 0xF},
        {22, 23, 0, NO_MEM, 0, {0}, 0, 0xF},
        {23, 24, 0, NO_MEM, 0, {0}, 0, 0xF},
        {24, 25, 0, CORE_MEM_SCENE, 4, {268, 264, 260, 256}, 0, 0xF},
        {25, 26, 0, CORE_MEM_IDM, 3, {80, 84, 88}, 0, 0x7},
        {26, 27, 0, CORE_MEM_FB, 3, {12, 8, 4}, 0, 0x7},
        {27, 28, 0, CORE_MEM_SCENE, 1, {4}, 0, 0xF},
        {28, 16, 1, NO_MEM, 0, {0}, 0, ANY},
        {16, 16, ANY, NO_MEM, 0, {0}, 0, ANY}, /* halt: next_pc not specified, checked below only as present */
    };
    const int nwant = (int)(sizeof want / sizeof want[0]);
    HookLog log;
    memset(&log, 0, sizeof log);
    TcCore t;
    tc_init(&t, prog, sizeof prog / sizeof prog[0], 4);
    core_set_hook(t.c, log_hook, &log);
    tc_run_halt(&t);
    cr_assert_eq(log.n, nwant, "%d records, expected %d (one per executed instruction)", log.n, nwant);
    cr_expect_eq(core_sreg(t.c, 10), 16u, "jal: ra := pc + 1");
    cr_expect_eq(core_sreg(t.c, 7), 64u + 4 * 5, "part: queue 1110 1110, the first 6 bits have 5 set");
    for (int i = 0; i < nwant; i++) {
        const CoreRecord *r = &log.rec[i];
        const WantRec *w = &want[i];
        cr_expect_eq(r->pc, w->pc, "record %d: pc %u, expected %u", i, r->pc, w->pc);
        cr_expect_not_null(r->in, "record %d: no instruction", i);
        if (r->in)
            cr_expect_eq(r->in->op, prog[w->pc].op, "record %d: instruction %s, expected %s", i,
                         isa_ops[r->in->op].mnemonic, isa_ops[prog[w->pc].op].mnemonic);
        cr_expect_eq(r->stage, 0, "record %d: stage", i);
        if (i == nwant - 1)
            break; /* halt */
        cr_expect_eq(r->next_pc, w->next_pc, "record %d (pc %u): next_pc %u, expected %u", i, w->pc, r->next_pc, w->next_pc);
        if (w->taken != ANY)
            cr_expect_eq(r->taken, w->taken, "record %d (pc %u): taken %u, expected %d", i, w->pc, r->taken, w->taken);
        if (w->mem != ANY)
            cr_expect_eq(r->mem, w->mem, "record %d (pc %u): mem %u, expected %d", i, w->pc, r->mem, w->mem);
        if (w->naddr != ANY) {
            cr_expect_eq(r->naddr, w->naddr, "record %d (pc %u): naddr %u, expected %d", i, w->pc, r->naddr, w->naddr);
            for (int k = 0; k < w->naddr && k < r->naddr; k++)
                cr_expect_eq(r->addr[k], w->addr[k], "record %d (pc %u): addr[%d] = %u, expected %u", i, w->pc, k,
                             r->addr[k], w->addr[k]);
        }
        if (w->count != ANY)
            cr_expect_eq(r->count, (uint32_t)w->count, "record %d (pc %u): count %u, expected %lld", i, w->pc, r->count,
                         w->count);
        if (w->exec != ANY)
            cr_expect_eq(r->exec, (uint64_t)w->exec, "record %d (pc %u): exec %#llx, expected %#llx", i, w->pc,
                         (unsigned long long)r->exec, (unsigned long long)w->exec);
    }
    /* base: the stream pointer before sfetch and sapp, the begin of a partition */
    cr_expect_eq(log.rec[11].base, 64u, "part: base %u", log.rec[11].base);
    cr_expect_eq(log.rec[16].base, 64u, "sfetch: base %u", log.rec[16].base);
    cr_expect_eq(log.rec[22].base, 80u, "sapp: base %u", log.rec[22].base);
    tc_free(&t);
}

Test(core_hook, stage_and_wide_addresses)
{
    /* At N = 64 a gather records 64 addresses, and the record carries the stage in force. */
    HookLog log;
    memset(&log, 0, sizeof log);
    TcCore t;
    tc_init(&t, PROG(I_I(STAGE, 2), V_A(VIOTA, 1, 0), V_ABCI(RGAT, 2, 1, 0, 100 * 4, 0), I_0(HALT)), 64);
    core_set_hook(t.c, log_hook, &log);
    tc_run_halt(&t);
    cr_assert_eq(log.n, 4);
    cr_expect_eq(log.rec[0].stage, ISA_STAGE_OTHER);
    cr_expect_eq(log.rec[1].stage, ISA_STAGE_INTERSECTION);
    const CoreRecord *r = &log.rec[2];
    cr_expect_eq(r->mem, CORE_MEM_RB0);
    cr_expect_eq(r->naddr, 64);
    cr_expect_eq(r->exec, ~0ull);
    for (int l = 0; l < 64; l++)
        cr_expect_eq(r->addr[l], 400u + 4u * (uint32_t)l, "lane %d", l);
    tc_free(&t);
}

/* The records of one opcode sent to a hook of their own: each record reaches exactly one of the
 * two hooks, in order, and core_set_hook sends them all back to one. */
static void log_hook_other(void *ctx, const CoreRecord *r)
{
    log_hook((HookLog *)ctx + 1, r);
}

Test(core_hook, a_hook_per_opcode)
{
    for (int again = 0; again < 2; again++) {
        HookLog log[2];
        memset(log, 0, sizeof log);
        TcCore t;
        tc_init(&t, PROG(I_ABI(ADDI, 1, 1, 1), V_A(VIOTA, 1, 0), I_ABI(ADDI, 1, 1, 1), V_ABCI(RGAT, 2, 1, 0, 0, 0),
                         I_ABI(ADDI, 1, 1, 1), I_0(HALT)),
                4);
        core_set_hook(t.c, log_hook, &log[0]);
        core_set_op_hook(t.c, ISA_OP_ADDI, log_hook_other);
        core_set_op_hook(t.c, -1, log_hook_other);           /* out of range: ignored */
        core_set_op_hook(t.c, ISA_OP_COUNT, log_hook_other);
        core_set_op_hook(t.c, ISA_OP_RGAT, NULL);            /* NULL: ignored */
        if (again)
            core_set_hook(t.c, log_hook, &log[0]);            /* all back to one */
        tc_run_halt(&t);
        if (!again) {
            cr_assert_eq(log[1].n, 3, "the three addi to their own hook: %d", log[1].n);
            cr_assert_eq(log[0].n, 3, "viota, rgat and halt to the core's hook: %d", log[0].n);
            for (int i = 0; i < 3; i++)
                cr_expect_eq(log[1].rec[i].pc, 2u * (uint32_t)i, "addi %d at pc %u", i, log[1].rec[i].pc);
            cr_expect_eq(log[0].rec[1].pc, 3u);
            cr_expect_eq(log[0].rec[1].naddr, 4, "the gather's record is whole");
        } else {
            cr_expect_eq(log[0].n, 6);
            cr_expect_eq(log[1].n, 0);
        }
        tc_free(&t);
    }
}

/* ==== core_run: limits and determinism ================================================================ */

Test(core_run, limit_is_resumable_and_zero_means_none)
{
    TcCore t;
    tc_init(&t, PROG(I_ABI(ADDI, 1, 1, 1), I_I(JMP, 0)), 4);
    cr_expect_eq(tc_run(&t, 10), CORE_EXIT_LIMIT);
    cr_expect_eq(core_sreg(t.c, 1), 5u);
    cr_expect_eq(core_instructions(t.c), 10u);
    cr_expect_eq(tc_run(&t, 7), CORE_EXIT_LIMIT, "max_instr more instructions");
    cr_expect_eq(core_instructions(t.c), 17u);
    cr_expect_eq(core_sreg(t.c, 1), 9u);
    cr_expect_eq(core_pc(t.c), 1u);
    tc_free(&t);

    /* 0 = no limit: a loop of 3 x 100000 + 2 instructions halts */
    tc_init(&t, PROG(I_AI(LI, 2, 100000), I_ABI(ADDI, 1, 1, 1), I_ABI(BLT, 1, 2, 1), I_0(HALT)), 4);
    cr_expect_eq(tc_run(&t, 0), CORE_EXIT_HALT, "%s", core_trap_message(t.c));
    cr_expect_eq(core_instructions(t.c), 200002u);
    tc_free(&t);

    /* a halt that is the max_instr-th instruction halts; one fewer stops at the limit */
    tc_init(&t, PROG(I_0(NOP), I_0(NOP), I_0(HALT)), 4);
    cr_expect_eq(tc_run(&t, 3), CORE_EXIT_HALT, "%s", core_trap_message(t.c));
    tc_free(&t);
    tc_init(&t, PROG(I_0(NOP), I_0(NOP), I_0(HALT)), 4);
    cr_expect_eq(tc_run(&t, 2), CORE_EXIT_LIMIT);
    tc_free(&t);
}

static void fill_for_filter(Core *c, uint32_t L)
{
    uint32_t seed = 12345;
    for (uint32_t id = 0; id < 1000; id++)
        tc_poke(c, CORE_MEM_RB0, 4 * id, (tc_lcg(&seed) & 1u) ? 1u : 0u);
    for (uint32_t i = 0; i < L; i++)
        tc_poke(c, CORE_MEM_IDM, 64 + 4 * i, (i * 389u + 11u) % 1000u);
    core_set_sreg(c, 6, 64);
    core_set_sreg(c, 7, 64 + 4 * L);
    core_set_sreg(c, 9, 64);
}

static void null_hook(void *ctx, const CoreRecord *r)
{
    (void)r;
    (*(uint64_t *)ctx)++;
}

static void expect_same_state(Core *a, Core *b, const char *what)
{
    int n = core_lanes(a);
    cr_assert_eq(core_lanes(b), n);
    cr_expect_eq(core_pc(a), core_pc(b), "%s: pc", what);
    cr_expect_eq(core_instructions(a), core_instructions(b), "%s: instructions", what);
    cr_expect_eq(core_current_rb(a), core_current_rb(b), "%s: current rb", what);
    for (int r = 0; r < ISA_NUM_SREGS; r++)
        cr_expect_eq(core_sreg(a, r), core_sreg(b, r), "%s: r%d", what, r);
    for (int v = 0; v < ISA_NUM_VREGS; v++)
        for (int l = 0; l < n; l++)
            cr_expect_eq(core_vreg(a, v, l), core_vreg(b, v, l), "%s: v%d[%d]", what, v, l);
    for (int m = 0; m < ISA_NUM_MREGS; m++)
        cr_expect_eq(core_mreg(a, m), core_mreg(b, m), "%s: m%d", what, m);
    for (int m = 0; m < CORE_MEM_COUNT; m++) {
        uint32_t sa, sb;
        uint8_t *pa = core_mem(a, (CoreMem)m, &sa), *pb = core_mem(b, (CoreMem)m, &sb);
        cr_expect_eq(sa, sb);
        cr_expect_eq(memcmp(pa, pb, sa), 0, "%s: %s differs", what, core_mem_names[m]);
    }
    cr_expect_eq(memcmp(core_stats(a), core_stats(b), sizeof(CoreStats)), 0, "%s: counters differ", what);
}

Test(core_run, deterministic_and_hook_does_not_change_results)
{
    /* The filter, then float work on the kept rays (vrcp, vsin, vexp2, fbadd), run three times:
     * twice without a hook and once with one. Everything must be identical. */
    static const IsaInstr prog[] = {
        V_AI(VLI, 9, 1, 0),              /*  0 */
        I_ABCD(SFETCH, 4, 1, 9, 7),      /*  1 */
        V_ABCI(RGAT, 5, 4, 20, 0, 1),    /*  2 */
        V_ABC(VIEQ, 2, 5, 9, 1),         /*  3 */
        I_A(PMASK, 2),                   /*  4 */
        I_ABI(BLT, 9, 7, 1),             /*  5 */
        I_ABC(PART, 16, 6, 7),           /*  6 */
        I_AB(MOV, 9, 6),                 /*  7 */
        I_ABCD(SFETCH, 4, 1, 9, 16),     /*  8 loop over the kept rays */
        V_AB(VCVTIF, 10, 4, 1),          /*  9 */
        V_AB(VRCP, 11, 10, 1),           /* 10 */
        V_AB(VSIN, 12, 10, 1),           /* 11 */
        V_AB(VEXP2, 13, 11, 1),          /* 12 */
        V_ABCD(VFMA, 14, 12, 13, 11, 1), /* 13 */
        V_ABI(VANDI, 15, 4, 63, 1),      /* 14 */
        V_ABI(VSHLI, 15, 15, 2, 1),      /* 15 */
        V_ABI(FBADD, 14, 15, 0, 1),      /* 16 */
        V_ABCI(RSCTN, 14, 4, 20, 0, 1),  /* 17 */
        I_ABI(BLT, 9, 16, 8),            /* 18 */
        I_0(RSWAP),                      /* 19 */
        I_0(HALT),                       /* 20 */
    };
    const size_t np = sizeof prog / sizeof prog[0];
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        TcCore a, b, h;
        tc_init(&a, prog, np, n);
        tc_init(&b, prog, np, n);
        tc_init(&h, prog, np, n);
        fill_for_filter(a.c, 131);
        fill_for_filter(b.c, 131);
        fill_for_filter(h.c, 131);
        uint64_t calls = 0;
        core_set_hook(h.c, null_hook, &calls);
        tc_run_halt(&a);
        tc_run_halt(&b);
        tc_run_halt(&h);
        expect_same_state(a.c, b.c, "two runs");
        expect_same_state(a.c, h.c, "with a hook");
        cr_expect_eq(calls, core_instructions(h.c), "N=%d: one hook call per instruction", n);
        tc_free(&a);
        tc_free(&b);
        tc_free(&h);
    }
}
