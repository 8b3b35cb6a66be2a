/* sim/run/engine.c -- the kernel engine (engine.h): kernels/pathtrace.s on functional cores, one
 * (tile, pass) unit or ray batch per run, host threads over them (sim/run/tiles.c).
 *
 * Owns: the kernel's launch block and counters (by name from the object's symbol table:
 * kernels/lib/abi.inc is their only definition), copying tiles in and out of the framebuffer, the
 * workers and their sums. Must not: compute radiance, make results depend on the thread count
 * (each tile's pixels come from its own runs only), or call up into sim/run/run.c (its caller
 * passes everything it needs in FuncParams, the scene's shared image included).
 */
#include "engine.h"

#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "chiprun.h"
#include "engine_int.h"
#include "kernel.h"
#include "tiles.h"
#include "timedcore.h"



static uint32_t spad_u32(Core *c, uint32_t addr)
{
    uint32_t v, size;
    uint8_t *m = core_mem(c, CORE_MEM_SPAD, &size);
    memcpy(&v, m + addr, 4);
    return v;
}

static void spad_set(Core *c, uint32_t addr, uint32_t v)
{
    uint32_t size;
    uint8_t *m = core_mem(c, CORE_MEM_SPAD, &size);
    memcpy(m + addr, &v, 4);
}

/* Add one run's kd counters, lanes 0..N-1 of each (kind, counter) vector. */
static void kd_counts_add(Core *c, const KernelAbi *a, int lanes, FuncStats *st)
{
    for (int k = 0; k < FUNC_KD_KINDS; k++)
        for (int n = 0; n < FUNC_KD_COUNTERS; n++) {
            uint32_t at = a->kc_base + (a->kind[k] * a->kc_counters + a->kc[n]) * a->kc_vec_bytes;
            for (int l = 0; l < lanes; l++)
                st->kd_counts[k][n] += spad_u32(c, at + 4u * (uint32_t)l);
        }
}

void eng_fail(Job *j, const char *msg, int trapped)
{
    pthread_mutex_lock(&j->lock);
    if (!atomic_load(&j->failed)) {
        snprintf(j->err, sizeof j->err, "%s", msg);
        j->trapped = trapped;
    }
    atomic_store(&j->failed, 1);
    pthread_mutex_unlock(&j->lock);
}

/* Detailed and sampled modes: start a cold machine for one run (a pass, or a trace batch). */
static void timing_begin(Worker *w, Core *c, TimingStats *before)
{
    if (!w->tc.tm)
        return;
    timing_attach(w->tc.tm, c);
    timing_reset(w->tc.tm);
    if (w->cu.chip)
        chipunit_reset(&w->cu);
    *before = *timing_stats(w->tc.tm);
}

/* Close the run and give its figures to fu (cycles, busy, stalls added); -1 if the model failed. */
static int timing_close(Worker *w, const TimingStats *before, FuncUnit *fu)
{
    if (!w->tc.tm)
        return 0;
    timing_end(w->tc.tm);
    const TimingStats *s = timing_stats(w->tc.tm);
    fu->cycles += s->cycles - before->cycles;
    fu->busy += s->busy - before->busy;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        fu->stalls[c] += s->stalls[c] - before->stalls[c];
    if (timing_error(w->tc.tm)) {
        eng_fail(w->job, timing_error(w->tc.tm), 0);
        return -1;
    }
    return 0;
}

/* A unit's (or a batch's) timed figures added to its tile's. */
static void tile_add_timed(FuncTile *ft, const FuncUnit *fu)
{
    ft->sampled = 1;
    ft->cycles += fu->cycles;
    ft->busy += fu->busy;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        ft->stalls[c] += fu->stalls[c];
}

static void rb_set(uint8_t *rb, uint32_t addr, uint32_t v) { memcpy(rb + addr, &v, 4); }
static uint32_t rb_get(const uint8_t *rb, uint32_t addr)
{
    uint32_t v;
    memcpy(&v, rb + addr, 4);
    return v;
}

/* Batch t's rays, [t * M, ...): the first and how many. */
static uint32_t batch_rays(const Job *j, uint32_t t, uint32_t *first)
{
    const uint32_t rays = j->k->rays, count = j->fp->batch->count;
    *first = t * rays;
    return count - *first < rays ? count - *first : rays;
}

void eng_batch_launch(Job *j, Core *c, uint32_t t)
{
    const KernelAbi *a = &j->k->abi;
    const RayBatch *b = j->fp->batch;
    uint32_t first, n = batch_rays(j, t, &first);
    FuncTile *ft = &j->tiles[t];
    ft->x0 = first;
    ft->w = n;
    ft->h = 1;
    core_restart(c);
    uint32_t size;
    uint8_t *sp = core_mem(c, CORE_MEM_SPAD, &size);
    memset(sp, 0, a->spad_clear);
    spad_set(c, a->l_w, n);
    uint8_t *rb = core_mem(c, CORE_MEM_RB0, &size);
    const float nan = NAN;
    uint32_t nanbits;
    memcpy(&nanbits, &nan, 4);
    for (uint32_t i = 0; i < n; i++) {
        const BatchRay *r = &b->rays[first + i];
        int invalid = raybatch_ray_invalid(r);
        for (int k = 0; k < 3; k++) {
            uint32_t o, d;
            memcpy(&o, &r->org[k], 4);
            memcpy(&d, &r->dir[k], 4);
            rb_set(rb, a->f_org[k] + 4 * i, invalid ? nanbits : o); /* NaN: the set-up filter drops it */
            rb_set(rb, a->f_dir[k] + 4 * i, d);
        }
        uint32_t tm;
        memcpy(&tm, &r->tmax, 4);
        rb_set(rb, a->f_tmax + 4 * i, tm);
        rb_set(rb, a->f_kind + 4 * i, r->query == RAY_ANY ? 2u : 0u);
        rb_set(rb, a->f_prim + 4 * i, UINT32_MAX);
    }
}

int eng_batch_end(Job *j, Core *c, uint32_t t, CoreExit ex, FuncStats *st)
{
    const KernelAbi *a = &j->k->abi;
    const RayBatch *b = j->fp->batch;
    uint32_t first, n = batch_rays(j, t, &first);
    uint32_t size;
    const uint8_t *rb = core_mem(c, CORE_MEM_RB0, &size);
    char msg[1400];
    if (ex != CORE_EXIT_HALT) {
        snprintf(msg, sizeof msg, "kernel, rays %u..%u: %s%s", first, first + n - 1, core_trap_message(c),
                 ex == CORE_EXIT_LIMIT ? " (sim.max_instructions)" : "");
        eng_fail(j, msg, 1);
        return -1;
    }
    if (spad_u32(c, a->l_error)) {
        snprintf(msg, sizeof msg, "kernel, rays %u..%u: traversal stack overflow (raise spad.size_kb)", first,
                 first + n - 1);
        eng_fail(j, msg, 1);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        const BatchRay *r = &b->rays[first + i];
        BatchHit *h = &j->fp->hits[first + i];
        memset(h, 0, sizeof *h);
        h->invalid = (uint32_t)raybatch_ray_invalid(r);
        uint32_t tm = rb_get(rb, a->f_tmax + 4 * i), u = rb_get(rb, a->f_u + 4 * i), v = rb_get(rb, a->f_v + 4 * i);
        if (r->query == RAY_ANY) {
            float tf;
            memcpy(&tf, &tm, 4);
            h->prim = !h->invalid && tf < 0.0f;
            continue;
        }
        h->prim = h->invalid ? UINT32_MAX : rb_get(rb, a->f_prim + 4 * i);
        if (h->prim != UINT32_MAX) {
            memcpy(&h->t, &tm, 4);
            memcpy(&h->u, &u, 4);
            memcpy(&h->v, &v, 4);
        }
    }
    st->rays_camera += n;
    if (j->fp->cfg->accel_structure == CFG_ACCEL_KD)
        kd_counts_add(c, a, j->k->cp.lanes, st);
    return 0;
}

/* One batch of `sfsim trace`: rays [t * M, ...) into RB0, run, hits out. */
static int trace_batch(Worker *w, Core *c, uint32_t t, FuncStats *st)
{
    Job *j = w->job;
    eng_batch_launch(j, c, t);
    TimingStats before;
    timing_begin(w, c, &before);
    CoreExit ex = core_run(c, (uint64_t)j->fp->cfg->sim_max_instructions);
    FuncUnit fu = {0};
    int trc = timing_close(w, &before, &fu);
    if (w->tc.tm)
        tile_add_timed(&j->tiles[t], &fu);
    if (trc)
        return -1;
    return eng_batch_end(j, c, t, ex, st);
}

/* Tile t's place in the frame. */
static void tile_place(const Job *j, uint32_t t, FuncTile *ft)
{
    const uint32_t tw = j->k->tile_w, th = j->k->tile_h;
    ft->x0 = (t % j->tiles_x) * tw;
    ft->y0 = (t / j->tiles_x) * th;
    ft->w = j->width - ft->x0 < tw ? j->width - ft->x0 : tw;
    ft->h = j->height - ft->y0 < th ? j->height - ft->y0 : th;
}

/* A pass's launch block on a restarted core: the scratchpad's counters cleared (a pass starts
 * from nothing an earlier pass left, so it runs alone exactly as inside its tile), and for a
 * tile's first pass the framebuffer zeroed (the passes add to it). */
void eng_pass_launch(Job *j, Core *c, const FuncTile *ft, int zero_fb)
{
    const KernelAbi *a = &j->k->abi;
    core_restart(c);
    uint32_t size;
    uint8_t *sp = core_mem(c, CORE_MEM_SPAD, &size);
    memset(sp, 0, a->spad_clear);
    spad_set(c, a->l_x0, ft->x0);
    spad_set(c, a->l_y0, ft->y0);
    spad_set(c, a->l_w, ft->w);
    spad_set(c, a->l_h, ft->h);
    spad_set(c, a->l_seed, j->fp->seed);
    uint8_t *fb = core_mem(c, CORE_MEM_FB, &size);
    if (zero_fb)
        memset(fb, 0, (size_t)ft->w * ft->h * 12);
}

void eng_pass_set(Job *j, Core *c, uint32_t pass)
{
    spad_set(c, j->k->abi.l_pass0, pass);
    spad_set(c, j->k->abi.l_pass1, pass + 1);
}

int eng_pass_end(Job *j, Core *c, const FuncTile *ft, uint32_t pass, CoreExit ex)
{
    const KernelAbi *a = &j->k->abi;
    char msg[1400];
    if (ex != CORE_EXIT_HALT) {
        snprintf(msg, sizeof msg, "kernel, tile at (%u, %u), pass %u: %s%s", ft->x0, ft->y0, pass,
                 core_trap_message(c), ex == CORE_EXIT_LIMIT ? " (sim.max_instructions)" : "");
        eng_fail(j, msg, 1);
        return -1;
    }
    uint32_t kerr = spad_u32(c, a->l_error);
    if (kerr) {
        snprintf(msg, sizeof msg, "kernel, tile at (%u, %u), pass %u: %s", ft->x0, ft->y0, pass,
                 kerr == a->err_stack         ? "traversal stack overflow (raise spad.size_kb)"
                 : kerr == a->err_generations ? "more generations than the kernel counts (64)"
                                             : "error code set");
        eng_fail(j, msg, 1);
        return -1;
    }
    return 0;
}

int eng_warm_l1(Job *j, Timing *t, uint32_t unit)
{
    if (!j->fp->unit_warm_l1)
        return 0;
    size_t n = 0;
    const uint64_t *lines = j->fp->unit_warm_l1(j->fp->unit_warm_ctx, unit, &n);
    const uint64_t line = (uint64_t)j->fp->cfg->scene_line_bytes;
    const uint64_t fb = unit % j->spp ? ((uint64_t)j->k->tile_w * j->k->tile_h * 12 + line - 1) / line * line : 0;
    if (timing_warm_l1(t, lines, lines ? n : 0, fb) != 0) {
        eng_fail(j, timing_error(t), 0);
        return -1;
    }
    return 0;
}

uint64_t eng_fb_tile_bytes(const Job *j)
{
    const uint64_t line = (uint64_t)j->fp->cfg->scene_line_bytes;
    return ((uint64_t)j->k->tile_w * j->k->tile_h * 12 + line - 1) / line * line;
}

/* The framebuffer lines of the tile at base, as written. */
static void warm_fb_written(Job *j, Chip *chip, uint64_t base)
{
    const uint64_t line = (uint64_t)j->fp->cfg->scene_line_bytes, bytes = eng_fb_tile_bytes(j);
    for (uint64_t b = 0; b < bytes; b += line) {
        const uint64_t a = ((uint64_t)1 << MEM_SPACE_SHIFT) + base + b;
        chip_warm_written(chip, &a, 1);
    }
}

void eng_warm_fb_shared(Job *j, Chip *chip, uint64_t base, uint32_t unit, int early)
{
    const uint32_t pass = unit % j->spp;
    if (!j->fp->unit_warm_l1 || pass == 0 || !chip || (early ? pass != 1 : pass == 1))
        return;
    warm_fb_written(j, chip, base);
}

void eng_warm_fb_tiles(Job *j, Chip *chip, uint32_t lo, uint32_t hi, uint32_t skip)
{
    if (!chip || hi <= lo)
        return;
    const uint64_t fbt = eng_fb_tile_bytes(j);
    const uint64_t cap = (uint64_t)j->fp->cfg->l2_size_kb * 1024 / fbt + 1; /* tiles an L2 holds, and one */
    if (hi - lo > cap)
        lo = hi - (uint32_t)cap;
    for (uint32_t t = lo; t < hi; t++)
        if (t != skip)
            warm_fb_written(j, chip, (uint64_t)t * fbt);
}

/* A chip's unit's traffic below its L1 (FuncUnit): the shared levels' counters now less m0's. */
static void unit_mem(const Chip *chip, const ChipMemStats *m0, FuncUnit *fu)
{
    ChipMemStats m1;
    chip_stats(chip, &m1);
    fu->mem_requests += m1.requests - m0->requests;
    fu->mem_read_latency += m1.read_latency - m0->read_latency;
    fu->l2_accesses += (m1.l2.reads + m1.l2.writes) - (m0->l2.reads + m0->l2.writes);
    fu->l2_hits += m1.l2.hits - m0->l2.hits;
    fu->dram_bytes += m1.dram.bytes - m0->dram.bytes;
}

/* One kernel run: unit `unit` (tile * spp + pass) of the launched tile, on a cold machine when
 * timed (fu gets its timed figures; on a chip's unit, its levels warmed first when asked). 0, or
 * -1 after eng_fail(). */
static int run_pass(Worker *w, Core *c, const FuncTile *ft, uint32_t unit, FuncUnit *fu)
{
    Job *j = w->job;
    const uint32_t pass = unit % j->spp;
    eng_pass_set(j, c, pass);
    TimingStats tbefore;
    timing_begin(w, c, &tbefore);
    const uint32_t tile = unit / j->spp;
    if (w->cu.chip) { /* the unit's framebuffer where the chip's frame has it, past the earlier tiles' */
        timing_set_fb_base(w->tc.tm, (uint64_t)tile * eng_fb_tile_bytes(j));
        uint32_t lo = 0, hi = 0;
        if (j->fp->unit_warm_tiles)
            j->fp->unit_warm_tiles(j->fp->unit_warm_ctx, unit, &lo, &hi);
        eng_warm_fb_tiles(j, w->cu.chip, lo, hi, tile);
    }
    if (w->cu.chip)
        eng_warm_fb_shared(j, w->cu.chip, (uint64_t)tile * eng_fb_tile_bytes(j), unit, 1);
    if (w->cu.chip && j->fp->unit_warm) {
        size_t n = 0;
        const uint64_t *lines = j->fp->unit_warm(j->fp->unit_warm_ctx, unit, &n);
        if (lines)
            chipunit_warm(&w->cu, lines, n);
    }
    if (w->cu.chip)
        eng_warm_fb_shared(j, w->cu.chip, (uint64_t)tile * eng_fb_tile_bytes(j), unit, 0);
    if (w->cu.chip && eng_warm_l1(j, w->tc.tm, unit) != 0)
        return -1;
    const uint64_t limit = (uint64_t)j->fp->cfg->sim_max_instructions;
    CoreExit ex;
    ChipMemStats m0;
    if (w->cu.chip) {
        chip_stats(w->cu.chip, &m0);
        char err[300];
        if (chipunit_run(&w->cu, c, limit, &ex, err, sizeof err)) {
            eng_fail(j, err, 0);
            return -1;
        }
        if (ex == CORE_EXIT_LIMIT && !core_trap_message(c)[0]) {
            char msg[300];
            snprintf(msg, sizeof msg, "kernel, tile at (%u, %u), pass %u: instruction limit of %llu reached (sim.max_instructions)",
                     ft->x0, ft->y0, pass, (unsigned long long)limit);
            eng_fail(j, msg, 1);
            return -1;
        }
    } else {
        ex = core_run(c, limit);
    }
    if (w->cu.chip && fu)
        unit_mem(w->cu.chip, &m0, fu);
    if (timing_close(w, &tbefore, fu))
        return -1;
    return eng_pass_end(j, c, ft, pass, ex);
}

/* The kernel's counters in the scratchpad, from the pass just run, added to st; the rays traced
 * returned. */
uint64_t eng_counters_add(Job *j, Core *c, FuncStats *st)
{
    const KernelAbi *a = &j->k->abi;
    st->dropped += spad_u32(c, a->st_dropped);
    st->rays_camera += spad_u32(c, a->st_camera);
    st->rays_indirect += spad_u32(c, a->st_indirect);
    st->rays_shadow += spad_u32(c, a->st_shadow);
    uint32_t g = spad_u32(c, a->st_generations);
    if (g > st->generations)
        st->generations = g;
    for (uint32_t k = 0; k < a->st_max_gen; k++)
        st->rays_per_generation[k] += spad_u32(c, a->st_per_gen + 4 * k);
    const uint32_t off[FUNC_STAGES] = {a->st_g_trav, a->st_g_isect, a->st_g_shade};
    for (uint32_t k = 0; k < a->st_max_gen; k++)
        for (int s = 0; s < FUNC_STAGES; s++) {
            uint32_t at = a->st_gen_base + k * a->st_gen_bytes + off[s];
            st->gen_streams[k][s] += spad_u32(c, at);
            st->gen_rays[k][s] += spad_u32(c, at + 4);
        }
    if (j->fp->cfg->accel_structure == CFG_ACCEL_KD)
        kd_counts_add(c, a, j->k->cp.lanes, st);
    return (uint64_t)spad_u32(c, a->st_camera) + spad_u32(c, a->st_indirect) + spad_u32(c, a->st_shadow);
}

/* Pass `pass` of the tile ft (placed) on core c: its kernel run, with its timed figures, rays,
 * instructions and active lanes added to ft's. 0, or -1 after eng_fail(). */
static int tile_pass(Worker *w, Core *c, FuncTile *ft, uint32_t pass, FuncStats *st)
{
    Job *j = w->job;
    uint64_t before = core_instructions(c), lanes_before[ISA_STAGE_COUNT];
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        lanes_before[k] = core_stats(c)->active_lanes[k];
    eng_pass_launch(j, c, ft, pass == 0);
    FuncUnit fu = {0};
    int rc = run_pass(w, c, ft, (uint32_t)(ft - j->tiles) * j->spp + pass, &fu);
    if (w->tc.tm)
        tile_add_timed(ft, &fu);
    if (rc)
        return -1;
    ft->rays += eng_counters_add(j, c, st);
    ft->instructions += core_instructions(c) - before;
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        ft->active_lanes[k] += core_stats(c)->active_lanes[k] - lanes_before[k];
    return 0;
}

/* Tile t placed, its counts zeroed (before its first pass). */
FuncTile *eng_tile_start(Job *j, uint32_t t)
{
    FuncTile *ft = &j->tiles[t];
    tile_place(j, t, ft);
    ft->rays = 0;
    ft->instructions = 0;
    memset(ft->active_lanes, 0, sizeof ft->active_lanes);
    return ft;
}

/* Row y of the tile ft in the frame's rgb (ft->w pixels of 12 bytes). */
static float *tile_row(const Job *j, const FuncTile *ft, uint32_t y)
{
    return &j->rgb[3 * ((size_t)(ft->y0 + y) * j->width + ft->x0)];
}

/* The pixels of the tile ft between the framebuffer's first w x h pixels and the frame's rgb
 * (to_fb: into the framebuffer). */
void eng_tile_pixels(Job *j, Core *c, const FuncTile *ft, int to_fb)
{
    uint32_t size;
    uint8_t *fb = core_mem(c, CORE_MEM_FB, &size);
    for (uint32_t y = 0; y < ft->h; y++) {
        float *px = tile_row(j, ft, y);
        uint8_t *row = fb + (size_t)12 * y * ft->w;
        if (to_fb)
            memcpy(row, px, (size_t)12 * ft->w);
        else
            memcpy(px, row, (size_t)12 * ft->w);
    }
}

/* Every pass of tile t, one kernel run each; the framebuffer carries over from pass to pass (and
 * nothing else), and the tile's pixels go to the image. */
static int run_tile(Worker *w, Core *c, uint32_t t, FuncStats *st)
{
    Job *j = w->job;
    if (j->fp->batch)
        return trace_batch(w, c, t, st);
    FuncTile *ft = eng_tile_start(j, t);
    for (uint32_t pass = 0; pass < j->spp; pass++)
        if (tile_pass(w, c, ft, pass, st))
            return -1;
    eng_tile_pixels(j, c, ft, 0);
    return 0;
}

/* Item i of a whole frame (Job.passes_done): pass i / ntiles of tile i % ntiles. The launcher starts it
 * after the tile's pass before (TileLaunch.chain), maybe on another thread: that pass left the
 * framebuffer in the frame's pixels, which go back into this core's framebuffer first, so the
 * kernel adds to the same bytes as when one core runs every pass of the tile (run_tile). */
static int run_tile_pass(Worker *w, Core *c, uint32_t i, FuncStats *st)
{
    Job *j = w->job;
    const uint32_t t = i % j->ntiles, pass = i / j->ntiles;
    FuncTile *ft = pass ? &j->tiles[t] : eng_tile_start(j, t);
    if (pass > 0)
        eng_tile_pixels(j, c, ft, 1);
    if (tile_pass(w, c, ft, pass, st))
        return -1;
    eng_tile_pixels(j, c, ft, 0);
    j->passes_done[t] = pass + 1;
    if (pass + 1 == j->spp) {
        uint32_t done = atomic_fetch_add(&j->tiles_done, 1u) + 1u;
        if (j->fp->progress)
            j->fp->progress(j->fp->progress_ctx, done, j->ntiles);
    }
    return 0;
}

/* Sampled mode: the i-th unit of the round alone, launched as every pass is (a pass reads nothing
 * an earlier pass left but the framebuffer it adds to, so its instructions and cycles are those it
 * has in the whole tile). */
static int run_unit(Worker *w, Core *c, uint32_t i, FuncStats *st)
{
    Job *j = w->job;
    FuncUnit *fu = &j->unit_out[i];
    memset(fu, 0, sizeof *fu);
    fu->unit = j->units[i];
    FuncTile place;
    tile_place(j, fu->unit / j->spp, &place);
    eng_pass_launch(j, c, &place, 1);
    uint64_t before = core_instructions(c), lanes_before[ISA_STAGE_COUNT];
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        lanes_before[k] = core_stats(c)->active_lanes[k];
    if (run_pass(w, c, &place, fu->unit, fu))
        return -1;
    fu->instructions = core_instructions(c) - before;
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        fu->active_lanes[k] = core_stats(c)->active_lanes[k] - lanes_before[k];
    fu->rays = eng_counters_add(j, c, st);
    return 0;
}

/* sim/run/tiles.h: a core (and in the timed modes a timing model) per host thread, with the scene
 * loaded once and kept until workers_close (sampled mode runs several launches on the same cores);
 * each tile or unit restarts the core. */
int eng_worker_begin(void *ctx, int index)
{
    Job *j = ctx;
    Worker *w = &j->workers[index];
    char err[512], msg[600];
    w->job = j;
    if (w->tc.core)
        return 0;
    int rc = timedcore_open(&w->tc, j->fp->cfg, &j->k->obj, j->fp->timed, err, sizeof err);
    if (rc != 0) {
        snprintf(msg, sizeof msg, "%s: %s", rc == -2 ? "timing model" : "kernel", err);
        eng_fail(j, msg, 0);
        return -1;
    }
    if (j->fp->chip_unit && w->tc.tm && chipunit_open(&w->cu, j->fp->cfg, w->tc.tm, err, sizeof err)) {
        snprintf(msg, sizeof msg, "chip: %s", err);
        eng_fail(j, msg, 0);
        return -1;
    }
    /* The packed scene into scene memory: mapped copy-on-write from the image the caller passed
     * (FuncParams.image, the open scene's), or copied. */
    if (j->fp->image) {
        if (core_load_image(w->tc.core, j->fp->image) != 0) {
            eng_fail(j, "out of memory loading the scene into scene memory", 0);
            return -1;
        }
    } else {
        uint32_t size;
        uint8_t *sm = core_mem(w->tc.core, CORE_MEM_SCENE, &size);
        memcpy(sm, j->p->mem, j->p->size);
    }
    return 0;
}

static int worker_tile(void *ctx, int index, uint32_t t)
{
    Job *j = ctx;
    Worker *w = &j->workers[index];
    if (j->units)
        return run_unit(w, w->tc.core, t, &w->st);
    return j->passes_done ? run_tile_pass(w, w->tc.core, t, &w->st) : run_tile(w, w->tc.core, t, &w->st);
}

/* Each worker's core and timing counters into its stats, and its core closed. */
static void workers_close(Job *j)
{
    for (int i = 0; i < j->nworkers; i++) {
        Worker *w = &j->workers[i];
        if (w->tc.core) {
            w->st.core = *core_stats(w->tc.core);
            w->st.instructions = core_instructions(w->tc.core);
        }
        if (w->tc.tm)
            w->st.timing = *timing_stats(w->tc.tm);
        chipunit_close(&w->cu);
        timedcore_close(&w->tc);
    }
}

/* The workers' counters, summed in worker order (the totals do not depend on which thread ran
 * which tile). */
void eng_stats_sum(FuncStats *st, const Worker *ws, int nthreads)
{
    for (int i = 0; i < nthreads; i++) {
        const FuncStats *s = &ws[i].st;
        for (int k = 0; k < ISA_STAGE_COUNT; k++) {
            st->core.instructions[k] += s->core.instructions[k];
            st->core.vec_instructions[k] += s->core.vec_instructions[k];
            st->core.active_lanes[k] += s->core.active_lanes[k];
            for (int c = 0; c < ISA_C_COUNT; c++)
                st->core.ops[k][c] += s->core.ops[k][c];
            for (int g = 0; g < CORE_GENERATIONS; g++) {
                st->core.gen_instructions[g][k] += s->core.gen_instructions[g][k];
                st->core.gen_vec_instructions[g][k] += s->core.gen_vec_instructions[g][k];
                st->core.gen_active_lanes[g][k] += s->core.gen_active_lanes[g][k];
            }
        }
        for (int o = 0; o < ISA_OP_COUNT; o++)
            st->core.by_op[o] += s->core.by_op[o];
        st->instructions += s->instructions;
        timing_stats_add(&st->timing, &s->timing);
        st->rays_camera += s->rays_camera;
        st->rays_indirect += s->rays_indirect;
        st->rays_shadow += s->rays_shadow;
        st->dropped += s->dropped;
        for (int g = 0; g < FUNC_MAX_GENERATIONS; g++)
            st->rays_per_generation[g] += s->rays_per_generation[g];
        if (s->generations > st->generations)
            st->generations = s->generations;
        for (int g = 0; g < FUNC_MAX_GENERATIONS; g++)
            for (int k = 0; k < FUNC_STAGES; k++) {
                st->gen_streams[g][k] += s->gen_streams[g][k];
                st->gen_rays[g][k] += s->gen_rays[g][k];
            }
        for (int k = 0; k < FUNC_KD_KINDS; k++)
            for (int c = 0; c < FUNC_KD_COUNTERS; c++)
                st->kd_counts[k][c] += s->kd_counts[k][c];
    }
    for (int g = 0; g < FUNC_MAX_GENERATIONS; g++) {
        st->trav_streams += st->gen_streams[g][0];
        st->trav_rays += st->gen_rays[g][0];
        st->isect_streams += st->gen_streams[g][1];
        st->isect_rays += st->gen_rays[g][1];
        st->shade_streams += st->gen_streams[g][2];
        st->shade_rays += st->gen_rays[g][2];
    }
}

/* The tiles (or ray batches) of the run. */
static int job_tiles(Job *job, const FuncParams *fp, char *err, size_t errlen)
{
    const PackedScene *p = job->p;
    const Kernel *k = job->k;
    job->width = sm_u32(p, sm_hdr(p, SM_HDR_WIDTH));
    job->height = sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT));
    job->spp = sm_u32(p, sm_hdr(p, SM_HDR_SPP));
    job->tiles_x = (job->width + k->tile_w - 1) / k->tile_w;
    job->ntiles = job->tiles_x * ((job->height + k->tile_h - 1) / k->tile_h);
    if (fp->batch)
        job->ntiles = (fp->batch->count + k->rays - 1) / k->rays;
    job->tiles = calloc(job->ntiles ? job->ntiles : 1, sizeof(FuncTile));
    if (!job->tiles) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    for (uint32_t t = 0; !fp->batch && t < job->ntiles; t++)
        tile_place(job, t, &job->tiles[t]);
    return 0;
}

/* A session: the kernel built for the scene and the machine, the tiles, and one worker per host
 * thread. func_render and the sampled-mode calls share it. */
struct FuncSession {
    Kernel k;
    Job job;
    FuncStats head;            /* the kernel's figures, known before any run */
    int built;
};

static void session_free(FuncSession *s)
{
    if (!s)
        return;
    workers_close(&s->job);
    free(s->job.tiles);
    free(s->job.workers);
    free(s->job.cores);
    free(s->job.chip_mem);
    free(s->job.pass_cycles);
    free(s->job.pass_mem);
    free(s->job.trace);
    pthread_mutex_destroy(&s->job.lock);
    if (s->built)
        kernel_free(&s->k);
    free(s);
}

int func_open(const PackedScene *p, const FuncParams *fp, FuncSession **out, char *err, size_t errlen)
{
    *out = NULL;
    FuncSession *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    Job *job = &s->job;
    pthread_mutex_init(&job->lock, NULL);
    atomic_init(&job->failed, 0);
    if (kernel_build(p, fp->cfg, fp->kernel_path, fp->needs, fp->batch != NULL, fp->batch ? fp->batch->count : 0, &s->k,
                     err, errlen) != 0) {
        session_free(s);
        return -1;
    }
    s->built = 1;
    FuncStats *h = &s->head;
    h->tile_w = s->k.tile_w;
    h->tile_h = s->k.tile_h;
    snprintf(h->defines, sizeof h->defines, "%s", s->k.defines);
    h->unroll_box = s->k.unroll_box;
    h->kd = s->k.kd;
    h->kd_stack_depth = s->k.kd_stack_depth;
    h->kernel_instructions = s->k.obj.ntext;
    job->p = p;
    job->fp = fp;
    job->k = &s->k;
    if (job_tiles(job, fp, err, errlen) != 0) {
        session_free(s);
        return -1;
    }
    job->nworkers = chip_run_wanted(fp) ? fp->cfg->chip_cores /* a worker per core */
                                        : tiles_threads(fp->threads, fp->batch ? job->ntiles : job->ntiles * job->spp);
    job->workers = calloc((size_t)job->nworkers, sizeof *job->workers);
    if (!job->workers) {
        snprintf(err, errlen, "out of memory");
        session_free(s);
        return -1;
    }
    *out = s;
    return 0;
}

uint64_t func_units_total(const FuncSession *s) { return (uint64_t)s->job.ntiles * s->job.spp; }

/* A failed launch's message and return (-2 when the kernel failed, -1 otherwise). */
static int job_failure(Job *job, char *err, size_t errlen)
{
    snprintf(err, errlen, "%s", job->err);
    return job->trapped ? -2 : -1;
}

int func_units(FuncSession *s, const uint32_t *units, uint32_t n, FuncUnit *out, char *err, size_t errlen)
{
    Job *job = &s->job;
    uint64_t total = func_units_total(s);
    for (uint32_t i = 0; i < n; i++)
        if (units[i] >= total) {
            snprintf(err, errlen, "unit %u: the frame has %llu (tile, pass) units", units[i], (unsigned long long)total);
            return -1;
        }
    job->units = units;
    job->unit_out = out;
    TileLaunch launch = {n, job->nworkers, eng_worker_begin, worker_tile, NULL, job, job->fp->progress,
                         job->fp->progress_ctx, 0};
    tiles_run(&launch);
    job->units = NULL;
    job->unit_out = NULL;
    if (atomic_load(&job->failed))
        return job_failure(job, err, errlen);
    /* The units' figures into their tiles, in list order (the same on any thread count). */
    for (uint32_t i = 0; i < n; i++) {
        FuncTile *ft = &job->tiles[out[i].unit / job->spp];
        tile_add_timed(ft, &out[i]);
        ft->units_timed++;
        ft->instructions += out[i].instructions;
        ft->rays += out[i].rays;
        for (int k = 0; k < ISA_STAGE_COUNT; k++)
            ft->active_lanes[k] += out[i].active_lanes[k];
    }
    return 0;
}

/* The session's figures into st (the workers' counters summed in worker order), the session
 * freed. 0, or -1 when the timing model's totals do not add up. */
static int session_finish(FuncSession *s, FuncStats *st, char *err, size_t errlen)
{
    Job *job = &s->job;
    *st = s->head;
    workers_close(job);
    eng_stats_sum(st, job->workers, job->nworkers);
    int rc = 0;
    if (job->fp->timed) {
        st->timed = 1;
        for (uint32_t i = 0; i < job->ntiles; i++) {
            st->tiles_timed += job->tiles[i].sampled;
            st->units_timed += job->tiles[i].units_timed;
        }
        /* (an opening stops cores inside a unit, whose busy and stall cycles are in and whose
         * cycles are not: its sums are not whole units') */
        if (!job->fp->opening)
            rc = timing_check(&st->timing, err, errlen);
    }
    st->tiles = job->tiles;
    st->ntiles = job->ntiles;
    st->tiles_done = job->ntiles;
    job->tiles = NULL;
    st->chip_cores = job->ncores;
    st->cores = job->cores;
    st->makespan = job->makespan;
    st->chip_mem = job->chip_mem;
    st->pass_cycles = job->pass_cycles;
    st->pass_spp = job->pass_cycles ? job->spp : 0;
    job->pass_cycles = NULL;
    st->pass_mem = job->pass_mem;
    job->pass_mem = NULL;
    st->trace = job->trace;
    st->ntrace = job->ntrace;
    job->trace = NULL;
    job->cores = NULL;
    job->chip_mem = NULL;
    session_free(s);
    return rc;
}

int func_close(FuncSession *s, FuncStats *st, char *err, size_t errlen)
{
    memset(st, 0, sizeof *st);
    if (!s)
        return 0;
    if (atomic_load(&s->job.failed)) {
        int rc = job_failure(&s->job, err, errlen);
        char ignored[256];
        session_finish(s, st, ignored, sizeof ignored);
        return rc;
    }
    return session_finish(s, st, err, errlen);
}

int func_render(const PackedScene *p, const FuncParams *fp, float *rgb, FuncStats *st, char *err,
                size_t errlen)
{
    memset(st, 0, sizeof *st);
    FuncSession *s;
    if (func_open(p, fp, &s, err, errlen) != 0)
        return -1;
    Job *job = &s->job;
    job->rgb = rgb;
    /* A frame's items are its (tile, pass) units, so that the threads share the work more evenly
     * than by whole tiles; a tile's passes still run one after the other, each adding to the
     * framebuffer the one before left (run_tile_pass). Without an image (rgb NULL), a pass table,
     * or with more units than a launch counts (2^32), whole tiles. */
    uint32_t done;
    const int by_pass = !chip_run_wanted(fp) && rgb && !fp->batch && (uint64_t)job->ntiles * job->spp <= UINT32_MAX;
    job->passes_done = by_pass ? calloc(job->ntiles ? job->ntiles : 1, sizeof *job->passes_done) : NULL;
    if (job->passes_done) {
        atomic_init(&job->tiles_done, 0u);
        TileLaunch launch = {job->ntiles * job->spp, job->nworkers, eng_worker_begin, worker_tile, NULL, job, NULL, NULL,
                             job->ntiles};
        tiles_run(&launch);
        done = 0;
        for (uint32_t t = 0; t < job->ntiles; t++) {
            if (job->passes_done[t] == job->spp) {
                done++;
            } else if (job->passes_done[t]) { /* unfinished: black, as a tile never started */
                for (uint32_t y = 0; y < job->tiles[t].h; y++)
                    memset(tile_row(job, &job->tiles[t], y), 0, (size_t)12 * job->tiles[t].w);
            }
        }
        free(job->passes_done);
        job->passes_done = NULL;
    } else if (chip_run_wanted(fp)) {
        done = chip_run_frame(job);
    } else {
        TileLaunch launch = {job->ntiles, job->nworkers, eng_worker_begin, worker_tile, NULL, job, fp->progress,
                             fp->progress_ctx, 0};
        done = tiles_run(&launch);
    }
    float inv = 1.0f / (float)job->spp;
    for (size_t i = 0; rgb && i < 3 * (size_t)job->width * job->height; i++)
        rgb[i] = rgb[i] * inv;
    if (atomic_load(&job->failed)) {
        int rc = job_failure(job, err, errlen);
        /* The tiles that finished are kept (the caller may write them as a partial image). */
        st->tiles_done = done;
        st->ntiles = job->ntiles;
        session_free(s);
        return rc;
    }
    return session_finish(s, st, err, errlen);
}

int func_trace(const PackedScene *p, const FuncParams *fp, FuncStats *st, char *err, size_t errlen)
{
    if (!fp->batch || !fp->hits) {
        snprintf(err, errlen, "trace: no ray batch");
        return -1;
    }
    return func_render(p, fp, NULL, st, err, errlen);
}

void func_stats_free(FuncStats *st)
{
    free(st->tiles);
    st->tiles = NULL;
    free(st->cores);
    st->cores = NULL;
    free(st->chip_mem);
    st->chip_mem = NULL;
    free(st->pass_cycles);
    st->pass_cycles = NULL;
    free(st->pass_mem);
    st->pass_mem = NULL;
    st->pass_spp = 0;
    free(st->trace);
    st->trace = NULL;
    st->ntrace = 0;
}
