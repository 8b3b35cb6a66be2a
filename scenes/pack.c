/* scenes/pack.c -- writes a Scene and its BVH into the scene-memory layout of layout.def.
 *
 * Owns: the packed byte image and the host-side precomputation stored in it (camera vectors,
 * light records, sRGB table). Must not: decide anything a reader could disagree with: every
 * value the golden model and the kernels need is computed here once, in one place.
 */
#include "pack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

typedef struct Writer {
    uint8_t *mem;
    size_t size, cap;
    uint32_t base;
    int oom;
} Writer;

/* Reserve n words aligned to 64 bytes; returns the scene-memory address. */
static uint32_t w_alloc(Writer *w, size_t words)
{
    size_t off = (w->size + 63) & ~(size_t)63;
    size_t need = off + 4 * words;
    if (need > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < need)
            cap *= 2;
        uint8_t *m = realloc(w->mem, cap);
        if (!m) {
            w->oom = 1;
            return 0;
        }
        memset(m + w->cap, 0, cap - w->cap);
        w->mem = m;
        w->cap = cap;
    }
    w->size = need;
    return w->base + (uint32_t)off;
}

static void put_u32(Writer *w, uint32_t addr, uint32_t v) { memcpy(w->mem + (addr - w->base), &v, 4); }
static void put_f32(Writer *w, uint32_t addr, float v) { memcpy(w->mem + (addr - w->base), &v, 4); }
/* n floats' bytes from v, as n put_f32 would store them, in one copy (n is a constant where it is
 * called, so the copy is a few moves: the loop was a tenth of the conference room's packing). */
static inline void put_vec(Writer *w, uint32_t addr, const float *v, int n)
{
    memcpy(w->mem + (addr - w->base), v, sizeof(float) * (size_t)n);
}

static uint32_t hdr(uint32_t base, int field) { return base + 4u * (uint32_t)field; }

static uint8_t srgb_encode8(float lin)
{
    float x = lin <= 0.0f ? 0.0f : (lin >= 1.0f ? 1.0f : lin);
    float e = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)lrintf(e * 255.0f);
}

/* srgb_encode8 once per distinct value: three powf per texel were most of a textured scene's
 * packing (sponza), and textures decoded from 8-bit files hold at most 256 values per channel.
 * Direct-mapped on the float's bits; a miss computes srgb_encode8, so every byte is the same. */
enum { SRGB_CACHE_SLOTS = 4096 };
typedef struct SrgbCache {
    uint64_t slot[SRGB_CACHE_SLOTS]; /* bits << 32 | 0x100 | code; 0: empty */
} SrgbCache;

static uint8_t srgb_encode8_cached(SrgbCache *c, float lin)
{
    if (!c)
        return srgb_encode8(lin);
    uint32_t bits;
    memcpy(&bits, &lin, 4);
    uint64_t *e = &c->slot[(bits * 2654435761u) >> 20];
    if ((*e & 0x100u) && (uint32_t)(*e >> 32) == bits)
        return (uint8_t)*e;
    uint8_t code = srgb_encode8(lin);
    *e = (uint64_t)bits << 32 | 0x100u | code;
    return code;
}

static float srgb_decode8(int code)
{
    float c = (float)code / 255.0f;
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

static void camera(const Scene *s, float *cw, float *cu, float *cv, float *lu, float *lv)
{
    const SceneCamera *c = &s->camera;
    double f[3], up[3] = {c->up[0], c->up[1], c->up[2]}, r[3], u[3];
    double dist = 0.0;
    for (int k = 0; k < 3; k++) {
        f[k] = (double)c->look_at[k] - c->position[k];
        dist += f[k] * f[k];
    }
    dist = sqrt(dist);
    for (int k = 0; k < 3; k++)
        f[k] /= dist;
    r[0] = f[1] * up[2] - f[2] * up[1];
    r[1] = f[2] * up[0] - f[0] * up[2];
    r[2] = f[0] * up[1] - f[1] * up[0];
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        r[k] /= rl;
    u[0] = r[1] * f[2] - r[2] * f[1];
    u[1] = r[2] * f[0] - r[0] * f[2];
    u[2] = r[0] * f[1] - r[1] * f[0];
    double d = c->focus_distance > 0.0f ? c->focus_distance : dist;
    double h = tan(0.5 * c->fov_y * M_PI / 180.0) * d;
    double wdt = h * (double)s->render.width / (double)s->render.height;
    double lens = 0.5 * c->aperture;
    for (int k = 0; k < 3; k++) {
        cw[k] = (float)(f[k] * d);
        cu[k] = (float)(r[k] * 2.0 * wdt);
        cv[k] = (float)(u[k] * 2.0 * h);
        lu[k] = (float)(r[k] * lens);
        lv[k] = (float)(u[k] * lens);
    }
}

static float tri_area(const float *p)
{
    float e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = p[3 + k] - p[k];
        e2[k] = p[6 + k] - p[k];
    }
    float cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
          cz = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5f * sqrtf(cx * cx + cy * cy + cz * cz);
}

/* The emissive texture a reader samples for material m: its own when it emits, else none. */
static int32_t emissive_texture(const Scene *s, const SceneMaterial *m)
{
    int emits = m->emission[0] + m->emission[1] + m->emission[2] > 0.0f;
    return emits && m->emissive_texture >= 0 && (uint32_t)m->emissive_texture < s->ntextures ? m->emissive_texture
                                                                                              : -1;
}

/* A triangle's extent on one axis from its vertices' coordinates a, b, c, as the first packer
 * computed it with libm: the object code called fminf(fminf(c, b), a) (GCC orders the operands of
 * these commutative calls so) and glibc's x86-64 fminf returns its second operand on a tie. So the
 * value is the minimum, and between -0.0 and +0.0 the earlier vertex's: the bytes of the node
 * boxes stay the same. Inlined: they were two million libm calls on the conference room. */
static inline float tri_min(float a, float b, float c)
{
    float m = b < a ? b : a;
    return c < m ? c : m;
}

static inline float tri_max(float a, float b, float c)
{
    float m = b > a ? b : a;
    return c > m ? c : m;
}

/* The BVH over the triangles' and spheres' bounding boxes, its invariants checked. */
static int pack_build_bvh(const Scene *s, const BvhParams *bp, uint32_t nprims, Bvh *bvh, char *err,
                          size_t errlen)
{
    float *lo = bvh_big_alloc(sizeof(float) * 3 * (nprims ? nprims : 1));
    float *hi = bvh_big_alloc(sizeof(float) * 3 * (nprims ? nprims : 1));
    if (!lo || !hi) {
        free(lo);
        free(hi);
        snprintf(err, errlen, "pack: out of memory");
        return -1;
    }
    uint32_t i = 0;
#if defined(__SSE2__)
    /* tri_min and tri_max on the three axes at once: minps(b, a) is b < a ? b : a, lane by lane.
     * Four floats are read from each vertex and stored at 3i (the fourth belongs to the next
     * triangle, which overwrites it): the last triangle is left to the loop below. */
    for (; i + 1 < s->ntris; i++) {
        const float *p = &s->pos[9 * (size_t)i];
        __m128 a = _mm_loadu_ps(p), b = _mm_loadu_ps(p + 3), c = _mm_loadu_ps(p + 6);
        _mm_storeu_ps(&lo[3 * (size_t)i], _mm_min_ps(c, _mm_min_ps(b, a)));
        _mm_storeu_ps(&hi[3 * (size_t)i], _mm_max_ps(c, _mm_max_ps(b, a)));
    }
#endif
    for (; i < s->ntris; i++) {
        const float *p = &s->pos[9 * i];
        for (int k = 0; k < 3; k++) {
            lo[3 * i + k] = tri_min(p[k], p[3 + k], p[6 + k]);
            hi[3 * i + k] = tri_max(p[k], p[3 + k], p[6 + k]);
        }
    }
    for (uint32_t j = 0; j < s->nspheres; j++) {
        const SceneSphere *sp = &s->spheres[j];
        for (int k = 0; k < 3; k++) {
            lo[3 * (s->ntris + j) + k] = sp->center[k] - sp->radius;
            hi[3 * (s->ntris + j) + k] = sp->center[k] + sp->radius;
        }
    }
    int rc = bvh_build(bp, lo, hi, nprims, bvh, err, errlen);
    /* The invariants are checked on every build, not only in tests: O(n), and a broken tree
     * would silently lose geometry. */
    if (rc == 0 && bvh_check(bvh, lo, hi, err, errlen) != 0) {
        bvh_free(bvh);
        rc = -1;
    }
    free(lo);
    free(hi);
    return rc ? -1 : 0;
}

/* Where each table of the image starts (scene-memory addresses; 0 for an absent table). */
typedef struct Layout {
    uint32_t nprims, nnodes, nlights;
    int emit_tex; /* emissive textures are packed (the scene needs them and has their UVs) */
    uint32_t h, nodes, prims, mats, texs, lights, normals, uvs, emit_uvs, matx, colors, lut;
    uint32_t *texels; /* per texture: its texel array (malloc'ed) */
} Layout;

/* Reserves every table in w, in image order. 0, or -1 with a message (and nothing to free). */
static int pack_lay_out(Writer *w, const Scene *s, Layout *l, char *err, size_t errlen)
{
    l->h = w_alloc(w, SM_HDR_WORDS);
    l->nodes = w_alloc(w, (size_t)SM_NODE_WORDS * l->nnodes);
    l->prims = w_alloc(w, (size_t)SM_PRIM_WORDS * l->nprims);
    l->mats = w_alloc(w, (size_t)SM_MAT_WORDS * s->nmaterials);
    l->texs = w_alloc(w, (size_t)SM_TEX_WORDS * s->ntextures);
    l->lights = w_alloc(w, (size_t)SM_LIGHT_WORDS * l->nlights);
    l->normals = s->nrm ? w_alloc(w, (size_t)9 * s->ntris) : 0;
    l->uvs = s->uv ? w_alloc(w, (size_t)6 * s->ntris) : 0;
    /* emissive textures and vertex colours only when the scene needs them, so a reader sees one
     * answer in the header and the needs */
    l->emit_tex = (s->needs & SCENE_NEED_EMISSIVE_TEXTURES) && s->uv_emit;
    l->emit_uvs = l->emit_tex ? w_alloc(w, (size_t)6 * s->ntris) : 0;
    l->matx = l->emit_tex ? w_alloc(w, (size_t)SM_MATX_WORDS * s->nmaterials) : 0;
    l->colors = (s->needs & SCENE_NEED_VERTEX_COLORS) && s->col ? w_alloc(w, (size_t)9 * s->ntris) : 0;
    l->lut = w_alloc(w, 256);
    l->texels = calloc(s->ntextures ? s->ntextures : 1, sizeof(uint32_t));
    for (uint32_t t = 0; l->texels && t < s->ntextures; t++)
        l->texels[t] = w_alloc(w, (size_t)s->textures[t].width * (size_t)s->textures[t].height);
    if (w->oom || !l->texels || w->size > (size_t)UINT32_MAX - w->base) {
        snprintf(err, errlen, "pack: scene does not fit in memory (%zu bytes)", w->size);
        free(l->texels);
        l->texels = NULL;
        return -1;
    }
    return 0;
}

/* pack_lay_out into one zeroed block of the image's size: a first pass with no memory learns the
 * size (w_alloc never grows a writer whose capacity is unbounded), the second reserves the same
 * addresses. Growing the block by doubling zeroed up to twice the image and copied it: a tenth of
 * the conference room's packing time, most of it in page faults. 0, or -1 with a message. */
static int pack_reserve(Writer *w, const Scene *s, Layout *l, char *err, size_t errlen)
{
    Writer probe = {NULL, 0, SIZE_MAX, w->base, 0};
    Layout sized = *l;
    if (pack_lay_out(&probe, s, &sized, err, errlen) != 0)
        return -1;
    free(sized.texels);
    w->mem = calloc(probe.size ? probe.size : 1, 1);
    if (!w->mem) {
        snprintf(err, errlen, "pack: scene does not fit in memory (%zu bytes)", probe.size);
        return -1;
    }
    w->cap = probe.size;
    return pack_lay_out(w, s, l, err, errlen);
}

/* The header: counts, table addresses, render settings, camera, bounds. */
static void pack_header(Writer *w, const Scene *s, const Layout *l)
{
    uint32_t h = l->h;
    put_u32(w, hdr(h, SM_HDR_MAGIC), SM_MAGIC);
    put_u32(w, hdr(h, SM_HDR_VERSION), SM_VERSION);
    put_u32(w, hdr(h, SM_HDR_NPRIMS), l->nprims);
    put_u32(w, hdr(h, SM_HDR_NNODES), l->nnodes);
    put_u32(w, hdr(h, SM_HDR_NMATS), s->nmaterials);
    put_u32(w, hdr(h, SM_HDR_NTEX), s->ntextures);
    put_u32(w, hdr(h, SM_HDR_NLIGHTS), l->nlights);
    put_u32(w, hdr(h, SM_HDR_NODES), l->nodes);
    put_u32(w, hdr(h, SM_HDR_PRIMS), l->prims);
    put_u32(w, hdr(h, SM_HDR_MATS), l->mats);
    put_u32(w, hdr(h, SM_HDR_TEXS), l->texs);
    put_u32(w, hdr(h, SM_HDR_LIGHTS), l->lights);
    put_u32(w, hdr(h, SM_HDR_NORMALS), l->normals);
    put_u32(w, hdr(h, SM_HDR_UVS), l->uvs);
    put_u32(w, hdr(h, SM_HDR_SRGB_LUT), l->lut);
    put_u32(w, hdr(h, SM_HDR_EMIT_UVS), l->emit_uvs);
    put_u32(w, hdr(h, SM_HDR_COLORS), l->colors);
    put_u32(w, hdr(h, SM_HDR_MATX), l->matx);
    put_u32(w, hdr(h, SM_HDR_WIDTH), (uint32_t)s->render.width);
    put_u32(w, hdr(h, SM_HDR_HEIGHT), (uint32_t)s->render.height);
    put_u32(w, hdr(h, SM_HDR_SPP), (uint32_t)s->render.spp);
    put_u32(w, hdr(h, SM_HDR_MAX_DEPTH), (uint32_t)s->render.max_depth);
    put_vec(w, hdr(h, SM_HDR_BACKGROUND), s->render.background, 3);
    put_vec(w, hdr(h, SM_HDR_AMBIENT), s->render.ambient, 3);
    put_vec(w, hdr(h, SM_HDR_CAM_POS), s->camera.position, 3);
    float cw[3], cu[3], cv[3], lu[3], lv[3];
    camera(s, cw, cu, cv, lu, lv);
    put_vec(w, hdr(h, SM_HDR_CAM_W), cw, 3);
    put_vec(w, hdr(h, SM_HDR_CAM_U), cu, 3);
    put_vec(w, hdr(h, SM_HDR_CAM_V), cv, 3);
    put_vec(w, hdr(h, SM_HDR_LENS_U), lu, 3);
    put_vec(w, hdr(h, SM_HDR_LENS_V), lv, 3);
    float eps = 0.0f;
    for (int k = 0; k < 3; k++)
        eps = fmaxf(eps, fmaxf(fabsf(s->bounds_min[k]), fabsf(s->bounds_max[k])));
    put_f32(w, hdr(h, SM_HDR_EPSILON), eps);
    put_u32(w, hdr(h, SM_HDR_NEEDS), s->needs);
    put_vec(w, hdr(h, SM_HDR_BOUNDS_MIN), s->bounds_min, 3);
    put_vec(w, hdr(h, SM_HDR_BOUNDS_MAX), s->bounds_max, 3);
}

enum { PACK_AHEAD = 16 };

/* The BVH nodes, then the primitives in leaf order, so a leaf's primitives are one contiguous run. */
static void pack_geometry(Writer *w, const Scene *s, const Bvh *bvh, const Layout *l)
{
    uint32_t nodes = l->nodes, prims = l->prims;
    for (uint32_t i = 0; i < bvh->nnodes; i++) {
        const BvhNode *n = &bvh->nodes[i];
        put_vec(w, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_BMIN), n->bmin, 3);
        put_vec(w, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_BMAX), n->bmax, 3);
        put_u32(w, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_FIRST), n->first);
        put_u32(w, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_INFO),
                n->count > 0 ? n->count : (SM_NODE_INNER | n->axis));
    }
    for (uint32_t i = 0; i < l->nprims; i++) {
        uint32_t src = bvh->prim_index[i];
        /* leaf order reads the triangles out of order: most of this loop's time was waiting for
         * them, so the triangle PACK_AHEAD places on is requested now (both lines it may span) */
        if (i + PACK_AHEAD < l->nprims) {
            uint32_t ahead = bvh->prim_index[i + PACK_AHEAD];
            const float *v = &s->pos[9 * (size_t)(ahead < s->ntris ? ahead : 0)];
            __builtin_prefetch(v);
            __builtin_prefetch(v + 8);
        }
        if (src < s->ntris) {
            put_vec(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_V0), &s->pos[9 * src], 9);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_MAT), s->tri_material[src]);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_KIND), 0);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_SRC), src);
        } else {
            const SceneSphere *sp = &s->spheres[src - s->ntris];
            put_vec(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_V0), sp->center, 3);
            put_f32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_V1), sp->radius);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_MAT), (uint32_t)sp->material);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_KIND), 1);
            put_u32(w, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_SRC), src - s->ntris);
        }
    }
}

/* The material records (and their extension records when emissive textures are packed). */
static void pack_materials(Writer *w, const Scene *s, const Layout *l)
{
    uint32_t mats = l->mats, matx = l->matx;
    for (uint32_t i = 0; i < s->nmaterials; i++) {
        const SceneMaterial *m = &s->materials[i];
        put_u32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_KIND), (uint32_t)m->kind);
        put_vec(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_BASE), m->base_color, 3);
        put_u32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_TEX), (uint32_t)m->base_texture);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_ROUGHNESS), m->roughness);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_METALLIC), m->metallic);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_IOR), m->ior);
        put_vec(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_EMISSION), m->emission, 3);
        put_u32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_ALPHA_MODE), (uint32_t)m->alpha_mode);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_ALPHA_CUT), m->alpha_cutoff);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_ALPHA), m->alpha);
        put_f32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_TRANSMISSION), m->transmission);
        put_u32(w, sm_rec(mats, SM_MAT_WORDS, i, SM_MAT_DOUBLE_SIDED), m->double_sided ? 1u : 0u);
        if (matx)
            put_u32(w, sm_rec(matx, SM_MATX_WORDS, i, SM_MATX_EMIT_TEX), (uint32_t)emissive_texture(s, m));
    }
}

/* The texture records and their texels, sRGB-encoded 8-bit RGBA words. */
static void pack_textures(Writer *w, const Scene *s, const Layout *l)
{
    uint32_t texs = l->texs;
    SrgbCache *cache = s->ntextures ? calloc(1, sizeof *cache) : NULL; /* NULL: uncached, same bytes */
    for (uint32_t t = 0; t < s->ntextures; t++) {
        const SceneTexture *tx = &s->textures[t];
        put_u32(w, sm_rec(texs, SM_TEX_WORDS, t, SM_TEX_WIDTH), (uint32_t)tx->width);
        put_u32(w, sm_rec(texs, SM_TEX_WORDS, t, SM_TEX_HEIGHT), (uint32_t)tx->height);
        put_u32(w, sm_rec(texs, SM_TEX_WORDS, t, SM_TEX_TEXELS), l->texels[t]);
        size_t n = (size_t)tx->width * (size_t)tx->height;
        for (size_t i = 0; i < n; i++) {
            const float *c = &tx->rgba[4 * i];
            float a = c[3] <= 0.0f ? 0.0f : (c[3] >= 1.0f ? 1.0f : c[3]);
            uint32_t word = (uint32_t)srgb_encode8_cached(cache, c[0]) |
                            (uint32_t)srgb_encode8_cached(cache, c[1]) << 8 |
                            (uint32_t)srgb_encode8_cached(cache, c[2]) << 16 | (uint32_t)lrintf(a * 255.0f) << 24;
            put_u32(w, l->texels[t] + 4u * (uint32_t)i, word);
        }
    }
    free(cache);
}

/* The file's lights: records 0 .. nlights-1 of the light table. */
static void pack_file_lights(Writer *w, const Scene *s, const Layout *l)
{
    uint32_t lights = l->lights;
    for (uint32_t li = 0; li < s->nlights; li++) {
        const SceneLight *sl = &s->lights[li];
        float rad[3] = {sl->color[0] * sl->intensity, sl->color[1] * sl->intensity, sl->color[2] * sl->intensity};
        uint32_t kind = sl->kind == SCENE_LIGHT_POINT ? SM_LIGHT_POINT
                      : sl->kind == SCENE_LIGHT_SPOT ? SM_LIGHT_SPOT
                      : sl->kind == SCENE_LIGHT_DIRECTIONAL ? SM_LIGHT_DIRECTIONAL : SM_LIGHT_QUAD;
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_KIND), kind);
        put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_RADIANCE), rad, 3);
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_TEX), (uint32_t)-1);
        if (kind == SM_LIGHT_DIRECTIONAL) {
            put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_P), sl->direction, 3);
        } else {
            put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_P), sl->position, 3);
        }
        if (kind == SM_LIGHT_SPOT) {
            put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_E1), sl->direction, 3);
            put_f32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_COS_INNER), cosf(sl->inner_cone));
            put_f32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_COS_OUTER), cosf(sl->outer_cone));
        }
        if (kind == SM_LIGHT_QUAD) {
            put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_E1), sl->edge_u, 3);
            put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_E2), sl->edge_v, 3);
            float cx = sl->edge_u[1] * sl->edge_v[2] - sl->edge_u[2] * sl->edge_v[1];
            float cy = sl->edge_u[2] * sl->edge_v[0] - sl->edge_u[0] * sl->edge_v[2];
            float cz = sl->edge_u[0] * sl->edge_v[1] - sl->edge_u[1] * sl->edge_v[0];
            put_f32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_AREA), sqrtf(cx * cx + cy * cy + cz * cz));
        }
    }
}

/* Emissive triangles become triangle lights, after the file's lights. */
static void pack_emissive_lights(Writer *w, const Scene *s, const Layout *l)
{
    uint32_t lights = l->lights, li = s->nlights;
    for (uint32_t e = 0; e < s->nemissive; e++, li++) {
        uint32_t t = s->emissive_tris[e];
        const float *p = &s->pos[9 * t];
        const SceneMaterial *m = &s->materials[s->tri_material[t]];
        float e1[3] = {p[3] - p[0], p[4] - p[1], p[5] - p[2]}, e2[3] = {p[6] - p[0], p[7] - p[1], p[8] - p[2]};
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_KIND), SM_LIGHT_TRIANGLE);
        put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_P), p, 3);
        put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_E1), e1, 3);
        put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_E2), e2, 3);
        put_vec(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_RADIANCE), m->emission, 3);
        put_f32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_AREA), tri_area(p));
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_TWO_SIDED), m->double_sided ? 1u : 0u);
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_TEX),
                l->emit_tex ? (uint32_t)emissive_texture(s, m) : (uint32_t)-1);
        put_u32(w, sm_rec(lights, SM_LIGHT_WORDS, li, SM_LIGHT_SRC), t);
    }
}

/* n floats from src at address at, when the table is present (at != 0): their bytes as they are,
 * in one copy (put_f32 stores a float's bytes too). */
static void pack_floats(Writer *w, uint32_t at, const float *src, uint32_t n)
{
    if (at && n)
        memcpy(w->mem + (at - w->base), src, sizeof(float) * (size_t)n);
}

/* Per-vertex attributes (normals, UVs, emissive UVs, colours) and the sRGB decoding table. */
static void pack_attributes(Writer *w, const Scene *s, const Layout *l)
{
    pack_floats(w, l->normals, s->nrm, 9 * s->ntris);
    pack_floats(w, l->uvs, s->uv, 6 * s->ntris);
    pack_floats(w, l->emit_uvs, s->uv_emit, 6 * s->ntris);
    pack_floats(w, l->colors, s->col, 9 * s->ntris);
    for (int c = 0; c < 256; c++)
        put_f32(w, l->lut + 4u * (uint32_t)c, srgb_decode8(c));
}

int pack_scene(const Scene *s, const BvhParams *bp, uint32_t base, PackedScene *out, char *err,
               size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (base % 64) {
        snprintf(err, errlen, "pack: base address 0x%x is not a multiple of 64", base);
        return -1;
    }
    uint32_t nprims = s->ntris + s->nspheres;
    if (pack_build_bvh(s, bp, nprims, &out->bvh, err, errlen) != 0)
        return -1;
    /* Emissive triangles and file lights become light records. */
    Layout l = {.nprims = nprims, .nnodes = out->bvh.nnodes, .nlights = s->nlights + s->nemissive};
    Writer w = {NULL, 0, 0, base, 0};
    if (pack_reserve(&w, s, &l, err, errlen) != 0) {
        free(w.mem);
        bvh_free(&out->bvh);
        return -1;
    }
    pack_header(&w, s, &l);
    pack_geometry(&w, s, &out->bvh, &l);
    pack_materials(&w, s, &l);
    pack_textures(&w, s, &l);
    free(l.texels);
    pack_file_lights(&w, s, &l);
    pack_emissive_lights(&w, s, &l);
    pack_attributes(&w, s, &l);

    out->mem = w.mem;
    out->size = (uint32_t)w.size;
    out->base = base;
    out->nprims = nprims;
    out->nspheres = s->nspheres;
    out->nlights = l.nlights;
    return 0;
}

/* KDNODE INFO keeps an index in 30 bits (the low 2 hold the axis or the leaf tag). The tree's
 * other invariants are kd_check's. */
static int kd_indices_fit(const KdTree *t, char *err, size_t errlen)
{
    for (uint32_t i = 0; i < t->nnodes; i++)
        if (t->nodes[i].a > SM_KD_MAX_INDEX) {
            snprintf(err, errlen, "pack: kd-tree node %u: %s %u does not fit the 30 bits of KDNODE INFO", i,
                     t->nodes[i].axis == KD_LEAF ? "leaf-list index" : "child index", t->nodes[i].a);
            return -1;
        }
    return 0;
}

static void kd_write(Writer *w, const KdTree *t, uint32_t nodes, uint32_t prims)
{
    for (uint32_t i = 0; i < t->nnodes; i++) {
        const KdNode *n = &t->nodes[i];
        uint32_t split_at = sm_rec(nodes, SM_KDNODE_WORDS, i, SM_KDNODE_SPLIT);
        if (n->axis == KD_LEAF)
            put_u32(w, split_at, n->count);
        else
            put_f32(w, split_at, n->split);
        put_u32(w, sm_rec(nodes, SM_KDNODE_WORDS, i, SM_KDNODE_INFO),
                n->a << SM_KD_SHIFT | (n->axis == KD_LEAF ? SM_KD_LEAF : n->axis));
    }
    for (uint32_t r = 0; r < t->nrefs; r++)
        put_u32(w, prims + 4u * r, t->prims[r]);
    uint32_t h = w->base;
    put_u32(w, hdr(h, SM_HDR_KD_NODES), nodes);
    put_u32(w, hdr(h, SM_HDR_KD_PRIMS), prims);
    put_u32(w, hdr(h, SM_HDR_KD_NNODES), t->nnodes);
    put_vec(w, hdr(h, SM_HDR_KD_BMIN), t->bmin, 3);
    put_vec(w, hdr(h, SM_HDR_KD_BMAX), t->bmax, 3);
}

int pack_add_kd(PackedScene *p, const KdTree *t, char *err, size_t errlen)
{
    if (sm_u32(p, sm_hdr(p, SM_HDR_KD_NODES)) != 0) {
        snprintf(err, errlen, "pack: the scene already has a kd-tree");
        return -1;
    }
    if (t->nprims != p->nprims) {
        snprintf(err, errlen, "pack: the kd-tree was built over %u primitives; the scene has %u", t->nprims,
                 p->nprims);
        return -1;
    }
    if (kd_indices_fit(t, err, errlen) != 0)
        return -1;
    Writer w = {p->mem, p->size, p->size, p->base, 0};
    uint32_t nodes = w_alloc(&w, (size_t)SM_KDNODE_WORDS * t->nnodes);
    uint32_t prims = w_alloc(&w, t->nrefs);
    p->mem = w.mem; /* possibly moved by realloc; the bytes up to p->size are the same */
    if (w.oom) {
        snprintf(err, errlen, "pack: out of memory for a kd-tree of %u nodes", t->nnodes);
        return -1;
    }
    if (w.size > (size_t)UINT32_MAX - p->base) {
        snprintf(err, errlen,
                 "pack: a kd-tree of %u nodes and %u leaf-list entries takes the scene past 4 GiB of addresses "
                 "(%zu bytes from 0x%x)", t->nnodes, t->nrefs, w.size, p->base);
        return -1;
    }
    kd_write(&w, t, nodes, prims);
    p->size = (uint32_t)w.size;
    p->kd_depth = t->depth;
    return 0;
}

void pack_free(PackedScene *p)
{
    if (p->host)
        p->host->free(p->host);
    free(p->mem);
    bvh_free(&p->bvh);
    memset(p, 0, sizeof *p);
}

int pack_load_file(const char *path, int width, int height, int spp, Scene *s, PackedScene *p, char *err,
                   size_t errlen)
{
    memset(p, 0, sizeof *p);
    if (scene_load(path, s, err, errlen) != 0)
        return -1;
    if (width > 0)
        s->render.width = width;
    if (height > 0)
        s->render.height = height;
    if (spp > 0)
        s->render.spp = spp;
    BvhParams bp;
    bvh_default_params(&bp);
    if (pack_scene(s, &bp, 0, p, err, errlen) != 0) {
        scene_free(s);
        return -1;
    }
    return 0;
}
