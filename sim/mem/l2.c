/* sim/mem/l2.c -- the chip's shared, banked L2 (see l2.h; docs/chip.md).
 *
 * Owns: the banks' queues, tags, miss-status registers and the order of the L2's own events.
 * Must not: hold data, or answer a request before every request that arrived before it at its
 * bank was taken (each bank is first come, first served).
 */
#include "l2.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An id below with this bit is a write the L2 sent (a write-back): its answer needs nothing. */
#define L2_BELOW_WRITE ((uint64_t)1 << 63)

typedef struct L2Req {
    uint64_t addr, cycle, id;
    uint8_t write;
} L2Req;

typedef struct L2Wait {         /* a read merged into a miss-status register */
    uint64_t id, cycle;
} L2Wait;

typedef struct L2Mshr {
    int busy;
    uint8_t dirty;              /* a write came while the line was being filled */
    uint32_t way;               /* the way the fill goes to (tag index in its bank) */
    L2Wait *wait;               /* the reads answered at the fill */
    uint32_t nwait, capwait;
} L2Mshr;

typedef struct L2Bank {
    L2Req *q;                   /* the bank's requests in arrival order: a ring of capq */
    uint32_t head, n, capq;
    uint64_t pcycle;            /* the cycle of the last tag access started ... */
    int pused;                  /* ... and how many started in it */
    uint64_t not_before;        /* a stopped bank's next start is at or after the fill that freed it */
    int stopped;                /* the head waits for a register (or a way) */
    uint64_t stopped_at;        /* the cycle it stopped (for mshr_wait) */
    uint64_t *tag;              /* sets x ways: line + 1, 0 = empty */
    uint64_t *lru;
    uint8_t *dirty, *pending;
    L2Mshr *mshr;
    int mshr_busy;
} L2Bank;

struct L2 {
    L2Params p;
    int sets, shift;
    L2Bank *bank;
    uint64_t *live;             /* a bit per bank with requests queued (n > 0), so that a step
                                   looks at those banks only, in bank order (host speed only) */
    int nlive_words;
    MemLevel below;
    uint64_t stamp;
    MemAnswer answer;           /* during l2_run */
    void *actx;
    /* l2_next's answer, kept until a push or a run changes the banks or the level below (nothing
     * else reaches them): the network asks it once per message it steps (host speed only). */
    uint64_t next_at;
    int next_ok, running;       /* (nothing is kept while l2_run changes the banks) */
    L2Stats st;
    L2CoreStats *core;          /* l2_count_cores: ncores of them, else NULL */
    int ncores;
    L2CoreStats *cur;           /* the share of the request being taken (else a sink) */
    L2CoreStats sink;
};

int l2_check(const L2Params *p, char *err, size_t errlen)
{
    if (p->line_bytes < 4 || (p->line_bytes & (p->line_bytes - 1))) {
        snprintf(err, errlen, "l2.line_bytes %d is not a power of two of at least 4", p->line_bytes);
        return -1;
    }
    if (p->ways < 1 || p->banks < 1 || p->ports < 1 || p->mshrs < 1 || p->hit_latency < 1) {
        snprintf(err, errlen, "l2: ways, banks, ports, mshrs and hit_latency must be at least 1");
        return -1;
    }
    const long long per_set = (long long)p->line_bytes * p->ways * p->banks;
    if (p->bytes <= 0 || p->bytes % per_set) {
        snprintf(err, errlen, "l2 size %d bytes is not a whole number of sets of %d ways x %d banks x %d-byte lines",
                 p->bytes, p->ways, p->banks, p->line_bytes);
        return -1;
    }
    return 0;
}

static int bank_alloc(L2Bank *b, size_t n, int mshrs)
{
    b->tag = calloc(n, sizeof *b->tag);
    b->lru = calloc(n, sizeof *b->lru);
    b->dirty = calloc(n, 1);
    b->pending = calloc(n, 1);
    b->mshr = calloc((size_t)mshrs, sizeof *b->mshr);
    return b->tag && b->lru && b->dirty && b->pending && b->mshr ? 0 : -1;
}

L2 *l2_new(const L2Params *p, MemLevel below, char *err, size_t errlen)
{
    if (l2_check(p, err, errlen))
        return NULL;
    L2 *l = calloc(1, sizeof *l);
    if (!l) {
        snprintf(err, errlen, "out of memory for the L2");
        return NULL;
    }
    l->p = *p;
    l->below = below;
    l->cur = &l->sink;
    l->sets = p->bytes / (p->line_bytes * p->ways * p->banks);
    while ((1 << l->shift) < p->line_bytes)
        l->shift++;
    l->bank = calloc((size_t)p->banks, sizeof *l->bank);
    l->nlive_words = (p->banks + 63) / 64;
    l->live = calloc((size_t)l->nlive_words, sizeof *l->live);
    int bad = !l->bank || !l->live;
    for (int i = 0; !bad && i < p->banks; i++)
        bad = bank_alloc(&l->bank[i], (size_t)l->sets * (size_t)p->ways, p->mshrs);
    if (bad) {
        l2_free(l);
        snprintf(err, errlen, "out of memory for the L2's tags");
        return NULL;
    }
    return l;
}

void l2_free(L2 *l)
{
    if (!l)
        return;
    for (int i = 0; l->bank && i < l->p.banks; i++) {
        L2Bank *b = &l->bank[i];
        for (int m = 0; b->mshr && m < l->p.mshrs; m++)
            free(b->mshr[m].wait);
        free(b->q);
        free(b->tag);
        free(b->lru);
        free(b->dirty);
        free(b->pending);
        free(b->mshr);
    }
    free(l->live);
    free(l->bank);
    free(l->core);
    free(l);
}

void l2_reset(L2 *l)
{
    l->next_ok = 0;
    const size_t n = (size_t)l->sets * (size_t)l->p.ways;
    for (int i = 0; i < l->p.banks; i++) {
        L2Bank *b = &l->bank[i];
        b->head = b->n = 0;
        l->live[i >> 6] &= ~((uint64_t)1 << (i & 63));
        b->pcycle = 0;
        b->pused = 0;
        b->not_before = 0;
        b->stopped = 0;
        memset(b->tag, 0, n * sizeof *b->tag);
        memset(b->lru, 0, n * sizeof *b->lru);
        memset(b->dirty, 0, n);
        memset(b->pending, 0, n);
        for (int m = 0; m < l->p.mshrs; m++) {
            b->mshr[m].busy = 0;
            b->mshr[m].nwait = 0;
        }
        b->mshr_busy = 0;
    }
    l->stamp = 0;
}

const L2Stats *l2_stats(const L2 *l) { return &l->st; }

int l2_count_cores(L2 *l, int cores)
{
    L2CoreStats *c = calloc(cores > 0 ? (size_t)cores : 1, sizeof *c);
    if (!c)
        return -1;
    free(l->core);
    l->core = c;
    l->ncores = cores > 0 ? cores : 0;
    return 0;
}

const L2CoreStats *l2_core_stats(const L2 *l, int k)
{
    return l->core && k >= 0 && k < l->ncores ? &l->core[k] : NULL;
}

/* The share a request counts into. */
static L2CoreStats *share_of(L2 *l, uint64_t id)
{
    const uint32_t k = MEM_ID_CORE(id);
    return l->core && k < (uint32_t)l->ncores ? &l->core[k] : &l->sink;
}

static int victim(const L2 *l, const L2Bank *b, size_t base);

static int warm_line(L2 *l, uint64_t addr, int dirty)
{
    const uint64_t line = addr >> l->shift;
    L2Bank *b = &l->bank[line % (uint64_t)l->p.banks];
    const size_t base = (size_t)((line / (uint64_t)l->p.banks) % (uint64_t)l->sets) * (size_t)l->p.ways;
    int w = 0;
    while (w < l->p.ways && b->tag[base + (size_t)w] != line + 1)
        w++;
    const int miss = w == l->p.ways;
    if (miss) { /* (an idle L2 has no way being filled: victim finds one) */
        w = victim(l, b, base);
        b->tag[base + (size_t)w] = line + 1;
        b->dirty[base + (size_t)w] = 0;
    }
    if (dirty)
        b->dirty[base + (size_t)w] = 1;
    b->lru[base + (size_t)w] = ++l->stamp;
    return miss;
}

int l2_warm(L2 *l, uint64_t addr) { return warm_line(l, addr, 0); }

int l2_warm_written(L2 *l, uint64_t addr) { return l->p.write_back ? warm_line(l, addr, 1) : 0; }

void l2_push(L2 *l, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    l->next_ok = 0;
    const uint64_t line = addr >> l->shift;
    const int bi = (int)(line % (uint64_t)l->p.banks);
    L2Bank *b = &l->bank[bi];
    l->live[bi >> 6] |= (uint64_t)1 << (bi & 63);
    if (b->n == b->capq) { /* grow the ring, keeping its order */
        uint32_t cap = b->capq ? 2 * b->capq : 16;
        L2Req *q = malloc(sizeof *q * cap);
        if (!q)
            abort(); /* a queue of a few requests per core: out of memory here is the host's end */
        for (uint32_t i = 0; i < b->n; i++)
            q[i] = b->q[(b->head + i) % b->capq];
        free(b->q);
        b->q = q;
        b->head = 0;
        b->capq = cap;
    }
    b->q[(b->head + b->n) % b->capq] = (L2Req){addr, cycle, id, (uint8_t)(write != 0)};
    b->n++;
}

/* The cycle the bank's head can start its tag access (UINT64_MAX: none, or stopped). */
static uint64_t head_start(const L2 *l, const L2Bank *b)
{
    if (!b->n || b->stopped)
        return UINT64_MAX;
    uint64_t s = b->q[b->head].cycle;
    if (s < b->not_before)
        s = b->not_before;
    if (s <= b->pcycle)
        s = b->pused < l->p.ports ? b->pcycle : b->pcycle + 1;
    return s;
}

/* The earliest of t and the cycles the banks' heads can start. */
static uint64_t banks_next(const L2 *l, uint64_t t)
{
    for (int w = 0; w < l->nlive_words; w++)
        for (uint64_t m = l->live[w]; m; m &= m - 1) {
            const uint64_t s = head_start(l, &l->bank[64 * w + __builtin_ctzll(m)]);
            if (s < t)
                t = s;
        }
    return t;
}

uint64_t l2_next(const L2 *l)
{
    if (l->next_ok)
        return l->next_at;
    const uint64_t t = banks_next(l, l->below.next(l->below.self));
    L2 *m = (L2 *)l; /* (the kept answer: not the level's state) */
    m->next_at = t;
    m->next_ok = !l->running;
    return t;
}

static void answer(L2 *l, uint64_t id, uint64_t cycle) { l->answer(l->actx, id, cycle); }

/* The least recently used way of set (tag index base) not being filled; -1 if all are. */
static int victim(const L2 *l, const L2Bank *b, size_t base)
{
    int v = -1;
    for (int w = 0; w < l->p.ways; w++)
        if (!b->pending[base + (size_t)w] && (v < 0 || b->lru[base + (size_t)w] < b->lru[base + (size_t)v]))
            v = w;
    return v;
}

/* A line written below at cycle at (a write-back or a write through). */
static void write_below(L2 *l, uint64_t addr, uint64_t at)
{
    l->st.writebacks++;
    l->cur->below++;
    l->below.push(l->below.self, addr, 1, at, L2_BELOW_WRITE);
}

/* Empties way k (tag index) for another line, writing its line below at cycle at if dirty. */
static void evict(L2 *l, L2Bank *b, size_t k, uint64_t at)
{
    if (b->tag[k] && b->dirty[k])
        write_below(l, (b->tag[k] - 1) << l->shift, at);
    b->tag[k] = 0;
    b->dirty[k] = 0;
}

/* A miss's register: index m, or -1 when none is free. */
static int mshr_free(const L2 *l, const L2Bank *b)
{
    for (int m = 0; m < l->p.mshrs; m++)
        if (!b->mshr[m].busy)
            return m;
    return -1;
}

static int mshr_of(const L2 *l, const L2Bank *b, size_t k)
{
    for (int m = 0; m < l->p.mshrs; m++)
        if (b->mshr[m].busy && b->mshr[m].way == k)
            return m;
    return -1;
}

static void mshr_wait_add(L2Mshr *m, uint64_t id, uint64_t cycle)
{
    if (m->nwait == m->capwait) {
        uint32_t cap = m->capwait ? 2 * m->capwait : 4;
        L2Wait *w = realloc(m->wait, sizeof *w * cap);
        if (!w)
            abort();
        m->wait = w;
        m->capwait = cap;
    }
    m->wait[m->nwait++] = (L2Wait){id, cycle};
}

/* The head request r of bank b (number bi) at cycle s: 1 when taken, 0 when the bank stops. */
static int take(L2 *l, L2Bank *b, int bi, const L2Req *r, uint64_t s)
{
    const uint64_t line = r->addr >> l->shift, done = s + (uint64_t)l->p.hit_latency;
    l->cur = share_of(l, r->id);
    const size_t base = (size_t)((line / (uint64_t)l->p.banks) % (uint64_t)l->sets) * (size_t)l->p.ways;
    int w = 0;
    while (w < l->p.ways && b->tag[base + (size_t)w] != line + 1)
        w++;
    const size_t k = base + (size_t)w;
    if (w < l->p.ways && b->pending[k]) { /* being filled: merge */
        L2Mshr *m = &b->mshr[mshr_of(l, b, k)];
        l->st.merged++;
        l->cur->accesses++;
        if (r->write) {
            l->st.writes++;
            if (l->p.write_back)
                m->dirty = 1;
            else
                write_below(l, r->addr, done);
            answer(l, r->id, done);
        } else {
            l->st.reads++;
            mshr_wait_add(m, r->id, r->cycle);
        }
        return 1;
    }
    if (w < l->p.ways) { /* a hit */
        l->st.hits++;
        l->cur->accesses++;
        l->cur->hits++;
        b->lru[k] = ++l->stamp;
        if (r->write) {
            l->st.writes++;
            if (l->p.write_back)
                b->dirty[k] = 1;
            else
                write_below(l, r->addr, done);
        } else {
            l->st.reads++;
            l->st.read_latency += done - r->cycle;
        }
        answer(l, r->id, done);
        return 1;
    }
    if (r->write && !l->p.write_back) { /* write-through, no allocate */
        l->st.writes++;
        l->cur->accesses++;
        l->st.misses++;
        write_below(l, r->addr, done);
        answer(l, r->id, done);
        return 1;
    }
    const int v = victim(l, b, base);
    const int m = r->write ? 0 : mshr_free(l, b);
    if (v < 0 || m < 0)
        return 0;
    const size_t kv = base + (size_t)v;
    l->st.misses++;
    l->cur->accesses++;
    evict(l, b, kv, done);
    b->tag[kv] = line + 1;
    b->lru[kv] = ++l->stamp;
    if (r->write) { /* a whole line: allocated dirty, nothing read */
        l->st.writes++;
        b->dirty[kv] = 1;
        answer(l, r->id, done);
        return 1;
    }
    l->st.reads++;
    L2Mshr *mr = &b->mshr[m];
    mr->busy = 1;
    mr->dirty = 0;
    mr->way = (uint32_t)kv;
    mr->nwait = 0;
    mshr_wait_add(mr, r->id, r->cycle);
    b->pending[kv] = 1;
    if (++b->mshr_busy > (int)l->st.mshr_max)
        l->st.mshr_max = (uint64_t)b->mshr_busy;
    l->st.fills++;
    l->cur->below++;
    l->below.push(l->below.self, line << l->shift, 0, done, (uint64_t)bi * (uint64_t)l->p.mshrs + (uint64_t)m);
    return 1;
}

/* A line from below, at cycle: installed, its merged reads answered, its register freed. */
static void fill(void *ctx, uint64_t id, uint64_t cycle)
{
    L2 *l = ctx;
    if (id & L2_BELOW_WRITE)
        return;
    L2Bank *b = &l->bank[id / (uint64_t)l->p.mshrs];
    L2Mshr *m = &b->mshr[id % (uint64_t)l->p.mshrs];
    const size_t k = m->way;
    b->pending[k] = 0;
    b->dirty[k] = m->dirty;
    for (uint32_t i = 0; i < m->nwait; i++) {
        l->st.read_latency += cycle - m->wait[i].cycle;
        answer(l, m->wait[i].id | MEM_FROM_BELOW, cycle);
    }
    m->busy = 0;
    m->nwait = 0;
    b->mshr_busy--;
    if (b->stopped) { /* its head may go on from this cycle */
        l->st.mshr_wait += cycle - b->stopped_at;
        b->stopped = 0;
        b->not_before = cycle;
    }
}

/* Every bank's requests that start at cycle t. */
static void start_bank(L2 *l, int i, uint64_t t)
{
    L2Bank *b = &l->bank[i];
    uint64_t s;
    while ((s = head_start(l, b)) == t) {
        const L2Req r = b->q[b->head];
        if (!take(l, b, i, &r, s)) {
            b->stopped = 1;
            b->stopped_at = s;
            break;
        }
        l->st.port_wait += s - (r.cycle > b->not_before ? r.cycle : b->not_before);
        if (s == b->pcycle) {
            b->pused++;
        } else {
            b->pcycle = s;
            b->pused = 1;
        }
        b->head = (b->head + 1) % b->capq;
        if (--b->n == 0)
            l->live[i >> 6] &= ~((uint64_t)1 << (i & 63));
    }
}

/* The banks whose heads start at t, in bank order (only those with requests queued). */
static void start_at(L2 *l, uint64_t t)
{
    for (int w = 0; w < l->nlive_words; w++)
        for (uint64_t m = l->live[w]; m; m &= m - 1) /* (a copy: a bit start_bank clears stays in it) */
            start_bank(l, 64 * w + __builtin_ctzll(m), t);
}

void l2_run(L2 *l, uint64_t until, MemAnswer ans, void *ctx)
{
    l->next_ok = 0;
    l->running = 1;
    l->answer = ans;
    l->actx = ctx;
    uint64_t t;
    for (;;) {
        const uint64_t tb = l->below.next(l->below.self);
        t = banks_next(l, tb);
        if (t >= until)
            break;
        if (tb == t) /* the level below's events of cycle t first: fills come before starts */
            l->below.run(l->below.self, t + 1, fill, l);
        start_at(l, t);
    }
    l->running = 0;
    l->next_at = t; /* what l2_next would say now */
    l->next_ok = 1;
}

static void lv_push(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    l2_push(self, addr, write, cycle, id);
}
static uint64_t lv_next(const void *self) { return l2_next(self); }
static void lv_run(void *self, uint64_t until, MemAnswer a, void *ctx) { l2_run(self, until, a, ctx); }

MemLevel l2_level(L2 *l) { return (MemLevel){l, lv_push, lv_next, lv_run}; }
