/* scenes/pack.h -- packing a loaded scene and its BVH (and, on request, a kd-tree) into
 * simulated scene memory.
 *
 * Owns: the byte image of a scene in scene memory, laid out per scenes/layout.def.
 * Must not: load files or execute anything; readers (golden model, kernels) use the layout
 * constants below, never their own offsets.
 */
#ifndef SFSIM_PACK_H
#define SFSIM_PACK_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bvh.h"
#include "kdtree.h"
#include "scene.h"

/* Word offsets and record sizes: SM_HDR_WORDS, SM_HDR_MAGIC, SM_NODE_BMIN, ... */
enum {
#define SM_RECORD(rec, words, desc) SM_##rec##_WORDS = (words),
#define SM_FIELD(rec, name, word, count, type, desc) SM_##rec##_##name = (word),
#include "layout.def"
#undef SM_RECORD
#undef SM_FIELD
};

#define SM_MAGIC 0x4D534653u
#define SM_VERSION 1u
#define SM_NODE_INNER 0x80000000u
/* KDNODE INFO: an index shifted past the 2-bit tag (axis 0..2, or 3 = leaf). */
#define SM_KD_SHIFT 2u
#define SM_KD_LEAF 3u
#define SM_KD_MAX_INDEX ((1u << (32u - SM_KD_SHIFT)) - 1u)

typedef enum SmLightKind {
    SM_LIGHT_POINT = 0, SM_LIGHT_SPOT = 1, SM_LIGHT_DIRECTIONAL = 2, SM_LIGHT_QUAD = 3,
    SM_LIGHT_TRIANGLE = 4
} SmLightKind;

/* A reader's private, host-only structure derived from a packed scene once (sim/ref_trace.c's
 * 4-wide BVH for the golden model's queries): its first member frees it, so pack_free can without
 * knowing what it is. Never part of the image. */
typedef struct PackHost {
    void (*free)(struct PackHost *h);
} PackHost;

typedef struct PackedScene {
    uint8_t *mem;        /* the packed bytes; address `base` of scene memory is mem[0] */
    uint32_t size;       /* bytes */
    uint32_t base;       /* scene-memory byte address of the header */
    Bvh bvh;             /* the tree that was packed (node i = packed node i) */
    uint32_t nprims;     /* triangles + spheres */
    uint32_t nspheres;   /* of which spheres (so a reader need not scan the primitive array) */
    uint32_t nlights;
    uint32_t kd_depth;   /* levels of the kd-tree pack_add_kd appended (root = 1); 0: none */
    PackHost *host;      /* NULL, or built on first use by its reader (atomically published); freed by pack_free */
} PackedScene;

/* Pack s with a BVH built by bp, for loading at scene-memory address base (a multiple of 64).
 * 0, or -1 with a message (for instance a scene that does not fit 4 GiB of addresses). */
int pack_scene(const Scene *s, const BvhParams *bp, uint32_t base, PackedScene *out, char *err,
               size_t errlen);
void pack_free(PackedScene *p);

/* Append kd-tree t, built over p's packed primitives (packed indices, as ref_kd_build builds it),
 * to the image: its KDNODE array and its leaf lists, each on a 64-byte boundary, and fill the
 * header's KD_* fields. 0, or -1 with a message (a second tree, a tree over other primitives, an
 * index that does not fit 30 bits, an image past 4 GiB of addresses); p is unchanged then. */
int pack_add_kd(PackedScene *p, const KdTree *t, char *err, size_t errlen);

/* Load a scene file, override its render size and samples (values > 0), and pack it with the
 * default BVH: a short set-up for unit tests (the commands, tools and benchmarks open scenes through
 * sim/run/run.h). 0, or -1 with a message (nothing to free). */
int pack_load_file(const char *path, int width, int height, int spp, Scene *s, PackedScene *p, char *err,
                   size_t errlen);

/* Readers of packed words (addresses are scene-memory byte addresses). */
static inline uint32_t sm_u32(const PackedScene *p, uint32_t addr)
{
    uint32_t v;
    memcpy(&v, p->mem + (addr - p->base), 4);
    return v;
}
static inline float sm_f32(const PackedScene *p, uint32_t addr)
{
    float v;
    memcpy(&v, p->mem + (addr - p->base), 4);
    return v;
}
/* Address of word `field` of header / record `i` of an array. */
static inline uint32_t sm_hdr(const PackedScene *p, int field) { return p->base + 4u * (uint32_t)field; }
static inline uint32_t sm_rec(uint32_t array, uint32_t words, uint32_t i, int field)
{
    return array + 4u * (words * i + (uint32_t)field);
}

#endif
