/* asm/expr.h -- sfasm's constant expressions (internal to asm/).
 *
 * Owns: expression grammar, C precedence, integer (64-bit) and float (double) arithmetic and the
 * final 32-bit range check. Must not: own symbols; names are resolved through the caller's
 * lookup callback, which also decides whether an unknown name is an error or a forward reference.
 */
#ifndef SFSIM_ASM_EXPR_H
#define SFSIM_ASM_EXPR_H

#include <stdint.h>

#include "lex.h"

/* A value: integer or float; sec is the object section a label value is relative to (0 for
 * plain numbers), kept through label +/- number so label operands can be checked. */
typedef struct AsmValue {
    int64_t i;
    double f;
    uint8_t is_float;
    uint8_t sec;
    uint8_t pending;    /* depends on a symbol not known yet (forward reference) */
} AsmValue;

typedef struct AsmExprError {
    uint32_t col;
    char msg[256];
} AsmExprError;

enum { ASM_EXPR_OK = 0, ASM_EXPR_PENDING = 1, ASM_EXPR_ERROR = -1 };

typedef struct AsmExprEnv {
    void *ctx;
    /* Value of the name in tok: ASM_EXPR_OK, ASM_EXPR_PENDING (not known yet) or
     * ASM_EXPR_ERROR (err filled). */
    int (*lookup)(void *ctx, const AsmToken *tok, AsmValue *out, AsmExprError *err);
    /* defined(NAME): 1 if NAME is a defined symbol. */
    int (*defined)(void *ctx, const AsmToken *tok);
    AsmValue dot;       /* value of '.', the current location */
} AsmExprEnv;

/* Evaluates toks[0, n) as one expression; at_col locates an empty expression. Returns
 * ASM_EXPR_OK with *out set (an integer within [-2^31, 2^32 - 1] or a finite float within
 * binary32 range), ASM_EXPR_PENDING with err naming the first unknown symbol, or
 * ASM_EXPR_ERROR with err filled. */
int asm_expr_eval(const AsmToken *toks, int n, uint32_t at_col, const AsmExprEnv *env,
                  AsmValue *out, AsmExprError *err);

/* The 32 bits an immediate or .word stores for v: integer bits, or binary32 bits of a float. */
uint32_t asm_value_bits(const AsmValue *v);

#endif
