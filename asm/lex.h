/* asm/lex.h -- sfasm's lexer: one source line into tokens (internal to asm/).
 *
 * Owns: the token grammar (identifiers, directives, registers, numbers, characters, strings,
 * operators, comments). Must not: look up symbols, know mnemonics or keep state between lines.
 */
#ifndef SFSIM_ASM_LEX_H
#define SFSIM_ASM_LEX_H

#include <stddef.h>
#include <stdint.h>

typedef enum AsmTokKind {
    ASM_TOK_EOL,        /* end of the line (always the last token) */
    ASM_TOK_IDENT,      /* name: [A-Za-z_][A-Za-z0-9_]* that is not a register */
    ASM_TOK_DIRECTIVE,  /* '.' followed by a name, e.g. ".word" */
    ASM_TOK_REG,        /* [rvm][0-9]+ (number not range-checked here) */
    ASM_TOK_INT,        /* integer or character literal */
    ASM_TOK_FLOAT,      /* float literal */
    ASM_TOK_STRING,     /* "..." with escapes resolved */
    ASM_TOK_PUNCT       /* operator or punctuation, see AsmPunct */
} AsmTokKind;

typedef enum AsmPunct {
    ASM_P_LPAREN, ASM_P_RPAREN, ASM_P_COMMA, ASM_P_COLON, ASM_P_ASSIGN, ASM_P_AT, ASM_P_DOT,
    ASM_P_PLUS, ASM_P_MINUS, ASM_P_STAR, ASM_P_SLASH, ASM_P_PERCENT, ASM_P_TILDE, ASM_P_BANG,
    ASM_P_SHL, ASM_P_SHR, ASM_P_LT, ASM_P_LE, ASM_P_GT, ASM_P_GE, ASM_P_EQ, ASM_P_NE,
    ASM_P_AMP, ASM_P_ANDAND, ASM_P_PIPE, ASM_P_OROR, ASM_P_CARET
} AsmPunct;

typedef struct AsmToken {
    AsmTokKind kind;
    int punct;            /* AsmPunct for ASM_TOK_PUNCT */
    uint32_t col;         /* 1-based column in the original source line */
    uint32_t off, len;    /* the token's bytes in the lexed text */
    const char *text;     /* lexed text + off (not NUL-terminated) */
    int64_t ival;         /* ASM_TOK_INT */
    double fval;          /* ASM_TOK_FLOAT */
    int reg_kind;         /* ASM_TOK_REG: IsaOperandKind (ISA_K_R, ISA_K_V or ISA_K_M) */
    int reg_num;          /* ASM_TOK_REG: number, saturated at 9999 */
    char *str;            /* ASM_TOK_STRING: unescaped, NUL-terminated, owned by the list */
} AsmToken;

typedef struct AsmTokens {
    AsmToken *v;
    int n, cap;
} AsmTokens;

typedef struct AsmLexError {
    uint32_t col;
    char msg[192];
} AsmLexError;

/* Tokenize text[0, len) (one line, no newline). colmap, if not NULL, gives the source column of
 * each byte (macro expansions); otherwise a byte's column is its offset + 1. Replaces the
 * contents of out. Returns 0, or -1 with err filled (the first lexical error of the line). */
int asm_lex_line(const char *text, size_t len, const uint32_t *colmap, AsmTokens *out,
                 AsmLexError *err);
void asm_tokens_clear(AsmTokens *t);
void asm_tokens_free(AsmTokens *t);
/* Printable name of a token for messages ("'foo'", "end of line"), into buf. */
const char *asm_tok_describe(const AsmToken *t, char *buf, size_t len);
const char *asm_punct_text(int punct);
/* Index of the first ',' (or '@' when stop_at_at) outside parentheses at or after i, or of the
 * end-of-line token: the end of one comma-separated argument. */
int asm_tok_arg_end(const AsmToken *t, int i, int stop_at_at);

#endif
