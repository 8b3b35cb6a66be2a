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

#include "../sim/run/run.h"
#include "../tests/support/xcheck.h"
#include "bench_scenes.h"

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
        /* the golden model's structure: the default BVH; accel.pack_seconds times its build */
        RunScene sc;
        char err[1024];
        if (run_scene_open(&sc, list[i], NULL, NULL, RUN_REFERENCE, NULL, err, sizeof err) != 0) {
            printf("%-58s error: %s\n", list[i], err);
            run_scene_close(&sc);
            failed = 1;
            continue;
        }
        double tb = sc.accel.pack_seconds;
        XcheckResult x;
        if (xcheck_run(&sc.s, &sc.p, NULL, rays / 4, rays - rays / 4, 17, &x, err, sizeof err) != 0) {
            printf("%-58s error: %s\n", list[i], err);
            failed = 1;
        } else {
            printf("%-58s %9u %9lu %9.4f %6lu %8lu %10.3f %10.3f %8.2f\n", list[i], sc.s.ntris,
                   (unsigned long)x.rays, 100.0 * (double)(x.agree + x.ties) / (double)x.rays,
                   (unsigned long)x.ties, (unsigned long)x.disagree, 1e-6 * (double)x.rays / x.ours_seconds,
                   1e-6 * (double)x.rays / x.embree_seconds, tb);
        }
        fflush(stdout);
        run_scene_close(&sc);
    }
    bench_scenes_summary("embree_xcheck", skipped, n);
    return failed;
}
