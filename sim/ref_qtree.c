/* sim/ref_qtree.c -- building the golden model's 4-wide walk layout (see ref_qtree.h).
 *
 * Owns: the copy of the packed BVH into QNodes and TriBlocks, once per scene. Must not: change
 * the scene memory the kernels read, or the hits the walks find.
 */
#include "ref_qtree.h"

#include <stdlib.h>
#include <string.h>

#include "ref_trace.h"
#include "util.h"

/* ---- The 4-wide walk: a private, host-only layout derived from the packed BVH ----
 *
 * The packed tree is binary (scenes/layout.def), one box test per node. The golden model's queries
 * without stats (walk_bare) instead walk a 4-wide copy of it that sim/ref_trace.c builds once per
 * scene, on the first such query, and hangs on the PackedScene (p->host; pack_free frees it): each
 * QNode stands for a binary inner node and holds its grandchildren (or a child, where that child
 * is a leaf), so one SIMD test covers the boxes of two binary levels, their boxes in SoA floats;
 * each leaf's triangles are copied into TriBlocks of 4 in SoA, so one SIMD test covers them. The
 * scene memory the kernels read is untouched.
 *
 * Same hits bit for bit as walk_fast (and so walk_body):
 *  - boxes: each lane computes box_hit_v's expressions on one child's box (the ISA min/max,
 *    operand order included), and the axis reductions are order-free as box_hit_v says;
 *  - a binary grandchild G of node N through child C is visited when G's box hits and its entry
 *    distance is still within the closest hit at its turn; the binary walks also need C's box to
 *    hit. C's box contains G's (checked at the build: with a child outside its parent's box the
 *    scene keeps walk_fast), the slab distances are monotone in the planes (rounding is), so G's
 *    [tn, tf] lies inside C's and "G hits" implies "C hits" at any far end: the same nodes;
 *  - order: each QNode keeps, per octant of the ray's direction signs, its children in the binary
 *    walks' near-first order (the split axes of N and of C), pushed far to near: the same order;
 *  - triangles: each lane computes tri_hit's expressions; the lanes that hit with the tmax at the
 *    leaf's entry are then taken in index order and re-tested against the tmax of that moment
 *    (T < tmax det and t < tmax, tri_hit's only tests of tmax, on the same T, det and t), which is
 *    what the sequential loop does. A block holding a sphere is tested lane by lane with hit_prim.
 * Rays with a non-finite origin or direction component take walk_fast (the containment argument
 * needs finite slab distances). */


static void qtree_free(PackHost *h)
{
    QTree *t = (QTree *)h;
    free(t->q);
    free(t->tb);
    free(t);
}

static void *aligned_grow(void *old, uint32_t n, uint32_t cap, size_t size)
{
    void *p = aligned_alloc(64, (size_t)cap * size);
    if (p && old)
        memcpy(p, old, (size_t)n * size);
    free(old);
    return p;
}

static inline void node_box(const uint8_t *nodes, uint32_t n, float *lo, float *hi)
{
    memcpy(lo, nodes + 4 * SM_NODE_WORDS * (size_t)n + 4 * SM_NODE_BMIN, 12);
    memcpy(hi, nodes + 4 * SM_NODE_WORDS * (size_t)n + 4 * SM_NODE_BMAX, 12);
}

static inline uint32_t node_word(const uint8_t *nodes, uint32_t n, int w)
{
    uint32_t x;
    memcpy(&x, nodes + 4 * SM_NODE_WORDS * (size_t)n + 4 * (size_t)w, 4);
    return x;
}

/* The leaf's primitives into TriBlocks; its reference, or QLEAF | 0 with t->usable = 0 when out of memory. */
static uint32_t qtree_leaf(QTree *t, const uint8_t *prims, uint32_t first, uint32_t count)
{
    uint32_t nb = (count + 3) / 4;
    if (t->ntb + nb > t->captb) {
        uint32_t cap = t->captb ? t->captb * 2 : 1024;
        while (cap < t->ntb + nb)
            cap *= 2;
        if (!(t->tb = aligned_grow(t->tb, t->ntb, cap, sizeof *t->tb))) {
            t->usable = 0;
            return QLEAF;
        }
        t->captb = cap;
    }
    uint32_t ref = QLEAF | t->ntb;
    for (uint32_t b = 0; b < nb; b++) {
        TriBlock *tb = &t->tb[t->ntb++];
        memset(tb, 0, sizeof *tb);
        for (uint32_t l = 0; l < 4 && 4 * b + l < count; l++) {
            uint32_t i = first + 4 * b + l;
            PrimRec pr;
            prim_read(prims, i, &pr);
            for (int k = 0; k < 9; k++)
                tb->v[k][l] = pr.g[k];
            tb->prim[l] = i;
            tb->valid |= 1u << l;
            if (pr.kind == 1) {
                tb->flags |= QB_SPHERE;
                for (int k = 0; k < 9; k++)
                    tb->v[k][l] = 0.0f;
            }
        }
        if (b + 1 == nb)
            tb->flags |= QB_LAST;
    }
    return ref;
}

static int box_inside(const float *lo, const float *hi, const float *plo, const float *phi)
{
    for (int k = 0; k < 3; k++)
        if (!(lo[k] >= plo[k] && hi[k] <= phi[k]))
            return 0;
    return 1;
}

static uint32_t qtree_node(QTree *t)
{
    if (t->nq == t->capq) {
        uint32_t cap = t->capq ? t->capq * 2 : 1024;
        if (!(t->q = aligned_grow(t->q, t->nq, cap, sizeof *t->q))) {
            t->usable = 0;
            return 0;
        }
        t->capq = cap;
    }
    memset(&t->q[t->nq], 0, sizeof *t->q);
    return t->nq++;
}

/* The 4-wide tree of p; NULL when out of memory. */
static QTree *qtree_build(const PackedScene *p)
{
    double t0 = util_now();
    QTree *t = calloc(1, sizeof *t);
    if (!t)
        return NULL;
    t->host.free = qtree_free;
    t->usable = 1;
    uint32_t nnodes = sm_u32(p, sm_hdr(p, SM_HDR_NNODES));
    const uint8_t *nodes = image_at(p, sm_u32(p, sm_hdr(p, SM_HDR_NODES)));
    const uint8_t *prims = image_at(p, sm_u32(p, sm_hdr(p, SM_HDR_PRIMS)));
    t->stack_len = 3 * (p->bvh.depth + 2) + 8;
    /* room for every inner node and every leaf's blocks, so the arrays never grow */
    uint32_t ninner = 0, nblocks = 0;
    for (uint32_t n = 0; n < nnodes; n++) {
        uint32_t info = node_word(nodes, n, SM_NODE_INFO);
        if (info & SM_NODE_INNER)
            ninner++;
        else
            nblocks += (info + 3) / 4;
    }
    t->capq = ninner ? ninner : 1;
    t->captb = nblocks ? nblocks : 1;
    t->q = aligned_alloc(64, sizeof *t->q * (size_t)t->capq);
    t->tb = aligned_alloc(64, sizeof *t->tb * (size_t)t->captb);
    if (!t->q || !t->tb) {
        qtree_free(&t->host);
        return NULL;
    }
    /* work: (binary inner node, its QNode) pairs still to fill */
    uint32_t *work = malloc(sizeof *work * 2 * (size_t)(nnodes + 1)), nw = 0;
    if (!work || nnodes == 0) {
        t->usable = 0;
        free(work);
        return t;
    }
    uint32_t info0 = node_word(nodes, 0, SM_NODE_INFO);
    if (!(info0 & SM_NODE_INNER)) {
        t->root = qtree_leaf(t, prims, node_word(nodes, 0, SM_NODE_FIRST), info0);
    } else {
        t->root = qtree_node(t);
        work[nw++] = 0;
        work[nw++] = t->root;
    }
    while (nw && t->usable) {
        uint32_t qi = work[--nw], bn = work[--nw];
        uint32_t first = node_word(nodes, bn, SM_NODE_FIRST), axis = node_word(nodes, bn, SM_NODE_INFO) & 3u;
        uint32_t slotnode[4], ns = 0, sidefirst[2], sidecount[2], sideaxis[2];
        for (uint32_t s = 0; s < 2; s++) {
            uint32_t c = first + s, ci = node_word(nodes, c, SM_NODE_INFO);
            sidefirst[s] = ns;
            if (ci & SM_NODE_INNER) {
                uint32_t g0 = node_word(nodes, c, SM_NODE_FIRST);
                float plo[3], phi[3], lo[3], hi[3];
                node_box(nodes, c, plo, phi);
                for (uint32_t g = 0; g < 2; g++) {
                    node_box(nodes, g0 + g, lo, hi);
                    if (!box_inside(lo, hi, plo, phi))
                        t->usable = 0;
                    slotnode[ns++] = g0 + g;
                }
                sidecount[s] = 2;
                sideaxis[s] = ci & 3u;
            } else {
                slotnode[ns++] = c;
                sidecount[s] = 1;
                sideaxis[s] = 0;
            }
        }
        uint32_t ref[4];
        for (uint32_t c = 0; c < ns; c++) {
            uint32_t n = slotnode[c], ni = node_word(nodes, n, SM_NODE_INFO);
            if (ni & SM_NODE_INNER) {
                ref[c] = qtree_node(t);
                work[nw++] = n;
                work[nw++] = ref[c];
            } else {
                ref[c] = qtree_leaf(t, prims, node_word(nodes, n, SM_NODE_FIRST), ni);
            }
        }
        if (!t->usable)
            break;
        QNode *q = &t->q[qi];
        for (uint32_t c = 0; c < ns; c++) {
            float lo[3], hi[3];
            node_box(nodes, slotnode[c], lo, hi);
            for (int k = 0; k < 3; k++) {
                q->b[k][c] = lo[k];
                q->b[3 + k][c] = hi[k];
            }
            q->child[c] = ref[c];
            q->valid |= 1u << c;
        }
        /* The binary walks' order: the near side first (the right one when dir[axis] < 0), and
         * within a side of two slots its near one first; unused slots fill the last positions, in
         * order, so each slot appears once (their valid bit is clear: never pushed). 2 bits a slot. */
        uint32_t side[2][2], unused = 0;
        for (uint32_t s = 0; s < 2; s++) {
            uint32_t a = sidefirst[s];
            side[s][0] = sidecount[s] == 2 ? (a | (a + 1) << 2) : a;
            side[s][1] = sidecount[s] == 2 ? ((a + 1) | a << 2) : a;
        }
        for (uint32_t c = ns; c < 4; c++)
            unused |= c << (2 * c);
        for (uint32_t o = 0; o < 8; o++) {
            uint32_t sa = o >> axis & 1u, sb = 1 - sa;
            uint32_t fa = sidecount[sa] == 2 ? (o >> sideaxis[sa] & 1u) : 0;
            uint32_t fb = sidecount[sb] == 2 ? (o >> sideaxis[sb] & 1u) : 0;
            q->order[o] = (uint8_t)(side[sa][fa] | side[sb][fb] << (2 * sidecount[sa]) | unused);
        }
    }
    free(work);
    t->build_seconds = util_now() - t0;
    return t;
}

/* p's 4-wide tree, built on the first call (thread-safe: a loser of the race frees its own);
 * NULL when out of memory. */
const QTree *ref_qtree_of(const PackedScene *p)
{
    PackedScene *mp = (PackedScene *)p; /* p->host is the reader's cache, not the scene */
    PackHost *h = __atomic_load_n(&mp->host, __ATOMIC_ACQUIRE);
    if (h)
        return (const QTree *)h;
    QTree *t = qtree_build(p);
    if (!t)
        return NULL;
    PackHost *expected = NULL;
    if (!__atomic_compare_exchange_n(&mp->host, &expected, &t->host, 0, __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
        qtree_free(&t->host);
        return (const QTree *)expected;
    }
    return t;
}

double ref_trace_layout_seconds(const PackedScene *p)
{
    const QTree *t = ref_qtree_of(p);
    return t ? t->build_seconds : -1.0;
}

int ref_trace_layout_usable(const PackedScene *p)
{
    const QTree *t = ref_qtree_of(p);
    return t && t->usable;
}
