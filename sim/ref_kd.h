/* sim/ref_kd.h -- the golden model's kd-tree traversals (seed 004, Appendix A): standard stack,
 * kd-restart, push-down and short-stack, for closest-hit and any-hit queries over a packed scene,
 * with the counters the paper compares (nodes and leaves visited, restarts, stack overflows and
 * underflows, primitive tests).
 *
 * Owns: the reference algorithms the kd-tree kernels must reproduce and the definition of each
 * counter. Must not: build trees (scenes/kdtree.c builds them, sim/run/accel.c for a packed scene) or shade.
 *
 * The traversals are the paper's, in binary32, with one change for robustness: a split distance
 * is widened to tSplit +- 2^-20 |tSplit| (more than its rounding error) before the paper's
 * comparisons, so a ray that may reach a child visits it, and a leaf's early exit uses the lower
 * end. A far child's segment starts at the upper end, where a restart resumes, so all variants
 * descend alike and a short stack as deep as the tree visits exactly the full stack's nodes.
 * With the BVH's primitive test and tie rule (the lower packed primitive wins at equal t), every
 * variant returns the BVH traversal's closest hit (tested bit for bit on random rays).
 * docs/kdtree.md explains each variant and counter.
 */
#ifndef SFSIM_REF_KD_H
#define SFSIM_REF_KD_H

#include <stdint.h>

#include "../scenes/kdtree.h"
#include "../scenes/pack.h"
#include "ref_trace.h"

typedef enum RefKdVariant {
    REF_KD_STACK = 0,      /* A.1: a full stack of (node, tmin, tmax) */
    REF_KD_RESTART = 1,    /* A.2: no stack; after each leaf, restart from the root at its exit */
    REF_KD_PUSHDOWN = 2,   /* A.3: restart from the deepest node the ray never crossed a plane above */
    REF_KD_SHORTSTACK = 3, /* A.4: a stack of `depth` entries (push-down too); a full stack drops its
                              bottom entry, an empty one restarts */
    REF_KD_VARIANTS
} RefKdVariant;

extern const char *const ref_kd_variant_names[REF_KD_VARIANTS]; /* "stack", "restart", "pushdown", "shortstack" */

typedef struct RefKdStats {
    uint64_t nodes_visited;    /* inner nodes and leaves entered during descents */
    uint64_t leaves_visited;
    uint64_t restarts;         /* descents from the (push-down) root after the first */
    uint64_t stack_overflows;  /* pushes that dropped the bottom entry (short-stack) */
    uint64_t stack_underflows; /* pops from an empty short stack while the ray was unfinished */
    uint64_t prims_tested;
    uint64_t packet_steps;     /* packets: nodes entered by the packet (one per node however many rays) */
} RefKdStats;

/* The packetized short-stack of A.5: n <= 64 rays traverse together with a live mask, one stack
 * of `depth` entries for the packet (each entry holds every ray's segment), push-down, restart
 * on underflow. Generalized so that any rays may share a packet: the packet follows the first
 * live ray's near child; a ray whose segment does not start at its progress point (it met its far
 * child first) does not advance its restart point past unvisited space. hits[i] is exactly ray
 * i's BVH closest hit. Counters count per ray, as the single-ray traversals do: a node the packet
 * enters counts once for each ray live in it (nodes_visited, leaves_visited), a restart or an
 * overflowing push once for each live ray; prims_tested counts ray-primitive tests. When a
 * restart finds that no ray advanced, the rays left finish with single-ray short stacks that
 * continue from their hits (counted as such). */
void ref_kd_packet_closest_hit(const PackedScene *p, const KdTree *t, int stack_depth, const RefRay *rays, int n,
                               RefHit *hits, RefKdStats *st);

/* Closest hit; stack_depth is the short stack's entries (variant shortstack, >= 1). */
void ref_kd_closest_hit(const PackedScene *p, const KdTree *t, RefKdVariant v, int stack_depth, const RefRay *r,
                        RefHit *hit, RefKdStats *st);
/* Any hit with 0 < t < tmax; 1 if occluded (stops at the first hit found). */
int ref_kd_any_hit(const PackedScene *p, const KdTree *t, RefKdVariant v, int stack_depth, const RefRay *r,
                   RefKdStats *st);

#endif
