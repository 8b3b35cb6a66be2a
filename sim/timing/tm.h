/* sim/timing/tm.h -- the timing model's inside, shared by its files: the model (sim/timing.c:
 * set-up and the statistics; sim/timing/issue.c: hazards, issue, completion, the hooks) and the
 * memo of blocks (sim/timing/memo.c). Nothing outside sim/timing* includes it: the interface is
 * sim/timing.h.
 *
 * Owns: struct Timing and what one instruction is to the model (TmDesc), the events' and kinds'
 * names, and the few steps every part takes (charge a stall, count an issue, push and apply
 * events). Must not: be included by a unit (sim/machine/, sim/mem/) or by anything above the
 * timing model.
 */
#ifndef SFSIM_TIMING_TM_H
#define SFSIM_TIMING_TM_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "../event.h"
#include "../timing.h"


/* Events on the queue: a unit class leaves its issue interval, fetch resumes after a taken
 * branch, the partition unit finishes. A result landing in a register is an event too, but the
 * most frequent one by far: it is kept in the scoreboard's table of ready cycles (simd.h) rather
 * than on the heap, and time jumps to the earliest of the queue's top and the landings the
 * waiting instruction needs (wait_hazards). */
enum { EV_UNIT, EV_FETCH, EV_PART };
/* The bubble after a taken branch (EV_FETCH) is the commonest of these: a block that ends at a
 * taken branch leaves it behind, and at most one is pending (nothing issues during it, so no
 * branch is taken). It is kept as a cycle beside the queue (Timing.fetch_at, while the SIMD unit's
 * fetch_pending), not pushed and popped; everything that reads the pending events (drain,
 * wait_hazards, the memo's keys) takes it as the event it stands for. */

/* The memory instructions that are most of a kernel's, by the ISA table's UNIT and FLAGS, each
 * timed on a straight path of its own (issue_units_complete); the others (AGU, partition unit,
 * a ray-buffer scalar access, a halt) take the general path. */
enum { TK_OTHER, TK_RB_GATHER, TK_RB_SCATTER, TK_SPAD_LOAD, TK_SPAD_STORE, TK_SCENE };
/* Kinds of hook (timing_op_hook), beside those: a plain instruction (TmDesc.plain) and a vector
 * scratchpad access. */
enum { TK_PLAIN = TK_SCENE + 1, TK_SPAD_VEC };
/* The instructions of the memory kinds (TK_RB_*, TK_SPAD_*, TK_SCENE) are neither branches nor
 * halts (the ISA table: tests/unit/test_timing.c checks it), so their paths leave out the tests
 * for a taken branch and for the end of the program (hazard_as, complete_as). */
enum { TM_NO_FLOW = 0 };

/* What the timing core needs of one program instruction, worked out the first time the
 * instruction runs in a run and kept by its pc (describe()): its ISA table row's unit and flags as
 * the few facts the hook branches on, its unit class's latency and issue interval, and its
 * scoreboard registers (simd_operands). All depend only on the instruction and the machine, so
 * the hook does no table walk for an instruction it has seen. */
typedef struct TmDesc {
    uint32_t run;                            /* the run (timing_reset) it was made in: a run's
                                                program is fixed, so pc names its instruction; a
                                                new run works it out again */
    uint8_t op, unit;
    uint8_t is_halt;                         /* ISA_FL_END */
    uint8_t vec;                             /* ISA_FL_VEC: counts toward stage_vec_busy */
    uint8_t mem;                             /* a memory unit: issue_units() when lanes touched memory */
    uint8_t special;                         /* its result time is not latency-after-issue
                                                (result_time()) */
    uint8_t nregs, ndst;
    uint32_t lat;                            /* the unit class's result latency */
    uint32_t issue;                          /* its issue interval when > 1 (else 0: never held) */
    uint8_t plain;                           /* times the same way every time it runs (no
                                                memory unit, fixed result time, not a halt): can
                                                be part of a memoized block */
    uint8_t kind;                            /* TK_*: the memory instructions issue_units_complete
                                                times on a path of their own */
    uint8_t short_block;                     /* a block starting here was shorter than MEMO_MIN
                                                in this run: it is timed as usual, not looked up */
    uint8_t spad;                            /* a scalar scratchpad access: plain, counted by
                                                spad_count_scalar() */
    uint8_t regs[2 * ISA_MAX_OPERANDS + 1];  /* sources, exec mask, destinations */
    uint8_t dsts[ISA_MAX_OPERANDS];
    struct MemoWays *memo;                   /* blocks starting here (kept across runs, each
                                                entry stamped with its run); NULL until one */
} TmDesc;


#include "memo.h"

typedef struct Pend Pend;

/* A sharing model's list of stored blocks it left replays of uncounted (Timing.touched). */
enum { TM_TOUCHED = 512 };

struct Timing {
    EvQueue q;
    uint64_t now;                  /* the cycle the next instruction may issue in */
    uint64_t fetch_at;             /* while simd.fetch_pending: the cycle the bubble ends (EV_FETCH) */
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) Type field;
#include "../machine/units.def" /* the units, each with its parameters, state and counters */
#undef TM_UNIT
    TmDesc *desc;                  /* by pc (describe()); grown to the program's size once */
    uint32_t desc_cap;
    uint32_t run;                  /* runs since timing_new, from 1 (TmDesc.run) */
    TmDesc spare;                  /* describe() when the table cannot grow */
    /* Memoized blocks (see MemoEntry): off when memo_off. */
    int memo_off;
    TimingMemoCounts mc;           /* timing_memo_counts */
    int mmode;                     /* MM_NONE, MM_RECORD (timing a block as usual, noting its
                                      outcome) or MM_REPLAY (following a stored block) */
    uint64_t m_t0;                 /* the block's start cycle */
    uint8_t m_stage, m_gen;
    CoreFollow follow;             /* replay (else where = CORE_FOLLOW_NONE): where, the next
                                      record on the path as core_record_where() gives it with no
                                      branch taken: its pc (the records matched so far: that pc -
                                      m_pc0), the block's stage and generation; last, the pc of
                                      the block's last record. A core given it (timing_follow)
                                      counts the records inside the block itself */
    MemoEntry *m_e;                /* replay: the stored block */
    uint32_t m_pc0;                /* the block's first instruction (its MemoWays): a pc, not a
                                      pointer, since the table may grow during the block */
    MemoEntry m_rec;               /* record: the block being noted */
    int m_ok;                      /* record: it still fits an entry */
    int m_xfree;                   /* record: xbar_dp_free at the block's start (a gather may join) */
    const IsaInstr *m_g0;          /* record: the block's first record when a gather, else NULL */
    uint32_t m_glines;             /* replay of a block with gathers: the first one's lines */
    size_t m_sway;                 /* replay or record of a block of scene loads: their way */
    uint64_t m_written[2], m_seen[2]; /* record: registers written, live-ins noted */
    uint64_t m_stalls0[MEMO_CHARGE_SLOTS]; /* record: tm_slot at the block's start */
    uint32_t m_bound[MEMO_REGS];   /* record: each live-in's first check, relative to m_t0 */
    /* Issue cycles by stage, statistics generation and vector flag: one count per instruction;
     * timing_stats() folds them into TimingStats' busy counters and the cycles per stage and
     * generation (busy + stalls). */
    uint64_t issues[ISA_STAGE_COUNT][CORE_GENERATIONS][2];
    int halted;
    uint64_t base;                 /* the cycle the program run started in (timing_continue) */
    MemPort tap_below;             /* timing_tap: the L1's port before the tap, and the tap */
    TimingTap tap;
    void *tap_ctx;
    Pend *pend;                    /* a chip's core: answers that come later (pend.c); else NULL */
    TimingWatch watch;             /* timing_watch: its callbacks, NULL when none */
    int memo_user_off;             /* timing_set_memo(t, 0); memo_off also while watched */
    /* timing_share_memo: the descriptions and stored blocks are another core's (share_owner, or
     * this one's when others use them); the stored blocks' replays this model left uncounted
     * (MemoEntry.lz_n), to be folded into its statistics before another model replays them. */
    Timing *share_owner;
    int memo_shared;
    MemoEntry **touched;
    uint32_t ntouched;
    MemPort watch_below;           /* timing_watch: the L1's port before the watch's */
    char err[256];
    TimingStats st;
};

/* ---- accounting --------------------------------------------------------------------------- */

/* Beside the causes, what a register's wait may be charged to (SimdUnit.rcause) on a chip's core:
 * scene_memory, counted as well in TimingStats.scene_from by where the line came from. The memo
 * notes a block's charges by slot: the causes (scene_memory without those) and these two. */
enum { TM_FROM_L2 = TM_CAUSE_COUNT, TM_FROM_DRAM, TM_CHARGE_SLOTS };
_Static_assert((int)TM_CHARGE_SLOTS == (int)MEMO_CHARGE_SLOTS, "memo.h sizes a block's charges by slot");

/* The watch's part of a charge, of an issue and of a unit's span (sim/timing.c). */
void tm_watch_charge(Timing *t, int slot, uint64_t cycles);
void tm_watch_instr(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, uint64_t end, uint64_t ready);
static inline void tm_watch_unit(Timing *t, int unit, uint64_t from, uint64_t to)
{
    if (__builtin_expect(t->watch.unit != NULL, 0))
        t->watch.unit(t->watch.ctx, unit, from, to);
}

static inline void charge(Timing *t, int cause, uint64_t cycles, int stage, int gen)
{
    if (!cycles)
        return;
    if (__builtin_expect(t->watch.charge != NULL, 0))
        tm_watch_charge(t, cause, cycles);
    if (__builtin_expect(cause >= TM_CAUSE_COUNT, 0)) {
        t->st.scene_from[cause - TM_CAUSE_COUNT] += cycles;
        cause = TM_SCENE_MEMORY;
    }
    t->st.stalls[cause] += cycles;
    t->st.stage_stalls[stage][cause] += cycles;
    t->st.gen_stalls[gen][cause] += cycles;
}

/* What a wait for a scene load's data is charged to: the L1's own scene_memory, or on a chip's
 * core the slot of the level its line's fill came from (Cache.from: 1 the L2, 2 DRAM). */
static inline int tm_from_slot(int from)
{
    return from == 0 ? TM_SCENE_MEMORY : from == 1 ? TM_FROM_L2 : TM_FROM_DRAM;
}

/* A charge slot's cycles so far (see TM_CHARGE_SLOTS). */
static inline uint64_t tm_slot(const TimingStats *s, int slot)
{
    if (slot >= TM_CAUSE_COUNT)
        return s->scene_from[slot - TM_CAUSE_COUNT];
    return slot == TM_SCENE_MEMORY ? s->stalls[slot] - s->scene_from[0] - s->scene_from[1] : s->stalls[slot];
}

/* One issue cycle of the instruction d (the cycles per stage and generation are folded in
 * timing_stats()). */
static inline void count_issue(Timing *t, const TmDesc *d, int stage, int gen)
{
    t->issues[stage][gen][d->vec]++;
    t->simd.st.uses[d->unit]++;
    if (__builtin_expect(d->spad, 0))
        spad_count_scalar(&t->spad, 1);
}

static inline void internal_error(Timing *t, const char *msg)
{
    if (!t->err[0])
        snprintf(t->err, sizeof t->err, "timing model: internal error: %s", msg);
}

/* ---- events ------------------------------------------------------------------------------- */

static inline void push(Timing *t, uint64_t time, int kind, int arg, uint32_t tag, int cause)
{
    if (evq_push(&t->q, time, (uint8_t)kind, (uint16_t)arg, tag, (uint8_t)cause))
        internal_error(t, "out of memory for events");
    if (t->mmode == MM_RECORD)
        memo_pushed(t, time, kind, arg, cause);
}


/* Apply every event due by cycle `at` (the queue's part: sim/timing/issue.c). */
void tm_drain_due(Timing *t, uint64_t at);

static inline void drain(Timing *t, uint64_t at)
{
    if (t->q.n && t->q.h[0].time <= at)
        tm_drain_due(t, at);
    if (t->simd.fetch_pending && t->fetch_at <= at)
        simd_fetch_resumed(&t->simd);
}


/* ---- a chip's core (sim/timing/pend.c) ---------------------------------------------------- */

/* What wait_hazards returns when the instruction yielded (nothing of it timed). */
#define TM_YIELDED UINT64_MAX
/* 1 when one of d's registers waits for an answer of the shared memory: the core is told to
 * yield (CoreFollow.yield) and a recording of a block is dropped. */
int tm_yield_if_pending(Timing *t, const TmDesc *d);
/* d's destinations were given a pending value (a scene load's: the only kind whose result can be
 * one); an answer looks at such registers only. */
void tm_pend_note(Timing *t, const TmDesc *d);
void tm_pend_free(Timing *t);
/* Every fill and group forgotten, ids from 0 again, as a new model's (timing_reset: a unit alone on
 * a chip's levels, whose chip_reset drops what was still in flight, so no answer comes for them). */
void tm_pend_reset(Timing *t);

/* ---- what the memo asks of the model (sim/timing/issue.c) --------------------------------- */

/* One instruction, timed as it runs (any kind). */
void tm_time(Timing *t, const TmDesc *d, const CoreRecord *rec);
/* A gather whose access's bank cycles c are known (0: no lanes), its access counted already. */
void tm_time_gather(Timing *t, const TmDesc *d, const CoreRecord *rec, int c);
/* A scalar scene load that hits the L1's line in `way` (its access counted apart: cache_hits). */
void tm_time_scene_hit(Timing *t, const TmDesc *d, const CoreRecord *rec, size_t way);

#endif
