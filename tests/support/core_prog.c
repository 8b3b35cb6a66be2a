/* tests/support/core_prog.c -- building and running small programs on the functional core
 * (core_prog.h).
 *
 * Owns: encoding test programs, the test machine's parameters, the core set-up, run and memory
 * helpers. Must not: make a test's assertions about results (only that the set-up worked).
 */
#include "core_prog.h"

#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const int tc_widths[TC_N_WIDTHS] = {1, 4, 12, 16, 20, 33, 64}; /* 20, 33: partial 16-lane blocks of the core */

uint32_t tc_fbits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

uint64_t tc_lanes_mask(int n) { return n >= 64 ? ~0ull : (1ull << n) - 1; }

/* Text-only object from an IsaInstr array; every word must decode back to the same instruction
 * (so a malformed test program fails here, not later). */
void tc_obj_from_prog(AsmObject *o, const IsaInstr *p, size_t n)
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

void tc_params(CoreParams *p, int lanes)
{
    memset(p, 0, sizeof *p);
    p->lanes = lanes;
    p->mem_bytes[CORE_MEM_RB0] = TC_RB_BYTES;
    p->mem_bytes[CORE_MEM_RB1] = TC_RB_BYTES;
    p->mem_bytes[CORE_MEM_IDM] = TC_IDM_BYTES;
    p->mem_bytes[CORE_MEM_SPAD] = TC_SPAD_BYTES;
    p->mem_bytes[CORE_MEM_SCENE] = TC_SCENE_BYTES;
    p->mem_bytes[CORE_MEM_FB] = TC_FB_BYTES;
}

void tc_init_p(TcCore *t, const IsaInstr *prog, size_t n, const CoreParams *p)
{
    char err[512];
    tc_obj_from_prog(&t->obj, prog, n);
    t->c = core_new(p, &t->obj, err, sizeof err);
    cr_assert_not_null(t->c, "core_new (N = %d): %s", p->lanes, err);
}

void tc_init(TcCore *t, const IsaInstr *prog, size_t n, int lanes)
{
    CoreParams p;
    tc_params(&p, lanes);
    tc_init_p(t, prog, n, &p);
}

void tc_free(TcCore *t)
{
    core_free(t->c);
    asm_object_free(&t->obj);
    memset(t, 0, sizeof *t);
}

CoreExit tc_run(TcCore *t, uint64_t limit)
{
    t->exit = core_run(t->c, limit);
    return t->exit;
}

void tc_run_halt(TcCore *t)
{
    CoreExit e = tc_run(t, 1000000);
    cr_assert_eq(e, CORE_EXIT_HALT, "N = %d: expected halt, got exit %d: %s", core_lanes(t->c), (int)e,
                 core_trap_message(t->c));
}

void tc_poke(Core *c, CoreMem m, uint32_t addr, uint32_t v)
{
    uint32_t size;
    uint8_t *p = core_mem(c, m, &size);
    cr_assert(addr + 4 <= size, "poke outside %s", core_mem_names[m]);
    memcpy(p + addr, &v, 4);
}

uint32_t tc_peek(Core *c, CoreMem m, uint32_t addr)
{
    uint32_t size, v;
    uint8_t *p = core_mem(c, m, &size);
    cr_assert(addr + 4 <= size, "peek outside %s", core_mem_names[m]);
    memcpy(&v, p + addr, 4);
    return v;
}

uint32_t tc_lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 16;
}
