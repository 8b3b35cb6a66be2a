/* tests/support/isa_expect.h -- the expectation language of the per-instruction programs
 * tests/isa/<mnemonic>.s (run by tests/unit/test_isa_programs.c): expressions, checks, and the
 * ";!" lines of a file collected into a Spec.
 *
 * Owns: lexing, parsing and evaluating expressions, parsing one check, reading a file's checks.
 * Must not: run programs or compare results (test_isa_programs.c does), or derive an expected
 * value by running the core.
 *
 * Expectation syntax:
 *
 *     ;! [if COND:] CHECK
 *
 * CHECK is one of
 *     rK OP EXPR             scalar register K
 *     vK[IDX] OP EXPR        lane IDX of vector register K
 *     mK[IDX] OP EXPR        bit IDX of mask register K (0 or 1)
 *     mK OP EXPR             the whole mask as an integer (bit l = lane l)
 *     mem M[ADDR] OP EXPR    32-bit little-endian word at byte ADDR of memory M: rb0 rb1 idm spad
 *                            scene fb, or rbc / rbn for the current / next ray buffer
 *     stat KEY OP EXPR       a core counter: total, instr.STAGE, vec.STAGE, lanes.STAGE,
 *                            op.MNEMONIC, cat.STAGE.CATEGORY (stage keys: other traversal ...),
 *                            genG.instr.STAGE, genG.vec.STAGE, genG.lanes.STAGE (generation G)
 *     pc OP EXPR             the pc after the run
 *     trap "TEXT" ...        the run must trap, and the message contain every TEXT
 *     limit                  the run must stop at the instruction limit
 *     max EXPR               the instruction limit (no guard; default 1000000)
 * A run must end in halt unless an applicable `trap` or `limit` says otherwise; the other checks
 * are made in every case, on the state the run stopped in.
 *
 * A check whose text (IDX, ADDR, EXPR or COND) uses the lane variable `l` is made for every lane
 * l = 0..N-1. Guards (`if COND:`) make a check apply only where COND is non-zero.
 *
 * OP:
 *     ==  !=        32-bit integer (in)equality (EXPR must be an integer; -1 matches 0xffffffff);
 *                   masks and counters compare as 64-bit integers
 *     ==f           binary32: the register's bits equal those of EXPR rounded to binary32;
 *                   an expected NaN matches any NaN
 *     ~= TOL        binary32 within an absolute tolerance: |value - EXPR| <= TOL (as `~= 1.5 1e-6`);
 *                   equal infinities and NaN/NaN match
 *
 * EXPR: C-like expressions over 64-bit integers and doubles (a double operand makes the operation
 * double): numbers (decimal, 0x hex, floats like 1.5 / 1e-6), ( ), unary - + ! ~, * / % + - << >>
 * < <= > >= == != & ^ | && || ?:, the names l (lane), N (width), nan, inf, any symbol of the
 * program (labels give instruction indices, `NAME = value` constants their value), and functions
 *     f(x)       binary32 bits of x            fl(x)      binary32 value of the bits x
 *     float(x)   x rounded to binary32         int(x)     x truncated to an integer
 *     u32(x) s32(x)  32-bit unsigned / sign-extended value of x
 *     popcount(x) min(a,b) max(a,b) abs(x) floor(x) sqrt(x) exp2(x) log2(x) sin(x) cos(x)
 * `float(float(a) + float(b))` is the binary32 sum of two binary32 values (the exact double sum
 * rounded once), so rounding cases can be written out without the core.
 */
#ifndef SFSIM_TESTS_ISA_EXPECT_H
#define SFSIM_TESTS_ISA_EXPECT_H

#include <stddef.h>
#include <stdint.h>

#include "../../asm/asm.h"

/* ---- expressions ------------------------------------------------------------------------ */

typedef enum { E_INT, E_FLT, E_NAME, E_UN, E_BIN, E_TERN, E_CALL } ExprKind;

typedef struct Expr {
    ExprKind kind;
    int op;                   /* operator token for E_UN/E_BIN */
    int64_t i;
    double f;
    char name[48];            /* E_NAME, E_CALL */
    struct Expr *a, *b, *c;   /* operands / arguments */
} Expr;

typedef struct Val {
    int isf;
    int64_t i;
    double f;
} Val;

/* Tokens beyond single characters. */
enum { T_EOF = 256, T_NUM, T_NAME, T_STR, T_EQ, T_NE, T_LE, T_GE, T_SHL, T_SHR, T_AND, T_OR, T_FEQ, T_APPROX };

typedef struct Lexer {
    const char *s;
    int tok;
    int64_t ival;
    double fval;
    int isf;
    char text[256];
    char err[160];
} Lexer;

/* Evaluation environment: N, the lane l, the program's symbols. */
typedef struct Env {
    int lanes;
    int lane;                  /* -1 outside per-lane checks */
    const AsmObject *obj;
    char err[160];
} Env;

/* ---- expectations ------------------------------------------------------------------------ */

typedef enum { X_SREG, X_VREG, X_MBIT, X_MASK, X_MEM, X_STAT, X_PC, X_TRAP, X_LIMIT, X_MAX } CheckKind;
typedef enum { OP_EQ, OP_NE, OP_FEQ, OP_APPROX } CmpOp;

typedef struct Check {
    int line;
    CheckKind kind;
    int reg;                 /* register number, or CoreMem (-1 rbc, -2 rbn) for X_MEM */
    char key[64];            /* X_STAT key; X_TRAP: substrings joined by '\0', count in nsub */
    char subs[4][128];
    int nsub;
    Expr *guard, *index, *expect, *tol;
    CmpOp op;
    int per_lane;
} Check;

typedef struct Spec {
    Check *checks;
    int n, cap;
    uint64_t limit;
} Spec;

/* The next token of lx->s into lx (T_EOF at the end of the line; errors in lx->err). */
void ie_lex_next(Lexer *lx);
/* An expression (a ?: b : c at the loosest) from the current token on; NULL with lx->err set on
 * error. Free with ie_expr_free. */
Expr *ie_parse_expr(Lexer *lx);
void ie_expr_free(Expr *e);
/* The value of e; errors (unknown names, functions) in env->err. */
Val ie_eval(const Expr *e, Env *env);
Val ie_vi(int64_t i);
double ie_as_f(Val v);
/* binary32 bits of d rounded to binary32; the binary32 value of bits u. */
uint32_t ie_f32_bits(double d);
float ie_bits_f32(uint32_t u);

/* Parse one ";!" line body; returns 0, or -1 with a message in err. */
int ie_parse_check(const char *body, int line, Check *ck, char *err, size_t errlen);
/* Collect the ";!" lines of path (limit 1000000 unless a `max` says otherwise). Parse errors are
 * test failures. Returns the number of errors. */
int ie_spec_load(const char *path, Spec *spec);
void ie_spec_free(Spec *s);

#endif
