/* scenes/bvh.h -- bounding volume hierarchy over primitive boxes: binned SAH build, invariants,
 * cost.
 *
 * Owns: the tree's topology and boxes and the primitive order. Must not: know what a primitive
 * is (callers pass boxes and centroids) or how the tree is laid out in simulated memory
 * (scenes/pack.c).
 *
 * The build follows the binned surface-area heuristic (Wald, "On fast construction of SAH-based
 * bounding volume hierarchies", IEEE RT 2007); 001 Sec. 4 builds its BVH with a SAH too.
 */
#ifndef SFSIM_BVH_H
#define SFSIM_BVH_H

#include <stddef.h>
#include <stdint.h>

typedef struct BvhParams {
    int max_leaf_size;     /* a node with more primitives is always split (default 4) */
    int bins;              /* SAH bins per axis, 2..256 (default 16) */
    float cost_traversal;  /* SAH cost of visiting an inner node (default 1) */
    float cost_intersect;  /* SAH cost of one primitive test (default 1) */
} BvhParams;

typedef struct BvhNode {
    float bmin[3], bmax[3];
    uint32_t first;        /* leaf: first index into prim_index; inner: index of the left child */
    uint32_t count;        /* leaf: primitive count (> 0); inner: 0 */
    uint32_t axis;         /* inner: split axis 0..2 (the right child holds the larger centroids) */
} BvhNode;

typedef struct Bvh {
    BvhNode *nodes;        /* nodes[0] is the root; children of an inner node are first, first+1 */
    uint32_t nnodes;
    uint32_t *prim_index;  /* leaf order -> caller's primitive index */
    uint32_t nprims;
    uint32_t depth;        /* levels, root = 1 */
    uint32_t nleaves;
    double sah_cost;       /* bvh_sah_cost() of the built tree */
} Bvh;

void bvh_default_params(BvhParams *p);
/* Build over n primitives given their boxes (n * 3 floats each). Primitives with a NaN or
 * inverted box are an error (the message names the first one). 0, or -1 with a message. */
int bvh_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out,
              char *err, size_t errlen);
void bvh_free(Bvh *b);

/* The build's input: parameters in range, every box finite with lo <= hi. 0, or -1 with a
 * message naming the parameter or the first bad primitive (bvh_build calls it first). */
int bvh_check_input(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, char *err, size_t errlen);
/* Check the invariants: every primitive in exactly one leaf, every primitive's box inside its
 * leaf's box, children inside parents, no NaN boxes, leaf sizes > 0, every node reachable once.
 * 0, or -1 with the first violation described. */
int bvh_check(const Bvh *b, const float *bmin, const float *bmax, char *err, size_t errlen);

/* SAH cost: sum over nodes of (area / root area) x (cost_traversal for inner nodes,
 * cost_intersect x count for leaves). */
double bvh_sah_cost(const Bvh *b, const BvhParams *p);

/* malloc for large host arrays, released by free(), aligned to 32 bytes at least; from 2 MiB on
 * (on Linux) aligned to 2 MiB and marked for transparent huge pages, so that first touching fresh
 * memory takes one page fault per 2 MiB instead of one per 4 KiB: page faults were about a tenth
 * of the conference room's build and pack. The build's arrays and scenes/pack.c's box arrays use
 * it. */
void *bvh_big_alloc(size_t size);

#endif
