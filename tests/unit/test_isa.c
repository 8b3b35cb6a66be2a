/* tests/unit/test_isa.c -- self-tests over the opcode table (isa/opcodes.def): the table is
 * consistent, encodings do not overlap and every valid word has one meaning, every opcode survives
 * encode -> decode -> disassemble -> assemble, every opcode executes on the functional core, and
 * docs/isa.md is what tools/gen_isadoc.c prints today.
 *
 * Suites: isa_table, isa_encoding, isa_roundtrip, isa_exec, isa_doc. */
#include <criterion/criterion.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"
#include "../../sim/core.h"
#include "../support/files.h"
#include "../support/rng.h"

/* Deterministic operand choices: the same words every run. */
static uint64_t rng_state = TEST_RNG_SEED;

static uint32_t rng_next(void) { return test_rng_u32(&rng_state); }

static int n_reg_operands(const IsaFormatInfo *f)
{
    int n = 0;
    for (int i = 0; i < f->nops; i++)
        n += f->ops[i].kind == ISA_K_R || f->ops[i].kind == ISA_K_V || f->ops[i].kind == ISA_K_M;
    return n;
}

static int format_has_kind(const IsaFormatInfo *f, IsaOperandKind k)
{
    for (int i = 0; i < f->nops; i++)
        if (f->ops[i].kind == k)
            return 1;
    return 0;
}

static uint8_t *field_ptr(IsaInstr *in, IsaField fld)
{
    switch (fld) {
    case ISA_FIELD_A: return &in->a;
    case ISA_FIELD_B: return &in->b;
    case ISA_FIELD_C: return &in->c;
    case ISA_FIELD_D: return &in->d;
    case ISA_FIELD_IMM: return NULL;
    }
    return NULL;
}

/* ---- the table itself --------------------------------------------------------------------- */

Test(isa_table, codes_are_unique_and_lookups_agree)
{
    for (int i = 0; i < ISA_OP_COUNT; i++) {
        for (int j = i + 1; j < ISA_OP_COUNT; j++)
            cr_expect_neq(isa_ops[i].code, isa_ops[j].code, "%s and %s share opcode 0x%02x", isa_ops[i].mnemonic,
                          isa_ops[j].mnemonic, isa_ops[i].code);
        cr_expect_eq(isa_op_from_code(isa_ops[i].code), i, "isa_op_from_code(0x%02x) is not %s", isa_ops[i].code,
                     isa_ops[i].name);
    }
}

Test(isa_table, mnemonics_are_unique_lowercase_and_lookups_agree)
{
    for (int i = 0; i < ISA_OP_COUNT; i++) {
        const char *m = isa_ops[i].mnemonic;
        cr_expect(m[0] != '\0', "%s has an empty mnemonic", isa_ops[i].name);
        for (const char *p = m; *p; p++)
            cr_expect((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9'), "mnemonic \"%s\" has character '%c'", m,
                      *p);
        for (int j = i + 1; j < ISA_OP_COUNT; j++)
            cr_expect_str_neq(m, isa_ops[j].mnemonic, "%s and %s share mnemonic %s", isa_ops[i].name, isa_ops[j].name,
                              m);
        cr_expect_eq(isa_op_from_mnemonic(m), i, "isa_op_from_mnemonic(\"%s\") is not %s", m, isa_ops[i].name);
    }
    cr_expect_eq(isa_op_from_mnemonic("nosuchop"), -1);
    cr_expect_eq(isa_op_from_mnemonic(""), -1);
    /* the lookup is a search of the sorted mnemonics: names before the first, after the last, a
     * prefix of one and one with a character more are not found */
    cr_expect_eq(isa_op_from_mnemonic("a"), -1);
    cr_expect_eq(isa_op_from_mnemonic("zzzzzz"), -1);
    cr_expect_eq(isa_op_from_mnemonic("vf"), -1);
    cr_expect_eq(isa_op_from_mnemonic("vfmulx"), -1);
    cr_expect_eq(isa_op_from_mnemonic("ADD"), -1);
}

Test(isa_table, formats_have_distinct_fields_of_the_right_kind)
{
    for (int f = 0; f < ISA_F_COUNT; f++) {
        const IsaFormatInfo *fi = &isa_formats[f];
        cr_assert(fi->nops >= 0 && fi->nops <= ISA_MAX_OPERANDS, "format %s: %d operands", fi->name, fi->nops);
        for (int i = 0; i < fi->nops; i++) {
            int is_reg = fi->ops[i].kind == ISA_K_R || fi->ops[i].kind == ISA_K_V || fi->ops[i].kind == ISA_K_M;
            if (is_reg)
                cr_expect(fi->ops[i].field <= ISA_FIELD_D, "format %s operand %d: register outside fields a..d",
                          fi->name, i + 1);
            else
                cr_expect_eq(fi->ops[i].field, ISA_FIELD_IMM, "format %s operand %d: immediate not in imm", fi->name,
                             i + 1);
            for (int j = i + 1; j < fi->nops; j++)
                cr_expect_neq(fi->ops[i].field, fi->ops[j].field, "format %s: operands %d and %d share a field",
                              fi->name, i + 1, j + 1);
        }
        if (fi->masked)
            cr_expect(format_has_kind(fi, ISA_K_V), "masked format %s has no vector operand", fi->name);
    }
}

/* ACC has one letter per register operand (immediates and labels are never written, and every
 * row of opcodes.def leaves them out), and only r, w, x. */
Test(isa_table, access_strings_match_formats)
{
    for (int i = 0; i < ISA_OP_COUNT; i++) {
        const IsaOpInfo *oi = &isa_ops[i];
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        cr_expect_eq((int)strlen(oi->access), n_reg_operands(fi), "%s: ACC \"%s\" for format %s with %d register operands",
                     oi->mnemonic, oi->access, fi->name, n_reg_operands(fi));
        for (const char *p = oi->access; *p; p++)
            cr_expect(*p == 'r' || *p == 'w' || *p == 'x', "%s: ACC \"%s\" has '%c'", oi->mnemonic, oi->access, *p);
    }
}

Test(isa_table, units_categories_flags_and_descriptions_are_valid)
{
    const uint32_t all_flags = ISA_FL_VEC | ISA_FL_FLOAT | ISA_FL_BRANCH | ISA_FL_END | ISA_FL_RB | ISA_FL_IDM |
                               ISA_FL_SPAD | ISA_FL_SCENE | ISA_FL_FB | ISA_FL_WRITE | ISA_FL_RBN | ISA_FL_SIDE;
    const uint32_t memories = ISA_FL_RB | ISA_FL_IDM | ISA_FL_SPAD | ISA_FL_SCENE | ISA_FL_FB;
    for (int i = 0; i < ISA_OP_COUNT; i++) {
        const IsaOpInfo *oi = &isa_ops[i];
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        cr_expect((int)oi->unit >= 0 && oi->unit < ISA_U_COUNT, "%s: unit", oi->mnemonic);
        cr_expect((int)oi->category >= 0 && oi->category < ISA_C_COUNT, "%s: category", oi->mnemonic);
        cr_expect((int)oi->format >= 0 && oi->format < ISA_F_COUNT, "%s: format", oi->mnemonic);
        cr_expect_eq(oi->flags & ~all_flags, 0u, "%s: unknown flag bits 0x%x", oi->mnemonic, oi->flags & ~all_flags);
        cr_expect(oi->desc != NULL && strlen(oi->desc) > 3, "%s: no meaning", oi->mnemonic);
        /* exec-mask lanes are what SIMD utilization counts, so a masked op must be a vector op */
        if (fi->masked)
            cr_expect(oi->flags & ISA_FL_VEC, "%s: masked format %s without ISA_FL_VEC", oi->mnemonic, fi->name);
        if (format_has_kind(fi, ISA_K_LABEL))
            cr_expect(oi->flags & ISA_FL_BRANCH, "%s: label operand without ISA_FL_BRANCH", oi->mnemonic);
        /* memory flags and memory units name the same memories */
        cr_expect_eq(!!(oi->flags & ISA_FL_RB), oi->unit == ISA_U_RBUF, "%s: rb flag vs unit %s", oi->mnemonic,
                     isa_unit_names[oi->unit]);
        cr_expect_eq(!!(oi->flags & ISA_FL_SPAD), oi->unit == ISA_U_SPAD, "%s: spad flag vs unit %s", oi->mnemonic,
                     isa_unit_names[oi->unit]);
        cr_expect_eq(!!(oi->flags & ISA_FL_SCENE), oi->unit == ISA_U_SCENE, "%s: scene flag vs unit %s", oi->mnemonic,
                     isa_unit_names[oi->unit]);
        cr_expect_eq(!!(oi->flags & ISA_FL_FB), oi->unit == ISA_U_FB, "%s: fb flag vs unit %s", oi->mnemonic,
                     isa_unit_names[oi->unit]);
        if (oi->flags & ISA_FL_IDM)
            cr_expect(oi->unit == ISA_U_AGU || oi->unit == ISA_U_PART, "%s: idm flag on unit %s", oi->mnemonic,
                      isa_unit_names[oi->unit]);
        /* the timing model tells loads from stores, gathers from scatters by the write flag */
        if (oi->flags & ISA_FL_RBN) /* the scheduler tells RBn from RBc by it */
            cr_expect(oi->flags & ISA_FL_RB, "%s: rbn flag without rb", oi->mnemonic);
        if (oi->flags & ISA_FL_WRITE)
            cr_expect(oi->flags & memories, "%s: write flag without a memory flag", oi->mnemonic);
        if (oi->category == ISA_C_STORE)
            cr_expect(oi->flags & ISA_FL_WRITE, "%s: store without the write flag", oi->mnemonic);
        if (oi->category == ISA_C_LOAD)
            cr_expect(!(oi->flags & ISA_FL_WRITE), "%s: load with the write flag", oi->mnemonic);
    }
    cr_expect_eq(isa_ops[isa_op_from_mnemonic("halt")].flags & ISA_FL_END, ISA_FL_END);
    for (int u = 0; u < ISA_U_COUNT; u++)
        cr_expect(isa_unit_names[u] && isa_unit_descs[u] && isa_unit_descs[u][0], "unit %d", u);
    for (int c = 0; c < ISA_C_COUNT; c++)
        cr_expect(isa_category_keys[c] && isa_category_keys[c][0], "category %d", c);
    cr_expect_eq(ISA_STAGE_COUNT, 4);
    cr_expect_str_eq(isa_stage_keys[ISA_STAGE_OTHER], "other");
    cr_expect_str_eq(isa_stage_keys[ISA_STAGE_TRAVERSAL], "traversal");
    cr_expect_str_eq(isa_stage_keys[ISA_STAGE_INTERSECTION], "intersection");
    cr_expect_str_eq(isa_stage_keys[ISA_STAGE_SHADING], "shading");
}

Test(isa_table, id_vector_moves_are_sfetch_and_sapp)
{
    /* The timing model sends ID fetches to the AGUs' run-ahead queue and ID appends over one
     * interconnect cycle by these flag tests; a new instruction that matched them would be timed
     * as one of the two. */
    for (int i = 0; i < ISA_OP_COUNT; i++) {
        const IsaOpInfo *oi = &isa_ops[i];
        cr_expect_eq(isa_id_fetch(oi->flags), i == ISA_OP_SFETCH, "%s: isa_id_fetch", oi->mnemonic);
        cr_expect_eq(isa_id_append(oi->flags), i == ISA_OP_SAPP, "%s: isa_id_append", oi->mnemonic);
    }
}

Test(isa_table, register_limits)
{
    cr_expect_eq(isa_kind_max_reg(ISA_K_R), 31);
    cr_expect_eq(isa_kind_max_reg(ISA_K_V), 31);
    cr_expect_eq(isa_kind_max_reg(ISA_K_M), 7);
    cr_expect_eq(isa_kind_max_reg(ISA_K_IMM), -1);
    cr_expect_eq(isa_kind_max_reg(ISA_K_LABEL), -1);
}

/* ---- encoding ----------------------------------------------------------------------------- */

/* A random legal instruction of op. */
static IsaInstr random_instr(int op)
{
    IsaInstr in = {(uint8_t)op, 0, 0, 0, 0, 0, 0};
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    for (int i = 0; i < f->nops; i++) {
        int maxr = isa_kind_max_reg(f->ops[i].kind);
        if (maxr >= 0)
            *field_ptr(&in, f->ops[i].field) = (uint8_t)(rng_next() % (unsigned)(maxr + 1));
        else
            in.imm = rng_next() ^ (rng_next() << 16);
    }
    if (f->masked)
        in.mask = (uint8_t)(rng_next() % ISA_NUM_MREGS);
    return in;
}

static int instr_eq(const IsaInstr *x, const IsaInstr *y)
{
    return x->op == y->op && x->a == y->a && x->b == y->b && x->c == y->c && x->d == y->d && x->mask == y->mask &&
           x->imm == y->imm;
}

Test(isa_encoding, random_legal_words_decode_to_the_same_instruction)
{
    char err[128];
    for (int op = 0; op < ISA_OP_COUNT; op++)
        for (int k = 0; k < 500; k++) {
            IsaInstr in = random_instr(op), out;
            uint64_t w = isa_encode(&in);
            cr_assert_eq((uint8_t)w, isa_ops[op].code, "%s: opcode byte", isa_ops[op].mnemonic);
            int rc = isa_decode(w, &out, err, sizeof err);
            cr_assert_eq(rc, 0, "%s: word 0x%016llx rejected: %s", isa_ops[op].mnemonic, (unsigned long long)w, err);
            cr_assert(instr_eq(&in, &out), "%s: word 0x%016llx decodes to another instruction (%s)",
                      isa_ops[op].mnemonic, (unsigned long long)w, isa_ops[out.op].mnemonic);
        }
}

Test(isa_encoding, every_opcode_byte_means_one_op_or_is_rejected)
{
    char err[128];
    int decoded = 0;
    for (int code = 0; code < 256; code++) {
        int owners = 0, owner = -1;
        for (int op = 0; op < ISA_OP_COUNT; op++)
            if (isa_ops[op].code == code) {
                owners++;
                owner = op;
            }
        cr_expect(owners <= 1, "opcode byte 0x%02x belongs to %d ops", code, owners);
        cr_expect_eq(isa_op_from_code((uint8_t)code), owner, "isa_op_from_code(0x%02x)", code);
        IsaInstr out;
        int rc = isa_decode((uint64_t)code, &out, err, sizeof err);
        if (owner < 0) {
            cr_expect_eq(rc, -1, "unassigned opcode byte 0x%02x decodes", code);
            if (rc == -1)
                cr_expect(strstr(err, "opcode") != NULL, "0x%02x: message \"%s\"", code, err);
        } else {
            cr_expect_eq(rc, 0, "0x%02x (%s) with all fields zero rejected: %s", code, isa_ops[owner].mnemonic, err);
            if (rc == 0)
                cr_expect_eq(out.op, owner, "0x%02x decodes to %s", code, isa_ops[out.op].mnemonic);
            decoded++;
        }
    }
    cr_expect_eq(decoded, ISA_OP_COUNT);
}

Test(isa_encoding, nonzero_unused_fields_are_rejected)
{
    char err[128];
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
        IsaInstr base = random_instr(op), out;
        uint64_t w = isa_encode(&base);
        unsigned used = 0;
        for (int i = 0; i < f->nops; i++)
            used |= 1u << f->ops[i].field;
        static const int shift[4] = {8, 13, 18, 23};
        for (int fld = ISA_FIELD_A; fld <= ISA_FIELD_D; fld++) {
            if (used & (1u << fld))
                continue;
            for (unsigned v = 1; v < 32; v <<= 1)
                cr_expect_eq(isa_decode(w | ((uint64_t)v << shift[fld]), &out, err, sizeof err), -1,
                             "%s: unused field %c = %u accepted", isa_ops[op].mnemonic, "abcd"[fld], v);
        }
        if (!(used & (1u << ISA_FIELD_IMM)))
            for (int bit = 32; bit < 64; bit++)
                cr_expect_eq(isa_decode(w | (1ull << bit), &out, err, sizeof err), -1,
                             "%s: unused immediate bit %d accepted", isa_ops[op].mnemonic, bit - 32);
        if (!f->masked)
            for (unsigned m = 1; m < 8; m++)
                cr_expect_eq(isa_decode(w | ((uint64_t)m << 28), &out, err, sizeof err), -1,
                             "%s: exec mask m%u on an unmasked format accepted", isa_ops[op].mnemonic, m);
        cr_expect_eq(isa_decode(w | (1ull << 31), &out, err, sizeof err), -1, "%s: reserved bit 31 accepted",
                     isa_ops[op].mnemonic);
        /* mask-register fields hold 0..7 only */
        for (int i = 0; i < f->nops; i++)
            if (f->ops[i].kind == ISA_K_M) {
                uint64_t clear = w & ~(0x1Full << shift[f->ops[i].field]);
                for (unsigned r = 8; r < 32; r++)
                    cr_expect_eq(isa_decode(clear | ((uint64_t)r << shift[f->ops[i].field]), &out, err, sizeof err),
                                 -1, "%s: mask operand %d = m%u accepted", isa_ops[op].mnemonic, i + 1, r);
            }
    }
}

/* Any word the decoder accepts re-encodes to itself: no two words share a meaning. */
Test(isa_encoding, accepted_random_words_reencode_identically)
{
    char err[128];
    int accepted = 0;
    for (int k = 0; k < 400000; k++) {
        uint64_t w = ((uint64_t)rng_next() << 32) | rng_next();
        /* bias toward plausible words: often clear the high fields so decodes succeed */
        if (k & 1)
            w &= 0x00000000FFFFFFFFull | ((uint64_t)(k & 2 ? 0xFFFFFFFFu : 0u) << 32);
        if (k & 4)
            w &= ~(0xFull << 28);
        if (k & 8)
            w &= ~(0x1Full << 23);
        if (k & 16)
            w &= ~(0x1Full << 18);
        IsaInstr out;
        if (isa_decode(w, &out, err, sizeof err) == 0) {
            accepted++;
            cr_assert_eq(isa_encode(&out), w, "word 0x%016llx decodes (%s) but re-encodes to 0x%016llx",
                         (unsigned long long)w, isa_ops[out.op].mnemonic, (unsigned long long)isa_encode(&out));
        }
    }
    cr_expect_gt(accepted, 1000, "too few random words decoded (%d) for the test to mean anything", accepted);
}

/* ---- encode -> decode -> disassemble -> assemble ------------------------------------------- */

/* Operand choices per opcode: zeros, maxima, mixed registers, and immediates of every printing
 * form (small, negative, the +-65536 boundary, hex above it, float bits, INT_MIN). */
static const uint32_t imm_choices[] = {0u,          1u,          0xFFFFFFFFu, 65536u,      0xFFFF0000u /* -65536 */,
                                       65537u,      0xFFFEFFFFu, 0x7FFFFFFFu, 0x80000000u, 0x3FC00000u /* 1.5f */,
                                       0xDEADBEEFu, 0xFFFFFFF8u};
#define N_IMM (sizeof imm_choices / sizeof imm_choices[0])

typedef struct Prog {
    IsaInstr *ins;
    int n, cap;
} Prog;

static void prog_add(Prog *p, IsaInstr in)
{
    if (p->n == p->cap) {
        p->cap = p->cap ? 2 * p->cap : 64;
        p->ins = realloc(p->ins, (size_t)p->cap * sizeof *p->ins);
        cr_assert_not_null(p->ins);
    }
    p->ins[p->n++] = in;
}

/* variant v of op: v 0 all zero, 1 all maxima, 2.. mixed */
static IsaInstr variant_instr(int op, int v, int nlabels)
{
    IsaInstr in = {(uint8_t)op, 0, 0, 0, 0, 0, 0};
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    for (int i = 0; i < f->nops; i++) {
        int maxr = isa_kind_max_reg(f->ops[i].kind);
        if (maxr >= 0) {
            int r = v == 0 ? 0 : v == 1 ? maxr : (v * 7 + i * 3) % (maxr + 1);
            *field_ptr(&in, f->ops[i].field) = (uint8_t)r;
        } else if (f->ops[i].kind == ISA_K_LABEL) {
            in.imm = v == 0 ? 0u : v == 1 ? (uint32_t)nlabels : (uint32_t)((v * 13) % (nlabels + 1));
        } else if (op == ISA_OP_STAGE) {
            in.imm = (uint32_t)(v % ISA_STAGE_COUNT); /* a stage number; other values need not assemble */
        } else {
            in.imm = imm_choices[(size_t)v % N_IMM];
        }
    }
    if (f->masked)
        in.mask = (uint8_t)(v == 1 ? 7 : v % 8);
    return in;
}

#define N_VARIANTS 14

Test(isa_roundtrip, every_opcode_disassembles_and_reassembles_to_the_same_words)
{
    Prog p = {0};
    int nprog = ISA_OP_COUNT * N_VARIANTS;
    for (int op = 0; op < ISA_OP_COUNT; op++)
        for (int v = 0; v < N_VARIANTS; v++)
            prog_add(&p, variant_instr(op, v, nprog));
    cr_assert_eq(p.n, nprog);

    /* Text: every instruction preceded by its label, so label operands (printed as L<pc>) resolve;
     * the last label is one past the end. */
    size_t cap = (size_t)nprog * 96 + 64, len = 0;
    char *src = malloc(cap);
    cr_assert_not_null(src);
    char line[128];
    for (int i = 0; i <= nprog; i++) {
        len += (size_t)snprintf(src + len, cap - len, "L%d:\n", i);
        if (i == nprog)
            break;
        char err[128];
        IsaInstr dec;
        uint64_t w = isa_encode(&p.ins[i]);
        cr_assert_eq(isa_decode(w, &dec, err, sizeof err), 0, "%s", err);
        cr_assert(instr_eq(&dec, &p.ins[i]));
        isa_disassemble(&dec, 1, line, sizeof line);
        len += (size_t)snprintf(src + len, cap - len, "        %s\n", line);
    }
    cr_assert_lt(len, cap);

    char *diag_buf = NULL;
    size_t diag_len = 0;
    FILE *diag = open_memstream(&diag_buf, &diag_len);
    AsmOptions opt = {.diag = diag};
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    int errors = asm_assemble_string("roundtrip.s", src, len, &opt, &obj);
    fclose(diag);
    cr_assert_eq(errors, 0, "the disassembly does not assemble (%d errors):\n%s", errors, diag_buf ? diag_buf : "");
    cr_assert_eq(obj.ntext, (uint32_t)nprog, "assembled %u words, expected %d", obj.ntext, nprog);
    int bad = 0;
    for (int i = 0; i < nprog; i++) {
        uint64_t w = isa_encode(&p.ins[i]);
        if (obj.text[i] != w && bad++ < 20) {
            isa_disassemble(&p.ins[i], 1, line, sizeof line);
            cr_expect_eq(obj.text[i], w, "L%d: \"%s\" assembled to 0x%016llx, expected 0x%016llx", i, line,
                         (unsigned long long)obj.text[i], (unsigned long long)w);
        }
    }
    cr_expect_eq(bad, 0, "%d words differ", bad);
    asm_object_free(&obj);
    free(diag_buf);
    free(src);
    free(p.ins);
}

/* Numeric label operands (label_names = 0) assemble too: `jmp 3` is an absolute target. */
Test(isa_roundtrip, numeric_label_operands_reassemble)
{
    char src[4096], line[128];
    size_t len = 0;
    int n = 0;
    IsaInstr ins[ISA_OP_COUNT];
    for (int op = 0; op < ISA_OP_COUNT; op++)
        if (format_has_kind(&isa_formats[isa_ops[op].format], ISA_K_LABEL)) {
            ins[n] = variant_instr(op, 2, 20);
            isa_disassemble(&ins[n], 0, line, sizeof line);
            cr_assert(strchr(line, 'L') == NULL, "\"%s\"", line);
            len += (size_t)snprintf(src + len, sizeof src - len, "%s\n", line);
            n++;
        }
    for (int k = n; k <= 20; k++)
        len += (size_t)snprintf(src + len, sizeof src - len, "nop\n");
    cr_assert_gt(n, 5);
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    FILE *diag = tmpfile();
    AsmOptions opt = {.diag = diag};
    int errors = asm_assemble_string("numeric.s", src, len, &opt, &obj);
    cr_assert_eq(errors, 0, "numeric label operands do not assemble:\n%s", src);
    for (int i = 0; i < n; i++)
        cr_expect_eq(obj.text[i], isa_encode(&ins[i]), "word %d (%s)", i, isa_ops[ins[i].op].mnemonic);
    asm_object_free(&obj);
    fclose(diag);
}

/* ---- every opcode executes ---------------------------------------------------------------- */

static void exec_params(CoreParams *p, int lanes)
{
    memset(p, 0, sizeof *p);
    p->lanes = lanes;
    p->mem_bytes[CORE_MEM_RB0] = 512 * 1024;
    p->mem_bytes[CORE_MEM_RB1] = 512 * 1024;
    p->mem_bytes[CORE_MEM_IDM] = 32 * 1024;
    p->mem_bytes[CORE_MEM_SPAD] = 64 * 1024;
    p->mem_bytes[CORE_MEM_SCENE] = 1024 * 1024;
    p->mem_bytes[CORE_MEM_FB] = 64 * 1024;
}

/* One instruction then halt. Operands: registers 0 (all memory addresses 0, vectors 0, m0 = all
 * lanes), except that r1 = 1 (set before the run) serves as the divisor of divu/remu and as the
 * target of jr; labels point at the halt; stage 1. The program must halt after two instructions
 * and the core must have counted the op once. */
Test(isa_exec, every_opcode_executes_once_and_halts)
{
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        IsaInstr in = {(uint8_t)op, 0, 0, 0, 0, 0, 0};
        const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
        for (int i = 0; i < f->nops; i++)
            if (f->ops[i].kind == ISA_K_LABEL)
                in.imm = 1;
        if (op == ISA_OP_STAGE)
            in.imm = 1;
        if (op == ISA_OP_DIVU || op == ISA_OP_REMU)
            in.c = 1;
        if (op == ISA_OP_JR)
            in.a = 1;
        IsaInstr halt = {ISA_OP_HALT, 0, 0, 0, 0, 0, 0};
        uint64_t text[2] = {isa_encode(&in), isa_encode(&halt)};
        AsmObject obj;
        memset(&obj, 0, sizeof obj);
        obj.text = text;
        obj.ntext = 2;
        CoreParams prm;
        exec_params(&prm, 4);
        char err[256];
        Core *c = core_new(&prm, &obj, err, sizeof err);
        cr_assert_not_null(c, "%s: core_new: %s", isa_ops[op].mnemonic, err);
        core_set_sreg(c, 1, 1);
        CoreExit ex = core_run(c, 100);
        cr_expect_eq(ex, CORE_EXIT_HALT, "%s: exit %d: %s", isa_ops[op].mnemonic, (int)ex,
                     ex == CORE_EXIT_HALT ? "" : core_trap_message(c));
        const CoreStats *st = core_stats(c);
        cr_expect_eq(st->by_op[op], 1u, "%s: executed %llu times, expected once", isa_ops[op].mnemonic,
                     (unsigned long long)st->by_op[op]);
        cr_expect_eq(core_instructions(c), op == ISA_OP_HALT ? 1u : 2u, "%s: %llu instructions executed",
                     isa_ops[op].mnemonic, (unsigned long long)core_instructions(c));
        uint64_t by_cat = 0;
        for (int s = 0; s < ISA_STAGE_COUNT; s++)
            by_cat += st->ops[s][isa_ops[op].category];
        cr_expect_geq(by_cat, 1u, "%s: not counted in category %s", isa_ops[op].mnemonic,
                      isa_category_keys[isa_ops[op].category]);
        core_free(c);
    }
}

/* ---- docs/isa.md is current ---------------------------------------------------------------- */

Test(isa_doc, docs_isa_md_is_current)
{
    tu_expect_generated("gen_isadoc", "SFSIM_GEN_ISADOC", "docs/isa.md");
}

/* The reference lists every instruction once, with its code. */
Test(isa_doc, docs_isa_md_lists_every_opcode)
{
    FILE *f = fopen("docs/isa.md", "r");
    cr_assert_not_null(f, "docs/isa.md is missing: run make docs");
    static char text[1 << 18];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        char row[64];
        snprintf(row, sizeof row, "| `%s` | `%s", isa_ops[op].mnemonic, isa_ops[op].mnemonic);
        const char *hit = strstr(text, row);
        cr_expect_not_null(hit, "docs/isa.md has no row for %s", isa_ops[op].mnemonic);
        if (hit)
            cr_expect_null(strstr(hit + 1, row), "docs/isa.md has two rows for %s", isa_ops[op].mnemonic);
    }
}
