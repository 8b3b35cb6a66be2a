/* sim/ref_trace.c -- the golden model's ray/box, ray/triangle and ray/sphere tests and its BVH
 * traversal over a packed scene, with the optional per-set counts of rays per node.
 *
 * Owns: the reference arithmetic for ray queries. Every expression is binary32 and evaluated in
 * the order written (the build uses ISO C mode, so no contraction into fused multiply-adds),
 * with the ISA's min/max NaN rule, so the assembly kernels can reproduce each value with the
 * same sequence of instructions. Must not: shade, sample or allocate per query in the common
 * case.
 */
#include "ref_trace.h"

#include "ref_qtree.h"
#include "util.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Conservative far bound for the slab test: 1 + 2 gamma(3) with gamma(n) = n eps / (1 - n eps)
 * (Ize, "Robust BVH Ray Traversal", JCGT 2013), so rounding in the slab distances cannot make a
 * ray miss a box it touches. */
#define REF_SLAB_FAR_SCALE 1.00000072f

void ref_sanitize_dir(float *dir)
{
    for (int k = 0; k < 3; k++)
        if (fabsf(dir[k]) < FLT_MIN)
            dir[k] = copysignf(FLT_MIN, dir[k]);
}

void ref_inv_dir(const float *dir, float *inv)
{
    for (int k = 0; k < 3; k++)
        inv[k] = 1.0f / dir[k];
}

#if defined(__SSE2__)
/* The slab test with its three axes in the lanes of one SSE register (x86-64 always has SSE2).
 * Each lane computes the scalar expressions: _mm_min_ps(c, b) is c < b ? c : b, ref_fmin(b, c)
 * exactly, NaN rule included. Lane 3 holds a NaN origin, so its slab distances are NaN and
 * neutral: ref_fmax(tn, NaN) keeps tn and ref_fmin(tf, NaN) keeps tf, as the scalar chain skips
 * a NaN axis. The chains over the axes become lane reductions: tn never is NaN (it starts at 0
 * and only takes a larger number) and tf is NaN in every lane or in none (only when tmax is), so
 * max and min reach the same values in any order, and the answer tn <= tf is the same; the only
 * values an order could change are the signs of zeros, which <= does not see. */
#include <emmintrin.h>

typedef struct BoxRay {
    __m128 org, inv;           /* origin x, y, z, NaN; inverse direction x, y, z, 0 */
} BoxRay;

static inline void box_ray(BoxRay *b, const float *org, const float *inv_dir)
{
    b->org = _mm_setr_ps(org[0], org[1], org[2], NAN);
    b->inv = _mm_setr_ps(inv_dir[0], inv_dir[1], inv_dir[2], 0.0f);
}

/* The far end of the ray for box tests, in every lane: tmax (the closest hit so far) widened by
 * REF_HIT_SCALE, because a hit distance from the triangle test and a box's entry distance from
 * the slab test round differently and a box whose entry rounds up past the hit could otherwise
 * hide a closer or tied hit. A traversal makes it when tmax changes. */
typedef __m128 BoxFar;

static inline BoxFar box_far(float tmax)
{
    return _mm_set1_ps(tmax * REF_HIT_SCALE);
}

/* bmin, bmax: x, y, z in lanes 0-2; lane 3 any number (not a denormal, preferably: a denormal
 * operand is slow on some hosts, whatever its lane). */
static inline int box_hit_v(__m128 bmin, __m128 bmax, const BoxRay *b, BoxFar tf)
{
    __m128 t0 = _mm_mul_ps(_mm_sub_ps(bmin, b->org), b->inv);
    __m128 t1 = _mm_mul_ps(_mm_sub_ps(bmax, b->org), b->inv);
    __m128 lo = _mm_min_ps(t1, t0);                                         /* ref_fmin(t0, t1) */
    __m128 hi = _mm_mul_ps(_mm_max_ps(t1, t0), _mm_set1_ps(REF_SLAB_FAR_SCALE));
    __m128 tn = _mm_max_ps(lo, _mm_setzero_ps());                           /* ref_fmax(0, lo) */
    tf = _mm_min_ps(hi, tf);                                                /* ref_fmin(tf, hi) */
    tn = _mm_max_ps(tn, _mm_movehl_ps(tn, tn));
    tn = _mm_max_ss(tn, _mm_shuffle_ps(tn, tn, 1));
    tf = _mm_min_ps(tf, _mm_movehl_ps(tf, tf));
    tf = _mm_min_ss(tf, _mm_shuffle_ps(tf, tf, 1));
    return _mm_cvtss_f32(tn) <= _mm_cvtss_f32(tf);
}

/* A packed BVH node's box (scenes/layout.def: BMIN at word 0, BMAX at word 3). */
_Static_assert(SM_NODE_BMIN == 0 && SM_NODE_BMAX == 3 && SM_NODE_WORDS == 8,
               "box_hit_node reads BMIN and BMAX with two 4-word loads inside the 8-word node");
static inline int box_hit_node(const uint8_t *node, const BoxRay *b, BoxFar tf)
{
    const __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    __m128 bmin = _mm_loadu_ps((const float *)node);               /* lane 3: BMAX x */
    __m128 bmax = _mm_and_ps(_mm_loadu_ps((const float *)node + 3), xyz); /* lane 3: FIRST -> 0 */
    return box_hit_v(bmin, bmax, b, tf);
}

int ref_hit_box(const float *bmin, const float *bmax, const float *org, const float *inv_dir,
                float tmax)
{
    BoxRay b;
    box_ray(&b, org, inv_dir);
    return box_hit_v(_mm_setr_ps(bmin[0], bmin[1], bmin[2], 0.0f), _mm_setr_ps(bmax[0], bmax[1], bmax[2], 0.0f),
                     &b, box_far(tmax));
}

#if defined(__AVX__)
/* Two sibling nodes' slab tests at once (walk_fast): box_hit_v's lanes, node c in lanes 0-3 and
 * node c + 1 in lanes 4-7, each half reduced on its own -- the same operations on the same values,
 * so the same answers and the same entry distances. Only with AVX: a build for the baseline CPU
 * (PORTABLE=1) measured the pair walk with two SSE tests slower than walk_body, so it keeps that. */
#include <immintrin.h>
#define REF_FAST_WALK 1

typedef struct BoxRay2 {
    __m256 org, inv;
} BoxRay2;

static inline void box_ray2(BoxRay2 *b2, const BoxRay *b)
{
    b2->org = _mm256_set_m128(b->org, b->org);
    b2->inv = _mm256_set_m128(b->inv, b->inv);
}

typedef __m256 BoxFar2;

static inline BoxFar2 box_far2(float tmax)
{
    return _mm256_set1_ps(tmax * REF_HIT_SCALE);
}

/* c: node c's first byte (node c + 1 follows it: siblings are adjacent, scenes/layout.def). Bit 0 /
 * bit 1: node c / c + 1 hit; tn_out: their entry distances, box_hit_v's tn (never NaN). */
static inline unsigned box_hit_pair(const uint8_t *c, const BoxRay2 *b, BoxFar2 tf, float tn_out[2])
{
    const float *f = (const float *)c;
    const __m256 xyz = _mm256_castsi256_ps(_mm256_setr_epi32(-1, -1, -1, 0, -1, -1, -1, 0));
    __m256 bmin = _mm256_loadu2_m128(f + SM_NODE_WORDS, f);                         /* lanes 3, 7: BMAX x */
    __m256 bmax = _mm256_and_ps(_mm256_loadu2_m128(f + SM_NODE_WORDS + 3, f + 3), xyz); /* FIRST -> 0 */
    __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(bmin, b->org), b->inv);
    __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(bmax, b->org), b->inv);
    __m256 lo = _mm256_min_ps(t1, t0);
    __m256 hi = _mm256_mul_ps(_mm256_max_ps(t1, t0), _mm256_set1_ps(REF_SLAB_FAR_SCALE));
    __m256 tn = _mm256_max_ps(lo, _mm256_setzero_ps());
    tf = _mm256_min_ps(hi, tf);
    tn = _mm256_max_ps(tn, _mm256_permute_ps(tn, 0x4E));
    tn = _mm256_max_ps(tn, _mm256_permute_ps(tn, 0xB1));
    tf = _mm256_min_ps(tf, _mm256_permute_ps(tf, 0x4E));
    tf = _mm256_min_ps(tf, _mm256_permute_ps(tf, 0xB1));
    unsigned m = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ));
    tn_out[0] = _mm256_cvtss_f32(tn);
    tn_out[1] = _mm_cvtss_f32(_mm256_extractf128_ps(tn, 1));
    return (m & 1u) | (m >> 3 & 2u);
}
#endif
#else
typedef struct BoxRay {
    float org[3], inv[3];
} BoxRay;

static inline void box_ray(BoxRay *b, const float *org, const float *inv_dir)
{
    for (int k = 0; k < 3; k++) {
        b->org[k] = org[k];
        b->inv[k] = inv_dir[k];
    }
}

typedef float BoxFar;      /* as above, one float */

static inline BoxFar box_far(float tmax)
{
    return tmax * REF_HIT_SCALE;
}

static inline int box_hit(const float *bmin, const float *bmax, const float *org, const float *inv_dir,
                          BoxFar far)
{
    float tn = 0.0f, tf = far;
    for (int k = 0; k < 3; k++) {
        /* inv_dir is finite (sanitized directions), so no 0 x inf = NaN can arise here. */
        float t0 = (bmin[k] - org[k]) * inv_dir[k];
        float t1 = (bmax[k] - org[k]) * inv_dir[k];
        float lo = ref_fmin(t0, t1);
        float hi = ref_fmax(t0, t1) * REF_SLAB_FAR_SCALE;
        tn = ref_fmax(tn, lo);
        tf = ref_fmin(tf, hi);
    }
    return tn <= tf;
}

static inline int box_hit_node(const uint8_t *node, const BoxRay *b, BoxFar far)
{
    float box[6];
    memcpy(box, node + 4 * SM_NODE_BMIN, sizeof box);
    return box_hit(box, box + 3, b->org, b->inv, far);
}

int ref_hit_box(const float *bmin, const float *bmax, const float *org, const float *inv_dir,
                float tmax)
{
    return box_hit(bmin, bmax, org, inv_dir, box_far(tmax));
}
#endif

void ref_ray_prepare(RefRayPre *R, const RefRay *r)
{
    for (int k = 0; k < 3; k++) {
        R->org[k] = r->org[k];
        R->dir[k] = r->dir[k];
    }
    ref_sanitize_dir(R->dir);
    const float *d = R->dir;
    float ax = fabsf(d[0]), ay = fabsf(d[1]), az = fabsf(d[2]);
    int kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) { /* keep the winding, so the sign of det means the same side */
        int tmp = kx;
        kx = ky;
        ky = tmp;
    }
    R->kx = kx;
    R->ky = ky;
    R->kz = kz;
    R->sx = d[kx] / d[kz];
    R->sy = d[ky] / d[kz];
    R->sz = 1.0f / d[kz];
}

/* Watertight ray/triangle test after Woop, Benthin and Wald, "Watertight Ray/Triangle
 * Intersection", JCGT 2(1), 2013: shear and scale so the ray runs along +z from the origin,
 * then 2D edge functions whose signs are computed identically for the two triangles sharing an
 * edge, so a ray through an edge or vertex hits at least one of them. Edge functions that are
 * exactly zero count as inside (the conservative choice; the paper's double-precision re-test
 * is left out because the simulated machine has no doubles: it cannot create leaks, only
 * report a hit on both triangles of an edge, and the closest-hit tie rule picks one).
 * Hits must satisfy 0 < t < tmax; t, u, v are written whenever det != 0 and T is in range. */
static inline int tri_hit(const RefRayPre *R, const float *v0, const float *v1, const float *v2, float tmax,
                          float *t, float *u, float *v)
{
    int kx = R->kx, ky = R->ky, kz = R->kz;
    float sx = R->sx, sy = R->sy, sz = R->sz;
    /* Only the components the test reads; each is the same difference as in the whole vector. */
    float Akx = v0[kx] - R->org[kx], Aky = v0[ky] - R->org[ky], Akz = v0[kz] - R->org[kz];
    float Bkx = v1[kx] - R->org[kx], Bky = v1[ky] - R->org[ky], Bkz = v1[kz] - R->org[kz];
    float Ckx = v2[kx] - R->org[kx], Cky = v2[ky] - R->org[ky], Ckz = v2[kz] - R->org[kz];
    float Ax = Akx - sx * Akz, Ay = Aky - sy * Akz;
    float Bx = Bkx - sx * Bkz, By = Bky - sy * Bkz;
    float Cx = Ckx - sx * Ckz, Cy = Cky - sy * Ckz;
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    /* One branch for the six comparisons (| and & instead of || and &&: the same answer, and a
     * mispredicted branch per comparison is what a miss would otherwise cost). */
    if (((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f)))
        return 0;
    float det = U + V + W;
    if (det == 0.0f)
        return 0;
    float Az = sz * Akz, Bz = sz * Bkz, Cz = sz * Ckz;
    float T = U * Az + V * Bz + W * Cz;
    if (det < 0.0f) { /* seen from behind: flip signs so the range test below holds for both */
        T = -T;
        det = -det;
        U = -U;
        V = -V;
        W = -W;
    }
    /* T must exceed its rounding error, which grows with the vertices' depths along the ray
     * (Az, Bz, Cz), not with t: a ray leaving a large triangle from an offset origin just above
     * it would otherwise "hit" it at a tiny t of either sign (docs/numerics.md). */
    float zmax = ref_fmax(ref_fmax(fabsf(Az), fabsf(Bz)), fabsf(Cz));
    float tlo = zmax * REF_T_ROUND * det;
    if (!(T > tlo) | !(T < tmax * det))
        return 0;
    float rcp = 1.0f / det;
    *t = T * rcp;
    *u = V * rcp;
    *v = W * rcp;
    return *t > 0.0f && *t < tmax;
}

int ref_hit_triangle(const float *v0, const float *v1, const float *v2, const RefRay *r,
                     float *t, float *u, float *v)
{
    RefRayPre R;
    ref_ray_prepare(&R, r);
    return tri_hit(&R, v0, v1, v2, r->tmax, t, u, v);
}

/* Ray/sphere with the discriminant computed from the closest-approach vector (Haines,
 * Guenther and Akenine-Moeller, "Precision Improvements for Ray/Sphere Intersection", Ray
 * Tracing Gems, 2019), which keeps small spheres far away from losing all precision. */
static int sph_hit(const RefRayPre *R, const float *center, float radius, float tmax, float *t)
{
    const float *d = R->dir;
    float oc[3] = {R->org[0] - center[0], R->org[1] - center[1], R->org[2] - center[2]};
    float a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (!(a > 0.0f))
        return 0;
    float b = -(oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2]); /* a x closest-approach parameter */
    float s = b / a;
    float l[3] = {oc[0] + s * d[0], oc[1] + s * d[1], oc[2] + s * d[2]};
    float r2 = radius * radius;
    float disc = a * (r2 - (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]));
    if (disc < 0.0f)
        return 0;
    float c = (oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2]) - r2;
    float q = b + copysignf(sqrtf(disc), b);
    if (q == 0.0f)
        return 0;
    float t0 = c / q, t1 = q / a;
    float lo = ref_fmin(t0, t1), hi = ref_fmax(t0, t1);
    if (lo > 0.0f && lo < tmax) {
        *t = lo;
        return 1;
    }
    if (hi > 0.0f && hi < tmax) {
        *t = hi;
        return 1;
    }
    return 0;
}

int ref_hit_sphere(const float *center, float radius, const RefRay *r, float *t)
{
    RefRayPre R;
    ref_ray_prepare(&R, r);
    return sph_hit(&R, center, radius, r->tmax, t);
}

int ref_count_init(RefSetCount *c, const PackedScene *p)
{
    uint32_t nnodes = sm_u32(p, sm_hdr(p, SM_HDR_NNODES));
    size_t nn = nnodes ? nnodes : 1;
    memset(c, 0, sizeof *c);
    c->p = p;
    c->node_rays = calloc(nn, sizeof *c->node_rays);
    c->leaf_rays = calloc(nn, sizeof *c->leaf_rays);
    c->touched = malloc(nn * sizeof *c->touched);
    if (c->node_rays && c->leaf_rays && c->touched)
        return 0;
    ref_count_free(c);
    return -1;
}

void ref_count_free(RefSetCount *c)
{
    free(c->node_rays);
    free(c->leaf_rays);
    free(c->touched);
    memset(c, 0, sizeof *c);
}

void ref_count_close(RefSetCount *c, uint32_t simd, uint64_t *node_steps, uint64_t *leaf_steps)
{
    uint32_t nodes = sm_u32(c->p, sm_hdr(c->p, SM_HDR_NODES));
    const uint64_t prim0 = c->line ? sm_u32(c->p, sm_hdr(c->p, SM_HDR_PRIMS)) : 0;
    for (uint32_t i = 0; i < c->ntouched; i++) {
        uint32_t n = c->touched[i];
        *node_steps += (c->node_rays[n] + (uint64_t)simd - 1) / simd;
        if (c->line)
            c->line(c->line_ctx, sm_rec(nodes, SM_NODE_WORDS, n, 0), 4u * SM_NODE_WORDS);
        if (c->leaf_rays[n]) {
            /* a leaf entered: its primitives, one after another, on each group of N rays */
            uint32_t prims = sm_u32(c->p, sm_rec(nodes, SM_NODE_WORDS, n, SM_NODE_INFO));
            *leaf_steps += (c->leaf_rays[n] + (uint64_t)simd - 1) / simd * prims;
            if (c->line && prims) {
                const uint32_t first = sm_u32(c->p, sm_rec(nodes, SM_NODE_WORDS, n, SM_NODE_FIRST));
                c->line(c->line_ctx, prim0 + 4ull * SM_PRIM_WORDS * first, 4ull * SM_PRIM_WORDS * prims);
            }
        }
        c->node_rays[n] = c->leaf_rays[n] = 0;
    }
    c->ntouched = 0;
}

static void count_node(RefSetCount *c, uint32_t n)
{
    if (c->node_rays[n]++ == 0)
        c->touched[c->ntouched++] = n;
}

typedef struct Walk {
    uint32_t small[256];
    uint32_t *stack;
} Walk;

static uint32_t *walk_stack(Walk *w, const PackedScene *p)
{
    w->stack = p->bvh.depth + 2 <= 256 ? w->small : malloc(sizeof(uint32_t) * (p->bvh.depth + 2));
    return w->stack;
}

static void walk_done(Walk *w)
{
    if (w->stack != w->small)
        free(w->stack);
}

/* A packed primitive's words, read straight from the image (scene memory's layout,
 * scenes/layout.def): vertices (sphere: centre and radius) and kind. */
/* prims: the primitive array's first byte in p->mem. */
static inline int hit_prim(const uint8_t *prims, uint32_t i, const RefRayPre *R, float tmax, float *t, float *u,
                           float *v)
{
    PrimRec pr;
    prim_read(prims, i, &pr);
    if (pr.kind == 1) {
        *u = *v = 0.0f;
        return sph_hit(R, pr.g, pr.g[3], tmax, t);
    }
    return tri_hit(R, pr.g, pr.g + 3, pr.g + 6, tmax, t, u, v);
}

/* What both walks set up before the first node: no hit yet, the node and primitive arrays, the
 * per-ray record and the slab test's ray. 0 for a scene without nodes (nothing to walk). */
typedef struct WalkStart {
    const uint8_t *nodes, *prims;
    RefRayPre R;
    BoxRay B;
} WalkStart;

static inline __attribute__((always_inline)) int walk_start(const PackedScene *p, const RefRay *r, RefHit *hit,
                                                             WalkStart *ws)
{
    hit->prim = REF_NO_HIT;
    hit->t = r->tmax;
    hit->u = hit->v = 0.0f;
    if (sm_u32(p, sm_hdr(p, SM_HDR_NNODES)) == 0)
        return 0;
    ws->nodes = image_at(p, sm_u32(p, sm_hdr(p, SM_HDR_NODES)));
    ws->prims = image_at(p, sm_u32(p, sm_hdr(p, SM_HDR_PRIMS)));
    ref_ray_prepare(&ws->R, r);
    float inv[3];
    ref_inv_dir(ws->R.dir, inv);
    box_ray(&ws->B, ws->R.org, inv);
    return 1;
}

/* Depth-first walk; closest != 0 keeps searching for the nearest hit, else stops at the first.
 * count: where box tests and leaf entries are also counted (st->count), or NULL. Inlined into
 * both walks below, so the one without counts has no test for them on its per-node path. */
static inline __attribute__((always_inline)) int walk_body(const PackedScene *p, const RefRay *r, RefHit *hit,
                                                            int closest, RefTraceStats *st, RefSetCount *count)
{
    WalkStart ws;
    if (!walk_start(p, r, hit, &ws))
        return 0;
    const uint8_t *nodes = ws.nodes, *prims = ws.prims;
    const RefRayPre R = ws.R;
    const BoxRay B = ws.B;
    BoxFar far = box_far(r->tmax); /* boxes: the closest hit so far, widened */
    float ptmax = r->tmax;         /* primitives: tmax, then the tie probe past the closest hit */
    Walk w;
    uint32_t *stack = walk_stack(&w, p);
    if (!stack)
        abort(); /* out of memory for a traversal stack: nothing sensible to return */
    uint32_t sp = 0, n = 0;
    for (;;) {
        const uint8_t *nd = nodes + 4 * SM_NODE_WORDS * (size_t)n;
        if (st) {
            st->nodes_visited++;
            st->boxes_tested++;
        }
        if (count)
            count_node(count, n);
        if (box_hit_node(nd, &B, far)) {
            uint32_t info, first;
            memcpy(&info, nd + 4 * SM_NODE_INFO, sizeof info);
            memcpy(&first, nd + 4 * SM_NODE_FIRST, sizeof first);
            if (info & SM_NODE_INNER) {
                /* Front to back: the right child holds the larger centroids on the split axis.
                 * The far child waits on the stack; the near one, which a stack would pop at
                 * once, goes next straight from a register (the next box's load then does not
                 * wait for a store to the stack and a load from it). */
                uint32_t axis = info & 3u;
                int neg = R.dir[axis] < 0.0f;
                stack[sp++] = neg ? first : first + 1;
                n = neg ? first + 1 : first;
                continue;
            }
            if (count)
                count->leaf_rays[n]++; /* n was touched by its box test */
            for (uint32_t i = first; i < first + info; i++) {
                float t, u, v;
                if (st)
                    st->prims_tested++;
                /* Hits at exactly the best distance are still tested (ptmax) so that the lower
                 * primitive index wins a tie whatever the visiting order. */
                if (!hit_prim(prims, i, &R, ptmax, &t, &u, &v))
                    continue;
                if (ref_hit_keep(hit, t, u, v, i)) {
                    far = box_far(t);
                    if (closest)
                        ptmax = ref_tie_probe(t);
                }
                if (!closest) {
                    walk_done(&w);
                    return 1;
                }
            }
        }
        if (sp == 0)
            break;
        n = stack[--sp];
    }
    walk_done(&w);
    return hit->prim != REF_NO_HIT;
}

#if REF_FAST_WALK
/* A node waiting on the fast walk's stack, with the entry distance its box test gave. */
typedef struct Pending {
    uint32_t n;
    float tn;
} Pending;

/* walk_body without stats, the same hits bit for bit, faster: at an inner node both children's
 * boxes are tested at once (siblings are adjacent in the image, so one pair of loads), the near
 * child is visited next if hit and the far one waits on the stack with its entry distance tn if
 * hit. walk_body tests the far child's box only when it pops it, with the closest hit of that
 * moment; that test is tn <= min(far, the box's own far end), and the far end can only have
 * shrunk since the push, so "hit at the push and tn <= far at the pop" is the same answer. The
 * nodes whose boxes hit, their order and every primitive test are therefore walk_body's; only
 * the boxes tested and missed differ, which nobody counts here. */
static int walk_fast(const PackedScene *p, const RefRay *r, RefHit *hit, int closest)
{
    WalkStart ws;
    if (!walk_start(p, r, hit, &ws))
        return 0;
    const uint8_t *nodes = ws.nodes, *prims = ws.prims;
    const RefRayPre R = ws.R;
    const BoxRay B = ws.B;
    BoxRay2 B2;
    box_ray2(&B2, &B);
    if (!box_hit_node(nodes, &B, box_far(r->tmax)))
        return 0;
    float fars = r->tmax * REF_HIT_SCALE; /* box_far's value, for the test at a pop */
    BoxFar2 far2 = box_far2(r->tmax);
    float ptmax = r->tmax;
    Pending small[256], *stack = small;
    if (p->bvh.depth + 2 > 256 && !(stack = malloc(sizeof *stack * (p->bvh.depth + 2))))
        abort(); /* out of memory for a traversal stack: nothing sensible to return */
    uint32_t sp = 0, n = 0;
    for (;;) {
        const uint8_t *nd = nodes + 4 * SM_NODE_WORDS * (size_t)n;
        uint32_t info, first;
        memcpy(&info, nd + 4 * SM_NODE_INFO, sizeof info);
        memcpy(&first, nd + 4 * SM_NODE_FIRST, sizeof first);
        if (info & SM_NODE_INNER) {
            float tn[2];
            unsigned m = box_hit_pair(nodes + 4 * SM_NODE_WORDS * (size_t)first, &B2, far2, tn);
            /* A branch, not arithmetic, picks the near child: predicted, the next node's address
             * then waits only for `first`, not for the split axis and the direction's sign too. */
            if (R.dir[info & 3u] < 0.0f) {
                if (m & 1u)
                    stack[sp++] = (Pending){first, tn[0]};
                if (m & 2u) {
                    n = first + 1;
                    continue;
                }
            } else {
                if (m & 2u)
                    stack[sp++] = (Pending){first + 1, tn[1]};
                if (m & 1u) {
                    n = first;
                    continue;
                }
            }
        } else {
            for (uint32_t i = first; i < first + info; i++) {
                float t, u, v;
                if (!hit_prim(prims, i, &R, ptmax, &t, &u, &v))
                    continue;
                if (ref_hit_keep(hit, t, u, v, i)) {
                    fars = t * REF_HIT_SCALE;
                    far2 = box_far2(t);
                    if (closest)
                        ptmax = ref_tie_probe(t);
                }
                if (!closest) {
                    sp = 0;
                    break;
                }
            }
        }
        do {
            if (sp == 0)
                goto done;
            --sp;
        } while (!(stack[sp].tn <= fars));
        n = stack[sp].n;
    }
done:
    if (stack != small)
        free(stack);
    return hit->prim != REF_NO_HIT;
}

#endif



/* A pending node of the 4-wide walk: its reference and its box's entry distance. */
typedef struct QPending {
    uint32_t ref;
    float tn;
} QPending;

#if defined(__SSE2__) && !defined(REF_TRACE_SCALAR)
typedef struct QRay {
    __m128 o[3], inv[3];
    __m128 ko[3], s[3];     /* origin at kx, ky, kz; sx, sy, sz (tri_hit's) */
} QRay;

static inline void qray_make(QRay *q, const RefRayPre *R, const float *inv)
{
    for (int k = 0; k < 3; k++) {
        q->o[k] = _mm_set1_ps(R->org[k]);
        q->inv[k] = _mm_set1_ps(inv[k]);
    }
    q->ko[0] = _mm_set1_ps(R->org[R->kx]);
    q->ko[1] = _mm_set1_ps(R->org[R->ky]);
    q->ko[2] = _mm_set1_ps(R->org[R->kz]);
    q->s[0] = _mm_set1_ps(R->sx);
    q->s[1] = _mm_set1_ps(R->sy);
    q->s[2] = _mm_set1_ps(R->sz);
}

/* box_hit_v on the 4 slots at once, far = box_far's value: bit c set when slot c's box hits; tn[c] its entry distance. */
static inline unsigned qbox(const QNode *nd, const QRay *q, float far, float *tn_out)
{
    const __m128 zero = _mm_setzero_ps(), scale = _mm_set1_ps(REF_SLAB_FAR_SCALE), f = _mm_set1_ps(far);
#define QBOX_AXIS(k, tnk, tfk)                                                                   \
    __m128 tnk, tfk;                                                                             \
    {                                                                                            \
        __m128 t0 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(nd->b[k]), q->o[k]), q->inv[k]);          \
        __m128 t1 = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(nd->b[3 + k]), q->o[k]), q->inv[k]);      \
        tnk = _mm_max_ps(_mm_min_ps(t1, t0), zero);                                              \
        tfk = _mm_min_ps(_mm_mul_ps(_mm_max_ps(t1, t0), scale), f);                              \
    }
    QBOX_AXIS(0, tn0, tf0)
    QBOX_AXIS(1, tn1, tf1)
    QBOX_AXIS(2, tn2, tf2)
#undef QBOX_AXIS
    __m128 tn = _mm_max_ps(_mm_max_ps(tn0, tn1), tn2), tf = _mm_min_ps(_mm_min_ps(tf0, tf1), tf2);
    _mm_storeu_ps(tn_out, tn);
    return (unsigned)_mm_movemask_ps(_mm_cmple_ps(tn, tf)) & nd->valid;
}

/* tri_hit on the 4 lanes with tmax: bit l set when lane l hits; its T and det (after the flip), t, u, v. */
static inline unsigned qtri(const TriBlock *tb, const RefRayPre *R, const QRay *q, float tmax, float *Tl, float *detl,
                            float *tl, float *ul, float *vl)
{
    const __m128 zero = _mm_setzero_ps(), sign = _mm_set1_ps(-0.0f);
    int kx = R->kx, ky = R->ky, kz = R->kz;
    __m128 Akx = _mm_sub_ps(_mm_load_ps(tb->v[kx]), q->ko[0]), Aky = _mm_sub_ps(_mm_load_ps(tb->v[ky]), q->ko[1]),
           Akz = _mm_sub_ps(_mm_load_ps(tb->v[kz]), q->ko[2]);
    __m128 Bkx = _mm_sub_ps(_mm_load_ps(tb->v[3 + kx]), q->ko[0]),
           Bky = _mm_sub_ps(_mm_load_ps(tb->v[3 + ky]), q->ko[1]),
           Bkz = _mm_sub_ps(_mm_load_ps(tb->v[3 + kz]), q->ko[2]);
    __m128 Ckx = _mm_sub_ps(_mm_load_ps(tb->v[6 + kx]), q->ko[0]),
           Cky = _mm_sub_ps(_mm_load_ps(tb->v[6 + ky]), q->ko[1]),
           Ckz = _mm_sub_ps(_mm_load_ps(tb->v[6 + kz]), q->ko[2]);
    __m128 Ax = _mm_sub_ps(Akx, _mm_mul_ps(q->s[0], Akz)), Ay = _mm_sub_ps(Aky, _mm_mul_ps(q->s[1], Akz));
    __m128 Bx = _mm_sub_ps(Bkx, _mm_mul_ps(q->s[0], Bkz)), By = _mm_sub_ps(Bky, _mm_mul_ps(q->s[1], Bkz));
    __m128 Cx = _mm_sub_ps(Ckx, _mm_mul_ps(q->s[0], Ckz)), Cy = _mm_sub_ps(Cky, _mm_mul_ps(q->s[1], Ckz));
    __m128 U = _mm_sub_ps(_mm_mul_ps(Cx, By), _mm_mul_ps(Cy, Bx));
    __m128 V = _mm_sub_ps(_mm_mul_ps(Ax, Cy), _mm_mul_ps(Ay, Cx));
    __m128 W = _mm_sub_ps(_mm_mul_ps(Bx, Ay), _mm_mul_ps(By, Ax));
    __m128 out = _mm_and_ps(
        _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero)),
        _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero)));
    unsigned m = ~(unsigned)_mm_movemask_ps(out) & tb->valid;
    if (!m)
        return 0;
    __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
    __m128 Az = _mm_mul_ps(q->s[2], Akz), Bz = _mm_mul_ps(q->s[2], Bkz), Cz = _mm_mul_ps(q->s[2], Ckz);
    __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, Az), _mm_mul_ps(V, Bz)), _mm_mul_ps(W, Cz));
    __m128 flip = _mm_and_ps(_mm_cmplt_ps(det, zero), sign);
    T = _mm_xor_ps(T, flip);
    __m128 ok = _mm_cmpneq_ps(det, zero); /* det == 0 fails; NaN passes, as in tri_hit */
    det = _mm_xor_ps(det, flip);
    V = _mm_xor_ps(V, flip);
    W = _mm_xor_ps(W, flip);
    __m128 zmax = _mm_max_ps(_mm_andnot_ps(sign, Cz), _mm_max_ps(_mm_andnot_ps(sign, Bz), _mm_andnot_ps(sign, Az)));
    __m128 tlo = _mm_mul_ps(_mm_mul_ps(zmax, _mm_set1_ps(REF_T_ROUND)), det);
    __m128 tm = _mm_set1_ps(tmax);
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(T, tlo), _mm_cmplt_ps(T, _mm_mul_ps(tm, det))));
    __m128 rcp = _mm_div_ps(_mm_set1_ps(1.0f), det);
    __m128 t = _mm_mul_ps(T, rcp);
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(t, zero), _mm_cmplt_ps(t, tm)));
    m &= (unsigned)_mm_movemask_ps(ok);
    if (!m)
        return 0;
    _mm_storeu_ps(Tl, T);
    _mm_storeu_ps(detl, det);
    _mm_storeu_ps(tl, t);
    _mm_storeu_ps(ul, _mm_mul_ps(V, rcp));
    _mm_storeu_ps(vl, _mm_mul_ps(W, rcp));
    return m;
}
#else
/* Plain C: the same expressions lane by lane (ref_fmin / ref_fmax are the SSE min / max). */
typedef struct QRay {
    float o[3], inv[3];
} QRay;

static inline void qray_make(QRay *q, const RefRayPre *R, const float *inv)
{
    for (int k = 0; k < 3; k++) {
        q->o[k] = R->org[k];
        q->inv[k] = inv[k];
    }
}

static inline unsigned qbox(const QNode *nd, const QRay *q, float far, float *tn_out)
{
    unsigned m = 0;
    for (int c = 0; c < 4; c++) {
        float tn = 0.0f, tf = far;
        for (int k = 0; k < 3; k++) {
            float t0 = (nd->b[k][c] - q->o[k]) * q->inv[k];
            float t1 = (nd->b[3 + k][c] - q->o[k]) * q->inv[k];
            float lo = ref_fmin(t0, t1), hi = ref_fmax(t0, t1) * REF_SLAB_FAR_SCALE;
            float tnk = ref_fmax(0.0f, lo), tfk = ref_fmin(far, hi);
            tn = k ? ref_fmax(tn, tnk) : tnk;
            tf = k ? ref_fmin(tf, tfk) : tfk;
        }
        tn_out[c] = tn;
        m |= (unsigned)(tn <= tf) << c;
    }
    return m & nd->valid;
}

static inline unsigned qtri(const TriBlock *tb, const RefRayPre *R, const QRay *q, float tmax, float *Tl, float *detl,
                            float *tl, float *ul, float *vl)
{
    (void)q;
    int kx = R->kx, ky = R->ky, kz = R->kz;
    float sx = R->sx, sy = R->sy, sz = R->sz;
    unsigned m = 0;
    for (int l = 0; l < 4; l++) {
        if (!(tb->valid >> l & 1u))
            continue;
        float Akx = tb->v[kx][l] - R->org[kx], Aky = tb->v[ky][l] - R->org[ky], Akz = tb->v[kz][l] - R->org[kz];
        float Bkx = tb->v[3 + kx][l] - R->org[kx], Bky = tb->v[3 + ky][l] - R->org[ky],
              Bkz = tb->v[3 + kz][l] - R->org[kz];
        float Ckx = tb->v[6 + kx][l] - R->org[kx], Cky = tb->v[6 + ky][l] - R->org[ky],
              Ckz = tb->v[6 + kz][l] - R->org[kz];
        float Ax = Akx - sx * Akz, Ay = Aky - sy * Akz;
        float Bx = Bkx - sx * Bkz, By = Bky - sy * Bkz;
        float Cx = Ckx - sx * Ckz, Cy = Cky - sy * Ckz;
        float U = Cx * By - Cy * Bx;
        float V = Ax * Cy - Ay * Cx;
        float W = Bx * Ay - By * Ax;
        if (((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f)))
            continue;
        float det = U + V + W;
        if (det == 0.0f)
            continue;
        float Az = sz * Akz, Bz = sz * Bkz, Cz = sz * Ckz;
        float T = U * Az + V * Bz + W * Cz;
        if (det < 0.0f) {
            T = -T;
            det = -det;
            V = -V;
            W = -W;
        }
        float zmax = ref_fmax(ref_fmax(fabsf(Az), fabsf(Bz)), fabsf(Cz));
        float tlo = zmax * REF_T_ROUND * det;
        if (!(T > tlo) | !(T < tmax * det))
            continue;
        float rcp = 1.0f / det;
        float t = T * rcp;
        if (!(t > 0.0f && t < tmax))
            continue;
        Tl[l] = T;
        detl[l] = det;
        tl[l] = t;
        ul[l] = V * rcp;
        vl[l] = W * rcp;
        m |= 1u << l;
    }
    return m;
}
#endif

static inline int ray_finite(const RefRayPre *R)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(R->org[k]) || !isfinite(R->dir[k]))
            return 0;
    return 1;
}

/* The 4-wide walk (see above); -1 when the ray or the scene must take the binary walk. */
static int walk_quad(const PackedScene *p, const QTree *qt, const RefRay *r, RefHit *hit, int closest)
{
    WalkStart ws;
    if (!walk_start(p, r, hit, &ws))
        return 0;
    const RefRayPre R = ws.R;
    if (!ray_finite(&R))
        return -1;
    if (!box_hit_node(ws.nodes, &ws.B, box_far(r->tmax)))
        return 0;
    const uint8_t *prims = ws.prims;
    float inv[3];
    ref_inv_dir(R.dir, inv);
    QRay Q;
    qray_make(&Q, &R, inv);
    const unsigned oct = (unsigned)(R.dir[0] < 0.0f) | (unsigned)(R.dir[1] < 0.0f) << 1 |
                         (unsigned)(R.dir[2] < 0.0f) << 2;
    const QNode *qn = qt->q;
    const TriBlock *tbs = qt->tb;
    float fars = r->tmax * REF_HIT_SCALE; /* box_far's value */
    float ptmax = r->tmax;
    QPending small[256], *stack = small;
    if (qt->stack_len > 256 && !(stack = malloc(sizeof *stack * qt->stack_len)))
        abort(); /* out of memory for a traversal stack: nothing sensible to return */
    uint32_t sp = 0, ref = qt->root;
    for (;;) {
        if (!(ref & QLEAF)) {
            const QNode *nd = &qn[ref];
            float tn[4];
            unsigned m = qbox(nd, &Q, fars, tn);
            if (m & (m - 1)) {
                unsigned ord = nd->order[oct];
                for (int j = 3; j >= 0; j--) { /* far to near, so the nearest is popped first; branch-free */
                    unsigned c = ord >> (2 * j) & 3u;
                    stack[sp] = (QPending){nd->child[c], tn[c]};
                    sp += m >> c & 1u;
                }
            } else if (m) { /* one child hit: it goes next, straight from a register */
                ref = nd->child[__builtin_ctz(m)];
                continue;
            }
        } else {
            const TriBlock *tb = &tbs[ref & ~QLEAF];
            for (;; tb++) {
                if (tb->flags & QB_SPHERE) {
                    for (unsigned l = 0; l < 4; l++) {
                        float t, u, v;
                        if (!(tb->valid >> l & 1u) || !hit_prim(prims, tb->prim[l], &R, ptmax, &t, &u, &v))
                            continue;
                        if (ref_hit_keep(hit, t, u, v, tb->prim[l])) {
                            fars = t * REF_HIT_SCALE;
                            if (closest)
                                ptmax = ref_tie_probe(t);
                        }
                        if (!closest)
                            goto done;
                    }
                } else {
                    float T[4], det[4], t[4], u[4], v[4];
                    unsigned m = qtri(tb, &R, &Q, ptmax, T, det, t, u, v);
                    for (; m; m &= m - 1) {
                        unsigned l = (unsigned)__builtin_ctz(m);
                        /* tri_hit's tests of tmax, with the tmax of this moment */
                        if (!(T[l] < ptmax * det[l]) || !(t[l] < ptmax))
                            continue;
                        if (ref_hit_keep(hit, t[l], u[l], v[l], tb->prim[l])) {
                            fars = t[l] * REF_HIT_SCALE;
                            if (closest)
                                ptmax = ref_tie_probe(t[l]);
                        }
                        if (!closest)
                            goto done;
                    }
                }
                if (tb->flags & QB_LAST)
                    break;
            }
        }
        do {
            if (sp == 0)
                goto done;
            --sp;
        } while (!(stack[sp].tn <= fars));
        ref = stack[sp].ref;
    }
done:
    if (stack != small)
        free(stack);
    return hit->prim != REF_NO_HIT;
}

/* The binary walk without stats: the pair walk on AVX hosts, walk_body elsewhere. */
static int walk_binary(const PackedScene *p, const RefRay *r, RefHit *hit, int closest)
{
#if REF_FAST_WALK
    return walk_fast(p, r, hit, closest);
#else
    return walk_body(p, r, hit, closest, NULL, NULL);
#endif
}

/* Batches of rays (sfsim trace, run_trace, per_ray) ask without stats: the 4-wide walk, or the
 * binary one for a ray or scene it does not take. */
static int walk_bare(const PackedScene *p, const RefRay *r, RefHit *hit, int closest)
{
    const QTree *qt = ref_qtree_of(p);
    if (qt && qt->usable) {
        int rc = walk_quad(p, qt, r, hit, closest);
        if (rc >= 0)
            return rc;
    }
    return walk_binary(p, r, hit, closest);
}

static int walk_plain(const PackedScene *p, const RefRay *r, RefHit *hit, int closest, RefTraceStats *st)
{
    return walk_body(p, r, hit, closest, st, NULL);
}

static int walk_counted(const PackedScene *p, const RefRay *r, RefHit *hit, int closest, RefTraceStats *st)
{
    return walk_body(p, r, hit, closest, st, st->count);
}

static int walk(const PackedScene *p, const RefRay *r, RefHit *hit, int closest, RefTraceStats *st)
{
    if (!st)
        return walk_bare(p, r, hit, closest);
    return st->count ? walk_counted(p, r, hit, closest, st) : walk_plain(p, r, hit, closest, st);
}

void ref_closest_hit(const PackedScene *p, const RefRay *r, RefHit *hit, RefTraceStats *stats)
{
    walk(p, r, hit, 1, stats);
}

int ref_any_hit(const PackedScene *p, const RefRay *r, RefTraceStats *stats)
{
    RefHit h;
    return walk(p, r, &h, 0, stats);
}

int ref_hit_prim_pre(const PackedScene *p, uint32_t i, const RefRayPre *R, float tmax, float *t, float *u,
                     float *v)
{
    return hit_prim(image_at(p, sm_u32(p, sm_hdr(p, SM_HDR_PRIMS))), i, R, tmax, t, u, v);
}

int ref_hit_prim(const PackedScene *p, uint32_t i, const RefRay *r, float *t, float *u, float *v)
{
    RefRayPre R;
    ref_ray_prepare(&R, r);
    return ref_hit_prim_pre(p, i, &R, r->tmax, t, u, v);
}
