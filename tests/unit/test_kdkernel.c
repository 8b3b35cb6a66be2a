/* tests/unit/test_kdkernel.c -- the kd-tree traversal kernels (kernels/lib/kdtrace.inc,
 * kdpacket.inc, kdstream.inc) against the golden model, through `sfsim trace`'s path (func_trace):
 * every variant's hits equal the BVH's bit for bit (closest: primitive, t, u, v; any-hit: the
 * answer), and the counters of the single-ray and packet variants equal sim/ref_kd.c's exactly,
 * per ray kind (the trace path makes closest rays camera rays and any-hit rays shadow rays).
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/kdtree.h"
#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/ref_kd.h"
#include "../../sim/run/accel.h"
#include "../../sim/ref_trace.h"

#include "../support/shared.h"

static uint64_t rng_state;
static float rnd(void)
{
    rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
    return (float)((rng_state >> 40) & 0xffffff) / 16777216.0f;
}

/* n rays in the scene's box: random (incoherent) ones, and fans of 16 from one point (coherent,
 * as camera rays are); every fourth ray with a finite tmax. any: every other ray an any-hit query. */
static void make_rays(const KdTree *t, uint32_t n, int any, BatchRay *r)
{
    float o[3] = {0}, d[3] = {0};
    for (uint32_t i = 0; i < n; i++) {
        int coherent = (i / 256) % 2 == 0;
        if (i % 16 == 0)
            for (int k = 0; k < 3; k++) {
                float c = 0.5f * (t->bmin[k] + t->bmax[k]), e = 0.5f * (t->bmax[k] - t->bmin[k]);
                o[k] = c + e * 0.8f * (2.0f * rnd() - 1.0f);
                d[k] = 2.0f * rnd() - 1.0f;
            }
        for (int k = 0; k < 3; k++) {
            float c = 0.5f * (t->bmin[k] + t->bmax[k]), e = 0.5f * (t->bmax[k] - t->bmin[k]);
            r[i].org[k] = coherent ? o[k] : c + e * 0.9f * (2.0f * rnd() - 1.0f);
            r[i].dir[k] = coherent ? d[k] + 0.03f * (float)((k == 0 ? (int)(i % 4) : k == 1 ? (int)(i % 16 / 4) : 0) - 1.5f)
                                   : 2.0f * rnd() - 1.0f;
        }
        if (i % 37 == 5)
            r[i].dir[i % 3] = 0.0f; /* axis-parallel rays */
        r[i].tmax = i % 4 == 3 ? 0.3f * (t->bmax[0] - t->bmin[0]) : INFINITY;
        r[i].query = any && i % 2 ? RAY_ANY : RAY_CLOSEST;
    }
}

typedef struct Case {
    const char *traversal;
    int depth;   /* kd.stack_depth */
    int any;     /* any-hit rays too */
} Case;

static void check_kernel(const char *path, uint32_t n, const Case *cases, int ncases)
{
    NEEDS_SCENE(path);
    Scene s;
    PackedScene p;
    char err[1024];
    cr_assert_eq(pack_load_file(path, 0, 0, 0, &s, &p, err, sizeof err), 0, "%s", err);
    KdTree t;
    KdParams kp;
    kd_default_params(&kp);
    cr_assert_eq(accel_kd_build(&p, &kp, &t, err, sizeof err), 0, "%s", err);
    CfgMachine base;
    cfg_defaults(&base);
    CfgErrors ce = {0};
    cr_assert_eq(cfg_set(&base, "accel.structure=kd", &ce), 0);
    AccelKdInfo info;
    cr_assert_eq(accel_add_kd(&p, &base, &info, err, sizeof err), 0, "%s", err);
    cr_assert_eq(info.nodes, t.nnodes, "the kernel's tree is the golden model's (default kd.* keys)");
    BatchRay *rays = calloc(n, sizeof *rays);
    BatchHit *hits = calloc(n, sizeof *hits);
    cr_assert(rays && hits);
    for (int c = 0; c < ncases; c++) {
        const Case *cs = &cases[c];
        rng_state = 4242; /* the same rays for every variant */
        make_rays(&t, n, cs->any, rays);
        CfgMachine cfg = base;
        char a[64];
        snprintf(a, sizeof a, "kd.traversal=%s", cs->traversal);
        cr_assert_eq(cfg_set(&cfg, a, &ce), 0, "%s", a);
        snprintf(a, sizeof a, "kd.stack_depth=%d", cs->depth);
        cr_assert_eq(cfg_set(&cfg, a, &ce), 0, "%s", a);
        RayBatch b = {rays, n};
        FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s.needs, .seed = 1,
                         .threads = 2, .batch = &b, .hits = hits};
        FuncStats st;
        cr_assert_eq(func_trace(&p, &fp, &st, err, sizeof err), 0, "%s %s: %s", path, cs->traversal, err);

        /* the golden model: the BVH's answers, and the kd variant's counters */
        RefKdStats gst[FUNC_KD_KINDS];
        memset(gst, 0, sizeof gst);
        long bad = 0;
        int packet = !strcmp(cs->traversal, "packet"), stream = !strcmp(cs->traversal, "stream");
        RefKdVariant v = !strcmp(cs->traversal, "stack")     ? REF_KD_STACK
                       : !strcmp(cs->traversal, "restart")   ? REF_KD_RESTART
                       : !strcmp(cs->traversal, "pushdown")  ? REF_KD_PUSHDOWN
                                                             : REF_KD_SHORTSTACK;
        int vdepth = v == REF_KD_SHORTSTACK ? cs->depth : 0;
        int width = cfg.core_simd_width, mrays = cfg.stream_rays;
        for (uint32_t i = 0; i < n; i++) {
            RefRay r;
            memcpy(r.org, rays[i].org, sizeof r.org);
            memcpy(r.dir, rays[i].dir, sizeof r.dir);
            r.tmax = rays[i].tmax;
            if (rays[i].query == RAY_ANY) {
                int o = ref_any_hit(&p, &r, NULL);
                if (!stream && !packet)
                    ref_kd_any_hit(&p, &t, v, vdepth, &r, &gst[FUNC_KD_SHADOW]);
                if ((int)hits[i].prim != o && bad++ < 3)
                    cr_log_error("%s %s ray %u: any-hit %u, BVH %d", path, cs->traversal, i, hits[i].prim, o);
                continue;
            }
            RefHit ref;
            ref_closest_hit(&p, &r, &ref, NULL);
            if (!stream && !packet) {
                RefHit h;
                ref_kd_closest_hit(&p, &t, v, vdepth, &r, &h, &gst[FUNC_KD_CAMERA]);
            }
            int same = hits[i].prim == ref.prim &&
                       (ref.prim == REF_NO_HIT || (memcmp(&hits[i].t, &ref.t, 4) == 0 &&
                                                   memcmp(&hits[i].u, &ref.u, 4) == 0 &&
                                                   memcmp(&hits[i].v, &ref.v, 4) == 0));
            if (!same && bad++ < 3)
                cr_log_error("%s %s ray %u: prim %u t %.9g, BVH prim %u t %.9g", path, cs->traversal, i,
                             hits[i].prim, hits[i].t, ref.prim, ref.t);
        }
        int golden = !stream && !(packet && cs->any); /* (the golden packets are closest-hit only) */
        if (packet && !cs->any) { /* the kernel's packets: N consecutive rays of each run of M */
            for (uint32_t r0 = 0; r0 < n; r0 += (uint32_t)mrays)
                for (uint32_t i = r0; i < n && i < r0 + (uint32_t)mrays; i += (uint32_t)width) {
                    uint32_t k = n - i < (uint32_t)width ? n - i : (uint32_t)width;
                    if (r0 + (uint32_t)mrays - i < k)
                        k = r0 + (uint32_t)mrays - i;
                    RefRay pr[64];
                    RefHit ph[64];
                    for (uint32_t j = 0; j < k; j++) {
                        memcpy(pr[j].org, rays[i + j].org, sizeof pr[j].org);
                        memcpy(pr[j].dir, rays[i + j].dir, sizeof pr[j].dir);
                        pr[j].tmax = rays[i + j].tmax;
                    }
                    ref_kd_packet_closest_hit(&p, &t, cs->depth, pr, (int)k, ph, &gst[FUNC_KD_CAMERA]);
                }
        }
        cr_expect_eq(bad, 0, "%s %s (depth %d): %ld rays differ from the BVH", path, cs->traversal, cs->depth, bad);
        const uint64_t *cam = st.kd_counts[FUNC_KD_CAMERA], *sh = st.kd_counts[FUNC_KD_SHADOW];
        printf("  %s %s depth %d, %u rays: camera nodes %llu leaves %llu prims %llu restarts %llu overflows %llu "
               "underflows %llu; shadow nodes %llu\n",
               path, cs->traversal, cs->depth, n, (unsigned long long)cam[FUNC_KD_NODES],
               (unsigned long long)cam[FUNC_KD_LEAVES], (unsigned long long)cam[FUNC_KD_PRIMS],
               (unsigned long long)cam[FUNC_KD_RESTARTS], (unsigned long long)cam[FUNC_KD_OVERFLOWS],
               (unsigned long long)cam[FUNC_KD_UNDERFLOWS], (unsigned long long)sh[FUNC_KD_NODES]);
        if (!golden) {
            /* no golden counters (stream: a ray counts at each node whose voxel it enters; packets
             * with any-hit rays: the golden packets are closest-hit only) */
            cr_expect_gt(cam[FUNC_KD_NODES], cam[FUNC_KD_LEAVES]);
            cr_expect_gt(cam[FUNC_KD_LEAVES], 0);
            if (stream)
                cr_expect_eq(cam[FUNC_KD_RESTARTS] + cam[FUNC_KD_OVERFLOWS] + cam[FUNC_KD_UNDERFLOWS], 0);
        } else {
            for (int k = 0; k < FUNC_KD_KINDS; k += 2) {
                const RefKdStats *g = &gst[k];
                const uint64_t want[FUNC_KD_COUNTERS] = {g->nodes_visited, g->leaves_visited, g->prims_tested,
                                                         g->restarts, g->stack_overflows, g->stack_underflows};
                for (int q = 0; q < FUNC_KD_COUNTERS; q++)
                    cr_expect_eq(st.kd_counts[k][q], want[q], "%s %s depth %d: %s %s = %llu, golden model %llu",
                                 path, cs->traversal, cs->depth, func_kd_kind_keys[k], func_kd_counter_keys[q],
                                 (unsigned long long)st.kd_counts[k][q], (unsigned long long)want[q]);
            }
        }
        cr_expect_eq(st.kd_counts[FUNC_KD_INDIRECT][FUNC_KD_NODES], 0, "no indirect rays in a trace");
        func_stats_free(&st);
    }
    free(rays);
    free(hits);
    kd_free(&t);
    pack_free(&p);
    scene_free(&s);
}

static const Case all_cases[] = {
    {"stack", 3, 1},      {"restart", 3, 1},    {"pushdown", 3, 1}, {"shortstack", 1, 1},
    {"shortstack", 3, 1}, {"packet", 1, 0},     {"packet", 3, 0},   {"packet", 3, 1},
    {"stream", 3, 1},
};

Test(kdkernel, spheres_every_variant_matches_bvh_and_golden_counters, .timeout = 300)
{
    /* triangles and spheres: the per-lane, packet and stream sphere paths */
    check_kernel("scenes/cornell/spheres.ini", 4096, all_cases, sizeof all_cases / sizeof *all_cases);
}

Test(kdkernel, conference_every_variant_matches_bvh_and_golden_counters, .timeout = 600)
{
    check_kernel("scenes/conference/scene.ini", 2048, all_cases, sizeof all_cases / sizeof *all_cases);
}

/* The structure must not change the picture: the path tracer renders the same image bits with the
 * BVH and with every kd-tree traversal (a small frame of the Cornell box and the conference room). */
static void check_images(const char *path, int w, int h, int workload, int bounces)
{
    NEEDS_SCENE(path);
    Scene s;
    PackedScene p;
    char err[65536];
    cr_assert_eq(pack_load_file(path, w, h, 1, &s, &p, err, sizeof err), 0, "%s", err);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.workload_kind = workload;
    cfg.workload_bounces = bounces;
    CfgErrors ce = {0};
    cr_assert_eq(cfg_set(&cfg, "accel.structure=kd", &ce), 0);
    AccelKdInfo info;
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    static const char *const trav[] = {NULL, "stack", "restart", "pushdown", "shortstack", "packet", "stream"};
    size_t n = 3 * (size_t)w * h;
    float *ref = calloc(n, sizeof(float)), *rgb = calloc(n, sizeof(float));
    cr_assert(ref && rgb);
    for (int v = 0; v < 7; v++) {
        CfgMachine c = cfg;
        char a[64];
        snprintf(a, sizeof a, "%s", v ? "accel.structure=kd" : "accel.structure=bvh");
        cr_assert_eq(cfg_set(&c, a, &ce), 0);
        if (v) {
            snprintf(a, sizeof a, "kd.traversal=%s", trav[v]);
            cr_assert_eq(cfg_set(&c, a, &ce), 0);
        }
        FuncParams fp = {.cfg = &c, .kernel_path = "kernels/pathtrace.s", .needs = s.needs, .seed = 1, .threads = 2};
        FuncStats st;
        memset(rgb, 0, n * sizeof(float));
        cr_assert_eq(func_render(&p, &fp, v ? rgb : ref, &st, err, sizeof err), 0, "%s %s: %s", path,
                     v ? trav[v] : "bvh", err);
        if (v) {
            size_t differ = 0;
            for (size_t i = 0; i < n; i++)
                differ += memcmp(&ref[i], &rgb[i], sizeof(float)) != 0;
            cr_expect_eq(differ, 0, "%s: kd.traversal = %s: %zu of %zu values differ from the BVH's image", path,
                         trav[v], differ, n);
            cr_expect_gt(st.kd_counts[FUNC_KD_CAMERA][FUNC_KD_NODES], 0, "%s %s: no nodes counted", path, trav[v]);
        }
        func_stats_free(&st);
    }
    free(ref);
    free(rgb);
    pack_free(&p);
    scene_free(&s);
}

Test(kdkernel, every_traversal_renders_the_bvh_image, .timeout = 600)
{
    check_images("scenes/cornell/scene.ini", 48, 48, CFG_WORKLOAD_PATH, 0);
}

Test(kdkernel, every_traversal_renders_the_bvh_image_of_the_conference_room, .timeout = 600)
{
    check_images("scenes/conference/scene.ini", 40, 32, CFG_WORKLOAD_PATH, 0);
}

/* Mirror bounces in Sponza: its walls once sat in kd-tree voxels one ulp thick, which bounce rays
 * stepped over (scenes/kdtree.h, KD_MIN_GAP). */
Test(kdkernel, sponza_mirror_bounces_render_the_bvh_image, .timeout = 600)
{
    check_images("scenes/sponza-dabrovic/scene.ini", 32, 32, CFG_WORKLOAD_PHONG, 3);
}
