/* sim/run/chiprun.c -- a frame on the chip (chiprun.h; docs/chip.md): K cores, the tiles handed
 * out in simulated time, and the shared memory stepped in one global time order.
 *
 * Owns: each core's place in its work (tile, pass, waiting for memory or for a tile), the
 * distributor, the rule of when the shared memory may do a cycle and when a tile may be handed
 * out, and the per-core figures. Must not: model a memory level (sim/chip/chip.c and sim/mem/ do),
 * time an instruction (sim/timing*), or make a result depend on the host.
 *
 * The rule (docs/chip.md, "Exact and deterministic"): every core runs until it must wait, for an
 * answer of the shared memory (it yielded) or for a tile (it finished one at cycle T). Then, with
 * no core running, the memory does its next cycle e only if no core woken since could still send
 * a request entering at or before e (a core woken at X sends from X on; its requests enter from
 * X + 1), and a core waiting since T gets the next tile only when no other core can still finish
 * before T (or at T with a lower number): T < the memory's next cycle (a core waiting for memory
 * is woken at that cycle at the earliest) and T < every woken core's cycle.
 */
#include "chiprun.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../chip/chip.h"
#include "../timeline.h"

enum { CS_RUN, CS_MEM, CS_TILE, CS_DONE };

typedef struct CoreRun {
    int state;
    int resume;                  /* it yielded: its record is timed again first */
    uint32_t tile, pass, pass_end;  /* the passes [pass, pass_end) of its tile */
    FuncTile *ft;
    uint64_t wake;               /* CS_RUN: the cycle it goes on from */
    uint64_t done_at;            /* CS_TILE: the cycle its tile ended */
    uint64_t instr0, lanes0[ISA_STAGE_COUNT];
    uint64_t pass_at;            /* the cycle its pass began (a timeline's) */
    uint64_t done;               /* the pass's instructions so far */
    int id;                      /* its number */
    FuncMemRec *tr;              /* FuncParams.mem_trace: its requests below, in order */
    size_t ntr, captr;
    int tr_oom;
    FuncUnit fu;                 /* the pass's timed figures so far */
    TimingStats before;
    ChipCoreStats mem0;          /* a wave's: its share of the shared memory's work when the pass began */
    ChipCoreStats mem1;          /* ... and when its last pass ended (that pass's is topped up at the end) */
    uint64_t last_unit;          /* that pass's unit; UINT64_MAX: none yet */
    uint32_t then_tile;          /* a wave's: the tile whose pass 0 it runs after its own (FuncParams.wave_next) */
} CoreRun;

/* Host threads over the cores that can run in a step: each takes the next core of the list until
 * none is left; the step ends when every thread has (a core runs on whichever thread takes it:
 * nothing of a core's run depends on that). */
typedef struct Pool {
    pthread_t *th;
    int nth;                     /* threads besides the caller's */
    pthread_mutex_t mu;
    pthread_cond_t go, done;
    uint64_t gen;                /* steps begun */
    int running;                 /* threads still in this step */
    int quit;
    const int *list;
    int nlist;
    atomic_int next;
    atomic_int failed;
    struct ChipRun *r;
} Pool;

typedef struct ChipRun {
    Job *job;
    Chip *chip;
    CoreRun *cr;
    Pool pool;
    int *runnable;               /* the cores woken or given a tile since the last step */
    int nrunnable;
    int nmem, ntile;             /* cores waiting for memory, for a tile */
    int k;
    uint32_t next_tile;
    atomic_uint tiles_done;
    uint64_t xmin;               /* the earliest cycle a core woken in this step goes on from */
    uint64_t fb_tile;            /* bytes of a tile's framebuffer, in whole lines */
    int cold;
    uint32_t passes;             /* a tile's passes (spp); a ray batch of `sfsim trace`: 1 */
    atomic_uint opening_left;    /* FuncParams.opening: the first wave's units still running */
} ChipRun;

int chip_run_wanted(const FuncParams *fp)
{
    if (fp->chip_unit)
        return 0;
    return fp->timed && (fp->cfg->chip_cores > 1 || chip_shared(fp->cfg) || fp->mem_trace || fp->timeline ||
                         fp->opening || fp->wave);
}

static Timing *tm_of(const ChipRun *r, int k) { return r->job->workers[k].tc.tm; }
static Core *core_of(const ChipRun *r, int k) { return r->job->workers[k].tc.core; }

/* A unit's share of the shared memory's work (FuncStats.pass_mem): *u += now - then. */
static void share_add(ChipCoreStats *u, const ChipCoreStats *now, const ChipCoreStats *then)
{
    u->requests += now->requests - then->requests;
    u->read_latency += now->read_latency - then->read_latency;
    u->l2_accesses += now->l2_accesses - then->l2_accesses;
    u->l2_hits += now->l2_hits - then->l2_hits;
    u->dram_bytes += now->dram_bytes - then->dram_bytes;
}

/* Pass cr->pass of the core's tile, from the cycle the core is at. */
static void pass_begin(ChipRun *r, int k)
{
    CoreRun *cr = &r->cr[k];
    Core *c = core_of(r, k);
    Timing *t = tm_of(r, k);
    if (r->job->fp->batch) {
        eng_batch_launch(r->job, c, cr->tile);
    } else {
        eng_pass_launch(r->job, c, cr->ft, cr->pass == 0 || r->job->fp->wave); /* (a wave's: as a unit) */
        eng_pass_set(r->job, c, cr->pass);
    }
    timing_continue(t, r->cold);
    cr->pass_at = timing_now(t);
    cr->before = *timing_stats(t);
    if (r->job->pass_mem) { /* what came in since the core's last unit ended is that unit's */
        chip_core_stats(r->chip, k, &cr->mem0);
        if (cr->last_unit != UINT64_MAX)
            share_add(&r->job->pass_mem[cr->last_unit], &cr->mem0, &cr->mem1);
    }
    cr->instr0 = core_instructions(c);
    cr->done = 0;
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        cr->lanes0[s] = core_stats(c)->active_lanes[s];
}

static void tile_begin(ChipRun *r, int k, uint32_t tile, uint32_t pass, uint32_t pass_end)
{
    CoreRun *cr = &r->cr[k];
    cr->tile = tile;
    cr->pass = pass;
    cr->pass_end = pass_end;
    cr->ft = r->job->fp->batch ? &r->job->tiles[tile] : eng_tile_start(r->job, tile);
    cr->ft->core = (uint32_t)k;
    r->job->cores[k].tiles++;
    /* The tile's framebuffer at its place in the frame's, so that two tiles' lines never meet in
     * the shared levels; a core on its own bus keeps the paper's one framebuffer (whose place
     * changes which L1 sets its lines meet), so that a tile there takes today's cycles. */
    timing_set_fb_base(tm_of(r, k), r->chip ? (uint64_t)tile * r->fb_tile : 0);
    cr->state = CS_RUN;
    pass_begin(r, k);
}

/* The pass ended (ex): its figures to the tile and the worker. 0, or -1 after eng_fail. */
static int pass_finish(ChipRun *r, int k, CoreExit ex)
{
    CoreRun *cr = &r->cr[k];
    Worker *w = &r->job->workers[k];
    Core *c = w->tc.core;
    Timing *t = w->tc.tm;
    timing_end(t);
    Timeline *tl = r->job->fp->timeline;
    if (tl) { /* the pass on the timeline; past its window, the core is not watched any more */
        timeline_pass(tl, k, cr->tile, cr->pass, cr->pass_at, timing_now(t));
        if (timeline_past(tl, timing_now(t)))
            timing_watch(t, NULL);
    }
    const TimingStats *s = timing_stats(t);
    FuncTile *ft = cr->ft;
    ft->sampled = 1;
    ft->cycles += s->cycles - cr->before.cycles;
    if (r->job->pass_cycles)
        r->job->pass_cycles[(uint64_t)cr->tile * r->passes + cr->pass] = s->cycles - cr->before.cycles;
    if (r->job->pass_mem) {
        cr->last_unit = (uint64_t)cr->tile * r->passes + cr->pass;
        chip_core_stats(r->chip, k, &cr->mem1);
        share_add(&r->job->pass_mem[cr->last_unit], &cr->mem1, &cr->mem0);
    }
    ft->busy += s->busy - cr->before.busy;
    for (int i = 0; i < TM_CAUSE_COUNT; i++)
        ft->stalls[i] += s->stalls[i] - cr->before.stalls[i];
    if (timing_error(t)) {
        eng_fail(r->job, timing_error(t), 0);
        return -1;
    }
    if (r->job->fp->batch) /* a ray batch: its hits out */
        return eng_batch_end(r->job, c, cr->tile, ex, &w->st);
    if (eng_pass_end(r->job, c, ft, cr->pass, ex))
        return -1;
    ft->rays += eng_counters_add(r->job, c, &w->st);
    ft->instructions += core_instructions(c) - cr->instr0;
    for (int i = 0; i < ISA_STAGE_COUNT; i++)
        ft->active_lanes[i] += core_stats(c)->active_lanes[i] - cr->lanes0[i];
    return 0;
}

/* Core k's run up to the instruction limit of a pass (cr->done: the pass's instructions so far). */
static CoreExit run_slice(ChipRun *r, int k)
{
    Core *c = core_of(r, k);
    CoreRun *cr = &r->cr[k];
    const uint64_t max = (uint64_t)r->job->fp->cfg->sim_max_instructions;
    if (cr->done >= max) /* (a yield at the limit's last instruction: the next one would trap) */
        return CORE_EXIT_LIMIT;
    const CoreExit ex = core_run_slice(c, max - cr->done, max);
    cr->done += core_slice_executed(c, max - cr->done);
    return ex;
}

/* Core k runs until it must wait: for memory (CS_MEM), for a tile (CS_TILE). 0, or -1 after
 * eng_fail. */
static int core_go(ChipRun *r, int k)
{
    CoreRun *cr = &r->cr[k];
    Core *c = core_of(r, k);
    Timing *t = tm_of(r, k);
    for (;;) {
        CoreExit ex;
        if (cr->resume) {
            cr->resume = 0;
            const CoreRecord *rec = core_record(c);
            timing_resume(t, rec);
            if (timing_yielded(t)) {
                eng_fail(r->job, "chip: internal error: a core went on before its answers were in", 0);
                return -1;
            }
            ex = (isa_ops[rec->in->op].flags & ISA_FL_END) ? CORE_EXIT_HALT : run_slice(r, k);
        } else {
            ex = run_slice(r, k);
        }
        if (ex == CORE_EXIT_YIELD) {
            cr->state = CS_MEM; /* (counted by the caller, after the step: threads run cores) */
            cr->resume = 1;
            return 0;
        }
        if (ex == CORE_EXIT_LIMIT && !core_trap_message(c)[0]) {
            char msg[300], where[80];
            if (r->job->fp->batch)
                snprintf(where, sizeof where, "rays %u..%u", cr->ft->x0, cr->ft->x0 + cr->ft->w - 1);
            else
                snprintf(where, sizeof where, "tile at (%u, %u), pass %u", cr->ft->x0, cr->ft->y0, cr->pass);
            snprintf(msg, sizeof msg, "kernel, %s: instruction limit of %llu reached (sim.max_instructions)", where,
                     (unsigned long long)r->job->fp->cfg->sim_max_instructions);
            eng_fail(r->job, msg, 1);
            return -1;
        }
        if (pass_finish(r, k, ex))
            return -1;
        if (r->job->fp->opening && cr->pass == 0 && cr->tile < (uint32_t)r->k)
            atomic_fetch_sub(&r->opening_left, 1u);
        if (++cr->pass < cr->pass_end) {
            pass_begin(r, k);
            continue;
        }
        if (!r->job->fp->batch && r->job->rgb) /* (an opening may make no picture) */
            eng_tile_pixels(r->job, c, cr->ft, 0);
        atomic_fetch_add(&r->tiles_done, 1u);
        cr->state = CS_TILE;
        cr->done_at = timing_now(t);
        return 0;
    }
}

/* ---- the trace of the L1s' requests (--mem-trace) ------------------------------------------- */

/* TimingTap: core cr->id's L1 sends a request. */
static void trace_tap(void *ctx, uint64_t addr, int write, uint64_t cycle)
{
    CoreRun *cr = ctx;
    if (cr->ntr == cr->captr) {
        size_t cap = cr->captr ? 2 * cr->captr : 1024;
        FuncMemRec *g = realloc(cr->tr, cap * sizeof *g);
        if (!g) {
            cr->tr_oom = 1;
            return;
        }
        cr->tr = g;
        cr->captr = cap;
    }
    cr->tr[cr->ntr] = (FuncMemRec){cycle, addr, (uint32_t)cr->id, (uint8_t)(write != 0), cr->ntr};
    cr->ntr++;
}

static int trace_order(const void *pa, const void *pb)
{
    const FuncMemRec *a = pa, *b = pb;
    if (a->cycle != b->cycle)
        return a->cycle < b->cycle ? -1 : 1;
    if (a->core != b->core)
        return a->core < b->core ? -1 : 1;
    return a->seq < b->seq ? -1 : a->seq > b->seq;
}

/* The cores' requests into the job, in (cycle, core, order sent) order. 0, or -1 after eng_fail. */
static int trace_gather(ChipRun *r)
{
    size_t n = 0;
    for (int k = 0; k < r->k; k++) {
        if (r->cr[k].tr_oom) {
            eng_fail(r->job, "out of memory for the memory trace (--mem-trace)", 0);
            return -1;
        }
        n += r->cr[k].ntr;
    }
    FuncMemRec *all = malloc((n ? n : 1) * sizeof *all);
    if (!all) {
        eng_fail(r->job, "out of memory for the memory trace (--mem-trace)", 0);
        return -1;
    }
    size_t o = 0;
    for (int k = 0; k < r->k; k++) {
        if (r->cr[k].ntr) /* (a core that sent nothing has no list) */
            memcpy(all + o, r->cr[k].tr, r->cr[k].ntr * sizeof *all);
        o += r->cr[k].ntr;
    }
    qsort(all, n, sizeof *all, trace_order);
    r->job->trace = all;
    r->job->ntrace = n;
    return 0;
}

static int int_order(const void *a, const void *b)
{
    const int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* ---- host threads ---------------------------------------------------------------------------- */

/* Takes cores off the step's list and runs them. */
static void pool_work(Pool *p)
{
    int i;
    while ((i = atomic_fetch_add(&p->next, 1)) < p->nlist)
        if (core_go(p->r, p->list[i]))
            atomic_store(&p->failed, 1);
}

static void *pool_thread(void *arg)
{
    Pool *p = arg;
    uint64_t seen = 0;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        while (p->gen == seen && !p->quit)
            pthread_cond_wait(&p->go, &p->mu);
        if (p->quit)
            break;
        seen = p->gen;
        pthread_mutex_unlock(&p->mu);
        pool_work(p);
        pthread_mutex_lock(&p->mu);
        if (--p->running == 0)
            pthread_cond_signal(&p->done);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

/* nth threads besides the caller's (fewer if they cannot be made: the same results, slower). */
static void pool_open(Pool *p, ChipRun *r, int nth)
{
    memset(p, 0, sizeof *p);
    p->r = r;
    pthread_mutex_init(&p->mu, NULL);
    pthread_cond_init(&p->go, NULL);
    pthread_cond_init(&p->done, NULL);
    p->th = nth > 0 ? calloc((size_t)nth, sizeof *p->th) : NULL;
    for (int i = 0; p->th && i < nth; i++) {
        if (pthread_create(&p->th[i], NULL, pool_thread, p) != 0)
            break;
        p->nth++;
    }
}

static void pool_close(Pool *p)
{
    pthread_mutex_lock(&p->mu);
    p->quit = 1;
    pthread_cond_broadcast(&p->go);
    pthread_mutex_unlock(&p->mu);
    for (int i = 0; i < p->nth; i++)
        pthread_join(p->th[i], NULL);
    free(p->th);
    pthread_mutex_destroy(&p->mu);
    pthread_cond_destroy(&p->go);
    pthread_cond_destroy(&p->done);
}

/* Runs the cores of list (n of them) to their next wait, on the pool's threads and the caller's.
 * 0, or -1 when one failed. */
static int pool_step(Pool *p, const int *list, int n)
{
    p->list = list;
    p->nlist = n;
    atomic_store(&p->next, 0);
    atomic_store(&p->failed, 0);
    /* With shared memory a step wakes about one core (docs/chip.md, "Host threads"): waking the
     * threads for it cost more than it gave (bench/chip_speed: 0.81x on 2 threads), so they take
     * the steps of cores on their own buses only, where every core runs its whole tile. */
    const int helpers = n > 1 && !p->r->chip ? (p->nth < n - 1 ? p->nth : n - 1) : 0;
    if (helpers) {
        pthread_mutex_lock(&p->mu);
        p->running = p->nth;
        p->gen++;
        pthread_cond_broadcast(&p->go);
        pthread_mutex_unlock(&p->mu);
    }
    pool_work(p);
    if (helpers) {
        pthread_mutex_lock(&p->mu);
        while (p->running > 0)
            pthread_cond_wait(&p->done, &p->mu);
        pthread_mutex_unlock(&p->mu);
    }
    return atomic_load(&p->failed) ? -1 : 0;
}

/* ChipWoke: core k has an answer at cycle x; it goes on once its yielded record needs no other. */
static void woke(void *ctx, int k, uint64_t x)
{
    ChipRun *r = ctx;
    CoreRun *cr = &r->cr[k];
    if (cr->state != CS_MEM || timing_blocked(tm_of(r, k), core_record(core_of(r, k))))
        return;
    cr->state = CS_RUN;
    cr->wake = x;
    r->nmem--;
    r->runnable[r->nrunnable++] = k;
    if (x < r->xmin)
        r->xmin = x;
}

/* The core waiting longest for a tile (the earliest cycle, then the lowest number); -1: none. */
static int first_waiting(const ChipRun *r)
{
    int best = -1;
    if (r->ntile == 0)
        return -1;
    for (int k = 0; k < r->k; k++)
        if (r->cr[k].state == CS_TILE && (best < 0 || r->cr[k].done_at < r->cr[best].done_at))
            best = k;
    return best;
}

/* With no core running: hand out tiles and step the shared memory until a core can go on, by the
 * rule above. 1 when one can, 0 when every core is done, -1 on a failure. */
static int shared_step(ChipRun *r)
{
    r->xmin = UINT64_MAX;
    if (r->chip)
        chip_collect(r->chip, r->runnable, r->nrunnable);
    /* the cores just run now wait: count them by what for */
    for (int i = 0; i < r->nrunnable; i++) {
        const int s = r->cr[r->runnable[i]].state;
        r->nmem += s == CS_MEM;
        r->ntile += s == CS_TILE;
    }
    r->nrunnable = 0;
    for (;;) {
        const uint64_t e = r->chip ? chip_next(r->chip) : UINT64_MAX;
        const int w = first_waiting(r);
        if (w >= 0 && r->cr[w].done_at < e && r->cr[w].done_at < r->xmin) {
            r->ntile--;
            const uint32_t then = r->cr[w].then_tile;
            if (r->next_tile < r->job->ntiles || then < r->job->ntiles) {
                const uint64_t at = r->cr[w].done_at;
                r->cr[w].then_tile = UINT32_MAX;
                if (then < r->job->ntiles) /* a wave's core: the next tile's first pass */
                    tile_begin(r, w, then, 0, 1);
                else
                    tile_begin(r, w, r->next_tile++, 0, r->passes);
                r->cr[w].wake = at;
                r->runnable[r->nrunnable++] = w;
                if (at < r->xmin)
                    r->xmin = at;
            } else {
                r->cr[w].state = CS_DONE;
            }
            continue;
        }
        const int waiting_mem = r->nmem > 0;
        if (e != UINT64_MAX && e <= r->xmin && (waiting_mem || w >= 0)) {
            chip_step(r->chip, e, woke, r);
            if (chip_error(r->chip)) {
                eng_fail(r->job, chip_error(r->chip), 0);
                return -1;
            }
            continue;
        }
        if (r->xmin != UINT64_MAX)
            return 1;
        if (waiting_mem || w >= 0) {
            eng_fail(r->job, "chip: internal error: cores wait for memory that has nothing in flight", 0);
            return -1;
        }
        return 0;
    }
}

/* The per-core figures and the makespan into the job. */
static void figures(ChipRun *r)
{
    Job *j = r->job;
    uint64_t makespan = 0;
    for (int k = 0; k < r->k; k++) {
        /* (an opening stops cores within a tile: each is as far as its model got) */
        const uint64_t at = j->fp->opening && r->cr[k].state != CS_DONE ? timing_now(tm_of(r, k)) : r->cr[k].done_at;
        if (at > makespan)
            makespan = at;
    }
    for (int k = 0; k < r->k; k++) {
        FuncCore *fc = &j->cores[k];
        const TimingStats *s = timing_stats(tm_of(r, k));
        fc->busy = s->busy;
        fc->stall = s->cycles - s->busy;
        memcpy(fc->stalls, s->stalls, sizeof fc->stalls);
        fc->finish = r->cr[k].done_at;
        fc->idle = makespan - (fc->busy + fc->stall);
        fc->instructions = core_instructions(core_of(r, k));
    }
    j->makespan = makespan;
    if (j->fp->timeline)
        timeline_end(j->fp->timeline, makespan);
    if (r->chip) {
        j->chip_mem = calloc(1, sizeof *j->chip_mem);
        if (j->chip_mem)
            chip_stats(r->chip, j->chip_mem);
    }
}

/* The cores opened, the scene loaded in each, and each joined to the shared memory. */
static int cores_open(ChipRun *r)
{
    Job *j = r->job;
    for (int k = 0; k < r->k; k++) {
        if (eng_worker_begin(j, k))
            return -1;
        if (r->chip && chip_attach(r->chip, k, tm_of(r, k))) {
            eng_fail(j, "out of memory for the chip", 0);
            return -1;
        }
        r->cr[k].id = k;
        if (j->fp->mem_trace)
            timing_tap(tm_of(r, k), trace_tap, &r->cr[k]);
        if (j->fp->timeline) { /* (after the tap: the watch sees what the tap passes on) */
            const TimingWatch w = timeline_core_watch(j->fp->timeline, k);
            timing_watch(tm_of(r, k), &w);
        }
        timing_reset(tm_of(r, k));
    }
    /* With shared memory the cores run one at a time on one host thread: they share core 0's memo
     * of blocks (one program, one machine), which keeps one memo in the host's caches instead of K
     * (docs/chip.md, "Host speed"); a core that cannot share keeps its own (the same results). */
    for (int k = 1; r->chip && k < r->k; k++)
        (void)timing_share_memo(tm_of(r, k), tm_of(r, 0), j->k->obj.ntext);
    return 0;
}

uint32_t chip_run_frame(Job *j)
{
    const CfgMachine *cfg = j->fp->cfg;
    ChipRun r = {.job = j, .k = cfg->chip_cores, .cold = cfg->chip_cold_units, .passes = j->fp->batch ? 1 : j->spp};
    r.fb_tile = eng_fb_tile_bytes(j);
    char err[600];
    r.cr = calloc((size_t)r.k, sizeof *r.cr);
    r.runnable = calloc((size_t)r.k, sizeof *r.runnable);
    j->cores = calloc((size_t)r.k, sizeof *j->cores);
    if (!j->fp->batch && j->ntiles && j->spp)
        j->pass_cycles = calloc((size_t)j->ntiles * j->spp, sizeof *j->pass_cycles);
    if (!r.cr || !r.runnable || !j->cores || (!j->fp->batch && j->ntiles && j->spp && !j->pass_cycles)) {
        eng_fail(j, "out of memory for the chip's cores", 0);
        free(r.cr);
        free(r.runnable);
        return 0;
    }
    for (uint32_t i = 0; j->fp->wave && i < j->fp->nwave; i++)
        if (j->fp->nwave > (uint32_t)r.k || j->fp->wave[i] >= (uint64_t)j->ntiles * j->spp) {
            snprintf(err, sizeof err, "chip: a wave of %u units on %d cores, unit %u of %llu", j->fp->nwave, r.k,
                     j->fp->wave[i], (unsigned long long)j->ntiles * j->spp);
            eng_fail(j, err, 0);
            free(r.cr);
            free(r.runnable);
            return 0;
        }
    for (int k = 0; k < r.k; k++) {
        r.cr[k].then_tile = UINT32_MAX;
        r.cr[k].last_unit = UINT64_MAX;
    }
    atomic_init(&r.tiles_done, 0u);
    atomic_init(&r.opening_left, j->fp->opening ? (j->ntiles < (uint32_t)r.k ? j->ntiles : (uint32_t)r.k) : 0u);
    j->ncores = (uint32_t)r.k;
    const MemWatch mw = j->fp->timeline ? timeline_mem_watch(j->fp->timeline) : (MemWatch){0};
    if (chip_shared(cfg) && !(r.chip = chip_new(cfg, r.k, j->fp->timeline ? &mw : NULL, err, sizeof err))) {
        eng_fail(j, err, 0);
        free(r.cr);
        free(r.runnable);
        return 0;
    }
    if (r.chip && j->fp->wave && j->pass_cycles && /* a wave's units' shares of the shared memory */
        (chip_count_cores(r.chip) != 0 || !(j->pass_mem = calloc((size_t)j->ntiles * j->spp, sizeof *j->pass_mem)))) {
        eng_fail(j, "out of memory for a wave's counts by core", 0);
        chip_free(r.chip);
        free(r.cr);
        free(r.runnable);
        return 0;
    }
    const int threads = j->fp->threads < 1 ? 1 : j->fp->threads > r.k ? r.k : j->fp->threads;
    pool_open(&r.pool, &r, threads - 1);
    if (cores_open(&r) == 0) {
        if (j->fp->wave) { /* one wave: unit i on core i, on levels warmed first; no more tiles */
            if (r.chip) {
                eng_warm_fb_tiles(j, r.chip, j->fp->wave_fb_lo, j->fp->wave_fb_hi, UINT32_MAX);
                for (uint32_t i = 0; i < j->fp->nwave && i < (uint32_t)r.k; i++) /* (pass 1's: engine_int.h) */
                    eng_warm_fb_shared(j, r.chip, (uint64_t)(j->fp->wave[i] / j->spp) * r.fb_tile, j->fp->wave[i], 1);
                chip_warm(r.chip, j->fp->wave_warm, j->fp->nwave_warm);
            }
            r.next_tile = j->ntiles;
        }
        for (int k = 0; k < r.k; k++) {
            if (j->fp->wave && (uint32_t)k < j->fp->nwave) {
                const uint32_t u = j->fp->wave[k], p = u % j->spp;
                tile_begin(&r, k, u / j->spp, p, p + (j->fp->wave_passes >= 2 && p + 1 < j->spp ? 2 : 1));
                if (j->fp->wave_passes >= 2 && p + 1 == j->spp && j->fp->wave_next)
                    r.cr[k].then_tile = j->fp->wave_next[k];
                if (eng_warm_l1(j, tm_of(&r, k), u) != 0)
                    break;
                eng_warm_fb_shared(j, r.chip, (uint64_t)(u / j->spp) * r.fb_tile, u, 0);
                r.runnable[r.nrunnable++] = k;
            } else if (!j->fp->wave && r.next_tile < j->ntiles) {
                tile_begin(&r, k, r.next_tile++, 0, r.passes);
                r.runnable[r.nrunnable++] = k;
            } else {
                r.cr[k].state = CS_DONE;
            }
        }
        int go = 1;
        while (go > 0 && !atomic_load(&j->failed) && !(j->fp->opening && atomic_load(&r.opening_left) == 0)) {
            /* the cores woken or given a tile, in core order (the order does not change a result:
                 * it only keeps the host's work the same from run to run) */
            qsort(r.runnable, (size_t)r.nrunnable, sizeof *r.runnable, int_order);
            const uint32_t before = atomic_load(&r.tiles_done);
            if (pool_step(&r.pool, r.runnable, r.nrunnable))
                go = -1;
            const uint32_t done = atomic_load(&r.tiles_done);
            if (done != before && j->fp->progress)
                j->fp->progress(j->fp->progress_ctx, done, j->ntiles);
            if (go > 0)
                go = shared_step(&r);
        }
        for (int k = 0; j->pass_mem && k < r.k; k++) /* what reached the levels after a core's last unit */
            if (r.cr[k].last_unit != UINT64_MAX) {
                ChipCoreStats end;
                chip_core_stats(r.chip, k, &end);
                share_add(&j->pass_mem[r.cr[k].last_unit], &end, &r.cr[k].mem1);
            }
        if (!atomic_load(&j->failed))
            figures(&r);
        if (!atomic_load(&j->failed) && j->fp->mem_trace)
            trace_gather(&r);
        if (r.k == 1 && !r.chip) { /* the paper's machine, run here for its trace: reported as ever */
            j->ncores = 0;
            free(j->pass_cycles);
            j->pass_cycles = NULL;
        }
    }
    /* Every core's replays of the blocks they share counted now, while core 0 (whose memo they
     * share) is alive: the workers' statistics are read again as each is closed, in core order. */
    for (int k = 0; r.chip && k < r.k; k++)
        if (tm_of(&r, k))
            (void)timing_stats(tm_of(&r, k));
    pool_close(&r.pool);
    chip_free(r.chip);
    for (int k = 0; k < r.k; k++)
        free(r.cr[k].tr);
    free(r.cr);
    free(r.runnable);
    return atomic_load(&r.tiles_done);
}
