/* tests/support/rng.h -- the tests' deterministic random numbers: xorshift64, the same sequence
 * every run from a state the test owns (static, so each test file keeps its own).
 */
#ifndef SFSIM_TEST_RNG_H
#define SFSIM_TEST_RNG_H

#include <stdint.h>

#define TEST_RNG_SEED 0x9E3779B97F4A7C15ull

/* The next 64-bit state. */
static inline uint64_t test_rng_step(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* 32 random bits. */
static inline uint32_t test_rng_u32(uint64_t *s) { return (uint32_t)(test_rng_step(s) >> 16); }

/* Uniform in [0, 1), 53 bits. */
static inline double test_rng_unit(uint64_t *s) { return (double)(test_rng_step(s) >> 11) * (1.0 / 9007199254740992.0); }

#endif
