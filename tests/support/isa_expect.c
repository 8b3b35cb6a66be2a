/* tests/support/isa_expect.c -- the expectation language of the programs tests/isa/<mnemonic>.s
 * (isa_expect.h).
 *
 * Owns: the lexer, the expression parser and evaluator, the check parser and the reading of a
 * file's ";!" lines. Must not: run the core or compare its results (tests/unit/test_isa_programs.c).
 */
#include "isa_expect.h"

#include <criterion/criterion.h>
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/core.h"

#define DEFAULT_LIMIT 1000000ull

/* ---- expressions ------------------------------------------------------------------------ */

void ie_lex_next(Lexer *lx)
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

void ie_expr_free(Expr *e)
{
    if (!e)
        return;
    ie_expr_free(e->a);
    ie_expr_free(e->b);
    ie_expr_free(e->c);
    free(e);
}

static Expr *parse_primary(Lexer *lx)
{
    if (lx->err[0])
        return NULL;
    if (lx->tok == T_NUM) {
        Expr *e = expr_new(lx->isf ? E_FLT : E_INT);
        e->i = lx->ival;
        e->f = lx->fval;
        ie_lex_next(lx);
        return e;
    }
    if (lx->tok == T_NAME) {
        Expr *e = expr_new(E_NAME);
        snprintf(e->name, sizeof e->name, "%.47s", lx->text);
        ie_lex_next(lx);
        if (lx->tok == '(') {
            e->kind = E_CALL;
            ie_lex_next(lx);
            Expr **slot[3] = {&e->a, &e->b, &e->c};
            int n = 0;
            if (lx->tok != ')')
                for (;;) {
                    if (n == 3) {
                        snprintf(lx->err, sizeof lx->err, "too many arguments to %s", e->name);
                        ie_expr_free(e);
                        return NULL;
                    }
                    *slot[n++] = ie_parse_expr(lx);
                    if (lx->err[0]) {
                        ie_expr_free(e);
                        return NULL;
                    }
                    if (lx->tok != ',')
                        break;
                    ie_lex_next(lx);
                }
            e->i = n;
            if (lx->tok != ')') {
                snprintf(lx->err, sizeof lx->err, "expected ')' after the arguments of %s", e->name);
                ie_expr_free(e);
                return NULL;
            }
            ie_lex_next(lx);
        }
        return e;
    }
    if (lx->tok == '(') {
        ie_lex_next(lx);
        Expr *e = ie_parse_expr(lx);
        if (!lx->err[0] && lx->tok != ')')
            snprintf(lx->err, sizeof lx->err, "expected ')'");
        if (lx->err[0]) {
            ie_expr_free(e);
            return NULL;
        }
        ie_lex_next(lx);
        return e;
    }
    snprintf(lx->err, sizeof lx->err, "expected a value at \"%.20s\"", lx->s);
    return NULL;
}

static Expr *parse_unary(Lexer *lx)
{
    if (lx->tok == '-' || lx->tok == '+' || lx->tok == '!' || lx->tok == '~') {
        int op = lx->tok;
        ie_lex_next(lx);
        Expr *e = expr_new(E_UN);
        e->op = op;
        e->a = parse_unary(lx);
        if (lx->err[0]) {
            ie_expr_free(e);
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
            ie_expr_free(left);
            return NULL;
        }
        int hit = 0;
        for (int k = 0; k < 5 && levels[lv][k]; k++)
            hit |= lx->tok == levels[lv][k];
        if (!hit)
            return left;
        Expr *e = expr_new(E_BIN);
        e->op = lx->tok;
        ie_lex_next(lx);
        e->a = left;
        e->b = parse_level(lx, lv + 1);
        left = e;
    }
}

Expr *ie_parse_expr(Lexer *lx)
{
    Expr *cond = parse_level(lx, 0);
    if (lx->err[0] || lx->tok != '?')
        return cond;
    ie_lex_next(lx);
    Expr *e = expr_new(E_TERN);
    e->a = cond;
    e->b = ie_parse_expr(lx);
    if (!lx->err[0] && lx->tok != ':')
        snprintf(lx->err, sizeof lx->err, "expected ':' in ?:");
    if (lx->err[0]) {
        ie_expr_free(e);
        return NULL;
    }
    ie_lex_next(lx);
    e->c = ie_parse_expr(lx);
    if (lx->err[0]) {
        ie_expr_free(e);
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

double ie_as_f(Val v) { return v.isf ? v.f : (double)v.i; }

Val ie_vi(int64_t i) { return (Val){0, i, 0}; }
static Val vf(double f) { return (Val){1, 0, f}; }

uint32_t ie_f32_bits(double d)
{
    float x = (float)d;
    uint32_t u;
    memcpy(&u, &x, 4);
    return u;
}

float ie_bits_f32(uint32_t u)
{
    float x;
    memcpy(&x, &u, 4);
    return x;
}

static Val eval_call(const Expr *e, Env *env)
{
    int n = (int)e->i;
    Val a = n > 0 ? ie_eval(e->a, env) : ie_vi(0), b = n > 1 ? ie_eval(e->b, env) : ie_vi(0);
    if (env->err[0])
        return ie_vi(0);
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
        return ie_vi(0);
    }
    if (fns[known].nargs != n) {
        snprintf(env->err, sizeof env->err, "%s takes %d argument(s)", e->name, fns[known].nargs);
        return ie_vi(0);
    }
    const char *f = e->name;
    if (!strcmp(f, "f"))
        return ie_vi(ie_f32_bits(ie_as_f(a)));
    if (!strcmp(f, "fl"))
        return vf(ie_bits_f32((uint32_t)a.i));
    if (!strcmp(f, "float"))
        return vf((float)ie_as_f(a));
    if (!strcmp(f, "int"))
        return ie_vi(a.isf ? (int64_t)a.f : a.i);
    if (!strcmp(f, "u32"))
        return ie_vi((int64_t)(uint32_t)(a.isf ? (int64_t)a.f : a.i));
    if (!strcmp(f, "s32"))
        return ie_vi((int64_t)(int32_t)(uint32_t)(a.isf ? (int64_t)a.f : a.i));
    if (!strcmp(f, "popcount"))
        return ie_vi(__builtin_popcountll((unsigned long long)a.i));
    if (!strcmp(f, "min") || !strcmp(f, "max")) {
        int lt = (a.isf || b.isf) ? ie_as_f(a) < ie_as_f(b) : a.i < b.i;
        int pick_a = !strcmp(f, "min") ? lt : !lt;
        return pick_a ? a : b;
    }
    if (!strcmp(f, "abs"))
        return a.isf ? vf(fabs(a.f)) : ie_vi(a.i < 0 ? -a.i : a.i);
    if (!strcmp(f, "floor"))
        return vf(floor(ie_as_f(a)));
    if (!strcmp(f, "sqrt"))
        return vf(sqrt(ie_as_f(a)));
    if (!strcmp(f, "exp2"))
        return vf(exp2(ie_as_f(a)));
    if (!strcmp(f, "log2"))
        return vf(log2(ie_as_f(a)));
    if (!strcmp(f, "sin"))
        return vf(sin(ie_as_f(a)));
    return vf(cos(ie_as_f(a)));
}

Val ie_eval(const Expr *e, Env *env)
{
    if (env->err[0] || !e)
        return ie_vi(0);
    switch (e->kind) {
    case E_INT: return ie_vi(e->i);
    case E_FLT: return vf(e->f);
    case E_NAME:
        if (!strcmp(e->name, "l")) {
            if (env->lane < 0)
                snprintf(env->err, sizeof env->err, "l outside a per-lane check");
            return ie_vi(env->lane);
        }
        if (!strcmp(e->name, "N"))
            return ie_vi(env->lanes);
        if (!strcmp(e->name, "nan"))
            return vf(NAN);
        if (!strcmp(e->name, "inf"))
            return vf(INFINITY);
        for (uint32_t k = 0; env->obj && k < env->obj->nsyms; k++)
            if (env->obj->syms[k].name && !strcmp(env->obj->syms[k].name, e->name))
                return ie_vi((int64_t)env->obj->syms[k].value);
        snprintf(env->err, sizeof env->err, "unknown name %s", e->name);
        return ie_vi(0);
    case E_CALL: return eval_call(e, env);
    case E_TERN: {
        Val c = ie_eval(e->a, env);
        int t = c.isf ? c.f != 0 : c.i != 0;
        return ie_eval(t ? e->b : e->c, env);
    }
    case E_UN: {
        Val a = ie_eval(e->a, env);
        switch (e->op) {
        case '-': return a.isf ? vf(-a.f) : ie_vi((int64_t)(0 - (uint64_t)a.i));
        case '+': return a;
        case '!': return ie_vi(a.isf ? a.f == 0 : a.i == 0);
        default:
            if (a.isf)
                snprintf(env->err, sizeof env->err, "~ of a float");
            return ie_vi(~a.i);
        }
    }
    case E_BIN: {
        Val a = ie_eval(e->a, env);
        if (e->op == T_AND || e->op == T_OR) {
            int ta = a.isf ? a.f != 0 : a.i != 0;
            if (e->op == T_AND && !ta)
                return ie_vi(0);
            if (e->op == T_OR && ta)
                return ie_vi(1);
            Val b = ie_eval(e->b, env);
            return ie_vi(b.isf ? b.f != 0 : b.i != 0);
        }
        Val b = ie_eval(e->b, env);
        if (env->err[0])
            return ie_vi(0);
        if (a.isf || b.isf) {
            double x = ie_as_f(a), y = ie_as_f(b);
            switch (e->op) {
            case '+': return vf(x + y);
            case '-': return vf(x - y);
            case '*': return vf(x * y);
            case '/': return vf(x / y);
            case '<': return ie_vi(x < y);
            case '>': return ie_vi(x > y);
            case T_LE: return ie_vi(x <= y);
            case T_GE: return ie_vi(x >= y);
            case T_EQ: return ie_vi(x == y);
            case T_NE: return ie_vi(x != y);
            default: snprintf(env->err, sizeof env->err, "integer operator on a float"); return ie_vi(0);
            }
        }
        int64_t x = a.i, y = b.i;
        uint64_t ux = (uint64_t)x, uy = (uint64_t)y;
        switch (e->op) {
        case '+': return ie_vi((int64_t)(ux + uy));
        case '-': return ie_vi((int64_t)(ux - uy));
        case '*': return ie_vi((int64_t)(ux * uy));
        case '/':
        case '%':
            if (y == 0) {
                snprintf(env->err, sizeof env->err, "division by zero in an expectation");
                return ie_vi(0);
            }
            return ie_vi(e->op == '/' ? x / y : x % y);
        case T_SHL: return ie_vi((int64_t)(ux << (y & 63)));
        case T_SHR: return ie_vi(x >> (y & 63));
        case '&': return ie_vi(x & y);
        case '|': return ie_vi(x | y);
        case '^': return ie_vi(x ^ y);
        case '<': return ie_vi(x < y);
        case '>': return ie_vi(x > y);
        case T_LE: return ie_vi(x <= y);
        case T_GE: return ie_vi(x >= y);
        case T_EQ: return ie_vi(x == y);
        case T_NE: return ie_vi(x != y);
        default: snprintf(env->err, sizeof env->err, "bad operator"); return ie_vi(0);
        }
    }
    }
    return ie_vi(0);
}

/* ---- expectations ------------------------------------------------------------------------ */

void ie_spec_free(Spec *s)
{
    for (int i = 0; i < s->n; i++) {
        ie_expr_free(s->checks[i].guard);
        ie_expr_free(s->checks[i].index);
        ie_expr_free(s->checks[i].expect);
        ie_expr_free(s->checks[i].tol);
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

int ie_parse_check(const char *body, int line, Check *ck, char *err, size_t errlen)
{
    memset(ck, 0, sizeof *ck);
    ck->line = line;
    Lexer lx;
    memset(&lx, 0, sizeof lx);
    lx.s = body;
    ie_lex_next(&lx);
    if (lx.tok == T_NAME && !strcmp(lx.text, "if")) {
        ie_lex_next(&lx);
        ck->guard = ie_parse_expr(&lx);
        if (!lx.err[0] && lx.tok != ':')
            snprintf(lx.err, sizeof lx.err, "expected ':' after the condition of if");
        if (lx.err[0])
            goto fail;
        ie_lex_next(&lx);
    }
    if (lx.tok != T_NAME) {
        snprintf(lx.err, sizeof lx.err, "expected a register, mem, stat, pc, trap, limit or max");
        goto fail;
    }
    char word[256];
    snprintf(word, sizeof word, "%s", lx.text);
    ie_lex_next(&lx);
    if (!strcmp(word, "trap")) {
        ck->kind = X_TRAP;
        while (lx.tok == T_STR && ck->nsub < 4) {
            snprintf(ck->subs[ck->nsub++], sizeof ck->subs[0], "%.127s", lx.text);
            ie_lex_next(&lx);
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
            ck->expect = ie_parse_expr(&lx);
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
        ie_lex_next(&lx);
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
        ie_lex_next(&lx);
    } else {
        snprintf(lx.err, sizeof lx.err, "unknown check \"%.100s\"", word);
        goto fail;
    }
    if (ck->kind == X_VREG || ck->kind == X_MBIT || ck->kind == X_MEM) {
        if (lx.tok != '[') {
            snprintf(lx.err, sizeof lx.err, "expected '[' after %.100s", word);
            goto fail;
        }
        ie_lex_next(&lx);
        ck->index = ie_parse_expr(&lx);
        if (!lx.err[0] && lx.tok != ']')
            snprintf(lx.err, sizeof lx.err, "expected ']'");
        if (lx.err[0])
            goto fail;
        ie_lex_next(&lx);
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
    ie_lex_next(&lx);
    ck->expect = ie_parse_expr(&lx);
    if (!lx.err[0] && ck->op == OP_APPROX) {
        if (lx.tok == T_EOF)
            snprintf(lx.err, sizeof lx.err, "~= needs a tolerance: ~= VALUE TOL");
        else
            ck->tol = ie_parse_expr(&lx);
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
    ie_expr_free(ck->guard);
    ie_expr_free(ck->index);
    ie_expr_free(ck->expect);
    ie_expr_free(ck->tol);
    memset(ck, 0, sizeof *ck);
    return -1;
}

int ie_spec_load(const char *path, Spec *spec)
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
        if (ie_parse_check(p + 2, line, &ck, err, sizeof err) != 0) {
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
