/* sim/timing/memo.h -- the memo of blocks: host-speed machinery of the timing model, behind the
 * few calls the model's hooks make (below). A block of instructions that times the same whatever
 * its data is not worked through again when its start state recurs: its stored outcome is applied
 * at its end, with the same result as timing it (docs/performance.md; tests/unit/test_timing.c
 * compares every micro-benchmark and a frame with the memo on and off).
 *
 * Owns: the stored blocks (MemoWays under a block's first instruction's TmDesc), the block being
 * recorded or replayed, and TimingMemoCounts. Must not: time anything itself (it asks the model:
 * tm_time, tm_time_gather, tm_time_scene_hit in tm.h), or change a result.
 */
#ifndef SFSIM_TIMING_MEMO_H
#define SFSIM_TIMING_MEMO_H

#include <stddef.h>
#include <stdint.h>

#include "../core.h"
#include "../timing.h"

struct TmDesc;

/*
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
/* A block's charges are noted by slot: the stall causes and two more (sim/timing/tm.h). */
enum { MEMO_CHARGE_SLOTS = TM_CAUSE_COUNT + 2 };
enum { MEMO_NO_LANES = 255 }; /* MemoEntry.gc of a gather with no lanes (no access, no transfer) */
enum { MEMO_SCENE = 254 };    /* MemoEntry.gc of a scene load */

/* What a block's key asks of its first record beyond the start state: a gather's bank cycles
 * (c0, as MemoEntry.gc; 0 for a plain instruction), or for a scene load (c0 MEMO_SCENE) its
 * address's place in its line and when its line's data are there (rel: the cycles from the
 * start, times 4, plus where a chip's fill came from, Cache.from; 0 if by its hit latency). */
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
    uint8_t ch_cause[MEMO_CHARGE_SLOTS];
    uint32_t ch_cycles[MEMO_CHARGE_SLOTS];
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
    Timing *lz_owner;               /* a shared memo (timing_share_memo): the model whose replays
                                       lz_n counts; another's replay folds them into it first */
} MemoEntry;

typedef struct MemoWays {
    MemoEntry e[MEMO_WAYS];
    uint8_t next;                   /* the way the next store replaces */
    uint8_t pred[MEMO_PRED];        /* by memo_sig of the start state: the way the last lookup
                                       from such a state found, tried first (then the others in
                                       turn) */
} MemoWays;

enum { MM_NONE, MM_RECORD, MM_REPLAY };

/* ---- what the model calls (sim/timing/issue.c, sim/timing.c) ------------------------------- */

/* No block being recorded or replayed; a following core (timing_follow) counts no record. */
void memo_none(Timing *t);
/* Every stored block's replays into the statistics (timing_stats, timing_reset). */
void memo_fold_all(Timing *t);
/* Starts a block at the plain instruction, gather or scene load d (first record rec; f: what the
 * key asks of it): 1 when a replay took it, else 0 (a recording when t's mode became MM_RECORD). */
int memo_begin(Timing *t, struct TmDesc *d, const CoreRecord *rec, const MemoFirst *f);
/* Recording: d timed as usual, its live-ins noted before and its writes after. */
void memo_time_noted(Timing *t, const struct TmDesc *d, const CoreRecord *rec);
/* Recording: the block ends before the record that came. */
void memo_store(Timing *t);
/* A replay met a record off its stored path: 1 when another stored way took it, else 0 (the
 * records so far were timed again). */
int memo_diverged(Timing *t, const CoreRecord *rec);
/* A gather's (TK_RB_GATHER) or scene-memory (TK_SCENE) record that came to the hook: 1 when a
 * block took it, 0 when it is to be timed alone. */
int memo_gather(Timing *t, struct TmDesc *d, const CoreRecord *rec);
int memo_scene(Timing *t, struct TmDesc *d, const CoreRecord *rec);
/* The stored block e's outcome, applied at its last record (flip: its last branch went the other
 * way than when stored). */
void memo_apply(Timing *t, MemoEntry *e, int flip);
/* A replay the core left or stopped in: the records so far timed one by one (record: while a
 * recording notes them, from the start's pending events ev). */
void memo_retime(Timing *t, int record, const MemoEv *ev, int nev);
/* Recording: an event pushed (its outcome if still pending at the block's end). */
void memo_pushed(Timing *t, uint64_t time, int kind, int arg, int cause);

#endif
