/* tests/unit/test_run.c -- the entry point's scene set-up (sim/run/run.h): run_scene_open packs
 * the same scene-memory bytes as the by-hand set-up it replaced in tools/validation.c and bench/
 * (scene_load, the size imposed, pack_scene with bvh_default_params, and for the kd-tree kernels
 * accel_add_kd), so their tables and figures did not move when they switched to it.
 */
#include <criterion/criterion.h>
#include <string.h>

#include "../../scenes/bvh.h"
#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/accel.h"
#include "../../sim/run/run.h"

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

Test(run_scene, default_config_packs_as_pack_scene_with_the_default_bvh)
{
    static const char *const paths[] = {"scenes/cornell/scene.ini", "scenes/cornell/mcguire.ini"};
    static const RunMode modes[] = {RUN_REFERENCE, RUN_FUNCTIONAL, RUN_DETAILED};
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; i++)
        for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
            Scene s;
            PackedScene p;
            pack_by_hand(paths[i], 32, 24, 2, 3, &s, &p);
            RunScene sc;
            char err[4096];
            RunSize z = {32, 24, 2, 3};
            cr_assert_eq(run_scene_open(&sc, paths[i], &z, NULL, modes[m], NULL, err, sizeof err), 0, "%s", err);
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

Test(run_scene, kd_config_packs_as_pack_scene_then_accel_add_kd)
{
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
