/* asm/macro.h -- sfasm macro definitions and their expansion into source lines (internal).
 *
 * Owns: a macro's parameters, defaults and body lines, and the text substitution of \param,
 * \@ and \() with a column map back to the body. Must not: decide when a macro is called, check
 * nesting depth or interpret the expanded lines (asm.c does).
 */
#ifndef SFSIM_ASM_MACRO_H
#define SFSIM_ASM_MACRO_H

#include <stddef.h>
#include <stdint.h>

/* One source line with its origin. cols gives each byte's source column (NULL: offset + 1). */
typedef struct AsmSrcLine {
    char *text;
    uint32_t len;
    uint32_t *cols;
    int file;
    uint32_t line;
} AsmSrcLine;

typedef struct AsmMacro {
    char *name;
    int nparams;
    char **params;      /* parameter names */
    char **defaults;    /* default text per parameter, or NULL when it has none */
    AsmSrcLine *body;
    size_t nbody, capbody;
    int file;           /* where the .macro line is */
    uint32_t line;
} AsmMacro;

AsmMacro *asm_macro_new(const char *name, size_t len, int file, uint32_t line);
/* Index of parameter name[0, len), or -1. */
int asm_macro_param(const AsmMacro *m, const char *name, size_t len);
/* Adds a parameter; def may be NULL (no default). 0, or -1 when out of memory. */
int asm_macro_add_param(AsmMacro *m, const char *name, size_t len, const char *def, size_t deflen);
/* Appends a copy of a body line. 0, or -1 when out of memory. */
int asm_macro_add_line(AsmMacro *m, const char *text, size_t len, const uint32_t *cols, int file,
                       uint32_t line);
/* Expands the body with args[i] for parameter i (every entry non-NULL) and unique for \@.
 * *out gets nbody lines, each with a column map into its body line. *bytes gets the total
 * expanded length. 0; -1 when out of memory; -2 when the expansion would exceed limit bytes
 * (nothing is left allocated on failure). */
int asm_macro_expand(const AsmMacro *m, char *const *args, unsigned long unique, size_t limit,
                     AsmSrcLine **out, size_t *bytes);
void asm_srclines_free(AsmSrcLine *lines, size_t n);
void asm_macro_free(AsmMacro *m);

#endif
