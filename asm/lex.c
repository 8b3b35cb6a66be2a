/* asm/lex.c -- sfasm's lexer: one source line into tokens.
 *
 * Owns: the spelling of every token (docs/assembler.md, "Lexical structure"). Must not: look up
 * symbols or mnemonics, or keep any state between lines; it reports only the first lexical error
 * of a line because the rest of a line after a bad token has no reliable meaning.
 */
#include "lex.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../isa/isa.h"

static const char *const punct_text[] = {
    [ASM_P_LPAREN] = "(", [ASM_P_RPAREN] = ")", [ASM_P_COMMA] = ",", [ASM_P_COLON] = ":",
    [ASM_P_ASSIGN] = "=", [ASM_P_AT] = "@", [ASM_P_DOT] = ".", [ASM_P_PLUS] = "+",
    [ASM_P_MINUS] = "-", [ASM_P_STAR] = "*", [ASM_P_SLASH] = "/", [ASM_P_PERCENT] = "%",
    [ASM_P_TILDE] = "~", [ASM_P_BANG] = "!", [ASM_P_SHL] = "<<", [ASM_P_SHR] = ">>",
    [ASM_P_LT] = "<", [ASM_P_LE] = "<=", [ASM_P_GT] = ">", [ASM_P_GE] = ">=", [ASM_P_EQ] = "==",
    [ASM_P_NE] = "!=", [ASM_P_AMP] = "&", [ASM_P_ANDAND] = "&&", [ASM_P_PIPE] = "|",
    [ASM_P_OROR] = "||", [ASM_P_CARET] = "^",
};

const char *asm_punct_text(int punct)
{
    if (punct < 0 || punct >= (int)(sizeof punct_text / sizeof punct_text[0]))
        return "?";
    return punct_text[punct];
}

/* The lexer's working state for one line. */
typedef struct Lexer {
    const char *s;
    size_t len, pos;
    const uint32_t *colmap;
    AsmTokens *out;
    AsmLexError *err;
} Lexer;

static uint32_t col_at(const Lexer *lx, size_t off)
{
    if (lx->colmap)
        return off < lx->len ? lx->colmap[off] : (lx->len ? lx->colmap[lx->len - 1] + 1 : 1);
    return (uint32_t)off + 1;
}

static int is_ident_start(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_digit(int c) { return c >= '0' && c <= '9'; }
static int is_ident_char(int c) { return is_ident_start(c) || is_digit(c); }

__attribute__((format(printf, 3, 4)))
static int lex_fail(Lexer *lx, size_t off, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    lx->err->col = col_at(lx, off);
    vsnprintf(lx->err->msg, sizeof lx->err->msg, fmt, ap);
    va_end(ap);
    return -1;
}

/* Source text for a message: long text is shortened in the message only. */
static const char *shown(const char *s, size_t n, char *buf, size_t len)
{
    if (n > 40)
        snprintf(buf, len, "%.40s...", s);
    else
        snprintf(buf, len, "%.*s", (int)n, s);
    return buf;
}

static AsmToken *push_token(Lexer *lx, AsmTokKind kind, size_t off, size_t len)
{
    AsmTokens *t = lx->out;
    if (t->n == t->cap) {
        int ncap = t->cap ? t->cap * 2 : 16;
        AsmToken *nv = realloc(t->v, (size_t)ncap * sizeof *nv);
        if (!nv)
            return NULL;
        t->v = nv;
        t->cap = ncap;
    }
    AsmToken *tok = &t->v[t->n++];
    memset(tok, 0, sizeof *tok);
    tok->kind = kind;
    tok->off = (uint32_t)off;
    tok->len = (uint32_t)len;
    tok->text = lx->s + off;
    tok->col = col_at(lx, off);
    return tok;
}

static int oom(Lexer *lx)
{
    lx->err->col = col_at(lx, lx->pos);
    snprintf(lx->err->msg, sizeof lx->err->msg, "out of memory");
    return -1;
}

/* ---- numbers -------------------------------------------------------------------------------- */

static size_t scan_digits(const char *s, size_t i, size_t end, int base)
{
    while (i < end) {
        int c = s[i];
        int ok = base == 2 ? (c == '0' || c == '1')
                 : base == 16 ? (is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F'))
                              : is_digit(c);
        if (!ok)
            break;
        i++;
    }
    return i;
}

/* Is s[0, n) a decimal float: digits [. digits] [e[+-]digits] [f], with a '.', exponent or
 * suffix, and at least one mantissa digit? *body gets the length without the suffix. */
static int is_decimal_float(const char *s, size_t n, size_t *body)
{
    size_t i = scan_digits(s, 0, n, 10), mant = i;
    int marked = 0;
    if (i < n && s[i] == '.') {
        size_t j = scan_digits(s, i + 1, n, 10);
        mant += j - i - 1;
        i = j;
        marked = 1;
    }
    if (mant == 0)
        return 0;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        size_t j = i + 1;
        if (j < n && (s[j] == '+' || s[j] == '-'))
            j++;
        size_t k = scan_digits(s, j, n, 10);
        if (k == j)
            return 0;
        i = k;
        marked = 1;
    }
    *body = i;
    if (i < n && (s[i] == 'f' || s[i] == 'F')) {
        i++;
        marked = 1;
    }
    return marked && i == n;
}

static int lex_int(Lexer *lx, size_t start, size_t n, int base, size_t skip)
{
    const char *s = lx->s + start;
    char sb[64];
    uint64_t v = 0;
    for (size_t i = skip; i < n; i++) {
        int c = s[i];
        unsigned d = is_digit(c) ? (unsigned)(c - '0') : (unsigned)((c | 0x20) - 'a' + 10);
        if (v > (UINT64_MAX - d) / (uint64_t)base || v * (uint64_t)base + d > (uint64_t)INT64_MAX)
            return lex_fail(lx, start, "integer literal '%s' is too large", shown(s, n, sb, sizeof sb));
        v = v * (uint64_t)base + d;
    }
    AsmToken *t = push_token(lx, ASM_TOK_INT, start, n);
    if (!t)
        return oom(lx);
    t->ival = (int64_t)v;
    return 0;
}

static int lex_float(Lexer *lx, size_t start, size_t n, size_t body)
{
    char tmp[128], sb[64];
    const char *s = lx->s + start;
    if (body >= sizeof tmp)
        return lex_fail(lx, start, "float literal '%s' is too long", shown(s, n, sb, sizeof sb));
    memcpy(tmp, s, body);
    tmp[body] = '\0';
    errno = 0;
    double d = strtod(tmp, NULL);
    /* Underflow to a denormal or zero is a fine value; only overflow is an error. */
    if (errno == ERANGE && isinf(d))
        return lex_fail(lx, start, "float literal '%s' is out of range", shown(s, n, sb, sizeof sb));
    AsmToken *t = push_token(lx, ASM_TOK_FLOAT, start, n);
    if (!t)
        return oom(lx);
    t->fval = d;
    return 0;
}

/* A number is the longest run of [0-9A-Za-z_.] (plus a sign after a decimal exponent), so
 * that "12abc" is one bad literal rather than 12 followed by a name. */
static int lex_number(Lexer *lx)
{
    size_t start = lx->pos, i = start;
    const char *s = lx->s;
    int hexish = lx->len - start >= 2 && s[start] == '0' &&
                 (s[start + 1] == 'x' || s[start + 1] == 'X' || s[start + 1] == 'b' || s[start + 1] == 'B');
    while (i < lx->len) {
        int c = s[i];
        if (is_ident_char(c) || c == '.')
            i++;
        else if ((c == '+' || c == '-') && !hexish && (s[i - 1] == 'e' || s[i - 1] == 'E'))
            i++;
        else
            break;
    }
    lx->pos = i;
    char sb[64];
    size_t n = i - start, body;
    const char *t = s + start;
    if (hexish) {
        int base = (t[1] == 'x' || t[1] == 'X') ? 16 : 2;
        if (n > 2 && scan_digits(t, 2, n, base) == n)
            return lex_int(lx, start, n, base, 2);
    } else if (scan_digits(t, 0, n, 10) == n) {
        return lex_int(lx, start, n, 10, 0);
    } else if (is_decimal_float(t, n, &body)) {
        return lex_float(lx, start, n, body);
    }
    return lex_fail(lx, start, "bad number literal '%s'", shown(t, n, sb, sizeof sb));
}

/* ---- names, characters, strings --------------------------------------------------------------- */

static int lex_name(Lexer *lx)
{
    size_t start = lx->pos, i = start;
    while (i < lx->len && is_ident_char(lx->s[i]))
        i++;
    lx->pos = i;
    const char *t = lx->s + start;
    size_t n = i - start;
    AsmTokKind kind = ASM_TOK_IDENT;
    int rk = -1;
    if (n >= 2 && (t[0] == 'r' || t[0] == 'v' || t[0] == 'm') && scan_digits(t, 1, n, 10) == n) {
        kind = ASM_TOK_REG;
        rk = t[0] == 'r' ? ISA_K_R : t[0] == 'v' ? ISA_K_V : ISA_K_M;
    }
    AsmToken *tok = push_token(lx, kind, start, n);
    if (!tok)
        return oom(lx);
    if (kind == ASM_TOK_REG) {
        int num = 0;
        for (size_t k = 1; k < n; k++)
            num = num >= 1000 ? 9999 : num * 10 + (t[k] - '0');
        tok->reg_kind = rk;
        tok->reg_num = num > 9999 ? 9999 : num;
    }
    return 0;
}

/* One escape after a backslash at s[i]; returns the byte or -1. */
static int escape_char(int c)
{
    switch (c) {
    case 'n': return '\n';
    case 't': return '\t';
    case 'r': return '\r';
    case '0': return '\0';
    case '\\': return '\\';
    case '\'': return '\'';
    case '"': return '"';
    default: return -1;
    }
}

static int lex_char(Lexer *lx)
{
    size_t start = lx->pos, i = start + 1;
    const char *s = lx->s;
    int v;
    if (i >= lx->len || s[i] == '\'')
        return lex_fail(lx, start, "empty or unterminated character literal");
    if (s[i] == '\\') {
        if (i + 1 >= lx->len || (v = escape_char(s[i + 1])) < 0)
            return lex_fail(lx, i, "bad escape '%.*s' in character literal", i + 1 < lx->len ? 2 : 1,
                            s + i);
        i += 2;
    } else {
        v = (unsigned char)s[i];
        i++;
    }
    if (i >= lx->len || s[i] != '\'')
        return lex_fail(lx, start, "unterminated character literal");
    lx->pos = i + 1;
    AsmToken *t = push_token(lx, ASM_TOK_INT, start, lx->pos - start);
    if (!t)
        return oom(lx);
    t->ival = v;
    return 0;
}

static int lex_string(Lexer *lx)
{
    size_t start = lx->pos, i = start + 1;
    const char *s = lx->s;
    char *buf = malloc(lx->len - start + 1);
    size_t n = 0;
    if (!buf)
        return oom(lx);
    for (;;) {
        if (i >= lx->len) {
            free(buf);
            return lex_fail(lx, start, "unterminated string");
        }
        if (s[i] == '"')
            break;
        if (s[i] == '\\') {
            int v = i + 1 < lx->len ? escape_char(s[i + 1]) : -1;
            if (v <= 0) { /* NUL inside a string would cut file names short: refused */
                free(buf);
                return lex_fail(lx, i, "bad escape '%.*s' in string", i + 1 < lx->len ? 2 : 1, s + i);
            }
            buf[n++] = (char)v;
            i += 2;
        } else if (s[i] == '\0') {
            free(buf);
            return lex_fail(lx, i, "NUL byte in string");
        } else {
            buf[n++] = s[i++];
        }
    }
    buf[n] = '\0';
    lx->pos = i + 1;
    AsmToken *t = push_token(lx, ASM_TOK_STRING, start, lx->pos - start);
    if (!t) {
        free(buf);
        return oom(lx);
    }
    t->str = buf;
    return 0;
}

/* ---- operators -------------------------------------------------------------------------------- */

static int match_punct(const char *s, size_t left, int *punct)
{
    static const struct { const char *text; int p; } two[] = {
        {"<<", ASM_P_SHL}, {">>", ASM_P_SHR}, {"<=", ASM_P_LE}, {">=", ASM_P_GE}, {"==", ASM_P_EQ},
        {"!=", ASM_P_NE}, {"&&", ASM_P_ANDAND}, {"||", ASM_P_OROR},
    };
    if (left >= 2)
        for (size_t k = 0; k < sizeof two / sizeof two[0]; k++)
            if (s[0] == two[k].text[0] && s[1] == two[k].text[1]) {
                *punct = two[k].p;
                return 2;
            }
    static const char one[] = "(),:=@.+-*/%~!<>&|^";
    static const int one_p[] = {ASM_P_LPAREN, ASM_P_RPAREN, ASM_P_COMMA, ASM_P_COLON, ASM_P_ASSIGN,
                                ASM_P_AT, ASM_P_DOT, ASM_P_PLUS, ASM_P_MINUS, ASM_P_STAR,
                                ASM_P_SLASH, ASM_P_PERCENT, ASM_P_TILDE, ASM_P_BANG, ASM_P_LT,
                                ASM_P_GT, ASM_P_AMP, ASM_P_PIPE, ASM_P_CARET};
    const char *p = s[0] ? strchr(one, s[0]) : NULL;
    if (!p)
        return 0;
    *punct = one_p[p - one];
    return 1;
}

static int lex_punct(Lexer *lx)
{
    int punct;
    int n = match_punct(lx->s + lx->pos, lx->len - lx->pos, &punct);
    if (n == 0) {
        unsigned char c = (unsigned char)lx->s[lx->pos];
        if (c >= 0x21 && c < 0x7F)
            return lex_fail(lx, lx->pos, "bad character '%c'", c);
        return lex_fail(lx, lx->pos, "bad character '\\x%02x'", c);
    }
    AsmToken *t = push_token(lx, ASM_TOK_PUNCT, lx->pos, (size_t)n);
    if (!t)
        return oom(lx);
    t->punct = punct;
    lx->pos += (size_t)n;
    return 0;
}

/* ---- the line --------------------------------------------------------------------------------- */

static int lex_one(Lexer *lx)
{
    const char *s = lx->s;
    int c = (unsigned char)s[lx->pos];
    int next = lx->pos + 1 < lx->len ? (unsigned char)s[lx->pos + 1] : 0;
    if (is_digit(c) || (c == '.' && is_digit(next)))
        return lex_number(lx);
    if (is_ident_start(c))
        return lex_name(lx);
    if (c == '.' && is_ident_start(next)) {
        size_t start = lx->pos++;
        while (lx->pos < lx->len && is_ident_char(s[lx->pos]))
            lx->pos++;
        return push_token(lx, ASM_TOK_DIRECTIVE, start, lx->pos - start) ? 0 : oom(lx);
    }
    if (c == '\'')
        return lex_char(lx);
    if (c == '"')
        return lex_string(lx);
    return lex_punct(lx);
}

int asm_lex_line(const char *text, size_t len, const uint32_t *colmap, AsmTokens *out,
                 AsmLexError *err)
{
    Lexer lx = {text, len, 0, colmap, out, err};
    asm_tokens_clear(out);
    while (lx.pos < len) {
        char c = text[lx.pos];
        if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            lx.pos++;
            continue;
        }
        if (c == ';' || (c == '/' && lx.pos + 1 < len && text[lx.pos + 1] == '/'))
            break;
        if (lex_one(&lx) < 0)
            return -1;
    }
    if (!push_token(&lx, ASM_TOK_EOL, len, 0))
        return oom(&lx);
    return 0;
}

void asm_tokens_clear(AsmTokens *t)
{
    for (int i = 0; i < t->n; i++)
        free(t->v[i].str);
    t->n = 0;
}

void asm_tokens_free(AsmTokens *t)
{
    asm_tokens_clear(t);
    free(t->v);
    t->v = NULL;
    t->cap = 0;
}

const char *asm_tok_describe(const AsmToken *t, char *buf, size_t len)
{
    if (t->kind == ASM_TOK_EOL)
        snprintf(buf, len, "end of line");
    else if (t->len > 40)
        snprintf(buf, len, "'%.40s...'", t->text);
    else
        snprintf(buf, len, "'%.*s'", (int)t->len, t->text);
    return buf;
}

int asm_tok_arg_end(const AsmToken *t, int i, int stop_at_at)
{
    int depth = 0;
    for (; t[i].kind != ASM_TOK_EOL; i++) {
        if (t[i].kind != ASM_TOK_PUNCT)
            continue;
        if (t[i].punct == ASM_P_LPAREN)
            depth++;
        else if (t[i].punct == ASM_P_RPAREN && depth > 0)
            depth--;
        else if (depth == 0 && (t[i].punct == ASM_P_COMMA || (stop_at_at && t[i].punct == ASM_P_AT)))
            break;
    }
    return i;
}
