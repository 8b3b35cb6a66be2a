/* asm/asm.c -- sfasm's driver: sources, includes, conditionals, macros, diagnostics, entry points.
 *
 * Owns: the stack of input frames (files and macro expansions), conditional assembly, macro
 * definition and calls, include search, the limits that keep hostile input bounded, and the
 * collection and ordering of diagnostics. Pass 1 reads every line once, in order; pass 2
 * (symbols.c) resolves what pass 1 deferred. Must not: interpret statements (stmt.c) or own
 * symbol values (symbols.c); it never exits or aborts, whatever the input.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ctx.h"
#include "../isa/isa.h"
#include "../host/infile.h"

/* ---- memory and diagnostics ------------------------------------------------------------------- */

void *asm_grow(void *v, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap && v)
        return v;
    size_t ncap = *cap ? *cap : 8;
    while (ncap < need) {
        if (ncap > SIZE_MAX / 2 / elem)
            return NULL;
        ncap *= 2;
    }
    void *nv = realloc(v, ncap * elem);
    if (nv)
        *cap = ncap;
    return nv;
}

const char *asm_file_name(const Asm *a, int file)
{
    if (file < 0 || (size_t)file >= a->nfiles)
        return "<command line>";
    return a->files[file];
}

AsmLoc asm_here(const Asm *a, uint32_t col)
{
    return (AsmLoc){a->cur.file, a->cur.line, col, a->cur.exp, a->seq};
}

/* A growing message text: one allocation per diagnostic in the common case (a run can report
 * hundreds of thousands when a macro with an error expands that often). */
typedef struct Msg {
    char *p;
    size_t n, cap;
    int failed;
} Msg;

static void msg_vadd(Msg *m, const char *fmt, va_list ap)
{
    va_list ap2;
    va_copy(ap2, ap);
    int k = m->failed ? -1 : vsnprintf(m->p + m->n, m->cap - m->n, fmt, ap);
    if (k >= 0 && (size_t)k >= m->cap - m->n) {
        size_t ncap = m->n + (size_t)k + 256;
        char *np = realloc(m->p, ncap);
        if (np) {
            m->p = np;
            m->cap = ncap;
            k = vsnprintf(m->p + m->n, m->cap - m->n, fmt, ap2);
        } else {
            k = -1;
        }
    }
    va_end(ap2);
    if (k < 0)
        m->failed = 1;
    else
        m->n += (size_t)k;
}

__attribute__((format(printf, 2, 3)))
static void msg_add(Msg *m, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    msg_vadd(m, fmt, ap);
    va_end(ap);
}

/* " (in expansion of macro 'm' from f:l; macro 'outer' from f:l)" for a line from a macro:
 * the innermost three calls, then how many are left out, then the outermost call. */
static void add_expansions(const Asm *a, Msg *m, int exp)
{
    if (exp < 0 || (size_t)exp >= a->nexps)
        return;
    size_t depth = 0;
    for (int e = exp; e >= 0; e = a->exps[e].parent)
        depth++;
    size_t k = 0;
    for (int e = exp; e >= 0; e = a->exps[e].parent, k++) {
        const AsmExpansion *x = &a->exps[e];
        if (k >= 3 && k + 1 < depth) {
            if (k == 3)
                msg_add(m, "; ... %zu more", depth - 4);
            continue;
        }
        msg_add(m, "%s macro '%s' from %s:%u", k == 0 ? " (in expansion of" : ";", x->macro,
                asm_file_name(a, x->call_file), x->call_line);
    }
    msg_add(m, ")");
}

/* Pass-2 messages are emitted after pass-1 ones; sorting by source line restores reading order
 * (ties keep their order: stable). */
static int diag_cmp(const void *x, const void *y)
{
    const AsmDiag *p = x, *q = y;
    if (p->seq != q->seq)
        return p->seq < q->seq ? -1 : 1;
    return p->order < q->order ? -1 : p->order > q->order;
}

/* Keeps the first ASM_MAX_ERRORS_SHOWN diagnostics in reading order and frees the rest: a
 * macro that fails in every one of its expansions would otherwise print (and hold) hundreds of
 * thousands of lines. */
static void trim_diags(Asm *a)
{
    if (a->ndiags <= ASM_MAX_ERRORS_SHOWN)
        return;
    qsort(a->diags, a->ndiags, sizeof *a->diags, diag_cmp);
    for (size_t i = ASM_MAX_ERRORS_SHOWN; i < a->ndiags; i++)
        free(a->diags[i].text);
    a->diags_dropped += a->ndiags - ASM_MAX_ERRORS_SHOWN;
    a->ndiags = ASM_MAX_ERRORS_SHOWN;
}

static void add_diag(Asm *a, uint64_t seq, char *text)
{
    if (a->ndiags >= 2 * ASM_MAX_ERRORS_SHOWN)
        trim_diags(a);
    AsmDiag *nd = asm_grow(a->diags, &a->capdiags, a->ndiags + 1, sizeof *nd);
    if (!nd) { /* cannot keep it for ordering: say it now rather than lose it */
        fputs(text, a->opt->diag ? a->opt->diag : stderr);
        free(text);
        return;
    }
    a->diags = nd;
    /* order counts every diagnostic so far, the trimmed ones too, so it only grows */
    a->diags[a->ndiags] = (AsmDiag){seq, a->ndiags + a->diags_dropped, text};
    a->ndiags++;
}

static void verror(Asm *a, const AsmLoc *loc, const char *fmt, va_list ap)
{
    Msg m = {malloc(256), 0, 256, 0};
    a->errors++;
    m.failed = m.p == NULL;
    msg_add(&m, "%s:%u:%u: ", asm_file_name(a, loc->file), loc->line, loc->col);
    msg_vadd(&m, fmt, ap);
    add_expansions(a, &m, loc->exp);
    msg_add(&m, "\n");
    if (m.failed) { /* out of memory: the error still counts; say so without the text */
        fprintf(a->opt->diag ? a->opt->diag : stderr, "%s:%u:%u: out of memory while reporting an error\n",
                asm_file_name(a, loc->file), loc->line, loc->col);
        free(m.p);
        return;
    }
    add_diag(a, loc->seq, m.p);
}

void asm_error(Asm *a, const AsmLoc *loc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    verror(a, loc, fmt, ap);
    va_end(ap);
}

void asm_error_at(Asm *a, uint32_t col, const char *fmt, ...)
{
    AsmLoc loc = asm_here(a, col);
    va_list ap;
    va_start(ap, fmt);
    verror(a, &loc, fmt, ap);
    va_end(ap);
}

void asm_oom(Asm *a)
{
    asm_error_at(a, 1, "out of memory");
    a->fatal = 1;
}

static void flush_diags(Asm *a)
{
    FILE *out = a->opt->diag ? a->opt->diag : stderr;
    trim_diags(a);
    if (a->ndiags > 1)
        qsort(a->diags, a->ndiags, sizeof *a->diags, diag_cmp);
    for (size_t i = 0; i < a->ndiags; i++) {
        fputs(a->diags[i].text, out);
        free(a->diags[i].text);
    }
    if (a->diags_dropped)
        fprintf(out, "... and %zu more error%s (only the first %d are shown)\n", a->diags_dropped,
                a->diags_dropped == 1 ? "" : "s", ASM_MAX_ERRORS_SHOWN);
    fflush(out);
    free(a->diags);
    a->diags = NULL;
    a->ndiags = a->capdiags = 0;
    a->diags_dropped = 0;
}

/* ---- files ------------------------------------------------------------------------------------ */

static int add_file(Asm *a, const char *name)
{
    for (size_t i = 0; i < a->nfiles; i++)
        if (strcmp(a->files[i], name) == 0)
            return (int)i;
    char **nf = asm_grow(a->files, &a->capfiles, a->nfiles + 1, sizeof *nf);
    char *copy = strdup(name);
    if (nf)
        a->files = nf;
    if (!nf || !copy) {
        free(copy);
        return -1;
    }
    a->files[a->nfiles] = copy;
    return (int)a->nfiles++;
}

/* Reads a regular file whole through the one input check (host/infile.h): FIFOs and devices (an
 * include of /dev/zero) are refused before a byte is read; room caps the input in all. */
static int read_source(const char *path, size_t room, char **buf, size_t *len, char *why, size_t whylen)
{
    char err[PATH_MAX + 256], what[64];
    snprintf(what, sizeof what, "the assembler's input (%u MiB in all)", ASM_MAX_INPUT_BYTES >> 20);
    if (infile_read(path, room, what, buf, len, err, sizeof err) != 0) {
        snprintf(why, whylen, "%s", infile_reason(err, path));
        return -1;
    }
    return 0;
}

static char *join_path(const char *dir, size_t dirlen, const char *name)
{
    size_t n = strlen(name);
    char *p = malloc(dirlen + 1 + n + 1);
    if (!p)
        return NULL;
    memcpy(p, dir, dirlen);
    if (dirlen)
        p[dirlen++] = '/';
    memcpy(p + dirlen, name, n + 1);
    return p;
}

/* A candidate for an include: anything there but a folder (as a C preprocessor skips folders). A
 * device or a FIFO is found, and then refused by name when read (read_source). */
static int is_candidate(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && !S_ISDIR(st.st_mode);
}

/* The including file's directory first, then each -I directory. */
static char *find_include(const Asm *a, const char *name, const char *from)
{
    if (name[0] == '/')
        return is_candidate(name) ? strdup(name) : NULL;
    const char *slash = strrchr(from, '/');
    char *p = join_path(from, slash ? (size_t)(slash - from) : 0, name);
    if (p && is_candidate(p))
        return p;
    free(p);
    for (int i = 0; i < a->opt->ninclude_dirs; i++) {
        const char *dir = a->opt->include_dirs[i];
        if (!dir)
            continue;
        p = join_path(dir, strlen(dir), name);
        if (p && is_candidate(p))
            return p;
        free(p);
    }
    return NULL;
}

/* ---- frames ----------------------------------------------------------------------------------- */

static AsmFrame *push_frame(Asm *a)
{
    AsmFrame *nf = asm_grow(a->frames, &a->capframes, a->nframes + 1, sizeof *nf);
    if (!nf)
        return NULL;
    a->frames = nf;
    AsmFrame *f = &a->frames[a->nframes++];
    memset(f, 0, sizeof *f);
    f->cond_base = a->nconds;
    f->exp = -1;
    return f;
}

static size_t count_frames(const Asm *a, int macro)
{
    size_t n = 0;
    for (size_t i = 0; i < a->nframes; i++)
        n += a->frames[i].is_macro == macro;
    return n;
}

/* Loads the frame's next line into a->cur; 0 at its end. */
static int next_line(Asm *a, AsmFrame *f)
{
    if (f->is_macro) {
        if (f->next >= f->nlines)
            return 0;
        const AsmSrcLine *l = &f->lines[f->next++];
        a->cur = (AsmCurLine){l->text, l->len, l->cols, l->file, l->line, f->exp};
        return 1;
    }
    if (f->pos >= f->len)
        return 0;
    const char *s = f->buf + f->pos, *nl = memchr(s, '\n', f->len - f->pos);
    size_t n = nl ? (size_t)(nl - s) : f->len - f->pos;
    f->pos += n + (nl != NULL);
    f->line++;
    a->cur = (AsmCurLine){s, n, NULL, f->file, f->line, -1};
    return 1;
}

static void pop_frame(Asm *a)
{
    AsmFrame *f = &a->frames[a->nframes - 1];
    if (!a->fatal) {
        for (size_t k = a->nconds; k > f->cond_base; k--)
            asm_error(a, &a->conds[k - 1].loc, "unterminated %s (no matching .endif)", a->conds[k - 1].what);
        if (a->defining && a->def_frame == a->nframes - 1)
            asm_error(a, &a->def_loc, "unterminated .macro '%s' (no matching .endm)", a->defining->name);
    }
    a->nconds = f->cond_base < a->nconds ? f->cond_base : a->nconds;
    if (a->defining && a->def_frame == a->nframes - 1) {
        asm_macro_free(a->defining);
        a->defining = NULL;
    }
    free(f->buf);
    asm_srclines_free(f->lines, f->nlines);
    a->nframes--;
}

/* ---- structure directives: found by a cheap scan so skipped text is never lexed ---------------- */

typedef enum Structural {
    ST_NONE, ST_IF, ST_IFDEF, ST_IFNDEF, ST_ELIF, ST_ELSE, ST_ENDIF, ST_MACRO, ST_ENDM, ST_INCLUDE
} Structural;

static Structural first_word(const char *s, size_t len)
{
    static const struct { const char *w; Structural st; } words[] = {
        {".if", ST_IF}, {".ifdef", ST_IFDEF}, {".ifndef", ST_IFNDEF}, {".elif", ST_ELIF},
        {".else", ST_ELSE}, {".endif", ST_ENDIF}, {".macro", ST_MACRO}, {".endm", ST_ENDM},
        {".include", ST_INCLUDE},
    };
    size_t i = 0;
    while (i < len && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r' || s[i] == '\f' || s[i] == '\v'))
        i++;
    size_t start = i;
    if (i >= len || s[i++] != '.')
        return ST_NONE;
    while (i < len && ((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= 'A' && s[i] <= 'Z') ||
                       (s[i] >= '0' && s[i] <= '9') || s[i] == '_'))
        i++;
    for (size_t k = 0; k < sizeof words / sizeof words[0]; k++)
        if (strlen(words[k].w) == i - start && memcmp(words[k].w, s + start, i - start) == 0)
            return words[k].st;
    return ST_NONE;
}

static int lex_current(Asm *a)
{
    AsmLexError err;
    if (asm_lex_line(a->cur.text, a->cur.len, a->cur.cols, &a->toks, &err) == 0)
        return 0;
    asm_error_at(a, err.col, "%s", err.msg);
    return -1;
}

int asm_active(const Asm *a) { return a->nconds == 0 || a->conds[a->nconds - 1].taking; }

/* ---- conditionals ----------------------------------------------------------------------------- */

/* Value of the condition on t[0] (a .if/.elif/.ifdef/.ifndef line): 1, 0, or -1 on error. */
static int condition(Asm *a, const AsmToken *t, Structural st)
{
    char d[64];
    if (st == ST_IFDEF || st == ST_IFNDEF) {
        if (t[1].kind != ASM_TOK_IDENT) {
            asm_error_at(a, t[1].col, "expected a symbol name after %.*s, found %s", (int)t[0].len,
                         t[0].text, asm_tok_describe(&t[1], d, sizeof d));
            return -1;
        }
        if (t[2].kind != ASM_TOK_EOL) {
            asm_error_at(a, t[2].col, "unexpected %s after %.*s", asm_tok_describe(&t[2], d, sizeof d),
                         (int)t[0].len, t[0].text);
            return -1;
        }
        int def = asm_sym_get(a, t[1].text, t[1].len) != NULL;
        return st == ST_IFDEF ? def : !def;
    }
    int n = 0;
    while (t[1 + n].kind != ASM_TOK_EOL)
        n++;
    AsmValue v;
    char what[32];
    snprintf(what, sizeof what, "%.*s condition", (int)t[0].len, t[0].text);
    if (asm_eval(a, &t[1], n, t[0].col + t[0].len + 1, &v, what) != ASM_EXPR_OK)
        return -1;
    return v.is_float ? v.f != 0.0 : v.i != 0;
}

static AsmCond *cond_top(Asm *a, const AsmToken *dir)
{
    if (a->nconds > a->frames[a->nframes - 1].cond_base)
        return &a->conds[a->nconds - 1];
    asm_error_at(a, dir->col, "%.*s without .if", (int)dir->len, dir->text);
    return NULL;
}

static void cond_push(Asm *a, Structural st, int active, uint32_t col)
{
    /* A wrong condition skips every branch, so nothing after it is judged on a guess. */
    int v = 0;
    if (active)
        v = lex_current(a) == 0 ? condition(a, a->toks.v, st) : -1;
    AsmCond *nc = asm_grow(a->conds, &a->capconds, a->nconds + 1, sizeof *nc);
    if (!nc) {
        asm_oom(a);
        return;
    }
    a->conds = nc;
    a->conds[a->nconds++] = (AsmCond){
        .parent_active = (uint8_t)active, .taking = active && v == 1, .taken = !active || v != 0,
        .what = st == ST_IF ? ".if" : st == ST_IFDEF ? ".ifdef" : ".ifndef", .loc = asm_here(a, col)};
}

static void conditional(Asm *a, Structural st)
{
    int active = asm_active(a);
    /* Lexing is needed for the column of the directive and for its operands; in skipped text a
     * lexical error is not reported (that text is not assembled). */
    AsmLexError lerr;
    uint32_t col = 1;
    if (asm_lex_line(a->cur.text, a->cur.len, a->cur.cols, &a->toks, &lerr) == 0)
        col = a->toks.v[0].col;
    if (st == ST_IF || st == ST_IFDEF || st == ST_IFNDEF) {
        cond_push(a, st, active, col);
        return;
    }
    AsmToken dir = {0};
    dir.text = st == ST_ELIF ? ".elif" : st == ST_ELSE ? ".else" : ".endif";
    dir.len = (uint32_t)strlen(dir.text);
    dir.col = col;
    AsmCond *c = cond_top(a, &dir);
    if (!c)
        return;
    if (st == ST_ENDIF || st == ST_ELSE) {
        if (c->parent_active && lex_current(a) == 0 && a->toks.v[1].kind != ASM_TOK_EOL) {
            char d[64];
            asm_error_at(a, a->toks.v[1].col, "unexpected %s after %s",
                         asm_tok_describe(&a->toks.v[1], d, sizeof d), dir.text);
        }
        if (st == ST_ENDIF) {
            a->nconds--;
            return;
        }
    }
    if (c->seen_else) {
        asm_error_at(a, col, "%s after .else", dir.text);
        c->taking = 0;
        return;
    }
    if (st == ST_ELSE) {
        c->taking = c->parent_active && !c->taken;
        c->taken = c->seen_else = 1;
        return;
    }
    int v = 0;
    if (c->parent_active && !c->taken)
        v = lex_current(a) == 0 ? condition(a, a->toks.v, ST_IF) : -1;
    c->taking = c->parent_active && !c->taken && v == 1;
    c->taken |= v != 0 || !c->parent_active;
}

/* ---- macros ----------------------------------------------------------------------------------- */

static int is_mnemonic(const AsmToken *t)
{
    char name[16];
    if (t->len >= sizeof name)
        return 0;
    memcpy(name, t->text, t->len);
    name[t->len] = '\0';
    return isa_op_from_mnemonic(name) >= 0;
}

/* Parameters "a, b=default, c": the default is the raw text up to the next top-level comma. */
static int macro_params(Asm *a, AsmMacro *m, const AsmToken *t, int k)
{
    char d[64];
    while (t[k].kind != ASM_TOK_EOL) {
        const AsmToken *p = &t[k];
        if (p->kind != ASM_TOK_IDENT && p->kind != ASM_TOK_REG) {
            asm_error_at(a, p->col, "expected a parameter name, found %s", asm_tok_describe(p, d, sizeof d));
            return -1;
        }
        if (asm_macro_param(m, p->text, p->len) >= 0) {
            asm_error_at(a, p->col, "duplicate parameter '%.*s'", (int)p->len, p->text);
            return -1;
        }
        int end = asm_tok_arg_end(t, k + 1, 0);
        const char *def = NULL;
        size_t deflen = 0;
        if (k + 1 < end && t[k + 1].kind == ASM_TOK_PUNCT && t[k + 1].punct == ASM_P_ASSIGN) {
            def = "";
            if (k + 2 < end) {
                def = t[k + 2].text;
                deflen = t[end - 1].off + t[end - 1].len - t[k + 2].off;
            }
        } else if (k + 1 < end) {
            asm_error_at(a, t[k + 1].col, "expected ',' or '=' after parameter '%.*s', found %s",
                         (int)p->len, p->text, asm_tok_describe(&t[k + 1], d, sizeof d));
            return -1;
        }
        if (asm_macro_add_param(m, p->text, p->len, def, deflen) < 0) {
            asm_oom(a);
            return -1;
        }
        k = t[end].kind == ASM_TOK_EOL ? end : end + 1;
        if (t[end].kind != ASM_TOK_EOL && t[k].kind == ASM_TOK_EOL) {
            asm_error_at(a, t[k].col, "expected a parameter name after ','");
            return -1;
        }
    }
    return 0;
}

static void begin_macro(Asm *a)
{
    /* Even a wrong .macro line opens a body (dropped at .endm), so its lines are not assembled. */
    static const AsmToken bad[2] = {{.kind = ASM_TOK_DIRECTIVE, .col = 1}, {.kind = ASM_TOK_EOL}};
    int lexed = lex_current(a) == 0;
    const AsmToken *t = lexed ? a->toks.v : bad, *name = &t[1];
    char d[64];
    int ok = lexed;
    const AsmMacro *old = name->kind == ASM_TOK_IDENT ? asm_table_get(&a->macrotab, name->text, name->len) : NULL;
    if (!lexed) {
        /* reported by the lexer */
    } else if (name->kind != ASM_TOK_IDENT) {
        asm_error_at(a, name->col, "expected a macro name after .macro, found %s", asm_tok_describe(name, d, sizeof d));
        ok = 0;
    } else if (is_mnemonic(name)) {
        asm_error_at(a, name->col, "macro name '%.*s' is an instruction mnemonic", (int)name->len, name->text);
        ok = 0;
    } else if (old) {
        asm_error_at(a, name->col, "macro '%.*s' is already defined at %s:%u", (int)name->len, name->text,
                     asm_file_name(a, old->file), old->line);
        ok = 0;
    }
    const char *nm = name->kind == ASM_TOK_IDENT ? name->text : "?";
    AsmMacro *m = asm_macro_new(nm, name->kind == ASM_TOK_IDENT ? name->len : 1, a->cur.file, a->cur.line);
    if (!m) {
        asm_oom(a);
        return;
    }
    if (ok && macro_params(a, m, t, 2) < 0)
        ok = 0;
    a->defining = m;
    a->def_discard = !ok;
    a->def_depth = 1;
    a->def_frame = a->nframes - 1;
    a->def_loc = asm_here(a, t[0].col);
}

static void finish_macro(Asm *a)
{
    AsmMacro *m = a->defining;
    a->defining = NULL;
    if (a->def_discard) {
        asm_macro_free(m);
        return;
    }
    AsmMacro **nl = asm_grow(a->macros, &a->capmacros, a->nmacros + 1, sizeof *nl);
    if (nl)
        a->macros = nl;
    if (!nl || asm_table_put(&a->macrotab, m->name, strlen(m->name), m) < 0) {
        asm_macro_free(m);
        asm_oom(a);
        return;
    }
    a->macros[a->nmacros++] = m;
}

/* A line while a .macro body is open: nested .macro/.endm pairs belong to the body. */
static void collect_macro_line(Asm *a, Structural st)
{
    if (st == ST_MACRO)
        a->def_depth++;
    else if (st == ST_ENDM && --a->def_depth == 0) {
        finish_macro(a);
        return;
    }
    if (asm_macro_add_line(a->defining, a->cur.text, a->cur.len, a->cur.cols, a->cur.file, a->cur.line) < 0)
        asm_oom(a);
}

/* Argument texts for a call: given ones, else defaults. NULL after reporting a problem. */
static char **macro_args(Asm *a, const AsmMacro *m, const AsmToken *t, int k, uint32_t call_col)
{
    char **args = calloc((size_t)(m->nparams ? m->nparams : 1), sizeof *args);
    if (!args) {
        asm_oom(a);
        return NULL;
    }
    for (int n = 0; t[k].kind != ASM_TOK_EOL || n > 0; n++) {
        int end = asm_tok_arg_end(t, k, 0);
        if (n >= m->nparams) {
            asm_error_at(a, t[k].col, "macro '%s' takes %d argument%s", m->name, m->nparams,
                         m->nparams == 1 ? "" : "s");
            goto fail;
        }
        if (end > k && !(args[n] = strndup(t[k].text, t[end - 1].off + t[end - 1].len - t[k].off))) {
            asm_oom(a);
            goto fail;
        }
        if (t[end].kind == ASM_TOK_EOL)
            break;
        k = end + 1; /* after a comma: one more (maybe empty) argument follows */
    }
    for (int i = 0; i < m->nparams; i++) {
        if (args[i])
            continue;
        if (!m->defaults[i]) {
            asm_error_at(a, call_col, "missing argument '%s' for macro '%s'", m->params[i], m->name);
            goto fail;
        }
        if (!(args[i] = strdup(m->defaults[i]))) {
            asm_oom(a);
            goto fail;
        }
    }
    return args;
fail:
    for (int i = 0; i < m->nparams; i++)
        free(args[i]);
    free(args);
    return NULL;
}

static int push_expansion(Asm *a, const AsmMacro *m)
{
    AsmExpansion *ne = asm_grow(a->exps, &a->capexps, a->nexps + 1, sizeof *ne);
    if (!ne)
        return -1;
    a->exps = ne;
    a->exps[a->nexps] = (AsmExpansion){m->name, a->cur.file, a->cur.line, a->cur.exp};
    return (int)a->nexps++;
}

void asm_macro_call(Asm *a, const AsmMacro *m, const AsmToken *t, int first_arg)
{
    const AsmToken *name = &t[first_arg - 1];
    if (count_frames(a, 1) >= ASM_MAX_MACRO_DEPTH) {
        /* Recursion without an end: one error, then stop, since the calls beside this one in
         * every enclosing expansion would each hit the limit again (2^64 errors for a macro that
         * calls itself twice). */
        asm_error_at(a, name->col,
                     "macro '%s' (defined at %s:%u) nested too deeply: more than %d nested expansions "
                     "(does it call itself without an end?)",
                     m->name, asm_file_name(a, m->file), m->line, ASM_MAX_MACRO_DEPTH);
        a->fatal = 1;
        return;
    }
    if (m->nbody > ASM_MAX_EXPAND_LINES - a->expand_lines) {
        asm_error_at(a, name->col, "macro expansions exceed %u lines in total (runaway recursion?)",
                     ASM_MAX_EXPAND_LINES);
        a->fatal = 1;
        return;
    }
    char **args = macro_args(a, m, t, first_arg, name->col);
    if (!args)
        return;
    AsmSrcLine *lines;
    size_t bytes;
    int rc = asm_macro_expand(m, args, ++a->unique, ASM_MAX_EXPAND_BYTES - a->expand_bytes, &lines, &bytes);
    for (int i = 0; i < m->nparams; i++)
        free(args[i]);
    free(args);
    if (rc == -2) {
        asm_error_at(a, name->col, "macro expansions exceed %u MiB of text in total (runaway recursion?)",
                     ASM_MAX_EXPAND_BYTES >> 20);
        a->fatal = 1;
        return;
    }
    int exp = rc == 0 ? push_expansion(a, m) : -1;
    AsmFrame *f = exp >= 0 ? push_frame(a) : NULL;
    if (!f) {
        if (rc == 0)
            asm_srclines_free(lines, m->nbody);
        asm_oom(a);
        return;
    }
    a->expand_lines += m->nbody;
    a->expand_bytes += bytes;
    f->is_macro = 1;
    f->lines = lines;
    f->nlines = m->nbody;
    f->exp = exp;
}

/* ---- .include --------------------------------------------------------------------------------- */

static void include(Asm *a)
{
    if (lex_current(a) < 0)
        return;
    const AsmToken *t = a->toks.v;
    char d[64], why[128];
    if (t[1].kind != ASM_TOK_STRING) {
        asm_error_at(a, t[1].col, "expected a file name in quotes after .include, found %s",
                     asm_tok_describe(&t[1], d, sizeof d));
        return;
    }
    if (t[2].kind != ASM_TOK_EOL) {
        asm_error_at(a, t[2].col, "unexpected %s after .include", asm_tok_describe(&t[2], d, sizeof d));
        return;
    }
    if (count_frames(a, 0) > ASM_MAX_INCLUDE_DEPTH) {
        asm_error_at(a, t[0].col, "includes nested too deeply (limit %d)", ASM_MAX_INCLUDE_DEPTH);
        return;
    }
    /* Depth alone does not bound a file that includes itself twice (2^32 reads). */
    if (++a->nincludes > ASM_MAX_INCLUDES) {
        asm_error_at(a, t[0].col, "more than %u .include operations in total (runaway includes?)",
                     ASM_MAX_INCLUDES);
        a->fatal = 1;
        return;
    }
    char *path = find_include(a, t[1].str, asm_file_name(a, a->cur.file));
    if (!path) {
        asm_error_at(a, t[1].col, "include file '%s' not found", t[1].str);
        return;
    }
    char *buf;
    size_t len;
    if (read_source(path, ASM_MAX_INPUT_BYTES - a->input_bytes, &buf, &len, why, sizeof why) < 0) {
        asm_error_at(a, t[1].col, "cannot read include file '%s': %s", path, why);
        free(path);
        return;
    }
    a->input_bytes += len;
    int file = add_file(a, path);
    free(path);
    AsmFrame *f = file >= 0 ? push_frame(a) : NULL;
    if (!f) {
        free(buf);
        asm_oom(a);
        return;
    }
    f->buf = buf;
    f->len = len;
    f->file = file;
}

/* ---- pass 1 ----------------------------------------------------------------------------------- */

static void process_line(Asm *a)
{
    Structural st = first_word(a->cur.text, a->cur.len);
    if (a->defining) {
        collect_macro_line(a, st);
        return;
    }
    if (st >= ST_IF && st <= ST_ENDIF) {
        conditional(a, st);
        return;
    }
    if (!asm_active(a))
        return;
    switch (st) {
    case ST_MACRO: begin_macro(a); return;
    case ST_INCLUDE: include(a); return;
    case ST_ENDM:
        if (lex_current(a) == 0)
            asm_error_at(a, a->toks.v[0].col, ".endm without .macro");
        return;
    default: break;
    }
    if (lex_current(a) == 0)
        asm_statement(a, a->toks.v);
}

static void pass1(Asm *a)
{
    while (a->nframes && !a->fatal) {
        if (!next_line(a, &a->frames[a->nframes - 1])) {
            pop_frame(a);
            continue;
        }
        a->seq++;
        process_line(a);
    }
    while (a->nframes)
        pop_frame(a);
}

/* ---- entry points ----------------------------------------------------------------------------- */

static void free_asm(Asm *a)
{
    while (a->nframes)
        pop_frame(a);
    free(a->frames);
    asm_macro_free(a->defining);
    asm_tokens_free(&a->toks);
    free(a->conds);
    asm_symbols_free(a);
    for (size_t i = 0; i < a->nmacros; i++)
        asm_macro_free(a->macros[i]);
    free(a->macros);
    asm_table_free(&a->macrotab);
    free(a->exps);
    free(a->smarks);
    free(a->text);
    free(a->lines);
    free(a->data.v);
    free(a->spad.v);
    for (size_t i = 0; i < a->nfiles; i++)
        free(a->files[i]);
    free(a->files);
}

/* The scheduling pass over the object, with the fences the source set (.barrier, .sched). */
static void schedule(Asm *a, AsmObject *obj)
{
    uint8_t *marks = calloc((size_t)obj->ntext + 1, 1);
    int off = 0;
    size_t k = 0;
    for (uint32_t i = 0; marks && i <= obj->ntext; i++) {
        for (; k < a->nsmarks && a->smarks[k].at == i; k++) {
            if (a->smarks[k].kind == ASM_SMARK_BARRIER)
                marks[i] |= SCHED_MARK_LEADER;
            else
                off = a->smarks[k].kind == ASM_SMARK_OFF;
        }
        if (off)
            marks[i] |= SCHED_MARK_FIXED;
    }
    if (!marks || sched_object(obj, marks, a->opt->schedule, a->opt->schedule_report, NULL) != 0) {
        asm_object_free(obj);
        asm_oom(a);
    }
    free(marks);
}

/* Assembles buf (taken over) as file name. */
static int assemble(const char *name, char *buf, size_t len, const AsmOptions *opt, AsmObject *obj)
{
    static const AsmOptions none = {0};
    Asm a = {.opt = opt ? opt : &none, .section = ASM_SEC_TEXT, .pass = 1};
    memset(obj, 0, sizeof *obj);
    for (int i = 0; i < a.opt->ndefines; i++)
        asm_define_cmdline(&a, &a.opt->defines[i]);
    int file = add_file(&a, name ? name : "<input>");
    AsmFrame *f = file >= 0 ? push_frame(&a) : NULL;
    if (!f) {
        free(buf);
        asm_oom(&a);
    } else if (len > ASM_MAX_INPUT_BYTES) {
        free(buf);
        a.cur = (AsmCurLine){.file = file, .line = 1, .exp = -1};
        asm_error_at(&a, 1, "input exceeds %u MiB", ASM_MAX_INPUT_BYTES >> 20);
        a.fatal = 1;
    } else {
        f->buf = buf;
        f->len = len;
        f->file = file;
        a.input_bytes = len;
        pass1(&a);
    }
    if (!a.fatal)
        asm_pass2(&a);
    if (a.errors == 0 && asm_build_object(&a, obj) == 0 && a.opt->schedule)
        schedule(&a, obj);
    flush_diags(&a);
    int errors = a.errors;
    free_asm(&a);
    return errors;
}

int asm_assemble_string(const char *name, const char *src, size_t len, const AsmOptions *opt,
                        AsmObject *obj)
{
    char *buf = malloc(len + 1);
    if (buf && len)
        memcpy(buf, src, len);
    if (!buf) {
        memset(obj, 0, sizeof *obj);
        fprintf(opt && opt->diag ? opt->diag : stderr, "%s:1:1: out of memory\n", name ? name : "<input>");
        return 1;
    }
    return assemble(name, buf, len, opt, obj);
}

int asm_assemble_file(const char *path, const AsmOptions *opt, AsmObject *obj)
{
    char *buf, why[128];
    size_t len;
    if (read_source(path, ASM_MAX_INPUT_BYTES, &buf, &len, why, sizeof why) < 0) {
        memset(obj, 0, sizeof *obj);
        fprintf(opt && opt->diag ? opt->diag : stderr, "%s:1:1: cannot read file: %s\n", path, why);
        return 1;
    }
    return assemble(path, buf, len, opt, obj);
}
