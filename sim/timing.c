/* sim/timing.c -- the timing model's set-up and statistics (see timing.h; the model and its
 * sources: docs/model.md). The model is three parts: this file (parameters, a model built from the
 * units of sim/machine/units.def and joined by ports, reset, statistics, the accounting check),
 * sim/timing/issue.c (one instruction: hazards, issue, completion, the hooks the functional core
 * calls) and sim/timing/memo.c (the memo of blocks, host-speed machinery behind sim/timing/memo.h).
 *
 * Owns: which units a core has and how their ports are joined, and the folding of the issue
 * counts into TimingStats. Must not: time an instruction (issue.c does), hold a unit's
 * parameters, state or cost formula (sim/machine/, sim/mem/ do), or compute an architectural
 * value.
 */
#include "timing.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "timing/tm.h"

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
    tm_pend_free(t);
    if (!t->share_owner) { /* (an owner is freed after the models that share its blocks) */
        for (uint32_t i = 0; i < t->desc_cap; i++)
            free(t->desc[i].memo);
        free(t->desc);
    }
    free(t->touched);
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) prefix##_free(&t->field);
#include "machine/units.def"
#undef TM_UNIT
    free(t);
}



/* Cold units from cycle `at` (the scoreboard, the queues, the units and the L1). */
static void units_cold(Timing *t, uint64_t at)
{
    evq_clear(&t->q);
    t->now = t->base = at;
#define TM_UNIT(field, Type, Params, Stats, params_fn, prefix) prefix##_reset(&t->field);
#include "machine/units.def"
#undef TM_UNIT
    t->halted = 0;
    t->follow.yield = 0;
    memo_none(t);
}

void timing_continue(Timing *t, int cold)
{
    if (t->mmode == MM_REPLAY)
        memo_retime(t, 0, NULL, 0);
    memo_none(t);
    if (cold) {
        units_cold(t, t->now);
        return;
    }
    t->base = t->now; /* (what is still in flight, an issue interval, goes on as it would) */
    t->halted = 0;
    t->follow.yield = 0;
}

uint64_t timing_now(const Timing *t) { return t->now; }

void timing_set_fb_base(Timing *t, uint64_t base) { t->mem.fb_base = base; }

int timing_warm_l1(Timing *t, const uint64_t *lines, size_t n, uint64_t fb_bytes)
{
    const uint64_t line = (uint64_t)t->l1.p.line_bytes, fb = ((uint64_t)1 << MEM_SPACE_SHIFT) + t->mem.fb_base;
    int rc = 0;
    for (uint64_t b = 0; rc == 0 && b < fb_bytes; b += line)
        rc = cache_warm(&t->l1, fb + b, 1);
    for (size_t i = 0; rc == 0 && i < n; i++)
        rc = cache_warm(&t->l1, lines[i], 0);
    if (rc)
        internal_error(t, "out of memory for the scene cache's tags");
    return rc;
}

static uint64_t tap_request(void *below, const MemReq *r)
{
    Timing *t = below;
    t->tap(t->tap_ctx, r->addr, r->write, r->at);
    return t->tap_below.request(t->tap_below.below, r);
}

void timing_tap(Timing *t, TimingTap tap, void *ctx)
{
    t->tap_below = t->l1.below;
    t->tap = tap;
    t->tap_ctx = ctx;
    cache_connect(&t->l1, (MemPort){tap_request, t});
}

void timing_reset(Timing *t)
{
    if (t->memo_shared) { /* (a new run would make the shared blocks look stale to the others) */
        internal_error(t, "a timing model sharing its memo was reset");
        return;
    }
    units_cold(t, 0);
    tm_pend_reset(t); /* (fills a unit left out are dropped with its chip's in-flight requests) */
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

CoreFollow *timing_follow(Timing *t) { return &t->follow; }

int timing_share_memo(Timing *t, Timing *owner, uint32_t ninstr)
{
    if (t == owner || t->share_owner || owner->share_owner || t->run != owner->run || t->mmode != MM_NONE ||
        owner->mmode != MM_NONE)
        return -1;
    /* the owner's table at the program's size: a sharer never grows it (its pointer would go stale) */
    if (owner->desc_cap < ninstr) {
        TmDesc *g = realloc(owner->desc, sizeof *g * ninstr);
        if (!g)
            return -1;
        memset(g + owner->desc_cap, 0, sizeof *g * (ninstr - owner->desc_cap));
        owner->desc = g;
        owner->desc_cap = ninstr;
    }
    if (!t->touched && !(t->touched = malloc(sizeof *t->touched * TM_TOUCHED)))
        return -1;
    if (!owner->touched && !(owner->touched = malloc(sizeof *owner->touched * TM_TOUCHED)))
        return -1;
    memo_fold_all(t);
    memo_fold_all(owner);
    for (uint32_t i = 0; i < t->desc_cap; i++)
        free(t->desc[i].memo);
    free(t->desc);
    t->desc = owner->desc;
    t->desc_cap = owner->desc_cap;
    t->share_owner = owner;
    t->memo_shared = owner->memo_shared = 1;
    return 0;
}

void timing_set_memo(Timing *t, int on)
{
    t->memo_user_off = !on;
    t->memo_off = t->memo_user_off || t->watch.instr != NULL;
}

/* ---- the watch (a timeline) ------------------------------------------------------------------ */

const char *const timing_unit_keys[TIMING_UNIT_COUNT] = {
#define TIMING_UNIT_KEY(name, key, desc) key,
    TIMING_UNITS(TIMING_UNIT_KEY)
#undef TIMING_UNIT_KEY
};

void tm_watch_charge(Timing *t, int slot, uint64_t cycles)
{
    const int from = slot == TM_FROM_L2 ? TIMING_FROM_L2 : slot == TM_FROM_DRAM ? TIMING_FROM_DRAM : -1;
    t->watch.charge(t->watch.ctx, from < 0 ? slot : TM_SCENE_MEMORY, from, cycles);
}

void tm_watch_instr(Timing *t, const TmDesc *d, const CoreRecord *rec, uint64_t at, uint64_t end, uint64_t ready)
{
    const TimingInstr in = {rec->pc, d->op, rec->stage, rec->gen, t->now, at, end,
                            mem_pending(ready) ? UINT64_MAX : ready};
    t->watch.instr(t->watch.ctx, &in);
}

/* The L1's port below while watched: a request answered at once is told to the watch. */
static uint64_t watch_request(void *below, const MemReq *r)
{
    Timing *t = below;
    const uint64_t done = t->watch_below.request(t->watch_below.below, r);
    if (t->watch.request && done != UINT64_MAX && !mem_pending(done))
        t->watch.request(t->watch.ctx, r->addr, r->write, r->at, done);
    return done;
}

void timing_watch(Timing *t, const TimingWatch *w)
{
    if (w && !t->watch.instr) {
        t->watch_below = t->l1.below;
        cache_connect(&t->l1, (MemPort){watch_request, t});
    } else if (!w && t->watch.instr) {
        cache_connect(&t->l1, t->watch_below);
    }
    if (w)
        t->watch = *w;
    else
        memset(&t->watch, 0, sizeof t->watch);
    t->memo_off = t->memo_user_off || t->watch.instr != NULL;
}

TimingMemoCounts timing_memo_counts(const Timing *t) { return t->mc; }

void timing_end(Timing *t)
{
    if (t->mmode == MM_REPLAY) /* stopped inside a replayed block: time what came */
        memo_retime(t, 0, NULL, 0);
    memo_none(t);
    if (!t->halted) {
        t->st.cycles += t->now - t->base;
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
