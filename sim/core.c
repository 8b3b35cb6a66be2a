/* sim/core.c -- the functional core: architectural state, memories, and one case per opcode.
 *
 * Owns: executing instructions exactly as isa/opcodes.def's DESC column says, for any N in
 * 1..ISA_MAX_LANES, and counting them per stage and category. Must not: count cycles, model
 * latency or change behaviour with timing (the timing model reads CoreRecord).
 *
 * The program is decoded once in core_new; core_run allocates nothing. The run loop
 * (sim/core_loop.h) keeps what every instruction shares (exec mask, record, counters); its
 * dispatch is isa/opcodes.def expanded into one label per opcode, each calling the family
 * function of its UNIT class, where the opcode's semantics are (see "the semantics" below for why
 * this shape).
 */
#include "core_int.h"

#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

/* ---- traps ----------------------------------------------------------------------------------- */

/* Compose "trap: <reason> at pc N (<instruction>) <file:line>". Always returns 1. */
static int trap(Core *c, const char *fmt, ...)
{
    char reason[384], dis[128], where[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(reason, sizeof reason, fmt, ap);
    va_end(ap);
    if (c->pc < c->ncode) {
        isa_disassemble(&c->code[c->pc].in, 0, dis, sizeof dis);
        asm_object_where(c->obj, c->pc, where, sizeof where);
    } else {
        snprintf(dis, sizeof dis, "no instruction");
        snprintf(where, sizeof where, "%s", c->ncode ? "after the last instruction" : "empty program");
    }
    snprintf(c->trap, sizeof c->trap, "trap: %s at pc %u (%s) %s", reason, c->pc, dis, where);
    return 1;
}

const char *core_trap_message(const Core *c) { return c->trap; }

/* The trap of check(): out of line, so the legal case stays a few instructions. Returns 1. */
static __attribute__((noinline, cold)) int check_trap(Core *c, CoreMem m, uint32_t addr, const char *what)
{
    if (addr & 3u)
        return trap(c, "%s %s misaligned: address 0x%08x", core_mem_long[m], what, addr);
    return trap(c, "%s %s out of range: address 0x%08x (size %u)", core_mem_long[m], what, addr, c->size[m]);
}

/* 0 if a 4-byte access at addr of memory m is legal, else traps and returns 1. */
static inline int check(Core *c, CoreMem m, uint32_t addr, const char *what)
{
    if (__builtin_expect((addr & 3u) == 0 && (int64_t)addr <= c->last[m], 1))
        return 0;
    return check_trap(c, m, addr, what);
}

static inline uint32_t rd32(const Core *c, CoreMem m, uint32_t a)
{
    uint32_t v;
    memcpy(&v, c->mem[m] + a, 4);
    return v;
}

static inline void wr32(Core *c, CoreMem m, uint32_t a, uint32_t v) { memcpy(c->mem[m] + a, &v, 4); }

/* ---- value helpers --------------------------------------------------------------------------- */

static inline float f_of(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static inline uint32_t u_of(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* The ISA's min/max: the second operand is ignored when it is NaN. */
static inline float isa_fmin(float b, float c) { return c < b ? c : b; }
static inline float isa_fmax(float b, float c) { return c > b ? c : b; }

static inline int32_t cvt_f2i(float x)
{
    if (x != x)
        return 0;
    if (x >= 2147483648.0f)
        return INT32_MAX;
    if (x <= -2147483648.0f)
        return INT32_MIN;
    return (int32_t)x;
}

static inline int popcount64(uint64_t x) { return __builtin_popcountll(x); }

/* ---- lane loops ---------------------------------------------------------------------------- */
/* Lanes are processed in blocks of CORE_BLOCK: each block's loop has a constant trip count, which
 * is what GCC's default (-O2, "very cheap") vectorizer needs to turn it into a few SIMD
 * instructions of the host; a loop to a run-time N stays scalar (measured with callgrind: the
 * scalar lane loops were most of the core's host instructions). Lanes from N up to the block's
 * end are computed too but never kept: pure arithmetic, no traps, and the merge below keeps
 * only the exec-mask lanes, which are all below N. Vector registers hold ISA_MAX_LANES lanes, a
 * whole number of blocks. Nothing here changes a lane's arithmetic: each lane's value is the
 * same expression, evaluated once, as before. */
#define CORE_BLOCK 16
_Static_assert(ISA_MAX_LANES % CORE_BLOCK == 0, "vector registers must hold whole blocks");

/* The 32-bit lane selects of lanes [l0, l0 + CORE_BLOCK): all ones where the mask bit is set, so
 * the merge of a block under a mask is an and/or; a per-lane shift of one 32-bit word, which the
 * compiler vectorizes (variable shifts, AVX2 and later). (A constant table of 8-lane rows was
 * tried: the same host instruction count.) */
static inline void block_sel(uint32_t *sel, uint64_t mask, int l0)
{
    const uint32_t bits = (uint32_t)(mask >> l0); /* the block's 16 bits, in 32-bit lanes */
    for (int l = 0; l < CORE_BLOCK; l++)
        sel[l] = 0u - ((bits >> l) & 1u);
}

/* Blocks covering lanes 0..n-1. */
static inline int lane_blocks(int n) { return (n + CORE_BLOCK - 1) / CORE_BLOCK; }

/* The largest of u[l] over the lanes l < n whose mask bit is set (0 if none), a block at a time. */
static inline uint32_t max_lane(const uint32_t *u, uint64_t mask, int n)
{
    uint32_t best[CORE_BLOCK] = {0};
    for (int b = 0; b < lane_blocks(n); b++) {
        uint32_t sel[CORE_BLOCK];
        block_sel(sel, mask, b * CORE_BLOCK);
        for (int l = 0; l < CORE_BLOCK; l++) {
            const uint32_t v = u[b * CORE_BLOCK + l] & sel[l];
            best[l] = v > best[l] ? v : best[l];
        }
    }
    uint32_t m = 0;
    for (int l = 0; l < CORE_BLOCK; l++)
        m = best[l] > m ? best[l] : m;
    return m;
}

/* Lanes [l0, l0 + CORE_BLOCK) of dst become src's where mask bit l is set. */
static inline void block_merge(uint32_t *restrict dst, const uint32_t *restrict src, uint64_t mask, int l0)
{
    uint32_t sel[CORE_BLOCK];
    block_sel(sel, mask, l0);
    for (int l = 0; l < CORE_BLOCK; l++)
        dst[l0 + l] = (src[l] & sel[l]) | (dst[l0 + l] & ~sel[l]);
}

/* Pack 8 bytes that are each 0 or 1 into 8 bits (byte l to bit l): each byte's bit lands in the
 * top byte of the product at a distinct position, so no two partial products collide. */
static inline uint64_t bits_of_bytes8(const uint8_t *b)
{
    uint64_t x;
    memcpy(&x, b, 8);
    return (x * 0x0102040810204080ull) >> 56;
}

/* Compute EXPR (which may use l, B, C, D: the operand registers) for every lane of a block into a
 * temporary, then merge the exec-mask lanes into the destination. FIELD selects u/i/f views. */
#define VOP(OUT, EXPR)                                                                          \
    do {                                                                                        \
        VReg *A_ = &c->v[in->a];                                                                \
        const VReg *B = &c->v[in->b], *C = &c->v[in->c], *D = &c->v[in->d];                     \
        (void)B; (void)C; (void)D;                                                              \
        for (int b_ = 0; b_ < lane_blocks(n); b_++) {                                           \
            VReg t_;                                                                            \
            for (int k_ = 0; k_ < CORE_BLOCK; k_++) {                                           \
                const int l = b_ * CORE_BLOCK + k_;                                             \
                (void)l;                                                                        \
                t_.OUT[k_] = (EXPR);                                                            \
            }                                                                                   \
            if (E == c->all && n - b_ * CORE_BLOCK >= CORE_BLOCK) /* a whole block: inline */ \
                memcpy(A_->u + b_ * CORE_BLOCK, t_.u, sizeof(uint32_t) * CORE_BLOCK);          \
            else if (E == c->all)                                                               \
                memcpy(A_->u + b_ * CORE_BLOCK, t_.u, sizeof(uint32_t) * (size_t)(n - b_ * CORE_BLOCK)); \
            else                                                                                \
                block_merge(A_->u, t_.u, E, b_ * CORE_BLOCK);                                   \
        }                                                                                       \
    } while (0)

/* Compare into mask register a: E & test. */
#define VCMP(TEST)                                                                              \
    do {                                                                                        \
        const VReg *B = &c->v[in->b], *C = &c->v[in->c];                                        \
        uint64_t res_ = 0;                                                                      \
        for (int b_ = 0; b_ < lane_blocks(n); b_++) {                                           \
            uint8_t t_[CORE_BLOCK];                                                             \
            for (int k_ = 0; k_ < CORE_BLOCK; k_++) {                                           \
                const int l = b_ * CORE_BLOCK + k_;                                             \
                (void)l;                                                                        \
                t_[k_] = (TEST) ? 1u : 0u;                                                      \
            }                                                                                   \
            for (int g_ = 0; g_ < CORE_BLOCK / 8; g_++)                                         \
                res_ |= bits_of_bytes8(t_ + 8 * g_) << (b_ * CORE_BLOCK + 8 * g_);              \
        }                                                                                       \
        c->m[in->a] = res_ & E;                                                                 \
    } while (0)

#define SR(i) c->r[i]
#define SF(i) f_of(c->r[i])
#define SETF(i, x) (c->r[i] = u_of(x))
#define IMM (in->imm)

static void record_reset(CoreRecord *rec, uint64_t where, const IsaInstr *in, uint64_t exec)
{
    core_record_start(rec, where);
    rec->in = in;
    rec->exec = exec;
    /* naddr, count and base are 0 here: only the memory families set them, and the run loop puts
     * them back to 0 after such an instruction's hook (and at its start). */
}

static inline void rec_addr(Core *c, int hooked, CoreMem m, uint32_t a)
{
    if (hooked) {
        c->rec.mem = (uint8_t)m;
        if (c->rec.naddr < ISA_MAX_LANES)
            c->rec.addr[c->rec.naddr++] = a;
    }
}

/* A lane loop's addresses: each lane's written at addr[k++] as the loop goes (k a local, so the
 * lanes do not wait on each other through naddr in memory), then the count and memory once. */
static inline void rec_addrs_done(Core *c, int hooked, CoreMem m, int k)
{
    if (hooked && k) {
        c->rec.naddr = (uint8_t)k;
        c->rec.mem = (uint8_t)m;
    }
}

/* a[l] = base + 4 * u[l] for the n lanes; a and u are apart (the record's addresses, a vector
 * register), which the compiler is told so that it vectorizes the loop. */
static inline void lane_addrs(uint32_t *restrict a, const uint32_t *restrict u, uint32_t base, int n)
{
    for (int l = 0; l < n; l++)
        a[l] = base + 4u * u[l];
}

/* a[l] = the word at mem + 4 * u[l] for the n lanes (a gather with every lane in its exec mask:
 * no loop over the mask's bits, whose count the host mispredicts); a and u are apart. */
static inline void gather_lanes(uint32_t *restrict a, const uint8_t *mem, const uint32_t *restrict u, int n)
{
    for (int l = 0; l < n; l++)
        memcpy(&a[l], mem + 4u * u[l], 4);
}

/* The record's addresses of a gather or scatter whose lanes all passed the check: base + 4 * ID
 * for each exec-mask lane, lowest first (what rec_addr per lane gives, in one pass; all N lanes,
 * the usual case, in a loop the compiler vectorizes). */
static inline void rec_lanes(Core *c, CoreMem m, uint32_t base, const VReg *B, uint64_t E, int n)
{
    if (!E)
        return;
    uint32_t *a = c->rec.addr;
    int k = 0;
    if (E == c->all) {
        lane_addrs(a, B->u, base, n);
        k = n;
    } else {
        for (uint64_t e = E; e; e &= e - 1)
            a[k++] = base + 4u * B->u[__builtin_ctzll(e)];
    }
    c->rec.naddr = (uint8_t)k;
    c->rec.mem = (uint8_t)m;
}

/* ---- the partition unit ---------------------------------------------------------------------- */

static int do_part(Core *c, const IsaInstr *in, int hooked)
{
    uint32_t b = SR(in->b), e = SR(in->c);
    if (b > e)
        return trap(c, "partition: bad stream: begin 0x%08x > end 0x%08x", b, e);
    if ((b | e) & 3u)
        return trap(c, "partition: stream bounds 0x%08x..0x%08x not word aligned", b, e);
    if (e > c->size[CORE_MEM_IDM])
        return trap(c, "partition: stream end 0x%08x beyond ID-stream memory (size %u)", e, c->size[CORE_MEM_IDM]);
    uint32_t len = (e - b) / 4;
    if (c->pq_len < len || c->pq_len >= len + (uint32_t)c->n)
        return trap(c, "partition: %u mask bits queued for a stream of %u IDs", c->pq_len, len);
    /* Branch-free (the bits are the rays' data, a branch on each mispredicts): every ID is written
     * at the next place of its side and the place moves on only if it belongs there, so a
     * place is overwritten until an ID of its side takes it; the last write of each pass may fall
     * one past (part_tmp holds one word more than the ID-stream memory). */
    const uint8_t *q = c->pq;
    const uint8_t *ids = c->mem[CORE_MEM_IDM] + b;
    uint32_t *tmp = c->part_tmp, k = 0;
    for (uint32_t i = 0; i < len; i++) {
        uint32_t v;
        memcpy(&v, ids + 4 * (size_t)i, 4);
        tmp[k] = v;
        k += q[i];
    }
    const uint32_t set = k;
    for (uint32_t i = 0; i < len; i++) {
        uint32_t v;
        memcpy(&v, ids + 4 * (size_t)i, 4);
        tmp[k] = v;
        k += 1u - q[i];
    }
    memcpy(c->mem[CORE_MEM_IDM] + b, tmp, 4 * (size_t)len);
    SR(in->a) = b + 4 * set;
    c->pq_len = 0;
    if (hooked) {
        c->rec.mem = CORE_MEM_IDM;
        c->rec.count = len;
        c->rec.base = b;
    }
    return 0;
}

/* ---- the semantics: one family per group of unit classes --------------------------------------- */
/* Each family is a switch over the opcodes of some of isa/opcodes.def's UNIT classes (the
 * machine's functional-unit classes, which the timing model dispatches on too), one line of
 * semantics per opcode where the ISA allows. The run loop (sim/core_loop.h) expands opcodes.def
 * into its dispatch: every row becomes a label that calls its unit's family (CORE_EXEC_<UNIT>)
 * with the opcode as a constant. The families are always_inline, so each call folds to that
 * opcode's case, the code a hand-written interpreter would have for it; a dispatch on the family
 * and then on the opcode would add a second indirect jump per instruction.
 * Because the labels come from the table, every opcode has one; a unit class without a CORE_EXEC_
 * line below fails the build; an opcode its family does not handle reaches the family's default,
 * an internal-error trap that test_isa_programs.c (a program per opcode) hits. */

/* What a family reads and changes besides the architectural state: a local of the run loop, which
 * the inlined families leave to the compiler to keep in registers. */
typedef struct Exec {
    const IsaInstr *in;
    uint64_t E;       /* exec mask as applied */
    int n;            /* lanes */
    uint32_t next;    /* pc after this instruction */
    uint64_t lanes;   /* the lanes counted active for a vector instruction (E; sfetch: the
                         lanes that received an ID), popcounted only when counted */
    int halt;
    int hooked;       /* a timing hook wants the CoreRecord: a constant in each copy of the run loop */
} Exec;

#define ALWAYS_INLINE inline __attribute__((always_inline))

/* An opcode routed to a family that has no case for it (a row added to opcodes.def without
 * semantics). Returns -1. */
static int no_semantics(Core *c, IsaOp op, const char *family)
{
    return -trap(c, "internal error: %s has no semantics in %s", isa_ops[op].mnemonic, family);
}

#define BRANCH_TO(cond)                                                                         \
    do {                                                                                        \
        if (cond) {                                                                             \
            if (IMM > c->ncode)                                                                 \
                return -trap(c, "branch target %u outside the program (%u instructions)", IMM, c->ncode); \
            x->next = IMM;                                                                      \
            if (x->hooked)                                                                      \
                c->rec.taken = 1;                                                               \
        }                                                                                       \
    } while (0)
#define MEMCHK(m, a, what)                                                                      \
    do {                                                                                        \
        if (check(c, (m), (a), (what)))                                                         \
            return -1;                                                                          \
    } while (0)

/* BRANCH: control, branches, statistics markers. */
static ALWAYS_INLINE int exec_control(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    switch (op) {
    case ISA_OP_NOP: break;
    case ISA_OP_HALT: x->halt = 1; break;
    case ISA_OP_SGEN:
        c->gen = (uint8_t)(SR(in->a) < CORE_GENERATIONS ? SR(in->a) : CORE_GENERATIONS - 1);
        core_count_select_row(c);
        break;
    case ISA_OP_STAGE:
        if (IMM >= ISA_STAGE_COUNT)
            return -trap(c, "bad stage %u (0..%d)", IMM, ISA_STAGE_COUNT - 1);
        c->stage = (uint8_t)IMM;
        core_count_select_row(c);
        break;
    case ISA_OP_JMP: BRANCH_TO(1); break;
    case ISA_OP_JAL: {
        uint32_t ret = c->pc + 1;
        BRANCH_TO(1);
        SR(in->a) = ret;
        break;
    }
    case ISA_OP_JR:
        if (SR(in->a) > c->ncode)
            return -trap(c, "jump target %u outside the program (%u instructions)", SR(in->a), c->ncode);
        x->next = SR(in->a);
        if (x->hooked)
            c->rec.taken = 1;
        break;
    case ISA_OP_BEQ: BRANCH_TO(SR(in->a) == SR(in->b)); break;
    case ISA_OP_BNE: BRANCH_TO(SR(in->a) != SR(in->b)); break;
    case ISA_OP_BLT: BRANCH_TO((int32_t)SR(in->a) < (int32_t)SR(in->b)); break;
    case ISA_OP_BGE: BRANCH_TO((int32_t)SR(in->a) >= (int32_t)SR(in->b)); break;
    case ISA_OP_BLTU: BRANCH_TO(SR(in->a) < SR(in->b)); break;
    case ISA_OP_BGEU: BRANCH_TO(SR(in->a) >= SR(in->b)); break;
    case ISA_OP_BMZ: BRANCH_TO((c->m[in->a] & c->all) == 0); break;
    case ISA_OP_BMNZ: BRANCH_TO((c->m[in->a] & c->all) != 0); break;
    default: return no_semantics(c, op, "the control family");
    }
    return 0;
}

/* SALU: scalar integer, uint32_t arithmetic, so overflow wraps without undefined behaviour. */
static ALWAYS_INLINE int exec_scalar_int(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    switch (op) {
    case ISA_OP_LI: SR(in->a) = IMM; break;
    case ISA_OP_MOV: SR(in->a) = SR(in->b); break;
    case ISA_OP_ADD: SR(in->a) = SR(in->b) + SR(in->c); break;
    case ISA_OP_SUB: SR(in->a) = SR(in->b) - SR(in->c); break;
    case ISA_OP_MUL: SR(in->a) = SR(in->b) * SR(in->c); break;
    case ISA_OP_DIVU:
        if (SR(in->c) == 0)
            return -trap(c, "integer division by zero");
        SR(in->a) = SR(in->b) / SR(in->c);
        break;
    case ISA_OP_REMU:
        if (SR(in->c) == 0)
            return -trap(c, "integer division by zero");
        SR(in->a) = SR(in->b) % SR(in->c);
        break;
    case ISA_OP_AND: SR(in->a) = SR(in->b) & SR(in->c); break;
    case ISA_OP_OR: SR(in->a) = SR(in->b) | SR(in->c); break;
    case ISA_OP_XOR: SR(in->a) = SR(in->b) ^ SR(in->c); break;
    case ISA_OP_SHL: SR(in->a) = SR(in->b) << (SR(in->c) & 31u); break;
    case ISA_OP_SHR: SR(in->a) = SR(in->b) >> (SR(in->c) & 31u); break;
    case ISA_OP_SRA: SR(in->a) = (uint32_t)((int32_t)SR(in->b) >> (SR(in->c) & 31u)); break;
    case ISA_OP_SLT: SR(in->a) = (int32_t)SR(in->b) < (int32_t)SR(in->c); break;
    case ISA_OP_SLTU: SR(in->a) = SR(in->b) < SR(in->c); break;
    case ISA_OP_ADDI: SR(in->a) = SR(in->b) + IMM; break;
    case ISA_OP_MULI: SR(in->a) = SR(in->b) * IMM; break;
    case ISA_OP_ANDI: SR(in->a) = SR(in->b) & IMM; break;
    case ISA_OP_ORI: SR(in->a) = SR(in->b) | IMM; break;
    case ISA_OP_XORI: SR(in->a) = SR(in->b) ^ IMM; break;
    case ISA_OP_SHLI: SR(in->a) = SR(in->b) << (IMM & 31u); break;
    case ISA_OP_SHRI: SR(in->a) = SR(in->b) >> (IMM & 31u); break;
    case ISA_OP_SRAI: SR(in->a) = (uint32_t)((int32_t)SR(in->b) >> (IMM & 31u)); break;
    case ISA_OP_SLTI: SR(in->a) = (int32_t)SR(in->b) < (int32_t)IMM; break;
    case ISA_OP_RDN: SR(in->a) = (uint32_t)x->n; break;
    default: return no_semantics(c, op, "the scalar integer family");
    }
    return 0;
}

/* SFPU and SSPEC: scalar float. */
static ALWAYS_INLINE int exec_scalar_float(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    switch (op) {
    case ISA_OP_FADD: SETF(in->a, SF(in->b) + SF(in->c)); break;
    case ISA_OP_FSUB: SETF(in->a, SF(in->b) - SF(in->c)); break;
    case ISA_OP_FMUL: SETF(in->a, SF(in->b) * SF(in->c)); break;
    case ISA_OP_FDIV: SETF(in->a, SF(in->b) / SF(in->c)); break;
    case ISA_OP_FMIN: SETF(in->a, isa_fmin(SF(in->b), SF(in->c))); break;
    case ISA_OP_FMAX: SETF(in->a, isa_fmax(SF(in->b), SF(in->c))); break;
    case ISA_OP_FMA: SETF(in->a, fmaf(SF(in->b), SF(in->c), SF(in->d))); break;
    case ISA_OP_FABS: SR(in->a) = SR(in->b) & 0x7FFFFFFFu; break;
    case ISA_OP_FNEG: SR(in->a) = SR(in->b) ^ 0x80000000u; break;
    case ISA_OP_FSQRT: SETF(in->a, sqrtf(SF(in->b))); break;
    case ISA_OP_FLT: SR(in->a) = SF(in->b) < SF(in->c); break;
    case ISA_OP_FLE: SR(in->a) = SF(in->b) <= SF(in->c); break;
    case ISA_OP_FEQ: SR(in->a) = SF(in->b) == SF(in->c); break;
    case ISA_OP_CVTIF: SETF(in->a, (float)(int32_t)SR(in->b)); break;
    case ISA_OP_CVTFI: SR(in->a) = (uint32_t)cvt_f2i(SF(in->b)); break;
    case ISA_OP_FFLOOR: SETF(in->a, floorf(SF(in->b))); break;
    default: return no_semantics(c, op, "the scalar float family");
    }
    return 0;
}

/* VADD, VMUL, VFMA, VSPEC and VLOGIC: vector arithmetic on float and integer lanes. */
static ALWAYS_INLINE int exec_vector(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    const int n = x->n;
    const uint64_t E = x->E;
    switch (op) {
    /* float */
    case ISA_OP_VFADD: VOP(f, B->f[l] + C->f[l]); break;
    case ISA_OP_VFSUB: VOP(f, B->f[l] - C->f[l]); break;
    case ISA_OP_VFMUL: VOP(f, B->f[l] * C->f[l]); break;
    case ISA_OP_VFDIV: VOP(f, B->f[l] / C->f[l]); break;
    case ISA_OP_VFMIN: VOP(f, isa_fmin(B->f[l], C->f[l])); break;
    case ISA_OP_VFMAX: VOP(f, isa_fmax(B->f[l], C->f[l])); break;
    case ISA_OP_VFMA: VOP(f, fmaf(B->f[l], C->f[l], D->f[l])); break;
    case ISA_OP_VFABS: VOP(u, B->u[l] & 0x7FFFFFFFu); break;
    case ISA_OP_VFNEG: VOP(u, B->u[l] ^ 0x80000000u); break;
    case ISA_OP_VFFLOOR: VOP(f, floorf(B->f[l])); break;
    case ISA_OP_VCVTIF: VOP(f, (float)B->i[l]); break;
    case ISA_OP_VCVTFI: VOP(i, cvt_f2i(B->f[l])); break;
    case ISA_OP_VRCP: VOP(f, 1.0f / B->f[l]); break;
    case ISA_OP_VSQRT: VOP(f, sqrtf(B->f[l])); break;
    case ISA_OP_VRSQRT: VOP(f, 1.0f / sqrtf(B->f[l])); break;
    case ISA_OP_VSIN: VOP(f, sinf(B->f[l])); break;
    case ISA_OP_VCOS: VOP(f, cosf(B->f[l])); break;
    case ISA_OP_VEXP2: VOP(f, exp2f(B->f[l])); break;
    case ISA_OP_VLOG2: VOP(f, log2f(B->f[l])); break;
    /* integer and bit patterns */
    case ISA_OP_VADD: VOP(u, B->u[l] + C->u[l]); break;
    case ISA_OP_VSUB: VOP(u, B->u[l] - C->u[l]); break;
    case ISA_OP_VMUL: VOP(u, B->u[l] * C->u[l]); break;
    case ISA_OP_VAND: VOP(u, B->u[l] & C->u[l]); break;
    case ISA_OP_VOR: VOP(u, B->u[l] | C->u[l]); break;
    case ISA_OP_VXOR: VOP(u, B->u[l] ^ C->u[l]); break;
    case ISA_OP_VSHL: VOP(u, B->u[l] << (C->u[l] & 31u)); break;
    case ISA_OP_VSHR: VOP(u, B->u[l] >> (C->u[l] & 31u)); break;
    case ISA_OP_VSRA: VOP(i, B->i[l] >> (C->u[l] & 31u)); break;
    case ISA_OP_VADDI: VOP(u, B->u[l] + IMM); break;
    case ISA_OP_VMULI: VOP(u, B->u[l] * IMM); break;
    case ISA_OP_VANDI: VOP(u, B->u[l] & IMM); break;
    case ISA_OP_VXORI: VOP(u, B->u[l] ^ IMM); break;
    case ISA_OP_VSHLI: VOP(u, B->u[l] << (IMM & 31u)); break;
    case ISA_OP_VSHRI: VOP(u, B->u[l] >> (IMM & 31u)); break;
    default: return no_semantics(c, op, "the vector family");
    }
    return 0;
}

/* VCMP, VSEL and MASK: compares into masks, moves and select, mask-register logic. */
static ALWAYS_INLINE int exec_mask(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    const int n = x->n;
    const uint64_t E = x->E;
    switch (op) {
    /* compares */
    case ISA_OP_VFLT: VCMP(B->f[l] < C->f[l]); break;
    case ISA_OP_VFLE: VCMP(B->f[l] <= C->f[l]); break;
    case ISA_OP_VFEQ: VCMP(B->f[l] == C->f[l]); break;
    case ISA_OP_VFNE: VCMP(!(B->f[l] == C->f[l])); break;
    case ISA_OP_VIEQ: VCMP(B->u[l] == C->u[l]); break;
    case ISA_OP_VILT: VCMP(B->i[l] < C->i[l]); break;
    case ISA_OP_VILTU: VCMP(B->u[l] < C->u[l]); break;
    /* moves and select */
    case ISA_OP_VSEL: { /* lane l: B where bit l of mask register d is set, else C */
        uint64_t msel = c->m[in->d];
        uint32_t sel[ISA_MAX_LANES];
        for (int b = 0; b < lane_blocks(n); b++)
            block_sel(sel + b * CORE_BLOCK, msel, b * CORE_BLOCK);
        VOP(u, (B->u[l] & sel[l]) | (C->u[l] & ~sel[l]));
        break;
    }
    case ISA_OP_VMOV: VOP(u, B->u[l]); break;
    case ISA_OP_VBCAST: {
        uint32_t v = SR(in->b);
        VOP(u, v);
        break;
    }
    case ISA_OP_VLI: VOP(u, IMM); break;
    case ISA_OP_VIOTA: VOP(u, (uint32_t)l); break;
    case ISA_OP_VEXT:
        if (IMM >= (uint32_t)n)
            return -trap(c, "vext lane %u out of range (N = %d)", IMM, n);
        SR(in->a) = c->v[in->b].u[IMM];
        break;
    /* mask registers */
    case ISA_OP_MAND: c->m[in->a] = c->m[in->b] & c->m[in->c]; break;
    case ISA_OP_MOR: c->m[in->a] = c->m[in->b] | c->m[in->c]; break;
    case ISA_OP_MXOR: c->m[in->a] = c->m[in->b] ^ c->m[in->c]; break;
    case ISA_OP_MANDN: c->m[in->a] = c->m[in->b] & ~c->m[in->c]; break;
    case ISA_OP_MNOT: c->m[in->a] = ~c->m[in->b] & c->all; break;
    case ISA_OP_MMOV: c->m[in->a] = c->m[in->b]; break;
    case ISA_OP_MALL: c->m[in->a] = c->all; break;
    case ISA_OP_MCLR: c->m[in->a] = 0; break;
    case ISA_OP_MTAIL: {
        int32_t k = (int32_t)SR(in->b);
        c->m[in->a] = k <= 0 ? 0 : (k >= n ? c->all : (1ull << k) - 1);
        break;
    }
    case ISA_OP_MPOP: SR(in->a) = (uint32_t)popcount64(c->m[in->b] & c->all); break;
    case ISA_OP_MFIRST: {
        uint64_t m = c->m[in->b] & c->all;
        SR(in->a) = m ? (uint32_t)__builtin_ctzll(m) : 0xFFFFFFFFu;
        break;
    }
    default: return no_semantics(c, op, "the mask family");
    }
    return 0;
}

/* AGU: ID streams (fetch, scalar access, append) and ray-slot allocation. */
static ALWAYS_INLINE int exec_stream(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    const int n = x->n;
    const uint64_t E = x->E;
    switch (op) {
    case ISA_OP_SFETCH: {
        uint32_t b = SR(in->c), e = SR(in->d);
        if (b > e)
            return -trap(c, "bad stream: begin 0x%08x > end 0x%08x", b, e);
        if ((b | e) & 3u)
            return -trap(c, "bad stream: bounds 0x%08x..0x%08x not word aligned", b, e);
        if (e > c->size[CORE_MEM_IDM])
            return -trap(c, "bad stream: end 0x%08x beyond ID-stream memory (size %u)", e, c->size[CORE_MEM_IDM]);
        uint32_t avail = (e - b) / 4, k = avail < (uint32_t)n ? avail : (uint32_t)n;
        VReg *A = &c->v[in->a];
        for (uint32_t l = 0; l < k; l++)
            A->u[l] = rd32(c, CORE_MEM_IDM, b + 4 * l);
        if (x->hooked) {
            for (uint32_t l = 0; l < k; l++)
                c->rec.addr[l] = b + 4 * l;
            rec_addrs_done(c, 1, CORE_MEM_IDM, (int)k);
        }
        if (k > 0)
            for (uint32_t l = k; l < (uint32_t)n; l++)
                A->u[l] = A->u[k - 1];
        c->m[in->b] = k >= 64 ? ~0ull : (1ull << k) - 1;
        SR(in->c) = b + 4 * k;
        /* Utilization counts the lanes that carry a ray: a stream's last, partial vector is the
         * paper's first source of under-utilization (Gribble & Ramani 2008, Sec. 4.1). */
        x->lanes = c->m[in->b];
        if (x->hooked) {
            c->rec.exec = c->m[in->b];
            c->rec.mem = CORE_MEM_IDM;
            c->rec.count = avail;
            c->rec.base = b;
        }
        break;
    }
    case ISA_OP_SLD: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_IDM, a, "load");
        SR(in->a) = rd32(c, CORE_MEM_IDM, a);
        rec_addr(c, x->hooked, CORE_MEM_IDM, a);
        break;
    }
    case ISA_OP_SST: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_IDM, a, "store");
        wr32(c, CORE_MEM_IDM, a, SR(in->a));
        rec_addr(c, x->hooked, CORE_MEM_IDM, a);
        break;
    }
    case ISA_OP_SAPP: {
        uint32_t p = SR(in->a);
        if (x->hooked)
            c->rec.base = p;
        const VReg *B = &c->v[in->b];
        int k = 0;
        for (uint64_t e_ = E; e_; e_ &= e_ - 1) { /* the exec-mask lanes, lowest first */
            const int l = __builtin_ctzll(e_);
            MEMCHK(CORE_MEM_IDM, p, "append");
            wr32(c, CORE_MEM_IDM, p, B->u[l]);
            if (x->hooked)
                c->rec.addr[k++] = p;
            p += 4;
        }
        rec_addrs_done(c, x->hooked, CORE_MEM_IDM, k);
        SR(in->a) = p;
        break;
    }
    case ISA_OP_RALLOC: {
        uint32_t base = SR(in->b), k = 0;
        VReg *A = &c->v[in->a];
        for (int l = 0; l < n; l++)
            if ((E >> l) & 1u)
                A->u[l] = base + k++;
        SR(in->b) = base + k;
        break;
    }
    default: return no_semantics(c, op, "the ID-stream family");
    }
    return 0;
}

/* RBUF and PART: ray-buffer gathers and scatters, the buffer swap, the partition unit. */
static ALWAYS_INLINE int exec_rbuf(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    const int n = x->n;
    const uint64_t E = x->E;
    switch (op) {
    case ISA_OP_RGAT:
    case ISA_OP_RGATN:
    case ISA_OP_RSCT:
    case ISA_OP_RSCTN: {
        int nextbuf = op == ISA_OP_RGATN || op == ISA_OP_RSCTN;
        int store = op == ISA_OP_RSCT || op == ISA_OP_RSCTN;
        CoreMem m = (CoreMem)(CORE_MEM_RB0 + (c->cur_rb ^ nextbuf));
        uint32_t base = SR(in->c) + IMM;
        VReg *A = &c->v[in->a];
        const VReg *B = &c->v[in->b];
        /* base + 4 * ID grows with the ID and has base's alignment, so when the largest ID of the
         * exec-mask lanes gives a legal address every lane's is: the lanes then go without a
         * check each. Otherwise the lanes are checked one by one below, lowest first, and the
         * first illegal one traps as it always did. */
        const uint64_t hi = (uint64_t)base + 4u * (uint64_t)max_lane(B->u, E, n);
        if (__builtin_expect((base & 3u) == 0 && (int64_t)hi <= c->last[m], 1)) {
            uint8_t *mem = c->mem[m] + base;
            if (store)
                for (uint64_t e = E; e; e &= e - 1) {
                    const int l = __builtin_ctzll(e);
                    memcpy(mem + 4u * B->u[l], &A->u[l], 4);
                }
            else if (!x->hooked && E == c->all) /* (in the timed copies measured slower) */
                gather_lanes(A->u, mem, B->u, n);
            else
                for (uint64_t e = E; e; e &= e - 1) {
                    const int l = __builtin_ctzll(e);
                    memcpy(&A->u[l], mem + 4u * B->u[l], 4);
                }
            if (x->hooked)
                rec_lanes(c, m, base, B, E, n);
            break;
        }
        int k = 0;
        for (uint64_t e = E; e; e &= e - 1) { /* the exec-mask lanes, lowest first */
            const int l = __builtin_ctzll(e);
            /* In 64 bits, so a huge ray ID cannot wrap around onto a valid address. */
            uint64_t a64 = (uint64_t)base + 4u * (uint64_t)B->u[l];
            if (a64 > UINT32_MAX)
                return -trap(c, "%s %s out of range: ray ID %u at base 0x%08x (size %u)", core_mem_long[m],
                             store ? "scatter" : "gather", B->u[l], base, c->size[m]);
            uint32_t a = (uint32_t)a64;
            MEMCHK(m, a, store ? "scatter" : "gather");
            if (store)
                wr32(c, m, a, A->u[l]);
            else
                A->u[l] = rd32(c, m, a);
            if (x->hooked)
                c->rec.addr[k++] = a;
        }
        rec_addrs_done(c, x->hooked, m, k);
        break;
    }
    case ISA_OP_RSWAP: c->cur_rb ^= 1; break;
    case ISA_OP_PMASK: {
        if (c->pq_len + (uint32_t)n > c->pq_cap)
            return -trap(c, "partition queue overflow: %u bits queued (capacity %u)", c->pq_len, c->pq_cap);
        uint64_t mk = c->m[in->a];
        uint8_t *q = c->pq + c->pq_len;
        for (int l = 0; l < n; l++)
            q[l] = (uint8_t)((mk >> l) & 1u);
        c->pq_len += (uint32_t)n;
        if (x->hooked)
            c->rec.count = c->pq_len;
        break;
    }
    case ISA_OP_PART:
        if (do_part(c, in, x->hooked))
            return -1;
        break;
    case ISA_OP_PCLR: c->pq_len = 0; break;
    default: return no_semantics(c, op, "the ray-buffer family");
    }
    return 0;
}

/* SPAD, SCENE and FB: scratchpad and scene-memory loads and stores, framebuffer scatter-add. */
static ALWAYS_INLINE int exec_memory(Core *c, Exec *x, IsaOp op)
{
    const IsaInstr *in = x->in;
    const int n = x->n;
    const uint64_t E = x->E;
    switch (op) {
    case ISA_OP_SPLD: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_SPAD, a, "load");
        SR(in->a) = rd32(c, CORE_MEM_SPAD, a);
        rec_addr(c, x->hooked, CORE_MEM_SPAD, a);
        break;
    }
    case ISA_OP_SPST: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_SPAD, a, "store");
        wr32(c, CORE_MEM_SPAD, a, SR(in->a));
        rec_addr(c, x->hooked, CORE_MEM_SPAD, a);
        break;
    }
    case ISA_OP_VSPLD:
    case ISA_OP_VSPST: {
        int store = op == ISA_OP_VSPST;
        uint32_t base = SR(in->b) + IMM;
        VReg *A = &c->v[in->a];
        int k = 0;
        for (uint64_t e_ = E; e_; e_ &= e_ - 1) { /* the exec-mask lanes, lowest first */
            const int l = __builtin_ctzll(e_);
            uint32_t a = base + 4u * (uint32_t)l;
            MEMCHK(CORE_MEM_SPAD, a, store ? "store" : "load");
            if (store)
                wr32(c, CORE_MEM_SPAD, a, A->u[l]);
            else
                A->u[l] = rd32(c, CORE_MEM_SPAD, a);
            if (x->hooked)
                c->rec.addr[k++] = a;
        }
        rec_addrs_done(c, x->hooked, CORE_MEM_SPAD, k);
        break;
    }
    case ISA_OP_LD: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_SCENE, a, "load");
        SR(in->a) = rd32(c, CORE_MEM_SCENE, a);
        rec_addr(c, x->hooked, CORE_MEM_SCENE, a);
        break;
    }
    case ISA_OP_ST: {
        uint32_t a = SR(in->b) + IMM;
        MEMCHK(CORE_MEM_SCENE, a, "store");
        wr32(c, CORE_MEM_SCENE, a, SR(in->a));
        rec_addr(c, x->hooked, CORE_MEM_SCENE, a);
        break;
    }
    case ISA_OP_LDB: {
        uint32_t a = SR(in->b) + IMM;
        if (E) { /* one access serves every lane; no lane, no access */
            MEMCHK(CORE_MEM_SCENE, a, "broadcast load");
            uint32_t v = rd32(c, CORE_MEM_SCENE, a);
            rec_addr(c, x->hooked, CORE_MEM_SCENE, a);
            VOP(u, v);
        }
        break;
    }
    case ISA_OP_LDG: {
        VReg *A = &c->v[in->a];
        const VReg *B = &c->v[in->b];
        int k = 0;
        for (uint64_t e_ = E; e_; e_ &= e_ - 1) { /* the exec-mask lanes, lowest first */
            const int l = __builtin_ctzll(e_);
            uint32_t a = B->u[l] + IMM;
            MEMCHK(CORE_MEM_SCENE, a, "gather");
            A->u[l] = rd32(c, CORE_MEM_SCENE, a);
            if (x->hooked)
                c->rec.addr[k++] = a;
        }
        rec_addrs_done(c, x->hooked, CORE_MEM_SCENE, k);
        break;
    }
    case ISA_OP_FBADD: {
        const VReg *A = &c->v[in->a], *B = &c->v[in->b];
        int k = 0;
        for (uint64_t e_ = E; e_; e_ &= e_ - 1) { /* the exec-mask lanes, lowest first */
            const int l = __builtin_ctzll(e_);
            uint32_t a = B->u[l] + IMM;
            MEMCHK(CORE_MEM_FB, a, "scatter-add");
            wr32(c, CORE_MEM_FB, a, u_of(f_of(rd32(c, CORE_MEM_FB, a)) + A->f[l]));
            if (x->hooked)
                c->rec.addr[k++] = a;
        }
        rec_addrs_done(c, x->hooked, CORE_MEM_FB, k);
        break;
    }
    default: return no_semantics(c, op, "the memory family");
    }
    return 0;
}
#undef BRANCH_TO
#undef MEMCHK

/* The family of each unit class (isa.h: ISA_UNITS). */
#define CORE_EXEC_BRANCH exec_control
#define CORE_EXEC_SALU   exec_scalar_int
#define CORE_EXEC_SFPU   exec_scalar_float
#define CORE_EXEC_SSPEC  exec_scalar_float
#define CORE_EXEC_VADD   exec_vector
#define CORE_EXEC_VMUL   exec_vector
#define CORE_EXEC_VFMA   exec_vector
#define CORE_EXEC_VSPEC  exec_vector
#define CORE_EXEC_VLOGIC exec_vector
#define CORE_EXEC_VCMP   exec_mask
#define CORE_EXEC_VSEL   exec_mask
#define CORE_EXEC_MASK   exec_mask
#define CORE_EXEC_AGU    exec_stream
#define CORE_EXEC_RBUF   exec_rbuf
#define CORE_EXEC_PART   exec_rbuf
#define CORE_EXEC_SPAD   exec_memory
#define CORE_EXEC_SCENE  exec_memory
#define CORE_EXEC_FB     exec_memory

/* ---- execution ----------------------------------------------------------------------------- */

/* The run loop with threaded dispatch (sim/core_loop.h), once per hook state (plain: functional
 * mode; hooked: the timed modes) and lane count (16, the default machine's N, and any N). */
#define CORE_LOOP_NAME run_loop_plain
#define CORE_LOOP_HOOKED 0
#define CORE_LOOP_LANES 0
#include "core_loop.h"
#define CORE_LOOP_NAME run_loop_hooked
#define CORE_LOOP_HOOKED 1
#define CORE_LOOP_LANES 0
#include "core_loop.h"
#define CORE_LOOP_NAME run_loop_plain16
#define CORE_LOOP_HOOKED 0
#define CORE_LOOP_LANES 16
#include "core_loop.h"
#define CORE_LOOP_NAME run_loop_hooked16
#define CORE_LOOP_HOOKED 1
#define CORE_LOOP_LANES 16
#include "core_loop.h"

CoreExit core_run_slice(Core *c, uint64_t max_instr, uint64_t limit)
{
    c->trap[0] = 0;
    if (c->n == 16)
        return c->hook ? run_loop_hooked16(c, max_instr, limit) : run_loop_plain16(c, max_instr, limit);
    return c->hook ? run_loop_hooked(c, max_instr, limit) : run_loop_plain(c, max_instr, limit);
}

uint64_t core_slice_executed(const Core *c, uint64_t max_instr) { return max_instr - c->slice_left; }

CoreExit core_run(Core *c, uint64_t max_instr)
{
    return core_run_slice(c, max_instr, max_instr);
}

