/* sim/ref_random.c -- the golden model's counter-based random numbers (reference.h): a path's key
 * from the seed, pixel and sample, and its numbers by path vertex and dimension, each a hash of
 * integers that the kernel computes with the same vector integer instructions
 * (docs/golden-model.md).
 *
 * Owns: the hash and the mapping of its bits to [0, 1). Must not: know what a dimension is used
 * for (sim/reference.c names them).
 */
#include "reference.h"

/* A 32-bit integer hash with good avalanche (the "lowbias32" constants published by
 * C. Wellons, 2018): xor-shift, multiply, xor-shift, multiply, xor-shift -- seven vector integer
 * instructions in the kernel. */
uint32_t ref_hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint32_t ref_path_key(uint32_t seed, uint32_t pixel, uint32_t sample)
{
    return ref_hash32(ref_hash32(pixel ^ ref_hash32(seed)) + sample);
}

float ref_rand(uint32_t path_key, uint32_t vertex, uint32_t dim)
{
    uint32_t h = ref_hash32(path_key + vertex * 16u + dim);
    return (float)(h >> 8) * (1.0f / 16777216.0f);
}
