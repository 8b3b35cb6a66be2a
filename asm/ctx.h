/* asm/ctx.h -- the state of one sfasm run, shared by its three passes' modules (internal).
 *
 *   asm.c      driver: sources, includes, conditionals, macro definition and expansion,
 *              diagnostics, the public entry points;
 *   stmt.c     one statement: labels, constants, directives, instructions and their operands;
 *   symbols.c  symbols and aliases, expression evaluation, deferred expressions, the second
 *              pass (fixups) and the output object.
 *
 * Must not: be included outside asm/.
 */
#ifndef SFSIM_ASM_CTX_H
#define SFSIM_ASM_CTX_H

#include <stdint.h>
#include <stdio.h>

#include "asm.h"
#include "expr.h"
#include "lex.h"
#include "macro.h"
#include "table.h"

/* Limits. Each one, when reached, is an error with a message: nothing is truncated silently. */
#define ASM_MAX_INCLUDE_DEPTH  32
#define ASM_MAX_MACRO_DEPTH    64
#define ASM_MAX_SECTION_BYTES  (64u << 20)              /* .data / .spad images */
#define ASM_MAX_TEXT_WORDS     (ASM_MAX_SECTION_BYTES / 8) /* 8M instructions */
/* All files read, includes too. Large enough for the disassembly of the largest object (two
 * 64 MiB images and 8M instructions come to about 1.3 GiB of text) to assemble again. */
#define ASM_MAX_INPUT_BYTES    (2048u << 20)
#define ASM_MAX_INCLUDES       10000u                   /* .include operations in total */
#define ASM_MAX_EXPAND_LINES   250000u                  /* all macro expansions together */
#define ASM_MAX_EXPAND_BYTES   (16u << 20)
#define ASM_MAX_DEFER_DEPTH    200                      /* chains of forward-defined constants */
/* Diagnostics printed: the first ones in source order, then "... and N more errors". Every error
 * still counts; at most twice this many are kept in memory at once. */
#define ASM_MAX_ERRORS_SHOWN   50

/* Where something is: file index, line, column (1-based), macro expansion (-1: none) and the
 * sequence number of the source line, which orders diagnostics. */
typedef struct AsmLoc {
    int file;
    uint32_t line, col;
    int exp;
    uint64_t seq;
} AsmLoc;

/* An expression kept for the second pass (it names a symbol defined later). */
typedef struct AsmDeferred {
    char *text;          /* copy of the source text the tokens point into */
    AsmToken *toks;
    int ntoks;
    uint32_t at_col;
    AsmValue dot;        /* '.' where the expression was written */
    AsmLoc loc;
} AsmDeferred;

typedef enum AsmSymKind { ASM_SYM_LABEL, ASM_SYM_EQU, ASM_SYM_SET, ASM_SYM_DEFINE } AsmSymKind;
typedef enum AsmSymState {
    ASM_SYM_KNOWN, ASM_SYM_PENDING, ASM_SYM_RESOLVING, ASM_SYM_FAILED
} AsmSymState;

typedef struct AsmSym {
    char *name;
    AsmSymKind kind;
    AsmSymState state;
    AsmValue value;
    AsmDeferred *expr;   /* ASM_SYM_PENDING: the defining expression */
    AsmLoc loc;
} AsmSym;

/* A value to store in the second pass: into an instruction's immediate or a data image. */
typedef enum AsmFixKind { ASM_FIX_IMM, ASM_FIX_LABEL, ASM_FIX_WORD, ASM_FIX_FLOAT, ASM_FIX_BYTE } AsmFixKind;

typedef struct AsmFixup {
    AsmFixKind kind;
    uint8_t sec;         /* ASM_SEC_TEXT / DATA / SPAD */
    uint32_t at;         /* instruction index or byte offset */
    int op, opidx;       /* instruction and 1-based operand, for messages */
    AsmDeferred *expr;   /* NULL when value is already known */
    AsmValue value;
    AsmLoc loc;
} AsmFixup;

typedef struct AsmAlias {
    int kind, num;       /* IsaOperandKind and register number */
    int live;            /* 0 after .unalias */
} AsmAlias;

typedef struct AsmExpansion {
    const char *macro;
    int call_file;
    uint32_t call_line;
    int parent;
} AsmExpansion;

typedef struct AsmCond {
    uint8_t parent_active, taking, taken, seen_else;
    const char *what;    /* ".if", ".ifdef", ".ifndef" */
    AsmLoc loc;
} AsmCond;

typedef struct AsmFrame {
    int is_macro;
    /* a file */
    char *buf;
    size_t len, pos;
    int file;
    uint32_t line;
    /* a macro expansion */
    AsmSrcLine *lines;
    size_t nlines, next;
    int exp;
    size_t cond_base;    /* conditional depth when the frame started */
} AsmFrame;

typedef struct AsmCurLine {
    const char *text;
    size_t len;
    const uint32_t *cols;
    int file;
    uint32_t line;
    int exp;
} AsmCurLine;

typedef struct AsmDiag {
    uint64_t seq;        /* source line it belongs to */
    size_t order;        /* order of reporting, to keep the sort stable */
    char *text;
} AsmDiag;

typedef struct AsmBytes {
    uint8_t *v;
    size_t n, cap;
} AsmBytes;

/* A scheduling fence at a text index (.barrier, .sched off, .sched on). */
enum { ASM_SMARK_BARRIER, ASM_SMARK_OFF, ASM_SMARK_ON };
typedef struct AsmSchedMark {
    uint32_t at;
    int kind;
} AsmSchedMark;

typedef struct Asm {
    const AsmOptions *opt;
    int errors;
    int fatal;                   /* stop reading input (a limit was hit) */
    AsmDiag *diags;   size_t ndiags, capdiags;
    size_t diags_dropped;        /* diagnostics beyond the first ASM_MAX_ERRORS_SHOWN, freed */
    char **files;     size_t nfiles, capfiles;
    AsmFrame *frames; size_t nframes, capframes;
    AsmCurLine cur;
    uint64_t seq;
    AsmTokens toks;
    AsmCond *conds;   size_t nconds, capconds;
    AsmTable symtab;  AsmSym **syms;       size_t nsyms, capsyms;
    AsmTable aliastab; AsmAlias **aliases; size_t naliases, capaliases;
    AsmTable macrotab; AsmMacro **macros;  size_t nmacros, capmacros;
    AsmMacro *defining;          /* a .macro body being collected */
    int def_discard;             /* the .macro line was wrong: collect, then drop */
    size_t def_depth, def_frame;
    AsmLoc def_loc;
    AsmExpansion *exps; size_t nexps, capexps;
    unsigned long unique;        /* \@ */
    size_t expand_lines, expand_bytes;
    size_t input_bytes, nincludes;
    int section;                 /* ASM_SEC_TEXT, ASM_SEC_DATA or ASM_SEC_SPAD */
    uint64_t *text;   AsmLine *lines; size_t ntext, captext, caplines;
    AsmBytes data, spad;
    AsmFixup *fix;    size_t nfix, capfix;
    AsmSchedMark *smarks; size_t nsmarks, capsmarks;
    int pass;                    /* 1 while reading, 2 while resolving */
    int defer_depth;
} Asm;

/* asm.c */
__attribute__((format(printf, 3, 4)))
void asm_error(Asm *a, const AsmLoc *loc, const char *fmt, ...);
__attribute__((format(printf, 3, 4)))
void asm_error_at(Asm *a, uint32_t col, const char *fmt, ...);  /* on the current line */
AsmLoc asm_here(const Asm *a, uint32_t col);
void asm_oom(Asm *a);
/* Returns v grown to hold need elements of size elem (cap updated), or NULL (v untouched). */
void *asm_grow(void *v, size_t *cap, size_t need, size_t elem);
const char *asm_file_name(const Asm *a, int file);
void asm_macro_call(Asm *a, const AsmMacro *m, const AsmToken *t, int first_arg);
int asm_active(const Asm *a);

/* stmt.c */
void asm_statement(Asm *a, const AsmToken *t);

/* symbols.c */
AsmSym *asm_sym_get(const Asm *a, const char *name, size_t len);
const AsmAlias *asm_alias_get(const Asm *a, const char *name, size_t len);
int asm_alias_set(Asm *a, const AsmToken *name, int kind, int num);
int asm_alias_remove(Asm *a, const AsmToken *name);
void asm_define_label(Asm *a, const AsmToken *name);
void asm_define_const(Asm *a, const AsmToken *name, AsmSymKind kind, const AsmToken *expr, int n,
                      uint32_t at_col);
void asm_define_cmdline(Asm *a, const AsmDefine *d);
/* Current location '.' in the current section. */
AsmValue asm_dot(const Asm *a);
/* Evaluates toks[0, n) in the first pass: ASM_EXPR_OK, ASM_EXPR_PENDING (nothing reported),
 * or ASM_EXPR_ERROR (reported). With must_resolve, PENDING is reported as an error naming
 * what (".if condition", ".space size"...) and ASM_EXPR_ERROR is returned. */
int asm_eval(Asm *a, const AsmToken *toks, int n, uint32_t at_col, AsmValue *out,
             const char *must_resolve);
AsmDeferred *asm_defer(Asm *a, const AsmToken *toks, int n, uint32_t at_col);
void asm_deferred_free(AsmDeferred *d);
int asm_add_fixup(Asm *a, const AsmFixup *f);
void asm_pass2(Asm *a);
int asm_build_object(Asm *a, AsmObject *obj);
void asm_symbols_free(Asm *a);
/* Checks a value for an instruction's immediate or label operand and returns its bits;
 * -1 after reporting at loc. Label range checks need ntext, so they run in pass 2. */
int asm_check_imm(Asm *a, int op, int opidx, int label, const AsmValue *v, const AsmLoc *loc,
                  uint32_t *bits);
int asm_check_data(Asm *a, AsmFixKind kind, const AsmValue *v, const AsmLoc *loc, uint8_t *bytes);

#endif
