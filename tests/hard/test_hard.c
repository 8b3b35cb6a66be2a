/* tests/hard/test_hard.c -- the slow hard cases of docs/numerics.md (`make test-hard`): a shared
 * scene's closed meshes, a million random rays in float32 against a float64 reference, and
 * scenes moved far from the origin or scaled (self-intersection rate, images equal up to noise).
 * Every case runs through the kernel on the functional core and through the golden model. */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/reference.h"
#include "../support/numerics.h"
#include "../support/rng.h"
#include "../support/shared.h"

static uint64_t rng = TEST_RNG_SEED;
static double urand(void) { return test_rng_unit(&rng); }

static void load_pack(const char *path, Scene *s, PackedScene *p)
{
    NEEDS_SCENE(path);
    char err[1024];
    cr_assert_eq(scene_load(path, s, err, sizeof err), 0, "%s", err);
    BvhParams bp;
    bvh_default_params(&bp);
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s", err);
}

/* ---- a shared scene's closed objects ------------------------------------------------------------ */

/* The two spheres of CornellBox-Sphere are closed triangle meshes (1,000+ triangles each): rays
 * from each one's centre through every one of its vertices and edge midpoints must hit it. */
Test(hard, shared_scene_sphere_meshes_are_watertight, .timeout = 600)
{
    Scene s;
    PackedScene p;
    load_pack("../shared/scenes/cornell-box/CornellBox-Sphere.glb", &s, &p);
    uint32_t total_rays = 0, total_leaks = 0;
    for (uint32_t m = 0; m < s.nmaterials; m++) {
        if (!s.materials[m].name || !strstr(s.materials[m].name, "Sphere"))
            continue;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        uint32_t ntri = 0;
        for (uint32_t t = 0; t < s.ntris; t++)
            if (s.tri_material[t] == m) {
                ntri++;
                for (int v = 0; v < 9; v++) {
                    lo[v % 3] = fmin(lo[v % 3], s.pos[9 * t + v]);
                    hi[v % 3] = fmax(hi[v % 3], s.pos[9 * t + v]);
                }
            }
        cr_assert(ntri > 100, "material %s: %u triangles", s.materials[m].name, ntri);
        float c[3];
        for (int k = 0; k < 3; k++)
            c[k] = (float)(0.5 * (lo[k] + hi[k]));
        RayBatch b = {0};
        uint32_t cap = 0;
        for (uint32_t t = 0; t < s.ntris; t++) {
            if (s.tri_material[t] != m)
                continue;
            for (int v = 0; v < 3; v++) {
                const float *a = &s.pos[9 * t + 3 * v], *e = &s.pos[9 * t + 3 * ((v + 1) % 3)];
                float d[3], mid[3];
                for (int k = 0; k < 3; k++) {
                    d[k] = a[k] - c[k];
                    mid[k] = 0.5f * (a[k] + e[k]);
                }
                batch_add(&b, &cap, c, d, INFINITY, RAY_CLOSEST);
                for (int k = 0; k < 3; k++)
                    d[k] = mid[k] - c[k];
                batch_add(&b, &cap, c, d, INFINITY, RAY_CLOSEST);
            }
        }
        BatchHit *kh, *rh;
        uint32_t differ = trace_both(&p, s.needs, &b, 16, 4096, &kh, &rh);
        uint32_t leak_k = 0, leak_r = 0;
        for (uint32_t i = 0; i < b.count; i++) {
            leak_k += kh[i].prim == UINT32_MAX || s.tri_material[prim_source(&p, kh[i].prim)] != m;
            leak_r += rh[i].prim == UINT32_MAX || s.tri_material[prim_source(&p, rh[i].prim)] != m;
        }
        printf("%s (%u triangles): %u rays through its vertices and edges from inside: leaks kernel %u, golden %u; "
               "%u differ\n", s.materials[m].name, ntri, b.count, leak_k, leak_r, differ);
        cr_expect_eq(leak_k, 0);
        cr_expect_eq(leak_r, 0);
        cr_expect_eq(differ, 0);
        total_rays += b.count;
        total_leaks += leak_k + leak_r;
        free(kh);
        free(rh);
        raybatch_free(&b);
    }
    cr_expect(total_rays > 0, "no sphere mesh found");
    pack_free(&p);
    scene_free(&s);
}

/* ---- float32 against float64 ------------------------------------------------------------------ */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* A million random rays in the conference room (origins in its bounds, directions uniform):
 * kernel and golden model agree on every ray; the float32 hit distance is compared with the
 * distance to the same triangle's plane computed in double precision. The error along the ray is
 * measured in units of the coordinates' precision, u = 2^-24 x max(|o|, |vertices|, |p|): the
 * watertight test's distance is a few roundings of values of that size, so errors are a few u,
 * larger only for grazing hits, where it grows as 1 / |cos| of the angle with the normal. */
Test(hard, float32_against_float64_on_a_million_rays, .timeout = 1200)
{
    Scene s;
    PackedScene p;
    load_pack("scenes/conference/scene.ini", &s, &p);
    const uint32_t n = 1000000;
    RayBatch b = {0};
    uint32_t cap = 0;
    for (uint32_t i = 0; i < n; i++) {
        float o[3], d[3];
        for (int k = 0; k < 3; k++)
            o[k] = (float)(s.bounds_min[k] + (s.bounds_max[k] - s.bounds_min[k]) * urand());
        double z = 2.0 * urand() - 1.0, ph = 2.0 * M_PI * urand(), r = sqrt(1.0 - z * z);
        d[0] = (float)(r * cos(ph));
        d[1] = (float)(r * sin(ph));
        d[2] = (float)z;
        batch_add(&b, &cap, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    uint32_t differ = trace_both(&p, s.needs, &b, 16, 4096, &kh, &rh);
    double *err = malloc(sizeof(double) * n), *errg = malloc(sizeof(double) * n);
    cr_assert(err && errg);
    uint32_t nh = 0, ng = 0;
    double worst_cond = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        if (kh[i].prim == UINT32_MAX)
            continue;
        uint32_t src = prim_source(&p, kh[i].prim);
        const float *v = &s.pos[9 * src];
        const BatchRay *r = &b.rays[i];
        double e1[3], e2[3], e3[3], nn[3], w[3], dd[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)v[3 + k] - v[k];
            e2[k] = (double)v[6 + k] - v[k];
            e3[k] = (double)v[6 + k] - v[3 + k];
            w[k] = (double)v[k] - r->org[k];
            dd[k] = r->dir[k];
        }
        nn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        nn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        nn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double dn = dd[0] * nn[0] + dd[1] * nn[1] + dd[2] * nn[2];
        double nl = sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
        double dl = sqrt(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
        if (nl == 0.0 || dn == 0.0)
            continue;
        double t64 = (w[0] * nn[0] + w[1] * nn[1] + w[2] * nn[2]) / dn;
        double scale = 0.0;
        for (int k = 0; k < 9; k++)
            scale = fmax(scale, fabs(v[k]));
        for (int k = 0; k < 3; k++)
            scale = fmax(fmax(scale, fabs(r->org[k])), fabs(r->org[k] + t64 * dd[k]));
        double u = scale * 0x1p-24;
        double cosang = fabs(dn) / (nl * dl);
        /* the sine of the triangle's smallest angle: 2 area / the product of its two longer sides */
        double l[3] = {sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]),
                       sqrt(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2]),
                       sqrt(e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2])};
        double lmin = fmin(l[0], fmin(l[1], l[2]));
        double sinmin = nl * lmin / (l[0] * l[1] * l[2]);
        double e = fabs((double)kh[i].t - t64) * dl / u; /* along the ray, in units u */
        err[nh++] = e;
        if (cosang > 0.1 && sinmin > 0.1) /* neither grazing nor a needle or sliver */
            errg[ng++] = e;
        worst_cond = fmax(worst_cond, e * cosang * sinmin);
    }
    qsort(err, nh, sizeof(double), cmp_double);
    qsort(errg, ng, sizeof(double), cmp_double);
    printf("float32 vs float64, %u random rays in the conference room: %u hits, %u rays differ between kernel and "
           "golden model\n  distance error along the ray in units u = 2^-24 x coordinate size: median %.2f, 99%% %.2f, "
           "99.9%% %.2f, max %.1f\n  well-conditioned hits (angle to the normal < 84 degrees, smallest triangle angle "
           "> 5.7 degrees): %u, max %.2f u; all hits: max of error x cos x sin(smallest angle) %.2f u\n",
           n, nh, differ, err[nh / 2], err[(size_t)(0.99 * nh)], err[(size_t)(0.999 * nh)], err[nh - 1], ng,
           errg[ng - 1], worst_cond);
    cr_expect_eq(differ, 0);
    cr_expect(nh > n / 2, "only %u hits", nh);
    /* The watertight test's distance is a few roundings of values of size u: 16 u bounds it with
     * room. It degrades as 1 / cos for grazing hits and as 1 / sin(smallest angle) for needles and
     * slivers (whose edge functions cancel), so the conditioned error obeys the same bound. */
    cr_expect(errg[ng - 1] <= 16.0, "well-conditioned distance error %.1f u", errg[ng - 1]);
    cr_expect(worst_cond <= 16.0, "conditioned distance error %.1f u", worst_cond);
    free(err);
    free(errg);
    free(kh);
    free(rh);
    raybatch_free(&b);
    pack_free(&p);
    scene_free(&s);
}

/* ---- far from the origin, scaled -------------------------------------------------------------- */

static void transform(Scene *s, double scale, double offset)
{
    for (uint32_t i = 0; i < 3 * s->ntris; i++)
        for (int k = 0; k < 3; k++)
            s->pos[3 * i + k] = (float)(s->pos[3 * i + k] * scale + offset);
    for (uint32_t i = 0; i < s->nlights; i++)
        for (int k = 0; k < 3; k++) {
            s->lights[i].position[k] = (float)(s->lights[i].position[k] * scale + offset);
            s->lights[i].edge_u[k] = (float)(s->lights[i].edge_u[k] * scale);
            s->lights[i].edge_v[k] = (float)(s->lights[i].edge_v[k] * scale);
        }
    for (int k = 0; k < 3; k++) {
        s->camera.position[k] = (float)(s->camera.position[k] * scale + offset);
        s->camera.look_at[k] = (float)(s->camera.look_at[k] * scale + offset);
        s->bounds_min[k] = (float)(s->bounds_min[k] * scale + offset);
        s->bounds_max[k] = (float)(s->bounds_max[k] * scale + offset);
    }
    if (s->camera.focus_distance > 0)
        s->camera.focus_distance = (float)(s->camera.focus_distance * scale);
    s->camera.aperture = (float)(s->camera.aperture * scale);
}

static float *render_kernel(Scene *s, uint32_t seed)
{
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[1024];
    cr_assert_eq(pack_scene(s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    size_t n = 3 * (size_t)s->render.width * s->render.height;
    float *rgb = calloc(n, sizeof(float));
    CfgMachine cfg;
    cfg_defaults(&cfg);
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = s->needs, .seed = seed, .threads = 2};
    FuncStats st;
    static char ferr[65536];
    cr_assert_eq(func_render(&p, &fp, rgb, &st, ferr, sizeof ferr), 0, "%s", ferr);
    cr_expect_eq(st.dropped, 0);
    func_stats_free(&st);
    pack_free(&p);
    return rgb;
}

static double rmse(const float *a, const float *b, size_t n, long *bad)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(a[i]))
            (*bad)++;
        s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    }
    return sqrt(s / (double)n);
}

/* Secondary rays leaving hit points, traced with both engines: the fraction that hit their own
 * triangle again (self-intersection). The hit point and origin are made as the renderer makes
 * them (docs/golden-model.md): interpolated from the vertices, moved off by offset_point. */
static double self_intersection_rate(const Scene *s, uint32_t nrays)
{
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[1024];
    cr_assert_eq(pack_scene(s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    /* primary rays from the camera to random points of the scene's bounds */
    RayBatch b1 = {0};
    uint32_t cap = 0;
    for (uint32_t i = 0; i < nrays; i++) {
        float t[3], d[3];
        for (int k = 0; k < 3; k++) {
            t[k] = (float)(s->bounds_min[k] + (s->bounds_max[k] - s->bounds_min[k]) * urand());
            d[k] = t[k] - s->camera.position[k];
        }
        batch_add(&b1, &cap, s->camera.position, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh, *rh;
    cr_expect_eq(trace_both(&p, s->needs, &b1, 16, 4096, &kh, &rh), 0);
    RayBatch b2 = {0};
    uint32_t cap2 = 0, *from = malloc(sizeof(uint32_t) * nrays);
    cr_assert(from);
    for (uint32_t i = 0; i < nrays; i++) {
        if (kh[i].prim == UINT32_MAX)
            continue;
        const BatchRay *r = &b1.rays[i];
        uint32_t src = prim_source(&p, kh[i].prim);
        const float *v = &s->pos[9 * src];
        float e1[3], e2[3], n[3], ph[3], o[3], d[3];
        float w0 = 1.0f - kh[i].u - kh[i].v;
        for (int k = 0; k < 3; k++) {
            e1[k] = v[3 + k] - v[k];
            e2[k] = v[6 + k] - v[k];
            ph[k] = w0 * v[k] + kh[i].u * v[3 + k] + kh[i].v * v[6 + k]; /* as the renderer does */
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        float l = 1.0f / sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        float side = n[0] * r->dir[0] + n[1] * r->dir[1] + n[2] * r->dir[2] > 0 ? -l : l;
        for (int k = 0; k < 3; k++)
            n[k] *= side;
        ref_offset_point(ph, n, o);
        /* a direction in the hemisphere of n */
        double z = urand(), a = 2.0 * M_PI * urand(), rr = sqrt(1.0 - z * z);
        float tt[3] = {0, 0, 0};
        int ax = fabsf(n[0]) < 0.5f ? 0 : 1;
        tt[ax] = 1.0f;
        float bt[3] = {n[1] * tt[2] - n[2] * tt[1], n[2] * tt[0] - n[0] * tt[2], n[0] * tt[1] - n[1] * tt[0]};
        float bl = 1.0f / sqrtf(bt[0] * bt[0] + bt[1] * bt[1] + bt[2] * bt[2]);
        float ct[3] = {n[1] * bt[2] - n[2] * bt[1], n[2] * bt[0] - n[0] * bt[2], n[0] * bt[1] - n[1] * bt[0]};
        for (int k = 0; k < 3; k++)
            d[k] = (float)(rr * cos(a)) * bt[k] * bl + (float)(rr * sin(a)) * ct[k] * bl + (float)z * n[k];
        from[b2.count] = kh[i].prim;
        batch_add(&b2, &cap2, o, d, INFINITY, RAY_CLOSEST);
    }
    BatchHit *kh2, *rh2;
    cr_expect_eq(trace_both(&p, s->needs, &b2, 16, 4096, &kh2, &rh2), 0);
    uint32_t self = 0;
    for (uint32_t i = 0; i < b2.count; i++)
        self += kh2[i].prim == from[i];
    double rate = b2.count ? (double)self / b2.count : 0.0;
    free(from);
    free(kh);
    free(rh);
    free(kh2);
    free(rh2);
    raybatch_free(&b1);
    raybatch_free(&b2);
    pack_free(&p);
    return rate;
}

static void far_case(const char *path, double scale, double offset, int w, int h, int spp)
{
    NEEDS_SCENE(path);
    Scene base, moved;
    char err[1024];
    cr_assert_eq(scene_load(path, &base, err, sizeof err), 0, "%s", err);
    cr_assert_eq(scene_load(path, &moved, err, sizeof err), 0, "%s", err);
    base.render.width = moved.render.width = w;
    base.render.height = moved.render.height = h;
    base.render.spp = moved.render.spp = spp;
    transform(&moved, scale, offset);
    double rate = self_intersection_rate(&moved, 100000);
    size_t n = 3 * (size_t)w * h;
    float *a = render_kernel(&base, 1), *a2 = render_kernel(&base, 2), *m = render_kernel(&moved, 1);
    long bad = 0;
    double noise = rmse(a2, a, n, &bad), diff = rmse(m, a, n, &bad);
    double ma = 0, mm = 0;
    for (size_t i = 0; i < n; i++) {
        ma += a[i];
        mm += m[i];
    }
    printf("%s x %g + %g: self-intersections %.2e of 100K secondary rays; image RMSE against the original %.4f "
           "(another seed: %.4f); mean %.4f vs %.4f; non-finite %ld\n",
           path, scale, offset, rate, diff, noise, mm / (double)n, ma / (double)n, bad);
    cr_expect(rate <= 1e-4, "self-intersection rate %g", rate);
    cr_expect(diff <= 1.25 * noise, "image differs by more than noise: RMSE %g against %g", diff, noise);
    cr_expect_eq(bad, 0);
    free(a);
    free(a2);
    free(m);
    scene_free(&base);
    scene_free(&moved);
}

Test(hard, cornell_box_moved_1e3, .timeout = 600) { far_case("scenes/cornell/scene.ini", 1.0, 1e3, 64, 64, 32); }

Test(hard, cornell_box_scaled_1e_minus_3, .timeout = 600) { far_case("scenes/cornell/scene.ini", 1e-3, 0.0, 64, 64, 32); }

Test(hard, cornell_box_scaled_1e4, .timeout = 600) { far_case("scenes/cornell/scene.ini", 1e4, 0.0, 64, 64, 32); }

Test(hard, conference_room_moved_1e5, .timeout = 900)
{
    far_case("scenes/conference/scene.ini", 1.0, 1e5, 48, 36, 8);
}
