/* sim/mem/dram_sched.c -- the DRAM's simulation: per channel an FR-FCFS controller with a read and a
 * write queue, write draining, all-bank refresh, and the banks' state machines; the completions.
 *
 * Owns: when each command issues. Every timing rule is kept as "the earliest cycle command X may
 * issue" in the bank, bank group, rank and channel, so a command is legal at t exactly when t is
 * not below each of its earliest cycles; the next cycle anything can happen is the smallest of
 * them, and the controller jumps there instead of ticking idle cycles (dram_set_tick_every_cycle
 * makes it tick, for the test that both give the same results). Must not: use floating point,
 * depend on the host, print, or exit. docs/dram.md describes the policy.
 */
#include <stdlib.h>
#include <string.h>

#include "dram.h"

typedef struct Req {
    uint64_t id, arrival;
    int32_t row;
    int16_t bank;          /* flat index in the channel: (rank x bankgroups + bg) x banks + ba */
    uint8_t rank, bg, write, outcome;
} Req;

enum { OUT_HIT = 0, OUT_MISS = 1, OUT_CONFLICT = 2 };

typedef struct Bank {
    int32_t open_row;                  /* -1: precharged */
    uint64_t t_act, t_pre, t_col;      /* earliest ACT, PRE, RD/WR */
} Bank;

typedef struct Group {
    uint64_t act_l, col_l, rd_l;       /* earliest ACT (tRRD_L), RD/WR (tCCD_L), RD (tWTR_L) */
} Group;

typedef struct Rank {
    uint64_t act_s, col_s, rd_s;       /* the same across bank groups (_S) */
    uint64_t faw[4];                   /* the last four ACTs, a ring */
    int faw_n, faw_i;
    uint64_t ref_due;
    int ref_pending;
    /* Its banks open, and since when (counted into active_cycles up to each dram_run's end); an
     * auto-precharge closes its bank at closed_at, maybe after the command that caused it. */
    int nopen;
    uint64_t open_since, closed_at;
} Rank;

typedef struct Queue {
    Req *e;
    int n, cap;
} Queue;

typedef struct Fifo {
    Req *e;
    size_t head, n, cap;
} Fifo;

typedef struct Chan {
    Bank *bank;
    Group *grp;
    Rank *rank;
    uint16_t *hits[2];                 /* per bank: requests of queue [w] that hit its open row */
    uint32_t *col_mark, *act_mark;     /* per bank: == mark when col_at / act_at hold this pass's value */
    uint64_t *col_at, *act_at;         /* per bank: earliest RD/WR, ACT (one pass: the state is fixed) */
    uint32_t mark;                     /* one evaluation pass of the queue */
    Queue q[2];                        /* [0] reads, [1] writes, oldest first */
    Fifo wait[2];                      /* requests waiting for a slot */
    int mode;                          /* 0 serving reads, 1 draining writes */
    uint64_t cmd_ok;                   /* one command per cycle: last command + 1 */
    uint64_t bus_free;                 /* end of the last data burst */
    int last_dir, last_rank;           /* of that burst; last_dir -1: none yet */
    uint64_t next, cursor, occ_t;
    DramChanStats *st;
} Chan;

typedef struct Done {
    uint64_t cycle, id;
    int write;
} Done;

struct Dram {
    DramParams p;
    Chan *ch;
    DramStats *stats;          /* its total is summed by dram_stats, on demand */
    Done *heap;
    size_t nheap, capheap;
    uint64_t now, outstanding;
    int tick, nbanks;
};

static uint64_t max64(uint64_t a, uint64_t b)
{
    return a > b ? a : b;
}

/* ---- completions: a min-heap on (cycle, id) --------------------------------------------------- */

static int done_less(const Done *a, const Done *b)
{
    return a->cycle != b->cycle ? a->cycle < b->cycle : a->id < b->id;
}

static void heap_push(Dram *d, Done x)
{
    if (d->nheap == d->capheap) {
        size_t cap = d->capheap ? 2 * d->capheap : 256;
        Done *n = realloc(d->heap, cap * sizeof *n);
        if (!n)
            abort(); /* out of memory in the timing loop: nothing sensible to return */
        d->heap = n;
        d->capheap = cap;
    }
    size_t i = d->nheap++;
    while (i && done_less(&x, &d->heap[(i - 1) / 2])) {
        d->heap[i] = d->heap[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    d->heap[i] = x;
}

static Done heap_pop(Dram *d)
{
    Done top = d->heap[0], x = d->heap[--d->nheap];
    size_t i = 0;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= d->nheap)
            break;
        if (c + 1 < d->nheap && done_less(&d->heap[c + 1], &d->heap[c]))
            c++;
        if (!done_less(&d->heap[c], &x))
            break;
        d->heap[i] = d->heap[c];
        i = c;
    }
    if (d->nheap)
        d->heap[i] = x;
    return top;
}

/* ---- the waiting FIFO --------------------------------------------------------------------------- */

static void fifo_push(Fifo *f, Req r)
{
    if (f->n == f->cap) {
        size_t cap = f->cap ? 2 * f->cap : 64;
        Req *n = malloc(cap * sizeof *n);
        if (!n)
            abort();
        for (size_t i = 0; i < f->n; i++)
            n[i] = f->e[(f->head + i) % f->cap];
        free(f->e);
        f->e = n;
        f->head = 0;
        f->cap = cap;
    }
    f->e[(f->head + f->n++) % f->cap] = r;
}

/* ---- timing rules: the earliest cycle of each command ------------------------------------------ */

static Bank *bank_of(const Dram *d, const Chan *c, const Req *r)
{
    (void)d;
    return &c->bank[r->bank];
}

static Group *group_of(const Dram *d, const Chan *c, const Req *r)
{
    return &c->grp[r->rank * d->p.bankgroups + r->bg];
}

/* Idle bus cycles a burst in direction dir of rank needs after the last one. */
static uint64_t bus_gap(const Dram *d, const Chan *c, int dir, int rank)
{
    if (c->last_dir < 0)
        return 0;
    uint64_t g = c->last_rank != rank ? (uint64_t)d->p.trtrs : 0;
    if (c->last_dir == 0 && dir == 1)
        g = max64(g, (uint64_t)d->p.trtw);
    return g;
}

static uint64_t col_time(const Dram *d, const Chan *c, const Req *r)
{
    const Bank *b = bank_of(d, c, r);
    const Group *g = group_of(d, c, r);
    const Rank *k = &c->rank[r->rank];
    uint64_t e = max64(max64(b->t_col, c->cmd_ok), max64(k->col_s, g->col_l));
    uint64_t lat = (uint64_t)(r->write ? d->p.cwl : d->p.cl);
    uint64_t data = c->bus_free + bus_gap(d, c, r->write, r->rank); /* first free data cycle */
    if (data > lat)
        e = max64(e, data - lat);
    if (!r->write)
        e = max64(e, max64(k->rd_s, g->rd_l));
    return e;
}

static uint64_t act_time(const Dram *d, const Chan *c, const Req *r)
{
    const Rank *k = &c->rank[r->rank];
    uint64_t e = max64(max64(bank_of(d, c, r)->t_act, c->cmd_ok), max64(k->act_s, group_of(d, c, r)->act_l));
    if (k->faw_n == 4)
        e = max64(e, k->faw[k->faw_i] + (uint64_t)d->p.tfaw); /* faw_i: the oldest of the four */
    return e;
}

enum { CMD_NONE, CMD_COL, CMD_ACT, CMD_PRE };

/* The command r needs next and its earliest cycle (CMD_NONE: none while the rank waits for a
 * refresh, or its bank's open row still has queued hits). Every request of the queue being served
 * goes one way (reads or writes), so the times depend on its bank alone: computed once a pass.
 * Inlined into the queue pass, the hottest loop of a replay (about 8 % faster than a call). */
static inline __attribute__((always_inline)) int req_cmd(const Dram *d, Chan *c, const Req *r,
                                                          uint64_t *when)
{
    const Bank *b = bank_of(d, c, r);
    int k = r->bank;
    if (c->rank[r->rank].ref_pending)
        return CMD_NONE;
    if (b->open_row == r->row) {
        if (c->col_mark[k] != c->mark) {
            c->col_mark[k] = c->mark;
            c->col_at[k] = col_time(d, c, r);
        }
        *when = c->col_at[k];
        return CMD_COL;
    }
    if (b->open_row < 0) {
        if (c->act_mark[k] != c->mark) {
            c->act_mark[k] = c->mark;
            c->act_at[k] = act_time(d, c, r);
        }
        *when = c->act_at[k];
        return CMD_ACT;
    }
    if (c->hits[c->mode][k])
        return CMD_NONE;
    *when = max64(b->t_pre, c->cmd_ok);
    return CMD_PRE;
}

/* A new evaluation pass: the per-bank times computed in the last one are stale. */
static void new_pass(const Dram *d, Chan *c)
{
    if (++c->mark == 0) {
        memset(c->col_mark, 0, (size_t)d->nbanks * sizeof *c->col_mark);
        memset(c->act_mark, 0, (size_t)d->nbanks * sizeof *c->act_mark);
        c->mark = 1;
    }
}

/* The queued hits of bank k, counted afresh (when it opens a row; and, ticking, as a check of the
 * counts kept as requests come and go). */
static void count_hits(Chan *c, int k, int w)
{
    uint16_t n = 0;
    for (int i = 0; i < c->q[w].n; i++)
        n += c->q[w].e[i].bank == k && c->q[w].e[i].row == c->bank[k].open_row;
    c->hits[w][k] = n;
}

/* ---- issuing commands --------------------------------------------------------------------------- */

static void issue_act(const Dram *d, Chan *c, Req *r, uint64_t t)
{
    Bank *b = bank_of(d, c, r);
    Group *g = group_of(d, c, r);
    Rank *k = &c->rank[r->rank];
    b->open_row = r->row;
    count_hits(c, r->bank, 0);
    count_hits(c, r->bank, 1);
    b->t_col = t + (uint64_t)d->p.trcd;
    b->t_pre = t + (uint64_t)d->p.tras;
    b->t_act = t + (uint64_t)d->p.trc;
    k->act_s = max64(k->act_s, t + (uint64_t)d->p.trrd_s);
    g->act_l = max64(g->act_l, t + (uint64_t)d->p.trrd_l);
    if (k->faw_n < 4) {
        k->faw[(k->faw_i + k->faw_n++) % 4] = t;
    } else {
        k->faw[k->faw_i] = t;
        k->faw_i = (k->faw_i + 1) % 4;
    }
    if (k->nopen++ == 0)
        k->open_since = max64(t, k->closed_at);
    c->cmd_ok = t + 1;
    c->st->activates++;
    if (r->outcome == OUT_HIT)
        r->outcome = OUT_MISS;
}

/* A bank of rank rk closes at t: the rank's active time ends with its last open bank. */
static void rank_close(Chan *c, Rank *rk, uint64_t t)
{
    if (--rk->nopen == 0) {
        if (t > rk->open_since)
            c->st->active_cycles += t - rk->open_since;
        rk->closed_at = t;
    }
}

static void issue_pre(const Dram *d, Chan *c, int k, uint64_t t)
{
    Bank *b = &c->bank[k];
    rank_close(c, &c->rank[k / (d->p.bankgroups * d->p.banks)], t);
    b->open_row = -1;
    c->hits[0][k] = c->hits[1][k] = 0;
    b->t_act = max64(b->t_act, t + (uint64_t)d->p.trp);
    c->cmd_ok = t + 1;
    c->st->precharges++;
}

static void issue_ref(const Dram *d, Chan *c, int rank, uint64_t t)
{
    int per = d->p.bankgroups * d->p.banks;
    for (int i = rank * per; i < (rank + 1) * per; i++)
        c->bank[i].t_act = max64(c->bank[i].t_act, t + (uint64_t)d->p.trfc);
    c->rank[rank].ref_pending = 0;
    c->rank[rank].ref_due += (uint64_t)d->p.trefi;
    c->cmd_ok = t + 1;
    c->st->refreshes++;
    c->st->refresh_cycles += (uint64_t)d->p.trfc;
}

static void account(Dram *d, Chan *c, const Req *r, uint64_t end)
{
    DramChanStats *s = c->st;
    uint64_t lat = end - r->arrival;
    if (r->write) {
        s->writes++;
        s->write_latency += lat;
    } else {
        s->reads++;
        s->read_latency += lat;
    }
    s->row_hits += r->outcome == OUT_HIT;
    s->row_misses += r->outcome == OUT_MISS;
    s->row_conflicts += r->outcome == OUT_CONFLICT;
    s->bytes += (uint64_t)d->p.burst_bytes;
    s->busy_cycles += (uint64_t)d->p.burst_cycles;
    if (lat > s->max_latency)
        s->max_latency = lat;
    s->hist[dram_hist_bucket(lat)]++;
    heap_push(d, (Done){end, r->id, r->write});
}

/* RD or WR for queue entry i of the queue being served; the entry leaves the queue. */
static void issue_col(Dram *d, Chan *c, int i, uint64_t t)
{
    Queue *q = &c->q[c->mode];
    Req r = q->e[i];
    memmove(&q->e[i], &q->e[i + 1], (size_t)(q->n - i - 1) * sizeof *q->e);
    q->n--;
    Bank *b = bank_of(d, c, &r);
    Group *g = group_of(d, c, &r);
    Rank *k = &c->rank[r.rank];
    const DramParams *p = &d->p;
    c->hits[c->mode][r.bank]--;
    uint64_t start = t + (uint64_t)(r.write ? p->cwl : p->cl), end = start + (uint64_t)p->burst_cycles;
    c->bus_free = end;
    c->last_dir = r.write;
    c->last_rank = r.rank;
    k->col_s = max64(k->col_s, t + (uint64_t)p->tccd_s);
    g->col_l = max64(g->col_l, t + (uint64_t)p->tccd_l);
    if (r.write) {
        k->rd_s = max64(k->rd_s, end + (uint64_t)p->twtr_s);
        g->rd_l = max64(g->rd_l, end + (uint64_t)p->twtr_l);
        b->t_pre = max64(b->t_pre, end + (uint64_t)p->twr);
    } else {
        b->t_pre = max64(b->t_pre, t + (uint64_t)p->trtp);
    }
    c->cmd_ok = t + 1;
    account(d, c, &r, end);
    if (p->page_policy == DRAM_PAGE_CLOSED && !c->hits[0][r.bank] && !c->hits[1][r.bank]) {
        /* auto-precharge: the bank closes at its earliest PRE, without a command slot */
        b->open_row = -1;
        b->t_act = max64(b->t_act, b->t_pre + (uint64_t)p->trp);
        c->st->precharges++;
        rank_close(c, k, b->t_pre);
    }
}

/* A refresh waiting in some rank: precharge its open banks, then REF. 1 when a command issued. */
static int refresh_step(Dram *d, Chan *c, uint64_t t)
{
    int per = d->p.bankgroups * d->p.banks;
    for (int k = 0; k < d->p.ranks; k++) {
        if (!c->rank[k].ref_pending)
            continue;
        int open = 0;
        uint64_t ready = c->cmd_ok;
        for (int i = k * per; i < (k + 1) * per; i++) {
            Bank *b = &c->bank[i];
            if (b->open_row >= 0) {
                open = 1;
                if (t >= max64(b->t_pre, c->cmd_ok)) {
                    issue_pre(d, c, i, t);
                    return 1;
                }
            }
            ready = max64(ready, b->t_act);
        }
        if (!open && t >= ready) {
            issue_ref(d, c, k, t);
            return 1;
        }
    }
    return 0;
}

/* Write draining with hysteresis: start at write_high entries or when no read waits; stop at
 * write_low entries while reads wait, or when the write queue is empty. */
static void update_mode(const Dram *d, Chan *c)
{
    int rq = c->q[0].n, wq = c->q[1].n;
    if (c->mode == 0 && (wq >= d->p.write_high || (rq == 0 && wq > 0)))
        c->mode = 1;
    else if (c->mode == 1 && (wq == 0 || (wq <= d->p.write_low && rq > 0)))
        c->mode = 0;
}

/* The earliest cycle a queued request of bank k can issue its command (DRAM_NEVER: none). */
static uint64_t bank_later(const Dram *d, Chan *c, int k)
{
    const Queue *q = &c->q[c->mode];
    uint64_t n = DRAM_NEVER, when;
    new_pass(d, c);
    for (int i = 0; i < q->n; i++)
        if (q->e[i].bank == k && req_cmd(d, c, &q->e[i], &when) != CMD_NONE && when < n)
            n = when;
    return n;
}

/* The two smallest earliest cycles of a pass, from different banks: after a command to bank k,
 * every other bank's requests can only have grown later (each timing rule only ever moves an
 * earliest cycle up), so the smaller one not of bank k is still a lower bound. */
typedef struct Later {
    uint64_t t1, t2;
    int b1;
} Later;

static void later_add(Later *l, uint64_t when, int bank)
{
    if (when < l->t1) {
        if (bank != l->b1)
            l->t2 = l->t1;
        l->t1 = when;
        l->b1 = bank;
    } else if (bank != l->b1 && when < l->t2) {
        l->t2 = when;
    }
}

static void issue_row(const Dram *d, Chan *c, Req *r, int cmd, uint64_t t)
{
    if (cmd == CMD_ACT) {
        issue_act(d, c, r, t);
    } else {
        issue_pre(d, c, r->bank, t);
        r->outcome = OUT_CONFLICT;
    }
}

/* FR-FCFS: the oldest request whose RD/WR is legal now (a row hit), else the oldest whose ACT or
 * PRE is legal now, issued. *later: a lower bound of the next cycle a queued request's command is
 * legal (DRAM_NEVER: none): after a command to bank k, the pass's bound for the other banks and
 * bank k's requests evaluated afresh; t + 1 when a command of another bank was legal too or the
 * mode changed. Returns 1 when a command issued. */
static int schedule(Dram *d, Chan *c, uint64_t t, uint64_t *later)
{
    *later = t + 1;
    if (refresh_step(d, c, t))
        return 1;
    Queue *q = &c->q[c->mode];
    new_pass(d, c);
    int col = -1, other = -1, other_cmd = CMD_NONE, legal_bank = -1, legal_banks = 0;
    Later l = {DRAM_NEVER, DRAM_NEVER, -1};
    for (int i = 0; i < q->n; i++) {
        uint64_t when;
        int cmd = req_cmd(d, c, &q->e[i], &when);
        if (cmd == CMD_NONE)
            continue;
        if (when > t) {
            later_add(&l, when, q->e[i].bank);
            continue;
        }
        if (legal_bank != q->e[i].bank) /* 1 exactly when every legal command is in one bank */
            legal_banks++;
        legal_bank = q->e[i].bank;
        if (cmd == CMD_COL && col < 0)
            col = i;
        else if (cmd != CMD_COL && other < 0) {
            other = i;
            other_cmd = cmd;
        }
    }
    if (!legal_banks) {
        *later = l.t1;
        return 0;
    }
    int mode = c->mode, k = q->e[col >= 0 ? col : other].bank;
    if (col >= 0)
        issue_col(d, c, col, t);
    else
        issue_row(d, c, &q->e[other], other_cmd, t);
    update_mode(d, c);
    if (legal_banks == 1 && mode == c->mode) { /* bank k's legal ones are evaluated afresh */
        uint64_t rest = l.b1 == k ? l.t2 : l.t1, mine = bank_later(d, c, k);
        *later = rest < mine ? rest : mine;
    }
    return 1;
}

/* ---- the channel's step and its next event ------------------------------------------------------ */

static void admit(Dram *d, Chan *c, uint64_t t)
{
    const int cap[2] = {d->p.read_queue, d->p.write_queue};
    for (int w = 0; w < 2; w++) {
        Fifo *f = &c->wait[w];
        while (f->n && f->e[f->head].arrival <= t && c->q[w].n < cap[w]) {
            Req r = f->e[f->head];
            f->head = (f->head + 1) % f->cap;
            f->n--;
            if (t > r.arrival) {
                c->st->backpressured++;
                c->st->backpressure += t - r.arrival;
            }
            c->q[w].e[c->q[w].n++] = r;
            c->hits[w][r.bank] += c->bank[r.bank].open_row == r.row;
        }
    }
    uint64_t occ = (uint64_t)(c->q[0].n + c->q[1].n);
    if (occ > c->st->occupancy_max)
        c->st->occupancy_max = occ;
}

/* The first cycle after t at which the channel may do something, given later (the earliest
 * command of a queued request): a request arrives at a free slot, a refresh falls due, or a
 * waiting refresh's PRE or REF becomes legal. */
static uint64_t next_event(const Dram *d, const Chan *c, uint64_t t, uint64_t later)
{
    uint64_t n = later;
    const int cap[2] = {d->p.read_queue, d->p.write_queue};
    int per = d->p.bankgroups * d->p.banks;
    for (int w = 0; w < 2; w++)
        if (c->wait[w].n && c->q[w].n < cap[w])
            n = c->wait[w].e[c->wait[w].head].arrival < n ? c->wait[w].e[c->wait[w].head].arrival : n;
    for (int k = 0; k < d->p.ranks; k++) {
        if (!c->rank[k].ref_pending) {
            n = c->rank[k].ref_due < n ? c->rank[k].ref_due : n;
            continue;
        }
        int open = 0;
        uint64_t ready = c->cmd_ok;
        for (int i = k * per; i < (k + 1) * per; i++) {
            if (c->bank[i].open_row >= 0) {
                open = 1;
                uint64_t e = max64(c->bank[i].t_pre, c->cmd_ok);
                n = e < n ? e : n;
            }
            ready = max64(ready, c->bank[i].t_act);
        }
        if (!open)
            n = ready < n ? ready : n;
    }
    return n <= t ? t + 1 : n;
}

/* One cycle of the channel: arrivals enter, refreshes fall due, the mode is chosen, at most one
 * command issues; then the next step is the earliest cycle anything may become legal. */
static void step(Dram *d, Chan *c, uint64_t t)
{
    c->st->occupancy_sum += (uint64_t)(c->q[0].n + c->q[1].n) * (t - c->occ_t);
    c->occ_t = t;
    admit(d, c, t);
    for (int k = 0; k < d->p.ranks; k++)
        if (!c->rank[k].ref_pending && t >= c->rank[k].ref_due)
            c->rank[k].ref_pending = 1;
    update_mode(d, c);
    if (d->tick) /* the test hook also checks the hit counts against a fresh count */
        for (int k = 0; k < d->nbanks; k++)
            for (int w = 0; w < 2; w++) {
                uint16_t kept = c->hits[w][k];
                count_hits(c, k, w);
                if (kept != c->hits[w][k])
                    abort();
            }
    uint64_t later;
    schedule(d, c, t, &later);
    c->next = next_event(d, c, t, later);
}

/* ---- the interface ------------------------------------------------------------------------------ */

static void chan_reset(Dram *d, Chan *c)
{
    for (int i = 0; i < d->nbanks; i++) {
        c->bank[i] = (Bank){-1, 0, 0, 0};
        c->hits[0][i] = c->hits[1][i] = 0;
    }
    memset(c->grp, 0, (size_t)(d->p.ranks * d->p.bankgroups) * sizeof *c->grp);
    for (int k = 0; k < d->p.ranks; k++)
        c->rank[k] = (Rank){.ref_due = (uint64_t)d->p.trefi};
    for (int w = 0; w < 2; w++) {
        c->q[w].n = 0;
        c->wait[w].n = c->wait[w].head = 0;
    }
    c->mode = 0;
    c->cmd_ok = c->bus_free = 0;
    c->last_dir = -1;
    c->last_rank = 0;
    c->cursor = c->occ_t = 0;
    c->next = (uint64_t)d->p.trefi;
}

void dram_reset(Dram *d)
{
    for (int i = 0; i < d->p.channels; i++)
        chan_reset(d, &d->ch[i]);
    d->nheap = 0;
    d->now = d->outstanding = 0;
}

static void chan_free(Chan *c)
{
    free(c->bank);
    free(c->grp);
    free(c->rank);
    free(c->hits[0]);
    free(c->hits[1]);
    free(c->col_mark);
    free(c->act_mark);
    free(c->col_at);
    free(c->act_at);
    for (int w = 0; w < 2; w++) {
        free(c->q[w].e);
        free(c->wait[w].e);
    }
}

Dram *dram_new(const DramParams *p, char *err, size_t errlen)
{
    Dram *d = calloc(1, sizeof *d);
    if (!d)
        goto oom;
    d->p = *p;
    if (dram_params_check(&d->p, err, errlen)) {
        free(d);
        return NULL;
    }
    d->nbanks = p->ranks * p->bankgroups * p->banks;
    d->ch = calloc((size_t)p->channels, sizeof *d->ch);
    d->stats = calloc(1, sizeof *d->stats);
    if (d->stats) {
        d->stats->chan = calloc((size_t)p->channels, sizeof *d->stats->chan);
        d->stats->channels = p->channels;
    }
    if (!d->ch || !d->stats || !d->stats->chan)
        goto oom;
    for (int i = 0; i < p->channels; i++) {
        Chan *c = &d->ch[i];
        c->bank = malloc((size_t)d->nbanks * sizeof *c->bank);
        c->grp = malloc((size_t)(p->ranks * p->bankgroups) * sizeof *c->grp);
        c->rank = malloc((size_t)p->ranks * sizeof *c->rank);
        c->hits[0] = calloc((size_t)d->nbanks, sizeof *c->hits[0]);
        c->hits[1] = calloc((size_t)d->nbanks, sizeof *c->hits[1]);
        c->col_mark = calloc((size_t)d->nbanks, sizeof *c->col_mark);
        c->act_mark = calloc((size_t)d->nbanks, sizeof *c->act_mark);
        c->col_at = calloc((size_t)d->nbanks, sizeof *c->col_at);
        c->act_at = calloc((size_t)d->nbanks, sizeof *c->act_at);
        c->q[0].e = malloc((size_t)p->read_queue * sizeof(Req));
        c->q[1].e = malloc((size_t)p->write_queue * sizeof(Req));
        c->st = &d->stats->chan[i];
        if (!c->bank || !c->grp || !c->rank || !c->hits[0] || !c->hits[1] || !c->col_mark || !c->act_mark || !c->col_at ||
            !c->act_at || !c->q[0].e || !c->q[1].e)
            goto oom;
    }
    dram_reset(d);
    return d;
oom:
    snprintf(err, errlen, "dram: out of memory");
    dram_free(d);
    return NULL;
}

void dram_free(Dram *d)
{
    if (!d)
        return;
    for (int i = 0; d->ch && i < d->p.channels; i++)
        chan_free(&d->ch[i]);
    free(d->ch);
    if (d->stats)
        free(d->stats->chan);
    free(d->stats);
    free(d->heap);
    free(d);
}

void dram_warm(Dram *d, uint64_t addr)
{
    if (d->p.page_policy != DRAM_PAGE_OPEN)
        return;
    const DramAddr a = dram_decode(&d->p, addr);
    d->ch[a.ch].bank[(a.ra * d->p.bankgroups + a.bg) * d->p.banks + a.ba].open_row = a.ro;
}

void dram_push(Dram *d, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    DramAddr a = dram_decode(&d->p, addr);
    Chan *c = &d->ch[a.ch];
    if (cycle < d->now)
        cycle = d->now;
    Req r = {id, cycle, a.ro, (int16_t)((a.ra * d->p.bankgroups + a.bg) * d->p.banks + a.ba), (uint8_t)a.ra,
             (uint8_t)a.bg, (uint8_t)(write != 0), OUT_HIT};
    fifo_push(&c->wait[r.write], r);
    d->outstanding++;
    if (cycle < c->next)
        c->next = cycle;
}

uint64_t dram_next(const Dram *d)
{
    uint64_t n = d->nheap ? d->heap[0].cycle : DRAM_NEVER;
    for (int i = 0; i < d->p.channels; i++)
        if (d->ch[i].next < n)
            n = d->ch[i].next;
    return n;
}

uint64_t dram_outstanding(const Dram *d)
{
    return d->outstanding;
}

static void sum_stats(const Dram *d)
{
    DramChanStats *t = &d->stats->total;
    memset(t, 0, sizeof *t);
    for (int i = 0; i < d->p.channels; i++) {
        const DramChanStats *s = &d->stats->chan[i];
#define DRAM_X(name, unit, desc) t->name += s->name;
        DRAM_STATS(DRAM_X)
#undef DRAM_X
        for (int b = 0; b < DRAM_HIST_BUCKETS; b++)
            t->hist[b] += s->hist[b];
        t->max_latency = s->max_latency > t->max_latency ? s->max_latency : t->max_latency;
    }
    /* Summed, occupancy_max would mean nothing: the largest over channels; cycles are common. */
    t->occupancy_max = t->cycles = 0;
    for (int i = 0; i < d->p.channels; i++) {
        t->occupancy_max = max64(t->occupancy_max, d->stats->chan[i].occupancy_max);
        t->cycles = d->stats->chan[i].cycles;
    }
}

void dram_run(Dram *d, uint64_t until, DramDone done, void *ctx)
{
    if (until <= d->now)
        return;
    for (int i = 0; i < d->p.channels; i++) {
        Chan *c = &d->ch[i];
        for (;;) {
            uint64_t t = d->tick ? c->cursor : c->next;
            if (t >= until)
                break;
            step(d, c, t);
            c->cursor = t + 1;
        }
        c->cursor = until;
        c->st->occupancy_sum += (uint64_t)(c->q[0].n + c->q[1].n) * (until - c->occ_t);
        c->occ_t = until;
        c->st->cycles = until;
        for (int k = 0; k < d->p.ranks; k++) { /* the open ranks' time so far */
            Rank *rk = &c->rank[k];
            if (rk->nopen && until > rk->open_since) {
                c->st->active_cycles += until - rk->open_since;
                rk->open_since = until;
            }
        }
    }
    d->now = until;
    while (d->nheap && d->heap[0].cycle < until) {
        Done x = heap_pop(d);
        d->outstanding--;
        if (done)
            done(ctx, x.id, x.write, x.cycle);
    }
}

const DramStats *dram_stats(const Dram *d)
{
    sum_stats(d);
    return d->stats;
}

const DramParams *dram_get_params(const Dram *d)
{
    return &d->p;
}

void dram_set_tick_every_cycle(Dram *d, int on)
{
    d->tick = on != 0;
}
