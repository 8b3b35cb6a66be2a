/* isa/isa.h -- the sfsim ISA as data: opcodes, operand formats, encoding, units, categories.
 *
 * Owns: the expansion of isa/opcodes.def into enums and descriptor tables, and the bit layout
 * of the 64-bit instruction word. Must not: execute instructions (sim/core.c) or know any
 * latency (the timing model reads those from the machine config).
 *
 * Instruction word (64 bits, little-endian in objects):
 *   [7:0] opcode  [12:8] field a  [17:13] field b  [22:18] field c  [27:23] field d
 *   [30:28] exec mask  [31] zero  [63:32] imm (32 bits)
 * Fields a..d hold register numbers (0..31 for r and v, 0..7 for m). A field the format does
 * not use must be zero; isa_decode rejects words that break this, so every valid word has
 * exactly one meaning.
 */
#ifndef SFSIM_ISA_H
#define SFSIM_ISA_H

#include <stdint.h>
#include <stddef.h>

#define ISA_NUM_SREGS   32
#define ISA_NUM_VREGS   32
#define ISA_NUM_MREGS   8
#define ISA_MAX_LANES   64   /* N is a run-time parameter, 1..ISA_MAX_LANES */
#define ISA_MAX_OPERANDS 4

/* Opcodes: ISA_OP_NOP, ISA_OP_HALT, ... */
typedef enum IsaOp {
#define ISA_OP(name, code, mnem, fmt, acc, unit, cat, flags, desc) ISA_OP_##name,
#include "opcodes.def"
#undef ISA_OP
    ISA_OP_COUNT
} IsaOp;

/* Operand kinds. */
typedef enum IsaOperandKind {
    ISA_K_R,     /* scalar register r0..r31 */
    ISA_K_V,     /* vector register v0..v31 */
    ISA_K_M,     /* mask register m0..m7 */
    ISA_K_IMM,   /* 32-bit immediate (integer or float bits) */
    ISA_K_LABEL  /* code address (instruction index) in the immediate */
} IsaOperandKind;

/* Instruction word fields an operand can occupy. */
typedef enum IsaField { ISA_FIELD_A, ISA_FIELD_B, ISA_FIELD_C, ISA_FIELD_D, ISA_FIELD_IMM } IsaField;

/* Operand formats: name, operand count, whether the exec mask applies, then the operands
 * ({kind, field} each; NONE lists a placeholder). */
#define ISA_FORMATS(X) \
    X(NONE, 0, 0, {0, 0}) \
    X(I,    1, 0, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(L,    1, 0, {ISA_K_LABEL, ISA_FIELD_IMM}) \
    X(R,    1, 0, {ISA_K_R, ISA_FIELD_A}) \
    X(RR,   2, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}) \
    X(RRR,  3, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}, {ISA_K_R, ISA_FIELD_C}) \
    X(RRRR, 4, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}, {ISA_K_R, ISA_FIELD_C}, {ISA_K_R, ISA_FIELD_D}) \
    X(RI,   2, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(RRI,  3, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(RL,   2, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_LABEL, ISA_FIELD_IMM}) \
    X(RRL,  3, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}, {ISA_K_LABEL, ISA_FIELD_IMM}) \
    X(ML,   2, 0, {ISA_K_M, ISA_FIELD_A}, {ISA_K_LABEL, ISA_FIELD_IMM}) \
    X(V,    1, 1, {ISA_K_V, ISA_FIELD_A}) \
    X(VV,   2, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}) \
    X(VVV,  3, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_V, ISA_FIELD_C}) \
    X(VVVV, 4, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_V, ISA_FIELD_C}, {ISA_K_V, ISA_FIELD_D}) \
    X(VVVM, 4, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_V, ISA_FIELD_C}, {ISA_K_M, ISA_FIELD_D}) \
    X(VR,   2, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}) \
    X(VI,   2, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(VRI,  3, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(VVI,  3, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(VVRI, 4, 1, {ISA_K_V, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_R, ISA_FIELD_C}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(MVV,  3, 1, {ISA_K_M, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_V, ISA_FIELD_C}) \
    X(RV,   2, 1, {ISA_K_R, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}) \
    X(RVI,  3, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_V, ISA_FIELD_B}, {ISA_K_IMM, ISA_FIELD_IMM}) \
    X(VMRR, 4, 0, {ISA_K_V, ISA_FIELD_A}, {ISA_K_M, ISA_FIELD_B}, {ISA_K_R, ISA_FIELD_C}, {ISA_K_R, ISA_FIELD_D}) \
    X(M,    1, 0, {ISA_K_M, ISA_FIELD_A}) \
    X(MM,   2, 0, {ISA_K_M, ISA_FIELD_A}, {ISA_K_M, ISA_FIELD_B}) \
    X(MMM,  3, 0, {ISA_K_M, ISA_FIELD_A}, {ISA_K_M, ISA_FIELD_B}, {ISA_K_M, ISA_FIELD_C}) \
    X(MR,   2, 0, {ISA_K_M, ISA_FIELD_A}, {ISA_K_R, ISA_FIELD_B}) \
    X(RM,   2, 0, {ISA_K_R, ISA_FIELD_A}, {ISA_K_M, ISA_FIELD_B})

typedef enum IsaFormat {
#define ISA_FMT_ENUM(name, n, masked, ...) ISA_F_##name,
    ISA_FORMATS(ISA_FMT_ENUM)
#undef ISA_FMT_ENUM
    ISA_F_COUNT
} IsaFormat;

/* Functional-unit classes. The timing model maps each to a latency and an issue rate taken
 * from the machine config; the ISA only names the class (SimpleScalar's split). */
#define ISA_UNITS(X) \
    X(SALU,   "scalar integer ALU") \
    X(SFPU,   "scalar float unit") \
    X(SSPEC,  "scalar divide/sqrt unit") \
    X(VADD,   "vector float add/min/max/convert") \
    X(VMUL,   "vector multiply") \
    X(VFMA,   "vector fused multiply-add") \
    X(VSPEC,  "vector special functions (div, rcp, sqrt, rsqrt, sin, cos, exp2, log2)") \
    X(VCMP,   "vector compare into mask") \
    X(VLOGIC, "vector integer/logic") \
    X(VSEL,   "vector select/move/broadcast") \
    X(MASK,   "mask-register logic") \
    X(AGU,    "address generation units: ID-stream fetch/append, slot allocation") \
    X(RBUF,   "ray-buffer banks (gather/scatter through the interconnect)") \
    X(PART,   "stream partition unit") \
    X(SPAD,   "scratchpad ports") \
    X(SCENE,  "scene memory") \
    X(FB,     "framebuffer") \
    X(BRANCH, "control: branches, calls, markers")

typedef enum IsaUnit {
#define ISA_UNIT_ENUM(name, desc) ISA_U_##name,
    ISA_UNITS(ISA_UNIT_ENUM)
#undef ISA_UNIT_ENUM
    ISA_U_COUNT
} IsaUnit;

/* Operation categories (Gribble & Ramani 2008, Table 5: load, store, compute, scatter/gather,
 * partition; plus integer/address and control, which that table folds into load and store). */
#define ISA_CATEGORIES(X) \
    X(LOAD,      "load") \
    X(STORE,     "store") \
    X(COMPUTE,   "compute") \
    X(SCATGATH,  "scatter_gather") \
    X(PARTITION, "partition") \
    X(INTEGER,   "integer") \
    X(CONTROL,   "control")

typedef enum IsaCategory {
#define ISA_CAT_ENUM(name, key) ISA_C_##name,
    ISA_CATEGORIES(ISA_CAT_ENUM)
#undef ISA_CAT_ENUM
    ISA_C_COUNT
} IsaCategory;

/* Statistics stages, set by the `stage` instruction. */
#define ISA_STAGES(X) \
    X(OTHER,        "other") \
    X(TRAVERSAL,    "traversal") \
    X(INTERSECTION, "intersection") \
    X(SHADING,      "shading")

typedef enum IsaStage {
#define ISA_STAGE_ENUM(name, key) ISA_STAGE_##name,
    ISA_STAGES(ISA_STAGE_ENUM)
#undef ISA_STAGE_ENUM
    ISA_STAGE_COUNT
} IsaStage;

/* Flags. */
enum {
    ISA_FL_VEC    = 1u << 0, /* operates on N lanes; counts toward SIMD utilization */
    ISA_FL_FLOAT  = 1u << 1, /* interprets values as binary32 */
    ISA_FL_BRANCH = 1u << 2, /* may change the pc */
    ISA_FL_END    = 1u << 3, /* ends execution */
    ISA_FL_RB     = 1u << 4, /* touches a ray buffer */
    ISA_FL_IDM    = 1u << 5, /* touches ID-stream memory */
    ISA_FL_SPAD   = 1u << 6, /* touches the scratchpad */
    ISA_FL_SCENE  = 1u << 7, /* touches scene memory */
    ISA_FL_FB     = 1u << 8, /* touches the framebuffer */
    ISA_FL_WRITE  = 1u << 9, /* writes the memory it touches (store, scatter, append, scatter-add,
                                in-place partition); without it a memory instruction only reads */
    ISA_FL_RBN    = 1u << 10, /* with RB: the next ray buffer (RBn), not the current one (RBc) */
    ISA_FL_SIDE   = 1u << 11  /* an effect no operand or memory flag shows: swaps the ray buffers
                                 (rswap), moves the statistics to another stage or generation (stage,
                                 sgen); the scheduling pass (asm/sched.c) moves nothing across it */
};

/* The two ID-vector moves, told apart by the flags (the timing model dispatches on these, never
 * on opcodes): an ID fetch reads the next ID vector of a stream (sfetch; the AGUs fetch it ahead),
 * an ID append writes one (sapp). */
static inline int isa_id_fetch(uint32_t flags)
{
    return (flags & (ISA_FL_VEC | ISA_FL_IDM | ISA_FL_WRITE)) == (ISA_FL_VEC | ISA_FL_IDM);
}
static inline int isa_id_append(uint32_t flags)
{
    return (flags & (ISA_FL_VEC | ISA_FL_IDM | ISA_FL_WRITE)) == (ISA_FL_VEC | ISA_FL_IDM | ISA_FL_WRITE);
}

/* Operand access, per operand (the ACC column). */
typedef enum IsaAccess { ISA_ACC_READ = 'r', ISA_ACC_WRITE = 'w', ISA_ACC_RW = 'x' } IsaAccess;

typedef struct IsaOperand {
    IsaOperandKind kind;
    IsaField field;
} IsaOperand;

typedef struct IsaFormatInfo {
    const char *name;
    int nops;
    int masked;                       /* exec mask (@mK) applies */
    IsaOperand ops[ISA_MAX_OPERANDS];
} IsaFormatInfo;

typedef struct IsaOpInfo {
    const char *name;     /* enum suffix, e.g. "VFADD" */
    uint8_t code;
    const char *mnemonic;
    IsaFormat format;
    const char *access;   /* one of r/w/x per operand */
    IsaUnit unit;
    IsaCategory category;
    uint32_t flags;
    const char *desc;
} IsaOpInfo;

/* A decoded instruction: what the functional core and the timing model work from. */
typedef struct IsaInstr {
    uint8_t op;           /* IsaOp */
    uint8_t a, b, c, d;   /* register fields */
    uint8_t mask;         /* exec mask register (masked formats; 0 otherwise) */
    uint32_t imm;
} IsaInstr;

extern const IsaOpInfo isa_ops[ISA_OP_COUNT];
extern const IsaFormatInfo isa_formats[ISA_F_COUNT];
extern const char *const isa_unit_names[ISA_U_COUNT];
extern const char *const isa_unit_descs[ISA_U_COUNT];
extern const char *const isa_category_keys[ISA_C_COUNT];
extern const char *const isa_stage_keys[ISA_STAGE_COUNT];

/* Opcode byte -> IsaOp, or -1 if the byte is not an opcode. */
int isa_op_from_code(uint8_t code);
/* Mnemonic -> IsaOp, or -1. */
int isa_op_from_mnemonic(const char *mnem);

/* Encode a decoded instruction; unused fields must already be zero. */
uint64_t isa_encode(const IsaInstr *in);
/* Decode a word. Returns 0, or -1 with a message in err (unknown opcode, register out of
 * range for its kind, non-zero unused field). */
int isa_decode(uint64_t word, IsaInstr *out, char *err, size_t errlen);

/* Disassemble one instruction as assembler text (no trailing newline). Label operands are
 * printed as `L<pc>` when label_names is non-zero, otherwise as numbers. */
void isa_disassemble(const IsaInstr *in, int label_names, char *buf, size_t len);

/* Maximum register number for an operand kind (31 for r/v, 7 for m). */
int isa_kind_max_reg(IsaOperandKind k);

#endif
