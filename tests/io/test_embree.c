/* tests/io/test_embree.c -- our BVH and intersector against Embree on the same rays: a
 * random triangle soup, and every shared scene (camera rays and random rays); the kd-tree
 * traversals too on the soup, the Cornell box, the toy car and the conference room (agreement as
 * the BVH's, and every hit the BVH's bit for bit). Agreement must be at least 99.99% of rays;
 * equal-distance hits on different triangles count as ties. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/scene.h"
#include "../../sim/ref_kd.h"
#include "../../sim/run/accel.h"
#include "../support/xcheck.h"
#include "../support/shared.h"

static void expect_tracer(const char *name, const char *tracer, const Scene *s, const PackedScene *p,
                          const XcheckTracer *tr, uint32_t ncam, uint32_t nrand)
{
    char err[512];
    XcheckResult x;
    cr_assert_eq(xcheck_run(s, p, tr, ncam, nrand, 17, &x, err, sizeof err), 0, "%s: %s", name, err);
    double rate = (double)(x.agree + x.ties) / (double)x.rays;
    cr_log_info("embree %-28s %-14s %7u tris %7lu rays: %.4f%% agree, %lu ties, %lu disagree (%lu hits)", name,
                tracer, s->ntris, (unsigned long)x.rays, 100.0 * rate, (unsigned long)x.ties,
                (unsigned long)x.disagree, (unsigned long)x.hits);
    cr_expect_geq(rate, 0.9999, "%s %s: %.4f%% agreement (first bad ray %lu)", name, tracer, 100.0 * rate,
                  (unsigned long)x.first_bad);
    cr_expect_gt(x.hits, x.rays / 20, "%s: too few hits for the check to mean anything", name);
    cr_expect_eq(x.unlike_bvh, 0, "%s %s: %lu hits differ from the BVH's", name, tracer, (unsigned long)x.unlike_bvh);
}

/* The BVH, and with kd = 1 also the kd-tree's full stack and 3-entry short stack (the kernels
 * return the golden model's hits, tests/unit/test_kdkernel.c). */
static void expect_agreement(const char *name, const Scene *s, uint32_t ncam, uint32_t nrand, int kd)
{
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[512];
    cr_assert_eq(pack_scene(s, &bp, 0, &p, err, sizeof err), 0, "%s: %s", name, err);
    expect_tracer(name, "bvh", s, &p, NULL, ncam, nrand);
    if (kd) {
        KdTree t;
        KdParams kp;
        kd_default_params(&kp);
        cr_assert_eq(accel_kd_build(&p, &kp, &t, err, sizeof err), 0, "%s: %s", name, err);
        XcheckTracer stack = {&t, REF_KD_STACK, 0}, shortstack = {&t, REF_KD_SHORTSTACK, 3};
        expect_tracer(name, "kd stack", s, &p, &stack, ncam, nrand);
        expect_tracer(name, "kd shortstack 3", s, &p, &shortstack, ncam, nrand);
        kd_free(&t);
    }
    pack_free(&p);
}

Test(embree, random_triangle_soup)
{
    uint32_t n = 20000;
    Scene s;
    memset(&s, 0, sizeof s);
    float *pos = malloc(sizeof(float) * 9 * n);
    uint32_t *tm = calloc(n, sizeof(uint32_t));
    uint32_t st = 7;
    for (uint32_t i = 0; i < 9 * n; i++) {
        st = st * 1664525u + 1013904223u;
        float r = (float)(st >> 8) / 16777216.0f;
        pos[i] = (i % 9 < 3) ? r * 10.0f - 5.0f : pos[9 * (i / 9) + i % 3] + (r - 0.5f) * 0.6f;
    }
    SceneMaterial m;
    memset(&m, 0, sizeof m);
    s.ntris = n;
    s.pos = pos;
    s.tri_material = tm;
    s.materials = &m;
    s.nmaterials = 1;
    s.camera = (SceneCamera){{0, 0, 12}, {0, 0, 0}, {0, 1, 0}, 50, 0, 0, 0};
    s.render = (SceneRender){64, 64, 1, 1, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < 3; k++) {
        s.bounds_min[k] = -5.5f;
        s.bounds_max[k] = 5.5f;
    }
    expect_agreement("random soup", &s, 20000, 80000, 1);
    free(pos);
    free(tm);
}

/* Every shared scene: its camera (the scene.ini's when the project ships one, else the file's or
 * the default) and random rays from inside its bounds. Ties are hits on different triangles at
 * the same distance (coplanar or duplicated geometry), which neither tracer is wrong about. */
static void shared_scene(const char *path, int kd)
{
    NEEDS_SCENE(path);
    Scene s;
    char err[1024];
    cr_assert_eq(scene_load(path, &s, err, sizeof err), 0, "%s", err);
    expect_agreement(path, &s, 25000, 75000, kd);
    scene_free(&s);
}

Test(embree_shared, cornell_original) { shared_scene("scenes/cornell/scene.ini", 1); }
Test(embree_shared, cornell_spheres) { shared_scene("../shared/scenes/cornell-box/CornellBox-Sphere.glb", 0); }
Test(embree_shared, glass_vase_flowers) { shared_scene("../shared/scenes/glass-vase-flowers/GlassVaseFlowers.glb", 0); }
Test(embree_shared, lights_punctual_lamp) { shared_scene("../shared/scenes/lights-punctual-lamp/LightsPunctualLamp.glb", 0); }
Test(embree_shared, sponza) { shared_scene("../shared/scenes/sponza-dabrovic/sponza.glb", 0); }
Test(embree_shared, toy_car) { shared_scene("../shared/scenes/toy-car/ToyCar.glb", 1); }
Test(embree_shared, conference_kd, .timeout = 300) { shared_scene("scenes/conference/scene.ini", 1); }
Test(embree_shared, transmission_test) { shared_scene("../shared/scenes/transmission-test/TransmissionTest.glb", 0); }
Test(embree_shared, stanford_bunny) { shared_scene("../shared/scenes/stanford-bunny/bunny.glb", 0); }
Test(embree_shared, lamborghini, .timeout = 300) { shared_scene("../shared/scenes/lamborghini/lamborghini.glb", 0); }
Test(embree_shared, lost_empire, .timeout = 300) { shared_scene("../shared/scenes/lost-empire/lost_empire.glb", 0); }
Test(embree_shared, conference, .timeout = 300) { shared_scene("../shared/scenes/conference/conference.glb", 0); }
Test(embree_shared, metal_rough_spheres, .timeout = 300) { shared_scene("../shared/scenes/metal-rough-spheres/MetalRoughSpheresNoTextures.glb", 0); }
