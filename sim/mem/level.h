/* sim/mem/level.h -- a shared level of memory as the chip steps it (docs/chip.md): requests go in
 * stamped with their cycle, answers come out through a callback, and time moves only when the
 * chip says how far (run to a cycle). Beside port.h's synchronous port, which a private level
 * (the L1, the paper's bus) answers at once, this is the shape of a level whose answer depends on
 * what else arrives: an L2 with miss-status registers, a network, a DRAM controller.
 *
 * Owns: the shape of such a level. Must not: know what is behind one.
 *
 * The contract, for exactness: requests are pushed in non-decreasing cycle order (ties in the
 * order of the cores that sent them); run(until) does every event before `until` and no other;
 * an answer is never for a cycle before the run that gives it started; the same pushes and runs
 * give the same answers.
 */
#ifndef SFSIM_MEM_LEVEL_H
#define SFSIM_MEM_LEVEL_H

#include <stdint.h>

/* The core a request id belongs to (bits 48..63), and the id of core c's n-th request: the chip
 * stamps its requests so; a level may read the core (the network's ports, the L2's per-core
 * counts) and keeps the id whole. */
#define MEM_ID_CORE(id) ((uint32_t)((id) >> 48))
#define MEM_ID(core, n) ((uint64_t)(core) << 48 | ((n) & (((uint64_t)1 << 48) - 1)))

/* Set in an answer's id by a level that got the read's line from the level below it (an L2 miss
 * filled from DRAM); a level in front (the network) passes it on. Ids leave it clear. */
#define MEM_FROM_BELOW ((uint64_t)1 << 46)

/* A request done: its id as pushed, the cycle it is done (a read's data delivered, a write taken). */
typedef void (*MemAnswer)(void *ctx, uint64_t id, uint64_t cycle);

typedef struct MemLevel {
    void *self;
    void (*push)(void *self, uint64_t addr, int write, uint64_t cycle, uint64_t id);
    /* The cycle of the next thing the level will do on its own; UINT64_MAX: nothing pending. */
    uint64_t (*next)(const void *self);
    /* Every event before until; each request done is answered once through answer(ctx, ...). */
    void (*run)(void *self, uint64_t until, MemAnswer answer, void *ctx);
} MemLevel;

#endif
