/* scenes/bvh.c -- binned SAH BVH builder, invariant checker and cost.
 *
 * Owns: BvhNode topology and prim_index order. Must not: look at primitive geometry beyond the
 * boxes it is given, or lay the tree out in simulated memory.
 *
 * Deterministic: the same boxes and parameters give the same tree, bit for bit (no threads, no
 * unstable sorts), so images and cycle counts do not change from run to run.
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

typedef struct Box { float lo[3], hi[3]; } Box;

static void box_empty(Box *b)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = INFINITY;
        b->hi[k] = -INFINITY;
    }
}

static void box_grow(Box *b, const float *lo, const float *hi)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = fminf(b->lo[k], lo[k]);
        b->hi[k] = fmaxf(b->hi[k], hi[k]);
    }
}

static float box_area(const Box *b)
{
    float d[3];
    for (int k = 0; k < 3; k++)
        d[k] = b->hi[k] > b->lo[k] ? b->hi[k] - b->lo[k] : 0.0f;
    return 2.0f * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

typedef struct Task { uint32_t node, begin, end, depth; } Task;

typedef struct Builder {
    const BvhParams *p;
    const float *bmin, *bmax;
    float *centroid;         /* n * 3 */
    Bvh *b;
} Builder;

/* Bin of a centroid on one axis; the same expression is used to count and to partition, so
 * the two always agree. */
static int bin_of(float c, float cmin, float scale, int bins)
{
    int i = (int)((c - cmin) * scale);
    return i < 0 ? 0 : (i >= bins ? bins - 1 : i);
}

typedef struct Split { int axis, bin; float cost; } Split;

static Split find_split(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, float parea)
{
    const BvhParams *p = B->p;
    int nb = p->bins;
    Split best = {-1, 0, INFINITY};
    Box bins[256], right[256];
    uint32_t cnt[256];
    for (int axis = 0; axis < 3; axis++) {
        float extent = cbox->hi[axis] - cbox->lo[axis];
        if (!(extent > 0.0f))
            continue;
        float scale = (float)nb / extent;
        if (!isfinite(scale)) /* a denormal extent: binning along it would be meaningless */
            continue;
        for (int i = 0; i < nb; i++) {
            box_empty(&bins[i]);
            cnt[i] = 0;
        }
        for (uint32_t j = begin; j < end; j++) {
            uint32_t pi = B->b->prim_index[j];
            int i = bin_of(B->centroid[3 * pi + axis], cbox->lo[axis], scale, nb);
            box_grow(&bins[i], &B->bmin[3 * pi], &B->bmax[3 * pi]);
            cnt[i]++;
        }
        /* Sweep from the right to get the right side's boxes, then from the left. */
        Box acc;
        box_empty(&acc);
        for (int i = nb - 1; i > 0; i--) {
            box_grow(&acc, bins[i].lo, bins[i].hi);
            right[i] = acc;
        }
        Box left;
        box_empty(&left);
        uint32_t nleft = 0, total = end - begin;
        for (int i = 0; i < nb - 1; i++) {
            box_grow(&left, bins[i].lo, bins[i].hi);
            nleft += cnt[i];
            uint32_t nright = total - nleft;
            if (nleft == 0 || nright == 0)
                continue;
            float cost = p->cost_traversal +
                         p->cost_intersect * (box_area(&left) * (float)nleft +
                                              box_area(&right[i + 1]) * (float)nright) / parea;
            if (cost < best.cost) {
                best.axis = axis;
                best.bin = i;
                best.cost = cost;
            }
        }
    }
    return best;
}

/* Partition prim_index[begin, end) so primitives whose bin <= split.bin come first. Returns mid. */
static uint32_t partition(Builder *B, uint32_t begin, uint32_t end, const Box *cbox, Split s)
{
    float scale = (float)B->p->bins / (cbox->hi[s.axis] - cbox->lo[s.axis]);
    uint32_t *idx = B->b->prim_index;
    uint32_t i = begin, j = end;
    while (i < j) {
        uint32_t pi = idx[i];
        if (bin_of(B->centroid[3 * pi + s.axis], cbox->lo[s.axis], scale, B->p->bins) <= s.bin) {
            i++;
        } else {
            j--;
            idx[i] = idx[j];
            idx[j] = pi;
        }
    }
    return i;
}

static void make_leaf(BvhNode *n, uint32_t begin, uint32_t end)
{
    n->first = begin;
    n->count = end - begin;
    n->axis = 0;
}

int bvh_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out,
              char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (p->max_leaf_size < 1 || p->bins < 2 || p->bins > 256 || !(p->cost_traversal >= 0.0f) ||
        !(p->cost_intersect > 0.0f)) {
        snprintf(err, errlen, "bvh: bad parameters (leaf size %d, bins %d, costs %g/%g)",
                 p->max_leaf_size, p->bins, (double)p->cost_traversal, (double)p->cost_intersect);
        return -1;
    }
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
    out->nprims = n;
    if (n == 0)
        return 0;

    Builder B = {p, bmin, bmax, malloc(sizeof(float) * 3 * n), out};
    out->prim_index = malloc(sizeof(uint32_t) * n);
    out->nodes = malloc(sizeof(BvhNode) * (2 * (size_t)n - 1));
    Task *stack = malloc(sizeof(Task) * (2 * (size_t)n));
    if (!B.centroid || !out->prim_index || !out->nodes || !stack) {
        snprintf(err, errlen, "bvh: out of memory for %u primitives", n);
        free(B.centroid);
        free(stack);
        bvh_free(out);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        out->prim_index[i] = i;
        for (int k = 0; k < 3; k++)
            B.centroid[3 * i + k] = 0.5f * (bmin[3 * i + k] + bmax[3 * i + k]);
    }

    uint32_t sp = 0;
    out->nnodes = 1;
    stack[sp++] = (Task){0, 0, n, 1};
    while (sp > 0) {
        Task t = stack[--sp];
        BvhNode *node = &out->nodes[t.node];
        Box nb, cb;
        box_empty(&nb);
        box_empty(&cb);
        for (uint32_t j = t.begin; j < t.end; j++) {
            uint32_t pi = out->prim_index[j];
            box_grow(&nb, &bmin[3 * pi], &bmax[3 * pi]);
            box_grow(&cb, &B.centroid[3 * pi], &B.centroid[3 * pi]);
        }
        memcpy(node->bmin, nb.lo, sizeof nb.lo);
        memcpy(node->bmax, nb.hi, sizeof nb.hi);
        if (t.depth > out->depth)
            out->depth = t.depth;

        uint32_t count = t.end - t.begin;
        uint32_t mid = 0;
        uint32_t axis = 0;
        if (count > 1) {
            float parea = box_area(&nb);
            Split s = find_split(&B, t.begin, t.end, &cb, parea > 0.0f ? parea : 1.0f);
            float leaf_cost = p->cost_intersect * (float)count;
            if (s.axis >= 0 && (s.cost < leaf_cost || count > (uint32_t)p->max_leaf_size)) {
                mid = partition(&B, t.begin, t.end, &cb, s);
                axis = (uint32_t)s.axis;
            } else if (s.axis < 0 && count > (uint32_t)p->max_leaf_size) {
                /* All centroids coincide: no box split can separate them; halve by index so
                 * leaves stay within the size limit. */
                mid = t.begin + count / 2;
            }
        }
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
        stack[sp++] = (Task){left + 1, mid, t.end, t.depth + 1};
        stack[sp++] = (Task){left, t.begin, mid, t.depth + 1};
    }
    free(stack);
    free(B.centroid);
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
