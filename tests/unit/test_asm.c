/* tests/unit/test_asm.c -- sfasm: the language, what each source assembles to.
 *
 * Suite: asm_features (expressions and precedence, float immediates, labels and the location
 * counter, constants, include files, macros, register frames and aliases, conditionals, data
 * sections, the line table, the file API). The diagnostics are test_asm_errors.c's; the .sfo
 * encoding and the disassembler round trip are test_asm_object.c's.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"
#include "../support/asm_fixture.h"
#include "../support/files.h"

/* ---- helpers ---------------------------------------------------------------------------------- */

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
    ta_assemble_ok(src, NULL, &obj);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        cr_expect_eq(imm_of(&obj, (uint32_t)i), cases[i].value, "%s: got 0x%x", cases[i].expr,
                     imm_of(&obj, (uint32_t)i));
    asm_object_free(&obj);
}

Test(asm_features, float_immediates)
{
    AsmObject obj;
    ta_assemble_ok("li r1, 1.5\nli r2, .5\nli r3, 1e-3\nli r4, 2.0f\nli r5, -1.5\n"
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
    ta_assemble_ok("        jmp end\n"
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
    ta_assemble_ok("SIZE = END - START\n"
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
    ta_put_file(dir, "local.inc", "LOCAL = 7\n  li r2, LOCAL\n");
    ta_put_file(incdir, "lib.inc", ".macro twice r\n  add \\r, \\r, \\r\n.endm\nLIBVAL = 9\n");
    /* The main file's directory is searched first, then -I directories. */
    snprintf(main_name, sizeof main_name, "%s/main.s", dir);
    const char *inc[] = {incdir};
    AsmOptions opt = {.include_dirs = inc, .ninclude_dirs = 1};
    AsmObject obj;
    int nerr;
    char *diag = ta_assemble(main_name, "li r1, 1\n.include \"local.inc\"\n.include \"lib.inc\"\n"
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
    diag = ta_assemble(main_name, ".include \"lib.inc\"\n", NULL, &obj, &nerr);
    snprintf(want, sizeof want, "%s:1:10: include file 'lib.inc' not found\n", main_name);
    cr_assert_str_eq(diag, want);
    free(diag);
    tu_remove_tree(dir);
}

Test(asm_features, macros_args_defaults_unique)
{
    AsmObject obj;
    ta_assemble_ok(".macro count reg, n=3, step=1\n"
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
    ta_assemble_ok(".regs v3, a, d:xyz, m\n.regs m2, hit\nvfadd dy, a, dz @hit\nvmov m, dx\n"
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

Test(asm_features, register_aliases)
{
    AsmObject obj;
    ta_assemble_ok(".alias orgx, v3\n.alias dirx, v31\n.alias hit, m5\n.alias tmp, r7\n.alias org2, orgx\n"
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
    ta_assemble_ok(src, &opt, &obj);
    cr_assert_eq(obj.ntext, 2);
    cr_assert_eq(imm_of(&obj, 0), 1);
    cr_assert_eq(imm_of(&obj, 1), 8);
    asm_object_free(&obj);
    opt = (AsmOptions){.defines = &d1[1], .ndefines = 1};
    ta_assemble_ok(src, &opt, &obj);
    cr_assert_eq(imm_of(&obj, 0), 2);
    asm_object_free(&obj);
    AsmDefine d2 = {"SPP", 1};
    opt = (AsmOptions){.defines = &d2, .ndefines = 1};
    ta_assemble_ok(src, &opt, &obj);
    cr_assert_eq(obj.ntext, 1);
    cr_assert_eq(imm_of(&obj, 0), 3);
    asm_object_free(&obj);
}

Test(asm_features, data_sections)
{
    AsmObject obj;
    ta_assemble_ok("        ld r1, r0, table + 4\n"
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
    ta_assemble_ok("; comment line\n"
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
    ta_put_file(dir, "k.s", "li r1, 5\nhalt");  /* no final newline */
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
    tu_remove_tree(dir);
}
