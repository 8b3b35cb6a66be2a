/* sim/reference.h -- the golden model: a plain C path tracer over a packed scene, the
 * specification the assembly kernel (kernels/pathtrace.s) must reproduce pixel for pixel.
 *
 * Owns: the rendering algorithm of docs/golden-model.md -- tiles of sqrt(M) x sqrt(M) pixels,
 * one pass per sample, breadth-first generations with at most one ray per path per generation,
 * the counter-based random numbers, the shading models. Must not: model any hardware timing.
 */
#ifndef SFSIM_REFERENCE_H
#define SFSIM_REFERENCE_H

#include <stddef.h>
#include <stdint.h>

#include "../scenes/pack.h"

#define REF_MAX_GENERATIONS 64

typedef enum RefRayKind { REF_RAY_CAMERA = 0, REF_RAY_INDIRECT = 1, REF_RAY_SHADOW = 2, REF_RAY_KINDS } RefRayKind;

/* What the golden model renders: the path tracer, or the Phong workload of seed 004 Sec. 4
 * (docs/golden-model.md; the kernel's workload.kind = phong). */
typedef enum RefWorkload { REF_WORKLOAD_PATH = 0, REF_WORKLOAD_PHONG = 1 } RefWorkload;

typedef struct RefParams {
    int tile;          /* tile edge in pixels: sqrt(M), 32 for M = 1024, 64 for M = 4096 */
    uint32_t seed;     /* render.seed */
    int threads;       /* host threads over tiles (results do not depend on it) */
    /* Called after each finished tile from the worker that finished it (may be NULL); calls
     * can come from several threads at once. */
    void (*progress)(void *ctx, uint32_t tiles_done, uint32_t tiles_total);
    void *progress_ctx;
    RefWorkload workload;  /* 0 (the default of a zeroed struct): the path tracer */
    int bounces;       /* phong: mirror bounces after the camera hit (workload.bounces, >= 0) */
    /* The passes (samples per pixel) to render, [pass0, pass1); pass1 = 0: every pass. The image
     * then holds the sum of those passes over the frame's spp (a pilot's image is not the frame). */
    uint32_t pass0, pass1;
    /* Every pass_step-th of those passes (pass0, pass0 + step, ...); 0 or 1: each of them. */
    uint32_t pass_step;
    /* When not NULL: the counts of each (tile, pass) unit, units[tile * spp + pass], ntiles * spp
     * entries zeroed by the caller (sampled mode's auxiliary variables, docs/sampling.md). */
    struct RefUnitStats *units;
    int simd_width;    /* N of the units' SIMD-step counts (core.simd_width); 0: 16. Only with units */
    /* When not NULL: told, unit by unit (tile * spp + pass), of each piece of scene memory the BVH
     * walks of a generation read, after the generation (RefSetCount's line sink: the nodes
     * box-tested, the primitives of the leaves entered; a sampled chip's functional warming,
     * docs/sampling.md). Calls come from several threads at once, each unit's from one. */
    void (*unit_line)(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes);
    void *unit_line_ctx;
    /* When not NULL: only these tiles (ntiles_only of them, each below the frame's count) are
     * rendered, the others left black and uncounted. */
    const uint32_t *tiles_only;
    uint32_t ntiles_only;
} RefParams;

/* One (tile, pass) unit's work in the golden model. The SIMD-step counts model a stream filter of
 * N = simd_width lanes (docs/golden-model.md): each generation's rays -- the Phong workload's
 * shadow rays, traced while shading it, included -- form one set; a BVH node's box test, each
 * primitive of an entered leaf and the generation itself cost ceil(rays of the set there / N)
 * steps. They describe the BVH walk the golden model does whatever the machine's
 * accel.structure (there is no kd-tree version). */
typedef struct RefUnitStats {
    uint64_t rays[REF_RAY_KINDS]; /* traced, by kind */
    uint64_t nodes_visited, prims_tested;
    uint64_t hits;             /* camera and indirect rays that hit a surface: shading events */
    uint64_t generations;      /* generations the pass reached */
    uint64_t node_steps;       /* per generation and node box-tested: ceil(rays that tested it / N) */
    uint64_t leaf_steps;       /* per generation and leaf entered: ceil(rays that entered it / N) x its prims */
    uint64_t ray_steps;        /* per generation: ceil(rays traced / N) */
} RefUnitStats;

typedef struct RefStats {
    uint64_t rays[REF_RAY_KINDS];                 /* traced, by kind */
    uint64_t rays_per_generation[REF_MAX_GENERATIONS];
    uint64_t generations;                         /* deepest generation reached + 1 */
    uint64_t nodes_visited, prims_tested;
    uint64_t dropped;                             /* rays with non-finite data, never traced */
    uint64_t tiles, passes;
} RefStats;

/* The random number of a path: dimension dim at path vertex `vertex` (0 = the camera), as a
 * float in [0, 1). path_key = ref_path_key(seed, pixel, sample). */
uint32_t ref_hash32(uint32_t x);
uint32_t ref_path_key(uint32_t seed, uint32_t pixel, uint32_t sample);
float ref_rand(uint32_t path_key, uint32_t vertex, uint32_t dim);

/* The origin of a ray leaving the surface point p on the side of the unit normal n (Waechter and
 * Binder 2019, docs/golden-model.md), as the renderer computes it. */
void ref_offset_point(const float *p, const float *n, float *out);

/* Render the whole image: rgb (width * height * 3 floats, zeroed by the caller) receives the
 * mean radiance per pixel. 0, or -1 with a message. stats may be NULL. */
int ref_render(const PackedScene *p, const RefParams *rp, float *rgb, RefStats *stats, char *err,
               size_t errlen);

#endif
