/* tests/unit/test_core.c -- the functional core (sim/core.h) against its specification.
 *
 * Every expected value here is written by hand from the DESC column of isa/opcodes.def, from
 * docs/isa.md and from the comments of sim/core.h; none is obtained by running the core. Only the
 * wording of trap reasons was matched to sim/core.c: the conditions under which a trap must (or
 * must not) happen come from the specification. Programs are built in C as IsaInstr arrays and
 * encoded with isa_encode into a text-only AsmObject, so the assembler is not under test here.
 *
 * Suites: core_new (construction and reset state), core_trap (every trap class and its message),
 * core_part (partition unit), core_sfetch (ID-stream fetch), core_mask (merge masking and
 * compares), core_stats (counters), core_hook (the timing model's record), core_run (limits,
 * determinism).
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

/* ---- building programs ------------------------------------------------------------------------ */

/* One instruction: op, fields a..d, exec mask register, immediate. Unused fields stay zero. */
#define X(OP, a, b, c, d, m, imm) {ISA_OP_##OP, (a), (b), (c), (d), (m), (uint32_t)(imm)}
#define I_0(OP)                      X(OP, 0, 0, 0, 0, 0, 0)
#define I_I(OP, imm)                 X(OP, 0, 0, 0, 0, 0, imm)
#define I_A(OP, a)                   X(OP, a, 0, 0, 0, 0, 0)
#define I_AI(OP, a, imm)             X(OP, a, 0, 0, 0, 0, imm)
#define I_AB(OP, a, b)               X(OP, a, b, 0, 0, 0, 0)
#define I_ABI(OP, a, b, imm)         X(OP, a, b, 0, 0, 0, imm)
#define I_ABC(OP, a, b, c)           X(OP, a, b, c, 0, 0, 0)
#define I_ABCD(OP, a, b, c, d)       X(OP, a, b, c, d, 0, 0)
/* masked formats: the last argument is K of @mK (0 = m0, the default) */
#define V_A(OP, a, m)                X(OP, a, 0, 0, 0, m, 0)
#define V_AI(OP, a, imm, m)          X(OP, a, 0, 0, 0, m, imm)
#define V_AB(OP, a, b, m)            X(OP, a, b, 0, 0, m, 0)
#define V_ABI(OP, a, b, imm, m)      X(OP, a, b, 0, 0, m, imm)
#define V_ABC(OP, a, b, c, m)        X(OP, a, b, c, 0, m, 0)
#define V_ABCD(OP, a, b, c, d, m)    X(OP, a, b, c, d, m, 0)
#define V_ABCI(OP, a, b, c, imm, m)  X(OP, a, b, c, 0, m, imm)

/* A program literal and its length, for the helpers below. */
#define PROG(...) ((const IsaInstr[]){__VA_ARGS__}), (sizeof((const IsaInstr[]){__VA_ARGS__}) / sizeof(IsaInstr))

static const int widths[] = {1, 4, 12, 16, 64};
#define N_WIDTHS (int)(sizeof widths / sizeof widths[0])

/* Memory sizes of the test machine (bytes): small, so that ranges are easy to hit. */
enum { RB_BYTES = 4096, IDM_BYTES = 1024, SPAD_BYTES = 512, SCENE_BYTES = 2048, FB_BYTES = 256 };

static uint32_t fbits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

static uint64_t lanes_mask(int n) { return n >= 64 ? ~0ull : (1ull << n) - 1; }

/* Text-only object from an IsaInstr array; every word must decode back to the same instruction
 * (so a malformed test program fails here, not later). */
static void obj_from_prog(AsmObject *o, const IsaInstr *p, size_t n)
{
    memset(o, 0, sizeof *o);
    o->text = calloc(n ? n : 1, sizeof(uint64_t));
    cr_assert_not_null(o->text);
    for (size_t i = 0; i < n; i++) {
        o->text[i] = isa_encode(&p[i]);
        IsaInstr back;
        char err[256];
        cr_assert_eq(isa_decode(o->text[i], &back, err, sizeof err), 0, "test program word %zu (%s) does not decode: %s",
                     i, isa_ops[p[i].op].mnemonic, err);
    }
    o->ntext = (uint32_t)n;
}

static void test_params(CoreParams *p, int lanes)
{
    memset(p, 0, sizeof *p);
    p->lanes = lanes;
    p->mem_bytes[CORE_MEM_RB0] = RB_BYTES;
    p->mem_bytes[CORE_MEM_RB1] = RB_BYTES;
    p->mem_bytes[CORE_MEM_IDM] = IDM_BYTES;
    p->mem_bytes[CORE_MEM_SPAD] = SPAD_BYTES;
    p->mem_bytes[CORE_MEM_SCENE] = SCENE_BYTES;
    p->mem_bytes[CORE_MEM_FB] = FB_BYTES;
}

typedef struct T {
    AsmObject obj;
    Core *c;
    CoreExit exit;
} T;

static void t_init_p(T *t, const IsaInstr *prog, size_t n, const CoreParams *p)
{
    char err[512];
    obj_from_prog(&t->obj, prog, n);
    t->c = core_new(p, &t->obj, err, sizeof err);
    cr_assert_not_null(t->c, "core_new (N = %d): %s", p->lanes, err);
}

static void t_init(T *t, const IsaInstr *prog, size_t n, int lanes)
{
    CoreParams p;
    test_params(&p, lanes);
    t_init_p(t, prog, n, &p);
}

static void t_free(T *t)
{
    core_free(t->c);
    asm_object_free(&t->obj);
    memset(t, 0, sizeof *t);
}

static CoreExit t_run(T *t, uint64_t limit)
{
    t->exit = core_run(t->c, limit);
    return t->exit;
}

/* Run and require halt; the failure shows the trap message. */
static void t_run_halt(T *t)
{
    CoreExit e = t_run(t, 1000000);
    cr_assert_eq(e, CORE_EXIT_HALT, "N = %d: expected halt, got exit %d: %s", core_lanes(t->c), (int)e,
                 core_trap_message(t->c));
}

static void poke(Core *c, CoreMem m, uint32_t addr, uint32_t v)
{
    uint32_t size;
    uint8_t *p = core_mem(c, m, &size);
    cr_assert(addr + 4 <= size, "poke outside %s", core_mem_names[m]);
    memcpy(p + addr, &v, 4);
}

static uint32_t peek(Core *c, CoreMem m, uint32_t addr)
{
    uint32_t size, v;
    uint8_t *p = core_mem(c, m, &size);
    cr_assert(addr + 4 <= size, "peek outside %s", core_mem_names[m]);
    memcpy(&v, p + addr, 4);
    return v;
}

/* The run must end with exit `want` and exactly the message
 * "trap: <reason> at pc <pc> (<dis>) <where>". */
static void expect_trap(T *t, CoreExit want, const char *reason, uint32_t pc, const char *dis, const char *where)
{
    char exp[1024];
    snprintf(exp, sizeof exp, "trap: %s at pc %u (%s) %s", reason, pc, dis, where);
    cr_assert_eq(t->exit, want, "expected exit %d (%s), got %d", (int)want, exp, (int)t->exit);
    cr_assert_str_eq(core_trap_message(t->c), exp);
    cr_expect_eq(core_pc(t->c), pc, "pc after the trap is %u, expected %u", core_pc(t->c), pc);
}

/* Build, set up to four scalar registers, run, and expect a trap without debug info ("?"). */
typedef struct RegInit {
    int r;
    uint32_t v;
} RegInit;

static void trap_case(const IsaInstr *prog, size_t n, int lanes, const RegInit *regs, int nregs, const char *reason,
                      uint32_t pc, const char *dis)
{
    T t;
    t_init(&t, prog, n, lanes);
    for (int i = 0; i < nregs; i++)
        core_set_sreg(t.c, regs[i].r, regs[i].v);
    t_run(&t, 100000);
    expect_trap(&t, CORE_EXIT_TRAP, reason, pc, dis, "?");
    t_free(&t);
}

/* Same program and registers, but the run must halt (the condition is not a trap). */
static void halt_case(const IsaInstr *prog, size_t n, int lanes, const RegInit *regs, int nregs, const char *what)
{
    T t;
    t_init(&t, prog, n, lanes);
    for (int i = 0; i < nregs; i++)
        core_set_sreg(t.c, regs[i].r, regs[i].v);
    CoreExit e = t_run(&t, 100000);
    cr_assert_eq(e, CORE_EXIT_HALT, "%s: must not trap, got: %s", what, core_trap_message(t.c));
    t_free(&t);
}

#define REGS(...) ((const RegInit[]){__VA_ARGS__}), (int)(sizeof((const RegInit[]){__VA_ARGS__}) / sizeof(RegInit))
#define NOREGS NULL, 0

/* ==== core_new: construction and reset state ======================================================== */

Test(core_new, reset_state)
{
    /* core.h: memories zeroed, then .data at scene address 0 and .spad at scratchpad address 0;
     * m0 = all lanes, other masks empty, registers 0, stage other, pc 0; RBc is RB0. */
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        T t;
        obj_from_prog(&t.obj, PROG(I_0(HALT)));
        uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8}, spad[4] = {0xAA, 0xBB, 0xCC, 0xDD};
        t.obj.data = malloc(sizeof data);
        t.obj.spad = malloc(sizeof spad);
        memcpy(t.obj.data, data, sizeof data);
        memcpy(t.obj.spad, spad, sizeof spad);
        t.obj.ndata = sizeof data;
        t.obj.nspad = sizeof spad;
        CoreParams p;
        test_params(&p, n);
        char err[256];
        t.c = core_new(&p, &t.obj, err, sizeof err);
        cr_assert_not_null(t.c, "%s", err);
        cr_expect_eq(core_lanes(t.c), n);
        cr_expect_eq(core_pc(t.c), 0u);
        cr_expect_eq(core_current_rb(t.c), 0);
        cr_expect_eq(core_instructions(t.c), 0u);
        for (int r = 0; r < ISA_NUM_SREGS; r++)
            cr_expect_eq(core_sreg(t.c, r), 0u, "N=%d r%d", n, r);
        for (int v = 0; v < ISA_NUM_VREGS; v++)
            for (int l = 0; l < n; l++)
                cr_expect_eq(core_vreg(t.c, v, l), 0u, "N=%d v%d[%d]", n, v, l);
        cr_expect_eq(core_mreg(t.c, 0), lanes_mask(n), "N=%d m0 = %#llx", n, (unsigned long long)core_mreg(t.c, 0));
        for (int m = 1; m < ISA_NUM_MREGS; m++)
            cr_expect_eq(core_mreg(t.c, m), 0u, "N=%d m%d", n, m);
        for (int m = 0; m < CORE_MEM_COUNT; m++) {
            uint32_t size;
            uint8_t *mem = core_mem(t.c, (CoreMem)m, &size);
            cr_expect_eq(size, p.mem_bytes[m], "%s size", core_mem_names[m]);
            for (uint32_t i = 0; i < size; i++) {
                uint8_t want = 0;
                if (m == CORE_MEM_SCENE && i < sizeof data)
                    want = data[i];
                if (m == CORE_MEM_SPAD && i < sizeof spad)
                    want = spad[i];
                if (mem[i] != want) {
                    cr_expect_eq(mem[i], want, "N=%d %s byte %u = %u, expected %u", n, core_mem_names[m], i, mem[i], want);
                    break;
                }
            }
        }
        const CoreStats *st = core_stats(t.c);
        CoreStats zero;
        memset(&zero, 0, sizeof zero);
        cr_expect_eq(memcmp(st, &zero, sizeof zero), 0, "counters are not zero at reset");
        t_free(&t);
    }
}

Test(core_new, memory_names)
{
    static const char *const want[CORE_MEM_COUNT] = {"rb0", "rb1", "idm", "spad", "scene", "fb"};
    for (int m = 0; m < CORE_MEM_COUNT; m++)
        cr_expect_str_eq(core_mem_names[m], want[m]);
}

static void expect_new_fails(const CoreParams *p, const AsmObject *o, const char *needle)
{
    char err[512] = "";
    Core *c = core_new(p, o, err, sizeof err);
    cr_expect_null(c, "core_new accepted a bad configuration (expected an error naming '%s')", needle);
    core_free(c);
    cr_expect(err[0] != 0, "no message");
    cr_expect(strstr(err, needle) != NULL, "message '%s' does not mention '%s'", err, needle);
}

Test(core_new, errors)
{
    AsmObject o;
    obj_from_prog(&o, PROG(I_0(HALT)));
    CoreParams p;

    /* lane count: 1..ISA_MAX_LANES */
    test_params(&p, 0);
    expect_new_fails(&p, &o, "0");
    test_params(&p, ISA_MAX_LANES + 1);
    expect_new_fails(&p, &o, "65");
    test_params(&p, -3);
    expect_new_fails(&p, &o, "-3");

    /* the two ray buffers must have the same size */
    test_params(&p, 4);
    p.mem_bytes[CORE_MEM_RB1] = RB_BYTES * 2;
    expect_new_fails(&p, &o, "8192");

    /* memory sizes must be multiples of 4 */
    test_params(&p, 4);
    p.mem_bytes[CORE_MEM_SPAD] = 510;
    expect_new_fails(&p, &o, "510");

    /* .data must fit scene memory, .spad the scratchpad (exactly full is fine) */
    test_params(&p, 4);
    o.ndata = SCENE_BYTES + 4;
    o.data = calloc(o.ndata, 1);
    expect_new_fails(&p, &o, ".data");
    o.ndata = SCENE_BYTES;
    char err[512];
    Core *c = core_new(&p, &o, err, sizeof err);
    cr_expect_not_null(c, ".data exactly filling scene memory was rejected: %s", err);
    core_free(c);
    free(o.data);
    o.data = NULL;
    o.ndata = 0;

    o.nspad = SPAD_BYTES + 4;
    o.spad = calloc(o.nspad, 1);
    expect_new_fails(&p, &o, ".spad");
    free(o.spad);
    o.spad = NULL;
    o.nspad = 0;

    /* an undecodable word (0xFF is not an opcode) */
    o.text[0] = 0xFF;
    expect_new_fails(&p, &o, "instruction 0");
    asm_object_free(&o);

    /* the extreme widths are accepted */
    for (int n = 1; n <= ISA_MAX_LANES; n += ISA_MAX_LANES - 1) {
        AsmObject ok;
        obj_from_prog(&ok, PROG(I_0(HALT)));
        test_params(&p, n);
        c = core_new(&p, &ok, err, sizeof err);
        cr_expect_not_null(c, "N = %d rejected: %s", n, err);
        core_free(c);
        asm_object_free(&ok);
    }
}

Test(core_new, r0_is_an_ordinary_register)
{
    /* docs/isa.md: r0 is not hard-wired to zero. */
    T t;
    t_init(&t, PROG(I_AI(LI, 0, 5), I_ABI(ADDI, 1, 0, 1), I_ABI(ADDI, 0, 0, 10), I_0(HALT)), 4);
    t_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 0), 15u);
    cr_expect_eq(core_sreg(t.c, 1), 6u);
    t_free(&t);
}

/* ==== core_trap: every trap class, exact messages ===================================================== */

Test(core_trap, scratchpad)
{
    /* SP[rb + imm]: a word at size - 4 is the last legal one; size is out of range. */
    halt_case(PROG(I_ABI(SPLD, 1, 2, 4), I_0(HALT)), 4, REGS({2, SPAD_BYTES - 8}), "spld of the last word");
    trap_case(PROG(I_ABI(SPLD, 1, 2, 4), I_0(HALT)), 4, REGS({2, SPAD_BYTES - 4}),
              "scratchpad load out of range: address 0x00000200 (size 512)", 0, "spld r1, r2, 4");
    trap_case(PROG(I_0(NOP), I_ABI(SPST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 6}),
              "scratchpad store misaligned: address 0x00000006", 1, "spst r1, r2, 0");
    /* vspld: lane l reads SP[rb + imm + 4l]; at N = 4 from size - 12, lane 3 is past the end */
    trap_case(PROG(V_ABI(VSPLD, 1, 2, 0, 0), I_0(HALT)), 4, REGS({2, SPAD_BYTES - 12}),
              "scratchpad load out of range: address 0x00000200 (size 512)", 0, "vspld v1, r2, 0");
    /* ... but not when lane 3 is outside the exec mask (m2 = lanes 0..2) */
    halt_case(PROG(I_AB(MTAIL, 2, 3), V_ABI(VSPLD, 1, 2, 0, 2), I_0(HALT)), 4, REGS({2, SPAD_BYTES - 12}, {3, 3}),
              "vspld with the bad lane masked off");
    trap_case(PROG(V_ABI(VSPST, 1, 2, 2, 0), I_0(HALT)), 4, NOREGS, "scratchpad store misaligned: address 0x00000002", 0,
              "vspst v1, r2, 2");
}

Test(core_trap, scene_memory)
{
    trap_case(PROG(I_ABI(LD, 1, 2, 0), I_0(HALT)), 4, REGS({2, SCENE_BYTES}),
              "scene memory load out of range: address 0x00000800 (size 2048)", 0, "ld r1, r2, 0");
    /* negative immediates are offsets: rb + imm wraps in 32 bits, 2052 - 8 = 2044 is legal */
    halt_case(PROG(I_ABI(LD, 1, 2, -8), I_0(HALT)), 4, REGS({2, SCENE_BYTES + 4}), "ld with a negative offset");
    trap_case(PROG(I_ABI(ST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 1}), "scene memory store misaligned: address 0x00000001", 0,
              "st r1, r2, 0");
    trap_case(PROG(V_ABI(LDB, 1, 2, 0, 0), I_0(HALT)), 4, REGS({2, 2 * SCENE_BYTES}),
              "scene memory broadcast load out of range: address 0x00001000 (size 2048)", 0, "ldb v1, r2, 0");
    trap_case(PROG(V_ABI(LDB, 1, 2, 2, 0), I_0(HALT)), 4, NOREGS, "scene memory broadcast load misaligned: address 0x00000002",
              0, "ldb v1, r2, 2");
    /* ldg: lane addresses 0, 1024, 2048, 3072: lane 2 is the first bad one */
    trap_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 1024, 0), V_ABI(LDG, 1, 2, 0, 0), I_0(HALT)), 4, NOREGS,
              "scene memory gather out of range: address 0x00000800 (size 2048)", 2, "ldg v1, v2, 0");
    trap_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 2, 0), V_ABI(LDG, 1, 2, 0, 0), I_0(HALT)), 4, NOREGS,
              "scene memory gather misaligned: address 0x00000002", 2, "ldg v1, v2, 0");
    /* lanes 2 and 3 masked off (m1 = lanes 0, 1): no access, no trap */
    halt_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 1024, 0), I_AB(MTAIL, 1, 4), V_ABI(LDG, 1, 2, 0, 1), I_0(HALT)), 4,
              REGS({4, 2}), "ldg with the bad lanes masked off");
}

Test(core_trap, ray_buffers)
{
    /* RBc[rc + imm + 4 * vb[l]]: ids 0, 512, 1024 at N = 3 give 0, 2048, 4096 */
    trap_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 512, 0), V_ABCI(RGAT, 1, 2, 4, 0, 0), I_0(HALT)), 3, NOREGS,
              "ray buffer 0 gather out of range: address 0x00001000 (size 4096)", 2, "rgat v1, v2, r4, 0");
    /* the offset and the base register add in: 4 + 8 + 4 * 1021 = 4096 */
    trap_case(PROG(V_AI(VLI, 2, 1021, 0), V_ABCI(RGAT, 1, 2, 4, 8, 0), I_0(HALT)), 4, REGS({4, 4}),
              "ray buffer 0 gather out of range: address 0x00001000 (size 4096)", 1, "rgat v1, v2, r4, 8");
    halt_case(PROG(V_AI(VLI, 2, 1020, 0), V_ABCI(RGAT, 1, 2, 4, 8, 0), I_0(HALT)), 4, REGS({4, 4}),
              "rgat of the last word");
    /* A huge ray ID must not wrap around 32 bits onto a valid address (2^30 + 1 -> 4 after
     * wrapping): regression for a bug these tests found. */
    trap_case(PROG(V_AI(VLI, 2, 0x40000001, 0), V_ABCI(RGAT, 1, 2, 4, 0, 0), I_0(HALT)), 4, NOREGS,
              "ray buffer 0 gather out of range: ray ID 1073741825 at base 0x00000000 (size 4096)", 1,
              "rgat v1, v2, r4, 0");
    trap_case(PROG(V_ABCI(RSCT, 1, 2, 4, 0, 0), I_0(HALT)), 4, REGS({4, 2}),
              "ray buffer 0 scatter misaligned: address 0x00000002", 0, "rsct v1, v2, r4, 0");
    trap_case(PROG(V_AI(VLI, 2, 1024, 0), V_ABCI(RGATN, 1, 2, 4, 0, 0), I_0(HALT)), 4, NOREGS,
              "ray buffer 1 gather out of range: address 0x00001000 (size 4096)", 1, "rgatn v1, v2, r4, 0");
    /* after rswap the current buffer is RB1 and the next RB0 */
    trap_case(PROG(I_0(RSWAP), V_AI(VLI, 2, 1024, 0), V_ABCI(RSCT, 1, 2, 4, 0, 0), I_0(HALT)), 4, NOREGS,
              "ray buffer 1 scatter out of range: address 0x00001000 (size 4096)", 2, "rsct v1, v2, r4, 0");
    trap_case(PROG(I_0(RSWAP), V_AI(VLI, 2, 1024, 0), V_ABCI(RSCTN, 1, 2, 4, 0, 0), I_0(HALT)), 4, NOREGS,
              "ray buffer 0 scatter out of range: address 0x00001000 (size 4096)", 2, "rsctn v1, v2, r4, 0");
    /* a bad id in a lane outside the exec mask is not an access */
    halt_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 1024, 0), I_AB(MTAIL, 1, 5), V_ABCI(RGAT, 1, 2, 4, 0, 1),
                   V_ABCI(RSCT, 1, 2, 4, 0, 1), I_0(HALT)),
              16, REGS({5, 1}), "rgat/rsct with bad ids masked off");
}

Test(core_trap, id_stream_memory)
{
    trap_case(PROG(I_ABI(SLD, 1, 2, 0), I_0(HALT)), 4, REGS({2, IDM_BYTES}),
              "ID-stream memory load out of range: address 0x00000400 (size 1024)", 0, "sld r1, r2, 0");
    trap_case(PROG(I_ABI(SST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 3}), "ID-stream memory store misaligned: address 0x00000003",
              0, "sst r1, r2, 0");
    /* sapp at N = 4 from size - 8: the third lane would go to size */
    trap_case(PROG(V_AB(SAPP, 2, 1, 0), I_0(HALT)), 4, REGS({2, IDM_BYTES - 8}),
              "ID-stream memory append out of range: address 0x00000400 (size 1024)", 0, "sapp r2, v1");
    /* two active lanes fit exactly */
    halt_case(PROG(I_AB(MTAIL, 3, 4), V_AB(SAPP, 2, 1, 3), I_0(HALT)), 4, REGS({2, IDM_BYTES - 8}, {4, 2}),
              "sapp of two lanes into the last two words");
    trap_case(PROG(V_AB(SAPP, 2, 1, 0), I_0(HALT)), 4, REGS({2, 2}), "ID-stream memory append misaligned: address 0x00000002",
              0, "sapp r2, v1");
    /* an empty exec mask appends nothing, so a bad pointer is no access */
    halt_case(PROG(V_AB(SAPP, 2, 1, 7), I_0(HALT)), 4, REGS({2, 2}), "sapp with an empty exec mask");
}

Test(core_trap, framebuffer)
{
    trap_case(PROG(V_ABI(FBADD, 1, 2, FB_BYTES, 0), I_0(HALT)), 4, NOREGS,
              "framebuffer scatter-add out of range: address 0x00000100 (size 256)", 0, "fbadd v1, v2, 256");
    trap_case(PROG(V_ABI(FBADD, 1, 2, 2, 0), I_0(HALT)), 4, NOREGS, "framebuffer scatter-add misaligned: address 0x00000002",
              0, "fbadd v1, v2, 2");
    halt_case(PROG(V_ABI(FBADD, 1, 2, FB_BYTES - 4, 0), I_0(HALT)), 4, NOREGS, "fbadd of the last word");
}

Test(core_trap, sfetch_bad_stream)
{
    /* rc > rd traps */
    trap_case(PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4, REGS({3, 16}, {4, 8}),
              "bad stream: begin 0x00000010 > end 0x00000008", 0, "sfetch v1, m1, r3, r4");
    /* rc == rd is an empty stream, not an error */
    halt_case(PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4, REGS({3, 16}, {4, 16}), "sfetch of an empty stream");
    /* a stream whose fetched words run past the end of IDM traps (any reason) at the sfetch */
    T t;
    t_init(&t, PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4);
    core_set_sreg(t.c, 3, IDM_BYTES - 8);
    core_set_sreg(t.c, 4, IDM_BYTES + 8);
    cr_assert_eq(t_run(&t, 100), CORE_EXIT_TRAP);
    cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0);
    cr_expect(strstr(core_trap_message(t.c), " at pc 0 (sfetch v1, m1, r3, r4) ?") != NULL, "%s", core_trap_message(t.c));
    t_free(&t);
}

Test(core_trap, part_queue_length)
{
    /* A stream of L IDs needs q queued bits with L <= q < L + N. At N = 4 pmask adds 4 bits. */
    const IsaInstr two[] = {I_A(PMASK, 0), I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)};
    const IsaInstr four[] = {I_A(PMASK, 0), I_A(PMASK, 0), I_A(PMASK, 0), I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)};
    const IsaInstr three[] = {I_A(PMASK, 0), I_A(PMASK, 0), I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)};
    /* L = 10, q = 8: too few */
    trap_case(two, 4, 4, REGS({2, 0}, {3, 40}), "partition: 8 mask bits queued for a stream of 10 IDs", 2, "part r1, r2, r3");
    /* L = 10, q = 16 >= L + N = 14: too many */
    trap_case(four, 6, 4, REGS({2, 0}, {3, 40}), "partition: 16 mask bits queued for a stream of 10 IDs", 4,
              "part r1, r2, r3");
    /* boundaries: L = 12, q = 12 (q = L); L = 9, q = 12 (q = L + N - 1) are fine; L = 8, q = 12 (q = L + N) traps */
    halt_case(three, 5, 4, REGS({2, 0}, {3, 48}), "q = L");
    halt_case(three, 5, 4, REGS({2, 0}, {3, 36}), "q = L + N - 1");
    trap_case(three, 5, 4, REGS({2, 0}, {3, 32}), "partition: 12 mask bits queued for a stream of 8 IDs", 3, "part r1, r2, r3");
    /* at N = 1 the queue must match the stream exactly */
    const IsaInstr one[] = {I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)};
    halt_case(one, 3, 1, REGS({2, 0}, {3, 4}), "N = 1, q = L = 1");
    trap_case(one, 3, 1, REGS({2, 0}, {3, 8}), "partition: 1 mask bits queued for a stream of 2 IDs", 1, "part r1, r2, r3");
    trap_case(one, 3, 1, REGS({2, 0}, {3, 0}), "partition: 1 mask bits queued for a stream of 0 IDs", 1, "part r1, r2, r3");
    /* an empty stream with an empty queue is fine */
    halt_case(PROG(I_ABC(PART, 1, 2, 3), I_0(HALT)), 4, REGS({2, 16}, {3, 16}), "empty stream, empty queue");
    /* pclr discards the queue: without it the second part would see N bits for 0 IDs */
    halt_case(PROG(I_A(PMASK, 0), I_0(PCLR), I_ABC(PART, 1, 2, 2), I_0(HALT)), 4, NOREGS, "pclr empties the queue");
    trap_case(PROG(I_A(PMASK, 0), I_ABC(PART, 1, 2, 2), I_0(HALT)), 4, NOREGS,
              "partition: 4 mask bits queued for a stream of 0 IDs", 1, "part r1, r2, r2");
}

Test(core_trap, part_bad_stream)
{
    /* begin > end, and a stream beyond IDM: both must trap at the part (wording is free) */
    struct { uint32_t b, e; } cases[] = {{40, 0}, {IDM_BYTES - 8, IDM_BYTES + 8}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        T t;
        t_init(&t, PROG(I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)), 4);
        core_set_sreg(t.c, 2, cases[i].b);
        core_set_sreg(t.c, 3, cases[i].e);
        cr_assert_eq(t_run(&t, 100), CORE_EXIT_TRAP, "part [%#x, %#x) did not trap", cases[i].b, cases[i].e);
        cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0);
        cr_expect(strstr(core_trap_message(t.c), " at pc 1 (part r1, r2, r3) ?") != NULL, "%s", core_trap_message(t.c));
        t_free(&t);
    }
}

Test(core_trap, division_by_zero)
{
    trap_case(PROG(I_AI(LI, 2, 7), I_ABC(DIVU, 1, 2, 3), I_0(HALT)), 4, NOREGS, "integer division by zero", 1,
              "divu r1, r2, r3");
    trap_case(PROG(I_AI(LI, 2, 7), I_ABC(REMU, 1, 2, 3), I_0(HALT)), 4, NOREGS, "integer division by zero", 1,
              "remu r1, r2, r3");
    /* unsigned: 0xFFFFFFFF / 2 and % 2 */
    T t;
    t_init(&t, PROG(I_AI(LI, 2, -1), I_AI(LI, 3, 2), I_ABC(DIVU, 1, 2, 3), I_ABC(REMU, 4, 2, 3), I_0(HALT)), 4);
    t_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 1), 0x7FFFFFFFu);
    cr_expect_eq(core_sreg(t.c, 4), 1u);
    t_free(&t);
}

Test(core_trap, vext_lane)
{
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        char reason[64];
        char dis[64];
        snprintf(reason, sizeof reason, "vext lane %d out of range (N = %d)", n, n);
        snprintf(dis, sizeof dis, "vext r1, v2, %d", n);
        const IsaInstr p[] = {V_A(VIOTA, 2, 0), I_ABI(VEXT, 1, 2, (uint32_t)n), I_0(HALT)};
        trap_case(p, 3, n, NOREGS, reason, 1, dis);
        /* lane N - 1 is the last legal one */
        const IsaInstr q[] = {V_A(VIOTA, 2, 0), I_ABI(VEXT, 1, 2, (uint32_t)(n - 1)), I_0(HALT)};
        T t;
        t_init(&t, q, 3, n);
        t_run_halt(&t);
        cr_expect_eq(core_sreg(t.c, 1), (uint32_t)(n - 1));
        t_free(&t);
    }
}

Test(core_trap, bad_stage)
{
    trap_case(PROG(I_I(STAGE, 3), I_I(STAGE, 4), I_0(HALT)), 4, NOREGS, "bad stage 4 (0..3)", 1, "stage 4");
}

Test(core_trap, control_outside_program)
{
    /* a 3-instruction program: valid pcs are 0..2 */
    trap_case(PROG(I_I(JMP, 100), I_0(NOP), I_0(HALT)), 4, NOREGS, "branch target 100 outside the program (3 instructions)",
              0, "jmp 100");
    trap_case(PROG(I_0(NOP), I_ABI(BEQ, 1, 2, 7), I_0(HALT)), 4, NOREGS,
              "branch target 7 outside the program (3 instructions)", 1, "beq r1, r2, 7");
    trap_case(PROG(I_AI(BMZ, 3, 9), I_0(NOP), I_0(HALT)), 4, NOREGS, "branch target 9 outside the program (3 instructions)",
              0, "bmz m3, 9");
    trap_case(PROG(I_AI(JAL, 5, 1000), I_0(NOP), I_0(HALT)), 4, NOREGS,
              "branch target 1000 outside the program (3 instructions)", 0, "jal r5, 1000");
    trap_case(PROG(I_AI(LI, 1, 77), I_A(JR, 1), I_0(HALT)), 4, NOREGS, "jump target 77 outside the program (3 instructions)",
              1, "jr r1");
    /* a branch that is not taken goes nowhere: its target does not matter */
    halt_case(PROG(I_AI(LI, 1, 1), I_ABI(BEQ, 1, 2, 500), I_AI(BMNZ, 3, 500), I_0(HALT)), 4, NOREGS,
              "untaken branches with bad targets");
    /* a jump to exactly the end of the program leaves it: it must trap, at the jump or at pc 2 */
    T t;
    t_init(&t, PROG(I_I(JMP, 2), I_0(HALT)), 4);
    cr_assert_eq(t_run(&t, 100), CORE_EXIT_TRAP);
    cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0, "%s", core_trap_message(t.c));
    t_free(&t);
}

/* trap_case expects "?" as the location; the fall-off case names no instruction, so check it here. */
Test(core_trap, falling_off_the_end_message)
{
    T t;
    t_init(&t, PROG(I_AI(LI, 1, 1), I_0(NOP)), 4);
    t_run(&t, 100);
    expect_trap(&t, CORE_EXIT_TRAP, "pc past the end of the program (2 instructions)", 2, "no instruction",
                "after the last instruction");
    cr_expect_eq(core_sreg(t.c, 1), 1u, "the instructions before the end ran");
    t_free(&t);
}

Test(core_trap, instruction_limit)
{
    T t;
    t_init(&t, PROG(I_I(JMP, 0)), 4);
    t_run(&t, 1000);
    expect_trap(&t, CORE_EXIT_LIMIT, "instruction limit of 1000 reached", 0, "jmp 0", "?");
    cr_expect_eq(core_instructions(t.c), 1000u);
    cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_JMP], 1000u);
    t_free(&t);
}

Test(core_trap, message_names_source_line)
{
    /* with a line table, <where> is file:line of the trapping instruction */
    T t;
    obj_from_prog(&t.obj, PROG(I_AI(LI, 2, 7), I_ABC(DIVU, 1, 2, 3), I_0(HALT)));
    t.obj.nfiles = 2;
    t.obj.files = calloc(2, sizeof(char *));
    t.obj.files[0] = strdup("kernels/main.s");
    t.obj.files[1] = strdup("kernels/lib/math.inc");
    t.obj.lines = calloc(3, sizeof(AsmLine));
    t.obj.lines[0] = (AsmLine){0, 10, 9};
    t.obj.lines[1] = (AsmLine){1, 42, 9};
    t.obj.lines[2] = (AsmLine){0, 12, 9};
    CoreParams p;
    test_params(&p, 4);
    char err[256];
    t.c = core_new(&p, &t.obj, err, sizeof err);
    cr_assert_not_null(t.c, "%s", err);
    t_run(&t, 100);
    expect_trap(&t, CORE_EXIT_TRAP, "integer division by zero", 1, "divu r1, r2, r3", "kernels/lib/math.inc:42");
    t_free(&t);
}

/* ==== core_sfetch ==================================================================================== */

/* One sfetch v4, m1, r9, r7 from IDM holding 0x1000 + i at byte 4i. Before it, v4 is 0xDEAD in
 * every lane and m1 all lanes, to see what the fetch leaves. */
static void sfetch_case(int n, uint32_t begin, uint32_t count)
{
    T t;
    t_init(&t, PROG(V_AI(VLI, 4, 0xDEAD, 0), I_A(MALL, 1), I_ABCD(SFETCH, 4, 1, 9, 7), I_0(HALT)), n);
    for (uint32_t a = 0; a < IDM_BYTES; a += 4)
        poke(t.c, CORE_MEM_IDM, a, 0x1000 + a / 4);
    uint32_t end = begin + 4 * count;
    core_set_sreg(t.c, 9, begin);
    core_set_sreg(t.c, 7, end);
    t_run_halt(&t);
    /* n := min(N, (rd - rc) / 4) */
    uint32_t k = count < (uint32_t)n ? count : (uint32_t)n;
    for (int l = 0; l < n; l++) {
        uint32_t want;
        if (k == 0)
            want = 0xDEAD; /* empty stream: the vector is left as it was */
        else if ((uint32_t)l < k)
            want = 0x1000 + begin / 4 + (uint32_t)l;
        else
            want = 0x1000 + begin / 4 + k - 1; /* lanes >= n repeat the last ID */
        cr_expect_eq(core_vreg(t.c, 4, l), want, "N=%d begin=%u count=%u: v4[%d] = %#x, expected %#x", n, begin, count, l,
                     core_vreg(t.c, 4, l), want);
    }
    cr_expect_eq(core_mreg(t.c, 1), lanes_mask((int)k), "N=%d count=%u: m1 = %#llx, expected lanes < %u", n, count,
                 (unsigned long long)core_mreg(t.c, 1), k);
    /* rc += 4N, capped at rd */
    uint32_t want_rc = begin + 4u * (uint32_t)n < end ? begin + 4u * (uint32_t)n : end;
    cr_expect_eq(core_sreg(t.c, 9), want_rc, "N=%d count=%u: rc = %u, expected %u", n, count, core_sreg(t.c, 9), want_rc);
    cr_expect_eq(core_sreg(t.c, 7), end, "rd must not change");
    t_free(&t);
}

Test(core_sfetch, tails_duplication_and_advance)
{
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        uint32_t counts[] = {0, 1, (uint32_t)n - 1, (uint32_t)n, (uint32_t)n + 1, 37, 100};
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
            sfetch_case(n, 8, counts[i]);
            sfetch_case(n, 400, counts[i]);
        }
    }
}

Test(core_sfetch, walks_a_stream)
{
    /* A loop of sfetch until rc reaches rd runs ceil(L / N) times and sees every ID once, in order:
     * the IDs of the valid lanes are appended (sapp @m1) to a copy at 512. */
    const uint32_t L = 37;
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        T t;
        t_init(&t,
               PROG(I_ABCD(SFETCH, 4, 1, 9, 7), /* 0 */
                    V_AB(SAPP, 10, 4, 1),       /* 1 */
                    I_ABI(BLT, 9, 7, 0),        /* 2 */
                    I_0(HALT)),
               n);
        for (uint32_t i = 0; i < L; i++)
            poke(t.c, CORE_MEM_IDM, 4 * i, 0x500 + 3 * i);
        core_set_sreg(t.c, 9, 0);
        core_set_sreg(t.c, 7, 4 * L);
        core_set_sreg(t.c, 10, 512);
        t_run_halt(&t);
        uint32_t fetches = (L + (uint32_t)n - 1) / (uint32_t)n;
        cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_SFETCH], fetches, "N=%d", n);
        cr_expect_eq(core_sreg(t.c, 10), 512 + 4 * L, "N=%d: appended %u words", n, (core_sreg(t.c, 10) - 512) / 4);
        for (uint32_t i = 0; i < L; i++)
            cr_expect_eq(peek(t.c, CORE_MEM_IDM, 512 + 4 * i), 0x500 + 3 * i, "N=%d copy[%u]", n, i);
        t_free(&t);
    }
}

/* ==== core_part ====================================================================================== */

/* A filter as in Fig. 5 of Gribble & Ramani 2008: for each block, sfetch the IDs, gather a flag by
 * ID from RB0, compare it with 1, pmask; then part. Then a second part on the empty stream
 * [end, end) that only succeeds if the first one cleared the queue. */
static const IsaInstr filter_prog[] = {
    V_AI(VLI, 9, 1, 0),              /* 0: v9 = 1 */
    I_ABCD(SFETCH, 4, 1, 9, 7),      /* 1: loop */
    V_ABCI(RGAT, 5, 4, 20, 0, 1),    /* 2: flag of each ID */
    V_ABC(VIEQ, 2, 5, 9, 1),         /* 3: m2 = m1 & (flag == 1) */
    I_A(PMASK, 2),                   /* 4 */
    I_ABI(BLT, 9, 7, 1),             /* 5 */
    I_ABC(PART, 16, 6, 7),           /* 6: r16 = split point */
    I_ABC(PART, 17, 7, 7),           /* 7: queue must be empty again */
    I_0(HALT),                       /* 8 */
};

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 16;
}

/* pattern: 0 random flags, 1 all set, 2 none set, 3 alternating */
static void partition_case(int n, uint32_t L, int pattern)
{
    const uint32_t base = 64;
    T t;
    t_init(&t, filter_prog, sizeof filter_prog / sizeof filter_prog[0], n);
    uint32_t ids[256], flag[1024];
    uint32_t seed = (uint32_t)(n * 1000 + (int)L * 10 + pattern);
    for (uint32_t id = 0; id < 1000; id++) {
        uint32_t f = pattern == 0 ? lcg(&seed) & 1u : pattern == 1 ? 1u : pattern == 2 ? 0u : id & 1u;
        flag[id] = f;
        poke(t.c, CORE_MEM_RB0, 4 * id, f ? 1u : 7u);
    }
    /* IDM: sentinels everywhere, the stream's IDs (distinct, in no particular order) in [base, end) */
    for (uint32_t a = 0; a < IDM_BYTES; a += 4)
        poke(t.c, CORE_MEM_IDM, a, 0xABCD0000u + a);
    for (uint32_t i = 0; i < L; i++) {
        ids[i] = (i * 389u + 11u) % 1000u;
        poke(t.c, CORE_MEM_IDM, base + 4 * i, ids[i]);
    }
    uint32_t end = base + 4 * L;
    core_set_sreg(t.c, 6, base);
    core_set_sreg(t.c, 7, end);
    core_set_sreg(t.c, 9, base);
    core_set_sreg(t.c, 20, 0);
    CoreExit e = t_run(&t, 1000000);
    cr_assert_eq(e, CORE_EXIT_HALT, "N=%d L=%u pattern %d: %s", n, L, pattern, core_trap_message(t.c));
    /* expected: stable, set first */
    uint32_t want[256], k = 0;
    for (uint32_t i = 0; i < L; i++)
        if (flag[ids[i]])
            want[k++] = ids[i];
    uint32_t nset = k;
    for (uint32_t i = 0; i < L; i++)
        if (!flag[ids[i]])
            want[k++] = ids[i];
    for (uint32_t i = 0; i < L; i++) {
        uint32_t got = peek(t.c, CORE_MEM_IDM, base + 4 * i);
        if (got != want[i]) {
            cr_expect_eq(got, want[i], "N=%d L=%u pattern %d: IDM[%u] = %u, expected %u (stable, set first)", n, L, pattern,
                         i, got, want[i]);
            break;
        }
    }
    /* nothing outside [base, end) changed */
    for (uint32_t a = 0; a < IDM_BYTES; a += 4)
        if (a < base || a >= end)
            cr_expect_eq(peek(t.c, CORE_MEM_IDM, a), 0xABCD0000u + a, "N=%d L=%u: IDM[%#x] outside the stream changed", n, L,
                         a);
    cr_expect_eq(core_sreg(t.c, 16), base + 4 * nset, "N=%d L=%u pattern %d: ra = %u, expected rb + 4 * %u = %u", n, L,
                 pattern, core_sreg(t.c, 16), nset, base + 4 * nset);
    cr_expect_eq(core_sreg(t.c, 17), end, "empty partition returns its begin");
    cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_PMASK], (L + (uint32_t)n - 1) / (uint32_t)n);
    t_free(&t);
}

Test(core_part, stable_set_first_return_value_queue_cleared)
{
    for (int w = 0; w < N_WIDTHS; w++)
        for (int pattern = 0; pattern < 4; pattern++) {
            partition_case(widths[w], 37, pattern);
            partition_case(widths[w], 131, pattern);
            partition_case(widths[w], 1, pattern);
        }
}

Test(core_part, bits_past_the_stream_are_ignored)
{
    /* N = 4, L = 5, two pmask of an all-set mask: 8 bits queued, bits 5..7 set but without IDs.
     * Every ID is kept, in order: ra = rb + 4 * L. */
    T t;
    t_init(&t, PROG(I_A(PMASK, 0), I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)), 4);
    for (uint32_t i = 0; i < 5; i++)
        poke(t.c, CORE_MEM_IDM, 16 + 4 * i, 50 - i);
    core_set_sreg(t.c, 2, 16);
    core_set_sreg(t.c, 3, 36);
    t_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 1), 36u);
    for (uint32_t i = 0; i < 5; i++)
        cr_expect_eq(peek(t.c, CORE_MEM_IDM, 16 + 4 * i), 50 - i);
    t_free(&t);
}

Test(core_part, queue_order_is_lane_zero_first)
{
    /* N = 4: m1 = lanes {0, 2} (0101 from lane 0), m2 = lane {3}; queue = 1,0,1,0, 0,0,0,1.
     * Stream of 8 IDs 10..17: set first -> 10 12 17, then 11 13 14 15 16. */
    T t;
    t_init(&t,
           PROG(V_A(VIOTA, 1, 0), V_ABI(VANDI, 2, 1, 1, 0), V_AI(VLI, 3, 0, 0), V_ABC(VIEQ, 1, 2, 3, 0), /* m1 even */
                I_AI(LI, 4, 3), I_AB(MTAIL, 2, 4), I_AB(MNOT, 2, 2),                                    /* m2 = {3} */
                I_A(PMASK, 1), I_A(PMASK, 2), I_ABC(PART, 5, 6, 7), I_0(HALT)),
           4);
    for (uint32_t i = 0; i < 8; i++)
        poke(t.c, CORE_MEM_IDM, 4 * i, 10 + i);
    core_set_sreg(t.c, 6, 0);
    core_set_sreg(t.c, 7, 32);
    t_run_halt(&t);
    const uint32_t want[8] = {10, 12, 17, 11, 13, 14, 15, 16};
    for (uint32_t i = 0; i < 8; i++)
        cr_expect_eq(peek(t.c, CORE_MEM_IDM, 4 * i), want[i], "IDM[%u] = %u, expected %u", i,
                     peek(t.c, CORE_MEM_IDM, 4 * i), want[i]);
    cr_expect_eq(core_sreg(t.c, 5), 12u);
    t_free(&t);
}

/* ==== core_mask: merge masking and compares =========================================================== */

Test(core_mask, merge_masking)
{
    /* m2 = even lanes, m3 = lanes 0..2. Each destination starts as 0x77 in every lane; a masked
     * instruction changes only the lanes of its exec mask. */
    static const IsaInstr prog[] = {
        V_A(VIOTA, 0, 0),                   /* v0 = l */
        V_ABI(VANDI, 1, 0, 1, 0),
        V_AI(VLI, 2, 0, 0),
        V_ABC(VIEQ, 2, 1, 2, 0),            /* m2 = even lanes */
        I_AI(LI, 1, 3),
        I_AB(MTAIL, 3, 1),                  /* m3 = lanes < 3 */
        V_AI(VLI, 20, 0x3FC00000, 0),       /* 1.5f */
        V_AI(VLI, 21, 0x40100000, 0),       /* 2.25f */
        V_ABI(VSHLI, 14, 0, 2, 0),          /* v14 = 4l */
        V_AI(VLI, 3, 0x77, 0), V_AI(VLI, 4, 0x77, 0), V_AI(VLI, 5, 0x77, 0), V_AI(VLI, 6, 0x77, 0),
        V_AI(VLI, 7, 0x77, 0), V_AI(VLI, 8, 0x77, 0), V_AI(VLI, 9, 0x77, 0), V_AI(VLI, 10, 0x77, 0),
        V_AI(VLI, 11, 0x77, 0), V_AI(VLI, 12, 0x77, 0), V_AI(VLI, 13, 0x77, 0), V_AI(VLI, 15, 0x77, 0),
        V_AI(VLI, 16, 0x77, 0), V_AI(VLI, 17, 0x77, 0),
        V_ABC(VADD, 3, 0, 0, 2),            /* even: 2l */
        V_ABC(VFADD, 4, 20, 21, 2),         /* even: 3.75f */
        V_ABCD(VSEL, 5, 14, 1, 2, 3),       /* lanes < 3: m2 ? 4l : (l & 1) */
        V_AB(VBCAST, 6, 1, 2),              /* even: r1 = 3 */
        V_A(VIOTA, 7, 2),                   /* even: l */
        V_AB(RALLOC, 8, 4, 2),              /* even: r4 + rank among even lanes */
        V_ABI(LDB, 9, 5, 0, 2),             /* even: SM[r5] */
        V_ABCI(RGAT, 10, 0, 0, 0, 2),       /* even: RB0[4l] (r0 = 0) */
        V_AB(VFNEG, 11, 20, 2),             /* even: -1.5f */
        V_AB(VCVTFI, 12, 20, 2),            /* even: 1 */
        V_ABI(LDG, 13, 14, 0, 2),           /* even: SM[4l] */
        V_ABI(VSPLD, 15, 0, 0, 2),          /* even: SP[4l] */
        V_ABCD(VFMA, 16, 20, 20, 21, 2),    /* even: 1.5 * 1.5 + 2.25 = 4.5 */
        V_AB(VMOV, 17, 14, 3),              /* lanes < 3: 4l */
        V_ABCI(RSCT, 0, 0, 6, 0, 2),        /* even: RB0[r6 + 4l] := l */
        V_AB(SAPP, 7, 0, 2),                /* even lanes' l, in order, at IDM[r7] */
        V_ABI(FBADD, 20, 14, 0, 2),         /* even: FB[4l] += 1.5 */
        I_0(HALT),
    };
    const int ws[] = {1, 4, 12, 64};
    for (size_t w = 0; w < sizeof ws / sizeof ws[0]; w++) {
        int n = ws[w];
        T t;
        t_init(&t, prog, sizeof prog / sizeof prog[0], n);
        core_set_sreg(t.c, 4, 100);
        core_set_sreg(t.c, 5, 1024);
        core_set_sreg(t.c, 6, 2048);
        core_set_sreg(t.c, 7, 256);
        poke(t.c, CORE_MEM_SCENE, 1024, 0xCAFE);
        for (int l = 0; l < n; l++) {
            poke(t.c, CORE_MEM_SCENE, 4 * (uint32_t)l, 0x9000u + (uint32_t)l);
            poke(t.c, CORE_MEM_RB0, 4 * (uint32_t)l, 0x500u + (uint32_t)l);
            poke(t.c, CORE_MEM_SPAD, 4 * (uint32_t)l, 0x3000u + (uint32_t)l);
        }
        t_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 2), 0x5555555555555555ull & lanes_mask(n), "N=%d m2", n);
        uint32_t even_count = 0;
        for (int l = 0; l < n; l++) {
            uint32_t ul = (uint32_t)l;
            int even = (l & 1) == 0, low = l < 3;
            struct { int v; uint32_t want; } exp[] = {
                {3, even ? 2 * ul : 0x77},
                {4, even ? fbits(3.75f) : 0x77},
                {5, low ? (even ? 4 * ul : (ul & 1)) : 0x77},
                {6, even ? 3u : 0x77},
                {7, even ? ul : 0x77},
                {8, even ? 100 + ul / 2 : 0x77},
                {9, even ? 0xCAFEu : 0x77},
                {10, even ? 0x500 + ul : 0x77},
                {11, even ? fbits(-1.5f) : 0x77},
                {12, even ? 1u : 0x77},
                {13, even ? 0x9000 + ul : 0x77},
                {15, even ? 0x3000 + ul : 0x77},
                {16, even ? fbits(4.5f) : 0x77},
                {17, low ? 4 * ul : 0x77},
            };
            for (size_t i = 0; i < sizeof exp / sizeof exp[0]; i++)
                cr_expect_eq(core_vreg(t.c, exp[i].v, l), exp[i].want, "N=%d v%d[%d] = %#x, expected %#x", n, exp[i].v, l,
                             core_vreg(t.c, exp[i].v, l), exp[i].want);
            /* scatters write nothing for lanes outside E */
            cr_expect_eq(peek(t.c, CORE_MEM_RB0, 2048 + 4 * ul), even ? ul : 0u, "N=%d rsct lane %d", n, l);
            cr_expect_eq(peek(t.c, CORE_MEM_FB, 4 * ul), even ? fbits(1.5f) : 0u, "N=%d fbadd lane %d", n, l);
            if (even) {
                cr_expect_eq(peek(t.c, CORE_MEM_IDM, 256 + 4 * even_count), ul, "N=%d sapp word %u", n, even_count);
                even_count++;
            }
        }
        cr_expect_eq(core_sreg(t.c, 4), 100 + even_count, "N=%d ralloc: rb += popcount(E)", n);
        cr_expect_eq(core_sreg(t.c, 7), 256 + 4 * even_count, "N=%d sapp: ra += 4 popcount(E)", n);
        cr_expect_eq(peek(t.c, CORE_MEM_IDM, 256 + 4 * even_count), 0u, "N=%d sapp wrote past its lanes", n);
        t_free(&t);
    }
}

Test(core_mask, compares_clear_lanes_outside_e)
{
    /* Destinations start all-set; every test below is true in every lane, so the result must be
     * exactly E (m2 = even lanes): lanes outside E are cleared, not merged. */
    static const IsaInstr a[] = {
        V_A(VIOTA, 0, 0), V_ABI(VANDI, 1, 0, 1, 0), V_AI(VLI, 2, 0, 0), V_ABC(VIEQ, 2, 1, 2, 0),
        V_AI(VLI, 3, 0x3F800000, 0),  /* 1.0f */
        V_AI(VLI, 4, 0x40000000, 0),  /* 2.0f */
        V_AI(VLI, 7, 0x7FC00000, 0),  /* NaN */
        V_AI(VLI, 6, 5, 0),
        I_A(MALL, 3), I_A(MALL, 4), I_A(MALL, 5), I_A(MALL, 6), I_A(MALL, 7),
        V_ABC(VFLT, 3, 3, 4, 2),      /* 1 < 2 */
        V_ABC(VFLE, 4, 3, 3, 2),      /* 1 <= 1 */
        V_ABC(VFEQ, 5, 4, 4, 2),      /* 2 == 2 */
        V_ABC(VFNE, 6, 7, 7, 2),      /* NaN != NaN: true */
        V_ABC(VILT, 7, 0, 6, 2),      /* l < 5: true only for l < 5 */
        I_0(HALT),
    };
    static const IsaInstr b[] = {
        V_A(VIOTA, 0, 0), V_ABI(VANDI, 1, 0, 1, 0), V_AI(VLI, 2, 0, 0), V_ABC(VIEQ, 2, 1, 2, 0),
        V_AI(VLI, 5, -1, 0), V_AI(VLI, 6, 5, 0), V_AI(VLI, 3, 0x3F800000, 0),
        I_A(MALL, 3), I_A(MALL, 4), I_A(MALL, 5), I_A(MALL, 6), I_A(MALL, 7), I_A(MCLR, 1),
        V_ABC(VIEQ, 3, 5, 5, 2),      /* true */
        V_ABC(VILT, 4, 5, 6, 2),      /* -1 < 5 signed: true */
        V_ABC(VILTU, 5, 6, 5, 2),     /* 5 < 0xFFFFFFFF unsigned: true */
        V_ABC(VILTU, 6, 5, 6, 2),     /* false */
        V_ABC(VFNE, 7, 3, 3, 2),      /* 1 != 1: false */
        V_ABC(VIEQ, 1, 0, 0, 0),      /* under m0: every lane, nothing above N */
        I_0(HALT),
    };
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        uint64_t even = 0x5555555555555555ull & lanes_mask(n), low5 = lanes_mask(n < 5 ? n : 5);
        T t;
        t_init(&t, a, sizeof a / sizeof a[0], n);
        t_run_halt(&t);
        for (int m = 3; m <= 6; m++)
            cr_expect_eq(core_mreg(t.c, m), even, "N=%d program a: m%d = %#llx, expected %#llx", n, m,
                         (unsigned long long)core_mreg(t.c, m), (unsigned long long)even);
        cr_expect_eq(core_mreg(t.c, 7), even & low5, "N=%d vilt: m7 = %#llx", n, (unsigned long long)core_mreg(t.c, 7));
        t_free(&t);

        t_init(&t, b, sizeof b / sizeof b[0], n);
        t_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 3), even, "N=%d vieq", n);
        cr_expect_eq(core_mreg(t.c, 4), even, "N=%d vilt signed", n);
        cr_expect_eq(core_mreg(t.c, 5), even, "N=%d viltu", n);
        cr_expect_eq(core_mreg(t.c, 6), 0u, "N=%d viltu false", n);
        cr_expect_eq(core_mreg(t.c, 7), 0u, "N=%d vfne false", n);
        cr_expect_eq(core_mreg(t.c, 1), lanes_mask(n), "N=%d compare under m0", n);
        t_free(&t);
    }
}

Test(core_mask, mask_registers_stay_within_n)
{
    /* bits for lanes >= N are always 0: mnot, mtail with a huge count, mxor of complements */
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        T t;
        t_init(&t,
               PROG(I_A(MCLR, 1), I_AB(MNOT, 2, 1), I_AI(LI, 1, 1000), I_AB(MTAIL, 3, 1), I_AI(LI, 2, -5),
                    I_AB(MTAIL, 4, 2), I_ABC(MXOR, 5, 2, 4), I_AB(MPOP, 3, 5), I_AB(MFIRST, 4, 4), I_AB(MFIRST, 5, 2),
                    I_0(HALT)),
               n);
        t_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 2), lanes_mask(n), "N=%d mnot", n);
        cr_expect_eq(core_mreg(t.c, 3), lanes_mask(n), "N=%d mtail 1000", n);
        cr_expect_eq(core_mreg(t.c, 4), 0u, "N=%d mtail -5", n);
        cr_expect_eq(core_mreg(t.c, 5), lanes_mask(n), "N=%d mxor", n);
        cr_expect_eq(core_sreg(t.c, 3), (uint32_t)n, "N=%d mpop", n);
        cr_expect_eq(core_sreg(t.c, 4), 0xFFFFFFFFu, "N=%d mfirst of empty = -1", n);
        cr_expect_eq(core_sreg(t.c, 5), 0u, "N=%d mfirst", n);
        t_free(&t);
    }
}

Test(core_mask, ldb_with_empty_mask_does_no_access)
{
    /* ldb: one access serves all lanes; with no lane there is no access: no trap even from an
     * address outside scene memory, and the destination keeps its value. */
    T t;
    t_init(&t, PROG(V_AI(VLI, 1, 0x1234, 0), V_ABI(LDB, 1, 2, 0, 7), I_0(HALT)), 16);
    core_set_sreg(t.c, 2, 0x7FFFFFF0u);
    t_run_halt(&t);
    for (int l = 0; l < 16; l++)
        cr_expect_eq(core_vreg(t.c, 1, l), 0x1234u);
    t_free(&t);
}

Test(core_mask, fbadd_adds_in_lane_order)
{
    /* Three lanes add 1, 1e8, -1e8 to the same word. In lane order 1 + 1e8 rounds to 1e8 and the
     * result is 0; in reverse order -1e8 + 1e8 = 0 and the result is 1. */
    T t;
    /* lane 0 = 1, lane 1 = 1e8, lane 2 = -1e8 (vli under one-lane masks), lane 3 idle */
    t_init(&t,
           PROG(V_A(VIOTA, 0, 0), V_AI(VLI, 5, 1, 0), V_ABC(VIEQ, 1, 0, 5, 0), /* m1 = {1} */
                V_AI(VLI, 5, 2, 0), V_ABC(VIEQ, 2, 0, 5, 0),                     /* m2 = {2} */
                V_AI(VLI, 6, fbits(1.0f), 0), V_AI(VLI, 6, fbits(1e8f), 1), V_AI(VLI, 6, fbits(-1e8f), 2),
                I_AI(LI, 3, 3), I_AB(MTAIL, 3, 3), V_AI(VLI, 7, 16, 0), V_ABI(FBADD, 6, 7, 0, 3), I_0(HALT)),
           4);
    t_run_halt(&t);
    cr_expect_eq(peek(t.c, CORE_MEM_FB, 16), fbits(0.0f), "FB[16] = %#x, expected +0 (lanes in order)",
                 peek(t.c, CORE_MEM_FB, 16));
    t_free(&t);
}

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
        T t;
        t_init(&t, stats_prog, sizeof stats_prog / sizeof stats_prog[0], n);
        t_run_halt(&t);
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
        t_free(&t);
    }
}

Test(core_stats, sfetch_counts_the_lanes_it_fills)
{
    /* core.h: for sfetch the active lanes are the n lanes that received an ID, and its record's
     * exec is that tail mask: a stream's last, partial vector is the under-utilization Gribble &
     * Ramani 2008 (Sec. 4.1) attribute to stream lengths that are not multiples of N. */
    T t;
    t_init(&t, PROG(I_ABCD(SFETCH, 1, 1, 2, 3), I_0(HALT)), 4);
    core_set_sreg(t.c, 2, 0);
    core_set_sreg(t.c, 3, 12);
    t_run_halt(&t);
    cr_expect_eq(core_mreg(t.c, 1), 0x7u);
    cr_expect_eq(core_stats(t.c)->vec_instructions[0], 1u);
    cr_expect_eq(core_stats(t.c)->active_lanes[0], 3u, "sfetch counted %llu active lanes, expected the 3 it filled",
                 (unsigned long long)core_stats(t.c)->active_lanes[0]);
    t_free(&t);
}

Test(core_stats, stage_instruction_belongs_to_the_previous_stage)
{
    /* "stage imm attributes the instructions that follow": the marker itself is not one of them */
    T t;
    t_init(&t, PROG(I_I(STAGE, 3), I_I(STAGE, 0), I_I(STAGE, 2), I_0(HALT)), 4);
    t_run_halt(&t);
    const CoreStats *st = core_stats(t.c);
    cr_expect_eq(st->instructions[ISA_STAGE_OTHER], 2u);
    cr_expect_eq(st->instructions[ISA_STAGE_SHADING], 1u);
    cr_expect_eq(st->instructions[ISA_STAGE_INTERSECTION], 1u);
    cr_expect_eq(st->instructions[ISA_STAGE_TRAVERSAL], 0u);
    t_free(&t);
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
    T t;
    t_init(&t, prog, sizeof prog / sizeof prog[0], 4);
    core_set_hook(t.c, log_hook, &log);
    t_run_halt(&t);
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
    t_free(&t);
}

Test(core_hook, stage_and_wide_addresses)
{
    /* At N = 64 a gather records 64 addresses, and the record carries the stage in force. */
    HookLog log;
    memset(&log, 0, sizeof log);
    T t;
    t_init(&t, PROG(I_I(STAGE, 2), V_A(VIOTA, 1, 0), V_ABCI(RGAT, 2, 1, 0, 100 * 4, 0), I_0(HALT)), 64);
    core_set_hook(t.c, log_hook, &log);
    t_run_halt(&t);
    cr_assert_eq(log.n, 4);
    cr_expect_eq(log.rec[0].stage, ISA_STAGE_OTHER);
    cr_expect_eq(log.rec[1].stage, ISA_STAGE_INTERSECTION);
    const CoreRecord *r = &log.rec[2];
    cr_expect_eq(r->mem, CORE_MEM_RB0);
    cr_expect_eq(r->naddr, 64);
    cr_expect_eq(r->exec, ~0ull);
    for (int l = 0; l < 64; l++)
        cr_expect_eq(r->addr[l], 400u + 4u * (uint32_t)l, "lane %d", l);
    t_free(&t);
}

/* ==== core_run: limits and determinism ================================================================ */

Test(core_run, limit_is_resumable_and_zero_means_none)
{
    T t;
    t_init(&t, PROG(I_ABI(ADDI, 1, 1, 1), I_I(JMP, 0)), 4);
    cr_expect_eq(t_run(&t, 10), CORE_EXIT_LIMIT);
    cr_expect_eq(core_sreg(t.c, 1), 5u);
    cr_expect_eq(core_instructions(t.c), 10u);
    cr_expect_eq(t_run(&t, 7), CORE_EXIT_LIMIT, "max_instr more instructions");
    cr_expect_eq(core_instructions(t.c), 17u);
    cr_expect_eq(core_sreg(t.c, 1), 9u);
    cr_expect_eq(core_pc(t.c), 1u);
    t_free(&t);

    /* 0 = no limit: a loop of 3 x 100000 + 2 instructions halts */
    t_init(&t, PROG(I_AI(LI, 2, 100000), I_ABI(ADDI, 1, 1, 1), I_ABI(BLT, 1, 2, 1), I_0(HALT)), 4);
    cr_expect_eq(t_run(&t, 0), CORE_EXIT_HALT, "%s", core_trap_message(t.c));
    cr_expect_eq(core_instructions(t.c), 200002u);
    t_free(&t);

    /* a halt that is the max_instr-th instruction halts; one fewer stops at the limit */
    t_init(&t, PROG(I_0(NOP), I_0(NOP), I_0(HALT)), 4);
    cr_expect_eq(t_run(&t, 3), CORE_EXIT_HALT, "%s", core_trap_message(t.c));
    t_free(&t);
    t_init(&t, PROG(I_0(NOP), I_0(NOP), I_0(HALT)), 4);
    cr_expect_eq(t_run(&t, 2), CORE_EXIT_LIMIT);
    t_free(&t);
}

static void fill_for_filter(Core *c, uint32_t L)
{
    uint32_t seed = 12345;
    for (uint32_t id = 0; id < 1000; id++)
        poke(c, CORE_MEM_RB0, 4 * id, (lcg(&seed) & 1u) ? 1u : 0u);
    for (uint32_t i = 0; i < L; i++)
        poke(c, CORE_MEM_IDM, 64 + 4 * i, (i * 389u + 11u) % 1000u);
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
    for (int w = 0; w < N_WIDTHS; w++) {
        int n = widths[w];
        T a, b, h;
        t_init(&a, prog, np, n);
        t_init(&b, prog, np, n);
        t_init(&h, prog, np, n);
        fill_for_filter(a.c, 131);
        fill_for_filter(b.c, 131);
        fill_for_filter(h.c, 131);
        uint64_t calls = 0;
        core_set_hook(h.c, null_hook, &calls);
        t_run_halt(&a);
        t_run_halt(&b);
        t_run_halt(&h);
        expect_same_state(a.c, b.c, "two runs");
        expect_same_state(a.c, h.c, "with a hook");
        cr_expect_eq(calls, core_instructions(h.c), "N=%d: one hook call per instruction", n);
        t_free(&a);
        t_free(&b);
        t_free(&h);
    }
}
