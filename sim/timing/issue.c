/* sim/timing/issue.c -- the timing model's steps for one instruction: hazards that an event
 * clears, the units it uses as it issues, its completion, and the hooks the functional core
 * calls (see sim/timing.h for the model, sim/timing.c for its set-up and statistics, and
 * sim/timing/memo.c for the memo of blocks the hooks consult first).
 *
 * Owns: the order in which hazards are charged, every charge to a stall cause, and which unit an
 * instruction uses, read from the ISA table's UNIT and FLAGS columns (never from opcode names).
 * Must not: hold a unit's parameters, state or cost formula (sim/machine/, sim/mem/ do), or
 * compute an architectural value.
 */
#include <stdlib.h>
#include <string.h>

#include "tm.h"

/* ---- events ------------------------------------------------------------------------------- */

/* Apply every event due by cycle `at`. */
void tm_drain_due(Timing *t, uint64_t at)
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
    /* A chip's core: a register waiting for an answer of the shared memory stops the core here,
     * before anything is charged (sim/timing/pend.c). */
    if (__builtin_expect(t->pend != NULL, 0) && tm_yield_if_pending(t, d))
        return TM_YIELDED;
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
    } else if (t->memo_shared) { /* (the shared table is the program's size: never here) */
        d = &t->spare;
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
    tm_watch_unit(t, TIMING_UNIT_INTERCONNECT, s, s + len);
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
            tm_watch_unit(t, TIMING_UNIT_PARTITION, is->at, e);
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
static inline __attribute__((always_inline)) void complete_as(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, uint64_t end,
                               uint64_t ready, int res_cause, int flow)
{
    if (__builtin_expect(t->watch.instr != NULL, 0))
        tm_watch_instr(t, d, rec, at, end, d->ndst ? ready : end);
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
        t->st.cycles += end - t->base;
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
        tm_watch_unit(t, TIMING_UNIT_RAYBUF, at, at + (uint64_t)c);
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
    const uint64_t at = hazards_cleared(t, d, rec, TM_NO_FLOW);
    if (__builtin_expect(at == TM_YIELDED, 0))
        return;
    issue_rb_c(t, d, rec, at, c);
}

/* A scalar scene load that hits the line in `way` (its access counted apart: mem_hits): time_kind's
 * and issue_scene's steps for it, from a record without addresses (a scene load's hazards do not
 * read them). */
static void time_scene_hit(Timing *t, const TmDesc *d, const CoreRecord *rec, size_t way)
{
    const uint64_t at = hazards_cleared(t, d, rec, TM_NO_FLOW);
    if (__builtin_expect(at == TM_YIELDED, 0))
        return;
    const uint64_t r = at + (uint64_t)t->l1.p.hit_latency, line = t->l1.ready[way];
    tm_watch_unit(t, TIMING_UNIT_L1, at, at + 1);
    count_issue(t, d, rec->stage, rec->gen);
    complete_as(t, d, rec, at, at + 1, r > line ? r : line, line > r ? tm_from_slot(t->l1.from[way]) : TM_SCENE_MEMORY,
                TM_NO_FLOW);
    if (__builtin_expect(mem_pending(line), 0))
        tm_pend_note(t, d);
}

static __attribute__((noinline)) void issue_spad(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at)
{
    const int stage = rec->stage, gen = rec->gen;
    uint64_t ext = 0;
    if (rec->naddr) {
        ext = spad_access(&t->spad, rec->addr, rec->naddr) - 1;
        charge(t, TM_SCRATCHPAD, ext, stage, gen);
        tm_watch_unit(t, TIMING_UNIT_SCRATCHPAD, at, at + ext + 1);
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
        tm_watch_unit(t, TIMING_UNIT_L1, at, at + ext + 1);
        cause = tm_from_slot(t->mem.last_from);
    }
    count_issue(t, d, stage, gen);
    complete_as(t, d, rec, at, at + ext + 1, ready ? ready : at + d->lat, cause, TM_NO_FLOW);
    if (__builtin_expect(mem_pending(ready), 0))
        tm_pend_note(t, d);
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
    if (__builtin_expect(at == TM_YIELDED, 0))
        return;
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


void tm_time(Timing *t, const TmDesc *d, const CoreRecord *rec) { time_one(t, d, rec); }

void tm_time_gather(Timing *t, const TmDesc *d, const CoreRecord *rec, int c) { time_gather_c(t, d, rec, c); }

void tm_time_scene_hit(Timing *t, const TmDesc *d, const CoreRecord *rec, size_t way)
{
    time_scene_hit(t, d, rec, way);
}
