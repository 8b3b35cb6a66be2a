/* bench/embree_xcheck.c -- per shared scene: closest-hit agreement between the golden model's
 * tracer and Embree on several hundred thousand rays, and both tracers' host speed.
 *
 *   build/bench/embree_xcheck [RAYS] [SCENE.glb|scene.ini ...]
 *
 * Without scene arguments it runs the shipped Cornell box and every scene of ../shared/scenes
 * (skipping, with the reason, those a clone on its own lacks). A benchmark, not a test:
 * tests/unit/test_embree.c asserts the agreement. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../scenes/scene.h"
#include "../tests/support/xcheck.h"
#include "bench_scenes.h"
#include "../sim/util.h"

static const char *const shared[] = {
    "scenes/cornell/cornell-box.gltf", /* the shipped box: the one scene a clone on its own has */
    "../shared/scenes/cornell-box/CornellBox-Original.glb",
    "../shared/scenes/cornell-box/CornellBox-Sphere.glb",
    "../shared/scenes/glass-vase-flowers/GlassVaseFlowers.glb",
    "../shared/scenes/lights-punctual-lamp/LightsPunctualLamp.glb",
    "../shared/scenes/sponza-dabrovic/sponza.glb",
    "../shared/scenes/toy-car/ToyCar.glb",
    "../shared/scenes/transmission-test/TransmissionTest.glb",
    "../shared/scenes/stanford-bunny/bunny.glb",
    "../shared/scenes/lamborghini/lamborghini.glb",
    "../shared/scenes/lost-empire/lost_empire.glb",
    "../shared/scenes/conference/conference.glb",
    "../shared/scenes/metal-rough-spheres/MetalRoughSpheresNoTextures.glb",
};

int main(int argc, char **argv)
{
    uint32_t rays = argc > 1 ? (uint32_t)strtoul(argv[1], NULL, 10) : 400000u;
    if (rays == 0) {
        fprintf(stderr, "usage: embree_xcheck [RAYS] [SCENE ...]\n");
        return 2;
    }
    const char *const *list = argc > 2 ? (const char *const *)argv + 2 : shared;
    int n = argc > 2 ? argc - 2 : (int)(sizeof shared / sizeof shared[0]);
    printf("%-58s %9s %9s %9s %6s %8s %10s %10s %8s\n", "scene", "tris", "rays", "agree%", "ties", "disagree",
           "ours Mr/s", "embree Mr/s", "bvh s");
    int failed = 0, skipped = 0;
    for (int i = 0; i < n; i++) {
        int ok = bench_scene_ok("embree_xcheck", list[i], &skipped);
        if (ok <= 0) {
            failed |= ok < 0;
            continue;
        }
        Scene s;
        char err[1024];
        if (scene_load(list[i], &s, err, sizeof err) != 0) {
            printf("%-58s error: %s\n", list[i], err);
            failed = 1;
            continue;
        }
        BvhParams bp;
        bvh_default_params(&bp);
        PackedScene p;
        double t0 = util_now();
        if (pack_scene(&s, &bp, 0, &p, err, sizeof err) != 0) {
            printf("%-58s error: %s\n", list[i], err);
            scene_free(&s);
            failed = 1;
            continue;
        }
        double tb = util_now() - t0;
        XcheckResult x;
        if (xcheck_run(&s, &p, NULL, rays / 4, rays - rays / 4, 17, &x, err, sizeof err) != 0) {
            printf("%-58s error: %s\n", list[i], err);
            failed = 1;
        } else {
            printf("%-58s %9u %9lu %9.4f %6lu %8lu %10.3f %10.3f %8.2f\n", list[i], s.ntris,
                   (unsigned long)x.rays, 100.0 * (double)(x.agree + x.ties) / (double)x.rays,
                   (unsigned long)x.ties, (unsigned long)x.disagree, 1e-6 * (double)x.rays / x.ours_seconds,
                   1e-6 * (double)x.rays / x.embree_seconds, tb);
        }
        fflush(stdout);
        pack_free(&p);
        scene_free(&s);
    }
    bench_scenes_summary("embree_xcheck", skipped, n);
    return failed;
}
