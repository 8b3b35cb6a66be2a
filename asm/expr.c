/* asm/expr.c -- sfasm's constant expressions: parsing and evaluation in one recursive descent.
 *
 * Owns: C precedence and the arithmetic rules of docs/assembler.md ("Expressions"): integers in
 * 64 bits with overflow, division by zero and shift range as errors; a float operand makes + - * /
 * and comparisons work in double; bit operators on floats are errors; the final value must fit
 * 32 bits. Must not: own symbols (the lookup callback does) or print anything.
 */
#include "expr.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* Deep enough for any hand-written expression, shallow enough for the C stack under ASan. */
#define EXPR_MAX_DEPTH 200

typedef struct Parser {
    const AsmToken *t;
    int n, pos;
    uint32_t end_col;
    const AsmExprEnv *env;
    AsmExprError *err;
    AsmExprError pend;  /* first forward reference seen */
    int have_pend;
    int depth;
    int skip;           /* > 0 inside a short-circuited operand: syntax only, no evaluation */
} Parser;

__attribute__((format(printf, 3, 4)))
static int fail(Parser *p, uint32_t col, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    p->err->col = col;
    vsnprintf(p->err->msg, sizeof p->err->msg, fmt, ap);
    va_end(ap);
    return -1;
}

static const AsmToken *peek(const Parser *p) { return p->pos < p->n ? &p->t[p->pos] : NULL; }

static uint32_t peek_col(const Parser *p)
{
    const AsmToken *t = peek(p);
    return t ? t->col : p->end_col;
}

static int is_punct(const AsmToken *t, int punct) { return t && t->kind == ASM_TOK_PUNCT && t->punct == punct; }

static int describe_fail(Parser *p, const char *what)
{
    const AsmToken *t = peek(p);
    char d[64];
    if (!t || t->kind == ASM_TOK_EOL)
        return fail(p, peek_col(p), "expected %s, found end of line", what);
    return fail(p, t->col, "expected %s, found %s", what, asm_tok_describe(t, d, sizeof d));
}

static AsmValue int_value(int64_t i) { return (AsmValue){.i = i}; }

static double as_double(const AsmValue *v) { return v->is_float ? v->f : (double)v->i; }

static int truthy(const AsmValue *v) { return v->is_float ? v->f != 0.0 : v->i != 0; }

/* ---- binary operators ------------------------------------------------------------------------- */

static int precedence(int punct)
{
    switch (punct) {
    case ASM_P_OROR: return 1;
    case ASM_P_ANDAND: return 2;
    case ASM_P_PIPE: return 3;
    case ASM_P_CARET: return 4;
    case ASM_P_AMP: return 5;
    case ASM_P_EQ: case ASM_P_NE: return 6;
    case ASM_P_LT: case ASM_P_LE: case ASM_P_GT: case ASM_P_GE: return 7;
    case ASM_P_SHL: case ASM_P_SHR: return 8;
    case ASM_P_PLUS: case ASM_P_MINUS: return 9;
    case ASM_P_STAR: case ASM_P_SLASH: case ASM_P_PERCENT: return 10;
    default: return 0;
    }
}

static int compare(int op, double a, double b)
{
    switch (op) {
    case ASM_P_EQ: return a == b;
    case ASM_P_NE: return a != b;
    case ASM_P_LT: return a < b;
    case ASM_P_LE: return a <= b;
    case ASM_P_GT: return a > b;
    default: return a >= b;
    }
}

static int compare_int(int op, int64_t a, int64_t b)
{
    switch (op) {
    case ASM_P_EQ: return a == b;
    case ASM_P_NE: return a != b;
    case ASM_P_LT: return a < b;
    case ASM_P_LE: return a <= b;
    case ASM_P_GT: return a > b;
    default: return a >= b;
    }
}

static int apply_float(Parser *p, const AsmToken *op, const AsmValue *a, const AsmValue *b, AsmValue *r)
{
    double x = as_double(a), y = as_double(b), z;
    switch (op->punct) {
    case ASM_P_PLUS: z = x + y; break;
    case ASM_P_MINUS: z = x - y; break;
    case ASM_P_STAR: z = x * y; break;
    case ASM_P_SLASH:
        if (y == 0.0)
            return fail(p, op->col, "division by zero");
        z = x / y;
        break;
    case ASM_P_EQ: case ASM_P_NE: case ASM_P_LT: case ASM_P_LE: case ASM_P_GT: case ASM_P_GE:
        *r = int_value(compare(op->punct, x, y));
        return 0;
    default:
        return fail(p, op->col, "operator '%s' needs integer operands, not floats",
                    asm_punct_text(op->punct));
    }
    if (!isfinite(z))
        return fail(p, op->col, "float overflow in expression");
    *r = (AsmValue){.f = z, .is_float = 1};
    return 0;
}

/* Label sections survive label +/- number and cancel in label - label (a distance). */
static uint8_t result_section(int op, const AsmValue *a, const AsmValue *b)
{
    if (op == ASM_P_PLUS)
        return a->sec && !b->sec ? a->sec : !a->sec && b->sec ? b->sec : 0;
    if (op == ASM_P_MINUS)
        return a->sec && !b->sec ? a->sec : 0;
    return 0;
}

static int apply_int(Parser *p, const AsmToken *op, const AsmValue *a, const AsmValue *b, AsmValue *r)
{
    int64_t x = a->i, y = b->i, z = 0;
    int ovf = 0;
    switch (op->punct) {
    case ASM_P_PLUS: ovf = __builtin_add_overflow(x, y, &z); break;
    case ASM_P_MINUS: ovf = __builtin_sub_overflow(x, y, &z); break;
    case ASM_P_STAR: ovf = __builtin_mul_overflow(x, y, &z); break;
    case ASM_P_SLASH:
    case ASM_P_PERCENT:
        if (y == 0)
            return fail(p, op->col, "division by zero");
        if (x == INT64_MIN && y == -1)
            ovf = 1;
        else
            z = op->punct == ASM_P_SLASH ? x / y : x % y;
        break;
    case ASM_P_SHL:
    case ASM_P_SHR:
        if (y < 0 || y > 63)
            return fail(p, op->col, "shift count %lld out of range 0..63", (long long)y);
        /* << wraps in 64 bits (the 32-bit check comes at the end); >> is arithmetic. */
        z = op->punct == ASM_P_SHL ? (int64_t)((uint64_t)x << y) : x >> y;
        break;
    case ASM_P_AMP: z = x & y; break;
    case ASM_P_PIPE: z = x | y; break;
    case ASM_P_CARET: z = x ^ y; break;
    default: z = compare_int(op->punct, x, y); break;
    }
    if (ovf)
        return fail(p, op->col, "integer overflow in expression");
    uint8_t sec = result_section(op->punct, a, b); /* r may be a: read before writing */
    *r = int_value(z);
    r->sec = sec;
    return 0;
}

static int apply_binary(Parser *p, const AsmToken *op, const AsmValue *a, const AsmValue *b, AsmValue *r)
{
    if (p->skip || a->pending || b->pending) {
        uint8_t pending = a->pending || b->pending; /* r may be a: read before writing */
        *r = int_value(0);
        r->pending = pending;
        return 0;
    }
    if (op->punct == ASM_P_ANDAND || op->punct == ASM_P_OROR) {
        int v = op->punct == ASM_P_ANDAND ? truthy(a) && truthy(b) : truthy(a) || truthy(b);
        *r = int_value(v);
        return 0;
    }
    if (a->is_float || b->is_float)
        return apply_float(p, op, a, b, r);
    return apply_int(p, op, a, b, r);
}

/* ---- grammar ---------------------------------------------------------------------------------- */

static int parse_binary(Parser *p, int min_prec, AsmValue *out);

static int parse_defined(Parser *p, AsmValue *out)
{
    p->pos++; /* '(' */
    const AsmToken *name = peek(p);
    if (!name || name->kind != ASM_TOK_IDENT)
        return describe_fail(p, "a symbol name in defined()");
    p->pos++;
    if (!is_punct(peek(p), ASM_P_RPAREN))
        return describe_fail(p, "')'");
    p->pos++;
    *out = int_value(!p->skip && p->env->defined ? p->env->defined(p->env->ctx, name) : 0);
    return 0;
}

static int parse_name(Parser *p, const AsmToken *t, AsmValue *out)
{
    p->pos++;
    if (t->len == 7 && memcmp(t->text, "defined", 7) == 0 && is_punct(peek(p), ASM_P_LPAREN))
        return parse_defined(p, out);
    *out = int_value(0);
    if (p->skip)
        return 0;
    int rc = p->env->lookup ? p->env->lookup(p->env->ctx, t, out, p->err) : ASM_EXPR_ERROR;
    if (rc == ASM_EXPR_ERROR) {
        if (!p->env->lookup)
            return fail(p, t->col, "undefined symbol '%.*s'", (int)t->len, t->text);
        return -1;
    }
    if (rc == ASM_EXPR_PENDING) {
        if (!p->have_pend) {
            p->pend.col = t->col;
            snprintf(p->pend.msg, sizeof p->pend.msg, "symbol '%.*s' is not defined yet",
                     (int)(t->len > 64 ? 64 : t->len), t->text);
            p->have_pend = 1;
        }
        *out = int_value(0);
        out->pending = 1;
    }
    return 0;
}

static int parse_primary(Parser *p, AsmValue *out)
{
    const AsmToken *t = peek(p);
    char d[64];
    if (!t)
        return describe_fail(p, "an expression");
    switch (t->kind) {
    case ASM_TOK_INT: p->pos++; *out = int_value(t->ival); return 0;
    case ASM_TOK_FLOAT: p->pos++; *out = (AsmValue){.f = t->fval, .is_float = 1}; return 0;
    case ASM_TOK_IDENT: return parse_name(p, t, out);
    case ASM_TOK_REG:
        return fail(p, t->col, "register %s cannot be used in an expression",
                    asm_tok_describe(t, d, sizeof d));
    case ASM_TOK_PUNCT:
        if (t->punct == ASM_P_DOT) {
            p->pos++;
            *out = p->env->dot;
            return 0;
        }
        if (t->punct == ASM_P_LPAREN) {
            p->pos++;
            if (parse_binary(p, 1, out) < 0)
                return -1;
            if (!is_punct(peek(p), ASM_P_RPAREN))
                return describe_fail(p, "')'");
            p->pos++;
            return 0;
        }
        return describe_fail(p, "an expression");
    case ASM_TOK_DIRECTIVE:
    case ASM_TOK_STRING:
    case ASM_TOK_EOL:
        break;
    }
    return describe_fail(p, "an expression");
}

static int parse_unary_op(Parser *p, const AsmToken *op, AsmValue *out)
{
    if (p->skip || out->pending)
        return 0;
    switch (op->punct) {
    case ASM_P_PLUS: return 0;
    case ASM_P_MINUS:
        if (out->is_float)
            out->f = -out->f;
        else if (out->i == INT64_MIN)
            return fail(p, op->col, "integer overflow in expression");
        else
            out->i = -out->i;
        out->sec = 0;
        return 0;
    case ASM_P_TILDE:
        if (out->is_float)
            return fail(p, op->col, "operator '~' needs an integer operand, not a float");
        *out = int_value(~out->i);
        return 0;
    default: /* '!' */
        *out = int_value(!truthy(out));
        return 0;
    }
}

static int parse_unary(Parser *p, AsmValue *out)
{
    const AsmToken *t = peek(p);
    if (++p->depth > EXPR_MAX_DEPTH)
        return fail(p, peek_col(p), "expression nested too deeply (limit %d)", EXPR_MAX_DEPTH);
    int rc;
    if (t && t->kind == ASM_TOK_PUNCT &&
        (t->punct == ASM_P_MINUS || t->punct == ASM_P_PLUS || t->punct == ASM_P_TILDE ||
         t->punct == ASM_P_BANG)) {
        p->pos++;
        rc = parse_unary(p, out);
        if (rc == 0)
            rc = parse_unary_op(p, t, out);
    } else {
        rc = parse_primary(p, out);
    }
    p->depth--;
    return rc;
}

/* Precedence climbing; && and || skip evaluating an operand that cannot change the result,
 * so "X != 0 && 10 / X" is fine when X is 0. */
static int parse_binary(Parser *p, int min_prec, AsmValue *out)
{
    if (parse_unary(p, out) < 0)
        return -1;
    for (;;) {
        const AsmToken *op = peek(p);
        int prec = op && op->kind == ASM_TOK_PUNCT ? precedence(op->punct) : 0;
        if (prec == 0 || prec < min_prec)
            return 0;
        p->pos++;
        int decided = !p->skip && !out->pending &&
                      ((op->punct == ASM_P_ANDAND && !truthy(out)) ||
                       (op->punct == ASM_P_OROR && truthy(out)));
        AsmValue rhs;
        p->skip += decided;
        int rc = parse_binary(p, prec + 1, &rhs);
        p->skip -= decided;
        if (rc < 0)
            return -1;
        if (decided)
            *out = int_value(op->punct == ASM_P_OROR);
        else if (apply_binary(p, op, out, &rhs, out) < 0)
            return -1;
    }
}

int asm_expr_eval(const AsmToken *toks, int n, uint32_t at_col, const AsmExprEnv *env,
                  AsmValue *out, AsmExprError *err)
{
    Parser p = {.t = toks, .n = n, .end_col = at_col, .env = env, .err = err};
    char d[64];
    err->col = at_col;
    err->msg[0] = '\0';
    if (n > 0) /* just past the last token: where a missing ')' or operand belongs */
        p.end_col = toks[n - 1].kind == ASM_TOK_EOL ? toks[n - 1].col : toks[n - 1].col + toks[n - 1].len;
    if (parse_binary(&p, 1, out) < 0)
        return ASM_EXPR_ERROR;
    const AsmToken *t = peek(&p);
    if (t && t->kind != ASM_TOK_EOL) {
        fail(&p, t->col, "unexpected %s after expression", asm_tok_describe(t, d, sizeof d));
        return ASM_EXPR_ERROR;
    }
    if (out->pending) {
        *err = p.pend;
        return ASM_EXPR_PENDING;
    }
    uint32_t col = n > 0 ? toks[0].col : at_col;
    if (!out->is_float && (out->i < INT32_MIN || out->i > (int64_t)UINT32_MAX)) {
        fail(&p, col, "value %lld does not fit in 32 bits", (long long)out->i);
        return ASM_EXPR_ERROR;
    }
    if (out->is_float && fabs(out->f) > FLT_MAX) {
        fail(&p, col, "float value %g is out of binary32 range", out->f);
        return ASM_EXPR_ERROR;
    }
    return ASM_EXPR_OK;
}

uint32_t asm_value_bits(const AsmValue *v)
{
    if (!v->is_float)
        return (uint32_t)v->i;
    /* Round to binary32; values beyond FLT_MAX were refused by asm_expr_eval. */
    float f = fabs(v->f) > FLT_MAX ? (v->f < 0 ? -FLT_MAX : FLT_MAX) : (float)v->f;
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    return bits;
}
