/* tests/unit/test_numerics.c -- the hard cases of docs/numerics.md that run in `make test`: every
 * case through the kernel (sfsim trace's engine, on the functional core) and the golden model,
 * asserting the property (no leak, the right hit, no NaN) for both and that the two agree bit
 * for bit. The slow cases are in tests/hard/ (`make test-hard`). */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/reference.h"
#include "../../sim/ref_trace.h"
#include "../../sim/run/accel.h"
#include "../../sim/run/run.h"
#include "../../sim/trace.h"
#include "../support/numerics.h"

static void pack_mesh(Mesh *m, Scene *s, PackedScene *p)
{
    mesh_scene(m, s);
    BvhParams bp;
    bvh_default_params(&bp);
    char err[512];
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s", err);
}

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float frand(uint32_t *s) { return (float)lcg(s) * (1.0f / 16777216.0f); }

/* Leaks: closest-hit rays that should hit the closed mesh and miss. */
static uint32_t leaks(const RayBatch *b, const BatchHit *h)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < b->count; i++)
        if (!h[i].invalid && h[i].prim == UINT32_MAX)
            n++;
    return n;
}

static uint32_t nonfinite_hits(const RayBatch *b, const BatchHit *h)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < b->count; i++)
        if (h[i].prim != UINT32_MAX && b->rays[i].query == RAY_CLOSEST &&
            (!isfinite(h[i].t) || !isfinite(h[i].u) || !isfinite(h[i].v)))
            n++;
    return n;
}

/* ---- watertightness ---------------------------------------------------------------------------- */

/* Rays through every vertex and every edge midpoint of a closed icosphere, from inside (its
 * centre and random interior points) and from outside: not one may pass between triangles. */
Test(numerics, icosphere_is_watertight_at_vertices_and_edges, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float c[3] = {0.25f, -0.5f, 0.125f};
    float *pts, *mids;
    uint32_t npts, nmids;
    mesh_icosphere(&m, c, 1.5f, 3, &pts, &npts, &mids, &nmids);
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch b = {0};
    uint32_t cap = 0, seed = 7;
    for (int pass = 0; pass < 2; pass++) {
        const float *set = pass ? mids : pts;
        uint32_t n = pass ? nmids : npts;
        for (uint32_t i = 0; i < n; i++) {
            const float *t = &set[3 * i];
            float d[3], o[3];
            for (int k = 0; k < 3; k++)
                d[k] = t[k] - c[k];
            batch_add(&b, &cap, c, d, INFINITY, RAY_CLOSEST); /* from the centre */
            for (int k = 0; k < 3; k++)
                o[k] = c[k] + 0.6f * (frand(&seed) - 0.5f);
            for (int k = 0; k < 3; k++)
                d[k] = t[k] - o[k];
            batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST); /* from inside, elsewhere */
            for (int k = 0; k < 3; k++) {
                o[k] = c[k] + 3.0f * (t[k] - c[k]);
                d[k] = t[k] - o[k];
            }
            batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST); /* from outside */
        }
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &b, 16, 4096, &kh, &rh);
    printf("icosphere (%u triangles): %u rays at %u vertices and %u edge midpoints: leaks kernel %u, golden %u; "
           "%u rays differ\n", m.ntris, b.count, npts, nmids, leaks(&b, kh), leaks(&b, rh), differ);
    cr_expect_eq(leaks(&b, kh), 0, "kernel: %u leaks", leaks(&b, kh));
    cr_expect_eq(leaks(&b, rh), 0, "golden model: %u leaks", leaks(&b, rh));
    cr_expect_eq(differ, 0, "%u rays differ between the kernel and the golden model", differ);
    cr_expect_eq(nonfinite_hits(&b, kh), 0);
    free(kh);
    free(rh);
    free(pts);
    free(mids);
    raybatch_free(&b);
    pack_free(&p);
    mesh_free(&m);
}

/* The inside of a cube (two triangles per face, sharing a diagonal): rays from inside at every
 * corner, every edge and face diagonal, and random points on edges. */
Test(numerics, cube_interior_is_watertight, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float lo[3] = {-1, -1, -1}, hi[3] = {1, 1, 1};
    mesh_box(&m, lo, hi, 0);
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch b = {0};
    uint32_t cap = 0, seed = 11;
    for (int i = 0; i < 2000; i++) {
        float o[3], t[3], d[3];
        for (int k = 0; k < 3; k++)
            o[k] = 1.8f * (frand(&seed) - 0.5f);
        /* a target on an edge, a corner or a face diagonal of the cube */
        int kind = i % 3;
        for (int k = 0; k < 3; k++)
            t[k] = frand(&seed) < 0.5f ? -1.0f : 1.0f;
        if (kind == 1) { /* edge: one free coordinate */
            int free_axis = (int)(lcg(&seed) % 3);
            t[free_axis] = 2.0f * frand(&seed) - 1.0f;
        } else if (kind == 2) { /* face diagonal x = y on a z face */
            float a = 2.0f * frand(&seed) - 1.0f;
            t[0] = a;
            t[1] = a;
        }
        for (int k = 0; k < 3; k++)
            d[k] = t[k] - o[k];
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &b, 8, 1024, &kh, &rh);
    printf("cube interior: %u rays at corners, edges, diagonals: leaks kernel %u, golden %u; %u differ\n", b.count,
           leaks(&b, kh), leaks(&b, rh), differ);
    cr_expect_eq(leaks(&b, kh), 0);
    cr_expect_eq(leaks(&b, rh), 0);
    cr_expect_eq(differ, 0);
    free(kh);
    free(rh);
    raybatch_free(&b);
    pack_free(&p);
    mesh_free(&m);
}

/* ---- flat geometry, axis-parallel rays, signed zeros, origins on slabs --------------------------- */

Test(numerics, flat_planes_and_boxes_of_zero_thickness, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float c[3] = {-1, 0, -1}, ea[3] = {0, 0, 2}, eb[3] = {2, 0, 0};
    mesh_quad(&m, c, ea, eb, 0); /* the plane y = 0, a BVH box of zero thickness */
    float c2[3] = {3, -1, -1}, ea2[3] = {0, 2, 0}, eb2[3] = {0, 0, 2};
    mesh_quad(&m, c2, ea2, eb2, 0); /* x = 3 */
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch b = {0};
    uint32_t cap = 0, seed = 3;
    int across = 0;
    for (int i = 0; i < 500; i++, across++) { /* across the plane, at random points */
        float o[3] = {1.8f * (frand(&seed) - 0.5f), 1.0f, 1.8f * (frand(&seed) - 0.5f)}, d[3] = {0, -1, 0};
        if (i % 2)
            d[0] = 0.1f * (frand(&seed) - 0.5f);
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    for (int i = 0; i < 200; i++) { /* within the plane: y = 0, dir.y = +0 or -0 */
        float o[3] = {-2.0f, 0.0f, 1.8f * (frand(&seed) - 0.5f)}, d[3] = {1.0f, i % 2 ? -0.0f : 0.0f, 0.0f};
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    uint32_t inplane_end = b.count;
    for (int i = 0; i < 50; i++) { /* along the quad's shared diagonal, in its plane, both ways */
        float o[3] = {-1.5f, 0.0f, -1.5f}, d[3] = {1.0f, 0.0f, 1.0f};
        if (i % 2) {
            o[0] = o[2] = 1.5f;
            d[0] = d[2] = -1.0f;
        }
        d[1] = i % 4 < 2 ? 0.0f : -0.0f;
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &b, 16, 1024, &kh, &rh);
    uint32_t wrong = 0;
    for (int i = 0; i < across; i++) {
        const BatchRay *r = &b.rays[i];
        float y = r->org[1] + kh[i].t * r->dir[1];
        if (kh[i].prim == UINT32_MAX || prim_source(&p, kh[i].prim) > 1 || fabsf(y) > 1e-6f)
            wrong++;
    }
    uint32_t along_wall = 0;
    for (uint32_t i = (uint32_t)across; i < inplane_end; i++) /* in the plane: the wall x = 3 at t = 5 */
        if (kh[i].prim != UINT32_MAX && prim_source(&p, kh[i].prim) >= 2 && fabsf(kh[i].t - 5.0f) <= 5.0f * 2 * FLT_EPSILON)
            along_wall++;
    printf("flat: %d rays across y = 0 (%u wrong), %u in the plane (%u reach the wall at t = 5 within 2 ulp), 50 along the "
           "shared diagonal; %u differ\n", across, wrong, inplane_end - across, along_wall, differ);
    cr_expect_eq(wrong, 0);
    cr_expect_eq(along_wall, inplane_end - (uint32_t)across, "rays in the plane must pass it and hit the wall");
    /* along the shared edge: the plane is met edge-on (a miss, or a hit at the plane is fine);
     * what matters is a defined, finite answer, the same in both engines (asserted below) */
    cr_expect_eq(differ, 0);
    cr_expect_eq(nonfinite_hits(&b, kh), 0);
    free(kh);
    free(rh);
    raybatch_free(&b);
    pack_free(&p);
    mesh_free(&m);
}

Test(numerics, axis_parallel_rays_signed_zeros_and_origins_on_slabs, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    mesh_box(&m, lo, hi, 0);
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch b = {0};
    uint32_t cap = 0, seed = 5;
    static const float z[2] = {0.0f, -0.0f};
    /* from outside along +x with every sign of zero in y and z: the face x = 0 at t = 1 */
    for (int i = 0; i < 64; i++) {
        float o[3] = {-1.0f, 0.05f + 0.9f * frand(&seed), 0.05f + 0.9f * frand(&seed)};
        float d[3] = {1.0f, z[i & 1], z[(i >> 1) & 1]};
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    /* origins exactly on the face x = 0, going in: the face x = 1 at t = 1 (t > 0 excludes x = 0) */
    for (int i = 0; i < 64; i++) {
        float o[3] = {0.0f, 0.05f + 0.9f * frand(&seed), 0.05f + 0.9f * frand(&seed)};
        float d[3] = {1.0f, z[i & 1], z[(i >> 1) & 1]};
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    /* (the watertight test's t = T / det is within an ulp or two, not exact) */
    /* origins on the slab y = 0 (the bottom face's plane), running along it: defined, no NaN */
    for (int i = 0; i < 64; i++) {
        float o[3] = {-1.0f, z[i & 1], 0.05f + 0.9f * frand(&seed)};
        float d[3] = {1.0f, z[(i >> 1) & 1], 0.0f};
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &b, 4, 1024, &kh, &rh);
    uint32_t bad_t = 0;
    for (int i = 0; i < 128; i++)
        if (kh[i].prim == UINT32_MAX || fabsf(kh[i].t - 1.0f) > 2 * FLT_EPSILON)
            bad_t++;
    printf("axis-parallel: 192 rays, %u without the hit at t = 1 (2 ulp); %u differ; %u non-finite\n", bad_t, differ,
           nonfinite_hits(&b, kh));
    cr_expect_eq(bad_t, 0);
    cr_expect_eq(differ, 0);
    cr_expect_eq(nonfinite_hits(&b, kh), 0);
    free(kh);
    free(rh);
    raybatch_free(&b);
    pack_free(&p);
    mesh_free(&m);
}

/* ---- grazing rays, degenerate, needle, tiny and huge triangles ---------------------------------- */

Test(numerics, degenerate_needle_tiny_and_huge_triangles, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float a[3] = {0, 0, 0}, b1[3] = {1, 0, 0}, c1[3] = {0, 1, 0};
    float mid[3] = {0.5f, 0, 0};
    mesh_tri(&m, a, a, a, 0);       /* 0: a point */
    mesh_tri(&m, a, b1, mid, 0);    /* 1: collinear */
    mesh_tri(&m, a, a, c1, 0);      /* 2: repeated vertex */
    float n0[3] = {2, 0, 0}, n1[3] = {3, 0, 0}, n2[3] = {2.5f, 1e-6f, 0};
    mesh_tri(&m, n0, n1, n2, 0);    /* 3: needle, 1e-6 high */
    float t0[3] = {1e-18f, 2e-18f, -3}, t1[3] = {2e-18f, 2e-18f, -3}, t2[3] = {1e-18f, 3e-18f, -3};
    mesh_tri(&m, t0, t1, t2, 0);    /* 4: tiny (1e-18 across, near the z axis) */
    float h0[3] = {-1e6f, -1e6f, -10}, h1[3] = {1e6f, -1e6f, -10}, h2[3] = {0, 1e6f, -10};
    mesh_tri(&m, h0, h1, h2, 0);    /* 5: large, z = -10 (the grazing target) */
    float g0[3] = {-1e18f, -1e18f, -20}, g1[3] = {1e18f, -1e18f, -20}, g2[3] = {0, 1e18f, -20};
    mesh_tri(&m, g0, g1, g2, 0);    /* 6: huge, z = -20 (products near 1e36, below FLT_MAX) */
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch bt = {0};
    uint32_t cap = 0, seed = 9;
    /* at the degenerate ones: nothing to hit but the huge triangle behind them */
    float targets[3][3] = {{0, 0, 0}, {0.25f, 0, 0}, {0, 0.5f, 0}};
    for (int i = 0; i < 3; i++) {
        float o[3] = {targets[i][0], targets[i][1], 1.0f}, d[3] = {0, 0, -1};
        batch_add(&bt, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    /* at the needle's inside, at the tiny triangle's centroid */
    float on[3] = {2.5f, 3e-7f, 1.0f}, ot[3] = {1.25e-18f, 2.25e-18f, 1.0f}, down[3] = {0, 0, -1};
    batch_add(&bt, &cap, on, down, INFINITY, RAY_CLOSEST);
    batch_add(&bt, &cap, ot, down, INFINITY, RAY_CLOSEST);
    /* past the large triangle's edge, at the huge one: z = -20 at t = 21 */
    float oh[3] = {2e6f, 0, 1.0f};
    batch_add(&bt, &cap, oh, down, INFINITY, RAY_CLOSEST);
    /* grazing the large triangle's plane from above, at shallower and shallower angles (t up to
     * 2^19, inside it; float32 cannot resolve a 1-unit offset at 1e15, so no farther) */
    for (int i = 0; i < 20; i++) {
        float o[3] = {100.0f * (frand(&seed) - 0.5f), 100.0f * (frand(&seed) - 0.5f), -9.0f};
        float d[3] = {1.0f, 0.0f, -ldexpf(1.0f, -i)};
        batch_add(&bt, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &bt, 16, 1024, &kh, &rh);
    for (int i = 0; i < 3; i++)
        cr_expect(kh[i].prim != UINT32_MAX && prim_source(&p, kh[i].prim) == 5,
                  "ray %d at a degenerate triangle: hit %u, expected only the huge triangle", i,
                  kh[i].prim == UINT32_MAX ? 999 : prim_source(&p, kh[i].prim));
    cr_expect(kh[3].prim != UINT32_MAX && prim_source(&p, kh[3].prim) == 3, "the needle is missed");
    cr_expect(kh[4].prim != UINT32_MAX && prim_source(&p, kh[4].prim) == 4, "the tiny triangle is missed");
    cr_expect(kh[5].prim != UINT32_MAX && prim_source(&p, kh[5].prim) == 6 && fabsf(kh[5].t - 21.0f) <= 21.0f * 2 * FLT_EPSILON,
              "the huge triangle: prim %u t %g", kh[5].prim, kh[5].t);
    uint32_t grazing_ok = 0, ninside = 0;
    for (uint32_t i = 6; i < bt.count; i++) {
        /* the plane z = -10 is reached at t = 2^k (slope 2^-k from z = -9); inside the large
         * triangle it must be hit there, within a few ulps of its coordinates (ulp(1e6) = 1/16)
         * along the ray; outside it must not be */
        double want = ldexp(1.0, (int)i - 6);
        const BatchRay *r = &bt.rays[i];
        double x = r->org[0] + want, y = r->org[1];
        int inside = y >= -1e6 && fabs(x) <= 0.5 * (1e6 - y);
        ninside += inside;
        double len = sqrt(1.0 + (double)r->dir[2] * r->dir[2]);
        int hit5 = kh[i].prim != UINT32_MAX && prim_source(&p, kh[i].prim) == 5;
        if (inside ? hit5 && fabs(kh[i].t - want) * len <= 4.0 * 0.0625 : !hit5)
            grazing_ok++;
    }
    printf("degenerate/needle/tiny/huge: %u rays differ; grazing rays right: %u of 20 (%u inside the triangle)\n",
           differ, grazing_ok, ninside);
    cr_expect_eq(grazing_ok, 20);
    cr_expect_eq(differ, 0);
    cr_expect_eq(nonfinite_hits(&bt, kh), 0);
    free(kh);
    free(rh);
    raybatch_free(&bt);
    pack_free(&p);
    mesh_free(&m);
}

/* Rays leaving a large floor upwards from offset origins (the conference room's floor: 2,600 x
 * 1,685 units at y = -1.572, origins 256 ulps above it, shadow-ray directions of length ~1,000 to
 * a ceiling): the triangle test's rounding error grows with the vertices' depths along the ray,
 * not with t, and exceeded the offset, so some rays "hit" the floor at t ~ 1e-8. A BVH hid it
 * (the floor's flat box lies behind the origin); a kd-tree leaf holding the floor did not. No ray
 * may hit, in the golden model, the BVH kernel or the kd-tree kernel (docs/numerics.md). */
Test(numerics, rays_leaving_a_large_triangle_do_not_hit_it, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float a[3] = {-946.887512f, -1.57215905f, -1016.10486f}, b[3] = {-946.887512f, -1.57215905f, 668.48938f},
          c[3] = {1653.24707f, -1.57215905f, -1016.10486f}, d[3] = {1653.24707f, -1.57215905f, 668.48938f};
    mesh_tri(&m, a, b, c, 0);
    mesh_tri(&m, b, d, c, 0);
    float e[3] = {-946.887512f, 700.0f, -1016.10486f}, f[3] = {1653.24707f, 700.0f, -1016.10486f},
          g[3] = {-946.887512f, 700.0f, 668.48938f};
    mesh_tri(&m, e, f, g, 0); /* a ceiling above the lights: the scene's box encloses the rays */
    Scene s;
    PackedScene p;
    pack_mesh(&m, &s, &p);
    RayBatch bt = {0};
    uint32_t cap = 0, seed = 77;
    const float up[3] = {0, 1, 0};
    for (int i = 0; i < 2000; i++) {
        float on[3] = {-940.0f + 2590.0f * frand(&seed), a[1], -1010.0f + 1675.0f * frand(&seed)}, o[3];
        ref_offset_point(on, up, o);
        float light[3] = {-940.0f + 2590.0f * frand(&seed), 640.0f, -1010.0f + 1675.0f * frand(&seed)};
        float dir[3] = {light[0] - o[0], light[1] - o[1], light[2] - o[2]};
        batch_add(&bt, &cap, o, dir, 0.999f, i % 2 ? RAY_ANY : RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &bt, 16, 1024, &kh, &rh);
    uint32_t hits = 0, kdhits = 0;
    for (uint32_t i = 0; i < bt.count; i++)
        hits += (bt.rays[i].query == RAY_ANY ? kh[i].prim == 1 : kh[i].prim != UINT32_MAX) ||
                (bt.rays[i].query == RAY_ANY ? rh[i].prim == 1 : rh[i].prim != UINT32_MAX);
    /* the kd-tree kernel, every traversal */
    CfgMachine cfg;
    cfg_defaults(&cfg);
    CfgErrors ce = {0};
    cr_assert_eq(cfg_set(&cfg, "accel.structure=kd", &ce), 0);
    AccelKdInfo info;
    char err[4096];
    cr_assert_eq(accel_add_kd(&p, &cfg, &info, err, sizeof err), 0, "%s", err);
    const char *trav[] = {"kd.traversal=stack", "kd.traversal=restart", "kd.traversal=shortstack",
                          "kd.traversal=packet", "kd.traversal=stream"};
    for (int v = 0; v < 5; v++) {
        cr_assert_eq(cfg_set(&cfg, trav[v], &ce), 0);
        RunSpec spec = {.mode = RUN_FUNCTIONAL, .cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .threads = 2};
        cr_assert_eq(run_trace(&p, NULL, s.needs, &spec, &bt, kh, NULL, err, sizeof err), 0, "%s", err);
        for (uint32_t i = 0; i < bt.count; i++)
            kdhits += bt.rays[i].query == RAY_ANY ? kh[i].prim == 1 : kh[i].prim != UINT32_MAX;
    }
    printf("rays leaving a large floor: %u rays, %u differ, %u hits (BVH kernel and golden model), %u (kd kernels)\n",
           bt.count, differ, hits, kdhits);
    cr_expect_eq(differ, 0);
    cr_expect_eq(hits, 0, "rays from just above the floor hit it");
    cr_expect_eq(kdhits, 0, "rays from just above the floor hit it in a kd-tree leaf");
    free(kh);
    free(rh);
    raybatch_free(&bt);
    pack_free(&p);
    mesh_free(&m);
}

/* ---- rendering guards: no NaN/Inf reaches the image; invalid rays are counted --------------------- */

/* The white furnace: objects of albedo 1 in an environment of radiance 1 and no lights; every
 * pixel's expected value is exactly 1 (Lambert, and a white dielectric: both conserve energy). */
static void furnace(uint32_t mat, const char *what)
{
    Mesh m;
    mesh_init(&m);
    float c[3] = {0, 0, 0};
    mesh_icosphere(&m, c, 1.0f, 2, NULL, NULL, NULL, NULL);
    for (uint32_t i = 0; i < m.ntris; i++)
        m.mat[i] = mat;
    m.spheres[0] = (SceneSphere){NULL, {1.6f, 0.4f, 0.5f}, 0.4f, (int)mat};
    m.nspheres = 1;
    Scene s;
    mesh_scene(&m, &s);
    s.render = (SceneRender){24, 24, 64, 63, {1, 1, 1}, {0, 0, 0}};
    s.needs |= SCENE_NEED_BACKGROUND;
    s.camera = (SceneCamera){{0, 0, 4}, {0.3f, 0.2f, 0}, {0, 1, 0}, 45.0f, 0, 0, SCENE_CAMERA_FILE};
    PackedScene p;
    BvhParams bp;
    bvh_default_params(&bp);
    char err[512];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    size_t n = 3 * 24 * 24;
    float *rgb = calloc(n, sizeof(float));
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s.needs, .seed = 1, .threads = 2};
    FuncStats st;
    static char ferr[65536];
    cr_assert_eq(func_render(&p, &fp, rgb, &st, ferr, sizeof ferr), 0, "%s", ferr);
    double sum = 0.0, worst = 0.0;
    long bad = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(rgb[i]))
            bad++;
        sum += rgb[i];
        worst = fmax(worst, fabs(rgb[i] - 1.0));
    }
    double mean = sum / (double)n;
    printf("white furnace, %s: mean %.5f (1 expected), largest pixel error %.3f, non-finite %ld, dropped %llu\n",
           what, mean, worst, bad, (unsigned long long)st.dropped);
    /* 576 pixels x 64 paths: the standard error of the mean is far below 0.01 */
    cr_expect(fabs(mean - 1.0) < 0.01, "%s: mean %g", what, mean);
    cr_expect_eq(bad, 0);
    cr_expect_eq(st.dropped, 0);
    free(rgb);
    func_stats_free(&st);
    pack_free(&p);
    mesh_free(&m);
}

Test(numerics, white_furnace_lambert, .timeout = 300) { furnace(3, "Lambert albedo 1"); }

Test(numerics, white_furnace_dielectric, .timeout = 300) { furnace(2, "white glass, ior 1.5"); }

/* Render s with the kernel (2 host threads) and the golden model: *k and *g receive the images
 * (free them), st the kernel's statistics (func_stats_free), rs the golden model's. */
static size_t render_both(const Scene *s, float **k, float **g, FuncStats *st, RefStats *rs)
{
    PackedScene p;
    BvhParams bp;
    bvh_default_params(&bp);
    static char err[65536];
    cr_assert_eq(pack_scene(s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    size_t n = 3 * (size_t)s->render.width * s->render.height;
    *k = calloc(n, sizeof(float));
    *g = calloc(n, sizeof(float));
    cr_assert(*k && *g);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s->needs, .seed = 1, .threads = 2};
    cr_assert_eq(func_render(&p, &fp, *k, st, err, sizeof err), 0, "%s", err);
    RefParams rp = {.tile = 64, .seed = 1, .threads = 2};
    cr_assert_eq(ref_render(&p, &rp, *g, rs, err, sizeof err), 0, "%s", err);
    pack_free(&p);
    return n;
}

/* Rays starting inside glass, nested glass, total internal reflection and grazing Fresnel: a
 * glass sphere inside a glass sphere with the camera inside the outer one; every pixel finite and
 * the same in both engines. */
Test(numerics, nested_glass_total_internal_reflection_camera_inside, .timeout = 300)
{
    Mesh m;
    mesh_init(&m);
    float c[3] = {0, 0, 0};
    mesh_icosphere(&m, c, 2.0f, 3, NULL, NULL, NULL, NULL);
    for (uint32_t i = 0; i < m.ntris; i++)
        m.mat[i] = 2;
    m.spheres[0] = (SceneSphere){NULL, {0.0f, 0.0f, -0.8f}, 0.6f, 2};
    m.spheres[1] = (SceneSphere){NULL, {0.3f, 0.1f, -0.8f}, 0.2f, 2};
    m.nspheres = 2;
    float lc[3] = {-4, 4, -4}, la[3] = {8, 0, 0}, lb[3] = {0, 0, 8};
    mesh_quad(&m, lc, lb, la, 1); /* a light above, facing down */
    Scene s;
    mesh_scene(&m, &s);
    s.render = (SceneRender){32, 24, 4, 12, {0.2f, 0.3f, 0.4f}, {0, 0, 0}};
    s.needs |= SCENE_NEED_BACKGROUND;
    s.camera = (SceneCamera){{0, 0, 1.5f}, {0, 0, -1}, {0, 1, 0}, 70.0f, 0, 0, SCENE_CAMERA_FILE};
    float *k, *g;
    FuncStats st;
    size_t n = render_both(&s, &k, &g, &st, NULL);
    long bad = 0;
    for (size_t i = 0; i < n; i++)
        bad += !isfinite(k[i]);
    printf("nested glass, camera inside: %llu rays, %llu dropped, non-finite %ld\n",
           (unsigned long long)(st.rays_camera + st.rays_indirect + st.rays_shadow), (unsigned long long)st.dropped,
           bad);
    cr_expect_eq(bad, 0);
    cr_expect(memcmp(k, g, n * sizeof(float)) == 0, "kernel and golden model differ");
    cr_expect(st.rays_indirect > st.rays_camera, "the glass should keep paths going");
    free(k);
    free(g);
    func_stats_free(&st);
    mesh_free(&m);
}

/* A triangle with a NaN vertex is rejected by the loader; a ray made non-finite by overflowing
 * throughput is dropped and counted, never traced: a glass sphere of ior 10^30 would blow
 * the numbers up -- here a surface whose base colour is 1e38 makes throughput overflow to inf. */
Test(numerics, rays_made_invalid_by_input_data_are_dropped_and_counted, .timeout = 120)
{
    Mesh m;
    mesh_init(&m);
    float lo[3] = {-2, -2, -2}, hi[3] = {2, 2, 2};
    mesh_box(&m, lo, hi, 0);
    float lc[3] = {-0.5f, 1.9f, -0.5f}, la[3] = {1, 0, 0}, lb[3] = {0, 0, 1};
    mesh_quad(&m, lc, la, lb, 1);
    Scene s;
    mesh_scene(&m, &s);
    m.mats[0].base_color[0] = m.mats[0].base_color[1] = m.mats[0].base_color[2] = 3e38f;
    s.render = (SceneRender){16, 16, 2, 6, {0, 0, 0}, {0, 0, 0}};
    s.camera = (SceneCamera){{0, 0, 1}, {0, 0, -1}, {0, 1, 0}, 60.0f, 0, 0, SCENE_CAMERA_FILE};
    float *k, *g;
    FuncStats st;
    RefStats rs;
    size_t n = render_both(&s, &k, &g, &st, &rs);
    printf("overflowing throughput: kernel dropped %llu rays, golden model %llu\n", (unsigned long long)st.dropped,
           (unsigned long long)rs.dropped);
    cr_expect(st.dropped > 0, "no ray was dropped: the case does not overflow");
    cr_expect_eq(st.dropped, rs.dropped);
    cr_expect(memcmp(k, g, n * sizeof(float)) == 0, "kernel and golden model differ");
    free(k);
    free(g);
    func_stats_free(&st);
    mesh_free(&m);
}
