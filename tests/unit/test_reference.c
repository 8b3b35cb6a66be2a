/* tests/unit/test_reference.c -- the golden model on scenes built in the test: an analytic
 * direct-lighting value (path tracer and Phong workload), determinism across host threads and
 * reruns, no NaN/Inf, and Monte Carlo convergence at the 1/sqrt(spp) rate; on the in-repo Cornell
 * box, the per-(tile, pass) unit counts and their SIMD-step counts. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/img.h"
#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/reference.h"

typedef struct Builder {
    float pos[9 * 64];
    uint32_t mat[64];
    uint32_t emissive[64];
    uint32_t n, nem;
    SceneMaterial mats[4];
} Builder;

/* Quad corner c, edges a and b, as two triangles. */
static void quad(Builder *b, const float *c, const float *ea, const float *eb, uint32_t m, int emits)
{
    float p[4][3];
    for (int k = 0; k < 3; k++) {
        p[0][k] = c[k];
        p[1][k] = c[k] + ea[k];
        p[2][k] = c[k] + ea[k] + eb[k];
        p[3][k] = c[k] + eb[k];
    }
    int idx[6] = {0, 1, 2, 0, 2, 3};
    for (int t = 0; t < 2; t++) {
        for (int v = 0; v < 3; v++)
            memcpy(&b->pos[9 * b->n + 3 * v], p[idx[3 * t + v]], sizeof(float) * 3);
        if (emits)
            b->emissive[b->nem++] = b->n;
        b->mat[b->n++] = m;
    }
}

static void to_scene(Builder *b, Scene *s, int w, int h, int spp, int depth)
{
    memset(s, 0, sizeof *s);
    s->ntris = b->n;
    s->pos = b->pos;
    s->tri_material = b->mat;
    s->materials = b->mats;
    s->nmaterials = 4;
    s->emissive_tris = b->emissive;
    s->nemissive = b->nem;
    s->render = (SceneRender){w, h, spp, depth, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = -2.0f;
        s->bounds_max[k] = 2.0f;
    }
}

static void lambert(SceneMaterial *m, float albedo, float emission)
{
    memset(m, 0, sizeof *m);
    m->kind = SCENE_MAT_LAMBERT;
    m->base_color[0] = m->base_color[1] = m->base_color[2] = albedo;
    m->emission[0] = m->emission[1] = m->emission[2] = emission;
    m->base_texture = -1;
    m->ior = 1.5f;
}

/* A floor (y = 0, 4 x 4, albedo 0.5) under a small square light (side 0.1 at y = 1, radiance
 * 100), seen from straight above. */
static void floor_scene(Builder *b, Scene *s, int spp, int depth)
{
    memset(b, 0, sizeof *b);
    lambert(&b->mats[0], 0.5f, 0.0f);
    lambert(&b->mats[1], 0.0f, 100.0f);
    lambert(&b->mats[2], 0.5f, 0.0f);
    lambert(&b->mats[3], 0.5f, 0.0f);
    float c0[3] = {-2, 0, -2}, ea[3] = {0, 0, 4}, eb[3] = {4, 0, 0};
    quad(b, c0, ea, eb, 0, 0);
    float lc[3] = {-0.05f, 1.0f, -0.05f}, la[3] = {0.1f, 0, 0}, lb[3] = {0, 0, 0.1f};
    quad(b, lc, la, lb, 1, 1);
    to_scene(b, s, 16, 16, spp, depth);
    s->camera = (SceneCamera){{0, 0.5f, 0}, {0, 0, 0}, {0, 0, -1}, 10.0f, 0, 0, SCENE_CAMERA_FILE};
}

static float *render_rp(const Scene *s, const RefParams *rp, RefStats *st)
{
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[256];
    cr_assert_eq(pack_scene(s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    float *rgb = calloc(3 * (size_t)s->render.width * s->render.height, sizeof(float));
    cr_assert_eq(ref_render(&p, rp, rgb, st, err, sizeof err), 0, "%s", err);
    pack_free(&p);
    return rgb;
}

static float *render(const Scene *s, uint32_t seed, int threads, RefStats *st)
{
    RefParams rp = {.tile = 32, .seed = seed, .threads = threads};
    return render_rp(s, &rp, st);
}

Test(reference, direct_light_matches_the_analytic_value)
{
    Builder b;
    Scene s;
    floor_scene(&b, &s, 256, 0);
    RefStats st;
    float *rgb = render(&s, 1, 2, &st);
    /* The camera looks straight down from y = 0.5 with a 10 degree field: every pixel sees the
     * floor within 0.05 of the point under the light, where E = L A cos cos / d^2 with
     * A = 0.01, d ~ 1: radiance = albedo / pi * E = 0.5 / pi * 100 * 0.01 = 0.159 (the finite
     * light and the 0.05 offset lower it by under 1%). The light quad itself is hidden behind
     * the camera. */
    double sum = 0.0;
    for (int i = 0; i < 16 * 16; i++)
        sum += rgb[3 * i];
    double mean = sum / 256.0, expect = 0.5 / M_PI * 100.0 * 0.01;
    cr_log_info("direct light: mean %.5f, analytic %.5f", mean, expect);
    cr_expect(fabs(mean - expect) < 0.02 * expect, "mean %.5f vs analytic %.5f", mean, expect);
    cr_expect_eq(st.rays[REF_RAY_CAMERA], 256u * 256u);
    cr_expect_eq(st.rays[REF_RAY_SHADOW], 256u * 256u, "max depth 0: every camera hit sends a shadow ray");
    cr_expect_eq(st.rays[REF_RAY_INDIRECT], 0u);
    free(rgb);
}

/* A closed box with an emissive ceiling panel and a sphere-free interior: full paths. */
static void box_scene(Builder *b, Scene *s, int spp)
{
    memset(b, 0, sizeof *b);
    lambert(&b->mats[0], 0.7f, 0.0f);
    lambert(&b->mats[1], 0.0f, 10.0f);
    lambert(&b->mats[2], 0.6f, 0.0f);
    b->mats[2].base_color[1] = 0.1f;
    lambert(&b->mats[3], 0.6f, 0.0f);
    b->mats[3].kind = SCENE_MAT_GLOSSY;
    b->mats[3].roughness = 0.3f;
    b->mats[3].metallic = 0.5f;
    float X[3] = {2, 0, 0}, Y[3] = {0, 2, 0}, Z[3] = {0, 0, 2};
    float o[3] = {-1, 0, -1};
    float top[3] = {-1, 2, -1}, right[3] = {1, 0, -1}, back[3] = {-1, 0, -1}, front[3] = {-1, 0, 1};
    quad(b, o, Z, X, 3, 0);      /* floor (glossy) */
    quad(b, top, X, Z, 0, 0);    /* ceiling */
    quad(b, o, Y, Z, 2, 0);      /* left wall (red) */
    quad(b, right, Z, Y, 0, 0);  /* right wall */
    quad(b, back, X, Y, 0, 0);   /* back wall */
    quad(b, front, Y, X, 0, 0);  /* front wall (behind the camera) */
    float lc[3] = {-0.3f, 1.99f, -0.3f}, la[3] = {0.6f, 0, 0}, lb[3] = {0, 0, 0.6f};
    quad(b, lc, la, lb, 1, 1);
    to_scene(b, s, 24, 24, spp, 3);
    s->camera = (SceneCamera){{0, 1, 0.9f}, {0, 1, -1}, {0, 1, 0}, 70.0f, 0, 0, SCENE_CAMERA_FILE};
}

/* The Phong workload under the same light (docs/golden-model.md): ambient 0.05 x albedo, plus for
 * each of the light's two triangles (area 0.005, centroid ~1 above) (albedo cos + ks cos_r^n) x
 * L A cos_l / d^2, with ks = 0.04 and, at roughness 1, shininess max(2 / 1 - 2, 1) = 1:
 * 0.025 + (0.5 + 0.04) x 100 x 0.01 = 0.565 (every cosine within 0.3% of 1). One shadow ray per
 * light per hit; a bounce (here: straight up, into the light for the middle pixels) only adds. */
Test(reference, phong_workload_matches_the_analytic_value)
{
    Builder b;
    Scene s;
    floor_scene(&b, &s, 4, 0);
    b.mats[0].roughness = 1.0f;
    RefStats st;
    RefParams rp = {.tile = 32, .seed = 1, .threads = 2, .workload = REF_WORKLOAD_PHONG, .bounces = 0};
    float *rgb = render_rp(&s, &rp, &st);
    double sum = 0.0;
    for (int i = 0; i < 16 * 16; i++)
        sum += rgb[3 * i];
    double mean = sum / 256.0, expect = 0.05 * 0.5 + (0.5 + 0.04) * 100.0 * 0.01;
    cr_log_info("phong: mean %.5f, analytic %.5f", mean, expect);
    cr_expect(fabs(mean - expect) < 0.01 * expect, "mean %.5f vs analytic %.5f", mean, expect);
    cr_expect_eq(st.rays[REF_RAY_CAMERA], 4u * 256u);
    cr_expect_eq(st.rays[REF_RAY_SHADOW], 2u * 4u * 256u, "one shadow ray per light per hit");
    cr_expect_eq(st.rays[REF_RAY_INDIRECT], 0u);
    cr_expect_eq(st.generations, 1u);
    rp.bounces = 2;
    RefStats st2;
    float *rgb2 = render_rp(&s, &rp, &st2);
    cr_expect_eq(st2.rays[REF_RAY_INDIRECT], 4u * 256u,
                 "every camera hit bounces once (then misses or meets the light)");
    cr_expect_eq(st2.rays[REF_RAY_SHADOW], st.rays[REF_RAY_SHADOW]);
    int brighter = 0;
    for (int i = 0; i < 3 * 16 * 16; i++) {
        /* the same terms in the same order, then more non-negative ones */
        cr_expect(rgb2[i] >= rgb[i], "value %d: %g with bounces below %g without", i, rgb2[i], rgb[i]);
        brighter += rgb2[i] > rgb[i];
    }
    cr_expect(brighter > 0, "no pixel sees the light in the mirror");
    free(rgb);
    free(rgb2);
    /* parameters the golden model does not render */
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    float *img = calloc(3 * 16 * 16, sizeof(float));
    RefParams bad[] = {{.tile = 32, .workload = (RefWorkload)7},
                       {.tile = 32, .workload = REF_WORKLOAD_PHONG, .bounces = -1}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        cr_expect_neq(ref_render(&p, &bad[k], img, NULL, err, sizeof err), 0);
        cr_expect(strstr(err, "golden model") != NULL, "%s", err);
    }
    free(img);
    pack_free(&p);
}

Test(reference, identical_bits_for_any_thread_count_and_rerun)
{
    Builder b;
    Scene s;
    box_scene(&b, &s, 8);
    float *a = render(&s, 7, 1, NULL), *c = render(&s, 7, 2, NULL), *d = render(&s, 7, 2, NULL);
    size_t bytes = sizeof(float) * 3 * 24 * 24;
    cr_expect_eq(memcmp(a, c, bytes), 0, "1 thread vs 2 threads");
    cr_expect_eq(memcmp(c, d, bytes), 0, "rerun");
    long bad = 0;
    double sum = 0.0;
    for (size_t i = 0; i < 3 * 24 * 24; i++) {
        bad += !isfinite(a[i]);
        sum += a[i];
    }
    cr_expect_eq(bad, 0, "%ld NaN/Inf values", bad);
    cr_expect_gt(sum, 0.0, "the box is lit");
    free(a);
    free(c);
    free(d);
}

Test(reference, rmse_falls_as_one_over_sqrt_spp, .timeout = 60)
{
    Builder b;
    Scene s;
    box_scene(&b, &s, 1024);
    float *ref = render(&s, 1000, 2, NULL);
    int spps[3] = {4, 16, 64};
    double lx[3], ly[3];
    for (int i = 0; i < 3; i++) {
        box_scene(&b, &s, spps[i]);
        float *img = render(&s, 1, 2, NULL);
        ImgCompare cmp;
        img_compare(img, ref, 24, 24, &cmp);
        lx[i] = log((double)spps[i]);
        ly[i] = log(cmp.rmse);
        cr_log_info("spp %d: RMSE %.5f mean %.4f ref mean %.4f max diff %.3f", spps[i], cmp.rmse, cmp.mean_a, cmp.mean_b, cmp.max_abs);
        free(img);
    }
    /* Least-squares slope of log RMSE against log spp; the reference's own noise (1024 spp)
     * flattens it slightly. */
    double mx = (lx[0] + lx[1] + lx[2]) / 3, my = (ly[0] + ly[1] + ly[2]) / 3, num = 0, den = 0;
    for (int i = 0; i < 3; i++) {
        num += (lx[i] - mx) * (ly[i] - my);
        den += (lx[i] - mx) * (lx[i] - mx);
    }
    double slope = num / den;
    cr_log_info("convergence slope %.3f (ideal -0.5)", slope);
    cr_expect(slope < -0.4 && slope > -0.6, "slope %.3f", slope);
    free(ref);
}

/* v's units (tiles x spp) are u's for the passes in the mask, and zero for the others. */
static void expect_passes(const RefUnitStats *v, const RefUnitStats *u, int tiles, int spp, unsigned mask,
                          const char *what)
{
    RefUnitStats zero;
    memset(&zero, 0, sizeof zero);
    for (int t = 0; t < tiles; t++)
        for (int q = 0; q < spp; q++) {
            const RefUnitStats *want = mask >> q & 1u ? &u[t * spp + q] : &zero;
            cr_expect_eq(memcmp(&v[t * spp + q], want, sizeof zero), 0, "%s: tile %d pass %d", what, t, q);
        }
}

/* Sampled mode's auxiliary variables: every (tile, pass) unit's counts add up to the frame's, and
 * a unit rendered alone (a pass range, or every second pass) counts exactly what it counted in the
 * whole frame. */
Test(reference, unit_counts_add_up_and_a_pass_alone_counts_the_same)
{
    Scene s;
    PackedScene p;
    char err[4096];
    enum { W = 80, H = 48, SPP = 3, T = 32, TILES = 6, UNITS = TILES * SPP }; /* 3 x 2 tiles, partial */
    cr_assert_eq(pack_load_file("scenes/cornell/scene.ini", W, H, SPP, &s, &p, err, sizeof err), 0, "%s", err);
    RefUnitStats *u = calloc(UNITS, sizeof *u), *v = calloc(UNITS, sizeof *v);
    float *rgb = calloc(3 * W * H, sizeof *rgb), *rgb1 = calloc(3 * W * H, sizeof *rgb1);
    cr_assert(u && v && rgb && rgb1);
    RefParams rp = {.tile = T, .seed = 5, .threads = 2, .units = u};
    RefStats st;
    cr_assert_eq(ref_render(&p, &rp, rgb, &st, err, sizeof err), 0, "%s", err);
    RefUnitStats sum;
    memset(&sum, 0, sizeof sum);
    for (int i = 0; i < UNITS; i++) {
        for (int k = 0; k < REF_RAY_KINDS; k++)
            sum.rays[k] += u[i].rays[k];
        sum.nodes_visited += u[i].nodes_visited;
        sum.prims_tested += u[i].prims_tested;
        sum.hits += u[i].hits;
        int t = i / SPP, tw = t % 3 == 2 ? W - 2 * T : T, th = t / 3 == 1 ? H - T : T;
        cr_expect_eq(u[i].rays[REF_RAY_CAMERA], (uint64_t)(tw * th), "unit %d: one camera ray per pixel", i);
        cr_expect_geq(u[i].generations, 1u, "unit %d", i);
    }
    for (int k = 0; k < REF_RAY_KINDS; k++)
        cr_expect_eq(sum.rays[k], st.rays[k], "ray kind %d", k);
    cr_expect_eq(sum.nodes_visited, st.nodes_visited);
    cr_expect_eq(sum.prims_tested, st.prims_tested);
    cr_expect_gt(sum.hits, 0u);
    cr_expect_leq(sum.hits, st.rays[REF_RAY_CAMERA] + st.rays[REF_RAY_INDIRECT]);
    /* pass 1 alone, on one thread */
    RefParams one = rp;
    one.pass0 = 1;
    one.pass1 = 2;
    one.threads = 1;
    one.units = v;
    cr_assert_eq(ref_render(&p, &one, rgb1, NULL, err, sizeof err), 0, "%s", err);
    expect_passes(v, u, TILES, SPP, 1u << 1, "pass 1 alone");
    /* every second pass (0 and 2), on two threads: those count what they counted, the others nothing */
    RefParams step = rp;
    step.pass_step = 2;
    memset(v, 0, UNITS * sizeof *v);
    step.units = v;
    cr_assert_eq(ref_render(&p, &step, rgb1, NULL, err, sizeof err), 0, "%s", err);
    expect_passes(v, u, TILES, SPP, 1u << 0 | 1u << 2, "every second pass");
    /* passes outside the frame */
    static const uint32_t bad[][2] = {{2, 2}, {0, 4}, {3, 1}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        RefParams r = rp;
        r.pass0 = bad[i][0];
        r.pass1 = bad[i][1];
        r.units = NULL;
        err[0] = 0;
        cr_expect_eq(ref_render(&p, &r, rgb1, NULL, err, sizeof err), -1, "[%u, %u)", bad[i][0], bad[i][1]);
        cr_expect(strstr(err, "outside the frame's 3") != NULL, "%s", err);
    }
    free(u);
    free(v);
    free(rgb);
    free(rgb1);
    pack_free(&p);
    scene_free(&s);
}

/* The units' SIMD-step counts (docs/golden-model.md) on the Cornell box, path tracer and Phong
 * workload: with N = 1 they are the plain counts they group (a step per box test, per ray; per
 * primitive of every leaf entered, which is every primitive tested except those a shadow ray left
 * after its hit); with N = 16 each lies between its N = 1 value / 16 and that value, and rays share
 * steps; they do not depend on the thread count; counting changes neither the image nor the totals. */
enum { SW = 80, SH = 48, SSPP = 2, ST = 32, SUNITS = 6 * SSPP }; /* 3 x 2 tiles, partial ones */

static void steps_render(const PackedScene *p, RefWorkload wl, int threads, int simd, RefUnitStats *u, float *rgb,
                         RefStats *st)
{
    char err[256];
    uint32_t w = sm_u32(p, sm_hdr(p, SM_HDR_WIDTH)), h = sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT));
    memset(rgb, 0, sizeof(float) * 3 * w * h);
    if (u)
        memset(u, 0, sizeof *u * SUNITS);
    RefParams rp = {.tile = ST, .seed = 3, .threads = threads, .workload = wl, .bounces = 1, .units = u,
                    .simd_width = simd};
    cr_assert_eq(ref_render(p, &rp, rgb, st, err, sizeof err), 0, "%s", err);
}

static uint64_t unit_rays(const RefUnitStats *u)
{
    return u->rays[REF_RAY_CAMERA] + u->rays[REF_RAY_INDIRECT] + u->rays[REF_RAY_SHADOW];
}

/* N = 16 groups each N = 1 count of unit i by at most 16 */
static void expect_grouped(uint64_t by16, uint64_t by1, const char *what, int i)
{
    cr_expect_leq(by16, by1, "unit %d: %s %llu with N = 16, %llu with N = 1", i, what, (unsigned long long)by16,
                  (unsigned long long)by1);
    cr_expect_geq(16 * by16, by1, "unit %d: %s %llu with N = 16, %llu with N = 1", i, what, (unsigned long long)by16,
                  (unsigned long long)by1);
}

static void check_simd_steps(const PackedScene *p, RefWorkload wl)
{
    size_t bytes = sizeof(float) * 3 * SW * SH;
    RefUnitStats *u1 = calloc(SUNITS, sizeof *u1), *u16 = calloc(SUNITS, sizeof *u16), *v16 = calloc(SUNITS, sizeof *v16);
    float *plain = malloc(bytes), *rgb = malloc(bytes);
    cr_assert(u1 && u16 && v16 && plain && rgb);
    RefStats st0, st;
    steps_render(p, wl, 2, 0, NULL, plain, &st0);
    cr_assert_eq(st0.dropped, 0u);
    steps_render(p, wl, 2, 1, u1, rgb, &st);
    cr_expect_eq(memcmp(rgb, plain, bytes), 0, "workload %d: the image with units counted (N = 1)", (int)wl);
    cr_expect_eq(memcmp(&st, &st0, sizeof st), 0, "workload %d: the totals with units counted", (int)wl);
    uint64_t pt = 0, ls1 = 0;
    for (int i = 0; i < SUNITS; i++) {
        cr_expect_eq(u1[i].node_steps, u1[i].nodes_visited, "unit %d: N = 1, a step per box test", i);
        cr_expect_geq(u1[i].leaf_steps, u1[i].prims_tested, "unit %d: N = 1, at least a step per primitive test", i);
        cr_expect_eq(u1[i].ray_steps, unit_rays(&u1[i]), "unit %d: N = 1, a step per ray", i);
        pt += u1[i].prims_tested;
        ls1 += u1[i].leaf_steps;
    }
    /* occluded shadow rays skip the rest of their last leaf; leaf steps count it */
    cr_expect_gt(ls1, pt, "workload %d: N = 1, leaf steps %llu, primitive tests %llu", (int)wl,
                 (unsigned long long)ls1, (unsigned long long)pt);
    steps_render(p, wl, 2, 16, u16, rgb, &st);
    cr_expect_eq(memcmp(rgb, plain, bytes), 0, "workload %d: the image with units counted (N = 16)", (int)wl);
    cr_expect_eq(memcmp(&st, &st0, sizeof st), 0);
    steps_render(p, wl, 1, 16, v16, rgb, NULL);
    uint64_t nv = 0, ns = 0, ls = 0, rays = 0, rs = 0;
    for (int i = 0; i < SUNITS; i++) {
        const RefUnitStats *u = &u16[i];
        cr_expect_eq(memcmp(u, &v16[i], sizeof *u), 0, "unit %d: 1 thread vs 2 threads", i);
        cr_expect_eq(memcmp(u->rays, u1[i].rays, sizeof u->rays), 0, "unit %d: the same rays whatever N", i);
        expect_grouped(u->node_steps, u1[i].node_steps, "node steps", i);
        expect_grouped(u->leaf_steps, u1[i].leaf_steps, "leaf steps", i);
        expect_grouped(u->ray_steps, u1[i].ray_steps, "ray steps", i);
        cr_expect_geq(u->ray_steps, u->generations, "unit %d: each generation traced rays", i);
        nv += u->nodes_visited;
        ns += u->node_steps;
        ls += u->leaf_steps;
        rays += unit_rays(u);
        rs += u->ray_steps;
    }
    cr_log_info("workload %d, N = 16: node steps %llu of %llu box tests, leaf steps %llu (N = 1: %llu, primitive "
                "tests %llu), ray steps %llu of %llu rays", (int)wl, (unsigned long long)ns, (unsigned long long)nv,
                (unsigned long long)ls, (unsigned long long)ls1, (unsigned long long)pt, (unsigned long long)rs,
                (unsigned long long)rays);
    /* Coherent camera rays share the root and the nodes near it: far fewer steps than tests. */
    cr_expect_lt(4 * ns, nv, "node steps %llu, box tests %llu", (unsigned long long)ns, (unsigned long long)nv);
    cr_expect_lt(2 * rs, rays, "ray steps %llu, rays %llu", (unsigned long long)rs, (unsigned long long)rays);
    free(u1);
    free(u16);
    free(v16);
    free(plain);
    free(rgb);
}

Test(reference, simd_steps_group_the_unit_counts_by_n)
{
    Scene s;
    PackedScene p;
    char err[4096];
    cr_assert_eq(pack_load_file("scenes/cornell/scene.ini", SW, SH, SSPP, &s, &p, err, sizeof err), 0, "%s", err);
    check_simd_steps(&p, REF_WORKLOAD_PATH);
    check_simd_steps(&p, REF_WORKLOAD_PHONG);
    /* a negative N is refused (0 means 16) */
    RefUnitStats u[SUNITS];
    memset(u, 0, sizeof u);
    float *rgb = calloc(3 * SW * SH, sizeof(float));
    RefParams bad = {.tile = ST, .units = u, .simd_width = -1};
    cr_expect_eq(ref_render(&p, &bad, rgb, NULL, err, sizeof err), -1);
    cr_expect(strstr(err, "SIMD width -1") != NULL, "%s", err);
    free(rgb);
    pack_free(&p);
    scene_free(&s);
}

/* Without lights there are no shadow rays, every ray tests every primitive of the leaves it
 * enters, and with N = 1 the leaf steps are exactly the primitive tests. */
Test(reference, simd_leaf_steps_are_the_primitive_tests_without_shadow_rays)
{
    Builder b;
    Scene s;
    box_scene(&b, &s, 2); /* 24 x 24: one tile of 32 */
    s.nemissive = 0;
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    cr_assert_eq(p.nlights, 0u);
    RefUnitStats u[SUNITS];
    float *rgb = calloc(3 * SW * SH, sizeof(float));
    RefStats st;
    steps_render(&p, REF_WORKLOAD_PATH, 1, 1, u, rgb, &st);
    cr_expect_eq(st.rays[REF_RAY_SHADOW], 0u);
    cr_expect_gt(st.rays[REF_RAY_INDIRECT], 0u);
    for (int i = 0; i < 2; i++) {
        cr_expect_eq(u[i].leaf_steps, u[i].prims_tested, "pass %d", i);
        cr_expect_gt(u[i].prims_tested, 0u, "pass %d", i);
    }
    free(rgb);
    pack_free(&p);
}
