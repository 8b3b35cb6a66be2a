/* sim/ref_qtree.h -- the golden model's 4-wide walk layout: a private, host-only copy of the packed
 * BVH that sim/ref_trace.c's queries without statistics walk (sim/ref_qtree.c builds it once per
 * scene). The reasoning, and why it finds the same hits bit for bit, is the comment at the top of
 * sim/ref_qtree.c.
 *
 * Owns: the layout's types, and the two readers of the packed scene that the walks and the build
 * share (prim_read, image_at). Must not: be used by anything but the golden model's walks.
 */
#ifndef SFSIM_REF_QTREE_H
#define SFSIM_REF_QTREE_H

#include <stdint.h>
#include <string.h>

#include "../scenes/pack.h"

/* A packed primitive as the walks read it (scenes/layout.def: its vertices or centre and radius,
 * and its kind, 1 for a sphere). */
typedef struct PrimRec {
    float g[9];
    uint32_t kind;
} PrimRec;

static inline void prim_read(const uint8_t *prims, uint32_t i, PrimRec *pr)
{
    const uint8_t *rec = prims + (size_t)4 * SM_PRIM_WORDS * i;
    memcpy(pr->g, rec + 4 * SM_PRIM_V0, sizeof pr->g);
    memcpy(&pr->kind, rec + 4 * SM_PRIM_KIND, sizeof pr->kind);
}

/* Where array `addr` (a scene-memory address) sits in the image. */
static inline const uint8_t *image_at(const PackedScene *p, uint32_t addr)
{
    return p->mem + (addr - p->base);
}


#define QLEAF 0x80000000u   /* QNode child / pending entry: a leaf's first TriBlock */
#define QB_LAST 1u          /* TriBlock flags: the leaf's last block */
#define QB_SPHERE 2u        /* a lane holds a sphere: test the block lane by lane */

typedef struct QNode {
    float b[6][4];          /* bmin x, y, z, bmax x, y, z; lane = child slot (unused slots: 0) */
    uint32_t child[4];      /* QNode index, or QLEAF | first TriBlock */
    uint8_t order[8];       /* per octant (bit k: dir[k] < 0): 4 x 2 bits, slot of the j-th nearest at bits 2j */
    uint32_t valid;         /* bit c: slot c used */
    uint32_t pad[1];
} __attribute__((aligned(64))) QNode;

typedef struct TriBlock {
    float v[9][4];          /* v0 x, y, z, v1 x, y, z, v2 x, y, z; lane = primitive (unused: 0) */
    uint32_t prim[4];       /* packed primitive index */
    uint32_t valid, flags;
    uint32_t pad[2];
} __attribute__((aligned(64))) TriBlock;

typedef struct QTree {
    PackHost host;          /* first: p->host points here */
    int usable;             /* 0: the binary walks (a child's box outside its parent's) */
    QNode *q;
    TriBlock *tb;
    uint32_t nq, ntb, capq, captb;
    uint32_t root;          /* QNode index or QLEAF | block (the root's box is tested first, as walk_fast does) */
    uint32_t stack_len;     /* pending entries a walk may need, plus 4 for the branch-free pushes */
    double build_seconds;
} QTree;

/* p's 4-wide tree, built on the first call (thread-safe: a loser of the race frees its own) and
 * hung on p->host (pack_free frees it); NULL when out of memory. */
const QTree *ref_qtree_of(const PackedScene *p);

#endif
