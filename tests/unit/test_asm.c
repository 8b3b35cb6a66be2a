/* tests/unit/test_asm.c -- sfasm: diagnostics, language features, object files, round trips.
 *
 * Suites: asm_errors (exact diagnostic texts), asm_features (what assembles to what),
 * asm_object (the .sfo encoding and its validation), asm_roundtrip (disassembly reassembles to
 * identical bytes for every opcode).
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"

/* ---- helpers ---------------------------------------------------------------------------------- */

/* Assembles src as "bad.s"; returns the diagnostics text (malloc'ed), *nerr the error count. */
static char *assemble_opt(const char *name, const char *src, const AsmOptions *base, AsmObject *obj,
                          int *nerr)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    cr_assert_not_null(m);
    AsmOptions opt = base ? *base : (AsmOptions){0};
    opt.diag = m;
    *nerr = asm_assemble_string(name, src, strlen(src), &opt, obj);
    fclose(m);
    return buf;
}

static char *assemble(const char *src, AsmObject *obj, int *nerr)
{
    return assemble_opt("bad.s", src, NULL, obj, nerr);
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

/* Assembles src that must be correct. */
static void assemble_ok(const char *src, const AsmOptions *opt, AsmObject *obj)
{
    int nerr;
    char *diag = assemble_opt("ok.s", src, opt, obj, &nerr);
    cr_assert_eq(nerr, 0, "unexpected errors:\n%s\nfor:\n%s", diag, src);
    cr_assert_str_eq(diag, "");
    free(diag);
}

static uint32_t imm_of(const AsmObject *obj, uint32_t pc)
{
    cr_assert_lt(pc, obj->ntext);
    return (uint32_t)(obj->text[pc] >> 32);
}

static IsaInstr decode_at(const AsmObject *obj, uint32_t pc)
{
    IsaInstr in;
    char err[128];
    cr_assert_lt(pc, obj->ntext);
    cr_assert_eq(isa_decode(obj->text[pc], &in, err, sizeof err), 0, "%s", err);
    return in;
}

static uint32_t fbits(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

static const AsmSymbol *find_sym(const AsmObject *obj, const char *name)
{
    for (uint32_t i = 0; i < obj->nsyms; i++)
        if (strcmp(obj->syms[i].name, name) == 0)
            return &obj->syms[i];
    return NULL;
}

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f, "%s", path);
    fputs(text, f);
    fclose(f);
}

static void remove_files(const char *dir, const char *const *names, int n)
{
    char path[512];
    for (int i = 0; i < n; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
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
    char *diag = assemble_opt("bad.s", ".ifdef HAS_DIELECTRIC\n  .error \"no dielectric support\"\n.endif\n",
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
    write_file(dir, "self.inc", "nop\n.include \"self.inc\"\n");
    char main_name[600], src[700];
    snprintf(main_name, sizeof main_name, "%s/main.s", dir);
    snprintf(src, sizeof src, ".include \"self.inc\"\n");
    AsmObject obj;
    int nerr;
    char *diag = assemble_opt(main_name, src, NULL, &obj, &nerr);
    char expected[700];
    snprintf(expected, sizeof expected, "%s/self.inc:2:1: includes nested too deeply (limit 32)\n", dir);
    cr_assert_str_eq(diag, expected);
    cr_assert_eq(nerr, 1);
    free(diag);
    const char *names[] = {"self.inc"};
    remove_files(dir, names, 1);
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

/* ---- asm_features ----------------------------------------------------------------------------- */

Test(asm_features, expressions_and_precedence)
{
    static const struct { const char *expr; uint32_t value; } cases[] = {
        {"1 + 2 * 3", 7}, {"(1 + 2) * 3", 9}, {"1 << 2 + 1", 8}, {"7 & 3 | 8", 11},
        {"1 | 2 ^ 3", 1}, {"6 ^ 3 & 1", 7}, {"-2 * -3", 6}, {"~0", 0xFFFFFFFFu}, {"!0 + !5", 1},
        {"17 % 5", 2}, {"-7 / 2", (uint32_t)-3}, {"1 < 2 == 1", 1}, {"3 > 2 && 0 || 1", 1},
        {"0x10 + 0b101 + 'A'", 16 + 5 + 65}, {"'\\n'", 10}, {"0xFFFFFFFF", 0xFFFFFFFFu},
        {"-0x80000000", 0x80000000u}, {"1 << 40 >> 38", 4}, {"2 >= 2", 1}, {"2 != 2", 0},
        {"(1 << 63) >> 62", (uint32_t)-2}, {"0 && 1 / 0", 0}, {"1 || 1 / 0", 1},
        {"defined(FOO) + defined(NOPE)", 1},
    };
    char src[4096] = "FOO = 1\n";
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        strcat(src, "li r1, ");
        strcat(src, cases[i].expr);
        strcat(src, "\n");
    }
    AsmObject obj;
    assemble_ok(src, NULL, &obj);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        cr_expect_eq(imm_of(&obj, (uint32_t)i), cases[i].value, "%s: got 0x%x", cases[i].expr,
                     imm_of(&obj, (uint32_t)i));
    asm_object_free(&obj);
}

Test(asm_features, float_immediates)
{
    AsmObject obj;
    assemble_ok("li r1, 1.5\nli r2, .5\nli r3, 1e-3\nli r4, 2.0f\nli r5, -1.5\n"
                "li r6, 1 + 0.5\nli r7, 3 / 2.0\nli r8, 1.5 > 1\nHALF = 0.5\nvli v1, HALF * 4\n"
                "li r9, -0.0\n",
                NULL, &obj);
    cr_assert_eq(imm_of(&obj, 0), fbits(1.5f));
    cr_assert_eq(imm_of(&obj, 1), fbits(0.5f));
    cr_assert_eq(imm_of(&obj, 2), fbits(1e-3f));
    cr_assert_eq(imm_of(&obj, 3), fbits(2.0f));
    cr_assert_eq(imm_of(&obj, 4), fbits(-1.5f));
    cr_assert_eq(imm_of(&obj, 5), fbits(1.5f));
    cr_assert_eq(imm_of(&obj, 6), fbits(1.5f));
    cr_assert_eq(imm_of(&obj, 7), 1);
    cr_assert_eq(imm_of(&obj, 8), fbits(2.0f));
    cr_assert_eq(imm_of(&obj, 9), 0x80000000u);
    asm_object_free(&obj);
}

Test(asm_features, forward_labels_and_location)
{
    AsmObject obj;
    assemble_ok("        jmp end\n"
                "loop:   bne r1, r2, loop\n"
                "        jal r31, sub\n"
                "        jmp . + 1\n"
                "end:    halt\n"
                "sub:    jr r31\n"
                "after:\n",
                NULL, &obj);
    cr_assert_eq(obj.ntext, 6);
    cr_assert_eq(imm_of(&obj, 0), 4);
    cr_assert_eq(imm_of(&obj, 1), 1);
    cr_assert_eq(imm_of(&obj, 2), 5);
    cr_assert_eq(imm_of(&obj, 3), 4);
    const AsmSymbol *s = find_sym(&obj, "after");
    cr_assert_not_null(s);
    cr_assert_eq(s->section, ASM_SEC_TEXT);
    cr_assert_eq(s->value, 6);
    asm_object_free(&obj);
}

Test(asm_features, constants_set_and_forward_constants)
{
    AsmObject obj;
    assemble_ok("SIZE = END - START\n"
                ".equ TWICE, SIZE * 2\n"
                ".set I, 1\n"
                "START: li r1, I\n"
                ".set I, I + 1\n"
                "li r2, I\n"
                "li r3, TWICE\n"
                "END:\n",
                NULL, &obj);
    cr_assert_eq(imm_of(&obj, 0), 1);
    cr_assert_eq(imm_of(&obj, 1), 2);
    cr_assert_eq(imm_of(&obj, 2), 6);
    const AsmSymbol *s = find_sym(&obj, "SIZE");
    cr_assert_not_null(s);
    cr_assert_eq(s->section, 0);
    cr_assert_eq(s->value, 3);
    asm_object_free(&obj);
}

Test(asm_features, include_files)
{
    char dir[] = "/tmp/sfasm-inc-XXXXXX", incdir[600], main_name[600], want[700];
    cr_assert_not_null(mkdtemp(dir));
    snprintf(incdir, sizeof incdir, "%s/lib", dir);
    cr_assert_eq(mkdir(incdir, 0700), 0);
    write_file(dir, "local.inc", "LOCAL = 7\n  li r2, LOCAL\n");
    write_file(incdir, "lib.inc", ".macro twice r\n  add \\r, \\r, \\r\n.endm\nLIBVAL = 9\n");
    /* The main file's directory is searched first, then -I directories. */
    snprintf(main_name, sizeof main_name, "%s/main.s", dir);
    const char *inc[] = {incdir};
    AsmOptions opt = {.include_dirs = inc, .ninclude_dirs = 1};
    AsmObject obj;
    int nerr;
    char *diag = assemble_opt(main_name, "li r1, 1\n.include \"local.inc\"\n.include \"lib.inc\"\n"
                              "  twice r3\nli r4, LIBVAL\n", &opt, &obj, &nerr);
    cr_assert_eq(nerr, 0, "%s", diag);
    free(diag);
    cr_assert_eq(obj.ntext, 4);
    cr_assert_eq(imm_of(&obj, 1), 7);
    cr_assert_eq(imm_of(&obj, 3), 9);
    /* The line table names the included files: the macro line is in lib.inc. */
    cr_assert_eq(obj.nfiles, 3);
    cr_assert_str_eq(obj.files[obj.lines[0].file], main_name);
    snprintf(want, sizeof want, "%s/local.inc", dir);
    cr_assert_str_eq(obj.files[obj.lines[1].file], want);
    cr_assert_eq(obj.lines[1].line, 2);
    cr_assert_eq(obj.lines[1].col, 3);
    snprintf(want, sizeof want, "%s/lib.inc", incdir);
    cr_assert_str_eq(obj.files[obj.lines[2].file], want);
    cr_assert_eq(obj.lines[2].line, 2);
    cr_assert_eq(obj.lines[2].col, 3);
    asm_object_free(&obj);
    /* Without -I the library is not found. */
    diag = assemble_opt(main_name, ".include \"lib.inc\"\n", NULL, &obj, &nerr);
    snprintf(want, sizeof want, "%s:1:10: include file 'lib.inc' not found\n", main_name);
    cr_assert_str_eq(diag, want);
    free(diag);
    const char *names[] = {"local.inc", "lib/lib.inc", "lib"};
    remove_files(dir, names, 3);
}

Test(asm_features, macros_args_defaults_unique)
{
    AsmObject obj;
    assemble_ok(".macro count reg, n=3, step=1\n"
                "        li \\reg, \\n\n"
                "loop\\@: addi \\reg, \\reg, -\\step\n"
                "        bne \\reg, r0, loop\\@\n"
                ".endm\n"
                ".macro twocounts\n"
                "        count r1\n"
                "        count r2, 5, (1 + 1)\n"
                ".endm\n"
                "        twocounts\n"
                "        halt\n",
                NULL, &obj);
    cr_assert_eq(obj.ntext, 7);
    cr_assert_eq(imm_of(&obj, 0), 3);
    cr_assert_eq(imm_of(&obj, 1), (uint32_t)-1);
    cr_assert_eq(imm_of(&obj, 2), 1); /* its own loop label */
    cr_assert_eq(imm_of(&obj, 3), 5);
    cr_assert_eq(imm_of(&obj, 4), (uint32_t)-2);
    cr_assert_eq(imm_of(&obj, 5), 4);
    IsaInstr in = decode_at(&obj, 3);
    cr_assert_eq(in.a, 2);
    /* Macro lines are located in the macro body. */
    cr_assert_eq(obj.lines[4].line, 3);
    cr_assert_eq(obj.lines[4].col, 9);
    asm_object_free(&obj);
}

/* A register frame (.regs) is one .alias per name on consecutive registers; name:xyz names three. */
Test(asm_features, register_frames)
{
    AsmObject obj;
    assemble_ok(".regs v3, a, d:xyz, m\n.regs m2, hit\nvfadd dy, a, dz @hit\nvmov m, dx\n"
                ".regs v29, t:ab, u\nvmov ta, u\n.alias dx, v9\nvmov dx, dz\n", NULL, &obj);
    IsaInstr in = decode_at(&obj, 0);
    cr_assert_eq(in.op, ISA_OP_VFADD);
    cr_assert_eq(in.a, 5);
    cr_assert_eq(in.b, 3);
    cr_assert_eq(in.c, 6);
    cr_assert_eq(in.mask, 2);
    in = decode_at(&obj, 1);
    cr_assert_eq(in.a, 7);
    cr_assert_eq(in.b, 4);
    in = decode_at(&obj, 2);
    cr_assert_eq(in.a, 29);
    cr_assert_eq(in.b, 31);
    in = decode_at(&obj, 3);
    cr_assert_eq(in.a, 9);
    cr_assert_eq(in.b, 6);
    asm_object_free(&obj);
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

Test(asm_features, register_aliases)
{
    AsmObject obj;
    assemble_ok(".alias orgx, v3\n.alias dirx, v31\n.alias hit, m5\n.alias tmp, r7\n.alias org2, orgx\n"
                "vfadd orgx, dirx, org2 @hit\nmpop tmp, hit\n.unalias orgx\n.alias orgx, v4\nvmov orgx, v0\n",
                NULL, &obj);
    IsaInstr in = decode_at(&obj, 0);
    cr_assert_eq(in.op, ISA_OP_VFADD);
    cr_assert_eq(in.a, 3);
    cr_assert_eq(in.b, 31);
    cr_assert_eq(in.c, 3);
    cr_assert_eq(in.mask, 5);
    in = decode_at(&obj, 1);
    cr_assert_eq(in.a, 7);
    cr_assert_eq(in.b, 5);
    in = decode_at(&obj, 2);
    cr_assert_eq(in.a, 4);
    asm_object_free(&obj);
}

Test(asm_features, conditionals_with_defines)
{
    const char *src = ".ifdef HAS_DIELECTRIC\n  li r1, 1\n.elif SPP > 4\n  li r1, 2\n.else\n  li r1, 3\n.endif\n"
                      ".ifndef NOT_SET\n  .if SPP == 8 && defined(SPP)\n    li r2, SPP\n  .endif\n.endif\n";
    AsmDefine d1[] = {{"HAS_DIELECTRIC", 1}, {"SPP", 8}};
    AsmOptions opt = {.defines = d1, .ndefines = 2};
    AsmObject obj;
    assemble_ok(src, &opt, &obj);
    cr_assert_eq(obj.ntext, 2);
    cr_assert_eq(imm_of(&obj, 0), 1);
    cr_assert_eq(imm_of(&obj, 1), 8);
    asm_object_free(&obj);
    opt = (AsmOptions){.defines = &d1[1], .ndefines = 1};
    assemble_ok(src, &opt, &obj);
    cr_assert_eq(imm_of(&obj, 0), 2);
    asm_object_free(&obj);
    AsmDefine d2 = {"SPP", 1};
    opt = (AsmOptions){.defines = &d2, .ndefines = 1};
    assemble_ok(src, &opt, &obj);
    cr_assert_eq(obj.ntext, 1);
    cr_assert_eq(imm_of(&obj, 0), 3);
    asm_object_free(&obj);
}

Test(asm_features, data_sections)
{
    AsmObject obj;
    assemble_ok("        ld r1, r0, table + 4\n"
                "        .data\n"
                "        .byte 1\n"
                "        .align 4\n"
                "table:  .word 0x11223344, -1, tail\n"
                "        .float 1.5, 2\n"
                "tail:   .space 3, 0xAB\n"
                "        .spad\n"
                "        .word 7\n"
                "stack:  .space 8\n",
                NULL, &obj);
    static const uint8_t data[] = {1, 0, 0, 0, 0x44, 0x33, 0x22, 0x11, 0xFF, 0xFF, 0xFF, 0xFF,
                                   24, 0, 0, 0, 0, 0, 0xC0, 0x3F, 0, 0, 0, 0x40, 0xAB, 0xAB, 0xAB};
    cr_assert_eq(obj.ndata, sizeof data);
    cr_assert_arr_eq(obj.data, data, sizeof data);
    cr_assert_eq(obj.nspad, 12);
    cr_assert_eq(obj.spad[0], 7);
    cr_assert_eq(imm_of(&obj, 0), 8);
    const AsmSymbol *s = find_sym(&obj, "stack");
    cr_assert_not_null(s);
    cr_assert_eq(s->section, ASM_SEC_SPAD);
    cr_assert_eq(s->value, 4);
    asm_object_free(&obj);
}

Test(asm_features, line_table)
{
    AsmObject obj;
    assemble_ok("; comment line\n"
                "start:  nop\n"
                "\n"
                "  vfadd v1, v2, v3 @m1 // trailing comment\n"
                "x: y: halt\n",
                NULL, &obj);
    cr_assert_eq(obj.ntext, 3);
    cr_assert_not_null(obj.lines);
    cr_assert_eq(obj.nfiles, 1);
    cr_assert_str_eq(obj.files[0], "ok.s");
    static const AsmLine want[] = {{0, 2, 9}, {0, 4, 3}, {0, 5, 7}};
    for (int i = 0; i < 3; i++) {
        cr_expect_eq(obj.lines[i].file, want[i].file);
        cr_expect_eq(obj.lines[i].line, want[i].line, "pc %d", i);
        cr_expect_eq(obj.lines[i].col, want[i].col, "pc %d", i);
    }
    char where[64];
    asm_object_where(&obj, 1, where, sizeof where);
    cr_assert_str_eq(where, "ok.s:4");
    asm_object_free(&obj);
}

Test(asm_features, file_api_and_missing_file)
{
    char dir[] = "/tmp/sfasm-file-XXXXXX", path[600];
    cr_assert_not_null(mkdtemp(dir));
    write_file(dir, "k.s", "li r1, 5\nhalt");  /* no final newline */
    snprintf(path, sizeof path, "%s/k.s", dir);
    AsmObject obj;
    AsmOptions opt = {0};
    char *buf = NULL;
    size_t len = 0;
    opt.diag = open_memstream(&buf, &len);
    cr_assert_eq(asm_assemble_file(path, &opt, &obj), 0);
    cr_assert_eq(obj.ntext, 2);
    asm_object_free(&obj);
    cr_assert_eq(asm_assemble_file("/nonexistent/x.s", &opt, &obj), 1);
    fclose(opt.diag);
    cr_assert_str_eq(buf, "/nonexistent/x.s:1:1: cannot read file: No such file or directory\n");
    free(buf);
    const char *names[] = {"k.s"};
    remove_files(dir, names, 1);
}

/* ---- asm_object ------------------------------------------------------------------------------- */

static void sample_object(AsmObject *obj)
{
    int nerr;
    char *diag = assemble_opt("obj.s", "N = 3\nstart: li r1, N\n  vfadd v1, v2, v3 @m2\n  jmp start\n"
                              ".data\nd: .word 1, 2\n.byte 9\n.spad\n.word 5\n",
                              NULL, obj, &nerr);
    cr_assert_eq(nerr, 0, "%s", diag);
    free(diag);
}

static void assert_same_object(const AsmObject *a, const AsmObject *b)
{
    cr_assert_eq(a->ntext, b->ntext);
    cr_assert_arr_eq(a->text, b->text, a->ntext * sizeof *a->text);
    cr_assert_eq(a->ndata, b->ndata);
    cr_assert_arr_eq(a->data, b->data, a->ndata);
    cr_assert_eq(a->nspad, b->nspad);
    cr_assert_arr_eq(a->spad, b->spad, a->nspad);
    cr_assert_eq(a->nfiles, b->nfiles);
    for (uint32_t i = 0; i < a->nfiles; i++)
        cr_assert_str_eq(a->files[i], b->files[i]);
    cr_assert_arr_eq(a->lines, b->lines, a->ntext * sizeof *a->lines);
    cr_assert_eq(a->nsyms, b->nsyms);
    for (uint32_t i = 0; i < a->nsyms; i++) {
        cr_assert_str_eq(a->syms[i].name, b->syms[i].name);
        cr_assert_eq(a->syms[i].section, b->syms[i].section);
        cr_assert_eq(a->syms[i].value, b->syms[i].value);
    }
}

Test(asm_object, write_read_round_trip)
{
    AsmObject obj, back;
    sample_object(&obj);
    char dir[] = "/tmp/sfasm-obj-XXXXXX", path[600], err[256];
    cr_assert_not_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/x.sfo", dir);
    cr_assert_eq(asm_object_write(&obj, path, err, sizeof err), 0, "%s", err);
    cr_assert_eq(asm_object_read(path, &back, err, sizeof err), 0, "%s", err);
    assert_same_object(&obj, &back);
    cr_assert_eq(back.nsyms, 3);
    asm_object_free(&back);
    asm_object_free(&obj);
    const char *names[] = {"x.sfo"};
    remove_files(dir, names, 1);
    cr_assert_eq(asm_object_read(path, &back, err, sizeof err), -1);
    cr_assert_not_null(strstr(err, "No such file"), "%s", err);
}

/* Encodes the sample, lets patch damage it, and expects decode to fail with msg in the error. */
static void expect_reject(void (*patch)(uint8_t *buf, size_t *len), const char *msg)
{
    AsmObject obj, back;
    uint8_t *buf;
    size_t len;
    char err[256];
    sample_object(&obj);
    cr_assert_eq(asm_object_encode(&obj, &buf, &len, err, sizeof err), 0);
    patch(buf, &len);
    cr_assert_eq(asm_object_decode(buf, len, "t.sfo", &back, err, sizeof err), -1, "accepted; want %s", msg);
    cr_assert_not_null(strstr(err, msg), "error '%s' lacks '%s'", err, msg);
    cr_assert(strncmp(err, "t.sfo: ", 7) == 0, "%s", err);
    cr_assert_null(back.text);
    free(buf);
    asm_object_free(&obj);
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get32(const uint8_t *p) { return p[0] | p[1] << 8 | p[2] << 16 | (uint32_t)p[3] << 24; }

/* Section table entry of the given kind. */
static uint8_t *entry(uint8_t *buf, uint32_t kind)
{
    for (uint32_t i = 0; i < get32(buf + 8); i++)
        if (get32(buf + 16 + 16 * i) == kind)
            return buf + 16 + 16 * i;
    cr_assert_fail("no section %u", kind);
    return NULL;
}

static void p_truncate_header(uint8_t *b, size_t *len) { (void)b; *len = 10; }
static void p_truncate_payload(uint8_t *b, size_t *len) { (void)b; *len -= 3; }
static void p_magic(uint8_t *b, size_t *len) { (void)len; b[0] = 'X'; }
static void p_version(uint8_t *b, size_t *len) { (void)len; put32(b + 4, 99); }
static void p_out_of_file(uint8_t *b, size_t *len) { (void)len; put32(entry(b, ASM_SEC_DATA) + 4, 0xFFFFFF00u); }
static void p_bad_word(uint8_t *b, size_t *len) { (void)len; b[get32(entry(b, ASM_SEC_TEXT) + 4) + 8 + 3] |= 0x80; }
static void p_unknown_kind(uint8_t *b, size_t *len) { (void)len; put32(entry(b, ASM_SEC_SPAD), 77); }
static void p_duplicate(uint8_t *b, size_t *len) { (void)len; put32(entry(b, ASM_SEC_SPAD), ASM_SEC_DATA); }
static void p_overlap(uint8_t *b, size_t *len)
{
    (void)len;
    put32(entry(b, ASM_SEC_SPAD) + 4, get32(entry(b, ASM_SEC_DATA) + 4));
}
static void p_lines_len(uint8_t *b, size_t *len) { (void)len; put32(entry(b, ASM_SEC_LINES) + 8, 12); }
static void p_line_file(uint8_t *b, size_t *len) { (void)len; put32(b + get32(entry(b, ASM_SEC_LINES) + 4), 5); }
static void p_table(uint8_t *b, size_t *len) { (void)len; put32(b + 8, 1000); }

Test(asm_object, decode_rejects_damage)
{
    expect_reject(p_truncate_header, "truncated header");
    expect_reject(p_truncate_payload, "outside the file");
    expect_reject(p_magic, "bad magic");
    expect_reject(p_version, "unsupported version 99");
    expect_reject(p_out_of_file, "outside the file");
    expect_reject(p_bad_word, "section TEXT word 1: vfadd: reserved bit 31 is set");
    expect_reject(p_unknown_kind, "unknown kind 77");
    expect_reject(p_duplicate, "duplicate section");
    expect_reject(p_overlap, "overlaps");
    expect_reject(p_lines_len, "section LINES");
    expect_reject(p_line_file, "file index 5 out of range");
    expect_reject(p_table, "truncated section table");
}

Test(asm_object, decode_unknown_opcode_message)
{
    uint64_t text[1] = {0xFE};
    AsmObject obj = {.text = text, .ntext = 1}, back;
    uint8_t *buf;
    size_t len;
    char err[256];
    cr_assert_eq(asm_object_encode(&obj, &buf, &len, err, sizeof err), 0);
    cr_assert_eq(asm_object_decode(buf, len, "u.sfo", &back, err, sizeof err), -1);
    cr_assert_str_eq(err, "u.sfo: section TEXT word 0: unknown opcode 0xfe");
    free(buf);
}

Test(asm_object, every_prefix_is_rejected_or_exact)
{
    AsmObject obj, back;
    uint8_t *buf;
    size_t len;
    char err[256];
    sample_object(&obj);
    cr_assert_eq(asm_object_encode(&obj, &buf, &len, err, sizeof err), 0);
    for (size_t n = 0; n < len; n++) {
        uint8_t *copy = malloc(n ? n : 1);
        memcpy(copy, buf, n);
        cr_assert_eq(asm_object_decode(copy, n, "p", &back, err, sizeof err), -1, "prefix %zu accepted", n);
        free(copy);
    }
    asm_object_free(&obj);
    free(buf);
}

Test(asm_object, where_without_debug_info)
{
    uint64_t text[1] = {0x01}; /* halt */
    AsmObject obj = {.text = text, .ntext = 1};
    char where[32];
    asm_object_where(&obj, 0, where, sizeof where);
    cr_assert_str_eq(where, "?");
    AsmObject full;
    sample_object(&full);
    asm_object_where(&full, 99, where, sizeof where);
    cr_assert_str_eq(where, "?");
    asm_object_where(&full, 2, where, sizeof where);
    cr_assert_str_eq(where, "obj.s:4");
    asm_object_free(&full);
}

/* ---- asm_roundtrip ---------------------------------------------------------------------------- */

static char *disassemble(const AsmObject *obj, int with_source)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    asm_disassemble(obj, m, with_source);
    fclose(m);
    return buf;
}

static void assert_reassembles(const AsmObject *obj, const char *what)
{
    char *text = disassemble(obj, 1);
    AsmObject back;
    int nerr;
    char *diag = assemble_opt("dis.s", text, NULL, &back, &nerr);
    cr_assert_eq(nerr, 0, "%s: reassembly failed:\n%s\n%s", what, diag, text);
    cr_assert_eq(back.ntext, obj->ntext, "%s", what);
    cr_assert(memcmp(back.text, obj->text, obj->ntext * sizeof *obj->text) == 0, "%s:\n%s", what, text);
    cr_assert_eq(back.ndata, obj->ndata, "%s", what);
    cr_assert(obj->ndata == 0 || memcmp(back.data, obj->data, obj->ndata) == 0, "%s", what);
    cr_assert_eq(back.nspad, obj->nspad, "%s", what);
    cr_assert(obj->nspad == 0 || memcmp(back.spad, obj->spad, obj->nspad) == 0, "%s", what);
    asm_object_free(&back);
    free(diag);
    free(text);
}

/* One instruction of op with the largest registers, a mask when masked and demanding immediates. */
static IsaInstr extreme_instr(int op, uint32_t ntext)
{
    static const uint32_t imms[] = {0xFFFFFFFBu, 0x7FFFFFFFu, 0x80000000u, 0xDEADBEEFu, 65536, 65537};
    IsaInstr in = {.op = (uint8_t)op};
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    for (int k = 0; k < f->nops; k++) {
        int max = isa_kind_max_reg(f->ops[k].kind);
        uint8_t v = (uint8_t)(max - k); /* distinct fields, so a swap would show */
        switch (f->ops[k].field) {
        case ISA_FIELD_A: in.a = v; break;
        case ISA_FIELD_B: in.b = v; break;
        case ISA_FIELD_C: in.c = v; break;
        case ISA_FIELD_D: in.d = v; break;
        case ISA_FIELD_IMM:
            if (f->ops[k].kind == ISA_K_LABEL)
                in.imm = ntext; /* the end of the program: the farthest legal target */
            else if (op == ISA_OP_STAGE)
                in.imm = 3;
            else
                in.imm = imms[op % 6];
            break;
        }
    }
    if (f->masked)
        in.mask = 7;
    return in;
}

Test(asm_roundtrip, every_opcode)
{
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        uint64_t text[2];
        IsaInstr in = extreme_instr(op, 2);
        text[0] = isa_encode(&in);
        IsaInstr halt = {.op = ISA_OP_HALT};
        text[1] = isa_encode(&halt);
        IsaInstr check;
        char err[128];
        cr_assert_eq(isa_decode(text[0], &check, err, sizeof err), 0, "%s: %s", isa_ops[op].mnemonic, err);
        AsmObject obj = {.text = text, .ntext = 2};
        assert_reassembles(&obj, isa_ops[op].mnemonic);
    }
}

Test(asm_roundtrip, all_opcodes_with_data_and_labels)
{
    uint64_t text[ISA_OP_COUNT];
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        IsaInstr in = extreme_instr(op, ISA_OP_COUNT);
        const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
        for (int k = 0; k < f->nops; k++)
            if (f->ops[k].kind == ISA_K_LABEL)
                in.imm = (uint32_t)((op * 7) % ISA_OP_COUNT); /* targets all over the program */
        text[op] = isa_encode(&in);
    }
    uint8_t data[11], spad[6];
    for (int i = 0; i < 11; i++)
        data[i] = (uint8_t)(0xF0 + i);
    for (int i = 0; i < 6; i++)
        spad[i] = (uint8_t)(i * 51);
    AsmObject obj = {.text = text, .ntext = ISA_OP_COUNT, .data = data, .ndata = 11, .spad = spad, .nspad = 6};
    assert_reassembles(&obj, "all opcodes");
}

Test(asm_roundtrip, assembled_source_with_line_comments)
{
    AsmObject obj;
    assemble_ok("top: li r1, -5\n  vfadd v1, v2, v3 @m7\n  bmnz m3, top\n  stage 2\n  jmp end2\n"
                ".data\n.float 1.25\n.byte 1, 2\nend:\n.text\nend2: halt\n",
                NULL, &obj);
    char *text = disassemble(&obj, 1);
    cr_assert_not_null(strstr(text, "L0:\n"), "%s", text);
    cr_assert_not_null(strstr(text, "bmnz m3, L0"), "%s", text);
    cr_assert_not_null(strstr(text, "; ok.s:2"), "%s", text);
    cr_assert_not_null(strstr(text, ".byte 0x01, 0x02"), "%s", text);
    free(text);
    assert_reassembles(&obj, "source");
    asm_object_free(&obj);
}
