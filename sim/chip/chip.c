/* sim/chip/chip.c -- the memory the chip's cores share (see chip.h; docs/chip.md).
 *
 * Owns: the shared levels built from the config and joined top to bottom (network, L2, DRAM),
 * the requests on their way in, and the answers handed back. Must not: run a core or hand out work.
 */
#include "chip.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../mem/dram_level.h"
#include "../mem/monitor.h"

/* A request id: the core (MEM_ID), then a write's flag and the fill a read answers. */
#define CHIP_WRITE ((uint64_t)1 << 47)

typedef struct InReq {
    uint64_t at;                 /* the cycle it enters the shared memory */
    uint64_t addr;
    uint32_t core, fill;         /* fill: UINT32_MAX for a write */
    uint64_t seq;                /* the core's requests in the order sent */
} InReq;

typedef struct ChipPort {        /* what core k's timing model sends through (timing_chip) */
    struct Chip *chip;
    int core;
    Timing *t;
    uint64_t seq;
    uint64_t *sent;              /* by fill: the cycle the L1 sent it */
    size_t nsent;
    InReq *out;                  /* sent while the core ran (its host thread's only), not yet in */
    size_t nout, capout;
    int oom;
    uint64_t reads, writes, lat_sum; /* its requests as they came in, its reads' latencies as they
                                        were answered (chip_core_stats) */
    uint64_t sent_lines;         /* its requests as its L1 sent them */
} ChipPort;

struct Chip {
    int cores;
    Dram *dram;
    DramLevel *dl;
    L2 *l2;
    Noc *noc;
    MemLevel top;
    MemMonitor *mon[CHIP_LEVELS];  /* chip_new's watch: one before each level, else NULL */
    ChipPort *port;
    InReq *h;                    /* the requests on their way in: a heap by (at, core, seq) */
    size_t n, cap;
    ChipWoke woke;
    void *wctx;
    uint64_t reads, writes, lat_sum, lat_max;
    uint64_t dram_line_bytes;    /* DRAM's bytes for a line: whole bursts */
    char err[256];
};

int chip_shared(const CfgMachine *cfg) { return cfg->chip_memory == CFG_CHIP_MEMORY_SHARED; }

static void l2_params_of(const CfgMachine *cfg, L2Params *p)
{
    memset(p, 0, sizeof *p);
    p->bytes = cfg->l2_size_kb * 1024;
    p->ways = cfg->l2_ways;
    p->line_bytes = cfg->scene_line_bytes;
    p->banks = cfg->l2_banks;
    p->hit_latency = cfg->l2_hit_latency;
    p->ports = cfg->l2_ports;
    p->mshrs = cfg->l2_mshrs;
    p->write_back = cfg->l2_write_policy == CFG_L2_WRITE_BACK;
}

static void noc_params_of(const CfgMachine *cfg, int cores, int dram_channels, NocParams *p)
{
    memset(p, 0, sizeof *p);
    p->cores = cores;
    p->banks = cfg->l2_size_kb > 0 ? cfg->l2_banks : dram_channels; /* the ports at the far side */
    p->latency = cfg->noc_latency;
    p->bytes_per_cycle = cfg->noc_bytes_per_cycle;
    p->line_bytes = cfg->scene_line_bytes;
}

/* The cores' clock in kHz, for the exact crossing into DRAM's (sim/mem/dram_level.h). */
static uint64_t core_khz(const CfgMachine *cfg)
{
    double k = cfg->core_clock_mhz * 1000.0;
    return k < 1.0 ? 1 : (uint64_t)(k + 0.5);
}

int chip_check(const CfgMachine *cfg, char *err, size_t errlen)
{
    if (!chip_shared(cfg))
        return 0;
    char why[400];
    DramParams dp;
    if (dram_params(cfg, &dp, why, sizeof why)) {
        snprintf(err, errlen, "chip.memory = shared: %s", why);
        return -1;
    }
    if ((double)(uint64_t)(cfg->core_clock_mhz * 1000.0 + 0.5) != cfg->core_clock_mhz * 1000.0) {
        snprintf(err, errlen, "chip.memory = shared: core.clock_mhz = %g must be a whole number of kHz (the "
                 "crossing into DRAM's clock is exact)", cfg->core_clock_mhz);
        return -1;
    }
    if (cfg->l2_size_kb > 0) {
        L2Params lp;
        l2_params_of(cfg, &lp);
        if (l2_check(&lp, why, sizeof why)) {
            snprintf(err, errlen, "l2.size_kb = %d, l2.ways = %d, l2.banks = %d, scene.line_bytes = %d: %s",
                     cfg->l2_size_kb, cfg->l2_ways, cfg->l2_banks, cfg->scene_line_bytes, why);
            return -1;
        }
    }
    return 0;
}

void chip_free(Chip *c)
{
    if (!c)
        return;
    noc_free(c->noc);
    l2_free(c->l2);
    for (int i = 0; i < CHIP_LEVELS; i++)
        monitor_free(c->mon[i]);
    dram_level_free(c->dl);
    dram_free(c->dram);
    for (int k = 0; c->port && k < c->cores; k++) {
        free(c->port[k].sent);
        free(c->port[k].out);
    }
    free(c->port);
    free(c->h);
    free(c);
}

const char *const chip_level_keys[CHIP_LEVELS] = {"noc", "l2", "dram"};

/* c->top, watched as level `level` when there is a watch. 0, or -1 on out of memory. */
static int watch_top(Chip *c, int level, const MemWatch *w)
{
    if (!w)
        return 0;
    if (!(c->mon[level] = monitor_new(c->top, level, w)))
        return -1;
    c->top = monitor_level(c->mon[level]);
    return 0;
}

Chip *chip_new(const CfgMachine *cfg, int cores, const MemWatch *watch, char *err, size_t errlen)
{
    if (chip_check(cfg, err, errlen))
        return NULL;
    Chip *c = calloc(1, sizeof *c);
    if (!c || !(c->port = calloc((size_t)cores, sizeof *c->port))) {
        free(c);
        snprintf(err, errlen, "out of memory for the chip");
        return NULL;
    }
    c->cores = cores;
    DramParams dp;
    char why[400];
    if (dram_params(cfg, &dp, why, sizeof why) || !(c->dram = dram_new(&dp, why, sizeof why)) ||
        !(c->dl = dram_level_new(c->dram, core_khz(cfg), cfg->scene_line_bytes))) {
        snprintf(err, errlen, "DRAM: %s", c->dram && !c->dl ? "out of memory" : why);
        chip_free(c);
        return NULL;
    }
    c->top = dram_level(c->dl);
    c->dram_line_bytes = ((uint64_t)cfg->scene_line_bytes + (uint64_t)dp.burst_bytes - 1) / (uint64_t)dp.burst_bytes *
                         (uint64_t)dp.burst_bytes;
    if (watch_top(c, CHIP_LEVEL_DRAM, watch))
        goto oom;
    if (cfg->l2_size_kb > 0) {
        L2Params lp;
        l2_params_of(cfg, &lp);
        if (!(c->l2 = l2_new(&lp, c->top, err, errlen))) {
            chip_free(c);
            return NULL;
        }
        c->top = l2_level(c->l2);
        if (watch_top(c, CHIP_LEVEL_L2, watch))
            goto oom;
    }
    if (cfg->noc_latency > 0) {
        NocParams np;
        noc_params_of(cfg, cores, dp.channels, &np);
        if (!(c->noc = noc_new(&np, c->top, err, errlen))) {
            chip_free(c);
            return NULL;
        }
        c->top = noc_level(c->noc);
        if (watch_top(c, CHIP_LEVEL_NOC, watch))
            goto oom;
    }
    return c;
oom:
    snprintf(err, errlen, "out of memory for the chip's timeline");
    chip_free(c);
    return NULL;
}

void chip_reset(Chip *c)
{
    if (c->noc)
        noc_reset(c->noc);
    if (c->l2)
        l2_reset(c->l2);
    dram_reset(c->dram);
    dram_level_reset(c->dl);
    c->n = 0;
    for (int k = 0; k < c->cores; k++) {
        c->port[k].seq = 0;
        c->port[k].nout = 0;
    }
}

void chip_warm(Chip *c, const uint64_t *addr, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        if (!c->l2 || l2_warm(c->l2, addr[i]))
            dram_warm(c->dram, addr[i]);
    }
}

void chip_warm_written(Chip *c, const uint64_t *addr, size_t n)
{
    for (size_t i = 0; c->l2 && i < n; i++)
        l2_warm_written(c->l2, addr[i]);
}

/* ---- requests on their way in ----------------------------------------------------------------- */

/* *a holds at least need elements of size bytes (its capacity *cap doubled as needed); -1 on out
 * of memory, *a unchanged. */
static int grow(void **a, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? 2 * *cap : 64;
    while (n < need)
        n *= 2;
    void *g = realloc(*a, n * size);
    if (!g)
        return -1;
    *a = g;
    *cap = n;
    return 0;
}

static int in_before(const InReq *a, const InReq *b)
{
    if (a->at != b->at)
        return a->at < b->at;
    if (a->core != b->core)
        return a->core < b->core;
    return a->seq < b->seq;
}

static void in_push(Chip *c, InReq r)
{
    if (grow((void **)&c->h, &c->cap, c->n + 1, sizeof *c->h)) {
        snprintf(c->err, sizeof c->err, "chip: out of memory for requests");
        return;
    }
    size_t i = c->n++;
    while (i > 0 && in_before(&r, &c->h[(i - 1) / 2])) {
        c->h[i] = c->h[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    c->h[i] = r;
}

static InReq in_pop(Chip *c)
{
    InReq top = c->h[0], last = c->h[--c->n];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, m = i;
        const InReq *best = &last;
        if (l < c->n && in_before(&c->h[l], best)) {
            m = l;
            best = &c->h[l];
        }
        if (l + 1 < c->n && in_before(&c->h[l + 1], best))
            m = l + 1;
        if (m == i)
            break;
        c->h[i] = c->h[m];
        i = m;
    }
    if (c->n)
        c->h[i] = last;
    return top;
}

/* TimingOut: core k's L1 sends a line request in cycle `at`; it enters in cycle at + 1. It waits in
 * the core's own list (the core may run on any host thread) until chip_collect. */
static void chip_out(void *ctx, uint64_t addr, int write, uint64_t at, uint32_t fill)
{
    ChipPort *p = ctx;
    if ((!write && grow((void **)&p->sent, &p->nsent, (size_t)fill + 1, sizeof *p->sent)) ||
        grow((void **)&p->out, &p->capout, p->nout + 1, sizeof *p->out)) {
        p->oom = 1;
        return;
    }
    if (!write)
        p->sent[fill] = at;
    p->out[p->nout++] = (InReq){at + 1, addr, (uint32_t)p->core, write ? UINT32_MAX : fill, p->seq++};
    p->sent_lines++; /* (on the core's own thread: chip_core_stats) */
}

void chip_collect(Chip *c, const int *cores, int n)
{
    for (int i = 0; i < n; i++) {
        ChipPort *p = &c->port[cores[i]];
        if (p->oom)
            snprintf(c->err, sizeof c->err, "chip: out of memory for requests");
        for (size_t q = 0; q < p->nout; q++)
            in_push(c, p->out[q]);
        p->nout = 0;
    }
}

int chip_attach(Chip *c, int k, Timing *t)
{
    c->port[k] = (ChipPort){.chip = c, .core = k, .t = t};
    return timing_chip(t, chip_out, &c->port[k]);
}

/* ---- stepping ------------------------------------------------------------------------------- */

uint64_t chip_next(const Chip *c)
{
    const uint64_t lv = c->top.next(c->top.self);
    return c->n && c->h[0].at < lv ? c->h[0].at : lv;
}


/* MemAnswer of the top level. */
static void answered(void *ctx, uint64_t id, uint64_t cycle)
{
    Chip *c = ctx;
    if (id & CHIP_WRITE)
        return;
    const int k = (int)MEM_ID_CORE(id);
    const uint32_t fill = (uint32_t)id;
    /* where the line came from: DRAM when there is no L2, or the L2 got it from below */
    const int source = !c->l2 || (id & MEM_FROM_BELOW) ? TIMING_FROM_DRAM : TIMING_FROM_L2;
    ChipPort *p = &c->port[k];
    if (k >= c->cores || fill >= p->nsent) {
        snprintf(c->err, sizeof c->err, "chip: an answer for no request (core %d, fill %u)", k, fill);
        return;
    }
    const uint64_t lat = cycle - p->sent[fill];
    c->lat_sum += lat;
    p->lat_sum += lat;
    if (lat > c->lat_max)
        c->lat_max = lat;
    timing_answer(p->t, fill, cycle, source);
    if (c->woke)
        c->woke(c->wctx, k, cycle);
}

void chip_step(Chip *c, uint64_t e, ChipWoke woke, void *ctx)
{
    while (c->n && c->h[0].at <= e) {
        const InReq r = in_pop(c);
        const int write = r.fill == UINT32_MAX;
        if (write) {
            c->writes++;
            c->port[r.core].writes++;
        } else {
            c->reads++;
            c->port[r.core].reads++;
        }
        c->top.push(c->top.self, r.addr, write, r.at, MEM_ID(r.core, write ? CHIP_WRITE | r.seq : r.fill));
    }
    c->woke = woke;
    c->wctx = ctx;
    c->top.run(c->top.self, e + 1, answered, c);
}

const char *chip_error(const Chip *c) { return c->err[0] ? c->err : NULL; }

void chip_stats(const Chip *c, ChipMemStats *s)
{
    memset(s, 0, sizeof *s);
    s->has_noc = c->noc != NULL;
    s->has_l2 = c->l2 != NULL;
    if (c->noc)
        s->noc = *noc_stats(c->noc);
    if (c->l2)
        s->l2 = *l2_stats(c->l2);
    const DramStats *d = dram_stats(c->dram);
    s->dram = d->total;
    s->dram_channels = d->channels;
    s->requests = c->reads;
    s->writes = c->writes;
    s->read_latency = c->lat_sum;
    s->read_latency_max = c->lat_max;
    const DramParams *p = dram_get_params(c->dram);
    s->dram_clock_mhz = p->clock_mhz;
    s->dram_peak_gbs = (double)p->channels * (p->bus_bits / 8) * p->beats * p->clock_mhz * 1e6 / 1e9;
}

int chip_count_cores(Chip *c) { return c->l2 ? l2_count_cores(c->l2, c->cores) : 0; }

void chip_core_stats(const Chip *c, int k, ChipCoreStats *s)
{
    memset(s, 0, sizeof *s);
    if (k < 0 || k >= c->cores)
        return;
    const ChipPort *p = &c->port[k];
    s->requests = p->reads;
    s->read_latency = p->lat_sum;
    const L2CoreStats *l = c->l2 ? l2_core_stats(c->l2, k) : NULL;
    if (l) {
        s->l2_accesses = l->accesses;
        s->l2_hits = l->hits;
        s->dram_bytes = l->below * c->dram_line_bytes;
    } else if (!c->l2) {
        s->dram_bytes = p->sent_lines * c->dram_line_bytes;
    }
}

void chip_mem_figures(const ChipMemStats *s, double seconds, double out[CHIP_FIG_COUNT])
{
    const uint64_t acc = s->l2.reads + s->l2.writes;
    out[CHIP_FIG_LATENCY] = s->requests ? (double)s->read_latency / (double)s->requests : -1.0;
    out[CHIP_FIG_L2_HIT_RATE] = s->has_l2 && acc ? (double)s->l2.hits / (double)acc : -1.0;
    out[CHIP_FIG_DRAM_GBS] = seconds > 0.0 ? (double)s->dram.bytes / seconds / 1e9 : -1.0;
}
