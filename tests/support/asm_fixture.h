/* tests/support/asm_fixture.h -- assembling sources in memory for the assembler's tests
 * (tests/unit/test_asm*.c): the diagnostics captured as text, and small input files on disk.
 *
 * Owns: running the assembler on a string with its diagnostics in a buffer, and the check every
 * test of a correct source makes (no error, no diagnostic). Must not: hold a test's expected
 * diagnostics or encodings (each test writes its own from the language's rules).
 */
#ifndef SFSIM_TESTS_ASM_FIXTURE_H
#define SFSIM_TESTS_ASM_FIXTURE_H

#include "../../asm/asm.h"

/* Assembles src as file `name` with the options of base (NULL: none); returns the diagnostics
 * text (malloc'ed), *nerr the error count. */
char *ta_assemble(const char *name, const char *src, const AsmOptions *base, AsmObject *obj, int *nerr);

/* Assembles src, which must be correct, as "ok.s": the test fails on any error or diagnostic. */
void ta_assemble_ok(const char *src, const AsmOptions *opt, AsmObject *obj);

/* Writes text to dir/name (the test fails when it cannot be written). */
void ta_put_file(const char *dir, const char *name, const char *text);

#endif
