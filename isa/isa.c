/* isa/isa.c -- descriptor tables expanded from opcodes.def, encoding, decoding, disassembly.
 *
 * Owns: the instruction word's bit layout. Must not: hold semantics or timing.
 */
#include "isa.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const IsaOpInfo isa_ops[ISA_OP_COUNT] = {
#define ISA_OP(name, code, mnem, fmt, acc, unit, cat, flags, desc) \
    {#name, code, mnem, fmt, acc, ISA_U_##unit, ISA_C_##cat, flags, desc},
#include "opcodes.def"
#undef ISA_OP
};

const IsaFormatInfo isa_formats[ISA_F_COUNT] = {
#define ISA_FMT_INFO(name, n, masked, ...) {#name, n, masked, {__VA_ARGS__}},
    ISA_FORMATS(ISA_FMT_INFO)
#undef ISA_FMT_INFO
};

const char *const isa_unit_names[ISA_U_COUNT] = {
#define ISA_UNIT_NAME(name, desc) #name,
    ISA_UNITS(ISA_UNIT_NAME)
#undef ISA_UNIT_NAME
};

const char *const isa_unit_descs[ISA_U_COUNT] = {
#define ISA_UNIT_DESC(name, desc) desc,
    ISA_UNITS(ISA_UNIT_DESC)
#undef ISA_UNIT_DESC
};

const char *const isa_category_keys[ISA_C_COUNT] = {
#define ISA_CAT_KEY(name, key) key,
    ISA_CATEGORIES(ISA_CAT_KEY)
#undef ISA_CAT_KEY
};

const char *const isa_stage_keys[ISA_STAGE_COUNT] = {
#define ISA_STAGE_KEY(name, key) key,
    ISA_STAGES(ISA_STAGE_KEY)
#undef ISA_STAGE_KEY
};

/* Opcode byte -> op + 1 (0: not an opcode), built from the table so it cannot drift. */
static const int16_t code_to_op1[256] = {
#define ISA_OP(name, code, mnem, fmt, acc, unit, cat, flags, desc) [code] = ISA_OP_##name + 1,
#include "opcodes.def"
#undef ISA_OP
};

int isa_op_from_code(uint8_t code) { return code_to_op1[code] - 1; }

/* isa_op_from_mnemonic's index: the opcodes in order of mnemonic (then of opcode), built once.
 * The assembler asks at every statement and macro line; a scan of the table with strcmp was
 * about half of assembling the path tracer, which every run does (fifteenth session,
 * docs/performance.md). */
static int16_t by_mnemonic[ISA_OP_COUNT];
static pthread_once_t by_mnemonic_once = PTHREAD_ONCE_INIT;

static int mnemonic_order(const void *pa, const void *pb)
{
    const int a = *(const int16_t *)pa, b = *(const int16_t *)pb;
    const int c = strcmp(isa_ops[a].mnemonic, isa_ops[b].mnemonic);
    return c ? c : (a > b) - (a < b);
}

static void by_mnemonic_build(void)
{
    for (int i = 0; i < ISA_OP_COUNT; i++)
        by_mnemonic[i] = (int16_t)i;
    qsort(by_mnemonic, ISA_OP_COUNT, sizeof by_mnemonic[0], mnemonic_order);
}

int isa_op_from_mnemonic(const char *mnem)
{
    pthread_once(&by_mnemonic_once, by_mnemonic_build);
    int lo = 0, hi = ISA_OP_COUNT; /* the first entry not below mnem */
    while (lo < hi) {
        const int mid = lo + (hi - lo) / 2;
        if (strcmp(isa_ops[by_mnemonic[mid]].mnemonic, mnem) < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < ISA_OP_COUNT && strcmp(isa_ops[by_mnemonic[lo]].mnemonic, mnem) == 0 ? by_mnemonic[lo] : -1;
}

int isa_kind_max_reg(IsaOperandKind k)
{
    switch (k) {
    case ISA_K_R: return ISA_NUM_SREGS - 1;
    case ISA_K_V: return ISA_NUM_VREGS - 1;
    case ISA_K_M: return ISA_NUM_MREGS - 1;
    case ISA_K_IMM:
    case ISA_K_LABEL: return -1;
    }
    return -1;
}

#define W_OP(w)   ((unsigned)((w) & 0xFFu))
#define W_A(w)    ((unsigned)(((w) >> 8) & 0x1Fu))
#define W_B(w)    ((unsigned)(((w) >> 13) & 0x1Fu))
#define W_C(w)    ((unsigned)(((w) >> 18) & 0x1Fu))
#define W_D(w)    ((unsigned)(((w) >> 23) & 0x1Fu))
#define W_MASK(w) ((unsigned)(((w) >> 28) & 0x7u))
#define W_PAD(w)  ((unsigned)(((w) >> 31) & 0x1u))
#define W_IMM(w)  ((uint32_t)((w) >> 32))

uint64_t isa_encode(const IsaInstr *in)
{
    uint8_t code = isa_ops[in->op].code;
    return (uint64_t)code | ((uint64_t)(in->a & 0x1F) << 8) | ((uint64_t)(in->b & 0x1F) << 13) |
           ((uint64_t)(in->c & 0x1F) << 18) | ((uint64_t)(in->d & 0x1F) << 23) |
           ((uint64_t)(in->mask & 0x7) << 28) | ((uint64_t)in->imm << 32);
}

static unsigned field_value(const IsaInstr *in, IsaField f)
{
    switch (f) {
    case ISA_FIELD_A: return in->a;
    case ISA_FIELD_B: return in->b;
    case ISA_FIELD_C: return in->c;
    case ISA_FIELD_D: return in->d;
    case ISA_FIELD_IMM: return 0;
    }
    return 0;
}

int isa_decode(uint64_t word, IsaInstr *out, char *err, size_t errlen)
{
    int op = isa_op_from_code((uint8_t)W_OP(word));
    if (op < 0) {
        snprintf(err, errlen, "unknown opcode 0x%02x", W_OP(word));
        return -1;
    }
    IsaInstr in = {(uint8_t)op, (uint8_t)W_A(word), (uint8_t)W_B(word), (uint8_t)W_C(word),
                   (uint8_t)W_D(word), (uint8_t)W_MASK(word), W_IMM(word)};
    const IsaFormatInfo *f = &isa_formats[isa_ops[op].format];
    unsigned used = 0; /* bit per field A..D, bit 4 = imm */
    for (int i = 0; i < f->nops; i++) {
        used |= 1u << f->ops[i].field;
        int maxr = isa_kind_max_reg(f->ops[i].kind);
        if (maxr >= 0 && (int)field_value(&in, f->ops[i].field) > maxr) {
            snprintf(err, errlen, "%s: operand %d register %u out of range (max %d)",
                     isa_ops[op].mnemonic, i + 1, field_value(&in, f->ops[i].field), maxr);
            return -1;
        }
    }
    static const char fname[] = "abcd";
    for (int fld = ISA_FIELD_A; fld <= ISA_FIELD_D; fld++) {
        if (!(used & (1u << fld)) && field_value(&in, (IsaField)fld) != 0) {
            snprintf(err, errlen, "%s: unused field %c is not zero", isa_ops[op].mnemonic, fname[fld]);
            return -1;
        }
    }
    if (!(used & (1u << ISA_FIELD_IMM)) && in.imm != 0) {
        snprintf(err, errlen, "%s: unused immediate is not zero", isa_ops[op].mnemonic);
        return -1;
    }
    if (!f->masked && in.mask != 0) {
        snprintf(err, errlen, "%s: exec mask on an unmasked instruction", isa_ops[op].mnemonic);
        return -1;
    }
    if (W_PAD(word)) {
        snprintf(err, errlen, "%s: reserved bit 31 is set", isa_ops[op].mnemonic);
        return -1;
    }
    *out = in;
    return 0;
}

void isa_disassemble(const IsaInstr *in, int label_names, char *buf, size_t len)
{
    const IsaOpInfo *oi = &isa_ops[in->op];
    const IsaFormatInfo *f = &isa_formats[oi->format];
    size_t n = (size_t)snprintf(buf, len, "%s", oi->mnemonic);
    for (int i = 0; i < f->nops && n < len; i++) {
        const char *sep = i == 0 ? " " : ", ";
        unsigned r = field_value(in, f->ops[i].field);
        switch (f->ops[i].kind) {
        case ISA_K_R: n += (size_t)snprintf(buf + n, len - n, "%sr%u", sep, r); break;
        case ISA_K_V: n += (size_t)snprintf(buf + n, len - n, "%sv%u", sep, r); break;
        case ISA_K_M: n += (size_t)snprintf(buf + n, len - n, "%sm%u", sep, r); break;
        case ISA_K_IMM:
            if ((int32_t)in->imm >= -65536 && (int32_t)in->imm <= 65536)
                n += (size_t)snprintf(buf + n, len - n, "%s%d", sep, (int32_t)in->imm);
            else
                n += (size_t)snprintf(buf + n, len - n, "%s0x%08x", sep, in->imm);
            break;
        case ISA_K_LABEL:
            n += (size_t)snprintf(buf + n, len - n, label_names ? "%sL%u" : "%s%u", sep, in->imm);
            break;
        }
    }
    if (f->masked && in->mask != 0 && n < len)
        snprintf(buf + n, len - n, " @m%u", in->mask);
}
