/* sim/ref_vec.h -- the golden model's small vector helpers (sim/reference.c), each one fixed
 * sequence of binary32 operations that kernels/pathtrace.s repeats bit for bit: dot and cross
 * products, normalization, the float's bits, the self-intersection offset and the orthonormal
 * basis around a normal.
 *
 * Owns: that arithmetic, evaluated left to right as written (no fused multiply-add: the build's
 * -ffp-contract=off). Must not: know rays, scenes or materials.
 */
#ifndef SFSIM_REF_VEC_H
#define SFSIM_REF_VEC_H

#include <math.h>
#include <stdint.h>
#include <string.h>

static inline float dot3(const float *a, const float *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static inline void normalize3(float *v)
{
    float il = 1.0f / sqrtf(dot3(v, v));
    v[0] = v[0] * il;
    v[1] = v[1] * il;
    v[2] = v[2] * il;
}

static inline void cross3(const float *a, const float *b, float *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static inline float bits_to_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static inline uint32_t float_to_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* Move a hit point off its surface along n, scale-independently: a fixed number of ulps for
 * coordinates away from zero, a fixed distance near zero (Waechter and Binder, "A Fast and
 * Robust Method for Avoiding Self-Intersection", Ray Tracing Gems, 2019). */
static inline void offset_point(const float *p, const float *n, float *out)
{
    for (int k = 0; k < 3; k++) {
        int32_t of = (int32_t)(256.0f * n[k]);
        uint32_t bits = float_to_bits(p[k]);
        uint32_t moved = p[k] < 0.0f ? bits - (uint32_t)of : bits + (uint32_t)of;
        out[k] = fabsf(p[k]) < (1.0f / 32.0f) ? p[k] + (1.0f / 65536.0f) * n[k] : bits_to_float(moved);
    }
}

/* Orthonormal basis around n (Duff et al., "Building an Orthonormal Basis, Revisited", JCGT
 * 2017); returns x * t + y * b + z * n. */
static inline void to_world(const float *n, float x, float y, float z, float *out)
{
    float sign = copysignf(1.0f, n[2]);
    float a = -1.0f / (sign + n[2]);
    float b = n[0] * n[1] * a;
    float t[3] = {1.0f + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    float bv[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    for (int k = 0; k < 3; k++)
        out[k] = x * t[k] + y * bv[k] + z * n[k];
}

#endif
