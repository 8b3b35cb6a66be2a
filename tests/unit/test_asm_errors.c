/* tests/unit/test_asm_errors.c -- sfasm: the exact text of every class of diagnostic.
 *
 * Suite: asm_errors (operands, registers, masks, immediates, symbols, blocks, lexing, includes,
 * stages, expressions, sections, conditionals, macros, aliases and register frames, the error
 * cap, several errors in one run). What correct sources assemble to is test_asm.c's.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/asm.h"
#include "../support/asm_fixture.h"
#include "../support/files.h"

/* ---- helpers ---------------------------------------------------------------------------------- */

static char *assemble(const char *src, AsmObject *obj, int *nerr)
{
    return ta_assemble("bad.s", src, NULL, obj, nerr);
}

/* The exact diagnostics for src, and no object. */
static void expect_diag(const char *src, const char *expected)
{
    AsmObject obj;
    int nerr;
    char *diag = assemble(src, &obj, &nerr);
    cr_assert_str_eq(diag, expected, "source:\n%s\ngot:\n%s\nwant:\n%s", src, diag, expected);
    int lines = 0;
    for (const char *p = expected; *p; p++)
        lines += *p == '\n';
    cr_assert_eq(nerr, lines, "error count %d for:\n%s", nerr, src);
    cr_assert_eq(obj.ntext, 0);
    cr_assert_null(obj.text);
    free(diag);
}

/* ---- asm_errors: the exact text of every class of diagnostic ------------------------------------ */

Test(asm_errors, operand_kind)
{
    expect_diag("        nop\n        vfadd v1, v2, r3\n",
                "bad.s:2:23: operand 3 of vfadd must be a vector register\n");
    expect_diag("add v1, r2, r3\n", "bad.s:1:5: operand 1 of add must be a scalar register\n");
    expect_diag("li r1, v3\n", "bad.s:1:8: operand 2 of li must be an immediate, not a register\n");
    expect_diag("jmp r3\n", "bad.s:1:5: operand 1 of jmp must be a label, not a register\n");
}

Test(asm_errors, unknown_mnemonic_and_directive)
{
    expect_diag("  vfad v1, v2, v3\n", "bad.s:1:3: unknown instruction 'vfad'\n");
    expect_diag("  .wrod 1\n", "bad.s:1:3: unknown directive '.wrod'\n");
    expect_diag("  ADD r1, r2, r3\n", "bad.s:1:3: unknown instruction 'ADD'\n");
}

Test(asm_errors, operand_count)
{
    expect_diag("add r1, r2\n", "bad.s:1:1: add expects 3 operands, got 2\n");
    expect_diag("add r1, r2, r3, r4\n", "bad.s:1:17: add expects 3 operands, got 4\n");
    expect_diag("halt r1\n", "bad.s:1:6: halt expects 0 operands, got 1\n");
    expect_diag("add r1,, r2\n", "bad.s:1:8: operand 2 of add is missing\n");
}

Test(asm_errors, register_range)
{
    expect_diag("add r32, r1, r2\n", "bad.s:1:5: register 'r32' out of range (r0..r31)\n");
    expect_diag("vmov v1, v99\n", "bad.s:1:10: register 'v99' out of range (v0..v31)\n");
    expect_diag("mall m8\n", "bad.s:1:6: register 'm8' out of range (m0..m7)\n");
}

Test(asm_errors, exec_mask)
{
    expect_diag("add r1, r2, r3 @m1\n", "bad.s:1:16: add takes no exec mask\n");
    expect_diag("vfadd v1, v2, v3 @r1\n", "bad.s:1:19: exec mask must be a mask register (m0..m7)\n");
    expect_diag("vfadd v1, v2, v3 @\n", "bad.s:1:19: exec mask must be a mask register (m0..m7)\n");
}

Test(asm_errors, immediate_range)
{
    expect_diag("li r1, 0x100000000\n", "bad.s:1:8: value 4294967296 does not fit in 32 bits\n");
    expect_diag("li r1, -0x80000000 - 1\n", "bad.s:1:8: value -2147483649 does not fit in 32 bits\n");
    expect_diag("li r1, 1e39\n", "bad.s:1:8: float value 1e+39 is out of binary32 range\n");
    expect_diag("li r1, 99999999999999999999\n",
                "bad.s:1:8: integer literal '99999999999999999999' is too large\n");
}

Test(asm_errors, undefined_symbol)
{
    expect_diag("li r1, missing + 1\n", "bad.s:1:8: undefined symbol 'missing'\n");
    expect_diag("X = Y * 2\n", "bad.s:1:5: undefined symbol 'Y'\n");
}

Test(asm_errors, duplicate_label_and_redefinition)
{
    expect_diag("a: nop\n  a: nop\n", "bad.s:2:3: duplicate label 'a' (first defined at bad.s:1)\n");
    expect_diag("X = 1\nX = 2\n", "bad.s:2:1: redefinition of symbol 'X' (first defined at bad.s:1)\n");
    expect_diag("r1: nop\n", "bad.s:1:1: 'r1' is a register name and cannot be a label\n");
}

Test(asm_errors, unterminated_blocks)
{
    expect_diag("nop\n.macro foo a\n  nop\n", "bad.s:2:1: unterminated .macro 'foo' (no matching .endm)\n");
    expect_diag("  .if 1\nnop\n", "bad.s:1:3: unterminated .if (no matching .endif)\n");
    expect_diag(".endif\n", "bad.s:1:1: .endif without .if\n");
    expect_diag(".if 1\n.else\n.else\n.endif\n", "bad.s:3:1: .else after .else\n");
    expect_diag(".endm\n", "bad.s:1:1: .endm without .macro\n");
}

Test(asm_errors, lexical)
{
    expect_diag(".data\n.word \"abc\n", "bad.s:2:7: unterminated string\n");
    expect_diag("li r1, 3 # 4\n", "bad.s:1:10: bad character '#'\n");
    expect_diag("li r1, 12abc\n", "bad.s:1:8: bad number literal '12abc'\n");
    expect_diag("li r1, 0x\n", "bad.s:1:8: bad number literal '0x'\n");
    expect_diag("li r1, 0b102\n", "bad.s:1:8: bad number literal '0b102'\n");
    expect_diag("li r1, 'ab'\n", "bad.s:1:8: unterminated character literal\n");
}

Test(asm_errors, include_not_found)
{
    expect_diag(".include \"no/such/file.inc\"\n", "bad.s:1:10: include file 'no/such/file.inc' not found\n");
}

Test(asm_errors, stage_and_labels)
{
    expect_diag("stage 4\n", "bad.s:1:7: stage must be 0..3, got 4\n");
    expect_diag("stage S\nS = -1\n", "bad.s:1:7: stage must be 0..3, got -1\n");
    expect_diag("nop\njmp 3\n", "bad.s:2:5: operand 1 of jmp: target 3 is outside the text section (0..2)\n");
    expect_diag(".data\nbuf: .word 0\n.text\nbeq r1, r2, buf\n",
                "bad.s:4:13: operand 3 of beq must be a text label, not a .data address\n");
    expect_diag("jmp 1.5\n", "bad.s:1:5: operand 1 of jmp must be a label, not a float\n");
}

Test(asm_errors, expression_errors)
{
    expect_diag("li r1, 1 / (2 - 2)\n", "bad.s:1:10: division by zero\n");
    expect_diag("li r1, 1.5 & 1\n", "bad.s:1:12: operator '&' needs integer operands, not floats\n");
    expect_diag("li r1, (1 + 2\n", "bad.s:1:14: expected ')', found end of line\n");
    expect_diag("li r1, 1 << 64\n", "bad.s:1:10: shift count 64 out of range 0..63\n");
    expect_diag("li r1, 1 2\n", "bad.s:1:10: unexpected '2' after expression\n");
    expect_diag("A = B\nB = A\n", "bad.s:1:5: circular definition of 'B'\n");
}

Test(asm_errors, sections_and_data)
{
    expect_diag(".align 4\n", "bad.s:1:1: .align is not allowed in .text (switch to .data or .spad)\n");
    expect_diag(".word 1\n", "bad.s:1:1: .word is not allowed in .text (switch to .data or .spad)\n");
    expect_diag(".data\n.align 3\n", "bad.s:2:8: .align boundary must be a power of two, got 3\n");
    expect_diag(".data\nnop\n", "bad.s:2:1: instruction nop outside .text (current section is .data)\n");
    expect_diag(".spad\n.byte 256\n", "bad.s:2:7: value 256 does not fit in a byte\n");
    expect_diag(".data\n.space 0x4000000\n.space 1\n", "bad.s:3:1: section .data would exceed 64 MiB\n");
    expect_diag(".data\n.space N\nN = 4\n",
                "bad.s:2:8: .space size must be known at this point: symbol 'N' is not defined yet\n");
}

Test(asm_errors, conditionals)
{
    expect_diag(".if LATER\n.endif\nLATER = 1\n",
                "bad.s:1:5: .if condition must be known at this point: symbol 'LATER' is not defined yet\n");
    AsmDefine d = {"HAS_DIELECTRIC", 1};
    AsmOptions opt = {.defines = &d, .ndefines = 1};
    AsmObject obj;
    int nerr;
    char *diag = ta_assemble("bad.s", ".ifdef HAS_DIELECTRIC\n  .error \"no dielectric support\"\n.endif\n",
                             &opt, &obj, &nerr);
    cr_assert_str_eq(diag, "bad.s:2:3: no dielectric support\n");
    cr_assert_eq(nerr, 1);
    free(diag);
    /* Skipped text is not lexed: a stray character there is no error. */
    diag = assemble(".if 0\n  li r1, #$%\n.endif\nnop\n", &obj, &nerr);
    cr_assert_str_eq(diag, "");
    asm_object_free(&obj);
    free(diag);
}

Test(asm_errors, macro_expansion_location)
{
    expect_diag(".macro addv d, a\n  vfadd \\d, \\a, v2\n.endm\n  nop\n  addv v1, r3\n",
                "bad.s:2:13: operand 2 of vfadd must be a vector register"
                " (in expansion of macro 'addv' from bad.s:5)\n");
    expect_diag(".macro inner x\n  li r1, \\x\n.endm\n.macro outer y\n  inner \\y + 1\n.endm\n  outer nowhere\n",
                "bad.s:2:10: undefined symbol 'nowhere' (in expansion of macro 'inner' from bad.s:5;"
                " macro 'outer' from bad.s:7)\n");
    expect_diag(".macro m a, b\n.endm\nm 1, 2, 3\n", "bad.s:3:9: macro 'm' takes 2 arguments\n");
    expect_diag(".macro m a, b\n.endm\nm 1\nx:  m 1,\n", "bad.s:3:1: missing argument 'b' for macro 'm'\n"
                "bad.s:4:5: missing argument 'b' for macro 'm'\n");
    expect_diag(".macro add a\n.endm\n", "bad.s:1:8: macro name 'add' is an instruction mnemonic\n");
}

Test(asm_errors, macro_recursion_limit)
{
    expect_diag(".macro r n\n r \\n\n.endm\n r 1\n",
                "bad.s:2:2: macro 'r' (defined at bad.s:1) nested too deeply: more than 64 nested expansions"
                " (does it call itself without an end?) (in expansion of"
                " macro 'r' from bad.s:2; macro 'r' from bad.s:2; macro 'r' from bad.s:2; ... 60 more;"
                " macro 'r' from bad.s:4)\n");
}

/* A macro that calls itself twice: one error naming it, not one per call of a binary tree of
 * expansions (it printed 125,000 lines, 27 MB). */
Test(asm_errors, macro_calling_itself_twice_is_one_error)
{
    expect_diag("  nop\n.macro m\n    m\n    m\n.endm\n    m\n",
                "bad.s:3:5: macro 'm' (defined at bad.s:2) nested too deeply: more than 64 nested expansions"
                " (does it call itself without an end?) (in expansion of"
                " macro 'm' from bad.s:3; macro 'm' from bad.s:3; macro 'm' from bad.s:3; ... 60 more;"
                " macro 'm' from bad.s:6)\n");
}

/* The text of n lines, each made by line(i). */
static char *lines_of(int n, const char *(*line)(int i, char *buf, size_t len))
{
    size_t cap = (size_t)n * 64 + 1, used = 0;
    char *src = malloc(cap), buf[64];
    cr_assert_not_null(src);
    src[0] = '\0';
    for (int i = 0; i < n; i++)
        used += (size_t)snprintf(src + used, cap - used, "%s", line(i, buf, sizeof buf));
    return src;
}

static const char *call_bad(int i, char *buf, size_t len)
{
    snprintf(buf, len, "%s", i == 0 ? ".macro bad\n  frob r1\n.endm\n" : "  bad\n");
    return buf;
}

/* At most 50 errors are printed, in source order, then how many more there were; all count. */
Test(asm_errors, error_cap_50_then_how_many_more)
{
    char *src = lines_of(1 + 300, call_bad);   /* the macro, then 300 calls: 300 errors */
    AsmObject obj;
    int nerr;
    char *diag = assemble(src, &obj, &nerr);
    cr_assert_eq(nerr, 300);
    int lines = 0;
    for (const char *p = diag; *p; p++)
        lines += *p == '\n';
    cr_expect_eq(lines, 51, "%d lines:\n%s", lines, diag);
    cr_expect(strstr(diag, "bad.s:2:3: unknown instruction 'frob' (in expansion of macro 'bad' from bad.s:4)\n")
              == diag, "%.300s", diag);
    cr_expect_not_null(strstr(diag, "(in expansion of macro 'bad' from bad.s:53)\n"
                                    "... and 250 more errors (only the first 50 are shown)\n"), "%s", diag);
    cr_expect_null(strstr(diag, "from bad.s:54)"), "the 51st error is printed");
    free(diag);
    free(src);
}

static const char *undefined_then_bogus(int i, char *buf, size_t len)
{
    if (i == 0)
        snprintf(buf, len, "  li r1, nowhere\n");      /* found in pass 2, after all the others */
    else
        snprintf(buf, len, "  bogus%d r1\n", i);
    return buf;
}

/* The cap keeps the first errors in reading order, not the first reported: a pass-2 error on
 * line 1 comes first although it is found after 200 pass-1 errors. */
Test(asm_errors, error_cap_keeps_reading_order)
{
    char *src = lines_of(201, undefined_then_bogus);
    AsmObject obj;
    int nerr;
    char *diag = assemble(src, &obj, &nerr);
    cr_assert_eq(nerr, 201);
    cr_expect(strstr(diag, "bad.s:1:10: undefined symbol 'nowhere'\nbad.s:2:3: unknown instruction 'bogus1'\n") == diag,
              "%.300s", diag);
    cr_expect_not_null(strstr(diag, "bad.s:50:3: unknown instruction 'bogus49'\n"
                                    "... and 151 more errors (only the first 50 are shown)\n"), "%s", diag);
    free(diag);
    free(src);
}

Test(asm_errors, include_recursion_limit)
{
    char dir[] = "/tmp/sfasm-inc-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    ta_put_file(dir, "self.inc", "nop\n.include \"self.inc\"\n");
    char main_name[600], src[700];
    snprintf(main_name, sizeof main_name, "%s/main.s", dir);
    snprintf(src, sizeof src, ".include \"self.inc\"\n");
    AsmObject obj;
    int nerr;
    char *diag = ta_assemble(main_name, src, NULL, &obj, &nerr);
    char expected[700];
    snprintf(expected, sizeof expected, "%s/self.inc:2:1: includes nested too deeply (limit 32)\n", dir);
    cr_assert_str_eq(diag, expected);
    cr_assert_eq(nerr, 1);
    free(diag);
    tu_remove_tree(dir);
}

Test(asm_errors, aliases)
{
    expect_diag(".alias pos, v3\n.unalias pos\nvmov pos, v1\n",
                "bad.s:3:6: operand 1 of vmov must be a vector register\n");
    expect_diag(".alias pos, r3\nvmov pos, v1\n", "bad.s:2:6: operand 1 of vmov must be a vector register\n");
    expect_diag(".alias pos, v40\n", "bad.s:1:13: register 'v40' out of range (v0..v31)\n");
    expect_diag(".alias pos, v1\nli r1, pos\n", "bad.s:2:8: operand 2 of li must be an immediate, not a register\n");
    expect_diag(".alias pos, v1\nli r1, pos + 1\n",
                "bad.s:2:8: register alias 'pos' cannot be used in an expression\n");
    expect_diag(".unalias nothing\n", "bad.s:1:10: 'nothing' is not a register alias\n");
}

Test(asm_errors, register_frames)
{
    expect_diag(".regs v30, a, d:xyz\n", "bad.s:1:15: register frame runs past v31 at 'd'\n");
    expect_diag(".regs v1\n", "bad.s:1:9: expected ',' and names after the first register of .regs\n");
    expect_diag(".regs v1, a b\n", "bad.s:1:13: expected ',' before the next name in .regs, found 'b'\n");
    expect_diag(".regs 3, a\n", "bad.s:1:7: expected the frame's first register after .regs, found '3'\n");
    expect_diag(".regs v1, a:\n", "bad.s:1:13: expected suffix letters after ':' in .regs, found end of line\n");
    expect_diag(".regs v1, v:_1\n", "bad.s:1:11: 'v1' is a register name and cannot be an alias\n");
    expect_diag("x = 1\n.regs v1, a, x\n", "bad.s:2:14: 'x' is already a symbol and cannot be an alias\n");
    expect_diag(".regs m6, p, q, r\n", "bad.s:1:17: register frame runs past m7 at 'r'\n");
}

/* Several errors in one file: all reported, in source order (pass-2 ones included), no cascade. */
Test(asm_errors, all_errors_in_one_run)
{
    const char *src =
        "start:  li r1, later_undefined\n"   /* pass 2 */
        "        vfadd v1, r2, v3\n"
        "        bogus r1\n"
        ".data\n"
        "        .word 1, 2 / 0, 3\n"
        ".text\n"
        "        jmp nowhere\n"              /* pass 2 */
        "        add r1, r2\n"
        "start:  halt\n";
    expect_diag(src,
                "bad.s:1:16: undefined symbol 'later_undefined'\n"
                "bad.s:2:19: operand 2 of vfadd must be a vector register\n"
                "bad.s:3:9: unknown instruction 'bogus'\n"
                "bad.s:5:20: division by zero\n"
                "bad.s:7:13: undefined symbol 'nowhere'\n"
                "bad.s:8:9: add expects 3 operands, got 2\n"
                "bad.s:9:1: duplicate label 'start' (first defined at bad.s:1)\n");
}
