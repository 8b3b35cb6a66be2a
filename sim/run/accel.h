/* sim/run/accel.h -- the acceleration structures the machine traverses, built and packed in one
 * place for every mode: the BVH (always; the golden model traverses it) and, with
 * accel.structure = kd, the kd-tree the kernel traverses instead.
 *
 * Owns: turning the config's bvh.* and kd.* keys into builder parameters, building, checking the
 * invariants, packing into scene memory (scenes/pack.c lays the bytes out), and the figures of
 * what was built. Must not: traverse (sim/ref_trace.c, sim/ref_kd.c and the kernels do), or
 * decide which mode needs which structure beyond the `kernel` flag its caller passes.
 */
#ifndef SFSIM_RUN_ACCEL_H
#define SFSIM_RUN_ACCEL_H

#include <stddef.h>
#include <stdint.h>

#include "../../scenes/kdtree.h"
#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../config.h"

/* accel.structure = kd: the tree accel_add_kd built and packed. */
typedef struct AccelKdInfo {
    uint32_t nodes, leaves, empty_leaves, depth, largest_leaf;
    uint32_t prims, refs;      /* primitives; leaf-list entries (a primitive may be in several leaves) */
    double sah_cost;
    double build_seconds;      /* build, invariant check and packing */
} AccelKdInfo;

/* What accel_pack did, for the report's host block. */
typedef struct AccelInfo {
    double pack_seconds;       /* BVH build and scene packing */
    AccelKdInfo kd;            /* zero unless a kd-tree was built */
} AccelInfo;

/* Pack scene s for the machine of cfg at scene-memory address 0: its BVH (bvh.leaf_size,
 * bvh.bins) and, when kernel is set (the kernel modes) and accel.structure = kd, its kd-tree
 * too. 0, or -1 with a message; out must be freed with pack_free either way. */
int accel_pack(const Scene *s, const CfgMachine *cfg, int kernel, PackedScene *out, AccelInfo *info, char *err,
               size_t errlen);

/* accel.structure = kd (cfg): build the kd-tree of the kd.* keys over p's packed primitives, check
 * its invariants and append it to p (pack_add_kd). For accel.structure = bvh nothing happens. 0,
 * or -1 with a message naming the keys. */
int accel_add_kd(PackedScene *p, const CfgMachine *cfg, AccelKdInfo *info, char *err, size_t errlen);

/* The kd.* keys as builder parameters. */
void accel_kd_params(const CfgMachine *cfg, KdParams *kp);
/* Build a kd-tree over the packed scene's primitives (packed indices), from their boxes. */
int accel_kd_build(const PackedScene *p, const KdParams *kp, KdTree *out, char *err, size_t errlen);
/* The packed primitives' boxes (3 floats each, malloc'ed); -1 when out of memory. */
int accel_prim_boxes(const PackedScene *p, float **bmin, float **bmax);

#endif
