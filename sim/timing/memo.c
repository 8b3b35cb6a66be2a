/* sim/timing/memo.c -- the memo of blocks (see memo.h; docs/performance.md).
 *
 * Owns: storing a block's outcome under its start state, matching a start state, replaying,
 * retiming a replay the core left. Must not: time an instruction itself (tm_time and its kin do)
 * or change a result: a replay leaves the model exactly as timing the block would.
 */
#include <stdlib.h>
#include <string.h>

#include "tm.h"

/* No block being recorded or replayed; a following core (timing_follow) counts no record. */
void memo_none(Timing *t)
{
    t->mmode = MM_NONE;
    t->follow.where = CORE_FOLLOW_NONE;
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

/* A shared stored block e this model starts to leave replays of uncounted: noted, so that they are
 * folded into this model's statistics (memo_fold_all); a full list is folded at once. */
static void memo_fold_touched(Timing *t)
{
    for (uint32_t i = 0; i < t->ntouched; i++)
        if (t->touched[i]->lz_n && t->touched[i]->lz_owner == t)
            memo_fold(t, t->touched[i]);
    t->ntouched = 0;
}

/* A shared block e replayed by t: replays another model left uncounted in it folded into that
 * one's statistics first; e noted in t's list when its count starts. */
static __attribute__((noinline)) void memo_touched(Timing *t, MemoEntry *e)
{
    if (e->lz_n && e->lz_owner != t)
        memo_fold(e->lz_owner, e);
    if (e->lz_n == 0) {
        if (t->ntouched == TM_TOUCHED)
            memo_fold_touched(t);
        t->touched[t->ntouched++] = e;
        e->lz_owner = t;
    }
}

/* Every stored block's replays into the statistics (memo_fold). A model that shares its stored
 * blocks (timing_share_memo) folds the ones whose uncounted replays are its own (MemoEntry.lz_owner,
 * noted in its list: memo_touched); another model's are folded into that one when this one replays
 * the block, or by that one. */
void memo_fold_all(Timing *t)
{
    if (t->memo_shared) {
        memo_fold_touched(t);
        return;
    }
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
void memo_apply(Timing *t, MemoEntry *e, int flip)
{
    const uint64_t t0 = t->m_t0, end = t0 + e->end_rel;
    const int stage = t->m_stage, gen = t->m_gen;
    drain(t, end); /* what the next record's drain would apply; the events left come after */
    t->now = end;
    if (__builtin_expect(t->memo_shared, 0) && (e->lz_n == 0 || e->lz_owner != t))
        memo_touched(t, e);
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
void memo_retime(Timing *t, int record, const MemoEv *ev, int nev)
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
            tm_time_scene_hit(t, d, &r, t->m_sway);
            if (record)
                memo_post(t, d, &r, g);
        } else if (g) {
            if (record)
                memo_pre(t, d);
            tm_time_gather(t, d, &r, g == MEMO_NO_LANES ? 0 : g);
            if (record)
                memo_post(t, d, &r, g);
        } else if (record) {
            memo_time_noted(t, d, &r);
        } else {
            tm_time(t, d, &r);
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
    for (int c = 0; c < TM_CHARGE_SLOTS; c++)
        t->m_stalls0[c] = tm_slot(&t->st, c);
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
__attribute__((noinline)) int memo_begin(Timing *t, TmDesc *d, const CoreRecord *rec, const MemoFirst *f)
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

void memo_pushed(Timing *t, uint64_t time, int kind, int arg, int cause)
{
    MemoEntry *m = &t->m_rec;
    if (m->nev_out == MEMO_EVENTS || time - t->m_t0 > UINT32_MAX) {
        t->m_ok = 0;
        return;
    }
    m->ev_out[m->nev_out++] = (MemoEv){(uint32_t)(time - t->m_t0), (uint16_t)arg, (uint8_t)kind, (uint8_t)cause};
}

/* The recorded block's end: its outcome into the first instruction's ways. */
__attribute__((noinline)) void memo_store(Timing *t)
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
    for (int c = 0; c < TM_CHARGE_SLOTS; c++) {
        uint64_t v = tm_slot(&t->st, c) - t->m_stalls0[c];
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
    if (old->lz_n) /* (a shared block's: into the model that replayed it) */
        memo_fold(t->memo_shared && old->lz_owner ? old->lz_owner : t, old);
    m->lz_n = 0;
    m->lz_owner = t;
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
__attribute__((noinline)) void memo_time_noted(Timing *t, const TmDesc *d, const CoreRecord *rec)
{
    memo_pre(t, d);
    tm_time(t, d, rec);
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
__attribute__((noinline)) int memo_diverged(Timing *t, const CoreRecord *rec)
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
__attribute__((noinline)) int memo_gather(Timing *t, TmDesc *d, const CoreRecord *rec)
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
__attribute__((noinline)) int memo_scene(Timing *t, TmDesc *d, const CoreRecord *rec)
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
    if (line > hit && line - t->now > (UINT32_MAX >> 2))
        return 0;
    /* the key: when the line's data are there, and where its fill came from (what a wait for
     * them is charged to: tm_from_slot) */
    const MemoFirst f = {MEMO_SCENE, rec->addr[0] & (uint32_t)(t->l1.p.line_bytes - 1),
                         line > hit ? (uint32_t)(line - t->now) << 2 | t->l1.from[way] : 0u};
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

