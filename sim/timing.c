/* sim/timing.c -- the timing core: the event loop, the stall accounting and the dispatch to the
 * units (see timing.h; each unit's model is one file in sim/machine/; the model and its sources:
 * docs/model.md).
 *
 * Owns: time (the event queue and the next issue cycle), the order in which hazards are charged,
 * every charge to a stall cause, and which unit an instruction uses, read from the ISA table's
 * UNIT and FLAGS columns (never from opcode names). Must not: hold a unit's parameters, state or
 * cost formula (sim/machine/ does), or compute an architectural value.
 *
 * One instruction record at a time, in program order:
 *   1. hazards that an event clears (taken-branch bubble, scoreboard, unit issue interval,
 *      partition unit busy): while one holds, time jumps to the next event on the queue and the
 *      interval is charged to the cause of the highest-priority hazard still holding;
 *   2. waits on units that work ahead of the data path (the AGU's ID vector, an interconnect
 *      port), charged in segments to the cause of each part of the wait;
 *   3. issue: one busy cycle, plus extra issue cycles the access itself needs (bank conflicts,
 *      alignment, scratchpad and scene-cache ports), each charged to its cause;
 *   4. completion: results become ready after the unit's latency (events), units get busy.
 * A block of instructions that time the same whatever their data (no memory unit but a scalar
 * scratchpad access), whose start state has been seen before, is not worked through again: its
 * stored outcome is applied at its end ("memoized blocks" below; docs/model.md).
 */
#include "timing.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "event.h"

const char *const tm_cause_keys[TM_CAUSE_COUNT] = {
#define TM_KEY(name, key, desc) key,
    TM_CAUSES(TM_KEY)
#undef TM_KEY
};
const char *const tm_cause_descs[TM_CAUSE_COUNT] = {
#define TM_DESC(name, key, desc) desc,
    TM_CAUSES(TM_DESC)
#undef TM_DESC
};

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

/* ---- memoized blocks (declarations; the code is after the hook's parts) ----------------------
 * A block is a run of plain instructions in one stage and statistics generation, up to a taken
 * branch or MEMO_LEN instructions. Its timing is a function of the state at its start: the
 * ready cycles (relative to the start) and causes of the registers it reads or writes before it
 * writes them (its live-ins) and the pending events (relative times, kinds, units), which also
 * stand for the bubble, the units' issue intervals and the partition unit (each is pending
 * exactly while its event is). The first time a start state is seen the block is timed as usual
 * and its outcome stored; when it recurs, the outcome is applied at the block's end and the
 * records in between are only checked against the stored path (docs/performance.md).
 *
 * Two relaxations keep one way good for more starts, each exact:
 *  - a slack live-in: one that had landed by the first hazard check of the instruction that
 *    first names it (rel <= that check's cycle, its slack) is only asked to have landed by then
 *    again. Every check of it then finds it landed, as in the recording (time only grows within
 *    a block), so nothing the block does reads its exact ready cycle or its cause; the others
 *    (which stalled an instruction) must land exactly as far ahead, with the same cause.
 *  - a flipped last branch: a block's last instruction taking its branch the other way than when
 *    stored changes only the taken-branch bubble after the block's end (the same instructions
 *    issued at the same cycles; a block ends at its last record however that branch goes), so
 *    the replay applies the stored outcome with the bubble added or left out (memo_apply).
 * MEMO_LEN and MEMO_WAYS: 32 and 8 against 16 and 4 took 4 % off the conference diffuse batch
 * with both relaxations (docs/performance.md, thirteenth session); 48 or 64 instructions, or 16
 * ways, were slower. 33, not 32: the box test's chunk loop (kernels/filters/traverse.inc) has 32
 * plain instructions after its gathers and its loop branch as the 33rd, which at 32 was left a
 * block of one, timed as usual at every chunk (fourteenth session). */
enum { MEMO_LEN = 40, MEMO_REGS = 40, MEMO_EVENTS = 6, MEMO_WAYS = 8 };
/* A block that starts with a ray-buffer gather (TK_RB_GATHER) may hold more gathers of the same
 * rays: a gather times as a function of the same start state and of its bank cycles (rb_access),
 * provided the data path finds a port free at once from the block's start on (xbar_dp_free: no
 * AGU or partition transfer can start inside a block, so none can take a port from it). The key
 * holds the first gather's cycles (MemoEntry.gc[0]), compared when its record starts the block.
 * A later gather joins only when it reads the same index, base and exec-mask registers, none
 * written since, at an offset a whole number of lines away (the next field of the same rays), with
 * a power-of-two bank count: it then has the first one's cycles and lines whatever the rays
 * (rb_same_as_last's case), so a replay needs no record of it, the core counts it like a plain
 * one, and its access is counted at the block's end (memo_apply) from the first one's lines. So
 * the box test's chunk loop (kernels/filters/traverse.inc: seven gathers, then 33 plain
 * instructions) is one block of 40 a chunk (fifteenth session). */
/* A block that starts with a scalar scene load (ld, ldb) that hits the cache may likewise hold
 * more loads of the same line (the same opcode, base and exec-mask registers, none written since,
 * an offset that stays in the first one's line: the box test's six loads of a node's bounds): the
 * first one's hit is keyed by its place in the line and by when the line's data are there
 * (relative to the start, 0 if by its hit latency), and nothing else touches the cache inside a
 * block, so every later load hits the same way; the core counts them like plain records, and
 * their accesses are counted at the block's end (mem_hits). */
enum { MEMO_NO_LANES = 255 }; /* MemoEntry.gc of a gather with no lanes (no access, no transfer) */
enum { MEMO_SCENE = 254 };    /* MemoEntry.gc of a scene load */

/* What a block's key asks of its first record beyond the start state: a gather's bank cycles
 * (c0, as MemoEntry.gc; 0 for a plain instruction), or for a scene load (c0 MEMO_SCENE) its
 * address's place in its line and when its line's data are there. */
typedef struct MemoFirst {
    int c0;
    uint32_t off, rel;
} MemoFirst;
/* Blocks shorter than this cost more to look up and replay than to time (callgrind): a start
 * that gave one is timed as usual for the rest of the run. */
enum { MEMO_MIN = 2 };
/* Lookups start at the way last found from a start state with the same few bits (memo_sig), one
 * of MEMO_PRED: on the conference diffuse batch, 98 % of replays then match the first way tried,
 * against 87 % when the way last found at the pc was tried first (fourteenth session). */
enum { MEMO_PRED = 8 };

typedef struct MemoEv { uint32_t rel; uint16_t arg; uint8_t kind, cause; } MemoEv;
typedef struct MemoReg { uint32_t rel; uint8_t reg, cause; } MemoReg;

/* A block's path is its first pc (the MemoWays it is stored under) and the len - 1 pcs after it in
 * order: only its last instruction may take a branch. */
typedef struct MemoEntry {
    uint32_t run;                   /* the run it was stored in (0: empty) */
    uint8_t len, nlive, nwrite, nev_in, nev_out, taken_last, nunits;
    uint8_t nlanded;                /* live[0..nlanded): slack live-ins (landed at the start, or
                                       before the first check that reads them); the rest exact */
    uint8_t landed[MEMO_REGS];      /* live[0..nlanded)'s registers, packed for memo_state_match */
    uint16_t slack[MEMO_REGS];      /* live[0..nlanded)'s slack: landed by t0 + slack at a match */
    MemoReg live[MEMO_REGS];        /* key: live-ins at the start (rel 0: landed, cause 0) */
    MemoEv ev_in[MEMO_EVENTS];      /* key: pending events, sorted */
    uint32_t end_rel;               /* outcome: the next issue slot after the block */
    uint32_t hz_rel;                /* the latest of write[] (0: none): the scoreboard's horizon
                                       (the registers it leaves as they are had landed under it) */
    MemoReg write[MEMO_REGS];       /* registers it wrote whose results land after end_rel: last
                                       ready cycle and cause (one landed by the block's end is
                                       left as it is: a landed register's ready cycle and cause
                                       are never read, every test is ready > a cycle >= now, and
                                       its old ready cycle had landed before the block wrote it,
                                       a destination being a hazard too) */
    MemoEv ev_out[MEMO_EVENTS];     /* events it left pending after end_rel */
    uint8_t ncharge;                /* stall causes it charged, with their cycles */
    uint8_t ch_cause[TM_CAUSE_COUNT];
    uint32_t ch_cycles[TM_CAUSE_COUNT];
    uint16_t issues[2];             /* scalar, vector */
    uint16_t nspad;                 /* scalar scratchpad accesses (TmDesc.spad) */
    uint8_t unit[MEMO_LEN], unit_n[MEMO_LEN];
    uint8_t ngath;                  /* gathers in the block (then the key asks xbar_dp_free) */
    uint8_t nicn;                   /* of which with lanes: data-path transfers (counted late) */
    uint8_t gc[MEMO_LEN];           /* by record, a gather's bank cycles (MEMO_NO_LANES: no lanes),
                                       0 for a plain instruction; gc[0] is part of the key, the
                                       others equal it */
    uint32_t dp_s, dp_e;            /* outcome: the last gather's data-path transfer (dp_e 0: none) */
    uint8_t nscene;                 /* scene loads in the block (gc MEMO_SCENE) */
    uint32_t sc_off, sc_rel;        /* key, a scene load first (MemoFirst): its place in its line,
                                       when the line's data are there relative to the start (0: by
                                       its hit latency) */
    /* Replays whose counts (stall charges, issue cycles, unit uses, scalar scratchpad accesses)
     * are not in the statistics yet, all in one stage and generation: memo_fold adds them, when
     * the block is replayed in another stage or generation, before the entry is replaced, and
     * when the statistics are read (timing_stats). A replay then only counts itself. */
    uint32_t lz_n;
    uint8_t lz_stage, lz_gen;
} MemoEntry;

typedef struct MemoWays {
    MemoEntry e[MEMO_WAYS];
    uint8_t next;                   /* the way the next store replaces */
    uint8_t pred[MEMO_PRED];        /* by memo_sig of the start state: the way the last lookup
                                       from such a state found, tried first (then the others in
                                       turn) */
} MemoWays;

enum { MM_NONE, MM_RECORD, MM_REPLAY };

struct Timing {
    EvQueue q;
    uint64_t now;                  /* the cycle the next instruction may issue in */
    uint64_t fetch_at;             /* while simd.fetch_pending: the cycle the bubble ends (EV_FETCH) */
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) Type field;
#include "machine/units.def" /* the units, each with its parameters, state and counters */
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
    uint64_t m_stalls0[TM_CAUSE_COUNT];
    uint32_t m_bound[MEMO_REGS];   /* record: each live-in's first check, relative to m_t0 */
    /* Issue cycles by stage, statistics generation and vector flag: one count per instruction;
     * timing_stats() folds them into TimingStats' busy counters and the cycles per stage and
     * generation (busy + stalls). */
    uint64_t issues[ISA_STAGE_COUNT][CORE_GENERATIONS][2];
    int halted;
    char err[256];
    TimingStats st;
};

void timing_params(const CfgMachine *c, TimingParams *p)
{
    memset(p, 0, sizeof *p);
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) params_fn(c, &p->field);
#include "machine/units.def"
#undef TM_UNIT
}

Timing *timing_new(const TimingParams *p, char *err, size_t errlen)
{
    Timing *t = aligned_alloc(_Alignof(Timing), sizeof *t); /* (its ray buffers' last access is aligned) */
    if (t)
        memset(t, 0, sizeof *t);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    evq_init(&t->q);
    int bad = 0;
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) bad |= prefix##_init(&t->field, &p->field);
#include "machine/units.def"
#undef TM_UNIT
    if (bad) {
        snprintf(err, errlen, "out of memory");
        timing_free(t);
        return NULL;
    }
    /* The ports: the L1's misses go to the paper's bus. */
    cache_connect(&t->l1, bus_port(&t->bus));
    timing_reset(t);
    return t;
}

void timing_free(Timing *t)
{
    if (!t)
        return;
    evq_free(&t->q);
    for (uint32_t i = 0; i < t->desc_cap; i++)
        free(t->desc[i].memo);
    free(t->desc);
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) prefix##_free(&t->field);
#include "machine/units.def"
#undef TM_UNIT
    free(t);
}

static void memo_fold_all(Timing *t);

/* No block being recorded or replayed; a following core (timing_follow) counts no record. */
static void memo_none(Timing *t)
{
    t->mmode = MM_NONE;
    t->follow.where = CORE_FOLLOW_NONE;
}

void timing_reset(Timing *t)
{
    evq_clear(&t->q);
    t->now = 0;
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) prefix##_reset(&t->field);
#include "machine/units.def"
#undef TM_UNIT
    t->halted = 0;
    memo_none(t);
    if (++t->run == 0) { /* wrapped: no entry may look current */
        memo_fold_all(t);
        for (uint32_t i = 0; i < t->desc_cap; i++)
            free(t->desc[i].memo);
        if (t->desc)
            memset(t->desc, 0, sizeof *t->desc * t->desc_cap);
        t->run = 1;
    }
}

const TimingStats *timing_stats(const Timing *t)
{
    memo_fold_all((Timing *)t); /* the replays' counts (MemoEntry.lz_n) */
    TimingStats *s = &((Timing *)t)->st;
    /* Each unit's counters, from the unit. */
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) s->field = t->field.st;
#include "machine/units.def"
#undef TM_UNIT
    /* The busy counters and the cycles per stage and generation, from the issue counts and the
     * stalls charged. */
    s->busy = 0;
    memset(s->gen_busy, 0, sizeof s->gen_busy);
    for (int g = 0; g < ISA_STAGE_COUNT; g++) {
        s->stage_busy[g] = s->stage_vec_busy[g] = 0;
        for (int k = 0; k < CORE_GENERATIONS; k++) {
            uint64_t n = t->issues[g][k][0] + t->issues[g][k][1];
            s->stage_busy[g] += n;
            s->stage_vec_busy[g] += t->issues[g][k][1];
            s->gen_busy[k] += n;
        }
        s->busy += s->stage_busy[g];
        s->stage_cycles[g] = s->stage_busy[g];
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            s->stage_cycles[g] += s->stage_stalls[g][c];
    }
    for (int k = 0; k < CORE_GENERATIONS; k++) {
        s->gen_cycles[k] = s->gen_busy[k];
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            s->gen_cycles[k] += s->gen_stalls[k][c];
    }
    return s;
}

const char *timing_error(const Timing *t)
{
    return t->err[0] ? t->err : NULL;
}

/* ---- accounting --------------------------------------------------------------------------- */

static inline void charge(Timing *t, int cause, uint64_t cycles, int stage, int gen)
{
    if (!cycles)
        return;
    t->st.stalls[cause] += cycles;
    t->st.stage_stalls[stage][cause] += cycles;
    t->st.gen_stalls[gen][cause] += cycles;
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

static void internal_error(Timing *t, const char *msg)
{
    if (!t->err[0])
        snprintf(t->err, sizeof t->err, "timing model: internal error: %s", msg);
}

/* ---- events ------------------------------------------------------------------------------- */

static void memo_pushed(Timing *t, uint64_t time, int kind, int arg, int cause);

static void push(Timing *t, uint64_t time, int kind, int arg, uint32_t tag, int cause)
{
    if (evq_push(&t->q, time, (uint8_t)kind, (uint16_t)arg, tag, (uint8_t)cause))
        internal_error(t, "out of memory for events");
    if (t->mmode == MM_RECORD)
        memo_pushed(t, time, kind, arg, cause);
}

/* Apply every event due by cycle `at`. */
static __attribute__((noinline)) void drain_due(Timing *t, uint64_t at)
{
    const EvEvent *e;
    while ((e = evq_top(&t->q)) && e->time <= at) {
        switch (e->kind) {
        case EV_UNIT: simd_unit_free(&t->simd, e->arg); break;
        case EV_PART: part_done(&t->part); break;
        }
        evq_pop(&t->q);
    }
}

static inline void drain(Timing *t, uint64_t at)
{
    if (t->q.n && t->q.h[0].time <= at)
        drain_due(t, at);
    if (t->simd.fetch_pending && t->fetch_at <= at)
        simd_fetch_resumed(&t->simd);
}

/* A taken branch's bubble, until the cycle until (see EV_FETCH). */
static void fetch_hold(Timing *t, uint64_t until)
{
    t->fetch_at = until;
    if (t->mmode == MM_RECORD)
        memo_pushed(t, until, EV_FETCH, 0, TM_CONTROL);
}

/* ---- 1. hazards that an event clears ------------------------------------------------------ */

/* The hazards after the registers': the unit's issue interval, the partition unit, and for a
 * halt everything in flight (waiting: the cause of a register still waiting, or -1). -1 if none. */
static inline int hazard_units(const Timing *t, const TmDesc *d, const CoreRecord *rec, int waiting, int flow)
{
    if (t->simd.unit_pending[d->unit])
        return TM_FU_BUSY;
    if (t->part.busy && part_blocks(&t->part, &isa_ops[d->op], rec))
        return TM_PARTITION;
    if (flow && d->is_halt) { /* the program ends when every result in flight has landed */
        if (t->part.busy)
            return TM_PARTITION;
        return waiting;
    }
    return -1;
}

/* The highest-priority hazard at cycle at that an event will clear, or -1 (docs/model.md, "Stall
 * causes"): fetch after a taken branch, then the instruction's registers (sources, mask,
 * destinations), then the units (hazard_units). flow: 0 when the instruction is known to be no
 * branch and no halt (a constant at the memory kinds' paths: TM_NO_FLOW), else 1. */
static inline int hazard_as(const Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, int flow)
{
    if (t->simd.fetch_pending)
        return TM_CONTROL;
    int cause = simd_waiting_operand(&t->simd, d->regs, d->nregs, at);
    if (cause >= 0)
        return cause;
    return hazard_units(t, d, rec, flow && d->is_halt ? simd_any_waiting(&t->simd, at) : -1, flow);
}

static inline int hazard(const Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    return hazard_as(t, d, rec, at, 1);
}

/* A hazard (cause) holds at cycle at: jump from event to event while one holds; returns the first
 * cycle free of them. The next event is the queue's top or a register landing the hazards read,
 * whichever is first: between two such events no hazard changes, so each interval goes to one
 * cause. */
static __attribute__((noinline)) uint64_t wait_hazards(Timing *t, const TmDesc *d, const CoreRecord *rec,
                                                       uint64_t at, int cause)
{
    /* The registers first, in one pass, when no taken-branch bubble is pending (the only hazard
     * above them; no event can start one during a wait): while one waits, the interval goes to the
     * first register in order still waiting, which is where the event-to-event walk below would
     * put it too; events between landings only clear the units' hazards, which rank below the
     * registers. So each register that lands past the time reached charges the span up to its
     * landing to its cause, and the events due by then are applied once. A halt waits on every
     * register and takes the walk. */
    if (!t->simd.fetch_pending && !d->is_halt) {
        uint64_t x = at;
        for (int i = 0; i < d->nregs; i++) {
            const uint64_t r = t->simd.ready[d->regs[i]];
            if (r > x) {
                charge(t, t->simd.rcause[d->regs[i]], r - x, rec->stage, rec->gen);
                x = r;
            }
        }
        if (x != at) {
            at = x;
            drain(t, at);
            cause = hazard(t, d, rec, at);
            if (cause < 0)
                return at;
        }
    }
    for (;;) {
        uint64_t next = simd_next_landing(&t->simd, d->regs, d->is_halt ? -1 : d->nregs, at);
        const EvEvent *e = evq_top(&t->q);
        if (e && e->time < next)
            next = e->time;
        if (t->simd.fetch_pending && t->fetch_at < next)
            next = t->fetch_at;
        if (next == UINT64_MAX || next <= at) {
            internal_error(t, "a hazard with no event to clear it");
            break;
        }
        charge(t, cause, next - at, rec->stage, rec->gen);
        at = next;
        drain(t, at);
        cause = hazard(t, d, rec, at);
        if (cause < 0)
            break;
    }
    return at;
}

/* What the timing core branches on for an opcode, from the ISA table's UNIT and FLAGS: the
 * TmDesc fields of that name (describe_fill) and the hook the opcode's records go to
 * (timing_op_hook), both from here. */
typedef struct TmClass {
    uint8_t is_halt, vec, wr, spad, mem, special, plain, kind;
} TmClass;

static TmClass tm_class(int op)
{
    const IsaOpInfo *oi = &isa_ops[op];
    TmClass k;
    k.is_halt = (oi->flags & ISA_FL_END) != 0;
    k.vec = (oi->flags & ISA_FL_VEC) != 0;
    k.wr = (oi->flags & ISA_FL_WRITE) != 0;
    /* A scalar scratchpad access (spld, spst) touches one line: one issue cycle at any port count,
     * a load's data spad.latency after it (spad.h), whatever the address; the partition unit's
     * pmask and pclr have their class's latency. Both time as plain instructions (a scalar access
     * is counted by d->spad). */
    k.spad = oi->unit == ISA_U_SPAD && !k.vec;
    const int spad_vec = oi->unit == ISA_U_SPAD && k.vec;
    const int part_data = oi->unit == ISA_U_PART && (oi->flags & ISA_FL_IDM);
    k.mem = oi->unit == ISA_U_AGU || oi->unit == ISA_U_RBUF || spad_vec || oi->unit == ISA_U_SCENE ||
            oi->unit == ISA_U_FB;
    k.special = oi->unit == ISA_U_AGU || oi->unit == ISA_U_RBUF || spad_vec || part_data;
    k.plain = !k.mem && !k.special && !k.is_halt;
    k.kind = oi->unit == ISA_U_RBUF && k.vec                       ? (k.wr ? TK_RB_SCATTER : TK_RB_GATHER)
             : oi->unit == ISA_U_SPAD                              ? (k.wr ? TK_SPAD_STORE : TK_SPAD_LOAD)
             : oi->unit == ISA_U_SCENE || oi->unit == ISA_U_FB     ? TK_SCENE
                                                                   : TK_OTHER;
    return k;
}

/* Works out d for the instruction at rec->pc (see TmDesc). */
static void describe_fill(Timing *t, TmDesc *d, const CoreRecord *rec)
{
    const IsaOpInfo *oi = &isa_ops[rec->in->op];
    const TmClass c = tm_class(rec->in->op);
    d->op = (uint8_t)rec->in->op;
    d->unit = (uint8_t)oi->unit;
    d->is_halt = c.is_halt;
    d->vec = c.vec;
    const int wr = c.wr;
    d->spad = c.spad;
    d->mem = c.mem;
    d->special = c.special;
    d->plain = c.plain;
    d->kind = c.kind;
    d->short_block = 0;
    d->lat = d->spad && !wr ? (uint32_t)(spad_load_ready(&t->spad, 0)) : (uint32_t)t->simd.p.lat[oi->unit];
    d->issue = t->simd.p.issue[oi->unit] > 1 ? (uint32_t)t->simd.p.issue[oi->unit] : 0;
    int ndst;
    int n = simd_operands(&t->simd, rec->in, d->regs, d->dsts, &ndst);
    /* A register named twice (a source read twice, a destination also read) is checked once, at
     * its first place: the hazard scans ask for the first register in order still waiting, and
     * the second copy always has the first's ready cycle. */
    int k = 0;
    for (int i = 0; i < n; i++) {
        int dup = 0;
        for (int j = 0; j < k; j++)
            dup |= d->regs[j] == d->regs[i];
        if (!dup)
            d->regs[k++] = d->regs[i];
    }
    d->nregs = (uint8_t)k;
    d->ndst = (uint8_t)ndst;
}

/* The description of the instruction at rec->pc: from the table, filled on first use. A failed
 * allocation works it out into t->spare instead (slower, same answer). */
static __attribute__((noinline)) const TmDesc *describe_slow(Timing *t, const CoreRecord *rec)
{
    TmDesc *d;
    if (rec->pc < t->desc_cap) {
        d = &t->desc[rec->pc];
    } else {
        uint32_t cap = t->desc_cap ? t->desc_cap : 256;
        while (cap <= rec->pc && cap < UINT32_MAX / 2)
            cap *= 2;
        TmDesc *g = cap > rec->pc ? realloc(t->desc, sizeof *g * cap) : NULL;
        if (g) {
            memset(g + t->desc_cap, 0, sizeof *g * (cap - t->desc_cap));
            t->desc = g;
            t->desc_cap = cap;
            d = &t->desc[rec->pc];
        } else {
            d = &t->spare;
        }
    }
    describe_fill(t, d, rec);
    d->run = d == &t->spare ? 0 : t->run;
    return d;
}

static inline const TmDesc *describe(Timing *t, const CoreRecord *rec)
{
    if (__builtin_expect(rec->pc < t->desc_cap, 1)) {
        const TmDesc *d = &t->desc[rec->pc];
        if (__builtin_expect(d->run == t->run, 1))
            return d;
    }
    return describe_slow(t, rec);
}

/* ---- 2, 3. the units an instruction uses as it issues ------------------------------------- */

typedef struct Issue {
    uint64_t at;       /* the cycle it issues in */
    uint64_t ext;      /* extra issue cycles its access needs, after at */
    int res_cause;     /* what a wait for its result is charged to */
} Issue;

static inline void extra(Timing *t, Issue *is, int cause, uint64_t cycles, const CoreRecord *rec)
{
    charge(t, cause, cycles, rec->stage, rec->gen);
    is->ext += cycles;
}

/* A data-path transfer of len cycles over the interconnect, asked for at is->at: the wait for a
 * port is charged to interconnect, and the instruction issues when it has one. */
static inline uint64_t dp_transfer(Timing *t, uint64_t at, uint64_t len, int stage, int gen)
{
    uint64_t s = xbar_transfer(&t->xbar, XBAR_DP, at, len, t->now);
    charge(t, TM_INTERCONNECT, s - at, stage, gen);
    return s;
}

/* The waits and extra issue cycles of the memory units, by the ISA table's UNIT and FLAGS. */
static void issue_units(Timing *t, const IsaOpInfo *oi, const CoreRecord *rec, Issue *is)
{
    const uint32_t fl = oi->flags;
    switch (oi->unit) {
    case ISA_U_AGU:
        if (isa_id_fetch(fl)) { /* sfetch: the vector the AGUs fetched ahead, or a fetch now */
            AguWait w;
            uint64_t s = agu_serve(&t->agu, &t->part, &t->xbar, rec->base, rec->naddr, rec->count, is->at, t->now,
                                   &w);
            if (t->xbar.overflow)
                internal_error(t, "too many AGU transfers in flight");
            charge(t, TM_PARTITION, w.partition, rec->stage, rec->gen);
            charge(t, TM_INTERCONNECT, w.interconnect, rec->stage, rec->gen);
            charge(t, TM_ADDRESS_FETCH, w.fetch, rec->stage, rec->gen);
            is->at = s;
        } else if (isa_id_append(fl)) { /* sapp: one cycle on an interconnect port */
            is->at = dp_transfer(t, is->at, 1, rec->stage, rec->gen);
        } else {
            break;
        }
        extra(t, is, TM_ALIGNMENT, rb_align_cycles(&t->rb, rec->base), rec);
        break;
    default: /* ray-buffer gathers and scatters, scratchpad, scene memory and framebuffer: their own
                paths in issue_units_complete (a ray-buffer scalar access has no unit cost) */
        break;
    }
}

/* ---- 4. completion ------------------------------------------------------------------------ */

/* When the instruction's result is ready (last: its last issue cycle; end: the next issue
 * slot), by the ISA table's UNIT and FLAGS; a partition starts its run here. */
static uint64_t result_time(Timing *t, const IsaOpInfo *oi, const CoreRecord *rec, Issue *is, uint64_t last,
                            uint64_t end)
{
    const uint32_t fl = oi->flags;
    switch (oi->unit) {
    case ISA_U_AGU:
        if (isa_id_fetch(fl) || isa_id_append(fl)) /* IDs and stream pointer by the next slot */
            return end;
        if ((fl & ISA_FL_IDM) && !(fl & ISA_FL_WRITE)) /* sld */
            return rb_scalar_ready(&t->rb, last);
        if (!(fl & ISA_FL_IDM)) /* ralloc: an AGU result, not memory data */
            is->res_cause = TM_ADDRESS_FETCH;
        break;
    case ISA_U_PART:
        if (fl & ISA_FL_IDM) { /* part: the unit runs on beside the data path */
            uint64_t e = part_start(&t->part, &t->xbar, rec->base, rec->count, is->at, t->now);
            if (part_hold(&t->part, end))
                push(t, e, EV_PART, 0, 0, TM_PARTITION);
            agu_drop_range(&t->agu, t->part.lo, t->part.hi); /* IDs fetched ahead from there are stale */
            is->res_cause = TM_PARTITION;
            return e;
        }
        break;
    default:
        break;
    }
    return simd_result_ready(&t->simd, oi->unit, is->at);
}

/* ---- one instruction ---------------------------------------------------------------------- */

/* The instruction d issued in cycle at and holds the issue slot until end; its results are ready
 * at ready (a wait for them charged to res_cause): the scoreboard, the unit's issue interval, a
 * taken branch's bubble, and the end of the program at a halt. */
static inline void complete_as(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, uint64_t end,
                               uint64_t ready, int res_cause, int flow)
{
    for (int i = 0; i < d->ndst; i++)
        simd_result(&t->simd, d->dsts[i], ready, res_cause);
    if (d->issue && at + d->issue > end) { /* the class is still inside its issue interval */
        uint64_t until;
        if (simd_hold_unit(&t->simd, d->unit, at, end, &until))
            push(t, until, EV_UNIT, d->unit, 0, TM_FU_BUSY);
    }
    if (flow && __builtin_expect(rec->taken, 0)) {
        uint64_t until;
        if (simd_redirect(&t->simd, end, &until))
            fetch_hold(t, until);
    }
    t->now = end;
    if (flow && __builtin_expect(d->is_halt, 0)) {
        t->st.cycles += end;
        t->st.runs++;
        t->halted = 1;
    }
}

static inline void complete(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, uint64_t end,
                            uint64_t ready, int res_cause)
{
    complete_as(t, d, rec, at, end, ready, res_cause, 1);
}

/* Issue and completion of an instruction that uses a memory unit, or whose result time is not its
 * class's latency (result_time()), free of hazards from cycle at. The usual kinds each have a
 * straight path of their own (the same steps as issue_units and result_time take for them), out
 * of line one by one: each saves only the registers it uses, where one function for all of them
 * saved, and aligned a stack frame for, the largest one's at every call (callgrind: about 26 host
 * instructions a call in the prologue and epilogue). The rest take issue_units_other. */
/* c: the bank cycles of its access (rb_access), 0 when it has no lanes. */
static inline void issue_rb_c(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, int c)
{
    const int stage = rec->stage, gen = rec->gen;
    uint64_t ext = 0; /* extra issue cycles after at */
    if (c) { /* its bank cycles on one interconnect port */
        at = dp_transfer(t, at, (uint64_t)c, stage, gen);
        ext = (uint64_t)c - 1;
        charge(t, TM_BANK_CONFLICT, ext, stage, gen);
    }
    count_issue(t, d, stage, gen);
    complete_as(t, d, rec, at, at + ext + 1,
                d->kind == TK_RB_GATHER ? rb_gather_ready(&t->rb, &t->xbar, at + ext) : at + d->lat, TM_DATA_DEPENDENCY,
                TM_NO_FLOW);
}

static __attribute__((noinline)) void issue_rb(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    issue_rb_c(t, d, rec, at, rec->naddr ? rb_access(&t->rb, rec->addr, rec->naddr) : 0);
}

/* The first cycle from now in which the instruction d is free of hazards (the events due by then
 * applied, the waits charged); flow as hazard_as takes it. */
static inline __attribute__((always_inline)) uint64_t hazards_cleared(Timing *t, const TmDesc *d,
                                                                      const CoreRecord *rec, int flow)
{
    uint64_t at = t->now;
    drain(t, at);
    int cause = hazard_as(t, d, rec, at, flow);
    if (__builtin_expect(cause >= 0, 0))
        at = wait_hazards(t, d, rec, at, cause);
    return at;
}

/* A gather whose access's bank cycles are known (c as issue_rb_c takes it; its access was
 * counted when its record came): time_kind's steps for it, from a record without addresses (a
 * gather's hazards do not read them: part_blocks only asks the ID-stream memory's). */
static void time_gather_c(Timing *t, const TmDesc *d, const CoreRecord *rec, int c)
{
    issue_rb_c(t, d, rec, hazards_cleared(t, d, rec, TM_NO_FLOW), c);
}

/* A scalar scene load that hits the line in `way` (its access counted apart: mem_hits): time_kind's
 * and issue_scene's steps for it, from a record without addresses (a scene load's hazards do not
 * read them). */
static void time_scene_hit(Timing *t, const TmDesc *d, const CoreRecord *rec, size_t way)
{
    const uint64_t at = hazards_cleared(t, d, rec, TM_NO_FLOW);
    const uint64_t r = at + (uint64_t)t->l1.p.hit_latency, line = t->l1.ready[way];
    count_issue(t, d, rec->stage, rec->gen);
    complete_as(t, d, rec, at, at + 1, r > line ? r : line, TM_SCENE_MEMORY, TM_NO_FLOW);
}

static __attribute__((noinline)) void issue_spad(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    const int stage = rec->stage, gen = rec->gen;
    uint64_t ext = 0;
    if (rec->naddr) {
        ext = spad_access(&t->spad, rec->addr, rec->naddr) - 1;
        charge(t, TM_SCRATCHPAD, ext, stage, gen);
    }
    count_issue(t, d, stage, gen);
    complete_as(t, d, rec, at, at + ext + 1, d->kind == TK_SPAD_LOAD ? spad_load_ready(&t->spad, at + ext) : at + d->lat,
                TM_DATA_DEPENDENCY, TM_NO_FLOW);
}

static __attribute__((noinline)) void issue_scene(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    const int stage = rec->stage, gen = rec->gen;
    uint64_t ext = 0, ready = 0;
    int cause = TM_DATA_DEPENDENCY;
    if (rec->naddr) {
        ext = mem_issue(&t->mem, &t->l1, isa_ops[d->op].flags, rec->addr, rec->naddr, at, &ready) - 1;
        if (ready == UINT64_MAX)
            internal_error(t, "out of memory for the scene cache");
        charge(t, TM_SCENE_MEMORY, ext, stage, gen);
        cause = TM_SCENE_MEMORY;
    }
    count_issue(t, d, stage, gen);
    complete_as(t, d, rec, at, at + ext + 1, ready ? ready : at + d->lat, cause, TM_NO_FLOW);
}

static __attribute__((noinline)) void issue_units_other(Timing *t, const TmDesc *d, const CoreRecord *rec,
                                                        uint64_t at)
{
    const IsaOpInfo *oi = &isa_ops[d->op];
    Issue is = {at, 0, TM_DATA_DEPENDENCY};
    if (d->mem && rec->naddr)
        issue_units(t, oi, rec, &is);
    count_issue(t, d, rec->stage, rec->gen);
    const uint64_t last = is.at + is.ext; /* the instruction's last issue cycle */
    const uint64_t end = last + 1;        /* the next instruction's earliest issue cycle */
    const uint64_t ready = d->special ? result_time(t, oi, rec, &is, last, end)
                                      : is.at + d->lat;
    complete(t, d, rec, is.at, end, ready, is.res_cause);
}

static inline void issue_units_complete(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    switch (d->kind) {
    case TK_RB_GATHER:
    case TK_RB_SCATTER: issue_rb(t, d, rec, at); return;
    case TK_SPAD_LOAD:
    case TK_SPAD_STORE: issue_spad(t, d, rec, at); return;
    case TK_SCENE: issue_scene(t, d, rec, at); return;
    default: issue_units_other(t, d, rec, at); return;
    }
}

/* One instruction, timed as it runs. kind: d->kind when the caller knows it as a constant
 * (the hooks by kind: the compiler keeps only that kind's path), or -1 for any instruction. */
static inline __attribute__((always_inline)) void time_kind(Timing *t, const TmDesc *d, const CoreRecord *rec,
                                                            int kind)
{
    const int flow = kind < 0 || kind == TK_PLAIN ? 1 : TM_NO_FLOW; /* (a plain instruction may branch) */
    const uint64_t at = hazards_cleared(t, d, rec, flow);
    switch (kind) {
    case TK_PLAIN: /* neither a memory unit nor a special result time (the common case below) */
        break;
    case TK_RB_GATHER:
    case TK_RB_SCATTER: issue_rb(t, d, rec, at); return; /* a ray-buffer vector access is special */
    case TK_SPAD_VEC: issue_spad(t, d, rec, at); return; /* so is a vector scratchpad access */
    case TK_SCENE:                                       /* a memory unit, its result time usual */
        if (rec->naddr) {
            issue_scene(t, d, rec, at);
            return;
        }
        break;
    default:
        if ((d->mem && rec->naddr) || d->special) {
            issue_units_complete(t, d, rec, at);
            return;
        }
        break;
    }
    /* The common case: one issue cycle, the result after the class's latency. */
    count_issue(t, d, rec->stage, rec->gen);
    complete(t, d, rec, at, at + 1, at + d->lat, TM_DATA_DEPENDENCY);
}

static inline __attribute__((always_inline)) void time_one(Timing *t, const TmDesc *d, const CoreRecord *rec)
{
    time_kind(t, d, rec, -1);
}

/* ---- memoized blocks ---------------------------------------------------------------------- */

static inline int bit_get(const uint64_t *b, int r) { return (int)(b[r >> 6] >> (r & 63) & 1u); }
static inline void bit_set(uint64_t *b, int r) { b[r >> 6] |= 1ull << (r & 63); }

/* The pending events relative to t0, sorted (the heap's order depends on its history): their
 * count, or -1 if more than MEMO_EVENTS. */
static inline __attribute__((always_inline)) int memo_events(const Timing *t, uint64_t t0, MemoEv *ev)
{
    const size_t nq = t->q.n, nf = t->simd.fetch_pending; /* the queue's, then the bubble (EV_FETCH) */
    if (nq + nf > MEMO_EVENTS)
        return -1;
    int n = 0;
    for (size_t i = 0; i < nq + nf; i++) {
        const uint64_t time = i < nq ? t->q.h[i].time : t->fetch_at;
        MemoEv v = {(uint32_t)(time - t0), i < nq ? t->q.h[i].arg : 0, i < nq ? t->q.h[i].kind : (uint8_t)EV_FETCH, 0};
        if (time - t0 > UINT32_MAX)
            return -1;
        int k = n++;
        while (k > 0 && (ev[k - 1].rel > v.rel || (ev[k - 1].rel == v.rel && (ev[k - 1].kind > v.kind ||
                                                   (ev[k - 1].kind == v.kind && ev[k - 1].arg > v.arg))))) {
            ev[k] = ev[k - 1];
            k--;
        }
        ev[k] = v;
    }
    return n;
}

/* A register's state relative to t0, as a key holds it. */
enum { MEMO_FAR = 255 }; /* the cause of a register landing too far ahead to key (never stored) */

static inline MemoReg memo_reg(const Timing *t, int r, uint64_t t0)
{
    uint64_t rd = t->simd.ready[r];
    if (rd <= t0)
        return (MemoReg){0, (uint8_t)r, 0};
    if (rd - t0 > UINT32_MAX) /* a key holds 32 bits: such a state matches nothing stored */
        return (MemoReg){UINT32_MAX, (uint8_t)r, MEMO_FAR};
    return (MemoReg){(uint32_t)(rd - t0), (uint8_t)r, t->simd.rcause[r]};
}

/* Whether the stored block e starts from the state of now ... */
static inline __attribute__((always_inline)) int memo_state_match(const Timing *t, const MemoEntry *e, const MemoEv *ev, int nev)
{
    if (e->run != t->run || e->nev_in != nev)
        return 0;
    for (int i = 0; i < nev; i++)
        if (e->ev_in[i].rel != ev[i].rel || e->ev_in[i].kind != ev[i].kind || e->ev_in[i].arg != ev[i].arg)
            return 0;
    /* memo_reg's value compared in place. A live-in that was in flight must land as far ahead (a
     * distance beyond 32 bits matches no stored rel) with its cause: the few of those tell the
     * ways apart, so they are checked first. The slack ones (stored first) must have landed by
     * their slack after now, which holds for all of them when nothing is in flight (the
     * scoreboard's horizon is past). */
    const uint64_t now = t->now;
    for (int i = e->nlanded; i < e->nlive; i++) {
        const MemoReg *m = &e->live[i];
        const uint64_t rd = t->simd.ready[m->reg];
        if (rd <= now || rd - now != m->rel || t->simd.rcause[m->reg] != m->cause)
            return 0;
    }
    if (t->simd.horizon <= now)
        return 1;
    /* stored by slack, smallest first: one whose slack reaches the horizon has landed by then */
    const uint64_t span = t->simd.horizon - now;
    int late = 0; /* one test at the end: which one is late does not matter */
    for (int i = 0; i < e->nlanded && e->slack[i] < span; i++)
        late |= t->simd.ready[e->landed[i]] > now + e->slack[i];
    return !late;
}

/* ... and whose first record is rec (a block of one instruction ends at its branch taken or not;
 * a longer block's first record took none). */
static inline int memo_match(const Timing *t, const MemoEntry *e, const CoreRecord *rec, const MemoEv *ev, int nev,
                             const MemoFirst *f, int *xfree)
{
    if (rec->taken != (e->len == 1 ? e->taken_last : 0) || e->gc[0] != f->c0 || e->sc_off != f->off ||
        e->sc_rel != f->rel || !memo_state_match(t, e, ev, nev))
        return 0;
    if (e->ngath) { /* the data path free from now on (worked out once a lookup, when first asked) */
        if (*xfree < 0)
            *xfree = xbar_dp_free(&t->xbar, t->now);
        return *xfree;
    }
    return 1;
}

/* The counts of e's replays not yet in the statistics (MemoEntry.lz_n) added to them. */
static __attribute__((noinline)) void memo_fold(Timing *t, MemoEntry *e)
{
    const uint64_t n = e->lz_n;
    const int stage = e->lz_stage, gen = e->lz_gen;
    for (int i = 0; i < e->ncharge; i++)
        charge(t, e->ch_cause[i], n * e->ch_cycles[i], stage, gen);
    t->issues[stage][gen][0] += n * e->issues[0];
    t->issues[stage][gen][1] += n * e->issues[1];
    for (int i = 0; i < e->nunits; i++)
        t->simd.st.uses[e->unit[i]] += n * e->unit_n[i];
    if (e->nspad)
        spad_count_scalar(&t->spad, n * e->nspad);
    t->xbar.st.transfers += n * e->nicn;
    e->lz_n = 0;
}

/* Every stored block's replays into the statistics (memo_fold). */
static void memo_fold_all(Timing *t)
{
    for (uint32_t i = 0; i < t->desc_cap; i++)
        if (t->desc[i].memo)
            for (int w = 0; w < MEMO_WAYS; w++)
                if (t->desc[i].memo->e[w].lz_n)
                    memo_fold(t, &t->desc[i].memo->e[w]);
}

/* The accesses of the gathers or scene loads at e's records [1, to), all after its first (a block
 * holds later ones only of the kind it starts with, gc[0]): they had its outcome, a gather its bank
 * cycles and lines (m_glines, from its access in this replay), a load its hit (way m_sway). */
static void memo_count_later(Timing *t, const MemoEntry *e, uint32_t to)
{
    const int g0 = e->gc[0];
    if (!g0 || g0 == MEMO_NO_LANES)
        return;
    uint64_t n = 0;
    if (to == e->len)
        n = (g0 == MEMO_SCENE ? e->nscene : e->ngath) - 1u;
    else
        for (uint32_t i = 1; i < to; i++)
            n += e->gc[i] != 0;
    if (!n)
        return;
    if (g0 == MEMO_SCENE) {
        cache_hits(&t->l1, t->m_sway, n);
        t->mem.st.instructions += n;
    } else {
        t->rb.st.accesses += n;
        t->rb.st.lines += n * t->m_glines;
        if (g0 > 1)
            t->rb.st.conflicted += n;
    }
}

/* The outcome of the stored block e, applied at once (the block's records have all come); its
 * counts are added later (MemoEntry.lz_n). flip: the block's last branch went the other way than
 * stored: the bubble after a taken branch is left out, or added as complete_as adds it. */
static void memo_apply(Timing *t, MemoEntry *e, int flip)
{
    const uint64_t t0 = t->m_t0, end = t0 + e->end_rel;
    const int stage = t->m_stage, gen = t->m_gen;
    drain(t, end); /* what the next record's drain would apply; the events left come after */
    t->now = end;
    if (__builtin_expect(e->lz_stage != stage || e->lz_gen != gen || e->lz_n == UINT32_MAX, 0)) {
        if (e->lz_n)
            memo_fold(t, e);
        e->lz_stage = (uint8_t)stage;
        e->lz_gen = (uint8_t)gen;
    }
    e->lz_n++;
    for (int i = 0; i < e->nwrite; i++) {
        t->simd.ready[e->write[i].reg] = t0 + e->write[i].rel;
        t->simd.rcause[e->write[i].reg] = e->write[i].cause;
    }
    if (t0 + e->hz_rel > t->simd.horizon)
        t->simd.horizon = t0 + e->hz_rel;
    if (__builtin_expect(e->gc[0] != 0, 0)) { /* its gathers' last transfer, the later accesses */
        if (e->dp_e)
            t->xbar.dp = (XbarIvl){t0 + e->dp_s, t0 + e->dp_e};
        memo_count_later(t, e, e->len);
    }
    for (int i = 0; i < e->nev_out; i++) {
        const MemoEv *v = &e->ev_out[i];
        if (v->kind == EV_FETCH) {
            if (!flip) {
                t->simd.fetch_pending = 1;
                t->fetch_at = t0 + v->rel;
            }
            continue;
        }
        if (v->kind == EV_UNIT)
            t->simd.unit_pending[v->arg] = 1;
        push(t, t0 + v->rel, v->kind, v->arg, 0, v->cause);
    }
    if (__builtin_expect(flip, 0)) {
        t->mc.flipped++;
        uint64_t until;
        if (!e->taken_last && simd_redirect(&t->simd, end, &until))
            t->fetch_at = until;
    }
    memo_none(t);
    t->mc.replays++;
}

static void memo_record_start(Timing *t, const MemoEv *ev, int nev);
static void memo_time_noted(Timing *t, const TmDesc *d, const CoreRecord *rec);
static void memo_pre(Timing *t, const TmDesc *d);
static void memo_post(Timing *t, const TmDesc *d, const CoreRecord *rec, int gc);

/* The replay goes on along the stored block e after rec, a record on its path that took no
 * branch (or e's last): the core is given the next record's place and e's last pc. */
static inline void memo_follow(Timing *t, MemoEntry *e, const CoreRecord *rec)
{
    t->m_e = e;
    t->follow.where = core_record_word(rec->pc + 1, rec->stage, rec->gen);
    t->follow.last = t->m_pc0 + e->len - 1u;
}

/* A replay the core left, or stopped in, after (pc of follow.where) - m_pc0 records: those are
 * timed one by one from the block's start state, which nothing has changed yet; with record,
 * while a recording with the start's pending events ev notes them. */
static void memo_retime(Timing *t, int record, const MemoEv *ev, int nev)
{
    const uint32_t n = (uint32_t)t->follow.where - t->m_pc0;
    const MemoEntry *e = t->m_e; /* its gathers so far had its bank cycles */
    memo_none(t);
    memo_count_later(t, e, n); /* the later accesses so far (the first was counted as it came) */
    if (record) {
        memo_record_start(t, ev, nev);
        t->m_rec.sc_off = e->sc_off; /* the same start: a first scene load's key */
        t->m_rec.sc_rel = e->sc_rel;
    }
    t->mc.retimed += n;
    for (uint32_t i = 0; i < n; i++) {
        CoreRecord r;
        memset(&r, 0, offsetof(CoreRecord, addr));
        r.pc = t->m_pc0 + i;
        r.next_pc = r.pc + 1;
        r.stage = t->m_stage;
        r.gen = t->m_gen;
        r.mem = CORE_MEM_COUNT;
        const TmDesc *d = &t->desc[r.pc]; /* described in this run: the entry's run is this one */
        const int g = e->gc[i];
        if (g == MEMO_SCENE) {
            if (record)
                memo_pre(t, d);
            time_scene_hit(t, d, &r, t->m_sway);
            if (record)
                memo_post(t, d, &r, g);
        } else if (g) {
            if (record)
                memo_pre(t, d);
            time_gather_c(t, d, &r, g == MEMO_NO_LANES ? 0 : g);
            if (record)
                memo_post(t, d, &r, g);
        } else if (record) {
            memo_time_noted(t, d, &r);
        } else {
            time_one(t, d, &r);
        }
    }
}

/* A recording of the block whose start (m_t0, m_pc0, m_stage, m_gen) is now, with the pending
 * events ev. */
static void memo_record_start(Timing *t, const MemoEv *ev, int nev)
{
    MemoEntry *m = &t->m_rec;
    m->len = m->nlive = m->nwrite = m->nev_out = 0;
    m->ngath = m->nicn = m->nscene = 0;
    m->dp_s = m->dp_e = m->sc_off = m->sc_rel = 0;
    t->m_g0 = NULL;
    t->m_xfree = xbar_dp_free(&t->xbar, t->now);
    m->nev_in = (uint8_t)nev;
    memcpy(m->ev_in, ev, sizeof *ev * (size_t)nev);
    t->m_ok = 1;
    t->m_written[0] = t->m_written[1] = t->m_seen[0] = t->m_seen[1] = 0;
    memcpy(t->m_stalls0, t->st.stalls, sizeof t->m_stalls0);
    t->mmode = MM_RECORD;
}

/* A few bits of the state at a block's start that tell a pc's stored ways apart more often than
 * not: the distance to the scoreboard's horizon (results in flight) and the first pending event,
 * relative to now. MemoWays.pred's index: only the order of the lookup, every way tried is still
 * matched whole. */
static inline unsigned memo_sig(const Timing *t, const MemoEv *ev, int nev)
{
    const uint64_t span = t->simd.horizon > t->now ? t->simd.horizon - t->now : 0;
    const unsigned e = nev > 0 ? ev[0].rel * 3u + ev[0].kind : 0u;
    return (unsigned)(span * 5u + e) % MEMO_PRED;
}

/* Starts a block at the plain instruction, gather or scene load d (its first record rec; f: what
 * the key asks of it): a replay when its start state is stored (1: the record is accounted for
 * but for a gather's or load's access, which the caller counts), else a recording (0: time it as
 * usual). */
static __attribute__((noinline)) int memo_begin(Timing *t, TmDesc *d, const CoreRecord *rec, const MemoFirst *f)
{
    drain(t, t->now);
    MemoEv ev[MEMO_EVENTS];
    int nev = memo_events(t, t->now, ev);
    if (nev < 0 || d == &t->spare)
        return 0;
    t->m_t0 = t->now;
    t->m_stage = rec->stage;
    t->m_gen = rec->gen;
    t->m_pc0 = rec->pc; /* d is in the table (not the spare), so desc[pc] stays its entry */
    if (d->memo) {
        uint8_t *pred = &d->memo->pred[memo_sig(t, ev, nev)];
        int xfree = -1;
        for (int k = 0; k < MEMO_WAYS; k++) {
            const int w = (*pred + k) % MEMO_WAYS;
            MemoEntry *e = &d->memo->e[w];
            if (memo_match(t, e, rec, ev, nev, f, &xfree)) {
                *pred = (uint8_t)w;
                memo_follow(t, e, rec); /* rec took no branch unless it is e's last (memo_match) */
                t->mmode = MM_REPLAY;
                if (e->len == 1)
                    memo_apply(t, e, 0);
                return 1;
            }
        }
    }
    memo_record_start(t, ev, nev);
    return 0;
}

/* Recording, before the instruction d is timed: its registers not yet written in the block are
 * live-ins, at their start state (nothing in the block has changed them). */
static void memo_pre(Timing *t, const TmDesc *d)
{
    MemoEntry *m = &t->m_rec;
    if (d == &t->spare) /* not in the table: the block cannot be kept */
        t->m_ok = 0;
    for (int i = 0; i < d->nregs; i++) {
        int r = d->regs[i];
        if (bit_get(t->m_written, r) || bit_get(t->m_seen, r))
            continue;
        bit_set(t->m_seen, r);
        if (m->nlive == MEMO_REGS) {
            t->m_ok = 0;
            continue;
        }
        t->m_bound[m->nlive] = (uint32_t)(t->now - t->m_t0);
        m->live[m->nlive] = memo_reg(t, r, t->m_t0);
        if (m->live[m->nlive++].cause == MEMO_FAR)
            t->m_ok = 0;
    }
}

static void memo_pushed(Timing *t, uint64_t time, int kind, int arg, int cause)
{
    MemoEntry *m = &t->m_rec;
    if (m->nev_out == MEMO_EVENTS || time - t->m_t0 > UINT32_MAX) {
        t->m_ok = 0;
        return;
    }
    m->ev_out[m->nev_out++] = (MemoEv){(uint32_t)(time - t->m_t0), (uint16_t)arg, (uint8_t)kind, (uint8_t)cause};
}

/* The recorded block's end: its outcome into the first instruction's ways. */
static __attribute__((noinline)) void memo_store(Timing *t)
{
    MemoEntry *m = &t->m_rec;
    memo_none(t);
    if (m->len < MEMO_MIN) {
        t->desc[t->m_pc0].short_block = 1;
        return;
    }
    if (!t->m_ok || t->err[0] || t->now - t->m_t0 > UINT32_MAX)
        return;
    m->end_rel = (uint32_t)(t->now - t->m_t0);
    uint64_t stalls = 0;
    m->ncharge = 0;
    for (int c = 0; c < TM_CAUSE_COUNT; c++) {
        uint64_t v = t->st.stalls[c] - t->m_stalls0[c];
        if (v > UINT32_MAX)
            return;
        if (v) {
            m->ch_cause[m->ncharge] = (uint8_t)c;
            m->ch_cycles[m->ncharge++] = (uint32_t)v;
        }
        stalls += v;
    }
    if (stalls + m->len != m->end_rel) /* every cycle of the block is an issue or a stall */
        return;
    m->nwrite = 0;
    m->hz_rel = 0;
    for (int r = 0; r < SIMD_NREGS; r++)
        if (bit_get(t->m_written, r) && t->simd.ready[r] > t->now) { /* landing after the end */
            if (m->nwrite == MEMO_REGS)
                return;
            const uint32_t rel = (uint32_t)(t->simd.ready[r] - t->m_t0);
            m->write[m->nwrite++] = (MemoReg){rel, (uint8_t)r, t->simd.rcause[r]};
            if (rel > m->hz_rel)
                m->hz_rel = rel;
        }
    MemoReg fly[MEMO_REGS]; /* the slack live-ins first, smallest slack first (memo_match) */
    int nfly = 0, nl = 0;
    for (int i = 0; i < m->nlive; i++) {
        const MemoReg r = m->live[i];
        if (r.rel > t->m_bound[i]) {
            fly[nfly++] = r;
            continue;
        }
        const uint16_t sl = t->m_bound[i] > UINT16_MAX ? UINT16_MAX : (uint16_t)t->m_bound[i];
        int j = nl++; /* (j <= i: the slack ones so far only move up over slots already read) */
        for (; j > 0 && m->slack[j - 1] > sl; j--) {
            m->live[j] = m->live[j - 1];
            m->slack[j] = m->slack[j - 1];
        }
        m->live[j] = r;
        m->slack[j] = sl;
    }
    memcpy(m->live + nl, fly, sizeof *fly * (size_t)nfly);
    m->nlanded = (uint8_t)nl;
    for (int i = 0; i < nl; i++)
        m->landed[i] = m->live[i].reg;
    int k = 0; /* only the events still pending after the block's end are left for later */
    for (int i = 0; i < m->nev_out; i++)
        if (m->ev_out[i].rel > m->end_rel)
            m->ev_out[k++] = m->ev_out[i];
    m->nev_out = (uint8_t)k;
    m->issues[0] = m->issues[1] = 0;
    m->nspad = 0;
    m->nunits = 0;
    for (int i = 0; i < m->len; i++) {
        const TmDesc *d = &t->desc[t->m_pc0 + (uint32_t)i];
        m->issues[d->vec]++;
        m->nspad += d->spad;
        int j = 0;
        while (j < m->nunits && m->unit[j] != d->unit)
            j++;
        if (j == m->nunits) {
            m->unit[j] = d->unit;
            m->unit_n[j] = 0;
            m->nunits++;
        }
        m->unit_n[j]++;
    }
    m->run = t->run;
    TmDesc *d0 = &t->desc[t->m_pc0];
    if (!d0->memo && !(d0->memo = calloc(1, sizeof *d0->memo)))
        return; /* no memory: the block is just not kept */
    MemoEntry *old = &d0->memo->e[d0->memo->next];
    if (old->lz_n)
        memo_fold(t, old);
    m->lz_n = 0;
    *old = *m;
    t->mc.stores++;
    d0->memo->next = (uint8_t)((d0->memo->next + 1) % MEMO_WAYS);
}

/* Recording, after the instruction d was timed: its writes, its place in the path; a taken
 * branch or a full path ends the block. */
static void memo_post(Timing *t, const TmDesc *d, const CoreRecord *rec, int gc)
{
    MemoEntry *m = &t->m_rec;
    for (int i = 0; i < d->ndst; i++)
        bit_set(t->m_written, d->dsts[i]);
    if (rec->pc != t->m_pc0 + m->len) /* not the next pc (cannot happen: a block ends at a taken branch) */
        t->m_ok = 0;
    m->gc[m->len] = (uint8_t)gc;
    if (gc == MEMO_SCENE) {
        m->nscene++;
    } else if (gc) { /* a gather (its bank cycles gc): the key holds them */
        if (!t->m_xfree)
            t->m_ok = 0;
        m->ngath++;
        if (gc != MEMO_NO_LANES) {
            m->nicn++;
            m->dp_s = (uint32_t)(t->xbar.dp.s - t->m_t0);
            m->dp_e = (uint32_t)(t->xbar.dp.e - t->m_t0);
        }
    }
    m->len++;
    m->taken_last = rec->taken;
    if (rec->taken || m->len == MEMO_LEN)
        memo_store(t);
}

/* Recording: the instruction timed as usual, its live-ins noted before and its writes after. */
static __attribute__((noinline)) void memo_time_noted(Timing *t, const TmDesc *d, const CoreRecord *rec)
{
    memo_pre(t, d);
    time_one(t, d, rec);
    memo_post(t, d, rec,
              d->kind == TK_SCENE        ? MEMO_SCENE
              : d->kind != TK_RB_GATHER ? 0
              : rec->naddr              ? t->rb.last_cycles /* (rb_access's) */
                                        : MEMO_NO_LANES);
}

/* A replay met rec, a record its stored path does not have (a branch taken where it was not, or
 * not where it was, or another stage or generation), after (pc of follow.where) - m_pc0 records
 * that matched. Nothing has changed the start state yet. If another way stored from the same
 * start state has the path so far and rec next, the replay goes on with it (1: rec accounted
 * for). Else (0) the records so far are timed one by one from the start state while a recording
 * notes them, so the path taken is stored as another way of the same start (rec then goes on as
 * the recording's next record, or ends it); a block that would end before MEMO_MIN records is
 * timed without one. A way that ended just before rec is applied, and rec comes after it (0).
 * A way's last record may take its branch either way (a flipped last branch), as in a replay. */
static __attribute__((noinline)) int memo_diverged(Timing *t, const CoreRecord *rec)
{
    const uint32_t k = (uint32_t)t->follow.where - t->m_pc0; /* rec's place on a path */
    t->mc.left++;
    MemoEv ev[MEMO_EVENTS];
    const int nev = memo_events(t, t->now, ev); /* as at the start: nothing changed */
    MemoWays *mw = t->desc[t->m_pc0].memo;      /* a replay's ways exist */
    const int same = rec->pc == t->m_pc0 + k && rec->stage == t->m_stage && rec->gen == t->m_gen;
    for (int w = 0; w < MEMO_WAYS; w++) {
        MemoEntry *e = &mw->e[w];
        /* (ways with gathers are left out: their bank cycles would have to agree too) */
        if (e == t->m_e || t->m_e->ngath || e->ngath || e->len < k || (e->len > k && !same) ||
            !memo_state_match(t, e, ev, nev))
            continue;
        if (e->len == k) { /* it ended before rec (another generation, say): its last record took
                              no branch here (a flipped last branch if it did when stored) */
            memo_apply(t, e, e->taken_last);
            return 0;     /* rec comes after it */
        }
        if (k + 1u < e->len && rec->taken) /* only a way's last record may take a branch */
            continue;
        memo_follow(t, e, rec);
        if (k + 1u == e->len)
            memo_apply(t, e, rec->taken != e->taken_last);
        return 1;
    }
    /* timed again, and noted unless the block would end before MEMO_MIN records (memo_store) */
    memo_retime(t, nev >= 0 && (same || k >= MEMO_MIN), ev, nev);
    return 0;
}

/* Whether none of d's sources and exec mask (simd_operands' order) was written in the block being
 * recorded so far. */
static int memo_reads_unwritten(const Timing *t, const TmDesc *d)
{
    for (int i = 0; i < d->nregs - d->ndst; i++)
        if (bit_get(t->m_written, d->regs[i]))
            return 0;
    return 1;
}

/* A gather's or scene load's record during a replay, that came to the hook (a following core
 * counts a block's later ones itself): 1 when it is the block's next record, a later one (counted
 * with the block at its end); else 0, after memo_diverged (no stored way has it next: the records
 * so far were timed again). */
static int memo_later(Timing *t, const CoreRecord *rec)
{
    MemoEntry *e = t->m_e;
    const uint32_t k = (uint32_t)t->follow.where - t->m_pc0; /* the block's records so far */
    if (k > 0 && k < e->len && e->gc[k] && core_record_word(rec->pc, rec->stage, rec->gen) == t->follow.where) {
        t->follow.where++;
        if (k + 1u == e->len)
            memo_apply(t, e, 0);
        return 1;
    }
    memo_diverged(t, rec);
    return 0;
}

/* Whether the gather d (instruction in) may join the block being recorded, which started with the
 * gather t->m_g0: see MEMO_LEN's note (the same opcode, index, base and exec-mask registers, none
 * written in the block so far, an offset a whole number of lines away, banks a power of two). */
static int memo_gather_joins(const Timing *t, const TmDesc *d, const IsaInstr *in)
{
    const IsaInstr *g0 = t->m_g0;
    if (!g0 || in->op != g0->op || in->b != g0->b || in->c != g0->c || in->mask != g0->mask ||
        (in->imm - g0->imm) % (uint32_t)t->rb.p.line != 0 || (t->rb.p.banks & (t->rb.p.banks - 1)) != 0)
        return 0;
    return memo_reads_unwritten(t, d);
}

/* A gather's record (TK_RB_GATHER) that came to the hook: 1 when a block took it in (a replay
 * whose next record it is: memo_later; a recording it may join; a block it starts), 0 when it is
 * to be timed alone. */
static __attribute__((noinline)) int memo_gather(Timing *t, TmDesc *d, const CoreRecord *rec)
{
    if (t->mmode == MM_REPLAY && memo_later(t, rec))
        return 1;
    if (t->mmode == MM_RECORD) {
        if (rec->stage == t->m_stage && rec->gen == t->m_gen && memo_gather_joins(t, d, rec->in)) {
            memo_time_noted(t, d, rec);
            return 1;
        }
        memo_store(t); /* the block ended before this gather */
    }
    if (d->short_block || t->memo_off || !xbar_dp_free(&t->xbar, t->now))
        return 0;
    const int c = rec->naddr ? rb_cycles(&t->rb, rec->addr, rec->naddr) : MEMO_NO_LANES; /* (counted below) */
    if (memo_begin(t, d, rec, &(const MemoFirst){c, 0, 0})) {
        if (c != MEMO_NO_LANES) { /* the first gather's access, counted as it comes */
            rb_count(&t->rb, 1);
            t->m_glines = (uint32_t)t->rb.last_lines;
        }
        return 1;
    }
    if (t->mmode == MM_RECORD) {
        t->m_g0 = rec->in;
        memo_time_noted(t, d, rec);
        return 1;
    }
    return 0;
}

/* Whether the scene load d (instruction in, address addr) may join the block being recorded, which
 * started with the scene load t->m_g0: see MEMO_SCENE's note (the same opcode, base and
 * exec-mask registers, none written in the block so far, its address in the first one's line). */
static int memo_scene_joins(const Timing *t, const TmDesc *d, const IsaInstr *in)
{
    const IsaInstr *g0 = t->m_g0;
    if (!g0 || t->m_rec.gc[0] != MEMO_SCENE || in->op != g0->op || in->b != g0->b || in->mask != g0->mask)
        return 0;
    const int64_t at = (int64_t)t->m_rec.sc_off + (int64_t)(int32_t)in->imm - (int64_t)(int32_t)g0->imm;
    if (at < 0 || at >= (int64_t)t->l1.p.line_bytes)
        return 0;
    return memo_reads_unwritten(t, d);
}

/* A scene-memory record (TK_SCENE) that came to the hook: as memo_gather, for the scalar loads that
 * a block may start with or take in (MEMO_SCENE's note); 0 when it is to be timed alone. */
static __attribute__((noinline)) int memo_scene(Timing *t, TmDesc *d, const CoreRecord *rec)
{
    if (t->mmode == MM_REPLAY && memo_later(t, rec))
        return 1;
    const int load = (rec->in->op == ISA_OP_LD || rec->in->op == ISA_OP_LDB) && rec->naddr == 1;
    if (t->mmode == MM_RECORD) {
        if (load && rec->stage == t->m_stage && rec->gen == t->m_gen && memo_scene_joins(t, d, rec->in)) {
            memo_time_noted(t, d, rec);
            return 1;
        }
        memo_store(t);
    }
    size_t way;
    if (!load || d->short_block || t->memo_off || !cache_peek(&t->l1, rec->addr[0], &way))
        return 0;
    const uint64_t line = t->l1.ready[way], hit = t->now + (uint64_t)t->l1.p.hit_latency;
    if (line > hit && line - t->now > UINT32_MAX)
        return 0;
    const MemoFirst f = {MEMO_SCENE, rec->addr[0] & (uint32_t)(t->l1.p.line_bytes - 1),
                         line > hit ? (uint32_t)(line - t->now) : 0u};
    t->m_sway = way;
    if (memo_begin(t, d, rec, &f)) {
        cache_hits(&t->l1, way, 1); /* the first load's access */
        t->mem.st.instructions++;
        return 1;
    }
    if (t->mmode == MM_RECORD) {
        t->m_g0 = rec->in;
        t->m_rec.sc_off = f.off;
        t->m_rec.sc_rel = f.rel;
        memo_time_noted(t, d, rec);
        return 1;
    }
    return 0;
}

/* Every record but the next one of a replayed block (timing_hook). */
static __attribute__((noinline)) void hook_any(Timing *t, const CoreRecord *rec)
{
    if (__builtin_expect(t->halted, 0)) { /* a halted core is not run again before timing_reset */
        internal_error(t, "instruction after halt");
        return;
    }
    TmDesc *d = (TmDesc *)describe(t, rec);
    if (d->kind == TK_RB_GATHER || d->kind == TK_SCENE) {
        if (!(d->kind == TK_RB_GATHER ? memo_gather(t, d, rec) : memo_scene(t, d, rec)))
            time_one(t, d, rec);
        return;
    }
    if (t->mmode == MM_REPLAY && memo_diverged(t, rec)) /* the core left the stored path */
        return;
    if (t->mmode == MM_RECORD) {
        if (d->plain && rec->stage == t->m_stage && rec->gen == t->m_gen) {
            memo_time_noted(t, d, rec);
            return;
        }
        memo_store(t); /* the block ended before this instruction */
    }
    if (d->plain && !d->short_block && !t->memo_off) {
        if (memo_begin(t, d, rec, &(const MemoFirst){0, 0, 0}))
            return;
        if (t->mmode == MM_RECORD) {
            memo_time_noted(t, d, rec);
            return;
        }
    }
    time_one(t, d, rec);
}

/* The next record of a replayed block, only checked (1), or not (0). Its last record may have
 * taken its branch either way (a flipped last branch: memo_apply). */
static inline __attribute__((always_inline)) int hook_followed(Timing *t, const CoreRecord *rec)
{
    const uint64_t w = core_record_where(rec); /* pc, stage, generation, taken */
    if (rec->pc != t->follow.last) { /* inside the block: the next pc, no branch taken */
        if (__builtin_expect(w == t->follow.where, 1)) {
            t->follow.where++;
            return 1;
        }
    } else if (core_record_word(rec->pc, rec->stage, rec->gen) == t->follow.where) { /* taken or not */
        t->follow.where++;
        memo_apply(t, t->m_e, rec->taken != t->m_e->taken_last);
        return 1;
    }
    return 0;
}

void timing_hook(void *ctx, const CoreRecord *rec)
{
    Timing *t = ctx;
    if (t->mmode == MM_REPLAY && hook_followed(t, rec)) /* the next record of a stored block */
        return;
    hook_any(t, rec);
}

/* ---- hooks by kind ------------------------------------------------------------------------
 * timing_hook's work for the records of one kind of instruction (tm_class), which the core
 * calls by opcode (timing_attach): the same steps with the kind a constant, so that the choice
 * between a plain instruction's block and a memory instruction's unit is made by the core's
 * dispatch on the opcode, not by branches on the instruction's description at every record (they
 * followed the kernel's data; callgrind's branch model put 3 M of a diffuse batch's 15 M
 * mispredicted branches there). */

/* A plain instruction (TmDesc.plain; hook_any's steps for one). */
static __attribute__((noinline)) void hook_plain_any(Timing *t, const CoreRecord *rec)
{
    if (__builtin_expect(t->halted, 0)) {
        internal_error(t, "instruction after halt");
        return;
    }
    if (t->mmode == MM_REPLAY && memo_diverged(t, rec))
        return;
    TmDesc *d = (TmDesc *)describe(t, rec);
    if (t->mmode == MM_RECORD) {
        if (rec->stage == t->m_stage && rec->gen == t->m_gen) {
            memo_time_noted(t, d, rec);
            return;
        }
        memo_store(t);
    }
    if (!d->short_block && !t->memo_off) {
        if (memo_begin(t, d, rec, &(const MemoFirst){0, 0, 0}))
            return;
        if (t->mmode == MM_RECORD) {
            memo_time_noted(t, d, rec);
            return;
        }
    }
    time_kind(t, d, rec, TK_PLAIN);
}

static void hook_plain(void *ctx, const CoreRecord *rec)
{
    Timing *t = ctx;
    if (t->mmode == MM_REPLAY && hook_followed(t, rec))
        return;
    hook_plain_any(t, rec);
}

/* An instruction that is not plain (hook_any's steps for one, of the kind given): it ends a
 * replay or a recording, and is timed as it runs. */
static inline __attribute__((always_inline)) void hook_unit(void *ctx, const CoreRecord *rec, int kind)
{
    Timing *t = ctx;
    if (__builtin_expect(t->halted, 0)) {
        internal_error(t, "instruction after halt");
        return;
    }
    if (t->mmode != MM_NONE) {
        if (t->mmode == MM_REPLAY && memo_diverged(t, rec)) /* (never 1: rec is on no block's path) */
            return;
        if (t->mmode == MM_RECORD)
            memo_store(t);
    }
    time_kind(t, describe(t, rec), rec, kind);
}

/* A gather or a scene-memory instruction (kind): in a block when one takes it (memo_gather,
 * memo_scene), else timed alone. */
static inline __attribute__((always_inline)) void hook_block_kind(void *ctx, const CoreRecord *rec, int kind)
{
    Timing *t = ctx;
    if (__builtin_expect(t->halted, 0)) {
        internal_error(t, "instruction after halt");
        return;
    }
    TmDesc *d = (TmDesc *)describe(t, rec);
    if (!(kind == TK_RB_GATHER ? memo_gather(t, d, rec) : memo_scene(t, d, rec)))
        time_kind(t, d, rec, kind);
}

static void hook_rb_gather(void *ctx, const CoreRecord *rec) { hook_block_kind(ctx, rec, TK_RB_GATHER); }
static void hook_rb_scatter(void *ctx, const CoreRecord *rec) { hook_unit(ctx, rec, TK_RB_SCATTER); }
static void hook_spad_vec(void *ctx, const CoreRecord *rec) { hook_unit(ctx, rec, TK_SPAD_VEC); }
static void hook_scene(void *ctx, const CoreRecord *rec) { hook_block_kind(ctx, rec, TK_SCENE); }
static void hook_other(void *ctx, const CoreRecord *rec) { hook_unit(ctx, rec, -1); }

CoreHook timing_op_hook(int op)
{
    if (op < 0 || op >= ISA_OP_COUNT)
        return timing_hook;
    const TmClass c = tm_class(op);
    if (c.plain)
        return hook_plain;
    switch (c.kind) {
    case TK_RB_GATHER: return hook_rb_gather;
    case TK_RB_SCATTER: return hook_rb_scatter;
    case TK_SPAD_LOAD:
    case TK_SPAD_STORE: return c.vec ? hook_spad_vec : hook_other;
    case TK_SCENE: return hook_scene;
    default: return hook_other;
    }
}

CoreFollow *timing_follow(Timing *t) { return &t->follow; }

void timing_set_memo(Timing *t, int on)
{
    t->memo_off = !on;
}

TimingMemoCounts timing_memo_counts(const Timing *t) { return t->mc; }

void timing_end(Timing *t)
{
    if (t->mmode == MM_REPLAY) /* stopped inside a replayed block: time what came */
        memo_retime(t, 0, NULL, 0);
    memo_none(t);
    if (!t->halted) {
        t->st.cycles += t->now;
        t->st.runs++;
        t->halted = 1;
    }
}

void timing_stats_add(TimingStats *d, const TimingStats *s)
{
    /* Every field is a uint64_t counter: add them as an array. */
    uint64_t *a = (uint64_t *)d;
    const uint64_t *b = (const uint64_t *)s;
    for (size_t i = 0; i < sizeof *d / sizeof(uint64_t); i++)
        a[i] += b[i];
}

int timing_check(const TimingStats *s, char *err, size_t errlen)
{
    uint64_t sum = s->busy;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        sum += s->stalls[c];
    if (sum != s->cycles) {
        snprintf(err, errlen, "timing: busy %llu + stalls %llu != cycles %llu", (unsigned long long)s->busy,
                 (unsigned long long)(sum - s->busy), (unsigned long long)s->cycles);
        return -1;
    }
    uint64_t total = 0;
    for (int g = 0; g < ISA_STAGE_COUNT; g++) {
        uint64_t st = s->stage_busy[g];
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            st += s->stage_stalls[g][c];
        if (st != s->stage_cycles[g]) {
            snprintf(err, errlen, "timing: stage %s: busy + stalls %llu != cycles %llu", isa_stage_keys[g],
                     (unsigned long long)st, (unsigned long long)s->stage_cycles[g]);
            return -1;
        }
        total += st;
    }
    uint64_t gsum = 0;
    for (int g = 0; g < CORE_GENERATIONS; g++) {
        uint64_t gs = s->gen_busy[g];
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            gs += s->gen_stalls[g][c];
        if (gs != s->gen_cycles[g]) {
            snprintf(err, errlen, "timing: generation %d: busy + stalls %llu != cycles %llu", g,
                     (unsigned long long)gs, (unsigned long long)s->gen_cycles[g]);
            return -1;
        }
        gsum += s->gen_cycles[g];
    }
    if (total != s->cycles || gsum != s->cycles) {
        snprintf(err, errlen, "timing: stage cycles %llu, generation cycles %llu, cycles %llu",
                 (unsigned long long)total, (unsigned long long)gsum, (unsigned long long)s->cycles);
        return -1;
    }
    return 0;
}
