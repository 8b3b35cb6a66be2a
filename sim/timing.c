/* sim/timing.c -- the timing model (see timing.h; the model and its sources: docs/model.md).
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
 */
#include "timing.h"

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

enum { EV_REG, EV_UNIT, EV_FETCH, EV_PART };
enum { NREGS = ISA_NUM_SREGS + ISA_NUM_VREGS + ISA_NUM_MREGS };
enum { AGU_MAX = 65, IVL_MAX = 128 };
enum { USER_DP, USER_AGU, USER_PART };

typedef struct OpRegs {            /* registers an opcode reads and writes, from the ISA table */
    uint8_t nsrc, ndst;
    uint8_t src_kind[ISA_MAX_OPERANDS + 1], src_field[ISA_MAX_OPERANDS + 1];
    uint8_t dst_kind[ISA_MAX_OPERANDS], dst_field[ISA_MAX_OPERANDS];
    uint8_t mask_src;              /* reads the exec mask register */
} OpRegs;

typedef struct AguEntry {          /* an ID vector the AGUs fetch */
    uint32_t addr, n;
    uint64_t ready;                /* the data path may take it from this cycle on */
    uint64_t part_end;             /* it waited for the partition unit until here */
    uint64_t icn_delay;            /* cycles it waited for an interconnect port */
} AguEntry;

typedef struct Ivl { uint64_t s, e; } Ivl;

struct Timing {
    TimingParams p;
    OpRegs ops[ISA_OP_COUNT];
    EvQueue q;
    uint64_t now;                  /* the cycle the next instruction may issue in */
    uint8_t pending[NREGS], rcause[NREGS];
    uint32_t rtag[NREGS], tagseq;
    uint8_t unit_pending[ISA_U_COUNT];
    uint8_t fetch_pending;
    /* partition unit */
    uint8_t part_busy;
    uint64_t part_s, part_e;
    uint32_t part_lo, part_hi;
    /* AGUs: the queue of ID vectors fetched ahead, and their interconnect transfers */
    AguEntry aq[AGU_MAX];
    int aq_head, aq_n;
    uint64_t agu_free;
    Ivl agu_ivl[IVL_MAX];
    int agu_ivl_n;
    /* interconnect: the data path's last transfer window */
    Ivl dp;
    SceneMem sm;
    int rb_shift, spad_shift;
    uint16_t *bank_cnt;
    uint32_t *bank_stamp, stamp;
    int halted;
    char err[256];
    TimingStats st;
};

static int log2i(int v)
{
    int s = 0;
    while ((1 << s) < v)
        s++;
    return s;
}

void timing_params(const CfgMachine *c, TimingParams *p)
{
    memset(p, 0, sizeof *p);
    p->lanes = c->core_simd_width;
    for (int u = 0; u < ISA_U_COUNT; u++)
        p->lat[u] = p->issue[u] = 1;
    p->lat[ISA_U_SALU] = c->latency_salu;
    p->lat[ISA_U_SFPU] = c->latency_sfpu;
    p->lat[ISA_U_SSPEC] = c->latency_sspec;
    p->lat[ISA_U_VADD] = c->latency_vadd;
    p->lat[ISA_U_VMUL] = c->latency_vmul;
    p->lat[ISA_U_VFMA] = c->latency_vfma;
    p->lat[ISA_U_VSPEC] = c->latency_vspec;
    p->lat[ISA_U_VCMP] = c->latency_vcmp;
    p->lat[ISA_U_VLOGIC] = c->latency_vlogic;
    p->lat[ISA_U_VSEL] = c->latency_vsel;
    p->lat[ISA_U_MASK] = c->latency_mask;
    p->lat[ISA_U_AGU] = c->latency_agu;
    p->issue[ISA_U_SSPEC] = c->issue_sspec;
    p->issue[ISA_U_VSPEC] = c->issue_vspec;
    p->issue[ISA_U_VMUL] = c->issue_vmul;
    p->issue[ISA_U_VFMA] = c->issue_vfma;
    p->taken_penalty = c->branch_taken_penalty;
    p->rb_banks = c->raybuf_banks;
    p->rb_line = c->raybuf_line_bytes;
    p->rb_access = c->raybuf_access_cycles;
    p->align_cycles = c->raybuf_align_cycles;
    p->agu_ids_per_cycle = c->agu_ids_per_cycle;
    p->agu_depth = c->agu_queue_depth;
    p->icn_latency = c->interconnect_latency;
    p->icn_ports = c->interconnect_ports;
    p->part_setup = c->partition_setup_cycles;
    p->part_ids_per_cycle = c->partition_ids_per_cycle ? c->partition_ids_per_cycle : c->core_simd_width;
    p->spad_ports = c->spad_ports;
    p->spad_latency = c->spad_latency;
    p->spad_line = c->spad_line_bytes;
    p->scene_ports = c->scene_ports;
    p->scene.latency = c->scene_latency;
    p->scene.bytes_per_cycle = c->scene_bytes_per_cycle;
    p->scene.line_bytes = c->scene_line_bytes;
    p->scene.hit_latency = c->scene_hit_latency;
    p->scene.cache_bytes = c->scene_cache_kb * 1024;
    p->scene.ways = c->scene_cache_ways;
}

static void build_op_regs(OpRegs *ops)
{
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaOpInfo *oi = &isa_ops[op];
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        OpRegs *r = &ops[op];
        memset(r, 0, sizeof *r);
        int ri = 0;
        for (int i = 0; i < fi->nops; i++) {
            IsaOperandKind k = fi->ops[i].kind;
            if (k != ISA_K_R && k != ISA_K_V && k != ISA_K_M)
                continue;
            char acc = oi->access[ri++];
            if (acc == 'r' || acc == 'x') {
                r->src_kind[r->nsrc] = (uint8_t)k;
                r->src_field[r->nsrc++] = (uint8_t)fi->ops[i].field;
            }
            if (acc == 'w' || acc == 'x') {
                r->dst_kind[r->ndst] = (uint8_t)k;
                r->dst_field[r->ndst++] = (uint8_t)fi->ops[i].field;
            }
        }
        r->mask_src = (uint8_t)fi->masked;
    }
}

Timing *timing_new(const TimingParams *p, char *err, size_t errlen)
{
    Timing *t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    t->p = *p;
    build_op_regs(t->ops);
    evq_init(&t->q);
    smem_init(&t->sm, &p->scene);
    t->rb_shift = log2i(p->rb_line);
    t->spad_shift = log2i(p->spad_line);
    t->bank_cnt = calloc((size_t)p->rb_banks, sizeof *t->bank_cnt);
    t->bank_stamp = calloc((size_t)p->rb_banks, sizeof *t->bank_stamp);
    if (!t->bank_cnt || !t->bank_stamp) {
        snprintf(err, errlen, "out of memory");
        timing_free(t);
        return NULL;
    }
    timing_reset(t);
    return t;
}

void timing_free(Timing *t)
{
    if (!t)
        return;
    evq_free(&t->q);
    smem_free(&t->sm);
    free(t->bank_cnt);
    free(t->bank_stamp);
    free(t);
}

void timing_reset(Timing *t)
{
    evq_clear(&t->q);
    t->now = 0;
    memset(t->pending, 0, sizeof t->pending);
    t->tagseq = 0;
    memset(t->unit_pending, 0, sizeof t->unit_pending);
    t->fetch_pending = 0;
    t->part_busy = 0;
    t->part_s = t->part_e = 0;
    t->aq_head = t->aq_n = 0;
    t->agu_free = 0;
    t->agu_ivl_n = 0;
    t->dp.s = t->dp.e = 0;
    smem_reset(&t->sm);
    t->halted = 0;
}

const TimingStats *timing_stats(const Timing *t)
{
    /* The scene-memory counters live in SceneMem; copy them in. */
    ((Timing *)t)->st.scene = t->sm.st;
    return &t->st;
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
    t->st.stage_cycles[stage] += cycles;
    t->st.gen_cycles[gen] += cycles;
    t->st.gen_stalls[gen][cause] += cycles;
}

static void internal_error(Timing *t, const char *msg)
{
    if (!t->err[0])
        snprintf(t->err, sizeof t->err, "timing model: internal error: %s", msg);
}

/* ---- events ------------------------------------------------------------------------------- */

static void push(Timing *t, uint64_t time, int kind, int arg, uint32_t tag, int cause)
{
    if (evq_push(&t->q, time, (uint8_t)kind, (uint16_t)arg, tag, (uint8_t)cause))
        internal_error(t, "out of memory for events");
}

/* Apply every event due by cycle `at`. */
static void drain(Timing *t, uint64_t at)
{
    const EvEvent *e;
    while ((e = evq_top(&t->q)) && e->time <= at) {
        switch (e->kind) {
        case EV_REG:
            if (t->rtag[e->arg] == e->tag)
                t->pending[e->arg] = 0;
            break;
        case EV_UNIT: t->unit_pending[e->arg] = 0; break;
        case EV_FETCH: t->fetch_pending = 0; break;
        case EV_PART: t->part_busy = 0; break;
        }
        evq_pop(&t->q);
    }
}

/* ---- the interconnect --------------------------------------------------------------------- */

/* The first cycle s >= from at which a transfer of len cycles finds a free port in each of its
 * cycles, given the other users' transfers. */
static uint64_t icn_earliest(Timing *t, uint64_t from, uint64_t len, int user)
{
    Ivl iv[IVL_MAX + 2];
    int n = 0;
    if (user != USER_PART && t->part_e > from)
        iv[n++] = (Ivl){t->part_s, t->part_e};
    if (user != USER_AGU)
        for (int i = 0; i < t->agu_ivl_n; i++)
            if (t->agu_ivl[i].e > from)
                iv[n++] = t->agu_ivl[i];
    if (user != USER_DP && t->dp.e > from)
        iv[n++] = t->dp;
    uint64_t s = from;
    for (;;) {
        /* The most ports taken at any cycle of [s, s + len): check s and every start inside. */
        int worst = 0;
        for (int a = -1; a < n; a++) {
            uint64_t pt = a < 0 ? s : iv[a].s;
            if (pt < s || pt >= s + len)
                continue;
            int used = 0;
            for (int b = 0; b < n; b++)
                used += iv[b].s <= pt && pt < iv[b].e;
            if (used > worst)
                worst = used;
        }
        if (worst < t->p.icn_ports)
            return s;
        uint64_t next = UINT64_MAX;
        for (int b = 0; b < n; b++)
            if (iv[b].e > s && iv[b].s < s + len && iv[b].e < next)
                next = iv[b].e;
        s = next;
    }
}

static void agu_ivl_add(Timing *t, uint64_t s, uint64_t e)
{
    /* Drop transfers that ended before the present. */
    int k = 0;
    for (int i = 0; i < t->agu_ivl_n; i++)
        if (t->agu_ivl[i].e > t->now)
            t->agu_ivl[k++] = t->agu_ivl[i];
    t->agu_ivl_n = k;
    if (k == IVL_MAX) {
        internal_error(t, "too many AGU transfers in flight");
        return;
    }
    t->agu_ivl[t->agu_ivl_n++] = (Ivl){s, e};
}

/* ---- the address-generation units --------------------------------------------------------- */

static int overlaps_partition(const Timing *t, uint32_t lo, uint32_t hi)
{
    return t->part_busy && lo < t->part_hi && t->part_lo < hi;
}

/* Schedule the fetch of n IDs at addr, starting no earlier than `from`. */
static AguEntry agu_fetch(Timing *t, uint32_t addr, uint32_t n, uint64_t from)
{
    AguEntry e = {addr, n, 0, 0, 0};
    uint64_t s = from > t->agu_free ? from : t->agu_free;
    if (overlaps_partition(t, addr, addr + 4 * n) && t->part_e > s) {
        s = t->part_e;
        e.part_end = s;
    }
    uint64_t x = (n + (uint32_t)t->p.agu_ids_per_cycle - 1) / (uint32_t)t->p.agu_ids_per_cycle;
    uint64_t g = icn_earliest(t, s, x, USER_AGU);
    e.icn_delay = g - s;
    t->st.icn_unit_delay += g - s;
    agu_ivl_add(t, g, g + x);
    t->agu_free = g + x;
    e.ready = g + x + (uint64_t)t->p.lat[ISA_U_AGU];
    t->st.agu_fetches++;
    return e;
}

/* sfetch of k IDs at addr with `avail` IDs left in the stream: wait for the vector (charged to
 * partition, interconnect and address fetch in turn), then fetch ahead. Returns the issue cycle. */
static uint64_t agu_serve(Timing *t, uint32_t addr, uint32_t k, uint32_t avail, uint64_t at, int stage, int gen)
{
    AguEntry e;
    if (t->aq_n > 0 && t->aq[t->aq_head].addr == addr && t->aq[t->aq_head].n == k) {
        e = t->aq[t->aq_head];
        t->aq_head = (t->aq_head + 1) % AGU_MAX;
        t->aq_n--;
        t->st.agu_ahead++;
    } else {
        t->aq_n = 0; /* another stream: what was fetched ahead is dropped */
        e = agu_fetch(t, addr, k, at);
    }
    if (e.ready > at) {
        uint64_t wait = e.ready - at, c;
        c = e.part_end > at ? e.part_end - at : 0;
        c = c < wait ? c : wait;
        charge(t, TM_PARTITION, c, stage, gen);
        wait -= c;
        c = e.icn_delay < wait ? e.icn_delay : wait;
        charge(t, TM_INTERCONNECT, c, stage, gen);
        wait -= c;
        charge(t, TM_ADDRESS_FETCH, wait, stage, gen);
        at = e.ready;
    }
    /* Run ahead: fetch the stream's next vectors, up to the queue depth. */
    uint32_t next = addr + 4 * k, left = avail > k ? avail - k : 0;
    for (int i = 0; i < t->aq_n; i++) {
        const AguEntry *q = &t->aq[(t->aq_head + i) % AGU_MAX];
        if (q->addr != next || q->n > left) { /* the stream changed under the queue: keep what still fits */
            t->aq_n = i;
            break;
        }
        next = q->addr + 4 * q->n;
        left -= q->n;
    }
    while (t->aq_n < t->p.agu_depth && left > 0) {
        uint32_t n = left < (uint32_t)t->p.lanes ? left : (uint32_t)t->p.lanes;
        t->aq[(t->aq_head + t->aq_n) % AGU_MAX] = agu_fetch(t, next, n, at);
        t->aq_n++;
        next += 4 * n;
        left -= n;
    }
    return at;
}

/* ---- memories: distinct lines ------------------------------------------------------------- */

/* Distinct values among v[0..n) (small n; lanes of one access). Writes them to out. */
static int distinct(const uint64_t *v, int n, uint64_t *out)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (k && out[k - 1] == v[i])
            continue;
        int seen = 0;
        for (int j = 0; j < k; j++)
            if (out[j] == v[i]) {
                seen = 1;
                break;
            }
        if (!seen)
            out[k++] = v[i];
    }
    return k;
}

/* Ray-buffer access: the cycles the banks need (the most distinct lines any bank serves). */
static int rb_bank_cycles(Timing *t, const CoreRecord *rec, int *nlines)
{
    uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
    for (int i = 0; i < rec->naddr; i++)
        lines[i] = rec->addr[i] >> t->rb_shift;
    int k = distinct(lines, rec->naddr, d);
    *nlines = k;
    if (++t->stamp == 0) {
        memset(t->bank_stamp, 0, (size_t)t->p.rb_banks * sizeof *t->bank_stamp);
        t->stamp = 1;
    }
    int worst = 0;
    for (int i = 0; i < k; i++) {
        uint32_t b = (uint32_t)(d[i] % (uint64_t)t->p.rb_banks);
        if (t->bank_stamp[b] != t->stamp) {
            t->bank_stamp[b] = t->stamp;
            t->bank_cnt[b] = 0;
        }
        if (++t->bank_cnt[b] > worst)
            worst = t->bank_cnt[b];
    }
    return worst;
}

/* ---- one instruction ---------------------------------------------------------------------- */

static inline int reg_id(int kind, int num)
{
    return kind == ISA_K_R ? num : kind == ISA_K_V ? ISA_NUM_SREGS + num : ISA_NUM_SREGS + ISA_NUM_VREGS + num;
}

static inline int field_val(const IsaInstr *in, int f)
{
    return f == ISA_FIELD_A ? in->a : f == ISA_FIELD_B ? in->b : f == ISA_FIELD_C ? in->c : in->d;
}

/* The highest-priority hazard that an event will clear, or -1. */
static int hazard(const Timing *t, const CoreRecord *rec, const int *regs, int nregs, int unit, int is_halt)
{
    if (t->fetch_pending)
        return TM_CONTROL;
    for (int i = 0; i < nregs; i++)
        if (t->pending[regs[i]])
            return t->rcause[regs[i]];
    if (t->unit_pending[unit])
        return TM_FU_BUSY;
    if (t->part_busy) {
        int op = rec->in->op;
        if (op == ISA_OP_PMASK || op == ISA_OP_PART || op == ISA_OP_PCLR)
            return TM_PARTITION;
        if ((op == ISA_OP_SLD || op == ISA_OP_SST || op == ISA_OP_SAPP) && rec->naddr > 0) {
            uint32_t lo = rec->addr[0], hi = rec->addr[rec->naddr - 1] + 4;
            if (overlaps_partition(t, lo, hi))
                return TM_PARTITION;
        }
    }
    if (is_halt) { /* the program ends when every result in flight has landed */
        if (t->part_busy)
            return TM_PARTITION;
        for (int r = 0; r < NREGS; r++)
            if (t->pending[r])
                return t->rcause[r];
    }
    return -1;
}

static void set_ready(Timing *t, int reg, uint64_t ready, uint64_t end, int cause)
{
    if (ready <= end) { /* ready by the next issue slot: nothing can wait for it */
        t->pending[reg] = 0;
        return;
    }
    t->pending[reg] = 1;
    t->rcause[reg] = (uint8_t)cause;
    t->rtag[reg] = ++t->tagseq;
    push(t, ready, EV_REG, reg, t->tagseq, cause);
}

void timing_hook(void *ctx, const CoreRecord *rec)
{
    Timing *t = ctx;
    const IsaInstr *in = rec->in;
    const int op = in->op;
    const IsaOpInfo *oi = &isa_ops[op];
    const OpRegs *orr = &t->ops[op];
    const int unit = oi->unit, stage = rec->stage, gen = rec->gen;
    const int is_halt = (oi->flags & ISA_FL_END) != 0;
    if (t->halted) { /* a halted core is not run again before timing_reset */
        internal_error(t, "instruction after halt");
        return;
    }

    int regs[2 * ISA_MAX_OPERANDS + 1], nregs = 0;
    for (int i = 0; i < orr->nsrc; i++)
        regs[nregs++] = reg_id(orr->src_kind[i], field_val(in, orr->src_field[i]));
    if (orr->mask_src)
        regs[nregs++] = reg_id(ISA_K_M, in->mask);
    int dsts[ISA_MAX_OPERANDS], ndst = 0;
    for (int i = 0; i < orr->ndst; i++) /* the destination too: no write after a pending write */
        regs[nregs++] = dsts[ndst++] = reg_id(orr->dst_kind[i], field_val(in, orr->dst_field[i]));

    /* 1. hazards cleared by events */
    uint64_t at = t->now;
    for (;;) {
        drain(t, at);
        int cause = hazard(t, rec, regs, nregs, unit, is_halt);
        if (cause < 0)
            break;
        const EvEvent *e = evq_top(&t->q);
        if (!e || e->time <= at) {
            internal_error(t, "a hazard with no event to clear it");
            break;
        }
        charge(t, cause, e->time - at, stage, gen);
        at = e->time;
    }

    /* 2. waits on units working ahead, and per-access issue cycles */
    uint64_t extra[TM_CAUSE_COUNT];       /* extra issue cycles by cause; valid where has_extra says */
    unsigned has_extra = 0;
    int rb_cycles = 0;
    uint64_t ready = 0;          /* result time for memory loads (0: by unit latency) */
    int res_cause = TM_DATA_DEPENDENCY;
    switch (op) {
    case ISA_OP_SFETCH:
        if (rec->naddr > 0) {
            at = agu_serve(t, rec->base, rec->naddr, rec->count, at, stage, gen);
            if (rec->base & (uint32_t)(t->p.rb_line - 1))
                if (t->p.align_cycles) {
                    extra[TM_ALIGNMENT] = (uint64_t)t->p.align_cycles;
                    has_extra |= 1u << TM_ALIGNMENT;
                }
        }
        break;
    case ISA_OP_SAPP:
        if (rec->naddr > 0) {
            uint64_t g = icn_earliest(t, at, 1, USER_DP);
            charge(t, TM_INTERCONNECT, g - at, stage, gen);
            at = g;
            t->dp = (Ivl){at, at + 1};
            t->st.icn_transfers++;
            if (rec->base & (uint32_t)(t->p.rb_line - 1))
                if (t->p.align_cycles) {
                    extra[TM_ALIGNMENT] = (uint64_t)t->p.align_cycles;
                    has_extra |= 1u << TM_ALIGNMENT;
                }
        }
        break;
    case ISA_OP_RGAT:
    case ISA_OP_RGATN:
    case ISA_OP_RSCT:
    case ISA_OP_RSCTN:
        if (rec->naddr > 0) {
            int nl;
            rb_cycles = rb_bank_cycles(t, rec, &nl);
            uint64_t g = icn_earliest(t, at, (uint64_t)rb_cycles, USER_DP);
            charge(t, TM_INTERCONNECT, g - at, stage, gen);
            at = g;
            t->dp = (Ivl){at, at + (uint64_t)rb_cycles};
            if (rb_cycles > 1) {
                extra[TM_BANK_CONFLICT] = (uint64_t)rb_cycles - 1;
                has_extra |= 1u << TM_BANK_CONFLICT;
            }
            t->st.rb_accesses++;
            t->st.rb_lines += (uint64_t)nl;
            t->st.rb_conflicted += rb_cycles > 1;
            t->st.icn_transfers++;
        }
        break;
    case ISA_OP_SPLD:
    case ISA_OP_SPST:
    case ISA_OP_VSPLD:
    case ISA_OP_VSPST:
        if (rec->naddr > 0) {
            uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
            for (int i = 0; i < rec->naddr; i++)
                lines[i] = rec->addr[i] >> t->spad_shift;
            int k = distinct(lines, rec->naddr, d);
            uint64_t cyc = ((uint64_t)k + (uint64_t)t->p.spad_ports - 1) / (uint64_t)t->p.spad_ports;
            if (cyc > 1) {
                extra[TM_SCRATCHPAD] = cyc - 1;
                has_extra |= 1u << TM_SCRATCHPAD;
            }
            t->st.spad_accesses++;
            t->st.spad_lines += (uint64_t)k;
        }
        break;
    default:
        break;
    }

    /* 3. issue */
    uint64_t ext = 0;
    for (int c = 0; has_extra && c < TM_CAUSE_COUNT; c++)
        if (has_extra & (1u << c)) {
            charge(t, c, extra[c], stage, gen);
            ext += extra[c];
        }
    /* Scene memory and framebuffer: ceil(lines / ports) port cycles, one line per port-slot. */
    if ((oi->flags & (ISA_FL_SCENE | ISA_FL_FB)) && rec->naddr > 0) {
        int space = (oi->flags & ISA_FL_FB) ? 1 : 0;
        int write = op == ISA_OP_ST || op == ISA_OP_FBADD;
        uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
        for (int i = 0; i < rec->naddr; i++)
            lines[i] = smem_line(&t->sm, space, rec->addr[i]);
        int k = distinct(lines, rec->naddr, d);
        for (int i = 0; i < k; i++) {
            uint64_t slot = at + ext + (uint64_t)(i / t->p.scene_ports);
            uint32_t addr = (uint32_t)((d[i] << t->sm.line_shift) & 0xffffffffu);
            uint64_t r = smem_access(&t->sm, space, addr, slot, write);
            if (r == UINT64_MAX)
                internal_error(t, "out of memory for the scene cache");
            if (r > ready)
                ready = r;
        }
        uint64_t cyc = ((uint64_t)k + (uint64_t)t->p.scene_ports - 1) / (uint64_t)t->p.scene_ports;
        charge(t, TM_SCENE_MEMORY, cyc - 1, stage, gen);
        ext += cyc - 1;
        res_cause = TM_SCENE_MEMORY;
        t->st.scene_instr++;
    }
    t->st.busy++;
    t->st.stage_busy[stage]++;
    t->st.stage_cycles[stage]++;
    t->st.gen_cycles[gen]++;
    t->st.gen_busy[gen]++;
    if (oi->flags & ISA_FL_VEC)
        t->st.stage_vec_busy[stage]++;
    t->st.unit_uses[unit]++;
    const uint64_t last = at + ext;     /* the instruction's last issue cycle */
    const uint64_t end = last + 1;      /* the next instruction's earliest issue cycle */

    /* 4. completion */
    switch (op) {
    case ISA_OP_RGAT:
    case ISA_OP_RGATN:
        ready = last + (uint64_t)t->p.rb_access + (uint64_t)t->p.icn_latency;
        break;
    case ISA_OP_SLD:
        ready = last + (uint64_t)t->p.rb_access;
        break;
    case ISA_OP_SPLD:
    case ISA_OP_VSPLD:
        ready = last + (uint64_t)t->p.spad_latency;
        break;
    case ISA_OP_SFETCH:
    case ISA_OP_SAPP:
        ready = end;
        break;
    case ISA_OP_PART: {
        uint64_t cost = (uint64_t)t->p.part_setup +
                        (rec->count + (uint64_t)t->p.part_ids_per_cycle - 1) / (uint64_t)t->p.part_ids_per_cycle;
        uint64_t s = icn_earliest(t, at, cost ? cost : 1, USER_PART);
        t->st.icn_unit_delay += s - at;
        t->part_s = s;
        t->part_e = s + cost;
        t->part_lo = rec->base;
        t->part_hi = rec->base + 4 * rec->count;
        if (t->part_e > end) {
            t->part_busy = 1;
            push(t, t->part_e, EV_PART, 0, 0, TM_PARTITION);
        }
        /* IDs fetched ahead from the range being reordered are stale: drop them. */
        for (int i = 0; i < t->aq_n; i++) {
            const AguEntry *q = &t->aq[(t->aq_head + i) % AGU_MAX];
            if (q->addr < t->part_hi && t->part_lo < q->addr + 4 * q->n) {
                t->aq_n = 0;
                break;
            }
        }
        ready = t->part_e;
        res_cause = TM_PARTITION;
        t->st.partitions++;
        t->st.partition_ids += rec->count;
        t->st.partition_cycles += cost;
        break;
    }
    default:
        if (!ready)
            ready = at + (uint64_t)t->p.lat[unit];
        break;
    }
    if (unit == ISA_U_AGU && op != ISA_OP_SFETCH && op != ISA_OP_SAPP && op != ISA_OP_SLD)
        res_cause = TM_ADDRESS_FETCH;
    for (int i = 0; i < ndst; i++)
        set_ready(t, dsts[i], ready, end, res_cause);
    if (t->p.issue[unit] > 1 && at + (uint64_t)t->p.issue[unit] > end) {
        t->unit_pending[unit] = 1;
        push(t, at + (uint64_t)t->p.issue[unit], EV_UNIT, unit, 0, TM_FU_BUSY);
    }
    if (rec->taken && t->p.taken_penalty > 0) {
        t->fetch_pending = 1;
        push(t, end + (uint64_t)t->p.taken_penalty, EV_FETCH, 0, 0, TM_CONTROL);
    }
    t->now = end;
    if (is_halt) {
        t->st.cycles += end;
        t->st.runs++;
        t->halted = 1;
    }
}

void timing_end(Timing *t)
{
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
