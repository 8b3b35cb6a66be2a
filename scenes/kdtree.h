/* scenes/kdtree.h -- kd-tree over primitive boxes: SAH build with the event sweep, invariants,
 * cost, statistics.
 *
 * Owns: the tree's split planes, its leaves' primitive lists, the builder's cost model.
 * Must not: know what a primitive is (callers pass boxes) or how the tree is laid out in
 * simulated memory.
 *
 * The build is the O(n log^2 n) event-sweep SAH builder of Wald & Havran, "On building fast
 * kd-trees for ray tracing, and on doing that in O(N log N)", IEEE RT 2006, Sec. 4: at each node
 * and axis the primitives' boxes, clipped to the node's voxel, give start, end and planar events;
 * a sweep over the sorted events evaluates the surface-area heuristic at every candidate plane,
 * putting planar primitives on the cheaper side; an empty side earns the empty-space bonus. The
 * default costs are those of Horn et al. 2007 (seed 004): one primitive test costs one traversal
 * step. A node becomes a leaf when splitting costs more than testing its primitives, when it
 * holds at most leaf_size primitives, or at max_depth.
 */
#ifndef SFSIM_KDTREE_H
#define SFSIM_KDTREE_H

#include <stddef.h>
#include <stdint.h>

/* No split leaves a child voxel thinner than this fraction of the scene's largest extent. The
 * traversals widen split distances by 2^-20 of the distance (sim/ref_kd.c); two planes closer
 * than that along a ray look like one, and a ray would step over the thin voxel between them --
 * found on Sponza, whose walls the SAH isolated in voxels one ulp thick. 2^-16 keeps planes 16x
 * farther apart than the widening for any origin inside the scene. */
#define KD_MIN_GAP 0x1p-16

typedef struct KdParams {
    float cost_traversal;  /* cost of one traversal step (default 1) */
    float cost_intersect;  /* cost of one primitive test (default 1: seed 004's setting) */
    float empty_bonus;     /* cost factor when one side is empty, 0..1 (default 0.8) */
    int leaf_size;         /* a node with at most this many primitives is a leaf (default 1) */
    int max_depth;         /* levels below the root; 0 = 8 + 1.3 log2(n) (default), at most 60 */
} KdParams;

typedef struct KdNode {
    float split;           /* inner: the plane's coordinate on its axis */
    uint32_t axis;         /* 0..2: inner node, split axis; 3: leaf */
    uint32_t a;            /* inner: left child (below the plane); the right child is a + 1. leaf: first index into prims */
    uint32_t count;        /* leaf: number of primitives (may be 0) */
} KdNode;

#define KD_LEAF 3u

typedef struct KdTree {
    KdNode *nodes;         /* nodes[0] is the root */
    uint32_t nnodes;
    uint32_t *prims;       /* leaf lists: caller's primitive indices */
    uint32_t nrefs;        /* entries in prims (a primitive may be in several leaves) */
    uint32_t nprims;       /* primitives the tree was built over */
    float bmin[3], bmax[3];/* the scene box: the root's voxel */
    uint32_t depth;        /* levels, root = 1 */
    uint32_t nleaves, nempty;
    uint32_t max_leaf;     /* most primitives in one leaf */
    double sah_cost;
} KdTree;

void kd_default_params(KdParams *p);
/* Build over n primitive boxes (n * 3 floats each). NaN or inverted boxes are an error naming
 * the first. 0, or -1 with a message. */
int kd_build(const KdParams *p, const float *bmin, const float *bmax, uint32_t n, KdTree *out, char *err,
             size_t errlen);
void kd_free(KdTree *t);
/* Invariants: every primitive is in every leaf whose voxel its box overlaps with positive
 * extent on all axes (and in at least one leaf), leaf lists hold valid indices, split planes lie
 * inside their voxels, every node is reachable exactly once. 0, or -1 with the first violation. */
int kd_check(const KdTree *t, const float *bmin, const float *bmax, char *err, size_t errlen);

#endif
