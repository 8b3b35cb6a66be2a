/* sim/run/accel.c -- building and packing the acceleration structures (see accel.h). */
#include "accel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../util.h"

int accel_prim_boxes(const PackedScene *p, float **bmin, float **bmax)
{
    uint32_t n = p->nprims, prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    *bmin = malloc(3 * ((size_t)n + 1) * sizeof **bmin);
    *bmax = malloc(3 * ((size_t)n + 1) * sizeof **bmax);
    if (!*bmin || !*bmax) {
        free(*bmin);
        free(*bmax);
        *bmin = *bmax = NULL;
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        float g[9];
        uint32_t a = sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_V0);
        for (int k = 0; k < 9; k++)
            g[k] = sm_f32(p, a + 4u * (uint32_t)k);
        int sphere = sm_u32(p, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_KIND)) == 1;
        for (int k = 0; k < 3; k++) {
            float lo, hi;
            if (sphere) {
                lo = g[k] - g[3];
                hi = g[k] + g[3];
            } else {
                lo = fminf(g[k], fminf(g[3 + k], g[6 + k]));
                hi = fmaxf(g[k], fmaxf(g[3 + k], g[6 + k]));
            }
            (*bmin)[3 * i + k] = lo;
            (*bmax)[3 * i + k] = hi;
        }
    }
    return 0;
}

int accel_kd_build(const PackedScene *p, const KdParams *kp, KdTree *out, char *err, size_t errlen)
{
    float *bmin, *bmax;
    if (accel_prim_boxes(p, &bmin, &bmax)) {
        snprintf(err, errlen, "kd-tree: out of memory for %u primitive boxes", p->nprims);
        return -1;
    }
    int rc = kd_build(kp, bmin, bmax, p->nprims, out, err, errlen);
    free(bmin);
    free(bmax);
    return rc;
}

void accel_kd_params(const CfgMachine *cfg, KdParams *kp)
{
    kd_default_params(kp);
    kp->cost_traversal = (float)cfg->kd_cost_traversal;
    kp->cost_intersect = (float)cfg->kd_cost_intersect;
    kp->empty_bonus = (float)cfg->kd_empty_bonus;
    kp->max_depth = cfg->kd_max_depth;
    kp->leaf_size = cfg->kd_leaf_size;
}

static void kd_info(const KdTree *t, AccelKdInfo *info)
{
    info->nodes = t->nnodes;
    info->leaves = t->nleaves;
    info->empty_leaves = t->nempty;
    info->depth = t->depth;
    info->largest_leaf = t->max_leaf;
    info->prims = t->nprims;
    info->refs = t->nrefs;
    info->sah_cost = t->sah_cost;
}

/* The invariants are checked on every build, as the BVH's are (scenes/pack.c): a broken tree
 * would silently lose geometry. */
static int kd_check_packed(const PackedScene *p, const KdTree *t, const CfgMachine *cfg, char *err, size_t errlen)
{
    float *bmin, *bmax;
    if (accel_prim_boxes(p, &bmin, &bmax) != 0) {
        snprintf(err, errlen, "accel.structure = kd: out of memory for %u primitive boxes", p->nprims);
        return -1;
    }
    char why[512];
    int rc = kd_check(t, bmin, bmax, why, sizeof why);
    if (rc != 0)
        snprintf(err, errlen,
                 "accel.structure = kd: the kd-tree built with kd.cost_traversal = %g, kd.cost_intersect = %g, "
                 "kd.empty_bonus = %g, kd.max_depth = %d, kd.leaf_size = %d breaks an invariant: %s",
                 cfg->kd_cost_traversal, cfg->kd_cost_intersect, cfg->kd_empty_bonus, cfg->kd_max_depth,
                 cfg->kd_leaf_size, why);
    free(bmin);
    free(bmax);
    return rc;
}

int accel_add_kd(PackedScene *p, const CfgMachine *cfg, AccelKdInfo *info, char *err, size_t errlen)
{
    memset(info, 0, sizeof *info);
    if (cfg->accel_structure != CFG_ACCEL_KD)
        return 0;
    double t0 = util_now();
    KdParams kp;
    accel_kd_params(cfg, &kp);
    KdTree t;
    char why[512];
    if (accel_kd_build(p, &kp, &t, why, sizeof why) != 0) {
        snprintf(err, errlen, "accel.structure = kd: %s", why);
        return -1;
    }
    int rc = kd_check_packed(p, &t, cfg, err, errlen);
    if (rc == 0 && (rc = pack_add_kd(p, &t, why, sizeof why)) != 0)
        snprintf(err, errlen, "accel.structure = kd: %s", why);
    if (rc == 0)
        kd_info(&t, info);
    kd_free(&t);
    info->build_seconds = util_now() - t0;
    return rc;
}

int accel_pack(const Scene *s, const CfgMachine *cfg, int kernel, PackedScene *out, AccelInfo *info, char *err,
               size_t errlen)
{
    memset(info, 0, sizeof *info);
    BvhParams bp;
    bvh_default_params(&bp);
    bp.max_leaf_size = cfg->bvh_leaf_size;
    bp.bins = cfg->bvh_bins;
    double t0 = util_now();
    if (pack_scene(s, &bp, 0, out, err, errlen) != 0)
        return -1;
    info->pack_seconds = util_now() - t0;
    /* The kernel modes with accel.structure = kd traverse a kd-tree; the golden model, the BVH. */
    return kernel ? accel_add_kd(out, cfg, &info->kd, err, errlen) : 0;
}
