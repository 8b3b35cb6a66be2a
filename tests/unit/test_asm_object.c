/* tests/unit/test_asm_object.c -- sfasm: object files and the disassembler.
 *
 * Suites: asm_object (the .sfo encoding, its validation of damaged files, source locations),
 * asm_roundtrip (disassembly reassembles to identical bytes for every opcode).
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"
#include "../support/asm_fixture.h"
#include "../support/files.h"

/* ---- asm_object ------------------------------------------------------------------------------- */

static void sample_object(AsmObject *obj)
{
    int nerr;
    char *diag = ta_assemble("obj.s", "N = 3\nstart: li r1, N\n  vfadd v1, v2, v3 @m2\n  jmp start\n"
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

/* The sample object, and its encoding in *buf (malloc'ed). */
static void encode_sample(AsmObject *obj, uint8_t **buf, size_t *len)
{
    char err[256];
    sample_object(obj);
    cr_assert_eq(asm_object_encode(obj, buf, len, err, sizeof err), 0, "%s", err);
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
    tu_remove_tree(dir);
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
    encode_sample(&obj, &buf, &len);
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
    encode_sample(&obj, &buf, &len);
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
    char *diag = ta_assemble("dis.s", text, NULL, &back, &nerr);
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
    ta_assemble_ok("top: li r1, -5\n  vfadd v1, v2, v3 @m7\n  bmnz m3, top\n  stage 2\n  jmp end2\n"
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
