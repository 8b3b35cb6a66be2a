/* tests/unit/test_chip.c -- detailed mode on a chip of K cores (docs/chip.md, sim/run/chiprun.c).
 *
 * What must hold: the picture is the one core's (timing never changes a pixel); every core's
 * cycles are busy + stall + idle = the makespan, so the chip's are K x makespan; the distributor
 * hands the next tile to the core that became idle first (ties to the lowest number); with cold
 * units and a bus of its own per core, each tile takes exactly the cycles it takes on the one
 * core of today's machine; and a run gives the same figures every time.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/chip/chip.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/reference.h"
#include "../../sim/timing.h"

#include "../support/packed.h"
#include "../support/shared.h"

static Scene scene;
static PackedScene packed;

static void load(const char *path, int w, int h, int spp) { packed_load(path, w, h, spp, &scene, &packed); }

static void unload(void) { packed_free(&scene, &packed); }

static float *render_on(const CfgMachine *cfg, int threads, FuncStats *st)
{
    size_t n = 3 * (size_t)scene.render.width * scene.render.height;
    float *rgb = calloc(n, sizeof *rgb);
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = threads, .timed = 1};
    cr_assert_eq(func_render(&packed, &fp, rgb, st, err, sizeof err), 0, "%s", err);
    return rgb;
}

static float *render(const CfgMachine *cfg, FuncStats *st) { return render_on(cfg, 2, st); }

/* 128 x 128 pixels in 32 x 32 tiles: 16 tiles. */
static void small_frame(CfgMachine *cfg)
{
    cfg_defaults(cfg);
    cfg->stream_rays = 1024;
}

static void shared_memory(CfgMachine *cfg, int cores)
{
    cfg->chip_cores = cores;
    cfg->chip_memory = CFG_CHIP_MEMORY_SHARED;
    cfg->chip_cold_units = 0;
    cfg->l2_size_kb = 256;
    cfg->l2_banks = 4;
    cfg->noc_latency = 4;
}

/* Every core: busy + stall + idle = the makespan, the makespan the latest finish; the chip's
 * timing totals the cores' sums. */
static void check_chip_accounting(const FuncStats *st, uint32_t k)
{
    cr_assert_eq(st->chip_cores, k);
    char err[256];
    cr_assert_eq(timing_check(&st->timing, err, sizeof err), 0, "%s", err);
    uint64_t latest = 0, busy = 0, stall = 0, idle = 0, tiles = 0;
    for (uint32_t c = 0; c < k; c++) {
        const FuncCore *fc = &st->cores[c];
        cr_expect_eq(fc->busy + fc->stall + fc->idle, st->makespan, "core %u: %llu + %llu + %llu != %llu", c,
                     (unsigned long long)fc->busy, (unsigned long long)fc->stall, (unsigned long long)fc->idle,
                     (unsigned long long)st->makespan);
        cr_expect_eq(fc->busy + fc->stall, fc->finish, "core %u works from cycle 0 to its finish, no gap", c);
        if (fc->finish > latest)
            latest = fc->finish;
        busy += fc->busy;
        stall += fc->stall;
        idle += fc->idle;
        tiles += fc->tiles;
    }
    cr_expect_eq(latest, st->makespan);
    cr_expect_eq(busy + stall + idle, (uint64_t)k * st->makespan);
    /* a frame's (tile, pass) units: each took cycles, and a tile's passes make its cycles */
    for (uint32_t t = 0; st->pass_cycles && t < st->ntiles; t++) {
        uint64_t sum = 0;
        for (uint32_t p = 0; p < st->pass_spp; p++) {
            cr_expect_gt(st->pass_cycles[(uint64_t)t * st->pass_spp + p], 0, "tile %u pass %u took no cycles", t, p);
            sum += st->pass_cycles[(uint64_t)t * st->pass_spp + p];
        }
        cr_expect_eq(sum, st->tiles[t].cycles, "tile %u: its passes %llu cycles, the tile %llu", t,
                     (unsigned long long)sum, (unsigned long long)st->tiles[t].cycles);
    }
    cr_expect_eq(busy, st->timing.busy);
    cr_expect_eq(busy + stall, st->timing.cycles);
    cr_expect_eq(tiles, st->ntiles);
}

/* The tiles go to the cores in the order the cores became idle: tile t (t >= K) to the core whose
 * earlier tile ended first among those still to be given one. Replays the distributor from the
 * tiles' own cycles and cores. */
static void check_distribution(const FuncStats *st, uint32_t k)
{
    uint64_t free_at[64] = {0};
    cr_assert(k <= 64);
    for (uint32_t t = 0; t < st->ntiles; t++) {
        uint32_t best = 0;
        for (uint32_t c = 1; c < k; c++)
            if (free_at[c] < free_at[best])
                best = c;
        cr_expect_eq(st->tiles[t].core, best, "tile %u went to core %u, the first idle was core %u", t,
                     st->tiles[t].core, best);
        free_at[st->tiles[t].core] += st->tiles[t].cycles;
    }
}

Test(chip, own_bus_cold_units_time_each_tile_as_one_core)
{
    load("scenes/cornell/scene.ini", 128, 128, 2);
    CfgMachine one, chip;
    small_frame(&one);
    small_frame(&chip);
    chip.chip_cores = 4; /* chip.memory = bus, chip.cold_units = 1: the defaults */
    /* a direct-mapped scene cache of 256 sets, small enough that the framebuffer's lines and the
     * scene's meet in its sets, and more sets than a tile's framebuffer has lines (192): where a
     * tile's framebuffer lies would change which lines meet */
    one.scene_cache_kb = chip.scene_cache_kb = 16;
    one.scene_cache_ways = chip.scene_cache_ways = 1;
    FuncStats a, b;
    float *ra = render(&one, &a), *rb = render(&chip, &b);
    cr_assert_eq(a.chip_cores, 0, "K = 1 on the paper's bus is today's run");
    cr_assert_eq(memcmp(ra, rb, 3 * sizeof(float) * 128 * 128), 0, "the picture does not depend on the chip");
    cr_assert_eq(a.ntiles, b.ntiles);
    for (uint32_t t = 0; t < a.ntiles; t++)
        cr_expect_eq(a.tiles[t].cycles, b.tiles[t].cycles, "tile %u: %llu cycles alone, %llu on the chip", t,
                     (unsigned long long)a.tiles[t].cycles, (unsigned long long)b.tiles[t].cycles);
    cr_expect_eq(a.timing.cycles, b.timing.cycles);
    cr_assert(b.pass_cycles && b.pass_spp == 2, "a chip's frame reports each pass's cycles");
    check_chip_accounting(&b, 4);
    check_distribution(&b, 4);
    free(ra);
    free(rb);
    func_stats_free(&a);
    func_stats_free(&b);
    unload();
}

Test(chip, shared_memory_accounts_for_every_cycle)
{
    load("scenes/cornell/scene.ini", 128, 128, 1);
    CfgMachine one, chip;
    small_frame(&one);
    small_frame(&chip);
    shared_memory(&chip, 4);
    FuncStats a, b;
    float *ra = render(&one, &a), *rb = render(&chip, &b);
    cr_assert_eq(memcmp(ra, rb, 3 * sizeof(float) * 128 * 128), 0, "the picture does not depend on the chip");
    cr_expect_eq(a.instructions, b.instructions);
    check_chip_accounting(&b, 4);
    check_distribution(&b, 4);
    cr_assert_not_null(b.chip_mem);
    const ChipMemStats *m = b.chip_mem;
    cr_expect_eq(m->requests, b.timing.l1.misses, "every L1 miss is one read below it");
    cr_expect_eq(m->writes, b.timing.l1.writebacks, "every write-back one write");
    cr_expect_eq(m->l2.reads, m->requests, "the network delivers every read to the L2");
    cr_expect_eq(m->l2.hits + m->l2.misses + m->l2.merged, m->l2.reads + m->l2.writes);
    cr_expect(m->l2.misses > 0 && m->dram.reads > 0, "a cold L2 misses to DRAM");
    cr_expect(m->read_latency > 0);
    /* the scene-memory stalls by where the line came from: part of scene_memory, some of each */
    const TimingStats *t = &b.timing;
    cr_expect(t->scene_from[0] + t->scene_from[1] <= t->stalls[TM_SCENE_MEMORY]);
    cr_expect(t->scene_from[0] > 0 && t->scene_from[1] > 0, "L2: %llu, DRAM: %llu stall cycles",
              (unsigned long long)t->scene_from[0], (unsigned long long)t->scene_from[1]);
    cr_expect_eq(a.timing.scene_from[0] + a.timing.scene_from[1], 0, "the paper's machine has no L2 and no DRAM");
    free(ra);
    free(rb);
    func_stats_free(&a);
    func_stats_free(&b);
    unload();
}

Test(chip, same_figures_every_run)
{
    load("scenes/cornell/scene.ini", 128, 128, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 3);
    FuncStats a, b;
    float *ra = render(&chip, &a), *rb = render(&chip, &b);
    cr_expect_eq(a.makespan, b.makespan);
    cr_expect_eq(memcmp(&a.timing, &b.timing, sizeof a.timing), 0);
    cr_expect_eq(memcmp(a.cores, b.cores, 3 * sizeof *a.cores), 0);
    cr_expect_eq(memcmp(a.chip_mem, b.chip_mem, sizeof *a.chip_mem), 0);
    for (uint32_t t = 0; t < a.ntiles; t++)
        cr_expect_eq(a.tiles[t].core, b.tiles[t].core);
    free(ra);
    free(rb);
    func_stats_free(&a);
    func_stats_free(&b);
    unload();
}

Test(chip, more_cores_than_tiles_leaves_cores_idle)
{
    load("scenes/cornell/scene.ini", 64, 64, 1); /* 4 tiles */
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 6);
    FuncStats st;
    float *rgb = render(&chip, &st);
    check_chip_accounting(&st, 6);
    for (uint32_t c = 0; c < 6; c++) {
        cr_expect_eq(st.cores[c].tiles, c < 4 ? 1u : 0u, "core %u", c);
        if (c >= 4)
            cr_expect_eq(st.cores[c].idle, st.makespan);
    }
    free(rgb);
    func_stats_free(&st);
    unload();
}

/* With a network slower than the L1's own bus would be, the scene-memory stalls grow: the chip's
 * memory reaches the timing. */
Test(chip, a_slower_network_stalls_more)
{
    load("scenes/cornell/scene.ini", 64, 64, 1);
    CfgMachine fast, slow;
    small_frame(&fast);
    shared_memory(&fast, 2);
    slow = fast;
    slow.noc_latency = 200;
    FuncStats a, b;
    float *ra = render(&fast, &a), *rb = render(&slow, &b);
    cr_expect(b.timing.stalls[TM_SCENE_MEMORY] > a.timing.stalls[TM_SCENE_MEMORY],
              "network latency 200: %llu scene-memory stall cycles, latency 4: %llu",
              (unsigned long long)b.timing.stalls[TM_SCENE_MEMORY], (unsigned long long)a.timing.stalls[TM_SCENE_MEMORY]);
    cr_expect(b.makespan > a.makespan);
    cr_expect_eq(a.instructions, b.instructions);
    free(ra);
    free(rb);
    func_stats_free(&a);
    func_stats_free(&b);
    unload();
}

/* The figures do not depend on the host threads (docs/chip.md): 16 cores on 1 and on 2 threads,
 * with the shared memory and with a bus per core (where every core runs in every step). */
static void same_on_threads(CfgMachine *chip)
{
    FuncStats a, b;
    float *ra = render_on(chip, 1, &a), *rb = render_on(chip, 2, &b);
    cr_assert_eq(memcmp(ra, rb, 3 * sizeof(float) * 128 * 128), 0);
    cr_expect_eq(a.makespan, b.makespan, "1 thread: %llu cycles, 2 threads: %llu", (unsigned long long)a.makespan,
                 (unsigned long long)b.makespan);
    cr_expect_eq(memcmp(&a.timing, &b.timing, sizeof a.timing), 0);
    cr_expect_eq(memcmp(a.cores, b.cores, 16 * sizeof *a.cores), 0);
    cr_expect((a.chip_mem == NULL) == (b.chip_mem == NULL));
    if (a.chip_mem)
        cr_expect_eq(memcmp(a.chip_mem, b.chip_mem, sizeof *a.chip_mem), 0);
    for (uint32_t t = 0; t < a.ntiles; t++)
        cr_expect_eq(a.tiles[t].core, b.tiles[t].core);
    free(ra);
    free(rb);
    func_stats_free(&a);
    func_stats_free(&b);
}

Test(chip, same_figures_on_one_and_two_host_threads)
{
    load("scenes/cornell/scene.ini", 128, 128, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 16);
    same_on_threads(&chip);
    small_frame(&chip);
    chip.chip_cores = 16;
    chip.chip_cold_units = 0;
    same_on_threads(&chip);
    unload();
}

/* Without an L2 every line a scene cache misses comes from DRAM: its waits are DRAM's. */
Test(chip, without_an_l2_every_miss_is_drams)
{
    load("scenes/cornell/scene.ini", 64, 64, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 2);
    chip.l2_size_kb = 0;
    FuncStats st;
    float *rgb = render(&chip, &st);
    cr_expect_eq(st.timing.scene_from[0], 0);
    cr_expect(st.timing.scene_from[1] > 0);
    cr_expect_eq(st.chip_mem->l2.reads, 0);
    cr_expect_eq(st.chip_mem->dram.reads, st.chip_mem->requests, "one DDR4 burst of 64 bytes a line");
    check_chip_accounting(&st, 2);
    free(rgb);
    func_stats_free(&st);
    unload();
}

/* A sampled chip's units (sim/run/chipunit.h): units [0, n) of the loaded frame, each alone on one
 * core of cfg's shared memory (chip_unit) or of its bus (not), on `threads`, in the order given. */
static void units_on(const CfgMachine *cfg, int chip_unit, int threads, const uint32_t *order, uint32_t n, FuncUnit *out)
{
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = threads, .timed = 1, .chip_unit = chip_unit};
    FuncSession *s;
    cr_assert_eq(func_open(&packed, &fp, &s, err, sizeof err), 0, "%s", err);
    cr_assert_eq(func_units_total(s), n);
    cr_assert_eq(func_units(s, order, n, out, err, sizeof err), 0, "%s", err);
    FuncStats st;
    cr_assert_eq(func_close(s, &st, err, sizeof err), 0, "%s", err);
    func_stats_free(&st);
}

/* A frame of one tile and one pass on a chip: its one unit is the chip's frame, so the unit timed
 * alone on one core of the chip's memory takes exactly the frame's cycles and stalls. */
Test(chip, a_unit_on_the_chips_memory_is_the_one_unit_frame)
{
    load("scenes/cornell/scene.ini", 32, 32, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    FuncStats st;
    float *rgb = render(&chip, &st);
    cr_assert_eq(st.ntiles, 1);
    const uint32_t unit = 0;
    FuncUnit u;
    units_on(&chip, 1, 1, &unit, 1, &u);
    cr_expect_eq(u.cycles, st.makespan, "alone %llu cycles, the chip's frame %llu", (unsigned long long)u.cycles,
                 (unsigned long long)st.makespan);
    cr_expect_eq(u.busy, st.tiles[0].busy);
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        cr_expect_eq(u.stalls[c], st.tiles[0].stalls[c], "stall cause %d", c);
    cr_expect_eq(u.instructions, st.tiles[0].instructions);
    free(rgb);
    func_stats_free(&st);
    unload();
}

/* Every unit starts from a cold chip: its figures do not depend on the units run before it on the
 * same host thread, nor on the threads; and they are the chip's memory's, not the bus's. */
Test(chip, chip_units_start_cold_on_any_thread_in_any_order)
{
    load("scenes/cornell/scene.ini", 64, 64, 2); /* 4 tiles, 2 passes: 8 units */
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 16);
    enum { N = 8 };
    const uint32_t fwd[N] = {0, 1, 2, 3, 4, 5, 6, 7}, back[N] = {7, 6, 5, 4, 3, 2, 1, 0};
    FuncUnit a[N], b[N], bus[N];
    units_on(&chip, 1, 1, fwd, N, a);
    units_on(&chip, 1, 2, back, N, b);
    units_on(&chip, 0, 2, fwd, N, bus);
    int differ = 0;
    for (uint32_t i = 0; i < N; i++) {
        const FuncUnit *x = &a[i], *y = &b[N - 1 - i];
        cr_assert_eq(x->unit, y->unit);
        cr_expect_eq(x->cycles, y->cycles, "unit %u: %llu cycles after the units before it on one thread, %llu "
                     "in the other order on two", x->unit, (unsigned long long)x->cycles, (unsigned long long)y->cycles);
        cr_expect_eq(x->instructions, bus[i].instructions);
        differ += x->cycles != bus[i].cycles;
    }
    cr_expect(differ > 0, "no unit's cycles changed with the chip's memory in place of the bus");
    unload();
}

/* A sampled chip's opening (FuncParams.opening): the chip's frame until pass 0 of its first K
 * tiles has ended. Every unit that ended by then took exactly its cycles in the whole frame; the
 * first wave's all did. On one host thread and on two. */
Test(chip, the_opening_is_the_frames_first_wave_exactly)
{
    load("scenes/cornell/scene.ini", 128, 128, 2); /* 16 tiles, 2 passes */
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    FuncStats full;
    float *rgb = render(&chip, &full);
    cr_assert(full.pass_cycles && full.pass_spp == 2);
    for (int threads = 1; threads <= 2; threads++) {
        static char err[65536];
        FuncParams fp = {.cfg = &chip, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                         .threads = threads, .timed = 1, .opening = 1};
        FuncStats op;
        cr_assert_eq(func_render(&packed, &fp, NULL, &op, err, sizeof err), 0, "%s", err);
        cr_assert(op.pass_cycles && op.pass_spp == 2);
        uint32_t ended = 0;
        for (uint32_t u = 0; u < 16 * 2; u++) {
            if (u % 2 == 0 && u / 2 < 4)
                cr_expect_gt(op.pass_cycles[u], 0, "the first wave's unit %u did not end", u);
            if (op.pass_cycles[u]) {
                ended++;
                cr_expect_eq(op.pass_cycles[u], full.pass_cycles[u], "unit %u: %llu cycles in the opening, %llu in the frame",
                             u, (unsigned long long)op.pass_cycles[u], (unsigned long long)full.pass_cycles[u]);
            }
        }
        cr_expect_lt(ended, 16 * 2, "the opening ran the whole frame");
        cr_expect_lt(op.makespan, full.makespan);
        func_stats_free(&op);
    }
    free(rgb);
    func_stats_free(&full);
    unload();
}

/* The golden model's record of what a unit reads (RefParams.unit_line): the nodes and primitives
 * of the kernel's packed scene at their scene-memory addresses, so they can warm a sampled chip's
 * L2. A frame of one unit on one core of a chip whose L1 starts cold: the lines its L1 fetched
 * are the lines the kernel read. The golden model walks each ray on its own and the kernel a
 * stream, so the two sets differ a little; most of the golden model's lines must be the kernel's
 * (a wrong address would give none). */
typedef struct LineSet {
    uint64_t *line;
    size_t n, cap;
    uint32_t units_seen;
} LineSet;

static void note_line(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes)
{
    LineSet *s = ctx;
    s->units_seen |= 1u << (unit & 31);
    for (uint64_t l = addr / 64; l <= (addr + bytes - 1) / 64; l++) {
        if (s->n == s->cap) {
            s->cap = s->cap ? 2 * s->cap : 1024;
            s->line = realloc(s->line, s->cap * sizeof *s->line);
            cr_assert_not_null(s->line);
        }
        s->line[s->n++] = l;
    }
}

/* The frame of chip with --mem-trace's record of its L1s' requests below (st: func_stats_free). */
static void traced_frame(const CfgMachine *chip, FuncStats *st)
{
    static char err[65536];
    FuncParams fp = {.cfg = chip, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = 1, .timed = 1, .mem_trace = 1};
    cr_assert_eq(func_render(&packed, &fp, NULL, st, err, sizeof err), 0, "%s", err);
}

static int u64_order(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

Test(chip, the_golden_models_lines_are_the_kernels)
{
    load("scenes/cornell/scene.ini", 32, 32, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 1);
    static char err[65536];
    FuncStats st;
    traced_frame(&chip, &st);
    uint64_t *kernel = malloc((st.ntrace ? st.ntrace : 1) * sizeof *kernel);
    size_t nk = 0;
    for (size_t i = 0; i < st.ntrace; i++)
        if (!st.trace[i].write)
            kernel[nk++] = st.trace[i].addr / 64;
    qsort(kernel, nk, sizeof *kernel, u64_order);
    size_t kd = 0; /* the kernel's distinct lines (a line its L1 evicted is fetched again) */
    for (size_t i = 0; i < nk; i++)
        if (!kd || kernel[i] != kernel[kd - 1])
            kernel[kd++] = kernel[i];
    nk = kd;

    LineSet g = {0};
    float *rgb = calloc(3 * 32 * 32, sizeof *rgb);
    RefParams rp = {.tile = 32, .seed = 1, .threads = 1, .unit_line = note_line, .unit_line_ctx = &g};
    cr_assert_eq(ref_render(&packed, &rp, rgb, NULL, err, sizeof err), 0, "%s", err);
    cr_assert_eq(g.units_seen, 1u, "one unit, unit 0");
    cr_assert_gt(g.n, 0);
    qsort(g.line, g.n, sizeof *g.line, u64_order);
    size_t distinct = 0, found = 0;
    for (size_t i = 0; i < g.n; i++) {
        if (i && g.line[i] == g.line[i - 1])
            continue;
        distinct++;
        found += bsearch(&g.line[i], kernel, nk, sizeof *kernel, u64_order) != NULL;
    }
    cr_expect_geq(found * 10, distinct * 9, "%zu of the golden model's %zu lines were the kernel's (of its %zu)", found,
                  distinct, nk);
    free(rgb);
    free(g.line);
    free(kernel);
    func_stats_free(&st);
    unload();
}

/* RefParams.tiles_only: the golden model renders just the tiles asked for (a warming needs a few
 * units' lines, not the frame's), and refuses a tile the frame does not have. */
Test(chip, the_golden_model_renders_only_the_tiles_asked_for)
{
    load("scenes/cornell/scene.ini", 64, 64, 1); /* 4 tiles */
    static char err[4096];
    LineSet g = {0};
    float *rgb = calloc(3 * 64 * 64, sizeof *rgb);
    const uint32_t two = 2, nine = 9;
    RefParams rp = {.tile = 32, .seed = 1, .threads = 2, .unit_line = note_line, .unit_line_ctx = &g,
                    .tiles_only = &two, .ntiles_only = 1};
    RefStats rs;
    cr_assert_eq(ref_render(&packed, &rp, rgb, &rs, err, sizeof err), 0, "%s", err);
    cr_expect_eq(g.units_seen, 1u << 2, "only tile 2's unit");
    cr_expect_eq(rs.tiles, 1);
    double outside = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++)
            if (!(x < 32 && y >= 32)) /* tile 2: the lower left */
                outside += rgb[3 * (64 * y + x)] + rgb[3 * (64 * y + x) + 1] + rgb[3 * (64 * y + x) + 2];
    cr_expect_eq(outside, 0.0, "pixels outside tile 2 were rendered");
    rp.tiles_only = &nine;
    cr_expect_eq(ref_render(&packed, &rp, rgb, NULL, err, sizeof err), -1);
    cr_expect(strstr(err, "tile 9 of a frame of 4 tiles"), "%s", err);
    free(rgb);
    free(g.line);
    unload();
}

/* FuncParams.unit_warm: a chip's unit starts with the levels warmed by the lines given. Warmed
 * with the very lines it will read (its own L1 misses, from --mem-trace's record of a run of it),
 * the unit finds them in the L2 and takes fewer cycles than cold, and the same each time. */
typedef struct Warm {
    uint64_t *lines;
    size_t n;
    uint32_t asked;
} Warm;

static const uint64_t *warm_lines(void *ctx, uint32_t unit, size_t *n)
{
    Warm *w = ctx;
    w->asked |= 1u << (unit & 31);
    *n = w->n;
    return w->lines;
}

Test(chip, a_chip_unit_warmed_with_its_own_lines_is_faster)
{
    load("scenes/cornell/scene.ini", 32, 32, 1);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    chip.scene_cache_kb = 4; /* an L1 the unit's lines overflow: they come again from below */
    static char err[65536];
    FuncStats st;
    traced_frame(&chip, &st);
    Warm w = {malloc((st.ntrace ? st.ntrace : 1) * sizeof(uint64_t)), 0, 0};
    for (size_t i = 0; i < st.ntrace; i++)
        if (!st.trace[i].write)
            w.lines[w.n++] = st.trace[i].addr;
    cr_assert_gt(w.n, 0);
    func_stats_free(&st);

    const uint32_t unit = 0;
    FuncUnit cold, warm[2];
    units_on(&chip, 1, 1, &unit, 1, &cold);
    for (int k = 0; k < 2; k++) {
        FuncParams up = {.cfg = &chip, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                         .threads = 1, .timed = 1, .chip_unit = 1, .unit_warm = warm_lines, .unit_warm_ctx = &w};
        FuncSession *s;
        cr_assert_eq(func_open(&packed, &up, &s, err, sizeof err), 0, "%s", err);
        cr_assert_eq(func_units(s, &unit, 1, &warm[k], err, sizeof err), 0, "%s", err);
        FuncStats ss;
        cr_assert_eq(func_close(s, &ss, err, sizeof err), 0, "%s", err);
        func_stats_free(&ss);
    }
    cr_expect_eq(w.asked, 1u, "asked for unit 0's lines");
    cr_expect_lt(warm[0].cycles, cold.cycles, "warmed %llu cycles, cold %llu", (unsigned long long)warm[0].cycles,
                 (unsigned long long)cold.cycles);
    cr_expect_eq(warm[0].cycles, warm[1].cycles);
    cr_expect_eq(warm[0].instructions, cold.instructions);
    free(w.lines);
    unload();
}

/* FuncParams.unit_warm_l1: a chip's unit starts with its L1 warmed by the lines given and, past
 * its tile's first pass, by its tile's framebuffer (which the earlier passes wrote). Unit 1 (tile
 * 0, pass 1) of a 32 x 32 x 2 Cornell frame, whose scene lines all fit in the 64 KB L1: with an
 * empty list its framebuffer's 32 x 32 x 12 bytes = 192 lines are warm, so it misses fewer lines
 * than cold, at most 192 fewer (the pixels a pass adds to: not all of them), and its stores do
 * not wait for their lines, so the cycles stay; with every scene line the frame read as well it
 * misses none (so the framebuffer's warming covered every line it added to) and takes fewer
 * cycles. Unit 0 (pass 0) has no framebuffer to warm. Each the same twice. */
static const uint64_t *no_lines(void *ctx, uint32_t unit, size_t *n)
{
    (void)ctx;
    (void)unit;
    *n = 0;
    return NULL;
}

static FuncUnit unit_l1(const CfgMachine *cfg, uint32_t unit, const uint64_t *(*l1)(void *, uint32_t, size_t *),
                        Warm *w, uint64_t *misses)
{
    static char err[65536];
    FuncParams up = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1, .threads = 1,
                     .timed = 1, .chip_unit = 1, .unit_warm_l1 = l1, .unit_warm_ctx = w};
    FuncSession *s;
    FuncUnit u;
    cr_assert_eq(func_open(&packed, &up, &s, err, sizeof err), 0, "%s", err);
    cr_assert_eq(func_units(s, &unit, 1, &u, err, sizeof err), 0, "%s", err);
    FuncStats ss;
    cr_assert_eq(func_close(s, &ss, err, sizeof err), 0, "%s", err);
    *misses = ss.timing.l1.misses;
    func_stats_free(&ss);
    return u;
}

Test(chip, a_chip_unit_with_its_l1_warmed_is_faster)
{
    load("scenes/cornell/scene.ini", 32, 32, 2);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    FuncStats st;
    traced_frame(&chip, &st);
    Warm w = {malloc((st.ntrace ? st.ntrace : 1) * sizeof(uint64_t)), 0, 0};
    for (size_t i = 0; i < st.ntrace; i++)
        if (!st.trace[i].write && !(st.trace[i].addr >> MEM_SPACE_SHIFT)) /* scene lines only */
            w.lines[w.n++] = st.trace[i].addr;
    cr_assert_gt(w.n, 0);
    cr_assert_lt(w.n, (size_t)chip.scene_cache_kb * 1024 / (size_t)chip.scene_line_bytes, "the L1 holds them");
    func_stats_free(&st);
    uint64_t m[7];
    const FuncUnit cold0 = unit_l1(&chip, 0, NULL, &w, &m[0]), cold1 = unit_l1(&chip, 1, NULL, &w, &m[1]);
    const FuncUnit fb = unit_l1(&chip, 1, no_lines, &w, &m[2]), fb2 = unit_l1(&chip, 1, no_lines, &w, &m[3]);
    const FuncUnit all = unit_l1(&chip, 1, warm_lines, &w, &m[4]), all2 = unit_l1(&chip, 1, warm_lines, &w, &m[5]);
    const FuncUnit first = unit_l1(&chip, 0, no_lines, &w, &m[6]);
    cr_expect(m[2] < m[1] && m[1] - m[2] <= 192, "cold %llu misses, framebuffer warmed %llu",
              (unsigned long long)m[1], (unsigned long long)m[2]);
    cr_expect_eq(fb.cycles, cold1.cycles);
    cr_expect_eq(m[4], 0, "%llu misses with every line warmed", (unsigned long long)m[4]);
    cr_expect_lt(all.cycles, cold1.cycles, "warmed %llu, cold %llu", (unsigned long long)all.cycles,
                 (unsigned long long)cold1.cycles);
    cr_expect(fb.cycles == fb2.cycles && m[2] == m[3] && all.cycles == all2.cycles && m[4] == m[5]);
    cr_expect_eq(all.instructions, cold1.instructions);
    cr_expect(first.cycles == cold0.cycles && m[6] == m[0], "a tile's first pass has no framebuffer to warm");
    free(w.lines);
    unload();
}

/* A sampled chip's wave (FuncParams.wave): K units starting together on a cold chip. A frame of K
 * tiles and one pass is one wave, so the wave of its units takes exactly the frame's cycles per
 * unit; warmed with lines, the same wave takes other cycles; more units than cores is refused. */
Test(chip, a_wave_of_the_frames_units_is_the_frame)
{
    load("scenes/cornell/scene.ini", 64, 64, 1); /* 4 tiles */
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    chip.scene_cache_kb = 4;
    FuncStats full;
    float *rgb = render(&chip, &full);
    static char err[65536];
    const uint32_t wave[5] = {0, 1, 2, 3, 0};
    FuncParams fp = {.cfg = &chip, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = 2, .timed = 1, .wave = wave, .nwave = 4};
    FuncStats w;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), 0, "%s", err);
    for (uint32_t u = 0; u < 4; u++)
        cr_expect_eq(w.pass_cycles[u], full.pass_cycles[u], "unit %u: %llu in the wave, %llu in the frame", u,
                     (unsigned long long)w.pass_cycles[u], (unsigned long long)full.pass_cycles[u]);
    func_stats_free(&w);
    /* warmed with every line the frame's L1s fetched: fewer cycles in all */
    fp.mem_trace = 1;
    FuncStats tr;
    cr_assert_eq(func_render(&packed, &fp, NULL, &tr, err, sizeof err), 0, "%s", err);
    uint64_t *lines = malloc((tr.ntrace ? tr.ntrace : 1) * sizeof *lines);
    size_t n = 0;
    for (size_t i = 0; i < tr.ntrace; i++)
        if (!tr.trace[i].write)
            lines[n++] = tr.trace[i].addr;
    func_stats_free(&tr);
    fp.mem_trace = 0;
    fp.wave_warm = lines;
    fp.nwave_warm = n;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), 0, "%s", err);
    uint64_t cold = 0, warm = 0;
    for (uint32_t u = 0; u < 4; u++) {
        cold += full.pass_cycles[u];
        warm += w.pass_cycles[u];
    }
    cr_expect_lt(warm, cold, "warmed %llu cycles, cold %llu", (unsigned long long)warm, (unsigned long long)cold);
    func_stats_free(&w);
    fp.nwave = 5;
    cr_expect_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), -1);
    cr_expect(strstr(err, "a wave of 5 units on 4 cores"), "%s", err);
    func_stats_free(&w);
    free(lines);
    free(rgb);
    func_stats_free(&full);
    unload();
}

/* A wave of two units a core (FuncParams.wave_passes = 2: a sampled chip's memory correction,
 * docs/sampling.md step 5): a core whose unit is not its tile's last pass runs the next pass after
 * it, one whose unit is the last runs pass 0 of wave_next's tile; the units' shares of the shared
 * memory's work (FuncStats.pass_mem: from a unit's start to the next's on its core, the last one's
 * to the end) add up to the chip's counters exactly. The same on 1 and 2 host threads. The Cornell
 * box at 128 x 64 x 2: 8 tiles, 16 units, on 4 cores. */
Test(chip, a_wave_of_two_passes_a_core)
{
    load("scenes/cornell/scene.ini", 128, 64, 2);
    CfgMachine chip;
    small_frame(&chip);
    shared_memory(&chip, 4);
    chip.scene_cache_kb = 1;
    static char err[65536];
    const uint32_t wave[4] = {0, 3, 4, 7}, next[4] = {UINT32_MAX, 5, UINT32_MAX, UINT32_MAX};
    FuncParams fp = {.cfg = &chip, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = 2, .timed = 1, .wave = wave, .nwave = 4, .wave_passes = 2, .wave_next = next};
    FuncStats w, w1;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), 0, "%s", err);
    fp.threads = 1;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w1, err, sizeof err), 0, "%s", err);
    cr_assert(w.pass_cycles && w.pass_mem && w.chip_mem);
    /* run: 0 then 1 (tile 0), 3 then 10 (tile 1's last pass, then tile 5's first), 4 then 5, 7 */
    const int ran[16] = {1, 1, 0, 1, 1, 1, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0};
    uint64_t req = 0, lat = 0, acc = 0, hits = 0, bytes = 0;
    for (uint32_t u = 0; u < 16; u++) {
        cr_expect_eq(w.pass_cycles[u] > 0, ran[u], "unit %u: %llu cycles", u, (unsigned long long)w.pass_cycles[u]);
        cr_expect_eq(w.pass_cycles[u], w1.pass_cycles[u], "unit %u on 1 and 2 threads", u);
        req += w.pass_mem[u].requests;
        lat += w.pass_mem[u].read_latency;
        acc += w.pass_mem[u].l2_accesses;
        hits += w.pass_mem[u].l2_hits;
        bytes += w.pass_mem[u].dram_bytes;
        cr_expect(ran[u] || w.pass_mem[u].requests == 0, "unit %u did not run but has requests", u);
    }
    const ChipMemStats *m = w.chip_mem;
    cr_expect_gt(req, 0);
    cr_expect_eq(req, m->requests);
    cr_expect_eq(lat, m->read_latency, "latency %llu of %llu", (unsigned long long)lat, (unsigned long long)m->read_latency);
    cr_expect_eq(acc, m->l2.reads + m->l2.writes);
    cr_expect_eq(hits, m->l2.hits);
    cr_expect_eq(bytes, m->dram.bytes);
    cr_expect_gt(bytes, 0);
    func_stats_free(&w);
    func_stats_free(&w1);
    /* one unit a core (wave_passes 0): units 1, 5 and 10 do not run */
    fp.wave_passes = 0;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), 0, "%s", err);
    for (uint32_t u = 0; u < 16; u++)
        cr_expect_eq(w.pass_cycles[u] > 0, ran[u] && u != 1 && u != 5 && u != 10, "unit %u", u);
    func_stats_free(&w);
    /* without an L2 every request is DRAM's: the units' reads add up to the chip's, and their
     * bytes (counted as their L1s sent them) to those DRAM served, those that came in and those
     * still on their way when the wave ended: served <= came in <= sent */
    chip.l2_size_kb = 0;
    fp.wave_passes = 2;
    cr_assert_eq(func_render(&packed, &fp, NULL, &w, err, sizeof err), 0, "%s", err);
    req = bytes = 0;
    for (uint32_t u = 0; u < 16; u++) {
        req += w.pass_mem[u].requests;
        bytes += w.pass_mem[u].dram_bytes;
        cr_expect_eq(w.pass_mem[u].l2_accesses, 0);
    }
    const uint64_t line = (uint64_t)chip.scene_line_bytes, in = w.chip_mem->requests + w.chip_mem->writes;
    cr_expect_eq(req, w.chip_mem->requests);
    cr_expect(w.chip_mem->dram.bytes <= in * line && in * line <= bytes && bytes > 0, "served %llu, in %llu, sent %llu",
              (unsigned long long)w.chip_mem->dram.bytes, (unsigned long long)(in * line), (unsigned long long)bytes);
    func_stats_free(&w);
    unload();
}
