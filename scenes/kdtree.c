/* scenes/kdtree.c -- SAH kd-tree build by event sweep, invariants (see kdtree.h). */
#include "kdtree.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define KD_DEPTH_LIMIT 60

void kd_default_params(KdParams *p)
{
    p->cost_traversal = 1.0f;
    p->cost_intersect = 1.0f;
    p->empty_bonus = 0.8f;
    p->leaf_size = 1;
    p->max_depth = 0;
}

typedef struct Event {
    float pos;
    uint32_t type;         /* 0 end, 1 planar, 2 start: the sweep order at equal positions */
} Event;

typedef struct Builder {
    const KdParams *p;
    const float *bmin, *bmax;
    KdTree *t;
    uint32_t cap_nodes, cap_refs;
    Event *ev;             /* scratch: events of one axis */
    size_t cap_ev;
    int max_depth;
    int oom;
    float min_gap;         /* no child voxel thinner than this (KD_MIN_GAP of the scene's extent) */
} Builder;

static int cmp_event(const void *a, const void *b)
{
    const Event *x = a, *y = b;
    if (x->pos != y->pos)
        return x->pos < y->pos ? -1 : 1;
    return (int)x->type - (int)y->type;
}

static double area(const float *lo, const float *hi)
{
    double d0 = (double)hi[0] - lo[0], d1 = (double)hi[1] - lo[1], d2 = (double)hi[2] - lo[2];
    return 2.0 * (d0 * d1 + d1 * d2 + d2 * d0);
}

/* A primitive's box clipped to the voxel, on one axis. */
static inline void clip(const Builder *b, uint32_t prim, int axis, const float *vmin, const float *vmax, float *lo,
                        float *hi)
{
    float l = b->bmin[3 * prim + axis], h = b->bmax[3 * prim + axis];
    *lo = l > vmin[axis] ? l : vmin[axis];
    *hi = h < vmax[axis] ? h : vmax[axis];
}

typedef struct Split {
    int axis;              /* -1: none */
    float pos;
    int planar_left;
    double cost;
} Split;

static Split find_split(Builder *b, const uint32_t *prims, uint32_t n, const float *vmin, const float *vmax)
{
    Split best = {-1, 0.0f, 1, INFINITY};
    double sa = area(vmin, vmax);
    if (!(sa > 0.0))
        return best;
    const double ct = b->p->cost_traversal, ci = b->p->cost_intersect, bonus = b->p->empty_bonus;
    if (b->cap_ev < 2 * (size_t)n) {
        free(b->ev);
        b->cap_ev = 2 * (size_t)n;
        b->ev = malloc(b->cap_ev * sizeof *b->ev);
        if (!b->ev) {
            b->oom = 1;
            b->cap_ev = 0;
            return best;
        }
    }
    for (int axis = 0; axis < 3; axis++) {
        if (!(vmax[axis] > vmin[axis]))
            continue;
        size_t ne = 0;
        for (uint32_t i = 0; i < n; i++) {
            float lo, hi;
            clip(b, prims[i], axis, vmin, vmax, &lo, &hi);
            if (lo == hi) {
                b->ev[ne++] = (Event){lo, 1};
            } else {
                b->ev[ne++] = (Event){lo, 2};
                b->ev[ne++] = (Event){hi, 0};
            }
        }
        qsort(b->ev, ne, sizeof *b->ev, cmp_event);
        uint32_t nl = 0, nr = n;
        float lo_box[3], hi_box[3];
        for (size_t i = 0; i < ne;) {
            float pos = b->ev[i].pos;
            uint32_t pe = 0, pp = 0, ps = 0;
            while (i < ne && b->ev[i].pos == pos && b->ev[i].type == 0) {
                pe++;
                i++;
            }
            while (i < ne && b->ev[i].pos == pos && b->ev[i].type == 1) {
                pp++;
                i++;
            }
            while (i < ne && b->ev[i].pos == pos && b->ev[i].type == 2) {
                ps++;
                i++;
            }
            nr -= pp + pe;
            if (pos - vmin[axis] >= b->min_gap && vmax[axis] - pos >= b->min_gap) {
                memcpy(lo_box, vmin, sizeof lo_box);
                memcpy(hi_box, vmax, sizeof hi_box);
                hi_box[axis] = pos;
                double pl = area(vmin, hi_box) / sa;
                lo_box[axis] = pos;
                double pr = area(lo_box, vmax) / sa;
                /* planar primitives on the left, then on the right */
                for (int side = 1; side >= 0; side--) {
                    uint32_t l = nl + (side ? pp : 0), r = nr + (side ? 0 : pp);
                    double c = ct + ci * (pl * l + pr * r);
                    if (l == 0 || r == 0)
                        c *= bonus;
                    if (c < best.cost) {
                        best.cost = c;
                        best.axis = axis;
                        best.pos = pos;
                        best.planar_left = side;
                    }
                }
            }
            nl += ps + pp;
        }
    }
    return best;
}

static uint32_t new_pair(Builder *b)
{
    if (b->t->nnodes + 2 > b->cap_nodes) {
        uint32_t cap = b->cap_nodes ? 2 * b->cap_nodes : 1024;
        KdNode *nn = realloc(b->t->nodes, (size_t)cap * sizeof *nn);
        if (!nn) {
            b->oom = 1;
            return 0;
        }
        b->t->nodes = nn;
        b->cap_nodes = cap;
    }
    uint32_t i = b->t->nnodes;
    b->t->nnodes += 2;
    return i;
}

static void make_leaf(Builder *b, uint32_t node, const uint32_t *prims, uint32_t n, uint32_t depth)
{
    KdTree *t = b->t;
    if (t->nrefs + n > b->cap_refs) {
        uint32_t cap = b->cap_refs ? 2 * b->cap_refs : 1024;
        while (cap < t->nrefs + n)
            cap *= 2;
        uint32_t *np = realloc(t->prims, (size_t)cap * sizeof *np);
        if (!np) {
            b->oom = 1;
            return;
        }
        t->prims = np;
        b->cap_refs = cap;
    }
    if (n)
        memcpy(t->prims + t->nrefs, prims, (size_t)n * sizeof *prims);
    t->nodes[node] = (KdNode){0.0f, KD_LEAF, t->nrefs, n};
    t->nrefs += n;
    t->nleaves++;
    t->nempty += n == 0;
    if (n > t->max_leaf)
        t->max_leaf = n;
    if (depth > t->depth)
        t->depth = depth;
}

/* Build the subtree of node over prims (owned by the caller) in voxel [vmin, vmax]. */
static void build(Builder *b, uint32_t node, uint32_t *prims, uint32_t n, const float *vmin, const float *vmax,
                  uint32_t depth, double sa_root)
{
    if (b->oom)
        return;
    const double ci = b->p->cost_intersect;
    Split s = {-1, 0.0f, 1, INFINITY};
    if (n > (uint32_t)b->p->leaf_size && (int)depth <= b->max_depth)
        s = find_split(b, prims, n, vmin, vmax);
    if (s.axis < 0 || !(s.cost < ci * (double)n)) {
        make_leaf(b, node, prims, n, depth);
        b->t->sah_cost += area(vmin, vmax) / sa_root * ci * (double)n;
        return;
    }
    /* Classify: left, right or both sides of the plane. */
    uint32_t *left = malloc(((size_t)n + 1) * sizeof *left), *right = malloc(((size_t)n + 1) * sizeof *right);
    if (!left || !right) {
        free(left);
        free(right);
        b->oom = 1;
        return;
    }
    uint32_t nl = 0, nr = 0;
    for (uint32_t i = 0; i < n; i++) {
        float lo, hi;
        clip(b, prims[i], s.axis, vmin, vmax, &lo, &hi);
        if (lo == s.pos && hi == s.pos) {
            if (s.planar_left)
                left[nl++] = prims[i];
            else
                right[nr++] = prims[i];
        } else {
            if (lo < s.pos)
                left[nl++] = prims[i];
            if (hi > s.pos)
                right[nr++] = prims[i];
        }
    }
    uint32_t c = new_pair(b);
    if (b->oom) {
        free(left);
        free(right);
        return;
    }
    b->t->nodes[node] = (KdNode){s.pos, (uint32_t)s.axis, c, 0};
    b->t->sah_cost += area(vmin, vmax) / sa_root * b->p->cost_traversal;
    float lmax[3], rmin[3];
    memcpy(lmax, vmax, sizeof lmax);
    memcpy(rmin, vmin, sizeof rmin);
    lmax[s.axis] = s.pos;
    rmin[s.axis] = s.pos;
    build(b, c, left, nl, vmin, lmax, depth + 1, sa_root);
    free(left);
    build(b, c + 1, right, nr, rmin, vmax, depth + 1, sa_root);
    free(right);
}

int kd_build(const KdParams *p, const float *bmin, const float *bmax, uint32_t n, KdTree *out, char *err,
             size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (p->max_depth < 0 || p->max_depth > KD_DEPTH_LIMIT || p->leaf_size < 0 || !(p->cost_traversal > 0.0f) ||
        !(p->cost_intersect > 0.0f) || !(p->empty_bonus > 0.0f && p->empty_bonus <= 1.0f)) {
        snprintf(err, errlen, "kd-tree: parameters out of range (max depth 0..%d, costs > 0, empty bonus in (0, 1])",
                 KD_DEPTH_LIMIT);
        return -1;
    }
    for (int k = 0; k < 3; k++) {
        out->bmin[k] = INFINITY;
        out->bmax[k] = -INFINITY;
    }
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            float lo = bmin[3 * i + k], hi = bmax[3 * i + k];
            if (isnan(lo) || isnan(hi) || lo > hi) {
                snprintf(err, errlen, "kd-tree: primitive %u has a bad box on axis %d ([%g, %g])", i, k, lo, hi);
                return -1;
            }
            out->bmin[k] = lo < out->bmin[k] ? lo : out->bmin[k];
            out->bmax[k] = hi > out->bmax[k] ? hi : out->bmax[k];
        }
    out->nprims = n;
    Builder b = {p, bmin, bmax, out, 0, 0, NULL, 0, 0, 0, 0.0f};
    for (int k = 0; k < 3; k++)
        if (n && (float)(KD_MIN_GAP * ((double)out->bmax[k] - out->bmin[k])) > b.min_gap)
            b.min_gap = (float)(KD_MIN_GAP * ((double)out->bmax[k] - out->bmin[k]));
    if (!(b.min_gap > 0.0f))
        b.min_gap = FLT_MIN; /* a point-sized scene: any split strictly inside */
    b.max_depth = p->max_depth ? p->max_depth : (int)lrint(8.0 + 1.3 * log2((double)(n > 1 ? n : 1)));
    if (b.max_depth > KD_DEPTH_LIMIT)
        b.max_depth = KD_DEPTH_LIMIT;
    out->nodes = malloc(1024 * sizeof *out->nodes);
    uint32_t *all = malloc(((size_t)n + 1) * sizeof *all);
    if (!out->nodes || !all) {
        free(all);
        kd_free(out);
        snprintf(err, errlen, "kd-tree: out of memory");
        return -1;
    }
    b.cap_nodes = 1024;
    out->nnodes = 1;
    for (uint32_t i = 0; i < n; i++)
        all[i] = i;
    if (n == 0) {
        make_leaf(&b, 0, NULL, 0, 1);
        for (int k = 0; k < 3; k++)
            out->bmin[k] = out->bmax[k] = 0.0f;
    } else {
        double sa = area(out->bmin, out->bmax);
        build(&b, 0, all, n, out->bmin, out->bmax, 1, sa > 0.0 ? sa : 1.0);
    }
    free(all);
    free(b.ev);
    if (b.oom) {
        kd_free(out);
        snprintf(err, errlen, "kd-tree: out of memory building over %u primitives", n);
        return -1;
    }
    return 0;
}

void kd_free(KdTree *t)
{
    free(t->nodes);
    free(t->prims);
    t->nodes = NULL;
    t->prims = NULL;
    t->nnodes = t->nrefs = 0;
}

/* Must primitive i be in a leaf with voxel [vmin, vmax]? Overlap with positive extent on every
 * axis where the box has extent; a flat axis must lie strictly inside the voxel. */
static int must_contain(const float *bmin, const float *bmax, uint32_t i, const float *vmin, const float *vmax)
{
    for (int k = 0; k < 3; k++) {
        float lo = bmin[3 * i + k], hi = bmax[3 * i + k];
        if (lo < hi) {
            if (!(lo < vmax[k] && hi > vmin[k]))
                return 0;
        } else if (!(lo > vmin[k] && lo < vmax[k])) {
            return 0;
        }
    }
    return 1;
}

typedef struct CheckCtx {
    const KdTree *t;
    const float *bmin, *bmax;
    uint8_t *seen_node;
    uint8_t *in_some_leaf;
    char *err;
    size_t errlen;
    int bad;
} CheckCtx;

static void check_node(CheckCtx *c, uint32_t node, const float *vmin, const float *vmax, uint32_t depth)
{
    const KdTree *t = c->t;
    if (c->bad)
        return;
    if (node >= t->nnodes || c->seen_node[node]) {
        snprintf(c->err, c->errlen, "kd-tree: node %u %s", node, node >= t->nnodes ? "out of range" : "reached twice");
        c->bad = 1;
        return;
    }
    c->seen_node[node] = 1;
    const KdNode *nd = &t->nodes[node];
    if (nd->axis == KD_LEAF) {
        if ((uint64_t)nd->a + nd->count > t->nrefs) {
            snprintf(c->err, c->errlen, "kd-tree: leaf %u lists past the end of the primitive list", node);
            c->bad = 1;
            return;
        }
        for (uint32_t i = 0; i < nd->count; i++) {
            uint32_t pr = t->prims[nd->a + i];
            if (pr >= t->nprims) {
                snprintf(c->err, c->errlen, "kd-tree: leaf %u holds primitive %u of %u", node, pr, t->nprims);
                c->bad = 1;
                return;
            }
            c->in_some_leaf[pr] = 1;
        }
        return;
    }
    if (nd->axis > 2 || !(nd->split >= vmin[nd->axis] && nd->split <= vmax[nd->axis])) {
        snprintf(c->err, c->errlen, "kd-tree: node %u: axis %u, split %g outside its voxel", node, nd->axis, nd->split);
        c->bad = 1;
        return;
    }
    float lmax[3], rmin[3];
    memcpy(lmax, vmax, sizeof lmax);
    memcpy(rmin, vmin, sizeof rmin);
    lmax[nd->axis] = nd->split;
    rmin[nd->axis] = nd->split;
    check_node(c, nd->a, vmin, lmax, depth + 1);
    check_node(c, nd->a + 1, rmin, vmax, depth + 1);
}

/* Every leaf that primitive pr must be in (must_contain) lists it: descend through the voxels its
 * box touches. */
static int check_prim(const KdTree *t, const float *bmin, const float *bmax, uint32_t pr, uint32_t node,
                      const float *vmin, const float *vmax, char *err, size_t errlen)
{
    for (int k = 0; k < 3; k++)
        if (bmin[3 * pr + k] > vmax[k] || bmax[3 * pr + k] < vmin[k])
            return 0;
    const KdNode *nd = &t->nodes[node];
    if (nd->axis == KD_LEAF) {
        if (!must_contain(bmin, bmax, pr, vmin, vmax))
            return 0;
        for (uint32_t i = 0; i < nd->count; i++)
            if (t->prims[nd->a + i] == pr)
                return 0;
        snprintf(err, errlen, "kd-tree: primitive %u overlaps leaf %u but is not in it", pr, node);
        return -1;
    }
    float lmax[3], rmin[3];
    memcpy(lmax, vmax, sizeof lmax);
    memcpy(rmin, vmin, sizeof rmin);
    lmax[nd->axis] = nd->split;
    rmin[nd->axis] = nd->split;
    if (check_prim(t, bmin, bmax, pr, nd->a, vmin, lmax, err, errlen))
        return -1;
    return check_prim(t, bmin, bmax, pr, nd->a + 1, rmin, vmax, err, errlen);
}

int kd_check(const KdTree *t, const float *bmin, const float *bmax, char *err, size_t errlen)
{
    CheckCtx c = {t, bmin, bmax, calloc(t->nnodes ? t->nnodes : 1, 1), calloc(t->nprims ? t->nprims : 1, 1), err,
                  errlen, 0};
    if (!c.seen_node || !c.in_some_leaf) {
        free(c.seen_node);
        free(c.in_some_leaf);
        snprintf(err, errlen, "kd-tree check: out of memory");
        return -1;
    }
    check_node(&c, 0, t->bmin, t->bmax, 1);
    for (uint32_t i = 0; !c.bad && i < t->nnodes; i++)
        if (!c.seen_node[i]) {
            snprintf(err, errlen, "kd-tree: node %u is not reachable", i);
            c.bad = 1;
        }
    for (uint32_t i = 0; !c.bad && i < t->nprims; i++)
        if (!c.in_some_leaf[i]) {
            snprintf(err, errlen, "kd-tree: primitive %u is in no leaf", i);
            c.bad = 1;
        }
    /* (the structure is sound now, so the descent below cannot leave the node array) */
    for (uint32_t i = 0; !c.bad && i < t->nprims; i++)
        if (check_prim(t, bmin, bmax, i, 0, t->bmin, t->bmax, err, errlen))
            c.bad = 1;
    free(c.seen_node);
    free(c.in_some_leaf);
    return c.bad ? -1 : 0;
}
