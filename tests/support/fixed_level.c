/* tests/support/fixed_level.c -- see fixed_level.h. */
#include "fixed_level.h"

#include <criterion/criterion.h>

static void below_push(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id)
{
    FixedLevel *b = self;
    cr_assert_lt(b->n, MAX_ANS);
    b->addr[b->n] = addr;
    b->write[b->n] = write;
    b->at[b->n] = cycle + BELOW_LATENCY;
    b->id[b->n++] = id;
}

static uint64_t below_next(const void *self)
{
    const FixedLevel *b = self;
    return b->head < b->n ? b->at[b->head] : UINT64_MAX;
}

static void below_run(void *self, uint64_t until, MemAnswer answer, void *ctx)
{
    FixedLevel *b = self;
    while (b->head < b->n && b->at[b->head] < until) {
        const int i = b->head++;
        answer(ctx, b->id[i], b->at[i]);
    }
}

MemLevel fixed_level(FixedLevel *b) { return (MemLevel){b, below_push, below_next, below_run}; }
