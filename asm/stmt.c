/* asm/stmt.c -- one sfasm statement: labels, constants, directives and instructions.
 *
 * Owns: statement syntax after lexing, operand checking against the isa/ format table, section
 * switching and the data directives (.word .float .byte .space .align), aliases and .error.
 * Must not: read lines, handle conditionals, includes or macro definitions (asm.c), or decide
 * symbol values (symbols.c). Operands are checked in the order written so that the first
 * message of a statement is the one a reader expects.
 */
#include <stdlib.h>
#include <string.h>

#include "ctx.h"
#include "../isa/isa.h"

static int is_punct(const AsmToken *t, int punct) { return t->kind == ASM_TOK_PUNCT && t->punct == punct; }

static int count_to_eol(const AsmToken *t)
{
    int n = 0;
    while (t[n].kind != ASM_TOK_EOL)
        n++;
    return n;
}

static int name_is(const AsmToken *t, const char *s)
{
    return strlen(s) == t->len && memcmp(t->text, s, t->len) == 0;
}

static const char *kind_name(int kind)
{
    switch (kind) {
    case ISA_K_R: return "scalar register";
    case ISA_K_V: return "vector register";
    case ISA_K_M: return "mask register";
    default: return "register";
    }
}

static char kind_letter(int kind) { return kind == ISA_K_R ? 'r' : kind == ISA_K_V ? 'v' : 'm'; }

/* Complains about anything after the last operand of a directive; 0 if the line is done. */
static int expect_eol(Asm *a, const AsmToken *t, const AsmToken *dir)
{
    char d[64];
    if (t->kind == ASM_TOK_EOL)
        return 0;
    asm_error_at(a, t->col, "unexpected %s after %.*s", asm_tok_describe(t, d, sizeof d),
                 (int)dir->len, dir->text);
    return -1;
}

/* ---- registers -------------------------------------------------------------------------------- */

/* A register operand is one token: a register or a live alias. 1 with kind/num, or 0. */
static int as_register(const Asm *a, const AsmToken *t, int n, int *kind, int *num)
{
    if (n != 1)
        return 0;
    if (t->kind == ASM_TOK_REG) {
        *kind = t->reg_kind;
        *num = t->reg_num;
        return 1;
    }
    const AsmAlias *al = t->kind == ASM_TOK_IDENT ? asm_alias_get(a, t->text, t->len) : NULL;
    if (!al)
        return 0;
    *kind = al->kind;
    *num = al->num;
    return 1;
}

/* Range check of a register token (aliases were checked when defined). */
static int reg_in_range(Asm *a, const AsmToken *t, int kind, int num)
{
    int max = isa_kind_max_reg((IsaOperandKind)kind);
    if (num <= max)
        return 1;
    char d[64];
    asm_error_at(a, t->col, "register %s out of range (%c0..%c%d)", asm_tok_describe(t, d, sizeof d),
                 kind_letter(kind), kind_letter(kind), max);
    return 0;
}

/* ---- labels and constants --------------------------------------------------------------------- */

static void equ_directive(Asm *a, const AsmToken *t, int i)
{
    const AsmToken *dir = &t[i], *name = &t[i + 1];
    char d[64];
    if (name->kind != ASM_TOK_IDENT && name->kind != ASM_TOK_REG) {
        asm_error_at(a, name->col, "expected a symbol name after %.*s, found %s", (int)dir->len,
                     dir->text, asm_tok_describe(name, d, sizeof d));
        return;
    }
    if (!is_punct(&t[i + 2], ASM_P_COMMA)) {
        asm_error_at(a, t[i + 2].col, "expected ',' after the symbol name, found %s",
                     asm_tok_describe(&t[i + 2], d, sizeof d));
        return;
    }
    asm_define_const(a, name, name_is(dir, ".set") ? ASM_SYM_SET : ASM_SYM_EQU, &t[i + 3],
                     count_to_eol(&t[i + 3]), t[i + 2].col + 1);
}

/* ---- sections and data ------------------------------------------------------------------------ */

static AsmBytes *cur_bytes(Asm *a) { return a->section == ASM_SEC_DATA ? &a->data : &a->spad; }

static const char *cur_section_name(const Asm *a)
{
    return a->section == ASM_SEC_TEXT ? ".text" : a->section == ASM_SEC_DATA ? ".data" : ".spad";
}

/* Appends n bytes of fill to the current data section; the offset, or -1 after an error. */
static long long reserve(Asm *a, uint64_t n, uint8_t fill, uint32_t col)
{
    AsmBytes *b = cur_bytes(a);
    if (n == 0)
        return (long long)b->n;
    if (n > ASM_MAX_SECTION_BYTES - b->n) {
        asm_error_at(a, col, "section %s would exceed %u MiB", cur_section_name(a),
                     ASM_MAX_SECTION_BYTES >> 20);
        return -1;
    }
    uint8_t *nv = asm_grow(b->v, &b->cap, b->n + (size_t)n, 1);
    if (!nv) {
        asm_oom(a);
        return -1;
    }
    b->v = nv;
    memset(b->v + b->n, fill, (size_t)n);
    b->n += (size_t)n;
    return (long long)(b->n - (size_t)n);
}

static int data_allowed(Asm *a, const AsmToken *dir)
{
    if (a->section != ASM_SEC_TEXT)
        return 1;
    asm_error_at(a, dir->col, "%.*s is not allowed in .text (switch to .data or .spad)",
                 (int)dir->len, dir->text);
    return 0;
}

static void data_item(Asm *a, AsmFixKind kind, const AsmToken *t, int n, uint32_t at_col)
{
    AsmValue v;
    int rc = asm_eval(a, t, n, at_col, &v, NULL);
    long long off = reserve(a, kind == ASM_FIX_BYTE ? 1 : 4, 0, n ? t[0].col : at_col);
    if (off < 0 || rc == ASM_EXPR_ERROR)
        return;
    AsmLoc loc = asm_here(a, n ? t[0].col : at_col);
    if (rc == ASM_EXPR_OK) {
        asm_check_data(a, kind, &v, &loc, cur_bytes(a)->v + off);
        return;
    }
    AsmFixup f = {.kind = kind, .sec = (uint8_t)a->section, .at = (uint32_t)off, .loc = loc};
    if ((f.expr = asm_defer(a, t, n, at_col)) && asm_add_fixup(a, &f) < 0)
        asm_deferred_free(f.expr); /* asm_add_fixup reported it; the copy is ours to drop */
}

static void data_directive(Asm *a, const AsmToken *t, int i)
{
    const AsmToken *dir = &t[i];
    AsmFixKind kind = name_is(dir, ".word") ? ASM_FIX_WORD : name_is(dir, ".float") ? ASM_FIX_FLOAT : ASM_FIX_BYTE;
    if (!data_allowed(a, dir))
        return;
    int k = i + 1;
    for (;;) {
        int end = asm_tok_arg_end(t, k, 0);
        uint32_t at_col = t[k].kind == ASM_TOK_EOL && k == i + 1 ? dir->col + dir->len + 1 : t[k].col;
        data_item(a, kind, &t[k], end - k, at_col);
        if (t[end].kind == ASM_TOK_EOL)
            return;
        k = end + 1;
    }
}

/* Evaluates the integer argument of .space / .align / their fill, which must be known now. */
static int int_arg(Asm *a, const AsmToken *t, int n, uint32_t at_col, const char *what,
                   long long lo, long long hi, long long *out)
{
    AsmValue v;
    if (asm_eval(a, t, n, at_col, &v, what) != ASM_EXPR_OK)
        return -1;
    uint32_t col = n ? t[0].col : at_col;
    if (v.is_float) {
        asm_error_at(a, col, "%s must be an integer", what);
        return -1;
    }
    if (v.i < lo || v.i > hi) {
        asm_error_at(a, col, "%s must be %lld..%lld, got %lld", what, lo, hi, (long long)v.i);
        return -1;
    }
    *out = v.i;
    return 0;
}

/* .space n[, fill] and .align n[, fill]: size and optional fill byte. */
static int size_and_fill(Asm *a, const AsmToken *t, int i, const char *what, long long *n, uint8_t *fill)
{
    const AsmToken *dir = &t[i];
    int end = asm_tok_arg_end(t, i + 1, 0);
    if (int_arg(a, &t[i + 1], end - i - 1, dir->col + dir->len + 1, what, 0, ASM_MAX_SECTION_BYTES, n) < 0)
        return -1;
    *fill = 0;
    if (t[end].kind == ASM_TOK_EOL)
        return 0;
    int fend = asm_tok_arg_end(t, end + 1, 0);
    long long f;
    if (int_arg(a, &t[end + 1], fend - end - 1, t[end].col + 1, "fill byte", -128, 255, &f) < 0)
        return -1;
    *fill = (uint8_t)f;
    return expect_eol(a, &t[fend], dir);
}

static void space_directive(Asm *a, const AsmToken *t, int i)
{
    long long n;
    uint8_t fill;
    if (data_allowed(a, &t[i]) && size_and_fill(a, t, i, ".space size", &n, &fill) == 0)
        reserve(a, (uint64_t)n, fill, t[i].col);
}

static void align_directive(Asm *a, const AsmToken *t, int i)
{
    long long n;
    uint8_t fill;
    if (!data_allowed(a, &t[i]) || size_and_fill(a, t, i, ".align boundary", &n, &fill) < 0)
        return;
    if (n == 0 || (n & (n - 1)) != 0) {
        asm_error_at(a, t[i + 1].col, ".align boundary must be a power of two, got %lld", n);
        return;
    }
    size_t pad = (size_t)(-(long long)cur_bytes(a)->n & (n - 1));
    reserve(a, pad, fill, t[i].col);
}

static void section_directive(Asm *a, const AsmToken *t, int i)
{
    if (expect_eol(a, &t[i + 1], &t[i]) < 0)
        return;
    a->section = name_is(&t[i], ".text") ? ASM_SEC_TEXT : name_is(&t[i], ".data") ? ASM_SEC_DATA : ASM_SEC_SPAD;
}

/* ---- aliases and .error ----------------------------------------------------------------------- */

static void alias_directive(Asm *a, const AsmToken *t, int i)
{
    const AsmToken *name = &t[i + 1], *reg = &t[i + 3];
    char d[64];
    int kind, num;
    if (name->kind != ASM_TOK_IDENT && name->kind != ASM_TOK_REG) {
        asm_error_at(a, name->col, "expected an alias name after .alias, found %s",
                     asm_tok_describe(name, d, sizeof d));
        return;
    }
    if (!is_punct(&t[i + 2], ASM_P_COMMA)) {
        asm_error_at(a, t[i + 2].col, "expected ',' after the alias name, found %s",
                     asm_tok_describe(&t[i + 2], d, sizeof d));
        return;
    }
    if (!as_register(a, reg, reg->kind == ASM_TOK_EOL ? 0 : 1, &kind, &num)) {
        asm_error_at(a, reg->col, "expected a register after ',' in .alias, found %s",
                     asm_tok_describe(reg, d, sizeof d));
        return;
    }
    if (!reg_in_range(a, reg, kind, num) || expect_eol(a, &t[i + 4], &t[i]) < 0)
        return;
    asm_alias_set(a, name, kind, num);
}

/* .regs FIRST, item, ...: a register frame -- consecutive registers of FIRST's kind from FIRST on,
 * one .alias per name; an item `name:SUFFIXES` names one register per suffix letter (`d:xyz` is
 * dx, dy, dz). docs/assembler.md, "Register frames". */
static void regs_directive(Asm *a, const AsmToken *t, int i)
{
    const AsmToken *first = &t[i + 1];
    char d[64];
    int kind, num;
    if (!as_register(a, first, first->kind == ASM_TOK_EOL ? 0 : 1, &kind, &num)) {
        asm_error_at(a, first->col, "expected the frame's first register after .regs, found %s",
                     asm_tok_describe(first, d, sizeof d));
        return;
    }
    if (!reg_in_range(a, first, kind, num))
        return;
    int max = isa_kind_max_reg((IsaOperandKind)kind), j = i + 2;
    if (t[j].kind == ASM_TOK_EOL) {
        asm_error_at(a, t[j].col, "expected ',' and names after the first register of .regs");
        return;
    }
    while (t[j].kind != ASM_TOK_EOL) {
        const AsmToken *name = &t[j + 1], *suf = NULL;
        if (!is_punct(&t[j], ASM_P_COMMA)) {
            asm_error_at(a, t[j].col, "expected ',' before the next name in .regs, found %s",
                         asm_tok_describe(&t[j], d, sizeof d));
            return;
        }
        if (name->kind != ASM_TOK_IDENT && name->kind != ASM_TOK_REG) {
            asm_error_at(a, name->col, "expected a register name in .regs, found %s",
                         asm_tok_describe(name, d, sizeof d));
            return;
        }
        j += 2;
        if (is_punct(&t[j], ASM_P_COLON)) {
            suf = &t[j + 1];
            if (suf->kind != ASM_TOK_IDENT) {
                asm_error_at(a, suf->col, "expected suffix letters after ':' in .regs, found %s",
                             asm_tok_describe(suf, d, sizeof d));
                return;
            }
            j += 2;
        }
        for (uint32_t k = 0; k < (suf ? suf->len : 1u); k++, num++) {
            if (num > max) {
                asm_error_at(a, name->col, "register frame runs past %c%d at '%.*s'", kind_letter(kind), max,
                             (int)name->len, name->text);
                return;
            }
            if (!suf) {
                asm_alias_set(a, name, kind, num);
                continue;
            }
            char buf[128];
            AsmToken one = *name;
            int len = snprintf(buf, sizeof buf, "%.*s%c", (int)name->len, name->text, suf->text[k]);
            AsmTokens lexed = {0};
            AsmLexError le;
            /* the joined name is lexed again: `v:1` would make the register v1, not an alias */
            if (len >= (int)sizeof buf || asm_lex_line(buf, (size_t)len, NULL, &lexed, &le) < 0 || lexed.n != 2) {
                asm_error_at(a, name->col, "'%s' is not a name", buf);
                asm_tokens_free(&lexed);
                return;
            }
            one.kind = lexed.v[0].kind;
            one.text = buf;
            one.len = (uint32_t)len;
            asm_tokens_free(&lexed);
            if (asm_alias_set(a, &one, kind, num) < 0)
                return;
        }
    }
}

static void unalias_directive(Asm *a, const AsmToken *t, int i)
{
    char d[64];
    if (t[i + 1].kind != ASM_TOK_IDENT) {
        asm_error_at(a, t[i + 1].col, "expected an alias name after .unalias, found %s",
                     asm_tok_describe(&t[i + 1], d, sizeof d));
        return;
    }
    if (expect_eol(a, &t[i + 2], &t[i]) == 0)
        asm_alias_remove(a, &t[i + 1]);
}

static void error_directive(Asm *a, const AsmToken *t, int i)
{
    char d[64];
    if (t[i + 1].kind != ASM_TOK_STRING) {
        asm_error_at(a, t[i + 1].col, "expected a message in quotes after .error, found %s",
                     asm_tok_describe(&t[i + 1], d, sizeof d));
        return;
    }
    if (expect_eol(a, &t[i + 2], &t[i]) == 0)
        asm_error_at(a, t[i].col, "%s", t[i + 1].str);
}

/* ---- scheduling fences (asm/sched.h) --------------------------------------------------------- */

/* .barrier: a block starts at the next instruction; .sched off / .sched on: the instructions
 * between stay where they are. Kept as marks at text indices; asm.c hands them to the pass. */
static void sched_mark(Asm *a, int kind)
{
    AsmSchedMark *m = asm_grow(a->smarks, &a->capsmarks, a->nsmarks + 1, sizeof *m);
    if (!m) {
        asm_oom(a);
        return;
    }
    a->smarks = m;
    a->smarks[a->nsmarks++] = (AsmSchedMark){(uint32_t)a->ntext, kind};
}

static void barrier_directive(Asm *a, const AsmToken *t, int i)
{
    if (expect_eol(a, &t[i + 1], &t[i]) == 0)
        sched_mark(a, ASM_SMARK_BARRIER);
}

static void sched_directive(Asm *a, const AsmToken *t, int i)
{
    char d[64];
    int on = t[i + 1].kind == ASM_TOK_IDENT && name_is(&t[i + 1], "on");
    if (!on && !(t[i + 1].kind == ASM_TOK_IDENT && name_is(&t[i + 1], "off"))) {
        asm_error_at(a, t[i + 1].col, "expected on or off after .sched, found %s",
                     asm_tok_describe(&t[i + 1], d, sizeof d));
        return;
    }
    if (expect_eol(a, &t[i + 2], &t[i]) == 0)
        sched_mark(a, on ? ASM_SMARK_ON : ASM_SMARK_OFF);
}

static void structural_directive(Asm *a, const AsmToken *t, int i)
{
    asm_error_at(a, t[i].col, "%.*s must begin its line (no label before it)", (int)t[i].len, t[i].text);
}

static const struct {
    const char *name;
    void (*fn)(Asm *, const AsmToken *, int);
} directives[] = {
    {".text", section_directive},  {".data", section_directive},   {".spad", section_directive},
    {".word", data_directive},     {".float", data_directive},     {".byte", data_directive},
    {".space", space_directive},   {".align", align_directive},    {".equ", equ_directive},
    {".set", equ_directive},       {".alias", alias_directive},    {".unalias", unalias_directive},
    {".regs", regs_directive},     {".barrier", barrier_directive}, {".sched", sched_directive},
    {".error", error_directive},   {".if", structural_directive},  {".ifdef", structural_directive},
    {".ifndef", structural_directive}, {".elif", structural_directive}, {".else", structural_directive},
    {".endif", structural_directive},  {".macro", structural_directive}, {".endm", structural_directive},
    {".include", structural_directive},
};

static void directive(Asm *a, const AsmToken *t, int i)
{
    for (size_t k = 0; k < sizeof directives / sizeof directives[0]; k++)
        if (name_is(&t[i], directives[k].name)) {
            directives[k].fn(a, t, i);
            return;
        }
    asm_error_at(a, t[i].col, "unknown directive '%.*s'", t[i].len > 64 ? 64 : (int)t[i].len, t[i].text);
}

/* ---- instructions ----------------------------------------------------------------------------- */

typedef struct Operand {
    const AsmToken *t;   /* first token */
    int n;               /* token count */
    uint32_t col;        /* where it is (or would be) */
} Operand;

static void set_field(IsaInstr *in, IsaField f, int v)
{
    switch (f) {
    case ISA_FIELD_A: in->a = (uint8_t)v; break;
    case ISA_FIELD_B: in->b = (uint8_t)v; break;
    case ISA_FIELD_C: in->c = (uint8_t)v; break;
    case ISA_FIELD_D: in->d = (uint8_t)v; break;
    case ISA_FIELD_IMM: break;
    }
}

/* Index of the exec-mask '@' outside parentheses, or -1. */
static int find_at(const AsmToken *t, int i)
{
    for (int k = i;; k++) {
        k = asm_tok_arg_end(t, k, 1);
        if (t[k].kind == ASM_TOK_EOL)
            return -1;
        if (is_punct(&t[k], ASM_P_AT))
            return k;
    }
}

static int reg_operand(Asm *a, const Operand *o, int want, int op, int opidx, int *num)
{
    int kind;
    if (!as_register(a, o->t, o->n, &kind, num) || kind != want) {
        if (opidx == 0)
            asm_error_at(a, o->col, "exec mask must be a mask register (m0..m7)");
        else
            asm_error_at(a, o->col, "operand %d of %s must be a %s", opidx, isa_ops[op].mnemonic,
                         kind_name(want));
        return -1;
    }
    return reg_in_range(a, o->t, kind, *num) ? 0 : -1;
}

static int imm_operand(Asm *a, const Operand *o, int label, int op, int opidx, size_t pc, uint32_t *imm)
{
    int kind, num;
    const char *mn = isa_ops[op].mnemonic;
    if (as_register(a, o->t, o->n, &kind, &num)) {
        asm_error_at(a, o->col, "operand %d of %s must be %s, not a register", opidx, mn,
                     label ? "a label" : "an immediate");
        return -1;
    }
    AsmValue v;
    int rc = asm_eval(a, o->t, o->n, o->col, &v, NULL);
    if (rc == ASM_EXPR_ERROR)
        return -1;
    AsmLoc loc = asm_here(a, o->col);
    if (rc == ASM_EXPR_OK && !label)
        return asm_check_imm(a, op, opidx, 0, &v, &loc, imm);
    /* Label ranges need the final text size, forward references the final symbols: pass 2. */
    AsmFixup f = {.kind = label ? ASM_FIX_LABEL : ASM_FIX_IMM, .sec = ASM_SEC_TEXT,
                  .at = (uint32_t)pc, .op = op, .opidx = opidx, .value = v, .loc = loc};
    if (rc == ASM_EXPR_PENDING && !(f.expr = asm_defer(a, o->t, o->n, o->col)))
        return -1;
    if (asm_add_fixup(a, &f) < 0) {
        asm_deferred_free(f.expr);
        return -1;
    }
    return 0;
}

/* Splits operands at top-level commas up to the exec mask '@' or the end of the line. */
static int split_operands(const AsmToken *t, int i, int stop, Operand *ops, int max)
{
    int n = 0, k = i;
    if (k == stop)
        return 0;
    for (;;) {
        int end = asm_tok_arg_end(t, k, 1);
        if (n < max)
            ops[n] = (Operand){&t[k], end - k, t[k].col};
        n++;
        if (end >= stop)
            return n;
        k = end + 1;
    }
}

static int append_slot(Asm *a, uint32_t col)
{
    uint64_t *nt = asm_grow(a->text, &a->captext, a->ntext + 1, sizeof *nt);
    if (nt)
        a->text = nt;
    AsmLine *nl = nt ? asm_grow(a->lines, &a->caplines, a->ntext + 1, sizeof *nl) : NULL;
    if (!nl) {
        asm_oom(a);
        return -1;
    }
    a->lines = nl;
    a->text[a->ntext] = 0;
    a->lines[a->ntext] = (AsmLine){(uint32_t)a->cur.file, a->cur.line, col};
    a->ntext++;
    return 0;
}

static int operands(Asm *a, const AsmToken *t, int i, int stop, int op, size_t pc, IsaInstr *in)
{
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    const char *mn = isa_ops[op].mnemonic;
    Operand ops[ISA_MAX_OPERANDS + 1] = {{0}}; /* one more, to point at the first extra operand */
    int nops = split_operands(t, i + 1, stop, ops, ISA_MAX_OPERANDS + 1);
    if (nops != f->nops) {
        uint32_t col = nops > f->nops ? ops[f->nops].col : t[i].col;
        asm_error_at(a, col, "%s expects %d operand%s, got %d", mn, f->nops, f->nops == 1 ? "" : "s", nops);
        return -1;
    }
    for (int k = 0; k < nops; k++) {
        const IsaOperand *fo = &f->ops[k];
        int num;
        if (ops[k].n == 0) {
            asm_error_at(a, ops[k].col, "operand %d of %s is missing", k + 1, mn);
            return -1;
        }
        if (fo->kind == ISA_K_IMM || fo->kind == ISA_K_LABEL) {
            if (imm_operand(a, &ops[k], fo->kind == ISA_K_LABEL, op, k + 1, pc, &in->imm) < 0)
                return -1;
        } else if (reg_operand(a, &ops[k], fo->kind, op, k + 1, &num) < 0) {
            return -1;
        } else {
            set_field(in, fo->field, num);
        }
    }
    return 0;
}

static void exec_mask(Asm *a, const AsmToken *t, int at, int end, int op, IsaInstr *in)
{
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    if (!f->masked) {
        asm_error_at(a, t[at].col, "%s takes no exec mask", isa_ops[op].mnemonic);
        return;
    }
    Operand m = {&t[at + 1], end - at - 1, t[at + 1].col};
    int num;
    if (reg_operand(a, &m, ISA_K_M, op, 0, &num) == 0)
        in->mask = (uint8_t)num;
}

static void instruction(Asm *a, const AsmToken *t, int i)
{
    const AsmToken *mn = &t[i];
    char name[16];
    int op = -1;
    if (mn->len < sizeof name) {
        memcpy(name, mn->text, mn->len);
        name[mn->len] = '\0';
        op = isa_op_from_mnemonic(name);
    }
    if (op < 0) {
        asm_error_at(a, mn->col, "unknown instruction '%.*s'", mn->len > 64 ? 64 : (int)mn->len, mn->text);
        return;
    }
    if (a->section != ASM_SEC_TEXT) {
        asm_error_at(a, mn->col, "instruction %s outside .text (current section is %s)", name,
                     cur_section_name(a));
        return;
    }
    int end = i + 1 + count_to_eol(&t[i + 1]), at = find_at(t, i + 1);
    if (a->ntext >= ASM_MAX_TEXT_WORDS) {
        asm_error_at(a, mn->col, "text section exceeds %u instructions", ASM_MAX_TEXT_WORDS);
        return;
    }
    /* Operands first, so '.' in them is this instruction's pc; the slot is taken even for a
     * wrong instruction so that later labels keep their addresses (no cascade). */
    size_t pc = a->ntext;
    IsaInstr in = {.op = (uint8_t)op};
    if (operands(a, t, i, at >= 0 ? at : end, op, pc, &in) == 0 && at >= 0)
        exec_mask(a, t, at, end, op, &in);
    if (append_slot(a, mn->col) == 0)
        a->text[pc] = isa_encode(&in); /* deferred immediates are or'ed in by pass 2 */
}

/* ---- the statement ---------------------------------------------------------------------------- */

void asm_statement(Asm *a, const AsmToken *t)
{
    int i = 0;
    char d[64];
    while ((t[i].kind == ASM_TOK_IDENT || t[i].kind == ASM_TOK_REG) && is_punct(&t[i + 1], ASM_P_COLON)) {
        asm_define_label(a, &t[i]);
        i += 2;
    }
    const AsmToken *h = &t[i];
    if (h->kind == ASM_TOK_EOL)
        return;
    if ((h->kind == ASM_TOK_IDENT || h->kind == ASM_TOK_REG) && is_punct(&t[i + 1], ASM_P_ASSIGN)) {
        asm_define_const(a, h, ASM_SYM_EQU, &t[i + 2], count_to_eol(&t[i + 2]), t[i + 1].col + 1);
        return;
    }
    if (h->kind == ASM_TOK_DIRECTIVE) {
        directive(a, t, i);
        return;
    }
    if (h->kind == ASM_TOK_IDENT) {
        const AsmMacro *m = asm_table_get(&a->macrotab, h->text, h->len);
        if (m)
            asm_macro_call(a, m, t, i + 1);
        else
            instruction(a, t, i);
        return;
    }
    asm_error_at(a, h->col, "expected a label, instruction or directive, found %s",
                 asm_tok_describe(h, d, sizeof d));
}
