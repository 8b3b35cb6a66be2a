/* tests/unit/test_core.c -- the functional core (sim/core.h) against its specification.
 *
 * Every expected value here is written by hand from the DESC column of isa/opcodes.def, from
 * docs/isa.md and from the comments of sim/core.h; none is obtained by running the core. Only the
 * wording of trap reasons was matched to sim/core.c: the conditions under which a trap must (or
 * must not) happen come from the specification. Programs are built in C as IsaInstr arrays and
 * encoded with isa_encode into a text-only AsmObject, so the assembler is not under test here.
 *
 * Suites: core_new (construction and reset state), core_trap (every trap class and its message),
 * core_image (a scene image shared copy-on-write, and its copy fallback) here; core_sfetch (ID-stream fetch), core_part (partition unit), core_mask (merge masking and
 * compares) in test_core_lanes.c; core_stats (counters), core_hook (the timing model's record),
 * core_run (limits, determinism) in test_core_run.c. The program-building macros and helpers are
 * tests/support/core_prog.h's.
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

/* The run must end with exit `want` and exactly the message
 * "trap: <reason> at pc <pc> (<dis>) <where>". */
static void expect_trap(TcCore *t, CoreExit want, const char *reason, uint32_t pc, const char *dis, const char *where)
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
    TcCore t;
    tc_init(&t, prog, n, lanes);
    for (int i = 0; i < nregs; i++)
        core_set_sreg(t.c, regs[i].r, regs[i].v);
    tc_run(&t, 100000);
    expect_trap(&t, CORE_EXIT_TRAP, reason, pc, dis, "?");
    tc_free(&t);
}

/* Same program and registers, but the run must halt (the condition is not a trap). */
static void halt_case(const IsaInstr *prog, size_t n, int lanes, const RegInit *regs, int nregs, const char *what)
{
    TcCore t;
    tc_init(&t, prog, n, lanes);
    for (int i = 0; i < nregs; i++)
        core_set_sreg(t.c, regs[i].r, regs[i].v);
    CoreExit e = tc_run(&t, 100000);
    cr_assert_eq(e, CORE_EXIT_HALT, "%s: must not trap, got: %s", what, core_trap_message(t.c));
    tc_free(&t);
}

#define REGS(...) ((const RegInit[]){__VA_ARGS__}), (int)(sizeof((const RegInit[]){__VA_ARGS__}) / sizeof(RegInit))
#define NOREGS NULL, 0

/* ==== core_new: construction and reset state ======================================================== */

Test(core_new, reset_state)
{
    /* core.h: memories zeroed, then .data at scene address 0 and .spad at scratchpad address 0;
     * m0 = all lanes, other masks empty, registers 0, stage other, pc 0; RBc is RB0. */
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        TcCore t;
        tc_obj_from_prog(&t.obj, PROG(I_0(HALT)));
        uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8}, spad[4] = {0xAA, 0xBB, 0xCC, 0xDD};
        t.obj.data = malloc(sizeof data);
        t.obj.spad = malloc(sizeof spad);
        memcpy(t.obj.data, data, sizeof data);
        memcpy(t.obj.spad, spad, sizeof spad);
        t.obj.ndata = sizeof data;
        t.obj.nspad = sizeof spad;
        CoreParams p;
        tc_params(&p, n);
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
        cr_expect_eq(core_mreg(t.c, 0), tc_lanes_mask(n), "N=%d m0 = %#llx", n, (unsigned long long)core_mreg(t.c, 0));
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
        tc_free(&t);
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
    tc_obj_from_prog(&o, PROG(I_0(HALT)));
    CoreParams p;

    /* lane count: 1..ISA_MAX_LANES */
    tc_params(&p, 0);
    expect_new_fails(&p, &o, "0");
    tc_params(&p, ISA_MAX_LANES + 1);
    expect_new_fails(&p, &o, "65");
    tc_params(&p, -3);
    expect_new_fails(&p, &o, "-3");

    /* the two ray buffers must have the same size */
    tc_params(&p, 4);
    p.mem_bytes[CORE_MEM_RB1] = TC_RB_BYTES * 2;
    expect_new_fails(&p, &o, "8192");

    /* memory sizes must be multiples of 4 */
    tc_params(&p, 4);
    p.mem_bytes[CORE_MEM_SPAD] = 510;
    expect_new_fails(&p, &o, "510");

    /* .data must fit scene memory, .spad the scratchpad (exactly full is fine) */
    tc_params(&p, 4);
    o.ndata = TC_SCENE_BYTES + 4;
    o.data = calloc(o.ndata, 1);
    expect_new_fails(&p, &o, ".data");
    o.ndata = TC_SCENE_BYTES;
    char err[512];
    Core *c = core_new(&p, &o, err, sizeof err);
    cr_expect_not_null(c, ".data exactly filling scene memory was rejected: %s", err);
    core_free(c);
    free(o.data);
    o.data = NULL;
    o.ndata = 0;

    o.nspad = TC_SPAD_BYTES + 4;
    o.spad = calloc(o.nspad, 1);
    expect_new_fails(&p, &o, ".spad");
    free(o.spad);
    o.spad = NULL;
    o.nspad = 0;

    /* an undecodable word (0xFF is not an opcode) */
    o.text[0] = 0xFF;
    expect_new_fails(&p, &o, "instruction 0");
    asm_object_free(&o);

    /* the extreme tc_widths are accepted */
    for (int n = 1; n <= ISA_MAX_LANES; n += ISA_MAX_LANES - 1) {
        AsmObject ok;
        tc_obj_from_prog(&ok, PROG(I_0(HALT)));
        tc_params(&p, n);
        c = core_new(&p, &ok, err, sizeof err);
        cr_expect_not_null(c, "N = %d rejected: %s", n, err);
        core_free(c);
        asm_object_free(&ok);
    }
}

Test(core_new, r0_is_an_ordinary_register)
{
    /* docs/isa.md: r0 is not hard-wired to zero. */
    TcCore t;
    tc_init(&t, PROG(I_AI(LI, 0, 5), I_ABI(ADDI, 1, 0, 1), I_ABI(ADDI, 0, 0, 10), I_0(HALT)), 4);
    tc_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 0), 15u);
    cr_expect_eq(core_sreg(t.c, 1), 6u);
    tc_free(&t);
}

/* ==== core_trap: every trap class, exact messages ===================================================== */

Test(core_trap, scratchpad)
{
    /* SP[rb + imm]: a word at size - 4 is the last legal one; size is out of range. */
    halt_case(PROG(I_ABI(SPLD, 1, 2, 4), I_0(HALT)), 4, REGS({2, TC_SPAD_BYTES - 8}), "spld of the last word");
    trap_case(PROG(I_ABI(SPLD, 1, 2, 4), I_0(HALT)), 4, REGS({2, TC_SPAD_BYTES - 4}),
              "scratchpad load out of range: address 0x00000200 (size 512)", 0, "spld r1, r2, 4");
    trap_case(PROG(I_0(NOP), I_ABI(SPST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 6}),
              "scratchpad store misaligned: address 0x00000006", 1, "spst r1, r2, 0");
    /* vspld: lane l reads SP[rb + imm + 4l]; at N = 4 from size - 12, lane 3 is past the end */
    trap_case(PROG(V_ABI(VSPLD, 1, 2, 0, 0), I_0(HALT)), 4, REGS({2, TC_SPAD_BYTES - 12}),
              "scratchpad load out of range: address 0x00000200 (size 512)", 0, "vspld v1, r2, 0");
    /* ... but not when lane 3 is outside the exec mask (m2 = lanes 0..2) */
    halt_case(PROG(I_AB(MTAIL, 2, 3), V_ABI(VSPLD, 1, 2, 0, 2), I_0(HALT)), 4, REGS({2, TC_SPAD_BYTES - 12}, {3, 3}),
              "vspld with the bad lane masked off");
    trap_case(PROG(V_ABI(VSPST, 1, 2, 2, 0), I_0(HALT)), 4, NOREGS, "scratchpad store misaligned: address 0x00000002", 0,
              "vspst v1, r2, 2");
}

Test(core_trap, scene_memory)
{
    trap_case(PROG(I_ABI(LD, 1, 2, 0), I_0(HALT)), 4, REGS({2, TC_SCENE_BYTES}),
              "scene memory load out of range: address 0x00000800 (size 2048)", 0, "ld r1, r2, 0");
    /* negative immediates are offsets: rb + imm wraps in 32 bits, 2052 - 8 = 2044 is legal */
    halt_case(PROG(I_ABI(LD, 1, 2, -8), I_0(HALT)), 4, REGS({2, TC_SCENE_BYTES + 4}), "ld with a negative offset");
    trap_case(PROG(I_ABI(ST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 1}), "scene memory store misaligned: address 0x00000001", 0,
              "st r1, r2, 0");
    trap_case(PROG(V_ABI(LDB, 1, 2, 0, 0), I_0(HALT)), 4, REGS({2, 2 * TC_SCENE_BYTES}),
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
    /* N = 16 (the core's 16-lane copy): ids 0, 128, ..., 1920; lane 8 is the first bad one, and
     * the lanes before it do not hide it */
    trap_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 128, 0), V_ABCI(RGAT, 1, 2, 4, 0, 0), I_0(HALT)), 16, NOREGS,
              "ray buffer 0 gather out of range: address 0x00001000 (size 4096)", 2, "rgat v1, v2, r4, 0");
    /* a bad id in a lane outside the exec mask is not an access */
    halt_case(PROG(V_A(VIOTA, 3, 0), V_ABI(VMULI, 2, 3, 1024, 0), I_AB(MTAIL, 1, 5), V_ABCI(RGAT, 1, 2, 4, 0, 1),
                   V_ABCI(RSCT, 1, 2, 4, 0, 1), I_0(HALT)),
              16, REGS({5, 1}), "rgat/rsct with bad ids masked off");
}

Test(core_trap, id_stream_memory)
{
    trap_case(PROG(I_ABI(SLD, 1, 2, 0), I_0(HALT)), 4, REGS({2, TC_IDM_BYTES}),
              "ID-stream memory load out of range: address 0x00000400 (size 1024)", 0, "sld r1, r2, 0");
    trap_case(PROG(I_ABI(SST, 1, 2, 0), I_0(HALT)), 4, REGS({2, 3}), "ID-stream memory store misaligned: address 0x00000003",
              0, "sst r1, r2, 0");
    /* sapp at N = 4 from size - 8: the third lane would go to size */
    trap_case(PROG(V_AB(SAPP, 2, 1, 0), I_0(HALT)), 4, REGS({2, TC_IDM_BYTES - 8}),
              "ID-stream memory append out of range: address 0x00000400 (size 1024)", 0, "sapp r2, v1");
    /* two active lanes fit exactly */
    halt_case(PROG(I_AB(MTAIL, 3, 4), V_AB(SAPP, 2, 1, 3), I_0(HALT)), 4, REGS({2, TC_IDM_BYTES - 8}, {4, 2}),
              "sapp of two lanes into the last two words");
    trap_case(PROG(V_AB(SAPP, 2, 1, 0), I_0(HALT)), 4, REGS({2, 2}), "ID-stream memory append misaligned: address 0x00000002",
              0, "sapp r2, v1");
    /* an empty exec mask appends nothing, so a bad pointer is no access */
    halt_case(PROG(V_AB(SAPP, 2, 1, 7), I_0(HALT)), 4, REGS({2, 2}), "sapp with an empty exec mask");
}

Test(core_trap, framebuffer)
{
    trap_case(PROG(V_ABI(FBADD, 1, 2, TC_FB_BYTES, 0), I_0(HALT)), 4, NOREGS,
              "framebuffer scatter-add out of range: address 0x00000100 (size 256)", 0, "fbadd v1, v2, 256");
    trap_case(PROG(V_ABI(FBADD, 1, 2, 2, 0), I_0(HALT)), 4, NOREGS, "framebuffer scatter-add misaligned: address 0x00000002",
              0, "fbadd v1, v2, 2");
    halt_case(PROG(V_ABI(FBADD, 1, 2, TC_FB_BYTES - 4, 0), I_0(HALT)), 4, NOREGS, "fbadd of the last word");
}

Test(core_trap, sfetch_bad_stream)
{
    /* rc > rd traps */
    trap_case(PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4, REGS({3, 16}, {4, 8}),
              "bad stream: begin 0x00000010 > end 0x00000008", 0, "sfetch v1, m1, r3, r4");
    /* rc == rd is an empty stream, not an error */
    halt_case(PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4, REGS({3, 16}, {4, 16}), "sfetch of an empty stream");
    /* a stream whose fetched words run past the end of IDM traps (any reason) at the sfetch */
    TcCore t;
    tc_init(&t, PROG(I_ABCD(SFETCH, 1, 1, 3, 4), I_0(HALT)), 4);
    core_set_sreg(t.c, 3, TC_IDM_BYTES - 8);
    core_set_sreg(t.c, 4, TC_IDM_BYTES + 8);
    cr_assert_eq(tc_run(&t, 100), CORE_EXIT_TRAP);
    cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0);
    cr_expect(strstr(core_trap_message(t.c), " at pc 0 (sfetch v1, m1, r3, r4) ?") != NULL, "%s", core_trap_message(t.c));
    tc_free(&t);
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
    struct { uint32_t b, e; } cases[] = {{40, 0}, {TC_IDM_BYTES - 8, TC_IDM_BYTES + 8}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        TcCore t;
        tc_init(&t, PROG(I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)), 4);
        core_set_sreg(t.c, 2, cases[i].b);
        core_set_sreg(t.c, 3, cases[i].e);
        cr_assert_eq(tc_run(&t, 100), CORE_EXIT_TRAP, "part [%#x, %#x) did not trap", cases[i].b, cases[i].e);
        cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0);
        cr_expect(strstr(core_trap_message(t.c), " at pc 1 (part r1, r2, r3) ?") != NULL, "%s", core_trap_message(t.c));
        tc_free(&t);
    }
}

Test(core_trap, division_by_zero)
{
    trap_case(PROG(I_AI(LI, 2, 7), I_ABC(DIVU, 1, 2, 3), I_0(HALT)), 4, NOREGS, "integer division by zero", 1,
              "divu r1, r2, r3");
    trap_case(PROG(I_AI(LI, 2, 7), I_ABC(REMU, 1, 2, 3), I_0(HALT)), 4, NOREGS, "integer division by zero", 1,
              "remu r1, r2, r3");
    /* unsigned: 0xFFFFFFFF / 2 and % 2 */
    TcCore t;
    tc_init(&t, PROG(I_AI(LI, 2, -1), I_AI(LI, 3, 2), I_ABC(DIVU, 1, 2, 3), I_ABC(REMU, 4, 2, 3), I_0(HALT)), 4);
    tc_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 1), 0x7FFFFFFFu);
    cr_expect_eq(core_sreg(t.c, 4), 1u);
    tc_free(&t);
}

Test(core_trap, vext_lane)
{
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        char reason[64];
        char dis[64];
        snprintf(reason, sizeof reason, "vext lane %d out of range (N = %d)", n, n);
        snprintf(dis, sizeof dis, "vext r1, v2, %d", n);
        const IsaInstr p[] = {V_A(VIOTA, 2, 0), I_ABI(VEXT, 1, 2, (uint32_t)n), I_0(HALT)};
        trap_case(p, 3, n, NOREGS, reason, 1, dis);
        /* lane N - 1 is the last legal one */
        const IsaInstr q[] = {V_A(VIOTA, 2, 0), I_ABI(VEXT, 1, 2, (uint32_t)(n - 1)), I_0(HALT)};
        TcCore t;
        tc_init(&t, q, 3, n);
        tc_run_halt(&t);
        cr_expect_eq(core_sreg(t.c, 1), (uint32_t)(n - 1));
        tc_free(&t);
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
    TcCore t;
    tc_init(&t, PROG(I_I(JMP, 2), I_0(HALT)), 4);
    cr_assert_eq(tc_run(&t, 100), CORE_EXIT_TRAP);
    cr_expect(strncmp(core_trap_message(t.c), "trap: ", 6) == 0, "%s", core_trap_message(t.c));
    tc_free(&t);
}

/* trap_case expects "?" as the location; the fall-off case names no instruction, so check it here. */
Test(core_trap, falling_off_the_end_message)
{
    TcCore t;
    tc_init(&t, PROG(I_AI(LI, 1, 1), I_0(NOP)), 4);
    tc_run(&t, 100);
    expect_trap(&t, CORE_EXIT_TRAP, "pc past the end of the program (2 instructions)", 2, "no instruction",
                "after the last instruction");
    cr_expect_eq(core_sreg(t.c, 1), 1u, "the instructions before the end ran");
    tc_free(&t);
}

Test(core_trap, instruction_limit)
{
    TcCore t;
    tc_init(&t, PROG(I_I(JMP, 0)), 4);
    tc_run(&t, 1000);
    expect_trap(&t, CORE_EXIT_LIMIT, "instruction limit of 1000 reached", 0, "jmp 0", "?");
    cr_expect_eq(core_instructions(t.c), 1000u);
    cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_JMP], 1000u);
    tc_free(&t);
}

Test(core_trap, message_names_source_line)
{
    /* with a line table, <where> is file:line of the trapping instruction */
    TcCore t;
    tc_obj_from_prog(&t.obj, PROG(I_AI(LI, 2, 7), I_ABC(DIVU, 1, 2, 3), I_0(HALT)));
    t.obj.nfiles = 2;
    t.obj.files = calloc(2, sizeof(char *));
    t.obj.files[0] = strdup("kernels/main.s");
    t.obj.files[1] = strdup("kernels/lib/math.inc");
    t.obj.lines = calloc(3, sizeof(AsmLine));
    t.obj.lines[0] = (AsmLine){0, 10, 9};
    t.obj.lines[1] = (AsmLine){1, 42, 9};
    t.obj.lines[2] = (AsmLine){0, 12, 9};
    CoreParams p;
    tc_params(&p, 4);
    char err[256];
    t.c = core_new(&p, &t.obj, err, sizeof err);
    cr_assert_not_null(t.c, "%s", err);
    tc_run(&t, 100);
    expect_trap(&t, CORE_EXIT_TRAP, "integer division by zero", 1, "divu r1, r2, r3", "kernels/lib/math.inc:42");
    tc_free(&t);
}

/* ---- core_image: one scene image shared copy-on-write (core_image_new, core_load_image) ------- */

enum { IMG_SCENE = 3 * 4096, IMG_BYTES = 5000 }; /* the image ends inside the second page */

static void img_params(CoreParams *p)
{
    tc_params(p, 4);
    p->mem_bytes[CORE_MEM_SCENE] = IMG_SCENE;
}

static void img_bytes(uint8_t *b)
{
    uint32_t s = 12345;
    for (int i = 0; i < IMG_BYTES; i++)
        b[i] = (uint8_t)tc_lcg(&s);
}

/* Scene memory must read as memcpy(scene memory, bytes, IMG_BYTES) over `before` would leave it. */
static void expect_scene(Core *c, const uint8_t *bytes, const uint8_t *before, const char *what)
{
    uint32_t size;
    const uint8_t *sm = core_mem(c, CORE_MEM_SCENE, &size);
    cr_assert_eq(size, (uint32_t)IMG_SCENE);
    cr_expect(memcmp(sm, bytes, IMG_BYTES) == 0, "%s: the image's bytes differ", what);
    cr_expect(memcmp(sm + IMG_BYTES, before + IMG_BYTES, IMG_SCENE - IMG_BYTES) == 0,
              "%s: scene memory past the image changed", what);
}

/* A store by one core goes to its own page: neither the image nor another core sharing it sees it. */
static void stores_stay_private(int flags)
{
    static uint8_t bytes[IMG_BYTES], zero[IMG_SCENE];
    img_bytes(bytes);
    uint8_t orig[IMG_BYTES];
    memcpy(orig, bytes, sizeof orig);
    CoreImage *im = core_image_new(bytes, IMG_BYTES, flags);
    cr_assert_not_null(im);
    cr_expect_eq(core_image_shared(im), !(flags & CORE_IMAGE_COPY), "memfd image expected on Linux");
    CoreParams p;
    img_params(&p);
    TcCore a, b;
    /* a: SM[8] := 0xdeadbeef, SM[4100] := 0xdeadbeef (two pages of the image) */
    tc_init_p(&a, PROG(I_AI(LI, 1, 0xdeadbeef), I_AI(LI, 2, 0), I_ABI(ST, 1, 2, 8), I_ABI(ST, 1, 2, 4100),
                       I_ABI(LD, 3, 2, 12), I_0(HALT)), &p);
    tc_init_p(&b, PROG(I_0(HALT)), &p);
    cr_assert_eq(core_load_image(a.c, im), 0);
    cr_assert_eq(core_load_image(b.c, im), 0);
    expect_scene(a.c, bytes, zero, "core a, loaded");
    tc_run_halt(&a);
    uint32_t w12;
    memcpy(&w12, bytes + 12, 4);
    cr_expect_eq(core_sreg(a.c, 3), w12, "core a read SM[12] = %08x, the image holds %08x", core_sreg(a.c, 3), w12);
    cr_expect_eq(tc_peek(a.c, CORE_MEM_SCENE, 8), 0xdeadbeefu);
    cr_expect_eq(tc_peek(a.c, CORE_MEM_SCENE, 4100), 0xdeadbeefu);
    expect_scene(b.c, bytes, zero, "core b, after a's stores");
    cr_expect(memcmp(bytes, orig, sizeof orig) == 0, "the image's source bytes changed");
    /* a core loading the image afterwards sees it as it was */
    TcCore c;
    tc_init_p(&c, PROG(I_0(HALT)), &p);
    cr_assert_eq(core_load_image(c.c, im), 0);
    expect_scene(c.c, bytes, zero, "core c, loaded after a's stores");
    tc_free(&a);
    tc_free(&b);
    core_image_free(im);
    /* the cores' mappings outlive the image */
    expect_scene(c.c, bytes, zero, "core c, after the image is freed");
    tc_free(&c);
}

Test(core_image, a_store_is_seen_by_its_core_only)
{
    stores_stay_private(0);
}

Test(core_image, the_copy_fallback_keeps_stores_private_too)
{
    stores_stay_private(CORE_IMAGE_COPY);
}

/* core_load_image leaves scene memory as the copy does: what was past the image's last byte on
 * its last page (and beyond) stays. */
Test(core_image, loading_is_the_copy_even_on_the_last_page)
{
    static uint8_t bytes[IMG_BYTES];
    img_bytes(bytes);
    CoreParams p;
    img_params(&p);
    for (int flags = 0; flags <= CORE_IMAGE_COPY; flags++) {
        CoreImage *im = core_image_new(bytes, IMG_BYTES, flags);
        TcCore t;
        tc_init_p(&t, PROG(I_0(HALT)), &p);
        tc_poke(t.c, CORE_MEM_SCENE, 0, 0x11111111u);
        tc_poke(t.c, CORE_MEM_SCENE, IMG_BYTES + 4, 0x22222222u);     /* the image's last page */
        tc_poke(t.c, CORE_MEM_SCENE, IMG_SCENE - 4, 0x33333333u);     /* a page past it */
        uint8_t before[IMG_SCENE];
        memcpy(before, core_mem(t.c, CORE_MEM_SCENE, NULL), sizeof before);
        cr_assert_eq(core_load_image(t.c, im), 0);
        expect_scene(t.c, bytes, before, flags ? "copy" : "memfd");
        cr_expect_eq(tc_peek(t.c, CORE_MEM_SCENE, IMG_BYTES + 4), 0x22222222u);
        tc_free(&t);
        core_image_free(im);
    }
}

Test(core_image, an_image_larger_than_scene_memory_is_refused)
{
    static uint8_t bytes[IMG_SCENE + 4];
    CoreParams p;
    img_params(&p);
    for (int flags = 0; flags <= CORE_IMAGE_COPY; flags++) {
        CoreImage *im = core_image_new(bytes, sizeof bytes, flags);
        TcCore t;
        tc_init_p(&t, PROG(I_0(HALT)), &p);
        cr_expect_eq(core_load_image(t.c, im), -1);
        tc_free(&t);
        core_image_free(im);
    }
}
