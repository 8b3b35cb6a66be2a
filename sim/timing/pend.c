/* sim/timing/pend.c -- a chip's core: answers of the shared memory that come later (docs/chip.md,
 * "Exact and deterministic").
 *
 * Owns: the core's outstanding line fills and the groups of them a load waits for, the pending
 * values (sim/mem/port.h, MEM_PENDING) that stand for them in the scoreboard and the L1, their
 * resolution when an answer comes (timing_answer), and the decision to yield: an instruction whose
 * registers are pending stops the core before anything of it is timed (tm_yield_if_pending).
 * Must not: know what lies below the L1 (its misses leave through the chip's TimingOut), or
 * charge a stall (the instruction is timed again, as usual, once its answers are in).
 *
 * A fill is one line read from below; its pending value is MEM_PENDING | fill. A load whose
 * lines wait for more than one fill, or for one and a known cycle (a hit on a line still being
 * filled: its hit latency), is ready at the latest of them: a group, MEM_PENDING |
 * MEM_PENDING_GROUP | group, with the known part and the fills still out. Values are replaced
 * everywhere they stand (registers, L1 lines, groups) when the answer comes, and the ids are used
 * again after that: a pending value never outlives what it names.
 */
#include <stdlib.h>
#include <string.h>

#include "tm.h"

typedef struct PendGroup {
    uint64_t known;                  /* the latest known part */
    int cause;                       /* of the answer that came latest (0 before one) */
    uint32_t n;                      /* fills still out */
    uint32_t fill[ISA_MAX_LANES + 1];
} PendGroup;

struct Pend {
    TimingOut out;
    void *ctx;
    uint64_t *line;                  /* by fill: the line's address (UINT64_MAX: free) */
    uint32_t nfill, capfill;
    uint32_t *free_fill, nfree_fill; /* ids free for use again */
    PendGroup *grp;
    uint8_t *grp_live;
    uint32_t ngrp, capgrp;
    uint32_t *free_grp, nfree_grp;
    uint32_t *live_grp, nlive_grp;   /* the live groups, in no order; grp_pos: each one's place */
    uint32_t *grp_pos;
    uint32_t live_fills;
    /* Registers given a pending value since they were last looked at (tm_pend_note): the only ones
     * an answer can stand in (a superset: one may have been written since). */
    uint64_t cand[(SIMD_NREGS + 63) / 64];
};

/* *p resized to cap elements of size bytes; -1 on out of memory (*p unchanged). */
static int resize(void **p, uint32_t cap, size_t size)
{
    void *g = realloc(*p, size * cap);
    if (!g)
        return -1;
    *p = g;
    return 0;
}

/* A new fill id for the line at addr; UINT32_MAX on out of memory. */
static uint32_t fill_new(Pend *p, uint64_t addr)
{
    uint32_t f;
    if (p->nfree_fill) {
        f = p->free_fill[--p->nfree_fill];
    } else {
        if (p->nfill == p->capfill) {
            const uint32_t cap = p->capfill ? 2 * p->capfill : 16;
            if (resize((void **)&p->line, cap, sizeof *p->line) ||
                resize((void **)&p->free_fill, cap, sizeof *p->free_fill))
                return UINT32_MAX;
            p->capfill = cap;
        }
        f = p->nfill++;
    }
    p->line[f] = addr;
    p->live_fills++;
    return f;
}

static uint32_t group_new(Pend *p)
{
    uint32_t g;
    if (p->nfree_grp) {
        g = p->free_grp[--p->nfree_grp];
    } else {
        if (p->ngrp == p->capgrp) {
            const uint32_t cap = p->capgrp ? 2 * p->capgrp : 16;
            if (resize((void **)&p->grp, cap, sizeof *p->grp) || resize((void **)&p->grp_live, cap, 1) ||
                resize((void **)&p->free_grp, cap, sizeof *p->free_grp) ||
                resize((void **)&p->live_grp, cap, sizeof *p->live_grp) ||
                resize((void **)&p->grp_pos, cap, sizeof *p->grp_pos))
                return UINT32_MAX;
            p->capgrp = cap;
        }
        g = p->ngrp++;
    }
    p->grp[g].known = 0;
    p->grp[g].cause = TM_SCENE_MEMORY;
    p->grp[g].n = 0;
    p->grp_live[g] = 1;
    p->grp_pos[g] = p->nlive_grp;
    p->live_grp[p->nlive_grp++] = g;
    return g;
}

/* The L1's port below (sim/mem/port.h): the request leaves through the chip's TimingOut; a read's
 * data come when timing_answer says. */
static uint64_t pend_request(void *below, const MemReq *r)
{
    Timing *t = below;
    Pend *p = t->pend;
    if (r->write) { /* nobody waits for a write */
        p->out(p->ctx, r->addr, 1, r->at, UINT32_MAX);
        return r->at;
    }
    const uint32_t f = fill_new(p, r->addr);
    if (f == UINT32_MAX)
        return UINT64_MAX; /* the caller's "out of memory" internal error */
    p->out(p->ctx, r->addr, 0, r->at, f);
    return MEM_PENDING | f;
}

/* Adds v (a cycle or a fill's pending value) to group g. */
static void group_add(PendGroup *g, uint64_t v)
{
    if (!mem_pending(v)) {
        if (v > g->known)
            g->known = v;
        return;
    }
    const uint32_t f = (uint32_t)v;
    for (uint32_t i = 0; i < g->n; i++)
        if (g->fill[i] == f)
            return;
    if (g->n < ISA_MAX_LANES + 1)
        g->fill[g->n++] = f;
}

static int is_group(uint64_t v) { return mem_pending(v) && (v & MEM_PENDING_GROUP); }

static void group_free(Pend *p, uint32_t g)
{
    p->grp_live[g] = 0;
    p->free_grp[p->nfree_grp++] = g;
    const uint32_t last = p->live_grp[--p->nlive_grp]; /* the last live one takes its place */
    p->live_grp[p->grp_pos[g]] = last;
    p->grp_pos[last] = p->grp_pos[g];
}

/* MemJoin: the later of a and b, either pending. A group value is one made for this access (lines
 * and answers never hold one: the L1's hit on a line being filled, or an earlier line of the same
 * access), so the other joins it, and two such groups become one. */
static uint64_t pend_join(void *ctx, uint64_t a, uint64_t b)
{
    Timing *t = ctx;
    Pend *p = t->pend;
    if (a == b)
        return a;
    if (is_group(b) && !is_group(a)) {
        const uint64_t s = a;
        a = b;
        b = s;
    }
    if (is_group(a)) {
        PendGroup *ga = &p->grp[(uint32_t)a];
        if (is_group(b)) {
            const PendGroup *gb = &p->grp[(uint32_t)b];
            group_add(ga, gb->known);
            for (uint32_t i = 0; i < gb->n; i++)
                group_add(ga, MEM_PENDING | gb->fill[i]);
            group_free(p, (uint32_t)b);
        } else {
            group_add(ga, b);
        }
        return a;
    }
    if (!mem_pending(a) && !mem_pending(b))
        return a > b ? a : b;
    const uint32_t g = group_new(p);
    if (g == UINT32_MAX)
        return UINT64_MAX;
    group_add(&p->grp[g], a);
    group_add(&p->grp[g], b);
    return MEM_PENDING | MEM_PENDING_GROUP | g;
}

int timing_chip(Timing *t, TimingOut out, void *ctx)
{
    if (!t->pend) {
        t->pend = calloc(1, sizeof *t->pend);
        if (!t->pend)
            return -1;
    }
    t->pend->out = out;
    t->pend->ctx = ctx;
    cache_connect(&t->l1, (MemPort){pend_request, t});
    cache_set_join(&t->l1, pend_join, t);
    return 0;
}

void tm_pend_free(Timing *t)
{
    Pend *p = t->pend;
    if (!p)
        return;
    free(p->line);
    free(p->free_fill);
    free(p->grp);
    free(p->grp_live);
    free(p->free_grp);
    free(p->live_grp);
    free(p->grp_pos);
    free(p);
    t->pend = NULL;
}

void tm_pend_reset(Timing *t)
{
    Pend *p = t->pend;
    if (!p)
        return;
    for (uint32_t f = 0; f < p->nfill; f++)
        p->line[f] = UINT64_MAX;
    for (uint32_t g = 0; g < p->ngrp; g++)
        p->grp_live[g] = 0;
    p->nfill = p->nfree_fill = p->live_fills = 0;
    p->ngrp = p->nfree_grp = p->nlive_grp = 0;
    memset(p->cand, 0, sizeof p->cand);
}

void tm_pend_note(Timing *t, const TmDesc *d)
{
    for (int i = 0; i < d->ndst; i++)
        t->pend->cand[d->dsts[i] >> 6] |= (uint64_t)1 << (d->dsts[i] & 63);
}

/* Every register standing at v gets x, a wait for it charged to cause; the scoreboard's horizon
 * again the latest ready cycle. Only the registers given a pending value can stand at v; while one
 * still waits, the horizon is the latest of theirs (a pending value is above every cycle), else the
 * latest of all. */
static void regs_resolve(Timing *t, uint64_t v, uint64_t x, int cause)
{
    Pend *p = t->pend;
    uint64_t hz = 0;
    int left = 0;
    for (int w = 0; w < (int)(sizeof p->cand / sizeof p->cand[0]); w++) {
        for (uint64_t m = p->cand[w]; m; m &= m - 1) {
            const int r = 64 * w + __builtin_ctzll(m);
            if (t->simd.ready[r] == v) {
                t->simd.ready[r] = x;
                t->simd.rcause[r] = (uint8_t)cause;
            }
            if (!mem_pending(t->simd.ready[r])) {
                p->cand[w] &= ~((uint64_t)1 << (r & 63));
            } else {
                left = 1;
                if (t->simd.ready[r] > hz)
                    hz = t->simd.ready[r];
            }
        }
    }
    if (!left) { /* (one pass a compiler can vectorize) */
        uint64_t pend = 0; /* bit 63: a pending value no path noted (tm_pend_note), a model error */
        for (int r = 0; r < SIMD_NREGS; r++) {
            const uint64_t rd = t->simd.ready[r];
            hz = rd > hz ? rd : hz;
            pend |= rd & ~(rd << 1); /* bit 63 set and bit 62 clear: mem_pending */
        }
        if (pend >> 63)
            internal_error(t, "a pending register not noted");
    }
    t->simd.horizon = hz;
}

void timing_answer(Timing *t, uint32_t fill, uint64_t x, int from)
{
    const int cause = from == TIMING_FROM_L2 ? TM_FROM_L2 : TM_FROM_DRAM;
    Pend *p = t->pend;
    if (!p || fill >= p->nfill || p->line[fill] == UINT64_MAX) {
        internal_error(t, "an answer for no outstanding fill");
        return;
    }
    const uint64_t v = MEM_PENDING | fill;
    cache_fill_done(&t->l1, p->line[fill], v, x, from);
    regs_resolve(t, v, x, cause);
    for (uint32_t i = p->nlive_grp; i-- > 0;) { /* (backwards: group_free moves the last one here) */
        const uint32_t g = p->live_grp[i];
        PendGroup *gr = &p->grp[g];
        for (uint32_t k = 0; k < gr->n; k++)
            if (gr->fill[k] == fill) {
                gr->fill[k] = gr->fill[--gr->n];
                if (x >= gr->known) { /* the latest answer's level (the known part: the L1's) */
                    gr->known = x;
                    gr->cause = cause;
                }
                break;
            }
        if (gr->n == 0) {
            regs_resolve(t, MEM_PENDING | MEM_PENDING_GROUP | g, gr->known, gr->cause);
            group_free(p, g);
        }
    }
    p->line[fill] = UINT64_MAX;
    p->free_fill[p->nfree_fill++] = fill;
    p->live_fills--;
}

/* Whether one of the registers instruction d waits for (all of them at a halt) is pending. */
static int regs_pending(const Timing *t, const TmDesc *d)
{
    if (d->is_halt) {
        for (int r = 0; r < SIMD_NREGS; r++)
            if (mem_pending(t->simd.ready[r]))
                return 1;
        return 0;
    }
    for (int i = 0; i < d->nregs; i++)
        if (mem_pending(t->simd.ready[d->regs[i]]))
            return 1;
    return 0;
}

int tm_yield_if_pending(Timing *t, const TmDesc *d)
{
    if (!regs_pending(t, d))
        return 0;
    /* Nothing of the instruction is timed: a recording it was part of is dropped (it would have
     * noted its live-ins), and the core stops after it (CORE_EXIT_YIELD). */
    if (t->mmode == MM_RECORD)
        memo_none(t);
    t->follow.yield = 1;
    return 1;
}

int timing_yielded(const Timing *t) { return t->follow.yield; }

int timing_blocked(Timing *t, const CoreRecord *rec)
{
    const TmDesc *d = &t->desc[rec->pc < t->desc_cap ? rec->pc : 0];
    if (rec->pc >= t->desc_cap || d->run != t->run) /* (described when it yielded) */
        return 0;
    return regs_pending(t, d);
}

void timing_resume(Timing *t, const CoreRecord *rec)
{
    t->follow.yield = 0;
    timing_hook(t, rec);
}

uint32_t timing_fills_out(const Timing *t) { return t->pend ? t->pend->live_fills : 0; }

