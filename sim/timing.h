/* sim/timing.h -- the cycle-accurate timing model of the stream-filtering machine (detailed mode).
 *
 * Owns: time. It consumes the functional core's CoreRecord stream (timing_attach(t, core)) and
 * schedules each instruction's issue and completion, and each unit's work,
 * as events on a time-ordered queue (sim/event.h); time jumps from event to event. The units,
 * one file each under sim/machine/ (Gribble & Ramani 2008, Sec. 3.3): the in-order single-issue
 * SIMD execution unit with per-class latency and issue interval and a register scoreboard
 * (simd.h); the banked ray buffers, lines, bank conflicts and alignment (raybuf.h); the
 * decoupled address-generation units that fetch ID vectors ahead of the data path (agu.h); the
 * multiplexer interconnect, its latency and the ports the data path, AGUs and partition unit
 * share (interconnect.h); the partition unit (partition.h); the scratchpad ports (spad.h); scene
 * memory with an optional cache (scenemem.h). sim/timing.c keeps the event loop, the stall
 * accounting and the dispatch to the units by the ISA table's UNIT and FLAGS columns, and a memo
 * of blocks of instructions that time the same whatever their data (no memory unit but a scalar
 * scratchpad access): a block whose start state recurs gets its stored outcome instead of being
 * timed again, with the same result (docs/model.md, "Host speed: memoized blocks").
 * Must not: compute any architectural value or change what the program does (the functional
 * core does); results are identical with and without timing.
 *
 * Accounting: every cycle of a run is either busy (an instruction issues in it) or a stall
 * charged to exactly one TmCause, to the stage and the statistics generation of the instruction
 * that waits. cycles = busy + sum of stalls, per stage too (timing_check). The model and the
 * source of each choice: docs/model.md.
 */
#ifndef SFSIM_TIMING_H
#define SFSIM_TIMING_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "core.h"
#include "machine/agu.h"
#include "machine/interconnect.h"
#include "machine/partition.h"
#include "machine/raybuf.h"
#include "machine/scenemem.h"
#include "machine/simd.h"
#include "machine/spad.h"
#include "mem/bus.h"
#include "mem/cache.h"

/* Stall causes (ARCHITECTURE.md Sec. 3), in the order reports list them. */
#define TM_CAUSES(X) \
    X(ADDRESS_FETCH,   "address_fetch",   "the data path waits for an ID vector the AGUs have not fetched yet") \
    X(BANK_CONFLICT,   "bank_conflict",   "lanes of one gather/scatter hit different lines of one ray-buffer bank") \
    X(ALIGNMENT,       "alignment",       "an ID vector read or appended off a line boundary is rotated into place") \
    X(INTERCONNECT,    "interconnect",    "no interconnect port is free (data path, AGUs and partition unit share them)") \
    X(FU_BUSY,         "fu_busy",         "the functional unit cannot accept another instruction yet (issue interval)") \
    X(DATA_DEPENDENCY, "data_dependency", "an operand (or the destination) waits for an arithmetic or ray-buffer result") \
    X(PARTITION,       "partition",       "the partition unit is busy, or its result or the IDs it moves are needed") \
    X(SCRATCHPAD,      "scratchpad",      "a vector scratchpad access needs more lines than there are ports") \
    X(SCENE_MEMORY,    "scene_memory",    "scene-memory or framebuffer lines: cache port cycles and waits for loaded data") \
    X(CONTROL,         "control",         "the bubble after a taken branch, jump, call or return")

typedef enum TmCause {
#define TM_CAUSE_ENUM(name, key, desc) TM_##name,
    TM_CAUSES(TM_CAUSE_ENUM)
#undef TM_CAUSE_ENUM
    TM_CAUSE_COUNT
} TmCause;

extern const char *const tm_cause_keys[TM_CAUSE_COUNT];
extern const char *const tm_cause_descs[TM_CAUSE_COUNT];

typedef struct TimingParams {  /* each unit's part (machine/units.def), filled from the config */
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) Params field;
#include "machine/units.def"
#undef TM_UNIT
} TimingParams;

void timing_params(const CfgMachine *cfg, TimingParams *p);

typedef struct TimingStats {
    uint64_t cycles, busy;
    uint64_t stalls[TM_CAUSE_COUNT];
    uint64_t stage_cycles[ISA_STAGE_COUNT], stage_busy[ISA_STAGE_COUNT];
    uint64_t stage_vec_busy[ISA_STAGE_COUNT];               /* issue cycles of vector instructions */
    uint64_t stage_stalls[ISA_STAGE_COUNT][TM_CAUSE_COUNT];
    uint64_t gen_cycles[CORE_GENERATIONS], gen_busy[CORE_GENERATIONS];
    uint64_t gen_stalls[CORE_GENERATIONS][TM_CAUSE_COUNT];
    uint64_t runs;                                          /* programs timed (passes of tiles; trace batches) */
    /* A chip's core: of the scene_memory stall cycles, those spent waiting for lines the shared L2
     * supplied, and for lines from DRAM (the rest: the L1's own, its ports and hits). */
    uint64_t scene_from[2];
    /* each unit's counters, under its field name (machine/units.def) */
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) Stats field;
#include "machine/units.def"
#undef TM_UNIT
} TimingStats;

typedef struct Timing Timing;

Timing *timing_new(const TimingParams *p, char *err, size_t errlen);
void timing_free(Timing *t);
/* A cold machine for the next program run (empty queues, idle units, empty cache, time 0);
 * statistics keep accumulating. */
void timing_reset(Timing *t);
/* The next program run on the same core from the cycle the last one ended in (a chip's core,
 * docs/chip.md): the same program; cold: its units idle and its L1 empty as after timing_reset,
 * else everything as the last run left it. The cycles of the run count from there. */
void timing_continue(Timing *t, int cold);
/* Where the core's framebuffer starts in the framebuffer's physical space (a chip: its tile's
 * place in the frame's framebuffer, so that two tiles' lines never meet below the L1s). */
void timing_set_fb_base(Timing *t, uint64_t base);
/* A sampled chip's functional warming of the core's L1 (docs/sampling.md, "Sampling a chip"),
 * after the reset and before the run: the first fb_bytes of the core's framebuffer (at its
 * fb_base; dirty, as the unit's earlier passes left them), then the n scene lines (oldest first),
 * each as cache_warm brings it in. 0, or -1 out of memory (the model's error set). */
int timing_warm_l1(Timing *t, const uint64_t *lines, size_t n, uint64_t fb_bytes);
/* The cycle the next instruction may issue in. */
uint64_t timing_now(const Timing *t);

/* ---- a chip's core (docs/chip.md, sim/timing/pend.c) ----
 * The L1's misses and write-backs leave through out(ctx, line address, write, cycle, fill): a read
 * names its fill (a write UINT32_MAX), whose answer the chip gives back with timing_answer. Until
 * then the data are pending: an instruction that needs them yields (the core stops with
 * CORE_EXIT_YIELD, timing_yielded), and is timed with timing_resume once timing_blocked says its
 * answers are in. 0; -1 on out of memory. */
typedef void (*TimingOut)(void *ctx, uint64_t addr, int write, uint64_t cycle, uint32_t fill);
int timing_chip(Timing *t, TimingOut out, void *ctx);
/* from: where the line came from, TIMING_FROM_L2 or TIMING_FROM_DRAM (TimingStats.scene_from). */
enum { TIMING_FROM_L2 = 0, TIMING_FROM_DRAM = 1 };
void timing_answer(Timing *t, uint32_t fill, uint64_t cycle, int from);
int timing_yielded(const Timing *t);
/* Whether rec, the record the core yielded at, still waits for an answer. */
int timing_blocked(Timing *t, const CoreRecord *rec);
void timing_resume(Timing *t, const CoreRecord *rec);
/* Every request the L1 sends below (misses' reads, write-backs, and with no cache every access)
 * is given to tap as it leaves, before the level below takes it: `sfsim run --mem-trace`. Install
 * after timing_chip. */
typedef void (*TimingTap)(void *ctx, uint64_t addr, int write, uint64_t cycle);
void timing_tap(Timing *t, TimingTap tap, void *ctx);
/* Fills sent and not answered yet. */
uint32_t timing_fills_out(const Timing *t);

/* ---- watching the model: a timeline (sim/timeline.h, docs/timeline.md) ----
 * While a watch is set the memo is off (every instruction is timed as it runs; the same results),
 * and the model tells the watch, as it times each instruction: every stall it charges (cause; from:
 * -1, or TIMING_FROM_L2 / TIMING_FROM_DRAM for a scene_memory wait a shared level answers), then
 * the instruction (the cycle it began waiting, the cycle it issued, the next issue slot: the
 * charges fill [start, issue) in the order given, then the cycles after issue), and the units'
 * busy spans it starts. Set or cleared between program runs only. */
typedef struct TimingInstr {
    uint32_t pc;
    uint8_t op, stage, gen;
    uint64_t start, issue, end;
    uint64_t ready;            /* its results' cycle (the latest; UINT64_MAX when a shared level
                                  has not answered yet, or it has none: then end) */
} TimingInstr;
#define TIMING_UNITS(X) \
    X(RAYBUF,       "raybuf",       "a gather's or scatter's bank cycles") \
    X(INTERCONNECT, "interconnect", "a data-path transfer on an interconnect port") \
    X(PARTITION,    "partition",    "the partition unit partitioning a stream") \
    X(SCRATCHPAD,   "scratchpad",   "a vector scratchpad access's line cycles") \
    X(L1,           "l1",           "a scene-memory or framebuffer access on the L1's (or bus's) port")
enum {
#define TIMING_UNIT_ENUM(name, key, desc) TIMING_UNIT_##name,
    TIMING_UNITS(TIMING_UNIT_ENUM)
#undef TIMING_UNIT_ENUM
    TIMING_UNIT_COUNT
};
extern const char *const timing_unit_keys[TIMING_UNIT_COUNT];
typedef struct TimingWatch {
    void (*charge)(void *ctx, int cause, int from, uint64_t cycles);
    void (*instr)(void *ctx, const TimingInstr *in);
    void (*unit)(void *ctx, int unit, uint64_t from, uint64_t to);
    /* a request below the L1 answered at once (a bus of its own): [at, done) */
    void (*request)(void *ctx, uint64_t addr, int write, uint64_t at, uint64_t done);
    void *ctx;
} TimingWatch;
/* w (copied), or NULL: no watch, the memo as timing_set_memo left it. Install after timing_tap. */
void timing_watch(Timing *t, const TimingWatch *w);

/* The CoreHook: one executed instruction. */
void timing_hook(void *ctx, const CoreRecord *rec);
/* The hook for the records of opcode op: timing_hook's work specialized to the op's kind of
 * instruction (same results; timing_attach gives each opcode its own). */
CoreHook timing_op_hook(int op);
/* t's CoreFollow, for a core whose hook calls timing_hook (core_set_follow after core_set_hook). */
CoreFollow *timing_follow(Timing *t);
/* Hooks c to t: timing_hook, and t's CoreFollow, so that c counts the records of a replayed block
 * itself instead of calling the hook for each (the same results with fewer calls; a core given
 * only the hook, core_set_hook(c, timing_hook, t), gives t every record). Inline here, so that
 * the timing model itself calls nothing of the core's (tests/fuzz links it without one). */
static inline void timing_attach(Timing *t, Core *c)
{
    core_set_hook(c, timing_hook, t);
    for (int op = 0; op < ISA_OP_COUNT; op++)
        core_set_op_hook(c, op, timing_op_hook(op));
    core_set_follow(c, timing_follow(t));
}
/* A chip's cores run one program on one machine: t uses owner's descriptions and stored blocks
 * from now on (docs/chip.md, "Host speed"), so that a block one core stored another replays, and
 * the cores' memos are one in the host's caches. Only for models run one at a time (the chip's
 * shared memory steps its cores on one host thread). Each model's replays still count in its own
 * statistics (a block holds one model's uncounted replays at a time, folded into it when another
 * replays the block). Both after timing_reset, with the same run, neither reset after
 * (timing_continue only); every model's statistics read (timing_stats) before the owner is freed,
 * the owner freed last. ninstr: the program's instructions. 0, or -1 (refused, or out of memory:
 * nothing shared). */
int timing_share_memo(Timing *t, Timing *owner, uint32_t ninstr);
/* Memoized blocks on (the default) or off: the same results either way (tests/unit/test_timing.c
 * compares them); off only to check that. */
void timing_set_memo(Timing *t, int on);
/* What the memo did since timing_new (host statistics, not the machine's). */
typedef struct TimingMemoCounts {
    uint64_t replays; /* blocks replayed whole */
    uint64_t stores;  /* blocks stored */
    uint64_t left;    /* replays that met a record off their stored path */
    uint64_t retimed; /* records timed again because no other stored way had the path taken */
    uint64_t flipped; /* replays whose last branch went the other way than when stored */
} TimingMemoCounts;
TimingMemoCounts timing_memo_counts(const Timing *t);
/* After core_run: a run that stopped without halt (trap, limit) counts the cycles so far. */
void timing_end(Timing *t);
const TimingStats *timing_stats(const Timing *t);
/* Non-NULL when the model met an impossible state (an internal error, never a user's). */
const char *timing_error(const Timing *t);
/* dst += src. */
void timing_stats_add(TimingStats *dst, const TimingStats *src);
/* cycles = busy + stalls, overall and per stage: 0, or -1 with the numbers in err. */
int timing_check(const TimingStats *s, char *err, size_t errlen);

#endif
