/* tests/support/numerics.h -- building hard-case scenes and ray batches for the numerics tests
 * (tests/unit/test_numerics.c, tests/hard/), and running a batch through both the kernel and
 * the golden model.
 *
 * Owns: test geometry (icospheres, cubes, planes, degenerate triangles) and the comparison of
 * the two engines. Must not: decide pass or fail (the tests assert).
 */
#ifndef SFSIM_TEST_NUMERICS_H
#define SFSIM_TEST_NUMERICS_H

#include <stdint.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/raybatch.h"

typedef struct Mesh {
    float *pos;            /* 9 floats per triangle */
    uint32_t *mat;
    uint32_t ntris, cap;
    SceneSphere spheres[8];
    uint32_t nspheres;
    SceneMaterial mats[4];
    uint32_t emissive[64];
    uint32_t nemissive;
} Mesh;

void mesh_init(Mesh *m);
void mesh_free(Mesh *m);
void mesh_tri(Mesh *m, const float *a, const float *b, const float *c, uint32_t mat);
/* Quad corner c, edges ea, eb: two triangles sharing the diagonal c + ea .. c + eb... */
void mesh_quad(Mesh *m, const float *c, const float *ea, const float *eb, uint32_t mat);
/* A closed icosphere of `levels` subdivisions (20 x 4^levels triangles), vertices shared
 * exactly between neighbouring triangles; returns the index of its first triangle. Its distinct
 * vertices (and edge midpoints) are appended to pts (3 floats each) if pts is not NULL. */
uint32_t mesh_icosphere(Mesh *m, const float *center, float radius, int levels, float **pts, uint32_t *npts,
                        float **mids, uint32_t *nmids);
/* The six faces of the box [lo, hi] (12 triangles), wound outward. */
void mesh_box(Mesh *m, const float *lo, const float *hi, uint32_t mat);
/* A Scene over the mesh (materials: 0 Lambert 0.8, 1 emitter, 2 glass, 3 Lambert 1.0); the mesh
 * must outlive it. Render settings and camera are defaults the tests may change. */
void mesh_scene(Mesh *m, Scene *s);

/* Ray batch helpers. */
void batch_add(RayBatch *b, uint32_t *cap, const float *org, const float *dir, float tmax, uint32_t query);

/* Trace b through the kernel (N = lanes, M = rays) and through the golden model. Returns the
 * number of rays whose results differ in any bit (t, prim, u, v, invalid). *kh and *rh are
 * malloc'ed hit arrays (free them). Asserts on engine errors. */
uint32_t trace_both(const PackedScene *p, uint32_t needs, const RayBatch *b, int lanes, int rays, BatchHit **kh,
                    BatchHit **rh);

/* Packed primitive -> source triangle index (or ntris + sphere index). */
uint32_t prim_source(const PackedScene *p, uint32_t prim);

#endif
