/* sim/core_int.h -- the functional core's inside, shared by its two files: sim/core.c (executing
 * instructions: the semantics and the run loop) and sim/core_state.c (building a core, its
 * memories and scene images, its counters and accessors). Nothing else includes it: the
 * interface is sim/core.h.
 *
 * Owns: struct Core, a decoded instruction (Dec), the counter rows. Must not: be included outside
 * sim/core*.c.
 */
#ifndef SFSIM_CORE_INT_H
#define SFSIM_CORE_INT_H

#include <stdint.h>

#include "core.h"


/* A vector register, aligned to a cache line (and so is the core: core_new): a vector instruction's
 * lane loops read and write it in 32- or 64-byte pieces, which then never straddle a line or a
 * page. Placed where malloc put the core, a register could cross a page boundary, and functional
 * mode ran 15-40 % slower for it (docs/performance.md, "Where the core's registers lie"). */
typedef union VReg {
    _Alignas(64) uint32_t u[ISA_MAX_LANES];
    int32_t i[ISA_MAX_LANES];
    float f[ISA_MAX_LANES];
} VReg;

#define CORE_MASK_ALL ISA_NUM_MREGS /* the hidden mask register unmasked instructions read */

typedef struct Dec {
    IsaInstr in;
    uint8_t cat;      /* IsaCategory */
    uint8_t vec;      /* ISA_FL_VEC */
    uint8_t emask;    /* the mask register its exec mask is read from: the instruction's for a
                         masked format, else CORE_MASK_ALL */
} Dec;

/* The counters: the run loop adds an execution to its opcode's column (and a vector instruction's
 * active lanes to the last column) of the row of the current statistics stage and generation,
 * which STAGE and SGEN select; CoreStats is folded from the rows when read (core_stats). Two
 * additions per instruction instead of up to eight into CoreStats's arrays. */
#define COUNT_COLS (ISA_OP_COUNT + 1)
#define COUNT_ROWS (ISA_STAGE_COUNT * CORE_GENERATIONS)

struct Core {
    int n;                        /* lanes */
    uint64_t all;                 /* mask of the N lanes */
    uint32_t r[ISA_NUM_SREGS];
    VReg v[ISA_NUM_VREGS];
    uint64_t m[ISA_NUM_MREGS + 1]; /* + CORE_MASK_ALL: always the N lanes, no instruction names it */
    uint32_t pc;
    uint8_t stage;
    uint8_t gen;                  /* statistics generation (sgen) */
    uint64_t rec_hi;              /* core_record_word(0, stage, gen), kept by count_select_row */
    int cur_rb;                   /* physical buffer (0/1) that is RBc */
    uint8_t *mem[CORE_MEM_COUNT];
    uint32_t size[CORE_MEM_COUNT];
    int64_t last[CORE_MEM_COUNT]; /* highest legal word address: size - 4 (negative: none) */
    Dec *code;
    uint32_t ncode;
    const AsmObject *obj;
    uint8_t *pq;                  /* partition unit's mask queue, one byte per bit */
    uint32_t pq_len, pq_cap;
    uint32_t *part_tmp;           /* scratch for the in-place partition */
    CoreStats st;                 /* folded from counts (count_fold) when asked for */
    uint64_t *counts;             /* COUNT_ROWS rows of COUNT_COLS: executions per opcode, then
                                     active lanes, per (stage, generation) */
    uint64_t *row;                /* the current (stage, gen)'s row */
    uint64_t touched[(COUNT_ROWS + 63) / 64]; /* rows that may hold counts not yet folded */
    CoreHook hook;                /* core_set_hook's: non-NULL selects the hooked run loops */
    CoreHook hook_op[ISA_OP_COUNT]; /* the hook each opcode's records go to (core_set_op_hook) */
    void *hook_ctx;
    CoreFollow *follow;           /* the hook's, or &no_follow */
    uint64_t slice_left;          /* the instructions the last run slice had left (core_slice_executed) */
    CoreFollow no_follow;         /* where = CORE_FOLLOW_NONE */
    CoreRecord rec;
    char trap[1024];
};

/* Each memory's name in a trap message ("ray buffer 0", ...). */
extern const char *const core_mem_long[CORE_MEM_COUNT];

/* Point c->row at the current (stage, gen) and mark it as holding counts (sim/core_state.c). */
void core_count_select_row(Core *c);

#endif
