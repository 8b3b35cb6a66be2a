/* tests/support/fixed_level.h -- a memory level (sim/mem/level.h) that answers every request a
 * fixed 20 cycles after it comes, and keeps what it was asked: the level below the L2 and the
 * network in their hand-derived tests. */
#ifndef SFSIM_TESTS_FIXED_LEVEL_H
#define SFSIM_TESTS_FIXED_LEVEL_H

#include <stdint.h>

#include "../../sim/mem/level.h"

enum { BELOW_LATENCY = 20, MAX_ANS = 64 };

/* Pushes come in cycle order, so the answers are a queue. */
typedef struct FixedLevel {
    uint64_t addr[MAX_ANS], at[MAX_ANS], id[MAX_ANS];
    int write[MAX_ANS];
    int n, head;
} FixedLevel;

MemLevel fixed_level(FixedLevel *b);

#endif
