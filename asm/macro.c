/* asm/macro.c -- sfasm macro definitions and expansion by text substitution.
 *
 * Owns: parameter lists, body storage and substitution (docs/assembler.md, "Macros"). Every
 * byte of an expanded line keeps the column of the body text it came from (an argument takes
 * the column of its \param), so diagnostics point into the macro body. Must not: lex, evaluate,
 * or limit depth (asm.c counts nesting and total expansion size).
 */
#include "macro.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

AsmMacro *asm_macro_new(const char *name, size_t len, int file, uint32_t line)
{
    AsmMacro *m = calloc(1, sizeof *m);
    if (!m)
        return NULL;
    m->name = dup_n(name, len);
    if (!m->name) {
        free(m);
        return NULL;
    }
    m->file = file;
    m->line = line;
    return m;
}

int asm_macro_param(const AsmMacro *m, const char *name, size_t len)
{
    for (int i = 0; i < m->nparams; i++)
        if (strlen(m->params[i]) == len && memcmp(m->params[i], name, len) == 0)
            return i;
    return -1;
}

int asm_macro_add_param(AsmMacro *m, const char *name, size_t len, const char *def, size_t deflen)
{
    char **np = realloc(m->params, (size_t)(m->nparams + 1) * sizeof *np);
    if (!np)
        return -1;
    m->params = np;
    char **nd = realloc(m->defaults, (size_t)(m->nparams + 1) * sizeof *nd);
    if (!nd)
        return -1;
    m->defaults = nd;
    char *pn = dup_n(name, len), *pd = def ? dup_n(def, deflen) : NULL;
    if (!pn || (def && !pd)) {
        free(pn);
        free(pd);
        return -1;
    }
    m->params[m->nparams] = pn;
    m->defaults[m->nparams] = pd;
    m->nparams++;
    return 0;
}

int asm_macro_add_line(AsmMacro *m, const char *text, size_t len, const uint32_t *cols, int file,
                       uint32_t line)
{
    if (m->nbody == m->capbody) {
        size_t ncap = m->capbody ? m->capbody * 2 : 8;
        AsmSrcLine *nb = realloc(m->body, ncap * sizeof *nb);
        if (!nb)
            return -1;
        m->body = nb;
        m->capbody = ncap;
    }
    AsmSrcLine *l = &m->body[m->nbody];
    l->text = dup_n(text, len);
    l->cols = cols ? malloc((len ? len : 1) * sizeof *cols) : NULL;
    if (!l->text || (cols && !l->cols)) {
        free(l->text);
        free(l->cols);
        return -1;
    }
    if (cols)
        memcpy(l->cols, cols, len * sizeof *cols);
    l->len = (uint32_t)len;
    l->file = file;
    l->line = line;
    m->nbody++;
    return 0;
}

/* ---- expansion -------------------------------------------------------------------------------- */

static int ident_char(int c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

/* The expanded line is built in two passes over the body line: one measures it, so that the
 * text and column map are allocated once at their final size, the other writes it. */
typedef struct OutLine {
    char *text;          /* NULL while measuring */
    uint32_t *cols;
    size_t len;
} OutLine;

static void out_put(OutLine *o, const char *s, size_t n, uint32_t col)
{
    if (o->text) {
        memcpy(o->text + o->len, s, n);
        for (size_t i = 0; i < n; i++)
            o->cols[o->len + i] = col;
    }
    o->len += n;
}

/* Substitutes one body line. A backslash not followed by @, () or a parameter name is kept,
 * so the lexer reports it where it stands. Returns -2 as soon as the line exceeds room. */
static int expand_line(const AsmMacro *m, const AsmSrcLine *in, char *const *args, const char *num,
                       size_t room, OutLine *o)
{
    const char *s = in->text;
    for (size_t i = 0; i < in->len;) {
        uint32_t col = in->cols ? in->cols[i] : (uint32_t)i + 1;
        const char *piece = s + i;
        size_t n = 1, used = 1;
        if (s[i] == '\\' && i + 1 < in->len) {
            size_t j = i + 1;
            while (j < in->len && ident_char(s[j]))
                j++;
            int p = j > i + 1 ? asm_macro_param(m, s + i + 1, j - i - 1) : -1;
            if (s[i + 1] == '@') {
                piece = num, n = strlen(num), used = 2;
            } else if (s[i + 1] == '(' && i + 2 < in->len && s[i + 2] == ')') {
                n = 0, used = 3;
            } else if (p >= 0) {
                piece = args[p], n = strlen(args[p]), used = j - i;
            }
        }
        if (n > room || o->len > room - n)
            return -2;
        out_put(o, piece, n, col);
        i += used;
    }
    return 0;
}

int asm_macro_expand(const AsmMacro *m, char *const *args, unsigned long unique, size_t limit,
                     AsmSrcLine **out, size_t *bytes)
{
    char num[24];
    snprintf(num, sizeof num, "%lu", unique);
    *out = NULL;
    *bytes = 0;
    AsmSrcLine *lines = calloc(m->nbody ? m->nbody : 1, sizeof *lines);
    if (!lines)
        return -1;
    for (size_t i = 0; i < m->nbody; i++) {
        OutLine o = {0};
        int rc = expand_line(m, &m->body[i], args, num, limit - *bytes, &o);
        size_t len = o.len;
        if (rc == 0) {
            o = (OutLine){malloc(len + 1), malloc((len ? len : 1) * sizeof *o.cols), 0};
            if (!o.text || !o.cols)
                rc = -1;
            else
                expand_line(m, &m->body[i], args, num, len, &o);
        }
        if (rc < 0) {
            free(o.text);
            free(o.cols);
            asm_srclines_free(lines, i);
            *bytes = 0;
            return rc;
        }
        o.text[len] = '\0';
        lines[i] = (AsmSrcLine){o.text, (uint32_t)len, o.cols, m->body[i].file, m->body[i].line};
        *bytes += len;
    }
    *out = lines;
    return 0;
}

void asm_srclines_free(AsmSrcLine *lines, size_t n)
{
    if (!lines)
        return;
    for (size_t i = 0; i < n; i++) {
        free(lines[i].text);
        free(lines[i].cols);
    }
    free(lines);
}

void asm_macro_free(AsmMacro *m)
{
    if (!m)
        return;
    free(m->name);
    for (int i = 0; i < m->nparams; i++) {
        free(m->params[i]);
        free(m->defaults[i]);
    }
    free(m->params);
    free(m->defaults);
    asm_srclines_free(m->body, m->nbody);
    free(m);
}
