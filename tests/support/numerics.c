/* tests/support/numerics.c -- hard-case geometry and the two-engine comparison for the numerics
 * tests (see numerics.h). */
#include "numerics.h"

#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/config.h"
#include "../../sim/run/run.h"
#include "../../sim/trace.h"

void mesh_init(Mesh *m) { memset(m, 0, sizeof *m); }

void mesh_free(Mesh *m)
{
    free(m->pos);
    free(m->mat);
    memset(m, 0, sizeof *m);
}

void mesh_tri(Mesh *m, const float *a, const float *b, const float *c, uint32_t mat)
{
    if (m->ntris == m->cap) {
        m->cap = m->cap ? 2 * m->cap : 256;
        m->pos = realloc(m->pos, sizeof(float) * 9 * m->cap);
        m->mat = realloc(m->mat, sizeof(uint32_t) * m->cap);
        cr_assert(m->pos && m->mat, "out of memory");
    }
    memcpy(&m->pos[9 * m->ntris], a, 12);
    memcpy(&m->pos[9 * m->ntris + 3], b, 12);
    memcpy(&m->pos[9 * m->ntris + 6], c, 12);
    m->mat[m->ntris++] = mat;
}

void mesh_quad(Mesh *m, const float *c, const float *ea, const float *eb, uint32_t mat)
{
    float p1[3], p2[3], p3[3];
    for (int k = 0; k < 3; k++) {
        p1[k] = c[k] + ea[k];
        p2[k] = c[k] + ea[k] + eb[k];
        p3[k] = c[k] + eb[k];
    }
    mesh_tri(m, c, p1, p2, mat);
    mesh_tri(m, c, p2, p3, mat);
}

void mesh_box(Mesh *m, const float *lo, const float *hi, uint32_t mat)
{
    /* corners: bit 0 x, bit 1 y, bit 2 z */
    float v[8][3];
    for (int i = 0; i < 8; i++) {
        v[i][0] = i & 1 ? hi[0] : lo[0];
        v[i][1] = i & 2 ? hi[1] : lo[1];
        v[i][2] = i & 4 ? hi[2] : lo[2];
    }
    static const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (int i = 0; i < 6; i++) {
        mesh_tri(m, v[f[i][0]], v[f[i][1]], v[f[i][2]], mat);
        mesh_tri(m, v[f[i][0]], v[f[i][2]], v[f[i][3]], mat);
    }
}

/* ---- icosphere: shared vertices, so neighbouring triangles use bit-identical coordinates ----- */

typedef struct Ico {
    float *v;          /* 3 per vertex */
    uint32_t nv, capv;
    uint32_t *f;       /* 3 per face */
    uint32_t nf, capf;
    uint64_t *ekey;    /* edge (lo << 32 | hi) -> midpoint vertex, linear probing */
    uint32_t *eval;
    uint32_t ecap;
} Ico;

static uint32_t ico_vertex(Ico *c, double x, double y, double z)
{
    if (c->nv == c->capv) {
        c->capv = c->capv ? 2 * c->capv : 64;
        c->v = realloc(c->v, sizeof(float) * 3 * c->capv);
        cr_assert(c->v);
    }
    double l = sqrt(x * x + y * y + z * z);
    c->v[3 * c->nv] = (float)(x / l);
    c->v[3 * c->nv + 1] = (float)(y / l);
    c->v[3 * c->nv + 2] = (float)(z / l);
    return c->nv++;
}

static uint32_t ico_mid(Ico *c, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    uint64_t key = (uint64_t)lo << 32 | hi;
    uint32_t h = (uint32_t)((key * 0x9E3779B97F4A7C15ull) >> 40) % c->ecap;
    while (c->ekey[h] != UINT64_MAX) {
        if (c->ekey[h] == key)
            return c->eval[h];
        h = (h + 1) % c->ecap;
    }
    const float *pa = &c->v[3 * a], *pb = &c->v[3 * b];
    uint32_t v = ico_vertex(c, (double)pa[0] + pb[0], (double)pa[1] + pb[1], (double)pa[2] + pb[2]);
    c->ekey[h] = key;
    c->eval[h] = v;
    return v;
}

static void ico_face(Ico *c, uint32_t a, uint32_t b, uint32_t d)
{
    if (c->nf == c->capf) {
        c->capf = c->capf ? 2 * c->capf : 64;
        c->f = realloc(c->f, sizeof(uint32_t) * 3 * c->capf);
        cr_assert(c->f);
    }
    c->f[3 * c->nf] = a;
    c->f[3 * c->nf + 1] = b;
    c->f[3 * c->nf + 2] = d;
    c->nf++;
}

uint32_t mesh_icosphere(Mesh *m, const float *center, float radius, int levels, float **pts, uint32_t *npts,
                        float **mids, uint32_t *nmids)
{
    Ico c;
    memset(&c, 0, sizeof c);
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                          {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (int i = 0; i < 12; i++)
        ico_vertex(&c, base[i][0], base[i][1], base[i][2]);
    static const uint32_t f0[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int i = 0; i < 20; i++)
        ico_face(&c, f0[i][0], f0[i][1], f0[i][2]);
    for (int l = 0; l < levels; l++) {
        uint32_t nf = c.nf;
        uint32_t *old = c.f;
        c.f = NULL;
        c.nf = c.capf = 0;
        free(c.ekey);
        free(c.eval);
        c.ecap = 4 * nf + 7;
        c.ekey = malloc(sizeof(uint64_t) * c.ecap);
        c.eval = malloc(sizeof(uint32_t) * c.ecap);
        cr_assert(c.ekey && c.eval);
        memset(c.ekey, 0xFF, sizeof(uint64_t) * c.ecap);
        for (uint32_t i = 0; i < nf; i++) {
            uint32_t a = old[3 * i], b = old[3 * i + 1], d = old[3 * i + 2];
            uint32_t ab = ico_mid(&c, a, b), bd = ico_mid(&c, b, d), da = ico_mid(&c, d, a);
            ico_face(&c, a, ab, da);
            ico_face(&c, b, bd, ab);
            ico_face(&c, d, da, bd);
            ico_face(&c, ab, bd, da);
        }
        free(old);
    }
    /* scale and move, each vertex once */
    for (uint32_t i = 0; i < c.nv; i++)
        for (int k = 0; k < 3; k++)
            c.v[3 * i + k] = center[k] + radius * c.v[3 * i + k];
    uint32_t first = m->ntris;
    for (uint32_t i = 0; i < c.nf; i++)
        mesh_tri(m, &c.v[3 * c.f[3 * i]], &c.v[3 * c.f[3 * i + 1]], &c.v[3 * c.f[3 * i + 2]], 0);
    if (pts) {
        *pts = malloc(sizeof(float) * 3 * c.nv);
        cr_assert(*pts);
        memcpy(*pts, c.v, sizeof(float) * 3 * c.nv);
        *npts = c.nv;
    }
    if (mids) {
        /* midpoints of every edge of the final mesh, computed in float as a user would */
        *mids = malloc(sizeof(float) * 9 * c.nf);
        cr_assert(*mids);
        *nmids = 0;
        for (uint32_t i = 0; i < c.nf; i++)
            for (int e = 0; e < 3; e++) {
                const float *a = &c.v[3 * c.f[3 * i + e]], *b = &c.v[3 * c.f[3 * i + (e + 1) % 3]];
                for (int k = 0; k < 3; k++)
                    (*mids)[3 * *nmids + k] = 0.5f * (a[k] + b[k]);
                (*nmids)++;
            }
    }
    free(c.v);
    free(c.f);
    free(c.ekey);
    free(c.eval);
    return first;
}

static void material(SceneMaterial *m, SceneMatKind kind, float albedo, float emission)
{
    memset(m, 0, sizeof *m);
    m->kind = kind;
    m->base_color[0] = m->base_color[1] = m->base_color[2] = albedo;
    m->emission[0] = m->emission[1] = m->emission[2] = emission;
    m->base_texture = -1;
    m->emissive_texture = -1;
    m->ior = 1.5f;
    m->roughness = 1.0f;
    if (kind == SCENE_MAT_DIELECTRIC)
        m->transmission = 1.0f;
}

void mesh_scene(Mesh *m, Scene *s)
{
    material(&m->mats[0], SCENE_MAT_LAMBERT, 0.8f, 0.0f);
    material(&m->mats[1], SCENE_MAT_LAMBERT, 0.0f, 10.0f);
    material(&m->mats[2], SCENE_MAT_DIELECTRIC, 1.0f, 0.0f);
    material(&m->mats[3], SCENE_MAT_LAMBERT, 1.0f, 0.0f);
    m->nemissive = 0;
    for (uint32_t i = 0; i < m->ntris && m->nemissive < 64; i++)
        if (m->mat[i] == 1)
            m->emissive[m->nemissive++] = i;
    memset(s, 0, sizeof *s);
    s->ntris = m->ntris;
    s->pos = m->pos;
    s->tri_material = m->mat;
    s->materials = m->mats;
    s->nmaterials = 4;
    s->spheres = m->spheres;
    s->nspheres = m->nspheres;
    s->emissive_tris = m->emissive;
    s->nemissive = m->nemissive;
    s->render = (SceneRender){32, 32, 1, 3, {0, 0, 0}, {0, 0, 0}};
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = INFINITY;
        s->bounds_max[k] = -INFINITY;
    }
    for (uint32_t i = 0; i < 3 * m->ntris; i++)
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], m->pos[3 * i + k]);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], m->pos[3 * i + k]);
        }
    for (uint32_t i = 0; i < m->nspheres; i++)
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], m->spheres[i].center[k] - m->spheres[i].radius);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], m->spheres[i].center[k] + m->spheres[i].radius);
        }
    uint32_t needs = SCENE_NEED_LAMBERT;
    for (uint32_t i = 0; i < m->ntris; i++)
        if (m->mat[i] == 2)
            needs |= SCENE_NEED_DIELECTRIC;
    for (uint32_t i = 0; i < m->nspheres; i++)
        if (m->spheres[i].material == 2)
            needs |= SCENE_NEED_DIELECTRIC;
    if (m->nspheres)
        needs |= SCENE_NEED_SPHERES;
    if (m->nemissive)
        needs |= SCENE_NEED_AREA_LIGHTS;
    s->needs = needs;
    s->camera = (SceneCamera){{0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 40.0f, 0, 0, SCENE_CAMERA_FILE};
}

void batch_add(RayBatch *b, uint32_t *cap, const float *org, const float *dir, float tmax, uint32_t query)
{
    if (b->count == *cap) {
        *cap = *cap ? 2 * *cap : 1024;
        b->rays = realloc(b->rays, sizeof(BatchRay) * *cap);
        cr_assert(b->rays);
    }
    BatchRay *r = &b->rays[b->count++];
    memcpy(r->org, org, 12);
    memcpy(r->dir, dir, 12);
    r->tmax = tmax;
    r->query = query;
}

uint32_t trace_both(const PackedScene *p, uint32_t needs, const RayBatch *b, int lanes, int rays, BatchHit **kh,
                    BatchHit **rh)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.core_simd_width = lanes;
    cfg.stream_rays = rays;
    *kh = calloc(b->count ? b->count : 1, sizeof(BatchHit));
    *rh = calloc(b->count ? b->count : 1, sizeof(BatchHit));
    cr_assert(*kh && *rh);
    static char err[65536];
    RunSpec kspec = {.mode = RUN_FUNCTIONAL, .cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .threads = 2};
    RunSpec rspec = {.mode = RUN_REFERENCE, .cfg = &cfg, .threads = 1};
    cr_assert_eq(run_trace(p, NULL, needs, &kspec, b, *kh, NULL, err, sizeof err), 0, "%s", err);
    cr_assert_eq(run_trace(p, NULL, needs, &rspec, b, *rh, NULL, err, sizeof err), 0, "%s", err);
    uint32_t differ = 0;
    for (uint32_t i = 0; i < b->count; i++)
        if (memcmp(&(*kh)[i], &(*rh)[i], sizeof(BatchHit)) != 0)
            differ++;
    return differ;
}

uint32_t prim_source(const PackedScene *p, uint32_t prim)
{
    uint32_t prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    return sm_u32(p, sm_rec(prims, SM_PRIM_WORDS, prim, SM_PRIM_SRC));
}
