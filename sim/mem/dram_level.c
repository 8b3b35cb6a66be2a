/* sim/mem/dram_level.c -- the DRAM as a level in the cores' clock (see dram_level.h).
 *
 * Owns: the clock crossing and the bursts of a line. Must not: change what the DRAM does.
 */
#include "dram_level.h"

#include <stdlib.h>

typedef struct Line {           /* a line in flight: its id above, its bursts not yet done */
    uint64_t id;
    uint32_t left;
    uint32_t next_free;
} Line;

struct DramLevel {
    Dram *d;
    uint64_t core_khz, dram_khz;
    uint32_t bursts;            /* per line */
    uint64_t burst_bytes;
    Line *line;
    uint32_t nline, capline, free_line; /* free list through next_free; UINT32_MAX: empty */
    MemAnswer answer;           /* during a run */
    void *actx;
    /* lv_next's answer, kept until a push or a run changes the DRAM (only this level reaches it):
     * the level above asks it once per cycle it steps (host speed only). */
    uint64_t next_at;
    int next_ok, running;       /* (nothing is kept while a run changes the DRAM) */
};

/* ceil(a x b / c) without overflow for any cycle a simulation reaches. */
static uint64_t mul_div_up(uint64_t a, uint64_t b, uint64_t c)
{
    const unsigned __int128 p = (unsigned __int128)a * b;
    const unsigned __int128 q = (p + c - 1) / c;
    return q > UINT64_MAX ? UINT64_MAX : (uint64_t)q;
}

uint64_t dram_level_to_dram(const DramLevel *l, uint64_t c)
{
    return c == UINT64_MAX ? UINT64_MAX : mul_div_up(c, l->dram_khz, l->core_khz);
}

uint64_t dram_level_to_core(const DramLevel *l, uint64_t d)
{
    return d == DRAM_NEVER ? UINT64_MAX : mul_div_up(d, l->core_khz, l->dram_khz);
}

DramLevel *dram_level_new(Dram *d, uint64_t core_khz, int line_bytes)
{
    DramLevel *l = calloc(1, sizeof *l);
    if (!l)
        return NULL;
    const DramParams *p = dram_get_params(d);
    l->d = d;
    l->core_khz = core_khz ? core_khz : 1;
    l->dram_khz = (uint64_t)p->clock_mhz * 1000u;
    l->burst_bytes = (uint64_t)p->burst_bytes;
    l->bursts = (uint32_t)(((uint64_t)line_bytes + l->burst_bytes - 1) / l->burst_bytes);
    if (l->bursts == 0)
        l->bursts = 1;
    l->free_line = UINT32_MAX;
    return l;
}

void dram_level_free(DramLevel *l)
{
    if (!l)
        return;
    free(l->line);
    free(l);
}

void dram_level_reset(DramLevel *l)
{
    l->next_ok = 0;
    l->nline = 0;
    l->free_line = UINT32_MAX;
}

static uint32_t line_new(DramLevel *l, uint64_t id)
{
    uint32_t i = l->free_line;
    if (i != UINT32_MAX) {
        l->free_line = l->line[i].next_free;
    } else {
        if (l->nline == l->capline) {
            uint32_t cap = l->capline ? 2 * l->capline : 64;
            Line *g = realloc(l->line, sizeof *g * cap);
            if (!g)
                abort(); /* lines in flight: the L2's miss registers and write-backs; the host's end */
            l->line = g;
            l->capline = cap;
        }
        i = l->nline++;
    }
    l->line[i] = (Line){id, l->bursts, UINT32_MAX};
    return i;
}

static void lv_push(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    DramLevel *l = self;
    l->next_ok = 0;
    const uint32_t k = line_new(l, id);
    const uint64_t at = dram_level_to_dram(l, cycle);
    for (uint32_t b = 0; b < l->bursts; b++)
        dram_push(l->d, addr + b * l->burst_bytes, write, at, k);
}

static uint64_t lv_next(const void *self)
{
    DramLevel *l = (DramLevel *)self; /* (the kept answer: not the level's state) */
    if (!l->next_ok) {
        l->next_at = dram_level_to_core(l, dram_next(l->d));
        l->next_ok = !l->running;
    }
    return l->next_at;
}

/* A burst done at DRAM cycle d: its line is done with its last burst. */
static void burst_done(void *ctx, uint64_t k, int write, uint64_t d)
{
    (void)write;
    DramLevel *l = ctx;
    Line *ln = &l->line[k];
    if (--ln->left)
        return;
    l->answer(l->actx, ln->id, dram_level_to_core(l, d));
    ln->next_free = l->free_line;
    l->free_line = (uint32_t)k;
}

static void lv_run(void *self, uint64_t until, MemAnswer answer, void *ctx)
{
    DramLevel *l = self;
    l->next_ok = 0;
    l->running = 1;
    l->answer = answer;
    l->actx = ctx;
    dram_run(l->d, dram_level_to_dram(l, until), burst_done, l);
    l->running = 0;
    l->next_ok = 0;
}

MemLevel dram_level(DramLevel *l) { return (MemLevel){l, lv_push, lv_next, lv_run}; }
