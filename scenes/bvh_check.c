/* scenes/bvh_check.c -- a build's input (bvh_check_input), a built BVH's invariants (bvh_check) and
 * its SAH cost (bvh_sah_cost).
 *
 * Owns: what a correct tree is. Must not: build or change a tree (scenes/bvh.c builds them).
 */
#include "bvh.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

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

/* First one pass without a branch per value (finite and ordered: lo <= hi, |lo| and |hi| <= FLT_MAX,
 * each false for a NaN), then, only when it fails, the loop that names the first bad box. */
static int check_boxes(const float *bmin, const float *bmax, uint32_t n, char *err, size_t errlen)
{
    int ok = 1;
    size_t t = 0, nt = 3 * (size_t)n;
#if defined(__SSE2__)
    /* the same comparisons, four values at a time (cmple is false for a NaN too) */
    __m128 all = _mm_castsi128_ps(_mm_set1_epi32(-1)), magnitude = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    __m128 big = _mm_set1_ps(FLT_MAX), good = all;
    for (; t + 4 <= nt; t += 4) {
        __m128 lo = _mm_loadu_ps(bmin + t), hi = _mm_loadu_ps(bmax + t);
        good = _mm_and_ps(good, _mm_cmple_ps(lo, hi));
        good = _mm_and_ps(good, _mm_cmple_ps(_mm_and_ps(lo, magnitude), big));
        good = _mm_and_ps(good, _mm_cmple_ps(_mm_and_ps(hi, magnitude), big));
    }
    ok = _mm_movemask_ps(good) == 15;
#endif
    for (; t < nt; t++)
        ok &= (bmin[t] <= bmax[t]) & (fabsf(bmin[t]) <= FLT_MAX) & (fabsf(bmax[t]) <= FLT_MAX);
    if (ok)
        return 0;
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

int bvh_check_input(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, char *err, size_t errlen)
{
    return check_params(p, err, errlen) != 0 || check_boxes(bmin, bmax, n, err, errlen) != 0 ? -1 : 0;
}

/* Six comparisons, no branch between them (most boxes are inside). */
static inline int inside(const float *lo, const float *hi, const float *plo, const float *phi)
{
    return !((lo[0] < plo[0]) | (lo[1] < plo[1]) | (lo[2] < plo[2]) | (hi[0] > phi[0]) | (hi[1] > phi[1]) |
             (hi[2] > phi[2]));
}

/* bvh_check's conditions without a branch per condition, and without naming a violation: 1 when
 * the tree passes them all, 0 otherwise (then bvh_check looks again, to name the first). seen_prim
 * and seen_node are zeroed. A leaf's primitives and an inner node's children are marked seen once;
 * with no mark made twice, every primitive is in a leaf when the leaves' counts add up to nprims,
 * and every node but the root is some node's child when the inner nodes are (nnodes - 1) / 2. */
static int check_fast(const Bvh *b, const float *bmin, const float *bmax, uint8_t *seen_prim, uint8_t *seen_node)
{
    uint32_t bad = 0, nprims = b->nprims, nnodes = b->nnodes, ninner = 0;
    uint64_t listed = 0;
    for (uint32_t i = 0; i < nnodes; i++) {
        const BvhNode *n = &b->nodes[i];
        /* not a NaN and not inverted */
        bad |= !(n->bmin[0] <= n->bmax[0]) | !(n->bmin[1] <= n->bmax[1]) | !(n->bmin[2] <= n->bmax[2]);
        if (n->count > 0) {
            if (n->first > nprims || n->count > nprims - n->first)
                return 0;
            listed += n->count;
            for (uint32_t j = n->first; j < n->first + n->count; j++) {
                uint32_t pi = b->prim_index[j];
                if (pi >= nprims)
                    return 0;
                bad |= seen_prim[pi];
                seen_prim[pi] = 1;
                bad |= !inside(&bmin[3 * pi], &bmax[3 * pi], n->bmin, n->bmax);
            }
        } else {
            if (n->first + 1 >= nnodes || n->first <= i || n->axis > 2)
                return 0;
            ninner++;
            for (uint32_t c = n->first; c <= n->first + 1; c++) {
                bad |= !inside(b->nodes[c].bmin, b->nodes[c].bmax, n->bmin, n->bmax);
                bad |= seen_node[c];
                seen_node[c] = 1;
            }
        }
    }
    return !bad && listed == nprims && 2 * (uint64_t)ninner == (uint64_t)nnodes - 1;
}

/* One pass over the nodes in index order. A child's index is above its parent's (checked), so a
 * node other than the root that is some inner node's child exactly once is reached from the root
 * exactly once: its parent, by induction on the index, is; so is every node, when each but the
 * root has one parent and the root none (no child index is 0). Visiting every node, reachable or
 * not, checks more than a walk from the root, and the pass keeps no stack. */
int bvh_check(const Bvh *b, const float *bmin, const float *bmax, char *err, size_t errlen)
{
    if (b->nprims == 0)
        return b->nnodes == 0 ? 0 : (snprintf(err, errlen, "bvh: nodes without primitives"), -1);
    int rc = -1;
    uint8_t *seen_prim = calloc(b->nprims, 1);
    uint8_t *seen_node = calloc(b->nnodes ? b->nnodes : 1, 1);
    if (!seen_prim || !seen_node) {
        snprintf(err, errlen, "bvh: out of memory");
        goto out;
    }
    if (b->nnodes == 0) {
        snprintf(err, errlen, "bvh: primitive 0 is in no leaf");
        goto out;
    }
    if (check_fast(b, bmin, bmax, seen_prim, seen_node)) {
        rc = 0;
        goto out;
    }
    memset(seen_prim, 0, b->nprims);
    memset(seen_node, 0, b->nnodes);
    for (uint32_t i = 0; i < b->nnodes; i++) {
        const BvhNode *n = &b->nodes[i];
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
                if (seen_node[c]++) {
                    snprintf(err, errlen, "bvh: node %u reached twice", c);
                    goto out;
                }
            }
        }
    }
    for (uint32_t i = 0; i < b->nprims; i++) {
        if (!seen_prim[i]) {
            snprintf(err, errlen, "bvh: primitive %u is in no leaf", i);
            goto out;
        }
    }
    for (uint32_t i = 1; i < b->nnodes; i++) {
        if (!seen_node[i]) {
            snprintf(err, errlen, "bvh: node %u is unreachable", i);
            goto out;
        }
    }
    rc = 0;
out:
    free(seen_prim);
    free(seen_node);
    return rc;
}

/* Surface area in double: a box of finite floats has a finite area here (extents up to 7e38,
 * products up to 5e77), where the float area overflows from extents of about 1e19 on (a sphere of
 * radius 1e30 gave inf / inf = NaN as the cost). */
static inline double node_area(const float *lo, const float *hi)
{
    double d[3];
    /* hi > lo exactly when the difference is above 0 (a positive difference of floats is not lost
     * in double), so this is hi > lo ? hi - lo : 0, without a branch (maxsd) */
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        d[k] = (double)hi[k] - (double)lo[k];
        d[k] = d[k] > 0.0 ? d[k] : 0.0;
    }
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
        /* both weights computed, one selected: leaves and inner nodes alternate unpredictably */
        double leaf = (double)p->cost_intersect * n->count, inner = (double)p->cost_traversal;
        cost += a * (n->count > 0 ? leaf : inner);
    }
    return cost;
}
