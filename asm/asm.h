/* asm/asm.h -- sfasm: assembles sfsim assembly into an AsmObject; disassembles objects.
 *
 * Owns: lexing, expressions, macros, includes, conditional assembly, symbol resolution,
 * encoding through isa/. Must not: execute code or read machine configs.
 * Errors: every error found is reported as "file:line:col: message" (one per line) into the
 * diagnostics sink; assembly fails if any error was reported.
 */
#ifndef SFSIM_ASM_H
#define SFSIM_ASM_H

#include <stdio.h>

#include "object.h"
#include "sched.h"

typedef struct AsmDefine { const char *name; long long value; } AsmDefine;

typedef struct AsmOptions {
    const AsmDefine *defines; int ndefines;     /* -D NAME[=value] (value 1 when omitted) */
    const char *const *include_dirs; int ninclude_dirs; /* -I DIR, searched after the including file's directory */
    FILE *diag;                                 /* where diagnostics go (stderr if NULL) */
    const AsmSchedModel *schedule;              /* NULL: the source order; else list-schedule the
                                                   basic blocks for this machine (asm/sched.h) */
    FILE *schedule_report;                      /* with schedule: the pass's per-block report */
} AsmOptions;

/* Assemble the file at path. Returns the number of errors (0 on success, *obj filled). */
int asm_assemble_file(const char *path, const AsmOptions *opt, AsmObject *obj);
/* Assemble source text held in memory; name is used in diagnostics and the line table. */
int asm_assemble_string(const char *name, const char *src, size_t len, const AsmOptions *opt,
                        AsmObject *obj);

/* Write obj as assembler text that assembles back to identical TEXT, DATA and SPAD bytes.
 * with_source adds each instruction's file:line as a comment. */
void asm_disassemble(const AsmObject *obj, FILE *out, int with_source);

#endif
