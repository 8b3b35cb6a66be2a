/* sim/core.h -- the functional core: executes sfsim instructions for any lane count N.
 *
 * Owns: architectural state (registers, masks, pc, stage, partition-unit mask queue, the
 * current/next ray-buffer selector) and the simulated memories; per-stage operation counts.
 * Must not: count cycles or model any latency (the timing model consumes CoreRecord).
 *
 * Memories (sizes from the machine config; all byte-addressed, 32-bit word accesses that
 * must be 4-byte aligned): two ray buffers (RB0, RB1; "current" and "next" swap on rswap),
 * ID-stream memory (IDM), scratchpad (SP), scene memory (SM), framebuffer (FB, floats).
 * Any access outside a memory, a misaligned access, a bad stream or partition, a division
 * by zero, a pc outside the program or the instruction limit stops the core with a trap
 * whose message names pc, instruction and source file:line.
 */
#ifndef SFSIM_CORE_H
#define SFSIM_CORE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../asm/object.h"
#include "../isa/isa.h"

typedef enum CoreMem {
    CORE_MEM_RB0, CORE_MEM_RB1, CORE_MEM_IDM, CORE_MEM_SPAD, CORE_MEM_SCENE, CORE_MEM_FB,
    CORE_MEM_COUNT
} CoreMem;

typedef struct CoreParams {
    int lanes;                         /* N, 1..ISA_MAX_LANES */
    uint32_t mem_bytes[CORE_MEM_COUNT]; /* RB0 and RB1 must be equal; each a multiple of 4 */
} CoreParams;

/* CORE_EXIT_YIELD: the hook asked the core to stop after the instruction it was given
 * (CoreFollow.yield: the timing model of a chip's core waits for an answer of the shared memory,
 * docs/chip.md). That instruction has executed; its record stays in the core (core_record) for the
 * hook's owner to take up again, and the next core_run goes on after it (on a halt: the core stays
 * on it, and a core_run runs it again only after core_restart). */
typedef enum CoreExit { CORE_EXIT_HALT = 0, CORE_EXIT_TRAP = 1, CORE_EXIT_LIMIT = 2, CORE_EXIT_YIELD = 3 } CoreExit;

#define CORE_GENERATIONS 64   /* statistics generations kept apart (sgen) */

/* Counters, per statistics stage (IsaStage). */
typedef struct CoreStats {
    uint64_t instructions[ISA_STAGE_COUNT];
    uint64_t ops[ISA_STAGE_COUNT][ISA_C_COUNT];   /* instructions by Table-5 category */
    uint64_t vec_instructions[ISA_STAGE_COUNT];   /* instructions with ISA_FL_VEC */
    uint64_t active_lanes[ISA_STAGE_COUNT];       /* sum of their active lanes: exec-mask lanes, and
                                                     for sfetch the n lanes that received an ID */
    uint64_t by_op[ISA_OP_COUNT];                 /* executions per opcode */
    /* The same per statistics generation (set by sgen; 0 at reset), for utilization per ray
     * generation: instructions, vector instructions and their active lanes. */
    uint64_t gen_instructions[CORE_GENERATIONS][ISA_STAGE_COUNT];
    uint64_t gen_vec_instructions[CORE_GENERATIONS][ISA_STAGE_COUNT];
    uint64_t gen_active_lanes[CORE_GENERATIONS][ISA_STAGE_COUNT];
} CoreStats;

/* Per-instruction record for the timing model (produced only when a hook is set). */
typedef struct CoreRecord {
    uint32_t pc;
    uint8_t stage;          /* IsaStage at execution */
    uint8_t gen;            /* statistics generation (sgen) at execution */
    uint8_t taken;          /* branch taken */
    uint8_t mem;            /* CoreMem touched (physical buffer for ray buffers), or CORE_MEM_COUNT */
    uint32_t next_pc;
    uint8_t naddr;          /* number of valid entries in addr (lanes that accessed memory) */
    const IsaInstr *in;
    uint32_t count;         /* part: stream length in IDs; pmask: bits queued after it; sfetch: IDs
                               left in the stream before it (rd - rc) / 4; else 0 */
    uint32_t base;          /* sfetch: stream pointer rc before it; sapp: ra before it; part: rb */
    uint64_t exec;          /* exec mask as applied (all N lanes for unmasked ops; sfetch: the
                               lanes that received an ID) */
    _Alignas(64) uint32_t addr[ISA_MAX_LANES]; /* byte addresses, lane order (sfetch/vspld: the N
                                                    words); a cache line's alignment, as the core's
                                                    vector registers (sim/core.c) */
} CoreRecord;

typedef void (*CoreHook)(void *ctx, const CoreRecord *rec);

/* A record's pc, stage, generation and taken flag as one number: the pc in the low 32 bits, then
 * the stage, the generation and the flag a byte each, and in the top byte CORE_MEM_COUNT whatever
 * memory the record touched (a program's instruction is named by its pc; the run loop keeps this
 * number, core_record_word's, from the record's start). The timing model compares it at once; the
 * fields sit side by side in this order, with the memory after them, so a compiler can read them
 * in one load. */
static inline uint64_t core_record_where(const CoreRecord *r)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    _Static_assert(offsetof(CoreRecord, stage) == 4 && offsetof(CoreRecord, gen) == 5 &&
                       offsetof(CoreRecord, taken) == 6 && offsetof(CoreRecord, mem) == 7,
                   "core_record_where reads the fields in one load");
    uint64_t w;
    memcpy(&w, r, sizeof w);
    return (w & 0x00ffffffffffffffull) | (uint64_t)CORE_MEM_COUNT << 56;
#else
    return (uint64_t)r->pc | (uint64_t)r->stage << 32 | (uint64_t)r->gen << 40 | (uint64_t)r->taken << 48 |
           (uint64_t)CORE_MEM_COUNT << 56;
#endif
}

/* core_record_where()'s number for a record of pc, stage and generation with no branch taken and
 * no memory touched (CORE_MEM_COUNT). */
static inline uint64_t core_record_word(uint32_t pc, uint8_t stage, uint8_t gen)
{
    return (uint64_t)pc | (uint64_t)stage << 32 | (uint64_t)gen << 40 | (uint64_t)CORE_MEM_COUNT << 56;
}

/* Sets a new record's pc, stage, generation, taken flag (0) and memory (none) to w, a
 * core_record_word, in one store on a little-endian host: a load of the same eight bytes then
 * comes straight from that store (separate byte stores make the host wait for them to reach the
 * cache before such a load). */
static inline void core_record_start(CoreRecord *r, uint64_t w)
{
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    memcpy(r, &w, sizeof w);
#else
    r->pc = (uint32_t)w;
    r->stage = (uint8_t)(w >> 32);
    r->gen = (uint8_t)(w >> 40);
    r->taken = 0;
    r->mem = CORE_MEM_COUNT;
#endif
}

/* A run of records the hook has said it only needs counted (the timing model replaying a stored
 * block: docs/performance.md, "Records a replay only counts"). While the next record's
 * core_record_where() is `where` and its pc is not `last`, the core adds one to `where` instead of
 * calling the hook; any other record goes to the hook as usual. The hook's owner keeps the struct
 * and sets where to CORE_FOLLOW_NONE when no such run is open. */
typedef struct CoreFollow {
    uint64_t where;
    uint32_t last;
    /* Set by the hook: stop after this record (CORE_EXIT_YIELD); the hook's owner clears it. */
    uint8_t yield;
} CoreFollow;
#define CORE_FOLLOW_NONE UINT64_MAX /* matches no record: core_record_where's top byte is CORE_MEM_COUNT */

typedef struct Core Core;

/* Build a core for obj (decoded once here; an undecodable word fails). Memories are zeroed,
 * then the object's DATA and SPAD images are copied to scene memory and scratchpad (error if
 * they do not fit). m0 = all lanes, other masks empty, registers 0, stage other, pc 0.
 * NULL with a message on failure. obj must outlive the core. */
Core *core_new(const CoreParams *p, const AsmObject *obj, char *err, size_t errlen);
void core_free(Core *c);
/* A read-only image of scene memory that cores share instead of each copying it: the bytes in a
 * sealed memfd, which a core maps copy-on-write, so it costs a page fault per page a run reads
 * and a private page per page it writes (only that core sees the write). Without memfd (or with
 * CORE_IMAGE_COPY) the cores copy the bytes. bytes must outlive the image and not change; NULL
 * when out of memory. */
typedef struct CoreImage CoreImage;
enum { CORE_IMAGE_COPY = 1 };     /* flags: never a memfd (the fallback, for tests) */
CoreImage *core_image_new(const void *bytes, uint32_t size, int flags);
void core_image_free(CoreImage *im);
int core_image_shared(const CoreImage *im); /* 1: a memfd the cores map; 0: the cores copy */
/* Scene memory from address 0 as memcpy(scene memory, bytes, size) would leave it, the rest of it
 * unchanged. 0, or -1 (the image does not fit scene memory, or out of memory; the memory may then
 * have lost its first pages). */
int core_load_image(Core *c, const CoreImage *im);
/* Back to the reset state for another run of the same program: registers 0, m0 all lanes,
 * pc 0, stage other, RB0 current, partition queue empty. Memories and statistics are kept
 * (the host rewrites what it needs; statistics keep accumulating). */
void core_restart(Core *c);

/* Run until halt, trap, or max_instr more instructions (0 = no limit). */
CoreExit core_run(Core *c, uint64_t max_instr);
/* core_run for one slice of a longer run: at most max_instr instructions; a CORE_EXIT_LIMIT trap
 * names `limit`, the whole run's limit, in its message. */
CoreExit core_run_slice(Core *c, uint64_t max_instr, uint64_t limit);
/* The instructions the last core_run_slice(c, max_instr, ...) executed (max_instr > 0). */
uint64_t core_slice_executed(const Core *c, uint64_t max_instr);
/* The trap message after CORE_EXIT_TRAP/CORE_EXIT_LIMIT:
 * "trap: <reason> at pc <n> (<disassembly>) <file>:<line>". */
const char *core_trap_message(const Core *c);

void core_set_hook(Core *c, CoreHook hook, void *ctx);
/* After core_set_hook: the records of opcode op go to hook instead (same ctx). A hook owner that
 * times instructions by kind gives each opcode its kind's hook, so that the choice is made once
 * per opcode, at the run loop's own dispatch, not by a branch in the hook on every record. No
 * effect without a hook set, or for an op out of range or a NULL hook. */
void core_set_op_hook(Core *c, int op, CoreHook hook);
/* The hook's CoreFollow (see there), or NULL for none; core_set_hook clears it. */
void core_set_follow(Core *c, CoreFollow *f);
/* The record of the instruction the core last gave its hook (after CORE_EXIT_YIELD: the one the
 * hook stopped at). */
const CoreRecord *core_record(const Core *c);

/* State access (for tests, the CLI and the renderer). */
int core_lanes(const Core *c);
uint32_t core_pc(const Core *c);
uint32_t core_sreg(const Core *c, int r);
void core_set_sreg(Core *c, int r, uint32_t v);
uint32_t core_vreg(const Core *c, int v, int lane);
uint64_t core_mreg(const Core *c, int m);
uint8_t *core_mem(Core *c, CoreMem m, uint32_t *bytes);
int core_current_rb(const Core *c);              /* 0 or 1: which physical buffer is RBc */
const CoreStats *core_stats(Core *c);           /* folds the counters: not for concurrent readers */
uint64_t core_instructions(const Core *c);       /* total executed */

extern const char *const core_mem_names[CORE_MEM_COUNT]; /* "rb0", "rb1", "idm", "spad", "scene", "fb" */

#endif
