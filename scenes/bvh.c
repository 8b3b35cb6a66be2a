/* scenes/bvh.c -- binned SAH BVH builder, invariant checker and cost.
 *
 * Owns: BvhNode topology and prim_index order. Must not: look at primitive geometry beyond the
 * boxes it is given, or lay the tree out in simulated memory.
 *
 * Deterministic: the same boxes and parameters give the same tree, bit for bit (no threads, no
 * unstable sorts), so images and cycle counts do not change from run to run.
 *
 * The build is written for speed (primitives copied into build order, one binning pass for the
 * three axes, children's boxes grown during the partition, only non-empty bins swept, inline
 * min/max) and must give the trees of the plain algorithm in tests/support/bvh_ref.c, bit for bit,
 * zeros' signs included: tests/unit/test_bvh.c compares them.
 */
#include "bvh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void bvh_default_params(BvhParams *p)
{
    p->max_leaf_size = 4;
    p->bins = 16;
    p->cost_traversal = 1.0f;
    p->cost_intersect = 1.0f;
}

/* Lane 3 is padding (4 lanes let the compiler grow a box with two vector min/max operations); it
 * is never read back. */
typedef struct Box { _Alignas(16) float lo[4]; float hi[4]; } Box;

/* The minimum and maximum the trees were first built with, bit for bit. That build called libm's
 * fminf(new, held) / fmaxf(new, held) (GCC orders the operands of these commutative calls so) and
 * glibc's x86-64 fminf / fmaxf (minss / maxss) return their second operand on a tie: so the value
 * already held stays, which decides between -0.0 and +0.0 and so the bytes stored. No NaN reaches
 * them: bvh_build rejects NaN boxes, and centroids of finite boxes are finite or infinite. */
static inline float min_keep(float held, float x) { return x < held ? x : held; }
static inline float max_keep(float held, float x) { return x > held ? x : held; }
/* The same result over a sequence visited backwards: on a tie take the new value (it comes
 * earlier in the forward order). */
static inline float min_take(float held, float x) { return held < x ? held : x; }
static inline float max_take(float held, float x) { return held > x ? held : x; }

static const Box box_none = {{INFINITY, INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY, -INFINITY}};

static void box_empty(Box *b) { *b = box_none; }

/* Grow b by the box [lo, hi] (4 lanes each). */
static inline void box_grow(Box *restrict b, const float *restrict lo, const float *restrict hi)
{
    for (int k = 0; k < 4; k++) {
        b->lo[k] = min_keep(b->lo[k], lo[k]);
        b->hi[k] = max_keep(b->hi[k], hi[k]);
    }
}

/* box_grow for primitives visited in decreasing position: the box box_grow gives in increasing
 * position, bit for bit. */
static inline void box_grow_backwards(Box *restrict b, const float *restrict lo, const float *restrict hi)
{
    for (int k = 0; k < 4; k++) {
        b->lo[k] = min_take(b->lo[k], lo[k]);
        b->hi[k] = max_take(b->hi[k], hi[k]);
    }
}

/* Written out: GCC -O2 does not unroll the three-axis loop, and the sweep calls this twice per
 * candidate split. */
static inline float box_area(const Box *b)
{
    float dx = b->hi[0] > b->lo[0] ? b->hi[0] - b->lo[0] : 0.0f;
    float dy = b->hi[1] > b->lo[1] ? b->hi[1] - b->lo[1] : 0.0f;
    float dz = b->hi[2] > b->lo[2] ? b->hi[2] - b->lo[2] : 0.0f;
    return 2.0f * (dx * dy + dy * dz + dz * dx);
}

/* A primitive during the build, kept in prim_index order so that every pass over a node reads
 * memory in sequence; the partition moves the records themselves. */
typedef struct BuildPrim {
    float lo[4], hi[4];
    float c[4]; /* centroid */
} BuildPrim;

/* A node to build: its own box is already in nodes[node]; cb is its centroids' box. */
typedef struct Task {
    uint32_t node, begin, end, depth;
    Box cb;
} Task;

typedef struct Builder {
    const BvhParams *p;
    BuildPrim *prim; /* n, in prim_index order (which the partition permutes with them) */
    Bvh *b;
} Builder;

/* Bin of a centroid on one axis; the same expression is used to count and to partition, so
 * the two always agree. */
static inline int bin_of(float c, float cmin, float scale, int bins)
{
    int i = (int)((c - cmin) * scale);
    return i < 0 ? 0 : (i >= bins ? bins - 1 : i);
}

typedef struct Split { int axis, bin; float cost; } Split;

/* The bins of one axis: their boxes and primitive counts. */
typedef struct Bins {
    Box box[256];
    uint32_t count[256];
} Bins;

/* The best split of one axis's bins into (best->bin and below, the rest), if it beats best.
 * Only non-empty bins are visited: a split after an empty bin has the same left box, right
 * box and counts, hence the same cost, as the split before it, and only a strictly lower cost
 * replaces best; growing a box by an empty bin leaves it unchanged, bit for bit. So the cost and
 * the bin found are those of sweeping every bin. */
static void sweep_axis(const BvhParams *p, const Bins *bins, int axis, uint32_t total, float parea,
                       Split *best)
{
    int nonempty[256], m = 0;
    for (int i = 0; i < p->bins; i++)
        if (bins->count[i] > 0)
            nonempty[m++] = i;
    /* right_area[r]: the area of the union of the non-empty bins r .. m-1, grown from the right */
    float right_area[256];
    Box acc = box_none;
    for (int r = m - 1; r > 0; r--) {
        const Box *bx = &bins->box[nonempty[r]];
        box_grow(&acc, bx->lo, bx->hi);
        right_area[r] = box_area(&acc);
    }
    Box left = box_none;
    uint32_t nleft = 0;
    for (int r = 0; r < m - 1; r++) {
        const Box *bx = &bins->box[nonempty[r]];
        box_grow(&left, bx->lo, bx->hi);
        nleft += bins->count[nonempty[r]];
        uint32_t nright = total - nleft;
        float cost = p->cost_traversal +
                     p->cost_intersect * (box_area(&left) * (float)nleft + right_area[r + 1] * (float)nright) /
                         parea;
        if (cost < best->cost) {
            best->axis = axis;
            best->bin = nonempty[r];
            best->cost = cost;
        }
    }
}

/* The axis scale of the binning, or 0 when the axis gives no split: no extent, a denormal
 * extent (scale infinite: binning along it would be meaningless), or an infinite one (scale 0:
 * every centroid would fall in bin 0). */
static float bin_scale(const Box *cbox, int axis, int bins)
{
    float extent = cbox->hi[axis] - cbox->lo[axis];
    if (!(extent > 0.0f))
        return 0.0f;
    float scale = (float)bins / extent;
    return isfinite(scale) ? scale : 0.0f;
}

/* Put primitive q in its bin on one axis. */
static inline void bin_add(Bins *bins, const BuildPrim *q, int axis, float cmin, float scale, int nb)
{
    int i = bin_of(q->c[axis], cmin, scale, nb);
    box_grow(&bins->box[i], q->lo, q->hi);
    bins->count[i]++;
}

static Split find_split(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, float parea)
{
    const BvhParams *p = B->p;
    int nb = p->bins;
    Split best = {-1, 0, INFINITY};
    float scale[3];
    int live = 0;
    Bins bins[3];
    for (int axis = 0; axis < 3; axis++) {
        scale[axis] = bin_scale(cbox, axis, nb);
        if (scale[axis] > 0.0f) {
            live |= 1 << axis;
            for (int i = 0; i < nb; i++) {
                bins[axis].box[i] = box_none;
                bins[axis].count[i] = 0;
            }
        }
    }
    if (!live)
        return best;
    /* One pass bins every axis; each bin still grows in primitive order. */
    const BuildPrim *prim = B->prim;
    if (live == 7) { /* the common case, unrolled */
        float lo0 = cbox->lo[0], lo1 = cbox->lo[1], lo2 = cbox->lo[2];
        float s0 = scale[0], s1 = scale[1], s2 = scale[2];
        for (uint32_t j = begin; j < end; j++) {
            bin_add(&bins[0], &prim[j], 0, lo0, s0, nb);
            bin_add(&bins[1], &prim[j], 1, lo1, s1, nb);
            bin_add(&bins[2], &prim[j], 2, lo2, s2, nb);
        }
    } else {
        for (uint32_t j = begin; j < end; j++)
            for (int axis = 0; axis < 3; axis++)
                if (live & 1 << axis)
                    bin_add(&bins[axis], &prim[j], axis, cbox->lo[axis], scale[axis], nb);
    }
    for (int axis = 0; axis < 3; axis++)
        if (live & 1 << axis)
            sweep_axis(p, &bins[axis], axis, end - begin, parea, &best);
    return best;
}

/* The children's boxes and centroid boxes, as a scan of each child's primitives in order gives. */
typedef struct Halves { Box box[2], cbox[2]; } Halves;

/* Partition [begin, end) so primitives whose bin <= split.bin come first; returns mid. The
 * halves' boxes are grown on the way: a left position is final once passed, in increasing order;
 * a right position once filled, in decreasing order (hence box_grow_backwards). */
static uint32_t partition(Builder *B, uint32_t begin, uint32_t end, const Box *cbox, Split s, Halves *h)
{
    float scale = (float)B->p->bins / (cbox->hi[s.axis] - cbox->lo[s.axis]);
    float cmin = cbox->lo[s.axis];
    int bins = B->p->bins;
    BuildPrim *prim = B->prim;
    uint32_t *id = B->b->prim_index;
    /* locals, not *h, so that the compiler keeps the four boxes in registers */
    Box box0 = box_none, cbox0 = box_none, box1 = box_none, cbox1 = box_none;
    uint32_t i = begin, j = end;
    while (i < j) {
        BuildPrim q = prim[i];
        if (bin_of(q.c[s.axis], cmin, scale, bins) <= s.bin) {
            box_grow(&box0, q.lo, q.hi);
            box_grow(&cbox0, q.c, q.c);
            i++;
        } else {
            j--;
            prim[i] = prim[j];
            prim[j] = q;
            uint32_t qi = id[i];
            id[i] = id[j];
            id[j] = qi;
            box_grow_backwards(&box1, q.lo, q.hi);
            box_grow_backwards(&cbox1, q.c, q.c);
        }
    }
    *h = (Halves){{box0, box1}, {cbox0, cbox1}};
    return i;
}

/* The box and centroid box of [begin, end), scanned in order. */
static void scan_bounds(const BuildPrim *prim, uint32_t begin, uint32_t end, Box *box, Box *cbox)
{
    box_empty(box);
    box_empty(cbox);
    for (uint32_t j = begin; j < end; j++) {
        box_grow(box, prim[j].lo, prim[j].hi);
        box_grow(cbox, prim[j].c, prim[j].c);
    }
}

static void set_box(BvhNode *n, const Box *b)
{
    memcpy(n->bmin, b->lo, sizeof n->bmin);
    memcpy(n->bmax, b->hi, sizeof n->bmax);
}

static void make_leaf(BvhNode *n, uint32_t begin, uint32_t end)
{
    n->first = begin;
    n->count = end - begin;
    n->axis = 0;
}

static int check_params(const BvhParams *p, char *err, size_t errlen)
{
    if (p->max_leaf_size < 1 || p->bins < 2 || p->bins > 256 || !(p->cost_traversal >= 0.0f) ||
        !(p->cost_intersect > 0.0f)) {
        snprintf(err, errlen, "bvh: bad parameters (leaf size %d, bins %d, costs %g/%g)",
                 p->max_leaf_size, p->bins, (double)p->cost_traversal, (double)p->cost_intersect);
        return -1;
    }
    return 0;
}

static int check_boxes(const float *bmin, const float *bmax, uint32_t n, char *err, size_t errlen)
{
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            float lo = bmin[3 * i + k], hi = bmax[3 * i + k];
            if (!isfinite(lo) || !isfinite(hi) || lo > hi) {
                snprintf(err, errlen, "bvh: primitive %u has a bad box on axis %d: [%g, %g]", i, k,
                         (double)lo, (double)hi);
                return -1;
            }
        }
    }
    return 0;
}

/* Where node t splits: mid, or 0 for a leaf; the halves' bounds in h, the axis in *axis. */
static uint32_t split_node(Builder *B, const Task *t, const Box *nb, Halves *h, uint32_t *axis)
{
    const BvhParams *p = B->p;
    uint32_t count = t->end - t->begin;
    *axis = 0;
    if (count < 2)
        return 0;
    float parea = box_area(nb);
    Split s = find_split(B, t->begin, t->end, &t->cb, parea > 0.0f ? parea : 1.0f);
    float leaf_cost = p->cost_intersect * (float)count;
    if (s.axis >= 0 && (s.cost < leaf_cost || count > (uint32_t)p->max_leaf_size)) {
        *axis = (uint32_t)s.axis;
        return partition(B, t->begin, t->end, &t->cb, s, h);
    }
    if (s.axis < 0 && count > (uint32_t)p->max_leaf_size) {
        /* All centroids coincide: no box split can separate them; halve by index so leaves
         * stay within the size limit. */
        uint32_t mid = t->begin + count / 2;
        scan_bounds(B->prim, t->begin, mid, &h->box[0], &h->cbox[0]);
        scan_bounds(B->prim, mid, t->end, &h->box[1], &h->cbox[1]);
        return mid;
    }
    return 0;
}

int bvh_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out,
              char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (check_params(p, err, errlen) != 0 || check_boxes(bmin, bmax, n, err, errlen) != 0)
        return -1;
    out->nprims = n;
    if (n == 0)
        return 0;

    Builder B = {p, malloc(sizeof(BuildPrim) * n), out};
    out->prim_index = malloc(sizeof(uint32_t) * n);
    out->nodes = malloc(sizeof(BvhNode) * (2 * (size_t)n - 1));
    /* Every task on the stack is the right sibling pending at a distinct depth of the path
     * being built, and a tree of n primitives has at most n levels. */
    Task *stack = malloc(sizeof(Task) * ((size_t)n + 1));
    if (!B.prim || !out->prim_index || !out->nodes || !stack) {
        snprintf(err, errlen, "bvh: out of memory for %u primitives", n);
        free(B.prim);
        free(stack);
        bvh_free(out);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        BuildPrim *q = &B.prim[i];
        out->prim_index[i] = i;
        for (int k = 0; k < 3; k++) {
            q->lo[k] = bmin[3 * i + k];
            q->hi[k] = bmax[3 * i + k];
            q->c[k] = 0.5f * (bmin[3 * i + k] + bmax[3 * i + k]);
        }
        q->lo[3] = q->hi[3] = q->c[3] = 0.0f;
    }

    Box root;
    uint32_t sp = 0;
    stack[sp] = (Task){0, 0, n, 1, box_none};
    scan_bounds(B.prim, 0, n, &root, &stack[sp].cb);
    set_box(&out->nodes[0], &root);
    sp++;
    out->nnodes = 1;
    while (sp > 0) {
        Task t = stack[--sp];
        BvhNode *node = &out->nodes[t.node];
        if (t.depth > out->depth)
            out->depth = t.depth;
        Box nb = box_none;
        memcpy(nb.lo, node->bmin, sizeof node->bmin);
        memcpy(nb.hi, node->bmax, sizeof node->bmax);
        Halves h;
        uint32_t axis;
        uint32_t mid = split_node(&B, &t, &nb, &h, &axis);
        if (mid == 0) {
            make_leaf(node, t.begin, t.end);
            out->nleaves++;
            continue;
        }
        uint32_t left = out->nnodes;
        out->nnodes += 2;
        node->first = left;
        node->count = 0;
        node->axis = axis;
        set_box(&out->nodes[left], &h.box[0]);
        set_box(&out->nodes[left + 1], &h.box[1]);
        stack[sp++] = (Task){left + 1, mid, t.end, t.depth + 1, h.cbox[1]};
        stack[sp++] = (Task){left, t.begin, mid, t.depth + 1, h.cbox[0]};
    }
    free(stack);
    free(B.prim);
    out->sah_cost = bvh_sah_cost(out, p);
    return 0;
}

void bvh_free(Bvh *b)
{
    free(b->nodes);
    free(b->prim_index);
    memset(b, 0, sizeof *b);
}

static int inside(const float *lo, const float *hi, const float *plo, const float *phi)
{
    for (int k = 0; k < 3; k++)
        if (lo[k] < plo[k] || hi[k] > phi[k])
            return 0;
    return 1;
}

int bvh_check(const Bvh *b, const float *bmin, const float *bmax, char *err, size_t errlen)
{
    if (b->nprims == 0)
        return b->nnodes == 0 ? 0 : (snprintf(err, errlen, "bvh: nodes without primitives"), -1);
    int rc = -1;
    uint8_t *seen_prim = calloc(b->nprims, 1);
    uint8_t *seen_node = calloc(b->nnodes, 1);
    uint32_t *stack = malloc(sizeof(uint32_t) * (b->nnodes + 1));
    if (!seen_prim || !seen_node || !stack) {
        snprintf(err, errlen, "bvh: out of memory");
        goto out;
    }
    uint32_t sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        uint32_t i = stack[--sp];
        const BvhNode *n = &b->nodes[i];
        if (seen_node[i]++) {
            snprintf(err, errlen, "bvh: node %u reached twice", i);
            goto out;
        }
        for (int k = 0; k < 3; k++) {
            if (isnan(n->bmin[k]) || isnan(n->bmax[k]) || n->bmin[k] > n->bmax[k]) {
                snprintf(err, errlen, "bvh: node %u has a bad box on axis %d", i, k);
                goto out;
            }
        }
        if (n->count > 0) {
            if (n->first > b->nprims || n->count > b->nprims - n->first) {
                snprintf(err, errlen, "bvh: leaf %u range [%u, +%u) outside %u primitives", i,
                         n->first, n->count, b->nprims);
                goto out;
            }
            for (uint32_t j = n->first; j < n->first + n->count; j++) {
                uint32_t pi = b->prim_index[j];
                if (pi >= b->nprims || seen_prim[pi]++) {
                    snprintf(err, errlen, "bvh: primitive %u is listed twice (again in leaf %u)", pi, i);
                    goto out;
                }
                if (!inside(&bmin[3 * pi], &bmax[3 * pi], n->bmin, n->bmax)) {
                    snprintf(err, errlen, "bvh: primitive %u sticks out of leaf %u", pi, i);
                    goto out;
                }
            }
        } else {
            if (n->first + 1 >= b->nnodes || n->first <= i || n->axis > 2) {
                snprintf(err, errlen, "bvh: inner node %u has bad children index %u", i, n->first);
                goto out;
            }
            for (uint32_t c = n->first; c <= n->first + 1; c++) {
                if (!inside(b->nodes[c].bmin, b->nodes[c].bmax, n->bmin, n->bmax)) {
                    snprintf(err, errlen, "bvh: child %u sticks out of its parent %u", c, i);
                    goto out;
                }
                stack[sp++] = c;
            }
        }
    }
    for (uint32_t i = 0; i < b->nprims; i++) {
        if (!seen_prim[i]) {
            snprintf(err, errlen, "bvh: primitive %u is in no leaf", i);
            goto out;
        }
    }
    for (uint32_t i = 0; i < b->nnodes; i++) {
        if (!seen_node[i]) {
            snprintf(err, errlen, "bvh: node %u is unreachable", i);
            goto out;
        }
    }
    rc = 0;
out:
    free(seen_prim);
    free(seen_node);
    free(stack);
    return rc;
}

/* Surface area in double: a box of finite floats has a finite area here (extents up to 7e38,
 * products up to 5e77), where the float area overflows from extents of about 1e19 on (a sphere of
 * radius 1e30 gave inf / inf = NaN as the cost). */
static double node_area(const float *lo, const float *hi)
{
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = hi[k] > lo[k] ? (double)hi[k] - (double)lo[k] : 0.0;
    return 2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

double bvh_sah_cost(const Bvh *b, const BvhParams *p)
{
    if (b->nnodes == 0)
        return 0.0;
    double ra = node_area(b->nodes[0].bmin, b->nodes[0].bmax);
    if (!(ra > 0.0))
        ra = 1.0;
    double cost = 0.0;
    for (uint32_t i = 0; i < b->nnodes; i++) {
        const BvhNode *n = &b->nodes[i];
        double a = node_area(n->bmin, n->bmax) / ra;
        cost += a * (n->count > 0 ? (double)p->cost_intersect * n->count : (double)p->cost_traversal);
    }
    return cost;
}
