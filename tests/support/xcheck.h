/* tests/support/xcheck.h -- cross-check of the golden model's closest hits against Embree on the
 * same rays (used by tests/unit/test_embree.c and bench/embree_xcheck.c).
 *
 * Owns: ray generation for the check (camera rays through the packed camera, random rays from
 * inside the bounds) and the agreement rule. Must not: change either tracer.
 */
#ifndef SFSIM_XCHECK_H
#define SFSIM_XCHECK_H

#include <embree3/rtcore.h>
#include <stdint.h>

#include "../../scenes/kdtree.h"
#include "../../scenes/pack.h"
#include "../../sim/ref_trace.h"

typedef struct XcheckResult {
    uint64_t rays;
    uint64_t agree;        /* same primitive (or both miss) and distances within tolerance */
    uint64_t ties;         /* different primitives at equal distance (within tolerance) */
    uint64_t disagree;     /* everything else */
    uint64_t hits;         /* rays our tracer says hit something */
    double ours_seconds, embree_seconds;
    uint64_t first_bad;    /* index of the first disagreeing ray, for diagnosis */
    uint64_t unlike_bvh;   /* kd-tree runs: rays whose hit differs in any bit from the BVH's */
} XcheckResult;

/* Which of our traversals to check: the golden model's BVH (kd = NULL), or its kd-tree traversal
 * `variant` (RefKdVariant) with a short stack of `depth` entries over kd. */
typedef struct XcheckTracer {
    const KdTree *kd;
    int variant, depth;
} XcheckTracer;

/* Trace `camera_rays` camera rays and `random_rays` random rays through both tracers.
 * `scene` gives the source triangles Embree builds from; p is its packing; tr NULL: the BVH.
 * 0, or -1 with a message (Embree device or build failure). */
int xcheck_run(const Scene *scene, const PackedScene *p, const XcheckTracer *tr, uint32_t camera_rays,
               uint32_t random_rays, uint32_t seed, XcheckResult *out, char *err, size_t errlen);

/* Embree 3 over a scene's triangles (primID = source triangle): one thread, robust, the
 * high-quality build (SAH with spatial splits); build_seconds times rtcCommitScene alone. */
typedef struct XcheckEmbree {
    RTCDevice dev;
    RTCScene scene;
    double build_seconds;
} XcheckEmbree;

/* 0, or -1 with a message (the device, a buffer or the build failed; nothing is left open). */
int xcheck_embree_open(const Scene *scene, XcheckEmbree *e, char *err, size_t errlen);
void xcheck_embree_close(XcheckEmbree *e);
/* r as Embree's ray: tnear 0, tfar r->tmax, every mask bit. */
void xcheck_embree_ray(const RefRay *r, struct RTCRay *er);

/* The agreement rule: our closest hit against Embree's (ehit: it hit; eprim its primID, et its t). */
typedef enum XcheckVerdict { XCHECK_AGREE = 0, XCHECK_TIE = 1, XCHECK_DISAGREE = 2 } XcheckVerdict;
XcheckVerdict xcheck_compare(const Scene *scene, const PackedScene *p, const RefRay *r, const RefHit *ours,
                             int ehit, uint32_t eprim, float et);

#endif
