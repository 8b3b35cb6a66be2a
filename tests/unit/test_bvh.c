/* tests/unit/test_bvh.c -- the binned SAH builder: invariants, degenerate inputs, determinism,
 * and that the checker catches broken trees. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/bvh.h"
#include "../../scenes/scene.h"
#include "../support/bvh_ref.h"
#include "../support/shared.h"

static uint32_t rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) / 16777216.0f;
}

/* n random small triangles' boxes in the unit cube. */
static void random_boxes(uint32_t n, float **lo, float **hi)
{
    *lo = malloc(sizeof(float) * 3 * n);
    *hi = malloc(sizeof(float) * 3 * n);
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            float c = frand(), e = 0.01f * frand();
            (*lo)[3 * i + k] = c - e;
            (*hi)[3 * i + k] = c + e;
        }
    }
}

/* SAH cost (same formula as bvh_sah_cost) of a tree that halves every node at the object
 * median of its longest centroid axis: the classic baseline a SAH build should beat. */
static const float *g_cent;
static int g_axis;
static int cmp_cent(const void *a, const void *b)
{
    float x = g_cent[3 * *(const uint32_t *)a + g_axis], y = g_cent[3 * *(const uint32_t *)b + g_axis];
    return x < y ? -1 : x > y;
}

static double area_of(const float *l, const float *h)
{
    double d0 = h[0] - l[0], d1 = h[1] - l[1], d2 = h[2] - l[2];
    return 2.0 * (d0 * d1 + d1 * d2 + d2 * d0);
}

static double median_rec(uint32_t *idx, uint32_t n, const float *lo, const float *hi,
                         const float *cent, const BvhParams *p, double root_area)
{
    float bl[3] = {INFINITY, INFINITY, INFINITY}, bh[3] = {-INFINITY, -INFINITY, -INFINITY};
    float cl[3] = {INFINITY, INFINITY, INFINITY}, ch[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            bl[k] = fminf(bl[k], lo[3 * idx[i] + k]);
            bh[k] = fmaxf(bh[k], hi[3 * idx[i] + k]);
            cl[k] = fminf(cl[k], cent[3 * idx[i] + k]);
            ch[k] = fmaxf(ch[k], cent[3 * idx[i] + k]);
        }
    double a = area_of(bl, bh) / root_area;
    if (n <= (uint32_t)p->max_leaf_size)
        return a * p->cost_intersect * n;
    int axis = 0;
    for (int k = 1; k < 3; k++)
        if (ch[k] - cl[k] > ch[axis] - cl[axis])
            axis = k;
    g_cent = cent;
    g_axis = axis;
    qsort(idx, n, sizeof *idx, cmp_cent);
    return a * p->cost_traversal + median_rec(idx, n / 2, lo, hi, cent, p, root_area) +
           median_rec(idx + n / 2, n - n / 2, lo, hi, cent, p, root_area);
}

static double median_tree_cost(const float *lo, const float *hi, uint32_t n, const BvhParams *p)
{
    uint32_t *idx = malloc(sizeof *idx * n);
    float *cent = malloc(sizeof(float) * 3 * n);
    float bl[3] = {INFINITY, INFINITY, INFINITY}, bh[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++) {
        idx[i] = i;
        for (int k = 0; k < 3; k++) {
            cent[3 * i + k] = 0.5f * (lo[3 * i + k] + hi[3 * i + k]);
            bl[k] = fminf(bl[k], lo[3 * i + k]);
            bh[k] = fmaxf(bh[k], hi[3 * i + k]);
        }
    }
    double c = median_rec(idx, n, lo, hi, cent, p, area_of(bl, bh));
    free(idx);
    free(cent);
    return c;
}

Test(bvh_build, random_boxes_keep_invariants)
{
    BvhParams p;
    bvh_default_params(&p);
    float *lo, *hi;
    uint32_t n = 20000;
    random_boxes(n, &lo, &hi);
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, n, &b, err, sizeof err), 0, "%s", err);
    cr_assert_eq(bvh_check(&b, lo, hi, err, sizeof err), 0, "%s", err);
    cr_expect_eq(b.nnodes, 2 * b.nleaves - 1);
    for (uint32_t i = 0; i < b.nnodes; i++)
        if (b.nodes[i].count > 0)
            cr_expect_leq(b.nodes[i].count, (uint32_t)p.max_leaf_size);
    /* The SAH tree must cost less than an object-median tree over the same boxes. */
    double median = median_tree_cost(lo, hi, n, &p);
    cr_expect_lt(b.sah_cost, median, "sah %g, median split %g", b.sah_cost, median);
    cr_log_info("SAH cost %.2f, object-median tree %.2f", b.sah_cost, median);
    cr_expect_float_eq(b.sah_cost, bvh_sah_cost(&b, &p), 1e-9);
    bvh_free(&b);
    free(lo);
    free(hi);
}

Test(bvh_build, identical_centroids_still_respect_leaf_size)
{
    BvhParams p;
    bvh_default_params(&p);
    uint32_t n = 1000;
    float *lo = malloc(sizeof(float) * 3 * n), *hi = malloc(sizeof(float) * 3 * n);
    for (uint32_t i = 0; i < 3 * n; i++) {
        lo[i] = -1.0f;
        hi[i] = 1.0f;
    }
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, n, &b, err, sizeof err), 0, "%s", err);
    cr_assert_eq(bvh_check(&b, lo, hi, err, sizeof err), 0, "%s", err);
    for (uint32_t i = 0; i < b.nnodes; i++)
        if (b.nodes[i].count > 0)
            cr_expect_leq(b.nodes[i].count, (uint32_t)p.max_leaf_size);
    bvh_free(&b);
    free(lo);
    free(hi);
}

Test(bvh_build, flat_and_single_primitive)
{
    BvhParams p;
    bvh_default_params(&p);
    /* Zero-thickness boxes (an axis-aligned plane of triangles) and a single primitive. */
    uint32_t n = 64;
    float lo[3 * 64], hi[3 * 64];
    for (uint32_t i = 0; i < n; i++) {
        lo[3 * i] = (float)(i % 8);
        hi[3 * i] = (float)(i % 8) + 1.0f;
        lo[3 * i + 1] = hi[3 * i + 1] = 0.0f;
        lo[3 * i + 2] = (float)(i / 8);
        hi[3 * i + 2] = (float)(i / 8) + 1.0f;
    }
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, n, &b, err, sizeof err), 0, "%s", err);
    cr_assert_eq(bvh_check(&b, lo, hi, err, sizeof err), 0, "%s", err);
    cr_expect_gt(b.nleaves, 1u);
    bvh_free(&b);
    cr_assert_eq(bvh_build(&p, lo, hi, 1, &b, err, sizeof err), 0, "%s", err);
    cr_expect_eq(b.nnodes, 1u);
    cr_expect_eq(b.nodes[0].count, 1u);
    bvh_free(&b);
}

Test(bvh_build, deterministic)
{
    BvhParams p;
    bvh_default_params(&p);
    float *lo, *hi;
    random_boxes(5000, &lo, &hi);
    Bvh a, b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, 5000, &a, err, sizeof err), 0);
    cr_assert_eq(bvh_build(&p, lo, hi, 5000, &b, err, sizeof err), 0);
    cr_assert_eq(a.nnodes, b.nnodes);
    cr_expect_eq(memcmp(a.nodes, b.nodes, sizeof(BvhNode) * a.nnodes), 0);
    cr_expect_eq(memcmp(a.prim_index, b.prim_index, sizeof(uint32_t) * a.nprims), 0);
    bvh_free(&a);
    bvh_free(&b);
    free(lo);
    free(hi);
}

/* Boxes of half-size 1e30 (a sphere of that radius, which the scene loader refuses today) have
 * surface areas beyond single precision; the SAH cost must still be a finite positive number (it
 * was NaN, printed "-nan" in report.txt and null in report.json). */
Test(bvh_build, sah_cost_of_boxes_whose_areas_overflow_is_a_number)
{
    const float lo[6] = {-1e30f, -1e30f, -1e30f, -1.0f, -1.0f, -3.0f};
    const float hi[6] = {1e30f, 1e30f, 1e30f, 1.0f, 1.0f, -1.0f};
    cr_assert(isinf((hi[0] - lo[0]) * (hi[1] - lo[1])), "the case must overflow a float area");
    BvhParams p;
    bvh_default_params(&p);
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, 2, &b, err, sizeof err), 0, "%s", err);
    double c = bvh_sah_cost(&b, &p);
    cr_expect(isfinite(c) && c > 0.0, "sah_cost %g", c);
    bvh_free(&b);
}

Test(bvh_errors, nan_box_rejected)
{
    BvhParams p;
    bvh_default_params(&p);
    float lo[6] = {0, 0, 0, 0, NAN, 0}, hi[6] = {1, 1, 1, 1, 1, 1};
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, 2, &b, err, sizeof err), -1);
    cr_expect_str_eq(err, "bvh: primitive 1 has a bad box on axis 1: [nan, 1]");
    p.bins = 1;
    cr_assert_eq(bvh_build(&p, lo, hi, 1, &b, err, sizeof err), -1);
    cr_expect(strstr(err, "bad parameters") != NULL, "%s", err);
}

/* check_boxes tests four values at a time, then the rest one by one: a bad value (NaN, either
 * infinity, an inverted pair) at every coordinate of 7 primitives, in lo and in hi, is rejected
 * and named. */
Test(bvh_errors, every_bad_coordinate_is_named)
{
    BvhParams p;
    bvh_default_params(&p);
    const float bad[] = {NAN, INFINITY, -INFINITY};
    enum { N = 7 };
    for (int t = 0; t < 3 * N; t++) {
        for (int v = 0; v < 4; v++) {
            for (int side = 0; side < 2; side++) {
                float lo[3 * N], hi[3 * N];
                for (int u = 0; u < 3 * N; u++) {
                    lo[u] = (float)u;
                    hi[u] = (float)u + 1.0f;
                }
                if (v < 3)
                    (side ? hi : lo)[t] = bad[v];
                else if (side)
                    hi[t] = lo[t] - 1.0f; /* inverted */
                else
                    lo[t] = hi[t] + 1.0f;
                Bvh b;
                char err[256], want[64];
                cr_assert_eq(bvh_build(&p, lo, hi, N, &b, err, sizeof err), -1, "value %d at %d", v, t);
                snprintf(want, sizeof want, "bvh: primitive %d has a bad box on axis %d:", t / 3, t % 3);
                cr_expect(strncmp(err, want, strlen(want)) == 0, "%s (wanted %s)", err, want);
            }
        }
    }
}

Test(bvh_errors, checker_catches_broken_trees)
{
    BvhParams p;
    bvh_default_params(&p);
    float *lo, *hi;
    random_boxes(1000, &lo, &hi);
    Bvh b;
    char err[256];
    cr_assert_eq(bvh_build(&p, lo, hi, 1000, &b, err, sizeof err), 0);
    /* A primitive listed twice in one leaf (and so another missing). */
    uint32_t leaf = 0;
    while (b.nodes[leaf].count < 2)
        leaf++;
    uint32_t f = b.nodes[leaf].first, saved = b.prim_index[f + 1];
    b.prim_index[f + 1] = b.prim_index[f];
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "listed twice") != NULL, "%s", err);
    b.prim_index[f + 1] = saved;
    /* A primitive outside its leaf's box. */
    uint32_t pi = b.prim_index[f];
    float oldlo = lo[3 * pi];
    lo[3 * pi] = b.nodes[leaf].bmin[0] - 1.0f;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "sticks out of leaf") != NULL, "%s", err);
    lo[3 * pi] = oldlo;
    /* A child that sticks out of its parent. */
    uint32_t c = b.nodes[0].first;
    float old = b.nodes[c].bmax[0];
    b.nodes[c].bmax[0] = b.nodes[0].bmax[0] + 1.0f;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "sticks out") != NULL, "%s", err);
    b.nodes[c].bmax[0] = old;
    /* The root's children index pointing at another inner node's children: those are reached
     * twice, the root's own unreachable. */
    uint32_t x = 1;
    while (b.nodes[x].count > 0)
        x++;
    b.nodes[0].first = b.nodes[x].first;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "reached twice") != NULL, "%s", err);
    b.nodes[0].first = c;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), 0, "%s", err);
    /* A NaN in a node's box, and an inverted one. */
    float saved_lo = b.nodes[c].bmin[2];
    b.nodes[c].bmin[2] = NAN;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "bad box on axis 2") != NULL, "%s", err);
    b.nodes[c].bmin[2] = b.nodes[c].bmax[2] + 1.0f;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "bad box on axis 2") != NULL, "%s", err);
    b.nodes[c].bmin[2] = saved_lo;
    /* A leaf's count past the primitives; a node no node points to (a copy of a leaf, past the
     * last: its primitives are listed twice). */
    uint32_t saved_count = b.nodes[leaf].count;
    b.nodes[leaf].count = b.nprims;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "outside") != NULL, "%s", err);
    b.nodes[leaf].count = saved_count;
    cr_assert_lt(b.nnodes, 2 * b.nprims - 1, "no room for one more node");
    b.nodes[b.nnodes++] = b.nodes[leaf];
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), -1);
    cr_expect(strstr(err, "listed twice") != NULL, "%s", err);
    b.nnodes--;
    cr_expect_eq(bvh_check(&b, lo, hi, err, sizeof err), 0, "%s", err);
    bvh_free(&b);
    free(lo);
    free(hi);
}

/* Boxes for the reference comparison, family f: 0 unit-cube boxes; 1 a coarse lattice where
 * coordinates tie and zeros come with either sign; 2 all the same box (the halving path); 3
 * boxes near FLT_MAX (infinite centroids and extents); 4 denormal extents. */
static void family_boxes(int f, uint32_t n, float *lo, float *hi)
{
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            float a, b;
            if (f == 0) {
                float c = frand(), e = 0.01f * frand();
                a = c - e;
                b = c + e;
            } else if (f == 1) {
                a = (float)((int)(frand() * 9.0f) - 4) * 0.5f;
                b = a + (float)(int)(frand() * 3.0f) * 0.5f;
                if (a == 0.0f && frand() < 0.5f)
                    a = -0.0f;
                if (b == 0.0f && frand() < 0.5f)
                    b = -0.0f;
            } else if (f == 2) {
                a = -1.0f;
                b = 1.0f;
            } else if (f == 3) {
                a = (frand() < 0.5f ? -3.0e38f : 1.0e38f) * frand();
                b = a + 2.0e38f * frand();
            } else {
                a = 1.0e-40f * (float)(int)(frand() * 4.0f);
                b = a + 1.0e-40f * (float)(int)(frand() * 2.0f);
            }
            lo[3 * i + k] = a;
            hi[3 * i + k] = b;
        }
    }
}

/* The fast builder's trees are the plain builder's, bit for bit: every node's box (zeros' signs
 * included), the primitive order, depth and cost, over degenerate inputs and several parameter
 * sets. */
Test(bvh_build, matches_the_plain_reference_bit_for_bit)
{
    static const BvhParams params[] = {{4, 16, 1.0f, 1.0f}, {1, 2, 1.0f, 1.0f}, {8, 256, 0.5f, 1.0f},
                                       {2, 7, 1.0f, 2.0f}, {16, 3, 0.0f, 1.0f}};
    uint32_t n = 3000;
    float *lo = malloc(sizeof(float) * 3 * n), *hi = malloc(sizeof(float) * 3 * n);
    char err[256];
    for (int f = 0; f < 5; f++) {
        family_boxes(f, n, lo, hi);
        for (size_t q = 0; q < sizeof params / sizeof params[0]; q++) {
            Bvh fast, ref;
            cr_assert_eq(bvh_build(&params[q], lo, hi, n, &fast, err, sizeof err), 0, "%s", err);
            cr_assert_eq(bvh_ref_build(&params[q], lo, hi, n, &ref), 0);
            cr_expect_eq(bvh_check(&fast, lo, hi, err, sizeof err), 0, "family %d: %s", f, err);
            cr_assert_eq(fast.nnodes, ref.nnodes, "family %d, parameters %zu", f, q);
            cr_expect_eq(memcmp(fast.nodes, ref.nodes, sizeof(BvhNode) * ref.nnodes), 0,
                         "family %d, parameters %zu: nodes differ", f, q);
            cr_expect_eq(memcmp(fast.prim_index, ref.prim_index, sizeof(uint32_t) * n), 0,
                         "family %d, parameters %zu: primitive order differs", f, q);
            cr_expect_eq(fast.depth, ref.depth);
            cr_expect_eq(fast.nleaves, ref.nleaves);
            cr_expect(fast.sah_cost == ref.sah_cost, "family %d, parameters %zu: %.17g != %.17g", f, q,
                      fast.sah_cost, ref.sah_cost);
            bvh_free(&fast);
            bvh_free(&ref);
        }
    }
    free(lo);
    free(hi);
}

/* Small inputs, 2 to 20 primitives: the builder's own paths for nodes of two primitives and of up
 * to eight (no bin arrays) decide every split here, against the plain reference, on every box
 * family and parameter set, ties and zeros' signs included. */
Test(bvh_build, small_nodes_match_the_plain_reference)
{
    static const BvhParams params[] = {{4, 16, 1.0f, 1.0f}, {1, 2, 1.0f, 1.0f}, {8, 256, 0.5f, 1.0f},
                                       {2, 7, 1.0f, 2.0f}, {1, 16, 0.0f, 1.0f}, {4, 16, 4.0f, 1.0f}};
    float lo[3 * 20], hi[3 * 20];
    char err[256];
    for (int f = 0; f < 5; f++) {
        for (uint32_t n = 2; n <= 20; n++) {
            for (int rep = 0; rep < 20; rep++) {
                family_boxes(f, n, lo, hi);
                for (size_t q = 0; q < sizeof params / sizeof params[0]; q++) {
                    Bvh fast, ref;
                    cr_assert_eq(bvh_build(&params[q], lo, hi, n, &fast, err, sizeof err), 0, "%s", err);
                    cr_assert_eq(bvh_ref_build(&params[q], lo, hi, n, &ref), 0);
                    cr_assert_eq(fast.nnodes, ref.nnodes, "family %d, n %u, parameters %zu", f, n, q);
                    cr_assert_eq(memcmp(fast.nodes, ref.nodes, sizeof(BvhNode) * ref.nnodes), 0,
                                 "family %d, n %u, parameters %zu: nodes differ", f, n, q);
                    cr_assert_eq(memcmp(fast.prim_index, ref.prim_index, sizeof(uint32_t) * n), 0,
                                 "family %d, n %u, parameters %zu: primitive order differs", f, n, q);
                    cr_assert(fast.sah_cost == ref.sah_cost);
                    bvh_free(&fast);
                    bvh_free(&ref);
                }
            }
        }
    }
}

/* The tie rule the trees were first built with: a box keeps the zero it holds when the other
 * sign comes later (the first build's fminf(new, held) returned held on a tie). The root box of
 * +0 then -0 keeps +0; of -0 then +0 keeps -0. */
Test(bvh_build, a_box_keeps_the_first_zero_on_a_tie)
{
    BvhParams p;
    bvh_default_params(&p);
    for (int first_negative = 0; first_negative < 2; first_negative++) {
        float z0 = first_negative ? -0.0f : 0.0f, z1 = first_negative ? 0.0f : -0.0f;
        float lo[6] = {z0, 0, 0, z1, 1, 0}, hi[6] = {z0, 1, 1, z1, 2, 1};
        Bvh b;
        char err[256];
        cr_assert_eq(bvh_build(&p, lo, hi, 2, &b, err, sizeof err), 0, "%s", err);
        cr_expect_eq(signbit(b.nodes[0].bmin[0]) != 0, first_negative, "root bmin.x %g", (double)b.nodes[0].bmin[0]);
        cr_expect_eq(signbit(b.nodes[0].bmax[0]) != 0, first_negative, "root bmax.x %g", (double)b.nodes[0].bmax[0]);
        bvh_free(&b);
    }
}

/* The fast builder against the plain one on real meshes (a scan and a modelled building, large
 * enough for the build's arrays to go on huge pages), over their triangles' boxes. */
static void compare_on_scene(const char *path, const BvhParams *p)
{
    NEEDS_SCENE(path);
    Scene sc;
    char err[1024];
    cr_assert_eq(scene_load(path, &sc, err, sizeof err), 0, "%s: %s", path, err);
    uint32_t n = sc.ntris;
    float *lo = malloc(sizeof(float) * 3 * n), *hi = malloc(sizeof(float) * 3 * n);
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            const float *v = &sc.pos[9 * i + k];
            lo[3 * i + k] = bvh_ref_min(bvh_ref_min(v[0], v[3]), v[6]);
            hi[3 * i + k] = bvh_ref_max(bvh_ref_max(v[0], v[3]), v[6]);
        }
    }
    Bvh fast, ref;
    cr_assert_eq(bvh_build(p, lo, hi, n, &fast, err, sizeof err), 0, "%s", err);
    cr_assert_eq(bvh_ref_build(p, lo, hi, n, &ref), 0);
    cr_assert_eq(fast.nnodes, ref.nnodes, "%s", path);
    cr_expect_eq(memcmp(fast.nodes, ref.nodes, sizeof(BvhNode) * ref.nnodes), 0, "%s: nodes differ", path);
    cr_expect_eq(memcmp(fast.prim_index, ref.prim_index, sizeof(uint32_t) * n), 0, "%s: order differs", path);
    cr_expect(fast.sah_cost == ref.sah_cost, "%s", path);
    bvh_free(&fast);
    bvh_free(&ref);
    free(lo);
    free(hi);
    scene_free(&sc);
}

Test(bvh_build, matches_the_plain_reference_on_real_meshes)
{
    BvhParams p;
    bvh_default_params(&p);
    compare_on_scene("scenes/stanford-bunny/scene.ini", &p);
    compare_on_scene("scenes/sponza-dabrovic/scene.ini", &p);
    p.bins = 256;
    p.max_leaf_size = 1;
    compare_on_scene("scenes/stanford-bunny/scene.ini", &p);
}
