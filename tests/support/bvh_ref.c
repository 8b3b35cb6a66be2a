/* tests/support/bvh_ref.c -- the plain binned SAH build (see bvh_ref.h): every node rescans its
 * primitives through prim_index, every axis is binned and swept over all its bins. */
#include "bvh_ref.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

float bvh_ref_min(float held, float x) { return x < held ? x : held; }
float bvh_ref_max(float held, float x) { return x > held ? x : held; }

typedef struct RefBox { float lo[3], hi[3]; } RefBox;

static void ref_empty(RefBox *b)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = INFINITY;
        b->hi[k] = -INFINITY;
    }
}

static void ref_grow(RefBox *b, const float *lo, const float *hi)
{
    for (int k = 0; k < 3; k++) {
        b->lo[k] = bvh_ref_min(b->lo[k], lo[k]);
        b->hi[k] = bvh_ref_max(b->hi[k], hi[k]);
    }
}

static float ref_area(const RefBox *b)
{
    float d[3];
    for (int k = 0; k < 3; k++)
        d[k] = b->hi[k] > b->lo[k] ? b->hi[k] - b->lo[k] : 0.0f;
    return 2.0f * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
}

static int ref_bin(float c, float cmin, float scale, int bins)
{
    int i = (int)((c - cmin) * scale);
    return i < 0 ? 0 : (i >= bins ? bins - 1 : i);
}

typedef struct RefTask { uint32_t node, begin, end, depth; } RefTask;

typedef struct RefSplit { int axis, bin; float cost; } RefSplit;

typedef struct RefBuild {
    const BvhParams *p;
    const float *bmin, *bmax, *cent;
    uint32_t *idx;
} RefBuild;

/* The cost of every split of one axis's bins; the lowest (first on ties) replaces *best. */
static void ref_sweep(const RefBuild *R, const RefBox *bins, const uint32_t *cnt, int axis, uint32_t total,
                      float parea, RefSplit *best)
{
    int nb = R->p->bins;
    RefBox right[256], acc, left;
    ref_empty(&acc);
    for (int i = nb - 1; i > 0; i--) {
        ref_grow(&acc, bins[i].lo, bins[i].hi);
        right[i] = acc;
    }
    ref_empty(&left);
    uint32_t nleft = 0;
    for (int i = 0; i < nb - 1; i++) {
        ref_grow(&left, bins[i].lo, bins[i].hi);
        nleft += cnt[i];
        uint32_t nright = total - nleft;
        if (nleft == 0 || nright == 0)
            continue;
        float cost = R->p->cost_traversal +
                     R->p->cost_intersect * (ref_area(&left) * (float)nleft + ref_area(&right[i + 1]) * (float)nright) /
                         parea;
        if (cost < best->cost)
            *best = (RefSplit){axis, i, cost};
    }
}

static RefSplit ref_find_split(const RefBuild *R, uint32_t begin, uint32_t end, const RefBox *cb, float parea)
{
    int nb = R->p->bins;
    RefSplit best = {-1, 0, INFINITY};
    for (int axis = 0; axis < 3; axis++) {
        float extent = cb->hi[axis] - cb->lo[axis];
        if (!(extent > 0.0f))
            continue;
        float scale = (float)nb / extent;
        /* An infinite extent (centroids of boxes near FLT_MAX) gives scale 0: every centroid in
         * bin 0, so no split; skipped here rather than converting (inf - x) * 0 = NaN to int. */
        if (!isfinite(scale) || scale == 0.0f)
            continue;
        RefBox bins[256];
        uint32_t cnt[256];
        for (int i = 0; i < nb; i++) {
            ref_empty(&bins[i]);
            cnt[i] = 0;
        }
        for (uint32_t j = begin; j < end; j++) {
            uint32_t pi = R->idx[j];
            int i = ref_bin(R->cent[3 * pi + axis], cb->lo[axis], scale, nb);
            ref_grow(&bins[i], &R->bmin[3 * pi], &R->bmax[3 * pi]);
            cnt[i]++;
        }
        ref_sweep(R, bins, cnt, axis, end - begin, parea, &best);
    }
    return best;
}

static uint32_t ref_partition(RefBuild *R, uint32_t begin, uint32_t end, const RefBox *cb, RefSplit s)
{
    float scale = (float)R->p->bins / (cb->hi[s.axis] - cb->lo[s.axis]);
    uint32_t i = begin, j = end;
    while (i < j) {
        uint32_t pi = R->idx[i];
        if (ref_bin(R->cent[3 * pi + s.axis], cb->lo[s.axis], scale, R->p->bins) <= s.bin) {
            i++;
        } else {
            j--;
            R->idx[i] = R->idx[j];
            R->idx[j] = pi;
        }
    }
    return i;
}

/* Where the node over [begin, end) with box nb and centroid box cb splits; 0 for a leaf. */
static uint32_t ref_split_at(RefBuild *R, uint32_t begin, uint32_t end, const RefBox *nb, const RefBox *cb,
                             uint32_t *axis)
{
    uint32_t count = end - begin;
    *axis = 0;
    if (count < 2)
        return 0;
    float parea = ref_area(nb);
    RefSplit s = ref_find_split(R, begin, end, cb, parea > 0.0f ? parea : 1.0f);
    if (s.axis >= 0 && (s.cost < R->p->cost_intersect * (float)count || count > (uint32_t)R->p->max_leaf_size)) {
        *axis = (uint32_t)s.axis;
        return ref_partition(R, begin, end, cb, s);
    }
    if (s.axis < 0 && count > (uint32_t)R->p->max_leaf_size)
        return begin + count / 2;
    return 0;
}

int bvh_ref_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out)
{
    memset(out, 0, sizeof *out);
    out->nprims = n;
    if (n == 0)
        return 0;
    float *cent = malloc(sizeof(float) * 3 * n);
    RefTask *stack = malloc(sizeof *stack * 2 * (size_t)n);
    out->prim_index = malloc(sizeof(uint32_t) * n);
    out->nodes = malloc(sizeof(BvhNode) * (2 * (size_t)n - 1));
    if (!cent || !stack || !out->prim_index || !out->nodes) {
        free(cent);
        free(stack);
        bvh_free(out);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        out->prim_index[i] = i;
        for (int k = 0; k < 3; k++)
            cent[3 * i + k] = 0.5f * (bmin[3 * i + k] + bmax[3 * i + k]);
    }
    RefBuild R = {p, bmin, bmax, cent, out->prim_index};
    uint32_t sp = 0;
    out->nnodes = 1;
    stack[sp++] = (RefTask){0, 0, n, 1};
    while (sp > 0) {
        RefTask t = stack[--sp];
        BvhNode *node = &out->nodes[t.node];
        RefBox nb, cb;
        ref_empty(&nb);
        ref_empty(&cb);
        for (uint32_t j = t.begin; j < t.end; j++) {
            uint32_t pi = out->prim_index[j];
            ref_grow(&nb, &bmin[3 * pi], &bmax[3 * pi]);
            ref_grow(&cb, &cent[3 * pi], &cent[3 * pi]);
        }
        memcpy(node->bmin, nb.lo, sizeof nb.lo);
        memcpy(node->bmax, nb.hi, sizeof nb.hi);
        if (t.depth > out->depth)
            out->depth = t.depth;
        uint32_t axis, mid = ref_split_at(&R, t.begin, t.end, &nb, &cb, &axis);
        if (mid == 0) {
            node->first = t.begin;
            node->count = t.end - t.begin;
            node->axis = 0;
            out->nleaves++;
            continue;
        }
        uint32_t left = out->nnodes;
        out->nnodes += 2;
        node->first = left;
        node->count = 0;
        node->axis = axis;
        stack[sp++] = (RefTask){left + 1, mid, t.end, t.depth + 1};
        stack[sp++] = (RefTask){left, t.begin, mid, t.depth + 1};
    }
    free(stack);
    free(cent);
    out->sah_cost = bvh_sah_cost(out, p);
    return 0;
}
