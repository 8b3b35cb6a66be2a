/* asm/symbols.c -- sfasm symbols, register aliases, expression evaluation and the second pass.
 *
 * Owns: the symbol table (labels, = / .equ / .set constants, -D defines), aliases, deferring an
 * expression that names a symbol not defined yet, resolving those in pass 2 (with cycle
 * detection), value checks for immediates and data, and building the output object.
 * Must not: read source lines or decide what a statement means (stmt.c, asm.c).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "../isa/isa.h"

static const char *section_name(int sec)
{
    switch (sec) {
    case ASM_SEC_TEXT: return ".text";
    case ASM_SEC_DATA: return ".data";
    case ASM_SEC_SPAD: return ".spad";
    default: return "absolute";
    }
}

/* ---- symbols ---------------------------------------------------------------------------------- */

AsmSym *asm_sym_get(const Asm *a, const char *name, size_t len)
{
    return asm_table_get(&a->symtab, name, len);
}

static AsmSym *sym_new(Asm *a, const char *name, size_t len, AsmSymKind kind, const AsmLoc *loc)
{
    AsmSym **nl = asm_grow(a->syms, &a->capsyms, a->nsyms + 1, sizeof *nl);
    AsmSym *s = calloc(1, sizeof *s);
    char *n = malloc(len + 1);
    if (nl)
        a->syms = nl;
    if (!nl || !s || !n || asm_table_put(&a->symtab, name, len, s) < 0) {
        free(s);
        free(n);
        asm_oom(a);
        return NULL;
    }
    memcpy(n, name, len);
    n[len] = '\0';
    s->name = n;
    s->kind = kind;
    s->loc = *loc;
    a->syms[a->nsyms++] = s;
    return s;
}

void asm_deferred_free(AsmDeferred *d)
{
    if (d) {
        free(d->text);
        free(d->toks);
        free(d);
    }
}

const AsmAlias *asm_alias_get(const Asm *a, const char *name, size_t len)
{
    const AsmAlias *al = asm_table_get(&a->aliastab, name, len);
    return al && al->live ? al : NULL;
}

/* A name may be one thing only: a register, a register alias or a symbol. */
static int name_is_free(Asm *a, const AsmToken *name, const char *what)
{
    if (name->kind == ASM_TOK_REG) {
        asm_error_at(a, name->col, "'%.*s' is a register name and cannot be %s", (int)name->len,
                     name->text, what);
        return 0;
    }
    if (asm_alias_get(a, name->text, name->len)) {
        asm_error_at(a, name->col, "'%.*s' is a register alias and cannot be %s", (int)name->len,
                     name->text, what);
        return 0;
    }
    return 1;
}

static void already_defined(Asm *a, const AsmToken *name, const AsmSym *old, int label)
{
    if (old->kind == ASM_SYM_DEFINE)
        asm_error_at(a, name->col, "symbol '%.*s' is already defined on the command line (-D)",
                     (int)name->len, name->text);
    else
        asm_error_at(a, name->col, "%s '%.*s' (first defined at %s:%u)",
                     label && old->kind == ASM_SYM_LABEL ? "duplicate label" : "redefinition of symbol",
                     (int)name->len, name->text, asm_file_name(a, old->loc.file), old->loc.line);
}

void asm_define_label(Asm *a, const AsmToken *name)
{
    if (!name_is_free(a, name, "a label"))
        return;
    AsmSym *old = asm_sym_get(a, name->text, name->len);
    if (old) {
        already_defined(a, name, old, 1);
        return;
    }
    AsmLoc loc = asm_here(a, name->col);
    AsmSym *s = sym_new(a, name->text, name->len, ASM_SYM_LABEL, &loc);
    if (s) {
        s->value = asm_dot(a);
        s->state = ASM_SYM_KNOWN;
    }
}

void asm_define_const(Asm *a, const AsmToken *name, AsmSymKind kind, const AsmToken *expr, int n,
                      uint32_t at_col)
{
    if (!name_is_free(a, name, "a symbol"))
        return;
    AsmSym *s = asm_sym_get(a, name->text, name->len);
    if (s && !(kind == ASM_SYM_SET && s->kind == ASM_SYM_SET)) {
        already_defined(a, name, s, 0);
        return;
    }
    AsmValue v;
    int rc = asm_eval(a, expr, n, at_col, &v, NULL);
    AsmLoc loc = asm_here(a, name->col);
    if (!s && !(s = sym_new(a, name->text, name->len, kind, &loc)))
        return;
    asm_deferred_free(s->expr);
    s->expr = NULL;
    s->loc = loc;
    s->value = (AsmValue){0};
    if (rc == ASM_EXPR_OK) {
        s->value = v;
        s->state = ASM_SYM_KNOWN;
    } else if (rc == ASM_EXPR_PENDING && (s->expr = asm_defer(a, expr, n, at_col))) {
        s->state = ASM_SYM_PENDING;
    } else {
        s->state = ASM_SYM_FAILED; /* reported; uses of it stay quiet */
    }
}

static int valid_define_name(const char *n)
{
    if (!n || !((*n >= 'a' && *n <= 'z') || (*n >= 'A' && *n <= 'Z') || *n == '_'))
        return 0;
    for (const char *p = n; *p; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || *p == '_'))
            return 0;
    size_t len = strlen(n);
    int reglike = len >= 2 && (n[0] == 'r' || n[0] == 'v' || n[0] == 'm') && strspn(n + 1, "0123456789") == len - 1;
    return !reglike;
}

void asm_define_cmdline(Asm *a, const AsmDefine *d)
{
    AsmLoc loc = {.file = -1, .line = 1, .col = 1, .exp = -1, .seq = 0};
    if (!valid_define_name(d->name)) {
        asm_error(a, &loc, "-D: '%s' is not a valid symbol name", d->name ? d->name : "(null)");
        return;
    }
    if (d->value < INT32_MIN || d->value > (long long)UINT32_MAX) {
        asm_error(a, &loc, "-D %s: value %lld does not fit in 32 bits", d->name, d->value);
        return;
    }
    size_t len = strlen(d->name);
    AsmSym *s = asm_sym_get(a, d->name, len); /* a later -D of the same name wins, as with cc */
    if (!s && !(s = sym_new(a, d->name, len, ASM_SYM_DEFINE, &loc)))
        return;
    s->value = (AsmValue){.i = d->value};
    s->state = ASM_SYM_KNOWN;
}

int asm_alias_set(Asm *a, const AsmToken *name, int kind, int num)
{
    if (name->kind == ASM_TOK_REG) {
        asm_error_at(a, name->col, "'%.*s' is a register name and cannot be an alias", (int)name->len,
                     name->text);
        return -1;
    }
    if (asm_sym_get(a, name->text, name->len)) {
        asm_error_at(a, name->col, "'%.*s' is already a symbol and cannot be an alias", (int)name->len,
                     name->text);
        return -1;
    }
    AsmAlias *al = asm_table_get(&a->aliastab, name->text, name->len);
    if (!al) {
        AsmAlias **nl = asm_grow(a->aliases, &a->capaliases, a->naliases + 1, sizeof *nl);
        if (nl)
            a->aliases = nl;
        al = calloc(1, sizeof *al);
        if (!nl || !al || asm_table_put(&a->aliastab, name->text, name->len, al) < 0) {
            free(al);
            asm_oom(a);
            return -1;
        }
        a->aliases[a->naliases++] = al;
    }
    *al = (AsmAlias){kind, num, 1};
    return 0;
}

int asm_alias_remove(Asm *a, const AsmToken *name)
{
    AsmAlias *al = asm_table_get(&a->aliastab, name->text, name->len);
    if (!al || !al->live) {
        asm_error_at(a, name->col, "'%.*s' is not a register alias", (int)name->len, name->text);
        return -1;
    }
    al->live = 0;
    return 0;
}

/* ---- evaluation ------------------------------------------------------------------------------- */

static int eval_deferred(Asm *a, const AsmDeferred *d, AsmValue *out);

/* Pass 2: a constant defined by a forward reference gets its value on first use. */
static void resolve(Asm *a, AsmSym *s)
{
    if (a->defer_depth >= ASM_MAX_DEFER_DEPTH) {
        asm_error(a, &s->expr->loc, "definition of '%s' depends on too long a chain of constants (limit %d)",
                  s->name, ASM_MAX_DEFER_DEPTH);
        s->state = ASM_SYM_FAILED;
        return;
    }
    AsmValue v;
    s->state = ASM_SYM_RESOLVING;
    a->defer_depth++;
    int rc = eval_deferred(a, s->expr, &v);
    a->defer_depth--;
    if (rc == ASM_EXPR_OK) {
        s->value = v;
        s->state = ASM_SYM_KNOWN;
    } else {
        s->state = ASM_SYM_FAILED;
    }
}

__attribute__((format(printf, 3, 4)))
static int lookup_fail(AsmExprError *err, uint32_t col, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    err->col = col;
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    va_end(ap);
    return ASM_EXPR_ERROR;
}

static int lookup(void *ctx, const AsmToken *tok, AsmValue *out, AsmExprError *err)
{
    Asm *a = ctx;
    int len = tok->len > 200 ? 200 : (int)tok->len;
    AsmSym *s = asm_sym_get(a, tok->text, tok->len);
    if (!s) {
        if (asm_alias_get(a, tok->text, tok->len))
            return lookup_fail(err, tok->col, "register alias '%.*s' cannot be used in an expression",
                               len, tok->text);
        if (a->pass == 1)
            return ASM_EXPR_PENDING;
        return lookup_fail(err, tok->col, "undefined symbol '%.*s'", len, tok->text);
    }
    if (s->state == ASM_SYM_PENDING && a->pass == 2)
        resolve(a, s);
    switch (s->state) {
    case ASM_SYM_KNOWN: *out = s->value; return ASM_EXPR_OK;
    case ASM_SYM_FAILED: *out = (AsmValue){0}; return ASM_EXPR_OK; /* already reported */
    case ASM_SYM_PENDING: return ASM_EXPR_PENDING;
    case ASM_SYM_RESOLVING: break;
    }
    return lookup_fail(err, tok->col, "circular definition of '%.*s'", len, tok->text);
}

static int defined(void *ctx, const AsmToken *tok)
{
    return asm_sym_get(ctx, tok->text, tok->len) != NULL;
}

AsmValue asm_dot(const Asm *a)
{
    AsmValue v = {.sec = (uint8_t)a->section};
    v.i = a->section == ASM_SEC_TEXT ? (int64_t)a->ntext
          : a->section == ASM_SEC_DATA ? (int64_t)a->data.n : (int64_t)a->spad.n;
    return v;
}

int asm_eval(Asm *a, const AsmToken *toks, int n, uint32_t at_col, AsmValue *out,
             const char *must_resolve)
{
    AsmExprEnv env = {a, lookup, defined, asm_dot(a)};
    AsmExprError err;
    int rc = asm_expr_eval(toks, n, at_col, &env, out, &err);
    if (rc == ASM_EXPR_ERROR) {
        asm_error_at(a, err.col, "%s", err.msg);
    } else if (rc == ASM_EXPR_PENDING && must_resolve) {
        asm_error_at(a, err.col, "%s must be known at this point: %s", must_resolve, err.msg);
        rc = ASM_EXPR_ERROR;
    }
    return rc;
}

static int eval_deferred(Asm *a, const AsmDeferred *d, AsmValue *out)
{
    AsmExprEnv env = {a, lookup, defined, d->dot};
    AsmExprError err;
    int rc = asm_expr_eval(d->toks, d->ntoks, d->at_col, &env, out, &err);
    if (rc != ASM_EXPR_OK) {
        AsmLoc loc = d->loc;
        loc.col = err.col;
        asm_error(a, &loc, "%s", err.msg);
        return ASM_EXPR_ERROR;
    }
    return rc;
}

AsmDeferred *asm_defer(Asm *a, const AsmToken *toks, int n, uint32_t at_col)
{
    AsmDeferred *d = calloc(1, sizeof *d);
    size_t span = n ? toks[n - 1].off + toks[n - 1].len - toks[0].off : 0;
    if (d) {
        d->text = malloc(span + 1);
        d->toks = malloc((size_t)(n ? n : 1) * sizeof *d->toks);
    }
    if (!d || !d->text || !d->toks) {
        asm_deferred_free(d);
        asm_oom(a);
        return NULL;
    }
    if (n)
        memcpy(d->text, toks[0].text, span);
    for (int i = 0; i < n; i++) {
        d->toks[i] = toks[i];
        d->toks[i].text = d->text + (toks[i].off - toks[0].off);
        d->toks[i].str = NULL; /* strings are never values; the copy must not own one */
    }
    d->ntoks = n;
    d->at_col = at_col;
    d->dot = asm_dot(a);
    d->loc = asm_here(a, n ? toks[0].col : at_col);
    return d;
}

int asm_add_fixup(Asm *a, const AsmFixup *f)
{
    AsmFixup *nf = asm_grow(a->fix, &a->capfix, a->nfix + 1, sizeof *nf);
    if (!nf) {
        asm_oom(a);
        return -1;
    }
    a->fix = nf;
    a->fix[a->nfix++] = *f;
    return 0;
}

/* ---- value checks ----------------------------------------------------------------------------- */

int asm_check_imm(Asm *a, int op, int opidx, int label, const AsmValue *v, const AsmLoc *loc,
                  uint32_t *bits)
{
    const char *mn = isa_ops[op].mnemonic;
    if (label) {
        if (v->is_float) {
            asm_error(a, loc, "operand %d of %s must be a label, not a float", opidx, mn);
            return -1;
        }
        if (v->sec == ASM_SEC_DATA || v->sec == ASM_SEC_SPAD) {
            asm_error(a, loc, "operand %d of %s must be a text label, not a %s address", opidx, mn,
                      section_name(v->sec));
            return -1;
        }
        if (v->i < 0 || v->i > (int64_t)a->ntext) {
            asm_error(a, loc, "operand %d of %s: target %lld is outside the text section (0..%zu)",
                      opidx, mn, (long long)v->i, a->ntext);
            return -1;
        }
        *bits = (uint32_t)v->i;
        return 0;
    }
    if (op == ISA_OP_STAGE && (v->is_float || v->i < 0 || v->i >= ISA_STAGE_COUNT)) {
        if (v->is_float)
            asm_error(a, loc, "stage must be an integer 0..%d, not a float", ISA_STAGE_COUNT - 1);
        else
            asm_error(a, loc, "stage must be 0..%d, got %lld", ISA_STAGE_COUNT - 1, (long long)v->i);
        return -1;
    }
    *bits = asm_value_bits(v);
    return 0;
}

int asm_check_data(Asm *a, AsmFixKind kind, const AsmValue *v, const AsmLoc *loc, uint8_t *bytes)
{
    uint32_t bits;
    if (kind == ASM_FIX_BYTE) {
        if (v->is_float) {
            asm_error(a, loc, ".byte needs an integer, not a float");
            return -1;
        }
        if (v->i < -128 || v->i > 255) {
            asm_error(a, loc, "value %lld does not fit in a byte", (long long)v->i);
            return -1;
        }
        bytes[0] = (uint8_t)v->i;
        return 0;
    }
    if (kind == ASM_FIX_FLOAT && !v->is_float) {
        AsmValue f = {.f = (double)v->i, .is_float = 1};
        bits = asm_value_bits(&f);
    } else {
        bits = asm_value_bits(v);
    }
    for (int i = 0; i < 4; i++)
        bytes[i] = (uint8_t)(bits >> (8 * i));
    return 0;
}

/* ---- pass 2 ----------------------------------------------------------------------------------- */

static void apply_fixup(Asm *a, const AsmFixup *f)
{
    AsmValue v = f->value;
    if (f->expr && eval_deferred(a, f->expr, &v) != ASM_EXPR_OK)
        return;
    if (f->sec == ASM_SEC_TEXT) {
        uint32_t bits;
        if (asm_check_imm(a, f->op, f->opidx, f->kind == ASM_FIX_LABEL, &v, &f->loc, &bits) == 0)
            a->text[f->at] = (a->text[f->at] & 0xFFFFFFFFu) | (uint64_t)bits << 32;
        return;
    }
    AsmBytes *b = f->sec == ASM_SEC_DATA ? &a->data : &a->spad;
    asm_check_data(a, f->kind, &v, &f->loc, b->v + f->at);
}

void asm_pass2(Asm *a)
{
    a->pass = 2;
    /* Every constant gets resolved, used or not, so a bad definition is always reported. Last
     * first: a forward reference points further down, so a chain A = B + 1, B = C + 1, ...
     * resolves one link at a time instead of recursing down the whole chain. */
    for (size_t i = a->nsyms; i-- > 0;)
        if (a->syms[i]->state == ASM_SYM_PENDING)
            resolve(a, a->syms[i]);
    for (size_t i = 0; i < a->nfix; i++)
        apply_fixup(a, &a->fix[i]);
}

/* ---- output ----------------------------------------------------------------------------------- */

static void *dup_mem(const void *p, size_t n)
{
    void *d = malloc(n ? n : 1);
    if (d && n)
        memcpy(d, p, n);
    return d;
}

static int build_syms(const Asm *a, AsmObject *obj)
{
    obj->syms = calloc(a->nsyms ? a->nsyms : 1, sizeof *obj->syms);
    if (!obj->syms)
        return -1;
    for (size_t i = 0; i < a->nsyms; i++) {
        const AsmSym *s = a->syms[i];
        if (s->state != ASM_SYM_KNOWN)
            continue;
        AsmSymbol *o = &obj->syms[obj->nsyms];
        if (!(o->name = strdup(s->name)))
            return -1;
        o->section = s->kind == ASM_SYM_LABEL ? s->value.sec : 0;
        o->value = asm_value_bits(&s->value);
        obj->nsyms++;
    }
    return 0;
}

int asm_build_object(Asm *a, AsmObject *obj)
{
    memset(obj, 0, sizeof *obj);
    obj->ntext = (uint32_t)a->ntext;
    obj->ndata = (uint32_t)a->data.n;
    obj->nspad = (uint32_t)a->spad.n;
    obj->text = dup_mem(a->text, a->ntext * sizeof *a->text);
    obj->lines = dup_mem(a->lines, a->ntext * sizeof *a->lines);
    obj->data = a->data.n ? dup_mem(a->data.v, a->data.n) : NULL;
    obj->spad = a->spad.n ? dup_mem(a->spad.v, a->spad.n) : NULL;
    obj->files = calloc(a->nfiles ? a->nfiles : 1, sizeof *obj->files);
    int bad = !obj->text || !obj->lines || (a->data.n && !obj->data) || (a->spad.n && !obj->spad) ||
              !obj->files;
    for (size_t i = 0; !bad && i < a->nfiles; i++) {
        if (!(obj->files[i] = strdup(a->files[i])))
            bad = 1;
        else
            obj->nfiles++;
    }
    if (bad || build_syms(a, obj) < 0) {
        asm_object_free(obj);
        asm_oom(a);
        return -1;
    }
    return 0;
}

void asm_symbols_free(Asm *a)
{
    for (size_t i = 0; i < a->nsyms; i++) {
        free(a->syms[i]->name);
        asm_deferred_free(a->syms[i]->expr);
        free(a->syms[i]);
    }
    free(a->syms);
    asm_table_free(&a->symtab);
    for (size_t i = 0; i < a->naliases; i++)
        free(a->aliases[i]);
    free(a->aliases);
    asm_table_free(&a->aliastab);
    for (size_t i = 0; i < a->nfix; i++)
        asm_deferred_free(a->fix[i].expr);
    free(a->fix);
}
