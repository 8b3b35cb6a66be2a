/* sim/timeline.c -- a run's timeline in the Chrome trace event format (see timeline.h;
 * docs/timeline.md). */
#include "timeline_int.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chip/chip.h"
#include "mem/noc.h"

/* ---- lists of events -------------------------------------------------------------------------- */

static TlEv *tl_push(TlList *l, int *oom)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 256;
        TlEv *v = realloc(l->v, cap * sizeof *v);
        if (!v) {
            *oom = 1;
            return NULL;
        }
        l->v = v;
        l->cap = cap;
    }
    TlEv *e = &l->v[l->n++];
    memset(e, 0, sizeof *e);
    return e;
}

/* [from, to) clipped to the window onto l; merged into the last span when it has the same name
 * and touches or overlaps it (merge). */
static void tl_span(Timeline *tl, TlList *l, int *oom, uint32_t name, uint64_t from, uint64_t to, int merge)
{
    if (from < tl->from)
        from = tl->from;
    if (to > tl->to)
        to = tl->to;
    if (from >= to)
        return;
    if (merge && l->n) {
        TlEv *p = &l->v[l->n - 1];
        if (p->name == name && from <= p->to && from >= p->from) {
            if (to > p->to)
                p->to = to;
            return;
        }
    }
    TlEv *e = tl_push(l, oom);
    if (e) {
        e->from = from;
        e->to = to;
        e->name = name;
    }
}

/* ---- the timing model's watch ------------------------------------------------------------------ */

static void w_charge(void *ctx, int cause, int from, uint64_t cycles)
{
    TlCore *c = ctx;
    if (c->nch == c->capch) {
        size_t cap = c->capch ? 2 * c->capch : 16;
        TlCharge *v = realloc(c->ch, cap * sizeof *v);
        if (!v) {
            c->oom = 1;
            return;
        }
        c->ch = v;
        c->capch = cap;
    }
    c->ch[c->nch++] = (TlCharge){from >= 0 ? (uint32_t)(N_FROM + from) : (uint32_t)(N_STALL + cause), cycles};
}

/* The instruction's charges laid over [start, issue) in the order charged, its busy cycle at
 * issue, and the charges after it over [issue + 1, end). */
static void w_instr(void *ctx, const TimingInstr *in)
{
    TlCore *c = ctx;
    Timeline *tl = c->tl;
    uint64_t cur = in->start, stalls = 0, most = 0;
    uint32_t most_name = 0;
    int issued = 0;
    for (size_t i = 0; i < c->nch; i++) {
        uint64_t n = c->ch[i].n;
        stalls += n;
        if (in->issue > in->start && n > most && !issued) {
            most = n;
            most_name = c->ch[i].name;
        }
        while (n > 0) {
            if (!issued && cur >= in->issue) {
                tl_span(tl, &c->t[T_ISSUE], &c->oom, N_BUSY, in->issue, in->issue + 1, 1);
                cur = in->issue + 1;
                issued = 1;
                continue;
            }
            const uint64_t lim = issued || in->issue - cur > n ? n : in->issue - cur;
            tl_span(tl, &c->t[T_ISSUE], &c->oom, c->ch[i].name, cur, cur + lim, 1);
            cur += lim;
            n -= lim;
        }
    }
    if (!issued) {
        if (cur != in->issue)
            c->mismatch++;
        tl_span(tl, &c->t[T_ISSUE], &c->oom, N_BUSY, in->issue, in->issue + 1, 1);
        cur = in->issue + 1;
    }
    if (cur != in->end)
        c->mismatch++;
    c->nch = 0;
    if (tl->pipeline && in->issue < tl->to && in->end > tl->from) {
        TlEv *e = tl_push(&c->t[T_PIPE], &c->oom);
        if (e) {
            const uint64_t r = in->ready == UINT64_MAX || in->ready <= in->issue ? in->end : in->ready;
            *e = (TlEv){in->issue, r, N_INSTR, most_name, (uint64_t)in->pc | (uint64_t)in->op << 32, stalls};
        }
    }
}

static void w_unit(void *ctx, int unit, uint64_t from, uint64_t to)
{
    TlCore *c = ctx;
    tl_span(c->tl, &c->t[T_UNIT + unit], &c->oom, (uint32_t)(N_UNIT + unit), from, to, 1);
}

static void w_request(void *ctx, uint64_t addr, int write, uint64_t at, uint64_t done)
{
    TlCore *c = ctx;
    const uint64_t id = c->nreq++;
    if (done <= c->tl->from || at >= c->tl->to)
        return;
    TlEv *e = tl_push(&c->t[T_BUS], &c->oom);
    if (e)
        *e = (TlEv){at, done > at ? done : at + 1, write ? N_WRITE : N_READ, 0, addr, id};
}

TimingWatch timeline_core_watch(Timeline *tl, int k)
{
    return (TimingWatch){w_charge, w_instr, w_unit, w_request, &tl->core[k]};
}

void timeline_pass(Timeline *tl, int k, uint32_t tile, uint32_t pass, uint64_t from, uint64_t to)
{
    TlCore *c = &tl->core[k];
    if (to <= tl->from || from >= tl->to)
        return;
    TlEv *e = tl_push(&c->t[T_WORK], &c->oom);
    if (e)
        *e = (TlEv){from, to > from ? to : from + 1, N_PASS, 0, tile, pass};
}

/* ---- the shared memory's watch ----------------------------------------------------------------- */

static uint64_t open_key(int level, uint64_t id) { return (id & ~MEM_FROM_BELOW) ^ ((uint64_t)(level + 1) << 60); }

static size_t open_slot(const Timeline *tl, uint64_t key)
{
    uint64_t h = key * 0x9E3779B97F4A7C15ull;
    return (size_t)(h >> 20) & (tl->capopen - 1);
}

static int open_grow(Timeline *tl)
{
    TlOpen *old = tl->open;
    const size_t oldcap = tl->capopen;
    size_t cap = oldcap ? oldcap : 1024;
    while (cap / 2 < tl->nopen + 1)
        cap *= 2;
    TlOpen *v = calloc(cap, sizeof *v);
    if (!v)
        return -1;
    tl->open = v;
    tl->capopen = cap;
    tl->used = tl->nopen;
    for (size_t i = 0; i < oldcap; i++) {
        if (old[i].key < 2)
            continue;
        size_t s = open_slot(tl, old[i].key);
        while (v[s].key)
            s = (s + 1) & (cap - 1);
        v[s] = old[i];
    }
    free(old);
    return 0;
}

static void m_pushed(void *ctx, int level, uint64_t id, uint64_t addr, int write, uint64_t cycle)
{
    Timeline *tl = ctx;
    if ((tl->used + 1) * 2 > tl->capopen && open_grow(tl)) {
        tl->oom = 1;
        return;
    }
    const uint64_t key = open_key(level, id);
    size_t s = open_slot(tl, key);
    while (tl->open[s].key >= 2)
        s = (s + 1) & (tl->capopen - 1);
    tl->used += tl->open[s].key == 0;
    tl->open[s] = (TlOpen){key, cycle, addr, write};
    tl->nopen++;
}

static void m_answered(void *ctx, int level, uint64_t id, uint64_t cycle)
{
    Timeline *tl = ctx;
    if (!tl->capopen)
        return;
    const uint64_t key = open_key(level, id);
    size_t s = open_slot(tl, key);
    while (tl->open[s].key && tl->open[s].key != key)
        s = (s + 1) & (tl->capopen - 1);
    if (tl->open[s].key != key)
        return; /* (pushed while out of memory: tl->oom tells) */
    const TlOpen o = tl->open[s];
    tl->open[s].key = 1;
    tl->nopen--;
    if (cycle <= tl->from || o.at >= tl->to)
        return;
    TlEv *e = tl_push(&tl->level[level], &tl->oom);
    if (e)
        *e = (TlEv){o.at, cycle > o.at ? cycle : o.at + 1, o.write ? N_WRITE : N_READ, 0, o.addr, id & ~MEM_FROM_BELOW};
}

MemWatch timeline_mem_watch(Timeline *tl) { return (MemWatch){m_pushed, m_answered, tl}; }

/* ---- the run's end ----------------------------------------------------------------------------- */

int timeline_past(const Timeline *tl, uint64_t now) { return now >= tl->to; }

void timeline_end(Timeline *tl, uint64_t makespan)
{
    const uint64_t end = makespan < tl->to ? makespan : tl->to;
    for (int k = 0; k < tl->cores; k++) {
        TlCore *c = &tl->core[k];
        TlList *l = &c->t[T_ISSUE], out = {0};
        uint64_t cur = tl->from;
        for (size_t i = 0; i <= l->n && !c->oom; i++) {
            const uint64_t at = i < l->n ? l->v[i].from : end;
            if (at > cur)
                tl_span(tl, &out, &c->oom, N_IDLE, cur, at, 0);
            if (i < l->n) {
                TlEv *e = tl_push(&out, &c->oom);
                if (e)
                    *e = l->v[i];
                cur = l->v[i].to;
            }
        }
        free(l->v);
        *l = out;
    }
}

/* ---- set-up ------------------------------------------------------------------------------------ */

Timeline *timeline_new(uint64_t from, uint64_t to, int cores, double clock_mhz, int pipeline)
{
    Timeline *tl = calloc(1, sizeof *tl);
    if (!tl || !(tl->core = calloc((size_t)(cores > 0 ? cores : 1), sizeof *tl->core))) {
        free(tl);
        return NULL;
    }
    tl->from = from;
    tl->to = to;
    tl->cores = cores > 0 ? cores : 1;
    tl->clock_mhz = clock_mhz;
    tl->pipeline = pipeline;
    for (int k = 0; k < tl->cores; k++) {
        tl->core[k].tl = tl;
        tl->core[k].k = k;
    }
    return tl;
}

void timeline_free(Timeline *tl)
{
    if (!tl)
        return;
    for (int k = 0; k < tl->cores; k++) {
        for (int i = 0; i < T_COUNT; i++)
            free(tl->core[k].t[i].v);
        free(tl->core[k].ch);
    }
    for (int i = 0; i < CHIP_LEVELS; i++)
        free(tl->level[i].v);
    free(tl->core);
    free(tl->open);
    free(tl);
}

void timeline_window(const Timeline *tl, uint64_t *from, uint64_t *to)
{
    *from = tl->from;
    *to = tl->to;
}

static int parse_u64(const char *s, size_t n, uint64_t *out)
{
    if (n == 0 || n > 20)
        return -1;
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return -1;
        const uint64_t d = (uint64_t)(s[i] - '0');
        if (v > (UINT64_MAX - d) / 10)
            return -1;
        v = v * 10 + d;
    }
    *out = v;
    return 0;
}

int timeline_parse_window(const char *s, uint64_t *from, uint64_t *to, char *err, size_t errlen)
{
    const char *colon = strchr(s, ':');
    const size_t nf = colon ? (size_t)(colon - s) : strlen(s);
    uint64_t f = 0, t = 0;
    int bad = !colon || (nf && parse_u64(s, nf, &f));
    if (!bad && colon[1])
        bad = parse_u64(colon + 1, strlen(colon + 1), &t);
    else if (!bad)
        t = f > UINT64_MAX - TIMELINE_DEFAULT_CYCLES ? UINT64_MAX : f + TIMELINE_DEFAULT_CYCLES;
    if (bad) {
        snprintf(err, errlen, "--timeline-window '%s': not FROM:TO in cycles (for example 0:200000, or 5000: for "
                 "%llu cycles from 5000)", s, (unsigned long long)TIMELINE_DEFAULT_CYCLES);
        return -1;
    }
    if (t <= f) {
        snprintf(err, errlen, "--timeline-window '%s': the window is empty (TO must be above FROM)", s);
        return -1;
    }
    *from = f;
    *to = t;
    return 0;
}
