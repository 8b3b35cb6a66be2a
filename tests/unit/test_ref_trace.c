/* tests/unit/test_ref_trace.c -- the golden model's primitive tests and BVH traversal:
 * hand-checked cases, the zero-direction and on-slab cases, the box test against its axis-by-axis
 * definition on random and special values, shared-edge watertightness, and traversal against
 * brute force over every primitive. */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/ref_trace.h"
#include "../support/shared.h"

Test(ref_box, zero_direction_components_and_slab_planes)
{
    float bmin[3] = {0, 0, 0}, bmax[3] = {1, 1, 1};
    float dir[3] = {1.0f, 0.0f, -0.0f};
    float inv[3];
    ref_sanitize_dir(dir);
    ref_inv_dir(dir, inv);
    cr_expect(isfinite(inv[1]) && isfinite(inv[2]) && signbit(inv[2]), "finite inverse keeps the sign of -0");
    float org_in[3] = {-1.0f, 0.5f, 0.5f};
    cr_expect(ref_hit_box(bmin, bmax, org_in, inv, 10.0f));
    float org_on_plane[3] = {-1.0f, 0.0f, 1.0f}; /* exactly on the y = 0 and z = 1 faces */
    /* y = +0 on the y = 0 face and z = -0 on the z = 1 face: both point into the box. */
    cr_expect(ref_hit_box(bmin, bmax, org_on_plane, inv, 10.0f), "ray on a face plane, pointing in");
    float dneg[3] = {1.0f, -0.0f, 0.0f}, invneg[3];
    ref_sanitize_dir(dneg);
    ref_inv_dir(dneg, invneg);
    cr_expect_not(ref_hit_box(bmin, bmax, org_on_plane, invneg, 10.0f),
                  "signs of zero swapped: the ray leaves through both faces at t = 0");
    float org_mid[3] = {-1.0f, 0.5f, 0.5f};
    cr_expect(ref_hit_box(bmin, bmax, org_mid, invneg, 10.0f));
    float org_out[3] = {-1.0f, 1.5f, 0.5f};
    cr_expect_not(ref_hit_box(bmin, bmax, org_out, inv, 10.0f));
    cr_expect_not(ref_hit_box(bmin, bmax, org_in, inv, 0.5f), "box beyond tmax");
    float flat_min[3] = {0, 0.25f, 0}, flat_max[3] = {1, 0.25f, 1}; /* zero thickness in y */
    float down[3] = {0, -1, 0}, inv_down[3];
    ref_sanitize_dir(down);
    ref_inv_dir(down, inv_down);
    float above[3] = {0.5f, 2.0f, 0.5f};
    cr_expect(ref_hit_box(flat_min, flat_max, above, inv_down, 10.0f), "zero-thickness box");
}

/* The slab test as docs/golden-model.md writes it, one axis after another: what the kernels
 * compute and what ref_hit_box must answer whatever its evaluation (SSE lanes on x86-64). */
static int box_chain(const float *bmin, const float *bmax, const float *org, const float *inv, float tmax)
{
    float tn = 0.0f, tf = tmax * REF_HIT_SCALE;
    for (int k = 0; k < 3; k++) {
        float t0 = (bmin[k] - org[k]) * inv[k], t1 = (bmax[k] - org[k]) * inv[k];
        tn = ref_fmax(tn, ref_fmin(t0, t1));
        tf = ref_fmin(tf, ref_fmax(t0, t1) * 1.00000072f);
    }
    return tn <= tf;
}

static float pick(unsigned *state, int special)
{
    static const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, 0x1p-126f, -0x1p-140f, 1e30f, -1e30f,
                                     INFINITY, -INFINITY, NAN, 0.5f};
    *state = *state * 1103515245u + 12345u;
    unsigned r = *state >> 8;
    if (special && r % 4 == 0)
        return specials[(r >> 2) % 12];
    return ((float)(r % 2001) - 1000.0f) / 250.0f;
}

Test(ref_box, lanes_answer_as_the_axis_chain)
{
    unsigned state = 7;
    long differ = 0, hits = 0;
    for (int i = 0; i < 200000; i++) {
        float bmin[3], bmax[3], org[3], dir[3], inv[3];
        for (int k = 0; k < 3; k++) {
            bmin[k] = pick(&state, i % 3 == 0);
            bmax[k] = i % 5 == 0 ? pick(&state, 1) : bmin[k] + fabsf(pick(&state, 0)); /* some inverted */
            org[k] = pick(&state, i % 7 == 0);
            dir[k] = pick(&state, 1);
        }
        ref_sanitize_dir(dir);
        ref_inv_dir(dir, inv);
        float tmax = i % 11 == 0 ? pick(&state, 1) : fabsf(pick(&state, 0)) * 4.0f;
        int want = box_chain(bmin, bmax, org, inv, tmax);
        differ += ref_hit_box(bmin, bmax, org, inv, tmax) != want;
        hits += want;
    }
    cr_expect_eq(differ, 0, "%ld of 200000 boxes answered differently from the axis chain", differ);
    cr_expect(hits > 10000 && hits < 190000, "both answers occur (%ld hits)", hits);
}

Test(ref_triangle, hit_barycentrics_and_both_sides)
{
    float v0[3] = {0, 0, 0}, v1[3] = {1, 0, 0}, v2[3] = {0, 1, 0};
    RefRay r = {{0.25f, 0.5f, 2.0f}, {0, 0, -1}, 100.0f};
    float t, u, v;
    cr_assert(ref_hit_triangle(v0, v1, v2, &r, &t, &u, &v));
    cr_expect_float_eq(t, 2.0f, 1e-6f);
    cr_expect_float_eq(u, 0.25f, 1e-6f);
    cr_expect_float_eq(v, 0.5f, 1e-6f);
    RefRay back = {{0.25f, 0.5f, -2.0f}, {0, 0, 1}, 100.0f};
    cr_expect(ref_hit_triangle(v0, v1, v2, &back, &t, &u, &v), "no culling of back faces");
    cr_expect_float_eq(u, 0.25f, 1e-6f);
    RefRay shortr = r;
    shortr.tmax = 2.0f;
    cr_expect_not(ref_hit_triangle(v0, v1, v2, &shortr, &t, &u, &v), "t must be < tmax");
    RefRay behind = {{0.25f, 0.5f, -2.0f}, {0, 0, -1}, 100.0f};
    cr_expect_not(ref_hit_triangle(v0, v1, v2, &behind, &t, &u, &v), "t must be > 0");
    /* An axis-parallel ray with signed zeros: sanitized, it still hits, with no NaN. */
    RefRay axis = {{0.25f, 0.5f, 2.0f}, {-0.0f, 0.0f, -1.0f}, 100.0f};
    cr_expect(ref_hit_triangle(v0, v1, v2, &axis, &t, &u, &v));
    cr_expect(isfinite(t) && isfinite(u) && isfinite(v));
}

Test(ref_triangle, shared_edges_do_not_leak)
{
    /* A unit quad split along its diagonal; rays aimed at interior points of the diagonal, from
     * several directions, must hit at least one of the two. (The quad's own corners are on the
     * mesh boundary: a ray whose rounded origin passes just outside them really misses.) */
    float a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {1, 1, 0}, d[3] = {0, 1, 0};
    int leaks = 0, tested = 0;
    for (int i = 1; i < 64; i++) {
        float s = (float)i / 64.0f;
        float target[3] = {s, s, 0.0f};
        for (int j = 0; j < 16; j++) {
            float ang = 0.37f * (float)j;
            RefRay r;
            r.dir[0] = 0.3f * cosf(ang);
            r.dir[1] = 0.3f * sinf(ang);
            r.dir[2] = -1.0f;
            for (int k = 0; k < 3; k++)
                r.org[k] = target[k] - 3.0f * r.dir[k];
            r.tmax = 100.0f;
            float t, u, v;
            int h1 = ref_hit_triangle(a, b, c, &r, &t, &u, &v);
            int h2 = ref_hit_triangle(a, c, d, &r, &t, &u, &v);
            leaks += !(h1 || h2);
            tested++;
        }
    }
    /* A fan of six triangles around a shared vertex at the origin: rays aimed at the vertex. */
    float ring[6][3];
    for (int k = 0; k < 6; k++) {
        ring[k][0] = cosf(1.0471976f * (float)k);
        ring[k][1] = sinf(1.0471976f * (float)k);
        ring[k][2] = 0.0f;
    }
    float centre[3] = {0, 0, 0};
    for (int j = 0; j < 64; j++) {
        float ang = 0.1f * (float)j;
        RefRay r = {{0, 0, 0}, {0.25f * cosf(ang), 0.25f * sinf(ang), j % 2 ? 1.0f : -1.0f}, 100.0f};
        for (int k = 0; k < 3; k++)
            r.org[k] = -2.0f * r.dir[k]; /* exact: scaling by a power of two */
        int hit = 0;
        float t, u, v;
        for (int k = 0; k < 6; k++)
            hit |= ref_hit_triangle(centre, ring[k], ring[(k + 1) % 6], &r, &t, &u, &v);
        leaks += !hit;
        tested++;
    }
    cr_log_info("shared edge and vertex: %d rays, %d leaks", tested, leaks);
    cr_expect_eq(leaks, 0, "%d of %d rays through the shared edge leaked", leaks, tested);
}

Test(ref_sphere, outside_inside_tangent)
{
    float c[3] = {0, 0, -5};
    RefRay r = {{0, 0, 0}, {0, 0, -1}, 100.0f};
    float t;
    cr_assert(ref_hit_sphere(c, 1.0f, &r, &t));
    cr_expect_float_eq(t, 4.0f, 1e-6f);
    RefRay in = {{0, 0, -5}, {0, 0, -2}, 100.0f};
    cr_assert(ref_hit_sphere(c, 1.0f, &in, &t));
    cr_expect_float_eq(t, 0.5f, 1e-6f, "from inside: the far wall, in units of |dir|");
    RefRay miss = {{0, 1.5f, 0}, {0, 0, -1}, 100.0f};
    cr_expect_not(ref_hit_sphere(c, 1.0f, &miss, &t));
    /* A tiny sphere far away keeps its hit (the precision-improved discriminant). */
    float far[3] = {0, 0, -1e4f};
    RefRay rf = {{0, 0, 0}, {0, 0, -1}, 1e6f};
    cr_expect(ref_hit_sphere(far, 1e-2f, &rf, &t));
    cr_expect_float_eq(t, 1e4f - 1e-2f, 1e-2f);
}

/* A soup of n small random triangles in [-5, 5]^3, each within spread of its centre, from the
 * generator state *st (left where the soup ends, for the caller's rays), packed with leaves of up
 * to max_leaf primitives (0: the default build). s->pos and s->tri_material are the caller's to
 * free. */
static void soup_pack(uint32_t n, float spread, uint32_t *st, int max_leaf, Scene *s, SceneMaterial *m,
                      PackedScene *p)
{
    memset(s, 0, sizeof *s);
    float *pos = malloc(sizeof(float) * 9 * n);
    uint32_t *tm = calloc(n, sizeof(uint32_t));
    cr_assert(pos && tm);
    for (uint32_t i = 0; i < n; i++) {
        float c[3];
        for (int k = 0; k < 3; k++) {
            *st = *st * 1664525u + 1013904223u;
            c[k] = (float)(*st >> 8) / 16777216.0f * 10.0f - 5.0f;
        }
        for (int v = 0; v < 3; v++)
            for (int k = 0; k < 3; k++) {
                *st = *st * 1664525u + 1013904223u;
                pos[9 * i + 3 * v + k] = c[k] + ((float)(*st >> 8) / 16777216.0f - 0.5f) * spread;
            }
    }
    memset(m, 0, sizeof *m);
    s->ntris = n;
    s->pos = pos;
    s->tri_material = tm;
    s->materials = m;
    s->nmaterials = 1;
    s->camera = (SceneCamera){{0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 45, 0, 0, 0};
    s->render = (SceneRender){8, 8, 1, 1, {0, 0, 0}, {0, 0, 0}};
    BvhParams bp;
    bvh_default_params(&bp);
    if (max_leaf > 0) {
        bp.max_leaf_size = max_leaf;
        if (max_leaf > 4)
            bp.cost_traversal = 40.0f; /* a costly node: the build then fills its leaves */
    }
    char err[256];
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s", err);
}

/* Random triangle soup packed with the real packer; closest hits from traversal must equal
 * brute force over all primitives with the same tie rule. */
Test(ref_traversal, matches_brute_force)
{
    uint32_t n = 3000, st = 99;
    Scene s;
    SceneMaterial m;
    PackedScene p;
    soup_pack(n, 0.8f, &st, 0, &s, &m, &p);
    uint32_t prims = sm_u32(&p, sm_hdr(&p, SM_HDR_PRIMS));
    int mismatches = 0, hits = 0, occl_mismatch = 0;
    for (int i = 0; i < 2000; i++) {
        RefRay r;
        for (int k = 0; k < 3; k++) {
            st = st * 1664525u + 1013904223u;
            r.org[k] = (float)(st >> 8) / 16777216.0f * 16.0f - 8.0f;
            st = st * 1664525u + 1013904223u;
            r.dir[k] = (float)(st >> 8) / 16777216.0f * 2.0f - 1.0f;
        }
        r.tmax = (i % 3 == 0) ? 4.0f : INFINITY;
        RefHit h;
        ref_closest_hit(&p, &r, &h, NULL);
        RefHit b = {r.tmax, 0, 0, REF_NO_HIT};
        for (uint32_t j = 0; j < n; j++) {
            float g[9], t, u, v;
            for (int k = 0; k < 9; k++)
                g[k] = sm_f32(&p, sm_rec(prims, SM_PRIM_WORDS, j, SM_PRIM_V0) + 4u * (uint32_t)k);
            if (ref_hit_triangle(g, g + 3, g + 6, &r, &t, &u, &v) &&
                (b.prim == REF_NO_HIT || t < b.t || (t == b.t && j < b.prim)))
                b = (RefHit){t, u, v, j};
        }
        hits += b.prim != REF_NO_HIT;
        mismatches += h.prim != b.prim || (b.prim != REF_NO_HIT && h.t != b.t);
        occl_mismatch += ref_any_hit(&p, &r, NULL) != (b.prim != REF_NO_HIT);
    }
    cr_log_info("traversal vs brute force: 2000 rays, %d hits, %d mismatches", hits, mismatches);
    cr_expect_gt(hits, 200, "the test rays should hit something");
    cr_expect_eq(mismatches, 0);
    cr_expect_eq(occl_mismatch, 0);
    pack_free(&p);
    free(s.pos);
    free(s.tri_material);
}

/* A query without stats takes the 4-wide walk over the private layout (sim/ref_trace.c; the
 * binary walks for rays with a non-finite component or a scene it refuses); one with stats takes
 * the plain walk, whose counts sampled mode uses. Their hits must agree bit for bit (prim, t, u, v)
 * and so must the any-hit answers, on rays that start inside and outside the scene, run along axes
 * (zero and negative-zero components), carry odd tmax values and, one in 64, an infinite or NaN
 * component. */
static void walks_agree(const PackedScene *p, const char *name, int nrays, int min_hits)
{
    uint32_t nodes = sm_u32(p, sm_hdr(p, SM_HDR_NODES));
    float lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = sm_f32(p, sm_rec(nodes, SM_NODE_WORDS, 0, SM_NODE_BMIN) + 4u * (uint32_t)k);
        hi[k] = sm_f32(p, sm_rec(nodes, SM_NODE_WORDS, 0, SM_NODE_BMAX) + 4u * (uint32_t)k);
    }
    static const float tmaxes[] = {INFINITY, 0.0f, -1.0f, 1e-30f, 0.5f, 3.0f, FLT_MAX};
    static const float odd[] = {INFINITY, -INFINITY, NAN};
    unsigned st = 12345u;
    int differ = 0, occl_differ = 0, hits = 0;
    uint64_t visited = 0;
    for (int i = 0; i < nrays; i++) {
        RefRay r;
        for (int k = 0; k < 3; k++) {
            st = st * 1664525u + 1013904223u;
            float f = (float)(st >> 8) / 16777216.0f;
            r.org[k] = lo[k] + (f * 1.4f - 0.2f) * (hi[k] - lo[k]);
            st = st * 1664525u + 1013904223u;
            r.dir[k] = (float)(st >> 8) / 16777216.0f * 2.0f - 1.0f;
            if ((st >> 4) % 16 == 0)
                r.dir[k] = (st >> 9) % 2 ? 0.0f : -0.0f;
        }
        st = st * 1664525u + 1013904223u;
        r.tmax = (st >> 8) % 4 ? INFINITY : tmaxes[(st >> 12) % (sizeof tmaxes / sizeof *tmaxes)];
        if (r.tmax > 0.0f && r.tmax < 10.0f)
            r.tmax *= hi[0] - lo[0];
        if (i % 64 == 63) {
            float *c = (st >> 20) % 2 ? r.org : r.dir;
            c[(st >> 21) % 3] = odd[(st >> 23) % 3];
        }
        RefHit fast, plain;
        RefTraceStats ts = {0};
        ref_closest_hit(p, &r, &fast, NULL);
        ref_closest_hit(p, &r, &plain, &ts);
        visited += ts.nodes_visited;
        hits += plain.prim != REF_NO_HIT;
        differ += memcmp(&fast, &plain, sizeof fast) != 0;
        occl_differ += ref_any_hit(p, &r, NULL) != ref_any_hit(p, &r, &ts);
    }
    cr_log_info("%s: %d rays, %d hits, %.1f nodes per ray", name, nrays, hits, (double)visited / nrays);
    cr_expect_geq(hits, min_hits, "%s: the test rays should hit something", name);
    cr_expect_eq(differ, 0, "%s: %d closest hits differ between the walks", name, differ);
    cr_expect_eq(occl_differ, 0, "%s: %d any-hit answers differ between the walks", name, occl_differ);
}

static void fast_walk_matches_plain(const char *path, int nrays)
{
    Scene s;
    PackedScene p;
    char err[4096];
    cr_assert_eq(pack_load_file(path, 0, 0, 0, &s, &p, err, sizeof err), 0, "%s", err);
    double sec = ref_trace_layout_seconds(&p);
    cr_log_info("%s: 4-wide layout built in %.1f ms", path, 1e3 * sec);
    cr_expect(sec >= 0.0 && ref_trace_layout_usable(&p), "%s: the 4-wide layout should be in use", path);
    walks_agree(&p, path, nrays, nrays / 4);
    pack_free(&p);
    scene_free(&s);
}

Test(ref_traversal, fast_walk_matches_plain_walk)
{
    fast_walk_matches_plain("scenes/cornell/scene.ini", 20000);
}

Test(ref_traversal, fast_walk_matches_plain_walk_on_shared_scenes)
{
    NEEDS_SCENE("scenes/cornell/spheres.ini");
    NEEDS_SCENE("scenes/sponza-dabrovic/scene.ini");
    NEEDS_SCENE("scenes/conference/scene.ini");
    fast_walk_matches_plain("scenes/cornell/spheres.ini", 20000);
    fast_walk_matches_plain("scenes/sponza-dabrovic/scene.ini", 20000);
    fast_walk_matches_plain("scenes/conference/scene.ini", 20000);
}


/* Leaves of 1 primitive, of up to 4 (one block of the layout) and of up to 11 (several blocks,
 * the lanes of a leaf's last block partly empty), and a single leaf (the root is a leaf). */
Test(ref_traversal, fast_walk_matches_plain_walk_on_leaf_sizes)
{
    static const struct {
        uint32_t n;
        int max_leaf;
    } cases[] = {{3000, 1}, {3000, 4}, {3000, 11}, {3, 4}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        Scene s;
        SceneMaterial m;
        PackedScene p;
        uint32_t st = 7;
        soup_pack(cases[c].n, 1.5f, &st, cases[c].max_leaf, &s, &m, &p);
        cr_expect(ref_trace_layout_usable(&p), "leaves of %d: the 4-wide layout should be in use", cases[c].max_leaf);
        uint32_t nodes = sm_u32(&p, sm_hdr(&p, SM_HDR_NODES)), big = 0;
        for (uint32_t n = 0; n < sm_u32(&p, sm_hdr(&p, SM_HDR_NNODES)); n++) {
            uint32_t info = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, n, SM_NODE_INFO));
            big += !(info & SM_NODE_INNER) && info > 4;
        }
        cr_expect_eq(big > 0, cases[c].max_leaf > 4, "leaves of up to %d: %u leaves of more than 4", cases[c].max_leaf, big);
        char name[64];
        snprintf(name, sizeof name, "soup of %u, leaves of %d", cases[c].n, cases[c].max_leaf);
        walks_agree(&p, name, 20000, cases[c].n > 100 ? 20000 / 4 : 20);
        pack_free(&p);
        free(s.pos);
        free(s.tri_material);
    }
}

/* The 4-wide walk skips the box tests of the binary levels it collapses, which gives the same
 * nodes only when every child box lies inside its parent's: a scene where one does not (the
 * image edited before the first query) must keep the binary walk, and the same hits. */
Test(ref_traversal, child_box_outside_parent_keeps_the_binary_walk)
{
    Scene s;
    SceneMaterial m;
    PackedScene p;
    uint32_t st = 7;
    soup_pack(3000, 1.5f, &st, 4, &s, &m, &p);
    uint32_t nodes = sm_u32(&p, sm_hdr(&p, SM_HDR_NODES));
    uint32_t first = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, 0, SM_NODE_FIRST));
    uint32_t info = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, first, SM_NODE_INFO));
    cr_assert(info & SM_NODE_INNER, "the root's left child should be an inner node");
    uint32_t g = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, first, SM_NODE_FIRST));
    /* grow grandchild g's box past its parent's on x by a unit: still a valid (larger) bound */
    uint32_t a = sm_rec(nodes, SM_NODE_WORDS, g, SM_NODE_BMAX);
    float x = sm_f32(&p, a) + 1.0f;
    memcpy(p.mem + (a - p.base), &x, 4);
    cr_expect_not(ref_trace_layout_usable(&p), "a child box outside its parent's should refuse the layout");
    walks_agree(&p, "soup with a grown box", 20000, 20000 / 4);
    pack_free(&p);
    free(s.pos);
    free(s.tri_material);
}
