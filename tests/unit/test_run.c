/* tests/unit/test_run.c -- the entry point's scene set-up (sim/run/run.h): run_scene_open packs
 * the same scene-memory bytes as the by-hand set-up it replaced in tools/validation.c and bench/
 * (scene_load, the size imposed, pack_scene with bvh_default_params, and for the kd-tree kernels
 * accel_add_kd), so their tables and figures did not move when they switched to it; and the
 * entry point's own rules: mode names and the render settings it checks (the options a command
 * refuses are tests/unit/test_runopts.c's); and the open scene's shared image, whose batches are
 * those of a copy.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/bvh.h"
#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/accel.h"
#include "../../sim/run/run.h"
#include "../support/shared.h"

/* The old set-up: load path, impose w x h x spp (> 0) and max_depth (>= 0), pack with the
 * default BVH. */
static void pack_by_hand(const char *path, int w, int h, int spp, int max_depth, Scene *s, PackedScene *p)
{
    char err[4096];
    cr_assert_eq(scene_load(path, s, err, sizeof err), 0, "%s", err);
    if (w > 0)
        s->render.width = w;
    if (h > 0)
        s->render.height = h;
    if (spp > 0)
        s->render.spp = spp;
    if (max_depth >= 0)
        s->render.max_depth = max_depth;
    BvhParams bp;
    bvh_default_params(&bp);
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s", err);
}

static void assert_same_pack(const PackedScene *a, const PackedScene *b)
{
    cr_assert_eq(a->size, b->size, "packed sizes differ: %u and %u bytes", a->size, b->size);
    cr_assert_eq(a->base, b->base);
    cr_assert_eq(a->nprims, b->nprims);
    cr_assert_eq(a->nlights, b->nlights);
    cr_assert_eq(a->kd_depth, b->kd_depth);
    cr_assert_eq(a->bvh.nnodes, b->bvh.nnodes);
    cr_assert(memcmp(a->mem, b->mem, a->size) == 0, "the packed bytes differ");
}

/* path packs the same through run_scene_open, in every mode, as by hand. */
static void expect_packs_as_by_hand(const char *path)
{
    static const RunMode modes[] = {RUN_REFERENCE, RUN_FUNCTIONAL, RUN_DETAILED};
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
        Scene s;
        PackedScene p;
        pack_by_hand(path, 32, 24, 2, 3, &s, &p);
        RunScene sc;
        char err[4096];
        RunSize z = {32, 24, 2, 3};
        cr_assert_eq(run_scene_open(&sc, path, &z, NULL, modes[m], NULL, err, sizeof err), 0, "%s", err);
        cr_assert_eq(sc.s.render.width, 32);
        cr_assert_eq(sc.s.render.height, 24);
        cr_assert_eq(sc.s.render.spp, 2);
        cr_assert_eq(sc.s.render.max_depth, 3);
        assert_same_pack(&sc.p, &p);
        run_scene_close(&sc);
        pack_free(&p);
        scene_free(&s);
    }
}

#define MCGUIRE_GLB "../shared/scenes/cornell-box/CornellBox-Original.glb" /* scenes/cornell/mcguire.ini's */

Test(run_scene, default_config_packs_as_pack_scene_with_the_default_bvh)
{
    expect_packs_as_by_hand("scenes/cornell/scene.ini");
}

Test(run_scene, default_config_packs_a_gltf_scene_as_pack_scene)
{
    NEEDS_SHARED(MCGUIRE_GLB);
    expect_packs_as_by_hand("scenes/cornell/mcguire.ini");
}

Test(run_scene, kd_config_packs_as_pack_scene_then_accel_add_kd)
{
    NEEDS_SHARED(MCGUIRE_GLB);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    CfgErrors ce = {0};
    cr_assert_eq(cfg_set(&cfg, "accel.structure=kd", &ce), 0, "%s", ce.text ? ce.text : "");
    cfg_errors_free(&ce);
    Scene s;
    PackedScene p;
    pack_by_hand("scenes/cornell/mcguire.ini", 32, 32, 1, 3, &s, &p);
    char err[4096];
    AccelKdInfo info;
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    cr_assert_gt(p.kd_depth, 0);
    RunScene sc;
    RunSize z = {32, 32, 1, 3};
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/mcguire.ini", &z, &cfg, RUN_DETAILED, NULL, err, sizeof err), 0,
                 "%s", err);
    assert_same_pack(&sc.p, &p);
    cr_assert_eq(sc.accel.kd.nodes, info.nodes);
    cr_assert_eq(sc.accel.kd.depth, info.depth);
    run_scene_close(&sc);
    /* the golden model traverses the BVH: no kd-tree for it, whatever the config says */
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/mcguire.ini", &z, &cfg, RUN_REFERENCE, NULL, err, sizeof err),
                 0, "%s", err);
    cr_assert_eq(sc.p.kd_depth, 0);
    run_scene_close(&sc);
    pack_free(&p);
    scene_free(&s);
}

Test(run_mode, names_round_trip_and_unknown_names_are_refused)
{
    for (int m = 0; m < RUN_MODE_COUNT; m++) {
        RunMode got = RUN_MODE_COUNT;
        cr_expect_eq(run_mode_parse(run_mode_names[m], &got), 0, "%s", run_mode_names[m]);
        cr_expect_eq(got, (RunMode)m);
    }
    RunMode got = RUN_FUNCTIONAL;
    cr_expect_eq(run_mode_parse("Detailed", &got), -1);
    cr_expect_eq(run_mode_parse("", &got), -1);
    cr_expect_eq(run_mode_parse(NULL, &got), -1);
    cr_expect_eq(got, RUN_FUNCTIONAL, "a refused name leaves the mode as it was");
    cr_expect(!run_mode_kernel(RUN_REFERENCE) && run_mode_kernel(RUN_FUNCTIONAL) && run_mode_kernel(RUN_SAMPLED));
    cr_expect(!run_mode_timed(RUN_FUNCTIONAL) && run_mode_timed(RUN_DETAILED) && run_mode_timed(RUN_SAMPLED));
}

/* A render setting out of range is refused with its name; without a size (ray batches) the scene
 * is taken as it is. */
Test(run_scene, a_size_out_of_range_is_refused_by_name)
{
    static const struct {
        RunSize size;
        const char *want;
    } cases[] = {
        {{16385, 8, 1, 1}, "render size 16385 x 8 out of range (1..16384)"},
        {{8, 8, 2000000, 1}, "render.spp 2000000 out of range (1..1048576)"},
        {{8, 8, 1, 10000}, "render.max_depth 10000 out of range"},
    };
    char err[4096];
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        RunScene sc;
        err[0] = 0;
        cr_expect_eq(run_scene_open(&sc, "scenes/cornell/scene.ini", &cases[i].size, NULL, RUN_FUNCTIONAL, NULL, err,
                                    sizeof err), -1);
        cr_expect(strstr(err, cases[i].want) != NULL, "case %zu: %s", i, err);
        run_scene_close(&sc);
    }
    RunScene sc;
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/scene.ini", NULL, NULL, RUN_REFERENCE, NULL, err, sizeof err), 0,
                 "%s", err);
    cr_expect_gt(sc.p.size, 0u);
    run_scene_close(&sc);
}

/* The golden model's frame through the entry point: an image and its rays, the tile of the
 * machine's stream, and the same bits on 1 and 2 host threads. */
Test(run_frame, golden_frame_is_the_same_on_any_thread_count)
{
    char err[4096];
    RunScene sc;
    RunSize size = {130, 70, 2, 2}; /* 3 x 2 tiles of 64 x 64, the last column and row partial */
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/scene.ini", &size, NULL, RUN_REFERENCE, NULL, err, sizeof err), 0,
                 "%s", err);
    RunFrame a, b;
    RunSpec spec = {.mode = RUN_REFERENCE, .seed = 7, .threads = 1};
    cr_assert_eq(run_frame(&sc, &spec, &a, err, sizeof err), 0, "%s", err);
    spec.threads = 2;
    cr_assert_eq(run_frame(&sc, &spec, &b, err, sizeof err), 0, "%s", err);
    cr_expect_eq(a.tile, 64, "stream.rays = 4096 by default: 64 x 64 tiles");
    cr_expect_eq(a.threads, 1);
    cr_expect_eq(b.threads, 2);
    cr_expect_eq(a.run.primary, 130u * 70u * 2u, "one camera ray per pixel and sample");
    cr_expect_eq(memcmp(a.rgb, b.rgb, 3 * 130 * 70 * sizeof(float)), 0);
    cr_expect_eq(a.has_est, 0);
    run_frame_free(&a);
    run_frame_free(&b);
    run_scene_close(&sc);
}

/* The kernel modes' cores map the open scene's image (RunScene.image, passed to run_trace)
 * instead of copying the packed bytes: a batch traced with it gives the same hits, instructions and
 * cycles as without it (NULL: each core copies the bytes). The golden model's scene has none. */
Test(run_scene, a_batch_from_the_shared_image_is_the_batch_from_the_copy)
{
    RunScene sc;
    char err[4096];
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/scene.ini", NULL, NULL, RUN_REFERENCE, NULL, err, sizeof err), 0,
                 "%s", err);
    cr_expect_null(sc.image, "the golden model starts no cores: no image");
    run_scene_close(&sc);
    cr_assert_eq(run_scene_open(&sc, "scenes/cornell/scene.ini", NULL, NULL, RUN_DETAILED, NULL, err, sizeof err), 0,
                 "%s", err);
    cr_assert_not_null(sc.image, "an open scene of a kernel mode owns a shared image (memfd)");
    enum { N = 700 };
    RayBatch b = {calloc(N, sizeof(BatchRay)), N};
    BatchHit *h[2] = {calloc(N, sizeof(BatchHit)), calloc(N, sizeof(BatchHit))};
    cr_assert(b.rays && h[0] && h[1]);
    uint32_t st = 99;
    for (uint32_t i = 0; i < N; i++) { /* from inside the box (scene.ini: about 0..555 on each axis) */
        BatchRay *r = &b.rays[i];
        for (int k = 0; k < 3; k++) {
            st = st * 1664525u + 1013904223u;
            r->org[k] = (k == 2 ? 280.0f : 275.0f) + 200.0f * ((float)(st >> 8) / (float)(1u << 24) - 0.5f);
            st = st * 1664525u + 1013904223u;
            r->dir[k] = (float)(st >> 8) / (float)(1u << 24) - 0.5f;
        }
        r->tmax = INFINITY;
        r->query = i % 4 == 3 ? RAY_ANY : RAY_CLOSEST;
    }
    static const RunMode modes[] = {RUN_FUNCTIONAL, RUN_DETAILED};
    for (int m = 0; m < 2; m++)
        for (int threads = 1; threads <= 2; threads++) {
            RunTrace rt[2];
            RunSpec spec = {.mode = modes[m], .kernel_path = "kernels/pathtrace.s", .threads = threads};
            cr_assert_eq(run_trace(&sc.p, sc.image, sc.s.needs, &spec, &b, h[0], &rt[0], err, sizeof err), 0, "%s",
                         err);
            cr_assert_eq(run_trace(&sc.p, NULL, sc.s.needs, &spec, &b, h[1], &rt[1], err, sizeof err), 0, "%s", err);
            const char *mn = run_mode_names[modes[m]];
            cr_expect(memcmp(h[0], h[1], N * sizeof(BatchHit)) == 0, "%s, %d threads: hits differ", mn, threads);
            cr_expect_eq(rt[0].instructions, rt[1].instructions, "%s: instructions differ", mn);
            cr_expect_gt(rt[0].instructions, 0u);
            cr_expect_eq(rt[0].timing.cycles, rt[1].timing.cycles, "%s: cycles differ", mn);
        }
    uint32_t hits = 0;
    for (uint32_t i = 0; i < N; i++)
        hits += b.rays[i].query == RAY_CLOSEST ? h[0][i].prim != UINT32_MAX : h[0][i].prim;
    cr_expect_gt(hits, N / 2, "the batch should hit the box (%u hits of %u)", hits, N);
    run_scene_close(&sc);
    cr_expect_null(sc.image, "a closed scene has no image");
    free(b.rays);
    free(h[0]);
    free(h[1]);
}
