/* tests/unit/test_units.c -- sampled mode's units (sim/run/engine.h func_open / func_units /
 * func_close): a (tile, pass) unit run alone takes exactly the instructions and cycles it takes in
 * the full detailed run, so timing every unit reproduces detailed mode exactly, in any order and
 * on any thread count; bad unit numbers are refused.
 */
#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/run/engine.h"
#include "../../sim/run/run.h"

#define SCENE "scenes/cornell/scene.ini"

static void open_scene(RunScene *sc, int w, int h, int spp)
{
    char err[4096];
    RunSize z = {w, h, spp, -1};
    cr_assert_eq(run_scene_open(sc, SCENE, &z, NULL, RUN_DETAILED, NULL, err, sizeof err), 0, "%s", err);
}

static FuncParams timed_params(const CfgMachine *cfg, const RunScene *sc, int threads)
{
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .image = sc->image, .needs = sc->s.needs,
                     .seed = 1, .threads = threads, .timed = 1};
    return fp;
}

/* Every unit, in the order given, on `threads`: each tile's units add up to its detailed figures,
 * and the sums to the frame's. */
static void expect_units_equal_detailed(const uint32_t *order, uint32_t n, int threads)
{
    RunScene sc;
    open_scene(&sc, 96, 32, 2); /* 3 tiles of 32 x 32, 2 passes: 6 units */
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024; /* tiles of 32 x 32 */
    char err[4096];
    FuncParams fp = timed_params(&cfg, &sc, threads);
    float *rgb = calloc(3 * 96 * 32, sizeof *rgb);
    FuncStats det;
    cr_assert_eq(func_render(&sc.p, &fp, rgb, &det, err, sizeof err), 0, "%s", err);

    FuncSession *s;
    cr_assert_eq(func_open(&sc.p, &fp, &s, err, sizeof err), 0, "%s", err);
    cr_assert_eq(func_units_total(s), det.ntiles * 2);
    cr_assert_eq(n, det.ntiles * 2);
    FuncUnit *out = calloc(n, sizeof *out);
    /* in two rounds, as the sequential rule would */
    cr_assert_eq(func_units(s, order, n / 3, out, err, sizeof err), 0, "%s", err);
    cr_assert_eq(func_units(s, order + n / 3, n - n / 3, out + n / 3, err, sizeof err), 0, "%s", err);
    FuncStats st;
    cr_assert_eq(func_close(s, &st, err, sizeof err), 0, "%s", err);

    uint64_t cycles = 0, instr = 0;
    for (uint32_t i = 0; i < n; i++) {
        cr_expect_eq(out[i].unit, order[i]);
        cycles += out[i].cycles;
        instr += out[i].instructions;
    }
    cr_expect_eq(cycles, det.timing.cycles, "units: %llu cycles, detailed: %llu", (unsigned long long)cycles,
                 (unsigned long long)det.timing.cycles);
    cr_expect_eq(instr, det.instructions, "units: %llu instructions, detailed: %llu", (unsigned long long)instr,
                 (unsigned long long)det.instructions);
    cr_expect_eq(st.timing.cycles, det.timing.cycles);
    cr_expect_eq(st.timing.busy, det.timing.busy);
    cr_expect_eq(st.instructions, det.instructions);
    cr_expect_eq(st.rays_camera + st.rays_indirect + st.rays_shadow,
                 det.rays_camera + det.rays_indirect + det.rays_shadow);
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        cr_expect_eq(st.timing.stalls[c], det.timing.stalls[c], "stall cause %d", c);
    cr_assert_eq(st.ntiles, det.ntiles);
    for (uint32_t t = 0; t < det.ntiles; t++) {
        cr_expect_eq(st.tiles[t].cycles, det.tiles[t].cycles, "tile %u: %llu, detailed %llu", t,
                     (unsigned long long)st.tiles[t].cycles, (unsigned long long)det.tiles[t].cycles);
        cr_expect_eq(st.tiles[t].instructions, det.tiles[t].instructions, "tile %u", t);
        cr_expect_eq(st.tiles[t].units_timed, 2u, "tile %u", t);
        cr_expect_eq(st.tiles[t].x0, det.tiles[t].x0);
        cr_expect_eq(st.tiles[t].w, det.tiles[t].w);
    }
    cr_expect_eq(st.units_timed, n);
    func_stats_free(&st);
    func_stats_free(&det);
    free(out);
    free(rgb);
    run_scene_close(&sc);
}

Test(units, every_unit_in_order_equals_detailed)
{
    uint32_t order[6];
    for (uint32_t i = 0; i < 6; i++)
        order[i] = i;
    expect_units_equal_detailed(order, 6, 1);
}

Test(units, every_unit_shuffled_on_two_threads_equals_detailed)
{
    const uint32_t order[6] = {5, 2, 0, 3, 1, 4};
    expect_units_equal_detailed(order, 6, 2);
}

Test(units, a_unit_outside_the_frame_is_refused)
{
    RunScene sc;
    open_scene(&sc, 32, 32, 2);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    char err[4096];
    FuncParams fp = timed_params(&cfg, &sc, 1);
    FuncSession *s;
    cr_assert_eq(func_open(&sc.p, &fp, &s, err, sizeof err), 0, "%s", err);
    cr_assert_eq(func_units_total(s), 2u);
    const uint32_t bad[1] = {2};
    FuncUnit out[1];
    cr_expect_eq(func_units(s, bad, 1, out, err, sizeof err), -1);
    cr_expect(strstr(err, "unit 2") != NULL, "%s", err);
    FuncStats st;
    cr_expect_eq(func_close(s, &st, err, sizeof err), 0, "%s", err);
    cr_expect_eq(st.units_timed, 0u);
    func_stats_free(&st);
    run_scene_close(&sc);
}
