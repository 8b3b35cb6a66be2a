/* sim/ref_trace.h -- the golden model's ray queries over a packed scene: closest hit and any
 * hit, by BVH traversal with the watertight ray/triangle test and a NaN-safe slab test.
 *
 * Owns: the reference arithmetic the assembly kernels must reproduce (docs/golden-model.md):
 * binary32 only, operations in the order written, min/max with the ISA's NaN rule.
 * Must not: shade, sample or touch images.
 */
#ifndef SFSIM_REF_TRACE_H
#define SFSIM_REF_TRACE_H

#include <stdint.h>
#include <string.h>

#include "../scenes/pack.h"

#define REF_NO_HIT 0xFFFFFFFFu

typedef struct RefRay {
    float org[3], dir[3];
    float tmax;           /* hits must satisfy 0 < t < tmax */
} RefRay;

typedef struct RefHit {
    float t, u, v;        /* distance (in units of |dir|) and barycentrics of v1, v2 (spheres: 0) */
    uint32_t prim;        /* packed primitive index, or REF_NO_HIT */
} RefHit;

/* Rays per BVH node over a set of rays traced together -- a generation of the golden model --
 * from which the SIMD-step counts of docs/golden-model.md follow: a stream filter spends
 * ceil(rays / N) steps on a node's box test, and as many on each primitive of a leaf the rays
 * enter. One per thread; a query counts into it only when RefTraceStats.count points to it, and
 * closing a set costs O(nodes touched), never O(nodes). */
/* A piece of scene memory a walk read: addr (a byte offset in the packed image, scene memory's
 * address) and its size in bytes. */
typedef void (*RefLineSink)(void *ctx, uint64_t addr, uint64_t bytes);

typedef struct RefSetCount {
    const PackedScene *p;
    RefLineSink line;          /* when not NULL, told at each close of the scene memory the set
                                  read: each node box-tested, each entered leaf's primitives, in
                                  the order the set first touched the nodes */
    void *line_ctx;
    uint32_t *node_rays;       /* nnodes entries: rays of the set that box-tested node n */
    uint32_t *leaf_rays;       /* nnodes entries: rays of the set that entered leaf n (box hit) */
    uint32_t *touched;         /* the nodes with a non-zero node_rays, ntouched of them */
    uint32_t ntouched;
} RefSetCount;

/* 0, or -1 when out of memory (the caller says so); counts zeroed. */
int ref_count_init(RefSetCount *c, const PackedScene *p);
void ref_count_free(RefSetCount *c);
/* Close the set: add sum over touched nodes of ceil(node_rays / simd) to *node_steps and sum over
 * entered leaves of ceil(leaf_rays / simd) x (primitives in the leaf) to *leaf_steps (and tell
 * c->line what the set read), and zero the counts for the next set. simd >= 1. */
void ref_count_close(RefSetCount *c, uint32_t simd, uint64_t *node_steps, uint64_t *leaf_steps);

typedef struct RefTraceStats {
    uint64_t nodes_visited, boxes_tested, prims_tested;
    RefSetCount *count;        /* NULL, or where each box test and leaf entry is also counted */
} RefTraceStats;

/* Closest hit; ties in t go to the lower primitive index, so the answer does not depend on
 * traversal order. stats may be NULL. */
void ref_closest_hit(const PackedScene *p, const RefRay *r, RefHit *hit, RefTraceStats *stats);
/* Any hit with 0 < t < tmax (occlusion); returns 1 if occluded. */
int ref_any_hit(const PackedScene *p, const RefRay *r, RefTraceStats *stats);

/* Queries without stats walk a private, host-only 4-wide copy of p's BVH (sim/ref_trace.c), built
 * on the first such query and freed by pack_free; the same hits bit for bit. Its build time in
 * seconds (building it now if needed; -1 when out of memory), and whether p's queries use it
 * (0: p has no nodes or a child box outside its parent's, and they take the binary walk). */
double ref_trace_layout_seconds(const PackedScene *p);
int ref_trace_layout_usable(const PackedScene *p);

/* Test packed primitive i (triangle or sphere) with a sanitized ray: 1 with t, u, v on a hit
 * with 0 < t < r->tmax (the test every traversal uses). */
int ref_hit_prim(const PackedScene *p, uint32_t i, const RefRay *r, float *t, float *u, float *v);

/* What a ray's primitive tests depend on that no primitive changes: its sanitized direction
 * and the shear of the watertight triangle test (dominant axis kz, kx and ky in winding order,
 * sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1 / d[kz]). A traversal prepares it once per ray
 * instead of once per primitive; the tests read the same values, so the answers are the same. */
typedef struct RefRayPre {
    float org[3], dir[3];      /* dir sanitized (ref_sanitize_dir) */
    int kx, ky, kz;
    float sx, sy, sz;
} RefRayPre;

void ref_ray_prepare(RefRayPre *R, const RefRay *r);
/* ref_hit_prim of the ray R was prepared from with tmax in place of its own, bit for bit. */
int ref_hit_prim_pre(const PackedScene *p, uint32_t i, const RefRayPre *R, float tmax, float *t, float *u,
                     float *v);

/* The smallest T / det a triangle hit may have, relative to the largest depth of its vertices
 * along the ray: 2^-19, 32 times the unit roundoff (kernels/lib/isect.inc: T_ROUND_F). */
#define REF_T_ROUND 0x1p-19f

/* A traversal prunes a box, voxel or leaf segment only beyond the closest hit so far widened by
 * 2^-12: a triangle's computed t errs by up to many ulps when its vertices lie far away compared
 * with t (the error grows with their depths, as REF_T_ROUND says), and a box entered just past
 * the hit could hide a closer or tied hit, so that different structures returned different hits
 * (kernels: HIT_SCALE_F). Only pruning widens; a hit still needs t < tmax. */
#define REF_HIT_SCALE 1.000244140625f

/* Once a ray has a hit at t, primitives are tested up to t + 4 ulps (the integer add on the bits;
 * kernels: isect.inc), so that a primitive hit at exactly t -- a tie, won by the lower index --
 * or closer is always accepted whatever the order of the tests: with 1 ulp, T < tmax det could
 * round false for a hit whose T / det rounds to t, and structures visiting primitives in
 * different orders returned different ties. t is positive and finite. */
static inline float ref_tie_probe(float t)
{
    uint32_t u;
    memcpy(&u, &t, 4);
    u += 4;
    memcpy(&t, &u, 4);
    return t;
}

/* The closest-hit rule every traversal shares (BVH, kd-trees, packets): a primitive hit at t
 * replaces the best hit so far when there is none, when t is lower, or when t ties and the
 * primitive index is lower -- so the answer does not depend on the order of the tests. 1 when
 * it replaced *best. */
static inline int ref_hit_keep(RefHit *best, float t, float u, float v, uint32_t prim)
{
    if (!(best->prim == REF_NO_HIT || t < best->t || (t == best->t && prim < best->prim)))
        return 0;
    best->t = t;
    best->u = u;
    best->v = v;
    best->prim = prim;
    return 1;
}

/* The tmax to test the next primitive with, given the best hit so far: the ray's own tmax, or
 * once there is a hit the tie probe past it (ref_tie_probe), so a tie or a closer hit is seen. */
static inline float ref_hit_tmax(const RefHit *best, float tmax)
{
    return best->prim == REF_NO_HIT ? tmax : ref_tie_probe(best->t);
}

/* The primitive tests themselves (exposed for the hard-case tests). */
int ref_hit_triangle(const float *v0, const float *v1, const float *v2, const RefRay *r,
                     float *t, float *u, float *v);
int ref_hit_sphere(const float *center, float radius, const RefRay *r, float *t);
/* Ray directions are sanitized where rays are made: a component with |d| < FLT_MIN (a zero of
 * either sign, or a denormal) becomes FLT_MIN with d's sign. The ray then is never exactly
 * parallel to an axis plane: its inverse direction is finite, slab distances never compute
 * 0 x inf = NaN, and a ray starting on a box face enters or leaves the box as its (tiny) sign
 * says -- consistently for boxes, triangles and spheres (docs/golden-model.md). The queries
 * below sanitize their ray themselves, so an unsanitized ray gives the same answer. */
void ref_sanitize_dir(float *dir);
void ref_inv_dir(const float *dir, float *inv);   /* 1 / d of a sanitized direction */
/* Slab test of the ray against a box: 1 if it overlaps [0, tmax]. inv_dir from ref_inv_dir. */
int ref_hit_box(const float *bmin, const float *bmax, const float *org, const float *inv_dir,
                float tmax);

/* The ISA's min/max (vfmin/vfmax): the second operand is ignored when it is NaN. */
static inline float ref_fmin(float b, float c) { return c < b ? c : b; }
static inline float ref_fmax(float b, float c) { return c > b ? c : b; }

#endif
