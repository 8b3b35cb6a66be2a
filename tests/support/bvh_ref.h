/* tests/support/bvh_ref.h -- the binned SAH BVH build in its first, plain form: the reference
 * scenes/bvh.c's fast builder must match bit for bit (tests/unit/test_bvh.c).
 *
 * Owns: nothing the simulator uses. Must not: be optimised; its value is being obviously the
 * algorithm of bvh.h (Wald 2007 binning, same tie-breaks, same evaluation order).
 */
#ifndef SFSIM_TEST_BVH_REF_H
#define SFSIM_TEST_BVH_REF_H

#include "../../scenes/bvh.h"

/* The minimum and maximum the trees were first built with: the value held stays on a tie (the
 * first build called glibc's x86-64 fminf(new, held), which returns its second operand then),
 * which decides between -0.0 and +0.0. */
float bvh_ref_min(float held, float x);
float bvh_ref_max(float held, float x);

/* bvh_build's contract (boxes valid, parameters valid: the caller checks); 0, or -1 when out of
 * memory. */
int bvh_ref_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out);

#endif
