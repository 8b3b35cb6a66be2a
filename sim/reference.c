/* sim/reference.c -- the golden model: the stream-filter path tracer's algorithm in plain C.
 *
 * Owns: the algorithm and arithmetic of docs/golden-model.md. Every float expression is binary32,
 * evaluated left to right as written (ISO C mode: no fused multiply-add contraction), and uses
 * only operations the ISA has (+ - * /, sqrtf, 1/sqrtf, sinf, cosf, exp2f, log2f, floorf,
 * min/max with the ISA's NaN rule), so kernels/pathtrace.s can compute the same bits; and the
 * per-(tile, pass) unit counts, SIMD steps included (counts of work grouped N rays at a time).
 * Must not: model hardware timing, or depend on thread count or traversal order.
 */
#include "reference.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ref_trace.h"
#include "ref_vec.h"
#include "run/tiles.h"

#define PI_F 3.14159265f
#define INV_PI_F 0.318309886f
#define INV_2PI_F 0.159154943f
#define TWO_PI_F 6.28318531f
#define SHADOW_TMAX 0.999f    /* shadow rays stop short of the light's own surface */
#define RR_START_DEPTH 3      /* Russian roulette on rays of this depth and deeper */
#define RR_MAX_SURVIVAL 0.95f
/* The Phong workload (docs/golden-model.md, "The Phong workload"). */
#define PHONG_AMBIENT 0.05f   /* ambient light when the scene has none (render.ambient) */
#define PHONG_EXP_MIN 1.0f    /* lowest shininess: no cos^0 step at the highlight's edge */
#define PHONG_TRI_U (4.0f / 9.0f) /* sample_light's u of a triangle's centroid (sqrt(u) = 2/3) */

/* ---- random numbers: the generator is sim/ref_random.c; the dimensions a hit vertex uses ---- */

/* Random dimensions used at a hit vertex (vertex 0 is the camera: jitter 0-1, lens 2-3). */
enum { DIM_DIRECT = 0, DIM_LIGHT = 1, DIM_LIGHT_U = 2, DIM_LIGHT_V = 3, DIM_LOBE = 4,
       DIM_DIR_U = 5, DIM_DIR_V = 6, DIM_RR = 7 };

/* ---- small vector helpers: sim/ref_vec.h ---------------------------------------------------- */

void ref_offset_point(const float *p, const float *n, float *out) { offset_point(p, n, out); }

/* ---- rays ------------------------------------------------------------------------------------ */

typedef struct Ray {
    float org[3], dir[3], tmax;
    float thr[3];       /* throughput; for shadow rays the radiance they add if unoccluded */
    uint32_t pixel, key;
    uint32_t depth;     /* bounces before this ray: camera 0 */
    uint8_t kind;       /* RefRayKind */
    uint8_t specular;   /* the previous bounce was a delta (dielectric) event */
    RefHit hit;
    int occluded;
} Ray;

typedef struct Ctx {
    const PackedScene *p;
    const RefParams *rp;
    float *rgb;               /* image accumulator (sum over passes) */
    uint32_t width, height, spp, max_depth, nlights;
    uint32_t mats, prims, lights, texs, normals, uvs, lut;
    uint32_t emit_uvs, colors, matx;  /* 0 when the scene needs no emissive textures / colours */
    float background[3], ambient[3];
    int ambient_mode;
    float scene_scale;
    RefWorkload workload;
    uint32_t bounces;         /* phong: mirror bounces */
} Ctx;

typedef struct Worker {
    Ctx *c;
    Ray *cur, *next;
    RefStats st;
    RefSetCount set;
    RefSetCount *count;       /* &set when units are asked for, else NULL: nothing is counted */
    uint32_t unit;            /* the unit being rendered (for RefParams.unit_line) */
} Worker;

/* RefSetCount's line sink: the worker's unit to RefParams.unit_line. */
static void unit_line(void *ctx, uint64_t addr, uint64_t bytes)
{
    Worker *w = ctx;
    w->c->rp->unit_line(w->c->rp->unit_line_ctx, w->unit, addr, bytes);
}

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static void add_radiance(const Ctx *c, uint32_t pixel, const float *v)
{
    float *px = &c->rgb[3 * (size_t)pixel];
    px[0] = px[0] + v[0];
    px[1] = px[1] + v[1];
    px[2] = px[2] + v[2];
}

static float hdr_f(const Ctx *c, int field) { return sm_f32(c->p, sm_hdr(c->p, field)); }

static void camera_ray(const Ctx *c, uint32_t x, uint32_t y, uint32_t sample, Ray *r)
{
    const PackedScene *p = c->p;
    uint32_t pixel = y * c->width + x;
    uint32_t key = ref_path_key(c->rp->seed, pixel, sample);
    float jx = ref_rand(key, 0, 0), jy = ref_rand(key, 0, 1);
    float px = ((float)x + jx) / (float)c->width - 0.5f;
    float py = 0.5f - ((float)y + jy) / (float)c->height;
    float lr = sqrtf(ref_rand(key, 0, 2)), phi = TWO_PI_F * ref_rand(key, 0, 3);
    float lx = lr * cosf(phi), ly = lr * sinf(phi);
    for (int k = 0; k < 3; k++) {
        float focal = hdr_f(c, SM_HDR_CAM_W + k) + px * hdr_f(c, SM_HDR_CAM_U + k) + py * hdr_f(c, SM_HDR_CAM_V + k);
        float lens = lx * hdr_f(c, SM_HDR_LENS_U + k) + ly * hdr_f(c, SM_HDR_LENS_V + k);
        r->org[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_POS + k)) + lens;
        r->dir[k] = focal - lens;
    }
    normalize3(r->dir);
    r->tmax = INFINITY;
    r->thr[0] = r->thr[1] = r->thr[2] = 1.0f;
    r->pixel = pixel;
    r->key = key;
    r->depth = 0;
    r->kind = REF_RAY_CAMERA;
    r->specular = 0;
}

/* ---- materials ----------------------------------------------------------------------------- */

typedef struct Surface {
    float p[3];         /* hit point */
    float ng[3];        /* geometric normal, as stored (winding / outward) */
    float nf[3];        /* geometric normal flipped to face the incoming ray */
    float ns[3];        /* shading normal, on nf's side */
    float base[3];
    uint32_t mat, kind;
    uint32_t src, is_sphere;  /* source triangle (or sphere) index; 1 for a sphere */
} Surface;

static uint32_t mat_u32(const Ctx *c, uint32_t m, int f) { return sm_u32(c->p, sm_rec(c->mats, SM_MAT_WORDS, m, f)); }
static float mat_f32(const Ctx *c, uint32_t m, int f) { return sm_f32(c->p, sm_rec(c->mats, SM_MAT_WORDS, m, f)); }

/* (tu, tv) := the texture coordinates at barycentrics (w0, u, v) of the 3 pairs at address a. */
static void interp2(const Ctx *c, uint32_t a, float w0, float u, float v, float *tu, float *tv)
{
    const PackedScene *p = c->p;
    *tu = w0 * sm_f32(p, a) + u * sm_f32(p, a + 8) + v * sm_f32(p, a + 16);
    *tv = w0 * sm_f32(p, a + 4) + u * sm_f32(p, a + 12) + v * sm_f32(p, a + 20);
}

/* The scene-memory address of texture tex's texel at (tu, tv): nearest texel, repeat wrapping
 * (docs/golden-model.md). */
static uint32_t texel_addr(const Ctx *c, uint32_t tex, float tu, float tv)
{
    const PackedScene *p = c->p;
    uint32_t ta = sm_rec(c->texs, SM_TEX_WORDS, tex, 0);
    uint32_t w = sm_u32(p, ta + 4 * SM_TEX_WIDTH), h = sm_u32(p, ta + 4 * SM_TEX_HEIGHT);
    float fu = tu - floorf(tu), fv = tv - floorf(tv);
    int32_t ix = (int32_t)(fu * (float)w), iy = (int32_t)(fv * (float)h);
    ix = ix < 0 ? 0 : (ix >= (int32_t)w ? (int32_t)w - 1 : ix);
    iy = iy < 0 ? 0 : (iy >= (int32_t)h ? (int32_t)h - 1 : iy);
    return sm_u32(p, ta + 4 * SM_TEX_TEXELS) + 4u * ((uint32_t)iy * w + (uint32_t)ix);
}

/* The texel word of texture tex at (tu, tv). */
static uint32_t texel(const Ctx *c, uint32_t tex, float tu, float tv) { return sm_u32(c->p, texel_addr(c, tex, tu, tv)); }

/* Channel k (0 red .. 2 blue) of a texel word, sRGB-decoded through the header's table. */
static float texel_channel(const Ctx *c, uint32_t t, int k)
{
    return sm_f32(c->p, c->lut + 4u * ((t >> (8 * k)) & 255u));
}

/* A material's emissive texture (MATX), -1 none or when the scene needs no emissive textures. */
static int32_t emit_texture(const Ctx *c, uint32_t mat)
{
    return c->matx ? (int32_t)sm_u32(c->p, sm_rec(c->matx, SM_MATX_WORDS, mat, SM_MATX_EMIT_TEX)) : -1;
}

static void surface(const Ctx *c, const Ray *r, Surface *s)
{
    const PackedScene *p = c->p;
    uint32_t i = r->hit.prim;
    uint32_t a = sm_rec(c->prims, SM_PRIM_WORDS, i, SM_PRIM_V0);
    float g[9];
    for (int k = 0; k < 9; k++)
        g[k] = sm_f32(p, a + 4u * (uint32_t)k);
    uint32_t is_sphere = sm_u32(p, sm_rec(c->prims, SM_PRIM_WORDS, i, SM_PRIM_KIND)) == 1;
    /* The hit point: a triangle's interpolated from its vertices (error relative to the vertices'
     * coordinates, so a floor at y = 0 gets y = 0 even in a scene far from the origin, as the
     * offsets of offset_point assume); a sphere's along the ray. */
    float w0 = 1.0f - r->hit.u - r->hit.v;
    for (int k = 0; k < 3; k++)
        s->p[k] = is_sphere ? r->org[k] + r->hit.t * r->dir[k]
                            : w0 * g[k] + r->hit.u * g[3 + k] + r->hit.v * g[6 + k];
    uint32_t src = sm_u32(p, sm_rec(c->prims, SM_PRIM_WORDS, i, SM_PRIM_SRC));
    if (is_sphere) {
        for (int k = 0; k < 3; k++)
            s->ng[k] = s->p[k] - g[k];
    } else {
        float e1[3] = {g[3] - g[0], g[4] - g[1], g[5] - g[2]}, e2[3] = {g[6] - g[0], g[7] - g[1], g[8] - g[2]};
        cross3(e1, e2, s->ng);
    }
    normalize3(s->ng);
    float side = dot3(s->ng, r->dir) > 0.0f ? -1.0f : 1.0f;
    for (int k = 0; k < 3; k++)
        s->nf[k] = side * s->ng[k];
    if (!is_sphere && c->normals) {
        uint32_t na = c->normals + 36u * src;
        for (int k = 0; k < 3; k++)
            s->ns[k] = w0 * sm_f32(p, na + 4u * (uint32_t)k) + r->hit.u * sm_f32(p, na + 12u + 4u * (uint32_t)k) +
                       r->hit.v * sm_f32(p, na + 24u + 4u * (uint32_t)k);
        normalize3(s->ns);
        if (!finite3(s->ns))
            memcpy(s->ns, s->nf, sizeof s->ns);
        else if (dot3(s->ns, s->nf) < 0.0f)
            for (int k = 0; k < 3; k++)
                s->ns[k] = -s->ns[k];
    } else {
        memcpy(s->ns, s->nf, sizeof s->ns);
    }
    s->mat = sm_u32(p, sm_rec(c->prims, SM_PRIM_WORDS, i, SM_PRIM_MAT));
    s->kind = mat_u32(c, s->mat, SM_MAT_KIND);
    for (int k = 0; k < 3; k++)
        s->base[k] = mat_f32(c, s->mat, SM_MAT_BASE + k);
    int32_t tex = (int32_t)mat_u32(c, s->mat, SM_MAT_TEX);
    if (tex >= 0 && !is_sphere && c->uvs) {
        float tu, tv;
        interp2(c, c->uvs + 24u * src, w0, r->hit.u, r->hit.v, &tu, &tv);
        uint32_t t = texel(c, (uint32_t)tex, tu, tv);
        for (int k = 0; k < 3; k++)
            s->base[k] = s->base[k] * texel_channel(c, t, k);
    }
    if (c->colors && !is_sphere) {
        /* COLOR_0 multiplies the base colour (docs/golden-model.md). */
        uint32_t ca = c->colors + 36u * src;
        for (int k = 0; k < 3; k++) {
            float col = w0 * sm_f32(p, ca + 4u * (uint32_t)k) + r->hit.u * sm_f32(p, ca + 12u + 4u * (uint32_t)k) +
                        r->hit.v * sm_f32(p, ca + 24u + 4u * (uint32_t)k);
            s->base[k] = s->base[k] * col;
        }
    }
    s->src = src;
    s->is_sphere = is_sphere;
}

/* Coupled glossy model: a Lambertian lobe kd = base (1 - metallic) and a normalized Phong lobe
 * around the mirror direction with ks = 0.04 (1 - metallic) + base metallic and exponent
 * 2 / max(roughness^2, 1e-3) - 2. */
typedef struct Glossy { float kd[3], ks[3], n, ps; } Glossy;

/* The Phong exponent of a roughness: 2 / max(roughness^2, 1e-3) - 2. */
static float phong_exponent(float rough) { return 2.0f / ref_fmax(rough * rough, 1e-3f) - 2.0f; }

static void glossy_params(const Ctx *c, const Surface *s, Glossy *g)
{
    float metal = mat_f32(c, s->mat, SM_MAT_METALLIC), rough = mat_f32(c, s->mat, SM_MAT_ROUGHNESS);
    for (int k = 0; k < 3; k++) {
        g->kd[k] = s->base[k] * (1.0f - metal);
        g->ks[k] = 0.04f * (1.0f - metal) + s->base[k] * metal;
    }
    g->n = phong_exponent(rough);
    float ls = g->ks[0] + g->ks[1] + g->ks[2], ld = g->kd[0] + g->kd[1] + g->kd[2];
    g->ps = ls / (ls + ld);
}

/* cos^n, 0 for cos <= 0 (so n = 0 cannot give 0 x inf). */
static float pow_lobe(float cosv, float n) { return cosv > 0.0f ? exp2f(n * log2f(cosv)) : 0.0f; }

static void reflect_dir(const float *d, const float *n, float *out)
{
    float dn = dot3(d, n);
    for (int k = 0; k < 3; k++)
        out[k] = d[k] - 2.0f * dn * n[k];
}

/* BRDF value times cos at the shading normal for direction wi (unit), Lambert or glossy. */
static void brdf_cos(const Ctx *c, const Surface *s, const Ray *r, const float *wi, float *f)
{
    float cosi = dot3(s->ns, wi);
    if (s->kind == SCENE_MAT_GLOSSY) {
        Glossy g;
        glossy_params(c, s, &g);
        float refl[3];
        reflect_dir(r->dir, s->ns, refl);
        float lobe = (g.n + 2.0f) * INV_2PI_F * pow_lobe(dot3(refl, wi), g.n);
        for (int k = 0; k < 3; k++)
            f[k] = (g.kd[k] * INV_PI_F + g.ks[k] * lobe) * cosi;
    } else {
        for (int k = 0; k < 3; k++)
            f[k] = s->base[k] * INV_PI_F * cosi;
    }
}

/* Sample light `l` from origin o: the shadow ray direction (unnormalized, to the light point or
 * far along a directional light) and the incident radiance factor le (radiance x geometry /
 * pdf of the point on the light). Returns 0 when the light cannot contribute. */
static int sample_light(const Ctx *c, uint32_t l, const float *o, float u, float v, float *dir,
                        float *wi, float *le)
{
    const PackedScene *p = c->p;
    uint32_t la = sm_rec(c->lights, SM_LIGHT_WORDS, l, 0);
    uint32_t kind = sm_u32(p, la + 4 * SM_LIGHT_KIND);
    float P[3], E1[3], E2[3], rad[3];
    int textured = 0;
    uint32_t tx = 0;
    for (int k = 0; k < 3; k++) {
        P[k] = sm_f32(p, la + 4u * (uint32_t)(SM_LIGHT_P + k));
        E1[k] = sm_f32(p, la + 4u * (uint32_t)(SM_LIGHT_E1 + k));
        E2[k] = sm_f32(p, la + 4u * (uint32_t)(SM_LIGHT_E2 + k));
        rad[k] = sm_f32(p, la + 4u * (uint32_t)(SM_LIGHT_RADIANCE + k));
    }
    if (kind == SM_LIGHT_DIRECTIONAL) {
        float far = 4.0f * c->scene_scale;
        for (int k = 0; k < 3; k++)
            wi[k] = -P[k];
        normalize3(wi);
        for (int k = 0; k < 3; k++) {
            dir[k] = wi[k] * far;
            le[k] = rad[k];
        }
        return 1;
    }
    float lp[3];
    if (kind == SM_LIGHT_QUAD) {
        for (int k = 0; k < 3; k++)
            lp[k] = P[k] + u * E1[k] + v * E2[k];
    } else if (kind == SM_LIGHT_TRIANGLE) {
        float su = sqrtf(u);
        float b1 = su * (1.0f - v), b2 = su * v;
        for (int k = 0; k < 3; k++)
            lp[k] = P[k] + b1 * E1[k] + b2 * E2[k];
        int32_t tex = c->matx ? (int32_t)sm_u32(p, la + 4 * SM_LIGHT_TEX) : -1;
        if (tex >= 0) {
            /* An emissive texture: the texel at the sampled point (its emissive coordinates at
             * barycentrics (1 - b1 - b2, b1, b2)) scales the radiance. */
            float tu, tv;
            interp2(c, c->emit_uvs + 24u * sm_u32(p, la + 4 * SM_LIGHT_SRC), 1.0f - b1 - b2, b1, b2, &tu, &tv);
            textured = 1;
            tx = texel(c, (uint32_t)tex, tu, tv);
        }
    } else {
        memcpy(lp, P, sizeof lp);
    }
    for (int k = 0; k < 3; k++)
        dir[k] = lp[k] - o[k];
    float d2 = dot3(dir, dir);
    if (!(d2 > 0.0f))
        return 0;
    float il = 1.0f / sqrtf(d2);
    for (int k = 0; k < 3; k++)
        wi[k] = dir[k] * il;
    float scale;
    if (kind == SM_LIGHT_QUAD || kind == SM_LIGHT_TRIANGLE) {
        float nl[3];
        cross3(E1, E2, nl);
        normalize3(nl);
        /* Light leaves the front side (cross(E1, E2)) only, unless marked two-sided. */
        float cosl = -dot3(nl, wi);
        if (sm_u32(p, la + 4 * SM_LIGHT_TWO_SIDED))
            cosl = fabsf(cosl);
        if (!(cosl > 0.0f))
            return 0;
        scale = cosl * sm_f32(p, la + 4 * SM_LIGHT_AREA) / d2;
    } else if (kind == SM_LIGHT_SPOT) {
        float sd[3] = {E1[0], E1[1], E1[2]};
        normalize3(sd);
        float cd = -dot3(sd, wi);
        float ci = sm_f32(p, la + 4 * SM_LIGHT_COS_INNER), co = sm_f32(p, la + 4 * SM_LIGHT_COS_OUTER);
        float fall = (cd - co) / ref_fmax(ci - co, 1e-6f);
        fall = ref_fmin(ref_fmax(fall, 0.0f), 1.0f);
        scale = fall / d2;
    } else {
        scale = 1.0f / d2;
    }
    for (int k = 0; k < 3; k++)
        le[k] = rad[k] * scale;
    if (textured)
        for (int k = 0; k < 3; k++)
            le[k] = le[k] * texel_channel(c, tx, k);
    return scale > 0.0f;
}

static Ray *push(Worker *w, uint32_t *n)
{
    return &w->next[(*n)++];
}

/* RefParams.unit_line: the light record a shadow ray was sampled from. */
static void note_light(const Worker *w, uint32_t l)
{
    if (w->set.line)
        w->set.line(w->set.line_ctx, sm_rec(w->c->lights, SM_LIGHT_WORDS, l, 0), 4u * SM_LIGHT_WORDS);
}

/* Direct lighting: one shadow ray toward a uniformly chosen light. */
static void shade_direct(Worker *w, const Ray *r, const Surface *s, float p_direct, uint32_t *n)
{
    const Ctx *c = w->c;
    uint32_t v = r->depth + 1;
    uint32_t l = (uint32_t)(ref_rand(r->key, v, DIM_LIGHT) * (float)c->nlights);
    if (l >= c->nlights)
        l = c->nlights - 1;
    float o[3], dir[3], wi[3], le[3], f[3];
    offset_point(s->p, s->nf, o);
    note_light(w, l);
    if (!sample_light(c, l, o, ref_rand(r->key, v, DIM_LIGHT_U), ref_rand(r->key, v, DIM_LIGHT_V), dir, wi, le))
        return;
    if (dot3(wi, s->nf) <= 0.0f || dot3(wi, s->ns) <= 0.0f)
        return;
    brdf_cos(c, s, r, wi, f);
    float wgt = (float)c->nlights / p_direct;
    Ray *q = push(w, n);
    memcpy(q->org, o, sizeof o);
    memcpy(q->dir, dir, sizeof dir);
    for (int k = 0; k < 3; k++)
        q->thr[k] = r->thr[k] * f[k] * le[k] * wgt;
    q->tmax = SHADOW_TMAX;
    q->pixel = r->pixel;
    q->key = r->key;
    q->depth = r->depth;
    q->kind = REF_RAY_SHADOW;
    q->specular = 0;
}

/* Continue the path with a new ray of direction d (unit) and throughput thr, leaving the hit
 * point on the side of the unit normal nside. */
static void spawn_from(Worker *w, const Ray *r, const Surface *s, const float *nside, const float *d,
                       const float *thr, int specular, uint32_t *n)
{
    Ray *q = push(w, n);
    offset_point(s->p, nside, q->org);
    memcpy(q->dir, d, sizeof q->dir);
    memcpy(q->thr, thr, sizeof q->thr);
    q->tmax = INFINITY;
    q->pixel = r->pixel;
    q->key = r->key;
    q->depth = r->depth + 1;
    q->kind = REF_RAY_INDIRECT;
    q->specular = (uint8_t)specular;
}

/* The same, leaving on the side of the geometry d points to. */
static void spawn(Worker *w, const Ray *r, const Surface *s, const float *d, const float *thr,
                  int specular, uint32_t *n)
{
    float nside[3];
    float sgn = dot3(d, s->nf) >= 0.0f ? 1.0f : -1.0f;
    for (int k = 0; k < 3; k++)
        nside[k] = sgn * s->nf[k];
    spawn_from(w, r, s, nside, d, thr, specular, n);
}

/* throughput x base colour x ambient, added at the hit */
static void add_ambient(const Ctx *c, const Ray *r, const Surface *s, const float *amb)
{
    float a[3] = {r->thr[0] * s->base[0] * amb[0], r->thr[1] * s->base[1] * amb[1], r->thr[2] * s->base[2] * amb[2]};
    add_radiance(c, r->pixel, a);
}

/* A shadow ray traced where it is made (the Phong workload's light passes): counted like the
 * rays of its generation, dropped if not finite, its radiance added if unoccluded. */
static void trace_shadow(Worker *w, const Ray *q)
{
    const Ctx *c = w->c;
    if (q->depth < REF_MAX_GENERATIONS)
        w->st.rays_per_generation[q->depth]++;
    if (!finite3(q->org) || !finite3(q->dir) || !finite3(q->thr)) {
        w->st.dropped++;
        return;
    }
    RefRay rr = {{q->org[0], q->org[1], q->org[2]}, {q->dir[0], q->dir[1], q->dir[2]}, q->tmax};
    RefTraceStats ts = {0, 0, 0, w->count};
    w->st.rays[REF_RAY_SHADOW]++;
    int occluded = ref_any_hit(c->p, &rr, &ts);
    w->st.nodes_visited += ts.nodes_visited;
    w->st.prims_tested += ts.prims_tested;
    if (!occluded)
        add_radiance(c, q->pixel, q->thr);
}

/* The Phong workload (seed 004 Sec. 4; docs/golden-model.md): ambient, then one shadow ray per
 * light carrying that light's diffuse and specular terms, then (generation < bounces) a mirror
 * bounce about the facing normal weighted by ks. Emitters were handled by the hit-light filter. */
static void shade_phong(Worker *w, const Ray *r, const Surface *s, uint32_t *n)
{
    const Ctx *c = w->c;
    const PackedScene *p = c->p;
    static const float amb0[3] = {PHONG_AMBIENT, PHONG_AMBIENT, PHONG_AMBIENT};
    add_ambient(c, r, s, c->ambient_mode ? c->ambient : amb0);
    float metal = mat_f32(c, s->mat, SM_MAT_METALLIC), rough = mat_f32(c, s->mat, SM_MAT_ROUGHNESS);
    float shin = ref_fmax(phong_exponent(rough), PHONG_EXP_MIN);
    float ks = 0.04f + metal * 0.96f;
    float o[3], refl[3];
    offset_point(s->p, s->nf, o);
    reflect_dir(r->dir, s->ns, refl);
    for (uint32_t l = 0; l < c->nlights; l++) {
        uint32_t kind = sm_u32(p, sm_rec(c->lights, SM_LIGHT_WORDS, l, SM_LIGHT_KIND));
        /* Area lights as a point: a quad's centre, a triangle's centroid. */
        float u = kind == SM_LIGHT_TRIANGLE ? PHONG_TRI_U : 0.5f;
        Ray q = {0};
        float wi[3], le[3];
        note_light(w, l);
        if (!sample_light(c, l, o, u, 0.5f, q.dir, wi, le))
            continue;
        if (dot3(wi, s->nf) <= 0.0f || dot3(wi, s->ns) <= 0.0f)
            continue;
        float cosi = dot3(s->ns, wi);
        float sp = ks * pow_lobe(dot3(refl, wi), shin);
        for (int k = 0; k < 3; k++)
            q.thr[k] = r->thr[k] * (s->base[k] * cosi + sp) * le[k];
        memcpy(q.org, o, sizeof o);
        q.tmax = SHADOW_TMAX;
        q.pixel = r->pixel;
        q.depth = r->depth;
        trace_shadow(w, &q);
    }
    if (r->depth >= c->bounces)
        return;
    float d[3], thr[3];
    reflect_dir(r->dir, s->nf, d);
    for (int k = 0; k < 3; k++)
        thr[k] = r->thr[k] * ks;
    spawn_from(w, r, s, s->nf, d, thr, 1, n);
}

/* Russian roulette for a ray about to be spawned at depth `depth`: 0 = terminate; else thr
 * is divided by the survival probability. */
static int roulette(const Ray *r, uint32_t depth, float *thr)
{
    if (depth < RR_START_DEPTH)
        return 1;
    float q = ref_fmin(ref_fmax(ref_fmax(thr[0], thr[1]), thr[2]), RR_MAX_SURVIVAL);
    if (!(ref_rand(r->key, r->depth + 1, DIM_RR) < q))
        return 0;
    for (int k = 0; k < 3; k++)
        thr[k] = thr[k] / q;
    return 1;
}

/* RefParams.unit_line: the scene memory a hit's shading reads (its material, the vertex normals,
 * colours and texture coordinates of its primitive, the texel of its base colour), as the kernel
 * reads them; the primitive itself was told with its leaf. */
static void note_surface(const Worker *w, const Ray *r, const Surface *s)
{
    const Ctx *c = w->c;
    const RefSetCount *k = &w->set;
    k->line(k->line_ctx, sm_rec(c->mats, SM_MAT_WORDS, s->mat, 0), 4u * SM_MAT_WORDS);
    if (s->is_sphere)
        return;
    if (c->normals)
        k->line(k->line_ctx, c->normals + 36u * s->src, 36);
    if (c->colors)
        k->line(k->line_ctx, c->colors + 36u * s->src, 36);
    const int32_t tex = (int32_t)mat_u32(c, s->mat, SM_MAT_TEX);
    if (tex >= 0 && c->uvs) {
        float tu, tv;
        k->line(k->line_ctx, c->uvs + 24u * s->src, 24);
        interp2(c, c->uvs + 24u * s->src, 1.0f - r->hit.u - r->hit.v, r->hit.u, r->hit.v, &tu, &tv);
        k->line(k->line_ctx, texel_addr(c, (uint32_t)tex, tu, tv), 4);
    }
}

static void shade_hit(Worker *w, const Ray *r, uint32_t *n)
{
    const Ctx *c = w->c;
    Surface s;
    surface(c, r, &s);
    if (w->set.line)
        note_surface(w, r, &s);
    float em[3];
    for (int k = 0; k < 3; k++)
        em[k] = mat_f32(c, s.mat, SM_MAT_EMISSION + k);
    int seen_front = dot3(s.ng, r->dir) < 0.0f || mat_u32(c, s.mat, SM_MAT_DOUBLE_SIDED);
    if (em[0] + em[1] + em[2] > 0.0f && seen_front) {
        /* Hit-light filter: emission counts for camera rays and after delta bounces; other
         * paths have already counted this light through their shadow rays. Lights end paths,
         * except those with an emissive texture: the texel scales the emission, and the surface
         * is also shaded, since a texture may be dark where it does not glow. */
        int32_t etex = emit_texture(c, s.mat);
        if (etex >= 0 && !s.is_sphere) {
            float tu, tv;
            interp2(c, c->emit_uvs + 24u * s.src, 1.0f - r->hit.u - r->hit.v, r->hit.u, r->hit.v, &tu, &tv);
            uint32_t t = texel(c, (uint32_t)etex, tu, tv);
            for (int k = 0; k < 3; k++)
                em[k] = em[k] * texel_channel(c, t, k);
        }
        if (r->depth == 0 || r->specular) {
            float v[3] = {r->thr[0] * em[0], r->thr[1] * em[1], r->thr[2] * em[2]};
            add_radiance(c, r->pixel, v);
        }
        if (etex < 0)
            return;
    }
    if (c->workload == REF_WORKLOAD_PHONG) {
        shade_phong(w, r, &s, n);
        return;
    }
    uint32_t v = r->depth + 1;
    int can_bounce = r->depth + 1 <= c->max_depth;

    if (s.kind == SCENE_MAT_DIELECTRIC) {
        if (!can_bounce)
            return;
        float ior = mat_f32(c, s.mat, SM_MAT_IOR);
        float cosi = dot3(r->dir, s.ng);
        int entering = cosi < 0.0f;
        float nn[3], eta = entering ? 1.0f / ior : ior;
        for (int k = 0; k < 3; k++)
            nn[k] = entering ? s.ng[k] : -s.ng[k];
        float cc = -dot3(r->dir, nn);
        float k2 = 1.0f - eta * eta * (1.0f - cc * cc);
        float F = 1.0f, ct = 0.0f;
        if (k2 > 0.0f) {
            ct = sqrtf(k2);
            float rs = (eta * cc - ct) / (eta * cc + ct);
            float rpl = (eta * ct - cc) / (eta * ct + cc);
            F = 0.5f * (rs * rs + rpl * rpl);
        }
        float d[3], thr[3];
        memcpy(thr, r->thr, sizeof thr);
        if (ref_rand(r->key, v, DIM_LOBE) < F) {
            reflect_dir(r->dir, nn, d);
        } else {
            for (int k = 0; k < 3; k++) {
                d[k] = eta * r->dir[k] + (eta * cc - ct) * nn[k];
                thr[k] = thr[k] * s.base[k];
            }
            normalize3(d);
        }
        if (roulette(r, r->depth + 1, thr))
            spawn(w, r, &s, d, thr, 1, n);
        return;
    }

    if (c->ambient_mode && s.kind == SCENE_MAT_LAMBERT)
        add_ambient(c, r, &s, c->ambient);
    float p_direct = (!can_bounce || (c->ambient_mode && s.kind == SCENE_MAT_LAMBERT)) ? 1.0f : 0.5f;
    if (c->nlights == 0)
        p_direct = 0.0f;
    if (ref_rand(r->key, v, DIM_DIRECT) < p_direct) {
        shade_direct(w, r, &s, p_direct, n);
        return;
    }
    if (!can_bounce)
        return;
    float wgt = 1.0f / (1.0f - p_direct);
    float u5 = ref_rand(r->key, v, DIM_DIR_U), phi = TWO_PI_F * ref_rand(r->key, v, DIM_DIR_V);
    float d[3], thr[3];
    if (s.kind == SCENE_MAT_GLOSSY) {
        Glossy g;
        glossy_params(c, &s, &g);
        if (ref_rand(r->key, v, DIM_LOBE) < g.ps) {
            float refl[3];
            reflect_dir(r->dir, s.ns, refl);
            float cosa = exp2f(log2f(u5) / (g.n + 1.0f));
            float sina = sqrtf(ref_fmax(0.0f, 1.0f - cosa * cosa));
            to_world(refl, sina * cosf(phi), sina * sinf(phi), cosa, d);
            float cosn = dot3(s.ns, d);
            if (!(cosn > 0.0f) || !(dot3(s.nf, d) > 0.0f))
                return; /* sampled below the surface: absorbed */
            float lobe = (g.n + 2.0f) / (g.n + 1.0f) * cosn / g.ps * wgt;
            for (int k = 0; k < 3; k++)
                thr[k] = r->thr[k] * g.ks[k] * lobe;
        } else {
            float rr = sqrtf(u5);
            to_world(s.ns, rr * cosf(phi), rr * sinf(phi), sqrtf(ref_fmax(0.0f, 1.0f - u5)), d);
            float lobe = wgt / (1.0f - g.ps);
            for (int k = 0; k < 3; k++)
                thr[k] = r->thr[k] * g.kd[k] * lobe;
        }
    } else {
        float rr = sqrtf(u5);
        to_world(s.ns, rr * cosf(phi), rr * sinf(phi), sqrtf(ref_fmax(0.0f, 1.0f - u5)), d);
        for (int k = 0; k < 3; k++)
            thr[k] = r->thr[k] * s.base[k] * wgt;
    }
    if (!(dot3(d, s.nf) > 0.0f))
        return; /* a shading-normal sample that points into the geometry */
    if (roulette(r, r->depth + 1, thr))
        spawn(w, r, &s, d, thr, 0, n);
}

/* A unit's counts: what the worker's counters gained over its pass, and its SIMD steps. */
static void unit_counts(RefUnitStats *u, const RefStats *before, const RefStats *after, uint64_t hits,
                        const RefUnitStats *steps)
{
    for (int k = 0; k < REF_RAY_KINDS; k++)
        u->rays[k] = after->rays[k] - before->rays[k];
    u->nodes_visited = after->nodes_visited - before->nodes_visited;
    u->prims_tested = after->prims_tested - before->prims_tested;
    u->hits = hits;
    for (uint32_t g = 0; g < REF_MAX_GENERATIONS; g++)
        if (after->rays_per_generation[g] != before->rays_per_generation[g])
            u->generations = g + 1;
    u->node_steps = steps->node_steps;
    u->leaf_steps = steps->leaf_steps;
    u->ray_steps = steps->ray_steps;
}

static uint64_t rays_traced(const RefStats *st)
{
    return st->rays[REF_RAY_CAMERA] + st->rays[REF_RAY_INDIRECT] + st->rays[REF_RAY_SHADOW];
}

/* Trace the generation's rays w->cur[0, n), dropping those with non-finite data. */
static void trace_generation(Worker *w, uint32_t n)
{
    const Ctx *c = w->c;
    RefTraceStats ts = {0, 0, 0, w->count};
    for (uint32_t i = 0; i < n; i++) {
        Ray *r = &w->cur[i];
        if (!finite3(r->org) || !finite3(r->dir) || !finite3(r->thr)) {
            r->kind = 255; /* dropped: never traced, counted */
            w->st.dropped++;
            continue;
        }
        RefRay q = {{r->org[0], r->org[1], r->org[2]}, {r->dir[0], r->dir[1], r->dir[2]}, r->tmax};
        w->st.rays[r->kind]++;
        if (r->kind == REF_RAY_SHADOW)
            r->occluded = ref_any_hit(c->p, &q, &ts);
        else
            ref_closest_hit(c->p, &q, &r->hit, &ts);
    }
    w->st.nodes_visited += ts.nodes_visited;
    w->st.prims_tested += ts.prims_tested;
}

/* Shade the generation's traced rays, appending the next generation's to w->next; returns how
 * many and adds the rays that hit a surface to *hits. */
static uint32_t shade_generation(Worker *w, uint32_t n, uint64_t *hits)
{
    const Ctx *c = w->c;
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++) {
        const Ray *r = &w->cur[i];
        if (r->kind == 255)
            continue;
        if (r->kind == REF_RAY_SHADOW) {
            if (!r->occluded)
                add_radiance(c, r->pixel, r->thr);
        } else if (r->hit.prim == REF_NO_HIT) {
            float v[3] = {r->thr[0] * c->background[0], r->thr[1] * c->background[1],
                          r->thr[2] * c->background[2]};
            add_radiance(c, r->pixel, v);
        } else {
            (*hits)++;
            shade_hit(w, r, &m);
        }
    }
    return m;
}

/* The end of a generation when units are counted: its SIMD steps (docs/golden-model.md) from the
 * rays it traced -- the Phong workload's shadow rays, traced while shading it, included. */
static void close_generation(Worker *w, uint64_t traced_before, RefUnitStats *steps)
{
    uint32_t simd = w->c->rp->simd_width ? (uint32_t)w->c->rp->simd_width : 16u;
    ref_count_close(w->count, simd, &steps->node_steps, &steps->leaf_steps);
    steps->ray_steps += (rays_traced(&w->st) - traced_before + simd - 1) / simd;
}

static void render_tile(Worker *w, uint32_t tile)
{
    Ctx *c = w->c;
    uint32_t T = (uint32_t)c->rp->tile;
    uint32_t tiles_x = (c->width + T - 1) / T;
    uint32_t x0 = (tile % tiles_x) * T, y0 = (tile / tiles_x) * T;
    uint32_t pass1 = c->rp->pass1 ? c->rp->pass1 : c->spp;
    const uint32_t step = c->rp->pass_step > 1 ? c->rp->pass_step : 1;
    for (uint32_t sample = c->rp->pass0; sample < pass1 && sample < c->spp; sample += step) {
        w->unit = tile * c->spp + sample;
        if (w->set.line) /* RefParams.unit_line: the kernel reads the header's fields in each pass */
            w->set.line(w->set.line_ctx, sm_hdr(c->p, 0), 4u * SM_HDR_WORDS);
        RefStats before = w->st;
        RefUnitStats steps;
        memset(&steps, 0, sizeof steps);
        uint64_t hits = 0;
        uint32_t n = 0;
        for (uint32_t ly = 0; ly < T; ly++)
            for (uint32_t lx = 0; lx < T; lx++)
                if (x0 + lx < c->width && y0 + ly < c->height)
                    camera_ray(c, x0 + lx, y0 + ly, sample, &w->cur[n++]);
        for (uint32_t gen = 0; n > 0; gen++) {
            if (gen < REF_MAX_GENERATIONS)
                w->st.rays_per_generation[gen] += n;
            if (gen + 1 > w->st.generations)
                w->st.generations = gen + 1;
            uint64_t traced_before = rays_traced(&w->st);
            trace_generation(w, n);
            uint32_t m = shade_generation(w, n, &hits);
            if (w->count)
                close_generation(w, traced_before, &steps);
            Ray *t = w->cur;
            w->cur = w->next;
            w->next = t;
            n = m;
        }
        w->st.passes++;
        if (c->rp->units)
            unit_counts(&c->rp->units[(size_t)tile * c->spp + sample], &before, &w->st, hits, &steps);
    }
    w->st.tiles++;
}

/* sim/run/tiles.h: thread `index` renders with worker ws[index]. */
typedef struct Launch {
    Worker *ws;
} Launch;

static int launch_tile(void *ctx, int index, uint32_t tile)
{
    Launch *l = ctx;
    const RefParams *rp = l->ws[index].c->rp;
    render_tile(&l->ws[index], rp->tiles_only ? rp->tiles_only[tile] : tile);
    return 0;
}

/* A worker's ray buffers (a generation holds at most one ray per path: T*T rays each) and, when
 * units are counted, its node counters. 0, or -1 with a message (ref_render frees what it got). */
static int worker_init(Worker *w, Ctx *c, uint32_t T, char *err, size_t errlen)
{
    w->c = c;
    w->cur = malloc(sizeof(Ray) * T * T);
    w->next = malloc(sizeof(Ray) * T * T);
    if (!w->cur || !w->next) {
        snprintf(err, errlen, "reference: out of memory for ray buffers");
        return -1;
    }
    if (c->rp->units || c->rp->unit_line) {
        if (ref_count_init(&w->set, c->p) != 0) {
            snprintf(err, errlen, "reference: out of memory for the unit counts' node counters");
            return -1;
        }
        w->count = &w->set;
        if (c->rp->unit_line) {
            w->set.line = unit_line;
            w->set.line_ctx = w;
        }
    }
    return 0;
}

static void sum_stats(RefStats *sum, const RefStats *s)
{
    for (int k = 0; k < REF_RAY_KINDS; k++)
        sum->rays[k] += s->rays[k];
    for (int g = 0; g < REF_MAX_GENERATIONS; g++)
        sum->rays_per_generation[g] += s->rays_per_generation[g];
    if (s->generations > sum->generations)
        sum->generations = s->generations;
    sum->nodes_visited += s->nodes_visited;
    sum->prims_tested += s->prims_tested;
    sum->dropped += s->dropped;
    sum->tiles += s->tiles;
    sum->passes += s->passes;
}

int ref_render(const PackedScene *p, const RefParams *rp, float *rgb, RefStats *stats, char *err,
               size_t errlen)
{
    if (rp->tile < 1 || rp->tile > 4096) {
        snprintf(err, errlen, "reference: tile size %d out of range", rp->tile);
        return -1;
    }
    if ((rp->workload != REF_WORKLOAD_PATH && rp->workload != REF_WORKLOAD_PHONG) || rp->bounces < 0 ||
        rp->bounces >= REF_MAX_GENERATIONS) {
        snprintf(err, errlen, "reference: workload %d with %d bounces is not one the golden model renders",
                 (int)rp->workload, rp->bounces);
        return -1;
    }
    Ctx c;
    memset(&c, 0, sizeof c);
    c.p = p;
    c.rp = rp;
    c.rgb = rgb;
    c.width = sm_u32(p, sm_hdr(p, SM_HDR_WIDTH));
    c.height = sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT));
    c.spp = sm_u32(p, sm_hdr(p, SM_HDR_SPP));
    c.max_depth = sm_u32(p, sm_hdr(p, SM_HDR_MAX_DEPTH));
    c.nlights = sm_u32(p, sm_hdr(p, SM_HDR_NLIGHTS));
    c.mats = sm_u32(p, sm_hdr(p, SM_HDR_MATS));
    c.prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    c.lights = sm_u32(p, sm_hdr(p, SM_HDR_LIGHTS));
    c.texs = sm_u32(p, sm_hdr(p, SM_HDR_TEXS));
    c.normals = sm_u32(p, sm_hdr(p, SM_HDR_NORMALS));
    c.uvs = sm_u32(p, sm_hdr(p, SM_HDR_UVS));
    c.lut = sm_u32(p, sm_hdr(p, SM_HDR_SRGB_LUT));
    c.emit_uvs = sm_u32(p, sm_hdr(p, SM_HDR_EMIT_UVS));
    c.colors = sm_u32(p, sm_hdr(p, SM_HDR_COLORS));
    c.matx = sm_u32(p, sm_hdr(p, SM_HDR_MATX));
    c.scene_scale = sm_f32(p, sm_hdr(p, SM_HDR_EPSILON));
    c.workload = rp->workload;
    c.bounces = (uint32_t)rp->bounces;
    for (int k = 0; k < 3; k++) {
        c.background[k] = sm_f32(p, sm_hdr(p, SM_HDR_BACKGROUND + k));
        c.ambient[k] = sm_f32(p, sm_hdr(p, SM_HDR_AMBIENT + k));
    }
    c.ambient_mode = c.ambient[0] + c.ambient[1] + c.ambient[2] > 0.0f;
    if (c.width == 0 || c.height == 0 || c.spp == 0) {
        snprintf(err, errlen, "reference: empty image (%u x %u, %u spp)", c.width, c.height, c.spp);
        return -1;
    }
    if (rp->units && rp->simd_width < 0) {
        snprintf(err, errlen, "reference: SIMD width %d for the unit counts is negative", rp->simd_width);
        return -1;
    }
    if (rp->pass1 && (rp->pass0 >= rp->pass1 || rp->pass1 > c.spp)) {
        snprintf(err, errlen, "reference: passes [%u, %u) outside the frame's %u", rp->pass0, rp->pass1, c.spp);
        return -1;
    }
    uint32_t T = (uint32_t)rp->tile;
    uint32_t ntiles = ((c.width + T - 1) / T) * ((c.height + T - 1) / T);
    for (uint32_t i = 0; rp->tiles_only && i < rp->ntiles_only; i++)
        if (rp->tiles_only[i] >= ntiles) {
            snprintf(err, errlen, "reference: tile %u of a frame of %u tiles", rp->tiles_only[i], ntiles);
            return -1;
        }
    if (rp->tiles_only)
        ntiles = rp->ntiles_only;
    int nthreads = tiles_threads(rp->threads, ntiles);
    Worker *ws = calloc((size_t)nthreads, sizeof(Worker));
    int rc = 0;
    if (!ws) {
        snprintf(err, errlen, "reference: out of memory");
        rc = -1;
        goto out;
    }
    for (int i = 0; i < nthreads; i++)
        if (worker_init(&ws[i], &c, T, err, errlen) != 0) {
            rc = -1;
            goto out;
        }
    Launch launch = {ws};
    TileLaunch tl = {ntiles, rp->threads, NULL, launch_tile, NULL, &launch, rp->progress, rp->progress_ctx, 0};
    tiles_run(&tl);
    /* Mean over samples. */
    float inv = 1.0f / (float)c.spp;
    for (size_t i = 0; i < 3 * (size_t)c.width * c.height; i++)
        rgb[i] = rgb[i] * inv;
    if (stats) {
        memset(stats, 0, sizeof *stats);
        for (int i = 0; i < nthreads; i++)
            sum_stats(stats, &ws[i].st);
    }
out:
    for (int i = 0; ws && i < nthreads; i++) {
        free(ws[i].cur);
        free(ws[i].next);
        ref_count_free(&ws[i].set);
    }
    free(ws);
    return rc;
}
