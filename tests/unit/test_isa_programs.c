/* tests/unit/test_isa_programs.c -- runs the per-instruction programs tests/isa/<mnemonic>.s on the
 * functional core at several vector widths and checks the expectations written in them.
 *
 * Each program is a small real program that exercises its instruction (masks, tails, edge values)
 * and ends in `halt`. Its expected results are written by hand from the DESC column of
 * isa/opcodes.def, as comment lines starting with ";!" (anywhere in the file; the assembler sees
 * comments). The harness never derives an expected value by running the core.
 *
 * Every file is assembled once (asm_assemble_file) and run for N = 1, 4, 12, 16, 64 with
 * memories RB0/RB1 512 KiB, IDM 32 KiB, SP 64 KiB, SM 1 MiB, FB 64 KiB, and a limit of 1,000,000
 * instructions. A failure names file, line, N and lane:
 *     tests/isa/vfadd.s:12 N=4 lane 3: v2 = 0x40000000 (2) expected 0x3fc00000 (1.5)
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
#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <ctype.h>
#include <glob.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"
#include "../../sim/core.h"

#define ISA_PROG_DIR "tests/isa"
#define DEFAULT_LIMIT 1000000ull

static const int widths[] = {1, 4, 12, 16, 64};
#define N_WIDTHS (int)(sizeof widths / sizeof widths[0])

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

static void lex_next(Lexer *lx)
{
    while (*lx->s == ' ' || *lx->s == '\t')
        lx->s++;
    const char *s = lx->s;
    if (*s == '\0' || *s == '\n' || *s == '\r') {
        lx->tok = T_EOF;
        return;
    }
    if (isdigit((unsigned char)*s) || (*s == '.' && isdigit((unsigned char)s[1]))) {
        char *end;
        if (s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
            lx->ival = (int64_t)strtoull(s, &end, 16);
            lx->isf = 0;
        } else {
            size_t n = strspn(s, "0123456789");
            int isfloat = s[n] == '.' || s[n] == 'e' || s[n] == 'E';
            if (isfloat) {
                lx->fval = strtod(s, &end);
                lx->isf = 1;
            } else {
                lx->ival = (int64_t)strtoull(s, &end, 10);
                lx->isf = 0;
            }
        }
        lx->s = end;
        lx->tok = T_NUM;
        return;
    }
    if (isalpha((unsigned char)*s) || *s == '_' || *s == '.') {
        size_t n = 0;
        while (isalnum((unsigned char)s[n]) || s[n] == '_' || s[n] == '.')
            n++;
        if (n >= sizeof lx->text)
            n = sizeof lx->text - 1;
        memcpy(lx->text, s, n);
        lx->text[n] = '\0';
        lx->s = s + n;
        lx->tok = T_NAME;
        return;
    }
    if (*s == '"') {
        const char *e = strchr(s + 1, '"');
        if (!e) {
            snprintf(lx->err, sizeof lx->err, "unterminated string");
            lx->tok = T_EOF;
            return;
        }
        size_t n = (size_t)(e - s - 1);
        if (n >= sizeof lx->text)
            n = sizeof lx->text - 1;
        memcpy(lx->text, s + 1, n);
        lx->text[n] = '\0';
        lx->s = e + 1;
        lx->tok = T_STR;
        return;
    }
    static const struct { const char *t; int tok; } two[] = {
        {"==f", T_FEQ}, {"==", T_EQ}, {"!=", T_NE}, {"<=", T_LE}, {">=", T_GE}, {"<<", T_SHL},
        {">>", T_SHR},  {"&&", T_AND}, {"||", T_OR}, {"~=", T_APPROX}};
    for (size_t k = 0; k < sizeof two / sizeof two[0]; k++) {
        size_t n = strlen(two[k].t);
        if (strncmp(s, two[k].t, n) == 0) {
            /* `==f` only when the f is not the start of a name or call such as f(1.5) */
            if (two[k].tok == T_FEQ && (isalnum((unsigned char)s[3]) || s[3] == '_' || s[3] == '('))
                continue;
            lx->s = s + n;
            lx->tok = two[k].tok;
            return;
        }
    }
    lx->s = s + 1;
    lx->tok = (unsigned char)*s;
}

static Expr *expr_new(ExprKind k)
{
    Expr *e = calloc(1, sizeof *e);
    cr_assert_not_null(e);
    e->kind = k;
    return e;
}

static void expr_free(Expr *e)
{
    if (!e)
        return;
    expr_free(e->a);
    expr_free(e->b);
    expr_free(e->c);
    free(e);
}

static Expr *parse_ternary(Lexer *lx);

static Expr *parse_primary(Lexer *lx)
{
    if (lx->err[0])
        return NULL;
    if (lx->tok == T_NUM) {
        Expr *e = expr_new(lx->isf ? E_FLT : E_INT);
        e->i = lx->ival;
        e->f = lx->fval;
        lex_next(lx);
        return e;
    }
    if (lx->tok == T_NAME) {
        Expr *e = expr_new(E_NAME);
        snprintf(e->name, sizeof e->name, "%.47s", lx->text);
        lex_next(lx);
        if (lx->tok == '(') {
            e->kind = E_CALL;
            lex_next(lx);
            Expr **slot[3] = {&e->a, &e->b, &e->c};
            int n = 0;
            if (lx->tok != ')')
                for (;;) {
                    if (n == 3) {
                        snprintf(lx->err, sizeof lx->err, "too many arguments to %s", e->name);
                        expr_free(e);
                        return NULL;
                    }
                    *slot[n++] = parse_ternary(lx);
                    if (lx->err[0]) {
                        expr_free(e);
                        return NULL;
                    }
                    if (lx->tok != ',')
                        break;
                    lex_next(lx);
                }
            e->i = n;
            if (lx->tok != ')') {
                snprintf(lx->err, sizeof lx->err, "expected ')' after the arguments of %s", e->name);
                expr_free(e);
                return NULL;
            }
            lex_next(lx);
        }
        return e;
    }
    if (lx->tok == '(') {
        lex_next(lx);
        Expr *e = parse_ternary(lx);
        if (!lx->err[0] && lx->tok != ')')
            snprintf(lx->err, sizeof lx->err, "expected ')'");
        if (lx->err[0]) {
            expr_free(e);
            return NULL;
        }
        lex_next(lx);
        return e;
    }
    snprintf(lx->err, sizeof lx->err, "expected a value at \"%.20s\"", lx->s);
    return NULL;
}

static Expr *parse_unary(Lexer *lx)
{
    if (lx->tok == '-' || lx->tok == '+' || lx->tok == '!' || lx->tok == '~') {
        int op = lx->tok;
        lex_next(lx);
        Expr *e = expr_new(E_UN);
        e->op = op;
        e->a = parse_unary(lx);
        if (lx->err[0]) {
            expr_free(e);
            return NULL;
        }
        return e;
    }
    return parse_primary(lx);
}

/* Binary levels, loosest first. */
static const int levels[][5] = {
    {T_OR}, {T_AND}, {'|'}, {'^'}, {'&'}, {T_EQ, T_NE}, {'<', T_LE, '>', T_GE}, {T_SHL, T_SHR}, {'+', '-'},
    {'*', '/', '%'},
};
#define N_LEVELS (int)(sizeof levels / sizeof levels[0])

static Expr *parse_level(Lexer *lx, int lv)
{
    if (lv == N_LEVELS)
        return parse_unary(lx);
    Expr *left = parse_level(lx, lv + 1);
    for (;;) {
        if (lx->err[0]) {
            expr_free(left);
            return NULL;
        }
        int hit = 0;
        for (int k = 0; k < 5 && levels[lv][k]; k++)
            hit |= lx->tok == levels[lv][k];
        if (!hit)
            return left;
        Expr *e = expr_new(E_BIN);
        e->op = lx->tok;
        lex_next(lx);
        e->a = left;
        e->b = parse_level(lx, lv + 1);
        left = e;
    }
}

static Expr *parse_ternary(Lexer *lx)
{
    Expr *cond = parse_level(lx, 0);
    if (lx->err[0] || lx->tok != '?')
        return cond;
    lex_next(lx);
    Expr *e = expr_new(E_TERN);
    e->a = cond;
    e->b = parse_ternary(lx);
    if (!lx->err[0] && lx->tok != ':')
        snprintf(lx->err, sizeof lx->err, "expected ':' in ?:");
    if (lx->err[0]) {
        expr_free(e);
        return NULL;
    }
    lex_next(lx);
    e->c = parse_ternary(lx);
    if (lx->err[0]) {
        expr_free(e);
        return NULL;
    }
    return e;
}

static int expr_uses_lane(const Expr *e)
{
    if (!e)
        return 0;
    if (e->kind == E_NAME && strcmp(e->name, "l") == 0)
        return 1;
    return expr_uses_lane(e->a) || expr_uses_lane(e->b) || expr_uses_lane(e->c);
}

/* Evaluation environment. */
typedef struct Env {
    int lanes;
    int lane;                  /* -1 outside per-lane checks */
    const AsmObject *obj;
    char err[160];
} Env;

static double as_f(Val v) { return v.isf ? v.f : (double)v.i; }

static Val vi(int64_t i) { return (Val){0, i, 0}; }
static Val vf(double f) { return (Val){1, 0, f}; }

static uint32_t f32_bits(double d)
{
    float x = (float)d;
    uint32_t u;
    memcpy(&u, &x, 4);
    return u;
}

static float bits_f32(uint32_t u)
{
    float x;
    memcpy(&x, &u, 4);
    return x;
}

static Val eval(const Expr *e, Env *env);

static Val eval_call(const Expr *e, Env *env)
{
    int n = (int)e->i;
    Val a = n > 0 ? eval(e->a, env) : vi(0), b = n > 1 ? eval(e->b, env) : vi(0);
    if (env->err[0])
        return vi(0);
    static const struct { const char *name; int nargs; } fns[] = {
        {"f", 1},     {"fl", 1},  {"float", 1}, {"int", 1},  {"u32", 1},  {"s32", 1},  {"popcount", 1},
        {"min", 2},   {"max", 2}, {"abs", 1},   {"floor", 1}, {"sqrt", 1}, {"exp2", 1}, {"log2", 1},
        {"sin", 1},   {"cos", 1}};
    int known = -1;
    for (size_t k = 0; k < sizeof fns / sizeof fns[0]; k++)
        if (strcmp(e->name, fns[k].name) == 0)
            known = (int)k;
    if (known < 0) {
        snprintf(env->err, sizeof env->err, "unknown function %s", e->name);
        return vi(0);
    }
    if (fns[known].nargs != n) {
        snprintf(env->err, sizeof env->err, "%s takes %d argument(s)", e->name, fns[known].nargs);
        return vi(0);
    }
    const char *f = e->name;
    if (!strcmp(f, "f"))
        return vi(f32_bits(as_f(a)));
    if (!strcmp(f, "fl"))
        return vf(bits_f32((uint32_t)a.i));
    if (!strcmp(f, "float"))
        return vf((float)as_f(a));
    if (!strcmp(f, "int"))
        return vi(a.isf ? (int64_t)a.f : a.i);
    if (!strcmp(f, "u32"))
        return vi((int64_t)(uint32_t)(a.isf ? (int64_t)a.f : a.i));
    if (!strcmp(f, "s32"))
        return vi((int64_t)(int32_t)(uint32_t)(a.isf ? (int64_t)a.f : a.i));
    if (!strcmp(f, "popcount"))
        return vi(__builtin_popcountll((unsigned long long)a.i));
    if (!strcmp(f, "min") || !strcmp(f, "max")) {
        int lt = (a.isf || b.isf) ? as_f(a) < as_f(b) : a.i < b.i;
        int pick_a = !strcmp(f, "min") ? lt : !lt;
        return pick_a ? a : b;
    }
    if (!strcmp(f, "abs"))
        return a.isf ? vf(fabs(a.f)) : vi(a.i < 0 ? -a.i : a.i);
    if (!strcmp(f, "floor"))
        return vf(floor(as_f(a)));
    if (!strcmp(f, "sqrt"))
        return vf(sqrt(as_f(a)));
    if (!strcmp(f, "exp2"))
        return vf(exp2(as_f(a)));
    if (!strcmp(f, "log2"))
        return vf(log2(as_f(a)));
    if (!strcmp(f, "sin"))
        return vf(sin(as_f(a)));
    return vf(cos(as_f(a)));
}

static Val eval(const Expr *e, Env *env)
{
    if (env->err[0] || !e)
        return vi(0);
    switch (e->kind) {
    case E_INT: return vi(e->i);
    case E_FLT: return vf(e->f);
    case E_NAME:
        if (!strcmp(e->name, "l")) {
            if (env->lane < 0)
                snprintf(env->err, sizeof env->err, "l outside a per-lane check");
            return vi(env->lane);
        }
        if (!strcmp(e->name, "N"))
            return vi(env->lanes);
        if (!strcmp(e->name, "nan"))
            return vf(NAN);
        if (!strcmp(e->name, "inf"))
            return vf(INFINITY);
        for (uint32_t k = 0; env->obj && k < env->obj->nsyms; k++)
            if (env->obj->syms[k].name && !strcmp(env->obj->syms[k].name, e->name))
                return vi((int64_t)env->obj->syms[k].value);
        snprintf(env->err, sizeof env->err, "unknown name %s", e->name);
        return vi(0);
    case E_CALL: return eval_call(e, env);
    case E_TERN: {
        Val c = eval(e->a, env);
        int t = c.isf ? c.f != 0 : c.i != 0;
        return eval(t ? e->b : e->c, env);
    }
    case E_UN: {
        Val a = eval(e->a, env);
        switch (e->op) {
        case '-': return a.isf ? vf(-a.f) : vi((int64_t)(0 - (uint64_t)a.i));
        case '+': return a;
        case '!': return vi(a.isf ? a.f == 0 : a.i == 0);
        default:
            if (a.isf)
                snprintf(env->err, sizeof env->err, "~ of a float");
            return vi(~a.i);
        }
    }
    case E_BIN: {
        Val a = eval(e->a, env);
        if (e->op == T_AND || e->op == T_OR) {
            int ta = a.isf ? a.f != 0 : a.i != 0;
            if (e->op == T_AND && !ta)
                return vi(0);
            if (e->op == T_OR && ta)
                return vi(1);
            Val b = eval(e->b, env);
            return vi(b.isf ? b.f != 0 : b.i != 0);
        }
        Val b = eval(e->b, env);
        if (env->err[0])
            return vi(0);
        if (a.isf || b.isf) {
            double x = as_f(a), y = as_f(b);
            switch (e->op) {
            case '+': return vf(x + y);
            case '-': return vf(x - y);
            case '*': return vf(x * y);
            case '/': return vf(x / y);
            case '<': return vi(x < y);
            case '>': return vi(x > y);
            case T_LE: return vi(x <= y);
            case T_GE: return vi(x >= y);
            case T_EQ: return vi(x == y);
            case T_NE: return vi(x != y);
            default: snprintf(env->err, sizeof env->err, "integer operator on a float"); return vi(0);
            }
        }
        int64_t x = a.i, y = b.i;
        uint64_t ux = (uint64_t)x, uy = (uint64_t)y;
        switch (e->op) {
        case '+': return vi((int64_t)(ux + uy));
        case '-': return vi((int64_t)(ux - uy));
        case '*': return vi((int64_t)(ux * uy));
        case '/':
        case '%':
            if (y == 0) {
                snprintf(env->err, sizeof env->err, "division by zero in an expectation");
                return vi(0);
            }
            return vi(e->op == '/' ? x / y : x % y);
        case T_SHL: return vi((int64_t)(ux << (y & 63)));
        case T_SHR: return vi(x >> (y & 63));
        case '&': return vi(x & y);
        case '|': return vi(x | y);
        case '^': return vi(x ^ y);
        case '<': return vi(x < y);
        case '>': return vi(x > y);
        case T_LE: return vi(x <= y);
        case T_GE: return vi(x >= y);
        case T_EQ: return vi(x == y);
        case T_NE: return vi(x != y);
        default: snprintf(env->err, sizeof env->err, "bad operator"); return vi(0);
        }
    }
    }
    return vi(0);
}

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

static void spec_free(Spec *s)
{
    for (int i = 0; i < s->n; i++) {
        expr_free(s->checks[i].guard);
        expr_free(s->checks[i].index);
        expr_free(s->checks[i].expect);
        expr_free(s->checks[i].tol);
    }
    free(s->checks);
    memset(s, 0, sizeof *s);
}

static int reg_number(const char *text, char kind, int max)
{
    if (text[0] != kind || !isdigit((unsigned char)text[1]))
        return -1;
    char *end;
    long r = strtol(text + 1, &end, 10);
    return (*end == '\0' && r >= 0 && r <= max) ? (int)r : -1;
}

/* Parse one ";!" line body; returns 0, or -1 with a message in err. */
static int parse_check(const char *body, int line, Check *ck, char *err, size_t errlen)
{
    memset(ck, 0, sizeof *ck);
    ck->line = line;
    Lexer lx;
    memset(&lx, 0, sizeof lx);
    lx.s = body;
    lex_next(&lx);
    if (lx.tok == T_NAME && !strcmp(lx.text, "if")) {
        lex_next(&lx);
        ck->guard = parse_ternary(&lx);
        if (!lx.err[0] && lx.tok != ':')
            snprintf(lx.err, sizeof lx.err, "expected ':' after the condition of if");
        if (lx.err[0])
            goto fail;
        lex_next(&lx);
    }
    if (lx.tok != T_NAME) {
        snprintf(lx.err, sizeof lx.err, "expected a register, mem, stat, pc, trap, limit or max");
        goto fail;
    }
    char word[256];
    snprintf(word, sizeof word, "%s", lx.text);
    lex_next(&lx);
    if (!strcmp(word, "trap")) {
        ck->kind = X_TRAP;
        while (lx.tok == T_STR && ck->nsub < 4) {
            snprintf(ck->subs[ck->nsub++], sizeof ck->subs[0], "%.127s", lx.text);
            lex_next(&lx);
        }
        if (lx.tok != T_EOF && !lx.err[0])
            snprintf(lx.err, sizeof lx.err, "trap takes quoted strings only");
        if (lx.err[0])
            goto fail;
        return 0;
    }
    if (!strcmp(word, "limit")) {
        ck->kind = X_LIMIT;
        if (lx.tok != T_EOF)
            snprintf(lx.err, sizeof lx.err, "limit takes no argument");
        if (lx.err[0])
            goto fail;
        return 0;
    }
    if (!strcmp(word, "max")) {
        ck->kind = X_MAX;
        if (ck->guard)
            snprintf(lx.err, sizeof lx.err, "max cannot be conditional");
        else
            ck->expect = parse_ternary(&lx);
        if (!lx.err[0] && lx.tok != T_EOF)
            snprintf(lx.err, sizeof lx.err, "junk after max");
        if (lx.err[0])
            goto fail;
        return 0;
    }
    int r;
    if ((r = reg_number(word, 'r', 31)) >= 0) {
        ck->kind = X_SREG;
        ck->reg = r;
    } else if ((r = reg_number(word, 'v', 31)) >= 0) {
        ck->kind = X_VREG;
        ck->reg = r;
    } else if ((r = reg_number(word, 'm', 7)) >= 0) {
        ck->kind = lx.tok == '[' ? X_MBIT : X_MASK;
        ck->reg = r;
    } else if (!strcmp(word, "pc")) {
        ck->kind = X_PC;
    } else if (!strcmp(word, "stat")) {
        ck->kind = X_STAT;
        if (lx.tok != T_NAME) {
            snprintf(lx.err, sizeof lx.err, "stat needs a key");
            goto fail;
        }
        snprintf(ck->key, sizeof ck->key, "%.63s", lx.text);
        lex_next(&lx);
    } else if (!strcmp(word, "mem")) {
        ck->kind = X_MEM;
        if (lx.tok != T_NAME) {
            snprintf(lx.err, sizeof lx.err, "mem needs a memory name");
            goto fail;
        }
        ck->reg = -99;
        if (!strcmp(lx.text, "rbc"))
            ck->reg = -1;
        else if (!strcmp(lx.text, "rbn"))
            ck->reg = -2;
        for (int m = 0; m < CORE_MEM_COUNT; m++)
            if (!strcmp(lx.text, core_mem_names[m]))
                ck->reg = m;
        if (ck->reg == -99) {
            snprintf(lx.err, sizeof lx.err, "unknown memory %.100s", lx.text);
            goto fail;
        }
        lex_next(&lx);
    } else {
        snprintf(lx.err, sizeof lx.err, "unknown check \"%.100s\"", word);
        goto fail;
    }
    if (ck->kind == X_VREG || ck->kind == X_MBIT || ck->kind == X_MEM) {
        if (lx.tok != '[') {
            snprintf(lx.err, sizeof lx.err, "expected '[' after %.100s", word);
            goto fail;
        }
        lex_next(&lx);
        ck->index = parse_ternary(&lx);
        if (!lx.err[0] && lx.tok != ']')
            snprintf(lx.err, sizeof lx.err, "expected ']'");
        if (lx.err[0])
            goto fail;
        lex_next(&lx);
    }
    switch (lx.tok) {
    case T_EQ: ck->op = OP_EQ; break;
    case T_NE: ck->op = OP_NE; break;
    case T_FEQ: ck->op = OP_FEQ; break;
    case T_APPROX: ck->op = OP_APPROX; break;
    default: snprintf(lx.err, sizeof lx.err, "expected ==, !=, ==f or ~="); goto fail;
    }
    if ((ck->op == OP_FEQ || ck->op == OP_APPROX) && ck->kind != X_SREG && ck->kind != X_VREG && ck->kind != X_MEM) {
        snprintf(lx.err, sizeof lx.err, "float comparison of a mask or counter");
        goto fail;
    }
    lex_next(&lx);
    ck->expect = parse_ternary(&lx);
    if (!lx.err[0] && ck->op == OP_APPROX) {
        if (lx.tok == T_EOF)
            snprintf(lx.err, sizeof lx.err, "~= needs a tolerance: ~= VALUE TOL");
        else
            ck->tol = parse_ternary(&lx);
    }
    if (!lx.err[0] && lx.tok != T_EOF)
        snprintf(lx.err, sizeof lx.err, "junk at \"%.20s\"", lx.s);
    if (lx.err[0])
        goto fail;
    ck->per_lane = expr_uses_lane(ck->guard) || expr_uses_lane(ck->index) || expr_uses_lane(ck->expect) ||
                   expr_uses_lane(ck->tol);
    return 0;
fail:
    snprintf(err, errlen, "%s", lx.err);
    expr_free(ck->guard);
    expr_free(ck->index);
    expr_free(ck->expect);
    expr_free(ck->tol);
    memset(ck, 0, sizeof *ck);
    return -1;
}

/* Collect the ";!" lines of path. Parse errors are test failures. Returns the number of errors. */
static int spec_load(const char *path, Spec *spec)
{
    memset(spec, 0, sizeof *spec);
    spec->limit = DEFAULT_LIMIT;
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "cannot open %s", path);
    char buf[1024];
    int line = 0, errors = 0;
    while (fgets(buf, sizeof buf, f)) {
        line++;
        const char *p = buf;
        while (*p == ' ' || *p == '\t')
            p++;
        if (p[0] != ';' || p[1] != '!')
            continue;
        Check ck;
        char err[200];
        if (parse_check(p + 2, line, &ck, err, sizeof err) != 0) {
            cr_expect_fail("%s:%d: bad expectation: %s", path, line, err);
            errors++;
            continue;
        }
        if (spec->n == spec->cap) {
            spec->cap = spec->cap ? 2 * spec->cap : 32;
            spec->checks = realloc(spec->checks, (size_t)spec->cap * sizeof *spec->checks);
            cr_assert_not_null(spec->checks);
        }
        spec->checks[spec->n++] = ck;
    }
    fclose(f);
    return errors;
}

/* ---- running ------------------------------------------------------------------------------ */

static void test_params(CoreParams *p, int lanes)
{
    memset(p, 0, sizeof *p);
    p->lanes = lanes;
    p->mem_bytes[CORE_MEM_RB0] = 512 * 1024;
    p->mem_bytes[CORE_MEM_RB1] = 512 * 1024;
    p->mem_bytes[CORE_MEM_IDM] = 32 * 1024;
    p->mem_bytes[CORE_MEM_SPAD] = 64 * 1024;
    p->mem_bytes[CORE_MEM_SCENE] = 1024 * 1024;
    p->mem_bytes[CORE_MEM_FB] = 64 * 1024;
}

typedef struct Run {
    const char *path;
    int lanes;
    Core *core;
    const AsmObject *obj;
    int failures;
} Run;

#define MAX_REPORTS 40

static void report(Run *run, const Check *ck, int lane, const char *fmt, ...)
{
    run->failures++;
    if (run->failures > MAX_REPORTS)
        return;
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (lane >= 0)
        cr_expect_fail("%s:%d N=%d lane %d: %s", run->path, ck->line, run->lanes, lane, msg);
    else
        cr_expect_fail("%s:%d N=%d: %s", run->path, ck->line, run->lanes, msg);
}

static int stage_from_key(const char *k, size_t n)
{
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        if (strlen(isa_stage_keys[s]) == n && !strncmp(k, isa_stage_keys[s], n))
            return s;
    return -1;
}

static int stat_value(Core *c, const char *key, uint64_t *out)
{
    const CoreStats *st = core_stats(c);
    if (!strcmp(key, "total")) {
        *out = core_instructions(c);
        return 0;
    }
    int gen = -1;
    if (!strncmp(key, "gen", 3) && key[3] >= '0' && key[3] <= '9') {
        char *end;
        long g = strtol(key + 3, &end, 10);
        if (*end != '.' || g < 0 || g >= CORE_GENERATIONS)
            return -1;
        gen = (int)g;
        key = end + 1;
    }
    const char *dot = strchr(key, '.');
    if (!dot)
        return -1;
    size_t head = (size_t)(dot - key);
    if (gen >= 0) {
        int gs = stage_from_key(dot + 1, strlen(dot + 1));
        if (gs < 0)
            return -1;
        if (head == 5 && !strncmp(key, "instr", 5))
            *out = st->gen_instructions[gen][gs];
        else if (head == 3 && !strncmp(key, "vec", 3))
            *out = st->gen_vec_instructions[gen][gs];
        else if (head == 5 && !strncmp(key, "lanes", 5))
            *out = st->gen_active_lanes[gen][gs];
        else
            return -1;
        return 0;
    }
    const char *rest = dot + 1;
    if (head == 2 && !strncmp(key, "op", 2)) {
        int op = isa_op_from_mnemonic(rest);
        if (op < 0)
            return -1;
        *out = st->by_op[op];
        return 0;
    }
    if (head == 3 && !strncmp(key, "cat", 3)) {
        const char *dot2 = strchr(rest, '.');
        if (!dot2)
            return -1;
        int s = stage_from_key(rest, (size_t)(dot2 - rest));
        for (int cat = 0; s >= 0 && cat < ISA_C_COUNT; cat++)
            if (!strcmp(dot2 + 1, isa_category_keys[cat])) {
                *out = st->ops[s][cat];
                return 0;
            }
        return -1;
    }
    int s = stage_from_key(rest, strlen(rest));
    if (s < 0)
        return -1;
    if (head == 5 && !strncmp(key, "instr", 5))
        *out = st->instructions[s];
    else if (head == 3 && !strncmp(key, "vec", 3))
        *out = st->vec_instructions[s];
    else if (head == 5 && !strncmp(key, "lanes", 5))
        *out = st->active_lanes[s];
    else
        return -1;
    return 0;
}

static int truthy(Val v) { return v.isf ? v.f != 0 : v.i != 0; }

static void fmt_word(char *buf, size_t len, uint32_t w, int as_float)
{
    if (as_float)
        snprintf(buf, len, "0x%08" PRIx32 " (%.9g)", w, (double)bits_f32(w));
    else
        snprintf(buf, len, "0x%08" PRIx32 " (%" PRId32 ")", w, (int32_t)w);
}

/* Compare a 32-bit value; 0 when it matches. */
static int compare_word(Run *run, const Check *ck, int lane, Env *env, const char *what, uint32_t actual)
{
    Val ex = eval(ck->expect, env);
    Val tol = ck->tol ? eval(ck->tol, env) : vi(0);
    if (env->err[0]) {
        report(run, ck, lane, "%s", env->err);
        return -1;
    }
    char got[64], want[64];
    switch (ck->op) {
    case OP_EQ:
    case OP_NE: {
        if (ex.isf) {
            report(run, ck, lane, "== needs an integer expectation (use ==f for floats)");
            return -1;
        }
        uint32_t w = (uint32_t)ex.i;
        int eq = actual == w;
        if (eq == (ck->op == OP_EQ))
            return 0;
        fmt_word(got, sizeof got, actual, 0);
        fmt_word(want, sizeof want, w, 0);
        report(run, ck, lane, "%s = %s expected %s%s", what, got, ck->op == OP_NE ? "not " : "", want);
        return -1;
    }
    case OP_FEQ: {
        uint32_t w = f32_bits(as_f(ex));
        float a = bits_f32(actual);
        if (actual == w || (isnan(a) && isnan(as_f(ex))))
            return 0;
        fmt_word(got, sizeof got, actual, 1);
        fmt_word(want, sizeof want, w, 1);
        report(run, ck, lane, "%s = %s expected %s", what, got, want);
        return -1;
    }
    case OP_APPROX: {
        double a = bits_f32(actual), e = as_f(ex), t = as_f(tol);
        if ((isnan(a) && isnan(e)) || a == e || fabs(a - e) <= t)
            return 0;
        fmt_word(got, sizeof got, actual, 1);
        report(run, ck, lane, "%s = %s expected %.9g within %g", what, got, e, t);
        return -1;
    }
    }
    return -1;
}

static int compare_u64(Run *run, const Check *ck, int lane, Env *env, const char *what, uint64_t actual)
{
    Val ex = eval(ck->expect, env);
    if (env->err[0]) {
        report(run, ck, lane, "%s", env->err);
        return -1;
    }
    if (ex.isf) {
        report(run, ck, lane, "%s needs an integer expectation", what);
        return -1;
    }
    int eq = actual == (uint64_t)ex.i;
    if (eq == (ck->op == OP_EQ))
        return 0;
    report(run, ck, lane, "%s = 0x%" PRIx64 " (%" PRIu64 ") expected %s0x%" PRIx64 " (%" PRId64 ")", what, actual,
           actual, ck->op == OP_NE ? "not " : "", (uint64_t)ex.i, ex.i);
    return -1;
}

static void check_one(Run *run, const Check *ck, int lane)
{
    Env env = {run->lanes, lane, run->obj, ""};
    if (ck->guard) {
        Val g = eval(ck->guard, &env);
        if (env.err[0]) {
            report(run, ck, lane, "%s", env.err);
            return;
        }
        if (!truthy(g))
            return;
    }
    int64_t idx = 0;
    if (ck->index) {
        Val iv = eval(ck->index, &env);
        if (env.err[0] || iv.isf) {
            report(run, ck, lane, "%s", env.err[0] ? env.err : "index is not an integer");
            return;
        }
        idx = iv.i;
    }
    char what[96];
    Core *c = run->core;
    switch (ck->kind) {
    case X_SREG:
        snprintf(what, sizeof what, "r%d", ck->reg);
        compare_word(run, ck, lane, &env, what, core_sreg(c, ck->reg));
        return;
    case X_VREG:
        if (idx < 0 || idx >= run->lanes) {
            report(run, ck, lane, "lane index %" PRId64 " outside 0..%d (add a guard)", idx, run->lanes - 1);
            return;
        }
        if (lane >= 0 && idx != lane)
            snprintf(what, sizeof what, "v%d[%" PRId64 "]", ck->reg, idx);
        else
            snprintf(what, sizeof what, "v%d", ck->reg);
        compare_word(run, ck, lane < 0 ? (int)idx : lane, &env, what, core_vreg(c, ck->reg, (int)idx));
        return;
    case X_MBIT:
        if (idx < 0 || idx >= run->lanes) {
            report(run, ck, lane, "lane index %" PRId64 " outside 0..%d (add a guard)", idx, run->lanes - 1);
            return;
        }
        snprintf(what, sizeof what, "m%d bit", ck->reg);
        compare_u64(run, ck, lane < 0 ? (int)idx : lane, &env, what, (core_mreg(c, ck->reg) >> idx) & 1u);
        return;
    case X_MASK:
        snprintf(what, sizeof what, "m%d", ck->reg);
        compare_u64(run, ck, lane, &env, what, core_mreg(c, ck->reg));
        return;
    case X_PC:
        compare_u64(run, ck, lane, &env, "pc", core_pc(c));
        return;
    case X_STAT: {
        uint64_t v;
        if (stat_value(c, ck->key, &v) != 0) {
            report(run, ck, lane, "unknown stat key %s", ck->key);
            return;
        }
        snprintf(what, sizeof what, "stat %s", ck->key);
        compare_u64(run, ck, lane, &env, what, v);
        return;
    }
    case X_MEM: {
        int m = ck->reg;
        if (m == -1)
            m = core_current_rb(c) ? CORE_MEM_RB1 : CORE_MEM_RB0;
        else if (m == -2)
            m = core_current_rb(c) ? CORE_MEM_RB0 : CORE_MEM_RB1;
        uint32_t bytes;
        uint8_t *mem = core_mem(c, (CoreMem)m, &bytes);
        if (idx < 0 || idx % 4 != 0 || (uint64_t)idx + 4 > bytes || !mem) {
            report(run, ck, lane, "address %" PRId64 " is not a word of %s (%u bytes)", idx, core_mem_names[m], bytes);
            return;
        }
        uint32_t w = (uint32_t)mem[idx] | (uint32_t)mem[idx + 1] << 8 | (uint32_t)mem[idx + 2] << 16 |
                     (uint32_t)mem[idx + 3] << 24;
        snprintf(what, sizeof what, "%s[%" PRId64 "]", core_mem_names[m], idx);
        compare_word(run, ck, lane, &env, what, w);
        return;
    }
    case X_TRAP:
    case X_LIMIT:
    case X_MAX: return;
    }
}

/* Guards of trap/limit checks use N only. */
static int applies(Run *run, const Check *ck)
{
    if (!ck->guard)
        return 1;
    Env env = {run->lanes, -1, run->obj, ""};
    Val g = eval(ck->guard, &env);
    if (env.err[0]) {
        report(run, ck, -1, "%s", env.err);
        return 0;
    }
    return truthy(g);
}

static void run_width(const char *path, const AsmObject *obj, const Spec *spec, int lanes, int file_op)
{
    CoreParams prm;
    test_params(&prm, lanes);
    char err[512];
    Run run = {path, lanes, NULL, obj, 0};
    run.core = core_new(&prm, obj, err, sizeof err);
    if (!run.core) {
        cr_expect_fail("%s N=%d: core_new failed: %s", path, lanes, err);
        return;
    }
    CoreExit ex = core_run(run.core, spec->limit);
    const char *msg = ex == CORE_EXIT_HALT ? "" : core_trap_message(run.core);
    if (!msg)
        msg = "";

    const Check *trap = NULL, *limit = NULL;
    for (int i = 0; i < spec->n; i++) {
        const Check *ck = &spec->checks[i];
        if (ck->kind == X_TRAP && applies(&run, ck) && !trap)
            trap = ck;
        if (ck->kind == X_LIMIT && applies(&run, ck) && !limit)
            limit = ck;
    }
    static const char *const exits[] = {"halt", "trap", "instruction limit"};
    if (trap) {
        if (ex != CORE_EXIT_TRAP)
            report(&run, trap, -1, "expected a trap, the run ended in %s %s", exits[ex], msg);
        for (int i = 0; ex == CORE_EXIT_TRAP && i < spec->n; i++) {
            const Check *ck = &spec->checks[i];
            if (ck->kind != X_TRAP || !applies(&run, ck))
                continue;
            for (int k = 0; k < ck->nsub; k++)
                if (!strstr(msg, ck->subs[k]))
                    report(&run, ck, -1, "trap message \"%s\" does not contain \"%s\"", msg, ck->subs[k]);
        }
    } else if (limit) {
        if (ex != CORE_EXIT_LIMIT)
            report(&run, limit, -1, "expected the instruction limit, the run ended in %s %s", exits[ex], msg);
    } else if (ex != CORE_EXIT_HALT) {
        run.failures++;
        cr_expect_fail("%s N=%d: the program did not halt: %s %s", path, lanes, exits[ex], msg);
    }

    for (int i = 0; i < spec->n; i++) {
        const Check *ck = &spec->checks[i];
        if (ck->kind == X_TRAP || ck->kind == X_LIMIT || ck->kind == X_MAX)
            continue;
        if (ck->per_lane)
            for (int l = 0; l < lanes; l++)
                check_one(&run, ck, l);
        else
            check_one(&run, ck, -1);
    }

    if (file_op >= 0 && core_stats(run.core)->by_op[file_op] == 0) {
        run.failures++;
        cr_expect_fail("%s N=%d: the program never executes %s", path, lanes, isa_ops[file_op].mnemonic);
    }
    if (run.failures > MAX_REPORTS)
        cr_expect_fail("%s N=%d: %d more failures not shown", path, lanes, run.failures - MAX_REPORTS);
    core_free(run.core);
}

/* The mnemonic a program is named after, or -1. */
static int op_of_path(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char name[64];
    snprintf(name, sizeof name, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot)
        *dot = '\0';
    return isa_op_from_mnemonic(name);
}

static void run_program(const char *path)
{
    Spec spec;
    int bad = spec_load(path, &spec);
    if (bad) {
        spec_free(&spec);
        return;
    }
    int has_checks = 0;
    for (int i = 0; i < spec.n; i++) {
        if (spec.checks[i].kind == X_MAX) {
            Env env = {1, -1, NULL, ""};
            Val v = eval(spec.checks[i].expect, &env);
            spec.limit = (uint64_t)(v.isf ? v.f : (double)v.i);
        } else {
            has_checks = 1;
        }
    }
    cr_expect(has_checks, "%s: no expectations (;! lines)", path);

    char *diag_buf = NULL;
    size_t diag_len = 0;
    FILE *diag = open_memstream(&diag_buf, &diag_len);
    AsmOptions opt = {.diag = diag};
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    int errors = asm_assemble_file(path, &opt, &obj);
    fclose(diag);
    if (errors) {
        cr_expect_fail("%s: %d assembly errors:\n%s", path, errors, diag_buf ? diag_buf : "");
    } else {
        int op = op_of_path(path);
        for (int w = 0; w < N_WIDTHS; w++)
            run_width(path, &obj, &spec, widths[w], op);
        asm_object_free(&obj);
    }
    free(diag_buf);
    spec_free(&spec);
}

/* ---- tests -------------------------------------------------------------------------------- */

typedef struct ProgParam {
    char path[256];
} ProgParam;

ParameterizedTestParameters(isa_programs, run)
{
    glob_t g;
    size_t n = 0;
    ProgParam *params = NULL;
    if (glob(ISA_PROG_DIR "/*.s", 0, NULL, &g) == 0) {
        n = g.gl_pathc;
        params = cr_malloc(n * sizeof *params);
        for (size_t i = 0; i < n; i++)
            snprintf(params[i].path, sizeof params[i].path, "%s", g.gl_pathv[i]);
        globfree(&g);
    }
    return cr_make_param_array(ProgParam, params, n);
}

ParameterizedTest(ProgParam *p, isa_programs, run)
{
    run_program(p->path);
}

Test(isa_programs, every_opcode_has_a_program)
{
    int missing = 0;
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        char path[128];
        struct stat st;
        snprintf(path, sizeof path, ISA_PROG_DIR "/%s.s", isa_ops[op].mnemonic);
        if (stat(path, &st) != 0) {
            missing++;
            cr_expect_fail("%s is missing: every opcode needs a test program", path);
        }
    }
    cr_expect_eq(missing, 0, "%d of %d opcodes have no test program", missing, (int)ISA_OP_COUNT);
}

/* The harness itself: the evaluator and the parser, on expectations whose answers are known. */
Test(isa_programs, expectation_language)
{
    struct { const char *text; int64_t want; } ints[] = {
        {"1 + 2 * 3", 7},          {"(1 + 2) * 3", 9},        {"7 / 2", 3},       {"-7 % 3", -1},
        {"1 << 31", 2147483648ll}, {"0xff & 0x0f | 0x100", 0x10f}, {"5 > 3 && 2 < 1", 0},
        {"0 || 3", 1},             {"N - 1", 3},              {"l * 2 + 1", 5},   {"l < 3 ? 10 : 20", 10},
        {"f(1.5)", 0x3FC00000},    {"f(-0.0)", 0x80000000ll}, {"u32(-1)", 0xFFFFFFFFll},
        {"s32(0xFFFFFFFF)", -1},   {"popcount(0xF0F0)", 8},   {"min(3, -2)", -2}, {"max(3, -2)", 3},
        {"int(-2.7)", -2},         {"f(float(float(0.1) + float(0.2)))", 0x3E99999A}, {"~0 & 0xF", 15},
        {"!0", 1},                 {"1 ? 2 ? 3 : 4 : 5", 3},  {"f(fl(0x7F800000))", 0x7F800000},
    };
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++) {
        Lexer lx;
        memset(&lx, 0, sizeof lx);
        lx.s = ints[i].text;
        lex_next(&lx);
        Expr *e = parse_ternary(&lx);
        cr_assert_eq(lx.err[0], 0, "\"%s\": %s", ints[i].text, lx.err);
        cr_assert_eq(lx.tok, T_EOF, "\"%s\": not fully parsed", ints[i].text);
        Env env = {4, 2, NULL, ""};
        Val v = eval(e, &env);
        cr_expect_eq(env.err[0], 0, "\"%s\": %s", ints[i].text, env.err);
        cr_expect(!v.isf && v.i == ints[i].want, "\"%s\" = %lld, expected %lld", ints[i].text, (long long)v.i,
                  (long long)ints[i].want);
        expr_free(e);
    }
    Check ck;
    char err[200];
    cr_expect_eq(parse_check(" v2[l] ==f l * 0.5", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_VREG);
    cr_expect_eq(ck.op, OP_FEQ);
    cr_expect(ck.per_lane);
    expr_free(ck.index);
    expr_free(ck.expect);
    cr_expect_eq(parse_check(" if N >= 4: r3 ~= 1.5 1e-6", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_SREG);
    cr_expect_eq(ck.op, OP_APPROX);
    cr_expect_not_null(ck.tol);
    cr_expect_not_null(ck.guard);
    cr_expect(!ck.per_lane);
    expr_free(ck.guard);
    expr_free(ck.expect);
    expr_free(ck.tol);
    cr_expect_eq(parse_check(" trap \"divu\" \"x.s:3\"", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.nsub, 2);
    cr_expect_str_eq(ck.subs[1], "x.s:3");
    cr_expect_eq(parse_check(" mem idm[4*l] == l", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_MEM);
    cr_expect_eq(ck.reg, CORE_MEM_IDM);
    expr_free(ck.index);
    expr_free(ck.expect);
    cr_expect_eq(parse_check(" m1 == 3", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_MASK);
    expr_free(ck.expect);
    cr_expect_eq(parse_check(" r3 = 7", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(parse_check(" r32 == 7", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(parse_check(" m1 ==f 1.0", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(parse_check(" r3 ~= 1.5", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(parse_check(" r3 == (1", 3, &ck, err, sizeof err), -1);
}
