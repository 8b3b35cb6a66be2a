/* tests/support/core_prog.h -- small programs on the functional core for its tests
 * (tests/unit/test_core*.c): instructions built in C as IsaInstr literals, encoded into a
 * text-only AsmObject, run on a core with small memories.
 *
 * Owns: the instruction-building macros, the test machine's memory sizes and widths, and the
 * helpers that build, run, poke and peek a core. Must not: hold expected values (each test writes
 * its own from the specification) or use the assembler (it is not under test here).
 */
#ifndef SFSIM_TESTS_CORE_PROG_H
#define SFSIM_TESTS_CORE_PROG_H

#include <stddef.h>
#include <stdint.h>

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

/* The vector widths every width-dependent test runs at. */
#define TC_N_WIDTHS 7
extern const int tc_widths[TC_N_WIDTHS];

/* Memory sizes of the test machine (bytes): small, so that ranges are easy to hit. */
enum { TC_RB_BYTES = 4096, TC_IDM_BYTES = 1024, TC_SPAD_BYTES = 512, TC_SCENE_BYTES = 2048, TC_FB_BYTES = 256 };

/* A core built from a test program, and how its last run ended. */
typedef struct TcCore {
    AsmObject obj;
    Core *c;
    CoreExit exit;
} TcCore;

/* The bits of a binary32. */
uint32_t tc_fbits(float f);
/* Bits 0..n-1 set. */
uint64_t tc_lanes_mask(int n);
/* A pseudo-random 16-bit number from the state *s (a linear congruential generator). */
uint32_t tc_lcg(uint32_t *s);
/* Text-only object from an IsaInstr array; every word must decode back to the same instruction
 * (so a malformed test program fails here, not later). */
void tc_obj_from_prog(AsmObject *o, const IsaInstr *p, size_t n);
/* The test machine with `lanes` lanes and the memory sizes above. */
void tc_params(CoreParams *p, int lanes);
/* A core for the program (the test fails if core_new does), on machine p or the test machine. */
void tc_init_p(TcCore *t, const IsaInstr *prog, size_t n, const CoreParams *p);
void tc_init(TcCore *t, const IsaInstr *prog, size_t n, int lanes);
void tc_free(TcCore *t);
/* core_run with an instruction limit (0: none); the exit is kept in t->exit. */
CoreExit tc_run(TcCore *t, uint64_t limit);
/* Run and require halt; the failure shows the trap message. */
void tc_run_halt(TcCore *t);
/* A 32-bit word of memory m at byte addr (the test fails outside the memory). */
void tc_poke(Core *c, CoreMem m, uint32_t addr, uint32_t v);
uint32_t tc_peek(Core *c, CoreMem m, uint32_t addr);

#endif
