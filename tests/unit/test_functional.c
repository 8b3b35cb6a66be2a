/* tests/unit/test_functional.c -- the path-tracing kernel (kernels/pathtrace.s) on the
 * functional core against the golden model: same pixels on the Cornell variants and on shared
 * scenes with textures, glass, punctual lights and the conference room; the same image for
 * every SIMD width N and stream size M (stream filtering changes nothing about any one ray)
 * and every host thread count; clear errors for machines too small for the kernel. The host side
 * of accel.structure = kd (tree, build symbols, memory checks, counters) runs with
 * tests/unit/kd_stub.s in place of the kernel. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/ref_kd.h"
#include "../../sim/run/accel.h"
#include "../../sim/reference.h"

#include "../support/packed.h"
#include "../support/shared.h"

typedef struct Img {
    float *rgb;
    int w, h;
} Img;

static Img golden(const PackedScene *p, int w, int h, int tile)
{
    Img im = {calloc(3 * (size_t)w * h, sizeof(float)), w, h};
    char err[1024];
    RefParams rp = {.tile = tile, .seed = 1, .threads = 2};
    cr_assert_eq(ref_render(p, &rp, im.rgb, NULL, err, sizeof err), 0, "%s", err);
    return im;
}

static Img kernel_cfg(const PackedScene *p, uint32_t needs, int w, int h, const CfgMachine *cfg, int threads,
                      FuncStats *st)
{
    Img im = {calloc(3 * (size_t)w * h, sizeof(float)), w, h};
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = needs, .seed = 1, .threads = threads};
    cr_assert_eq(func_render(p, &fp, im.rgb, st, err, sizeof err), 0, "%s", err);
    return im;
}

static Img kernel(const PackedScene *p, uint32_t needs, int w, int h, int lanes, int rays, int threads,
                  FuncStats *st)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.core_simd_width = lanes;
    cfg.stream_rays = rays;
    return kernel_cfg(p, needs, w, h, &cfg, threads, st);
}

static double util(const FuncStats *st, int lanes, int gen_from, int stage)
{
    uint64_t act = 0, vec = 0;
    for (int g = gen_from; g < CORE_GENERATIONS; g++) {
        act += st->core.gen_active_lanes[g][stage];
        vec += st->core.gen_vec_instructions[g][stage];
    }
    return vec ? (double)act / ((double)lanes * (double)vec) : 0.0;
}

/* Max |a - b| over all values, the mean of b, and non-finite values in a. */
static void diff(const Img *a, const Img *b, double *maxd, double *mean, long *bad)
{
    *maxd = 0.0;
    *mean = 0.0;
    *bad = 0;
    size_t n = 3 * (size_t)a->w * a->h;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(a->rgb[i]))
            (*bad)++;
        double d = fabs((double)a->rgb[i] - (double)b->rgb[i]);
        if (d > *maxd || d != d)
            *maxd = d;
        *mean += b->rgb[i];
    }
    *mean /= (double)n;
}

static void matches_golden(const char *path, int w, int h, int spp)
{
    Scene s;
    PackedScene p;
    packed_load(path, w, h, spp, &s, &p);
    Img g = golden(&p, w, h, 64);
    FuncStats st;
    Img k = kernel(&p, s.needs, w, h, 16, 4096, 2, &st);
    double maxd, mean;
    long bad;
    diff(&k, &g, &maxd, &mean, &bad);
    char needs[256];
    scene_needs_string(s.needs, needs, sizeof needs);
    printf("functional vs golden  %-48s %3dx%-3d %d spp  max |diff| %.3g (%.3g of the mean %.4f)  "
           "non-finite %ld  rays %llu  instructions %llu  [%s]\n",
           path, w, h, spp, maxd, mean > 0 ? maxd / mean : 0.0, mean, bad,
           (unsigned long long)(st.rays_camera + st.rays_indirect + st.rays_shadow),
           (unsigned long long)st.instructions, needs);
    cr_expect(mean > 0.0, "%s: black image", path);
    cr_expect(maxd <= 1e-3 * mean, "%s: max difference %g exceeds 1e-3 of the mean %g", path, maxd, mean);
    cr_expect_eq(bad, 0, "%s: %ld non-finite values", path, bad);
    cr_expect(st.rays_camera == (uint64_t)w * h * spp, "%s: %llu camera rays", path,
              (unsigned long long)st.rays_camera);
    free(g.rgb);
    free(k.rgb);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}

Test(functional, cornell_box_matches_the_golden_model, .timeout = 120)
{
    matches_golden("scenes/cornell/scene.ini", 80, 64, 4);
}

Test(functional, cornell_glossy_matches_the_golden_model, .timeout = 120)
{
    matches_golden("scenes/cornell/glossy.ini", 80, 64, 4);
}

Test(functional, cornell_spheres_glass_matches_the_golden_model, .timeout = 120)
{
    matches_golden("scenes/cornell/spheres.ini", 80, 64, 4);
}

Test(functional, cornell_analytic_spheres_match_the_golden_model, .timeout = 120)
{
    matches_golden("scenes/cornell/analytic.ini", 80, 64, 4);
}

/* Every kind of light (point, spot, directional, quad), ambient term, background, an analytic
 * glass sphere: every optional path of the kernel at once. */
Test(functional, every_light_kind_ambient_and_background_match_the_golden_model, .timeout = 120)
{
    matches_golden("tests/scenes/ok_every_section.ini", 64, 48, 4);
}

Test(functional, conference_room_matches_the_golden_model, .timeout = 300)
{
    matches_golden("scenes/conference/scene.ini", 64, 48, 1);
}

Test(functional, textured_sponza_matches_the_golden_model, .timeout = 300)
{
    matches_golden("scenes/sponza-dabrovic/scene.ini", 64, 48, 1);
}

Test(functional, glass_and_textures_match_the_golden_model, .timeout = 300)
{
    matches_golden("scenes/transmission-test/scene.ini", 64, 48, 1);
}

Test(functional, punctual_lights_match_the_golden_model, .timeout = 300)
{
    matches_golden("scenes/lights-punctual-lamp/scene.ini", 64, 48, 1);
}

/* Stream filtering does not change what happens to any one ray: every N and M gives the same
 * bits, and so does the host's thread count. */
Test(functional, same_image_for_every_simd_width_stream_size_and_thread_count, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 72, h = 40;
    packed_load("scenes/cornell/spheres.ini", w, h, 2, &s, &p);
    FuncStats st;
    Img base = kernel(&p, s.needs, w, h, 16, 4096, 1, &st);
    func_stats_free(&st);
    static const int lanes[] = {4, 8, 12, 16, 64};
    static const int rays[] = {1024, 4096};
    for (size_t i = 0; i < sizeof lanes / sizeof lanes[0]; i++) {
        for (size_t j = 0; j < sizeof rays / sizeof rays[0]; j++) {
            Img k = kernel(&p, s.needs, w, h, lanes[i], rays[j], 1 + (int)(i % 2), &st);
            cr_expect(memcmp(k.rgb, base.rgb, sizeof(float) * 3 * (size_t)w * h) == 0,
                      "N = %d, M = %d: the image differs from N = 16, M = 4096", lanes[i], rays[j]);
            free(k.rgb);
            func_stats_free(&st);
        }
    }
    free(base.rgb);
    pack_free(&p);
    scene_free(&s);
}

/* Utilization and stream lengths are measured, not assumed: wider SIMD units are used less
 * (Gribble & Ramani 2008, Table 2), and bigger streams are longer in every stage (Table 4). */
Test(functional, utilization_falls_with_n_and_streams_grow_with_m, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 64, h = 64;
    packed_load("scenes/cornell/scene.ini", w, h, 1, &s, &p);
    double util[2];
    double len[2][3];
    int ns[2] = {8, 64};
    for (int i = 0; i < 2; i++) {
        FuncStats st;
        Img k = kernel(&p, s.needs, w, h, ns[i], 4096, 2, &st);
        util[i] = (double)st.core.active_lanes[ISA_STAGE_TRAVERSAL] /
                  ((double)ns[i] * (double)st.core.vec_instructions[ISA_STAGE_TRAVERSAL]);
        cr_expect(util[i] > 0.0 && util[i] <= 1.0, "utilization %g out of range", util[i]);
        free(k.rgb);
        func_stats_free(&st);
    }
    cr_expect(util[1] < util[0], "traversal utilization at N = 64 (%g) not below N = 8 (%g)", util[1], util[0]);
    int ms[2] = {1024, 4096};
    for (int i = 0; i < 2; i++) {
        FuncStats st;
        Img k = kernel(&p, s.needs, w, h, 16, ms[i], 2, &st);
        len[i][0] = (double)st.trav_rays / (double)st.trav_streams;
        len[i][1] = (double)st.isect_rays / (double)st.isect_streams;
        len[i][2] = (double)st.shade_rays / (double)st.shade_streams;
        free(k.rgb);
        func_stats_free(&st);
    }
    for (int k = 0; k < 3; k++)
        cr_expect(len[1][k] > len[0][k], "stage %d: mean stream length at M = 4096 (%g) not above M = 1024 (%g)", k,
                  len[1][k], len[0][k]);
    pack_free(&p);
    scene_free(&s);
}

Test(functional, machines_too_small_for_the_kernel_are_refused_by_key)
{
    Scene s;
    PackedScene p;
    packed_load("scenes/cornell/scene.ini", 16, 16, 1, &s, &p);
    struct { const char *key; int value; const char *want; } cases[] = {
        {"raybuf", 64, "raybuf.size_kb"}, {"idm", 8, "idm.size_kb"}, {"fb", 4, "fb.size_kb"},
        {"spad", 1, "spad.size_kb"}, {"scene", 0, "scene.size_mb"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        CfgMachine cfg;
        cfg_defaults(&cfg);
        if (!strcmp(cases[i].key, "raybuf"))
            cfg.raybuf_size_kb = cases[i].value;
        if (!strcmp(cases[i].key, "idm"))
            cfg.idm_size_kb = cases[i].value;
        if (!strcmp(cases[i].key, "fb"))
            cfg.fb_size_kb = cases[i].value;
        if (!strcmp(cases[i].key, "spad"))
            cfg.spad_size_kb = cases[i].value;
        if (!strcmp(cases[i].key, "scene")) {
            cfg.scene_size_mb = 1;
            p.size = 2u << 20; /* pretend the scene is 2 MiB (only the size check reads it) */
        }
        float *rgb = calloc(3 * 16 * 16, sizeof(float));
        char err[4096];
        FuncStats st;
        FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s.needs, .seed = 1, .threads = 1};
        cr_expect_neq(func_render(&p, &fp, rgb, &st, err, sizeof err), 0, "%s: accepted", cases[i].key);
        cr_expect(strstr(err, cases[i].want) != NULL, "%s: message '%s' does not name %s", cases[i].key, err,
                  cases[i].want);
        free(rgb);
    }
    pack_free(&p);
    scene_free(&s);
}

/* A frame's (tile, pass) units (sim/run/engine.c, run_tile_pass): tests/unit/pass_trap.s adds 1.0
 * per pass to the first N floats of its tile's framebuffer, so after the division by spp those
 * pixels hold exactly 1.0 when every pass of the tile ran once and handed the framebuffer on, on
 * whichever threads; the rest of the frame stays 0. Tiles are 32 x 32 (M = 1024), N = 16. */
static void pass_trap_frame(int w, int h, int spp, int threads, float **rgb, FuncStats *st, int *rc, char *err,
                            size_t errlen)
{
    Scene s;
    PackedScene p;
    packed_load("scenes/cornell/scene.ini", w, h, spp, &s, &p);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    *rgb = calloc(3 * (size_t)w * h, sizeof(float));
    cr_assert_not_null(*rgb);
    FuncParams fp = {.cfg = &cfg, .kernel_path = "tests/unit/pass_trap.s", .needs = s.needs, .seed = 1,
                     .threads = threads};
    *rc = func_render(&p, &fp, *rgb, st, err, errlen);
    pack_free(&p);
    scene_free(&s);
}

/* Whether the 32 x 32 tile at (x0, y0) of rgb (width w) is what N = 16 lanes leave: its first 16
 * floats `first`, every other float 0. */
static int tile_is(const float *rgb, int w, int x0, int y0, float first)
{
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 3 * 32; x++) {
            float v = rgb[3 * ((size_t)(y0 + y) * w + x0) + x];
            if (v != (y == 0 && x < 16 ? first : 0.0f))
                return 0;
        }
    return 1;
}

Test(functional, every_pass_of_every_tile_runs_once_in_order_on_any_thread_count)
{
    for (int threads = 1; threads <= 4; threads++) {
        float *rgb;
        FuncStats st;
        int rc;
        char err[4096];
        pass_trap_frame(32, 128, 5, threads, &rgb, &st, &rc, err, sizeof err); /* 4 tiles, no x0 = 32 */
        cr_assert_eq(rc, 0, "%d threads: %s", threads, err);
        cr_expect_eq(st.ntiles, 4u);
        for (int t = 0; t < 4; t++)
            cr_expect(tile_is(rgb, 32, 0, 32 * t, 1.0f), "%d threads: tile %d did not get each of 5 passes once",
                      threads, t);
        uint64_t sum = 0; /* the same instructions in every pass of every tile: counted once each */
        for (uint32_t t = 0; t < st.ntiles; t++) {
            cr_expect_eq(st.tiles[t].instructions, st.tiles[0].instructions, "%d threads: tile %u", threads, t);
            sum += st.tiles[t].instructions;
        }
        cr_expect_eq(sum, st.instructions);
        cr_expect_eq(st.tiles[0].instructions % 5u, 0u);
        free(rgb);
        func_stats_free(&st);
    }
}

Test(functional, a_pass_that_fails_leaves_its_tile_black_and_keeps_finished_tiles)
{
    for (int threads = 1; threads <= 3; threads++) {
        float *rgb;
        FuncStats st;
        int rc;
        char err[4096];
        pass_trap_frame(96, 32, 2, threads, &rgb, &st, &rc, err, sizeof err); /* 3 tiles; (32, 0) traps in pass 1 */
        cr_expect_eq(rc, -2, "%d threads: rc %d (%s)", threads, rc, err);
        cr_expect(strstr(err, "tile at (32, 0), pass 1") != NULL, "%s", err);
        cr_expect(tile_is(rgb, 96, 32, 0, 0.0f), "%d threads: the failed tile is not black", threads);
        uint32_t finished = 0;
        for (int x0 = 0; x0 < 96; x0 += 64) {
            int done = tile_is(rgb, 96, x0, 0, 1.0f);
            cr_expect(done || tile_is(rgb, 96, x0, 0, 0.0f), "%d threads: tile at x0 = %d is neither finished nor black",
                      threads, x0);
            finished += (uint32_t)done;
        }
        cr_expect_eq(st.tiles_done, finished, "%d threads: %u tiles done, %u finished in the image", threads,
                     st.tiles_done, finished);
        if (threads == 1) /* passes go out in pass order: tile 0's second pass ran before tile 1's */
            cr_expect_eq(finished, 1u);
        free(rgb);
        func_stats_free(&st);
    }
}

Test(functional, a_missing_kernel_is_an_error_naming_it)
{
    Scene s;
    PackedScene p;
    packed_load("scenes/cornell/scene.ini", 16, 16, 1, &s, &p);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    float *rgb = calloc(3 * 16 * 16, sizeof(float));
    char err[4096];
    FuncStats st;
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/no_such_kernel.s", .needs = s.needs, .seed = 1, .threads = 1};
    cr_expect_neq(func_render(&p, &fp, rgb, &st, err, sizeof err), 0);
    cr_expect(strstr(err, "no_such_kernel.s") != NULL, "%s", err);
    free(rgb);
    pack_free(&p);
    scene_free(&s);
}

/* Packet tracing (stream size = N, 001 Table 7) renders the same image -- it is the same
 * algorithm on smaller streams -- and uses the SIMD unit less than streams of M rays. */
Test(functional, packet_tracing_same_image_lower_utilization, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 64, h = 48;
    packed_load("scenes/cornell/glossy.ini", w, h, 2, &s, &p);
    Img g = golden(&p, w, h, 64);
    static const int lanes[] = {4, 8, 12, 16};
    for (size_t i = 0; i < sizeof lanes / sizeof lanes[0]; i++) {
        CfgMachine cfg;
        cfg_defaults(&cfg);
        cfg.core_simd_width = lanes[i];
        cfg.stream_mode = CFG_STREAM_MODE_PACKET;
        FuncStats pk, sm;
        Img a = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &pk);
        cr_expect_eq(pk.tile_w * pk.tile_h, (uint32_t)lanes[i], "N = %d: packet of %u x %u", lanes[i], pk.tile_w,
                     pk.tile_h);
        cr_expect(memcmp(a.rgb, g.rgb, sizeof(float) * 3 * (size_t)w * h) == 0, "N = %d: packet image differs",
                  lanes[i]);
        cfg.stream_mode = CFG_STREAM_MODE_STREAM;
        Img b = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &sm);
        for (int stage = ISA_STAGE_TRAVERSAL; stage <= ISA_STAGE_SHADING; stage++)
            cr_expect(util(&pk, lanes[i], 1, stage) < util(&sm, lanes[i], 1, stage),
                      "N = %d stage %d: packet utilization %g not below stream %g", lanes[i], stage,
                      util(&pk, lanes[i], 1, stage), util(&sm, lanes[i], 1, stage));
        free(a.rgb);
        free(b.rgb);
        func_stats_free(&pk);
        func_stats_free(&sm);
    }
    free(g.rgb);
    pack_free(&p);
    scene_free(&s);
}

/* Forced specular workload: every camera ray that hits bounces BOUNCES times (a closed box
 * keeps every ray), so each generation has as many rays as the first. */
Test(functional, forced_specular_workload_bounces_every_ray, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 48, h = 40;
    packed_load("scenes/cornell/scene.ini", w, h, 1, &s, &p);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.workload_kind = CFG_WORKLOAD_SPECULAR;
    cfg.workload_bounces = 3;
    FuncStats st;
    Img k = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &st);
    cr_expect_eq(st.generations, 4);
    cr_expect_eq(st.rays_shadow, 0);
    cr_expect_eq(st.rays_camera, (uint64_t)w * h);
    for (int g = 1; g < 4; g++)
        cr_expect(st.rays_per_generation[g] <= st.rays_per_generation[g - 1] && st.rays_per_generation[g] > 0,
                  "generation %d: %llu rays", g, (unsigned long long)st.rays_per_generation[g]);
    double maxd, mean;
    long bad;
    diff(&k, &k, &maxd, &mean, &bad);
    cr_expect_eq(bad, 0);
    cr_expect(mean > 0.0);
    free(k.rgb);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}

/* One-bounce diffuse workload: two generations, one bounce per camera hit, no shadow rays. */
Test(functional, one_bounce_diffuse_workload_has_two_generations, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 48, h = 40;
    packed_load("scenes/cornell/scene.ini", w, h, 4, &s, &p);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.workload_kind = CFG_WORKLOAD_DIFFUSE;
    FuncStats st;
    Img k = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &st);
    cr_expect_eq(st.generations, 2);
    cr_expect_eq(st.rays_shadow, 0);
    cr_expect(st.rays_per_generation[1] > 0 && st.rays_per_generation[1] <= st.rays_per_generation[0]);
    cr_expect_eq(st.rays_indirect, st.rays_per_generation[1]);
    free(k.rgb);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}

/* ---- workload.kind = phong (seed 004 Sec. 4-5): local Phong shading with one shadow ray per light
 * at every hit and workload.bounces mirror bounces, the same bits as the golden model ---------- */

static Img golden_phong(const PackedScene *p, int w, int h, int bounces, RefStats *rs)
{
    Img im = {calloc(3 * (size_t)w * h, sizeof(float)), w, h};
    char err[1024];
    RefParams rp = {.tile = 64, .seed = 1, .threads = 2, .workload = REF_WORKLOAD_PHONG, .bounces = bounces};
    cr_assert_eq(ref_render(p, &rp, im.rgb, rs, err, sizeof err), 0, "%s", err);
    return im;
}

/* B = 0 (the paper's "Shadow"), 1 ("1 Bounce") and 3: bit-identical images, the same rays of every
 * kind and generation as the golden model; shadow rays always, bounce rays (generation g <= B)
 * only with B >= 1, at most one shadow ray per light per hit. Then packet mode (tiles of N
 * pixels, buffers of 2N rays) and M = 1024 (tiles of 32 x 16) give the same image. */
static void phong_matches_golden(const char *path, int w, int h, int spp)
{
    Scene s;
    PackedScene p;
    packed_load(path, w, h, spp, &s, &p);
    uint32_t nlights = sm_u32(&p, sm_hdr(&p, SM_HDR_NLIGHTS));
    static const int bounces[] = {0, 1, 3};
    for (size_t b = 0; b < sizeof bounces / sizeof bounces[0]; b++) {
        int B = bounces[b];
        RefStats rs;
        Img g = golden_phong(&p, w, h, B, &rs);
        CfgMachine cfg;
        cfg_defaults(&cfg);
        cfg.workload_kind = CFG_WORKLOAD_PHONG;
        cfg.workload_bounces = B;
        FuncStats st;
        Img k = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &st);
        double maxd, mean;
        long bad;
        diff(&k, &g, &maxd, &mean, &bad);
        printf("phong B = %d vs golden  %-40s %3dx%-3d %d spp  max |diff| %.3g  mean %.4f  rays: %llu camera, %llu "
               "shadow, %llu indirect; %llu generations  [%s]\n",
               B, path, w, h, spp, maxd, mean, (unsigned long long)st.rays_camera,
               (unsigned long long)st.rays_shadow, (unsigned long long)st.rays_indirect,
               (unsigned long long)st.generations, st.defines);
        cr_expect(memcmp(k.rgb, g.rgb, sizeof(float) * 3 * (size_t)w * h) == 0,
                  "%s, B = %d: the kernel's image differs from the golden model's (max %g)", path, B, maxd);
        cr_expect(mean > 0.0, "%s, B = %d: black image", path, B);
        cr_expect_eq(bad, 0);
        cr_expect(strstr(st.defines, "WORKLOAD=3") != NULL, "%s", st.defines);
        cr_expect_eq(st.tile_w, 64);
        cr_expect_eq(st.tile_h, 32);
        cr_expect_eq(st.rays_camera, (uint64_t)w * h * spp);
        cr_expect_eq(st.rays_camera, rs.rays[REF_RAY_CAMERA]);
        cr_expect_eq(st.rays_shadow, rs.rays[REF_RAY_SHADOW], "%s, B = %d: %llu shadow rays, golden %llu", path, B,
                     (unsigned long long)st.rays_shadow, (unsigned long long)rs.rays[REF_RAY_SHADOW]);
        cr_expect_eq(st.rays_indirect, rs.rays[REF_RAY_INDIRECT]);
        cr_expect_eq(st.dropped + rs.dropped, 0);
        cr_expect_eq(st.generations, rs.generations);
        for (int gen = 0; gen < FUNC_MAX_GENERATIONS; gen++)
            cr_expect_eq(st.rays_per_generation[gen], rs.rays_per_generation[gen], "generation %d: %llu vs %llu",
                         gen, (unsigned long long)st.rays_per_generation[gen],
                         (unsigned long long)rs.rays_per_generation[gen]);
        cr_expect(st.rays_shadow > 0, "%s, B = %d: no shadow rays", path, B);
        cr_expect(st.rays_shadow <= (uint64_t)nlights * (st.rays_camera + st.rays_indirect));
        if (B == 0) {
            cr_expect_eq(st.rays_indirect, 0);
            cr_expect_eq(st.generations, 1);
        } else {
            cr_expect(st.rays_indirect > 0, "%s, B = %d: no bounce rays", path, B);
            cr_expect(st.generations >= 2 && st.generations <= (uint64_t)B + 1, "%llu generations",
                      (unsigned long long)st.generations);
        }
        free(k.rgb);
        func_stats_free(&st);
        if (B == 1) {
            static const struct { int mode, lanes, rays; } m[] = {{CFG_STREAM_MODE_PACKET, 8, 4096},
                                                                  {CFG_STREAM_MODE_STREAM, 12, 1024}};
            for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
                cfg.stream_mode = m[i].mode;
                cfg.core_simd_width = m[i].lanes;
                cfg.stream_rays = m[i].rays;
                Img a = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &st);
                cr_expect(memcmp(a.rgb, g.rgb, sizeof(float) * 3 * (size_t)w * h) == 0,
                          "%s: %s, N = %d, M = %d: the image differs", path, m[i].mode ? "packets" : "streams",
                          m[i].lanes, m[i].rays);
                cr_expect_eq(st.tile_w * st.tile_h, m[i].mode ? 8u : 512u);
                free(a.rgb);
                func_stats_free(&st);
            }
        }
        free(g.rgb);
    }
    pack_free(&p);
    scene_free(&s);
}

Test(functional, phong_workload_cornell_box_matches_the_golden_model, .timeout = 300)
{
    phong_matches_golden("scenes/cornell/scene.ini", 32, 32, 2);
}

/* point, spot, directional and quad lights, ambient, background, an emitter, a glass sphere */
Test(functional, phong_workload_every_light_kind_matches_the_golden_model, .timeout = 300)
{
    phong_matches_golden("tests/scenes/ok_every_section.ini", 32, 32, 2);
}

/* glTF punctual lights and 600-odd emissive triangles, textures, vertex normals */
Test(functional, phong_workload_punctual_lamp_matches_the_golden_model, .timeout = 300)
{
    phong_matches_golden("scenes/lights-punctual-lamp/scene.ini", 24, 24, 1);
}

/* stream.order = first (the papers' traversal: the stream follows its first ray) visits children
 * in another order than the golden model for some rays; hits differ only where two primitives
 * tie in distance within rounding, so almost every pixel keeps its exact value. */
Test(functional, first_ray_order_differs_only_in_rare_ties, .timeout = 300)
{
    Scene s;
    PackedScene p;
    int w = 64, h = 48;
    packed_load("scenes/conference/scene.ini", w, h, 1, &s, &p);
    Img g = golden(&p, w, h, 64);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_order = CFG_STREAM_ORDER_FIRST;
    FuncStats st;
    Img k = kernel_cfg(&p, s.needs, w, h, &cfg, 2, &st);
    long differ = 0;
    for (int i = 0; i < w * h; i++)
        if (memcmp(&k.rgb[3 * i], &g.rgb[3 * i], 12) != 0)
            differ++;
    printf("stream.order = first on the conference room: %ld of %d pixels differ from the golden model\n", differ,
           w * h);
    cr_expect(differ <= w * h / 100, "%ld of %d pixels differ", differ, w * h);
    cr_expect(strstr(st.defines, "ORDER_FIRST") != NULL, "%s", st.defines);
    free(g.rgb);
    free(k.rgb);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}

/* ---- accel.structure = kd: the host side, with tests/unit/kd_stub.s standing in for the kernel ---- */

#define KD_STUB "tests/unit/kd_stub.s"

static void kd_cfg(CfgMachine *cfg, int traversal)
{
    cfg_defaults(cfg);
    cfg->accel_structure = CFG_ACCEL_KD;
    cfg->kd_traversal = traversal;
    cfg->stream_rays = 1024;
}

static int kd_render(const PackedScene *p, uint32_t needs, const CfgMachine *cfg, int w, int h, FuncStats *st,
                     char *err, size_t errlen)
{
    float *rgb = calloc(3 * (size_t)w * h, sizeof(float));
    cr_assert_not_null(rgb);
    FuncParams fp = {.cfg = cfg, .kernel_path = KD_STUB, .needs = needs, .seed = 1, .threads = 2};
    int rc = func_render(p, &fp, rgb, st, err, errlen);
    free(rgb);
    return rc;
}

Test(functional, kd_tree_from_the_kd_keys_is_packed)
{
    Scene s;
    PackedScene p;
    packed_load("scenes/cornell/scene.ini", 16, 16, 1, &s, &p);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    AccelKdInfo info;
    char err[1024];
    /* accel.structure = bvh: nothing to add */
    cr_expect_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NODES)), 0u);
    cr_expect_eq(info.nodes, 0u);
    kd_cfg(&cfg, CFG_KD_STACK);
    cfg.kd_leaf_size = 4;
    cfg.kd_empty_bonus = 0.5;
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    /* The tree of those keys: the builder's with the same parameters. */
    KdParams kp;
    kd_default_params(&kp);
    kp.leaf_size = 4;
    kp.empty_bonus = 0.5f;
    KdTree t;
    cr_assert_eq(accel_kd_build(&p, &kp, &t, err, sizeof err), 0, "%s", err);
    cr_expect_eq(info.nodes, t.nnodes);
    cr_expect_eq(info.leaves, t.nleaves);
    cr_expect_eq(info.empty_leaves, t.nempty);
    cr_expect_eq(info.depth, t.depth);
    cr_expect_eq(info.refs, t.nrefs);
    cr_expect_eq(info.prims, p.nprims);
    cr_expect_eq(info.largest_leaf, t.max_leaf);
    cr_expect_eq(info.sah_cost, t.sah_cost);
    cr_expect(info.build_seconds >= 0.0);
    cr_expect_eq(p.kd_depth, t.depth);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NNODES)), t.nnodes);
    kd_default_params(&kp);
    KdTree d;
    cr_assert_eq(accel_kd_build(&p, &kp, &d, err, sizeof err), 0, "%s", err);
    cr_expect_neq(d.nnodes, t.nnodes, "kd.leaf_size and kd.empty_bonus changed nothing");
    kd_free(&d);
    kd_free(&t);
    pack_free(&p);
    scene_free(&s);
}

/* Counters: lanes 0..N-1 of every (kind, counter) vector summed over tiles and threads, cleared
 * before each run; KD_STACK_DEPTH per traversal. */
Test(functional, kd_counters_and_build_symbols)
{
    Scene s;
    PackedScene p;
    int w = 128, h = 64;           /* 8 tiles of 32 x 32 */
    packed_load("scenes/cornell/scene.ini", w, h, 1, &s, &p);
    CfgMachine cfg;
    kd_cfg(&cfg, CFG_KD_STACK);
    AccelKdInfo info;
    char err[65536];
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    struct { int traversal, lanes; uint32_t depth; } cases[] = {
        {CFG_KD_STACK, 16, info.depth + 1}, {CFG_KD_RESTART, 16, 1}, {CFG_KD_PUSHDOWN, 5, 1},
        {CFG_KD_SHORTSTACK, 5, 7}, {CFG_KD_PACKET, 16, 7}, {CFG_KD_STREAM, 8, 1}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        kd_cfg(&cfg, cases[i].traversal);
        cfg.core_simd_width = cases[i].lanes;
        cfg.kd_stack_depth = 7;
        FuncStats st;
        cr_assert_eq(kd_render(&p, s.needs, &cfg, w, h, &st, err, sizeof err), 0, "%s", err);
        char want[128];
        snprintf(want, sizeof want, "ACCEL_KD=1 KD_VARIANT=%d KD_STACK_DEPTH=%u", cases[i].traversal,
                 cases[i].depth);
        cr_expect(strstr(st.defines, want) != NULL, "defines '%s' lack '%s'", st.defines, want);
        cr_expect_eq(st.kd, 1);
        cr_expect_eq(st.kd_stack_depth, cases[i].depth);
        cr_expect_eq(st.rays_camera, 8u * 2);
        cr_expect_eq(st.rays_indirect, 8u * 3);
        uint64_t lanes = (uint64_t)cases[i].lanes, per_vector = 8 * lanes * (lanes + 1) / 2;
        for (int k = 0; k < FUNC_KD_KINDS; k++)
            for (int c = 0; c < FUNC_KD_COUNTERS; c++) {
                uint64_t want_n = per_vector * (uint64_t)(k * FUNC_KD_COUNTERS + c + 1);
                cr_expect_eq(st.kd_counts[k][c], want_n, "%s, N = %d: %s %s = %llu, expected %llu",
                             cfg_enum_name("kd", "traversal", cases[i].traversal), cases[i].lanes,
                             func_kd_kind_keys[k], func_kd_counter_keys[c], (unsigned long long)st.kd_counts[k][c],
                             (unsigned long long)want_n);
            }
        func_stats_free(&st);
    }
    pack_free(&p);
    scene_free(&s);
}

Test(functional, kd_memory_checks_name_the_keys)
{
    Scene s;
    PackedScene p;
    packed_load("scenes/cornell/scene.ini", 16, 16, 1, &s, &p);
    CfgMachine cfg;
    kd_cfg(&cfg, CFG_KD_STACK);
    AccelKdInfo info;
    char err[65536];
    FuncStats st;
    /* A kd run needs the tree in the packed scene. */
    cr_expect_neq(kd_render(&p, s.needs, &cfg, 16, 16, &st, err, sizeof err), 0);
    cr_expect(strstr(err, "accel.structure = kd") && strstr(err, "without a kd-tree"), "%s", err);
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    cr_assert_geq(p.kd_depth, 4u, "the stream case below assumes a depth of 4 or more");
    /* Counters end at 4096 + 3 x 6 x 256 = 8704 bytes, the per-lane state at 8704 + 29 x 256 = 16128;
     * packet stacks of 3 x 1040 bytes need 19248; the stream filter's 36 x (3 x depth + 8) bytes
     * more than 16 KiB. Packet mode (RAYS = N = 16) leaves the ray buffer small enough for per-lane
     * stacks of 1 KiB per entry to overflow it. */
    struct { int traversal, packet_mode, spad_kb, raybuf_kb, depth; const char *key, *why; } cases[] = {
        {CFG_KD_STACK, 0, 8, 512, 3, "spad.size_kb = 8", "counters"},
        {CFG_KD_RESTART, 0, 15, 512, 3, "spad.size_kb = 15", "per-lane state"},
        {CFG_KD_PACKET, 0, 18, 512, 3, "spad.size_kb = 18", "kd.stack_depth"},
        {CFG_KD_STREAM, 0, 16, 512, 3, "spad.size_kb = 16", "kd.max_depth"},
        {CFG_KD_SHORTSTACK, 1, 64, 8, 16, "raybuf.size_kb = 8", "kd.stack_depth"},
        {CFG_KD_PACKET, 1, 64, 8, 16, "raybuf.size_kb = 8", "kd.stack_depth"},
        {CFG_KD_STACK, 1, 64, 4, 3, "raybuf.size_kb = 4", "kd.max_depth"}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        kd_cfg(&cfg, cases[i].traversal);
        cfg.stream_mode = cases[i].packet_mode ? CFG_STREAM_MODE_PACKET : CFG_STREAM_MODE_STREAM;
        cfg.spad_size_kb = cases[i].spad_kb;
        cfg.raybuf_size_kb = cases[i].raybuf_kb;
        cfg.kd_stack_depth = cases[i].depth;
        cr_expect_eq(kd_render(&p, s.needs, &cfg, 16, 16, &st, err, sizeof err), -1, "case %zu accepted", i);
        cr_expect(strstr(err, cases[i].key) && strstr(err, cases[i].why), "case %zu: '%s' lacks '%s' or '%s'", i, err,
                  cases[i].key, cases[i].why);
    }
    /* The same machines with room enough run. */
    kd_cfg(&cfg, CFG_KD_PACKET);
    cfg.spad_size_kb = 19;
    cr_expect_eq(kd_render(&p, s.needs, &cfg, 16, 16, &st, err, sizeof err), 0, "%s", err);
    func_stats_free(&st);
    kd_cfg(&cfg, CFG_KD_STREAM);
    cfg.spad_size_kb = 64;
    cr_expect_eq(kd_render(&p, s.needs, &cfg, 16, 16, &st, err, sizeof err), 0, "%s", err);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}
