/* tests/unit/test_detailed.c -- detailed mode: the path-tracing kernel timed on the machine.
 *
 * The timing model must not change the picture (same image bits as functional mode), must
 * account for every cycle (busy + stalls = cycles overall, per stage, per generation, per tile:
 * func_render asserts it on every run and these tests check it again), and must give the same
 * cycles for any host thread count and on reruns. Also: the trends the model exists to show go
 * the right way (wider SIMD: fewer busy cycles; a one-port interconnect: contention; no scene
 * cache: more scene-memory stalls; a longer partition: more partition stalls).
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/timing.h"

#include "../support/packed.h"
#include "../support/shared.h"

static Scene scene;
static PackedScene packed;

static void load(const char *path, int w, int h, int spp) { packed_load(path, w, h, spp, &scene, &packed); }

static void unload(void) { packed_free(&scene, &packed); }

static float *render(const CfgMachine *cfg, int threads, int timed, FuncStats *st)
{
    size_t n = 3 * (size_t)scene.render.width * scene.render.height;
    float *rgb = calloc(n, sizeof *rgb);
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1, .threads = threads, .timed = timed};
    cr_assert_eq(func_render(&packed, &fp, rgb, st, err, sizeof err), 0, "%s", err);
    return rgb;
}

static uint64_t stall_sum(const TimingStats *t)
{
    uint64_t s = 0;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        s += t->stalls[c];
    return s;
}

/* spp: the render's samples per pixel (each pass of each tile is one timed run). */
static void check_accounting(const FuncStats *st, uint32_t spp)
{
    const TimingStats *t = &st->timing;
    char err[256];
    cr_assert_eq(timing_check(t, err, sizeof err), 0, "%s", err);
    cr_expect_eq(t->busy + stall_sum(t), t->cycles);
    cr_expect_eq(t->busy, st->instructions, "one busy cycle per instruction: %llu vs %llu",
                 (unsigned long long)t->busy, (unsigned long long)st->instructions);
    uint64_t tiles = 0;
    for (uint32_t i = 0; i < st->ntiles; i++) {
        uint64_t s = st->tiles[i].busy;
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            s += st->tiles[i].stalls[c];
        cr_expect_eq(s, st->tiles[i].cycles, "tile %u: busy + stalls != cycles", i);
        tiles += st->tiles[i].cycles;
    }
    cr_expect_eq(tiles, t->cycles, "tile cycles add up to %llu, total %llu", (unsigned long long)tiles,
                 (unsigned long long)t->cycles);
    cr_expect_eq(t->runs, (uint64_t)st->ntiles * spp, "one timed run per pass of each tile: %llu runs, %u tiles x %u",
                 (unsigned long long)t->runs, st->ntiles, spp);
}

Test(detailed, same_image_bits_as_functional_and_every_cycle_accounted, .fini = unload)
{
    load("scenes/cornell/spheres.ini", 64, 48, 2);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    FuncStats fs, ds;
    float *f = render(&cfg, 2, 0, &fs);
    float *d = render(&cfg, 2, 1, &ds);
    size_t n = 3 * (size_t)scene.render.width * scene.render.height;
    cr_expect_eq(memcmp(f, d, n * sizeof *f), 0, "the timing model changed the image");
    cr_expect_eq(fs.instructions, ds.instructions);
    cr_expect_eq(fs.timed, 0);
    cr_expect_eq(ds.timed, 1);
    cr_expect_eq(fs.timing.cycles, 0, "functional mode counted cycles");
    check_accounting(&ds, (uint32_t)scene.render.spp);
    const TimingStats *t = &ds.timing;
    cr_expect_gt(t->cycles, t->busy, "a real kernel stalls");
    cr_expect_gt(t->stalls[TM_DATA_DEPENDENCY], 0);
    cr_expect_gt(t->stalls[TM_CONTROL], 0);
    cr_expect_gt(t->rb.accesses, 0);
    cr_expect_gt(t->agu.fetches, 0);
    cr_expect_gt(t->part.runs, 0);
    cr_expect_gt(t->l1.accesses, 0);
    printf("detailed: cornell spheres 64x48 2 spp M=1024: %llu cycles, %llu busy, %llu instructions\n",
           (unsigned long long)t->cycles, (unsigned long long)t->busy, (unsigned long long)ds.instructions);
    free(f);
    free(d);
    func_stats_free(&fs);
    func_stats_free(&ds);
}

Test(detailed, identical_cycles_for_any_thread_count_and_rerun, .fini = unload)
{
    load("scenes/cornell/scene.ini", 96, 64, 2);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    FuncStats a, b, c;
    float *ia = render(&cfg, 1, 1, &a);
    float *ib = render(&cfg, 2, 1, &b);
    float *ic = render(&cfg, 2, 1, &c);
    size_t n = 3 * (size_t)scene.render.width * scene.render.height;
    cr_expect_eq(memcmp(ia, ib, n * sizeof *ia), 0);
    cr_expect_eq(memcmp(&a.timing, &b.timing, sizeof a.timing), 0, "timing differs between 1 and 2 threads");
    cr_expect_eq(memcmp(&b.timing, &c.timing, sizeof b.timing), 0, "timing differs between reruns");
    for (uint32_t i = 0; i < a.ntiles; i++)
        cr_expect_eq(a.tiles[i].cycles, b.tiles[i].cycles, "tile %u", i);
    free(ia);
    free(ib);
    free(ic);
    func_stats_free(&a);
    func_stats_free(&b);
    func_stats_free(&c);
}

/* One detailed run of the Cornell box with a config change; returns its timing. */
static TimingStats run_with(const char *set)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    CfgErrors errs = {0};
    if (set)
        cr_assert_eq(cfg_set(&cfg, set, &errs), 0, "%s", errs.text);
    FuncStats st;
    float *rgb = render(&cfg, 2, 1, &st);
    check_accounting(&st, (uint32_t)scene.render.spp);
    TimingStats t = st.timing;
    free(rgb);
    func_stats_free(&st);
    return t;
}

Test(detailed, machine_changes_move_the_cycles_the_right_way, .fini = unload)
{
    load("scenes/cornell/scene.ini", 64, 64, 1);
    TimingStats base = run_with(NULL);
    TimingStats n8 = run_with("core.simd_width=8");
    TimingStats port1 = run_with("interconnect.ports=1");
    TimingStats nocache = run_with("scene.cache_kb=0");
    TimingStats slowpart = run_with("partition.ids_per_cycle=2");
    TimingStats slowagu = run_with("agu.ids_per_cycle=1");
    TimingStats conflict = run_with("raybuf.banks=1");
    cr_expect_gt(n8.busy, base.busy, "N = 8 needs more instructions than N = 16");
    cr_expect_gt(port1.stalls[TM_INTERCONNECT] + port1.xbar.unit_delay, base.stalls[TM_INTERCONNECT] + base.xbar.unit_delay);
    cr_expect_eq(port1.busy, base.busy, "the interconnect does not change the program");
    cr_expect_gt(nocache.stalls[TM_SCENE_MEMORY], base.stalls[TM_SCENE_MEMORY]);
    cr_expect_eq(nocache.l1.hits, 0);
    cr_expect_gt(slowpart.stalls[TM_PARTITION], base.stalls[TM_PARTITION]);
    cr_expect_gt(slowagu.stalls[TM_ADDRESS_FETCH], base.stalls[TM_ADDRESS_FETCH]);
    cr_expect_gt(conflict.stalls[TM_BANK_CONFLICT], base.stalls[TM_BANK_CONFLICT]);
    printf("detailed trends (cornell 64x64, 1 spp, M=1024): cycles N16 %llu, N8 %llu; interconnect stalls 2 ports %llu, "
           "1 port %llu; scene stalls cached %llu, uncached %llu\n",
           (unsigned long long)base.cycles, (unsigned long long)n8.cycles,
           (unsigned long long)base.stalls[TM_INTERCONNECT], (unsigned long long)port1.stalls[TM_INTERCONNECT],
           (unsigned long long)base.stalls[TM_SCENE_MEMORY], (unsigned long long)nocache.stalls[TM_SCENE_MEMORY]);
}
