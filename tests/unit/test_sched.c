/* tests/unit/test_sched.c -- the scheduling pass (asm/sched.h): a scheduled program computes what
 * its source order computes, and the pass moves what it may and nothing else.
 *
 * Owns: the randomized equivalence test (generated blocks of register, mask and memory operations
 * on every memory, with aliasing, run both ways on the functional core and compared in their
 * whole final state), the fences (.barrier, .sched off, stage markers, labels, branches), the
 * report, the disassembly of a scheduled object and the machine model sfsim fills. Must not: time
 * anything (the cycle effect is measured by the runs, docs/assembler.md).
 */
#include <criterion/criterion.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../asm/asm.h"
#include "../../asm/sched.h"
#include "../../isa/isa.h"
#include "../../sim/config.h"
#include "../../sim/core.h"
#include "../../sim/run/schedmodel.h"
#include "../support/core_prog.h"

/* ==== random programs ================================================================================ */

/* Registers the generator keeps for addressing: r1..r3 bases (multiples of 4 in 0..128), r8 the
 * append pointer, r9 / r10 the ID-fetch pointer and end, r11 the slot counter, r13 / r14 the
 * partitioned stream; v28..v31 index vectors (lane, lane * 4, lane & 3, (lane & 3) * 4). */
enum { IDM_APPEND = 512, IDM_PART = 768 };
static const int free_sregs[] = {0, 4, 5, 6, 7, 12, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 28, 29, 30, 31};
#define NFREE_S ((int)(sizeof free_sregs / sizeof free_sregs[0]))

typedef struct Gen {
    uint32_t s;
    IsaInstr *p;
    int n, cap;
    int lanes;
    int base[4];    /* values of r1..r3 as the program runs */
    int appends;
    uint8_t *inside; /* inside[i]: instruction i follows a queued mask in its partition group (no
                        branch may land there, past the pmask) */
} Gen;

static uint32_t rnd(Gen *g, uint32_t k) /* 0..k-1 */
{
    uint32_t x = tc_lcg(&g->s) << 16 | tc_lcg(&g->s);
    return k ? x % k : 0;
}

static void emit(Gen *g, IsaInstr in)
{
    cr_assert_lt(g->n, g->cap);
    g->p[g->n++] = in;
}

static int any_sreg(Gen *g) { return (int)rnd(g, 32); }
static int free_sreg(Gen *g) { return free_sregs[rnd(g, NFREE_S)]; }
static int any_vreg(Gen *g) { return (int)rnd(g, 32); }
static int free_vreg(Gen *g) { return (int)rnd(g, 28); }
static int any_mreg(Gen *g) { return (int)rnd(g, 8); }
static int base_reg(Gen *g) { return 1 + (int)rnd(g, 3); }
static uint32_t off4(Gen *g, uint32_t max) { return 4u * rnd(g, max / 4 + 1); }

/* An operand register of kind k for an instruction without memory: any to read, a free one to write. */
static int plain_reg(Gen *g, IsaOperandKind k, int write)
{
    if (k == ISA_K_R)
        return write ? free_sreg(g) : any_sreg(g);
    if (k == ISA_K_V)
        return write ? free_vreg(g) : any_vreg(g);
    return any_mreg(g);
}

/* An instruction of no memory, branch or side effect that cannot trap, with random operands. */
static void gen_plain(Gen *g)
{
    for (;;) {
        int op = (int)rnd(g, ISA_OP_COUNT);
        const IsaOpInfo *oi = &isa_ops[op];
        if (oi->flags & (ISA_FL_BRANCH | ISA_FL_END | ISA_FL_SIDE | ISA_FL_RB | ISA_FL_IDM | ISA_FL_SPAD |
                         ISA_FL_SCENE | ISA_FL_FB) ||
            oi->unit == ISA_U_AGU || oi->unit == ISA_U_PART || op == ISA_OP_DIVU || op == ISA_OP_REMU)
            continue; /* the memory ones have templates below; divu and remu trap on 0 */
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        IsaInstr in = {(uint8_t)op, 0, 0, 0, 0, 0, 0};
        int ri = 0;
        for (int i = 0; i < fi->nops; i++) {
            IsaOperandKind k = fi->ops[i].kind;
            if (k == ISA_K_IMM) {
                in.imm = op == ISA_OP_VEXT ? rnd(g, (uint32_t)g->lanes) : rnd(g, 4) ? rnd(g, 64) : rnd(g, 0xFFFFFFFFu);
                continue;
            }
            int r = plain_reg(g, k, oi->access[ri++] != 'r');
            uint8_t *f = fi->ops[i].field == ISA_FIELD_A ? &in.a : fi->ops[i].field == ISA_FIELD_B ? &in.b
                       : fi->ops[i].field == ISA_FIELD_C ? &in.c : &in.d;
            *f = (uint8_t)r;
        }
        if (fi->masked)
            in.mask = (uint8_t)(rnd(g, 3) ? 0 : any_mreg(g));
        emit(g, in);
        return;
    }
}

/* A base register changed within its range (the pass must see the new value is another address). */
static void gen_base_change(Gen *g)
{
    int b = base_reg(g);
    int d = 4 * ((int)rnd(g, 5) - 2);
    if (g->base[b] + d < 0 || g->base[b] + d > 128)
        d = -d;
    if (rnd(g, 4) == 0) {
        int o = base_reg(g);
        emit(g, (IsaInstr){ISA_OP_MOV, (uint8_t)b, (uint8_t)o, 0, 0, 0, 0});
        g->base[b] = g->base[o];
    } else {
        emit(g, (IsaInstr){ISA_OP_ADDI, (uint8_t)b, (uint8_t)b, 0, 0, 0, (uint32_t)d});
        g->base[b] += d;
    }
}

static uint8_t msk(Gen *g) { return (uint8_t)(rnd(g, 3) ? 0 : any_mreg(g)); }

/* A memory instruction on one of the six memories, inside it (the ranges: see the enum above). */
static void gen_memory(Gen *g)
{
    uint8_t b = (uint8_t)base_reg(g), v = (uint8_t)free_vreg(g), s = (uint8_t)free_sreg(g);
    uint8_t idx = (uint8_t)(rnd(g, 2) ? 28 : 30), fbidx = 31;
    switch (rnd(g, 19)) {
    case 0: emit(g, (IsaInstr){ISA_OP_SPLD, s, b, 0, 0, 0, off4(g, 128)}); break;
    case 1: emit(g, (IsaInstr){ISA_OP_SPST, (uint8_t)any_sreg(g), b, 0, 0, 0, off4(g, 128)}); break;
    case 2: emit(g, (IsaInstr){ISA_OP_VSPLD, v, b, 0, 0, msk(g), off4(g, 128)}); break;
    case 3: emit(g, (IsaInstr){ISA_OP_VSPST, (uint8_t)any_vreg(g), b, 0, 0, msk(g), off4(g, 128)}); break;
    case 4: emit(g, (IsaInstr){ISA_OP_LD, s, b, 0, 0, 0, off4(g, 1024)}); break;
    case 5: emit(g, (IsaInstr){ISA_OP_ST, (uint8_t)any_sreg(g), b, 0, 0, 0, off4(g, 1024)}); break;
    case 6: emit(g, (IsaInstr){ISA_OP_LDB, v, b, 0, 0, msk(g), off4(g, 1024)}); break;
    case 7: emit(g, (IsaInstr){ISA_OP_LDG, v, 28, 0, 0, msk(g), off4(g, 1024)}); break;
    case 8: emit(g, (IsaInstr){ISA_OP_RGAT, v, idx, b, 0, msk(g), off4(g, 1024)}); break;
    case 9: emit(g, (IsaInstr){ISA_OP_RSCT, (uint8_t)any_vreg(g), idx, b, 0, msk(g), off4(g, 1024)}); break;
    case 10: emit(g, (IsaInstr){ISA_OP_RGATN, v, idx, b, 0, msk(g), off4(g, 1024)}); break;
    case 11: emit(g, (IsaInstr){ISA_OP_RSCTN, (uint8_t)any_vreg(g), idx, b, 0, msk(g), off4(g, 1024)}); break;
    case 12: emit(g, (IsaInstr){ISA_OP_FBADD, (uint8_t)any_vreg(g), fbidx, 0, 0, msk(g), off4(g, 192)}); break;
    case 13: emit(g, (IsaInstr){ISA_OP_SLD, s, b, 0, 0, 0, off4(g, 256)}); break;
    case 14: emit(g, (IsaInstr){ISA_OP_SST, (uint8_t)any_sreg(g), b, 0, 0, 0, off4(g, 256)}); break;
    case 15: emit(g, (IsaInstr){ISA_OP_SFETCH, v, (uint8_t)(1 + rnd(g, 7)), 9, 10, 0, 0}); break;
    case 16:
        if (g->appends++ < 3)
            emit(g, (IsaInstr){ISA_OP_SAPP, 8, (uint8_t)any_vreg(g), 0, 0, msk(g), 0});
        break;
    case 17: emit(g, (IsaInstr){ISA_OP_RALLOC, v, 11, 0, 0, msk(g), 0}); break;
    default: /* a partition of the N IDs at IDM_PART by one queued mask */
        if (rnd(g, 2))
            emit(g, (IsaInstr){ISA_OP_PCLR, 0, 0, 0, 0, 0, 0});
        emit(g, (IsaInstr){ISA_OP_PMASK, (uint8_t)any_mreg(g), 0, 0, 0, 0, 0});
        if (rnd(g, 2)) {
            g->inside[g->n] = 1;
            gen_plain(g);
        }
        g->inside[g->n] = 1;
        emit(g, (IsaInstr){ISA_OP_PART, s, 13, 14, 0, 0, 0});
        break;
    }
}

/* The prologue sets the index vectors and fills the other vectors and the masks from memory; the
 * body is len random instructions with now and then a base change, a side effect or a branch. */
static void gen_program(Gen *g, int len)
{
    g->n = 0;
    g->appends = 0;
    memset(g->inside, 0, (size_t)g->cap);
    emit(g, (IsaInstr){ISA_OP_MALL, 0, 0, 0, 0, 0, 0});
    emit(g, (IsaInstr){ISA_OP_VIOTA, 29, 0, 0, 0, 0, 0});
    emit(g, (IsaInstr){ISA_OP_VSHLI, 28, 29, 0, 0, 0, 2});
    emit(g, (IsaInstr){ISA_OP_VANDI, 30, 29, 0, 0, 0, 3});
    emit(g, (IsaInstr){ISA_OP_VSHLI, 31, 30, 0, 0, 0, 2});
    for (int v = 0; v < 28; v++)
        emit(g, (IsaInstr){ISA_OP_LDG, (uint8_t)v, 28, 0, 0, 0, 64u * (uint32_t)v});
    for (int m = 1; m < 8; m++)
        emit(g, (IsaInstr){ISA_OP_MTAIL, (uint8_t)m, (uint8_t)free_sreg(g), 0, 0, 0, 0});
    for (int k = 0; k < len; k++) {
        uint32_t c = rnd(g, 100);
        if (c < 45)
            gen_plain(g);
        else if (c < 90)
            gen_memory(g);
        else if (c < 95)
            gen_base_change(g);
        else if (c == 95)
            emit(g, (IsaInstr){ISA_OP_STAGE, 0, 0, 0, 0, 0, rnd(g, 4)});
        else if (c == 96)
            emit(g, (IsaInstr){ISA_OP_SGEN, (uint8_t)any_sreg(g), 0, 0, 0, 0, 0});
        else if (c == 97)
            emit(g, (IsaInstr){ISA_OP_RSWAP, 0, 0, 0, 0, 0, 0});
        else /* a forward branch over a few instructions (taken or not, by the registers) */
            emit(g, (IsaInstr){ISA_OP_BEQ, (uint8_t)any_sreg(g), (uint8_t)any_sreg(g), 0, 0, 0,
                               (uint32_t)(g->n + 1 + (int)rnd(g, 4))});
    }
    /* branch targets past the end land on the halt */
    for (int i = 0; i < g->n; i++)
        if (g->p[i].op == ISA_OP_BEQ) {
            while (g->p[i].imm < (uint32_t)g->n && g->inside[g->p[i].imm])
                g->p[i].imm++;
            if (g->p[i].imm > (uint32_t)g->n)
                g->p[i].imm = (uint32_t)g->n;
        }
    emit(g, (IsaInstr){ISA_OP_HALT, 0, 0, 0, 0, 0, 0});
}

/* A core for obj with the generator's registers and random memories (the same for seed). */
static Core *start_core(const AsmObject *obj, int lanes, uint32_t seed)
{
    CoreParams p;
    char err[256];
    tc_params(&p, lanes);
    Core *c = core_new(&p, obj, err, sizeof err);
    cr_assert_not_null(c, "%s", err);
    uint32_t s = seed;
    for (int m = 0; m < CORE_MEM_COUNT; m++) {
        uint32_t bytes;
        uint8_t *mem = core_mem(c, (CoreMem)m, &bytes);
        for (uint32_t i = 0; i < bytes; i++)
            mem[i] = (uint8_t)tc_lcg(&s);
    }
    for (int r = 0; r < 32; r++)
        core_set_sreg(c, r, (uint32_t)tc_lcg(&s) << 16 | tc_lcg(&s));
    static const int base0[4] = {0, 0, 64, 128};
    for (int b = 1; b <= 3; b++)
        core_set_sreg(c, b, (uint32_t)base0[b]);
    core_set_sreg(c, 8, IDM_APPEND);
    core_set_sreg(c, 9, 0);
    core_set_sreg(c, 10, 256);
    core_set_sreg(c, 11, 0);
    core_set_sreg(c, 13, IDM_PART);
    core_set_sreg(c, 14, IDM_PART + 4u * (uint32_t)lanes);
    return c;
}

/* The whole architectural state and the counters must be the same. */
static void expect_same_state(Core *a, Core *b, int lanes, int prog)
{
    for (int r = 0; r < 32; r++)
        cr_assert_eq(core_sreg(a, r), core_sreg(b, r), "program %d: r%d differs", prog, r);
    for (int v = 0; v < 32; v++)
        for (int l = 0; l < lanes; l++)
            cr_assert_eq(core_vreg(a, v, l), core_vreg(b, v, l), "program %d: v%d lane %d differs", prog, v, l);
    for (int m = 0; m < 8; m++)
        cr_assert_eq(core_mreg(a, m), core_mreg(b, m), "program %d: m%d differs", prog, m);
    for (int m = 0; m < CORE_MEM_COUNT; m++) {
        uint32_t na, nb;
        uint8_t *ma = core_mem(a, (CoreMem)m, &na), *mb = core_mem(b, (CoreMem)m, &nb);
        cr_assert_eq(na, nb);
        cr_assert(memcmp(ma, mb, na) == 0, "program %d: memory %s differs", prog, core_mem_names[m]);
    }
    cr_assert_eq(core_current_rb(a), core_current_rb(b), "program %d: current ray buffer", prog);
    cr_assert_eq(core_instructions(a), core_instructions(b), "program %d: instruction count", prog);
    cr_assert(memcmp(core_stats(a), core_stats(b), sizeof(CoreStats)) == 0,
              "program %d: the per-stage, per-category or per-generation counters differ", prog);
}

static int cmp_u64(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : a > b;
}

/* The same words, in another order. */
static void expect_permutation(const AsmObject *a, const AsmObject *b)
{
    cr_assert_eq(a->ntext, b->ntext);
    uint64_t *x = malloc(8u * a->ntext), *y = malloc(8u * a->ntext);
    cr_assert(x && y);
    memcpy(x, a->text, 8u * a->ntext);
    memcpy(y, b->text, 8u * a->ntext);
    qsort(x, a->ntext, 8, cmp_u64);
    qsort(y, a->ntext, 8, cmp_u64);
    cr_assert(memcmp(x, y, 8u * a->ntext) == 0, "the scheduled text is not a permutation of the source's");
    free(x);
    free(y);
}

static void random_model(Gen *g, AsmSchedModel *m, int lanes)
{
    sched_model_default(m);
    if (rnd(g, 2))
        for (int u = 0; u < ISA_U_COUNT; u++) {
            m->lat[u] = 1 + (int)rnd(g, 8);
            m->issue[u] = 1 + (int)rnd(g, 3);
        }
    m->lanes = rnd(g, 4) ? lanes : 0;
}

Test(sched, random_blocks_compute_the_same, .timeout = 120)
{
    enum { PROGRAMS = 3000 };
    Gen g = {.s = 12345, .cap = 2048};
    g.p = calloc((size_t)g.cap, sizeof *g.p);
    g.inside = calloc((size_t)g.cap, 1);
    cr_assert(g.p && g.inside);
    uint64_t moved = 0, reordered = 0;
    for (int prog = 0; prog < PROGRAMS; prog++) {
        int lanes = prog % 3 == 0 ? 8 : prog % 3 == 1 ? 16 : 5;
        g.lanes = lanes;
        g.base[1] = 0, g.base[2] = 64, g.base[3] = 128;
        gen_program(&g, prog % 500 == 0 ? 1300 : prog % 50 == 0 ? 600 : 4 + (int)rnd(&g, 120));
        AsmObject src, opt;
        tc_obj_from_prog(&src, g.p, (size_t)g.n);
        tc_obj_from_prog(&opt, g.p, (size_t)g.n);
        AsmSchedModel m;
        random_model(&g, &m, lanes);
        SchedStats st;
        cr_assert_eq(sched_object(&opt, NULL, &m, NULL, &st), 0);
        cr_assert_leq(st.after, st.before, "program %d: the estimate got worse", prog);
        expect_permutation(&src, &opt);
        moved += st.moved;
        reordered += st.reordered;
        uint32_t seed = 777u + (uint32_t)prog;
        Core *a = start_core(&src, lanes, seed), *b = start_core(&opt, lanes, seed);
        CoreExit ea = core_run(a, 100000), eb = core_run(b, 100000);
        cr_assert_eq(ea, CORE_EXIT_HALT, "program %d (source order) did not halt: %s", prog, core_trap_message(a));
        cr_assert_eq(eb, CORE_EXIT_HALT, "program %d (scheduled) did not halt: %s", prog, core_trap_message(b));
        expect_same_state(a, b, lanes, prog);
        core_free(a);
        core_free(b);
        asm_object_free(&src);
        asm_object_free(&opt);
    }
    /* the test means something only if the pass moved a good share of the instructions */
    cr_expect_gt(reordered, PROGRAMS / 2, "only %llu of %d programs were reordered", (unsigned long long)reordered,
                 PROGRAMS);
    cr_expect_gt(moved, 50000, "only %llu instructions moved", (unsigned long long)moved);
    free(g.p);
    free(g.inside);
}

/* ==== fences, labels, the report, the disassembly ==================================================== */

/* Assembles src scheduled with the default model; returns the disassembly of .text (no labels). */
static char *assemble_sched(const char *src, int schedule, AsmObject *obj, char **report)
{
    AsmSchedModel m;
    sched_model_default(&m);
    char *rep = NULL, *dis = NULL;
    size_t rlen = 0, dlen = 0;
    FILE *rf = open_memstream(&rep, &rlen);
    AsmOptions opt = {.schedule = schedule ? &m : NULL, .schedule_report = rf};
    int errs = asm_assemble_string("t.s", src, strlen(src), &opt, obj);
    fclose(rf);
    cr_assert_eq(errs, 0, "the test source does not assemble");
    FILE *df = open_memstream(&dis, &dlen);
    for (uint32_t i = 0; i < obj->ntext; i++) {
        IsaInstr in;
        char err[64], line[128];
        cr_assert_eq(isa_decode(obj->text[i], &in, err, sizeof err), 0);
        isa_disassemble(&in, 0, line, sizeof line);
        fprintf(df, "%s\n", line);
    }
    fclose(df);
    if (report)
        *report = rep;
    else
        free(rep);
    return dis;
}

/* A dependent chain with an independent instruction after it: the independent one moves up into
 * the chain's shadow. */
static const char chain[] = "        vfma    v1, v2, v3, v4\n"
                            "        vfadd   v5, v1, v1\n"
                            "        vfmul   v6, v7, v8\n"
                            "        halt\n";

Test(sched, an_independent_instruction_fills_a_latency)
{
    AsmObject o;
    char *d = assemble_sched(chain, 1, &o, NULL);
    cr_expect_str_eq(d, "vfma v1, v2, v3, v4\nvfmul v6, v7, v8\nvfadd v5, v1, v1\nhalt\n");
    free(d);
    asm_object_free(&o);
    d = assemble_sched(chain, 0, &o, NULL);
    cr_expect_str_eq(d, "vfma v1, v2, v3, v4\nvfadd v5, v1, v1\nvfmul v6, v7, v8\nhalt\n", "without the pass: as written");
    free(d);
    asm_object_free(&o);
}

Test(sched, fences_keep_the_order)
{
    static const char *const fenced[] = {
        /* .barrier between producer and consumer */
        "        vfma    v1, v2, v3, v4\n        vfadd   v5, v1, v1\n        .barrier\n        vfmul   v6, v7, v8\n        halt\n",
        /* .sched off around the chain */
        "        .sched off\n        vfma    v1, v2, v3, v4\n        vfadd   v5, v1, v1\n        vfmul   v6, v7, v8\n"
        "        .sched on\n        halt\n",
        /* a stage marker */
        "        vfma    v1, v2, v3, v4\n        vfadd   v5, v1, v1\n        stage   2\n        vfmul   v6, v7, v8\n        halt\n",
        /* a label */
        "        vfma    v1, v2, v3, v4\n        vfadd   v5, v1, v1\nhere:   vfmul   v6, v7, v8\n        halt\n",
        /* a store and a load that may alias (different base registers) */
        "        vfma    v1, v2, v3, v4\n        vspst   v1, r1, 0\n        vspld   v6, r2, 0\n        halt\n",
        /* the exec mask the independent one needs is written by the chain */
        "        vfma    v1, v2, v3, v4\n        vflt    m1, v1, v1\n        vfmul   v6, v7, v8 @m1\n        halt\n",
    };
    for (size_t k = 0; k < sizeof fenced / sizeof fenced[0]; k++) {
        AsmObject a, b;
        char *x = assemble_sched(fenced[k], 0, &a, NULL), *y = assemble_sched(fenced[k], 1, &b, NULL);
        cr_expect_str_eq(y, x, "source %zu: the pass moved something across a fence", k);
        free(x);
        free(y);
        asm_object_free(&a);
        asm_object_free(&b);
    }
}

Test(sched, disjoint_accesses_and_macros_move)
{
    /* the same base register, words apart: the load may go above the store; and a macro's body
     * is no barrier */
    static const char src[] = ".macro  mix d, a\n"
                              "        vfma    \\d, \\a, \\a, \\a\n"
                              "        vfadd   \\d, \\d, \\d\n"
                              ".endm\n"
                              "        spst    r5, r1, 0\n"
                              "        mix     v1, v2\n"
                              "        mix     v3, v4\n"
                              "        spld    r6, r1, 4\n"
                              "        halt\n";
    AsmObject o;
    char *d = assemble_sched(src, 1, &o, NULL);
    cr_expect_str_eq(d, "vfma v1, v2, v2, v2\nvfma v3, v4, v4, v4\nspst r5, r1, 0\nspld r6, r1, 4\nvfadd v1, v1, v1\n"
                        "vfadd v3, v3, v3\nhalt\n");
    free(d);
    asm_object_free(&o);
}

Test(sched, labels_keep_their_index_and_lines_follow)
{
    static const char src[] = "top:    vfma    v1, v2, v3, v4\n"
                              "        vfadd   v5, v1, v1\n"
                              "        vfmul   v6, v7, v8\n"
                              "mid:    bne     r1, r2, top\n"
                              "end:    halt\n";
    AsmObject o;
    char *d = assemble_sched(src, 1, &o, NULL);
    free(d);
    for (uint32_t s = 0; s < o.nsyms; s++) {
        uint32_t want = !strcmp(o.syms[s].name, "top") ? 0 : !strcmp(o.syms[s].name, "mid") ? 3 : 4;
        cr_expect_eq(o.syms[s].value, want, "label %s", o.syms[s].name);
    }
    cr_assert_not_null(o.lines);
    cr_expect_eq(o.lines[1].line, 3u, "the moved vfmul keeps its source line");
    cr_expect_eq(o.lines[2].line, 2u);
    asm_object_free(&o);
}

Test(sched, the_disassembler_shows_the_scheduled_order)
{
    AsmObject o;
    char *d = assemble_sched(chain, 1, &o, NULL), *dis = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&dis, &len);
    asm_disassemble(&o, f, 1);
    fclose(f);
    const char *fma = strstr(dis, "vfma"), *mul = strstr(dis, "vfmul"), *add = strstr(dis, "vfadd");
    cr_assert(fma && mul && add, "%s", dis);
    cr_expect(fma < mul && mul < add, "the disassembly is not in the scheduled order:\n%s", dis);
    const char *nl = strchr(mul, '\n'), *at = strstr(mul, "; t.s:3");
    cr_expect(at && nl && at < nl, "the moved instruction keeps its line:\n%s", dis);
    free(d);
    free(dis);
    asm_object_free(&o);
}

Test(sched, the_report_gives_each_block)
{
    AsmObject o;
    char *rep;
    char *d = assemble_sched(chain, 1, &o, &rep);
    cr_expect_str_eq(rep, "block 0-3 (t.s:1): 4 instructions, critical path 6, cycles 8 -> 6\n"
                          "total: 1 blocks, 1 reordered, 2 instructions moved, cycles 8 -> 6 (estimates: each block "
                          "once, every result of a block landed)\n");
    free(rep);
    free(d);
    asm_object_free(&o);
}

Test(sched, directive_errors)
{
    static const char *const bad[] = {"        .sched\n", "        .sched maybe\n", "        .barrier 3\n",
                                      "        .sched on off\n"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        AsmObject o;
        char *diag = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&diag, &len);
        AsmOptions opt = {.diag = f};
        int errs = asm_assemble_string("t.s", bad[k], strlen(bad[k]), &opt, &o);
        fclose(f);
        cr_expect_eq(errs, 1, "'%s' should be one error, got %d: %s", bad[k], errs, diag);
        cr_expect(strstr(diag, "t.s:1:") != NULL, "%s", diag);
        free(diag);
        asm_object_free(&o);
    }
}

/* ==== the machine model ============================================================================== */

Test(sched, the_default_model_is_streamray_ini)
{
    const char *path = "configs/streamray.ini";
    cr_assert(access(path, R_OK) == 0, "%s is missing", path);
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_assert_eq(cfg_load(&c, path, &e), 0, "%s", e.text ? e.text : "");
    cfg_errors_free(&e);
    AsmSchedModel from_cfg, dflt;
    schedmodel_fill(&c, &from_cfg);
    sched_model_default(&dflt);
    for (int u = 0; u < ISA_U_COUNT; u++) {
        cr_expect_eq(dflt.lat[u], from_cfg.lat[u], "latency of %s", isa_unit_names[u]);
        cr_expect_eq(dflt.issue[u], from_cfg.issue[u], "issue interval of %s", isa_unit_names[u]);
    }
    cr_expect_eq(dflt.idm_load, from_cfg.idm_load);
    cr_expect_eq(dflt.lanes, from_cfg.lanes);
}

Test(sched, the_model_follows_the_config)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors e = {0};
    cr_assert_eq(cfg_set(&c, "latency.vfma=7", &e), 0);
    cr_assert_eq(cfg_set(&c, "issue.vmul=3", &e), 0);
    cr_assert_eq(cfg_set(&c, "raybuf.access_cycles=5", &e), 0);
    cr_assert_eq(cfg_set(&c, "scene.cache_kb=0", &e), 0);
    cfg_errors_free(&e);
    AsmSchedModel m;
    schedmodel_fill(&c, &m);
    cr_expect_eq(m.lat[ISA_U_VFMA], 7);
    cr_expect_eq(m.issue[ISA_U_VMUL], 3);
    cr_expect_eq(m.lat[ISA_U_RBUF], 5 + c.interconnect_latency, "a gather: the access and the interconnect");
    cr_expect_eq(m.idm_load, 5);
    cr_expect_eq(m.lat[ISA_U_SCENE], c.scene_latency, "no cache: every load goes to memory");
    cr_expect_eq(sched_unit_from_name("vfma"), ISA_U_VFMA);
    cr_expect_eq(sched_unit_from_name("VFMA"), -1, "class names are lower case");
    cr_expect_eq(sched_unit_from_name("vfm"), -1);
}
